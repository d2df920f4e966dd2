/*
 * test_accuracy.c -- the engine against exact answers, through the same
 * command users run.
 *
 * Each test writes a scene from tests/data/cases.json (exact view factors
 * and radiosities; see tests/data/README.md for their sources) as OBJ+MTL,
 * runs `radiosity viewfactors` or `radiosity render --stats`, reads the JSON
 * it wrote and compares.  The path of the radiosity binary is argv[1].
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static const char *radiosity_bin;
static char workdir[256];
static cJSON *cases;

/* ---- helpers ---- */

static char *read_text(const char *path)
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

static cJSON *read_json(const char *path)
{
    char *text = read_text(path);
    if (!text)
        return NULL;
    cJSON *j = cJSON_Parse(text);
    free(text);
    return j;
}

static const cJSON *find_case(const char *id)
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

static double exact_value(const cJSON *c) { return cJSON_GetObjectItem(c, "exact")->valuedouble; }

/* A scene being written: OBJ text and MTL text. */
typedef struct scene_writer {
    FILE *obj, *mtl;
    int vertices;
    char obj_path[512];
} scene_writer;

static void scene_begin(scene_writer *w, const char *name)
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

/* rho and E (exitance, W/m^2); Ke = E / pi is emitted radiance. */
static void scene_material(scene_writer *w, const char *name, double rho, double E)
{
    fprintf(w->mtl, "newmtl %s\nKd %.17g %.17g %.17g\nKe %.17g %.17g %.17g\n\n", name, rho, rho, rho,
            E / M_PI, E / M_PI, E / M_PI);
}

static void scene_polygon(scene_writer *w, const char *surface, const char *material,
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

/* A surface of the case geometry, as listed in cases.json. */
static void scene_case_surface(scene_writer *w, const cJSON *surface, const char *name,
                               const char *material)
{
    const cJSON *verts = cJSON_GetObjectItem(surface, "vertices");
    double v[16][3];
    int n = 0;
    const cJSON *p;
    cJSON_ArrayForEach(p, verts)
    {
        for (int c = 0; c < 3; c++)
            v[n][c] = cJSON_GetArrayItem(p, c)->valuedouble;
        n++;
    }
    scene_polygon(w, name, material, (const double(*)[3])v, n);
}

static void scene_end(scene_writer *w)
{
    fclose(w->obj);
    fclose(w->mtl);
}

/* Run the binary with arguments; returns its exit status. */
static int run(const char *fmt, ...)
{
    char args[2048], cmd[4096];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(args, sizeof args, fmt, ap);
    va_end(ap);
    snprintf(cmd, sizeof cmd, "'%s' %s --quiet", radiosity_bin, args);
    int status = system(cmd);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* View factors of a written scene: returns the parsed JSON (caller frees). */
static cJSON *view_factors(const scene_writer *w, const char *extra)
{
    char out[600];
    snprintf(out, sizeof out, "%s.F.json", w->obj_path);
    assert_int_equal(run("viewfactors '%s' -o '%s' %s", w->obj_path, out, extra), 0);
    cJSON *j = read_json(out);
    assert_non_null(j);
    return j;
}

static int surface_index(const cJSON *vf, const char *name)
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

static double vf_get(const cJSON *vf, const char *from, const char *to)
{
    int i = surface_index(vf, from), j = surface_index(vf, to);
    return cJSON_GetArrayItem(cJSON_GetArrayItem(cJSON_GetObjectItem(vf, "F"), i), j)->valuedouble;
}

static double vf_area(const cJSON *vf, const char *name)
{
    int i = surface_index(vf, name);
    return cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(vf, "surfaces"), i), "area")
        ->valuedouble;
}

static void assert_relative(double got, double exact, double tol, const char *what)
{
    double rel = fabs(got - exact) / fabs(exact);
    if (!(rel <= tol))
        fail_msg("%s: got %.9f, exact %.9f, relative error %.2e > %.1e", what, got, exact, rel, tol);
}

/* ---- view factors between two surfaces ---- */

static void two_surface_case(const char *id, const char *extra, double tol)
{
    const cJSON *c = find_case(id);
    const cJSON *g = cJSON_GetObjectItem(c, "geometry");
    scene_writer w;
    scene_begin(&w, id);
    scene_material(&w, "grey", 0.5, 0.0);
    scene_case_surface(&w, cJSON_GetObjectItem(g, "A1"), "A1", "grey");
    scene_case_surface(&w, cJSON_GetObjectItem(g, "A2"), "A2", "grey");
    if (cJSON_GetObjectItem(g, "blocker"))
        scene_case_surface(&w, cJSON_GetObjectItem(g, "blocker"), "blocker", "grey");
    scene_end(&w);
    cJSON *vf = view_factors(&w, extra);
    double f12 = vf_get(vf, "A1", "A2"), f21 = vf_get(vf, "A2", "A1");
    assert_relative(f12, exact_value(c), tol, id);
    /* Reciprocity at surface level: A1 F12 = A2 F21. */
    assert_relative(vf_area(vf, "A1") * f12, vf_area(vf, "A2") * f21, 1e-6, "reciprocity");
    cJSON_Delete(vf);
}

static void test_parallel_squares(void **state)
{
    (void)state;
    two_surface_case("par_rect_1x1_d1", "", 1e-5); /* ~1e-8 at the defaults */
}

static void test_perpendicular_shared_edge(void **state)
{
    (void)state;
    two_surface_case("perp_rect_1_1_1_cube", "", 1e-5);
}

static void test_occluded_squares(void **state)
{
    (void)state;
    two_surface_case("occluded_squares_blocker0.5", "", 2e-3); /* ray-sampled: ~1e-4 at the defaults */
}

/* Coaxial disks as inscribed regular 64-gons: compare with the exact value
 * for the polygons (cases.json gives it; the circle's differs by 0.07%). */
static void test_coaxial_disks(void **state)
{
    (void)state;
    const cJSON *c = find_case("disks_r1_r1_h1");
    double exact = cJSON_GetObjectItem(cJSON_GetObjectItem(c, "tessellated_inscribed_regular_Ngon_F12"),
                                       "N=64")->valuedouble;
    enum { N = 64 };
    double d1[N][3], d2[N][3];
    for (int k = 0; k < N; k++) {
        double a = 2.0 * M_PI * k / N;
        d1[k][0] = cos(a), d1[k][1] = sin(a), d1[k][2] = 0.0;      /* counter-clockwise about +z */
        d2[N - 1 - k][0] = cos(a), d2[N - 1 - k][1] = sin(a), d2[N - 1 - k][2] = 1.0; /* about -z */
    }
    scene_writer w;
    scene_begin(&w, "disks");
    scene_material(&w, "grey", 0.5, 0.0);
    scene_polygon(&w, "disk1", "grey", (const double(*)[3])d1, N);
    scene_polygon(&w, "disk2", "grey", (const double(*)[3])d2, N);
    scene_end(&w);
    cJSON *vf = view_factors(&w, "");
    assert_relative(vf_get(vf, "disk1", "disk2"), exact, 1e-5, "disk1 -> disk2");
    assert_relative(vf_get(vf, "disk2", "disk1"), exact, 1e-5, "disk2 -> disk1");
    cJSON_Delete(vf);
}

/* ---- the unit cube: full matrix, closure ---- */

static const char *cube_faces[6] = {"x0", "x1", "y0", "y1", "z0", "z1"};

static void write_cube(scene_writer *w, const char *name, const char *case_id)
{
    const cJSON *c = find_case(case_id);
    const cJSON *g = cJSON_GetObjectItem(c, "geometry");
    scene_begin(w, name);
    for (int f = 0; f < 6; f++) {
        const cJSON *s = cJSON_GetObjectItem(g, cube_faces[f]);
        const cJSON *rho = cJSON_GetObjectItem(s, "rho"), *E = cJSON_GetObjectItem(s, "E");
        char mat[16];
        snprintf(mat, sizeof mat, "m_%s", cube_faces[f]);
        scene_material(w, mat, rho ? rho->valuedouble : 0.5, E ? E->valuedouble : 0.0);
        scene_case_surface(w, s, cube_faces[f], mat);
    }
    scene_end(w);
}

static void test_cube_matrix_and_closure(void **state)
{
    (void)state;
    const cJSON *c = find_case("cube_row_sum");
    const cJSON *M = cJSON_GetObjectItem(c, "full_matrix");
    scene_writer w;
    write_cube(&w, "cube", "cube_row_sum");
    cJSON *vf = view_factors(&w, "");
    for (int i = 0; i < 6; i++) {
        double row = 0.0;
        for (int j = 0; j < 6; j++) {
            double exact = cJSON_GetArrayItem(cJSON_GetArrayItem(M, i), j)->valuedouble;
            double got = vf_get(vf, cube_faces[i], cube_faces[j]);
            row += got;
            if (exact == 0.0)
                assert_true(fabs(got) < 1e-12);
            else
                assert_relative(got, exact, 1e-5, "cube F_ij");
        }
        assert_true(fabs(row - 1.0) < 1e-5);
        double reported = cJSON_GetObjectItem(
                              cJSON_GetArrayItem(cJSON_GetObjectItem(vf, "surfaces"), surface_index(vf, cube_faces[i])),
                              "row_sum")->valuedouble;
        assert_true(fabs(reported - row) < 1e-9);
    }
    cJSON_Delete(vf);
}

/* ---- radiosity: furnace, six-patch exact solution, energy balance ---- */

static cJSON *render_stats(const scene_writer *w, const char *extra)
{
    char stats[600], png[600];
    snprintf(stats, sizeof stats, "%s.stats.json", w->obj_path);
    snprintf(png, sizeof png, "%s.png", w->obj_path);
    assert_int_equal(run("render '%s' -o '%s' --stats '%s' --width 32 --height 32 %s", w->obj_path, png,
                         stats, extra),
                     0);
    cJSON *j = read_json(stats);
    assert_non_null(j);
    return j;
}

static void stats_surface_radiosity(const cJSON *stats, const char *name, double rgb[3])
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

static double stats_number(const cJSON *stats, const char *object, const char *key)
{
    return cJSON_GetObjectItem(cJSON_GetObjectItem(stats, object), key)->valuedouble;
}

static void furnace(const char *solver)
{
    scene_writer w;
    write_cube(&w, "furnace", "furnace_cube_rho0.5");
    char extra[128];
    snprintf(extra, sizeof extra, "--solver %s --elements 600", solver);
    cJSON *stats = render_stats(&w, extra);
    double exact = exact_value(find_case("furnace_cube_rho0.5"));
    for (int f = 0; f < 6; f++) {
        double B[3];
        stats_surface_radiosity(stats, cube_faces[f], B);
        for (int c = 0; c < 3; c++)
            assert_relative(B[c], exact, 1e-4, "furnace B");
    }
    /* Energy balance in a closed scene: all emitted power is absorbed. */
    assert_relative(stats_number(stats, "power_W", "absorbed"), stats_number(stats, "power_W", "emitted"),
                    1e-4, "absorbed vs emitted");
    cJSON_Delete(stats);
}

static void test_furnace_gauss_seidel(void **state)
{
    (void)state;
    furnace("gauss-seidel");
}

static void test_furnace_southwell(void **state)
{
    (void)state;
    furnace("southwell");
}

static void six_patch(const char *solver)
{
    const cJSON *c = find_case("cube_top_emitter_6patch");
    scene_writer w;
    write_cube(&w, "six_patch", "cube_top_emitter_6patch");
    char extra[128];
    /* --mesh-size 2: one element per face, as the exact solution assumes. */
    snprintf(extra, sizeof extra, "--solver %s --mesh-size 2 --tolerance 1e-9", solver);
    cJSON *stats = render_stats(&w, extra);
    assert_int_equal((int)cJSON_GetObjectItem(stats, "elements")->valuedouble, 6);
    for (int f = 0; f < 6; f++) {
        double B[3];
        stats_surface_radiosity(stats, cube_faces[f], B);
        double exact = cJSON_GetObjectItem(cJSON_GetObjectItem(c, "exact"), cube_faces[f])->valuedouble;
        for (int k = 0; k < 3; k++)
            assert_relative(B[k], exact, 1e-6, cube_faces[f]);
    }
    assert_relative(stats_number(stats, "power_W", "absorbed"), stats_number(stats, "power_W", "emitted"),
                    1e-6, "six-patch energy balance");
    cJSON_Delete(stats);
}

static void test_six_patch_gauss_seidel(void **state)
{
    (void)state;
    six_patch("gauss-seidel");
}

static void test_six_patch_southwell(void **state)
{
    (void)state;
    six_patch("southwell");
}

/* ---- matrix-free shooting: a Monte Carlo estimate of the same answers ---- */

/* Its error is statistical (~1/sqrt of the rays an element receives), so the
 * tolerances are a few standard errors at these ray counts, measured: the
 * furnace's faces scatter by ~0.1%, the six-patch faces by ~0.2%. */
static void test_shooting_exact_cases(void **state)
{
    (void)state;
    scene_writer w;
    write_cube(&w, "furnace_shoot", "furnace_cube_rho0.5");
    cJSON *stats = render_stats(&w, "--solver shooting --elements 96 --ff-samples 20000 --unshot-tolerance 1e-6");
    double exact = exact_value(find_case("furnace_cube_rho0.5"));
    for (int f = 0; f < 6; f++) {
        double B[3];
        stats_surface_radiosity(stats, cube_faces[f], B);
        assert_relative(B[0], exact, 1e-2, "shooting furnace");
    }
    /* Closed box: everything emitted is absorbed (what is not yet shot,
     * 1e-6 of it, aside). */
    assert_relative(stats_number(stats, "power_W", "absorbed"), stats_number(stats, "power_W", "emitted"),
                    1e-5, "shooting energy balance");
    cJSON_Delete(stats);

    const cJSON *c = find_case("cube_top_emitter_6patch");
    write_cube(&w, "six_shoot", "cube_top_emitter_6patch");
    stats = render_stats(&w, "--solver shooting --mesh-size 2 --ff-samples 100000 --unshot-tolerance 1e-7");
    for (int f = 0; f < 6; f++) {
        double B[3];
        stats_surface_radiosity(stats, cube_faces[f], B);
        double ex = cJSON_GetObjectItem(cJSON_GetObjectItem(c, "exact"), cube_faces[f])->valuedouble;
        assert_relative(B[0], ex, 1.5e-2, cube_faces[f]);
    }
    /* No matrix was stored. */
    assert_true(cJSON_GetObjectItem(cJSON_GetObjectItem(stats, "memory_bytes"), "form_factor_matrix")->valuedouble == 0.0);
    cJSON_Delete(stats);
}

/* ---- Embree against the brute-force reference, on the Cornell box ---- */

static void test_embree_matches_brute_force(void **state)
{
    (void)state;
    char a[600], b[600];
    snprintf(a, sizeof a, "%s/cornell_embree.json", workdir);
    snprintf(b, sizeof b, "%s/cornell_brute.json", workdir);
    assert_int_equal(run("viewfactors -o '%s' --elements 300 --visibility embree", a), 0);
    assert_int_equal(run("viewfactors -o '%s' --elements 300 --visibility brute", b), 0);
    cJSON *ja = read_json(a), *jb = read_json(b);
    assert_non_null(ja);
    assert_non_null(jb);
    const cJSON *Fa = cJSON_GetObjectItem(ja, "F"), *Fb = cJSON_GetObjectItem(jb, "F");
    int S = cJSON_GetArraySize(Fa);
    assert_int_equal(S, 8);
    double worst = 0.0, blocked = 0.0;
    for (int i = 0; i < S; i++)
        for (int j = 0; j < S; j++) {
            double x = cJSON_GetArrayItem(cJSON_GetArrayItem(Fa, i), j)->valuedouble;
            double y = cJSON_GetArrayItem(cJSON_GetArrayItem(Fb, i), j)->valuedouble;
            worst = fmax(worst, fabs(x - y));
            blocked += x;
        }
    /* Same seeded rays: only rays grazing an edge within float rounding may
     * differ, each moving one pair's visibility by 1/4 of a small factor. */
    assert_true(worst < 1e-4);
    assert_true(blocked > 1.0); /* the comparison saw real factors */
    cJSON_Delete(ja);
    cJSON_Delete(jb);
}

/* ---- the Cornell box: closure with occlusion, energy, reciprocity ---- */

static void test_cornell_box_closure_and_energy(void **state)
{
    (void)state;
    char stats_path[600], png[600];
    snprintf(stats_path, sizeof stats_path, "%s/cornell_stats.json", workdir);
    snprintf(png, sizeof png, "%s/cornell.png", workdir);
    assert_int_equal(run("render -o '%s' --stats '%s' --elements 1000 --width 64 --height 64", png,
                         stats_path),
                     0);
    cJSON *s = read_json(stats_path);
    assert_non_null(s);
    /* The box is open at the front (z = 0): rows sum below 1.  A row can
     * exceed 1 only by the noise of its shadow-ray visibility estimates
     * (unbiased; ~0.2% on the worst of 1000 rows at 4-16 rays per pair);
     * a closure error of the factors themselves would show as a mean above
     * the open box's (~0.81). */
    assert_true(stats_number(s, "form_factors", "row_sum_max") < 1.0 + 5e-3);
    assert_true(stats_number(s, "form_factors", "row_sum_mean") < 0.83);
    assert_true(stats_number(s, "form_factors", "row_sum_mean") > 0.78);
    assert_true(stats_number(s, "form_factors", "reciprocity_max") < 1e-5);
    assert_true(stats_number(s, "form_factors", "diagonal_max") == 0.0);
    double emitted = stats_number(s, "power_W", "emitted"), absorbed = stats_number(s, "power_W", "absorbed");
    double escaped = stats_number(s, "power_W", "escaped");
    assert_true(absorbed > 0.3 * emitted && absorbed < emitted);
    assert_relative(absorbed + escaped, emitted, 1e-9, "power bookkeeping");
    assert_true(stats_number(s, "solver", "residual") < 1e-6);
    /* Colour bleeding: the red wall reflects mostly red, the green mostly green. */
    double red[3], green[3];
    stats_surface_radiosity(s, "left_wall", red);
    stats_surface_radiosity(s, "right_wall", green);
    assert_true(red[0] > 3.0 * red[1]);
    assert_true(green[1] > 2.0 * green[0]);
    cJSON_Delete(s);
}

static int setup(void **state)
{
    (void)state;
    snprintf(workdir, sizeof workdir, "/tmp/radiosity-accuracy-XXXXXX");
    if (!mkdtemp(workdir))
        return -1;
    cases = read_json(RAD_TEST_DATA "/cases.json");
    return cases ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    cJSON_Delete(cases);
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", workdir);
    return system(cmd) == 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_accuracy PATH_TO_RADIOSITY\n");
        return 2;
    }
    radiosity_bin = argv[1];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parallel_squares),
        cmocka_unit_test(test_perpendicular_shared_edge),
        cmocka_unit_test(test_coaxial_disks),
        cmocka_unit_test(test_occluded_squares),
        cmocka_unit_test(test_cube_matrix_and_closure),
        cmocka_unit_test(test_furnace_gauss_seidel),
        cmocka_unit_test(test_furnace_southwell),
        cmocka_unit_test(test_six_patch_gauss_seidel),
        cmocka_unit_test(test_six_patch_southwell),
        cmocka_unit_test(test_shooting_exact_cases),
        cmocka_unit_test(test_embree_matches_brute_force),
        cmocka_unit_test(test_cornell_box_closure_and_energy),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
