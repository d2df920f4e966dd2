/*
 * solve_jacobi.c -- Jacobi iteration (Cohen & Wallace 1993, sec. 5.3; the
 * notes' "Jacobi Iteration"): every element gathers from the previous
 * iterate, so all rows of a sweep are independent and run in parallel,
 * optionally weighted (omega = --relaxation):
 *
 *     B_i' = (1 - w) B_i + w (E_i + rho_i sum_{j != i} F_ij B_j) / (1 - rho_i F_ii)
 *
 * F_ii (concave elements) is moved to the left as in gauss-seidel.  The
 * iteration matrix rho F has spectral radius at most max rho < 1, so w = 1
 * converges, by about the mean reflectance per sweep -- slower than
 * Gauss-Seidel, which uses the newest values, but without its serial
 * dependence.  Weighted Jacobi converges for 0 < w < 2 / (1 + max rho).
 *
 * The gathered sums of a sweep are those the residual needs, so each sweep
 * measures the residual of the iterate it starts from at no extra cost:
 * sweep k+1 reports the residual of B^k, exactly rad_residual's value (same
 * sums, same order), and stops before updating once it is below the
 * tolerance.  Rows write their own slots and are summed in order, so the
 * result does not depend on the thread count.
 */
#include "solve/solve.h"

#include <stdlib.h>
#include <string.h>

static rad_result jacobi(rad_context *ctx, const rad_system *sys, const rad_solve_params *p,
                         double *B, rad_solve_stats *stats)
{
    size_t n = sys->n;
    double w = p->relaxation > 0.0 ? p->relaxation : 1.0;
    rad_solve_bound bound = rad_solve_bound_make(p->max_iterations, rad_system_contraction(sys), w, p->tolerance, 1.0);
    int max_sweeps = (int)bound.limit; /* at most the user's int or the cap */
    stats->iteration_limit = bound.limit;
    double *next = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n + 1, sizeof *next, "solve: jacobi: next iterate");
    double *row = rad_alloc(ctx, RAD_MEM_SOLVER, n + 1, sizeof *row, "solve: jacobi: row residuals");
    if (!next || !row) {
        rad_free(next);
        rad_free(row);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    double emitted = 0.0;
    for (size_t i = 0; i < n; i++)
        emitted += sys->area[i] * (sys->emission[3 * i] + sys->emission[3 * i + 1] +
                                   sys->emission[3 * i + 2]);
    double t0 = rad_seconds();
    rad_result result = RAD_OK;
    int sweep = 0;
    for (;;) {
#pragma omp parallel for schedule(static) num_threads(rad_pass_threads(sys))
        for (size_t i = 0; i < n; i++) {
            double g[3];
            const double *Fi = sys->F + i * n;
            rad_gather(Fi, B, n, g);
            const double *rho = sys->reflectance + 3 * i, *E = sys->emission + 3 * i;
            double fii = Fi[i]; /* nonzero only for concave elements */
            double r = 0.0;
            for (int c = 0; c < 3; c++) {
                double old = B[3 * i + c];
                r += fabs(old - E[c] - rho[c] * g[c]);
                double gathered = (E[c] + rho[c] * (g[c] - fii * old)) / (1.0 - rho[c] * fii);
                next[3 * i + c] = (1.0 - w) * old + w * gathered;
            }
            row[i] = sys->area[i] * r;
        }
        double num = 0.0;
        for (size_t i = 0; i < n; i++)
            num += row[i];
        stats->residual = emitted > 0.0 ? num / emitted : num; /* of B^sweep, as rad_residual */
        if (sweep > 0) {
            if (p->monitor) {
                rad_solve_step step = {sweep, rad_seconds() - t0, stats->residual, NAN};
                if (p->monitor(p->monitor_user, &step, B, NULL)) {
                    result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: stopped after %d sweeps", sweep);
                    break;
                }
            }
            rad_progress(ctx, "solve", (uint64_t)sweep, (uint64_t)max_sweeps);
            if (rad_cancelled(ctx)) {
                result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: interrupted after %d sweeps", sweep);
                break;
            }
        }
        if (!(stats->residual > p->tolerance) || sweep == max_sweeps)
            break;
        memcpy(B, next, 3 * n * sizeof *B);
        sweep++;
    }
    stats->iterations = sweep;
    stats->converged = result == RAD_OK && stats->residual <= p->tolerance;
    if (result == RAD_OK && !stats->converged)
        rad_solve_warn(stats, "jacobi", &bound, sweep, "sweeps", "residual", stats->residual, p->tolerance,
                       RAD_SOLVE_FASTER_HINT);
    rad_free(next);
    rad_free(row);
    return result;
}

const rad_solver rad_solver_jacobi = {
    "jacobi",
    "Jacobi iteration: all rows from the last sweep, in parallel, optional weighting "
    "(rad_options.relaxation); O(n^2) per sweep, error shrinks ~rho per sweep",
    jacobi,
    0,
};
