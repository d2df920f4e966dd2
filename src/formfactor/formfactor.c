/*
 * formfactor.c -- the registry of form-factor methods, and what every
 * method gets for free: the memory check before the dense matrix is
 * allocated, timing, and the diagnostics (row sums, reciprocity, F_ii).
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
 * single-precision rounding of F dominates the relative error. */
static void diagnostics(const rad_mesh *mesh, const float *F, rad_ff_stats *s)
{
    size_t n = mesh->element_count;
    double rmin = INFINITY, rmax = -INFINITY, rsum = 0.0, recip = 0.0, diag = 0.0;
    for (size_t i = 0; i < n; i++) {
        double row = 0.0;
        const float *Fi = F + i * n;
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

void rad_ff_row_done(rad_context *ctx, uint64_t *rows_done, size_t rows, volatile int *stop)
{
    uint64_t done;
#pragma omp atomic capture
    done = ++*rows_done;
#ifdef _OPENMP
    if (omp_get_thread_num() != 0)
        return;
#endif
    rad_progress(ctx, "form factors", done, rows);
    if (rad_cancelled(ctx))
        *stop = 1;
}

rad_result rad_ff_close(rad_context *ctx, const rad_mesh *mesh, float *F)
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
            const float *Fi = F + i * n;
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
            F[i * n + j] = (float)((double)F[i * n + j] * x[i] * x[j]);
    rad_free(x);
    return RAD_OK;
}

rad_result rad_form_factors(rad_context *ctx, const rad_ff_method *method, const rad_ff_request *req,
                            double max_memory, bool close, float **F_out, float **variance_out,
                            rad_ff_stats *stats)
{
    *F_out = NULL;
    bool want_variance = variance_out && (method->flags & RAD_FF_VARIANCE);
    if (variance_out)
        *variance_out = NULL;
    memset(stats, 0, sizeof *stats);
    stats->method = method->name;
    size_t n = req->mesh->element_count;
    double bytes = (double)n * (double)n * sizeof(float) * (want_variance ? 2.0 : 1.0);
    if (bytes > max_memory)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                        "form factors: the dense matrix for %zu elements needs %.2f GiB, above "
                        "the memory limit of %.2f GiB (--max-memory); use the matrix-free "
                        "solver (--solver shooting, O(n) memory) or fewer elements (--elements)",
                        n, bytes / 1073741824.0, max_memory / 1073741824.0);
    float *F = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, n * n, sizeof *F, "form factors: dense matrix");
    float *var = F && want_variance
                     ? rad_alloc(ctx, RAD_MEM_FORM_FACTORS, n * n, sizeof *var, "form factors: variances")
                     : NULL;
    if (!F || (want_variance && !var)) {
        rad_free(F);
        rad_free(var);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    double t0 = rad_seconds();
    rad_result r = method->compute(ctx, req, F, var, stats);
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
    return r;
}
