/*
 * bench_hier.c -- the hierarchical solver's figures (docs/hierarchical.md):
 *
 *   1. the Cornell box at falling epsilon: leaves, links, seconds and the
 *      worst per-surface error against the uniform 16k-element solution;
 *   2. generated offices (radiosity generate office) of 1, 10, 100 rooms
 *      (and 1000 with --big, 1000 and 1800 with --huge: about 10^6
 *      leaves) at a fixed epsilon and minimum area: leaves, links,
 *      seconds, memory, the energy balance (|absorbed - emitted| /
 *      emitted: the building is closed) and the link closure, and the
 *      fitted exponents of links and seconds against leaves; then 1, 10
 *      and 100 rooms again at the same tolerance per room (epsilon 1e-3 /
 *      rooms: epsilon is relative to the whole building's power);
 *   3. the Cornell box at about the peer's element count (issue #5: a
 *      hierarchical Galerkin solver measured at 5,398 elements, 42,475
 *      links, 0.55 s) with the classic oracle and the default one.
 *
 *   ./build/bench/bench_hier [--big | --huge] [--threads N] [--csv FILE]
 *
 * Fixed scenes, seeds and options: the counts are reproducible, the
 * seconds are this machine's.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/solution.h"

/* `radiosity render --elements 16000 --stats s.json` (tests/test_hier.c). */
static const struct {
    const char *name;
    double B[3];
} REF[] = {
    {"floor", {0.341265, 0.230563, 0.054476}},       {"ceiling", {0.296770, 0.189049, 0.040970}},
    {"back_wall", {0.516638, 0.345292, 0.081467}},   {"right_wall", {0.067887, 0.204937, 0.010718}},
    {"left_wall", {0.320233, 0.020442, 0.005289}},   {"short_block", {0.340573, 0.245550, 0.055724}},
    {"tall_block", {0.482032, 0.297611, 0.072377}},
};

static double worst_error(const rad_solution *s)
{
    double worst = 0.0;
    for (size_t i = 0; i < sizeof REF / sizeof REF[0]; i++)
        for (size_t k = 0; k < s->scene->surface_count; k++) {
            if (strcmp(s->scene->surfaces[k].name, REF[i].name))
                continue;
            double B[3];
            rad_solution_surface_radiosity(s, k, B);
            for (int c = 0; c < 3; c++)
                worst = fmax(worst, fabs(B[c] - REF[i].B[c]) / REF[i].B[c]);
        }
    return worst;
}

static int run(rad_context *ctx, const rad_scene *scene, double epsilon, double min_area, int classic,
               rad_solution **out)
{
    rad_options o = {0};
    o.solver = "hierarchical";
    o.epsilon = epsilon;
    o.min_area = min_area;
    o.classic_oracle = classic;
    rad_solution *s = NULL;
    if (rad_solution_create(ctx, scene, &o, &s) != RAD_OK || rad_solution_solve(ctx, s) != RAD_OK) {
        fprintf(stderr, "bench_hier: %s\n", rad_context_error(ctx));
        rad_solution_destroy(s);
        return 1;
    }
    *out = s;
    return 0;
}

/* Generated offices of rooms[0 .. count): leaves, links, seconds, memory,
 * the power balance (the building is closed) and the closure, then the
 * fitted exponents of links and seconds against leaves.  epsilon 1e-3, or
 * 1e-3 / rooms when per_room. */
static int offices(rad_context *ctx, const int *rooms, int count, bool per_room, FILE *out, const char *tag)
{
    printf("%6s %9s %8s %9s %9s %8s %9s %9s %8s %8s\n", "rooms", "epsilon", "patches", "leaves", "links", "links/el",
           "seconds", "MB", "power", "closure");
    double lx[8], ll[8], lt[8];
    int runs = 0;
    for (int i = 0; i < count && i < 8; i++) {
        rad_office_options oo = {rooms[i], 0, 0};
        rad_scene *scene = NULL;
        if (rad_scene_generate_office(ctx, &oo, &scene) != RAD_OK)
            return 1;
        double epsilon = per_room ? 1e-3 / rooms[i] : 1e-3;
        rad_solution *s = NULL;
        if (run(ctx, scene, epsilon, 0.02, 0, &s))
            return 1;
        const rad_hier_stats *h = s->view.hier;
        double emitted, absorbed;
        rad_solution_power(s, &emitted, &absorbed);
        double power = fabs(absorbed - emitted) / emitted;
        printf("%6d %9.0e %8zu %9zu %9zu %8.1f %9.2f %9.1f %7.2f%% %8.4f\n", rooms[i], epsilon,
               s->view.hier->patches, h->leaves, h->links, (double)h->links / (double)h->leaves,
               s->view.solve->seconds, h->bytes / 1e6, 100.0 * power, h->closure_power);
        if (out)
            fprintf(out, "%s%d,%g,%zu,%zu,%.4f,%.0f,,%.5f\n", tag, rooms[i], epsilon, h->leaves, h->links,
                    s->view.solve->seconds, h->bytes, power);
        lx[runs] = log((double)h->leaves);
        ll[runs] = log((double)h->links);
        lt[runs] = log(s->view.solve->seconds);
        runs++;
        rad_solution_destroy(s);
        rad_scene_destroy(scene);
    }
    /* Least-squares slopes in log-log. */
    double mx = 0, ml = 0, mt = 0;
    for (int i = 0; i < runs; i++)
        mx += lx[i] / runs, ml += ll[i] / runs, mt += lt[i] / runs;
    double sxx = 0, sxl = 0, sxt = 0;
    for (int i = 0; i < runs; i++) {
        sxx += (lx[i] - mx) * (lx[i] - mx);
        sxl += (lx[i] - mx) * (ll[i] - ml);
        sxt += (lx[i] - mx) * (lt[i] - mt);
    }
    printf("fitted exponents against leaves: links %.2f, seconds %.2f\n", sxl / sxx, sxt / sxx);
    return 0;
}

int main(int argc, char **argv)
{
    int threads = 0, big = 0;
    const char *csv = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--big") == 0)
            big = 1;
        else if (strcmp(argv[i], "--huge") == 0)
            big = 2;
        else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--csv") == 0 && i + 1 < argc)
            csv = argv[++i];
        else {
            fprintf(stderr, "usage: bench_hier [--big | --huge] [--threads N] [--csv FILE]\n");
            return 2;
        }
    }
    rad_context *ctx = NULL;
    rad_context_options co = {0};
    co.threads = threads;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    FILE *out = csv ? fopen(csv, "w") : NULL;
    if (out)
        fprintf(out, "scene,epsilon,leaves,links,seconds,bytes,error,power\n");

    printf("Cornell box (%d threads), error = worst per-surface channel vs 16k uniform\n",
           rad_context_threads(ctx));
    printf("%9s %8s %9s %8s %9s %8s\n", "epsilon", "leaves", "links", "links/el", "seconds", "error");
    rad_scene *box = NULL;
    if (rad_scene_create_cornell_box(ctx, &box) != RAD_OK)
        return 1;
    const double eps[] = {1e-3, 3e-4, 1e-4, 3e-5, 1e-5};
    for (size_t i = 0; i < sizeof eps / sizeof eps[0]; i++) {
        rad_solution *s = NULL;
        if (run(ctx, box, eps[i], 0.0, 0, &s))
            return 1;
        const rad_hier_stats *h = s->view.hier;
        printf("%9.0e %8zu %9zu %8.1f %9.3f %7.2f%%\n", eps[i], h->leaves, h->links,
               (double)h->links / (double)h->leaves, s->view.solve->seconds, 100.0 * worst_error(s));
        if (out)
            fprintf(out, "cornell,%g,%zu,%zu,%.4f,%.0f,%.5f,\n", eps[i], h->leaves, h->links, s->view.solve->seconds,
                    h->bytes, worst_error(s));
        rad_solution_destroy(s);
    }

    /* The epsilons that give about the peer's 5,398 elements. */
    printf("\nCornell box near the peer's element count (peer: 5398 elements, 42475 links, 0.55 s)\n");
    printf("%8s %9s %8s %9s %8s %9s %8s\n", "oracle", "epsilon", "leaves", "links", "links/el", "seconds", "error");
    const struct {
        const char *name;
        double epsilon;
        int classic;
    } peer[] = {{"classic", 1.65e-5, 1}, {"sources", 1e-5, 0}};
    for (size_t i = 0; i < sizeof peer / sizeof peer[0]; i++) {
        rad_solution *s = NULL;
        if (run(ctx, box, peer[i].epsilon, 0.0, peer[i].classic, &s))
            return 1;
        const rad_hier_stats *h = s->view.hier;
        printf("%8s %9.2e %8zu %9zu %8.1f %9.3f %7.2f%%\n", peer[i].name, peer[i].epsilon, h->leaves, h->links,
               (double)h->links / (double)h->leaves, s->view.solve->seconds, 100.0 * worst_error(s));
        if (out)
            fprintf(out, "cornell_%s,%g,%zu,%zu,%.4f,%.0f,%.5f,\n", peer[i].name, peer[i].epsilon, h->leaves,
                    h->links, s->view.solve->seconds, h->bytes, worst_error(s));
        rad_solution_destroy(s);
    }
    rad_scene_destroy(box);

    printf("\nOffices (seed 0, epsilon 1e-3, min area 0.02 m^2)\n");
    const int rooms[] = {1, 10, 100, 1000, 1800};
    if (offices(ctx, rooms, 3 + big, false, out, "office"))
        return 1;
    /* The same tolerance per room: epsilon (relative to the whole building)
     * falls as 1 / rooms, so every room is solved about as accurately. */
    printf("\nOffices at the same tolerance per room (epsilon 1e-3 / rooms, min area 0.02 m^2)\n");
    if (offices(ctx, rooms, 3, true, out, "perroom"))
        return 1;
    if (out)
        fclose(out);
    rad_context_destroy(ctx);
    return 0;
}
