/*
 * solve_southwell.c -- progressive refinement by shooting (Cohen, Chen,
 * Wallace & Greenberg, SIGGRAPH 1988; the notes' "Progressive Refinement"):
 * the element with the most unshot power dB_i A_i shoots it to all others,
 *
 *     dB_j += rho_j F_ji dB_i,  B_j += the same,  dB_i = 0,
 *
 * which is Southwell iteration on the radiosity system: with B' = B - dB
 * the light already shot, K B' = E - dB, so dB is the residual of B' and a
 * shot relaxes one equation.  Over-relaxation (omega > 1, "overshooting",
 * Feda & Purgathofer 1992) shoots omega dB_i and leaves (1 - omega) dB_i
 * unshot, negative; selection is then by |dB_i| A_i.  F_ji is read from
 * row i through reciprocity, F_ji = F_ij A_i / A_j, so the pass is one
 * contiguous row.  Shooting stops when the unshot power falls below the
 * tolerance times the emitted power; the residual is then measured.
 *
 * The ambient term (the notes' "Ambient Term"; Cohen et al. 1988) estimates
 * the light not yet shot, for display of a partial solution:
 *
 *     I_a = mu * sum_j dB_j A_j / sum_k A_k,  mu = 1 / (1 - rho_avg)
 *
 * and rad_southwell_ambient() returns it; display adds rho_i I_a.
 */
#include "solve/solve.h"

#include <stdlib.h>


void rad_southwell_ambient(const rad_system *sys, const double *dB, double ambient[3])
{
    double area = 0.0, rho_area[3] = {0, 0, 0}, unshot[3] = {0, 0, 0};
    for (size_t i = 0; i < sys->n; i++) {
        area += sys->area[i];
        for (int c = 0; c < 3; c++) {
            rho_area[c] += sys->reflectance[3 * i + c] * sys->area[i];
            unshot[c] += dB[3 * i + c] * sys->area[i];
        }
    }
    for (int c = 0; c < 3; c++) {
        double rho_avg = area > 0.0 ? rho_area[c] / area : 0.0;
        double mu = 1.0 / (1.0 - rho_avg);
        ambient[c] = area > 0.0 ? mu * unshot[c] / area : 0.0;
    }
}

static rad_result southwell(rad_context *ctx, const rad_system *sys, const rad_solve_params *p,
                            double *B, rad_solve_stats *stats)
{
    size_t n = sys->n;
    double w = p->relaxation > 0.0 ? p->relaxation : 1.0;
    double *dB = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *dB, "solve: unshot radiosity");
    if (!dB)
        return RAD_ERROR_OUT_OF_MEMORY;
    double emitted = 0.0;
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++)
            dB[3 * i + c] = B[3 * i + c];
        emitted += sys->area[i] * (sys->emission[3 * i] + sys->emission[3 * i + 1] +
                                   sys->emission[3 * i + 2]);
    }
    /* Unshot power alone does not bound the residual tightly (the residual is
     * rho F dB); shooting stops on unshot power below the residual tolerance,
     * or below unshot_tolerance when given, and the residual is then measured. */
    double unshot_goal = p->unshot_tolerance > 0.0 ? p->unshot_tolerance : p->tolerance;
    /* A bounce of light is about n shots (every element shoots once). */
    rad_solve_bound bound = rad_solve_bound_make(p->max_iterations, rad_system_contraction(sys), w, unshot_goal,
                                                 (double)(n > 0 ? n : 1));
    long long max_shots = (long long)bound.limit;
    stats->iteration_limit = bound.limit;
    long long shot = 0;
    double t0 = rad_seconds(), unshot = 0.0;
    rad_result result = RAD_OK;
    for (; shot < max_shots; shot++) {
        size_t best = 0;
        double best_power = -1.0;
        unshot = 0.0;
        for (size_t i = 0; i < n; i++) {
            double power = sys->area[i] * (fabs(dB[3 * i]) + fabs(dB[3 * i + 1]) + fabs(dB[3 * i + 2]));
            unshot += power;
            if (power > best_power) {
                best_power = power;
                best = i;
            }
        }
        unshot = emitted > 0.0 ? unshot / emitted : unshot;
        if (!(unshot > unshot_goal) || best_power <= 0.0)
            break;
        /* Shoot w dB_i (overshooting for w > 1: Southwell over-relaxation);
         * B_i keeps its value, the rest of dB_i stays unshot (negative). */
        const double *Fi = sys->F + best * n;
        double s0 = w * dB[3 * best], s1 = w * dB[3 * best + 1], s2 = w * dB[3 * best + 2];
        double ai = sys->area[best];
        for (size_t j = 0; j < n; j++) {
            double fji = Fi[j] * ai / sys->area[j];
            if (fji == 0.0)
                continue;
            const double *rho = sys->reflectance + 3 * j;
            double d0 = rho[0] * fji * s0, d1 = rho[1] * fji * s1, d2 = rho[2] * fji * s2;
            dB[3 * j] += d0;
            dB[3 * j + 1] += d1;
            dB[3 * j + 2] += d2;
            B[3 * j] += d0;
            B[3 * j + 1] += d1;
            B[3 * j + 2] += d2;
        }
        dB[3 * best] -= s0;
        dB[3 * best + 1] -= s1;
        dB[3 * best + 2] -= s2;
        if (p->monitor) {
            rad_southwell_ambient(sys, dB, stats->ambient);
            rad_solve_step step = {(int)(shot + 1 < 2147483647LL ? shot + 1 : 2147483647LL),
                                   rad_seconds() - t0, NAN, unshot};
            if (p->monitor(p->monitor_user, &step, B, stats->ambient)) {
                shot++;
                result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: stopped after %lld shots", shot);
                break;
            }
        }
        if ((shot & 255) == 0) {
            rad_progress(ctx, "solve", (uint64_t)shot, (uint64_t)max_shots);
            if (rad_cancelled(ctx)) {
                shot++;
                result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: interrupted after %lld shots", shot);
                break;
            }
        }
    }
    stats->iterations = shot > 2147483647LL ? 2147483647 : (int)shot;
    /* What is left unshot after the last shot (the loop measured it before). */
    unshot = 0.0;
    for (size_t i = 0; i < n; i++)
        unshot += sys->area[i] * (fabs(dB[3 * i]) + fabs(dB[3 * i + 1]) + fabs(dB[3 * i + 2]));
    unshot = emitted > 0.0 ? unshot / emitted : unshot;
    stats->unshot = unshot;
    rad_southwell_ambient(sys, dB, stats->ambient);
    rad_free(dB);
    rad_result measured = rad_residual(ctx, sys, B, &stats->residual);
    if (result == RAD_OK)
        result = measured;
    stats->converged = result == RAD_OK && stats->residual <= p->tolerance;
    if (result == RAD_OK && !stats->converged && unshot > unshot_goal)
        rad_solve_warn(stats, "southwell", &bound, (double)shot, "shots", "unshot power", unshot, unshot_goal,
                       RAD_SOLVE_FASTER_HINT);
    else if (result == RAD_OK && !stats->converged)
        snprintf(stats->warning, sizeof stats->warning,
                 "southwell shot the unshot power down to %.3g of the emitted (goal %.3g), which leaves the "
                 "residual at %.3g, above the tolerance %.3g",
                 unshot, unshot_goal, stats->residual, p->tolerance);
    return result;
}

const rad_solver rad_solver_southwell = {
    "southwell",
    "progressive refinement: shoot the largest unshot power (Cohen et al. 1988), "
    "overshooting with rad_options.relaxation > 1, ambient term for display; O(n) per shot",
    southwell,
    RAD_SOLVER_RECIPROCAL,
};
