/*
 * stream.c -- view factors in row blocks (rad_scene_stream_view_factors):
 * mesh, then for each block of element rows the form factors
 * (formfactor/rows.c) and the output's row sink (output/vf_stream.c),
 * never the n x n matrix.  Memory: the mesh, the ray structure and the
 * per-element arrays (O(n)), one block (block_rows x n doubles), and the
 * sink's state (O(n) names, or the S x S surface table).
 *
 *     rank 0:  block 0 --> sink   block 1 <-- rank 1   block 2 --> sink ...
 *     rank 1:              make block 1 --> rank 0     make block 3 ...
 *
 * With several ranks (rad_stream_ranks) block b is made by rank b % size
 * and rank 0 takes the blocks in order, so the rows reach the sink in the
 * same order and with the same bits whatever the number of ranks.
 */
#include "strategy/options.h"
#include "output/output.h"

#include <stdlib.h>
#include <string.h>
#include <sys/statvfs.h>

/* Is there room for `need` more bytes beside `path`?  Streams and devices
 * are not checked (their space is not a file system's). */
static rad_result check_disk(rad_context *ctx, const char *path, double need)
{
    if (need <= 0.0 || strncmp(path, "/dev/", 5) == 0)
        return RAD_OK;
    char *folder = rad_path_folder(path);
    struct statvfs fs;
    if (!folder)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "view factors: out of memory");
    if (statvfs(folder, &fs) != 0) {
        rad_free(folder);
        return RAD_OK; /* no file system to ask: the writes will tell */
    }
    double space = (double)fs.f_bavail * (double)fs.f_frsize;
    rad_result r = RAD_OK;
    if (need > space) /* the folder, not the path: a caller's temporary name means nothing */
        r = rad_fail(ctx, RAD_ERROR_IO,
                     "view factors: the element-level rows need about %.1f GB more in %s, whose file system has "
                     "%.1f GB free: refused (surface level writes S^2 numbers)",
                     need / 1e9, folder, space / 1e9);
    rad_free(folder);
    return r;
}

/* The refusals that do not need the mesh. */
static rad_result check_request(rad_context *ctx, const rad_options *o, const rad_ff_method *method,
                                const rad_ff_request *req, const char *path, bool elements, bool writes,
                                const rad_view_factor_options *factors, const char *why, const rad_vf_sink **sink)
{
    *sink = NULL;
    if (elements && factors && (factors->smooth || factors->sparse_threshold > 0.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "view factors: element-level factors are written as computed: smoothing and sparse "
                        "thresholds are for surface-level factors");
    if (writes) {
        *sink = rad_vf_sink_find(path, elements);
        char ext[16];
        rad_path_extension(path, ext, sizeof ext);
        if (!*sink && elements && strcmp(ext, "json") == 0)
            return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                            "view factors: element-level JSON is not written in row blocks (each row's sum "
                            "comes before all the rows): use .csv or .mtx%s",
                            why);
        if (!*sink)
            return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                            "%s: unknown view-factor format (use .json, .csv, .mtx or, for surfaces, .vf)", path);
    }
    if (o->adaptive_levels > 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "view factors in row blocks: adaptive subdivision refines the mesh between solves of "
                        "the whole matrix; leave rad_options.adaptive_levels at 0%s", why);
    return rad_ff_rows_check(ctx, method, req, o->closure_correction != 0, why);
}

/* Rank 0's part of a block: diagnostics and the sink, row by row. */
static rad_result take_block(rad_context *ctx, const rad_vf_sink *sink, void *state, const double *block,
                             size_t r0, size_t r1, size_t n, rad_stream_stats *st, double *row_total)
{
    for (size_t i = r0; i < r1; i++) {
        const double *Fi = block + (i - r0) * n;
        double row = 0.0;
        for (size_t j = 0; j < n; j++)
            row += Fi[j];
        st->row_sum_min = fmin(st->row_sum_min, row);
        st->row_sum_max = fmax(st->row_sum_max, row);
        *row_total += row;
        st->diagonal_max = fmax(st->diagonal_max, Fi[i]);
        rad_result r = sink->row(ctx, state, i, Fi);
        if (r != RAD_OK)
            return r;
    }
    return RAD_OK;
}

/* The rows per block: as asked, else what fits in 1/8 of the limit, and
 * with several ranks at most a quarter of a rank's share, so that every
 * rank gets blocks and the last ones do not leave the others idle long. */
static size_t block_rows(const rad_stream_options *so, size_t n, double limit, int size)
{
    size_t rows = so->block_rows;
    if (rows == 0) {
        double fit = limit / 8.0 / (8.0 * (double)(n ? n : 1));
        rows = fit < 1.0 ? 1 : fit > (double)n ? n : (size_t)fit;
        size_t share = (n + 4 * (size_t)size - 1) / (4 * (size_t)size);
        if (size > 1 && rows > share)
            rows = share;
    }
    return rows > n ? n : rows ? rows : 1;
}

rad_result rad_scene_stream_view_factors(rad_context *ctx, const rad_scene *scene, const rad_options *options,
                                         const rad_stream_options *so, const char *path, rad_stream_stats *st)
{
    rad_api_enter(ctx);
    if (st)
        memset(st, 0, sizeof *st);
    int rank = so && so->ranks && so->ranks->size > 1 ? so->ranks->rank : 0;
    int size = so && so->ranks && so->ranks->size > 1 ? so->ranks->size : 1;
    if (!ctx || !scene || !so || !st || (rank == 0 && !path) || rank < 0 || rank >= size)
        return rad_null_argument(ctx, __func__);
    rad_options o;
    rad_method_names names;
    rad_result r = rad_options_resolve(ctx, options, &o, &names);
    if (r != RAD_OK)
        return r;
    rad_memory_limit_call(ctx, o.max_memory_bytes);
    o.max_memory_bytes = rad_memory_limit(ctx);
    const rad_ff_method *method = rad_ff_find(o.form_factors);
    bool elements = so->elements != 0;
    const rad_vf_sink *sink = NULL;
    rad_ff_request req = {NULL, NULL, o.seed, o.shadow_rays, o.hemicube_resolution, o.samples, o.near_field,
                          NULL, scene->source, o.raw_form_factors != 0};
    /* Refused before the mesh is made, except where the dense route may
     * still be taken (only_if_needed): then once the stream is decided. */
    bool decided = !so->only_if_needed || size > 1;
    r = decided ? check_request(ctx, &o, method, &req, path, elements, rank == 0, so->factors, "", &sink) : RAD_OK;
    if (r != RAD_OK)
        return r;

    /* 1. mesh and ray structure, as the dense strategy makes them */
    rad_meshed m;
    r = rad_meshed_init(ctx, scene, &o, &m);
    if (r != RAD_OK)
        return r;
    size_t n = m.mesh->element_count;
    st->elements = n;
    st->mesh_seconds = m.seconds.mesh + m.seconds.visibility;
    double dense = 8.0 * (double)n * (double)n * ((method->flags & RAD_FF_VARIANCE) ? 2.0 : 1.0) *
                   (elements ? 2.0 : 1.0);
    if (so->only_if_needed && size == 1 && dense <= o.max_memory_bytes) {
        rad_meshed_free(&m);
        return RAD_OK;
    }
    if (!decided) {
        /* Say why the stream was taken: the caller did not ask for it. */
        char why[160];
        snprintf(why, sizeof why,
                 " (the dense matrix of %zu elements, %.2f GiB, passes the memory limit of %.2f GiB: the factors "
                 "are made in row blocks)", n, dense / 1073741824.0, o.max_memory_bytes / 1073741824.0);
        r = check_request(ctx, &o, method, &req, path, elements, rank == 0, so->factors, why, &sink);
        if (r != RAD_OK) {
            rad_meshed_free(&m);
            return r;
        }
    }
    st->streamed = 1;
    req.mesh = m.mesh;
    req.vis = m.vis;
    rad_solution_view view;
    memset(&view, 0, sizeof view);
    rad_meshed_view(&m, &view);
    rad_ff_stats ff = {0};
    ff.method = method->name;
    view.ff = &ff;
    view.scene = scene;
    view.options = &o;
    view.threads = m.threads;

    /* 2. blocks: made here or received, handed to the sink in order */
    size_t rows = block_rows(so, n, o.max_memory_bytes, size);
    st->block_rows = rows;
    st->block_bytes = 8.0 * (double)(rows * n + RAD_STREAM_TALLY);
    st->row_sum_min = n ? INFINITY : 0.0;
    st->row_sum_max = n ? -INFINITY : 0.0;
    double *block = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, rows * n + RAD_STREAM_TALLY, sizeof *block,
                              "view factors: block of rows");
    rad_ff_rows *maker = NULL;
    void *state = NULL;
    double t0 = rad_seconds(), row_total = 0.0;
    r = block ? rad_ff_rows_create(ctx, method, &req, &maker) : RAD_ERROR_OUT_OF_MEMORY;
    rad_vf_stream_info info = {&view, path, so->factors};
    if (r == RAD_OK && sink)
        r = sink->begin(ctx, &info, &state);
    if (r == RAD_OK && sink && sink->estimate)
        r = check_disk(ctx, path, sink->estimate(state, 0, n));
    size_t blocks = n ? (n + rows - 1) / rows : 0;
    for (size_t b = 0; b < blocks && r == RAD_OK; b++) {
        size_t r0 = b * rows, r1 = r0 + rows < n ? r0 + rows : n;
        size_t count = (r1 - r0) * n;
        int owner = (int)(b % (size_t)size);
        double *tally = block + count;
        if (owner == rank) {
            rad_ff_block_stats bs;
            r = rad_ff_rows_block(ctx, maker, r0, r1, block, r0, n, &bs);
            tally[0] = (double)bs.pairs;
            tally[1] = (double)bs.pairs_again;
            tally[2] = (double)bs.rays;
            tally[3] = (double)bs.near_pairs;
            tally[4] = bs.reciprocity_max;
            if (r == RAD_OK && rank != 0 && so->ranks->send(so->ranks->user, block, count + RAD_STREAM_TALLY))
                r = rad_fail(ctx, RAD_ERROR_IO, "view factors: rank %d could not send rows %zu-%zu", rank, r0, r1);
        } else if (rank == 0) {
            if (so->ranks->receive(so->ranks->user, owner, block, count + RAD_STREAM_TALLY))
                r = rad_fail(ctx, RAD_ERROR_IO, "view factors: rows %zu-%zu did not arrive from rank %d", r0, r1,
                             owner);
            rad_progress(ctx, "form factors", r1, n);
            if (r == RAD_OK && rad_cancelled(ctx))
                r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "form factors: interrupted");
        } else {
            continue;
        }
        if (r != RAD_OK)
            break;
        st->blocks++;
        st->pairs += (uint64_t)tally[0];
        st->pairs_again += (uint64_t)tally[1];
        st->rays += (uint64_t)tally[2];
        st->reciprocity_max = fmax(st->reciprocity_max, tally[4]);
        if (rank == 0)
            r = take_block(ctx, sink, state, block, r0, r1, n, st, &row_total);
        if (r == RAD_OK && b == 0 && sink && sink->estimate && blocks > 1)
            r = check_disk(ctx, path, sink->estimate(state, r1, n));
    }
    if (sink)
        r = r == RAD_OK ? sink->end(ctx, state, true) : (sink->end(ctx, state, false), r);
    st->row_sum_mean = n ? row_total / (double)n : 0.0;
    st->seconds = rad_seconds() - t0;
    if (r == RAD_OK && rank == 0)
        rad_progress(ctx, "form factors", n, n);
    rad_ff_rows_destroy(maker);
    rad_free(block);
    rad_meshed_free(&m);
    return r;
}
