/*
 * thermal.c -- the public handles of radiative heat exchange (radiosity.h,
 * "Radiative heat exchange"): the conditions of a scene's surfaces, and the
 * net-radiation solve (thermal/thermal.c) on a solution's elements and
 * form factors, with its per-surface sums.
 */
#include "api/solution.h"
#include "thermal/thermal.h"

#include <stdlib.h>
#include <string.h>

/* ---- conditions ---- */

rad_result rad_thermal_conditions_create(rad_context *ctx, const rad_scene *scene, rad_thermal_conditions **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !scene || !out)
        return rad_null_argument(ctx, __func__);
    rad_thermal_conditions *c = rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *c, "thermal conditions");
    rad_thermal_surface *s = c ? rad_alloc(ctx, RAD_MEM_SCENE, scene->surface_count ? scene->surface_count : 1,
                                           sizeof *s, "thermal conditions")
                               : NULL;
    if (!s) {
        rad_free(c);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    c->ctx = ctx;
    c->scene = scene;
    c->surface_count = scene->surface_count;
    c->surfaces = s;
    for (size_t k = 0; k < scene->surface_count; k++)
        if (scene->surfaces[k].obstruction || scene->surfaces[k].mask)
            s[k].condition = RAD_THERMAL_OBSTRUCTION;
    *out = c;
    return RAD_OK;
}

void rad_thermal_conditions_destroy(rad_thermal_conditions *c)
{
    if (!c)
        return;
    rad_free(c->source);
    rad_free(c->surfaces);
    rad_free(c);
}

rad_result rad_thermal_conditions_load_memory(rad_context *ctx, const rad_scene *scene, const char *name,
                                              const void *data, size_t size, rad_thermal_conditions **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !scene || !name || !out || (!data && size))
        return rad_null_argument(ctx, __func__);
    return rad_thermal_conditions_parse(ctx, scene, name, data ? data : "", size, out);
}

rad_result rad_thermal_conditions_load_file(rad_context *ctx, const rad_scene *scene, const char *path,
                                            rad_thermal_conditions **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !scene || !path || !out)
        return rad_null_argument(ctx, __func__);
    unsigned char *data = NULL;
    size_t size = 0;
    rad_result r = rad_read_whole_file(ctx, path, &data, &size);
    if (r == RAD_OK)
        r = rad_thermal_conditions_parse(ctx, scene, path, (const char *)data, size, out);
    rad_free(data);
    return r;
}

rad_result rad_thermal_conditions_set(rad_context *ctx, rad_thermal_conditions *c, size_t surface,
                                      const rad_thermal_surface *s)
{
    rad_api_enter(ctx);
    if (!ctx || !c || !s)
        return rad_null_argument(ctx, __func__);
    if (surface >= c->surface_count)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: surface %zu of %zu", __func__, surface,
                        c->surface_count);
    if (c->surfaces[surface].condition == RAD_THERMAL_OBSTRUCTION)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: surface '%s' is obstruction-only: it takes no "
                        "condition", __func__, c->scene->surfaces[surface].name);
    char why[160];
    if (!rad_thermal_surface_valid(s, why, sizeof why))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: surface '%s': %s", __func__,
                        c->scene->surfaces[surface].name, why);
    c->surfaces[surface] = *s;
    return RAD_OK;
}

rad_result rad_thermal_conditions_set_environment(rad_context *ctx, rad_thermal_conditions *c, double kelvin)
{
    rad_api_enter(ctx);
    if (!ctx || !c)
        return rad_null_argument(ctx, __func__);
    if (!(isfinite(kelvin) && kelvin >= 0.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: the environment temperature must be finite and "
                        ">= 0 K, got %.6g", __func__, kelvin);
    c->environment_temperature = kelvin;
    return RAD_OK;
}

bool rad_thermal_conditions_get(const rad_thermal_conditions *c, size_t surface, rad_thermal_surface *out)
{
    if (!c || !out || surface >= c->surface_count)
        return false;
    *out = c->surfaces[surface];
    return true;
}

double rad_thermal_conditions_environment(const rad_thermal_conditions *c)
{
    return c ? c->environment_temperature : NAN;
}

/* ---- the solve ---- */

void rad_thermal_destroy(rad_thermal *t)
{
    if (!t)
        return;
    rad_free(t->emissivity);
    rad_free(t->value);
    rad_free(t->known_temperature);
    rad_free(t->surface);
    rad_free(t->surface_names);
    rad_free(t->fields.radiosity);
    rad_free(t->fields.irradiation);
    rad_free(t->fields.heat_flux);
    rad_free(t->fields.temperature);
    rad_free(t->surfaces);
    rad_free(t->element_condition);
    rad_free(t->environment);
    rad_free(t);
}

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
    t->solution = solution;
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

static void element_values(const rad_thermal *t, size_t i, rad_thermal_values *out)
{
    out->area = t->sys.area[i];
    out->emissivity = t->emissivity[i];
    out->temperature = t->fields.temperature[i];
    out->radiosity = t->fields.radiosity[i];
    out->irradiation = t->fields.irradiation[i];
    out->heat_flux = t->fields.heat_flux[i];
    out->heat = t->sys.area[i] * t->fields.heat_flux[i];
    out->condition = t->element_condition[i];
}

bool rad_thermal_surface_values(const rad_thermal *t, size_t surface, rad_thermal_values *out)
{
    if (!t || !out || surface >= t->scene->surface_count)
        return false;
    *out = t->surfaces[surface];
    return true;
}

bool rad_thermal_element_values(const rad_thermal *t, size_t element, rad_thermal_values *out)
{
    if (!t || !out || element >= t->sys.n)
        return false;
    element_values(t, element, out);
    return true;
}

double rad_thermal_get_balance(const rad_thermal *t, rad_thermal_balance *out)
{
    if (!t) {
        if (out)
            *out = (rad_thermal_balance){NAN, NAN, NAN, NAN, NAN};
        return NAN;
    }
    if (out)
        *out = t->balance;
    return t->stats.residual;
}

rad_result rad_thermal_gebhart(rad_context *ctx, const rad_thermal *t, double *G)
{
    rad_api_enter(ctx);
    if (!ctx || !t || !G)
        return rad_null_argument(ctx, __func__);
    return rad_thermal_gebhart_factors(ctx, &t->sys, t->scene->surface_count, t->solver, &t->params, G);
}

rad_result rad_thermal_write(rad_context *ctx, const rad_thermal *t, const char *path, bool elements)
{
    rad_api_enter(ctx);
    if (!ctx || !t || !path)
        return rad_null_argument(ctx, __func__);
    return rad_write_thermal(ctx, t, path, elements);
}

rad_result rad_thermal_write_gebhart(rad_context *ctx, const rad_thermal *t, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !t || !path)
        return rad_null_argument(ctx, __func__);
    char ext[16];
    rad_path_extension(path, ext, sizeof ext);
    if (strcmp(ext, "json") != 0 && strcmp(ext, "csv") != 0) /* before the solves */
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: unknown Gebhart-factor format (use .csv or .json)",
                        path);
    size_t S = t->scene->surface_count;
    double *G = rad_alloc(ctx, RAD_MEM_OUTPUT, S ? S * S : 1, sizeof *G, "thermal: Gebhart factors");
    if (!G)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = rad_thermal_gebhart_factors(ctx, &t->sys, S, t->solver, &t->params, G);
    if (r == RAD_OK)
        r = rad_write_gebhart(ctx, t, G, path);
    rad_free(G);
    return r;
}

rad_result rad_thermal_write_stats(rad_context *ctx, const rad_thermal *t, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !t || !path)
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, t->solution->options.max_memory_bytes);
    return rad_write_thermal_stats(ctx, &t->solution->view, t, path);
}
