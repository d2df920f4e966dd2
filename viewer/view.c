/*
 * view.c -- `radiosity view [SCENE | SOLUTION]`: load, then either draw one
 * frame off-screen (--offscreen -o FILE) or open the window, which solves
 * progressively (window.c).
 *
 * The off-screen frame is the window's drawing code (renderer.c) into a
 * float framebuffer, read back as radiance and written through the
 * library's image writer: the same exposure rule, sRGB curve and atomic
 * file as `radiosity render`, so the two can be compared pixel by pixel
 * (tests/test_viewer.c, docs/viewer.md).
 */
#include "viewer.h"
#include "viewer_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

rad_result rv_load(rad_context *ctx, const rv_args *a, rv_step_slot *slot, rad_scene **scene, rad_solution **solution, bool *saved)
{
    *scene = NULL;
    *solution = NULL;
    *saved = a->input && rad_file_is_solution(a->input);
    if (*saved)
        return rad_solution_load_file(ctx, a->input, scene, solution);
    rad_result r = a->input ? rad_scene_load_file(ctx, a->input, scene) : rad_scene_create_cornell_box(ctx, scene);
    if (r == RAD_OK && a->luminaires)
        r = rad_scene_load_luminaires(ctx, *scene, a->luminaires);
    rad_options options = a->solve;
    options.on_step = rv_step_forward;
    options.on_step_user = slot;
    if (r == RAD_OK)
        r = rad_solution_create(ctx, *scene, &options, solution);
    if (r != RAD_OK) {
        rad_scene_destroy(*scene);
        *scene = NULL;
    }
    return r;
}

rv_camera rv_start_camera(const rad_scene *scene, const rv_args *a, const rv_renderer *renderer, double aspect)
{
    rad_camera camera;
    if (a->camera)
        return rv_camera_from(a->camera);
    if (rad_scene_camera(scene, &camera))
        return rv_camera_from(&camera);
    /* No camera: look along -z at the whole scene (the renderer's framing
     * looks the same way). */
    double centre[3], radius;
    rv_renderer_bounds(renderer, centre, &radius);
    rv_camera c = {{centre[0], centre[1], centre[2] + 1.0}, {centre[0], centre[1], centre[2]}, {0.0, 1.0, 0.0}, 40.0};
    rv_camera_frame(&c, centre, radius, aspect);
    return c;
}

/* Display values (3 per element and vertex) of a solution not being
 * solved; NULL arrays on failure. */
bool rv_display_values(rad_context *ctx, const rad_solution *solution, bool ambient, double **element_rgb,
                       double **vertex_rgb)
{
    size_t ne = rad_solution_element_count(solution), nv = rad_solution_vertex_count(solution);
    *element_rgb = malloc((ne ? ne : 1) * 3 * sizeof **element_rgb);
    *vertex_rgb = malloc((nv ? nv : 1) * 3 * sizeof **vertex_rgb);
    if (*element_rgb && *vertex_rgb &&
        rad_solution_display_radiosity(ctx, solution, ambient, *element_rgb, *vertex_rgb) == RAD_OK)
        return true;
    free(*element_rgb);
    free(*vertex_rgb);
    *element_rgb = *vertex_rgb = NULL;
    return false;
}

rad_result rv_write_frame(rad_context *ctx, const char *path, int width, int height, const float *rgb,
                          double exposure)
{
    rad_image *image = NULL;
    rad_result r = rad_image_from_pixels(ctx, width, height, rgb, &image);
    if (r == RAD_OK)
        r = rad_image_write_exposed(ctx, image, path, exposure);
    rad_image_destroy(image);
    return r;
}

static int offscreen_frame(rad_context *ctx, const rv_args *a, const rad_scene *scene, rad_solution *solution)
{
    char why[256];
    rv_offscreen *o = rv_offscreen_create(why, sizeof why);
    if (!o) {
        fprintf(stderr, "radiosity: view: %s\n", why);
        return RV_EXIT_NO_DEVICE;
    }
    int status = 1;
    int width = a->width ? a->width : 512, height = a->height ? a->height : 512;
    double *element_rgb = NULL, *vertex_rgb = NULL;
    float *rgb = malloc((size_t)width * (size_t)height * 3 * sizeof *rgb);
    rv_renderer *renderer = NULL;
    if (!rgb || !rv_display_values(ctx, solution, !a->no_ambient, &element_rgb, &vertex_rgb)) {
        fprintf(stderr, "radiosity: view: %s\n", rgb ? rad_context_error(ctx) : "out of memory");
        goto done;
    }
    renderer = rv_renderer_create(solution, element_rgb, vertex_rgb);
    if (!renderer) {
        fprintf(stderr, "radiosity: view: cannot build the OpenGL buffers\n");
        goto done;
    }
    rv_camera camera = rv_start_camera(scene, a, renderer, (double)width / height);
    rv_draw d = {.camera = &camera, .width = width, .height = height, .shading = a->shading,
                 .output = RV_OUTPUT_RADIANCE};
    if (!rv_offscreen_draw(o, renderer, &d, a->samples ? a->samples : 4, rgb)) {
        fprintf(stderr, "radiosity: view: cannot draw a %d x %d frame off-screen\n", width, height);
        goto done;
    }
    const char *path = a->output ? a->output : "view.png";
    rad_result r = rv_write_frame(ctx, path, width, height, rgb, a->exposure);
    if (r != RAD_OK) {
        fprintf(stderr, "radiosity: view: %s\n", rad_context_error(ctx));
        goto done;
    }
    if (!a->quiet)
        printf("wrote %s (%d x %d, %zu elements, OpenGL: %s)\n", path, width, height,
               rad_solution_element_count(solution), rv_offscreen_renderer_name(o));
    status = 0;
done:
    rv_renderer_destroy(renderer);
    free(element_rgb);
    free(vertex_rgb);
    free(rgb);
    rv_offscreen_destroy(o);
    return status;
}

int rv_main(rad_context *ctx, const rv_args *a)
{
    rad_scene *scene = NULL;
    rad_solution *solution = NULL;
    bool saved = false;
    rv_step_slot slot = {NULL, NULL};
    rad_result r = rv_load(ctx, a, &slot, &scene, &solution, &saved);
    if (r != RAD_OK) {
        fprintf(stderr, "radiosity: view: %s\n", rad_context_error(ctx));
        return 1;
    }
    int status;
    if (a->offscreen) {
        /* One frame: solved first (a solution file already is). */
        r = saved ? RAD_OK : rad_solution_solve(ctx, solution);
        if (r != RAD_OK) {
            fprintf(stderr, "radiosity: view: %s\n", rad_context_error(ctx));
            status = 1;
        } else {
            status = offscreen_frame(ctx, a, scene, solution);
        }
    } else {
        status = rv_window_run(ctx, a, scene, solution, &slot, saved);
    }
    rad_solution_destroy(solution);
    rad_scene_destroy(scene);
    return status;
}
