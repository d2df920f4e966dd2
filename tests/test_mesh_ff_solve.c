/*
 * test_mesh_ff_solve.c -- unit tests of the numerical core: meshing
 * (element counts, area conservation, point location, welding,
 * T-vertices), the point-to-polygon kernel against exact values, the
 * analytic element method (reciprocity, closure, culling), the
 * form-factor loop every method runs in (thread count, reciprocity,
 * cancellation) and the solvers on systems with known solutions.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>

#include "formfactor/formfactor.h"
#include "solve/solve.h"

static rad_context *ctx;

/* A closed unit cube, normals inward, one material (rho, E on face z1). */
static rad_scene *make_cube(double rho, double E_top, double E_all)
{
    rad_scene_builder *b = rad_scene_builder_create(ctx, "cube");
    double r[3] = {rho, rho, rho}, e0[3] = {E_all, E_all, E_all}, e1[3] = {E_top, E_top, E_top};
    int m0 = rad_scene_builder_material(b, "wall", r, e0);
    int m1 = rad_scene_builder_material(b, "top", r, e1);
    const vec3 faces[6][4] = {
        {{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}, {{1, 0, 0}, {1, 0, 1}, {1, 1, 1}, {1, 1, 0}},
        {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}, {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}},
        {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}},
    };
    const char *names[6] = {"x0", "x1", "y0", "y1", "z0", "z1"};
    for (int f = 0; f < 6; f++) {
        int s = rad_scene_builder_surface(b, names[f]);
        assert_int_equal(rad_scene_builder_polygon(b, s, f == 5 ? m1 : m0, faces[f], 4, 0), RAD_OK);
    }
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    return scene;
}

/* ---- mesh ---- */

static void test_mesh_counts_and_area(void **state)
{
    (void)state;
    rad_scene *scene = make_cube(0.5, 1.0, 0.0);
    rad_mesh_options o = {0.25, 0, 0};
    rad_mesh *mesh = NULL;
    assert_int_equal(rad_mesh_build(ctx, scene, &o, &mesh), RAD_OK);
    assert_int_equal(mesh->element_count, 6 * 16);
    double area = 0.0;
    for (size_t i = 0; i < mesh->element_count; i++) {
        area += mesh->elements[i].area;
        assert_true(fabs(mesh->elements[i].area - 1.0 / 16) < 1e-12);
    }
    assert_true(fabs(area - 6.0) < 1e-12);
    /* 6 faces of 5x5 grid points, welded only within a face (90-degree
     * corners exceed the crease angle): 150 vertices, no T-vertices. */
    assert_int_equal(mesh->vertex_count, 150);
    assert_int_equal(mesh->tvertex_count, 0);
    rad_mesh_destroy(mesh);

    /* A target count is met closely. */
    o.mesh_size = 0.0;
    o.target_elements = 600;
    assert_int_equal(rad_mesh_build(ctx, scene, &o, &mesh), RAD_OK);
    assert_true(mesh->element_count >= 480 && mesh->element_count <= 720);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

static void test_mesh_locate_round_trip(void **state)
{
    (void)state;
    rad_scene_builder *b = rad_scene_builder_create(ctx, "shapes");
    double r[3] = {0.5, 0.5, 0.5}, e[3] = {0, 0, 0};
    int m = rad_scene_builder_material(b, "m", r, e);
    int s = rad_scene_builder_surface(b, "s");
    const vec3 trapezoid[4] = {{0, 0, 0}, {2, 0, 0}, {1.5, 1, 0.2}, {0.3, 1, 0.2}};
    const vec3 tri[3] = {{0, 0, 3}, {1, 0, 3}, {0.2, 1.3, 3}};
    assert_int_equal(rad_scene_builder_polygon(b, s, m, trapezoid, 4, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_polygon(b, s, m, tri, 3, 0), RAD_OK);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    rad_mesh_options o = {0.2, 0, 0};
    rad_mesh *mesh = NULL;
    assert_int_equal(rad_mesh_build(ctx, scene, &o, &mesh), RAD_OK);
    rad_rng rng = rad_rng_keyed(1, 2, 3);
    for (size_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        double patch_area = 0.0;
        for (uint32_t k = 0; k < patch->element_count; k++)
            patch_area += mesh->elements[patch->first_element + k].area;
        for (int k = 0; k < 2000; k++) {
            double s0 = rad_rng_uniform(&rng), t0 = rad_rng_uniform(&rng);
            if (patch->corner_count == 3 && s0 + t0 > 1.0) {
                s0 = 1.0 - s0;
                t0 = 1.0 - t0;
            }
            vec3 q = rad_patch_point(patch, s0, t0);
            double s1, t1, ls, lt;
            rad_patch_parameters(patch, q, &s1, &t1);
            assert_true(fabs(s1 - s0) < 1e-9 && fabs(t1 - t0) < 1e-9);
            uint32_t el = rad_patch_locate(patch, s1, t1, &ls, &lt);
            assert_true(el >= patch->first_element && el < patch->first_element + patch->element_count);
            /* The element's own parametrisation gives back the point. */
            const rad_element *e2 = &mesh->elements[el];
            vec3 back;
            if (e2->vertex_count == 3) {
                vec3 a = mesh->vertices[e2->vertex[0]];
                back = v3_add(a, v3_add(v3_scale(v3_sub(mesh->vertices[e2->vertex[1]], a), ls),
                                        v3_scale(v3_sub(mesh->vertices[e2->vertex[2]], a), lt)));
            } else {
                back = rad_element_sample(mesh, e2, ls, lt);
            }
            assert_true(v3_length(v3_sub(back, q)) < 1e-9);
        }
        (void)patch_area;
    }
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* Two coplanar rectangles of one surface with different grids: the shared
 * edge gets T-vertices, and vertices at common points are welded. */
static void test_mesh_welding_and_tvertices(void **state)
{
    (void)state;
    rad_scene_builder *b = rad_scene_builder_create(ctx, "floor");
    double r[3] = {0.5, 0.5, 0.5}, e[3] = {0, 0, 0};
    int m = rad_scene_builder_material(b, "m", r, e);
    int s = rad_scene_builder_surface(b, "floor");
    const vec3 left[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const vec3 right[4] = {{1, 0, 0}, {1.3, 0, 0}, {1.3, 1, 0}, {1, 1, 0}};
    assert_int_equal(rad_scene_builder_polygon(b, s, m, left, 4, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_polygon(b, s, m, right, 4, 0), RAD_OK);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    rad_mesh_options o = {0.3, 0, 0};
    rad_mesh *mesh = NULL;
    assert_int_equal(rad_mesh_build(ctx, scene, &o, &mesh), RAD_OK);
    /* left: 4x4 cells at 0.25; right: 1x4 cells -> its x=1 edge points
     * coincide with the left's at y = 0, .25, .5, .75, 1: all welded. */
    assert_int_equal(mesh->element_count, 16 + 4);
    assert_int_equal(mesh->vertex_count, 25 + 5);
    assert_int_equal(mesh->tvertex_count, 0);
    rad_mesh_destroy(mesh);
    /* Now 0.2: left 5x5 at y steps 0.2, right 2x5 -> same y: still conforming.
     * Use 0.45: left 3x3 (y = 1/3, 2/3), right 1x3: conforming again; so make
     * the right taller than it is wide to force a different y-count. */
    rad_scene_destroy(scene);

    b = rad_scene_builder_create(ctx, "floor2");
    m = rad_scene_builder_material(b, "m", r, e);
    s = rad_scene_builder_surface(b, "floor");
    const vec3 big[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const vec3 small[4] = {{1, 0, 0}, {1.5, 0, 0}, {1.5, 0.5, 0}, {1, 0.5, 0}};
    assert_int_equal(rad_scene_builder_polygon(b, s, m, big, 4, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_polygon(b, s, m, small, 4, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    o.mesh_size = 0.4; /* big: 3x3 (y = 0, 1/3, ...), small: 2x2 (y = 0, 0.25, 0.5) */
    assert_int_equal(rad_mesh_build(ctx, scene, &o, &mesh), RAD_OK);
    assert_int_equal(mesh->element_count, 9 + 4);
    /* small's (1, 0.25) and (1, 0.5) lie inside big's edge (1,0)-(1,1/3) and
     * (1,1/3)-(1,2/3); big's (1, 1/3) lies inside small's edge (1,.25)-(1,.5),
     * but only a coarser element's edge constrains a vertex (weld.c: mutual
     * constraints along a line admit only a linear solution). */
    assert_int_equal(mesh->tvertex_count, 2);
    for (size_t k = 0; k < mesh->tvertex_count; k++) {
        const rad_tvertex *tv = &mesh->tvertices[k];
        vec3 p = v3_lerp(mesh->vertices[tv->a], mesh->vertices[tv->b], tv->t);
        assert_true(v3_length(v3_sub(p, mesh->vertices[tv->vertex])) < 1e-12);
    }
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);

    /* The same two grids, the small one turned up 90 degrees about the
     * shared edge (a box's faces are one surface): their vertices along
     * the edge are not T-vertices of each other, or one face's shading
     * would pass to the other across the corner. */
    b = rad_scene_builder_create(ctx, "corner");
    m = rad_scene_builder_material(b, "m", r, e);
    s = rad_scene_builder_surface(b, "box");
    const vec3 upright[4] = {{1, 0, 0}, {1, 0.5, 0}, {1, 0.5, 0.5}, {1, 0, 0.5}};
    assert_int_equal(rad_scene_builder_polygon(b, s, m, big, 4, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_polygon(b, s, m, upright, 4, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    assert_int_equal(rad_mesh_build(ctx, scene, &o, &mesh), RAD_OK);
    assert_int_equal(mesh->element_count, 9 + 4);
    assert_int_equal(mesh->tvertex_count, 0);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* ---- the point-to-polygon kernel: exact cases from cases.json ---- */

static cJSON *load_cases(void)
{
    FILE *f = fopen(RAD_TEST_DATA "/cases.json", "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = malloc((size_t)n + 1);
    assert_int_equal(fread(text, 1, (size_t)n, f), (size_t)n);
    text[n] = '\0';
    fclose(f);
    cJSON *j = cJSON_Parse(text);
    free(text);
    assert_non_null(j);
    return j;
}

static vec3 json_vec3(const cJSON *a)
{
    return v3(cJSON_GetArrayItem(a, 0)->valuedouble, cJSON_GetArrayItem(a, 1)->valuedouble,
              cJSON_GetArrayItem(a, 2)->valuedouble);
}

static void test_point_polygon_exact(void **state)
{
    (void)state;
    cJSON *cases = load_cases();
    int checked = 0;
    const cJSON *c;
    cJSON_ArrayForEach(c, cJSON_GetObjectItem(cases, "cases"))
    {
        if (strcmp(cJSON_GetObjectItem(c, "group")->valuestring, "point_form_factor") != 0)
            continue;
        const cJSON *g = cJSON_GetObjectItem(c, "geometry");
        const cJSON *dA = cJSON_GetObjectItem(g, "dA1");
        vec3 poly[8];
        size_t n = 0;
        const cJSON *v;
        cJSON_ArrayForEach(v, cJSON_GetObjectItem(cJSON_GetObjectItem(g, "A2"), "vertices"))
            poly[n++] = json_vec3(v);
        double f = rad_point_polygon_ff(json_vec3(cJSON_GetObjectItem(dA, "point")),
                                        json_vec3(cJSON_GetObjectItem(dA, "normal")), poly, n);
        double exact = cJSON_GetObjectItem(c, "exact")->valuedouble;
        if (!(fabs(f - exact) < 1e-10))
            fail_msg("%s: %.12f vs %.12f", cJSON_GetObjectItem(c, "id")->valuestring, f, exact);
        checked++;
    }
    assert_int_equal(checked, 2);
    cJSON_Delete(cases);
}

/* A polygon straddling the tangent plane: only the part in front counts.
 * A square [-1,1]^2 at z = 1 seen from the origin with normal +x: by
 * symmetry half of what a normal of (1,0,1)/sqrt2 ... instead compare with
 * the square clipped by hand to x >= 0. */
static void test_point_polygon_clipping(void **state)
{
    (void)state;
    const vec3 square[4] = {{-1, -1, 1}, {-1, 1, 1}, {1, 1, 1}, {1, -1, 1}};
    const vec3 half[4] = {{0, -1, 1}, {0, 1, 1}, {1, 1, 1}, {1, -1, 1}};
    vec3 n = v3_normalize(v3(1, 0, 0.0));
    double full = rad_point_polygon_ff(v3(0, 0, 0), n, square, 4);
    double clipped = rad_point_polygon_ff(v3(0, 0, 0), n, half, 4);
    assert_true(clipped > 0.01);
    assert_true(fabs(full - clipped) < 1e-14);
    /* Back side: the same square seen from above gives nothing. */
    assert_true(rad_point_polygon_ff(v3(0, 0, 2), v3(0, 0, -1), square, 4) == 0.0);
}

/* ---- the analytic method on the cube: reciprocity, closure, F_ii ---- */

static void test_analytic_cube(void **state)
{
    (void)state;
    rad_scene *scene = make_cube(0.5, 1.0, 0.0);
    rad_mesh_options o = {0.34, 0, 0}; /* 3x3 per face */
    rad_mesh *mesh = NULL;
    assert_int_equal(rad_mesh_build(ctx, scene, &o, &mesh), RAD_OK);
    rad_ff_request req = {.mesh = mesh, .seed = 7, .shadow_rays = 4}; /* no occluders in a cube */
    double *F = NULL;
    rad_ff_stats st;
    assert_int_equal(rad_form_factors(ctx, rad_ff_find("analytic"), &req, 1e9, false, &F, NULL, &st), RAD_OK);
    size_t n = mesh->element_count;
    assert_int_equal(n, 54);
    assert_true(st.row_sum_min > 1.0 - 1e-4 && st.row_sum_max < 1.0 + 1e-4);
    assert_true(st.reciprocity_max < 1e-6);
    assert_true(st.diagonal_max == 0.0);
    /* Coplanar elements see nothing of each other. */
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++)
            if (mesh->elements[i].surface == mesh->elements[j].surface)
                assert_true(F[i * n + j] == 0.0);
    rad_free(F);

    /* The memory limit is checked before allocating. */
    assert_int_equal(rad_form_factors(ctx, rad_ff_find("analytic"), &req, 100.0, false, &F, NULL, &st),
                     RAD_ERROR_OUT_OF_MEMORY);
    assert_null(F);
    assert_non_null(strstr(rad_context_error(ctx), "rad_options.max_memory_bytes"));
    assert_non_null(strstr(rad_context_error(ctx), "'shooting' (rad_options.solver"));
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* ---- every digit: the meshed cube against its closed form ---- */

/* Phi'' = ln sqrt(u^2 + d^2): the double antiderivative of the contour
 * integrand along two parallel lines d apart (Sparrow 1963; the constant
 * -d^2/4 cancels in the alternating sum and is left out). */
static double contour_phi(double u, double d)
{
    double s = u * u + d * d;
    if (s == 0.0)
        return 0.0;
    return 0.25 * (u * u - d * d) * log(s) - 0.75 * u * u + (d > 0.0 ? d * u * atan(u / d) : 0.0);
}

/* A_i F_ij of two axis-aligned rectangular elements in closed form: by
 * Stokes, A_i F_ij = 1/(2 pi) times the sum over pairs of parallel edges
 * (vertices counter-clockwise about the normals) of the double integral of
 * ln r dr_i . dr_j (Sparrow 1963; Cohen & Wallace 1993, sec. 4.9), each
 * -[Phi(p1-q1) - Phi(p0-q1) - Phi(p1-q0) + Phi(p0-q0)] for edges p0->p1
 * and q0->q1 along the same axis, d apart. */
static double rectangle_coupling(const rad_mesh *mesh, size_t i, size_t j)
{
    const rad_element *a = &mesh->elements[i], *b = &mesh->elements[j];
    if (fabs(v3_dot(a->normal, b->normal) - 1.0) < 1e-12)
        return 0.0; /* coplanar (or parallel facing away: not in a cube) */
    double sum = 0.0;
    for (uint32_t p = 0; p < a->vertex_count; p++) {
        vec3 p0 = mesh->vertices[a->vertex[p]], p1 = mesh->vertices[a->vertex[(p + 1) % a->vertex_count]];
        double pe[3][2] = {{p0.x, p1.x}, {p0.y, p1.y}, {p0.z, p1.z}};
        for (uint32_t q = 0; q < b->vertex_count; q++) {
            vec3 q0 = mesh->vertices[b->vertex[q]], q1 = mesh->vertices[b->vertex[(q + 1) % b->vertex_count]];
            double qe[3][2] = {{q0.x, q1.x}, {q0.y, q1.y}, {q0.z, q1.z}};
            for (int axis = 0; axis < 3; axis++) {
                int o1 = (axis + 1) % 3, o2 = (axis + 2) % 3;
                if (pe[axis][0] == pe[axis][1] || qe[axis][0] == qe[axis][1])
                    continue; /* not both along this axis */
                double d = hypot(pe[o1][0] - qe[o1][0], pe[o2][0] - qe[o2][0]);
                double x0 = pe[axis][0], x1 = pe[axis][1], y0 = qe[axis][0], y1 = qe[axis][1];
                sum -= contour_phi(x1 - y1, d) - contour_phi(x0 - y1, d) - contour_phi(x1 - y0, d) +
                       contour_phi(x0 - y0, d);
            }
        }
    }
    return sum / (2.0 * M_PI);
}

/* B of the cube's system with factors F, by LU (solve_direct.c). */
static void cube_solution(const rad_scene *scene, const rad_mesh *mesh, const double *F, double *B)
{
    size_t n = mesh->element_count;
    double *area = malloc(n * sizeof *area), *rho = malloc(3 * n * sizeof *rho), *E = malloc(3 * n * sizeof *E);
    for (size_t i = 0; i < n; i++) {
        const rad_material *m = &scene->materials[mesh->elements[i].material];
        area[i] = mesh->elements[i].area;
        for (int c = 0; c < 3; c++) {
            rho[3 * i + c] = m->reflectance[c];
            E[3 * i + c] = B[3 * i + c] = m->emission[c];
        }
    }
    rad_system sys = {.n = n, .F = F, .area = area, .reflectance = rho, .emission = E, .threads = 2};
    rad_solve_params p = {.tolerance = 1e-14};
    rad_solve_stats st;
    memset(&st, 0, sizeof st);
    assert_int_equal(rad_solver_find("direct")->solve(ctx, &sys, &p, B, &st), RAD_OK);
    free(area);
    free(rho);
    free(E);
}

/* The closed unit cube at 1, 2x2 and 3x3 elements a face, lit from its
 * top: F by the contour method gives rows that sum to 1 within 1e-9 and,
 * solved by LU, the radiosity of F in closed form (the rectangle formulas)
 * within 1e-9 (measured: 1e-14); the analytic method (point-to-polygon
 * factor integrated by Gauss) within 1e-6 (measured: 1.2e-7; 2.8e-6 with
 * its former 3x3 rule near the source).  F stored as float fails both
 * contour bounds (at one element a face: rows 3.0e-8 off, B 5.8e-8). */
static void test_cube_every_digit(void **state)
{
    (void)state;
    rad_scene *scene = make_cube(0.5, 1.0, 0.0);
    const double sizes[3] = {1.0, 0.5, 1.0 / 3.0};
    const struct {
        const char *method;
        double tolerance;
    } methods[2] = {{"contour", 1e-9}, {"analytic", 1e-6}};
    for (int s = 0; s < 3; s++) {
        rad_mesh_options o = {sizes[s] * (1.0 + 1e-9), 0, 0};
        rad_mesh *mesh = NULL;
        assert_int_equal(rad_mesh_build(ctx, scene, &o, &mesh), RAD_OK);
        size_t n = mesh->element_count;
        assert_int_equal(n, 6 * (size_t)((s + 1) * (s + 1)));
        double *exact = calloc(n * n, sizeof *exact), *B_exact = malloc(3 * n * sizeof *B_exact),
               *B = malloc(3 * n * sizeof *B);
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < n; j++)
                exact[i * n + j] = rectangle_coupling(mesh, i, j) / mesh->elements[i].area;
        double worst_row = 0.0;
        for (size_t i = 0; i < n; i++) {
            double row = 0.0;
            for (size_t j = 0; j < n; j++)
                row += exact[i * n + j];
            worst_row = fmax(worst_row, fabs(row - 1.0));
        }
        assert_true(worst_row < 1e-13); /* the closed form itself closes the cube */
        cube_solution(scene, mesh, exact, B_exact);
        for (int k = 0; k < 2; k++) {
            rad_ff_request req = {.mesh = mesh, .seed = 7};
            double *F = NULL;
            rad_ff_stats st;
            assert_int_equal(rad_form_factors(ctx, rad_ff_find(methods[k].method), &req, 1e9, false, &F, NULL, &st),
                             RAD_OK);
            double tol = methods[k].tolerance, worst_B = 0.0;
            if (!(fabs(st.row_sum_min - 1.0) < tol && fabs(st.row_sum_max - 1.0) < tol))
                fail_msg("%s, %zu elements: rows sum to 1 %+.2e .. %+.2e", methods[k].method, n,
                         st.row_sum_min - 1.0, st.row_sum_max - 1.0);
            cube_solution(scene, mesh, F, B);
            for (size_t i = 0; i < 3 * n; i++)
                worst_B = fmax(worst_B, fabs(B[i] - B_exact[i]) / B_exact[i]);
            if (!(worst_B < tol))
                fail_msg("%s, %zu elements: B %.2e off the closed form's", methods[k].method, n, worst_B);
            rad_free(F);
        }
        free(exact);
        free(B_exact);
        free(B);
        rad_mesh_destroy(mesh);
    }
    rad_scene_destroy(scene);
}

/* ---- the form-factor loop (formfactor.c): threads, reciprocity, cancellation ---- */

static rad_result form_factors_with(int threads, bool cancel, const rad_ff_method *method,
                                    const rad_ff_request *req, double **F, double **variance,
                                    rad_ff_stats *st)
{
    rad_context_options o = {0};
    o.threads = threads;
    rad_context *c = NULL;
    assert_int_equal(rad_context_create(&o, &c), RAD_OK);
    rad_context_cancel(c, cancel);
    rad_result r = rad_form_factors(c, method, req, 1e9, false, F, variance, st);
    rad_context_destroy(c);
    return r;
}

/* Every method on the Cornell box (occluding blocks, elements of many
 * sizes): F, its variances and the counts are the same with 1 thread and
 * with 3 (the dynamic schedule hands rows out differently); the pair
 * methods' factors are reciprocal, A_i F_ij = A_j F_ji, to float rounding;
 * a raised cancel flag interrupts every method. */
static void test_ff_loop(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    rad_mesh_options mo = {0, 150, 0};
    rad_mesh *mesh = NULL;
    assert_int_equal(rad_mesh_build(ctx, scene, &mo, &mesh), RAD_OK);
    rad_vis *vis = NULL;
    assert_int_equal(rad_vis_create(ctx, "embree", mesh, &vis), RAD_OK);
    rad_ff_request req = {.mesh = mesh, .vis = vis, .seed = 11, .hemicube_resolution = 64, .samples = 16};
    size_t n = mesh->element_count;
    for (size_t k = 0; rad_ff_methods[k]; k++) {
        const rad_ff_method *m = rad_ff_methods[k];
        double *F1 = NULL, *F3 = NULL, *V1 = NULL, *V3 = NULL;
        rad_ff_stats s1, s3;
        assert_int_equal(form_factors_with(1, false, m, &req, &F1, &V1, &s1), RAD_OK);
        assert_int_equal(form_factors_with(3, false, m, &req, &F3, &V3, &s3), RAD_OK);
        assert_memory_equal(F1, F3, n * n * sizeof *F1);
        if (m->flags & RAD_FF_VARIANCE)
            assert_memory_equal(V1, V3, n * n * sizeof *V1);
        assert_true(s1.rays == s3.rays && s1.pairs == s3.pairs && s1.near_pairs == s3.near_pairs);
        assert_true(s1.pairs > 0);
        if (m->pair) {
            size_t coupled = 0;
            for (size_t i = 0; i < n; i++) {
                assert_true(F1[i * n + i] == 0.0);
                for (size_t j = i + 1; j < n; j++) {
                    double gij = mesh->elements[i].area * F1[i * n + j];
                    double gji = mesh->elements[j].area * F1[j * n + i];
                    assert_true(fabs(gij - gji) <= 1e-6 * fmax(gij, gji));
                    coupled += gij > 0.0 && mesh->elements[i].area != mesh->elements[j].area;
                }
            }
            assert_true(coupled > n); /* the check above saw unequal areas */
        }
        rad_free(F1);
        rad_free(F3);
        rad_free(V1);
        rad_free(V3);

        double *F = NULL;
        assert_int_equal(form_factors_with(2, true, m, &req, &F, NULL, &s1), RAD_ERROR_INTERRUPTED);
        assert_true(s1.pairs < s3.pairs);
        rad_free(F);
    }
    rad_vis_destroy(vis);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* ---- solvers on small systems with known answers ---- */

/* Two facing elements: B1 = E1 + r F B2, B2 = r F B1  =>  closed form. */
static void test_solvers_two_patch(void **state)
{
    (void)state;
    const double F[4] = {0.0, 0.25, 0.25, 0.0};
    const double area[2] = {1.0, 1.0};
    const double rho[6] = {0.8, 0.5, 0.2, 0.8, 0.5, 0.2};
    const double E[6] = {1.0, 2.0, 3.0, 0.0, 0.0, 0.0};
    rad_system sys = {.n = 2, .F = F, .area = area, .reflectance = rho, .emission = E, .threads = 2};
    for (size_t k = 0; rad_solvers[k]; k++) { /* every one works on F (shooting: through the CLI) */
        double B[6];
        memcpy(B, E, sizeof B);
        rad_solve_params p = {.tolerance = 1e-12};
        rad_solve_stats st;
        memset(&st, 0, sizeof st);
        assert_int_equal(rad_solvers[k]->solve(ctx, &sys, &p, B, &st), RAD_OK);
        for (int c = 0; c < 3; c++) {
            double r = rho[c], f = 0.25, e = E[c];
            double b1 = e / (1.0 - r * r * f * f), b2 = r * f * b1;
            assert_true(fabs(B[c] - b1) < 1e-10 * b1);
            assert_true(fabs(B[3 + c] - b2) < 1e-10 * b1);
        }
        assert_true(st.converged);
        assert_true(st.residual < 1e-12);
        double residual;
        assert_int_equal(rad_residual(ctx, &sys, B, &residual), RAD_OK);
        assert_true(residual < 1e-12);
    }
}

/* The residual measures what it claims: for B = E it is the reflected
 * first bounce over the emitted power. */
static void test_residual_definition(void **state)
{
    (void)state;
    const double F[4] = {0.0, 0.5, 0.5, 0.0};
    const double area[2] = {2.0, 2.0};
    const double rho[6] = {0.5, 0.5, 0.5, 0.5, 0.5, 0.5};
    const double E[6] = {1, 1, 1, 0, 0, 0};
    rad_system sys = {.n = 2, .F = F, .area = area, .reflectance = rho, .emission = E, .threads = 2};
    /* r_2 = -rho F B_1 = -0.25 per channel; sum A|r| = 2*0.25*3; emitted = 2*3. */
    double residual;
    assert_int_equal(rad_residual(ctx, &sys, E, &residual), RAD_OK);
    assert_true(fabs(residual - 0.25) < 1e-15);
}

/* ---- how long a solver may run (solve.h) ---- */

static void test_bound_arithmetic(void **state)
{
    (void)state;
    /* q = 0.5: 0.5^20 < 1e-6 <= 0.5^19, so k = 20 and 2 k + 10 = 50 sweeps. */
    rad_solve_bound b = rad_solve_bound_make(0, 0.5, 1.0, 1e-6, 1.0);
    assert_true(b.bounces == 20.0 && b.limit == 50.0 && b.reason == RAD_BOUND_PHYSICS);
    /* A shot is 1/24 of a bounce in a system of 24 elements. */
    assert_true(rad_solve_bound_make(0, 0.5, 1.0, 1e-6, 24.0).limit == 50.0 * 24.0);
    /* rho = 0.999999 needs 1.4e7 bounces: the cap. */
    b = rad_solve_bound_make(0, 0.999999, 1.0, 1e-6, 1.0);
    assert_true(b.bounces > 1.38e7 && b.bounces < 1.39e7);
    assert_true(b.limit == RAD_SOLVE_BOUNCE_CAP && b.reason == RAD_BOUND_CAP);
    /* Row sums above 1 / rho bound nothing: the cap. */
    b = rad_solve_bound_make(0, 1.00001, 1.0, 1e-6, 1.0);
    assert_true(isinf(b.bounces) && b.limit == RAD_SOLVE_BOUNCE_CAP && b.reason == RAD_BOUND_CAP);
    /* The user's cap: kept below the physics, lowered to it above, and
     * allowed past the automatic cap (the user asked for the time). */
    b = rad_solve_bound_make(7, 0.5, 1.0, 1e-6, 1.0);
    assert_true(b.limit == 7.0 && b.reason == RAD_BOUND_USER);
    b = rad_solve_bound_make(1000, 0.5, 1.0, 1e-6, 1.0);
    assert_true(b.limit == 50.0 && b.reason == RAD_BOUND_PHYSICS);
    b = rad_solve_bound_make(20000, 0.999, 1.0, 1e-6, 1.0);
    assert_true(b.limit == 20000.0 && b.reason == RAD_BOUND_USER);
    /* Relaxation: weighted Jacobi contracts by |1 - w| + w q. */
    b = rad_solve_bound_make(0, 0.5, 0.5, 1e-6, 1.0); /* 0.75 per sweep: k = 49 */
    assert_true(b.bounces == 49.0 && b.limit == 108.0);
    b = rad_solve_bound_make(0, 0.9, 1.5, 1e-6, 1.0); /* 1.85: no bound */
    assert_true(b.reason == RAD_BOUND_CAP);
    /* Nothing reflected: one bounce. */
    assert_true(rad_solve_bound_make(0, 0.0, 1.0, 1e-6, 1.0).bounces == 1.0);
}

/* Two facing planes that see only each other (F = [0 1; 1 0], rows exactly
 * 1): both emit E = 1 and reflect rho, so B = E / (1 - rho). */
static rad_system plates(double rho, double *reflectance, double *emission)
{
    static const double F[4] = {0.0, 1.0, 1.0, 0.0};
    static const double area[2] = {1.0, 1.0};
    for (int k = 0; k < 6; k++) {
        reflectance[k] = rho;
        emission[k] = 1.0;
    }
    return (rad_system){.n = 2, .F = F, .area = area, .reflectance = reflectance, .emission = emission, .threads = 2};
}

static bool is_solver(size_t k, const char *name) { return strcmp(rad_solvers[k]->name, name) == 0; }

/* Every solver on rho = 0.99 converges to B = 100; on rho = 0.999999 the
 * gathering and Southwell solvers stop at the cap, unconverged, saying so,
 * and report the true residual of what they stopped at (Gauss-Seidel used
 * to report the estimate its sweeps make: 1.99 where the residual was
 * 0.95); conjugate gradients and LU reach B = 10^6.  A user's cap stops a
 * solve where it says, with the same honesty. */
static void test_solvers_stop(void **state)
{
    (void)state;
    double rho[6], E[6];
    for (size_t k = 0; rad_solvers[k]; k++) {
        const char *name = rad_solvers[k]->name;
        /* 0.99: converged, 100 to what the tolerance leaves. */
        rad_system sys = plates(0.99, rho, E);
        double B[6];
        memcpy(B, E, sizeof B);
        rad_solve_params p = {.tolerance = 1e-6};
        rad_solve_stats st;
        memset(&st, 0, sizeof st);
        assert_int_equal(rad_solvers[k]->solve(ctx, &sys, &p, B, &st), RAD_OK);
        assert_true(st.converged && st.warning[0] == '\0');
        for (int c = 0; c < 6; c++)
            if (!(fabs(B[c] - 100.0) < 1e-4 * 100.0))
                fail_msg("%s: rho 0.99: B = %.9g, not 100", name, B[c]);
        assert_true(st.iterations <= st.iteration_limit);

        /* 0.999999 */
        sys = plates(0.999999, rho, E);
        memcpy(B, E, sizeof B);
        memset(&st, 0, sizeof st);
        assert_int_equal(rad_solvers[k]->solve(ctx, &sys, &p, B, &st), RAD_OK);
        double residual;
        assert_int_equal(rad_residual(ctx, &sys, B, &residual), RAD_OK);
        if (is_solver(k, "direct") || is_solver(k, "conjugate-gradient")) {
            assert_true(st.converged);
            for (int c = 0; c < 6; c++)
                if (!(fabs(B[c] - 1e6) < 1e-6 * 1e6))
                    fail_msg("%s: rho 0.999999: B = %.9g, not 10^6", name, B[c]);
        } else {
            double per_bounce = is_solver(k, "southwell") ? 2.0 : 1.0;
            assert_false(st.converged);
            assert_true(st.iteration_limit == RAD_SOLVE_BOUNCE_CAP * per_bounce);
            assert_true(st.iterations == st.iteration_limit);
            if (!strstr(st.warning, "did not converge") || !strstr(st.warning, "(the cap; reflectance x row sum 0.999999") ||
                !strstr(st.warning, name) || !strstr(st.warning, "conjugate-gradient or direct"))
                fail_msg("%s: warning '%s'", name, st.warning);
            /* What it reports is the residual of what it stopped at. */
            if (!(st.residual == residual))
                fail_msg("%s: reports residual %.17g, its B has %.17g", name, st.residual, residual);
            /* B rose from E but is far from 10^6: 10^4 bounces of 10^6. */
            for (int c = 0; c < 6; c++)
                assert_true(B[c] > 1e3 && B[c] < 2e4);
        }

        /* A user's cap of 3 iterations (shots for Southwell). */
        sys = plates(0.99, rho, E);
        memcpy(B, E, sizeof B);
        memset(&st, 0, sizeof st);
        p.max_iterations = 3;
        assert_int_equal(rad_solvers[k]->solve(ctx, &sys, &p, B, &st), RAD_OK);
        p.max_iterations = 0;
        assert_int_equal(rad_residual(ctx, &sys, B, &residual), RAD_OK);
        if (is_solver(k, "direct") || is_solver(k, "conjugate-gradient"))
            continue; /* exact, or exact at once on this system */
        assert_true(st.iterations == 3 && st.iteration_limit == 3.0 && !st.converged);
        assert_non_null(strstr(st.warning, "(rad_options.max_iterations)"));
        if (!(st.residual == residual))
            fail_msg("%s: capped at 3: reports residual %.17g, its B has %.17g", name, st.residual, residual);
    }
}

/* A raised cancel flag interrupts every solver, direct (between the
 * panels of its factorisation) included, and leaves a finite iterate. */
static void test_solvers_cancel(void **state)
{
    (void)state;
    rad_context_options o = {0};
    o.threads = 2;
    rad_context *c = NULL;
    assert_int_equal(rad_context_create(&o, &c), RAD_OK);
    rad_context_cancel(c, true);
    double rho[6], E[6];
    for (size_t k = 0; rad_solvers[k]; k++) {
        rad_system sys = plates(0.999999, rho, E);
        double B[6];
        memcpy(B, E, sizeof B);
        rad_solve_params p = {.tolerance = 1e-6};
        rad_solve_stats st;
        memset(&st, 0, sizeof st);
        rad_api_enter(c);
        if (rad_solvers[k]->solve(c, &sys, &p, B, &st) != RAD_ERROR_INTERRUPTED)
            fail_msg("%s: not interrupted by the cancel flag", rad_solvers[k]->name);
        assert_false(st.converged);
        assert_true(st.warning[0] == '\0');
        for (int i = 0; i < 6; i++)
            assert_true(isfinite(B[i]) && B[i] >= 1.0);
    }
    rad_context_destroy(c);
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
        cmocka_unit_test(test_mesh_counts_and_area),
        cmocka_unit_test(test_mesh_locate_round_trip),
        cmocka_unit_test(test_mesh_welding_and_tvertices),
        cmocka_unit_test(test_point_polygon_exact),
        cmocka_unit_test(test_point_polygon_clipping),
        cmocka_unit_test(test_analytic_cube),
        cmocka_unit_test(test_cube_every_digit),
        cmocka_unit_test(test_ff_loop),
        cmocka_unit_test(test_solvers_two_patch),
        cmocka_unit_test(test_residual_definition),
        cmocka_unit_test(test_bound_arithmetic),
        cmocka_unit_test(test_solvers_stop),
        cmocka_unit_test(test_solvers_cancel),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
