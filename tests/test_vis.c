/*
 * test_vis.c -- the visibility backends: Embree against the brute-force
 * reference on random rays through a scene of boxes and triangles, the
 * shadow-ray epsilon, ray segment limits, thread safety and the registry.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "test_support.h"

#include "vis/vis.h"

#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

/* ---- scenes, built by hand (patches only: that is all vis reads) ---- */

typedef struct test_scene {
    rad_mesh mesh;
    rad_patch patches[256];
} test_scene;

static void add_patch(test_scene *s, const vec3 *corners, uint32_t n)
{
    assert_true(s->mesh.patch_count < 256);
    rad_patch *p = &s->patches[s->mesh.patch_count++];
    memset(p, 0, sizeof *p);
    p->corner_count = n;
    for (uint32_t i = 0; i < n; i++)
        p->corner[i] = corners[i];
    p->normal = v3_normalize(v3_cross(v3_sub(corners[1], corners[0]), v3_sub(corners[n - 1], corners[0])));
    p->nu = p->nv = 1;
    rad_mesh_measure(&s->mesh);
}

/* An axis-aligned box as six quads, counter-clockwise about outward normals. */
static void add_box(test_scene *s, vec3 lo, vec3 hi)
{
    const vec3 c[8] = {
        {lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
        {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z},
    };
    const int faces[6][4] = {
        {0, 3, 2, 1}, /* -z */ {4, 5, 6, 7}, /* +z */ {0, 1, 5, 4}, /* -y */
        {3, 7, 6, 2}, /* +y */ {0, 4, 7, 3}, /* -x */ {1, 2, 6, 5}, /* +x */
    };
    vec3 centre = v3_scale(v3_add(lo, hi), 0.5);
    for (int f = 0; f < 6; f++) {
        vec3 q[4] = {c[faces[f][0]], c[faces[f][1]], c[faces[f][2]], c[faces[f][3]]};
        add_patch(s, q, 4);
        const rad_patch *p = &s->patches[s->mesh.patch_count - 1];
        assert_true(v3_dot(p->normal, v3_sub(q[0], centre)) > 0.0); /* outward */
    }
}

static vec3 random_point(rad_rng *rng, double lo, double hi)
{
    double x = lo + (hi - lo) * rad_rng_uniform(rng);
    double y = lo + (hi - lo) * rad_rng_uniform(rng);
    double z = lo + (hi - lo) * rad_rng_uniform(rng);
    return v3(x, y, z);
}

/* Several boxes and loose triangles in [0, 1]^3, shifted by `offset`;
 * triangles sit between the boxes in patch order so the Embree backend's
 * primID -> patch maps are exercised. */
static void make_scene(test_scene *s, vec3 offset)
{
    memset(s, 0, sizeof *s);
    s->mesh.patches = s->patches;
    rad_rng rng = rad_rng_keyed(42, 0, 0);
    for (int b = 0; b < 6; b++) {
        vec3 lo = random_point(&rng, 0.0, 0.8), size = random_point(&rng, 0.05, 0.3);
        add_box(s, v3_add(lo, offset), v3_add(v3_add(lo, size), offset));
        for (int t = 0; t < 3; t++) {
            vec3 a = random_point(&rng, 0.0, 1.0);
            vec3 q[3] = {v3_add(a, offset),
                         v3_add(v3_add(a, random_point(&rng, -0.3, 0.3)), offset),
                         v3_add(v3_add(a, random_point(&rng, -0.3, 0.3)), offset)};
            add_patch(s, q, 3);
        }
    }
}

static rad_vis *make_vis(rad_context *ctx, const char *name, const rad_mesh *mesh)
{
    rad_vis *vis = NULL;
    rad_result r = rad_vis_create(ctx, name, mesh, &vis);
    if (r != RAD_OK)
        fail_msg("rad_vis_create(%s): %s", name, rad_context_error(ctx));
    assert_non_null(vis);
    assert_true(vis->build_seconds >= 0.0);
    return vis;
}

/* ---- the reach of a view (reach.c) ---- */

/* Two closed rooms side by side, [0, 4] x [0, 3] x [0, 4] and [4.2, 8.2] x
 * ...: from the first room's middle the reach holds the first room and
 * stops short of the second's middle (widened by the fan's spacing times
 * the distance, 0.31 x 2.6 m at 512 rays); with a hole in the wall
 * between (the second room's near wall left out, the first's cut to a
 * doorway) it reaches the second room's far wall; in the open it is
 * everywhere. */
static void test_reach(void **unused)
{
    (void)unused;
    test_scene *s = calloc(1, sizeof *s);
    s->mesh.patches = s->patches;
    add_box(s, v3(0, 0, 0), v3(4, 3, 4));
    add_box(s, v3(4.2, 0, 0), v3(8.2, 3, 4));
    rad_context *ctx = test_context(1);
    for (int b = 0; rad_vis_backends[b]; b++) {
        rad_vis *vis = make_vis(ctx, rad_vis_backends[b]->name, &s->mesh);
        vec3 lo, hi;
        assert_true(rad_vis_reach(vis, v3(2, 1.5, 2), 0.0, 512, 0.0, &lo, &hi));
        assert_true(lo.x <= 0.0 && lo.y <= 0.0 && lo.z <= 0.0 && hi.x >= 4.0 && hi.y >= 3.0 && hi.z >= 4.0);
        assert_true(hi.x < 6.2); /* the second room's middle is out of reach */
        assert_false(rad_vis_reach(vis, v3(9, 1.5, 2), 0.0, 512, 0.0, &lo, &hi)); /* outside: open */
        assert_true(isinf(lo.x) && isinf(hi.x));
        rad_vis_destroy(vis);
    }
    /* A doorway: the first room's +x face is replaced by the wall around a
     * 1 x 2 m opening, the second room's -x face left out. */
    s->mesh.patch_count = 0;
    add_box(s, v3(0, 0, 0), v3(4, 3, 4));
    add_box(s, v3(4.2, 0, 0), v3(8.2, 3, 4));
    rad_patch keep[12];
    memcpy(keep, s->patches, sizeof keep);
    s->mesh.patch_count = 0;
    for (int f = 0; f < 12; f++)
        if (f != 5 && f != 6 + 4) /* the first box's +x, the second's -x */
            s->patches[s->mesh.patch_count++] = keep[f];
    const vec3 wall[3][4] = {{{4, 0, 0}, {4, 3, 0}, {4, 3, 1.5}, {4, 0, 1.5}},
                             {{4, 0, 2.5}, {4, 3, 2.5}, {4, 3, 4}, {4, 0, 4}},
                             {{4, 2, 1.5}, {4, 3, 1.5}, {4, 3, 2.5}, {4, 2, 2.5}}};
    for (int w = 0; w < 3; w++)
        add_patch(s, wall[w], 4);
    rad_mesh_measure(&s->mesh);
    rad_vis *vis = make_vis(ctx, "embree", &s->mesh);
    vec3 lo, hi;
    assert_true(rad_vis_reach(vis, v3(2, 1.5, 2), 0.0, 512, 0.0, &lo, &hi));
    assert_true(hi.x >= 8.2); /* through the doorway to the far wall */
    rad_vis_destroy(vis);
    rad_context_destroy(ctx);
    free(s);
}

/* ---- Embree against brute force ---- */

#define RAY_COUNT 20000

static void test_embree_matches_brute(void **unused)
{
    (void)unused;
    test_scene *s = calloc(1, sizeof *s);
    make_scene(s, v3(0, 0, 0));
    rad_context *ctx = test_context(2);
    rad_vis *embree = make_vis(ctx, "embree", &s->mesh);
    rad_vis *brute = make_vis(ctx, "brute", &s->mesh);

    rad_ray *rays = calloc(RAY_COUNT, sizeof *rays);
    uint8_t *occluded_e = calloc(RAY_COUNT, 1), *occluded_b = calloc(RAY_COUNT, 1);
    rad_hit *hits_e = calloc(RAY_COUNT, sizeof *hits_e), *hits_b = calloc(RAY_COUNT, sizeof *hits_b);

    /* Shadow rays between random points of free space (not on surfaces:
     * end points on a surface would test float rounding, not the BVH). */
    rad_rng rng = rad_rng_keyed(7, 1, 2);
    for (size_t k = 0; k < RAY_COUNT; k++) {
        vec3 a = random_point(&rng, -0.2, 1.2), b = random_point(&rng, -0.2, 1.2);
        rays[k] = (rad_ray){a, v3_sub(b, a), 0.0, 1.0};
    }
    embree->backend->occluded(embree->state, rays, RAY_COUNT, occluded_e);
    brute->backend->occluded(brute->state, rays, RAY_COUNT, occluded_b);
    size_t mismatches = 0, blocked = 0;
    for (size_t k = 0; k < RAY_COUNT; k++) {
        mismatches += occluded_e[k] != occluded_b[k];
        blocked += occluded_b[k];
    }
    print_message("occlusion: %zu of %d rays blocked, %zu disagree\n", blocked, RAY_COUNT,
                  mismatches);
    assert_true(blocked > RAY_COUNT / 10 && blocked < RAY_COUNT * 9 / 10); /* a real test */
    assert_true(mismatches * 1000 < RAY_COUNT); /* < 0.1%: float grazing of edges */

    /* Closest hits: random rays, unbounded. */
    for (size_t k = 0; k < RAY_COUNT; k++) {
        vec3 a = random_point(&rng, -0.2, 1.2), d = random_point(&rng, -1.0, 1.0);
        rays[k] = (rad_ray){a, d, 0.0, INFINITY};
    }
    embree->backend->intersect(embree->state, rays, RAY_COUNT, hits_e);
    brute->backend->intersect(brute->state, rays, RAY_COUNT, hits_b);
    size_t hit_count = 0;
    mismatches = 0;
    for (size_t k = 0; k < RAY_COUNT; k++) {
        int finite_e = isfinite(hits_e[k].t), finite_b = isfinite(hits_b[k].t);
        if (finite_e != finite_b || (finite_b && hits_e[k].patch != hits_b[k].patch)) {
            mismatches++;
            continue;
        }
        if (!finite_b)
            continue;
        hit_count++;
        assert_near(hits_e[k].t, hits_b[k].t, 1e-5 * hits_b[k].t);
    }
    print_message("closest hit: %zu of %d rays hit, %zu disagree\n", hit_count, RAY_COUNT,
                  mismatches);
    assert_true(hit_count > RAY_COUNT / 10);
    assert_true(mismatches * 1000 < RAY_COUNT);

    free(rays);
    free(occluded_e);
    free(occluded_b);
    free(hits_e);
    free(hits_b);
    rad_vis_destroy(embree);
    rad_vis_destroy(brute);
    rad_context_destroy(ctx);
    free(s);
}

/* Concurrent queries from OpenMP threads give what one thread gives. */
static void test_thread_safety(void **unused)
{
    (void)unused;
    test_scene *s = calloc(1, sizeof *s);
    make_scene(s, v3(0, 0, 0));
    rad_context *ctx = test_context(4);
    rad_vis *embree = make_vis(ctx, "embree", &s->mesh);
    enum { N = 40000, CHUNK = 64 };
    rad_ray *rays = calloc(N, sizeof *rays);
    uint8_t *serial = calloc(N, 1), *parallel = calloc(N, 1);
    rad_hit *hits_serial = calloc(N, sizeof *hits_serial), *hits_parallel = calloc(N, sizeof *hits_parallel);
    rad_rng rng = rad_rng_keyed(9, 9, 9);
    for (size_t k = 0; k < N; k++) {
        vec3 a = random_point(&rng, -0.2, 1.2), b = random_point(&rng, -0.2, 1.2);
        rays[k] = (rad_ray){a, v3_sub(b, a), 0.0, 1.0};
    }
    embree->backend->occluded(embree->state, rays, N, serial);
    embree->backend->intersect(embree->state, rays, N, hits_serial);
#pragma omp parallel for num_threads(4) schedule(dynamic)
    for (size_t c = 0; c < N / CHUNK; c++) {
        embree->backend->occluded(embree->state, rays + c * CHUNK, CHUNK, parallel + c * CHUNK);
        embree->backend->intersect(embree->state, rays + c * CHUNK, CHUNK,
                                   hits_parallel + c * CHUNK);
    }
    assert_memory_equal(serial, parallel, N);
    for (size_t k = 0; k < N; k++) {
        assert_true(hits_serial[k].t == hits_parallel[k].t ||
                    (isnan(hits_serial[k].t) && isnan(hits_parallel[k].t)));
        assert_int_equal(hits_serial[k].patch, hits_parallel[k].patch);
    }
    free(rays);
    free(serial);
    free(parallel);
    free(hits_serial);
    free(hits_parallel);
    rad_vis_destroy(embree);
    rad_context_destroy(ctx);
    free(s);
}

/* ---- the shadow-ray epsilon ---- */

/* A ray leaving a patch from eps above it must not see that patch, in a
 * scene near the origin and in one 100 m away (float rounding of the
 * coordinates grows with distance from the origin). */
static void check_epsilon(vec3 offset)
{
    test_scene *s = calloc(1, sizeof *s);
    make_scene(s, offset);
    rad_context *ctx = test_context(1);
    double eps = rad_vis_epsilon(&s->mesh);
    for (const rad_vis_backend *const *b = rad_vis_backends; *b; b++) {
        rad_vis *vis = make_vis(ctx, (*b)->name, &s->mesh);
        rad_rng rng = rad_rng_keyed(3, 1, 4);
        size_t tested = 0;
        for (size_t i = 0; i < s->mesh.patch_count; i++) {
            const rad_patch *p = &s->patches[i];
            for (int k = 0; k < 200; k++) {
                double u = rad_rng_uniform(&rng), v = rad_rng_uniform(&rng);
                if (p->corner_count == 3 && u + v > 1.0) {
                    u = 1.0 - u;
                    v = 1.0 - v;
                }
                vec3 q = p->corner_count == 3
                             ? v3_add(p->corner[0], v3_add(v3_scale(v3_sub(p->corner[1], p->corner[0]), u),
                                                           v3_scale(v3_sub(p->corner[2], p->corner[0]), v)))
                             : v3_lerp(v3_lerp(p->corner[0], p->corner[1], u),
                                       v3_lerp(p->corner[3], p->corner[2], u), v);
                /* Away from either side, down to 5 degrees above the plane. */
                double side = k % 2 ? 1.0 : -1.0;
                vec3 d = random_point(&rng, -1.0, 1.0);
                d = v3_sub(d, v3_scale(p->normal, v3_dot(d, p->normal)));
                d = v3_add(v3_normalize(d), v3_scale(p->normal, side * (0.09 + rad_rng_uniform(&rng))));
                rad_ray ray = {v3_mad(q, p->normal, side * eps), d, 0.0, INFINITY};
                rad_hit hit;
                vis->backend->intersect(vis->state, &ray, 1, &hit);
                if (isfinite(hit.t) && hit.patch == i)
                    fail_msg("%s: ray leaving patch %zu at eps %g hits it at t = %g", (*b)->name,
                             i, eps, hit.t);
                /* Occlusion up to eps short of the first other hit. */
                if (isfinite(hit.t) && hit.t > 2.0 * eps / v3_length(d)) {
                    ray.tfar = hit.t - eps / v3_length(d);
                    uint8_t blocked;
                    vis->backend->occluded(vis->state, &ray, 1, &blocked);
                    if (blocked)
                        fail_msg("%s: patch %zu sample %d: blocked before t = %g (patch %u)",
                                 (*b)->name, i, k, hit.t, hit.patch);
                }
                tested++;
            }
        }
        assert_true(tested > 1000);
        rad_vis_destroy(vis);
    }
    rad_context_destroy(ctx);
    free(s);
}

static void test_epsilon(void **unused)
{
    (void)unused;
    test_scene *s = calloc(1, sizeof *s);
    vec3 quad[4] = {{0, 0, 0}, {3, 0, 0}, {3, 4, 0}, {0, 4, 0}};
    s->mesh.patches = s->patches;
    add_patch(s, quad, 4);
    assert_near(rad_vis_epsilon(&s->mesh), 5e-5, 1e-15); /* diagonal 5 m */
    free(s);
    check_epsilon(v3(0, 0, 0));
    check_epsilon(v3(100, -100, 100));
}

/* ---- ray segments ---- */

static void test_segment_limits(void **unused)
{
    (void)unused;
    test_scene *s = calloc(1, sizeof *s);
    s->mesh.patches = s->patches;
    vec3 quad[4] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    vec3 tri[3] = {{-1, -1, 2}, {1, -1, 2}, {-1, 1, 2}};
    add_patch(s, quad, 4);
    add_patch(s, tri, 3);
    rad_context *ctx = test_context(1);
    for (const rad_vis_backend *const *b = rad_vis_backends; *b; b++) {
        rad_vis *vis = make_vis(ctx, (*b)->name, &s->mesh);
        const vec3 o = {-0.1, -0.2, -1.0}, up = {0, 0, 1};
        struct {
            rad_ray ray;
            uint8_t occluded;
            double t;
            uint32_t patch;
        } cases[] = {
            {{o, up, 0.0, 0.9}, 0, INFINITY, 0},       /* stops short of the quad */
            {{o, up, 0.0, 1.1}, 1, 1.0, 0},            /* reaches it */
            {{o, up, 1.1, INFINITY}, 1, 3.0, 1},       /* starts past it: the triangle */
            {{o, up, 1.1, 2.9}, 0, INFINITY, 0},       /* between the two */
            {{o, up, 3.1, INFINITY}, 0, INFINITY, 0},  /* past both */
            {{o, v3(0, 0, 2), 0.0, INFINITY}, 1, 0.5, 0}, /* t in units of |direction| */
            {{v3(-0.1, -0.2, 1.0), v3(0, 0, -1), 0.0, INFINITY}, 1, 1.0, 0}, /* back side */
            {{o, up, 2.0, 1.0}, 0, INFINITY, 0},       /* empty segment */
            {{v3(-0.5, -0.5, 1.0), v3(0, 0, 1), -5.0, INFINITY}, 1, 1.0, 1}, /* tnear < 0 is 0 */
        };
        for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
            uint8_t occluded;
            rad_hit hit;
            vis->backend->occluded(vis->state, &cases[k].ray, 1, &occluded);
            vis->backend->intersect(vis->state, &cases[k].ray, 1, &hit);
            if (occluded != cases[k].occluded)
                fail_msg("%s case %zu: occluded %d", (*b)->name, k, occluded);
            if (isfinite(cases[k].t)) {
                assert_near(hit.t, cases[k].t, 1e-12);
                assert_int_equal(hit.patch, cases[k].patch);
            } else if (isfinite(hit.t)) {
                fail_msg("%s case %zu: hit at %g", (*b)->name, k, hit.t);
            }
        }
        rad_vis_destroy(vis);
    }
    rad_context_destroy(ctx);
    free(s);
}

/* An empty mesh builds and blocks nothing. */
static void test_empty_scene(void **unused)
{
    (void)unused;
    rad_mesh mesh = {0};
    rad_context *ctx = test_context(1);
    for (const rad_vis_backend *const *b = rad_vis_backends; *b; b++) {
        rad_vis *vis = make_vis(ctx, (*b)->name, &mesh);
        rad_ray ray = {v3(0, 0, 0), v3(1, 0, 0), 0.0, INFINITY};
        uint8_t occluded = 1;
        rad_hit hit;
        vis->backend->occluded(vis->state, &ray, 1, &occluded);
        vis->backend->intersect(vis->state, &ray, 1, &hit);
        assert_int_equal(occluded, 0);
        assert_false(isfinite(hit.t));
        rad_vis_destroy(vis);
    }
    rad_context_destroy(ctx);
}

/* ---- registry ---- */

static void test_registry(void **unused)
{
    (void)unused;
    assert_string_equal(rad_vis_backends[0]->name, "embree");
    assert_string_equal(rad_vis_backends[1]->name, "brute");
    assert_null(rad_vis_backends[2]);
    assert_ptr_equal(rad_vis_find("brute"), rad_vis_backends[1]);
    assert_null(rad_vis_find("optix"));
    assert_null(rad_vis_find(NULL));

    rad_mesh mesh = {0};
    rad_context *ctx = test_context(1);
    rad_vis *vis = (rad_vis *)&mesh; /* must be reset to NULL */
    assert_int_equal(rad_vis_create(ctx, "optix", &mesh, &vis), RAD_ERROR_INVALID_ARGUMENT);
    assert_null(vis);
    assert_string_equal(rad_context_error(ctx),
                        "unknown visibility backend 'optix' (known: embree, brute)");
    rad_vis_destroy(NULL);
    rad_context_destroy(ctx);
}

/* ---- speed (printed, not asserted) ---- */

static void test_speed(void **unused)
{
    (void)unused;
    test_scene *s = calloc(1, sizeof *s);
    make_scene(s, v3(0, 0, 0));
    rad_context *ctx = test_context(1);
    enum { N = 200000 };
    rad_ray *rays = calloc(N, sizeof *rays);
    uint8_t *occluded = calloc(N, 1);
    rad_rng rng = rad_rng_keyed(5, 5, 5);
    for (size_t k = 0; k < N; k++) {
        vec3 a = random_point(&rng, -0.2, 1.2), b = random_point(&rng, -0.2, 1.2);
        rays[k] = (rad_ray){a, v3_sub(b, a), 0.0, 1.0};
    }
    for (const rad_vis_backend *const *b = rad_vis_backends; *b; b++) {
        rad_vis *vis = make_vis(ctx, (*b)->name, &s->mesh);
        double start = rad_seconds();
        vis->backend->occluded(vis->state, rays, N, occluded);
        double seconds = rad_seconds() - start;
        print_message("%s: %zu patches, %.2f M occlusion rays/s (one thread), build %.3f ms\n",
                      (*b)->name, s->mesh.patch_count, N / seconds * 1e-6,
                      vis->build_seconds * 1e3);
        rad_vis_destroy(vis);
    }
    free(rays);
    free(occluded);
    rad_context_destroy(ctx);
    free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_registry),
        cmocka_unit_test(test_segment_limits),
        cmocka_unit_test(test_empty_scene),
        cmocka_unit_test(test_epsilon),
        cmocka_unit_test(test_reach),
        cmocka_unit_test(test_embree_matches_brute),
        cmocka_unit_test(test_thread_safety),
        cmocka_unit_test(test_speed),
    };
    return cmocka_run_group_tests_name("vis", tests, NULL, NULL);
}
