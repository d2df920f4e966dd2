/*
 * formfactor.c -- the registry of form-factor methods, and what every
 * method gets for free: the memory check before the dense matrix is
 * allocated, the one parallel loop that calls the method's kernel, timing,
 * the diagnostics (row sums, reciprocity, F_ii), and the plane tolerance
 * and facing test that every method culls with.
 *
 * The loop runs over rows i, in parallel with a dynamic schedule (rows of
 * the upper triangle shrink with i); a pair method's kernel sees the pairs
 * (i, j > i) that face each other, a row method's kernel row i whole:
 *
 *          j ->                      pair methods: kernel(i, j) gives
 *     i  [ . x x x x x ]             F_ij (x) and F_ji (o) at once
 *     |  [ o . x x x x ]
 *     v  [ o o . x x x ]             row methods: kernel(i) fills row i
 *        [ o o o . x x ]
 *
 * Each thread gets its scratch once; kernels key their random numbers on
 * (seed, elements), so F does not depend on the thread count.
 */
#include "formfactor/formfactor.h"

#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

extern const rad_ff_method rad_ff_analytic;
extern const rad_ff_method rad_ff_hemicube;
extern const rad_ff_method rad_ff_hemisphere;
extern const rad_ff_method rad_ff_montecarlo;
extern const rad_ff_method rad_ff_contour;
extern const rad_ff_method rad_ff_hybrid;

const rad_ff_method *const rad_ff_methods[] = {
    &rad_ff_analytic,
    &rad_ff_hemicube,
    &rad_ff_hemisphere,
    &rad_ff_montecarlo,
    &rad_ff_contour,
    &rad_ff_hybrid,
    NULL,
};

const rad_ff_method *rad_ff_find(const char *name)
{
    for (size_t i = 0; rad_ff_methods[i]; i++)
        if (strcmp(rad_ff_methods[i]->name, name) == 0)
            return rad_ff_methods[i];
    return NULL;
}

/* Row sums, the worst reciprocity error and the largest F_ii.  Pairs whose
 * larger power coupling is below 1e-9 of the larger area are ignored: there
 * the rounding of the methods' sums dominates the relative error. */
static void diagnostics(const rad_mesh *mesh, const double *F, rad_ff_stats *s)
{
    size_t n = mesh->element_count;
    double rmin = INFINITY, rmax = -INFINITY, rsum = 0.0, recip = 0.0, diag = 0.0;
    for (size_t i = 0; i < n; i++) {
        double row = 0.0;
        const double *Fi = F + i * n;
        for (size_t j = 0; j < n; j++)
            row += Fi[j];
        rmin = fmin(rmin, row);
        rmax = fmax(rmax, row);
        rsum += row;
        diag = fmax(diag, Fi[i]);
    }
    /* Reciprocity over the upper triangle, in tiles to keep F[j][i] cached. */
    const size_t tile = 64;
    for (size_t i0 = 0; i0 < n; i0 += tile)
        for (size_t j0 = i0; j0 < n; j0 += tile)
            for (size_t i = i0; i < i0 + tile && i < n; i++)
                for (size_t j = j0 > i + 1 ? j0 : i + 1; j < j0 + tile && j < n; j++) {
                    double ai = mesh->elements[i].area, aj = mesh->elements[j].area;
                    double gij = ai * F[i * n + j], gji = aj * F[j * n + i];
                    double big = fmax(gij, gji);
                    if (big > 1e-9 * fmax(ai, aj))
                        recip = fmax(recip, fabs(gij - gji) / big);
                }
    s->row_sum_min = n ? rmin : 0.0;
    s->row_sum_max = n ? rmax : 0.0;
    s->row_sum_mean = n ? rsum / (double)n : 0.0;
    s->reciprocity_max = recip;
    s->diagonal_max = diag;
}

/* Count one finished row; the master thread reports progress, and every
 * thread polls cancellation, raising *stop (so that a flag raised before
 * the start stops the loop after one row per thread, whichever threads get
 * the rows).  Called inside the parallel region. */
static void row_done(rad_context *ctx, uint64_t *rows_done, size_t rows, volatile int *stop)
{
    uint64_t done;
#pragma omp atomic capture
    done = ++*rows_done;
    bool master = true;
#ifdef _OPENMP
    master = omp_get_thread_num() == 0;
#endif
    if (master)
        rad_progress(ctx, "form factors", done, rows);
    if (rad_cancelled(ctx))
        *stop = 1;
}

/* Row i of a pair method: the facing pairs (i, j > i), both directions. */
static void pair_row(const rad_ff_method *method, const rad_ff_request *req, const void *shared,
                     void *scratch, uint32_t i, double plane_tol, double *F, double *variance,
                     rad_ff_tally *tally)
{
    const rad_mesh *mesh = req->mesh;
    size_t n = mesh->element_count;
    for (size_t j = (size_t)i + 1; j < n; j++) {
        if (!rad_ff_facing(mesh, i, (uint32_t)j, plane_tol))
            continue;
        tally->pairs++;
        rad_ff_pair f = {0};
        method->pair(req, shared, scratch, i, (uint32_t)j, &f, tally);
        F[i * n + j] = f.F_ij;
        F[j * n + i] = f.F_ji;
        if (variance) {
            variance[i * n + j] = f.var_ij;
            variance[j * n + i] = f.var_ji;
        }
    }
}

/* The one loop: every row, in parallel; the counts into stats. */
static rad_result run_method(rad_context *ctx, const rad_ff_method *method, const rad_ff_request *req,
                             const void *shared, double *F, double *variance, rad_ff_stats *stats)
{
    size_t n = req->mesh->element_count;
    double plane_tol = rad_ff_plane_tolerance(req->mesh);
    /* Every thread's scratch in one allocation before the region: a slice
     * each, whole cache lines apart (64 bytes), so no thread allocates. */
    size_t threads = (size_t)(ctx->threads > 0 ? ctx->threads : 1);
    size_t slice = method->scratch ? (method->scratch(req, shared, NULL) + 63) / 64 * 64 : 0;
    unsigned char *scratch_blocks = NULL;
    if (slice) {
        char what[64];
        snprintf(what, sizeof what, "form factors (%s): threads' scratch", method->name);
        scratch_blocks = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, threads, slice, what);
        if (!scratch_blocks)
            return RAD_ERROR_OUT_OF_MEMORY;
    }
    uint64_t rays = 0, pairs = 0, near_pairs = 0, rows_done = 0;
    volatile int stop = 0;
#pragma omp parallel num_threads(ctx->threads) reduction(+ : rays, pairs, near_pairs)
    {
        void *scratch = NULL;
        if (slice) {
            scratch = scratch_blocks + (size_t)omp_get_thread_num() * slice;
            method->scratch(req, shared, scratch);
        }
        rad_ff_tally tally = {0, 0, 0};
#pragma omp for schedule(dynamic, 4)
        for (size_t i = 0; i < n; i++) {
            if (stop)
                continue;
            if (method->row)
                method->row(req, shared, scratch, (uint32_t)i, F + i * n, variance ? variance + i * n : NULL,
                            &tally);
            else
                pair_row(method, req, shared, scratch, (uint32_t)i, plane_tol, F, variance, &tally);
            row_done(ctx, &rows_done, n, &stop);
        }
        rays += tally.rays;
        pairs += tally.pairs;
        near_pairs += tally.near_pairs;
    }
    rad_free(scratch_blocks);
    stats->rays = rays;
    stats->pairs = pairs;
    stats->near_pairs = near_pairs;
    if (stop)
        return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "form factors: interrupted");
    rad_progress(ctx, "form factors", n, n);
    return RAD_OK;
}

rad_result rad_ff_close(rad_context *ctx, const rad_mesh *mesh, double *F)
{
    size_t n = mesh->element_count;
    double *x = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, 2 * n, sizeof *x, "form factors: closure correction");
    if (!x)
        return RAD_ERROR_OUT_OF_MEMORY;
    double *row = x + n;
    for (size_t i = 0; i < n; i++)
        x[i] = 1.0;
    /* Symmetric Sinkhorn iteration on G_ij = A_i F_ij: with s_i = sum_j G_ij x_j,
     * x_i <- sqrt(x_i A_i / s_i) converges to x_i s_i = A_i (Knight 2008).
     * 200 sweeps or a largest row error of 1e-12. */
    for (int it = 0; it < 200; it++) {
        double worst = 0.0;
        for (size_t i = 0; i < n; i++) {
            const double *Fi = F + i * n;
            double s = 0.0;
            for (size_t j = 0; j < n; j++)
                s += (double)Fi[j] * x[j];
            row[i] = s * mesh->elements[i].area;
        }
        for (size_t i = 0; i < n; i++) {
            double a = mesh->elements[i].area, target = row[i] * x[i];
            if (!(row[i] > 0.0))
                continue; /* sees nothing: stays 0 */
            worst = fmax(worst, fabs(target / a - 1.0));
            x[i] = sqrt(x[i] * a / row[i]);
        }
        if (worst < 1e-12)
            break;
    }
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++)
            F[i * n + j] *= x[i] * x[j];
    rad_free(x);
    return RAD_OK;
}

rad_result rad_ff_escape_rays(rad_context *ctx, const rad_mesh *mesh, const rad_vis *vis, uint64_t seed,
                              double *fraction)
{
    enum { BLOCK = 64 };
    size_t n = mesh->element_count;
    if (n == 0 || !vis) {
        for (size_t i = 0; i < n; i++)
            fraction[i] = 0.0;
        return RAD_OK;
    }
    double per = ceil(262144.0 / (double)n);
    int rays = per < 16.0 ? 16 : per > 4096.0 ? 4096 : (int)per, side = (int)sqrt((double)rays);
    double eps = rad_vis_epsilon(mesh);
    volatile int stop = 0;
#pragma omp parallel for schedule(dynamic, 16) num_threads(ctx->threads > 0 ? ctx->threads : 1)
    for (size_t i = 0; i < n; i++) {
        fraction[i] = 0.0;
        if (stop)
            continue;
        const rad_element *e = &mesh->elements[i];
        /* Lifted as shooting lifts its rays, by the bend of a quad too. */
        double lift = eps;
        if (e->vertex_count == 4)
            for (int k = 1; k < 4; k++)
                lift += fabs(v3_dot(e->normal, v3_sub(mesh->vertices[e->vertex[k]], mesh->vertices[e->vertex[0]])));
        rad_rng rng = rad_rng_keyed(seed ^ 0x436c6f736564ULL, i, 0); /* "Closed" */
        rad_ray ray[BLOCK];
        rad_hit hit[BLOCK];
        int missed = 0;
        for (int first = 0; first < rays; first += BLOCK) {
            int count = rays - first < BLOCK ? rays - first : BLOCK;
            rad_element_cosine_rays(mesh, e, lift, side, first, count, &rng, ray);
            vis->backend->intersect(vis->state, ray, (size_t)count, hit);
            for (int k = 0; k < count; k++)
                missed += !isfinite(hit[k].t);
        }
        fraction[i] = (double)missed / rays;
        if (rad_cancelled(ctx))
            stop = 1;
    }
    if (stop)
        return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "closure: interrupted");
    return RAD_OK;
}

double rad_ff_escaped(const rad_mesh *mesh, const double *fraction, const double *F)
{
    size_t n = mesh->element_count;
    double area = 0.0, lost = 0.0;
    for (size_t i = 0; i < n; i++) {
        bool sees = fraction[i] < 1.0;
        if (F) {
            double row = 0.0;
            for (size_t j = 0; j < n; j++)
                row += F[i * n + j];
            sees = row > 0.0;
        }
        if (!sees)
            continue;
        area += mesh->elements[i].area;
        lost += mesh->elements[i].area * fraction[i];
    }
    return area > 0.0 ? lost / area : 0.0;
}

rad_result rad_ff_refuse_open(rad_context *ctx, const char *source, double escaped)
{
    return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                    "%s: rad_options.closure_correction is for closed scenes, and %.1f%% of the light leaving "
                    "this one's surfaces escapes it (rays from every element that meet nothing; up to %g%% is "
                    "taken as the cracks of a closed model): refused, it would put that light back",
                    source ? source : "scene", 100.0 * escaped, 100.0 * RAD_FF_OPEN_SCENE_ESCAPE);
}

rad_result rad_form_factors(rad_context *ctx, const rad_ff_method *method, const rad_ff_request *req,
                            double max_memory, bool close, double **F_out, double **variance_out,
                            rad_ff_stats *stats)
{
    *F_out = NULL;
    /* The balance weighs a pair method's factors by their variances (reciprocity.c):
     * kept for it even where the caller declines them. */
    bool balanced = (method->flags & RAD_FF_BALANCE) && !req->raw;
    bool want_variance = (method->flags & RAD_FF_VARIANCE) && (variance_out || (balanced && method->pair));
    if (variance_out)
        *variance_out = NULL;
    memset(stats, 0, sizeof *stats);
    stats->method = method->name;
    size_t n = req->mesh->element_count;
    double bytes = (double)n * (double)n * sizeof(double) * (want_variance ? 2.0 : 1.0);
    if (bytes > max_memory)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                        "form factors: the dense matrix for %zu elements needs %.2f GiB, above "
                        "the memory limit of %.2f GiB (rad_options.max_memory_bytes); use the matrix-free "
                        "solver 'shooting' (rad_options.solver, O(n) memory) or fewer elements "
                        "(rad_options.target_elements)",
                        n, bytes / 1073741824.0, max_memory / 1073741824.0);
    double *F = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, n * n, sizeof *F, "form factors: dense matrix");
    double *var = F && want_variance
                     ? rad_alloc(ctx, RAD_MEM_FORM_FACTORS, n * n, sizeof *var, "form factors: variances")
                     : NULL;
    if (!F || (want_variance && !var)) {
        rad_free(F);
        rad_free(var);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    double t0 = rad_seconds();
    void *shared = NULL;
    rad_result r = method->prepare ? method->prepare(ctx, req, &shared) : RAD_OK;
    if (r == RAD_OK)
        r = run_method(ctx, method, req, shared, F, var, stats);
    if (r == RAD_OK && balanced) {
        rad_ff_stats raw;
        diagnostics(req->mesh, F, &raw);
        stats->raw_reciprocity_max = raw.reciprocity_max;
        r = rad_ff_balance(ctx, method, req, shared, F, var, stats);
    }
    rad_free(shared);
    if (r == RAD_OK && close && req->escape) {
        /* Now that F says which elements see something (what sees
         * nothing keeps its zero row): is the scene closed? */
        stats->escaped = rad_ff_escaped(req->mesh, req->escape, F);
        if (stats->escaped > RAD_FF_OPEN_SCENE_ESCAPE)
            r = rad_ff_refuse_open(ctx, req->source, stats->escaped);
    }
    if (r == RAD_OK && close) {
        r = rad_ff_close(ctx, req->mesh, F);
        stats->closure_corrected = r == RAD_OK;
    }
    stats->seconds = rad_seconds() - t0;
    if (r != RAD_OK && r != RAD_ERROR_INTERRUPTED) {
        rad_free(F);
        rad_free(var);
        return r;
    }
    diagnostics(req->mesh, F, stats);
    if (var) {
        double worst = 0.0;
        for (size_t k = 0; k < n * n; k++)
            worst = fmax(worst, var[k]);
        stats->std_error_max = sqrt(worst);
    }
    *F_out = F;
    if (variance_out)
        *variance_out = var;
    else
        rad_free(var);
    return r;
}
