/*
 * cmd_generate.c -- `radiosity generate office [--rooms N] [--seed S]
 * [-o office.obj] [--quiet]`: build a procedural scene with the library
 * (rad_scene_generate_office) and write it as OBJ + MTL
 * (rad_scene_write_obj, atomic: both files or neither; a signal before
 * they are in place leaves neither).  The kinds of scene and their
 * options are in docs/scenes.md.
 */
#include "cli.h"

#include <inttypes.h>
#include <stdio.h>

int cmd_generate(cli_job *job)
{
    const cli_settings *s = &job->s;
    rad_context *ctx = job->ctx;
    double start = cli_now();
    rad_scene *scene = NULL;
    rad_result r = rad_scene_generate_office(ctx, &s->office, &scene);
    double generated = cli_now();
    if (r == RAD_OK)
        r = rad_scene_write_obj(ctx, scene, s->output);
    int status = 0;
    if (r == RAD_ERROR_INTERRUPTED) {
        fprintf(stderr, "radiosity: interrupted; nothing written\n");
        status = 1; /* 130 / 143 below */
    } else if (r != RAD_OK) {
        char message[1024];
        cli_rewrite_message(rad_context_error(ctx), message, sizeof message);
        fprintf(stderr, "radiosity: %s\n", message);
        status = r == RAD_ERROR_INVALID_ARGUMENT ? EXIT_USAGE : 1;
    } else if (!s->quiet) {
        /* 0 rooms is the library's default, which its option table gives. */
        const rad_option_info *rooms_row = rad_option_find(RAD_OPTION_SET_OFFICE, "rooms");
        int rooms = s->office.rooms ? s->office.rooms : (int)rooms_row->default_value;
        printf("wrote %s (office, %d rooms, seed %" PRIu64 ": %zu surfaces, %zu polygons; "
               "generated in %.3f s, written in %.3f s)\n",
               s->output, rooms, s->office.seed, rad_scene_surface_count(scene),
               rad_scene_polygon_count(scene), generated - start, cli_now() - generated);
    }
    rad_scene_destroy(scene);
    return cli_status(status);
}
