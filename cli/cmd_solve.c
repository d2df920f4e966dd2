/*
 * cmd_solve.c -- `radiosity solve [SCENE]`: solve the scene and write the
 * solution file (.radsol, docs/formats.md), which render, export, bake and
 * illuminance load to draw or light it again without solving.
 *
 * An interrupted solve is not a solution: it leaves the partial stats
 * only, where render and export write the partial iterate.
 */
#include "cli.h"

#include <limits.h>
#include <stdio.h>

int cmd_solve(cli_job *job)
{
    int status = cli_load(job);
    if (status < 0)
        status = cli_solve(job, "rendering");
    if (status >= 0)
        return status;
    /* 5. the solution file, with the stats and the history, put in place
     * together */
    const cli_settings *s = &job->s;
    cli_begin_saving(job->ctx);
    if (job->partial)
        rad_output_set_drop(job->out.set, s->output);
    rad_result r = job->partial ? RAD_OK : rad_solution_save(job->ctx, job->sol, job->out.main);
    r = cli_commit(job, cli_write_records(job, r));
    if (r != RAD_OK)
        return cli_fail(job->ctx, r);
    if (job->partial) {
        fprintf(stderr, "radiosity: interrupted while solving; no solution file written%s\n",
                s->stats ? ", the partial stats only" : "");
        return cli_interrupted_status();
    }
    char full[PATH_MAX];
    if (!s->quiet)
        printf("wrote %s (%zu elements, residual %.2g, %.1f s)\n", cli_where(s->output, full),
               rad_solution_element_count(job->sol), rad_solution_residual(job->sol), cli_now() - job->t0);
    return cli_status(0);
}
