/*
 * hierarchical.c -- hierarchical radiosity as a strategy (hier/: Hanrahan,
 * Salzman & Aupperle 1991, with clusters).  The patches are the roots of
 * the hierarchy and its first elements; solving refines the links and
 * splits nodes, and its leaves become the elements.  The ray structure is
 * built once, on the patches, and serves every level.  Luminaires and
 * daylight light every node where it is made (hier/direct.c); the leaves
 * carry their direct irradiance out as the dense strategies' elements do.
 */
#include "strategy/strategy.h"

#include "light/light.h"

#include <stdlib.h>
#include <string.h>

typedef struct hierarchical_state {
    const rad_scene *scene;
    const rad_options *options;
    rad_mesh *patches;         /* one element per patch: the roots */
    rad_vis *vis;              /* built on the patches */
    rad_light_reach *reach;    /* where each luminaire's light arrives; NULL without luminaires */
    rad_elements patch_elements;
    rad_mesh *leaves;          /* the leaves after a solve, else NULL */
    rad_elements leaf_elements;
    rad_ff_stats ff_stats;     /* none: names the method "none" */
    rad_solve_stats solve_stats;
    rad_hier_stats hier_stats;
    rad_phase_seconds seconds;
    bool solved;
    const rad_step_hook *hook; /* during a solve */
    rad_context *ctx;          /* during a solve */
} hierarchical_state;

static bool hierarchical_solver_info(size_t index, const char **name, const char **description)
{
    if (index > 0)
        return false;
    *name = "hierarchical";
    *description = "matrix-free: Hanrahan-Salzman-Aupperle links between element quadtrees, clusters, "
                   "BF refinement; meshes as it solves; ~10 links per element (rad_options.epsilon, "
                   "rad_options.min_area)";
    return true;
}

static void hierarchical_destroy(void *state)
{
    hierarchical_state *st = state;
    if (!st)
        return;
    rad_light_reach_destroy(st->reach);
    rad_vis_destroy(st->vis);
    rad_mesh_destroy(st->patches);
    rad_mesh_destroy(st->leaves);
    rad_elements_free(&st->patch_elements);
    rad_elements_free(&st->leaf_elements);
    rad_free(st);
}

static rad_result hierarchical_create(rad_context *ctx, const rad_scene *scene, const rad_options *o,
                                      void **out)
{
    *out = NULL;
    hierarchical_state *st = rad_alloc(ctx, RAD_MEM_SOLVER, 1, sizeof *st, "solution: hierarchical state");
    if (!st)
        return RAD_ERROR_OUT_OF_MEMORY;
    st->scene = scene;
    st->options = o;
    st->ff_stats.method = "none (matrix-free solver)";
    /* The patches are the roots: one element each; the solver splits them. */
    rad_mesh_options mo = {1e30, 0, o->crease_angle_degrees};
    rad_result r = rad_strategy_mesh_and_vis(ctx, scene, o, &mo, &st->patches, &st->vis, &st->seconds);
    if (r == RAD_OK) {
        /* The patches' rays decide: the correction leaves a patch whose
         * closure is below 0.5 alone (hier.c), so what sees next to
         * nothing does not need F's verdict. */
        double *escape = NULL;
        r = rad_strategy_check_closed(ctx, scene, o, st->patches, st->vis, &escape, &st->ff_stats.escaped);
        rad_free(escape);
    }
    if (r == RAD_OK)
        r = rad_elements_create(ctx, scene, st->patches, &st->patch_elements);
    /* The nodes and the grids' points ask the luminaires in reach, not all
     * of a building's (light/reach.c). */
    if (r == RAD_OK && scene->luminaires.count > 0)
        r = rad_light_reach_build(ctx, scene, st->patches, st->vis, rad_context_threads(ctx), &st->reach);
    if (r != RAD_OK) {
        hierarchical_destroy(st);
        return r;
    }
    *out = st;
    return RAD_OK;
}

/* Progressive display (the hook asks for it): the current leaves become
 * the elements before each step reaches the hook, a new mesh once per
 * refinement round and only the values between, so the view shows the
 * iterate. */
static rad_result hierarchical_display(void *user, rad_mesh *mesh, const double *B, size_t leaves)
{
    hierarchical_state *st = user;
    if (mesh) {
        rad_elements e;
        if (rad_elements_create(st->ctx, st->scene, mesh, &e) != RAD_OK) {
            rad_mesh_destroy(mesh);
            return RAD_ERROR_OUT_OF_MEMORY;
        }
        rad_mesh_destroy(st->leaves);
        rad_elements_free(&st->leaf_elements);
        st->leaves = mesh;
        st->leaf_elements = e;
    }
    memcpy(st->leaf_elements.radiosity, B, 3 * leaves * sizeof *B);
    return RAD_OK;
}

/* Steps reach the hook, displayable when the leaves are shown as they go. */
static int hierarchical_monitor(void *user, const rad_solve_step *step, const double *B, const double *ambient)
{
    (void)B, (void)ambient;
    hierarchical_state *st = user;
    return st->hook->fn ? st->hook->fn(st->hook->user, step, st->hook->display) : 0;
}

static rad_result hierarchical_solve(rad_context *ctx, void *state, const rad_step_hook *hook)
{
    hierarchical_state *st = state;
    const rad_options *o = st->options;
    rad_hier_params hp = {.scene = st->scene,
                          .base = st->patches,
                          .vis = st->vis,
                          .epsilon = o->epsilon,
                          .min_area = o->min_area,
                          .clustering = o->clustering,
                          .classic_oracle = o->classic_oracle != 0,
                          .closure_correction = o->closure_correction != 0,
                          .seed = o->seed,
                          .shadow_rays = o->shadow_rays,
                          .tolerance = o->tolerance,
                          .max_iterations = o->max_iterations,
                          .max_memory = o->max_memory_bytes,
                          .crease_angle_degrees = o->crease_angle_degrees,
                          .light_reach = st->reach,
                          .monitor = hierarchical_monitor,
                          .monitor_user = st};
    if (hook->fn && hook->display) {
        hp.display = hierarchical_display;
        hp.display_user = st;
    }
    st->hook = hook;
    st->ctx = ctx;
    st->solved = false;
    memset(&st->solve_stats, 0, sizeof st->solve_stats);
    st->solve_stats.method = "hierarchical";
    st->solve_stats.unshot = NAN;
    double t = rad_seconds();
    rad_mesh *leaves = NULL;
    double *B = NULL, *direct = NULL;
    rad_result r = rad_hier_run(ctx, &hp, &leaves, &B, &direct, &st->solve_stats, &st->hier_stats);
    st->hier_stats.patches = st->patches->patch_count;
    st->solve_stats.seconds = rad_seconds() - t;
    st->seconds.solve = st->solve_stats.seconds;
    st->hook = NULL;
    st->ctx = NULL;
    if (leaves) {
        /* The leaves, also of an interrupted solve, become the elements. */
        rad_elements e;
        if (rad_elements_create(ctx, st->scene, leaves, &e) != RAD_OK) {
            rad_free(B);
            rad_free(direct);
            rad_mesh_destroy(leaves);
            return RAD_ERROR_OUT_OF_MEMORY;
        }
        rad_free(e.radiosity);
        e.radiosity = B;
        /* Luminaires and daylight: each leaf's direct irradiance, its first
         * reflection in the emission, as rad_elements_add_light leaves the
         * dense strategies' elements (the power balance and the grids'
         * gathering read them so).  The reflectance is each leaf's, its
         * texture's mean over it where textured, as the solver's nodes
         * took it (rad_texture_mean). */
        if (direct) {
            for (size_t i = 0; i < 3 * leaves->element_count; i++)
                e.emission[i] += e.reflectance[i] * direct[i];
            e.direct = direct;
        }
        rad_mesh_destroy(st->leaves);
        rad_elements_free(&st->leaf_elements);
        st->leaves = leaves;
        st->leaf_elements = e;
    }
    st->solved = r == RAD_OK;
    return r;
}

static void hierarchical_view(const void *state, rad_solution_view *v)
{
    const hierarchical_state *st = state;
    if (st->leaves)
        rad_view_elements(v, st->leaves, &st->leaf_elements);
    else
        rad_view_elements(v, st->patches, &st->patch_elements);
    v->vis = st->vis;
    v->light_reach = st->reach;
    v->F = NULL;
    v->F_variance = NULL;
    v->vertex_radiosity = NULL;
    v->ff = &st->ff_stats;
    v->solve = &st->solve_stats;
    v->hier = st->leaves ? &st->hier_stats : NULL;
    v->solved = st->solved;
    v->seconds.mesh = st->seconds.mesh;
    v->seconds.visibility = st->seconds.visibility;
    v->seconds.form_factors = 0.0;
    v->seconds.solve = st->seconds.solve;
}

const rad_strategy rad_strategy_hierarchical = {
    "hierarchical",
    "links between quadtree nodes and clusters, refined as the radiosity converges",
    /* Progress images: with a step hook that displays, the current leaves
     * are the elements at every sweep (hierarchical_display). */
    RAD_CAN_MIRRORS | RAD_CAN_CLOSURE_CORRECTION | RAD_CAN_LIGHTS | RAD_CAN_PROGRESS_IMAGES,
    hierarchical_solver_info,
    hierarchical_create,
    hierarchical_solve,
    hierarchical_view,
    hierarchical_destroy,
};
