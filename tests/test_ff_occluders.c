/*
 * test_ff_occluders.c -- the analytic method's visibility without rays
 * (src/formfactor/occluders.c): which pairs are clear, blocked or partial,
 * the source minus the blockers' shadows, and what they give on the
 * View3D box of bench/view3d_box.py (a closed unit box, faces split
 * N x N, a 0.3 m cube in its middle: every row of F sums to exactly 1).
 *
 *   - on the box at 8 x 8 per face, every pair called clear has all of 64
 *     shadow rays pass, every pair called blocked all 64 blocked, and all
 *     three verdicts occur; on the Cornell box (its blocks bent by up to
 *     2 mm) too;
 *   - a point's factor to a square half hidden by one blocker is half the
 *     square's (by symmetry), and a quarter with a second blocker that
 *     overlaps the first's shadow (the overlap is not subtracted twice);
 *   - the box at 8 x 8 per face (390 elements): rows within 1e-3 of 1
 *     (measured 4.6e-4: elements 1/8 m against a 0.3 m cube leave wide
 *     penumbras) and at 20 x 20 (2,406 elements) within 2e-4 (measured
 *     1.75e-4; the target); without the cube within 2e-5 (the
 *     quadrature alone, 1.4e-5); no ray cast; reciprocity to rounding; F
 *     the same bit for bit with 1 and 2 threads.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "formfactor/formfactor.h"
#include "scene/scene.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The box of bench/view3d_box.py: faces n x n quads (inward), each a
 * polygon of its face's surface; with `cube`, the cube's six faces. */
static rad_scene *box_scene(rad_context *ctx, int n, bool cube)
{
    rad_scene_builder *b = rad_scene_builder_create(ctx, "view3d box");
    assert_non_null(b);
    const double grey[3] = {0.5, 0.5, 0.5}, black[3] = {0, 0, 0};
    int mat = rad_scene_builder_material(b, "grey", grey, black);
    /* face f: point (u, v) -> corner; counter-clockwise seen from inside */
    for (int f = 0; f < 6; f++) {
        static const char *names[6] = {"floor", "ceiling", "x0", "x1", "y0", "y1"};
        int surface = rad_scene_builder_surface(b, names[f]);
        for (int a = 0; a < n; a++)
            for (int c = 0; c < n; c++) {
                double uv[4][2] = {{(double)a / n, (double)c / n},
                                   {(double)(a + 1) / n, (double)c / n},
                                   {(double)(a + 1) / n, (double)(c + 1) / n},
                                   {(double)a / n, (double)(c + 1) / n}};
                vec3 q[4];
                for (int k = 0; k < 4; k++) {
                    double u = uv[k][0], v = uv[k][1];
                    switch (f) {
                    case 0: q[k] = v3(u, v, 0.0); break;
                    case 1: q[k] = v3(v, u, 1.0); break;
                    case 2: q[k] = v3(0.0, u, v); break;
                    case 3: q[k] = v3(1.0, v, u); break;
                    case 4: q[k] = v3(v, 0.0, u); break;
                    default: q[k] = v3(u, 1.0, v); break;
                    }
                }
                assert_int_equal(rad_scene_builder_polygon(b, surface, mat, q, 4, 0), RAD_OK);
            }
    }
    if (cube) {
        const double lo = 0.35, hi = 0.65;
        const vec3 faces[6][4] = {
            {{lo, lo, lo}, {lo, hi, lo}, {hi, hi, lo}, {hi, lo, lo}},
            {{lo, lo, hi}, {hi, lo, hi}, {hi, hi, hi}, {lo, hi, hi}},
            {{lo, lo, lo}, {lo, lo, hi}, {lo, hi, hi}, {lo, hi, lo}},
            {{hi, lo, lo}, {hi, hi, lo}, {hi, hi, hi}, {hi, lo, hi}},
            {{lo, lo, lo}, {hi, lo, lo}, {hi, lo, hi}, {lo, lo, hi}},
            {{lo, hi, lo}, {lo, hi, hi}, {hi, hi, hi}, {hi, hi, lo}},
        };
        int surface = rad_scene_builder_surface(b, "cube");
        for (int f = 0; f < 6; f++)
            assert_int_equal(rad_scene_builder_polygon(b, surface, mat, faces[f], 4, 0), RAD_OK);
    }
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    return scene;
}

typedef struct box_run {
    rad_context *ctx;
    rad_scene *scene;
    rad_mesh *mesh;
    rad_vis *vis;
} box_run;

static void box_open(box_run *r, int n, bool cube, int threads)
{
    rad_context_options co = {0};
    co.threads = threads;
    assert_int_equal(rad_context_create(&co, &r->ctx), RAD_OK);
    r->scene = box_scene(r->ctx, n, cube);
    rad_mesh_options mo = {10.0, 0, 0}; /* one element per polygon */
    assert_int_equal(rad_mesh_build(r->ctx, r->scene, &mo, &r->mesh), RAD_OK);
    assert_int_equal(r->mesh->element_count, (size_t)(6 * n * n + (cube ? 6 : 0)));
    assert_int_equal(rad_vis_create(r->ctx, "embree", r->mesh, &r->vis), RAD_OK);
}

static void box_close(box_run *r)
{
    rad_vis_destroy(r->vis);
    rad_mesh_destroy(r->mesh);
    rad_scene_destroy(r->scene);
    rad_context_destroy(r->ctx);
}

/* F of the box by the analytic method, its stats in *st. */
static double *box_factors(box_run *r, rad_ff_stats *st)
{
    rad_ff_request req = {0};
    req.mesh = r->mesh;
    req.vis = r->vis;
    double *F = NULL;
    assert_int_equal(rad_form_factors(r->ctx, rad_ff_find("analytic"), &req, 1e12, false, &F, NULL, st), RAD_OK);
    return F;
}

static double worst_row(const rad_ff_stats *st)
{
    return fmax(fabs(st->row_sum_max - 1.0), fabs(st->row_sum_min - 1.0));
}

/* Every pair's verdict against 64 stratified shadow rays: clear ones all
 * pass, blocked ones none; counts[3] of the verdicts. */
static void verdicts_against_rays(box_run *r, size_t counts[3])
{
    void *block = NULL;
    const rad_ff_occluders *occ = NULL;
    assert_int_equal(rad_ff_occluders_build(r->ctx, r->mesh, 16, &block, &occ), RAD_OK);
    assert_non_null(occ);
    double eps = rad_vis_epsilon(r->mesh), tol = rad_ff_plane_tolerance(r->mesh);
    size_t n = r->mesh->element_count;
    counts[0] = counts[1] = counts[2] = 0;
    uint64_t rays = 0;
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = i + 1; j < n; j++) {
            if (!rad_ff_facing(r->mesh, i, j, tol))
                continue;
            rad_ff_blockers blockers;
            rad_ff_verdict v = rad_ff_occluders_classify(occ, i, j, &blockers);
            counts[v]++;
            if (v == RAD_FF_PARTIAL) {
                assert_true(blockers.count > 0 || !blockers.complete);
                continue;
            }
            rad_ff_end a, b;
            rad_ff_end_element(r->mesh, i, eps, &a);
            rad_ff_end_element(r->mesh, j, eps, &b);
            rad_rng rng = rad_rng_keyed(7, i, j);
            int cast = 0;
            int pass = rad_ff_rays(r->vis, &a, &b, 64, &rng, &rays, &cast);
            if (v == RAD_FF_CLEAR)
                assert_int_equal(pass, cast);
            else
                assert_int_equal(pass, 0);
        }
    print_message("%zu elements: %zu clear, %zu blocked, %zu partial pairs; %llu rays agree\n", n, counts[0],
                  counts[1], counts[2], (unsigned long long)rays);
    rad_free(block);
}

/* The Cornell box, whose blocks are bent by up to 2 mm: their primitives
 * get slabs, the pairs beside them rays; the verdicts given still hold. */
static void test_verdicts_cornell(void **state)
{
    (void)state;
    box_run r;
    rad_context_options co = {0};
    co.threads = 1;
    assert_int_equal(rad_context_create(&co, &r.ctx), RAD_OK);
    assert_int_equal(rad_scene_load_file(r.ctx, RAD_TEST_DATA "/cornell_box.obj", &r.scene), RAD_OK);
    rad_mesh_options mo = {0.0, 400, 0};
    assert_int_equal(rad_mesh_build(r.ctx, r.scene, &mo, &r.mesh), RAD_OK);
    assert_int_equal(rad_vis_create(r.ctx, "embree", r.mesh, &r.vis), RAD_OK);
    size_t counts[3];
    verdicts_against_rays(&r, counts);
    assert_true(counts[RAD_FF_CLEAR] > 0 && counts[RAD_FF_BLOCKED] > 0 && counts[RAD_FF_PARTIAL] > 0);
    box_close(&r);
}

/* Clear and blocked verdicts against 64 stratified shadow rays per pair. */
static void test_verdicts_against_rays(void **state)
{
    (void)state;
    box_run r;
    box_open(&r, 8, true, 1);
    size_t counts[3];
    verdicts_against_rays(&r, counts);
    assert_true(counts[RAD_FF_CLEAR] > 0 && counts[RAD_FF_BLOCKED] > 0 && counts[RAD_FF_PARTIAL] > 0);
    box_close(&r);
}

/* A point above a unit square, blockers half way between. */
static void test_visible_point_factor(void **state)
{
    (void)state;
    const vec3 square[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    vec3 x = v3(0.5, 0.5, 1.0), down = v3(0, 0, -1), up = v3(0, 0, 1);
    double open = rad_point_polygon_ff(x, down, square, 4);
    assert_true(open > 0.2);
    rad_ff_blockers b;
    memset(&b, 0, sizeof b);
    b.complete = true;
    /* Its shadow from x (scale 2 about (0.5, 0.5)) covers x < 0.5. */
    const vec3 half_x[4] = {{0, 0, 0.5}, {0.5, 0, 0.5}, {0.5, 1, 0.5}, {0, 1, 0.5}};
    memcpy(b.corner[0], half_x, sizeof half_x);
    b.corners[0] = 4;
    b.top[0] = INFINITY;
    b.count = 1;
    double half = rad_point_polygon_ff_visible(x, down, square, 4, up, &b);
    assert_true(fabs(half - 0.5 * open) < 1e-14);
    /* A second one, its shadow y < 0.5, overlapping the first's: a quarter
     * is left, not 0 (the overlap hidden once). */
    const vec3 half_y[4] = {{0, 0, 0.5}, {1, 0, 0.5}, {1, 0.5, 0.5}, {0, 0.5, 0.5}};
    memcpy(b.corner[1], half_y, sizeof half_y);
    b.corners[1] = 4;
    b.top[1] = INFINITY;
    b.count = 2;
    double quarter = rad_point_polygon_ff_visible(x, down, square, 4, up, &b);
    assert_true(fabs(quarter - 0.25 * open) < 1e-14);
    /* Trimmed for a receiver through x facing down: the same. */
    rad_ff_blockers_trim(&b, square[0], up, x, down);
    assert_int_equal(b.count, 2);
    assert_true(fabs(rad_point_polygon_ff_visible(x, down, square, 4, up, &b) - 0.25 * open) < 1e-14);
    /* Below the source's plane, or above x: nothing hidden. */
    const vec3 below[4] = {{0, 0, -0.5}, {1, 0, -0.5}, {1, 1, -0.5}, {0, 1, -0.5}};
    memcpy(b.corner[0], below, sizeof below);
    b.count = 1;
    b.trimmed = false;
    assert_true(fabs(rad_point_polygon_ff_visible(x, down, square, 4, up, &b) - open) < 1e-15);
}

static void check_box(int n, bool cube, double row_tol)
{
    box_run r1, r2;
    box_open(&r1, n, cube, 1);
    box_open(&r2, n, cube, 2);
    rad_ff_stats s1, s2;
    double *F1 = box_factors(&r1, &s1), *F2 = box_factors(&r2, &s2);
    size_t m = r1.mesh->element_count;
    print_message("box %d x %d%s: %zu elements, max |row sum - 1| %.3g, reciprocity %.3g, rays %llu\n", n, n,
                  cube ? " + cube" : "", m, worst_row(&s1), s1.reciprocity_max, (unsigned long long)s1.rays);
    assert_true(worst_row(&s1) <= row_tol);
    assert_true(s1.reciprocity_max < 1e-12);
    assert_int_equal(s1.rays, 0);
    assert_true(memcmp(F1, F2, m * m * sizeof *F1) == 0);
    rad_free(F1);
    rad_free(F2);
    box_close(&r1);
    box_close(&r2);
}

static void test_box_8(void **state)
{
    (void)state;
    check_box(8, true, 1e-3);
}

static void test_box_20(void **state)
{
    (void)state;
    check_box(20, true, 2e-4);
}

static void test_box_without_cube(void **state)
{
    (void)state;
    check_box(20, false, 2e-5);
}

int main(int argc, char **argv)
{
    /* "--slow": the cases at scale instead of the quick ones. */
    bool slow = argc == 2 && strcmp(argv[1], "--slow") == 0;
    if (argc > 2 || (argc == 2 && !slow)) {
        fprintf(stderr, "usage: test_ff_occluders [--slow]\n");
        return 2;
    }
    const struct CMUnitTest fast_tests[] = {
        cmocka_unit_test(test_verdicts_against_rays),
        cmocka_unit_test(test_verdicts_cornell),
        cmocka_unit_test(test_visible_point_factor),
        cmocka_unit_test(test_box_8),
        cmocka_unit_test(test_box_without_cube),
    };
    /* At scale: with --slow alone (CTest: test_ff_occluders_slow, label slow). */
    const struct CMUnitTest slow_tests[] = {
        cmocka_unit_test(test_box_20),
    };
    return slow ? cmocka_run_group_tests_name("ff_occluders_slow", slow_tests, NULL, NULL)
                : cmocka_run_group_tests_name("ff_occluders", fast_tests, NULL, NULL);
}
