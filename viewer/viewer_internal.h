/*
 * viewer_internal.h -- what view.c shares with window.c: loading the
 * input, the first camera, display values and writing a frame.
 */
#ifndef RAD_VIEWER_INTERNAL_H
#define RAD_VIEWER_INTERNAL_H

#include "viewer.h"

/* The scene (or solution file) of the arguments: *saved when it was a
 * solution file (solved), else a solution made but not solved. */
rad_result rv_load(rad_context *ctx, const rv_args *a, rv_step_slot *slot, rad_scene **scene, rad_solution **solution, bool *saved);
/* --camera, the scene's camera, or the whole scene framed. */
rv_camera rv_start_camera(const rad_scene *scene, const rv_args *a, const rv_renderer *renderer, double aspect);
/* malloc'd display values of a solution not being solved; false on failure. */
bool rv_display_values(rad_context *ctx, const rad_solution *solution, bool ambient, double **element_rgb,
                       double **vertex_rgb);
/* A read-back radiance frame written as the renderer's images are. */
rad_result rv_write_frame(rad_context *ctx, const char *path, int width, int height, const float *rgb,
                          double exposure);
/* The window: returns the exit status. */
int rv_window_run(rad_context *ctx, const rv_args *a, const rad_scene *scene, rad_solution *solution, rv_step_slot *slot,
                  bool saved);

#endif /* RAD_VIEWER_INTERNAL_H */
