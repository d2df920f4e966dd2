/*
 * api.c -- the public solution object: resolves the options, hands the
 * work to the strategy that answers to the solver's name (strategy/), keeps
 * the convergence history, and answers questions through the strategy's
 * read-only view.  The public calls that take a solution and belong to a
 * room below (the writers, the grids' illuminance, false colour) unpack it
 * here and hand that room the view.  What a solver can do is asked of its
 * capability bits (rad_strategy_capabilities), never of its name.
 *
 *     options --> strategy: mesh -> visibility -> couplings -> B --> view
 */
#include "api/solution.h"
#include "grid/grid.h"
#include "strategy/saved.h"
#include "solve/vpl.h"
#include "light/light.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* The view downstream code reads, after the strategy changed its state. */
static void refresh_view(rad_solution *s)
{
    s->strategy->view(s->state, &s->view);
    /* on_step ended it: the iterate is the result, with its own warning */
    s->view.ended_early = s->finished_early ? s->finish_warning : NULL;
    if (s->finished_early)
        s->view.solved = true;
    s->view.scene = s->scene;
    s->view.options = &s->options;
    s->view.threads = s->threads;
}

rad_result rad_solution_create(rad_context *ctx, const rad_scene *scene, const rad_options *options,
                               rad_solution **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !scene || !out)
        return rad_null_argument(ctx, __func__);
    rad_solution *s = rad_alloc(ctx, RAD_MEM_SOLVER, 1, sizeof *s, "solution");
    if (!s)
        return RAD_ERROR_OUT_OF_MEMORY;
    s->ctx = ctx;
    s->scene = scene;
    s->threads = rad_context_threads(ctx);
    rad_result r = rad_options_resolve(ctx, options, &s->options, &s->names);
    if (r != RAD_OK) {
        rad_free(s);
        return r;
    }
    /* One limit: the context's, or the solution's own where lower. */
    rad_memory_limit_call(ctx, s->options.max_memory_bytes);
    s->options.max_memory_bytes = rad_memory_limit(ctx);
    /* mesh -> visibility -> couplings, as the strategy does them */
    s->strategy = rad_strategy_for_solver(s->options.solver);
    /* The first pass's light through mirrors is the dense solvers' and the
     * hierarchy's (RAD_CAN_MIRRORS; formfactor/ff_mirror.c, hier/mirror.c),
     * a solver that reads F through reciprocity refuses it, the others
     * solve the diffuse part alone. */
    bool mirrors = false;
    for (size_t m = 0; m < scene->material_count; m++)
        mirrors |= scene->materials[m].specular_kind == RAD_SPECULAR_MIRROR;
    unsigned can = rad_strategy_capabilities(s->options.solver);
    if (mirrors && (can & RAD_REFUSES_MIRRORS)) {
        /* The message first: the solver's name lives in s. */
        r = rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                     "%s: solver '%s' reads F_ji through reciprocity, which light through mirrors "
                     "does not keep; use gauss-seidel, jacobi, direct or conjugate-gradient",
                     scene->source, s->options.solver);
        rad_free(s);
        return r;
    }
    if (mirrors && !(can & RAD_CAN_MIRRORS))
        rad_warn(ctx,
                 "%s: solver '%s' does not carry light through mirrors (the first pass's mirror images "
                 "are the dense and hierarchical solvers'); the render's second pass still shows them",
                 scene->source, s->options.solver);
    r = s->strategy->create(ctx, scene, &s->options, &s->state);
    if (r != RAD_OK) {
        rad_free(s);
        return r;
    }
    s->view.seconds.load = scene->load_seconds;
    refresh_view(s);
    *out = s;
    return RAD_OK;
}

static bool history_push(rad_solution *s, const rad_solve_step *step)
{
    if (s->history_count == s->history_capacity) {
        size_t cap = s->history_capacity ? 2 * s->history_capacity : 256;
        rad_solve_step *h = rad_realloc(s->ctx, RAD_MEM_SOLVER, s->history, cap, sizeof *h, "solve: history");
        if (!h) {
            s->history_failed = true;
            return false;
        }
        s->history = h;
        s->history_capacity = cap;
    }
    s->history[s->history_count++] = *step;
    return true;
}

/* Every step: kept in the history when asked, and handed to the caller's
 * on_step where the view shows the iterate (progressive display). */
static int on_strategy_step(void *user, const rad_solve_step *step, bool displayable)
{
    rad_solution *s = user;
    if (s->options.record_history && !history_push(s, step))
        return 1;
    if (displayable && s->options.on_step) {
        /* Adaptive subdivision remeshes between solves: the view anew, and
         * point values made again on demand. */
        refresh_view(s);
        rad_free(s->point_values);
        s->point_values = NULL;
        int stop = s->options.on_step(s->options.on_step_user, s, step);
        if (stop == RAD_STEP_FINISH)
            s->finish_asked = true;
        return stop;
    }
    return 0;
}

/* Conservation bounds every solution: when no element gathers more than
 * its whole hemisphere (rows of F summing to at most 1), B_i <= E_max /
 * (1 - rho_max) for every element (the maximum norm of rho F is below
 * rho_max).  Estimated factors can break that premise: Monte Carlo rows
 * reaching 2.8 on hostile geometry made Gauss-Seidel return B = 1e66 as a
 * success (fuzz_solve).  A solution four times over the bound, or not
 * finite, is refused; its values stay readable for inspection.  Not
 * checked where rho_max >= 1 (refused at scene validation anyway). */
static rad_result check_bounded(rad_context *ctx, const rad_solution_view *v)
{
    double e_max = 0.0, rho_max = 0.0;
    for (size_t i = 0; i < 3 * v->n; i++) {
        e_max = fmax(e_max, v->emission[i]);
        rho_max = fmax(rho_max, v->reflectance[i]);
    }
    if (!(rho_max < 1.0))
        return RAD_OK;
    double bound = 4.0 * e_max / (1.0 - rho_max);
    /* Galerkin's linear elements (vertex values of their own) project the
     * radiosity onto their basis, which undershoots beside a shadow's edge
     * (Gibbs): element means a little below 0 are that answer, not
     * divergence.  1e-3 of the bound: 5 times the Cornell box's worst at
     * 300 elements (-2e-4 of it). */
    double below = v->vertex_radiosity ? 1e-3 * bound : 1e-9 * bound;
    for (size_t i = 0; i < 3 * v->n; i++) {
        double b = v->radiosity[i];
        if (isfinite(b) && b >= -below && b <= bound)
            continue;
        const rad_element *e = &v->mesh->elements[i / 3];
        char rows[160] = "";
        if (v->F && v->ff->row_sum_max > 1.0)
            snprintf(rows, sizeof rows, "; the form factors ('%s') have rows summing to %.3g, above 1",
                     v->ff->method, v->ff->row_sum_max);
        return rad_fail(ctx, RAD_ERROR_NUMERICAL,
                        "the solution diverged: element %zu (surface '%s') has B = %.3g W/m^2, outside "
                        "[0, %.3g], four times what conservation allows (E_max / (1 - rho_max))%s; "
                        "more samples or the analytic method (rad_options.form_factors) keep the "
                        "factors within their hemisphere",
                        i / 3, rad_scene_surface_name(v->scene, e->surface), b, bound, rows);
    }
    return RAD_OK;
}

rad_result rad_solution_solve(rad_context *ctx, rad_solution *s)
{
    rad_api_enter(ctx);
    if (!ctx || !s)
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    if (!rad_scene_has_emitter(s->scene) && !rad_light_present(s->scene))
        return rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                        "%s: the scene has no emitter (no material with Ke > 0, no luminaire, no daylight): "
                        "nothing to light it",
                        s->scene->source);
    rad_step_hook hook = {NULL, s, s->options.on_step != NULL};
    if (s->options.record_history || s->options.on_step)
        hook.fn = on_strategy_step;
    s->history_count = 0;
    s->history_failed = false;
    rad_free(s->vertex_radiosity);
    s->vertex_radiosity = NULL;
    rad_free(s->point_values);
    s->point_values = NULL;
    s->finish_asked = s->finished_early = false;
    rad_result r = s->strategy->solve(ctx, s->state, &hook);
    if (r == RAD_ERROR_INTERRUPTED && s->finish_asked && !rad_context_cancelled(ctx)) {
        /* Ended by on_step with RAD_STEP_FINISH: a result, not an interruption. */
        s->finished_early = true;
        r = RAD_OK;
        size_t last = s->history_count;
        snprintf(s->finish_warning, sizeof s->finish_warning,
                 "the solve was ended by on_step (RAD_STEP_FINISH) after %d iterations, before its tolerance",
                 last ? s->history[last - 1].iteration : s->view.solve->iterations);
    }
    refresh_view(s);
    if (r == RAD_OK)
        r = check_bounded(ctx, &s->view);
    /* The final state always ends the history: as a new row, or completing
     * the last one where it was the same step with the residual unmeasured.
     * (Steps count across independent groups, so the last row's iteration
     * can exceed the largest group's count.) */
    const rad_solve_stats *st = s->view.solve;
    rad_solve_step last = {st->iterations, st->seconds, st->residual, st->unshot};
    rad_solve_step *tail = s->history_count ? &s->history[s->history_count - 1] : NULL;
    if (!tail || tail->iteration < last.iteration) {
        history_push(s, &last);
    } else {
        if (isnan(tail->residual))
            tail->residual = last.residual;
        if (isnan(tail->unshot))
            tail->unshot = last.unshot;
    }
    /* A history that could not grow stopped the solve (or lost its last row):
     * out of memory, as the allocator's message says, not an interruption. */
    return s->history_failed ? RAD_ERROR_OUT_OF_MEMORY : r;
}

const rad_solve_step *rad_solution_history(const rad_solution *s, size_t *count)
{
    if (!s || !count) {
        if (count)
            *count = 0;
        return NULL;
    }
    *count = s->history_count;
    return s->history;
}

void rad_solution_destroy(rad_solution *s)
{
    if (!s)
        return;
    if (s->strategy)
        s->strategy->destroy(s->state);
    rad_free(s->history);
    rad_free(s->vertex_radiosity);
    rad_free(s->point_values);
    rad_free(s);
}

size_t rad_solution_element_count(const rad_solution *s) { return s ? s->view.n : 0; }
double rad_solution_residual(const rad_solution *s) { return s ? s->view.solve->residual : NAN; }
int rad_solution_iterations(const rad_solution *s) { return s ? s->view.solve->iterations : 0; }
bool rad_solution_converged(const rad_solution *s)
{
    return s && s->view.solved && !s->finished_early && s->view.solve->converged;
}
const char *rad_solution_warning(const rad_solution *s)
{
    if (s && s->finished_early)
        return s->finish_warning;
    return s && s->view.solved && !s->view.solve->converged ? s->view.solve->warning : "";
}

void rad_solution_surface_radiosity(const rad_solution *s, size_t surface, double rgb[3])
{
    if (!rgb)
        return;
    if (!s) {
        rgb[0] = rgb[1] = rgb[2] = 0.0;
        return;
    }
    rad_view_surface_radiosity(&s->view, surface, rgb);
}

void rad_solution_surface_view_factors(const rad_solution *s, double *F)
{
    if (s && F)
        rad_view_surface_view_factors(s->ctx, &s->view, F);
}

void rad_solution_power(const rad_solution *s, double *emitted, double *absorbed)
{
    double unused_emitted, unused_absorbed;
    emitted = emitted ? emitted : &unused_emitted;
    absorbed = absorbed ? absorbed : &unused_absorbed;
    if (!s) {
        *emitted = *absorbed = NAN;
        return;
    }
    rad_view_power(s->ctx, &s->view, emitted, absorbed);
}

size_t rad_solution_vertex_count(const rad_solution *s) { return s && s->view.mesh ? s->view.mesh->vertex_count : 0; }

bool rad_solution_vertex_position(const rad_solution *s, size_t vertex, double xyz[3])
{
    if (!s || !xyz || vertex >= rad_solution_vertex_count(s))
        return false;
    vec3 p = s->view.mesh->vertices[vertex];
    xyz[0] = p.x, xyz[1] = p.y, xyz[2] = p.z;
    return true;
}

rad_result rad_solution_vertex_radiosity(rad_context *ctx, const rad_solution *s, double *rgb)
{
    rad_api_enter(ctx);
    if (!ctx || !s || !rgb)
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    return rad_view_vertex_values(ctx, &s->view, s->view.radiosity, rgb);
}

/* The element, or NULL when out of range. */
static const rad_element *element_at(const rad_solution *s, size_t element)
{
    return s && element < s->view.n ? &s->view.mesh->elements[element] : NULL;
}

int rad_solution_element_vertices(const rad_solution *s, size_t element, size_t vertex[4])
{
    const rad_element *e = element_at(s, element);
    if (!e || !vertex)
        return 0;
    for (uint32_t k = 0; k < e->vertex_count; k++)
        vertex[k] = e->vertex[k];
    return (int)e->vertex_count;
}

size_t rad_solution_element_surface(const rad_solution *s, size_t element)
{
    const rad_element *e = element_at(s, element);
    return e ? e->surface : SIZE_MAX;
}

double rad_solution_element_area(const rad_solution *s, size_t element)
{
    return element_at(s, element) ? s->view.area[element] : 0.0;
}

bool rad_solution_element_geometry(const rad_solution *s, size_t element, double normal[3], double centroid[3])
{
    const rad_element *e = element_at(s, element);
    if (!e)
        return false;
    if (normal)
        normal[0] = e->normal.x, normal[1] = e->normal.y, normal[2] = e->normal.z;
    if (centroid)
        centroid[0] = e->centroid.x, centroid[1] = e->centroid.y, centroid[2] = e->centroid.z;
    return true;
}

bool rad_solution_element_values(const rad_solution *s, size_t element, double reflectance[3], double emission[3],
                                 double radiosity[3])
{
    if (!element_at(s, element))
        return false;
    for (int c = 0; c < 3; c++) {
        if (reflectance)
            reflectance[c] = s->view.reflectance[3 * element + (size_t)c];
        if (emission)
            emission[c] = s->view.emission[3 * element + (size_t)c];
        if (radiosity)
            radiosity[c] = s->view.radiosity[3 * element + (size_t)c];
    }
    return true;
}

/* Each element's radiosity plus the ambient term of a partial shooting
 * solution, in display (3n).  Never below 0: overshooting (Southwell with
 * relaxation above 1) makes the unshot light, and so the ambient term,
 * negative on purpose.  Cannot fail. */
static void display_elements(const rad_solution *s, double *display)
{
    size_t n = s->view.mesh->element_count;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            display[3 * i + c] = fmax(s->view.radiosity[3 * i + c] +
                                          s->view.reflectance[3 * i + c] * s->view.solve->ambient[c],
                                      0.0);
}

/* What is displayed: each element's radiosity (plus the ambient term of a
 * partial shooting solution) in *display (3n, rad_free it), and the vertex
 * values interpolated from it in s->vertex_radiosity. */
static rad_result display_values(rad_context *ctx, rad_solution *s, double **display_out)
{
    size_t n = s->view.mesh->element_count;
    double *display = rad_alloc(ctx, RAD_MEM_RENDER, 3 * n, sizeof *display, "render: element values");
    if (!display)
        return RAD_ERROR_OUT_OF_MEMORY;
    display_elements(s, display);
    rad_free(s->vertex_radiosity);
    s->vertex_radiosity = rad_alloc(ctx, RAD_MEM_RENDER, 3 * s->view.mesh->vertex_count, sizeof *s->vertex_radiosity,
                                    "render: vertex values");
    if (!s->vertex_radiosity) {
        rad_free(display);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    rad_result r = rad_view_vertex_values(ctx, &s->view, display, s->vertex_radiosity);
    if (r != RAD_OK) {
        rad_free(display);
        return r;
    }
    *display_out = display;
    return RAD_OK;
}

/* What the final gather draws (render/render.h): the mesh (the solved one,
 * or for a hierarchical solution a uniform one of the same patches), its
 * elements' reflectance and emission, the residual the picture
 * interpolates and its vertex values, and the emitters. */
typedef struct render_gather {
    rad_direct_light direct;
    rad_mesh *own_mesh;           /* NULL: the solved mesh */
    double *reflectance, *emission, *residual, *vertex; /* 3 per element (vertex: per vertex) */
} render_gather;

static void render_gather_free(render_gather *g)
{
    rad_direct_light_free(&g->direct);
    rad_mesh_destroy(g->own_mesh);
    rad_free(g->reflectance);
    rad_free(g->emission);
    rad_free(g->residual);
    rad_free(g->vertex);
    memset(g, 0, sizeof *g);
}

/* Fill *g for solution s with display values `display`; nothing emits, too
 * much does, or the scene is beyond the gather's limits (render.h):
 * g->direct inactive, nothing else kept.  Fails only for memory. */
static rad_result render_gather_make(rad_context *ctx, const rad_solution *s, const double *display,
                                     render_gather *g)
{
    const rad_solution_view *v = &s->view;
    memset(g, 0, sizeof *g);
    if (v->mesh->patch_count > RAD_INDIRECT_MAX_PATCHES || v->mesh->element_count > RAD_INDIRECT_MAX_ELEMENTS)
        return RAD_OK;
    rad_result r = rad_render_mesh_create(ctx, s->scene, v->mesh, s->options.crease_angle_degrees, &g->own_mesh);
    if (r != RAD_OK)
        return r;
    const rad_mesh *mesh = g->own_mesh ? g->own_mesh : v->mesh;
    size_t n = mesh->element_count;
    double *work = rad_alloc(ctx, RAD_MEM_RENDER, 9 * n + 1, sizeof *work, "render: gather arrays");
    g->reflectance = rad_alloc(ctx, RAD_MEM_RENDER, 3 * n + 1, sizeof *g->reflectance, "render: reflectance");
    g->emission = rad_alloc(ctx, RAD_MEM_RENDER, 3 * n + 1, sizeof *g->emission, "render: emission");
    g->residual = rad_alloc(ctx, RAD_MEM_RENDER, 3 * n + 1, sizeof *g->residual, "render: residual");
    g->vertex = rad_alloc(ctx, RAD_MEM_RENDER, 3 * mesh->vertex_count + 1, sizeof *g->vertex, "render: vertex values");
    if (!work || !g->reflectance || !g->emission || !g->residual || !g->vertex) {
        rad_free(work);
        render_gather_free(g);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    /* The elements' B, luminaires' and daylight's direct irradiance, and
     * self-emission (the emission less that light's first reflection). */
    double *B = work, *direct = work + 3 * n, *self = work + 6 * n;
    if (g->own_mesh) {
        const double *from[3] = {v->reflectance, v->emission, v->direct};
        double *to[3] = {g->reflectance, g->emission, direct};
        rad_render_mesh_sample(v->mesh, s->vertex_radiosity, from, 3, mesh, B, to);
    } else {
        memcpy(B, display, 3 * n * sizeof *B);
        memcpy(g->reflectance, v->reflectance, 3 * n * sizeof *B);
        memcpy(g->emission, v->emission, 3 * n * sizeof *B);
        for (size_t i = 0; i < 3 * n; i++)
            direct[i] = v->direct ? v->direct[i] : 0.0;
    }
    for (size_t i = 0; i < 3 * n; i++)
        self[i] = fmax(g->emission[i] - g->reflectance[i] * direct[i], 0.0);
    r = rad_direct_light_create(ctx, mesh, v->vis, self, s->options.seed, &g->direct);
    bool gathered = false;
    if (r == RAD_OK && rad_direct_light_active(&g->direct))
        r = rad_indirect_residual(ctx, &g->direct, B, self, g->reflectance, v->direct ? direct : NULL,
                                  ctx->threads, g->residual, &gathered);
    /* Beyond the gather's limits (render.h) the picture is the elements'
     * alone, as it was: a gather of the direct light over elements that
     * large scenes leave coarse would cost more than it mends. */
    if (r == RAD_OK && !gathered)
        rad_direct_light_free(&g->direct);
    if (r == RAD_OK && rad_direct_light_active(&g->direct))
        r = rad_vertex_values(ctx, mesh, g->residual, g->vertex);
    rad_free(work);
    if (r != RAD_OK || !rad_direct_light_active(&g->direct))
        render_gather_free(g);
    return r;
}

rad_result rad_solution_render(rad_context *ctx, rad_solution *s, const rad_render_options *options,
                               rad_image **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !s || !out)
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    rad_render_options o = options ? *options : (rad_render_options){0};
    double *display = NULL;
    double t = rad_seconds();
    rad_result r = display_values(ctx, s, &display);
    if (r != RAD_OK)
        return r;
    rad_render_input in;
    in.mesh = s->view.mesh;
    in.vis = s->view.vis;
    in.element_radiosity = display;
    in.vertex_radiosity = s->vertex_radiosity;
    in.materials = rad_scene_has_specular(s->scene) ? s->scene->materials : NULL;
    in.daylight = s->scene->daylight;
    int w = o.width > 0 ? o.width : 512, h = o.height > 0 ? o.height : 512;
    /* The image (3 floats a pixel) and its 8-bit copy for PNG. */
    double image_bytes = 15.0 * (double)w * (double)h;
    if (w <= 16384 && h <= 16384 && image_bytes > s->options.max_memory_bytes) {
        rad_free(display);
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
    /* Per-pixel instant radiosity: its VPLs, for this image only. */
    rad_vpl_set vpls = {0};
    in.vpls = NULL;
    in.reflectance = s->view.reflectance;
    in.emission = s->view.emission;
    in.seed = s->options.seed;
    in.scene = s->scene;
    if (o.vpl_paths < 0 || o.vpl_paths > 10000000) {
        rad_free(display);
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "rad_render_options.vpl_paths must be in [1, 10000000], got %d (0: off)", o.vpl_paths);
    }
    if (o.vpl_paths > 0) {
        r = rad_vpl_create(ctx, s->view.mesh, s->view.vis, s->view.reflectance, s->view.emission,
                           (size_t)o.vpl_paths, s->options.seed, &vpls);
        if (r != RAD_OK) {
            rad_free(display);
            return r;
        }
        in.vpls = &vpls;
    }
    /* The final gather (render/render.h): the residual B - rho D drawn
     * smooth, the emitters' direct light added at each shading point.  Not
     * with per-pixel VPLs (they gather it themselves), nor flat (which shows
     * the elements as solved), nor where the vertex values are the
     * solution's own unknowns (Galerkin's linear elements). */
    render_gather gather = {0};
    in.direct = NULL;
    if (o.direct_gather < -1 || o.direct_gather > 1) {
        rad_vpl_free(&vpls);
        rad_free(display);
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "rad_render_options.direct_gather must be in [-1, 1], got %d", o.direct_gather);
    }
    if (o.direct_gather >= 0 && o.vpl_paths == 0 && o.shading != RAD_SHADING_FLAT && !s->view.vertex_radiosity &&
        s->view.vis)
        r = render_gather_make(ctx, s, display, &gather);
    if (r == RAD_OK && rad_direct_light_active(&gather.direct)) {
        in.direct = &gather.direct;
        in.mesh = gather.direct.mesh;
        in.element_radiosity = gather.residual;
        in.vertex_radiosity = gather.vertex;
        in.reflectance = gather.reflectance;
        in.emission = gather.emission;
    }
    if (r == RAD_OK)
        r = rad_render_image(ctx, &in, &o, out);
    render_gather_free(&gather);
    rad_vpl_free(&vpls);
    s->view.seconds.render = rad_seconds() - t;
    int spp = o.samples > 0 ? o.samples : 4;
    s->view.render_rays = (uint64_t)w * (uint64_t)h * (uint64_t)spp * (uint64_t)spp;
    rad_free(display);
    return r;
}

rad_result rad_solution_point_radiosity(rad_context *ctx, rad_solution *s, size_t surface,
                                       const double point[3], double rgb[3])
{
    rad_api_enter(ctx);
    if (rgb)
        rgb[0] = rgb[1] = rgb[2] = NAN;
    if (!ctx || !s || !point || !rgb)
        return rad_null_argument(ctx, __func__);
    if (surface >= s->scene->surface_count)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "point radiosity: surface %zu of %zu", surface,
                        s->scene->surface_count);
    vec3 p = v3(point[0], point[1], point[2]);
    if (!v3_finite(p))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "point radiosity: the point is not finite");
    /* The nearest point of the surface's patches: parameters clamped to
     * the patch (the unit square, or the triangle s, t >= 0, s + t <= 1). */
    const rad_mesh *mesh = s->view.mesh;
    double best = INFINITY, best_s = 0.0, best_t = 0.0;
    uint32_t best_patch = 0;
    for (size_t i = 0; i < mesh->patch_count; i++) {
        const rad_patch *patch = &mesh->patches[i];
        if (patch->surface != surface)
            continue;
        double ps, pt;
        rad_patch_parameters(patch, p, &ps, &pt);
        ps = fmin(fmax(ps, 0.0), 1.0);
        pt = fmin(fmax(pt, 0.0), 1.0);
        if (patch->corner_count == 3 && ps + pt > 1.0) {
            double excess = 0.5 * (ps + pt - 1.0);
            ps = fmax(ps - excess, 0.0);
            pt = fmin(1.0 - ps, fmax(pt - excess, 0.0));
        }
        double d = v3_length(v3_sub(p, rad_patch_point(patch, ps, pt)));
        if (d < best) {
            best = d;
            best_s = ps;
            best_t = pt;
            best_patch = (uint32_t)i;
        }
    }
    double allowed = 1e-3 * rad_scene_diagonal(s->scene);
    if (!(best <= allowed))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "point radiosity: (%g, %g, %g) is %.3g m from surface '%s', more than 1e-3 of "
                        "the scene's size (%.3g m): give a point on the surface",
                        p.x, p.y, p.z, best, s->scene->surfaces[surface].name, allowed);
    if (!s->point_values) {
        rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
        double *values = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * mesh->vertex_count, sizeof *values,
                                   "point radiosity: vertex values");
        if (!values)
            return RAD_ERROR_OUT_OF_MEMORY;
        rad_result r = rad_view_vertex_values(ctx, &s->view, s->view.radiosity, values);
        if (r != RAD_OK) {
            rad_free(values);
            return r;
        }
        s->point_values = values;
    }
    double ls, lt;
    uint32_t e = rad_mesh_locate(mesh, best_patch, best_s, best_t, &ls, &lt);
    rad_element_interpolate(mesh, &mesh->elements[e], s->point_values, ls, lt, rgb);
    return RAD_OK;
}

rad_result rad_solution_save(rad_context *ctx, rad_solution *s, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !s || !path)
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    /* A solution file holds element values, from which a loaded solution
     * derives its vertex values: a strategy whose vertex values are its
     * unknowns would come back as another solution. */
    if (s->view.vertex_radiosity)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "solution file: solver '%s' solves for vertex values, which a solution file "
                        "does not hold (it keeps element values): not saved",
                        s->options.solver);
    double *display = NULL;
    rad_result r = display_values(ctx, s, &display);
    if (r == RAD_OK)
        r = rad_write_solution(ctx, &s->view, s->vertex_radiosity, path);
    rad_free(display);
    return r;
}

rad_result rad_solution_load_memory(rad_context *ctx, const char *name, const void *data, size_t size,
                                    rad_scene **scene, rad_solution **out)
{
    rad_api_enter(ctx);
    if (scene)
        *scene = NULL;
    if (out)
        *out = NULL;
    if (!ctx || !name || (!data && size) || !scene || !out)
        return rad_null_argument(ctx, __func__);
    rad_solution *s = rad_alloc(ctx, RAD_MEM_SOLVER, 1, sizeof *s, "solution");
    if (!s)
        return RAD_ERROR_OUT_OF_MEMORY;
    s->ctx = ctx;
    s->threads = rad_context_threads(ctx);
    rad_scene *loaded = NULL;
    double t = rad_seconds();
    rad_result r = rad_saved_read(ctx, name, data, size, &loaded, &s->options, &s->names, &s->state);
    if (r != RAD_OK) {
        rad_free(s);
        return r;
    }
    s->options.max_memory_bytes = rad_memory_limit(ctx);
    loaded->load_seconds = rad_seconds() - t;
    s->scene = loaded;
    s->strategy = &rad_strategy_saved;
    s->view.seconds.load = loaded->load_seconds;
    refresh_view(s);
    *scene = loaded;
    *out = s;
    return RAD_OK;
}

/* As solution.h says. */
rad_result rad_solution_load_file(rad_context *ctx, const char *path, rad_scene **scene, rad_solution **out)
{
    rad_api_enter(ctx);
    if (scene)
        *scene = NULL;
    if (out)
        *out = NULL;
    if (!ctx || !path || !scene || !out)
        return rad_null_argument(ctx, __func__);
    unsigned char *data;
    size_t size;
    double t = rad_seconds();
    rad_result r = rad_read_whole_file(ctx, path, &data, &size);
    if (r != RAD_OK)
        return r;
    r = rad_solution_load_memory(ctx, path, data, size, scene, out);
    rad_free(data);
    if (r != RAD_OK)
        return r;
    /* The file is the scene's one input (an output must not overwrite it). */
    char **inputs = rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *inputs, "solution file: inputs");
    char *copy = inputs ? rad_strdup(ctx, RAD_MEM_SCENE, path, "solution file: inputs") : NULL;
    if (!copy) {
        rad_free(inputs);
        rad_solution_destroy(*out);
        rad_scene_destroy(*scene);
        *out = NULL;
        *scene = NULL;
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    inputs[0] = copy;
    rad_scene_set_inputs(*scene, inputs, 1);
    (*scene)->load_seconds = rad_seconds() - t;
    (*out)->view.seconds.load = (*scene)->load_seconds;
    return RAD_OK;
}

bool rad_file_is_solution(const char *path)
{
    if (!path)
        return false;
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return false;
    FILE *f = fopen(path, "rb");
    if (!f)
        return false;
    unsigned char magic[RAD_SAVED_MAGIC_SIZE];
    bool is = fread(magic, 1, sizeof magic, f) == sizeof magic &&
              memcmp(magic, RAD_SAVED_MAGIC, RAD_SAVED_MAGIC_SIZE) == 0;
    fclose(f);
    return is;
}

rad_result rad_solution_write_stats(rad_context *ctx, const rad_solution *s, const char *path, bool partial)
{
    rad_api_enter(ctx);
    if (!ctx || !s || !path)
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    return rad_write_stats(ctx, &s->view, path, partial);
}

rad_result rad_solution_write_view_factors(rad_context *ctx, const rad_solution *s, const char *path,
                                           bool elements)
{
    rad_api_enter(ctx);
    if (!ctx || !s || !path)
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    return rad_write_view_factors(ctx, &s->view, path, elements);
}

rad_result rad_solution_write_view_factors_with(rad_context *ctx, const rad_solution *s, const char *path,
                                                const rad_view_factor_options *options)
{
    rad_api_enter(ctx);
    if (!ctx || !s || !path)
        return rad_null_argument(ctx, __func__);
    rad_view_factor_options o = {0};
    if (options)
        o = *options;
    if (o.smooth != RAD_SMOOTH_NONE && o.smooth != RAD_SMOOTH_ENCLOSURE && o.smooth != RAD_SMOOTH_OPEN)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "view factors: smooth %d is not a rad_smoothing", (int)o.smooth);
    if (!(o.sparse_threshold >= 0.0 && o.sparse_threshold < 1.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "view factors: sparse threshold %g is not in [0, 1)",
                        o.sparse_threshold);
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    return rad_write_view_factors_with(ctx, &s->view, path, &o);
}

rad_result rad_solution_write_mesh(rad_context *ctx, const rad_solution *s, const char *path, double exposure)
{
    rad_api_enter(ctx);
    if (!ctx || !s || !path)
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    return rad_write_mesh(ctx, &s->view, path, exposure);
}

rad_result rad_solution_bake(rad_context *ctx, const rad_solution *s, const rad_bake_options *options,
                             rad_output_set *set, const char *path, rad_bake_stats *stats)
{
    rad_api_enter(ctx);
    if (!ctx || !s || !set || !path)
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    rad_bake_options o = options ? *options : (rad_bake_options){0};
    double t = rad_seconds();
    rad_bake_stats figures = {0};
    rad_result r = rad_write_bake(ctx, &s->view, &o, set, path, &figures);
    figures.seconds = rad_seconds() - t;
    if (r == RAD_OK && stats)
        *stats = figures;
    return r;
}

rad_result rad_solution_write_history(rad_context *ctx, const rad_solution *s, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !s || !path)
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    return rad_write_history(ctx, s->history, s->history_count, path);
}

rad_result rad_solution_write_false_colour(rad_context *ctx, rad_solution *s, const rad_render_options *render,
                                           const rad_false_colour_options *options, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !s || !path)
        return rad_null_argument(ctx, __func__);
    rad_result r = rad_false_colour_check(ctx, options);
    if (r != RAD_OK)
        return r;
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    /* Luminance is what the solution's own render shows (textures, the
     * second pass); illuminance needs no render of the radiance. */
    rad_image *radiance = NULL;
    if (!options || options->quantity != RAD_FALSE_COLOUR_ILLUMINANCE)
        r = rad_solution_render(ctx, s, render, &radiance);
    if (r == RAD_OK)
        r = rad_write_false_colour_view(ctx, &s->view, render, options, radiance, path);
    rad_image_destroy(radiance);
    return r;
}

rad_result rad_illuminance_evaluate_memory(rad_context *ctx, const rad_solution *s, const char *name,
                                           const void *data, size_t size, rad_illuminance **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !s || !name || (!data && size > 0) || !out)
        return rad_null_argument(ctx, __func__);
    return rad_illuminance_from_view(ctx, &s->view, name, data, size, out);
}

rad_result rad_illuminance_evaluate_file(rad_context *ctx, const rad_solution *s, const char *path,
                                         rad_illuminance **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !s || !path || !out)
        return rad_null_argument(ctx, __func__);
    return rad_illuminance_from_view_file(ctx, &s->view, path, out);
}

double rad_solution_direct_lumens(const rad_solution *s) { return s ? rad_view_direct_lumens(&s->view) : 0.0; }

rad_result rad_camera_from_string(rad_context *ctx, const char *text, rad_camera *camera)
{
    rad_api_enter(ctx);
    if (!ctx || !text || !camera)
        return rad_null_argument(ctx, __func__);
    return rad_camera_parse(ctx, text, camera);
}

rad_result rad_scene_check_camera(rad_context *ctx, const rad_scene *scene, const rad_camera *camera)
{
    rad_api_enter(ctx);
    if (!ctx || !scene || !camera)
        return rad_null_argument(ctx, __func__);
    return rad_camera_check_distance(ctx, camera, scene->bounds_min, scene->bounds_max);
}

rad_result rad_solution_display_radiosity(rad_context *ctx, const rad_solution *s, bool ambient,
                                          double *element_rgb, double *vertex_rgb)
{
    rad_api_enter(ctx);
    if (!ctx || !s || (!element_rgb && !vertex_rgb))
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, s->options.max_memory_bytes); /* the solution's limit, where lower */
    size_t n = s->view.mesh->element_count;
    if (!ambient) {
        if (element_rgb)
            memcpy(element_rgb, s->view.radiosity, 3 * n * sizeof *element_rgb);
        return vertex_rgb ? rad_vertex_values(ctx, s->view.mesh, s->view.radiosity, vertex_rgb) : RAD_OK;
    }
    double *display = element_rgb;
    if (!display) {
        display = rad_alloc(ctx, RAD_MEM_RENDER, 3 * n, sizeof *display, "display: element values");
        if (!display)
            return RAD_ERROR_OUT_OF_MEMORY;
    }
    display_elements(s, display);
    rad_result r = vertex_rgb ? rad_vertex_values(ctx, s->view.mesh, display, vertex_rgb) : RAD_OK;
    if (display != element_rgb)
        rad_free(display);
    return r;
}

size_t rad_solution_link_count(const rad_solution *s) { return s && s->view.hier ? s->view.hier->links : 0; }
