/*
 * test_view3d.c -- View3D's files and the factors thermal solvers take:
 * .vs3 models read through the `radiosity` program and their .vf output
 * read back against closed forms (Howell's catalogue, cases C-11 and
 * C-14: parallel and perpendicular rectangles) and view-factor algebra
 * (sub-surfaces, null surfaces, combined surfaces, obstructions); the
 * enclosure smoothing on exact and perturbed matrices; the sparse
 * threshold; line-numbered errors for bad files, with nothing written.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli_support.h"
#include "core/core.h"
#include "radiosity.h"

#define DATA RAD_TEST_DATA "/view3d/"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int setup(void **state)
{
    (void)state;
    return cli_setup("view3d");
}

static int teardown(void **state)
{
    (void)state;
    return cli_teardown();
}

/* Howell C-11: directly opposed parallel rectangles a x b at distance c. */
static double parallel_rectangles(double a, double b, double c)
{
    double X = a / c, Y = b / c;
    double x1 = sqrt(1.0 + X * X), y1 = sqrt(1.0 + Y * Y);
    return 2.0 / (M_PI * X * Y) *
           (log(x1 * y1 / sqrt(1.0 + X * X + Y * Y)) + X * y1 * atan(X / y1) + Y * x1 * atan(Y / x1) -
            X * atan(X) - Y * atan(Y));
}

typedef struct vf_file {
    char program[64], version[64];
    int format, encl, emit, n;
    double area[8], F[8][8], emissivity[8];
} vf_file;

/* View3D's text file read as View3D's ReadVF reads it (docs/formats.md). */
static void read_vf(const char *path, vf_file *v)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char header[40];
    assert_non_null(fgets(header, 35, f));
    assert_int_equal(strlen(header), 31); /* padded to 30, then the newline */
    assert_int_equal(sscanf(header, "%63s %63s %d %d %d %d", v->program, v->version, &v->format, &v->encl,
                            &v->emit, &v->n), 6);
    assert_true(v->n >= 1 && v->n <= 8);
    for (int i = 0; i < v->n; i++)
        assert_int_equal(fscanf(f, "%lf", &v->area[i]), 1);
    for (int i = 0; i < v->n; i++)
        for (int j = 0; j < v->n; j++)
            assert_int_equal(fscanf(f, "%lf", &v->F[i][j]), 1);
    for (int i = 0; i < v->n; i++)
        assert_int_equal(fscanf(f, "%lf", &v->emissivity[i]), 1);
    double extra;
    assert_int_equal(fscanf(f, "%lf", &extra), EOF);
    fclose(f);
}

static void run_vs3(const char *name, const char *extra, vf_file *v)
{
    char out[512];
    snprintf(out, sizeof out, "%s/%s.vf", test_workdir(), name);
    assert_int_equal(cli_run("viewfactors %s%s.vs3 -o %s --elements 400 %s", DATA, name, out, extra), 0);
    read_vf(out, v);
}

/* 5e-6: the .vf file's six decimals, and the default method's error
 * (4e-7 on these) well inside it. */
#define VF_TOL 5e-6

static void test_parallel_squares(void **state)
{
    (void)state;
    vf_file v;
    run_vs3("parallel_squares", "", &v);
    assert_string_equal(v.program, "radiosity");
    assert_int_equal(v.format, 0);
    assert_int_equal(v.encl, 0);
    assert_int_equal(v.emit, 0);
    assert_int_equal(v.n, 2);
    assert_float_equal(v.area[0], 1.0, 1e-12);
    double exact = parallel_rectangles(1.0, 1.0, 1.0); /* 0.1998249 */
    assert_float_equal(v.F[0][1], exact, VF_TOL);
    assert_float_equal(v.F[1][0], exact, VF_TOL);
    assert_float_equal(v.F[0][0], 0.0, 0.0);
    /* Emissivities kept, in order (rho = 1 - emit in the scene). */
    assert_float_equal(v.emissivity[0], 0.9, 1e-12);
    assert_float_equal(v.emissivity[1], 0.5, 1e-12);
}

static void test_binary(void **state)
{
    (void)state;
    char out[512];
    snprintf(out, sizeof out, "%s/binary.vf", test_workdir());
    assert_int_equal(cli_run("viewfactors %sparallel_binary.vs3 -o %s --elements 400", DATA, out), 0);
    /* out=1: a 32-byte header ending in CR LF, then float32 areas, rows
     * and emissivities, nothing more (View3D's SaveF1). */
    FILE *f = fopen(out, "rb");
    assert_non_null(f);
    char header[33] = {0};
    assert_int_equal(fread(header, 1, 32, f), 32);
    assert_memory_equal(header + 30, "\r\n", 2);
    int format = -1, encl = -1, emit = -1, n = -1;
    assert_int_equal(sscanf(header, "%*s %*s %d %d %d %d", &format, &encl, &emit, &n), 4);
    assert_int_equal(format, 1);
    assert_int_equal(n, 2);
    float values[2 + 4 + 2];
    assert_int_equal(fread(values, sizeof *values, 8, f), 8);
    assert_int_equal(fgetc(f), EOF);
    fclose(f);
    assert_float_equal(values[0], 1.0, 1e-6);
    assert_float_equal(values[2 + 1], parallel_rectangles(1.0, 1.0, 1.0), 2e-6);
    assert_float_equal(values[2 + 2], parallel_rectangles(1.0, 1.0, 1.0), 2e-6);
    assert_float_equal(values[2 + 0], 0.0, 0.0);
    assert_float_equal(values[6], 0.9, 1e-6);
    assert_float_equal(values[7], 0.5, 1e-6);
}

static void test_perpendicular(void **state)
{
    (void)state;
    vf_file v;
    run_vs3("perpendicular", "", &v);
    /* Howell C-14 for unit squares sharing an edge: (1 - F_parallel) / 4. */
    double exact = 0.25 * (1.0 - parallel_rectangles(1.0, 1.0, 1.0));
    assert_float_equal(v.F[0][1], exact, VF_TOL);
    assert_float_equal(v.F[1][0], exact, VF_TOL);
}

static void test_cube_enclosure(void **state)
{
    (void)state;
    vf_file v;
    run_vs3("cube", "", &v); /* encl=1: smoothed as View3D normalises */
    assert_int_equal(v.encl, 1);
    assert_int_equal(v.n, 6);
    double opposite = parallel_rectangles(1.0, 1.0, 1.0);
    for (int i = 0; i < 6; i++) {
        double sum = 0.0;
        for (int j = 0; j < 6; j++)
            sum += v.F[i][j];
        assert_float_equal(sum, 1.0, 6 * 5e-7); /* six values rounded to 1e-6 */
        assert_float_equal(v.F[i][(i + 3) % 6], opposite, VF_TOL);
        assert_float_equal(v.F[i][(i + 1) % 6], 0.25 * (1.0 - opposite), VF_TOL);
    }
}

static void test_obstruction(void **state)
{
    (void)state;
    vf_file v;
    run_vs3("obstruction", "", &v);
    /* The obstruction is not in the output, and blocks the whole view. */
    assert_int_equal(v.n, 2);
    assert_float_equal(v.F[0][1], 0.0, 0.0);
    assert_float_equal(v.F[1][0], 0.0, 0.0);
}

static void test_blocker(void **state)
{
    (void)state;
    char out[512];
    snprintf(out, sizeof out, "%s/blocker.vf", test_workdir());
    assert_int_equal(cli_run("viewfactors %sblocker.vs3 -o %s", DATA, out), 0);
    vf_file v;
    read_vf(out, &v);
    assert_int_equal(v.n, 2);
    /* cases.json occluded_squares_blocker0.5: 0.0314027 (0.0685896 without
     * the blocker); the default 2000 elements give it to 3e-6. */
    const cJSON *c = cli_find_case("occluded_squares_blocker0.5");
    assert_float_equal(v.F[0][1], cli_exact_value(c), 1e-5);
    assert_float_equal(v.F[1][0], cli_exact_value(c), 1e-5);
}

static void test_window_and_null(void **state)
{
    (void)state;
    vf_file w, h;
    run_vs3("window", "", &w);
    run_vs3("null", "", &h);
    /* The wall is reported without the window's area, the window apart. */
    assert_int_equal(w.n, 3);
    assert_float_equal(w.area[0], 3.0, 1e-5);
    assert_float_equal(w.area[1], 1.0, 1e-5);
    assert_float_equal(w.emissivity[1], 0.8, 1e-12);
    /* Algebra: the wall and the window together are the 2 x 2 square. */
    double full = parallel_rectangles(2.0, 2.0, 1.0);
    assert_float_equal(3.0 * w.F[0][2] + 1.0 * w.F[1][2], 4.0 * full, 4 * VF_TOL);
    /* The window (1 x 1, centred) to the 2 x 2 wall opposite, by the
     * corner decomposition of four 1.5 x 1.5 rectangles' worth: symmetric
     * parts, so F = F(window -> 3x3 centred)... checked by reciprocity. */
    assert_float_equal(1.0 * w.F[1][2], 4.0 * w.F[2][1], 4 * VF_TOL);
    assert_float_equal(w.F[0][1], 0.0, 0.0); /* coplanar */
    /* A null surface is a hole: no surface of its own, the wall as above. */
    assert_int_equal(h.n, 2);
    assert_float_equal(h.area[0], 3.0, 1e-5);
    assert_float_equal(h.F[0][1], w.F[0][2], 2e-6);
}

static void test_mask(void **state)
{
    (void)state;
    vf_file m, h;
    run_vs3("mask", "", &m);
    run_vs3("null", "", &h);
    /* View3D's mask: the wall keeps its whole area (4 m^2), its factors are
     * those of the open part (the null case's wall, 3 m^2) times 3/4, plus
     * 1/4 to the mask; the mask sees only the wall; the facing wall sees
     * the open part only, and not the mask. */
    assert_int_equal(m.n, 3);
    assert_float_equal(m.area[0], 4.0, 1e-5);
    assert_float_equal(m.area[1], 1.0, 1e-5);
    assert_float_equal(m.F[0][1], 0.25, 1e-6);
    assert_float_equal(m.F[0][2], 0.75 * h.F[0][1], 2e-6);
    assert_float_equal(m.F[1][0], 1.0, 0.0);
    assert_float_equal(m.F[1][2], 0.0, 0.0);
    assert_float_equal(m.F[2][1], 0.0, 0.0);
    assert_float_equal(m.F[2][0], h.F[1][0], 2e-6);
    assert_float_equal(m.emissivity[1], 0.6, 1e-12);
}

static void test_combined(void **state)
{
    (void)state;
    vf_file v;
    run_vs3("combined", "", &v);
    assert_int_equal(v.n, 2); /* floor-b is part of floor */
    assert_float_equal(v.area[0], 2.0, 1e-12);
    double exact = parallel_rectangles(2.0, 1.0, 1.0);
    assert_float_equal(v.F[0][1], exact, VF_TOL);
    assert_float_equal(v.F[1][0], exact, VF_TOL);
}

static void test_script_f(void **state)
{
    (void)state;
    vf_file v;
    run_vs3("cube_two", "", &v);
    /* A two-surface enclosure (the floor, and the five other faces combined,
     * F_12 = 1): Hottel's closed form A1 SF_12 = 1 / ((1 - e1)/(e1 A1) +
     * 1/(A1 F_12) + (1 - e2)/(e2 A2)), rows summing to the emissivities. */
    assert_int_equal(v.emit, 1);
    assert_int_equal(v.n, 2);
    assert_float_equal(v.area[1], 5.0, 1e-12);
    double e1 = 0.5, e2 = 0.8, A1 = 1.0, A2 = 5.0;
    double sf12 = 1.0 / ((1.0 - e1) / (e1 * A1) + 1.0 / A1 + (1.0 - e2) / (e2 * A2)) / A1;
    assert_float_equal(v.F[0][1], sf12, VF_TOL);
    assert_float_equal(v.F[0][0], e1 - sf12, VF_TOL);
    assert_float_equal(v.F[1][0], A1 * sf12 / A2, VF_TOL);
    assert_float_equal(v.F[1][1], e2 - A1 * sf12 / A2, VF_TOL);
    assert_float_equal(v.emissivity[1], 0.8, 1e-12);
    /* Six faces, one of emissivity 0.9: reciprocal, rows sum to e_i. */
    run_vs3("cube_emit", "", &v);
    for (int i = 0; i < 6; i++) {
        double sum = 0.0;
        for (int j = 0; j < 6; j++) {
            sum += v.F[i][j];
            assert_float_equal(v.F[i][j], v.F[j][i], 1e-6);
        }
        assert_float_equal(sum, v.emissivity[i], 6 * 5e-7);
    }
    assert_float_equal(v.emissivity[1], 0.9, 1e-12);
}

/* The exact unit-cube matrix (opposite faces k, k+3). */
static void cube_matrix(double *F)
{
    double opposite = parallel_rectangles(1.0, 1.0, 1.0), side = 0.25 * (1.0 - opposite);
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++)
            F[i * 6 + j] = i == j ? 0.0 : (j == (i + 3) % 6 ? opposite : side);
}

static void check_closed(const double *F, const double *area, int n, double tol)
{
    for (int i = 0; i < n; i++) {
        double sum = 0.0;
        for (int j = 0; j < n; j++) {
            sum += F[i * n + j];
            assert_true(F[i * n + j] >= 0.0);
            assert_float_equal(area[i] * F[i * n + j], area[j] * F[j * n + i], tol);
        }
        assert_float_equal(sum, 1.0, tol);
    }
}

static void test_smooth_exact_unchanged(void **state)
{
    (void)state;
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    double F[36], G[36], area[6] = {1, 1, 1, 1, 1, 1};
    cube_matrix(F);
    /* Make the rows sum to 1 to the last bit first: the closed form is. */
    memcpy(G, F, sizeof F);
    rad_smooth_report rep;
    assert_int_equal(rad_view_factors_smooth(ctx, 6, area, G, true, &rep), RAD_OK);
    for (int k = 0; k < 36; k++)
        assert_float_equal(G[k], F[k], 1e-15);
    assert_true(rep.max_relative_change < 1e-14);
    rad_context_destroy(ctx);
}

static void test_smooth_perturbed(void **state)
{
    (void)state;
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    /* A box 1 x 2 x 3 is not needed: unequal areas by scaling the cube's
     * pairs would break its exactness, so perturb the cube by +-1%. */
    double exact[36], F[36], area[6] = {1, 1, 1, 1, 1, 1};
    cube_matrix(exact);
    double perturbation = 0.0;
    for (int k = 0; k < 36; k++) {
        double p = exact[k] * 0.01 * sin(7.0 * k + 1.0);
        F[k] = exact[k] + p;
        perturbation = fmax(perturbation, fabs(p));
    }
    rad_smooth_report rep;
    assert_int_equal(rad_view_factors_smooth(ctx, 6, area, F, true, &rep), RAD_OK);
    check_closed(F, area, 6, 1e-12);
    assert_true(rep.row_error_before > 1e-3);
    assert_true(rep.row_error_after < 1e-12);
    assert_true(rep.reciprocity_after < 1e-12);
    /* Closer to the exact matrix than the perturbed one was. */
    double moved = 0.0;
    for (int k = 0; k < 36; k++)
        moved = fmax(moved, fabs(F[k] - exact[k]));
    assert_true(moved < perturbation);
    for (int i = 0; i < 6; i++)
        assert_float_equal(F[i * 6 + i], 0.0, 0.0); /* F_ii of planar faces kept 0 */
    rad_context_destroy(ctx);
}

static void test_smooth_unequal_areas(void **state)
{
    (void)state;
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    /* Three surfaces of areas 1, 2, 3 seeing each other: a consistent
     * enclosure has A1 F12 = ... solved from the sums; start far from it. */
    double area[3] = {1.0, 2.0, 3.0};
    double F[9] = {0.0, 0.3, 0.6, 0.2, 0.0, 0.9, 0.25, 0.55, 0.0};
    rad_smooth_report rep;
    assert_int_equal(rad_view_factors_smooth(ctx, 3, area, F, true, &rep), RAD_OK);
    check_closed(F, area, 3, 1e-12);
    /* Three flat surfaces: the enclosure's factors are unique (g12 = 0,
     * g13 = 1, g23 = 2 from the sums), and smoothing must find them. */
    assert_float_equal(F[0 * 3 + 1], 0.0, 1e-12);
    assert_float_equal(F[0 * 3 + 2], 1.0, 1e-12);
    assert_float_equal(F[1 * 3 + 2], 1.0, 1e-12);
    rad_context_destroy(ctx);
}

static void test_smooth_arguments(void **state)
{
    (void)state;
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    double area[2] = {1.0, 2.0}, F[4] = {0.0, 0.5, 0.25, 0.0};
    assert_int_equal(rad_view_factors_smooth(NULL, 2, area, F, true, NULL), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_view_factors_smooth(ctx, 2, NULL, F, true, NULL), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_view_factors_smooth(ctx, 0, NULL, NULL, true, NULL), RAD_OK);
    /* Two plates of areas 1 and 2 that see only each other cannot both
     * close (A1 F12 = 1 and A2 F21 = 2): refused, F kept. */
    assert_int_equal(rad_view_factors_smooth(ctx, 2, area, F, true, NULL), RAD_ERROR_INVALID_ARGUMENT);
    assert_float_equal(F[1], 0.5, 0.0);
    /* ... but their measured sums can be kept (open: a singular system, its
     * null vector changing no factor). */
    assert_int_equal(rad_view_factors_smooth(ctx, 2, area, F, false, NULL), RAD_OK);
    assert_float_equal(F[1], 0.5, 1e-15);
    assert_float_equal(F[2], 0.25, 1e-15);
    /* Two equal facing plates close with F = 1: the least change does that. */
    double equal[2] = {1.0, 1.0}, G[4] = {0.0, 0.2, 0.2, 0.0};
    assert_int_equal(rad_view_factors_smooth(ctx, 2, equal, G, true, NULL), RAD_OK);
    assert_float_equal(G[1], 1.0, 1e-15);
    F[1] = -0.1;
    assert_int_equal(rad_view_factors_smooth(ctx, 2, area, F, false, NULL), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_write_view_factors_with(NULL, NULL, "x.vf", NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_context_destroy(ctx);
}

static void test_smooth_large(void **state)
{
    (void)state;
    /* 300 surfaces of seven sizes, every pair seeing each other, factors
     * far from reciprocal (independent random rows closing to 0.999): the
     * smoothing must still give reciprocity to rounding and rows to 1e-12. */
    enum { N = 300 };
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    double *F = malloc(N * N * sizeof *F), area[N];
    assert_non_null(F);
    uint64_t seed = 12345;
    for (int i = 0; i < N; i++) {
        area[i] = 1.0 + (double)(i % 7);
        double sum = 0.0;
        for (int j = 0; j < N; j++) {
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            F[i * N + j] = i == j ? 0.0 : (double)(seed >> 40) + 1.0;
            sum += F[i * N + j];
        }
        for (int j = 0; j < N; j++)
            F[i * N + j] /= sum * 1.001;
    }
    rad_smooth_report rep;
    assert_int_equal(rad_view_factors_smooth(ctx, N, area, F, true, &rep), RAD_OK);
    assert_true(rep.reciprocity_before > 0.1);
    assert_true(rep.reciprocity_after < 1e-15);
    assert_true(rep.row_error_after < 1e-12);
    for (int i = 0; i < N; i++) {
        double sum = 0.0;
        for (int j = 0; j < N; j++) {
            assert_true(F[i * N + j] >= 0.0);
            sum += F[i * N + j];
        }
        assert_float_equal(sum, 1.0, 1e-12);
    }
    free(F);
    rad_context_destroy(ctx);
}

static void test_sparse_threshold(void **state)
{
    (void)state;
    char out[512], errors[512];
    snprintf(out, sizeof out, "%s/cube.mtx", test_workdir());
    snprintf(errors, sizeof errors, "%s/errors.txt", test_workdir());
    /* 0.2 drops the opposite faces (0.19982): 24 factors kept, rows still 1. */
    assert_int_equal(cli_run("viewfactors %scube.vs3 -o %s --elements 400 --smooth enclosure "
                             "--sparse-threshold 0.2", DATA, out), 0);
    FILE *f = fopen(out, "r");
    assert_non_null(f);
    char line[256];
    int rows = -1, cols = -1, nnz = -1;
    while (fgets(line, sizeof line, f))
        if (line[0] != '%' && sscanf(line, "%d %d %d", &rows, &cols, &nnz) == 3)
            break;
    assert_int_equal(rows, 6);
    assert_int_equal(nnz, 24);
    double F[36] = {0}, area[6] = {1, 1, 1, 1, 1, 1};
    for (int k = 0; k < nnz; k++) {
        int i, j;
        double v;
        assert_int_equal(fscanf(f, "%d %d %lf", &i, &j, &v), 3);
        assert_true(v >= 0.2);
        F[(i - 1) * 6 + (j - 1)] = v;
    }
    fclose(f);
    check_closed(F, area, 6, 1e-12);
    for (int i = 0; i < 6; i++)
        assert_float_equal(F[i * 6 + (i + 1) % 6], 0.25, 1e-12);
    /* Options that cannot apply: usage errors before any work. */
    snprintf(line, sizeof line, "%s/cube.json", test_workdir());
    assert_int_equal(cli_run_capture(errors, "viewfactors %scube.vs3 -o %s --sparse-threshold 0.1", DATA, line), 2);
    assert_int_equal(cli_run_capture(errors, "viewfactors %scube.vs3 -o %s --level element --smooth open", DATA,
                                     out), 2);
    assert_int_not_equal(access(line, F_OK), 0);
    /* A threshold that leaves nothing: refused, nothing written. */
    unlink(out);
    assert_int_not_equal(cli_run_capture(errors, "viewfactors %scube.vs3 -o %s --elements 400 "
                                         "--sparse-threshold 0.9", DATA, out), 0);
    assert_int_not_equal(access(out, F_OK), 0);
}

static void expect_error(const char *text, int line, const char *words)
{
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    rad_scene *scene = NULL;
    rad_result r = rad_scene_load_memory(ctx, "bad.vs3", text, strlen(text), NULL, 0, &scene);
    assert_int_not_equal(r, RAD_OK);
    assert_null(scene);
    char where[32];
    snprintf(where, sizeof where, "bad.vs3:%d: ", line);
    const char *message = rad_context_error(ctx);
    if (!strstr(message, where) || !strstr(message, words))
        fail_msg("expected '%s...%s', got '%s'", where, words, message);
    rad_context_destroy(ctx);
}

#define HEAD "T bad\nF 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\n"

static void test_bad_files(void **state)
{
    (void)state;
    expect_error(HEAD "S 1 1 2 3 4 0 0 0.5\n", 7, "needs");
    expect_error(HEAD "S 1 1 2 3 9 0 0 0.5 a\n", 7, "vertex 9 of 4");
    expect_error("T x\nF 3\nV 1 0 0 nan\n", 3, "not a finite number");
    expect_error("T x\nF 3\nV 2 0 0 0\n", 3, "out of sequence");
    expect_error(HEAD "S 1 1 2 3 4 0 0 1.5 a\n", 7, "emissivity");
    expect_error(HEAD "S 1 1 2 2 4 0 0 0.5 a\n", 7, "repeats vertex 2");
    expect_error("T x\nF 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 2 0 0\nS 1 1 2 3 0 0 0 0.5 a\n", 6, "no area");
    expect_error(HEAD "V 5 0.5 0.5 0.5\nS 1 1 2 5 4 0 0 0.5 a\n", 8, "not planar");
    expect_error(HEAD "V 5 0.2 0.2 0\nS 1 1 2 5 4 0 0 0.5 a\n", 8, "not convex");
    expect_error(HEAD "S 1 1 2 3 4 0 0 0.5 a\nS 2 1 2 4 0 0 0 0.5 a\n", 8, "already surface 1");
    expect_error(HEAD "V 5 .2 .2 0\nV 6 .8 .2 0\nV 7 .8 .8 0\nS 1 1 2 3 4 0 0 0.5 a\nM 2 5 6 7 0 1 0 0.5 m\n",
                 11, "must face its base");
    expect_error(HEAD "S 1 1 2 3 4 0 0 0.5 a\nM 2 4 3 2 1 0 0 0.5 m\n", 8, "needs a base");
    expect_error(HEAD "S 1 1 2 3 4 0 0 0.5 a\nS 2 1 2 3 0 0 2 0.5 b\n", 8, "earlier surface");
    expect_error("T x\nC emit=1\nF 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 2 0 0\n"
                 "S 1 1 2 3 0 0 0 0.5 a\nS 2 2 4 3 0 0 1 0.6 b\n", 9, "emissivity 0.6 differs");
    expect_error("T x\nC row=2\nF 3\n", 2, "not supported");
    expect_error("T x\nC bogus=1\nF 3\n", 2, "unknown control");
    expect_error("T x\nF 3a\n", 2, "only F 3");
    expect_error(HEAD "S 1 1 2 3 4 0 0 0.5 a\nQ 2\n", 8, "unknown record");
    expect_error(HEAD "V 5 2 2 0\nS 1 1 2 3 4 0 0 0.5 a\nS 2 1 2 5 0 1 0 0.5 b\n", 9, "not inside");
    /* The program: a line-numbered error, exit 1, nothing written. */
    char bad[512], out[512], errors[512];
    snprintf(bad, sizeof bad, "%s/bad.vs3", test_workdir());
    snprintf(out, sizeof out, "%s/bad.vf", test_workdir());
    snprintf(errors, sizeof errors, "%s/errors.txt", test_workdir());
    FILE *f = fopen(bad, "w");
    assert_non_null(f);
    fputs(HEAD "S 1 1 2 3 4 0 0 0.5 a\nS 2 1 2 3 0 0 0 zero b\n", f);
    fclose(f);
    assert_int_equal(cli_run_capture(errors, "viewfactors %s -o %s", bad, out), 1);
    assert_int_not_equal(access(out, F_OK), 0);
    char *text = test_read_file(errors, NULL);
    assert_non_null(text);
    assert_non_null(strstr(text, "bad.vs3:8: surface 2: emissivity"));
    free(text);
}

/* Every allocation of the View3D path failing in turn (SQLite's sweep, as
 * test_alloc): loading with a sub-surface, a null surface, a mask, a
 * combined surface and an obstruction; the .vf with script-F; the sparse
 * .mtx with smoothing.  Each run ends with RAD_ERROR_OUT_OF_MEMORY and gives
 * all its memory back; the last succeeds. */
static const char sweep_vs3[] =
    "T sweep\nC encl=1 emit=1\nF 3\n"
    "V 1 0 0 0\nV 2 2 0 0\nV 3 2 2 0\nV 4 0 2 0\nV 5 0 0 1\nV 6 2 0 1\nV 7 2 2 1\nV 8 0 2 1\n"
    "V 9 .2 .2 0\nV 10 .6 .2 0\nV 11 .6 .6 0\nV 12 .2 .6 0\nV 13 1 1 0\nV 14 1.5 1 0\nV 15 1.5 1.5 0\n"
    "V 16 1 .2 0\nV 17 1.5 .2 0\nV 18 1.5 .6 0\nV 19 1 .6 0\nV 20 1 1 .5\nV 21 1.4 1 .5\nV 22 1.4 1.4 .5\n"
    "S 1 1 2 3 4 0 0 0.9 floor\nS 2 9 10 11 12 1 0 0.8 window\nN 3 13 15 14 0 1 0 0.9 hole\n"
    "M 4 16 19 18 17 1 0 0.7 mask\nS 5 5 8 7 6 0 0 0.9 ceiling\nS 6 1 5 6 2 0 0 0.9 wall-a\n"
    "S 7 2 6 7 3 0 6 0.9 wall-b\nO 8 20 22 21 0\nE\n";

static rad_result sweep_once(uint64_t fail_at, const char *folder)
{
    rad_context *ctx = NULL;
    rad_context_options co = {0};
    co.threads = 1;
    assert_int_equal(rad_context_create(&co, &ctx), RAD_OK);
    rad_context_fail_allocation(ctx, fail_at);
    rad_scene *scene = NULL;
    rad_solution *sol = NULL;
    rad_result r = rad_scene_load_memory(ctx, "sweep.vs3", sweep_vs3, sizeof sweep_vs3 - 1, NULL, 0, &scene);
    rad_options o = {0};
    o.target_elements = 60;
    if (r == RAD_OK)
        r = rad_solution_create(ctx, scene, &o, &sol);
    char path[512];
    if (r == RAD_OK) {
        snprintf(path, sizeof path, "%s/sweep.vf", folder);
        r = rad_solution_write_view_factors_with(ctx, sol, path, NULL);
    }
    if (r == RAD_OK) {
        rad_view_factor_options vo = {0};
        vo.smooth = RAD_SMOOTH_ENCLOSURE;
        vo.sparse_threshold = 1e-3;
        snprintf(path, sizeof path, "%s/sweep.mtx", folder);
        r = rad_solution_write_view_factors_with(ctx, sol, path, &vo);
    }
    if (r != RAD_OK && r != RAD_ERROR_OUT_OF_MEMORY)
        fail_msg("allocation %llu: %s", (unsigned long long)fail_at, rad_context_error(ctx));
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    assert_int_equal(rad_memory_in_use(ctx, RAD_MEM_CATEGORIES), 0);
    rad_context_destroy(ctx);
    return r;
}

static void test_allocation_sweep(void **state)
{
    (void)state;
    assert_int_equal(sweep_once(0, test_workdir()), RAD_OK);
    uint64_t k = 1;
    for (; k < 100000; k++)
        if (sweep_once(k, test_workdir()) == RAD_OK)
            break;
    assert_true(k > 20); /* the path does allocate, and every failure was reported */
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_view3d PATH_TO_RADIOSITY\n");
        return 2;
    }
    cli_set_binary(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parallel_squares),
        cmocka_unit_test(test_binary),
        cmocka_unit_test(test_perpendicular),
        cmocka_unit_test(test_cube_enclosure),
        cmocka_unit_test(test_obstruction),
        cmocka_unit_test(test_blocker),
        cmocka_unit_test(test_window_and_null),
        cmocka_unit_test(test_mask),
        cmocka_unit_test(test_combined),
        cmocka_unit_test(test_script_f),
        cmocka_unit_test(test_smooth_exact_unchanged),
        cmocka_unit_test(test_smooth_perturbed),
        cmocka_unit_test(test_smooth_unequal_areas),
        cmocka_unit_test(test_smooth_arguments),
        cmocka_unit_test(test_smooth_large),
        cmocka_unit_test(test_sparse_threshold),
        cmocka_unit_test(test_bad_files),
        cmocka_unit_test(test_allocation_sweep),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
