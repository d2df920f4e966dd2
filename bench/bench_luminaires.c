/*
 * bench_luminaires.c -- the cost of the luminaires' direct light: the room
 * of tests/data/luminaires (4 x 4 x 3 m, five luminaires of a 0.3 m round
 * opening, one tilted 0.5 m below the ceiling) meshed at 500, 2000 and
 * 8000 elements, solution creation (mesh, rays, the direct light; the
 * matrix-free strategy, so no form factors) with and without the layout:
 * the difference is the direct-light pass.  Also the lumens landing
 * against the luminaires' flux.  Fixed scene, no sampling: the same
 * figures each run but for the clock.
 *
 *     build/bench/bench_luminaires [THREADS]        (default 1)
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

int main(int argc, char **argv)
{
    int threads = argc > 1 ? atoi(argv[1]) : 1;
    rad_context_options co = {.threads = threads};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    const size_t counts[] = {500, 2000, 8000};
    printf("elements  create s  lit s    direct s  us/element/luminaire  landed/flux - 1  (%d thread%s)\n", threads,
           threads == 1 ? "" : "s");
    for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++) {
        double seconds[2] = {0, 0}, landed = 0.0, flux = 0.0;
        size_t n = 0, lights = 0;
        for (int lit = 0; lit < 2; lit++) {
            rad_scene *scene = NULL;
            rad_solution *sol = NULL;
            if (rad_scene_load_file(ctx, RAD_BENCH_DATA "/luminaires/room.obj", &scene) != RAD_OK ||
                (lit && rad_scene_load_luminaires(ctx, scene, RAD_BENCH_DATA "/luminaires/layout.json") != RAD_OK)) {
                fprintf(stderr, "bench_luminaires: %s\n", rad_context_error(ctx));
                return 1;
            }
            rad_options o = {.solver = "shooting", .target_elements = counts[k]};
            double t = now();
            if (rad_solution_create(ctx, scene, &o, &sol) != RAD_OK) {
                fprintf(stderr, "bench_luminaires: %s\n", rad_context_error(ctx));
                return 1;
            }
            seconds[lit] = now() - t;
            n = rad_solution_element_count(sol);
            if (lit) {
                lights = rad_scene_luminaire_count(scene);
                for (size_t i = 0; i < lights; i++)
                    flux += rad_scene_luminaire_flux(scene, i);
                landed = rad_solution_direct_lumens(sol);
            }
            rad_solution_destroy(sol);
            rad_scene_destroy(scene);
        }
        double direct = seconds[1] - seconds[0];
        printf("%8zu  %8.3f  %8.3f  %8.3f  %20.1f  %15.2e\n", n, seconds[0], seconds[1], direct,
               1e6 * direct / ((double)n * (double)lights), landed / flux - 1.0);
    }
    rad_context_destroy(ctx);
    return 0;
}
