/*
 * shared.c -- what the strategies share: the element arrays (area,
 * reflectance with textures averaged, emission, the direct light of
 * luminaires and daylight), mesh + ray structure timed, the closed-scene
 * check of the closure correction, and the meshed base of the strategies
 * that mesh once (dense, matrix-free, Galerkin, instant).
 */
#include "strategy/strategy.h"

#include "light/light.h"

#ifdef _OPENMP
#include <omp.h>
#endif
#include <stdlib.h>
#include <string.h>

/* A textured element's reflectance: the texture (times Kd) averaged over
 * the element (rad_texture_mean); untextured elements keep their
 * material's value. */
static void element_texture_mean(const rad_scene *scene, const rad_mesh *mesh, const rad_element *el,
                                 double rgb[3])
{
    vec3 corner[4];
    for (uint32_t k = 0; k < el->vertex_count && k < 4; k++)
        corner[k] = mesh->vertices[el->vertex[k]];
    rad_texture_mean(scene, mesh->patches[el->patch].polygon, corner, el->vertex_count, el->area, rgb);
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
    rad_progress(ctx, "direct light", 0, n);
    /* Each element alone: its values do not depend on the schedule. */
#pragma omp parallel for schedule(dynamic, 16) num_threads(rad_context_threads(ctx))
    for (size_t i = 0; i < n; i++) {
        if (stop)
            continue;
        rad_light_element_irradiance(scene, mesh, vis, i, direct + 3 * i);
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
                        .control_variate = !o->no_control_variate,
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

