/*
 * solve.h -- solvers of the radiosity system (I - P F) B = E behind one
 * small table (Cohen & Wallace 1993, ch. 5).  All work on RGB at once and
 * share the residual measure of the lecture notes:
 *
 *     r_i = B_i - E_i - rho_i sum_j F_ij B_j
 *     residual = sum_c sum_i A_i |r_ic|  /  sum_c sum_i A_i E_ic
 *
 * i.e. the power not yet accounted for, as a fraction of the emitted power.
 */
#ifndef RAD_SOLVE_H
#define RAD_SOLVE_H

#include "core/core.h"

typedef struct rad_system {
    size_t n;
    const float *F;           /* n x n, row i = factors from i */
    const double *area;       /* n, m^2 */
    const double *reflectance;/* 3n, interleaved RGB */
    const double *emission;   /* 3n, W/m^2 */
    int threads;              /* for the O(n^2) passes that run in parallel */
} rad_system;

typedef struct rad_solve_params {
    double tolerance;
    int max_iterations;
} rad_solve_params;

typedef struct rad_solve_stats {
    const char *method;
    int iterations;           /* sweeps (gathering) or shots (shooting) */
    double residual;
    double seconds;
    bool converged;
    double ambient[3];        /* shooting: estimate of unshot light for display, W/m^2 */
} rad_solve_stats;

typedef struct rad_solver {
    const char *name;
    const char *description;
    /* B (3n) holds the starting guess (E) and receives the answer. */
    rad_result (*solve)(rad_context *ctx, const rad_system *sys, const rad_solve_params *p,
                        double *B, rad_solve_stats *stats);
} rad_solver;

extern const rad_solver *const rad_solvers[]; /* NULL-terminated */
const rad_solver *rad_solver_find(const char *name);

/* Irradiance gathered by one row: g[c] = sum_j F_ij B_jc (B interleaved RGB). */
static inline void rad_gather(const float *F_row, const double *B, size_t n, double g[3])
{
    double g0 = 0.0, g1 = 0.0, g2 = 0.0;
    for (size_t j = 0; j < n; j++) {
        double f = F_row[j];
        g0 += f * B[3 * j];
        g1 += f * B[3 * j + 1];
        g2 += f * B[3 * j + 2];
    }
    g[0] = g0;
    g[1] = g1;
    g[2] = g2;
}

/* The residual measure above (O(n^2)). */
double rad_residual(const rad_system *sys, const double *B);

/* The ambient term of progressive refinement for unshot radiosity dB
 * (solve_southwell.c). */
void rad_southwell_ambient(const rad_system *sys, const double *dB, double ambient[3]);

#endif /* RAD_SOLVE_H */
