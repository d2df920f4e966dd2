/*
 * test_viewer.c -- the viewer's drawing and progressive display, without a
 * screen (EGL surfaceless + Mesa's llvmpipe; skipped with CTest's code 77
 * where no EGL device opens).
 *
 *   frame vs ray caster   the off-screen frame (the window's drawing code)
 *                         against rad_solution_render of the same solution,
 *                         camera, shading and exposure, in exposed 8-bit
 *                         sRGB: mean difference and the share of pixels
 *                         beyond 12 levels bounded; a camera moved by 1% of
 *                         its distance must break the bounds (the test sees
 *                         a misplaced picture)
 *   progressive           shooting on the worker thread, every step
 *                         published: each element's B never decreases
 *                         between snapshots (shooting only adds light), the
 *                         distance to the final solution is monotone, the
 *                         final one is bit for bit the solve's without the
 *                         viewer; the ambient
 *                         term makes the first snapshot much closer
 *   hierarchical          its leaves change as rounds refine: snapshots carry
 *                         the new mesh; the power leaving the surfaces (over
 *                         each snapshot's mesh) and, on the final mesh, the
 *                         element values move monotonically to the end,
 *                         reached exactly; the copied mesh draws the
 *                         solution's frame pixel for pixel
 *   pause / stop          paused, the solver does not advance; stopped, the
 *                         iterate is the solution: consistent with the last
 *                         snapshot, saved and read back equal
 *   the program           `radiosity view --offscreen` writes the frame at
 *                         its size and refuses an unknown format; the window
 *                         on SDL's off-screen driver, scripted by --keys,
 *                         prints the --camera that gives its view back and
 *                         saves a converged solution
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "test_support.h"

#include "output/output.h"
#include "viewer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static rv_offscreen *offscreen;

/* The Cornell box solved (or only made, solve = false) with `solver`. */
static rad_solution *cornell(rad_context *ctx, rad_scene **scene, const char *solver, size_t elements,
                             rv_step_slot *slot, bool solve)
{
    assert_int_equal(rad_scene_create_cornell_box(ctx, scene), RAD_OK);
    rad_options o = {.solver = solver, .target_elements = elements, .seed = 1};
    if (slot) {
        o.on_step = rv_step_forward;
        o.on_step_user = slot;
    }
    if (solver && strcmp(solver, "shooting") == 0)
        o.unshot_tolerance = 1e-4;
    rad_solution *solution = NULL;
    assert_int_equal(rad_solution_create(ctx, *scene, &o, &solution), RAD_OK);
    if (solve)
        assert_int_equal(rad_solution_solve(ctx, solution), RAD_OK);
    return solution;
}

static double *display(rad_context *ctx, const rad_solution *solution, bool ambient, bool per_element)
{
    size_t n = per_element ? rad_solution_element_count(solution) : rad_solution_vertex_count(solution);
    double *rgb = malloc(3 * n * sizeof *rgb);
    assert_non_null(rgb);
    assert_int_equal(rad_solution_display_radiosity(ctx, solution, ambient, per_element ? rgb : NULL,
                                                    per_element ? NULL : rgb),
                     RAD_OK);
    return rgb;
}

/* ---- the off-screen frame against the ray caster ---- */

#define FRAME 160

typedef struct frame_difference {
    double mean_levels;     /* mean |difference| over pixels and channels, 8-bit levels */
    double beyond;          /* share of pixels with a channel more than 12 levels off */
} frame_difference;

static frame_difference compare(const float *a, const float *b, double exposure)
{
    frame_difference d = {0.0, 0.0};
    size_t pixels = (size_t)FRAME * FRAME, beyond = 0;
    for (size_t i = 0; i < pixels; i++) {
        double worst = 0.0;
        for (int c = 0; c < 3; c++) {
            double la = round(255.0 * rad_srgb_encode(exposure * a[3 * i + (size_t)c]));
            double lb = round(255.0 * rad_srgb_encode(exposure * b[3 * i + (size_t)c]));
            d.mean_levels += fabs(la - lb);
            worst = fmax(worst, fabs(la - lb));
        }
        beyond += worst > 12.0;
    }
    d.mean_levels /= 3.0 * (double)pixels;
    d.beyond = (double)beyond / (double)pixels;
    return d;
}

static void frame_against_render(rad_shading shading)
{
    rad_context *ctx = test_context(0);
    rad_scene *scene = NULL;
    rad_solution *solution = cornell(ctx, &scene, "gauss-seidel", 1000, NULL, true);
    rad_camera camera;
    assert_true(rad_scene_camera(scene, &camera));
    /* The viewer draws the solution's values: the ray caster's picture of
     * them is the one without the final gather. */
    rad_render_options ro = {.width = FRAME, .height = FRAME, .samples = 4, .camera = &camera, .shading = shading,
                             .direct_gather = -1};
    rad_image *image = NULL;
    assert_int_equal(rad_solution_render(ctx, solution, &ro, &image), RAD_OK);
    double exposure = rad_image_auto_exposure(image);

    double *element_rgb = display(ctx, solution, true, true), *vertex_rgb = display(ctx, solution, true, false);
    rv_renderer *renderer = rv_renderer_create(solution, element_rgb, vertex_rgb);
    assert_non_null(renderer);
    float *rgb = malloc((size_t)FRAME * FRAME * 3 * sizeof *rgb);
    assert_non_null(rgb);
    rv_camera view = rv_camera_from(&camera);
    rv_draw d = {.camera = &view, .width = FRAME, .height = FRAME, .shading = shading, .output = RV_OUTPUT_RADIANCE};
    assert_true(rv_offscreen_draw(offscreen, renderer, &d, 4, rgb));
    frame_difference same = compare(rgb, rad_image_pixels(image), exposure);
    printf("# %s: mean %.3f levels, %.4f of pixels beyond 12 levels\n",
           shading == RAD_SHADING_FLAT ? "flat" : "smooth", same.mean_levels, same.beyond);
    /* Edges rasterise differently (4 MSAA samples against 16 jittered
     * rays), and smooth quads interpolate linearly on two triangles here,
     * bilinearly there: measured 0.65 (flat) and 0.74 (smooth) levels, 1.6% of
     * the pixels beyond 12 levels (element edges, flat; silhouettes).  The
     * moved camera below: 6.2 levels, 11% to 17% beyond. */
    assert_true(same.mean_levels < 1.2);
    assert_true(same.beyond < 0.03);

    /* The test sees a misplaced picture: the camera moved sideways by 1%
     * of its distance to what it looks at. */
    rv_camera moved = view;
    double distance = 0.0;
    for (int k = 0; k < 3; k++)
        distance += (view.target[k] - view.position[k]) * (view.target[k] - view.position[k]);
    moved.position[0] += 0.01 * sqrt(distance);
    moved.target[0] += 0.01 * sqrt(distance);
    d.camera = &moved;
    assert_true(rv_offscreen_draw(offscreen, renderer, &d, 4, rgb));
    frame_difference off = compare(rgb, rad_image_pixels(image), exposure);
    printf("# moved camera: mean %.3f levels, %.4f beyond\n", off.mean_levels, off.beyond);
    assert_true(off.mean_levels >= 1.2 || off.beyond >= 0.03);

    free(rgb);
    free(element_rgb);
    free(vertex_rgb);
    rv_renderer_destroy(renderer);
    rad_image_destroy(image);
    rad_solution_destroy(solution);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

static void offscreen_smooth_matches_render(void **state)
{
    (void)state;
    frame_against_render(RAD_SHADING_SMOOTH);
}

static void offscreen_flat_matches_render(void **state)
{
    (void)state;
    frame_against_render(RAD_SHADING_FLAT);
}

/* ---- progressive display ---- */

static void sleep_ms(int ms)
{
    struct timespec t = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&t, NULL);
}

/* The emission of every element (3 each): the snapshots are compared on
 * the reflected light B - E, which the solve is finding (E is exact from
 * the start and would swamp the measure: the light's B is 150 times the
 * walls'). */
static double *emission(const rad_solution *solution)
{
    size_t n = rad_solution_element_count(solution);
    double *e = malloc(3 * n * sizeof *e);
    assert_non_null(e);
    for (size_t i = 0; i < n; i++)
        assert_true(rad_solution_element_values(solution, i, NULL, &e[3 * i], NULL));
    return e;
}

static void subtract(double *a, const double *b, size_t n)
{
    for (size_t i = 0; i < n; i++)
        a[i] -= b[i];
}

/* sum |a - b| / sum |b| over n values. */
static double distance(const double *a, const double *b, size_t n)
{
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < n; i++) {
        num += fabs(a[i] - b[i]);
        den += fabs(b[i]);
    }
    return num / den;
}

#define MAX_SNAPSHOTS 4096

typedef struct run {
    size_t count;                 /* snapshots taken */
    double *element[MAX_SNAPSHOTS];
    int iteration[MAX_SNAPSHOTS];
    size_t elements;
} run;

/* Shooting on the worker, every step published; every snapshot the poll
 * sees is kept. */
static rad_solution *progressive_run(rad_context *ctx, rad_scene **scene, bool ambient, run *out)
{
    rv_step_slot slot = {NULL, NULL};
    rad_solution *solution = cornell(ctx, scene, "shooting", 600, &slot, false);
    out->elements = rad_solution_element_count(solution);
    out->count = 0;
    /* Held at its first step until the poll has seen it (the poll sees only
     * the latest snapshot: without the pause it may miss the first). */
    rv_progress *p = rv_progress_start(solution, &slot, 1, ambient, 0.0, true);
    assert_non_null(p);
    uint64_t generation = 0;
    double *element = malloc(3 * out->elements * sizeof *element);
    bool held = true;
    for (;;) {
        rv_status status;
        if (rv_progress_take(p, &generation, element, NULL, &status) && out->count < MAX_SNAPSHOTS) {
            out->element[out->count] = malloc(3 * out->elements * sizeof *element);
            memcpy(out->element[out->count], element, 3 * out->elements * sizeof *element);
            out->iteration[out->count++] = status.step.iteration;
        }
        if (held && out->count > 0 && status.paused) {
            rv_progress_pause(p, false);
            held = false;
        }
        if (status.done && !rv_progress_take(p, &generation, NULL, NULL, NULL))
            break;
        sleep_ms(1);
    }
    free(element);
    char message[512];
    assert_int_equal(rv_progress_finish(p, message, sizeof message), RAD_OK);
    return solution;
}

static void run_free(run *r)
{
    for (size_t k = 0; k < r->count; k++)
        free(r->element[k]);
}

static void progressive_moves_toward_solution(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    rad_scene *scene = NULL;
    run r;
    rad_solution *solution = progressive_run(ctx, &scene, false, &r);
    size_t n3 = 3 * r.elements;
    double *final_rgb = display(ctx, solution, false, true), *E = emission(solution);
    subtract(final_rgb, E, n3);
    for (size_t k = 0; k < r.count; k++)
        subtract(r.element[k], E, n3);
    printf("# %zu snapshots of %d shots\n", r.count, rad_solution_iterations(solution));
    assert_true(r.count >= 10);
    double previous = INFINITY;
    for (size_t k = 0; k < r.count; k++) {
        /* Shooting adds light and never takes it away. */
        if (k > 0)
            for (size_t i = 0; i < n3; i++)
                assert_true(r.element[k][i] >= r.element[k - 1][i] - 1e-12 * fabs(r.element[k - 1][i]));
        double d = distance(r.element[k], final_rgb, n3);
        assert_true(d <= previous * (1.0 + 1e-12));
        previous = d;
    }
    assert_true(distance(r.element[0], final_rgb, n3) > 0.1); /* the first shot lights little */
    assert_true(previous == 0.0);                              /* the last snapshot is the end */

    /* The end is the solution the same solve reaches on this thread, with
     * no viewer: bit for bit (the worker, the pauses for snapshots and the
     * display values change nothing in the solve). */
    rad_scene *scene_plain = NULL;
    rad_solution *plain_solve = cornell(ctx, &scene_plain, "shooting", 600, NULL, true);
    assert_int_equal(rad_solution_element_count(plain_solve), r.elements);
    assert_int_equal(rad_solution_iterations(plain_solve), rad_solution_iterations(solution));
    double *plain_rgb = display(ctx, plain_solve, false, true);
    subtract(plain_rgb, E, n3);
    assert_memory_equal(final_rgb, plain_rgb, n3 * sizeof *plain_rgb);

    /* The ambient term (Cohen et al. 1988) puts the first picture much
     * nearer the end: the same first shot, the unshot light added (measured:
     * 0.44 of the reflected light off, 0.28 with it). */
    rad_scene *scene_ambient = NULL;
    run with;
    rad_solution *ambient = progressive_run(ctx, &scene_ambient, true, &with);
    double *ambient_final = display(ctx, ambient, true, true);
    subtract(ambient_final, E, n3);
    subtract(with.element[0], E, n3);
    assert_int_equal(with.iteration[0], r.iteration[0]);
    double plain = distance(r.element[0], final_rgb, n3), lifted = distance(with.element[0], ambient_final, n3);
    printf("# first snapshot (shot %d): %.3f from the end, %.3f with the ambient term\n", r.iteration[0], plain,
           lifted);
    assert_true(lifted < 0.75 * plain);

    free(ambient_final);
    run_free(&with);
    rad_solution_destroy(ambient);
    rad_scene_destroy(scene_ambient);
    free(plain_rgb);
    rad_solution_destroy(plain_solve);
    rad_scene_destroy(scene_plain);
    free(final_rgb);
    free(E);
    run_free(&r);
    rad_solution_destroy(solution);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* Area of each element of a copied mesh (fan of triangles), m^2. */
static double *mesh_areas(const rv_mesh *m)
{
    double *area = malloc((m->elements ? m->elements : 1) * sizeof *area);
    assert_non_null(area);
    for (size_t i = 0; i < m->elements; i++) {
        const double *p0 = &m->position[3 * (size_t)m->corner[4 * i]];
        area[i] = 0.0;
        for (int k = 1; k + 1 < m->corners[i]; k++) {
            const double *p1 = &m->position[3 * (size_t)m->corner[4 * i + (size_t)k]];
            const double *p2 = &m->position[3 * (size_t)m->corner[4 * i + (size_t)k + 1]];
            double a[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
            double b[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
            double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
            area[i] += 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        }
    }
    return area;
}

/* Power leaving the surfaces, sum A B (channels summed), W. */
static double power(const double *area, const double *rgb, size_t n)
{
    double p = 0.0;
    for (size_t i = 0; i < n; i++)
        p += area[i] * (rgb[3 * i] + rgb[3 * i + 1] + rgb[3 * i + 2]);
    return p;
}

#define MAX_HIER 512

/* The hierarchical solver on the worker: its leaves change after each
 * refinement round, and the snapshots carry the new mesh (a mesh
 * generation), which the frame loop takes before the colours.  Measured on
 * two scales that stay meaningful when the mesh changes: the power leaving
 * the surfaces, sum A B over the snapshot's own mesh, against the final
 * solution's, relative to the reflected part sum A (B - E) (0 at the
 * start): it falls within each mesh, and a refinement round moves it by
 * far less than the first sweeps do; and, on the snapshots of the final
 * mesh, the elements' distance to the final values (B - E) falls.  Both
 * reach exactly 0: the last snapshot is the solution.
 * The final mesh drawn from the copy is the frame drawn from the solution,
 * pixel for pixel. */
static void progressive_hierarchical_meshes(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    rad_scene *scene = NULL;
    rv_step_slot slot = {NULL, NULL};
    rad_solution *solution = cornell(ctx, &scene, "hierarchical", 0, &slot, false);
    size_t patches = rad_solution_element_count(solution);
    rv_progress *p = rv_progress_start(solution, &slot, 1, false, 0.0, true);
    assert_non_null(p);
    uint64_t generation = 0;
    rv_mesh mesh = {0};
    double *element = malloc(3 * patches * sizeof *element), *vertex = malloc(3 * rad_solution_vertex_count(solution) * sizeof *vertex);
    double *area = NULL;
    size_t count = 0, meshes = 0, mesh_of[MAX_HIER], elements_of[MAX_HIER];
    double power_of[MAX_HIER], *values[MAX_HIER];
    size_t links_seen = 0;
    bool held = true;
    for (;;) {
        bool fresh = false;
        if (rv_progress_take_mesh(p, &generation, &mesh, &element, &vertex)) {
            meshes++;
            free(area);
            area = mesh_areas(&mesh);
            fresh = true;
        }
        rv_status status;
        fresh |= rv_progress_take(p, &generation, element, vertex, &status);
        if (fresh && count < MAX_HIER && meshes > 0) {
            mesh_of[count] = meshes;
            elements_of[count] = mesh.elements;
            power_of[count] = power(area, element, mesh.elements);
            values[count] = malloc(3 * mesh.elements * sizeof *element);
            memcpy(values[count++], element, 3 * mesh.elements * sizeof *element);
        }
        if (status.links > links_seen)
            links_seen = status.links;
        if (held && status.paused && status.mesh_generation > 0) {
            rv_progress_pause(p, false);
            held = false;
        }
        if (status.done && !rv_progress_take(p, &generation, NULL, NULL, NULL) &&
            status.mesh_generation == meshes)
            break;
        sleep_ms(1);
    }
    char message[512];
    assert_int_equal(rv_progress_finish(p, message, sizeof message), RAD_OK);
    assert_true(rad_solution_converged(solution));
    size_t n = rad_solution_element_count(solution);
    double *final_rgb = display(ctx, solution, false, true), *E = emission(solution);
    printf("# hierarchical: %zu snapshots, %zu meshes (%zu -> %zu elements), %zu links while solving\n", count,
           meshes, elements_of[0], n, links_seen);
    assert_true(count >= 5);
    assert_true(meshes >= 2);              /* the mesh changed during the solve */
    assert_true(elements_of[0] > patches); /* the first snapshot shows leaves, not patches */
    assert_int_equal(mesh.elements, n);
    assert_int_equal(mesh.vertices, rad_solution_vertex_count(solution));
    assert_true(links_seen > 0 && links_seen >= rad_solution_link_count(solution));
    double emitted = power(area, E, n), final_power = power(area, final_rgb, n);
    double previous = INFINITY, first = NAN;
    size_t final_first = count;
    for (size_t k = 0; k < count; k++) {
        if (k > 0)
            assert_true(elements_of[k] >= elements_of[k - 1]);
        double d = fabs(power_of[k] - final_power) / (final_power - emitted);
        if (k == 0)
            first = d;
        printf("#   snapshot %zu: mesh %zu, %zu elements, reflected power %.4f from the end\n", k, mesh_of[k],
               elements_of[k], d);
        /* Within one mesh the sweeps approach the end, up to what a
         * refinement round moves it: under 1% of the reflected power
         * (measured: 0.3 to 0.6%; a round's answer is not the end's, so
         * the last sweeps of a round may drift from the end by that
         * much), against 50% for the first sweep. */
        if (k > 0 && mesh_of[k] == mesh_of[k - 1])
            assert_true(d <= previous + 0.01);
        if (mesh_of[k] > 1)
            assert_true(d < 0.01);
        previous = d;
        if (elements_of[k] == n && final_first == count)
            final_first = k;
    }
    assert_true(first > 0.1);   /* the first sweep reflects little */
    assert_true(previous == 0.0);
    /* on the final mesh: element values toward the end, the last exactly it */
    subtract(final_rgb, E, 3 * n);
    previous = INFINITY;
    for (size_t k = final_first; k < count; k++) {
        assert_int_equal(mesh_of[k], meshes);
        subtract(values[k], E, 3 * n);
        double d = distance(values[k], final_rgb, 3 * n);
        assert_true(d <= previous * (1.0 + 1e-9) + 1e-12);
        previous = d;
    }
    assert_true(count - final_first >= 2);
    assert_true(previous == 0.0);

    /* The copied mesh draws the solution's frame, pixel for pixel. */
    double *element_rgb = display(ctx, solution, false, true), *vertex_rgb = display(ctx, solution, false, false);
    rv_renderer *from_solution = rv_renderer_create(solution, element_rgb, vertex_rgb);
    rv_renderer *from_copy = rv_renderer_create_mesh(&mesh, element_rgb, vertex_rgb);
    assert_non_null(from_solution);
    assert_non_null(from_copy);
    assert_int_equal(rv_renderer_elements(from_copy), n);
    rad_camera camera;
    assert_true(rad_scene_camera(scene, &camera));
    rv_camera view = rv_camera_from(&camera);
    rv_draw d = {.camera = &view, .width = 64, .height = 64, .shading = RAD_SHADING_SMOOTH, .output = RV_OUTPUT_RADIANCE};
    float *a = malloc(64 * 64 * 3 * sizeof *a), *b = malloc(64 * 64 * 3 * sizeof *b);
    assert_true(rv_offscreen_draw(offscreen, from_solution, &d, 1, a));
    assert_true(rv_offscreen_draw(offscreen, from_copy, &d, 1, b));
    assert_memory_equal(a, b, 64 * 64 * 3 * sizeof *a);
    free(a);
    free(b);
    rv_renderer_destroy(from_solution);
    rv_renderer_destroy(from_copy);
    free(element_rgb);
    free(vertex_rgb);

    for (size_t k = 0; k < count; k++)
        free(values[k]);
    free(final_rgb);
    free(E);
    free(area);
    free(element);
    free(vertex);
    rv_mesh_free(&mesh);
    rad_solution_destroy(solution);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

static rv_status wait_for(rv_progress *p, uint64_t *generation, uint64_t at_least, bool paused)
{
    rv_status status;
    for (int tries = 0; tries < 60000; tries++) {
        rv_progress_take(p, generation, NULL, NULL, &status);
        if (status.generation >= at_least && (!paused || status.paused))
            return status;
        assert_false(status.done);
        sleep_ms(1);
    }
    fail_msg("the worker did not get there in 60 s");
    return status;
}

static void pause_and_stop_keep_a_solution(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    rad_scene *scene = NULL;
    rv_step_slot slot = {NULL, NULL};
    rad_solution *solution = cornell(ctx, &scene, "shooting", 600, &slot, false);
    size_t n3 = 3 * rad_solution_element_count(solution);
    rv_progress *p = rv_progress_start(solution, &slot, 1, true, 0.0, true); /* held at its first step */
    assert_non_null(p);
    uint64_t generation = 0;
    rv_status paused = wait_for(p, &generation, 1, true);
    sleep_ms(200);
    rv_status later;
    assert_false(rv_progress_take(p, &generation, NULL, NULL, &later));
    assert_int_equal(later.generation, paused.generation);
    assert_int_equal(later.step.iteration, paused.step.iteration);
    assert_true(later.paused);
    rv_progress_pause(p, false);
    wait_for(p, &generation, paused.generation + 5, false);
    rv_progress_stop(p);
    double *last = malloc(n3 * sizeof *last);
    rv_status end;
    do {
        rv_progress_take(p, &generation, last, NULL, &end);
        sleep_ms(1);
    } while (!end.done);
    rv_progress_take(p, &generation, last, NULL, &end);
    char message[512];
    assert_int_equal(rv_progress_finish(p, message, sizeof message), RAD_OK);
    assert_false(rad_solution_converged(solution));
    assert_true(strstr(rad_solution_warning(solution), "RAD_STEP_FINISH") != NULL);
    printf("# stopped after %d shots: %s\n", rad_solution_iterations(solution), rad_solution_warning(solution));

    /* The last snapshot is the solution the solver kept. */
    double *kept = display(ctx, solution, true, true);
    assert_memory_equal(kept, last, n3 * sizeof *kept);

    /* It saves, and reads back the same. */
    char folder[] = "/tmp/test_viewer_XXXXXX", path[64];
    assert_non_null(mkdtemp(folder));
    snprintf(path, sizeof path, "%s/stopped.radsol", folder);
    assert_int_equal(rad_solution_save(ctx, solution, path), RAD_OK);
    rad_scene *loaded_scene = NULL;
    rad_solution *loaded = NULL;
    assert_int_equal(rad_solution_load_file(ctx, path, &loaded_scene, &loaded), RAD_OK);
    unlink(path);
    rmdir(folder);
    double *reread = display(ctx, loaded, true, true);
    assert_true(distance(reread, kept, n3) < 1e-12);

    free(reread);
    rad_solution_destroy(loaded);
    rad_scene_destroy(loaded_scene);
    free(kept);
    free(last);
    rad_solution_destroy(solution);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* ---- cameras ---- */

/* Orbiting keeps the distance to the target; the --camera text gives the
 * same camera back. */
static void camera_orbit_and_text(void **state)
{
    (void)state;
    rv_camera c = {{0.0, 1.0, 5.0}, {0.0, 1.0, 0.0}, {0.0, 1.0, 0.0}, 40.0};
    rv_camera_orbit(&c, 0.7, 0.3);
    double d = 0.0;
    for (int k = 0; k < 3; k++)
        d += (c.position[k] - c.target[k]) * (c.position[k] - c.target[k]);
    assert_true(fabs(sqrt(d) - 5.0) < 1e-12);
    assert_true(c.position[1] > 1.0); /* pitched up: the eye rises */
    char text[512];
    rv_camera_text(&c, text, sizeof text);
    rad_context *ctx = test_context(1);
    rad_camera parsed;
    assert_int_equal(rad_camera_from_string(ctx, text, &parsed), RAD_OK);
    rad_camera back = rv_camera_to(&c);
    assert_memory_equal(&parsed, &back, sizeof parsed);
    rad_context_destroy(ctx);
}

/* ---- the program: radiosity view (argv[1] is its path) ---- */

static const char *program;
static char workdir[64];

/* Run `radiosity ARGS` in the work folder, stdout and stderr into files
 * there; returns the exit status. */
static int run_view(const char *environment, const char *args)
{
    char command[2048];
    snprintf(command, sizeof command, "cd '%s' && %s '%s' view %s > out.txt 2> err.txt", workdir, environment,
             program, args);
    int status = system(command);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static char *read_file(const char *name, size_t *size)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", workdir, name);
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *text = calloc(1, 1 << 20);
    *size = fread(text, 1, (1 << 20) - 1, f);
    fclose(f);
    return text;
}

/* --offscreen writes the frame at the size asked (the PNG's header says). */
static void cli_offscreen_frame(void **state)
{
    (void)state;
    assert_int_equal(run_view("", "--offscreen -o frame.png --width 64 --height 48 --elements 300 "
                                  "--solver gauss-seidel --threads 1 -q"),
                     0);
    size_t size = 0;
    unsigned char *png = (unsigned char *)read_file("frame.png", &size);
    assert_non_null(png);
    assert_true(size > 33 && memcmp(png, "\x89PNG\r\n\x1a\n", 8) == 0);
    unsigned width = (unsigned)png[16] << 24 | (unsigned)png[17] << 16 | (unsigned)png[18] << 8 | png[19];
    unsigned height = (unsigned)png[20] << 24 | (unsigned)png[21] << 16 | (unsigned)png[22] << 8 | png[23];
    assert_int_equal(width, 64);
    assert_int_equal(height, 48);
    free(png);
    /* An unknown format: one line naming the file, no file. */
    assert_int_not_equal(run_view("", "--offscreen -o frame.xyz --elements 300 --solver gauss-seidel -q"), 0);
    size_t err_size = 0;
    char *err = read_file("err.txt", &err_size);
    assert_non_null(strstr(err, "frame.xyz"));
    free(err);
    char *none = read_file("frame.xyz", &size);
    assert_null(none);
}

/* The window, driven by --keys on SDL's off-screen video driver (no X):
 * it solves, prints the --camera of the view (the scene's, untouched:
 * exactly), saves a solution that loads, converged, and quits. */
static void cli_window_script(void **state)
{
    (void)state;
    /* Leak checking off for this child alone (ASan's other checks stay):
     * SDL's video shutdown terminates its EGL display, which unloads
     * Mesa's driver, and the driver loses 112 bytes at dlclose (Mesa 22.3,
     * frames in an unloaded module, which no suppression can name).  The
     * off-screen path, which keeps its display, is leak-checked. */
    int status = run_view("SDL_VIDEODRIVER=offscreen ASAN_OPTIONS=\"$ASAN_OPTIONS:detect_leaks=0\"",
                          "--elements 300 --threads 1 --width 160 --height 120 "
                          "--keys wait,c,s,p,q");
    if (status == RV_EXIT_NO_DEVICE) {
        printf("# the window could not open here: skipped\n");
        return;
    }
    assert_int_equal(status, 0);
    size_t size = 0;
    char *out = read_file("out.txt", &size);
    assert_non_null(out);
    const char *line = strstr(out, "--camera ");
    assert_non_null(line);
    char text[512];
    assert_int_equal(sscanf(line + 9, "%511s", text), 1);
    rad_context *ctx = test_context(1);
    rad_camera printed, expected;
    assert_int_equal(rad_camera_from_string(ctx, text, &printed), RAD_OK);
    rad_scene *box = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &box), RAD_OK);
    assert_true(rad_scene_camera(box, &expected));
    assert_memory_equal(&printed, &expected, sizeof printed);
    char path[256];
    snprintf(path, sizeof path, "%s/view.radsol", workdir);
    rad_scene *scene = NULL;
    rad_solution *solution = NULL;
    assert_int_equal(rad_solution_load_file(ctx, path, &scene, &solution), RAD_OK);
    assert_true(rad_solution_converged(solution));
    char *png = read_file("view-0001.png", &size);
    assert_non_null(png);
    free(png);
    free(out);
    rad_solution_destroy(solution);
    rad_scene_destroy(scene);
    rad_scene_destroy(box);
    rad_context_destroy(ctx);
}

int main(int argc, char **argv)
{
    char why[256];
    offscreen = rv_offscreen_create(why, sizeof why);
    if (!offscreen) {
        printf("# skipped: %s\n", why);
        return 77; /* CTest's SKIP_RETURN_CODE */
    }
    printf("# OpenGL: %s\n", rv_offscreen_renderer_name(offscreen));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(camera_orbit_and_text),
        cmocka_unit_test(offscreen_smooth_matches_render),
        cmocka_unit_test(offscreen_flat_matches_render),
        cmocka_unit_test(progressive_moves_toward_solution),
        cmocka_unit_test(progressive_hierarchical_meshes),
        cmocka_unit_test(pause_and_stop_keep_a_solution),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    if (argc > 1) {
        program = argv[1];
        snprintf(workdir, sizeof workdir, "/tmp/test_viewer_cli_XXXXXX");
        if (!mkdtemp(workdir))
            return 1;
        const struct CMUnitTest cli[] = {
            cmocka_unit_test(cli_offscreen_frame),
            cmocka_unit_test(cli_window_script),
        };
        failed += cmocka_run_group_tests_name("radiosity view", cli, NULL, NULL);
        char command[128];
        snprintf(command, sizeof command, "rm -rf '%s'", workdir);
        if (system(command) != 0)
            failed++;
    }
    rv_offscreen_destroy(offscreen);
    return failed;
}
