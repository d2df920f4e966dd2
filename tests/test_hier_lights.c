/*
 * test_hier_lights.c -- luminaires and daylight in the hierarchical solver
 * (src/hier/direct.c): each node's direct irradiance from the light module,
 * B_leaf = E + rho (H + H_d), leaves split where the direct light varies.
 *
 *   - a room lit only by luminaires (tests/data/luminaires) agrees with
 *     gauss-seidel on 3,000 uniform elements, per surface (2.5%) and at
 *     every point of a work-plane grid (3%, the mean to 1%);
 *   - it is closed, so what it absorbs is what the luminaires send into it:
 *     power balanced to 1%, and the direct light landing is their flux;
 *   - a point luminaire over a floating slab: the slab's shadow edge on the
 *     floor lies at x = 1 + 2.9 / 1.5 (similar triangles from the lamp
 *     through the slab's lower edge); every floor leaf that line crosses is
 *     one min_area forbids splitting further, leaves wholly in the shadow
 *     have no direct light and leaves wholly lit have some, while the floor
 *     is not meshed finely everywhere;
 *   - one and two threads give the same leaves, direct light and radiosity
 *     to the bit;
 *   - the solver named by no option is hierarchical for a lit scene;
 *   - a daylit solution file keeps its daylight and direct light, and a sky
 *     out of range in its header is refused in one line.
 *   - slow (test_hier_lights_slow): a daylit room (sky, sun, two openings)
 *     agrees with gauss-seidel per surface and per grid point, and its
 *     solution file gives the same grid to the bit.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "test_support.h"
#include "api/solution.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static rad_context *ctx;

static int setup(void **state)
{
    (void)state;
    if (test_workdir_make("hier_lights") != 0)
        return -1;
    ctx = test_context(2);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    rad_context_destroy(ctx);
    return test_workdir_remove();
}

static double rel(double a, double b) { return fabs(a - b) / fabs(b); }

/* The data room (4 x 4 x 3 m, z up, closed, no emitters) with its layout:
 * a 2 x 2 array of downlights and one aimed at a wall. */
static rad_scene *lit_room(void)
{
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_file(ctx, RAD_TEST_DATA "/luminaires/room.obj", &scene), RAD_OK);
    assert_int_equal(rad_scene_load_luminaires(ctx, scene, RAD_TEST_DATA "/luminaires/layout.json"), RAD_OK);
    return scene;
}

static rad_solution *solve(rad_context *c, const rad_scene *scene, rad_options o)
{
    rad_solution *sol = NULL;
    if (rad_solution_create(c, scene, &o, &sol) != RAD_OK)
        fail_msg("%s", rad_context_error(c));
    if (rad_solution_solve(c, sol) != RAD_OK)
        fail_msg("%s", rad_context_error(c));
    return sol;
}

/* The work plane at 0.8 m, 0.25 m from the walls, 14 x 14 points. */
static const char work_plane[] = "{\"up\": \"z\", \"grids\": [{\"name\": \"work\", \"rectangle\": "
                                 "{\"origin\": [0.25, 0.25, 0.8], \"u\": [3.5, 0, 0], \"v\": [0, 3.5, 0]}, "
                                 "\"facing\": \"up\", \"spacing\": 0.25}]}";

static rad_illuminance *grid(const rad_solution *sol, const char *json)
{
    rad_illuminance *il = NULL;
    if (rad_illuminance_evaluate_memory(ctx, sol, "grid.json", json, strlen(json), &il) != RAD_OK)
        fail_msg("%s", rad_context_error(ctx));
    return il;
}

/* Per surface (2.5%) and per grid point (3%; the mean 1%), hierarchical
 * against gauss-seidel.  The direct part at the points is exact in both;
 * what differs is the interreflection the solutions' radiosities give. */
static void compare_grids(const rad_solution *h, const rad_solution *g, const char *json, double point_tol,
                          double mean_tol);
static void compare(const rad_scene *scene, const rad_solution *h, const rad_solution *g, const char *json,
                    double surface_tol, double point_tol, double mean_tol)
{
    for (size_t s = 0; s < rad_scene_surface_count(scene); s++) {
        double bh[3], bg[3];
        rad_solution_surface_radiosity(h, s, bh);
        rad_solution_surface_radiosity(g, s, bg);
        print_message("%-12s B hierarchical %.5f gauss-seidel %.5f (%+.2f%%)\n", rad_scene_surface_name(scene, s),
                      bh[1], bg[1], 100.0 * (bh[1] / bg[1] - 1.0));
        if (!(rel(bh[1], bg[1]) < surface_tol))
            fail_msg("surface %s: %g against %g", rad_scene_surface_name(scene, s), bh[1], bg[1]);
    }
    compare_grids(h, g, json, point_tol, mean_tol);
}

/* The grids' part of compare. */
static void compare_grids(const rad_solution *h, const rad_solution *g, const char *json, double point_tol,
                          double mean_tol)
{
    rad_illuminance *ih = grid(h, json), *ig = grid(g, json);
    for (size_t k = 0; k < rad_illuminance_grid_count(ih); k++) {
        const rad_grid_result *a = rad_illuminance_grid(ih, k), *b = rad_illuminance_grid(ig, k);
        assert_int_equal(a->point_count, b->point_count);
        double worst = 0.0;
        for (size_t i = 0; i < a->point_count; i++) {
            /* The same points, the same direct light: only the radiosity differs. */
            assert_true(a->points[i].direct == b->points[i].direct);
            worst = fmax(worst, rel(a->points[i].illuminance, b->points[i].illuminance));
        }
        print_message("grid %s: Eavg %.2f against %.2f lux, worst point %.2f%%\n", a->name, a->average, b->average,
                      100.0 * worst);
        assert_true(worst < point_tol);
        assert_true(rel(a->average, b->average) < mean_tol);
    }
    rad_illuminance_destroy(ih);
    rad_illuminance_destroy(ig);
}

static void test_luminaires_agree_with_dense(void **state)
{
    (void)state;
    rad_scene *scene = lit_room();
    rad_solution *h = solve(ctx, scene, (rad_options){.seed = 1});
    assert_string_equal(h->options.solver, "hierarchical");
    rad_solution *g = solve(ctx, scene, (rad_options){.solver = "gauss-seidel", .target_elements = 3000});
    compare(scene, h, g, work_plane, 0.025, 0.03, 0.01);
    rad_solution_destroy(h);
    rad_solution_destroy(g);
    rad_scene_destroy(scene);
}

/* A closed room without emitters: everything the luminaires send lands and
 * is absorbed, after bounces. */
static void test_luminaires_energy(void **state)
{
    (void)state;
    rad_scene *scene = lit_room();
    rad_solution *h = solve(ctx, scene, (rad_options){0});
    double flux = 0.0, emitted = 0.0, absorbed = 0.0;
    for (size_t k = 0; k < rad_scene_luminaire_count(scene); k++)
        flux += rad_scene_luminaire_flux(scene, k);
    double landing = rad_solution_direct_lumens(h);
    rad_solution_power(h, &emitted, &absorbed);
    print_message("flux %.2f lm, landing %.2f lm; emitted %.5f W (%.2f lm), absorbed %.5f W\n", flux, landing,
                  emitted, emitted * 179.0, absorbed);
    /* The leaves' direct light adds up to the luminaires' flux (the wall
     * washer's near field puts it 0.1% above: docs/lighting.md). */
    assert_true(rel(landing, flux) < 0.005);
    /* Grey light: lumens = 179 lm/W x W. */
    assert_true(rel(179.0 * emitted, flux) < 0.005);
    assert_true(rel(absorbed, emitted) < 1e-4);
    rad_solution_destroy(h);
    rad_scene_destroy(scene);
}

/* ---- the luminaires' reach (light/reach.c) ---- */

/* The bounding box of a surface's polygons. */
static void surface_box(const rad_scene *scene, const char *name, vec3 *lo, vec3 *hi)
{
    *lo = v3(INFINITY, INFINITY, INFINITY), *hi = v3(-INFINITY, -INFINITY, -INFINITY);
    for (size_t i = 0; i < scene->polygon_count; i++) {
        const rad_polygon *pg = &scene->polygons[i];
        if (strcmp(scene->surfaces[pg->surface].name, name) != 0)
            continue;
        for (uint32_t k = 0; k < pg->vertex_count; k++) {
            *lo = v3_min(*lo, scene->positions[scene->indices[pg->first_index + k]]);
            *hi = v3_max(*hi, scene->positions[scene->indices[pg->first_index + k]]);
        }
    }
    assert_true(lo->x <= hi->x);
}

/* Two generated rooms, each lit by one downlight at its centre 10 cm
 * under its ceiling. */
static rad_scene *rooms_lit(int rooms, int closed_doors)
{
    rad_office_options oo = {.rooms = rooms, .seed = 3, .closed_doors = closed_doors};
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_generate_office(ctx, &oo, &scene), RAD_OK);
    for (size_t m = 0; m < scene->material_count; m++)
        for (int c = 0; c < 3; c++)
            scene->materials[m].emission[c] = 0.0; /* lit by the downlights only */
    char layout[1024];
    int at = snprintf(layout, sizeof layout, "{\"up\": [0, 1, 0], \"luminaires\": [");
    for (int r = 0; r < rooms; r++) {
        char floor[32], ceiling[32];
        vec3 flo, fhi, clo, chi;
        snprintf(floor, sizeof floor, "room%d/floor", r);
        snprintf(ceiling, sizeof ceiling, "room%d/ceiling", r);
        surface_box(scene, floor, &flo, &fhi);
        surface_box(scene, ceiling, &clo, &chi);
        at += snprintf(layout + at, sizeof layout - (size_t)at,
                       "%s{\"file\": \"downlight.ies\", \"lumens\": 3000, \"position\": [%.4f, %.4f, %.4f]}",
                       r ? ", " : "", 0.5 * (flo.x + fhi.x), chi.y - 0.1, 0.5 * (flo.z + fhi.z));
    }
    snprintf(layout + at, sizeof layout - (size_t)at, "]}");
    assert_int_equal(rad_scene_load_luminaires_memory(ctx, scene, RAD_TEST_DATA "/luminaires/layout.json", layout,
                                                      strlen(layout)),
                     RAD_OK);
    return scene;
}

static rad_scene *two_rooms(int closed_doors) { return rooms_lit(2, closed_doors); }

static const char two_floors[] = "{\"up\": \"y\", \"grids\": ["
                                 "{\"name\": \"r0\", \"surface\": \"room0/floor\", \"height\": 0.8, \"spacing\": 0.4},"
                                 "{\"name\": \"r1\", \"surface\": \"room1/floor\", \"height\": 0.8, \"spacing\": 0.4}]}";

/* Through the open door each room's downlight lights the other's floor:
 * the hierarchy and the grid, which ask only the luminaires in reach, get
 * the same direct light at every point as the dense solver, which asks
 * all (compare_grids: bit for bit).  With the doors closed the reach of
 * room 0's downlight stops at its walls (and its margin): no point of the
 * middle of room 1's work plane is in it. */
static void test_reach_rooms(void **state)
{
    (void)state;
    rad_scene *scene = two_rooms(0);
    rad_solution *h = solve(ctx, scene, (rad_options){.seed = 1});
    assert_string_equal(h->options.solver, "hierarchical");
    assert_non_null(h->view.light_reach);
    rad_solution *g = solve(ctx, scene, (rad_options){.solver = "gauss-seidel", .target_elements = 2500});
    assert_null(g->view.light_reach);
    compare_grids(h, g, two_floors, 0.1, 0.03);
    {
        /* The reach by sectors of the fan (vis/reach.c): every point of
         * room 1's work plane that room 0's downlight lights (its light
         * alone, shadow rays to every point of its opening) is in reach,
         * and of those it does not light a share is out of it, where one
         * box round the fan held them all (measured: 875 lit, all in
         * reach; 630 of 2,193 unlit out of it). */
        const rad_light_reach *reach = h->view.light_reach;
        static const uint32_t first[1] = {0};
        rad_light_among alone = {first, 1, NULL};
        vec3 lo, hi, up = v3(0, 1, 0);
        surface_box(scene, "room1/floor", &lo, &hi);
        int lit = 0, dark = 0, dark_out = 0;
        for (double x = lo.x + 0.05; x < hi.x; x += 0.1)
            for (double z = lo.z + 0.05; z < hi.z; z += 0.1) {
                double e[3];
                vec3 p = v3(x, 0.8, z);
                rad_light_irradiance_among(scene, h->view.mesh, h->view.vis, p, up, &alone, e);
                if (e[0] > 0.0) {
                    lit++;
                    if (!rad_light_reach_holds(reach, 0, p))
                        fail_msg("(%g, 0.8, %g) lit by room 0's downlight but out of its reach", x, z);
                } else {
                    dark++;
                    dark_out += !rad_light_reach_holds(reach, 0, p);
                }
            }
        print_message("open door: %d points of room 1 lit by room 0's downlight; of %d not lit, %d out of "
                      "reach\n", lit, dark, dark_out);
        assert_true(lit > 10 && dark > 100);
        assert_true(dark_out > dark / 5);
    }
    rad_solution_destroy(h);
    rad_solution_destroy(g);
    rad_scene_destroy(scene);

    scene = two_rooms(1);
    h = solve(ctx, scene, (rad_options){.seed = 1});
    const rad_light_reach *reach = h->view.light_reach;
    assert_int_equal(rad_light_reach_everywhere(reach), 0);
    vec3 lo, hi;
    surface_box(scene, "room1/floor", &lo, &hi);
    int inside = 0, points = 0;
    /* The box is widened by the fan's spacing times the distance (up to
     * 0.6 m across a room): points 1.2 m in from room 1's walls. */
    for (double x = lo.x + 1.2; x < hi.x - 1.2; x += 0.3)
        for (double z = lo.z + 1.2; z < hi.z - 1.2; z += 0.3, points++)
            inside += rad_light_reach_holds(reach, 0, v3(x, 0.8, z));
    print_message("sealed rooms: %d of %d points of room 1 in reach of room 0's downlight\n", inside, points);
    assert_true(points > 20);
    assert_int_equal(inside, 0);
    surface_box(scene, "room0/floor", &lo, &hi);
    assert_true(rad_light_reach_holds(reach, 0, v3(0.5 * (lo.x + hi.x), 0.8, 0.5 * (lo.z + hi.z))));
    rad_solution_destroy(h);
    rad_scene_destroy(scene);
}

/* ---- pockets ---- */

/* The generator's ceiling lights hang 2 cm under the ceiling in a closed
 * housing: the housing's top and the ceiling over it see each other and,
 * through the slit, little of the room.  A coarse ceiling node straddling
 * that pocket used to pass its links' mean visibility down to the leaves
 * in it, and the housings read three times the dense solution's radiosity
 * (the room's light absorbed in the pocket, the ceiling the room sees
 * darker); the links' quarters (hier.h, HR_LINK_QUADS) keep the light
 * where the other end is seen.  Measured: housings 0.029 against
 * gauss-seidel's 0.037 at 3,000 elements and 0.0255 at 8,000 (its coarse
 * elements over the pocket see past the housing's edge), 0.116 before the
 * quarters; the ceiling -0.9% against +1.95% before (-0.22% once the
 * quarters took the factor's shape too; housings 0.028). */
static void test_pocket(void **state)
{
    (void)state;
    rad_scene *scene = rooms_lit(1, 0);
    rad_solution *h = solve(ctx, scene, (rad_options){.seed = 1});
    rad_solution *g = solve(ctx, scene, (rad_options){.solver = "gauss-seidel", .target_elements = 3000});
    int housings = 0;
    for (size_t k = 0; k < rad_scene_surface_count(scene); k++) {
        const char *name = rad_scene_surface_name(scene, k);
        double bh[3], bg[3];
        rad_solution_surface_radiosity(h, k, bh);
        rad_solution_surface_radiosity(g, k, bg);
        if (strstr(name, "housing")) {
            print_message("%-24s hierarchical %.4f gauss-seidel %.4f (%+.1f%%)\n", name, bh[1], bg[1],
                          100.0 * (bh[1] / bg[1] - 1.0));
            if (!(bh[1] < 1.5 * bg[1] && bg[1] < 1.5 * bh[1]))
                fail_msg("%s: %g against %g: the pocket takes the room's light", name, bh[1], bg[1]);
            housings++;
        }
        if (strstr(name, "ceiling")) {
            print_message("%-24s hierarchical %.4f gauss-seidel %.4f (%+.2f%%)\n", name, bh[1], bg[1],
                          100.0 * (bh[1] / bg[1] - 1.0));
            assert_true(rel(bh[1], bg[1]) < 0.015);
        }
    }
    assert_true(housings > 0);
    /* Probes 2 cm under the ceiling, facing it: each reads the ceiling's
     * radiosity within a few cm.  The surface's mean hides where its light
     * is; these see the middle of it, which the work plane sees. */
    vec3 lo, hi;
    surface_box(scene, "room0/ceiling", &lo, &hi);
    char probes[512];
    snprintf(probes, sizeof probes,
             "{\"up\": \"y\", \"grids\": [{\"name\": \"under the ceiling\", \"rectangle\": {\"origin\": "
             "[%.4f, %.4f, %.4f], \"u\": [%.4f, 0, 0], \"v\": [0, 0, %.4f]}, \"facing\": \"up\", \"spacing\": 0.2}]}",
             lo.x + 0.1, hi.y - 0.02, lo.z + 0.1, hi.x - lo.x - 0.2, hi.z - lo.z - 0.2);
    rad_illuminance *ih = grid(h, probes), *ig = grid(g, probes);
    double eh = rad_illuminance_grid(ih, 0)->average, eg = rad_illuminance_grid(ig, 0)->average;
    print_message("under the ceiling: hierarchical %.2f lux, gauss-seidel %.2f (%+.2f%%)\n", eh, eg,
                  100.0 * (eh / eg - 1.0));
    /* Measured: -2.19%; -3.23% before the quarters took the factor's shape
     * (refine.c, quarter_shape: the strip along the walls took the middle's
     * light).  Gauss-seidel's 3,000 elements are themselves coarse here. */
    assert_true(rel(eh, eg) < 0.027);
    rad_illuminance_destroy(ih);
    rad_illuminance_destroy(ig);
    rad_solution_destroy(h);
    rad_solution_destroy(g);
    rad_scene_destroy(scene);
}

/* ---- a shadow edge ---- */

/* The lamp: the downlight's distribution from a point (no luminous
 * opening), so that the shadow is sharp. */
static const char point_ies[] = "IESNA:LM-63-2002\n[TEST] point downlight\nTILT=NONE\n"
                                "1 1000 1 10 1 1 2 0 0 0\n1 1 10\n0 10 20 30 40 50 60 70 80 90\n0\n"
                                "318.3099 313.4740 299.1135 275.6644 243.8395 204.6057 159.1549 108.8684 "
                                "55.2739 0.0000\n";

/* A closed 4 x 4 x 3 m room (z up, faces inward) with a closed slab x in
 * [2, 3], y in [0.5, 3.5], z in [1.4, 1.6] (faces outward) and the point
 * lamp at (1, 2, 2.9) aimed down. */
static rad_scene *shadow_scene(rad_context *c)
{
    test_write_file("shadow.mtl", "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl wall\nKd 0.6 0.6 0.6\n");
    test_write_file("shadow.obj",
                    "mtllib shadow.mtl\n"
                    "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\nv 0 0 3\nv 4 0 3\nv 4 4 3\nv 0 4 3\n"
                    "v 2 0.5 1.4\nv 3 0.5 1.4\nv 3 3.5 1.4\nv 2 3.5 1.4\n"
                    "v 2 0.5 1.6\nv 3 0.5 1.6\nv 3 3.5 1.6\nv 2 3.5 1.6\n"
                    "usemtl floor\no floor\nf 1 2 3 4\n"
                    "usemtl wall\no ceiling\nf 5 8 7 6\no west\nf 1 4 8 5\no east\nf 2 6 7 3\n"
                    "o south\nf 1 5 6 2\no north\nf 4 3 7 8\n"
                    "o slab\nf 9 12 11 10\nf 13 14 15 16\nf 9 10 14 13\nf 10 11 15 14\nf 11 12 16 15\n"
                    "f 12 9 13 16\n");
    test_write_file("point.ies", point_ies);
    test_write_file("shadow.json", "{\"up\": [0, 0, 1], \"luminaires\": [{\"file\": \"point.ies\", "
                                   "\"position\": [1, 2, 2.9], \"lumens\": 4000, \"name\": \"lamp\"}]}");
    rad_scene *scene = NULL;
    if (rad_scene_load_file(c, test_path("shadow.obj"), &scene) != RAD_OK ||
        rad_scene_load_luminaires(c, scene, test_path("shadow.json")) != RAD_OK)
        fail_msg("%s", rad_context_error(c));
    return scene;
}

static void test_shadow_edge_leaves(void **state)
{
    (void)state;
    rad_scene *scene = shadow_scene(ctx);
    rad_solution *h = solve(ctx, scene, (rad_options){0});
    const rad_solution_view *v = &h->view;
    assert_non_null(v->hier);
    assert_non_null(v->direct);
    double min_area = v->hier->min_area, edge = 1.0 + 2.9 / 1.5;
    size_t floor = SIZE_MAX;
    for (size_t s = 0; s < rad_scene_surface_count(scene); s++)
        if (strcmp(rad_scene_surface_name(scene, s), "floor") == 0)
            floor = s;
    size_t crossing = 0, shadowed = 0, lit = 0, leaves = 0;
    double finest = INFINITY, floor_area = 0.0;
    for (size_t i = 0; i < v->n; i++) {
        const rad_element *e = &v->mesh->elements[i];
        if (e->surface != floor)
            continue;
        leaves++;
        floor_area += e->area;
        finest = fmin(finest, e->area);
        double lo = INFINITY, hi = -INFINITY;
        for (uint32_t k = 0; k < e->vertex_count; k++) {
            lo = fmin(lo, v->mesh->vertices[e->vertex[k]].x);
            hi = fmax(hi, v->mesh->vertices[e->vertex[k]].x);
        }
        const double *hd = &v->direct[3 * i];
        if (lo < edge && hi > edge) {
            /* On the line: split as far as min_area lets a leaf be split. */
            crossing++;
            if (!(0.25 * e->area < min_area))
                fail_msg("leaf x in [%g, %g] of %g m^2 crosses the shadow edge x = %g but could be split "
                         "(min_area %g m^2)", lo, hi, e->area, edge, min_area);
        } else if (lo >= edge) {
            shadowed++;
            assert_true(hd[0] == 0.0 && hd[1] == 0.0 && hd[2] == 0.0);
        } else {
            lit++;
            assert_true(hd[1] > 0.0);
        }
    }
    print_message("floor: %zu leaves (%zu on the edge, %zu in the shadow, %zu lit), finest %.4f m^2, min_area "
                  "%.4f m^2\n", leaves, crossing, shadowed, lit, finest, min_area);
    /* The line crosses the 4 m floor: at least 4 m / the finest side. */
    assert_true((double)crossing >= 4.0 / sqrt(finest) - 1e-9);
    assert_true(shadowed > 0 && lit > 0);
    /* Refined along the edge, not everywhere: under half the leaves a
     * uniform mesh at the finest size would have. */
    assert_true((double)leaves < 0.5 * floor_area / finest);
    rad_solution_destroy(h);
    rad_scene_destroy(scene);
}

/* One and two threads: the same hierarchy, direct light and radiosity. */
static void test_threads_identical(void **state)
{
    (void)state;
    rad_context *one = test_context(1);
    rad_scene *s1 = shadow_scene(one), *s2 = shadow_scene(ctx);
    rad_solution *a = solve(one, s1, (rad_options){0}), *b = solve(ctx, s2, (rad_options){0});
    assert_int_equal(a->view.n, b->view.n);
    assert_memory_equal(a->view.direct, b->view.direct, 3 * a->view.n * sizeof(double));
    assert_memory_equal(a->view.radiosity, b->view.radiosity, 3 * a->view.n * sizeof(double));
    assert_memory_equal(a->view.emission, b->view.emission, 3 * a->view.n * sizeof(double));
    rad_solution_destroy(a);
    rad_solution_destroy(b);
    rad_scene_destroy(s1);
    rad_scene_destroy(s2);
    rad_context_destroy(one);
}

/* ---- daylight (slow) ---- */

/* The daylight data room (y up: a skylight and a window) at a looser
 * integration tolerance than its file's, which the comparison does not
 * need (both solvers see the same light). */
static rad_scene *daylit_room(void)
{
    char *json = test_read_file(RAD_TEST_DATA "/daylight/room.json", NULL);
    char *at = strstr(json, "\"tolerance\": 1e-4");
    assert_non_null(at);
    memcpy(at, "\"tolerance\": 1e-2", strlen("\"tolerance\": 1e-2"));
    test_write_file("sky.json", json);
    free(json);
    rad_scene *scene = NULL;
    if (rad_scene_load_file(ctx, RAD_TEST_DATA "/daylight/room.obj", &scene) != RAD_OK ||
        rad_scene_daylight_load_file(ctx, scene, test_path("sky.json")) != RAD_OK)
        fail_msg("%s", rad_context_error(ctx));
    return scene;
}

static const char floor_plane[] = "{\"up\": \"y\", \"grids\": [{\"name\": \"floor\", \"rectangle\": "
                                  "{\"origin\": [0.2, 0.85, 0.2], \"u\": [3.6, 0, 0], \"v\": [0, 0, 3.6]}, "
                                  "\"facing\": \"up\", \"spacing\": 0.4}]}";

static void test_daylight_agrees_and_saves(void **state)
{
    (void)state;
    rad_scene *scene = daylit_room();
    rad_solution *h = solve(ctx, scene, (rad_options){0});
    assert_string_equal(h->options.solver, "hierarchical");
    rad_solution *g = solve(ctx, scene, (rad_options){.solver = "gauss-seidel", .target_elements = 1500});
    /* The sun patch's edges are what a uniform mesh smears: 3% per surface. */
    compare(scene, h, g, floor_plane, 0.03, 0.05, 0.015);
    /* The solution file keeps the daylight: the same grid to the bit. */
    assert_int_equal(rad_solution_save(ctx, h, test_path("day.radsol")), RAD_OK);
    rad_scene *loaded_scene = NULL;
    rad_solution *loaded = NULL;
    assert_int_equal(rad_solution_load_file(ctx, test_path("day.radsol"), &loaded_scene, &loaded), RAD_OK);
    assert_non_null(loaded_scene->daylight);
    rad_illuminance *a = grid(h, floor_plane), *b = grid(loaded, floor_plane);
    const rad_grid_result *ra = rad_illuminance_grid(a, 0), *rb = rad_illuminance_grid(b, 0);
    assert_int_equal(ra->point_count, rb->point_count);
    for (size_t i = 0; i < ra->point_count; i++) {
        assert_true(ra->points[i].illuminance == rb->points[i].illuminance);
        assert_true(ra->points[i].daylight_factor == rb->points[i].daylight_factor);
    }
    rad_illuminance_destroy(a);
    rad_illuminance_destroy(b);
    rad_solution_destroy(loaded);
    rad_scene_destroy(loaded_scene);
    rad_solution_destroy(h);
    rad_solution_destroy(g);
    rad_scene_destroy(scene);
}

/* The solution file's daylight part: kept (a coarse daylit solution saved
 * and loaded has the same daylight and direct light), and checked (a sky
 * type out of range in the header is one line naming the file). */
static void test_daylight_solution_file(void **state)
{
    (void)state;
    rad_scene *scene = daylit_room();
    rad_solution *sol = solve(ctx, scene, (rad_options){.solver = "gauss-seidel", .target_elements = 60});
    assert_int_equal(rad_solution_save(ctx, sol, test_path("coarse.radsol")), RAD_OK);
    rad_scene *loaded_scene = NULL;
    rad_solution *loaded = NULL;
    assert_int_equal(rad_solution_load_file(ctx, test_path("coarse.radsol"), &loaded_scene, &loaded), RAD_OK);
    assert_non_null(loaded_scene->daylight);
    assert_true(rad_scene_daylight_sky_illuminance(loaded_scene) == rad_scene_daylight_sky_illuminance(scene));
    assert_int_equal(rad_scene_daylight_opening_count(loaded_scene), rad_scene_daylight_opening_count(scene));
    assert_int_equal(loaded->view.n, sol->view.n);
    assert_non_null(loaded->view.direct);
    assert_memory_equal(loaded->view.direct, sol->view.direct, 3 * sol->view.n * sizeof(double));
    assert_memory_equal(loaded->view.emission, sol->view.emission, 3 * sol->view.n * sizeof(double));
    rad_solution_destroy(loaded);
    rad_scene_destroy(loaded_scene);
    /* Sky type 12 -> 99 in the header (same length; the header is not in
     * the payload's checksum). */
    size_t size = 0;
    char *bytes = test_read_file(test_path("coarse.radsol"), &size);
    char *type = strstr(bytes + 12, "\"type\":\t12"); /* after the signature and the header's length */
    assert_non_null(type);
    memcpy(type + strlen("\"type\":\t"), "99", 2);
    assert_int_equal(rad_solution_load_memory(ctx, "bad.radsol", bytes, size, &loaded_scene, &loaded),
                     RAD_ERROR_PARSE);
    assert_non_null(strstr(rad_context_error(ctx), "bad.radsol: daylight: the sky, sun or ground is out of range"));
    free(bytes);
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
}

int main(int argc, char **argv)
{
    /* "--slow": the daylit case (a minute of sky integration) instead of
     * the quick ones. */
    bool slow = argc == 2 && strcmp(argv[1], "--slow") == 0;
    if (argc > 2 || (argc == 2 && !slow)) {
        fprintf(stderr, "usage: test_hier_lights [--slow]\n");
        return 2;
    }
    const struct CMUnitTest fast_tests[] = {
        cmocka_unit_test(test_luminaires_agree_with_dense),
        cmocka_unit_test(test_luminaires_energy),
        cmocka_unit_test(test_reach_rooms),
        cmocka_unit_test(test_pocket),
        cmocka_unit_test(test_shadow_edge_leaves),
        cmocka_unit_test(test_threads_identical),
        cmocka_unit_test(test_daylight_solution_file),
    };
    const struct CMUnitTest slow_tests[] = {
        cmocka_unit_test(test_daylight_agrees_and_saves),
    };
    return slow ? cmocka_run_group_tests_name("hier_lights_slow", slow_tests, setup, teardown)
                : cmocka_run_group_tests_name("hier_lights", fast_tests, setup, teardown);
}
