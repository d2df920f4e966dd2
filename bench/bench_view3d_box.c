/*
 * bench_view3d_box.c -- the element view factors of one scene file, timed
 * without writing them: the View3D comparison of issue #17 (the box of
 * bench/view3d_box.py, driven by bench/view3d_box.sh).
 *
 *   build/bench/bench_view3d_box SCENE [--method NAME] [--threads N] [--elements N]
 *
 * Meshes with one element per polygon (a mesh size of 10 m: the box's
 * facets are 1/N m; with --elements, about that many in all), builds the Embree BVH, runs the form-factor method
 * (default analytic) and prints: elements, wall and CPU seconds of the
 * form-factor phase, rays, pairs, max |row sum - 1|, the worst reciprocity
 * error.  Seed 0; no closure correction or other smoothing: on a closed
 * scene the row sums are a true error measure.
 */
#include "api/solution.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

static double cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv)
{
    const char *path = NULL, *method_name = "analytic";
    int threads = 1;
    size_t elements = 0;
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--threads") == 0 && a + 1 < argc)
            threads = atoi(argv[++a]);
        else if (strcmp(argv[a], "--elements") == 0 && a + 1 < argc)
            elements = (size_t)atol(argv[++a]);
        else if (strcmp(argv[a], "--method") == 0 && a + 1 < argc)
            method_name = argv[++a];
        else if (argv[a][0] != '-' && !path)
            path = argv[a];
        else {
            fprintf(stderr, "usage: bench_view3d_box SCENE [--method NAME] [--threads N] [--elements N]\n");
            return 2;
        }
    }
    const rad_ff_method *method = rad_ff_find(method_name);
    if (!path || threads < 1 || !method) {
        fprintf(stderr, "usage: bench_view3d_box SCENE [--method NAME] [--threads N] [--elements N]\n");
        return 2;
    }
    rad_context_options co = {0};
    co.threads = threads;
    co.read_outside_scene_folder = true;
    rad_context *ctx;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_vis *vis = NULL;
    rad_mesh_options mo = {elements ? 0.0 : 10.0, elements, 0};
    if (rad_scene_load_file(ctx, path, &scene) != RAD_OK || rad_mesh_build(ctx, scene, &mo, &mesh) != RAD_OK ||
        rad_vis_create(ctx, "embree", mesh, &vis) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    rad_ff_request req = {0};
    req.mesh = mesh;
    req.vis = vis;
    req.source = path;
    double *F = NULL;
    rad_ff_stats st;
    double wall = rad_seconds(), cpu = cpu_seconds();
    if (rad_form_factors(ctx, method, &req, 1e12, false, &F, NULL, &st) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    wall = rad_seconds() - wall;
    cpu = cpu_seconds() - cpu;
    double worst = fmax(fabs(st.row_sum_max - 1.0), fabs(st.row_sum_min - 1.0));
    printf("%9zu %7d %9.2f %9.2f %12llu %12llu %12.2e %12.2e\n", mesh->element_count, threads, wall, cpu,
           (unsigned long long)st.rays, (unsigned long long)st.pairs, worst, st.reciprocity_max);
    rad_free(F);
    rad_vis_destroy(vis);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
