/*
 * solve_gauss_seidel.c -- gathering: each element in turn gathers from all
 * others, using the newest values at once (Cohen & Wallace 1993, sec. 5.3;
 * the notes' "Gathering"), optionally over-relaxed (SOR, omega in (0, 2)):
 *
 *     B_i <- (1 - w) B_i + w (E_i + rho_i sum_{j != i} F_ij B_j) / (1 - rho_i F_ii)
 *
 * The radiosity matrix is diagonally dominant (rho_i sum_j F_ij <= rho_i <
 * 1), so the iteration converges, each sweep shrinking the error by about
 * the mean reflectance.  A sweep's change sum_i A_i |B_i' - B_i| bounds the
 * residual left behind it (r_i = rho_i sum_{j>i} F_ij (B_j' - B_j) for w = 1),
 * so unless every step is to be measured (a history or a monitor wants it)
 * the true residual (solve.h, an O(n^2) pass) is measured only once the
 * change falls below the tolerance; the sweeps stop when it does too, or
 * at the bound of solve.h (then the residual is measured, so that what is
 * reported is never the estimate).
 */
#include "solve/solve.h"

static rad_result gauss_seidel(rad_context *ctx, const rad_system *sys, const rad_solve_params *p,
                               double *B, rad_solve_stats *stats)
{
    size_t n = sys->n;
    double w = p->relaxation > 0.0 ? p->relaxation : 1.0;
    rad_solve_bound bound = rad_solve_bound_make(p->max_iterations, rad_system_contraction(sys), w, p->tolerance, 1.0);
    double max_sweeps = bound.limit;
    stats->iteration_limit = max_sweeps;
    double emitted = 0.0;
    for (size_t i = 0; i < n; i++)
        emitted += sys->area[i] * (sys->emission[3 * i] + sys->emission[3 * i + 1] + sys->emission[3 * i + 2]);
    double *row = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *row, "solve: gauss-seidel: row residuals");
    if (!row)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result result = RAD_OK;
    double t0 = rad_seconds();
    stats->residual = rad_residual_in(sys, B, row);
    bool measured = true; /* stats->residual is the true residual, not the estimate */
    for (int sweep = 0; sweep < max_sweeps && stats->residual > p->tolerance; sweep++) {
        double change = 0.0;
        for (size_t i = 0; i < n; i++) {
            double g[3];
            const double *Fi = sys->F + i * n;
            rad_gather(Fi, B, n, g);
            const double *rho = sys->reflectance + 3 * i, *E = sys->emission + 3 * i;
            double fii = Fi[i]; /* nonzero only for concave elements */
            for (int c = 0; c < 3; c++) {
                double old = B[3 * i + c];
                double gathered = (E[c] + rho[c] * (g[c] - fii * old)) / (1.0 - rho[c] * fii);
                double updated = (1.0 - w) * old + w * gathered;
                change += sys->area[i] * fabs(updated - old);
                B[3 * i + c] = updated;
            }
        }
        stats->iterations = sweep + 1;
        double estimate = emitted > 0.0 ? change / emitted : change;
        bool measure = p->monitor != NULL || estimate <= p->tolerance || w != 1.0;
        stats->residual = measure ? rad_residual_in(sys, B, row) : estimate;
        measured = measure;
        if (p->monitor) {
            rad_solve_step step = {sweep + 1, rad_seconds() - t0, stats->residual, NAN};
            if (p->monitor(p->monitor_user, &step, B, NULL)) {
                result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: stopped after %d sweeps", sweep + 1);
                break;
            }
        }
        rad_progress(ctx, "solve", (uint64_t)(sweep + 1), (uint64_t)max_sweeps);
        if (rad_cancelled(ctx)) {
            result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: interrupted after %d sweeps", sweep + 1);
            break;
        }
    }
    if (!measured)
        stats->residual = rad_residual_in(sys, B, row);
    rad_free(row);
    if (result == RAD_OK) {
        stats->converged = stats->residual <= p->tolerance;
        if (!stats->converged)
            rad_solve_warn(stats, "gauss-seidel", &bound, stats->iterations, "sweeps", "residual", stats->residual,
                           p->tolerance, RAD_SOLVE_FASTER_HINT);
    }
    return result;
}

const rad_solver rad_solver_gauss_seidel = {
    "gauss-seidel",
    "gathering, newest values first, optional SOR (rad_options.relaxation); O(n^2) per sweep, "
    "error shrinks ~rho per sweep",
    gauss_seidel,
    0,
};
