/*
 * system.c -- what every solver of B = E + rho F B shares: the residual
 * it reports, the contraction bound on how long an iterative solver may
 * run, and the warning when it stops short.
 */
#include "solve/solve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void rad_residual_rows(const rad_system *sys, const double *B, double *row)
{
    size_t n = sys->n;
#pragma omp parallel for schedule(static) num_threads(rad_pass_threads(sys))
    for (size_t i = 0; i < n; i++) {
        double g[3];
        rad_gather(sys->F + i * n, B, n, g);
        const double *rho = sys->reflectance + 3 * i, *E = sys->emission + 3 * i;
        row[i] = sys->area[i] * (fabs(B[3 * i] - E[0] - rho[0] * g[0]) +
                                 fabs(B[3 * i + 1] - E[1] - rho[1] * g[1]) +
                                 fabs(B[3 * i + 2] - E[2] - rho[2] * g[2]));
    }
}

/* Rows in parallel, each into its own slot, then a sequential sum: the
 * result is bit-identical whatever the thread count (a reduction clause
 * would add in a thread-dependent order). */
double rad_residual_in(const rad_system *sys, const double *B, double *row)
{
    size_t n = sys->n;
    rad_residual_rows(sys, B, row);
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < n; i++) {
        num += row[i];
        den += sys->area[i] * (sys->emission[3 * i] + sys->emission[3 * i + 1] + sys->emission[3 * i + 2]);
    }
    return den > 0.0 ? num / den : num;
}

rad_result rad_residual(rad_context *ctx, const rad_system *sys, const double *B, double *residual)
{
    double *row = rad_alloc(ctx, RAD_MEM_SOLVER, sys->n, sizeof *row, "solve: residual");
    if (!row) {
        *residual = INFINITY; /* not measured: never reported as converged */
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    *residual = rad_residual_in(sys, B, row);
    rad_free(row);
    return RAD_OK;
}

/* ---- how long an iterative solver may run ---- */

double rad_system_contraction(const rad_system *sys)
{
    size_t n = sys->n;
    double rho = 0.0, rows = sys->F ? 0.0 : 1.0;
    for (size_t k = 0; k < 3 * n; k++)
        rho = fmax(rho, sys->reflectance[k]);
    if (sys->F) {
        /* The largest of sums each made in one order: thread-count independent. */
#pragma omp parallel for schedule(static) reduction(max : rows) num_threads(rad_pass_threads(sys))
        for (size_t i = 0; i < n; i++) {
            const double *Fi = sys->F + i * n;
            double s = 0.0;
            for (size_t j = 0; j < n; j++)
                s += Fi[j];
            rows = fmax(rows, s);
        }
    }
    return rho * rows;
}

rad_solve_bound rad_solve_bound_make(int max_iterations, double q, double relaxation, double goal,
                                     double per_bounce)
{
    double w = relaxation > 0.0 ? relaxation : 1.0;
    double rate = fabs(1.0 - w) + w * q;
    rad_solve_bound b = {0.0, INFINITY, q, RAD_BOUND_PHYSICS, NULL};
    if (!(rate < 1.0))
        b.bounces = INFINITY;               /* no bound from the physics */
    else if (rate <= 0.0 || !(goal < 1.0))
        b.bounces = 1.0;                    /* nothing is reflected, or nothing asked */
    else
        b.bounces = fmax(1.0, ceil(log(goal) / log(rate)));
    double physics = (2.0 * b.bounces + 10.0) * per_bounce;
    if (max_iterations > 0 && (double)max_iterations <= physics) {
        b.limit = max_iterations;
        b.reason = RAD_BOUND_USER;
    } else if (max_iterations > 0 || physics <= RAD_SOLVE_BOUNCE_CAP * per_bounce) {
        b.limit = physics;
    } else {
        b.limit = RAD_SOLVE_BOUNCE_CAP * per_bounce;
        b.reason = RAD_BOUND_CAP;
    }
    b.limit = fmax(1.0, ceil(b.limit));
    return b;
}

void rad_solve_warn(rad_solve_stats *stats, const char *who, const rad_solve_bound *bound, double done,
                    const char *units, const char *measure, double value, double goal, const char *hint)
{
    const char *k_units = bound->k_units ? bound->k_units : "bounces";
    char why[192];
    if (bound->reason == RAD_BOUND_USER)
        snprintf(why, sizeof why, "rad_options.max_iterations");
    else if (bound->reason == RAD_BOUND_CAP && isfinite(bound->bounces))
        snprintf(why, sizeof why, "the cap; reflectance x row sum %.7g needs k = %.2g %s", bound->contraction,
                 bound->bounces, k_units);
    else if (bound->reason == RAD_BOUND_CAP)
        snprintf(why, sizeof why, "the cap; reflectance x row sum %.7g bounds no count", bound->contraction);
    else
        snprintf(why, sizeof why, "its bound, 2 k + 10 for the k = %.0f %s that reflectance x row sum %.7g needs",
                 bound->bounces, k_units, bound->contraction);
    snprintf(stats->warning, sizeof stats->warning, "%s did not converge in %.0f %s (%s): %s %.3g, tolerance %.3g%s",
             who, done, units, why, measure, value, goal, hint ? hint : "");
}
