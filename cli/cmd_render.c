/*
 * cmd_render.c -- `radiosity render [SCENE|SOLUTION.radsol]`: solve the
 * scene (or load the solution) and draw it from a camera: the image
 * (PNG exposed in sRGB, HDR or PFM linear), or with --false-colour a
 * picture of luminance or illuminance with its legend.
 *
 * The camera is the user's (--camera, whose syntax the library owns), the
 * scene's, or one framing the scene; one that cannot see the scene is
 * refused before the solve, not after it.
 */
#include "cli.h"

#include <stdio.h>

int cmd_render(cli_job *job)
{
    cli_settings *s = &job->s;
    rad_context *ctx = job->ctx;
    rad_false_colour_options false_colour;
    int status = cli_false_colour_options(job, &false_colour);
    if (status >= 0)
        return status;
    status = cli_load(job);
    if (status >= 0)
        return status;
    rad_camera camera;
    if (s->camera) {
        /* The library owns the camera syntax (docs/cli.md).  Its messages
         * begin "camera: "; with "--" before them they name our flag. */
        if (rad_camera_from_string(ctx, s->camera, &camera) != RAD_OK) {
            fprintf(stderr, "radiosity: --%s (see radiosity render --help)\n", rad_context_error(ctx));
            return EXIT_USAGE;
        }
        s->render.camera = &camera;
    }
    /* A camera too far from the scene to draw it is refused now, not after
     * the solve (the automatic one frames the scene). */
    rad_camera chosen;
    if ((s->camera ? (chosen = camera, true) : rad_scene_camera(job->scene, &chosen)) &&
        rad_scene_check_camera(ctx, job->scene, &chosen) != RAD_OK) {
        fprintf(stderr, "radiosity: %s%s\n", s->camera ? "--" : "", rad_context_error(ctx));
        return s->camera ? EXIT_USAGE : 1;
    }
    status = cli_solve(job, "rendering");
    if (status >= 0)
        return status;

    /* 5. the image, or the false colour picture */
    cli_begin_saving(ctx);
    rad_image *image = NULL;
    rad_result r;
    if (s->false_colour) {
        r = rad_solution_write_false_colour(ctx, job->sol, &s->render, &false_colour, job->out.main);
        cli_progress_end(&job->progress);
    } else {
        r = rad_solution_render(ctx, job->sol, &s->render, &image);
        cli_progress_end(&job->progress);
        if (r == RAD_OK)
            r = rad_image_write_exposed(ctx, image, job->out.main, s->render.exposure);
    }
    int width = image ? rad_image_width(image) : s->render.width ? s->render.width : 512;
    int height = image ? rad_image_height(image) : s->render.height ? s->render.height : 512;
    rad_image_destroy(image);
    return cli_finish(job, r, " (%dx%d, ", width, height);
}
