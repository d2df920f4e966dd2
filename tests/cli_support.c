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
static cJSON *cases;
static char err_text[8192], out_text[65536]; /* what cli_run_here's run printed */

void cli_set_binary(const char *path) { radiosity_bin = path; }

const char *cli_binary(void) { return radiosity_bin; }

int cli_setup(const char *tag)
{
    if (test_workdir_make(tag) != 0)
        return -1;
    cases = cli_read_json(RAD_TEST_DATA "/cases.json");
    return cases ? 0 : -1;
}

int cli_teardown(void)
{
    cJSON_Delete(cases);
    cases = NULL;
    return test_workdir_remove();
}

cJSON *cli_read_json(const char *path)
{
    char *text = test_read_file(path, NULL);
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
    snprintf(w->obj_path, sizeof w->obj_path, "%s/%s.obj", test_workdir(), name);
    snprintf(mtl_path, sizeof mtl_path, "%s/%s.mtl", test_workdir(), name);
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

void cli_scene_two_surfaces(cli_scene_writer *w, const char *id, const char *name)
{
    const cJSON *g = cJSON_GetObjectItem(cli_find_case(id), "geometry");
    cli_scene_begin(w, name ? name : id);
    cli_scene_material(w, "grey", 0.5, 0.0);
    cli_scene_case_surface(w, cJSON_GetObjectItem(g, "A1"), "A1", "grey");
    cli_scene_case_surface(w, cJSON_GetObjectItem(g, "A2"), "A2", "grey");
    if (cJSON_GetObjectItem(g, "blocker"))
        cli_scene_case_surface(w, cJSON_GetObjectItem(g, "blocker"), "blocker", "grey");
    cli_scene_end(w);
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

/* ---- running in the work folder ---- */

int cli_run_here(const char *fmt, ...)
{
    char args[4096], cmd[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(args, sizeof args, fmt, ap);
    va_end(ap);
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' %s >stdout.txt 2>stderr.txt </dev/null", test_workdir(),
             radiosity_bin, args);
    int status = system(cmd);
    test_read_into(test_path("stderr.txt"), err_text, sizeof err_text);
    test_read_into(test_path("stdout.txt"), out_text, sizeof out_text);
    unlink(test_path("stderr.txt"));
    unlink(test_path("stdout.txt"));
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

const char *cli_stdout(void) { return out_text; }

const char *cli_stderr(void) { return err_text; }

void cli_stderr_from(const char *path) { test_read_into(path, err_text, sizeof err_text); }

void cli_assert_one_line_error(const char *needle1, const char *needle2)
{
    size_t len = strlen(err_text);
    if (len == 0 || err_text[len - 1] != '\n' || strchr(err_text, '\n') != err_text + len - 1)
        fail_msg("expected exactly one line on stderr, got: <%s>", err_text);
    if (needle1 && !strstr(err_text, needle1))
        fail_msg("stderr lacks '%s': %s", needle1, err_text);
    if (needle2 && !strstr(err_text, needle2))
        fail_msg("stderr lacks '%s': %s", needle2, err_text);
}

const char cli_good_mtl[] = "newmtl white\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n";

const char cli_good_obj[] = "mtllib good.mtl\n"
                            "o floor\nusemtl white\n"
                            "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 4 3 2\n"
                            "o lamp\nusemtl lamp\n"
                            "v 0 1 0\nv 1 1 0\nv 1 1 1\nv 0 1 1\nf 5 6 7 8\n";

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
