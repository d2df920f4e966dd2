/*
 * rows.c -- form factors one block of rows at a time, for scenes whose
 * n x n matrix does not fit in memory (8 n^2 bytes: 80 GB at 10^5
 * elements).  The caller hands each block on (to a file, a surface-level
 * sum, another process) and reuses its memory for the next.
 *
 * Pair methods give F_ij and F_ji from one kernel call on (i < j).  The
 * dense loop writes both; a block of rows [r0, r1) needs, for its row i,
 *
 *          j ->   0      r0        r1       n
 *     r0 [ a a a a | . x x x x | x x x x x ]   x: kernel(i, j), F_ij, once;
 *     i  [ a a a a | o . x x x | x x x x x ]      o: its F_ji, for row j in the block
 *     r1 [ a a a a | o o . x x | x x x x x ]   a: kernel(j, i) again, its F_ji
 *
 * so every factor comes from the same call on the same ordered pair as in
 * the dense matrix, with the pair's own random numbers (keyed on the
 * seed and the two elements): bit for bit the dense rows, reciprocal as
 * exactly.  The price is the `a` part: the pairs between this block and
 * the rows before it, evaluated once more (their rows went out with
 * earlier blocks).  Over n / B blocks of B rows that is n^2 (1 - B/n) / 2
 * more evaluations, about twice the dense loop's for small blocks; larger
 * blocks cost less, one block of n rows exactly the dense loop.  Keeping
 * the `x` factors of earlier blocks for later ones would be the lower
 * triangle: the O(n^2) memory this file exists to avoid.
 *
 * Row methods (hemicube, hemisphere, Monte Carlo) fill row i themselves:
 * any block is the dense rows as they come out of the kernel, before the
 * balance step that needs all of them (refused here, as the closure
 * correction is: rad_ff_rows_check).
 */
#include "formfactor/formfactor.h"

#include <stdlib.h>
#include <string.h>

#include <omp.h>

struct rad_ff_rows {
    rad_context *ctx;
    const rad_ff_method *method;
    const rad_ff_request *req;
    void *shared;                 /* the method's prepared tables, or NULL */
    unsigned char *scratch;       /* every thread's slice */
    size_t slice;                 /* bytes per thread, whole cache lines */
    double plane_tol;             /* m */
};

rad_result rad_ff_rows_check(rad_context *ctx, const rad_ff_method *method, const rad_ff_request *req,
                             bool close, const char *why)
{
    if ((method->flags & RAD_FF_BALANCE) && !req->raw)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "view factors in row blocks: method '%s' samples, and its balance step (reciprocity "
                        "and closure) needs the whole matrix; use a pair method (analytic, contour, hybrid), "
                        "or keep its raw estimate (rad_options.raw_form_factors)%s",
                        method->name, why);
    if (close)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "view factors in row blocks: the closure correction rescales every row by all the "
                        "others and needs the whole matrix; leave rad_options.closure_correction off%s", why);
    return RAD_OK;
}

rad_result rad_ff_rows_create(rad_context *ctx, const rad_ff_method *method, const rad_ff_request *req,
                              rad_ff_rows **out)
{
    *out = NULL;
    rad_ff_rows *rows = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, 1, sizeof *rows, "form factors: row blocks");
    if (!rows)
        return RAD_ERROR_OUT_OF_MEMORY;
    rows->ctx = ctx;
    rows->method = method;
    rows->req = req;
    rows->plane_tol = rad_ff_plane_tolerance(req->mesh);
    rad_result r = method->prepare ? method->prepare(ctx, req, &rows->shared) : RAD_OK;
    size_t threads = (size_t)(ctx->threads > 0 ? ctx->threads : 1);
    rows->slice = method->scratch ? (method->scratch(req, rows->shared, NULL) + 63) / 64 * 64 : 0;
    if (r == RAD_OK && rows->slice) {
        char what[64];
        snprintf(what, sizeof what, "form factors (%s): threads' scratch", method->name);
        rows->scratch = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, threads, rows->slice, what);
        if (!rows->scratch)
            r = RAD_ERROR_OUT_OF_MEMORY;
    }
    if (r != RAD_OK) {
        rad_ff_rows_destroy(rows);
        return r;
    }
    *out = rows;
    return RAD_OK;
}

void rad_ff_rows_destroy(rad_ff_rows *rows)
{
    if (!rows)
        return;
    rad_free(rows->shared);
    rad_free(rows->scratch);
    rad_free(rows);
}

/* The relative reciprocity error of one pair, as formfactor.c's
 * diagnostics measure it: 0 where the larger coupling is below 1e-9 of the
 * larger area (rounding dominates there). */
static double pair_reciprocity(double ai, double aj, double F_ij, double F_ji)
{
    double gij = ai * F_ij, gji = aj * F_ji, big = fmax(gij, gji);
    return big > 1e-9 * fmax(ai, aj) ? fabs(gij - gji) / big : 0.0;
}

/* Row i of a pair method into the block: the three parts of the sketch. */
static void pair_row(const rad_ff_rows *rows, void *scratch, size_t i, size_t r0, size_t r1, double *block,
                     rad_ff_tally *tally, uint64_t *again, double *recip)
{
    const rad_ff_request *req = rows->req;
    const rad_mesh *mesh = req->mesh;
    size_t n = mesh->element_count;
    double *Fi = block + (i - r0) * n;
    for (size_t j = 0; j < r0; j++) { /* a: (j, i), seen from row j before */
        if (!rad_ff_facing(mesh, (uint32_t)j, (uint32_t)i, rows->plane_tol))
            continue;
        (*again)++;
        rad_ff_pair f = {0};
        rows->method->pair(req, rows->shared, scratch, (uint32_t)j, (uint32_t)i, &f, tally);
        Fi[j] = f.F_ji;
    }
    for (size_t j = i + 1; j < n; j++) { /* x, and o for rows j in the block */
        if (!rad_ff_facing(mesh, (uint32_t)i, (uint32_t)j, rows->plane_tol))
            continue;
        tally->pairs++;
        rad_ff_pair f = {0};
        rows->method->pair(req, rows->shared, scratch, (uint32_t)i, (uint32_t)j, &f, tally);
        Fi[j] = f.F_ij;
        if (j < r1)
            block[(j - r0) * n + i] = f.F_ji;
        *recip = fmax(*recip, pair_reciprocity(mesh->elements[i].area, mesh->elements[j].area, f.F_ij, f.F_ji));
    }
}

rad_result rad_ff_rows_block(rad_context *ctx, rad_ff_rows *rows, size_t r0, size_t r1, double *block,
                             uint64_t done, uint64_t total, rad_ff_block_stats *stats)
{
    memset(stats, 0, sizeof *stats);
    const rad_ff_method *method = rows->method;
    const rad_ff_request *req = rows->req;
    size_t n = req->mesh->element_count;
    memset(block, 0, (r1 - r0) * n * sizeof *block);
    uint64_t rays = 0, pairs = 0, near_pairs = 0, again = 0, finished = 0;
    double recip = 0.0;
    volatile int stop = 0;
    /* Rows of the upper triangle shrink with i: dynamic schedule.  Two
     * threads write one row only at different columns (row j's column i
     * from row i < j, the rest from row j), so no entry is shared. */
#pragma omp parallel num_threads(ctx->threads > 0 ? ctx->threads : 1) reduction(+ : rays, pairs, near_pairs, again) \
    reduction(max : recip)
    {
        void *scratch = NULL;
        if (rows->slice) {
            scratch = rows->scratch + (size_t)omp_get_thread_num() * rows->slice;
            method->scratch(req, rows->shared, scratch);
        }
        rad_ff_tally tally = {0, 0, 0};
#pragma omp for schedule(dynamic, 1)
        for (size_t i = r0; i < r1; i++) {
            if (stop)
                continue;
            if (method->row)
                method->row(req, rows->shared, scratch, (uint32_t)i, block + (i - r0) * n, NULL, &tally);
            else
                pair_row(rows, scratch, i, r0, r1, block, &tally, &again, &recip);
            uint64_t now;
#pragma omp atomic capture
            now = ++finished;
            if (omp_get_thread_num() == 0)
                rad_progress(ctx, "form factors", done + now, total);
            if (rad_cancelled(ctx))
                stop = 1;
        }
        rays += tally.rays;
        pairs += tally.pairs;
        near_pairs += tally.near_pairs;
    }
    if (method->row) {
        /* Reciprocity where both rows are at hand: the block's own pairs. */
        const rad_element *e = req->mesh->elements;
        for (size_t i = r0; i < r1; i++)
            for (size_t j = i + 1; j < r1; j++)
                recip = fmax(recip, pair_reciprocity(e[i].area, e[j].area, block[(i - r0) * n + j],
                                                     block[(j - r0) * n + i]));
    }
    stats->rays = rays;
    stats->pairs = pairs;
    stats->pairs_again = again;
    stats->near_pairs = near_pairs;
    stats->reciprocity_max = recip;
    if (stop)
        return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "form factors: interrupted");
    return RAD_OK;
}
