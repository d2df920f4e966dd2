/*
 * bench_stream.c -- memory and time of view factors in row blocks
 * (rad_scene_stream_view_factors) on a generated office, at one element
 * count per run (bench/stream.sh runs it at 10k, 50k and 100k elements).
 *
 *     bench_stream ELEMENTS [--rooms R] [--block-rows B] [--threads N]
 *                  [--method NAME] [--seconds T] [--output FILE]
 *
 * Prints one line: elements, surfaces, rows per block and the block's
 * bytes, the process's peak resident memory (getrusage: everything,
 * Embree's BVH and the C library included), the dense matrix it did not
 * hold, and the time.  With --seconds T the form factors are cancelled
 * after T seconds and the total is projected from the rows done: each row
 * costs about n pair evaluations whatever its place (the pairs after it,
 * and those before its block evaluated again), so the rate is steady.
 * Surface level; the output is written only when the run completes.
 */
#include "radiosity.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct watch {
    rad_context *ctx;
    double limit;      /* s of form factors before cancelling; 0 = none */
    double start;      /* when the first row was reported */
    double last;       /* when the latest was */
    uint64_t rows;     /* rows done then */
} watch;

static void on_progress(void *user, const char *phase, uint64_t done, uint64_t total)
{
    watch *w = user;
    (void)total;
    if (strcmp(phase, "form factors") != 0)
        return;
    double t = now();
    if (w->start == 0.0)
        w->start = t;
    w->last = t;
    w->rows = done;
    if (w->limit > 0.0 && t - w->start > w->limit)
        rad_context_cancel(w->ctx, true);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_stream ELEMENTS [--rooms R] [--block-rows B] [--threads N] "
                        "[--method NAME] [--seconds T] [--output FILE]\n");
        return 2;
    }
    size_t elements = strtoull(argv[1], NULL, 10);
    int rooms = 16, threads = 2;
    size_t block = 64;
    double seconds = 0.0;
    const char *method = "hybrid", *output = "/tmp/bench_stream.json";
    for (int k = 2; k + 1 < argc; k += 2) {
        if (!strcmp(argv[k], "--rooms"))
            rooms = atoi(argv[k + 1]);
        else if (!strcmp(argv[k], "--block-rows"))
            block = strtoull(argv[k + 1], NULL, 10);
        else if (!strcmp(argv[k], "--threads"))
            threads = atoi(argv[k + 1]);
        else if (!strcmp(argv[k], "--method"))
            method = argv[k + 1];
        else if (!strcmp(argv[k], "--seconds"))
            seconds = atof(argv[k + 1]);
        else if (!strcmp(argv[k], "--output"))
            output = argv[k + 1];
    }
    watch w = {NULL, seconds, 0.0, 0.0, 0};
    rad_context_options co = {0};
    co.threads = threads;
    co.progress = on_progress;
    co.progress_user = &w;
    rad_context *ctx = NULL;
    rad_scene *scene = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    w.ctx = ctx;
    rad_office_options oo = {rooms, 1, 0};
    if (rad_scene_generate_office(ctx, &oo, &scene) != RAD_OK) {
        fprintf(stderr, "bench_stream: %s\n", rad_context_error(ctx));
        return 1;
    }
    rad_options o = {0};
    o.target_elements = elements;
    o.form_factors = method;
    rad_stream_options so = {block, 0, 0, NULL, NULL};
    rad_stream_stats st;
    double t0 = now();
    rad_result r = rad_scene_stream_view_factors(ctx, scene, &o, &so, output, &st);
    double total = now() - t0;
    if (r != RAD_OK && r != RAD_ERROR_INTERRUPTED) {
        fprintf(stderr, "bench_stream: %s\n", rad_context_error(ctx));
        return 1;
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double rss = (double)ru.ru_maxrss * 1024.0; /* Linux: kilobytes */
    double n = (double)st.elements;
    printf("elements %zu, surfaces %zu, %s, %d threads, blocks of %zu rows (%.1f MB): peak RSS %.1f MB "
           "(%.0f bytes per element; the dense matrix would be %.1f GB); mesh + BVH %.1f s",
           st.elements, rad_scene_surface_count(scene), method, threads, st.block_rows, st.block_bytes / 1e6,
           rss / 1e6, rss / n, 8.0 * n * n / 1e9, st.mesh_seconds);
    if (r == RAD_OK)
        printf(", form factors + output %.1f s (%.1f s in all)\n", st.seconds, total);
    else
        printf(", %llu rows in %.1f s: %.0f s projected for all %zu rows\n", (unsigned long long)w.rows,
               w.last - w.start, (w.last - w.start) * n / (double)(w.rows ? w.rows : 1), st.elements);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
