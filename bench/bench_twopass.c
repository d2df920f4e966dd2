/*
 * bench_twopass.c -- the cost of two-pass rendering on the Cornell box
 * with a mirror block (tests/data/cornell_mirror.obj) against the plain
 * box (cornell_box.obj, the same geometry): the first pass with and
 * without the mirror images' extended form factors, and the render with
 * and without the second pass.  One thread, fixed meshes: the ratios are
 * the figures (docs/methods.md "Two-pass rendering").
 *
 *   build/bench/bench_twopass [elements ...]     (default 500 1000 2000)
 */
#include "radiosity.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Seconds to mesh and couple (F, F_ext), to solve, to render 256 x 256
 * with the second pass and without it. */
static int measure(rad_context *ctx, const char *path, size_t elements, double out[4], size_t *n)
{
    rad_scene *scene = NULL;
    if (rad_scene_load_file(ctx, path, &scene) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    rad_options o = {.target_elements = elements, .solver = "gauss-seidel"};
    rad_solution *s = NULL;
    double t = now();
    if (rad_solution_create(ctx, scene, &o, &s) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        rad_scene_destroy(scene);
        return 1;
    }
    out[0] = now() - t;
    t = now();
    rad_solution_solve(ctx, s);
    out[1] = now() - t;
    *n = rad_solution_element_count(s);
    for (int pass = 0; pass < 2; pass++) {
        rad_render_options ro = {.width = 256, .height = 256, .specular_depth = pass == 0 ? 0 : -1};
        rad_image *image = NULL;
        t = now();
        rad_solution_render(ctx, s, &ro, &image);
        out[2 + pass] = now() - t;
        rad_image_destroy(image);
    }
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
    return 0;
}

int main(int argc, char **argv)
{
    size_t sizes[8] = {500, 1000, 2000};
    int count = 3;
    if (argc > 1) {
        count = 0;
        for (int a = 1; a < argc && count < 8; a++)
            sizes[count++] = (size_t)strtoul(argv[a], NULL, 10);
    }
    rad_context_options co = {.threads = 1};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    printf("# Cornell box, mirror block against plain, 1 thread, gauss-seidel, 256x256 render, s\n");
    printf("# elements  F_plain  F+images  ratio  solve_mirror  render_2pass  render_1pass  ratio\n");
    for (int k = 0; k < count; k++) {
        double plain[4], mirror[4];
        size_t n_plain, n_mirror;
        if (measure(ctx, RAD_BENCH_DATA "/cornell_box.obj", sizes[k], plain, &n_plain) ||
            measure(ctx, RAD_BENCH_DATA "/cornell_mirror.obj", sizes[k], mirror, &n_mirror))
            return 1;
        printf("%9zu  %7.3f  %8.3f  %5.2f  %12.3f  %12.3f  %12.3f  %5.2f\n", n_mirror, plain[0], mirror[0],
               mirror[0] / plain[0], mirror[1], mirror[2], mirror[3], mirror[2] / mirror[3]);
    }
    rad_context_destroy(ctx);
    return 0;
}
