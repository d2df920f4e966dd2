/*
 * solve_cg.c -- preconditioned conjugate gradients on the symmetrised
 * radiosity system (Hestenes & Stiefel 1952; Saad, "Iterative Methods for
 * Sparse Linear Systems", 2003, alg. 9.1; the notes' "Matrix Properties").
 *
 * Row i of (I - diag(rho) F) B = E scaled by A_i / rho_i reads
 *
 *     (A_i / rho_i) B_i - sum_j A_i F_ij B_j = A_i E_i / rho_i
 *
 * and A_i F_ij = A_j F_ji (reciprocity) makes that matrix symmetric; it is
 * positive definite because sum_j A_i F_ij <= A_i < A_i / rho_i (strict
 * diagonal dominance).  Per colour channel c:
 *
 *   - elements with rho_ic = 0 have B_i = E_i: they are eliminated (their
 *     search directions are held at zero, so their known values act only
 *     through the right-hand side of the others);
 *   - reciprocity holds only to the rounding of F (and to the
 *     form-factor method's own error), so CG runs on the symmetric part
 *
 *         M_ij = (A_i / rho_i) delta_ij - (A_i F_ij + A_j F_ji) / 2,
 *
 *     applied without storing it: one pass over the rows of F (F p) and
 *     one over its columns (F^T (A p)), in blocks of columns per thread so
 *     that every sum runs in the same order whatever the thread count;
 *   - Jacobi preconditioning by diag(M): A_i (1 / rho_i - F_ii).
 *
 * The answer of the symmetric part differs from the engine's by the
 * antisymmetric part (A_i F_ij - A_j F_ji) / 2, so plain CG stalls at a
 * residual of that size: on the Cornell box (analytic F, reciprocity to
 * 1.2e-7) at 7.7e-10 with 800 elements, 4.8e-10 with 3000.  So the true
 * residual is tracked beside CG's own (F x is updated with F p, which the
 * step computes anyway), and a channel restarts from the true residual
 * once CG's has fallen ten times below it: defect correction, each restart
 * gaining as many digits as the asymmetry allows (one restart per channel
 * takes those boxes to 1e-12 in 19 and 20 iterations).  Every iteration
 * measures the engine's residual (solve.h) from the tracked F x; once it
 * is below the tolerance it is measured afresh (one more pass, identical
 * to rad_residual bit for bit), and the solve stops if that confirms it.
 * Each iteration costs two passes over F, about two Gauss-Seidel sweeps,
 * but both run in parallel; the error shrinks by about
 * (sqrt(k) - 1) / (sqrt(k) + 1) per iteration, k <= (1 + rho) / (1 - rho).
 */
#include "solve/solve.h"

#include <stdlib.h>
#include <string.h>

/* Columns per block of the transposed product: 3 x 256 double accumulators
 * (6 KiB) stay in L1 while a thread streams its 1 KiB slice of each row. */
enum { COLUMNS = 256 };

/* Restart a channel when CG's residual (preconditioned norm) falls below
 * this fraction of the true one: below it, CG is solving the asymmetry. */
static const double restart_ratio = 0.1;

typedef struct cg_state {
    const rad_system *sys;
    size_t n;
    int threads;
    double *diag;    /* 3n: A_i (1/rho_i - F_ii); 0 where rho_i = 0 (eliminated) */
    double *Fx;      /* 3n: F x, tracked */
    double *r;       /* 3n: CG's residual of the scaled system */
    double *z;       /* 3n: preconditioned residual */
    double *p;       /* 3n: search direction */
    double *Fp;      /* 3n: F p */
    double *Ap;      /* 3n: A p */
    double *FtAp;    /* 3n: F^T (A p) */
    double *q;       /* 3n: M p */
    double *row;     /* n: per-row residual, summed in order */
    double emitted;  /* sum_i A_i (E_i summed over RGB), W */
} cg_state;

/* out = F v, rows in parallel (each row's sum in a fixed order). */
static void multiply_rows(const cg_state *s, const double *v, double *out)
{
    size_t n = s->n;
    const double *F = s->sys->F;
#pragma omp parallel for schedule(static) num_threads(s->threads)
    for (size_t i = 0; i < n; i++)
        rad_gather(F + i * n, v, n, out + 3 * i);
}

/* out = F^T v: each block of COLUMNS outputs is summed over j in order by
 * one thread, so the result does not depend on the thread count. */
static void multiply_columns(const cg_state *s, const double *v, double *out)
{
    size_t n = s->n;
    const double *F = s->sys->F;
    size_t blocks = (n + COLUMNS - 1) / COLUMNS;
#pragma omp parallel for schedule(static) num_threads(s->threads)
    for (size_t b = 0; b < blocks; b++) {
        size_t i0 = b * COLUMNS, i1 = i0 + COLUMNS < n ? i0 + COLUMNS : n, m = i1 - i0;
        double acc0[COLUMNS] = {0}, acc1[COLUMNS] = {0}, acc2[COLUMNS] = {0};
        for (size_t j = 0; j < n; j++) {
            const double *Fj = F + j * n + i0;
            double w0 = v[3 * j], w1 = v[3 * j + 1], w2 = v[3 * j + 2];
            for (size_t k = 0; k < m; k++) {
                double f = Fj[k];
                acc0[k] += f * w0;
                acc1[k] += f * w1;
                acc2[k] += f * w2;
            }
        }
        for (size_t k = 0; k < m; k++) {
            out[3 * (i0 + k)] = acc0[k];
            out[3 * (i0 + k) + 1] = acc1[k];
            out[3 * (i0 + k) + 2] = acc2[k];
        }
    }
}

/* The engine's residual measure of x given F x (solve.h); with an exact
 * F x it is rad_residual's value bit for bit (same terms, same order). */
static double engine_residual(const cg_state *s, const double *x)
{
    const rad_system *sys = s->sys;
    for (size_t i = 0; i < s->n; i++) {
        const double *rho = sys->reflectance + 3 * i, *E = sys->emission + 3 * i, *g = s->Fx + 3 * i;
        s->row[i] = sys->area[i] * (fabs(x[3 * i] - E[0] - rho[0] * g[0]) +
                                    fabs(x[3 * i + 1] - E[1] - rho[1] * g[1]) +
                                    fabs(x[3 * i + 2] - E[2] - rho[2] * g[2]));
    }
    double num = 0.0;
    for (size_t i = 0; i < s->n; i++)
        num += s->row[i];
    return s->emitted > 0.0 ? num / s->emitted : num;
}

/* The true residual of the scaled system, (A_i / rho_i)(E_i - x_i) + A_i (F x)_i,
 * into `out` for channel c (0 where eliminated). */
static void true_residual(const cg_state *s, const double *x, int c, double *out)
{
    const rad_system *sys = s->sys;
    for (size_t i = 0; i < s->n; i++) {
        size_t k = 3 * i + (size_t)c;
        double rho = sys->reflectance[k];
        out[k] = rho > 0.0 ? sys->area[i] * ((sys->emission[k] - x[k]) / rho + s->Fx[k]) : 0.0;
    }
}

/* Start (or restart) channel c from the true residual; returns r.z. */
static double restart(cg_state *s, const double *x, int c)
{
    true_residual(s, x, c, s->r);
    double rz = 0.0;
    for (size_t i = 0; i < s->n; i++) {
        size_t k = 3 * i + (size_t)c;
        s->z[k] = s->diag[k] > 0.0 ? s->r[k] / s->diag[k] : 0.0;
        s->p[k] = s->z[k];
        rz += s->r[k] * s->z[k];
    }
    return rz;
}

static rad_result conjugate_gradient(rad_context *ctx, const rad_system *sys, const rad_solve_params *p,
                                     double *B, rad_solve_stats *stats)
{
    size_t n = sys->n;
    /* The bound of solve.h at CG's rate: with Jacobi preconditioning the
     * symmetrised system's eigenvalues lie in [1 - q, 1 + q], so the error
     * shrinks by (sqrt(kappa) - 1) / (sqrt(kappa) + 1) per iteration,
     * kappa = (1 + q) / (1 - q) (Saad 2003, sec. 6.11.3). */
    double q = rad_system_contraction(sys);
    double cg_rate = q < 1.0 ? (sqrt((1.0 + q) / (1.0 - q)) - 1.0) / (sqrt((1.0 + q) / (1.0 - q)) + 1.0) : 1.0;
    rad_solve_bound bound = rad_solve_bound_make(p->max_iterations, cg_rate, 1.0, p->tolerance, 1.0);
    bound.contraction = q; /* what the warning names */
    bound.k_units = "iterations at CG's rate";
    int max_iterations = (int)bound.limit;
    stats->iteration_limit = bound.limit;
    cg_state s = {sys, n, rad_pass_threads(sys), NULL, NULL, NULL, NULL, NULL, NULL,
                  NULL, NULL, NULL, NULL, 0.0};
    double *work = rad_alloc(ctx, RAD_MEM_SOLVER, 27 * n + 1, sizeof *work, "solve: conjugate-gradient: vectors");
    s.row = rad_alloc(ctx, RAD_MEM_SOLVER, n + 1, sizeof *s.row, "solve: conjugate-gradient: row residuals");
    if (!work || !s.row) {
        rad_free(work);
        rad_free(s.row);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    double **vectors[] = {&s.diag, &s.Fx, &s.r, &s.z, &s.p, &s.Fp, &s.Ap, &s.FtAp, &s.q};
    for (size_t v = 0; v < sizeof vectors / sizeof vectors[0]; v++)
        *vectors[v] = work + 3 * n * v;

    for (size_t i = 0; i < n; i++) {
        double fii = sys->F[i * n + i]; /* nonzero only for concave elements */
        for (int c = 0; c < 3; c++) {
            size_t k = 3 * i + (size_t)c;
            double rho = sys->reflectance[k];
            s.diag[k] = rho > 0.0 ? sys->area[i] * (1.0 / rho - fii) : 0.0;
            if (!(rho > 0.0))
                B[k] = sys->emission[k]; /* eliminated: known */
        }
        s.emitted += sys->area[i] * (sys->emission[3 * i] + sys->emission[3 * i + 1] +
                                     sys->emission[3 * i + 2]);
    }
    double t0 = rad_seconds();
    multiply_rows(&s, B, s.Fx);
    stats->residual = engine_residual(&s, B);
    double rz[3];
    for (int c = 0; c < 3; c++)
        rz[c] = restart(&s, B, c);

    rad_result result = RAD_OK;
    int it = 0;
    while (stats->residual > p->tolerance && it < max_iterations) {
        /* q = M p = (A / rho) p - (A (F p) + F^T (A p)) / 2, p = 0 where eliminated. */
        multiply_rows(&s, s.p, s.Fp);
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++)
                s.Ap[3 * i + c] = sys->area[i] * s.p[3 * i + c];
        multiply_columns(&s, s.Ap, s.FtAp);
        double pq[3] = {0.0, 0.0, 0.0};
        for (size_t i = 0; i < n; i++) {
            double fii = sys->F[i * n + i];
            for (int c = 0; c < 3; c++) {
                size_t k = 3 * i + (size_t)c;
                double rho = sys->reflectance[k];
                /* diag holds A (1/rho - F_ii); add F_ii back, as M's off-diagonal part has it */
                s.q[k] = rho > 0.0 ? (s.diag[k] + sys->area[i] * fii) * s.p[k] -
                                         0.5 * (sys->area[i] * s.Fp[k] + s.FtAp[k])
                                   : 0.0;
                pq[c] += s.p[k] * s.q[k];
            }
        }
        double alpha[3];
        for (int c = 0; c < 3; c++)
            alpha[c] = rz[c] > 0.0 && pq[c] > 0.0 ? rz[c] / pq[c] : 0.0;
        for (size_t k = 0; k < 3 * n; k++) {
            int c = (int)(k % 3);
            B[k] += alpha[c] * s.p[k];
            s.Fx[k] += alpha[c] * s.Fp[k];
            s.r[k] -= alpha[c] * s.q[k];
        }
        it++;
        stats->residual = engine_residual(&s, B);
        bool restarted = false;
        if (!(stats->residual > p->tolerance)) {
            /* Confirm on an exact F x; if rounding in the tracked one had
             * misled us, go on from the exact one. */
            multiply_rows(&s, B, s.Fx);
            stats->residual = engine_residual(&s, B);
            if (stats->residual > p->tolerance) {
                for (int c = 0; c < 3; c++)
                    rz[c] = restart(&s, B, c);
                restarted = true;
            }
        }
        if (stats->residual > p->tolerance && !restarted) {
            for (int c = 0; c < 3; c++) {
                double rz_new = 0.0, true_norm = 0.0;
                for (size_t i = 0; i < n; i++) {
                    size_t k = 3 * i + (size_t)c;
                    s.z[k] = s.diag[k] > 0.0 ? s.r[k] / s.diag[k] : 0.0;
                    rz_new += s.r[k] * s.z[k];
                }
                true_residual(&s, B, c, s.q); /* q is free until the next product */
                for (size_t i = 0; i < n; i++) {
                    size_t k = 3 * i + (size_t)c;
                    if (s.diag[k] > 0.0)
                        true_norm += s.q[k] * s.q[k] / s.diag[k];
                }
                if (rz_new < restart_ratio * restart_ratio * true_norm || !(alpha[c] > 0.0)) {
                    rz[c] = restart(&s, B, c);
                    continue;
                }
                double beta = rz[c] > 0.0 ? rz_new / rz[c] : 0.0;
                for (size_t i = 0; i < n; i++) {
                    size_t k = 3 * i + (size_t)c;
                    s.p[k] = s.z[k] + beta * s.p[k];
                }
                rz[c] = rz_new;
            }
        }
        if (p->monitor) {
            rad_solve_step step = {it, rad_seconds() - t0, stats->residual, NAN};
            if (p->monitor(p->monitor_user, &step, B, NULL)) {
                result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: stopped after %d iterations", it);
                break;
            }
        }
        rad_progress(ctx, "solve", (uint64_t)it, (uint64_t)max_iterations);
        if (rad_cancelled(ctx)) {
            result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: interrupted after %d iterations", it);
            break;
        }
    }
    stats->iterations = it;
    stats->converged = result == RAD_OK && stats->residual <= p->tolerance;
    if (result == RAD_OK && !stats->converged)
        rad_solve_warn(stats, "conjugate-gradient", &bound, it, "iterations", "residual", stats->residual,
                       p->tolerance, "");
    rad_free(work);
    rad_free(s.row);
    return result;
}

const rad_solver rad_solver_conjugate_gradient = {
    "conjugate-gradient",
    "Jacobi-preconditioned CG on the system symmetrised by A/rho, restarted on the true "
    "residual; two parallel O(n^2) passes per iteration",
    conjugate_gradient,
    0,
};
