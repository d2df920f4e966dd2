/*
 * test_galerkin.c -- the galerkin strategy (src/strategy/galerkin.c):
 * Galerkin elements, constant and linear, and point collocation.
 *
 *   - a closed box of uniform emission and reflectance: the continuum
 *     solution is uniform, B = E / (1 - rho); every basis reproduces it
 *     (quads: a cube; triangles: a tetrahedron), and the power balances;
 *   - M: every element's mass sums to its area (partition of unity);
 *   - K of the constant basis against A_i F_ij by the double contour
 *     integral (ff_contour.c), and its reciprocity;
 *   - the convergence orders on a floor under a small square emitter,
 *     whose radiosity is rho E F(x -> emitter) exactly: O(h) for constant
 *     elements, O(h^2) for linear ones and collocation;
 *   - galerkin-constant against the dense strategy on the Cornell box;
 *   - the vertex values are the solution's (not averages), solution files
 *     and mixed reflectance around a vertex are refused.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "strategy/options.h"
#include "api/solution.h"
#include "interp/interp.h"
#include "strategy/strategy.h"

static rad_context *ctx;

/* A closed unit cube, normals inward, rho and E on every face. */
static rad_scene *make_cube(double rho, double E)
{
    rad_scene_builder *b = rad_scene_builder_create(ctx, "cube");
    double r[3] = {rho, rho, rho}, e[3] = {E, E, E};
    int m = rad_scene_builder_material(b, "wall", r, e);
    const vec3 faces[6][4] = {
        {{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}, {{1, 0, 0}, {1, 0, 1}, {1, 1, 1}, {1, 1, 0}},
        {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}, {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}},
        {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}},
    };
    const char *names[6] = {"x0", "x1", "y0", "y1", "z0", "z1"};
    for (int f = 0; f < 6; f++)
        assert_int_equal(rad_scene_builder_polygon(b, rad_scene_builder_surface(b, names[f]), m, faces[f], 4, 0),
                         RAD_OK);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    return scene;
}

/* A closed regular tetrahedron, normals inward: triangle patches. */
static rad_scene *make_tetrahedron(double rho, double E)
{
    rad_scene_builder *b = rad_scene_builder_create(ctx, "tetrahedron");
    double r[3] = {rho, rho, rho}, e[3] = {E, E, E};
    int m = rad_scene_builder_material(b, "wall", r, e);
    const vec3 v[4] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
    const int face[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
    for (int f = 0; f < 4; f++) {
        vec3 t[3] = {v[face[f][0]], v[face[f][1]], v[face[f][2]]};
        vec3 n = v3_cross(v3_sub(t[1], t[0]), v3_sub(t[2], t[0]));
        if (v3_dot(n, v3_add(t[0], v3_add(t[1], t[2]))) > 0.0) { /* outward: turn it */
            vec3 s = t[1];
            t[1] = t[2];
            t[2] = s;
        }
        char name[8];
        snprintf(name, sizeof name, "f%d", f);
        assert_int_equal(rad_scene_builder_polygon(b, rad_scene_builder_surface(b, name), m, t, 3, 0), RAD_OK);
    }
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    return scene;
}

/* A unit square floor (rho 0.5) under a 0.2 m square emitter (E = 1,
 * rho 0) 0.5 m above its middle, as bench_galerkin's. */
static const vec3 light_square[4] = {{0.4, 0.5, 0.4}, {0.6, 0.5, 0.4}, {0.6, 0.5, 0.6}, {0.4, 0.5, 0.6}};

static rad_scene *make_floor(void)
{
    rad_scene_builder *b = rad_scene_builder_create(ctx, "floor");
    double rho[3] = {0.5, 0.5, 0.5}, none[3] = {0, 0, 0}, E[3] = {1, 1, 1};
    int fm = rad_scene_builder_material(b, "floor", rho, none), lm = rad_scene_builder_material(b, "light", none, E);
    const vec3 square[4] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}};
    assert_int_equal(rad_scene_builder_polygon(b, rad_scene_builder_surface(b, "floor"), fm, square, 4, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_polygon(b, rad_scene_builder_surface(b, "light"), lm, light_square, 4, 0),
                     RAD_OK);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    return scene;
}

/* Create and solve the galerkin strategy directly (its matrices are not
 * public); *view filled. */
static void *solve_state(const rad_scene *scene, const char *solver, double mesh_size, size_t elements,
                         rad_options *resolved, rad_solution_view *view)
{
    rad_options in = {0};
    rad_method_names names;
    in.solver = solver;
    in.mesh_size = mesh_size;
    in.target_elements = elements;
    in.tolerance = 1e-12;
    assert_int_equal(rad_options_resolve(ctx, &in, resolved, &names), RAD_OK);
    resolved->solver = solver; /* names lives on this stack frame */
    resolved->form_factors = "analytic";
    resolved->visibility = "embree";
    void *state = NULL;
    assert_int_equal(rad_strategy_galerkin.create(ctx, scene, resolved, &state), RAD_OK);
    rad_step_hook hook = {0};
    assert_int_equal(rad_strategy_galerkin.solve(ctx, state, &hook), RAD_OK);
    memset(view, 0, sizeof *view);
    rad_strategy_galerkin.view(state, view);
    view->scene = scene;
    view->options = resolved;
    return state;
}

/* ---- the closed box ---- */

static void uniform_box(rad_scene *scene, double mesh_size)
{
    const char *solvers[3] = {"galerkin-constant", "galerkin-linear", "collocation"};
    for (int k = 0; k < 3; k++) {
        rad_options o;
        rad_solution_view v;
        void *st = solve_state(scene, solvers[k], mesh_size, 0, &o, &v);
        rad_galerkin_matrices g;
        rad_galerkin_get_matrices(st, &g);
        /* B = E / (1 - rho) = 2 at every node and in every element. */
        for (size_t i = 0; i < 3 * g.unknowns; i++)
            if (!(fabs(g.node_radiosity[i] - 2.0) < 1e-6))
                fail_msg("%s: node %zu B %.9f", solvers[k], i / 3, g.node_radiosity[i]);
        for (size_t i = 0; i < 3 * v.n; i++)
            assert_true(fabs(v.radiosity[i] - 2.0) < 1e-6);
        /* The power balances: all that is emitted is absorbed. */
        double emitted, absorbed;
        assert_int_equal(rad_view_power(ctx, &v, &emitted, &absorbed), RAD_OK);
        assert_true(fabs(absorbed - emitted) < 1e-6 * emitted);
        /* Every row of K sums to its node's mass (Galerkin) or 1
         * (collocation): the closed box's closure, to rounding. */
        for (size_t i = 0; i < g.unknowns; i++) {
            double row = 0.0;
            for (size_t j = 0; j < g.unknowns; j++)
                row += g.K[i * g.unknowns + j];
            double expected = strcmp(solvers[k], "collocation") == 0 ? 1.0 : g.node_mass[i];
            assert_true(fabs(row - expected) < 1e-7 * expected);
        }
        rad_strategy_galerkin.destroy(st);
    }
}

static void test_closed_cube_uniform(void **state)
{
    (void)state;
    rad_scene *scene = make_cube(0.5, 1.0);
    uniform_box(scene, 0.25);
    rad_scene_destroy(scene);
}

static void test_closed_tetrahedron_uniform(void **state)
{
    (void)state;
    rad_scene *scene = make_tetrahedron(0.5, 1.0);
    uniform_box(scene, 0.7);
    rad_scene_destroy(scene);
}

/* ---- M: partition of unity ---- */

static void test_mass_partition_of_unity(void **state)
{
    (void)state;
    rad_scene *scenes[2] = {make_cube(0.5, 1.0), make_tetrahedron(0.5, 1.0)};
    for (int k = 0; k < 2; k++) {
        rad_options o;
        rad_solution_view v;
        void *st = solve_state(scenes[k], "galerkin-linear", k == 0 ? 0.25 : 0.7, 0, &o, &v);
        rad_galerkin_matrices g;
        rad_galerkin_get_matrices(st, &g);
        double total = 0.0, nodes = 0.0;
        for (size_t e = 0; e < v.n; e++) {
            const rad_element *el = &v.mesh->elements[e];
            const double *Me = g.element_mass + 16 * e;
            double sum = 0.0;
            for (uint32_t a = 0; a < el->vertex_count; a++)
                for (uint32_t b = 0; b < el->vertex_count; b++) {
                    sum += Me[4 * a + b];
                    assert_true(fabs(Me[4 * a + b] - Me[4 * b + a]) < 1e-15); /* symmetric */
                }
            assert_true(fabs(sum - el->area) < 1e-12 * el->area);
            /* Linear triangles: A/12 (2 on the diagonal, 1 off it). */
            if (el->vertex_count == 3) {
                assert_true(fabs(Me[0] - el->area / 6.0) < 1e-12 * el->area);
                assert_true(fabs(Me[1] - el->area / 12.0) < 1e-12 * el->area);
            } else { /* bilinear on a square: A/36 (4, 2, 1, 2) */
                assert_true(fabs(Me[0] - 4.0 * el->area / 36.0) < 1e-12 * el->area);
                assert_true(fabs(Me[1] - 2.0 * el->area / 36.0) < 1e-12 * el->area);
                assert_true(fabs(Me[2] - el->area / 36.0) < 1e-12 * el->area);
            }
            total += el->area;
        }
        for (size_t i = 0; i < g.unknowns; i++)
            nodes += g.node_mass[i];
        assert_true(fabs(nodes - total) < 1e-12 * total);
        rad_strategy_galerkin.destroy(st);
        rad_scene_destroy(scenes[k]);
    }
}

/* ---- K of the constant basis = A F ---- */

static void test_constant_kernel_is_AF(void **state)
{
    (void)state;
    rad_scene *scene = make_cube(0.5, 0.0);
    rad_options o;
    rad_solution_view v;
    void *st = solve_state(scene, "galerkin-constant", 0.5, 0, &o, &v);
    rad_galerkin_matrices g;
    rad_galerkin_get_matrices(st, &g);
    assert_int_equal(g.unknowns, v.n);
    double tol = rad_ff_plane_tolerance(v.mesh), worst_far = 0.0, worst_near = 0.0, worst_reciprocity = 0.0;
    for (uint32_t i = 0; i < v.n; i++)
        for (uint32_t j = 0; j < v.n; j++) {
            double AF = i == j ? 0.0 : rad_element_coupling(v.mesh, i, j, tol), K = g.K[(size_t)i * v.n + j];
            if (AF < 1e-12) { /* coplanar: 0 up to the contour integral's rounding */
                assert_true(K == 0.0);
                continue;
            }
            /* Pairs with a shared edge: the outer rule meets the factor's
             * d log d there. */
            bool near = v3_length(v3_sub(v.mesh->elements[i].centroid, v.mesh->elements[j].centroid)) < 0.75;
            double rel = fabs(K - AF) / AF;
            if (near)
                worst_near = fmax(worst_near, rel);
            else
                worst_far = fmax(worst_far, rel);
            worst_reciprocity = fmax(worst_reciprocity, fabs(K - g.K[(size_t)j * v.n + i]) / AF);
        }
    print_message("K against A F: far pairs %.2e, pairs sharing an edge %.2e, reciprocity %.2e\n", worst_far,
                  worst_near, worst_reciprocity);
    /* Measured: 5.5e-6, 1.0e-6, 5.4e-6 (the 3 x 3 Gauss rule of the
     * outer integral; the inner factor is exact). */
    assert_true(worst_far < 2e-5);
    assert_true(worst_near < 5e-6);
    assert_true(worst_reciprocity < 2e-5);
    rad_strategy_galerkin.destroy(st);
    rad_scene_destroy(scene);
}

/* ---- the convergence orders ---- */

/* Relative L2 error of the floor's B_h against rho E F(x -> emitter), by
 * an 8 x 8 midpoint rule in each element (its cells are parallelograms). */
static double floor_error(const rad_solution_view *v)
{
    enum { S = 8 };
    double err2 = 0.0, ref2 = 0.0;
    for (size_t e = 0; e < v->n; e++) {
        const rad_element *el = &v->mesh->elements[e];
        if (el->surface != 0)
            continue;
        vec3 c[4];
        for (uint32_t k = 0; k < 4; k++)
            c[k] = v->mesh->vertices[el->vertex[k]];
        for (int a = 0; a < S; a++)
            for (int b = 0; b < S; b++) {
                double s = (a + 0.5) / S, t = (b + 0.5) / S, rgb[3];
                vec3 x = v3_add(v3_add(v3_scale(c[0], (1 - s) * (1 - t)), v3_scale(c[1], s * (1 - t))),
                                v3_add(v3_scale(c[2], s * t), v3_scale(c[3], (1 - s) * t)));
                double exact = 0.5 * rad_point_polygon_ff(x, el->normal, light_square, 4);
                if (v->vertex_radiosity)
                    rad_element_interpolate(v->mesh, el, v->vertex_radiosity, s, t, rgb);
                else
                    rgb[0] = v->radiosity[3 * e];
                err2 += el->area / (S * S) * (rgb[0] - exact) * (rgb[0] - exact);
                ref2 += el->area / (S * S) * exact * exact;
            }
    }
    return sqrt(err2 / ref2);
}

static void test_convergence_orders(void **state)
{
    (void)state;
    rad_scene *scene = make_floor();
    const char *solvers[3] = {"galerkin-constant", "galerkin-linear", "collocation"};
    /* bench_galerkin floor: constant 1.0 (0.204, 0.104, 0.052 at h = 1/4,
     * 1/8, 1/16), linear 2.1, collocation 2. */
    const double lo[3] = {0.9, 1.8, 1.7}, hi[3] = {1.1, 2.4, 2.4};
    double error[3][2];
    size_t unknowns[3][2];
    for (int k = 0; k < 3; k++) {
        for (int m = 0; m < 2; m++) {
            rad_options o;
            rad_solution_view v;
            void *st = solve_state(scene, solvers[k], m == 0 ? 0.125 : 0.0625, 0, &o, &v);
            rad_galerkin_matrices g;
            rad_galerkin_get_matrices(st, &g);
            error[k][m] = floor_error(&v);
            unknowns[k][m] = g.unknowns;
            rad_strategy_galerkin.destroy(st);
        }
        double order = log2(error[k][0] / error[k][1]);
        print_message("%s: error %.3e (%zu unknowns) -> %.3e (%zu): order %.2f\n", solvers[k], error[k][0],
                      unknowns[k][0], error[k][1], unknowns[k][1], order);
        assert_true(order > lo[k] && order < hi[k]);
    }
    /* At about equal unknowns (constant at h = 1/16: 272, linear at 1/16:
     * 314), linear elements are far better (measured 28 times). */
    assert_true(error[1][1] < error[0][1] / 10.0);
    rad_scene_destroy(scene);
}

/* ---- the Cornell box: constant Galerkin = the dense strategy ---- */

static void test_cornell_constant_matches_dense(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    rad_options o = {0};
    o.target_elements = 150;
    o.solver = "gauss-seidel";
    o.tolerance = 1e-10;
    rad_solution *dense = NULL, *galerkin = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &dense), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, dense), RAD_OK);
    o.solver = "galerkin-constant";
    assert_int_equal(rad_solution_create(ctx, scene, &o, &galerkin), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, galerkin), RAD_OK);
    /* The same exact unoccluded factors (to the outer rule's 1e-5); they
     * differ in visibility: the analytic method integrates the exact
     * visible part of a source behind flat blockers (occluders.c), the
     * Galerkin kernel multiplies by keyed shadow-ray fractions.  Measured
     * 2.3e-2 (the back wall; each against tests/data/cornell_converged.json
     * at 150 elements: dense 2.4e-2, Galerkin 4.7e-2).  With the analytic
     * method's shadow rays they agreed to 4.1e-3. */
    double worst = 0.0;
    for (size_t s = 0; s < scene->surface_count; s++) {
        double a[3], b[3];
        rad_solution_surface_radiosity(dense, s, a);
        rad_solution_surface_radiosity(galerkin, s, b);
        for (int c = 0; c < 3; c++)
            worst = fmax(worst, fabs(a[c] - b[c]) / a[c]);
    }
    print_message("Cornell box, 150 elements: surface means within %.2e of the dense strategy's\n", worst);
    assert_true(worst < 3e-2);
    /* Both balance the same power: emitted equal, absorbed within 1e-2. */
    double e1, a1, e2, a2;
    rad_solution_power(dense, &e1, &a1);
    rad_solution_power(galerkin, &e2, &a2);
    assert_true(fabs(e1 - e2) < 1e-12 * e1);
    assert_true(fabs(a1 - a2) < 1e-2 * a1);
    rad_solution_destroy(dense);
    rad_solution_destroy(galerkin);
    rad_scene_destroy(scene);
}

/* ---- the same answer on any thread count ---- */

static void test_threads_identical(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    const char *solvers[2] = {"galerkin-linear", "collocation"};
    for (int k = 0; k < 2; k++) {
        double *values[2] = {NULL, NULL};
        size_t count = 0;
        for (int t = 0; t < 2; t++) {
            rad_context_options co = {0};
            co.threads = t == 0 ? 1 : 3;
            rad_context *c = NULL;
            assert_int_equal(rad_context_create(&co, &c), RAD_OK);
            rad_options o = {0};
            o.target_elements = 60;
            o.solver = solvers[k];
            rad_solution *s = NULL;
            assert_int_equal(rad_solution_create(c, scene, &o, &s), RAD_OK);
            assert_int_equal(rad_solution_solve(c, s), RAD_OK);
            count = 3 * rad_solution_vertex_count(s);
            values[t] = malloc(count * sizeof(double));
            assert_non_null(values[t]);
            assert_int_equal(rad_solution_vertex_radiosity(c, s, values[t]), RAD_OK);
            rad_solution_destroy(s);
            rad_context_destroy(c);
        }
        /* Colours of elements that share no vertex add to K's rows one
         * after another; collocation's rows are independent. */
        assert_memory_equal(values[0], values[1], count * sizeof(double));
        free(values[0]);
        free(values[1]);
    }
    rad_scene_destroy(scene);
}

/* ---- the vertex values, refusals ---- */

static void test_vertex_values_are_the_solution(void **state)
{
    (void)state;
    rad_scene *scene = make_floor();
    rad_options o = {0};
    o.mesh_size = 0.25;
    o.solver = "galerkin-linear";
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
    size_t nv = rad_solution_vertex_count(s);
    double *rgb = malloc(3 * nv * sizeof *rgb), *averaged = malloc(3 * nv * sizeof *averaged);
    assert_non_null(rgb);
    assert_non_null(averaged);
    assert_int_equal(rad_solution_vertex_radiosity(ctx, s, rgb), RAD_OK);
    assert_non_null(s->view.vertex_radiosity);
    assert_memory_equal(rgb, s->view.vertex_radiosity, 3 * nv * sizeof *rgb);
    /* ... which is not what averaging the element means gives. */
    assert_int_equal(rad_vertex_values(ctx, s->view.mesh, s->view.radiosity, averaged), RAD_OK);
    double differ = 0.0;
    for (size_t i = 0; i < 3 * nv; i++)
        differ = fmax(differ, fabs(rgb[i] - averaged[i]));
    assert_true(differ > 1e-3);
    /* A point query interpolates them with the basis: at the floor's
     * middle, a vertex, the vertex's own value. */
    double xyz[3] = {0.5, 0.0, 0.5}, at[3];
    assert_int_equal(rad_solution_point_radiosity(ctx, s, 0, xyz, at), RAD_OK);
    bool found = false;
    for (size_t i = 0; i < nv; i++) {
        double p[3];
        rad_solution_vertex_position(s, i, p);
        if (fabs(p[0] - 0.5) < 1e-12 && fabs(p[1]) < 1e-12 && fabs(p[2] - 0.5) < 1e-12) {
            assert_true(fabs(at[0] - rgb[3 * i]) < 1e-12);
            found = true;
        }
    }
    assert_true(found);
    /* A solution file keeps element values only: refused, nothing written. */
    char path[] = "/tmp/test_galerkin_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    unlink(path);
    assert_int_equal(rad_solution_save(ctx, s, path), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "vertex values"));
    assert_int_equal(access(path, F_OK), -1);
    free(rgb);
    free(averaged);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
}

static void test_refusals(void **state)
{
    (void)state;
    /* Two materials of different reflectance in one surface, sharing an
     * edge: their vertices would carry two reflectances. */
    rad_scene_builder *b = rad_scene_builder_create(ctx, "mixed");
    double r1[3] = {0.5, 0.5, 0.5}, r2[3] = {0.8, 0.8, 0.8}, E[3] = {1, 1, 1};
    int m1 = rad_scene_builder_material(b, "a", r1, E), m2 = rad_scene_builder_material(b, "b", r2, E);
    int s = rad_scene_builder_surface(b, "floor");
    const vec3 q1[4] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}, q2[4] = {{1, 0, 0}, {1, 0, 1}, {2, 0, 1}, {2, 0, 0}};
    assert_int_equal(rad_scene_builder_polygon(b, s, m1, q1, 4, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_polygon(b, s, m2, q2, 4, 0), RAD_OK);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    rad_options o = {0};
    o.mesh_size = 0.5;
    o.solver = "galerkin-linear";
    rad_solution *sol = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &sol), RAD_ERROR_INVALID_ARGUMENT);
    assert_null(sol);
    assert_non_null(strstr(rad_context_error(ctx), "different reflectance"));
    /* The constant basis has no shared nodes: accepted. */
    o.solver = "galerkin-constant";
    assert_int_equal(rad_solution_create(ctx, scene, &o, &sol), RAD_OK);
    rad_solution_destroy(sol);
    /* The closure correction rescales form factors, which it has none of. */
    o.solver = "galerkin-linear";
    o.closure_correction = 1;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &sol), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "closure_correction"));
    rad_scene_destroy(scene);
}

/* A cancel flag raised while the kernel is assembled (from the progress
 * callback) stops it, of either kind. */
static void cancel_in_kernel(void *user, const char *phase, uint64_t done, uint64_t total)
{
    (void)done, (void)total;
    if (strstr(phase, "kernel"))
        rad_context_cancel(*(rad_context **)user, true);
}

static void test_cancel(void **state)
{
    (void)state;
    rad_scene *scene = make_cube(0.5, 1.0);
    const char *solvers[2] = {"galerkin-linear", "collocation"};
    for (int k = 0; k < 2; k++) {
        rad_context *c = NULL;
        rad_context_options co = {0};
        co.threads = 2;
        co.progress = cancel_in_kernel;
        co.progress_user = &c;
        assert_int_equal(rad_context_create(&co, &c), RAD_OK);
        rad_options o = {0};
        o.mesh_size = 0.125;
        o.solver = solvers[k];
        rad_solution *s = NULL;
        assert_int_equal(rad_solution_create(c, scene, &o, &s), RAD_ERROR_INTERRUPTED);
        assert_null(s);
        assert_non_null(strstr(rad_context_error(c), "kernel: interrupted"));
        rad_context_destroy(c);
    }
    rad_scene_destroy(scene);
}

static int setup(void **state)
{
    (void)state;
    rad_context_options o = {0};
    o.threads = 2;
    return rad_context_create(&o, &ctx) == RAD_OK ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    rad_context_destroy(ctx);
    return 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_cube_uniform),
        cmocka_unit_test(test_closed_tetrahedron_uniform),
        cmocka_unit_test(test_mass_partition_of_unity),
        cmocka_unit_test(test_constant_kernel_is_AF),
        cmocka_unit_test(test_convergence_orders),
        cmocka_unit_test(test_cornell_constant_matches_dense),
        cmocka_unit_test(test_threads_identical),
        cmocka_unit_test(test_vertex_values_are_the_solution),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_cancel),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
