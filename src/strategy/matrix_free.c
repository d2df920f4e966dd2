/*
 * matrix_free.c -- progressive refinement without a stored matrix: each
 * shot samples its form-factor column with rays from the shooter
 * (solve/solve_shooting.c), so memory is O(n) and scenes of 10^5 - 10^6
 * elements fit (Cohen, Chen, Wallace & Greenberg 1988, with ray-cast
 * factors after Wallace, Elmquist & Haines 1989).
 */
#include "strategy/strategy.h"

#include <stdlib.h>

static bool matrix_free_solver_info(size_t index, const char **name, const char **description)
{
    if (index > 0)
        return false;
    *name = rad_solver_shooting.name;
    *description = rad_solver_shooting.description;
    return true;
}

static void matrix_free_destroy(void *state)
{
    rad_meshed *m = state;
    if (!m)
        return;
    rad_meshed_free(m);
    rad_free(m);
}

static rad_result matrix_free_create(rad_context *ctx, const rad_scene *scene, const rad_options *o, void **out)
{
    *out = NULL;
    if (o->closure_correction)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "rad_options.closure_correction rescales form factors, and solver '%s' computes "
                        "them afresh for every shot: use a gathering solver or hierarchical",
                        o->solver);
    rad_meshed *m = rad_alloc(ctx, RAD_MEM_SOLVER, 1, sizeof *m, "solution: matrix-free state");
    if (!m)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = rad_meshed_init(ctx, scene, o, m);
    if (r != RAD_OK) {
        rad_free(m);
        return r;
    }
    m->ff_stats.method = "none (matrix-free solver)";
    *out = m;
    return RAD_OK;
}

static rad_result matrix_free_solve(rad_context *ctx, void *state, const rad_step_hook *hook)
{
    rad_meshed *m = state;
    rad_system sys;
    rad_solve_params p;
    rad_meshed_begin(m, rad_solver_shooting.name, hook, &sys, &p);
    double t0 = rad_seconds();
    rad_result r = rad_solver_shooting.solve(ctx, &sys, &p, m->elements.radiosity, &m->solve_stats);
    rad_meshed_end(m, r, t0);
    return r;
}

static void matrix_free_view(const void *state, rad_solution_view *v)
{
    rad_meshed_view(state, v);
}

const rad_strategy rad_strategy_matrix_free = {
    "matrix-free",
    "no stored matrix: form-factor columns sampled by rays for each shot; O(n) memory",
    RAD_HAS_UNIFORM_MESH | RAD_CAN_LIGHTS | RAD_CAN_PROGRESS_IMAGES,
    matrix_free_solver_info,
    matrix_free_create,
    matrix_free_solve,
    matrix_free_view,
    matrix_free_destroy,
};
