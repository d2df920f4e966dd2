/*
 * strategy.c -- the strategy table, lookup by solver name, what the
 * strategies share (element arrays, mesh + ray structure), and the
 * questions every solution answers from its view: power balance,
 * per-surface radiosity, surface-to-surface view factors, the direct
 * lumens landing.
 */
#include "strategy/strategy.h"

#include "light/light.h"
#include "photometry/photometry.h"

#ifdef _OPENMP
#include <omp.h>
#endif
#include <stdlib.h>
#include <string.h>

extern const rad_strategy rad_strategy_dense;
extern const rad_strategy rad_strategy_matrix_free;
extern const rad_strategy rad_strategy_hierarchical;
extern const rad_strategy rad_strategy_instant;

const rad_strategy *const rad_strategies[] = {
    &rad_strategy_dense,
    &rad_strategy_matrix_free,
    &rad_strategy_hierarchical,
    &rad_strategy_galerkin,
    &rad_strategy_instant,
    NULL,
};

const rad_strategy *rad_strategy_for_solver(const char *name)
{
    const char *solver, *description;
    for (size_t k = 0; rad_strategies[k]; k++)
        for (size_t i = 0; rad_strategies[k]->solver_info(i, &solver, &description); i++)
            if (strcmp(solver, name) == 0)
                return rad_strategies[k];
    return NULL;
}

unsigned rad_strategy_capabilities(const char *name)
{
    const rad_strategy *strategy = name ? rad_strategy_for_solver(name) : NULL;
    if (!strategy)
        return 0;
    unsigned capabilities = strategy->capabilities;
    /* The mirror images' factors (ff_mirror.c) break reciprocity: a linear
     * solver that relies on it cannot take them. */
    const rad_solver *linear = rad_solver_find(name);
    if (linear && (linear->flags & RAD_SOLVER_RECIPROCAL) && (capabilities & RAD_CAN_MIRRORS))
        capabilities = (capabilities & ~(unsigned)RAD_CAN_MIRRORS) | RAD_REFUSES_MIRRORS;
    return capabilities;
}

bool rad_strategy_solver_info(size_t index, const char **name, const char **description)
{
    for (size_t k = 0; rad_strategies[k]; k++) {
        size_t i = 0;
        while (rad_strategies[k]->solver_info(i, name, description)) {
            if (index == 0)
                return true;
            index--, i++;
        }
    }
    return false;
}

/* ---- shared parts ---- */

/* A textured element's reflectance: the texture (times Kd) averaged over
 * the element, so that the power it reflects is the texels' (docs/
 * methods.md, "Textures"): k x k stratum centres, k from the texels the
 * element spans (two samples a texel, 4 to 64 a side).  Untextured
 * elements keep their material's value. */
static void element_texture_mean(const rad_scene *scene, const rad_mesh *mesh, const rad_element *el,
                                 double rgb[3])
{
    uint32_t polygon = mesh->patches[el->patch].polygon;
    if (!rad_scene_textured(scene, polygon))
        return;
    const rad_texture *t = &scene->textures[scene->materials[scene->polygons[polygon].material].texture - 1];
    double lo_u = INFINITY, hi_u = -INFINITY, lo_v = INFINITY, hi_v = -INFINITY;
    for (uint32_t k = 0; k < el->vertex_count; k++) {
        double u, v;
        if (!rad_scene_uv(scene, polygon, mesh->vertices[el->vertex[k]], &u, &v))
            return;
        lo_u = fmin(lo_u, u), hi_u = fmax(hi_u, u), lo_v = fmin(lo_v, v), hi_v = fmax(hi_v, v);
    }
    double span = fmax((hi_u - lo_u) * t->width, (hi_v - lo_v) * t->height);
    int side = (int)fmin(64.0, fmax(4.0, ceil(2.0 * span)));
    double sum[3] = {0, 0, 0}, weights = 0.0;
    for (int a = 0; a < side; a++)
        for (int b = 0; b < side; b++) {
            double u = (a + 0.5) / side, v = (b + 0.5) / side, w = rad_element_sample_weight(mesh, el, u, v);
            double texel[3];
            rad_scene_reflectance_at(scene, polygon, rad_element_sample(mesh, el, u, v), texel);
            for (int c = 0; c < 3; c++)
                sum[c] += w * texel[c];
            weights += w;
        }
    for (int c = 0; c < 3; c++)
        rgb[c] = weights > 0.0 ? sum[c] / weights : rgb[c];
}

rad_result rad_elements_create(rad_context *ctx, const rad_scene *scene, const rad_mesh *mesh,
                               rad_elements *out)
{
    memset(out, 0, sizeof *out);
    size_t n = mesh->element_count;
    rad_elements e = {0};
    e.area = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *e.area, "solution: areas");
    e.reflectance = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *e.reflectance, "solution: reflectance");
    e.emission = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *e.emission, "solution: emission");
    e.radiosity = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *e.radiosity, "solution: radiosity");
    if (!e.area || !e.reflectance || !e.emission || !e.radiosity) {
        rad_elements_free(&e);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < n; i++) {
        const rad_element *el = &mesh->elements[i];
        const rad_material *m = &scene->materials[el->material];
        e.area[i] = el->area;
        for (int c = 0; c < 3; c++) {
            e.reflectance[3 * i + (size_t)c] = m->reflectance[c];
            e.emission[3 * i + (size_t)c] = m->emission[c];
        }
        if (scene->texture_count > 0)
            element_texture_mean(scene, mesh, el, e.reflectance + 3 * i);
    }
    memcpy(e.radiosity, e.emission, 3 * n * sizeof *e.radiosity);
    *out = e;
    return RAD_OK;
}

rad_result rad_elements_add_light(rad_context *ctx, const rad_scene *scene, const rad_mesh *mesh,
                                  const rad_vis *vis, rad_elements *e)
{
    if (!rad_light_present(scene))
        return RAD_OK;
    size_t n = mesh->element_count;
    double *direct = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n + 1, sizeof *direct, "solution: direct light");
    if (!direct)
        return RAD_ERROR_OUT_OF_MEMORY;
    uint64_t done = 0;
    volatile int stop = 0;
    double lift = rad_vis_epsilon(mesh);
    rad_progress(ctx, "direct light", 0, n);
    /* Each element alone: its values do not depend on the schedule. */
#pragma omp parallel for schedule(dynamic, 16) num_threads(rad_context_threads(ctx))
    for (size_t i = 0; i < n; i++) {
        if (stop)
            continue;
        rad_light_element_irradiance_lifted(scene, mesh, vis, lift, i, direct + 3 * i);
        uint64_t now;
#pragma omp atomic capture
        now = ++done;
#ifdef _OPENMP
        if (omp_get_thread_num() == 0)
#endif
            rad_progress(ctx, "direct light", now, n);
        if (rad_cancelled(ctx))
            stop = 1;
    }
    if (stop) {
        rad_free(direct);
        return RAD_ERROR_INTERRUPTED;
    }
    rad_progress(ctx, "direct light", n, n);
    for (size_t k = 0; k < 3 * n; k++) {
        e->emission[k] += e->reflectance[k] * direct[k];
        e->radiosity[k] = e->emission[k];
    }
    rad_free(e->direct);
    e->direct = direct;
    return RAD_OK;
}

void rad_elements_free(rad_elements *e)
{
    rad_free(e->area);
    rad_free(e->reflectance);
    rad_free(e->emission);
    rad_free(e->radiosity);
    rad_free(e->direct);
    memset(e, 0, sizeof *e);
}

void rad_view_elements(rad_solution_view *view, const rad_mesh *mesh, const rad_elements *e)
{
    view->mesh = mesh;
    view->n = mesh ? mesh->element_count : 0;
    view->area = e->area;
    view->reflectance = e->reflectance;
    view->emission = e->emission;
    view->direct = e->direct;
    view->radiosity = e->radiosity;
}

rad_result rad_strategy_mesh_and_vis(rad_context *ctx, const rad_scene *scene, const rad_options *options,
                                     const rad_mesh_options *mesh_options, rad_mesh **mesh, rad_vis **vis,
                                     rad_phase_seconds *seconds)
{
    *vis = NULL;
    double t = rad_seconds();
    rad_result r = rad_mesh_build_within(ctx, scene, mesh_options, options->max_memory_bytes, mesh);
    seconds->mesh = rad_seconds() - t;
    if (r != RAD_OK)
        return r;
    r = rad_vis_create(ctx, options->visibility, *mesh, vis);
    if (r != RAD_OK) {
        rad_mesh_destroy(*mesh);
        *mesh = NULL;
        return r;
    }
    seconds->visibility = (*vis)->build_seconds;
    /* Scale ratios: what the shadow rays cannot resolve is said once. */
    double narrowest;
    uint32_t which;
    size_t unresolved = rad_vis_unresolved(*mesh, &narrowest, &which);
    if (unresolved > 0)
        rad_warn(ctx,
                 "%s: %zu polygon%s (the narrowest %.3g m across, in surface '%s') %s narrower than "
                 "the shadow rays' tolerance of %.3g m, 1e-5 of the scene's size: an occluder "
                 "nearer to %s than that is not seen",
                 scene->source, unresolved, unresolved == 1 ? "" : "s", narrowest,
                 scene->surfaces[(*mesh)->patches[which].surface].name, unresolved == 1 ? "is" : "are",
                 rad_vis_epsilon(*mesh), unresolved == 1 ? "it" : "them");
    return RAD_OK;
}

rad_result rad_strategy_check_closed(rad_context *ctx, const rad_scene *scene, const rad_options *o,
                                     const rad_mesh *mesh, const rad_vis *vis, double **escape, double *escaped)
{
    *escape = NULL;
    *escaped = 0.0;
    if (!o->closure_correction)
        return RAD_OK;
    double *fraction = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, mesh->element_count + 1, sizeof *fraction,
                                 "closure: escaping light");
    if (!fraction)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = rad_ff_escape_rays(ctx, mesh, vis, o->seed, fraction);
    if (r == RAD_OK) {
        *escaped = rad_ff_escaped(mesh, fraction, NULL);
        if (*escaped > RAD_FF_OPEN_SCENE_ESCAPE)
            r = rad_ff_refuse_open(ctx, scene->source, *escaped);
    }
    if (r != RAD_OK) {
        rad_free(fraction);
        return r;
    }
    *escape = fraction;
    return RAD_OK;
}

rad_result rad_meshed_init(rad_context *ctx, const rad_scene *scene, const rad_options *o, rad_meshed *m)
{
    memset(m, 0, sizeof *m);
    m->scene = scene;
    m->options = o;
    m->threads = rad_context_threads(ctx);
    rad_mesh_options mo = {o->mesh_size, o->target_elements, o->crease_angle_degrees};
    rad_result r = rad_strategy_mesh_and_vis(ctx, scene, o, &mo, &m->mesh, &m->vis, &m->seconds);
    if (r == RAD_OK)
        r = rad_elements_create(ctx, scene, m->mesh, &m->elements);
    if (r == RAD_OK)
        r = rad_elements_add_light(ctx, scene, m->mesh, m->vis, &m->elements);
    if (r != RAD_OK)
        rad_meshed_free(m);
    return r;
}

void rad_meshed_free(rad_meshed *m)
{
    rad_vis_destroy(m->vis);
    rad_mesh_destroy(m->mesh);
    rad_elements_free(&m->elements);
    m->vis = NULL;
    m->mesh = NULL;
}

static int meshed_monitor(void *user, const rad_solve_step *step, const double *B, const double *ambient)
{
    rad_meshed *m = user;
    (void)B; /* the iterate is m->elements.radiosity, updated in place */
    if (ambient)
        memcpy(m->solve_stats.ambient, ambient, sizeof m->solve_stats.ambient);
    return m->hook->fn(m->hook->user, step, true);
}

void rad_meshed_begin(rad_meshed *m, const char *method, const rad_step_hook *hook, rad_system *sys,
                      rad_solve_params *p)
{
    const rad_options *o = m->options;
    size_t n = m->mesh->element_count;
    *sys = (rad_system){.n = n,
                        .F = NULL,
                        .area = m->elements.area,
                        .reflectance = m->elements.reflectance,
                        .emission = m->elements.emission,
                        .threads = m->threads,
                        .mesh = m->mesh,
                        .vis = m->vis,
                        .seed = o->seed,
                        .samples = o->samples,
                        .max_memory = o->max_memory_bytes};
    *p = (rad_solve_params){o->tolerance, o->unshot_tolerance, o->max_iterations, o->relaxation, NULL, m};
    m->hook = hook;
    if (hook->fn)
        p->monitor = meshed_monitor;
    memcpy(m->elements.radiosity, m->elements.emission, 3 * n * sizeof *m->elements.radiosity);
    memset(&m->solve_stats, 0, sizeof m->solve_stats);
    m->solve_stats.method = method;
    m->solve_stats.unshot = NAN;   /* progressive refinement measures it */
    m->solve_stats.absorbed = NAN; /* matrix-free solvers count it; else read from F */
}

void rad_meshed_end(rad_meshed *m, rad_result r, double t0)
{
    m->solve_stats.seconds = rad_seconds() - t0;
    m->seconds.solve = m->solve_stats.seconds;
    m->solved = r == RAD_OK;
    m->hook = NULL;
}

void rad_meshed_view(const rad_meshed *m, rad_solution_view *v)
{
    rad_view_elements(v, m->mesh, &m->elements);
    v->vis = m->vis;
    v->F = v->F_coupling = NULL;
    v->F_variance = NULL;
    v->vertex_radiosity = NULL;
    v->ff = &m->ff_stats;
    v->solve = &m->solve_stats;
    v->hier = NULL;
    v->adaptive = NULL;
    v->solved = m->solved;
    v->seconds.mesh = m->seconds.mesh;
    v->seconds.visibility = m->seconds.visibility;
    v->seconds.form_factors = m->seconds.form_factors;
    v->seconds.solve = m->seconds.solve;
}

/* ---- questions answered from a view ---- */

void rad_view_surface_radiosity(const rad_solution_view *v, size_t surface, double rgb[3])
{
    double sum[3] = {0, 0, 0}, area = 0.0;
    for (size_t i = 0; i < v->n; i++) {
        if (v->mesh->elements[i].surface != surface)
            continue;
        area += v->area[i];
        for (int c = 0; c < 3; c++)
            sum[c] += v->area[i] * v->radiosity[3 * i + c];
    }
    for (int c = 0; c < 3; c++)
        rgb[c] = area > 0.0 ? sum[c] / area : 0.0;
}

rad_result rad_view_surface_view_factors(rad_context *ctx, const rad_solution_view *v, double *F)
{
    size_t S = v->scene->surface_count, n = v->n;
    memset(F, 0, S * S * sizeof *F);
    if (!v->F) /* no factors were computed */
        return RAD_OK;
    double *area = rad_alloc(ctx, RAD_MEM_OUTPUT, S, sizeof *area, "view factors: surface areas");
    if (!area) {
        for (size_t k = 0; k < S * S; k++)
            F[k] = NAN;
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < n; i++) {
        uint32_t si = v->mesh->elements[i].surface;
        area[si] += v->area[i];
        const double *Fi = v->F + i * n;
        double *row = F + (size_t)si * S;
        for (size_t j = 0; j < n; j++)
            row[v->mesh->elements[j].surface] += v->area[i] * Fi[j];
    }
    for (size_t a = 0; a < S; a++)
        for (size_t b = 0; b < S; b++)
            F[a * S + b] = area[a] > 0.0 ? F[a * S + b] / area[a] : 0.0;
    rad_free(area);
    return RAD_OK;
}

/* The direct light of luminaires and daylight landing on the elements,
 * sum A H_d, and the part of it absorbed at once, sum A (1 - rho) H_d (W,
 * means over RGB): the solve sees only the reflected part rho H_d, as
 * emission. */
static void direct_power(const rad_solution_view *v, double *landing, double *absorbed)
{
    double land = 0.0, ab = 0.0;
    for (size_t i = 0; v->direct && i < v->n; i++)
        for (int c = 0; c < 3; c++) {
            double p = v->area[i] * v->direct[3 * i + c];
            land += p;
            ab += (1.0 - v->reflectance[3 * i + c]) * p;
        }
    *landing = land / 3.0;
    *absorbed = ab / 3.0;
}

rad_result rad_view_power(rad_context *ctx, const rad_solution_view *v, double *emitted, double *absorbed)
{
    size_t n = v->n;
    double em = 0.0, landing, direct_absorbed;
    /* With luminaires or daylight, the power entering is the surfaces' own
     * emission and the direct light landing; what the solve calls emission
     * holds only its reflected part, so the absorbed part is added to both
     * sides. */
    direct_power(v, &landing, &direct_absorbed);
    if (!v->F) { /* the strategy counted what it deposited */
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++)
                em += v->area[i] * v->emission[3 * i + c];
        *emitted = em / 3.0 + direct_absorbed;
        *absorbed = v->solve->absorbed + direct_absorbed;
        return RAD_OK;
    }
    /* Per-element absorption in parallel, summed in order (thread-independent). */
    double *absorbed_by = rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *absorbed_by, "power balance"), ab = 0.0;
    if (!absorbed_by) {
        *emitted = *absorbed = NAN;
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    /* With mirrors: irradiance through the coupling the solve used (the
     * mirror images' light included), and a mirror absorbs what it
     * reflects neither diffusely nor specularly. */
    const double *F = v->F_coupling ? v->F_coupling : v->F;
#pragma omp parallel for schedule(static) num_threads(v->threads)
    for (size_t i = 0; i < n; i++) {
        double h[3];
        rad_gather(F + i * n, v->radiosity, n, h);
        const rad_material *m = &v->scene->materials[v->mesh->elements[i].material];
        bool mirror = v->F_coupling && m->specular_kind == RAD_SPECULAR_MIRROR;
        double a = 0.0;
        for (int c = 0; c < 3; c++) {
            double rho_s = mirror ? (m->specular[0] + m->specular[1] + m->specular[2]) / 3.0 : 0.0;
            a += v->area[i] * (1.0 - v->reflectance[3 * i + c] - rho_s) * h[c];
        }
        absorbed_by[i] = a;
    }
    for (size_t i = 0; i < n; i++) {
        ab += absorbed_by[i];
        for (int c = 0; c < 3; c++)
            em += v->area[i] * v->emission[3 * i + c];
    }
    rad_free(absorbed_by);
    *emitted = em / 3.0 + direct_absorbed;
    *absorbed = ab / 3.0 + direct_absorbed;
    return RAD_OK;
}

double rad_view_direct_lumens(const rad_solution_view *v)
{
    if (!v->direct)
        return 0.0;
    double landing = 0.0;
    for (size_t i = 0; i < v->n; i++) {
        const double *h = v->direct + 3 * i;
        landing += v->area[i] * (RAD_Y_R * h[0] + RAD_Y_G * h[1] + RAD_Y_B * h[2]);
    }
    return RAD_LUMINOUS_EFFICACY * landing;
}

/* Every registry of the pipeline, for --list-methods and the option
 * table's method names (radiosity.h). */
bool rad_method_info(rad_method_kind kind, size_t index, const char **name, const char **description)
{
    size_t count = 0;
    const char *method_name = NULL, *method_description = NULL;
    switch (kind) {
    case RAD_METHOD_FORM_FACTOR:
        while (rad_ff_methods[count])
            count++;
        if (index >= count)
            return false;
        method_name = rad_ff_methods[index]->name;
        method_description = rad_ff_methods[index]->description;
        break;
    case RAD_METHOD_SOLVER:
        if (!rad_strategy_solver_info(index, &method_name, &method_description))
            return false;
        break;
    case RAD_METHOD_VISIBILITY:
        while (rad_vis_backends[count])
            count++;
        if (index >= count)
            return false;
        method_name = rad_vis_backends[index]->name;
        method_description = rad_vis_backends[index]->description;
        break;
    default:
        return false;
    }
    if (name)
        *name = method_name;
    if (description)
        *description = method_description;
    return true;
}

unsigned rad_method_capabilities(rad_method_kind kind, const char *name)
{
    return kind == RAD_METHOD_SOLVER ? rad_strategy_capabilities(name) : 0;
}
