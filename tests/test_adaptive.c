/*
 * test_adaptive.c -- adaptive subdivision of the dense strategy's mesh
 * (src/strategy/adaptive.c) on a sharp shadow, tests/data/plate_shadow.obj:
 * a floor under a small square light with a plate floating between.  Its
 * floor receives direct light only, so its radiosity is known in closed
 * form (rho E times the factor to the part of the light the plate leaves
 * visible: two parallel rectangles), and a fine uniform solution agrees
 * with it to 1%.
 *
 *   accuracy     the adaptive solution's floor element values, read at the
 *                centres of a 128 x 128 grid (elements 4 times smaller than
 *                the finest here), are as close to the exact floor (RMS and
 *                max) as those of a uniform mesh with at least 4 times the
 *                adaptive mesh's elements; the uniform starting mesh is far
 *                off
 *   penumbra     along a line across the shadow edge, the smooth floor
 *                radiosity crosses half the unoccluded value within one
 *                finest element of the exact place
 *   mesh         restricted quadtrees, of quads and (a triangular floor)
 *                of triangles: every T-vertex at the middle of its edge
 *                (neighbours one level apart at most); each element found
 *                at its own centre; the elements tile each surface
 *   refinement   elements were split where the shadow edge is, and more
 *                levels or a lower threshold never give fewer elements; the
 *                budget (and the memory limit's cap on it) is kept up to
 *                the balancing splits
 *   determinism  1 and 2 threads give bit-identical radiosities
 *   options      the non-dense solvers refuse it, naming the field
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/solution.h"

static rad_context *ctx, *ctx1;
static rad_scene *scene;

/* The geometry of plate_shadow.obj. */
#define LIGHT_HALF 0.05  /* m: the light spans [-0.05, 0.05]^2 at z = 1.5 */
#define LIGHT_Z 1.5
#define PLATE_HALF 0.3   /* m: the plate spans [-0.3, 0.3]^2 at z = 0.5 */
#define PLATE_Z 0.5
#define RHO 0.5
#define EMISSION (40.0 * M_PI) /* W/m^2 */
#define BASE 0.125       /* m: the starting mesh size */
#define LEVELS 3
#define FINE (BASE / 8.0) /* m: the finest element's side */

static int setup(void **state)
{
    (void)state;
    rad_context_options co = {0};
    co.threads = 2;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return -1;
    co.threads = 1;
    if (rad_context_create(&co, &ctx1) != RAD_OK)
        return -1;
    return rad_scene_load_file(ctx, RAD_TEST_DATA "/plate_shadow.obj", &scene) == RAD_OK ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    rad_context_destroy(ctx1);
    return 0;
}

static rad_solution *solve_with(rad_context *c, rad_options o)
{
    if (!o.solver)
        o.solver = "gauss-seidel"; /* adaptive subdivision is the dense solvers' */
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(c, scene, &o, &s), RAD_OK);
    assert_int_equal(rad_solution_solve(c, s), RAD_OK);
    return s;
}

static rad_solution *uniform(double h) { return solve_with(ctx, (rad_options){.mesh_size = h}); }

static rad_solution *adaptive(int levels, double threshold, size_t budget)
{
    return solve_with(ctx, (rad_options){.mesh_size = BASE,
                                         .adaptive_levels = levels,
                                         .adaptive_threshold = threshold,
                                         .adaptive_max_elements = budget});
}

static size_t surface_named(const char *name)
{
    for (size_t k = 0; k < scene->surface_count; k++)
        if (strcmp(scene->surfaces[k].name, name) == 0)
            return k;
    fail_msg("no surface %s", name);
    return 0;
}

/* The value of the element of s holding floor point p (flat shading). */
static double flat_value(const rad_solution *s, vec3 p)
{
    const rad_mesh *mesh = s->view.mesh;
    size_t floor = surface_named("floor");
    for (uint32_t k = 0; k < mesh->patch_count; k++) {
        if (mesh->patches[k].surface != floor)
            continue;
        double u, v, ls, lt;
        rad_patch_parameters(&mesh->patches[k], p, &u, &v);
        uint32_t e = rad_mesh_locate(mesh, k, u, v, &ls, &lt);
        return s->view.radiosity[3 * (size_t)e];
    }
    fail_msg("no floor patch");
    return 0.0;
}

/* The factor from a floor point to the rectangle [x0, x1] x [y0, y1] (in
 * coordinates relative to the point) at height c, parallel to the floor:
 * the corner formula (Howell's catalogue, case B-3) G(X, Y) = (X / sqrt(1 +
 * X^2) atan(Y / sqrt(1 + X^2)) + Y / sqrt(1 + Y^2) atan(X / sqrt(1 + Y^2)))
 * / (2 pi) is odd in X and Y, so any rectangle is four signed corners. */
static double corner_factor(double X, double Y)
{
    double a = sqrt(1.0 + X * X), b = sqrt(1.0 + Y * Y);
    return (X / a * atan(Y / a) + Y / b * atan(X / b)) / (2.0 * M_PI);
}

static double rectangle_factor(double x0, double x1, double y0, double y1, double c)
{
    if (!(x1 > x0 && y1 > y0))
        return 0.0;
    return corner_factor(x1 / c, y1 / c) - corner_factor(x0 / c, y1 / c) - corner_factor(x1 / c, y0 / c) +
           corner_factor(x0 / c, y0 / c);
}

/* The floor's factor to the light at (x, y): all of it, and the part the
 * plate leaves visible (the plate seen from the point covers, in the
 * light's plane, its square scaled by LIGHT_Z / PLATE_Z about the point). */
static void light_seen(double x, double y, double *all, double *visible)
{
    const double L = LIGHT_HALF, P = PLATE_HALF, k = LIGHT_Z / PLATE_Z;
    double sx0 = x + k * (-P - x), sx1 = x + k * (P - x), sy0 = y + k * (-P - y), sy1 = y + k * (P - y);
    *all = rectangle_factor(-L - x, L - x, -L - y, L - y, LIGHT_Z);
    *visible = *all - rectangle_factor(fmax(-L, sx0) - x, fmin(L, sx1) - x, fmax(-L, sy0) - y,
                                       fmin(L, sy1) - y, LIGHT_Z);
}

static double exact_floor(double x, double y)
{
    double all, visible;
    light_seen(x, y, &all, &visible);
    return RHO * EMISSION * visible;
}

typedef struct floor_error {
    double rms, max; /* relative to the exact floor's brightest value */
} floor_error;

/* s's element values against the exact floor at the centres of a 128 x 128
 * grid. */
static floor_error error_against_exact(const rad_solution *s)
{
    const int N = 128;
    double top = 0.0, sum = 0.0, worst = 0.0;
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            double x = -1.0 + (i + 0.5) * 2.0 / N, y = -1.0 + (j + 0.5) * 2.0 / N;
            double exact = exact_floor(x, y), d = flat_value(s, (vec3){x, y, 0.0}) - exact;
            top = fmax(top, exact);
            sum += d * d;
            worst = fmax(worst, fabs(d));
        }
    return (floor_error){sqrt(sum / (N * N)) / top, worst / top};
}

/* The closed form against a solution, away from the shadow's edges (the
 * elements more than 0.1 m from them, fully lit or fully hidden): the
 * reference is the engine's own answer where a mesh can resolve it. */
static void check_exact(const rad_solution *s, double tolerance)
{
    size_t floor = surface_named("floor");
    double top = exact_floor(0.9, 0.0), worst = 0.0;
    for (size_t i = 0; i < s->view.n; i++) {
        const rad_element *e = &s->view.mesh->elements[i];
        double all, visible;
        if (e->surface != floor)
            continue;
        bool edge = false;
        for (int dx = -2; dx <= 2; dx++)
            for (int dy = -2; dy <= 2; dy++) {
                light_seen(e->centroid.x + 0.05 * dx, e->centroid.y + 0.05 * dy, &all, &visible);
                edge |= visible > 0.0 && visible < all;
            }
        if (!edge)
            worst = fmax(worst, fabs(s->view.radiosity[3 * i] - exact_floor(e->centroid.x, e->centroid.y)));
    }
    print_message("closed form against %zu elements: worst %.2e of the floor's light\n", s->view.n, worst / top);
    assert_true(worst < tolerance * top);
}

/* Along y = Y, x rising through the penumbra: the first x (steps of 0.1
 * mm) where s's smooth floor radiosity reaches `fraction` of the unoccluded
 * value, or with s NULL, where that fraction of the light is visible
 * (kernel-weighted). */
#define Y 0.013 /* off the element edges of every mesh here */
static double crossing(rad_solution *s, double fraction)
{
    size_t floor = surface_named("floor");
    for (double x = 0.35; x < 0.55; x += 1e-4) {
        double all, visible;
        light_seen(x, Y, &all, &visible);
        if (s) {
            double p[3] = {x, Y, 0.0}, rgb[3];
            assert_int_equal(rad_solution_point_radiosity(ctx, s, floor, p, rgb), RAD_OK);
            visible = rgb[0] / (RHO * EMISSION);
        }
        if (visible >= fraction * all)
            return x;
    }
    return INFINITY;
}

static void test_accuracy(void **state)
{
    (void)state;
    rad_solution *a = adaptive(LEVELS, 0.0, 0);
    const rad_adaptive_stats *as = a->view.adaptive;
    assert_non_null(as);
    floor_error ea = error_against_exact(a);
    print_message("adaptive: %zu elements (from %zu, %d rounds), rms %.4f max %.4f\n", a->view.n,
                  as->initial_elements, as->rounds, ea.rms, ea.max);
    /* Uniform meshes, coarse to fine, up to the first with 4x the
     * elements. */
    const double sizes[] = {BASE, 0.0625, 0.05, 0.04, 0.03};
    bool compared = false;
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0] && !compared; k++) {
        rad_solution *u = uniform(sizes[k]);
        floor_error eu = error_against_exact(u);
        print_message("uniform %.4f m: %zu elements, rms %.4f max %.4f\n", sizes[k], u->view.n, eu.rms, eu.max);
        if (k == 0) { /* the starting mesh is far off: the measure can tell */
            assert_true(eu.rms > 2.0 * ea.rms);
            assert_true(eu.max > 2.0 * ea.max);
        }
        if (u->view.n >= 4 * a->view.n) {
            check_exact(u, 0.01);
            assert_true(ea.rms <= eu.rms);
            assert_true(ea.max <= eu.max);
            compared = true;
        }
        rad_solution_destroy(u);
    }
    assert_true(compared);
    check_exact(a, 0.01);
    rad_solution_destroy(a);
}

static void test_penumbra(void **state)
{
    (void)state;
    double exact = crossing(NULL, 0.5), width = crossing(NULL, 0.75) - crossing(NULL, 0.25);
    assert_true(fabs(exact - 0.45) < 0.005); /* the geometry's midpoint, bent a little by the kernel */
    rad_solution *a = adaptive(LEVELS, 0.0, 0), *u = uniform(BASE);
    double got = crossing(a, 0.5), got_width = crossing(a, 0.75) - crossing(a, 0.25);
    double u_width = crossing(u, 0.75) - crossing(u, 0.25);
    print_message("half crossing: exact %.4f m, adaptive %.4f m (finest element %.4f m), uniform %.4f m\n", exact,
                  got, FINE, crossing(u, 0.5));
    print_message("25%% to 75%%: exact %.4f m, adaptive %.4f m, uniform %.4f m\n", width, got_width, u_width);
    assert_true(fabs(got - exact) <= FINE);
    /* The shadow edge as sharp as the finest elements can draw it; the
     * starting mesh smears it over its own. */
    assert_true(fabs(got_width - width) <= FINE);
    assert_true(u_width > width + 2.0 * FINE);
    rad_solution_destroy(a);
    rad_solution_destroy(u);
}

/* The mesh of solution a: balanced (a T-vertex two levels apart would sit
 * at t = 1/4 or 3/4: every one here is inside one patch), each element
 * found at its own centre, the elements tiling each surface. */
static void check_mesh(const rad_solution *a)
{
    const rad_mesh *mesh = a->view.mesh;
    assert_non_null(mesh->tree);
    assert_true(mesh->tvertex_count > 0);
    for (size_t k = 0; k < mesh->tvertex_count; k++)
        assert_true(fabs(mesh->tvertices[k].t - 0.5) < 1e-9);
    const rad_scene *sc = a->scene;
    double *area = calloc(sc->surface_count, sizeof *area);
    for (size_t i = 0; i < mesh->element_count; i++) {
        const rad_element *e = &mesh->elements[i];
        double u, v, ls, lt;
        rad_patch_parameters(&mesh->patches[e->patch], e->centroid, &u, &v);
        assert_int_equal(rad_mesh_locate(mesh, e->patch, u, v, &ls, &lt), i);
        area[e->surface] += e->area;
    }
    for (size_t k = 0; k < sc->surface_count; k++)
        assert_true(fabs(area[k] - sc->surfaces[k].area) < 1e-12 * sc->surfaces[k].area);
    free(area);
}

static void test_mesh(void **state)
{
    (void)state;
    rad_solution *a = adaptive(LEVELS, 0.0, 0);
    check_mesh(a);
    rad_solution_destroy(a);
    /* Triangle quadtrees (corner and medial children): the floor as one
     * triangle, its shadow edge crossing it. */
    rad_scene_builder *b = rad_scene_builder_create(ctx, "triangle floor");
    const double grey[3] = {0.5, 0.5, 0.5}, black[3] = {0, 0, 0}, light[3] = {EMISSION, EMISSION, EMISSION};
    int m_grey = rad_scene_builder_material(b, "grey", grey, black);
    int m_light = rad_scene_builder_material(b, "light", black, light);
    const vec3 floor[3] = {{-1, -1, 0}, {1, -1, 0}, {-1, 1, 0}};
    const vec3 plate[4] = {{-0.3, -0.3, 0.5}, {0.3, -0.3, 0.5}, {0.3, 0.3, 0.5}, {-0.3, 0.3, 0.5}};
    const vec3 lamp[4] = {{-0.05, -0.05, 1.5}, {-0.05, 0.05, 1.5}, {0.05, 0.05, 1.5}, {0.05, -0.05, 1.5}};
    assert_int_equal(rad_scene_builder_polygon(b, rad_scene_builder_surface(b, "floor"), m_grey, floor, 3, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_polygon(b, rad_scene_builder_surface(b, "plate"), m_grey, plate, 4, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_polygon(b, rad_scene_builder_surface(b, "light"), m_light, lamp, 4, 0),
                     RAD_OK);
    rad_scene *tri = NULL;
    assert_int_equal(rad_scene_builder_finish(b, &tri), RAD_OK);
    rad_options o = {.mesh_size = BASE, .adaptive_levels = LEVELS, .solver = "gauss-seidel"};
    rad_solution *t = NULL;
    assert_int_equal(rad_solution_create(ctx, tri, &o, &t), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, t), RAD_OK);
    assert_int_equal(t->view.mesh->patches[0].corner_count, 3);
    assert_true(t->view.adaptive->split > 0);
    check_mesh(t);
    rad_solution_destroy(t);
    rad_scene_destroy(tri);
}

static void test_refinement(void **state)
{
    (void)state;
    rad_solution *a1 = adaptive(1, 0.0, 0), *a3 = adaptive(3, 0.0, 0), *low = adaptive(3, 0.02, 0);
    const rad_adaptive_stats *s1 = a1->view.adaptive, *s3 = a3->view.adaptive;
    assert_int_equal(s1->initial_elements, s3->initial_elements);
    assert_true(s1->rounds == 1 && s3->rounds >= 2);
    assert_true(a1->view.n > s1->initial_elements && a3->view.n > a1->view.n);
    assert_true(low->view.n >= a3->view.n);
    assert_true(s3->split > 0);
    /* The elements on the shadow edge are split to the finest level. */
    const rad_mesh *mesh = a3->view.mesh;
    size_t floor = surface_named("floor");
    double smallest = INFINITY;
    for (size_t i = 0; i < mesh->element_count; i++) {
        const rad_element *e = &mesh->elements[i];
        if (e->surface == floor && fabs(e->centroid.x - 0.45) < 0.025 && fabs(e->centroid.y) < 0.3)
            smallest = fmin(smallest, e->area);
    }
    assert_true(fabs(smallest - FINE * FINE) < 1e-12);
    /* A budget: no round splits past it; balancing adds at most a few. */
    size_t budget = s3->initial_elements + 60;
    rad_solution *b = adaptive(3, 0.0, budget);
    assert_true(b->view.n <= budget + 3 * b->view.adaptive->balanced);
    assert_true(b->view.n < a3->view.n);
    rad_solution_destroy(b);
    rad_solution_destroy(a1);
    rad_solution_destroy(a3);
    rad_solution_destroy(low);
    /* The memory limit caps the budget where the matrix (16 n^2 bytes at
     * most) would not fit: 10 MiB, 809 elements (with no other solution
     * alive: the limit counts the context's memory). */
    rad_solution *small = solve_with(ctx, (rad_options){.mesh_size = BASE, .adaptive_levels = 3,
                                                        .max_memory_bytes = 10485760.0});
    size_t fits = (size_t)sqrt(10485760.0 / 16.0);
    assert_true(small->view.n > small->view.adaptive->initial_elements);
    assert_true(small->view.n <= fits + 3 * small->view.adaptive->balanced + 3);
    rad_solution_destroy(small);
}

static void test_determinism(void **state)
{
    (void)state;
    rad_options o = {.mesh_size = BASE, .adaptive_levels = 2};
    rad_solution *two = solve_with(ctx, o), *one = solve_with(ctx1, o);
    assert_int_equal(two->view.n, one->view.n);
    assert_memory_equal(two->view.radiosity, one->view.radiosity, 3 * one->view.n * sizeof(double));
    rad_solution_destroy(two);
    rad_solution_destroy(one);
}

static void test_options(void **state)
{
    (void)state;
    const char *solvers[] = {"hierarchical", "shooting"};
    for (int k = 0; k < 2; k++) {
        rad_options o = {.adaptive_levels = 2, .solver = solvers[k]};
        rad_solution *s = (rad_solution *)1;
        assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_ERROR_INVALID_ARGUMENT);
        assert_null(s);
        assert_non_null(strstr(rad_context_error(ctx), "rad_options.adaptive_levels"));
    }
    rad_options o = {.adaptive_levels = 13};
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_ERROR_INVALID_ARGUMENT);
    /* Without it, the dense strategy shows no adaptive figures. */
    s = uniform(BASE);
    assert_null(s->view.adaptive);
    rad_solution_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_accuracy),    cmocka_unit_test(test_penumbra),
        cmocka_unit_test(test_mesh),        cmocka_unit_test(test_refinement),
        cmocka_unit_test(test_determinism), cmocka_unit_test(test_options),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
