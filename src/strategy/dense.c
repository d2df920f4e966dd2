/*
 * dense.c -- the classic method: the full n x n form-factor matrix by one
 * of the methods in the form-factor table, then the linear system
 * (I - P F) B = E by one of the solvers in the solver table (Cohen &
 * Wallace 1993, ch. 4-5).  Memory grows as 8 n^2 bytes, so it is the
 * strategy for up to some 10^4 elements, and the one that can write view
 * factors.
 */
#include "strategy/strategy.h"

#include <stdlib.h>
#include <string.h>

typedef struct dense_state {
    rad_meshed base;           /* mesh, visibility, elements, stats */
    double *F;                 /* n x n */
    double *F_variance;        /* n x n, or NULL */
    double *F_ext;             /* n x n: F with the mirror images' factors added (scenes with
                                  mirrors; the solve uses it), else NULL */
    rad_adaptive *adaptive;    /* rad_options.adaptive_levels > 0: the quadtrees, else NULL */
} dense_state;

static bool dense_solver_info(size_t index, const char **name, const char **description)
{
    size_t count = 0;
    while (rad_solvers[count])
        count++;
    if (index >= count)
        return false;
    *name = rad_solvers[index]->name;
    *description = rad_solvers[index]->description;
    return true;
}

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
    double matrix = 8.0 * (double)n * (double)n;
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

static void dense_destroy(void *state)
{
    dense_state *st = state;
    if (!st)
        return;
    rad_meshed_free(&st->base);
    rad_adaptive_destroy(st->adaptive);
    rad_free(st->F);
    rad_free(st->F_variance);
    rad_free(st->F_ext);
    rad_free(st);
}

/* F (and its variances) for the current mesh, the old ones freed (the
 * adaptive mesh's coupling hook too). */
static rad_result dense_couple(rad_context *ctx, void *state)
{
    dense_state *st = state;
    rad_meshed *m = &st->base;
    const rad_options *o = m->options;
    const rad_scene *scene = m->scene;
    rad_free(st->F);
    rad_free(st->F_variance);
    rad_free(st->F_ext);
    st->F = st->F_variance = st->F_ext = NULL;
    /* An open scene is refused the closure correction before F where the
     * rays show it, after F (rad_form_factors) where only F can. */
    double *escape = NULL, escaped = 0.0;
    rad_result r = rad_strategy_check_closed(ctx, scene, o, m->mesh, m->vis, &escape, &escaped);
    if (r == RAD_OK)
        r = check_ff_scratch(ctx, o, m->mesh->element_count, m->threads);
    if (r == RAD_OK) {
        rad_ff_request req = {m->mesh, m->vis, o->seed, o->shadow_rays, o->hemicube_resolution, o->samples,
                              o->near_field, escape, scene->source, o->raw_form_factors != 0};
        r = rad_form_factors(ctx, rad_ff_find(o->form_factors), &req, o->max_memory_bytes,
                             o->closure_correction != 0, &st->F, &st->F_variance, &m->ff_stats);
        m->seconds.form_factors = m->ff_stats.seconds;
    }
    /* The first pass of two-pass rendering: light by way of ideal mirrors
     * (formfactor/ff_mirror.c); F itself stays the geometric factors the
     * view-factor outputs write. */
    if (r == RAD_OK && rad_mesh_has_mirror(m->mesh, scene->materials)) {
        rad_ff_mirror_stats ms;
        r = rad_ff_mirror_images(ctx, m->mesh, m->vis, scene->materials, st->F, &st->F_ext, &ms);
        m->seconds.form_factors += ms.seconds;
        m->ff_stats.rays += ms.rays;
    }
    rad_free(escape);
    return r;
}

static rad_result dense_create(rad_context *ctx, const rad_scene *scene, const rad_options *o, void **out)
{
    *out = NULL;
    dense_state *st = rad_alloc(ctx, RAD_MEM_SOLVER, 1, sizeof *st, "solution: dense state");
    if (!st)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_meshed *m = &st->base;
    rad_result r = rad_meshed_init(ctx, scene, o, m);
    if (r != RAD_OK) {
        rad_free(st);
        return r;
    }
    if (o->adaptive_levels > 0)
        r = rad_adaptive_create(ctx, m, &st->adaptive);
    if (r == RAD_OK)
        r = dense_couple(ctx, st);
    if (r != RAD_OK) {
        dense_destroy(st);
        return r;
    }
    *out = st;
    return RAD_OK;
}

static rad_result dense_solve_mesh(rad_context *ctx, void *state, const rad_step_hook *hook)
{
    dense_state *st = state;
    rad_meshed *m = &st->base;
    const rad_solver *solver = rad_solver_find(m->options->solver);
    rad_system sys;
    rad_solve_params p;
    rad_meshed_begin(m, solver->name, hook, &sys, &p);
    sys.F = st->F_ext ? st->F_ext : st->F;
    double t0 = rad_seconds();
    /* Independent groups of elements (rooms that cannot see each other) are
     * solved separately; one group is solved as is. */
    rad_result r = rad_solve_by_components(ctx, solver, &sys, &p, m->elements.radiosity, &m->solve_stats);
    rad_meshed_end(m, r, t0);
    return r;
}

/* Solve; with adaptive subdivision, then refine, couple and solve again. */
static rad_result dense_solve(rad_context *ctx, void *state, const rad_step_hook *hook)
{
    dense_state *st = state;
    rad_result r = dense_solve_mesh(ctx, st, hook);
    if (r == RAD_OK && st->adaptive) {
        rad_adaptive_hooks h = {dense_couple, dense_solve_mesh, st};
        r = rad_adaptive_refine(ctx, st->adaptive, &st->base, &h, hook);
    }
    return r;
}

static void dense_view(const void *state, rad_solution_view *v)
{
    const dense_state *st = state;
    rad_meshed_view(&st->base, v);
    v->F = st->F;
    v->F_coupling = st->F_ext;
    v->F_variance = st->F_variance;
    v->adaptive = rad_adaptive_get_stats(st->adaptive);
}

const rad_strategy rad_strategy_dense = {
    "dense",
    "the n x n form-factor matrix (rad_options.form_factors), then a linear solver",
    RAD_HAS_FORM_FACTORS | RAD_HAS_UNIFORM_MESH | RAD_CAN_ADAPTIVE | RAD_CAN_MIRRORS | RAD_CAN_LIGHTS |
        RAD_CAN_CLOSURE_CORRECTION | RAD_CAN_PROGRESS_IMAGES,
    dense_solver_info,
    dense_create,
    dense_solve,
    dense_view,
    dense_destroy,
};
