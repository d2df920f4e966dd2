/*
 * thermal.c -- rad_thermal_solve: the net-radiation solve (thermal/) on a
 * solution's elements and form factors, with its per-surface sums.  The
 * conditions are thermal/conditions.c's, the result's accessors
 * thermal/result.c's, its writers output/thermal_write.c's.
 */
#include "api/solution.h"
#include "thermal/thermal.h"

#include <stdlib.h>
#include <string.h>

/* ---- the solve ---- */

/* Per-surface sums: areas, Q, and area-weighted means of eps, J, G, T^4. */
static void surface_sums(rad_thermal *t)
{
    size_t S = t->scene->surface_count, n = t->sys.n;
    for (size_t i = 0; i < n; i++) {
        rad_thermal_values *v = &t->surfaces[t->surface[i]];
        double a = t->sys.area[i];
        v->area += a;
        v->emissivity += a * t->emissivity[i];
        v->radiosity += a * t->fields.radiosity[i];
        v->irradiation += a * t->fields.irradiation[i];
        v->heat += a * t->fields.heat_flux[i];
        v->temperature += a * pow(t->fields.temperature[i], 4);
    }
    for (size_t k = 0; k < S; k++) {
        rad_thermal_values *v = &t->surfaces[k];
        if (v->area > 0.0) {
            v->emissivity /= v->area;
            v->radiosity /= v->area;
            v->irradiation /= v->area;
            v->heat_flux = v->heat / v->area;
            v->temperature = pow(v->temperature / v->area, 0.25);
        }
    }
}

rad_result rad_thermal_solve(rad_context *ctx, const rad_solution *solution, const rad_thermal_conditions *c,
                             const rad_thermal_options *options, rad_thermal **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !solution || !c || !out)
        return rad_null_argument(ctx, __func__);
    rad_thermal_options o = options ? *options : (rad_thermal_options){0};
    const rad_solution_view *v = &solution->view;
    if (c->scene != solution->scene)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: the conditions are for another scene", __func__);
    if (!v->F)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "thermal: the solution has no form-factor matrix (solver '%s'): make it with a dense "
                        "solver (rad_options.solver: direct, gauss-seidel, ...)", solution->options.solver);
    const rad_solver *solver = rad_solver_find(o.solver ? o.solver : "direct");
    if (!solver)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "rad_thermal_options.solver: '%s' is not a linear solver "
                        "(rad_method_info lists them)", o.solver);
    if (o.tolerance != 0.0 && !(o.tolerance > 0.0 && o.tolerance < 1.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "rad_thermal_options.tolerance must be in (0, 1), got %g",
                        o.tolerance);
    if (o.max_iterations < 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "rad_thermal_options.max_iterations must be >= 0, got %d",
                        o.max_iterations);
    for (size_t k = 0; k < c->surface_count; k++)
        if (c->surfaces[k].condition == RAD_THERMAL_UNSET)
            return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: surface '%s' has no condition",
                            c->source ? c->source : "thermal", c->scene->surfaces[k].name);
    rad_memory_limit_call(ctx, solution->options.max_memory_bytes);

    size_t n = v->n, S = c->surface_count;
    rad_thermal *t = rad_alloc(ctx, RAD_MEM_SOLVER, 1, sizeof *t, "thermal");
    if (!t)
        return RAD_ERROR_OUT_OF_MEMORY;
    t->ctx = ctx;
    t->view = &solution->view;
    t->max_memory_bytes = solution->options.max_memory_bytes;
    t->scene = solution->scene;
    t->mesh = v->mesh;
    t->F = v->F;
    size_t m = n ? n : 1;
    t->emissivity = rad_alloc(ctx, RAD_MEM_SOLVER, m, sizeof(double), "thermal: emissivity");
    t->value = rad_alloc(ctx, RAD_MEM_SOLVER, m, sizeof(double), "thermal: conditions");
    t->known_temperature = rad_alloc(ctx, RAD_MEM_SOLVER, m, 1, "thermal: conditions");
    t->surface = rad_alloc(ctx, RAD_MEM_SOLVER, m, sizeof(uint32_t), "thermal: surfaces");
    t->surface_names = rad_alloc(ctx, RAD_MEM_SOLVER, S ? S : 1, sizeof(char *), "thermal: surfaces");
    t->fields.radiosity = rad_alloc(ctx, RAD_MEM_SOLVER, m, sizeof(double), "thermal: radiosity");
    t->fields.irradiation = rad_alloc(ctx, RAD_MEM_SOLVER, m, sizeof(double), "thermal: irradiation");
    t->fields.heat_flux = rad_alloc(ctx, RAD_MEM_SOLVER, m, sizeof(double), "thermal: heat flux");
    t->fields.temperature = rad_alloc(ctx, RAD_MEM_SOLVER, m, sizeof(double), "thermal: temperature");
    t->surfaces = rad_alloc(ctx, RAD_MEM_SOLVER, S ? S : 1, sizeof *t->surfaces, "thermal: surfaces");
    t->element_condition = rad_alloc(ctx, RAD_MEM_SOLVER, m, sizeof *t->element_condition, "thermal: conditions");
    t->environment = rad_alloc(ctx, RAD_MEM_SOLVER, m, 1, "thermal: conditions");
    if (!t->emissivity || !t->value || !t->known_temperature || !t->surface || !t->surface_names ||
        !t->fields.radiosity || !t->fields.irradiation || !t->fields.heat_flux || !t->fields.temperature ||
        !t->surfaces || !t->element_condition || !t->environment) {
        rad_thermal_destroy(t);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t k = 0; k < S; k++) {
        t->surface_names[k] = c->scene->surfaces[k].name;
        t->surfaces[k].condition = c->surfaces[k].condition;
    }
    for (size_t i = 0; i < n; i++) {
        uint32_t k = v->mesh->elements[i].surface;
        const rad_thermal_surface *s = &c->surfaces[k];
        const double *rho = v->reflectance + 3 * i;
        t->surface[i] = k;
        /* Without a given emissivity, 1 - the mean reflectance: in (0, 1]
         * since the scene's reflectances are in [0, 1). */
        t->emissivity[i] = s->emissivity > 0.0 ? s->emissivity : 1.0 - (rho[0] + rho[1] + rho[2]) / 3.0;
        t->known_temperature[i] = s->condition == RAD_THERMAL_TEMPERATURE;
        t->value[i] = s->condition == RAD_THERMAL_ADIABATIC ? 0.0 : s->value;
        t->element_condition[i] = s->condition;
        t->environment[i] = s->condition == RAD_THERMAL_OBSTRUCTION;
        if (t->environment[i]) { /* black, at the environment's temperature */
            t->emissivity[i] = 1.0;
            t->known_temperature[i] = 1;
            t->value[i] = c->environment_temperature;
        }
    }
    t->sys = (rad_thermal_system){.n = n, .F = v->F, .area = v->area, .emissivity = t->emissivity,
                                  .known_temperature = t->known_temperature, .value = t->value,
                                  .environment = t->environment,
                                  .environment_temperature = c->environment_temperature, .surface = t->surface,
                                  .surface_names = t->surface_names, .source = c->source, .threads = solution->threads,
                                  .max_memory = solution->options.max_memory_bytes};
    t->solver = solver;
    double tolerance = o.tolerance > 0.0 ? o.tolerance : 1e-10;
    double q = 1.0; /* rows of rho = 1 bound nothing: the cap, or the user's count */
    rad_solve_bound bound = rad_solve_bound_make(o.max_iterations, q, 1.0, tolerance, 1.0);
    t->params = (rad_solve_params){.tolerance = tolerance, .relaxation = 1.0,
                                   .max_iterations = o.max_iterations > 0 ? o.max_iterations : (int)bound.limit};
    rad_result r = rad_thermal_solve_system(ctx, &t->sys, solver, &t->params, &t->fields, &t->balance, &t->stats);
    if (r != RAD_OK) {
        rad_thermal_destroy(t);
        return r;
    }
    surface_sums(t);
    *out = t;
    return RAD_OK;
}
