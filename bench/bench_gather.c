/*
 * bench_gather.c -- the illuminance gathering at calculation points, every
 * element exactly against the element tree (src/grid/cluster.c, far
 * clusters as one source), on the seeded office lit by its ceiling panels:
 * one grid per room (its floor footprint at 0.8 m, border 0.5 m), the
 * solution by matrix-free shooting at a target element count.  Prints the
 * points, the elements, the seconds of each gathering, their ratio, and
 * the tree's error against the exact values per point (lux, total and
 * indirect; mean, 99th percentile and largest relative error).
 *
 *   build/bench/bench_gather [--rooms N] [--elements N] [--spacing M] [--threads N] [--theta T]
 *
 * --theta sets the opening criterion (RAD_GRID_GATHER_THETA by default):
 * the trade of speed against error that chose the default.  Fixed seeds:
 * figures are comparable across commits on one machine.
 */
#include "api/solution.h"
#include "grid/grid.h"

#include <stdlib.h>
#include <string.h>

static void usage(void)
{
    fprintf(stderr, "usage: bench_gather [--rooms N] [--elements N] [--spacing M] [--threads N] [--theta T]\n");
    exit(2);
}

static double lux(const double H[3])
{
    return 179.0 * (0.265 * H[0] + 0.670 * H[1] + 0.065 * H[2]);
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    int threads = 1, rooms = 10;
    size_t elements = 8000;
    double spacing = 0.4, theta = 0.0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--rooms") == 0 && i + 1 < argc)
            rooms = atoi(argv[++i]);
        else if (strcmp(argv[i], "--elements") == 0 && i + 1 < argc)
            elements = (size_t)atol(argv[++i]);
        else if (strcmp(argv[i], "--spacing") == 0 && i + 1 < argc)
            spacing = atof(argv[++i]);
        else if (strcmp(argv[i], "--theta") == 0 && i + 1 < argc)
            theta = atof(argv[++i]);
        else
            usage();
    }
    if (rooms < 1 || elements < 1 || !(spacing > 0.0) || threads < 0 || theta < 0.0)
        usage();
    rad_context_options co = {0};
    co.threads = threads;
    rad_context *ctx;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    rad_office_options oo = {rooms, 1, 0};
    rad_scene *scene;
    if (rad_scene_generate_office(ctx, &oo, &scene) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    /* One grid per room: its floor footprint at 0.8 m (docs/lighting.md). */
    size_t cap = 256 + 160 * scene->surface_count, len = 0;
    char *json = malloc(cap);
    len += (size_t)snprintf(json + len, cap - len, "{\"up\": \"y\", \"grids\": [");
    for (size_t s = 0, k = 0; s < scene->surface_count; s++) {
        const char *name = scene->surfaces[s].name, *slash = strchr(name, '/');
        if (slash && strcmp(slash, "/floor") == 0)
            len += (size_t)snprintf(json + len, cap - len, "%s{\"name\": \"%s\", \"surface\": \"%s\", \"height\": 0.8, "
                                    "\"spacing\": %.6f}", k++ ? ", " : "", name, name, spacing);
    }
    snprintf(json + len, cap - len, "]}");

    rad_options o = {0};
    o.target_elements = elements;
    o.solver = "shooting";
    o.seed = 1;
    rad_solution *sol;
    if (rad_solution_create(ctx, scene, &o, &sol) != RAD_OK || rad_solution_solve(ctx, sol) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    rad_grid_set *set;
    if (rad_grid_parse(ctx, scene, "office_grid.json", json, strlen(json), &set) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    free(json);
    size_t n = set->point_count;
    rad_solution_view view = sol->view;
    view.threads = rad_context_threads(ctx);
    /* 0: exact, 1: the tree, 2: exact again with another seed (its shadow
     * rays' own noise), 3: the reference, exact with 8 x 8 rays for every
     * element (the default's single ray to a far element, its hidden part
     * taken from the unoccluded factor and clamped to [0, F], lets a
     * little of a wholly blocked element through: a bias, not noise). */
    enum { RUNS = 4 };
    double *H[RUNS];
    rad_grid_gather_stats st[RUNS];
    rad_options reseeded = *view.options;
    reseeded.seed += 1;
    for (int m = 0; m < RUNS; m++) {
        H[m] = malloc(6 * n * sizeof *H[m]);
        rad_solution_view v = view;
        if (m == 2)
            v.options = &reseeded;
        rad_grid_gather_method method = m == 1 ? RAD_GRID_GATHER_TREE : RAD_GRID_GATHER_EXACT;
        if (rad_grid_gather_tuned(ctx, &v, set, method, theta, m == 3 ? 8 : 0, H[m], H[m] + 3 * n, &st[m]) !=
            RAD_OK) {
            fprintf(stderr, "%s\n", rad_context_error(ctx));
            return 1;
        }
    }
    /* Errors per point against the reference: the exact gathering's, the
     * tree's, and the exact one's against itself with another seed. */
    static const char *const what[3] = {"exact against the reference", "tree against the reference",
                                        "exact against exact, seed + 1"};
    double *rel[3], sum[3] = {0, 0, 0}, mean[RUNS] = {0, 0, 0, 0};
    for (int m = 0; m < 3; m++)
        rel[m] = malloc((n + 1) * sizeof *rel[m]);
    for (size_t k = 0; k < n; k++)
        for (int m = 0; m < RUNS; m++)
            mean[m] += (lux(H[m] + 3 * k) + lux(H[m] + 3 * (n + k))) / (double)n;
    /* Differences in lux over the reference's mean over the grid: a point
     * inside furniture (a fraction of a lux) says nothing relative to its
     * own value. */
    for (size_t k = 0; k < n; k++) {
        double E[RUNS];
        for (int m = 0; m < RUNS; m++)
            E[m] = lux(H[m] + 3 * k) + lux(H[m] + 3 * (n + k));
        double against[3] = {E[3], E[3], E[0]}, value[3] = {E[0], E[1], E[2]};
        for (int m = 0; m < 3; m++) {
            rel[m][k] = mean[3] > 0.0 ? fabs(value[m] - against[m]) / mean[3] : 0.0;
            sum[m] += rel[m][k];
        }
    }
    size_t p99 = n ? (size_t)(0.99 * (double)(n - 1)) : 0;
    for (int m = 0; m < 3; m++)
        qsort(rel[m], n, sizeof *rel[m], by_value);
    printf("office: %d rooms (seed 1), lit by its panels; %zu elements (shooting, target %zu), %d threads\n", rooms,
           view.n, elements, rad_context_threads(ctx));
    printf("grid: %zu floor footprints at 0.8 m, spacing %.2f m: %zu points; mean lux: exact %.2f, tree %.2f, "
           "reference %.2f\n", set->grid_count, spacing, n, mean[0], mean[1], mean[3]);
    printf("%-9s %9s %10s %12s %12s %12s %12s\n", "gather", "seconds", "points/s", "exact pairs", "ray pairs",
           "clusters", "rays");
    static const char *const name[RUNS] = {"exact", "tree", "exact'", "reference"};
    for (int m = 0; m < RUNS; m++)
        if (m != 2)
            printf("%-9s %9.3f %10.0f %12llu %12llu %12llu %12llu\n", name[m], st[m].seconds,
                   (double)n / st[m].seconds, (unsigned long long)st[m].exact_pairs,
                   (unsigned long long)st[m].ray_pairs, (unsigned long long)st[m].cluster_pairs,
                   (unsigned long long)st[m].rays);
    printf("points %zu elements %zu exact_s %.3f tree_s %.3f ratio %.2f theta %.3f (tree rays to representatives "
           "%llu)\n", n, view.n, st[0].seconds, st[1].seconds, st[0].seconds / st[1].seconds,
           theta > 0.0 ? theta : RAD_GRID_GATHER_THETA, (unsigned long long)st[1].cluster_rays);
    for (int m = 0; m < 3; m++) {
        printf("%s: |difference| per point over the grid's mean: mean %.2e, 99%% %.2e, max %.2e\n", what[m],
               n ? sum[m] / (double)n : 0.0, rel[m][p99], n ? rel[m][n - 1] : 0.0);
        free(rel[m]);
    }
    for (int m = 0; m < RUNS; m++)
        free(H[m]);
    rad_grid_set_destroy(set);
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
