/*
 * cmd_view.c -- `radiosity view [SCENE|SOLUTION.radsol]`: the window that
 * shows the solution as the solver refines it, or with --offscreen one
 * frame drawn with OpenGL (viewer/, docs/viewer.md), when this program was
 * built with the viewer (CMake RADIOSITY_VIEWER).
 */
#include "cli.h"
#ifdef RADIOSITY_HAVE_VIEWER
#include "viewer.h"
#endif

#include <stdio.h>

int cmd_view(cli_job *job)
{
#ifdef RADIOSITY_HAVE_VIEWER
    const cli_settings *s = &job->s;
    rad_camera camera;
    if (s->camera && rad_camera_from_string(job->ctx, s->camera, &camera) != RAD_OK) {
        fprintf(stderr, "radiosity: --%s (see radiosity view --help)\n", rad_context_error(job->ctx));
        return cli_status(EXIT_USAGE);
    }
    if (s->luminaires && s->scene_path && rad_file_is_solution(s->scene_path)) {
        fprintf(stderr, "radiosity: --luminaires: %s is a solution file, solved already (give the layout with "
                        "the scene)\n", s->scene_path);
        return cli_status(EXIT_USAGE);
    }
    rv_args a = {.input = s->scene_path, .luminaires = s->luminaires, .solve = s->solve, .width = s->render.width,
                 .height = s->render.height, .camera = s->camera ? &camera : NULL,
                 .shading = s->render.shading, .exposure = s->render.exposure, .output = s->output,
                 .offscreen = s->offscreen != 0, .no_ambient = s->no_ambient != 0, .keys = s->keys,
                 .quiet = s->quiet != 0};
    return cli_status(rv_main(job->ctx, &a));
#else
    (void)job;
    fprintf(stderr, "radiosity: view: this program was built without the viewer (it needs libsdl2-dev and "
                    "libepoxy-dev: scripts/setup.sh installs them, then rebuild; docs/viewer.md)\n");
    return cli_status(1);
#endif
}
