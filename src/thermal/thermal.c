/*
 * thermal.c -- the net-radiation equations of thermal.h built from F and
 * solved by a solver of the table, and Gebhart factors by the same solvers.
 */
#include "thermal/thermal.h"

#include <stdlib.h>
#include <string.h>

static size_t find_root(size_t *parent, size_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* "surface 'floor'" or "element 12", for messages. */
static void element_name(const rad_thermal_system *sys, size_t i, char *out, size_t size)
{
    if (sys->surface && sys->surface_names)
        snprintf(out, size, "surface '%s'", sys->surface_names[sys->surface[i]]);
    else
        snprintf(out, size, "element %zu", i);
}

/* Refuse a group of elements coupled through F with heat fluxes only and
 * (almost) nothing escaping: its system is singular.  Union-find over the
 * pairs with F_ij > 0 (one O(n^2) scan), then per group its known
 * temperatures and its escaping fraction. */
static rad_result check_determined(rad_context *ctx, const rad_thermal_system *sys)
{
    size_t n = sys->n;
    size_t *parent = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *parent, "thermal: groups");
    double *escape = rad_alloc(ctx, RAD_MEM_SOLVER, 2 * n, sizeof *escape, "thermal: groups");
    unsigned char *has_t = rad_alloc(ctx, RAD_MEM_SOLVER, n, 1, "thermal: groups");
    if (!parent || !escape || !has_t) {
        rad_free(parent);
        rad_free(escape);
        rad_free(has_t);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < n; i++)
        parent[i] = i;
    for (size_t i = 0; i < n; i++) {
        const double *Fi = sys->F + i * n;
        for (size_t j = 0; j < n; j++) {
            if (Fi[j] > 0.0 && j != i) {
                size_t a = find_root(parent, i), b = find_root(parent, j);
                if (a != b)
                    parent[a < b ? b : a] = a < b ? a : b;
            }
        }
    }
    for (size_t i = 0; i < n; i++) {
        const double *Fi = sys->F + i * n;
        double s = 0.0;
        for (size_t j = 0; j < n; j++)
            s += Fi[j];
        size_t r = find_root(parent, i);
        escape[2 * r] += sys->area[i] * (1.0 - s);
        escape[2 * r + 1] += sys->area[i];
        has_t[r] |= sys->known_temperature[i];
    }
    rad_result result = RAD_OK;
    for (size_t i = 0; i < n && result == RAD_OK; i++) {
        if (parent[i] != i || has_t[i])
            continue;
        double fraction = escape[2 * i] / escape[2 * i + 1];
        if (!(fraction >= RAD_THERMAL_CLOSED_ESCAPE)) {
            char name[320];
            element_name(sys, i, name, sizeof name);
            result = rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                              "%s: %s and the surfaces it exchanges radiation with form a closed "
                              "enclosure (%.2g of their radiation escapes, below %.0e) with heat fluxes "
                              "only: their temperatures are undetermined; give one of them a temperature",
                              sys->source ? sys->source : "thermal", name, fraction, RAD_THERMAL_CLOSED_ESCAPE);
        }
    }
    rad_free(parent);
    rad_free(escape);
    rad_free(has_t);
    return result;
}

/* rho and E of the system of thermal.h, E split in two channels (E+, E-). */
static void build_rows(const rad_thermal_system *sys, const double *row_sum, double *rho, double *E)
{
    double env = RAD_SIGMA * pow(sys->environment_temperature, 4);
    for (size_t i = 0; i < sys->n; i++) {
        double eps = sys->emissivity[i], e;
        if (sys->known_temperature[i]) {
            rho[3 * i] = 1.0 - eps;
            e = eps * RAD_SIGMA * pow(sys->value[i], 4) + (1.0 - eps) * (1.0 - row_sum[i]) * env;
        } else {
            rho[3 * i] = 1.0;
            e = sys->value[i] + (1.0 - row_sum[i]) * env;
        }
        rho[3 * i + 1] = rho[3 * i + 2] = rho[3 * i];
        E[3 * i] = e > 0.0 ? e : 0.0;
        E[3 * i + 1] = e < 0.0 ? -e : 0.0;
        E[3 * i + 2] = 0.0;
    }
}

static void row_sums(const rad_thermal_system *sys, double *row_sum)
{
    size_t n = sys->n;
    for (size_t i = 0; i < n; i++) {
        const double *Fi = sys->F + i * n;
        double s = 0.0;
        for (size_t j = 0; j < n; j++)
            s += Fi[j];
        row_sum[i] = s;
    }
}

rad_result rad_thermal_solve_system(rad_context *ctx, const rad_thermal_system *sys, const rad_solver *solver,
                                    const rad_solve_params *p, rad_thermal_fields *out,
                                    rad_thermal_balance *balance, rad_solve_stats *stats)
{
    size_t n = sys->n;
    rad_solve_stats local = {0};
    rad_solve_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    st->unshot = NAN;
    st->absorbed = NAN;
    if (!solver)
        solver = rad_solver_find("direct");
    st->method = solver->name;
    rad_result r = check_determined(ctx, sys);
    if (r != RAD_OK)
        return r;
    double *rho = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *rho, "thermal: reflectances");
    double *E = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *E, "thermal: emission");
    double *B = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *B, "thermal: radiosity");
    double *row_sum = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *row_sum, "thermal: row sums");
    if (!rho || !E || !B || !row_sum) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    row_sums(sys, row_sum);
    build_rows(sys, row_sum, rho, E);
    memcpy(B, E, 3 * n * sizeof *B);
    rad_system lin = {.n = n, .F = sys->F, .area = sys->area, .reflectance = rho, .emission = E,
                      .threads = sys->threads, .max_memory = sys->max_memory};
    double t0 = rad_seconds();
    r = solver->solve(ctx, &lin, p, B, st);
    st->seconds = rad_seconds() - t0;
    if (r != RAD_OK)
        goto done;

    double env = RAD_SIGMA * pow(sys->environment_temperature, 4);
    rad_thermal_balance b = {0};
    for (size_t i = 0; i < n; i++)
        out->radiosity[i] = B[3 * i] - B[3 * i + 1];
    for (size_t i = 0; i < n && r == RAD_OK; i++) {
        const double *Fi = sys->F + i * n;
        double g = 0.0, to_environment = 1.0 - row_sum[i]; /* and to obstruction surfaces */
        for (size_t j = 0; j < n; j++) {
            g += Fi[j] * out->radiosity[j];
            if (sys->environment && sys->environment[j])
                to_environment += Fi[j];
        }
        g += (1.0 - row_sum[i]) * env;
        double J = out->radiosity[i], q = J - g;
        out->irradiation[i] = g;
        out->heat_flux[i] = q;
        if (sys->known_temperature[i]) {
            out->temperature[i] = sys->value[i];
        } else {
            /* sigma T^4 = q / eps + G; the given q, not J - G, which carries
             * the solve's rounding.  A little below zero is rounding of a
             * surface radiating nothing; more is a flux it cannot emit. */
            double t4 = sys->value[i] / sys->emissivity[i] + g;
            double scale = fabs(sys->value[i]) / sys->emissivity[i] + fabs(g);
            if (t4 < -1e-9 * scale) {
                char name[320];
                element_name(sys, i, name, sizeof name);
                r = rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                             "%s: %s: a heat flux of %.6g W/m^2 needs more than its emissivity %.6g "
                             "times its irradiation %.6g W/m^2 can absorb (the flux leaving it must be at "
                             "least -eps G): no temperature gives it",
                             sys->source ? sys->source : "thermal", name, sys->value[i], sys->emissivity[i], g);
                break;
            }
            out->temperature[i] = t4 > 0.0 ? pow(t4 / RAD_SIGMA, 0.25) : 0.0;
        }
        if (sys->environment && sys->environment[i])
            continue;
        double Q = sys->area[i] * q;
        b.net_power += Q;
        b.power_scale += fabs(Q);
        b.environment_power += sys->area[i] * to_environment * (J - env);
    }
    b.imbalance = b.net_power - b.environment_power;
    b.relative_imbalance = b.power_scale > 0.0 ? b.imbalance / b.power_scale : 0.0;
    if (balance)
        *balance = b;
done:
    rad_free(rho);
    rad_free(E);
    rad_free(B);
    rad_free(row_sum);
    return r;
}

rad_result rad_thermal_gebhart_factors(rad_context *ctx, const rad_thermal_system *sys, size_t S, const rad_solver *solver,
                               const rad_solve_params *p, double *G)
{
    size_t n = sys->n;
    if (!solver)
        solver = rad_solver_find("direct");
    memset(G, 0, S * S * sizeof *G);
    double *rho = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *rho, "thermal: Gebhart reflectances");
    double *E = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *E, "thermal: Gebhart emission");
    double *B = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *B, "thermal: Gebhart radiosity");
    double *emitted = rad_alloc(ctx, RAD_MEM_SOLVER, S, sizeof *emitted, "thermal: Gebhart emission");
    rad_result r = RAD_OK;
    if (!rho || !E || !B || !emitted) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    for (size_t i = 0; i < n; i++) {
        rho[3 * i] = rho[3 * i + 1] = rho[3 * i + 2] = 1.0 - sys->emissivity[i];
        emitted[sys->surface[i]] += sys->area[i] * sys->emissivity[i];
    }
    rad_system lin = {.n = n, .F = sys->F, .area = sys->area, .reflectance = rho, .emission = E,
                      .threads = sys->threads, .max_memory = sys->max_memory};
    for (size_t s0 = 0; s0 < S && r == RAD_OK; s0 += 3) {
        size_t k = S - s0 < 3 ? S - s0 : 3;
        bool any = false;
        for (size_t c = 0; c < k; c++)
            any |= emitted[s0 + c] > 0.0;
        if (!any)
            continue;
        /* Unit emissive power on surfaces s0, s0 + 1, s0 + 2: one channel each. */
        for (size_t i = 0; i < n; i++)
            for (size_t c = 0; c < 3; c++)
                E[3 * i + c] = c < k && sys->surface[i] == s0 + c ? sys->emissivity[i] : 0.0;
        memcpy(B, E, 3 * n * sizeof *B);
        rad_solve_stats st = {0};
        r = solver->solve(ctx, &lin, p, B, &st);
        if (r != RAD_OK)
            break;
        for (size_t j = 0; j < n; j++) {
            double g[3];
            rad_gather(sys->F + j * n, B, n, g);
            double absorber = sys->area[j] * sys->emissivity[j];
            for (size_t c = 0; c < k; c++)
                if (emitted[s0 + c] > 0.0)
                    G[(s0 + c) * S + sys->surface[j]] += absorber * g[c] / emitted[s0 + c];
        }
        rad_progress(ctx, "gebhart", (uint64_t)(s0 + k), (uint64_t)S);
        if (rad_cancelled(ctx))
            r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "thermal: Gebhart factors interrupted");
    }
done:
    rad_free(rho);
    rad_free(E);
    rad_free(B);
    rad_free(emitted);
    return r;
}
