/*
 * cmd_bake.c -- `radiosity bake [SCENE|SOLUTION.radsol]`: solve the scene
 * (or load the solution) and bake it into lightmaps (HDR, RGBM PNG) with
 * the glTF lit mesh that uses them (rad_solution_bake, docs/formats.md).
 * The first atlas's lightmaps are planned with the outputs (main.c); the
 * others join the output set when the packing knows them.
 */
#include "cli.h"

int cmd_bake(cli_job *job)
{
    int status = cli_load(job);
    if (status < 0)
        status = cli_solve(job, "baking");
    if (status >= 0)
        return status;
    /* 5. the lightmaps and the mesh */
    const cli_settings *s = &job->s;
    cli_begin_saving(job->ctx);
    rad_bake_options bo = {s->texels_per_metre, s->atlas_size, (rad_lightmap_quantity)s->lightmap_quantity,
                           s->render.exposure};
    rad_bake_stats baked = {0};
    rad_result r = rad_solution_bake(job->ctx, job->sol, &bo, job->out.set, s->output, &baked);
    return cli_finish(job, r, " and %zu lightmap%s (fill %.1f%%, baked in %.2f s; ", baked.atlases,
                      baked.atlases == 1 ? "" : "s", 100.0 * baked.chart_texels / baked.atlas_texels, baked.seconds);
}
