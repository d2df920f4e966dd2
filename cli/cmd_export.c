/*
 * cmd_export.c -- `radiosity export [SCENE|SOLUTION.radsol]`: solve the
 * scene (or load the solution) and write the lit mesh, glTF 2.0 (.glb,
 * .gltf) or PLY, each vertex coloured by its radiosity (docs/formats.md).
 */
#include "cli.h"

int cmd_export(cli_job *job)
{
    int status = cli_load(job);
    if (status < 0)
        status = cli_solve(job, "exporting");
    if (status >= 0)
        return status;
    /* 5. the lit mesh */
    cli_begin_saving(job->ctx);
    rad_result r = rad_solution_write_mesh(job->ctx, job->sol, job->out.main, job->s.render.exposure);
    return cli_finish(job, r, " (%zu vertices, ", rad_solution_vertex_count(job->sol));
}
