/*
 * smooth.c -- enclosure smoothing: the least change to a surface view-factor
 * matrix that makes it reciprocal (A_i F_ij = A_j F_ji) and gives each row
 * its target sum (1 in an enclosure), by weighted least squares with the
 * factors kept non-negative (van Leersum 1989; Lawson 1995, "An improved
 * method for smoothing approximate exchange areas", Int. J. Heat Mass
 * Transfer 38; Taylor & Luck 1995).
 *
 * The unknowns are the symmetric exchange areas g_ij = A_i F_ij.  Starting
 * from the reciprocity average g0_ij = (A_i F_ij + A_j F_ji) / 2, minimise
 *
 *     sum_{i<=j} (g_ij - g0_ij)^2 / g0_ij    subject to  sum_j g_ij = t_i
 *
 * (t_i = A_i, or A_i times the measured row sum for an open set).  The
 * weight 1 / g0 is the chi-square weight of a count (a factor's variance
 * grows with its size): the stationarity conditions give
 *
 *     g_ij = g0_ij (1 - lambda_i - lambda_j),   (diag(s) + G0) lambda = s - t
 *
 * with s_i = sum_j g0_ij: one symmetric n x n solve.  The relative change
 * of a factor is -(lambda_i + lambda_j); factors that are 0 stay 0 (a
 * planar surface keeps F_ii = 0, a sparse pattern keeps its zeros).  A
 * factor driven below 0 is held at 0 and the system solved again without
 * it (clamp and re-solve, at most n^2 rounds; in practice one or two).
 *
 * With a sparse threshold (the .mtx of output/view3d.c), the pairs whose
 * two factors are both below it are dropped first and the rest smoothed on
 * the kept pattern, to the row sums from before the drop.
 *
 * The multiplicative closure of formfactor.c (rad_ff_close, Sinkhorn) acts
 * on the element matrix during the solve; this acts on the surface matrix
 * written out, and is the least-squares answer (docs/methods.md).
 */
#include "formfactor/formfactor.h"

#include <string.h>

/* Solve M x = b (M n x n row-major, destroyed; b destroyed) by Gaussian
 * elimination to row echelon form with partial pivoting.  M may be
 * singular: a column without a pivot above `tiny` is a free unknown, set to
 * 0 (the system of a group of surfaces that see only the other group,
 * two facing plates, is singular, its null vector +1 on one side and -1
 * on the other changing no factor).  `col` holds n indices of scratch.
 * False when the system is inconsistent: a row left without a pivot whose
 * right-hand side exceeds `consistent` (the targets cannot be met). */
static bool solve_dense(double *M, double *b, double *x, size_t *col, size_t n, double tiny,
                        double consistent)
{
    size_t rows = 0; /* pivot rows found so far */
    for (size_t k = 0; k < n && rows < n; k++) {
        size_t p = rows;
        for (size_t i = rows + 1; i < n; i++)
            if (fabs(M[i * n + k]) > fabs(M[p * n + k]))
                p = i;
        if (!(fabs(M[p * n + k]) > tiny))
            continue; /* a free unknown */
        if (p != rows) {
            for (size_t j = 0; j < n; j++) {
                double t = M[rows * n + j];
                M[rows * n + j] = M[p * n + j];
                M[p * n + j] = t;
            }
            double t = b[rows];
            b[rows] = b[p];
            b[p] = t;
        }
        for (size_t i = rows + 1; i < n; i++) {
            double f = M[i * n + k] / M[rows * n + k];
            if (f == 0.0)
                continue;
            for (size_t j = k; j < n; j++)
                M[i * n + j] -= f * M[rows * n + j];
            b[i] -= f * b[rows];
        }
        col[rows++] = k;
    }
    for (size_t i = rows; i < n; i++)
        if (!(fabs(b[i]) <= consistent))
            return false;
    for (size_t k = 0; k < n; k++)
        x[k] = 0.0;
    for (size_t r = rows; r-- > 0;) {
        double v = b[r];
        for (size_t j = col[r] + 1; j < n; j++)
            v -= M[r * n + j] * x[j];
        x[col[r]] = v / M[r * n + col[r]];
    }
    return true;
}

/* The factor's multiplier 1 - lambda_i - lambda_j, the same to the bit for
 * (i, j) and (j, i) ((1 - a) - b is not (1 - b) - a: near a clamp, where
 * it is small, that broke reciprocity by 3e-11 at 1,000 surfaces). */
static double pair_scale(const double *lambda, size_t i, size_t j)
{
    return i == j ? 1.0 - 2.0 * lambda[i] : 1.0 - (lambda[i] + lambda[j]);
}

/* Worst row error against the targets and worst reciprocity error
 * (|A_i F_ij - A_j F_ji| over the larger of the two). */
static void measure(size_t n, const double *area, const double *F, const double *target, double *row,
                    double *recip)
{
    *row = 0.0;
    *recip = 0.0;
    for (size_t i = 0; i < n; i++) {
        double sum = 0.0;
        for (size_t j = 0; j < n; j++) {
            sum += F[i * n + j];
            double a = area[i] * F[i * n + j], b = area[j] * F[j * n + i];
            double big = fmax(fabs(a), fabs(b));
            if (big > 0.0)
                *recip = fmax(*recip, fabs(a - b) / big);
        }
        *row = fmax(*row, fabs(sum - target[i]));
    }
}

rad_result rad_ff_smooth(rad_context *ctx, size_t n, const double *area, double *F, bool enclosure,
                         double sparse_threshold, double *dropped, rad_smooth_report *report)
{
    rad_smooth_report rep;
    memset(&rep, 0, sizeof rep);
    if (dropped)
        *dropped = 0.0;
    if (n == 0) {
        if (report)
            *report = rep;
        return RAD_OK;
    }
    if (n > 46340) /* n^2 doubles must be countable; the dense solve is O(n^3) anyway */
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "smoothing: %zu surfaces is too many", n);
    double *g0 = rad_alloc(ctx, RAD_MEM_OUTPUT, n * n, sizeof *g0, "smoothing: exchange areas");
    double *M = g0 ? rad_alloc(ctx, RAD_MEM_OUTPUT, n * n, sizeof *M, "smoothing: system") : NULL;
    double *lambda = M ? rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *lambda, "smoothing: multipliers") : NULL;
    double *target = lambda ? rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *target, "smoothing: targets") : NULL;
    double *rhs = target ? rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *rhs, "smoothing: system") : NULL;
    size_t *col = rhs ? rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *col, "smoothing: system") : NULL;
    rad_result result = col ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
    /* The targets, from the rows as they came: 1 in an enclosure; an open
     * set keeps what each row measured. */
    for (size_t i = 0; result == RAD_OK && i < n; i++) {
        double sum = 0.0;
        for (size_t j = 0; j < n; j++)
            sum += F[i * n + j];
        target[i] = enclosure ? 1.0 : (sum < 1.0 ? (sum > 0.0 ? sum : 0.0) : 1.0);
    }
    if (result == RAD_OK && sparse_threshold > 0.0) {
        /* A pair goes when both of its factors are below the threshold, so
         * the pattern stays symmetric and reciprocity can hold on it. */
        double most = 0.0;
        for (size_t i = 0; i < n; i++) {
            double row = 0.0;
            for (size_t j = 0; j < n; j++)
                if (F[i * n + j] < sparse_threshold && F[j * n + i] < sparse_threshold)
                    row += F[i * n + j];
            most = fmax(most, row);
        }
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < n; j++)
                if (F[i * n + j] < sparse_threshold && F[j * n + i] < sparse_threshold)
                    F[i * n + j] = F[j * n + i] = 0.0;
        if (dropped)
            *dropped = most;
    }
    for (size_t i = 0; result == RAD_OK && i < n; i++) {
        if (!(area[i] > 0.0 && isfinite(area[i])))
            result = rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "smoothing: surface %zu has area %g", i, area[i]);
        for (size_t j = 0; result == RAD_OK && j < n; j++)
            if (!(F[i * n + j] >= 0.0 && F[i * n + j] <= 1.0 + 1e-6))
                result = rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                                  "smoothing: F[%zu][%zu] = %g is not a view factor", i, j, F[i * n + j]);
    }
    if (result == RAD_OK) {
        measure(n, area, F, target, &rep.row_error_before, &rep.reciprocity_before);
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < n; j++)
                g0[i * n + j] = 0.5 * (area[i] * F[i * n + j] + area[j] * F[j * n + i]);
    }
    /* Every clamp removes one pair from the pattern: at most n(n+1)/2 rounds. */
    for (size_t round = 0; result == RAD_OK; round++) {
        for (size_t i = 0; i < n; i++) {
            double s = 0.0;
            for (size_t j = 0; j < n; j++) {
                s += g0[i * n + j];
                M[i * n + j] = g0[i * n + j];
            }
            M[i * n + i] += s;
            rhs[i] = s - area[i] * target[i];
        }
        /* Pivots below 1e-12 of the largest area are rounding (elimination
         * of n rows of sums of areas loses ~n 1e-16 of them); a row without
         * a pivot whose sum is off by 1e-10 of it is a sum that cannot be
         * met (a surface that sees nothing, two that see only each other
         * with different areas and the sums of an enclosure). */
        double big = 0.0;
        for (size_t i = 0; i < n; i++)
            big = fmax(big, area[i]);
        if (!solve_dense(M, rhs, lambda, col, n, 1e-12 * big, 1e-10 * big)) {
            result = rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                              "smoothing: the row sums cannot be met by changing the non-zero factors "
                              "(a surface that sees nothing, or two that see only each other with "
                              "different areas)");
            break;
        }
        size_t clamped = 0;
        for (size_t i = 0; i < n; i++)
            for (size_t j = i; j < n; j++) {
                double scale = pair_scale(lambda, i, j);
                if (g0[i * n + j] > 0.0 && scale < 0.0) {
                    g0[i * n + j] = g0[j * n + i] = 0.0;
                    clamped++;
                }
            }
        rep.clamped += clamped;
        if (clamped == 0 || round > n * (n + 1) / 2)
            break;
    }
    if (result == RAD_OK) {
        double sum_sq = 0.0, max_change = 0.0;
        size_t count = 0;
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < n; j++) {
                double scale = pair_scale(lambda, i, j);
                double g = g0[i * n + j] * fmax(scale, 0.0);
                double before = F[i * n + j];
                F[i * n + j] = g / area[i];
                if (before > 0.0) {
                    double change = fabs(F[i * n + j] - before) / before;
                    max_change = fmax(max_change, change);
                    sum_sq += change * change;
                    count++;
                }
            }
        rep.max_relative_change = max_change;
        rep.rms_relative_change = count ? sqrt(sum_sq / (double)count) : 0.0;
        measure(n, area, F, target, &rep.row_error_after, &rep.reciprocity_after);
    }
    rad_free(g0);
    rad_free(M);
    rad_free(lambda);
    rad_free(target);
    rad_free(rhs);
    rad_free(col);
    if (report)
        *report = rep;
    return result;
}

rad_result rad_view_factors_smooth(rad_context *ctx, size_t n, const double *area, double *F, bool enclosure,
                                   rad_smooth_report *report)
{
    rad_api_enter(ctx);
    if (!ctx || (n > 0 && (!area || !F)))
        return rad_null_argument(ctx, __func__);
    return rad_ff_smooth(ctx, n, area, F, enclosure, 0.0, NULL, report);
}
