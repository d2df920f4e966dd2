/*
 * test_ff_methods.c -- the sampled and rasterised form-factor methods
 * (hemicube, hemisphere, montecarlo) against exact answers, through the
 * same command users run, plus the hemicube's delta factors directly.
 *
 * Each case of tests/data/cases.json is written as OBJ+MTL, `radiosity
 * viewfactors --form-factors NAME` runs on it, and the JSON it writes is
 * compared with the exact value:
 *
 *   hemicube    deterministic: within 1e-2 relative at --hemicube-res 512;
 *   hemisphere  Monte Carlo: within 4 of its reported standard errors
 *               ("F_std_error"), with enough rays that this is a tight test;
 *   montecarlo  Monte Carlo: within 3 standard errors, touching surfaces
 *               included (their calibration over seeds: test_ff_stats.c);
 *   occluded squares: within 1e-2 relative for all three.
 *
 * hybrid's energy in closed boxes: rows at most 1 + 1e-4, absorbed =
 * emitted and the furnace's B = E / (1 - rho) within 1e-4.
 *
 * Then every method against the analytic one on the Cornell box (per-surface
 * mean radiosity, within 1%: issue #3).  The path of the radiosity binary is argv[1].
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "cli_support.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "formfactor/formfactor.h"

/* The reported standard error of F[from][to] (RAD_FF_VARIANCE methods). */
static double vf_std_error(const cJSON *vf, const char *from, const char *to)
{
    return cli_vf_matrix(vf, "F_std_error", from, to);
}

/* How a method's answer is judged. */
typedef struct judge {
    const char *method;
    const char *options;     /* extra command-line options */
    double relative;         /* > 0: |F - exact| <= relative * exact */
    double sigmas;           /* > 0: |F - exact| <= sigmas * reported standard error ... */
    double sigmas_shared;    /* ... or this many where the surfaces share an edge */
    double max_std_error;    /* ... and the standard error <= this * exact, so the test is tight */
} judge;

/* One view factor against its exact value, as the judge says. */
static void check_factor(const judge *jd, const cJSON *vf, const char *from, const char *to, double exact,
                         bool shared_edge, const char *what)
{
    double got = cli_vf_get(vf, from, to);
    if (jd->relative > 0.0)
        cli_assert_relative(got, exact, jd->relative, what);
    if (jd->sigmas > 0.0) {
        double se = vf_std_error(vf, from, to), k = shared_edge ? jd->sigmas_shared : jd->sigmas;
        if (!(se > 0.0 && se <= jd->max_std_error * exact))
            fail_msg("%s (%s): standard error %.3e is not in (0, %.1e x %.6f]", what, jd->method, se,
                     jd->max_std_error, exact);
        if (!(fabs(got - exact) <= k * se))
            fail_msg("%s (%s): got %.9f, exact %.9f: %.2f standard errors (%.3e), more than %.0f", what,
                     jd->method, got, exact, (got - exact) / se, se, k);
    }
}

/* ---- the cases ---- */

/* Two surfaces (and the case's blocker, if any): F_12 and F_21. */
static void two_surface_case(const judge *jd, const char *id, bool shared_edge)
{
    const cJSON *c = cli_find_case(id);
    char name[128], options[256];
    snprintf(name, sizeof name, "%s_%s", id, jd->method);
    cli_scene_writer w;
    cli_scene_two_surfaces(&w, id, name);
    snprintf(options, sizeof options, "--form-factors %s %s", jd->method, jd->options);
    cJSON *vf = cli_view_factors(&w, options);
    /* Equal areas: F_21 = F_12. */
    check_factor(jd, vf, "A1", "A2", cli_exact_value(c), shared_edge, id);
    check_factor(jd, vf, "A2", "A1", cli_exact_value(c), shared_edge, id);
    if (strcmp(jd->method, "montecarlo") == 0) /* one estimate per pair: reciprocal by construction */
        cli_assert_relative(cli_vf_area(vf, "A1") * cli_vf_get(vf, "A1", "A2"),
                            cli_vf_area(vf, "A2") * cli_vf_get(vf, "A2", "A1"), 1e-6, "reciprocity");
    cJSON_Delete(vf);
}

/* Coaxial disks as inscribed regular 64-gons, against the exact value for
 * the polygons. */
static void disks_case(const judge *jd)
{
    const cJSON *c = cli_find_case("disks_r1_r1_h1");
    double exact = cJSON_GetObjectItem(cJSON_GetObjectItem(c, "tessellated_inscribed_regular_Ngon_F12"),
                                       "N=64")->valuedouble;
    enum { N = 64 };
    double d1[N][3], d2[N][3];
    for (int k = 0; k < N; k++) {
        double a = 2.0 * M_PI * k / N;
        d1[k][0] = cos(a), d1[k][1] = sin(a), d1[k][2] = 0.0;                       /* about +z */
        d2[N - 1 - k][0] = cos(a), d2[N - 1 - k][1] = sin(a), d2[N - 1 - k][2] = 1.0; /* about -z */
    }
    char name[128], options[256];
    snprintf(name, sizeof name, "disks_%s", jd->method);
    cli_scene_writer w;
    cli_scene_begin(&w, name);
    cli_scene_material(&w, "grey", 0.5, 0.0);
    cli_scene_polygon(&w, "disk1", "grey", (const double(*)[3])d1, N);
    cli_scene_polygon(&w, "disk2", "grey", (const double(*)[3])d2, N);
    cli_scene_end(&w);
    snprintf(options, sizeof options, "--form-factors %s %s", jd->method, jd->options);
    cJSON *vf = cli_view_factors(&w, options);
    check_factor(jd, vf, "disk1", "disk2", exact, false, "disk1 -> disk2");
    check_factor(jd, vf, "disk2", "disk1", exact, false, "disk2 -> disk1");
    cJSON_Delete(vf);
}

static const char *cube_faces[6] = {"x0", "x1", "y0", "y1", "z0", "z1"};

/* The closed unit cube: the full matrix (opposite faces are C-11, adjacent
 * ones share an edge, C-14) and the row sums, which must be 1. */
static void cube_case(const judge *jd, double row_tolerance)
{
    const cJSON *c = cli_find_case("cube_row_sum");
    const cJSON *g = cJSON_GetObjectItem(c, "geometry"), *M = cJSON_GetObjectItem(c, "full_matrix");
    char name[128], options[256];
    snprintf(name, sizeof name, "cube_%s", jd->method);
    cli_scene_writer w;
    cli_scene_begin(&w, name);
    cli_scene_material(&w, "grey", 0.5, 0.0);
    for (int f = 0; f < 6; f++)
        cli_scene_case_surface(&w, cJSON_GetObjectItem(g, cube_faces[f]), cube_faces[f], "grey");
    cli_scene_end(&w);
    snprintf(options, sizeof options, "--form-factors %s %s", jd->method, jd->options);
    cJSON *vf = cli_view_factors(&w, options);
    for (int i = 0; i < 6; i++) {
        double row = 0.0, row_var = 0.0;
        for (int j = 0; j < 6; j++) {
            double exact = cJSON_GetArrayItem(cJSON_GetArrayItem(M, i), j)->valuedouble;
            double got = cli_vf_get(vf, cube_faces[i], cube_faces[j]);
            row += got;
            if (jd->sigmas > 0.0)
                row_var += pow(vf_std_error(vf, cube_faces[i], cube_faces[j]), 2);
            char what[64];
            snprintf(what, sizeof what, "cube F[%s][%s]", cube_faces[i], cube_faces[j]);
            if (exact == 0.0)
                assert_true(fabs(got) < 1e-12); /* a face does not see itself */
            else
                check_factor(jd, vf, cube_faces[i], cube_faces[j], exact, i / 2 != j / 2, what);
        }
        /* Closure: |1 - row| within row_tolerance, or for sampled methods
         * within 4 standard errors of the row (independent pairs). */
        double tol = fmax(row_tolerance, 4.0 * sqrt(row_var));
        if (!(fabs(row - 1.0) <= tol))
            fail_msg("cube row %s (%s): sum %.9f, |1 - sum| > %.2e", cube_faces[i], jd->method, row, tol);
    }
    cJSON_Delete(vf);
}

/* ---- hemicube ---- */

/* Deterministic: 1e-2 relative at R = 512.  The errors are the one-point
 * (centroid) outer rule and aliasing; measured at 400 elements: parallel
 * 5e-4, perpendicular 1e-5, disks 6e-3, cube 2e-3, occluded 7e-3 (at 200
 * elements the disks' and the occluded case's exceed 1e-2). */
static const judge hemicube_judge = {"hemicube", "--hemicube-res 512 --elements 400", 1e-2, 0, 0, 0};

static void test_hemicube_delta_factors(void **state)
{
    (void)state;
    enum { R = 512 };
    double *delta = malloc(3 * (size_t)R * R * sizeof *delta);
    assert_non_null(delta);
    double sum = rad_hemicube_deltas(R, delta);
    /* Nusselt: the delta factors tile the hemisphere's projection. */
    assert_true(fabs(sum - 1.0) < 1e-6);
    double top = 0.0, h = 2.0 / R, worst = 0.0;
    for (size_t k = 0; k < (size_t)R * R; k++)
        top += delta[k];
    /* The top face alone: 4 x the corner-rectangle factor of [0,1]^2,
     * (2 sqrt(2) / pi) atan(1 / sqrt(2)); a swapped or mis-scaled formula
     * changes this at the first digit. */
    assert_true(fabs(top - 2.0 * sqrt(2.0) / M_PI * atan(1.0 / sqrt(2.0))) < 1e-9);
    /* Each pixel is its midpoint value dF = dA / (pi (x^2+y^2+1)^2) (top),
     * z dA / (pi (y^2+z^2+1)^2) (sides) up to O(h^2), and the faces are
     * symmetric. */
    for (int r = 0; r < R; r++)
        for (int c = 0; c < R; c++) {
            double x = -1.0 + (c + 0.5) * h, y = -1.0 + (r + 0.5) * h, q = x * x + y * y + 1.0;
            double mid = h * h / (M_PI * q * q), got = delta[(size_t)r * R + c];
            worst = fmax(worst, fabs(got / mid - 1.0));
            assert_true(fabs(got - delta[(size_t)(R - 1 - r) * R + c]) < 1e-15);
        }
    for (int face = 0; face < 4; face++)
        for (int r = 0; r < R / 2; r++)
            for (int c = 0; c < R; c++) {
                double y = -1.0 + (c + 0.5) * h, z = (r + 0.5) * h, q = y * y + z * z + 1.0;
                double mid = z * h * h / (M_PI * q * q);
                double got = delta[(size_t)R * R + ((size_t)face * (R / 2) + (size_t)r) * R + (size_t)c];
                worst = fmax(worst, fabs(got / mid - 1.0));
            }
    /* The midpoint rule's relative error, ~h^2/24 |laplacian f| / f:
     * measured 1.0e-5 at R = 512. */
    assert_true(worst < 3e-5);
    free(delta);
}

static void test_hemicube_parallel_squares(void **state)
{
    (void)state;
    two_surface_case(&hemicube_judge, "par_rect_1x1_d1", false);
}

static void test_hemicube_perpendicular_shared_edge(void **state)
{
    (void)state;
    two_surface_case(&hemicube_judge, "perp_rect_1_1_1_cube", true);
}

static void test_hemicube_disks(void **state)
{
    (void)state;
    disks_case(&hemicube_judge);
}

static void test_hemicube_cube(void **state)
{
    (void)state;
    /* Rows of a closed box sum to 1 to rounding: the faces' frustums tile
     * the hemisphere and the scanlines leave no pixel between two
     * polygons sharing an edge. */
    cube_case(&hemicube_judge, 1e-6);
}

static void test_hemicube_occluded(void **state)
{
    (void)state;
    two_surface_case(&hemicube_judge, "occluded_squares_blocker0.5", false);
}

/* ---- hemisphere ---- */

/* 4 standard errors, each at most 0.5% of the value (so this is a test to
 * 2%): 200 elements x 4096 rays.  The reported error, sqrt(F(1-F)/N) per
 * element pair, ignores the stratification and is conservative. */
static const judge hemisphere_judge = {"hemisphere", "--elements 200 --ff-samples 4096", 0, 4, 4, 5e-3};

static void test_hemisphere_parallel_squares(void **state)
{
    (void)state;
    two_surface_case(&hemisphere_judge, "par_rect_1x1_d1", false);
}

static void test_hemisphere_perpendicular_shared_edge(void **state)
{
    (void)state;
    two_surface_case(&hemisphere_judge, "perp_rect_1_1_1_cube", true);
}

static void test_hemisphere_disks(void **state)
{
    (void)state;
    disks_case(&hemisphere_judge);
}

static void test_hemisphere_cube(void **state)
{
    (void)state;
    /* Six faces share the elements: 300 of them for a 0.5% standard error.
     * Every ray from inside a closed box hits a wall, so rows are 1 up to
     * the density correction of non-parallelogram elements (none here). */
    judge jd = hemisphere_judge;
    jd.options = "--elements 300 --ff-samples 4096";
    cube_case(&jd, 1e-6);
}

static void test_hemisphere_occluded(void **state)
{
    (void)state;
    /* The blocker leaves F = 0.0314: 4x more rays for 1e-2 relative. */
    const judge jd = {"hemisphere", "--elements 200 --ff-samples 16384", 1e-2, 4, 4, 1e-2};
    two_surface_case(&jd, "occluded_squares_blocker0.5", false);
}

/* ---- montecarlo ---- */

/* 3 standard errors (the stratified variance), each at most 1% of the
 * value: 200 elements at the default samples (4 to 256 per pair by
 * nearness).  Touching surfaces no longer need more: near pairs integrate
 * the other polygon exactly, so the per-sample values are bounded
 * (ff_montecarlo.c). */
static const judge montecarlo_judge = {"montecarlo", "--elements 200", 0, 3, 3, 1e-2};

static void test_montecarlo_parallel_squares(void **state)
{
    (void)state;
    two_surface_case(&montecarlo_judge, "par_rect_1x1_d1", false);
}

static void test_montecarlo_perpendicular_shared_edge(void **state)
{
    (void)state;
    two_surface_case(&montecarlo_judge, "perp_rect_1_1_1_cube", true);
}

static void test_montecarlo_disks(void **state)
{
    (void)state;
    disks_case(&montecarlo_judge);
}

static void test_montecarlo_cube(void **state)
{
    (void)state;
    /* The default step holds the closed cube's rows to 1 (every closure
     * ray meets a wall): 1e-6, float rounding. */
    cube_case(&montecarlo_judge, 1e-6);
}

static void test_montecarlo_occluded(void **state)
{
    (void)state;
    const judge jd = {"montecarlo", "--elements 200 --ff-samples 64", 1e-2, 3, 3, 1e-2};
    two_surface_case(&jd, "occluded_squares_blocker0.5", false);
}

/* ---- non-parallelogram elements ---- */

/* Two trapezoids, one element each (--mesh-size 10), `height` apart and
 * the upper one moved `shift` along y: the bilinear map of
 * rad_element_sample is not uniform in area on them, so a sampled method
 * must carry its density correction or be biased (1.3% in the far case).
 * The analytic method (exact to ~1e-6 here) is the reference.  Near and far
 * pairs take different paths in montecarlo. */
static void trapezoids_case(const judge *jd, double height, double shift)
{
    const double a[4][3] = {{0, 0, 0}, {2, 0, 0}, {1.6, 1, 0}, {0.4, 1, 0}}; /* about +z */
    const double b[4][3] = {{0.3, 0.2 + shift, height}, {0.3, 1.2 + shift, height},
                            {1.7, 1.2 + shift, height}, {2.3, 0.2 + shift, height}}; /* about -z */
    char name[128], options[256];
    snprintf(name, sizeof name, "trapezoids_%g_%s", height, jd->method);
    cli_scene_writer w;
    cli_scene_begin(&w, name);
    cli_scene_material(&w, "grey", 0.5, 0.0);
    cli_scene_polygon(&w, "A1", "grey", a, 4);
    cli_scene_polygon(&w, "A2", "grey", b, 4);
    cli_scene_end(&w);
    cJSON *ref = cli_view_factors(&w, "--form-factors analytic --mesh-size 10");
    snprintf(options, sizeof options, "--form-factors %s --mesh-size 10 %s", jd->method, jd->options);
    cJSON *vf = cli_view_factors(&w, options);
    check_factor(jd, vf, "A1", "A2", cli_vf_get(ref, "A1", "A2"), false, name);
    check_factor(jd, vf, "A2", "A1", cli_vf_get(ref, "A2", "A1"), false, name);
    cJSON_Delete(ref);
    cJSON_Delete(vf);
}

static void test_trapezoids(void **state)
{
    (void)state;
    const judge hs = {"hemisphere", "--ff-samples 262144", 0, 4, 4, 5e-3};
    const judge mc = {"montecarlo", "--ff-samples 65536", 0, 3, 3, 5e-3};
    trapezoids_case(&hs, 0.5, 0.0);
    trapezoids_case(&mc, 0.5, 0.0);
    trapezoids_case(&mc, 4.0, 3.0); /* F = 0.012: the hemisphere would need 100x the rays */
}

/* ---- hybrid: energy in closed scenes ---- */

/* The box [0, X] x [0, Y] x [0, Z] with its faces wound inward: material
 * "wall" everywhere but the ceiling (z = Z), which takes "top". */
static void inward_box(cli_scene_writer *w, double X, double Y, double Z)
{
    const double face[6][4][3] = {
        {{0, 0, 0}, {X, 0, 0}, {X, Y, 0}, {0, Y, 0}}, /* floor, normal +z */
        {{0, 0, Z}, {0, Y, Z}, {X, Y, Z}, {X, 0, Z}}, /* ceiling, -z */
        {{0, 0, 0}, {0, 0, Z}, {X, 0, Z}, {X, 0, 0}}, /* y = 0, +y */
        {{0, Y, 0}, {X, Y, 0}, {X, Y, Z}, {0, Y, Z}}, /* y = Y, -y */
        {{0, 0, 0}, {0, Y, 0}, {0, Y, Z}, {0, 0, Z}}, /* x = 0, +x */
        {{X, 0, 0}, {X, 0, Z}, {X, Y, Z}, {X, Y, 0}}, /* x = X, -x */
    };
    const char *names[6] = {"floor", "ceiling", "y0", "y1", "x0", "x1"};
    for (int f = 0; f < 6; f++)
        cli_scene_polygon(w, names[f], f == 1 ? "top" : "wall", face[f], 4);
}

/* Rows, power and (furnace: every face emitting E) B = E / (1 - rho) of
 * hybrid on a closed box, to 1e-4.  The one-point (centroid) rule hybrid
 * had for far pairs put every row above 1 (docs/methods.md): measured,
 * the 1 x 2 x 3 m furnace at 482 elements rows up to 1.0048, B 7.0e-3
 * high, power 8.7e-3; CIE 171's 4 m cube at rho 0.95, ceiling emitting,
 * 384 elements: rows 1.0048, 3.1% more power absorbed than emitted.  Now
 * (2x2 Gauss over the receiver): -1.1e-5 / -1.4e-5 and -5.3e-5. */
static void hybrid_closed_box(const char *name, double X, double Y, double Z, double rho, bool furnace,
                              const char *mesh)
{
    const double E = furnace ? 0.5 : M_PI;
    cli_scene_writer w;
    cli_scene_begin(&w, name);
    cli_scene_material(&w, "wall", rho, furnace ? E : 0.0);
    cli_scene_material(&w, "top", rho, E);
    inward_box(&w, X, Y, Z);
    cli_scene_end(&w);
    char stats[600], png[600];
    snprintf(stats, sizeof stats, "%s.stats.json", w.obj_path);
    snprintf(png, sizeof png, "%s.png", w.obj_path);
    assert_int_equal(cli_run("render '%s' -o '%s' --stats '%s' --width 8 --height 8 --form-factors hybrid "
                             "--solver gauss-seidel --tolerance 1e-10 %s",
                             w.obj_path, png, stats, mesh),
                     0);
    cJSON *j = cli_read_json(stats);
    assert_non_null(j);
    double rows = cli_stats_number(j, "form_factors", "row_sum_max");
    double power = cli_stats_number(j, "power_W", "absorbed") / cli_stats_number(j, "power_W", "emitted") - 1.0;
    print_message("hybrid, %s: rows up to 1 + %.2e, absorbed / emitted - 1 = %.2e\n", name, rows - 1.0, power);
    if (!(rows <= 1.0 + 1e-4 && fabs(power) < 1e-4))
        fail_msg("hybrid, %s: rows up to 1 + %.2e, absorbed / emitted - 1 = %.2e (both within 1e-4)", name,
                 rows - 1.0, power);
    if (furnace) {
        const char *names[6] = {"floor", "ceiling", "y0", "y1", "x0", "x1"};
        for (int f = 0; f < 6; f++) {
            double B[3];
            cli_stats_surface_radiosity(j, names[f], B);
            char what[96];
            snprintf(what, sizeof what, "hybrid furnace, %s: B = E / (1 - rho)", names[f]);
            cli_assert_relative(B[0], E / (1.0 - rho), 1e-4, what);
        }
    }
    cJSON_Delete(j);
}

static void test_hybrid_furnace(void **state)
{
    (void)state;
    hybrid_closed_box("hybrid_furnace", 1, 2, 3, 0.8, true, "--elements 500");
}

static void test_hybrid_white_cube(void **state)
{
    (void)state;
    hybrid_closed_box("hybrid_cie171_cube", 4, 4, 4, 0.95, false, "--mesh-size 0.5");
}

/* ---- cross-method agreement: the Cornell box ---- */

/* Per-surface mean radiosity from `radiosity render --stats`. */
static cJSON *cornell_stats(const char *method, const char *extra)
{
    char stats[600], png[600];
    snprintf(stats, sizeof stats, "%s/cornell_%s.json", test_workdir(), method);
    snprintf(png, sizeof png, "%s/cornell_%s.png", test_workdir(), method);
    assert_int_equal(cli_run("render -o '%s' --stats '%s' --width 16 --height 16 --elements 1000 "
                             "--form-factors %s %s",
                             png, stats, method, extra),
                     0);
    cJSON *j = cli_read_json(stats);
    assert_non_null(j);
    return j;
}

static cJSON *cornell_analytic; /* the reference, computed once */

static void cross_method(const char *method, const char *extra, double tolerance)
{
    if (!cornell_analytic)
        cornell_analytic = cornell_stats("analytic", "");
    const cJSON *ref = cornell_analytic;
    cJSON *got = cornell_stats(method, extra);
    const cJSON *rs = cJSON_GetObjectItem(ref, "surfaces"), *gs = cJSON_GetObjectItem(got, "surfaces");
    int S = cJSON_GetArraySize(rs);
    assert_int_equal(S, 8);
    assert_int_equal(cJSON_GetArraySize(gs), S);
    for (int k = 0; k < S; k++) {
        const cJSON *a = cJSON_GetArrayItem(rs, k), *b = cJSON_GetArrayItem(gs, k);
        const char *name = cJSON_GetObjectItem(a, "name")->valuestring;
        assert_string_equal(name, cJSON_GetObjectItem(b, "name")->valuestring);
        for (int c = 0; c < 3; c++) {
            double x = cJSON_GetArrayItem(cJSON_GetObjectItem(a, "radiosity"), c)->valuedouble;
            double y = cJSON_GetArrayItem(cJSON_GetObjectItem(b, "radiosity"), c)->valuedouble;
            char what[128];
            snprintf(what, sizeof what, "Cornell box %s, channel %d: %s vs analytic", name, c, method);
            cli_assert_relative(y, x, tolerance, what);
        }
    }
    cJSON_Delete(got);
}

/* Issue #3: every method's per-surface means within 1% of analytic at
 * 1,000 elements, each at settings that keep its own error well below
 * that.  Measured (seed 0, worst surface and channel): contour 1.4e-3,
 * hybrid 2.8e-3, hemicube 4.1e-3 (R = 512), hemisphere 4.0e-3 (16,384
 * rays), montecarlo 1.2e-3 (256 pairs).  The analytic reference itself is
 * within 0.13% of a brute-force gather (262,144 cosine-weighted rays per
 * floor element, docs/methods.md).  Failure modes this catches: the
 * hemicube's one-point outer rule (+2.5% on the floor at R = 512: elements
 * straddling a block's footprint saw all or nothing), montecarlo at 64
 * pairs (+1.1%: edge-pair outliers), a wrong cosine weight or back-face
 * rule (5-35%). */
static void test_cornell_contour(void **state)
{
    (void)state;
    cross_method("contour", "", 0.01);
}

static void test_cornell_hybrid(void **state)
{
    (void)state;
    cross_method("hybrid", "", 0.01);
}

static void test_cornell_hemicube(void **state)
{
    (void)state;
    cross_method("hemicube", "--hemicube-res 512", 0.01);
}

static void test_cornell_hemisphere(void **state)
{
    (void)state;
    cross_method("hemisphere", "--ff-samples 16384", 0.01);
}

static void test_cornell_montecarlo(void **state)
{
    (void)state;
    cross_method("montecarlo", "--ff-samples 256", 0.01);
}

static int setup(void **state)
{
    (void)state;
    return cli_setup("ff-methods");
}

static int teardown(void **state)
{
    (void)state;
    cJSON_Delete(cornell_analytic);
    return cli_teardown();
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_ff_methods PATH_TO_RADIOSITY\n");
        return 2;
    }
    cli_set_binary(argv[1]);
    /* "--slow" after the program's path: the cases at scale instead of the quick ones. */
    bool slow = argc == 3 && strcmp(argv[2], "--slow") == 0;
    if (argc > 3 || (argc == 3 && !slow)) {
        fprintf(stderr, "usage: test_ff_methods PATH_TO_RADIOSITY [--slow]\n");
        return 2;
    }
    const struct CMUnitTest fast_tests[] = {
        cmocka_unit_test(test_hemicube_delta_factors),
        cmocka_unit_test(test_hemicube_parallel_squares),
        cmocka_unit_test(test_hemicube_perpendicular_shared_edge),
        cmocka_unit_test(test_hemicube_disks),
        cmocka_unit_test(test_hemicube_cube),
        cmocka_unit_test(test_hemicube_occluded),
        cmocka_unit_test(test_hemisphere_parallel_squares),
        cmocka_unit_test(test_hemisphere_perpendicular_shared_edge),
        cmocka_unit_test(test_hemisphere_disks),
        cmocka_unit_test(test_hemisphere_cube),
        cmocka_unit_test(test_hemisphere_occluded),
        cmocka_unit_test(test_montecarlo_parallel_squares),
        cmocka_unit_test(test_montecarlo_perpendicular_shared_edge),
        cmocka_unit_test(test_montecarlo_disks),
        cmocka_unit_test(test_montecarlo_cube),
        cmocka_unit_test(test_montecarlo_occluded),
        cmocka_unit_test(test_trapezoids),
        cmocka_unit_test(test_hybrid_furnace),
        cmocka_unit_test(test_hybrid_white_cube),
    };
    /* At scale: with --slow alone (CTest: test_ff_methods_slow, label slow). */
    const struct CMUnitTest slow_tests[] = {
        cmocka_unit_test(test_cornell_contour),
        cmocka_unit_test(test_cornell_hybrid),
        cmocka_unit_test(test_cornell_hemicube),
        cmocka_unit_test(test_cornell_hemisphere),
        cmocka_unit_test(test_cornell_montecarlo),
    };
    return slow ? cmocka_run_group_tests_name("ff_methods_slow", slow_tests, setup, teardown)
                : cmocka_run_group_tests_name("ff_methods", fast_tests, setup, teardown);
}
