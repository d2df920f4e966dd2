/*
 * cli_support.c -- helpers shared by the suites that drive the `radiosity`
 * program; see cli_support.h.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "cli_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static const char *radiosity_bin;
static char workdir[256];
static cJSON *cases;

void cli_set_binary(const char *path) { radiosity_bin = path; }

const char *cli_binary(void) { return radiosity_bin; }

const char *cli_workdir(void) { return workdir; }

int cli_setup(const char *tag)
{
    snprintf(workdir, sizeof workdir, "/tmp/radiosity-%s-XXXXXX", tag);
    if (!mkdtemp(workdir))
        return -1;
    cases = cli_read_json(RAD_TEST_DATA "/cases.json");
    return cases ? 0 : -1;
}

int cli_teardown(void)
{
    cJSON_Delete(cases);
    cases = NULL;
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", workdir);
    return system(cmd) == 0 ? 0 : -1;
}

char *cli_read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    if (buf)
        buf[n] = '\0';
    fclose(f);
    return buf;
}

cJSON *cli_read_json(const char *path)
{
    char *text = cli_read_text(path);
    if (!text)
        return NULL;
    cJSON *j = cJSON_Parse(text);
    free(text);
    return j;
}

const cJSON *cli_find_case(const char *id)
{
    const cJSON *c;
    cJSON_ArrayForEach(c, cJSON_GetObjectItem(cases, "cases"))
    {
        if (strcmp(cJSON_GetObjectItem(c, "id")->valuestring, id) == 0)
            return c;
    }
    fail_msg("case %s missing from cases.json", id);
    return NULL;
}

double cli_exact_value(const cJSON *c) { return cJSON_GetObjectItem(c, "exact")->valuedouble; }

/* ---- scenes ---- */

void cli_scene_begin(cli_scene_writer *w, const char *name)
{
    char mtl_path[512];
    snprintf(w->obj_path, sizeof w->obj_path, "%s/%s.obj", workdir, name);
    snprintf(mtl_path, sizeof mtl_path, "%s/%s.mtl", workdir, name);
    w->obj = fopen(w->obj_path, "w");
    w->mtl = fopen(mtl_path, "w");
    assert_non_null(w->obj);
    assert_non_null(w->mtl);
    fprintf(w->obj, "mtllib %s.mtl\n", name);
    w->vertices = 0;
}

void cli_scene_material(cli_scene_writer *w, const char *name, double rho, double E)
{
    const double rgb[3] = {rho, rho, rho};
    cli_scene_material_rgb(w, name, rgb, E);
}

void cli_scene_material_rgb(cli_scene_writer *w, const char *name, const double rho[3], double E)
{
    fprintf(w->mtl, "newmtl %s\nKd %.17g %.17g %.17g\nKe %.17g %.17g %.17g\n\n", name, rho[0], rho[1],
            rho[2], E / M_PI, E / M_PI, E / M_PI);
}

void cli_scene_polygon(cli_scene_writer *w, const char *surface, const char *material,
                       const double (*v)[3], int n)
{
    fprintf(w->obj, "o %s\nusemtl %s\n", surface, material);
    for (int k = 0; k < n; k++)
        fprintf(w->obj, "v %.17g %.17g %.17g\n", v[k][0], v[k][1], v[k][2]);
    fprintf(w->obj, "f");
    for (int k = 0; k < n; k++)
        fprintf(w->obj, " %d", w->vertices + k + 1);
    fprintf(w->obj, "\n");
    w->vertices += n;
}

int cli_case_vertices(const cJSON *surface, double v[16][3])
{
    int n = 0;
    const cJSON *p;
    cJSON_ArrayForEach(p, cJSON_GetObjectItem(surface, "vertices"))
    {
        if (n == 16)
            fail_msg("case surface with more than 16 vertices");
        for (int c = 0; c < 3; c++)
            v[n][c] = cJSON_GetArrayItem(p, c)->valuedouble;
        n++;
    }
    return n;
}

void cli_scene_case_surface(cli_scene_writer *w, const cJSON *surface, const char *name,
                            const char *material)
{
    static const double zero[3] = {0.0, 0.0, 0.0};
    cli_scene_case_surface_moved(w, surface, name, material, zero);
}

void cli_scene_case_surface_moved(cli_scene_writer *w, const cJSON *surface, const char *name,
                                  const char *material, const double offset[3])
{
    double v[16][3];
    int n = cli_case_vertices(surface, v);
    for (int k = 0; k < n; k++)
        for (int c = 0; c < 3; c++)
            v[k][c] += offset[c];
    cli_scene_polygon(w, name, material, (const double(*)[3])v, n);
}

void cli_scene_end(cli_scene_writer *w)
{
    fclose(w->obj);
    fclose(w->mtl);
}

/* ---- running ---- */

static int run_args(const char *errors, const char *fmt, va_list ap) CLI_PRINTF(2, 0);

static int run_args(const char *errors, const char *fmt, va_list ap)
{
    char args[2048], cmd[4096];
    vsnprintf(args, sizeof args, fmt, ap);
    if (errors)
        snprintf(cmd, sizeof cmd, "'%s' %s --quiet 2>'%s'", radiosity_bin, args, errors);
    else
        snprintf(cmd, sizeof cmd, "'%s' %s --quiet", radiosity_bin, args);
    int status = system(cmd);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int cli_run(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int status = run_args(NULL, fmt, ap);
    va_end(ap);
    return status;
}

int cli_run_capture(const char *errors, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int status = run_args(errors, fmt, ap);
    va_end(ap);
    return status;
}

cJSON *cli_view_factors(const cli_scene_writer *w, const char *extra)
{
    char out[600];
    snprintf(out, sizeof out, "%s.F.json", w->obj_path);
    assert_int_equal(cli_run("viewfactors '%s' -o '%s' %s", w->obj_path, out, extra), 0);
    cJSON *j = cli_read_json(out);
    assert_non_null(j);
    return j;
}

/* ---- reading output ---- */

int cli_surface_index(const cJSON *vf, const char *name)
{
    int i = 0;
    const cJSON *s;
    cJSON_ArrayForEach(s, cJSON_GetObjectItem(vf, "surfaces"))
    {
        if (strcmp(cJSON_GetObjectItem(s, "name")->valuestring, name) == 0)
            return i;
        i++;
    }
    fail_msg("surface %s not in the output", name);
    return -1;
}

double cli_vf_matrix(const cJSON *vf, const char *key, const char *from, const char *to)
{
    const cJSON *M = cJSON_GetObjectItem(vf, key);
    if (!M)
        fail_msg("no \"%s\" in the view-factor file", key);
    int i = cli_surface_index(vf, from), j = cli_surface_index(vf, to);
    return cJSON_GetArrayItem(cJSON_GetArrayItem(M, i), j)->valuedouble;
}

double cli_vf_get(const cJSON *vf, const char *from, const char *to)
{
    return cli_vf_matrix(vf, "F", from, to);
}

double cli_vf_area(const cJSON *vf, const char *name)
{
    int i = cli_surface_index(vf, name);
    return cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(vf, "surfaces"), i), "area")
        ->valuedouble;
}

double cli_stats_number(const cJSON *stats, const char *object, const char *key)
{
    const cJSON *v = cJSON_GetObjectItem(cJSON_GetObjectItem(stats, object), key);
    if (!cJSON_IsNumber(v))
        fail_msg("stats: %s.%s missing", object, key);
    return v->valuedouble;
}

void cli_stats_surface_radiosity(const cJSON *stats, const char *name, double rgb[3])
{
    const cJSON *s;
    cJSON_ArrayForEach(s, cJSON_GetObjectItem(stats, "surfaces"))
    {
        if (strcmp(cJSON_GetObjectItem(s, "name")->valuestring, name) == 0) {
            for (int c = 0; c < 3; c++)
                rgb[c] = cJSON_GetArrayItem(cJSON_GetObjectItem(s, "radiosity"), c)->valuedouble;
            return;
        }
    }
    fail_msg("surface %s not in stats", name);
}

void cli_assert_relative(double got, double exact, double tol, const char *what)
{
    double rel = fabs(got - exact) / fabs(exact);
    if (!(rel <= tol))
        fail_msg("%s: got %.12g, exact %.12g, relative error %.2e > %.1e", what, got, exact, rel, tol);
}
