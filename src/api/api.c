/*
 * api.c -- the public solution object: runs the pipeline stages in order
 * and answers the per-surface questions.
 *
 *     scene --mesh--> elements --vis--> rays --formfactor--> F --solve--> B
 */
#include "api/solution.h"

#include <stdlib.h>
#include <string.h>

/* The sampling methods' per-thread scratch (ray permutations, a hemicube's
 * depth and item buffers, a row of sums) beside the dense matrix the
 * form-factor table checks: refused up front, naming the option that
 * shrinks it.  The dense matrix's own check (formfactor.c) names its way
 * out. */
static rad_result check_ff_scratch(rad_context *ctx, const rad_options *o, size_t n, int threads)
{
    const char *method = o->form_factors, *option = NULL;
    double per_thread = 8.0 * (double)n;
    if (strcmp(method, "hemisphere") == 0 || strcmp(method, "montecarlo") == 0) {
        per_thread += 4.0 * (double)(o->samples > 0 ? o->samples : 0);
        option = "rad_options.samples";
    } else if (strcmp(method, "hemicube") == 0) {
        double R = o->hemicube_resolution > 0 ? o->hemicube_resolution : 256;
        per_thread += 3.0 * R * R * 8.0; /* depth (float) and item (uint32) per pixel */
        option = "rad_options.hemicube_resolution";
    }
    double matrix = 4.0 * (double)n * (double)n;
    double scratch = per_thread * (threads > 0 ? threads : 1);
    if (option && matrix <= o->max_memory_bytes && matrix + scratch > o->max_memory_bytes)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                        "form factors: %s needs %.2f GiB of scratch on %d threads beside the "
                        "%.2f GiB matrix, above the memory limit of %.2f GiB (rad_options.max_memory_bytes); "
                        "use a smaller %s or fewer threads",
                        method, scratch / 1073741824.0, threads, matrix / 1073741824.0,
                        o->max_memory_bytes / 1073741824.0, option);
    return RAD_OK;
}

/* Area, reflectance and emission per element of `mesh` (3 per element for
 * the last two); nothing is allocated on failure. */
static rad_result element_arrays(rad_context *ctx, const rad_scene *scene, const rad_mesh *mesh, double **area,
                                 double **reflectance, double **emission)
{
    size_t n = mesh->element_count;
    double *a = rad_alloc_array(ctx, n, sizeof *a, "solution: areas");
    double *rho = rad_alloc_array(ctx, 3 * n, sizeof *rho, "solution: reflectance");
    double *E = rad_alloc_array(ctx, 3 * n, sizeof *E, "solution: emission");
    if (!a || !rho || !E) {
        free(a);
        free(rho);
        free(E);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < n; i++) {
        const rad_element *e = &mesh->elements[i];
        const rad_material *m = &scene->materials[e->material];
        a[i] = e->area;
        for (int c = 0; c < 3; c++) {
            rho[3 * i + (size_t)c] = m->reflectance[c];
            E[3 * i + (size_t)c] = m->emission[c];
        }
    }
    *area = a;
    *reflectance = rho;
    *emission = E;
    return RAD_OK;
}

rad_result rad_solution_create(rad_context *ctx, const rad_scene *scene, const rad_options *options,
                               rad_solution **out)
{
    *out = NULL;
    if (!ctx || !scene)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "rad_solution_create: NULL argument");
    rad_solution *s = calloc(1, sizeof *s);
    if (!s)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "out of memory");
    s->scene = scene;
    s->threads = rad_context_threads(ctx);
    s->seconds.load = scene->load_seconds;
    rad_result r = rad_options_resolve(ctx, options, &s->options, &s->names);
    if (r != RAD_OK) {
        free(s);
        return r;
    }

    /* 1. mesh: surfaces -> elements */
    double t = rad_seconds();
    rad_mesh_options mo = {s->options.mesh_size, s->options.target_elements,
                           s->options.crease_angle_degrees};
    /* Hierarchical: the patches are the roots; it subdivides them itself. */
    if (rad_solver_find(s->options.solver)->flags & RAD_SOLVER_HIERARCHICAL)
        mo.mesh_size = 1e30, mo.target_elements = 0;
    r = rad_mesh_build_within(ctx, scene, &mo, s->options.max_memory_bytes, &s->mesh);
    s->seconds.mesh = rad_seconds() - t;
    if (r != RAD_OK)
        goto fail;
    size_t n = s->mesh->element_count;

    /* 2. visibility: acceleration structure over the patches */
    r = rad_vis_create(ctx, s->options.visibility, s->mesh, &s->vis);
    if (r != RAD_OK)
        goto fail;
    s->seconds.visibility = s->vis->build_seconds;

    /* 3. per-element materials */
    s->radiosity = rad_alloc_array(ctx, 3 * n, sizeof *s->radiosity, "solution: radiosity");
    if (!s->radiosity || element_arrays(ctx, scene, s->mesh, &s->area, &s->reflectance, &s->emission) != RAD_OK) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto fail;
    }
    memcpy(s->radiosity, s->emission, 3 * n * sizeof *s->radiosity);

    /* 4. form factors (unless the solver computes its own on the fly) */
    if (!(rad_solver_find(s->options.solver)->flags & RAD_SOLVER_MATRIX_FREE)) {
        r = check_ff_scratch(ctx, &s->options, n, s->threads);
        if (r != RAD_OK)
            goto fail;
        rad_ff_request req = {s->mesh, s->vis, s->options.seed, s->options.shadow_rays,
                              s->options.hemicube_resolution, s->options.samples, s->options.near_field};
        r = rad_form_factors(ctx, rad_ff_find(s->options.form_factors), &req, s->options.max_memory_bytes,
                             s->options.closure_correction != 0, &s->F, &s->F_variance, &s->ff_stats);
        s->seconds.form_factors = s->ff_stats.seconds;
        if (r != RAD_OK)
            goto fail;
    } else {
        s->ff_stats.method = "none (matrix-free solver)";
    }
    *out = s;
    return RAD_OK;
fail:
    rad_solution_destroy(s);
    return r;
}

/* The solver's monitor: keeps the history, exposes the shooting ambient
 * term for display, and hands the step to the caller's on_step. */
typedef struct monitor_state {
    rad_solution *solution;
    bool keep_all;
} monitor_state;

static bool history_push(rad_solution *s, const rad_solve_step *step)
{
    if (s->history_count == s->history_capacity) {
        size_t cap = s->history_capacity ? 2 * s->history_capacity : 256;
        rad_solve_step *h = realloc(s->history, cap * sizeof *h);
        if (!h)
            return false;
        s->history = h;
        s->history_capacity = cap;
    }
    s->history[s->history_count++] = *step;
    return true;
}

static int solve_monitor(void *user, const rad_solve_step *step, const double *B, const double *ambient)
{
    monitor_state *m = user;
    rad_solution *s = m->solution;
    (void)B; /* B is s->radiosity, updated in place */
    if (ambient)
        memcpy(s->solve_stats.ambient, ambient, sizeof s->solve_stats.ambient);
    if (m->keep_all && !history_push(s, step))
        return 1;
    if (s->options.on_step)
        return s->options.on_step(s->options.on_step_user, s, step);
    return 0;
}

const rad_solve_step *rad_solution_history(const rad_solution *s, size_t *count)
{
    *count = s->history_count;
    return s->history;
}

/* The hierarchical solver makes its own elements: the solution's mesh
 * becomes its leaves (the patches, and the ray structure built on them,
 * stay), and the per-element arrays follow.  Steps go to the history only:
 * on_step would see a mesh that changes while the solver runs. */
static int hier_monitor(void *user, const rad_solve_step *step, const double *B, const double *ambient)
{
    (void)B, (void)ambient;
    rad_solution *s = user;
    return s->options.record_history && !history_push(s, step);
}

static rad_result solve_hierarchical(rad_context *ctx, rad_solution *s)
{
    const rad_mesh *base = s->hier_base ? s->hier_base : s->mesh;
    rad_hier_params hp = {.scene = s->scene,
                          .base = base,
                          .vis = s->vis,
                          .epsilon = s->options.epsilon,
                          .min_area = s->options.min_area,
                          .clustering = s->options.clustering,
                          .classic_oracle = s->options.classic_oracle != 0,
                          .closure_correction = s->options.closure_correction != 0,
                          .seed = s->options.seed,
                          .shadow_rays = s->options.shadow_rays,
                          .tolerance = s->options.tolerance,
                          .max_iterations = s->options.max_iterations,
                          .max_memory = s->options.max_memory_bytes,
                          .crease_angle_degrees = s->options.crease_angle_degrees,
                          .monitor = hier_monitor,
                          .monitor_user = s};
    memset(&s->solve_stats, 0, sizeof s->solve_stats);
    s->solve_stats.method = "hierarchical";
    s->solve_stats.unshot = NAN;
    s->history_count = 0;
    double t = rad_seconds();
    rad_mesh *leaves = NULL;
    double *B = NULL;
    rad_result r = rad_hier_run(ctx, &hp, &leaves, &B, &s->solve_stats, &s->hier_stats);
    s->solve_stats.seconds = rad_seconds() - t;
    s->seconds.solve = s->solve_stats.seconds;
    if (leaves) {
        double *area, *rho, *E;
        if (element_arrays(ctx, s->scene, leaves, &area, &rho, &E) != RAD_OK) {
            free(B);
            rad_mesh_destroy(leaves);
            return RAD_ERROR_OUT_OF_MEMORY;
        }
        if (!s->hier_base)
            s->hier_base = s->mesh;
        else
            rad_mesh_destroy(s->mesh);
        s->mesh = leaves;
        free(s->area);
        free(s->reflectance);
        free(s->emission);
        free(s->radiosity);
        s->area = area;
        s->reflectance = rho;
        s->emission = E;
        s->radiosity = B;
    }
    rad_solve_step last = {s->solve_stats.iterations, s->solve_stats.seconds, s->solve_stats.residual, NAN};
    if (s->history_count == 0 || s->history[s->history_count - 1].iteration < last.iteration)
        history_push(s, &last);
    s->solved = r == RAD_OK;
    free(s->vertex_radiosity);
    s->vertex_radiosity = NULL;
    return r;
}

rad_result rad_solution_solve(rad_context *ctx, rad_solution *s)
{
    if (!rad_scene_has_emitter(s->scene))
        return rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                        "%s: the scene has no emitter (no material with Ke > 0): nothing to light it",
                        s->scene->source);
    if (rad_solver_find(s->options.solver)->flags & RAD_SOLVER_HIERARCHICAL)
        return solve_hierarchical(ctx, s);
    rad_system sys = {.n = s->mesh->element_count,
                      .F = s->F,
                      .area = s->area,
                      .reflectance = s->reflectance,
                      .emission = s->emission,
                      .threads = s->threads,
                      .mesh = s->mesh,
                      .vis = s->vis,
                      .seed = s->options.seed,
                      .samples = s->options.samples,
                      .max_memory = s->options.max_memory_bytes};
    monitor_state m = {s, s->options.record_history != 0};
    rad_solve_params p = {s->options.tolerance, s->options.unshot_tolerance, s->options.max_iterations,
                          s->options.relaxation, NULL, &m};
    if (m.keep_all || s->options.on_step)
        p.monitor = solve_monitor;
    const rad_solver *solver = rad_solver_find(s->options.solver);
    memcpy(s->radiosity, s->emission, 3 * sys.n * sizeof *s->radiosity);
    memset(&s->solve_stats, 0, sizeof s->solve_stats);
    s->history_count = 0;
    s->solve_stats.method = solver->name;
    s->solve_stats.unshot = NAN; /* shooting solvers measure it */
    s->solve_stats.absorbed = NAN; /* matrix-free solvers report it */
    double t = rad_seconds();
    /* Independent groups of elements (rooms that cannot see each other) are
     * solved separately; one group is solved as is. */
    rad_result r = rad_solve_by_components(ctx, solver, &sys, &p, s->radiosity, &s->solve_stats);
    s->solve_stats.seconds = rad_seconds() - t;
    /* The final state always ends the history: as a new row, or completing
     * the last one where it was the same step with the residual unmeasured.
     * (Steps count across independent groups, so the last row's iteration
     * can exceed the largest group's count.) */
    rad_solve_step last = {s->solve_stats.iterations, s->solve_stats.seconds, s->solve_stats.residual,
                           s->solve_stats.unshot};
    rad_solve_step *tail = s->history_count ? &s->history[s->history_count - 1] : NULL;
    if (!tail || tail->iteration < last.iteration) {
        history_push(s, &last);
    } else {
        if (isnan(tail->residual))
            tail->residual = last.residual;
        if (isnan(tail->unshot))
            tail->unshot = last.unshot;
    }
    s->seconds.solve = s->solve_stats.seconds;
    s->solved = r == RAD_OK;
    free(s->vertex_radiosity);
    s->vertex_radiosity = NULL;
    return r;
}

void rad_solution_destroy(rad_solution *s)
{
    if (!s)
        return;
    rad_vis_destroy(s->vis);
    rad_mesh_destroy(s->mesh);
    rad_mesh_destroy(s->hier_base);
    free(s->F);
    free(s->F_variance);
    free(s->history);
    free(s->area);
    free(s->reflectance);
    free(s->emission);
    free(s->radiosity);
    free(s->vertex_radiosity);
    free(s);
}

size_t rad_solution_element_count(const rad_solution *s) { return s->mesh->element_count; }
double rad_solution_residual(const rad_solution *s) { return s->solve_stats.residual; }
int rad_solution_iterations(const rad_solution *s) { return s->solve_stats.iterations; }

void rad_solution_surface_radiosity(const rad_solution *s, size_t surface, double rgb[3])
{
    double sum[3] = {0, 0, 0}, area = 0.0;
    for (size_t i = 0; i < s->mesh->element_count; i++) {
        if (s->mesh->elements[i].surface != surface)
            continue;
        area += s->area[i];
        for (int c = 0; c < 3; c++)
            sum[c] += s->area[i] * s->radiosity[3 * i + c];
    }
    for (int c = 0; c < 3; c++)
        rgb[c] = area > 0.0 ? sum[c] / area : 0.0;
}

void rad_solution_surface_view_factors(const rad_solution *s, double *F)
{
    size_t S = s->scene->surface_count, n = s->mesh->element_count;
    if (!s->F) { /* matrix-free: no factors were computed */
        memset(F, 0, S * S * sizeof *F);
        return;
    }
    double *area = calloc(S ? S : 1, sizeof *area);
    memset(F, 0, S * S * sizeof *F);
    for (size_t i = 0; i < n; i++) {
        uint32_t si = s->mesh->elements[i].surface;
        if (area)
            area[si] += s->area[i];
        const float *Fi = s->F + i * n;
        double *row = F + (size_t)si * S;
        for (size_t j = 0; j < n; j++)
            row[s->mesh->elements[j].surface] += s->area[i] * Fi[j];
    }
    for (size_t a = 0; a < S; a++)
        for (size_t b = 0; b < S; b++)
            F[a * S + b] = area && area[a] > 0.0 ? F[a * S + b] / area[a] : 0.0;
    free(area);
}

void rad_solution_power(const rad_solution *s, double *emitted, double *absorbed)
{
    /* Per-element absorption in parallel, summed in order (thread-independent). */
    size_t n = s->mesh->element_count;
    if (!s->F) { /* matrix-free: the solver measured what it deposited */
        double em = 0.0;
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++)
                em += s->area[i] * s->emission[3 * i + c];
        *emitted = em / 3.0;
        *absorbed = s->solve_stats.absorbed;
        return;
    }
    double *absorbed_by = malloc((n ? n : 1) * sizeof *absorbed_by);
    double em = 0.0, ab = 0.0;
    if (!absorbed_by) {
        *emitted = *absorbed = NAN;
        return;
    }
#pragma omp parallel for schedule(static) num_threads(s->threads)
    for (size_t i = 0; i < n; i++) {
        double h[3];
        rad_gather(s->F + i * n, s->radiosity, n, h);
        double a = 0.0;
        for (int c = 0; c < 3; c++)
            a += s->area[i] * (1.0 - s->reflectance[3 * i + c]) * h[c];
        absorbed_by[i] = a;
    }
    for (size_t i = 0; i < n; i++) {
        ab += absorbed_by[i];
        for (int c = 0; c < 3; c++)
            em += s->area[i] * s->emission[3 * i + c];
    }
    free(absorbed_by);
    *emitted = em / 3.0;
    *absorbed = ab / 3.0;
}

rad_result rad_solution_render(rad_context *ctx, rad_solution *s, const rad_render_options *options,
                               rad_image **out)
{
    *out = NULL;
    rad_render_options o = options ? *options : (rad_render_options){0};
    size_t n = s->mesh->element_count;
    /* Display values: a partial shooting solution gets the ambient term. */
    double *display = rad_alloc_array(ctx, 3 * n, sizeof *display, "render: element values");
    if (!display)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            display[3 * i + c] = s->radiosity[3 * i + c] +
                                 s->reflectance[3 * i + c] * s->solve_stats.ambient[c];
    free(s->vertex_radiosity);
    s->vertex_radiosity = rad_alloc_array(ctx, 3 * s->mesh->vertex_count, sizeof *s->vertex_radiosity,
                                          "render: vertex values");
    if (!s->vertex_radiosity) {
        free(display);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    double t = rad_seconds();
    rad_result r = rad_vertex_values(ctx, s->mesh, display, s->vertex_radiosity);
    if (r != RAD_OK) {
        free(display);
        return r;
    }
    rad_render_input in;
    in.mesh = s->mesh;
    in.vis = s->vis;
    in.element_radiosity = display;
    in.vertex_radiosity = s->vertex_radiosity;
    int w = o.width > 0 ? o.width : 512, h = o.height > 0 ? o.height : 512;
    /* The image (3 floats a pixel) and its 8-bit copy for PNG. */
    double image_bytes = 15.0 * (double)w * (double)h;
    if (w <= 16384 && h <= 16384 && image_bytes > s->options.max_memory_bytes) {
        free(display);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                        "render: a %dx%d image needs %.2f GiB, above the memory limit of %.2f GiB "
                        "(rad_options.max_memory_bytes); use a smaller rad_render_options.width / "
                        "rad_render_options.height",
                        w, h, image_bytes / 1073741824.0, s->options.max_memory_bytes / 1073741824.0);
    }
    if (o.camera)
        in.camera = *o.camera;
    else if (!rad_scene_camera(s->scene, &in.camera))
        in.camera = rad_camera_frame(s->scene->bounds_min, s->scene->bounds_max, (double)w / h);
    r = rad_render_image(ctx, &in, &o, out);
    s->seconds.render = rad_seconds() - t;
    int spp = o.samples > 0 ? o.samples : 4;
    s->render_rays = (uint64_t)w * (uint64_t)h * (uint64_t)spp * (uint64_t)spp;
    free(display);
    return r;
}

rad_result rad_camera_from_string(rad_context *ctx, const char *text, rad_camera *camera)
{
    return rad_camera_parse(ctx, text, camera);
}

int rad_method_info(rad_method_kind kind, size_t index, const char **name, const char **description)
{
    size_t count = 0;
    switch (kind) {
    case RAD_METHOD_FORM_FACTOR:
        while (rad_ff_methods[count])
            count++;
        if (index >= count)
            return 0;
        *name = rad_ff_methods[index]->name;
        *description = rad_ff_methods[index]->description;
        return 1;
    case RAD_METHOD_SOLVER:
        while (rad_solvers[count])
            count++;
        if (index >= count)
            return 0;
        *name = rad_solvers[index]->name;
        *description = rad_solvers[index]->description;
        return 1;
    case RAD_METHOD_VISIBILITY:
        while (rad_vis_backends[count])
            count++;
        if (index >= count)
            return 0;
        *name = rad_vis_backends[index]->name;
        *description = rad_vis_backends[index]->description;
        return 1;
    }
    return 0;
}
