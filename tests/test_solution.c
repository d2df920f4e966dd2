/*
 * test_solution.c -- solutions through include/radiosity.h only:
 *
 *   strategies    every solver name resolves; one solver of each strategy
 *                 (dense, matrix-free, hierarchical) on the closed furnace
 *                 box gives B = E / (1 - rho) and conserves power
 *   accessors     per-element and per-vertex values add up to the
 *                 per-surface answers (areas to the surface areas, area-
 *                 weighted B to the surface means); the hierarchical
 *                 solution's elements are its leaves after solving
 *   errors        the first failure of a call is the one kept and the one
 *                 the error callback hears, once; a later call's failure
 *                 replaces it
 *   cancellation  an atomic flag: a cancelled context interrupts, with
 *                 nothing returned, and runs again once cleared
 *   early end     on_step's RAD_STEP_FINISH keeps the iterate as a
 *                 solution that saves; display values with and without
 *                 the ambient term
 *   hier steps    the hierarchical solver's on_step shows its current
 *                 leaves (counts never fall, areas tile the scene), the
 *                 last step is the solution, RAD_STEP_FINISH keeps a step
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "radiosity.h"

#include <cjson/cJSON.h>

static rad_context *ctx;

typedef struct error_log {
    int calls;
    rad_result last;
    char message[512];
} error_log;

static void on_error(void *user, rad_result result, const char *message)
{
    error_log *log = user;
    log->calls++;
    log->last = result;
    snprintf(log->message, sizeof log->message, "%s", message);
}

static error_log errors;

static int setup(void **state)
{
    (void)state;
    rad_context_options co = {0};
    co.threads = 2;
    co.on_error = on_error;
    co.error_user = &errors;
    return rad_context_create(&co, &ctx) == RAD_OK ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    rad_context_destroy(ctx);
    return 0;
}

/* A closed unit cube, normals inward, rho 0.5 and E 1 on every face, as
 * OBJ: the furnace, B = E / (1 - rho) = 2 everywhere. */
static rad_scene *furnace(void)
{
    static const char obj[] = "mtllib f.mtl\nusemtl m\n"
                              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                              "o bottom\nf 1 2 3 4\no top\nf 5 8 7 6\no front\nf 1 5 6 2\n"
                              "o back\nf 4 3 7 8\no left\nf 1 4 8 5\no right\nf 2 6 7 3\n";
    static const char mtl[] = "newmtl m\nKd 0.5 0.5 0.5\nKe 0.318309886 0.318309886 0.318309886\n";
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "furnace.obj", obj, strlen(obj), mtl, strlen(mtl), &scene),
                     RAD_OK);
    return scene;
}

static rad_solution *solved(const rad_scene *scene, const char *solver)
{
    rad_options o = {0};
    o.solver = solver;
    o.target_elements = 600;
    o.epsilon = 1e-5;
    o.tolerance = 1e-7;
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
    return s;
}

static void test_every_solver_name_resolves(void **state)
{
    (void)state;
    const char *name, *description;
    size_t count = 0;
    for (size_t i = 0; rad_method_info(RAD_METHOD_SOLVER, i, &name, &description); i++, count++) {
        assert_true(strlen(description) > 10);
        rad_options o = {0};
        o.solver = name;
        o.max_memory_bytes = 1.0; /* fails after the name is resolved, before any work */
        rad_solution *s = (rad_solution *)&o;
        rad_scene *scene = furnace();
        rad_result r = rad_solution_create(ctx, scene, &o, &s);
        assert_int_equal(r, RAD_ERROR_OUT_OF_MEMORY);
        assert_null(s);
        assert_null(strstr(rad_context_error(ctx), "unknown solver"));
        rad_scene_destroy(scene);
    }
    assert_int_equal(count, 12); /* five linear solvers, shooting, hierarchical, two Galerkin, collocation,
                                    two instant radiosity */
    rad_options o = {0};
    o.solver = "no-such-solver";
    rad_solution *s = NULL;
    rad_scene *scene = furnace();
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "hierarchical")); /* the known ones are listed */
    rad_scene_destroy(scene);
}

/* One solver of each strategy: the furnace's exact answer, power conserved,
 * and the accessors adding up to the per-surface figures. */
static void test_strategies_furnace_and_accessors(void **state)
{
    (void)state;
    const char *solvers[] = {"gauss-seidel", "direct", "shooting", "hierarchical", "collocation"};
    rad_scene *scene = furnace();
    size_t S = rad_scene_surface_count(scene);
    for (size_t k = 0; k < sizeof solvers / sizeof solvers[0]; k++) {
        rad_solution *s = solved(scene, solvers[k]);
        /* Relative error allowed in the power balance and per element:
         * the dense solvers are exact to the factors' 1e-8 and the
         * tolerance; shooting samples its factors with rays (measured
         * 1.0e-3 and 6.0e-2); hierarchical stops where epsilon allows
         * (measured 8.6e-5 and 2.3e-2 at 1e-5). */
        double tol = 2e-5, element_tol = 2e-5;
        if (strcmp(solvers[k], "shooting") == 0)
            tol = 5e-3, element_tol = 0.12;
        else if (strcmp(solvers[k], "hierarchical") == 0)
            tol = 5e-4, element_tol = 5e-2;
        double emitted, absorbed;
        rad_solution_power(s, &emitted, &absorbed);
        assert_true(fabs(emitted - 6.0) < 1e-6);
        assert_true(fabs(absorbed - emitted) < tol * emitted);

        double worst = 0.0;
        size_t n = rad_solution_element_count(s), V = rad_solution_vertex_count(s);
        assert_true(n >= 6 && V >= 8);
        double *area = calloc(S, sizeof *area), *sum = calloc(3 * S, sizeof *sum);
        for (size_t i = 0; i < n; i++) {
            size_t surface = rad_solution_element_surface(s, i);
            assert_true(surface < S);
            double a = rad_solution_element_area(s, i), rho[3], E[3], B[3], normal[3], centroid[3];
            assert_true(a > 0.0);
            assert_true(rad_solution_element_values(s, i, rho, E, B));
            assert_true(rad_solution_element_geometry(s, i, normal, centroid));
            assert_true(fabs(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2] - 1.0) < 1e-9);
            for (int c = 0; c < 3; c++) {
                assert_true(rho[c] == 0.5);
                assert_true(fabs(E[c] - 1.0) < 1e-6);
                worst = fmax(worst, fabs(B[c] - 2.0) / 2.0);
                assert_true(centroid[c] >= -1e-12 && centroid[c] <= 1.0 + 1e-12);
                sum[3 * surface + (size_t)c] += a * B[c];
            }
            area[surface] += a;
            size_t vertex[4];
            int corners = rad_solution_element_vertices(s, i, vertex);
            assert_true(corners == 3 || corners == 4);
            for (int q = 0; q < corners; q++)
                assert_true(vertex[q] < V);
        }
        assert_true(worst < element_tol);
        for (size_t j = 0; j < S; j++) {
            assert_true(fabs(area[j] - rad_scene_surface_area(scene, j)) < 1e-9);
            double mean[3];
            rad_solution_surface_radiosity(s, j, mean);
            for (int c = 0; c < 3; c++)
                assert_true(fabs(sum[3 * j + (size_t)c] / area[j] - mean[c]) < 1e-9 * mean[c]);
        }
        double *vb = malloc(3 * V * sizeof *vb), xyz[3];
        assert_int_equal(rad_solution_vertex_radiosity(ctx, s, vb), RAD_OK);
        for (size_t v = 0; v < V; v++) {
            assert_true(rad_solution_vertex_position(s, v, xyz));
            assert_true(fabs(vb[3 * v] - 2.0) < 2.0 * element_tol * 2.0); /* extrapolated at edges */
        }
        /* Out of range: nothing written, nothing read. */
        assert_false(rad_solution_vertex_position(s, V, xyz));
        assert_false(rad_solution_element_values(s, n, NULL, NULL, NULL));
        assert_int_equal(rad_solution_element_surface(s, n), SIZE_MAX);
        assert_true(rad_solution_element_area(s, n) == 0.0);
        size_t vertex[4];
        assert_int_equal(rad_solution_element_vertices(s, n, vertex), 0);
        free(vb);
        free(area);
        free(sum);
        rad_solution_destroy(s);
    }
    rad_scene_destroy(scene);
}

/* The hierarchical solution's elements are its patches until solved, then
 * its leaves. */
static void test_hierarchical_elements_are_leaves(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    rad_options o = {0};
    o.solver = "hierarchical";
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    size_t patches = rad_solution_element_count(s);
    assert_int_equal(rad_solution_link_count(s), 0); /* not solved yet */
    /* One element per patch: the polygons (coplanar triangle pairs merged
     * into quads), the floor cut along the blocks' footprints. */
    assert_true(patches >= rad_scene_surface_count(scene) && patches <= 2 * rad_scene_polygon_count(scene));
    assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
    size_t leaves = rad_solution_element_count(s);
    assert_true(leaves > 10 * patches);
    double total = 0.0, want = 0.0;
    for (size_t i = 0; i < leaves; i++)
        total += rad_solution_element_area(s, i);
    for (size_t j = 0; j < rad_scene_surface_count(scene); j++)
        want += rad_scene_surface_area(scene, j);
    assert_true(fabs(total - want) < 1e-6 * want);
    /* Its links: the stats file's count. */
    const char *stats = "/tmp/test_solution_links.json";
    assert_int_equal(rad_solution_write_stats(ctx, s, stats, false), RAD_OK);
    FILE *f = fopen(stats, "rb");
    assert_non_null(f);
    static char text[1 << 20];
    size_t size = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    remove(stats);
    text[size] = '\0';
    cJSON *json = cJSON_Parse(text);
    const cJSON *links = cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(json, "solver"), "hierarchical"),
                                             "links");
    assert_true(cJSON_IsNumber(links));
    assert_true(rad_solution_link_count(s) > 0);
    assert_true((double)rad_solution_link_count(s) == links->valuedouble);
    cJSON_Delete(json);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
}

static void test_first_error_kept_and_reported_once(void **state)
{
    (void)state;
    memset(&errors, 0, sizeof errors);
    rad_scene *scene = (rad_scene *)&errors;
    assert_int_equal(rad_scene_load_file(ctx, "/nonexistent/room.obj", &scene), RAD_ERROR_IO);
    assert_null(scene);
    assert_int_equal(errors.calls, 1);
    assert_int_equal(errors.last, RAD_ERROR_IO);
    assert_string_equal(errors.message, rad_context_error(ctx));
    assert_non_null(strstr(rad_context_error(ctx), "/nonexistent/room.obj"));

    /* A malformed file: the message names the file and the line, and the
     * callback hears exactly that one message. */
    static const char bad[] = "v 0 0 0\nv 1 0 0\nf 1 2\n";
    memset(&errors, 0, sizeof errors);
    rad_result r = rad_scene_load_memory(ctx, "bad.obj", bad, strlen(bad), NULL, 0, &scene);
    assert_int_not_equal(r, RAD_OK);
    assert_null(scene);
    assert_int_equal(errors.calls, 1);
    assert_string_equal(errors.message, rad_context_error(ctx));
    assert_non_null(strstr(rad_context_error(ctx), "bad.obj"));

    /* Success leaves the last failure's message and calls nothing. */
    memset(&errors, 0, sizeof errors);
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    assert_int_equal(errors.calls, 0);
    assert_non_null(strstr(rad_context_error(ctx), "bad.obj"));
    /* An option out of range: the next failure replaces it. */
    rad_options o = {0};
    o.tolerance = 2.0;
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(errors.calls, 1);
    assert_non_null(strstr(rad_context_error(ctx), "tolerance"));
    rad_scene_destroy(scene);
}

/* A solve that stops short of its tolerance says so: converged false and
 * one line naming the solver, the count and the limit, for every strategy
 * (the user's cap of 2 sweeps, shots or batches). */
static void test_unconverged_is_reported(void **state)
{
    (void)state;
    rad_scene *scene = furnace();
    const char *names[] = {"gauss-seidel", "shooting", "hierarchical"};
    const char *units[] = {"2 sweeps", "2 batches", "2 sweeps"};
    for (int k = 0; k < 3; k++) {
        rad_options o = {0};
        o.solver = names[k];
        o.target_elements = 600;
        o.max_iterations = 2;
        /* With its control variate shooting has nothing to shoot in the
         * furnace, and converges at once. */
        o.no_control_variate = 1;
        rad_solution *s = NULL;
        assert_false(rad_solution_converged(s));
        assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
        assert_false(rad_solution_converged(s)); /* not solved yet */
        assert_string_equal(rad_solution_warning(s), "");
        assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
        assert_false(rad_solution_converged(s));
        const char *w = rad_solution_warning(s);
        if (!strstr(w, names[k]) || !strstr(w, units[k]) || !strstr(w, "(rad_options.max_iterations)") ||
            strchr(w, '\n'))
            fail_msg("%s: warning '%s'", names[k], w);
        rad_solution_destroy(s);
    }
    rad_scene_destroy(scene);
}

static void test_cancellation_flag(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    rad_options o = {0};
    o.solver = "gauss-seidel"; /* its create computes the form factors */
    o.target_elements = 400;
    assert_false(rad_context_cancelled(ctx));
    rad_context_cancel(ctx, true);
    assert_true(rad_context_cancelled(ctx));
    rad_solution *s = (rad_solution *)&o;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_ERROR_INTERRUPTED);
    assert_null(s);
    rad_context_cancel(ctx, false);
    assert_false(rad_context_cancelled(ctx));
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    rad_context_cancel(ctx, true);
    assert_int_equal(rad_solution_solve(ctx, s), RAD_ERROR_INTERRUPTED);
    assert_false(rad_solution_converged(s));
    assert_string_equal(rad_solution_warning(s), ""); /* interrupted: no warning to give */
    rad_context_cancel(ctx, false);
    assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
    assert_true(rad_solution_converged(s));
    assert_string_equal(rad_solution_warning(s), "");
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
    rad_context_cancel(NULL, true); /* no-op */
    assert_false(rad_context_cancelled(NULL));
}

/* on_step's answers: RAD_STEP_FINISH at step `finish_at` ends the solve
 * with its iterate as the solution; 1 at `interrupt_at` interrupts it. */
typedef struct step_stopper {
    int finish_at, interrupt_at, last;
} step_stopper;

static int stop_at(void *user, rad_solution *solution, const rad_solve_step *step)
{
    step_stopper *s = user;
    (void)solution;
    s->last = step->iteration;
    if (step->iteration == s->finish_at)
        return RAD_STEP_FINISH;
    return step->iteration == s->interrupt_at ? 1 : 0;
}

/* An interactive stop (the viewer's Backspace): the iterate of the step
 * that said RAD_STEP_FINISH is the result, solved and not converged, and
 * saves; any other nonzero answer still interrupts, and an interrupted
 * solve is not saved.  The display values: without the ambient term the
 * vertex values are rad_solution_vertex_radiosity's to the bit; with it,
 * a partial shooting solution is brighter (the unshot light), never
 * darker, while a converged Gauss-Seidel one is unchanged. */
static void test_step_finish_keeps_the_iterate(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    const char *solvers[] = {"shooting", "gauss-seidel"};
    for (int k = 0; k < 2; k++) {
        step_stopper stopper = {.finish_at = 4};
        rad_options o = {.solver = solvers[k], .target_elements = 300, .on_step = stop_at, .on_step_user = &stopper};
        rad_solution *s = NULL;
        assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
        assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
        assert_int_equal(stopper.last, 4);
        assert_false(rad_solution_converged(s));
        assert_non_null(strstr(rad_solution_warning(s), "after 4 iterations"));
        char path[64];
        snprintf(path, sizeof path, "/tmp/test_solution_finish_%d.radsol", k);
        assert_int_equal(rad_solution_save(ctx, s, path), RAD_OK);
        /* The file says so too: read back, it is not converged and gives the
         * same warning. */
        rad_scene *loaded_scene = NULL;
        rad_solution *loaded = NULL;
        assert_int_equal(rad_solution_load_file(ctx, path, &loaded_scene, &loaded), RAD_OK);
        assert_false(rad_solution_converged(loaded));
        assert_string_equal(rad_solution_warning(loaded), rad_solution_warning(s));
        rad_solution_destroy(loaded);
        rad_scene_destroy(loaded_scene);
        remove(path);
        /* And the stats: not converged, the warning given. */
        snprintf(path, sizeof path, "/tmp/test_solution_finish_%d.json", k);
        assert_int_equal(rad_solution_write_stats(ctx, s, path, false), RAD_OK);
        FILE *f = fopen(path, "rb");
        assert_non_null(f);
        static char text[1 << 20];
        size_t size = fread(text, 1, sizeof text - 1, f);
        fclose(f);
        remove(path);
        text[size] = '\0';
        cJSON *json = cJSON_Parse(text);
        const cJSON *solver = cJSON_GetObjectItem(json, "solver");
        assert_true(cJSON_IsFalse(cJSON_GetObjectItem(solver, "converged")));
        assert_string_equal(cJSON_GetStringValue(cJSON_GetObjectItem(solver, "warning")), rad_solution_warning(s));
        cJSON_Delete(json);
        snprintf(path, sizeof path, "/tmp/test_solution_finish_%d.radsol", k);

        size_t nv = rad_solution_vertex_count(s), ne = rad_solution_element_count(s);
        double *plain = malloc(3 * nv * sizeof *plain), *vertex = malloc(3 * nv * sizeof *vertex);
        double *with = malloc(3 * ne * sizeof *with), *without = malloc(3 * ne * sizeof *without);
        assert_int_equal(rad_solution_vertex_radiosity(ctx, s, plain), RAD_OK);
        assert_int_equal(rad_solution_display_radiosity(ctx, s, false, without, vertex), RAD_OK);
        assert_memory_equal(plain, vertex, 3 * nv * sizeof *plain);
        assert_int_equal(rad_solution_display_radiosity(ctx, s, true, with, NULL), RAD_OK);
        int brighter = 0;
        for (size_t i = 0; i < 3 * ne; i++) {
            assert_true(with[i] >= without[i]);
            brighter += with[i] > without[i];
        }
        if (k == 0)
            assert_true(brighter > 0); /* four shots leave light unshot */

        /* Interrupted (1) instead: not a solution to save. */
        stopper = (step_stopper){.interrupt_at = 2};
        assert_int_equal(rad_solution_solve(ctx, s), RAD_ERROR_INTERRUPTED);
        assert_int_equal(rad_solution_save(ctx, s, path), RAD_ERROR_INVALID_ARGUMENT);
        /* And with no stop it converges: the early end left nothing behind. */
        stopper = (step_stopper){0};
        assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
        assert_true(rad_solution_converged(s));
        assert_string_equal(rad_solution_warning(s), "");
        if (k == 1) {
            assert_int_equal(rad_solution_display_radiosity(ctx, s, true, with, NULL), RAD_OK);
            assert_int_equal(rad_solution_display_radiosity(ctx, s, false, without, NULL), RAD_OK);
            assert_memory_equal(with, without, 3 * ne * sizeof *with); /* no ambient term */
        }
        free(plain);
        free(vertex);
        free(with);
        free(without);
        rad_solution_destroy(s);
    }
    rad_scene_destroy(scene);
}

/* What a hierarchical step shows: its leaves and their radiosity. */
typedef struct hier_watch {
    int steps, finish_at, renders;
    size_t first_elements, last_elements, last_links;
    bool decreased, bad_area, no_links;
    double area;                  /* the scene's, m^2 */
    double *values;               /* 3 per element of the last step */
    size_t values_count;
} hier_watch;

static int watch_hier(void *user, rad_solution *s, const rad_solve_step *step)
{
    hier_watch *w = user;
    size_t n = rad_solution_element_count(s);
    if (w->steps == 0)
        w->first_elements = n;
    w->decreased |= n < w->last_elements;
    w->last_elements = n;
    w->last_links = rad_solution_link_count(s);
    w->no_links |= w->last_links == 0;
    w->steps++;
    /* The leaves tile the patches: their areas add up to the scene's. */
    double area = 0.0;
    for (size_t i = 0; i < n; i++)
        area += rad_solution_element_area(s, i);
    w->bad_area |= fabs(area - w->area) > 1e-5 * w->area; /* leaf quads of non-square patches: 5e-7 */
    free(w->values);
    w->values = malloc(3 * n * sizeof *w->values);
    w->values_count = n;
    for (size_t i = 0; w->values && i < n; i++)
        rad_solution_element_values(s, i, NULL, NULL, w->values + 3 * i);
    /* The iterate renders (the first step and every fifth). */
    if (step->iteration == 1 || step->iteration % 5 == 0) {
        rad_render_options ro = {.width = 24, .height = 24};
        rad_image *image = NULL;
        if (rad_solution_render(ctx, s, &ro, &image) == RAD_OK) {
            const float *px = rad_image_pixels(image);
            double sum = 0.0;
            for (int i = 0; i < 3 * 24 * 24; i++)
                sum += px[i];
            w->renders += sum > 0.0;
        }
        rad_image_destroy(image);
    }
    return step->iteration == w->finish_at ? RAD_STEP_FINISH : 0;
}

/* The hierarchical solver's progressive display: on_step comes after every
 * sweep with the current leaves as the elements (their areas adding up to
 * the scene's), their count never falling and rising as rounds refine,
 * links counted during the solve, and the iterate renders.  The last
 * step's values are the solution's to the bit, which are those of a solve
 * without on_step (the display changes nothing); RAD_STEP_FINISH keeps
 * the step's leaves and values as the result. */
static void test_hierarchical_steps_show_leaves(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    hier_watch w = {0};
    rad_options o = {.solver = "hierarchical", .on_step = watch_hier, .on_step_user = &w};
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    for (size_t i = 0; i < rad_solution_element_count(s); i++)
        w.area += rad_solution_element_area(s, i);
    size_t patches = rad_solution_element_count(s);
    assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
    assert_true(rad_solution_converged(s));
    size_t n = rad_solution_element_count(s);
    assert_true(w.steps >= 5);
    assert_false(w.decreased);
    assert_false(w.bad_area);
    assert_false(w.no_links);
    assert_true(w.first_elements > patches);
    assert_true(w.first_elements < w.last_elements); /* a later round split more */
    assert_int_equal(w.last_elements, n);
    assert_int_equal(w.last_links, rad_solution_link_count(s));
    assert_true(w.renders >= 2);
    double *final = malloc(3 * n * sizeof *final);
    for (size_t i = 0; i < n; i++)
        rad_solution_element_values(s, i, NULL, NULL, final + 3 * i);
    assert_memory_equal(w.values, final, 3 * n * sizeof *final);
    size_t count = 0;
    const rad_solve_step *h = rad_solution_history(s, &count);
    assert_int_equal(h[count - 1].iteration, w.steps);

    /* Without on_step: the same leaves, the same values. */
    rad_options plain = {.solver = "hierarchical"};
    rad_solution *q = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &plain, &q), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, q), RAD_OK);
    assert_int_equal(rad_solution_element_count(q), n);
    for (size_t i = 0; i < n; i++) {
        double b[3];
        rad_solution_element_values(q, i, NULL, NULL, b);
        assert_memory_equal(b, final + 3 * i, sizeof b);
    }
    rad_solution_destroy(q);

    /* Finished at step 3: that step's leaves and values are the result. */
    int steps = w.steps;
    w = (hier_watch){.finish_at = 3, .area = w.area, .values = w.values};
    assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
    assert_int_equal(w.steps, 3);
    assert_true(steps > 3);
    assert_false(rad_solution_converged(s));
    assert_non_null(strstr(rad_solution_warning(s), "after 3 iterations"));
    assert_int_equal(rad_solution_element_count(s), w.values_count);
    for (size_t i = 0; i < w.values_count; i++) {
        double b[3];
        rad_solution_element_values(s, i, NULL, NULL, b);
        assert_memory_equal(b, w.values + 3 * i, sizeof b);
    }
    char path[] = "/tmp/test_solution_hier_finish.radsol";
    assert_int_equal(rad_solution_save(ctx, s, path), RAD_OK);
    remove(path);
    free(w.values);
    free(final);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
}

/* Factors that make up power.  Monte Carlo at 16 samples on polygons that
 * touch at sharp angles (a fuzz_solve find) had rows summing to 3.4, and
 * Gauss-Seidel returned B = 1e5 (1e66 at other seeds) as a success; its
 * estimator is bounded now (ff_montecarlo.c) and that scene solves within
 * the bound, raw or balanced, as with the analytic factors.  What still
 * makes up power: eight coincident copies of a white square over a lamp,
 * each seen whole (analytic rows sum to 6.6).  The solve fails with
 * RAD_ERROR_NUMERICAL naming the row sums; montecarlo's default balance
 * step holds the lamp's row to the closure its rays measure (1) and
 * solves it. */
static void test_diverged_solution_refused(void **state)
{
    (void)state;
    static const char obj[] =
        "mtllib m.mtl\n"
        "o white\n"
        "usemtl white\n"
        "v 0.0 0.0 0.0\n"
        "v 0.0 0.0 1.0\n"
        "v 1.0 0.0 1.0\n"
        "v 1.0 0.0 0.0\n"
        "f 1 2 3 4\n"
        "o white\n"
        "usemtl white\n"
        "v 0.0 1.0 0.0\n"
        "v 1.0 1.0 0.0\n"
        "v 1.0 1.0 1.0\n"
        "v 1.0 1.0 1.0\n"
        "f 5 6 7 8\n"
        "o lamp\n"
        "usemtl lamp\n"
        "v 2.75 0.3125 0.0\n"
        "v 0.0 1.0 0.0\n"
        "v 1.0 1.0 1.0\n"
        "f 9 10 11\n"
        "o lamp\n"
        "usemtl lamp\n"
        "v 1.0 1.0 0.0\n"
        "v 1.0 0.0625 0.375\n"
        "v 0.9375 0.375 0.625\n"
        "f 12 13 14\n"
        "o black\n"
        "usemtl black\n"
        "v 0.5 4.0625 0.9375\n"
        "v 0.625 0.375 0.9375\n"
        "v 0.5 4.0625 0.9375\n"
        "v 0.625 0.375 0.9375\n"
        "v 0.625 0.0 0.0\n"
        "v 0.0 0.0 0.0\n"
        "f 15 16 17 18 19 20\n";
    static const char mtl[] = "newmtl lamp\nKd 0.3 0.3 0.3\nKe 3.1830988618379 3.1830988618379 3.1830988618379\n"
                              "newmtl white\nKd 0.8 0.8 0.8\nnewmtl black\nKd 0 0 0\n";
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "m.obj", obj, strlen(obj), mtl, strlen(mtl), &scene), RAD_OK);
    rad_options o = {.solver = "gauss-seidel", .target_elements = 32, .form_factors = "montecarlo",
                     .samples = 16, .max_iterations = 200, .seed = 1};
    rad_solution *s = NULL;
    for (int method = 0; method < 3; method++) {
        o.form_factors = method < 2 ? "montecarlo" : "analytic";
        o.raw_form_factors = method == 1;
        assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
        assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
        for (size_t i = 0; i < rad_solution_element_count(s); i++) {
            double b[3];
            assert_true(rad_solution_element_values(s, i, NULL, NULL, b));
            assert_true(isfinite(b[0]) && b[0] >= 0.0 && b[0] <= 10.0 / (1.0 - 0.8));
        }
        rad_solution_destroy(s);
    }
    rad_scene_destroy(scene);

    char copies[2048] = "mtllib c.mtl\no lamp\nusemtl lamp\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    for (int k = 0; k < 8; k++)
        snprintf(copies + strlen(copies), sizeof copies - strlen(copies),
                 "o white\nusemtl white\nv 0 0 0.1\nv 0 1 0.1\nv 1 1 0.1\nv 1 0 0.1\nf %d %d %d %d\n",
                 5 + 4 * k, 6 + 4 * k, 7 + 4 * k, 8 + 4 * k);
    static const char copies_mtl[] = "newmtl lamp\nKd 0.3 0.3 0.3\nKe 0.3183 0.3183 0.3183\n"
                                     "newmtl white\nKd 0.9 0.9 0.9\n";
    assert_int_equal(rad_scene_load_memory(ctx, "copies.obj", copies, strlen(copies), copies_mtl,
                                           strlen(copies_mtl), &scene),
                     RAD_OK);
    rad_options c = {.target_elements = 16, .form_factors = "analytic", .solver = "gauss-seidel", .max_iterations = 200};
    assert_int_equal(rad_solution_create(ctx, scene, &c, &s), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, s), RAD_ERROR_NUMERICAL);
    assert_non_null(strstr(rad_context_error(ctx), "the solution diverged"));
    assert_non_null(strstr(rad_context_error(ctx), "('analytic') have rows summing to"));
    rad_solution_destroy(s);
    c.form_factors = "montecarlo";
    assert_int_equal(rad_solution_create(ctx, scene, &c, &s), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
    for (size_t i = 0; i < rad_solution_element_count(s); i++) {
        double b[3];
        assert_true(rad_solution_element_values(s, i, NULL, NULL, b));
        assert_true(isfinite(b[0]) && b[0] >= 0.0 && b[0] <= 1.0 / (1.0 - 0.9));
    }
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
}

/* The point query: at a mesh vertex it is that vertex's value; over a
 * fine grid of points its mean is the surface's area-weighted mean, to
 * what interpolation moves (3%; 2.1% measured for shooting's noisy
 * elements); on every strategy's mesh; a point off the surface and a
 * surface out of range are refused. */
static void test_point_radiosity(void **state)
{
    (void)state;
    static const char *const solvers[3] = {"gauss-seidel", "shooting", "hierarchical"};
    for (int k = 0; k < 3; k++) {
        rad_scene *scene = NULL;
        assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
        rad_options o = {0};
        o.solver = solvers[k];
        o.target_elements = 400; /* hierarchical: its default epsilon (at 1e-3 the coarse leaves beside
                                    the blocks' footprints interpolate 3.6% above their mean) */
        rad_solution *s = NULL;
        assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
        assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
        size_t V = rad_solution_vertex_count(s);
        double *vertex = malloc(3 * V * sizeof *vertex);
        assert_int_equal(rad_solution_vertex_radiosity(ctx, s, vertex), RAD_OK);
        /* At the corners of some floor elements: the vertex values. */
        int checked = 0;
        for (size_t e = 0; e < rad_solution_element_count(s) && checked < 40; e++) {
            if (rad_solution_element_surface(s, e) != 0)
                continue;
            size_t corners[4];
            int count = rad_solution_element_vertices(s, e, corners);
            for (int c = 0; c < count; c++, checked++) {
                double xyz[3], rgb[3];
                assert_true(rad_solution_vertex_position(s, corners[c], xyz));
                assert_int_equal(rad_solution_point_radiosity(ctx, s, 0, xyz, rgb), RAD_OK);
                for (int ch = 0; ch < 3; ch++)
                    if (!(fabs(rgb[ch] - vertex[3 * corners[c] + ch]) <= 1e-9 * fmax(vertex[3 * corners[c] + ch], 1.0)))
                        fail_msg("%s: vertex %zu: %.17g, the vertex value %.17g", solvers[k], corners[c], rgb[ch],
                                 vertex[3 * corners[c] + ch]);
            }
        }
        assert_true(checked >= 12);
        /* The floor (y = 0, x in [0, 0.556], z in [0, 0.559]) on a 60 x 60 grid. */
        double sum = 0.0, mean[3];
        int points = 0;
        for (int i = 0; i < 60; i++)
            for (int j = 0; j < 60; j++) {
                double p[3] = {0.01 + 0.536 * (i + 0.5) / 60.0, 0.0, 0.01 + 0.539 * (j + 0.5) / 60.0}, rgb[3];
                assert_int_equal(rad_solution_point_radiosity(ctx, s, 0, p, rgb), RAD_OK);
                assert_true(isfinite(rgb[0]) && rgb[0] >= 0.0); /* 0 under the blocks */
                sum += rgb[0];
                points++;
            }
        rad_solution_surface_radiosity(s, 0, mean);
        assert_string_equal(rad_scene_surface_name(scene, 0), "floor");
        if (!(fabs(sum / points - mean[0]) <= 0.03 * mean[0]))
            fail_msg("%s: floor: points' mean %g, the surface's %g", solvers[k], sum / points, mean[0]);
        /* Off the surface, out of range, NULL. */
        double above[3] = {0.3, 0.2, 0.3}, rgb[3];
        assert_int_equal(rad_solution_point_radiosity(ctx, s, 0, above, rgb), RAD_ERROR_INVALID_ARGUMENT);
        assert_non_null(strstr(rad_context_error(ctx), "from surface 'floor'"));
        assert_true(isnan(rgb[0]));
        assert_int_equal(rad_solution_point_radiosity(ctx, s, 99, above, rgb), RAD_ERROR_INVALID_ARGUMENT);
        assert_int_equal(rad_solution_point_radiosity(ctx, s, 0, NULL, rgb), RAD_ERROR_INVALID_ARGUMENT);
        assert_int_equal(rad_solution_point_radiosity(ctx, NULL, 0, above, rgb), RAD_ERROR_INVALID_ARGUMENT);
        free(vertex);
        rad_solution_destroy(s);
        rad_scene_destroy(scene);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_solver_name_resolves),
        cmocka_unit_test(test_strategies_furnace_and_accessors),
        cmocka_unit_test(test_hierarchical_elements_are_leaves),
        cmocka_unit_test(test_first_error_kept_and_reported_once),
        cmocka_unit_test(test_unconverged_is_reported),
        cmocka_unit_test(test_cancellation_flag),
        cmocka_unit_test(test_step_finish_keeps_the_iterate),
        cmocka_unit_test(test_hierarchical_steps_show_leaves),
        cmocka_unit_test(test_diverged_solution_refused),
        cmocka_unit_test(test_point_radiosity),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
