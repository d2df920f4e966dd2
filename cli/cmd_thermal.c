/*
 * cmd_thermal.c -- `radiosity thermal [SCENE] --bc BC.json`: radiative
 * heat exchange between grey diffuse surfaces with given temperatures or
 * heat fluxes (docs/thermal.md).  The form factors are coupled as for
 * radiosity; the net-radiation equations are then solved on that matrix
 * (rad_thermal_solve) for the radiosity, net flux, net power and the
 * unknown temperatures per surface, with the energy balance printed.
 */
#include "cli.h"

#include <limits.h>
#include <stdio.h>
#include <string.h>

int cmd_thermal_check(const cli_settings *s, char *err, size_t err_size)
{
    if (!s->bc) {
        snprintf(err, err_size, "thermal needs --bc FILE.json: the surfaces' emissivities and temperatures or "
                                "heat fluxes");
        return 1;
    }
    if (!(rad_method_capabilities(RAD_METHOD_SOLVER, s->solve.solver) & RAD_HAS_FORM_FACTORS)) {
        snprintf(err, err_size, "--solver %s keeps no form-factor matrix: thermal takes direct, gauss-seidel, "
                                "jacobi, southwell or conjugate-gradient", s->solve.solver);
        return 1;
    }
    return 0;
}

/* 4-5. the net-radiation solve on F for the conditions; the figures (and
 * the Gebhart factors, the stats) as one output set; the balance. */
static int solve_heat(cli_job *job, const rad_thermal_conditions *bc)
{
    const cli_settings *s = &job->s;
    rad_context *ctx = job->ctx;
    rad_thermal_options to = {s->solve.solver, s->thermal_tolerance, s->solve.max_iterations};
    rad_thermal *heat = NULL;
    rad_result r = rad_thermal_solve(ctx, job->sol, bc, &to, &heat);
    cli_progress_end(&job->progress);
    if (r == RAD_OK) {
        cli_begin_saving(ctx);
        r = rad_thermal_write(ctx, heat, job->out.main, s->element_level);
    }
    if (r == RAD_OK && s->gebhart)
        r = rad_thermal_write_gebhart(ctx, heat, job->out.gebhart);
    if (r == RAD_OK && s->stats)
        r = rad_thermal_write_stats(ctx, heat, job->out.stats);
    r = cli_commit(job, r);
    if (r != RAD_OK) {
        rad_thermal_destroy(heat);
        return cli_fail(ctx, r);
    }
    if (!s->quiet) {
        rad_thermal_balance b;
        double residual = rad_thermal_get_balance(heat, &b);
        char full[PATH_MAX];
        printf("wrote %s (%zu surfaces, %zu elements, residual %.2g, %.1f s)\n", cli_where(s->output, full),
               rad_scene_surface_count(job->scene), rad_solution_element_count(job->sol), residual,
               cli_now() - job->t0);
        printf("balance: sum Q = %.6g W, to the environment %.6g W, imbalance %.3g W (%.2g of sum |Q| = %.6g W)\n",
               b.net_power, b.environment_power, b.imbalance, b.relative_imbalance, b.power_scale);
    }
    rad_thermal_destroy(heat);
    return cli_status(0);
}

int cmd_thermal(cli_job *job)
{
    int status = cli_load(job);
    if (status >= 0)
        return status;
    /* A bad conditions file: before any work. */
    rad_thermal_conditions *bc = NULL;
    if (rad_thermal_conditions_load_file(job->ctx, job->scene, job->s.bc, &bc) != RAD_OK)
        status = cli_fail(job->ctx, RAD_ERROR_PARSE);
    else if ((status = cli_couple(job)) < 0)
        status = solve_heat(job, bc);
    rad_thermal_conditions_destroy(bc);
    return status;
}
