/*
 * solve_gauss_seidel.c -- gathering: each element in turn gathers from all
 * others, using the newest values at once (Cohen & Wallace 1993, sec. 5.3;
 * the notes' "Gathering"):
 *
 *     B_i <- E_i + rho_i sum_{j != i} F_ij B_j
 *
 * The radiosity matrix is diagonally dominant (rho_i sum_j F_ij <= rho_i <
 * 1), so the iteration converges, each sweep shrinking the error by about
 * the mean reflectance.  A sweep's change sum_i A_i |B_i' - B_i| bounds the
 * residual left behind it (r_i = rho_i sum_{j>i} F_ij (B_j' - B_j)), so the
 * true residual (solve.h, an O(n^2) pass) is measured only once the change
 * falls below the tolerance, and the sweeps stop when it does too.
 */
#include "solve/solve.h"

static rad_result gauss_seidel(rad_context *ctx, const rad_system *sys, const rad_solve_params *p,
                               double *B, rad_solve_stats *stats)
{
    size_t n = sys->n;
    int max_sweeps = p->max_iterations > 0 ? p->max_iterations : 1000;
    double emitted = 0.0;
    for (size_t i = 0; i < n; i++)
        emitted += sys->area[i] * (sys->emission[3 * i] + sys->emission[3 * i + 1] + sys->emission[3 * i + 2]);
    stats->residual = rad_residual(sys, B);
    for (int sweep = 0; sweep < max_sweeps && stats->residual > p->tolerance; sweep++) {
        double change = 0.0;
        for (size_t i = 0; i < n; i++) {
            /* F_ii B_i is included: the element's own (concave) share. */
            double g[3];
            rad_gather(sys->F + i * n, B, n, g);
            const double *rho = sys->reflectance + 3 * i, *E = sys->emission + 3 * i;
            double b0 = E[0] + rho[0] * g[0], b1 = E[1] + rho[1] * g[1], b2 = E[2] + rho[2] * g[2];
            change += sys->area[i] * (fabs(b0 - B[3 * i]) + fabs(b1 - B[3 * i + 1]) + fabs(b2 - B[3 * i + 2]));
            B[3 * i] = b0;
            B[3 * i + 1] = b1;
            B[3 * i + 2] = b2;
        }
        stats->iterations = sweep + 1;
        double estimate = emitted > 0.0 ? change / emitted : change;
        stats->residual = estimate > p->tolerance ? estimate : rad_residual(sys, B);
        rad_progress(ctx, "solve", (uint64_t)(sweep + 1), (uint64_t)max_sweeps);
        if (rad_cancelled(ctx))
            return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: interrupted after %d sweeps",
                            sweep + 1);
    }
    stats->converged = stats->residual <= p->tolerance;
    return RAD_OK;
}

const rad_solver rad_solver_gauss_seidel = {
    "gauss-seidel",
    "gathering, newest values first (Cohen & Wallace 1993); O(n^2) per sweep, "
    "error shrinks ~rho per sweep",
    gauss_seidel,
};
