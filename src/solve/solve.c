/*
 * solve.c -- the solver registry and the residual every solver reports.
 */
#include "solve/solve.h"

#include <stdlib.h>
#include <string.h>

extern const rad_solver rad_solver_gauss_seidel;
extern const rad_solver rad_solver_southwell;
extern const rad_solver rad_solver_jacobi;
extern const rad_solver rad_solver_direct;
extern const rad_solver rad_solver_conjugate_gradient;

const rad_solver *const rad_solvers[] = {
    &rad_solver_gauss_seidel,
    &rad_solver_southwell,
    &rad_solver_jacobi,
    &rad_solver_direct,
    &rad_solver_conjugate_gradient,
    NULL,
};

const rad_solver *rad_solver_find(const char *name)
{
    for (size_t i = 0; rad_solvers[i]; i++)
        if (strcmp(rad_solvers[i]->name, name) == 0)
            return rad_solvers[i];
    return NULL;
}

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
