/*
 * options.c -- rad_options as a solution uses them: defaults filled in,
 * every field checked against its range, method names looked up in the
 * registries (an unknown name lists the known ones).
 */
#include "api/options.h"

#include "strategy/strategy.h"

#include <string.h>

/* Registry names are short; the copy keeps the options independent of the
 * caller's strings. */
static void copy_name(char *dst, size_t size, const char *name)
{
    snprintf(dst, size, "%s", name);
}

/* "a, b, c" listing of a registry, for error messages. */
static void list_methods(rad_method_kind kind, char *buf, size_t size)
{
    buf[0] = '\0';
    const char *name, *desc;
    for (size_t i = 0; rad_method_info(kind, i, &name, &desc); i++) {
        if (i)
            strncat(buf, ", ", size - strlen(buf) - 1);
        strncat(buf, name, size - strlen(buf) - 1);
    }
}

rad_result rad_options_resolve(rad_context *ctx, const rad_options *in, rad_options *out, rad_method_names *names)
{
    rad_options o = in ? *in : (rad_options){0};
    char known[256];
    if (!o.form_factors)
        o.form_factors = "analytic";
    if (!o.solver)
        o.solver = "gauss-seidel";
    if (!o.visibility)
        o.visibility = "embree";
    if (!rad_ff_find(o.form_factors)) {
        list_methods(RAD_METHOD_FORM_FACTOR, known, sizeof known);
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "unknown form-factor method '%s' (known: %s)",
                        o.form_factors, known);
    }
    if (!rad_strategy_for_solver(o.solver)) {
        list_methods(RAD_METHOD_SOLVER, known, sizeof known);
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "unknown solver '%s' (known: %s)", o.solver,
                        known);
    }
    if (!rad_vis_find(o.visibility)) {
        list_methods(RAD_METHOD_VISIBILITY, known, sizeof known);
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "unknown visibility backend '%s' (known: %s)", o.visibility, known);
    }
    if (o.tolerance == 0.0)
        o.tolerance = 1e-6;
    if (!(o.tolerance > 0.0 && o.tolerance < 1.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "tolerance must be in (0, 1), got %g",
                        o.tolerance);
    if (o.max_iterations < 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "max iterations must be >= 0");
    if (o.shadow_rays < 0 || o.shadow_rays > 48)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "shadow rays must be in [1, 48], got %d",
                        o.shadow_rays);
    if (o.shadow_rays == 0)
        o.shadow_rays = 4;
    if (o.hemicube_resolution < 0 || o.hemicube_resolution > 8192)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "hemicube resolution must be in [2, 8192], got %d",
                        o.hemicube_resolution);
    if (o.samples < 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "samples must be positive, got %d", o.samples);
    if (!(o.near_field >= 0.0) || !isfinite(o.near_field))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "near field must be a positive number of element sizes");
    if (o.relaxation == 0.0)
        o.relaxation = 1.0;
    if (!(o.relaxation > 0.0 && o.relaxation < 2.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "relaxation must be in (0, 2), got %g", o.relaxation);
    if (!(o.unshot_tolerance >= 0.0 && o.unshot_tolerance < 1.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "unshot tolerance must be in [0, 1), got %g",
                        o.unshot_tolerance);
    if (o.max_memory_bytes == 0.0)
        o.max_memory_bytes = 0.8 * (double)rad_physical_memory_bytes();
    if (!(o.epsilon >= 0.0 && o.epsilon < 1e6))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "epsilon must be positive, got %g", o.epsilon);
    if (!(o.min_area >= 0.0) || !isfinite(o.min_area))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "min area must be a positive area in m^2");
    if (o.clustering < -1 || o.clustering > 1)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "clustering must be -1, 0 or 1");
    if (!(o.max_memory_bytes > 0.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "max memory must be positive");
    copy_name(names->form_factors, sizeof names->form_factors, o.form_factors);
    copy_name(names->solver, sizeof names->solver, o.solver);
    copy_name(names->visibility, sizeof names->visibility, o.visibility);
    o.form_factors = names->form_factors;
    o.solver = names->solver;
    o.visibility = names->visibility;
    *out = o;
    return RAD_OK;
}

