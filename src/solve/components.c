/*
 * components.c -- independent sets of elements solved separately (the
 * notes' "Sometimes, there are independent sets of elements (2 separate
 * rooms) -- the matrix is then block diagonal and separable"; Cohen &
 * Wallace 1993, sec. 5.1).
 *
 * Elements i and j interact when F_ij > 0 or F_ji > 0.  The connected
 * components of that graph (union-find with path halving and union by
 * size; Tarjan 1975) are the diagonal blocks of F after a permutation:
 *
 *         room 1   room 2            each block is its own radiosity
 *        [ F_11  |   0   ]           system: solving it alone costs
 *    F = [-------+-------]           n_1^2 + n_2^2 per sweep instead
 *        [   0   |  F_22 ]           of (n_1 + n_2)^2, and n_k^3 for LU
 *
 * One row-major scan of F finds them, and stops as soon as everything is
 * joined (the usual single room: a few rows).  Isolated elements are
 * solved in closed form, B_i = E_i / (1 - rho_i F_ii); groups without an
 * emitter keep B = E = 0, which is exact; every other group gets a copy of
 * its block of F (elements in their original order) and the caller's
 * solver.  Its monitor steps are renumbered over the whole run, and their
 * residual and unshot power rescaled from the group's emitted power to
 * the whole system's, the groups not being solved counting with what they
 * had at the start (pending) or at their end (done): the whole system's
 * measure, since F has no coupling between groups.
 */
#include "solve/solve.h"

#include <stdlib.h>
#include <string.h>

/* ---- union-find (solve.h) ---- */

size_t rad_union_find_root(size_t *parent, size_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]]; /* path halving */
        i = parent[i];
    }
    return i;
}

size_t rad_union_find_join(size_t *parent, size_t *size, size_t a, size_t b)
{
    a = rad_union_find_root(parent, a);
    b = rad_union_find_root(parent, b);
    if (a == b)
        return SIZE_MAX;
    if (size[a] < size[b]) {
        size_t t = a;
        a = b;
        b = t;
    }
    parent[b] = a;
    size[a] += size[b];
    return a;
}

/* Label the components 0, 1, ... in order of their first element; returns
 * the count.  label[i] receives element i's component. */
static size_t label_components(const rad_system *sys, size_t *parent, size_t *size, size_t *label)
{
    size_t n = sys->n, sets = n;
    for (size_t i = 0; i < n; i++) {
        parent[i] = i;
        size[i] = 1;
    }
    for (size_t i = 0; i < n && sets > 1; i++) {
        const double *Fi = sys->F + i * n;
        for (size_t j = 0; j < n; j++)
            if (j != i && Fi[j] > 0.0 && rad_union_find_join(parent, size, i, j) != SIZE_MAX)
                sets--;
    }
    size_t count = 0;
    for (size_t i = 0; i < n; i++)
        label[i] = SIZE_MAX;
    for (size_t i = 0; i < n; i++) {
        size_t root = rad_union_find_root(parent, i);
        if (label[root] == SIZE_MAX)
            label[root] = count++;
        label[i] = label[root];
    }
    return count;
}

/* ---- the monitor seen by each group's solver ---- */

typedef struct group_monitor {
    const rad_solve_params *outer;
    double *B;              /* the whole system's iterate */
    const size_t *members;  /* the group's elements, in order */
    size_t count;
    int offset;             /* steps reported by the groups before */
    double t0;
    double emitted;         /* the group's emitted power, W */
    double emitted_total;   /* the whole system's, W */
    double others_residual; /* the other groups' residual numerators, W */
    double others_unshot;   /* the other groups' unshot power, W */
} group_monitor;

static int group_step(void *user, const rad_solve_step *step, const double *B_group, const double *ambient)
{
    group_monitor *g = user;
    for (size_t k = 0; k < g->count; k++)
        memcpy(g->B + 3 * g->members[k], B_group + 3 * k, 3 * sizeof *g->B);
    rad_solve_step whole = *step;
    whole.iteration = g->offset + step->iteration;
    whole.seconds = rad_seconds() - g->t0;
    whole.residual = (g->others_residual + step->residual * g->emitted) / g->emitted_total;
    whole.unshot = (g->others_unshot + step->unshot * g->emitted) / g->emitted_total; /* NAN stays NAN */
    return g->outer->monitor(g->outer->monitor_user, &whole, g->B, ambient);
}


static double emitted_power(const rad_system *sys, size_t i)
{
    const double *E = sys->emission + 3 * i;
    return sys->area[i] * (E[0] + E[1] + E[2]);
}

/* ---- the split solve ---- */

typedef struct groups {
    size_t count;
    size_t *label;   /* n: group of each element */
    size_t *start;   /* count + 1: offsets into members */
    size_t *members; /* n: elements grouped, in order within a group */
    double *emitted; /* count: W */
    double *residual;/* count: residual numerator now, W */
} groups;

static void groups_free(groups *g)
{
    rad_free(g->label);
    rad_free(g->start);
    rad_free(g->members);
    rad_free(g->emitted);
    rad_free(g->residual);
}

/* Find the groups; returns false only when out of memory. */
static bool groups_find(rad_context *ctx, const rad_system *sys, groups *g)
{
    size_t n = sys->n;
    memset(g, 0, sizeof *g);
    size_t *parent = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *parent, "solve: components: union-find");
    size_t *size = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *size, "solve: components: union-find");
    g->label = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *g->label, "solve: components: labels");
    g->members = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *g->members, "solve: components: members");
    if (!parent || !size || !g->label || !g->members) {
        rad_free(parent);
        rad_free(size);
        return false;
    }
    g->count = label_components(sys, parent, size, g->label);
    rad_free(parent);
    rad_free(size);
    g->start = rad_alloc(ctx, RAD_MEM_SOLVER, g->count + 1, sizeof *g->start, "solve: components: offsets");
    g->emitted = rad_alloc(ctx, RAD_MEM_SOLVER, g->count, sizeof *g->emitted, "solve: components: power");
    g->residual = rad_alloc(ctx, RAD_MEM_SOLVER, g->count, sizeof *g->residual, "solve: components: residuals");
    if (!g->start || !g->emitted || !g->residual)
        return false;
    for (size_t i = 0; i < n; i++)
        g->start[g->label[i] + 1]++;
    for (size_t k = 0; k < g->count; k++)
        g->start[k + 1] += g->start[k];
    for (size_t i = 0, *fill = g->start; i < n; i++) /* counting sort, stable */
        g->members[fill[g->label[i]]++] = i;
    for (size_t k = g->count; k > 0; k--) /* the fill moved each start to the next one's */
        g->start[k] = g->start[k - 1];
    g->start[0] = 0;
    return true;
}

rad_result rad_solve_by_components(rad_context *ctx, const rad_solver *solver, const rad_system *sys,
                                   const rad_solve_params *p, double *B, rad_solve_stats *stats)
{
    size_t n = sys->n;
    if (!sys->F || n < 4)
        return solver->solve(ctx, sys, p, B, stats);
    groups g;
    if (!groups_find(ctx, sys, &g)) {
        groups_free(&g);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    size_t multi = 0, largest = 0;
    for (size_t k = 0; k < g.count; k++) {
        size_t m = g.start[k + 1] - g.start[k];
        multi += m > 1;
        largest = m > largest ? m : largest;
    }
    /* One block (the usual case), or no room for a copy of the largest
     * block beside F (splitting is an optimisation): solve as a whole. */
    double limit = sys->max_memory > 0.0 ? sys->max_memory : rad_memory_limit(ctx);
    double copy_bytes = 8.0 * (double)largest * (double)largest + 80.0 * (double)largest;
    if (multi < 2 || 8.0 * (double)n * (double)n + copy_bytes > limit) {
        groups_free(&g);
        return solver->solve(ctx, sys, p, B, stats);
    }

    double t0 = rad_seconds();
    double *F_sub = rad_alloc(ctx, RAD_MEM_SOLVER, largest * largest, sizeof *F_sub, "solve: components: block of F");
    double *vectors = rad_alloc(ctx, RAD_MEM_SOLVER, 10 * largest, sizeof *vectors, "solve: components: block vectors");
    double *row = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *row, "solve: components: row residuals");
    if (!F_sub || !vectors || !row) {
        rad_free(F_sub);
        rad_free(vectors);
        rad_free(row);
        groups_free(&g);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    double *area = vectors, *reflectance = area + largest, *emission = reflectance + 3 * largest,
           *B_sub = emission + 3 * largest;

    /* Where every group starts: its residual and emitted power. */
    rad_residual_rows(sys, B, row);
    double emitted_total = 0.0;
    for (size_t k = 0; k < g.count; k++) {
        g.emitted[k] = g.residual[k] = 0.0;
        for (size_t s = g.start[k]; s < g.start[k + 1]; s++) {
            g.emitted[k] += emitted_power(sys, g.members[s]);
            g.residual[k] += row[g.members[s]];
        }
        emitted_total += g.emitted[k];
    }

    /* Single elements in closed form; groups in the dark are exact at B = E = 0. */
    for (size_t k = 0; k < g.count; k++) {
        size_t m = g.start[k + 1] - g.start[k];
        if (m == 1) {
            size_t i = g.members[g.start[k]];
            double fii = sys->F[i * n + i];
            for (int c = 0; c < 3; c++)
                B[3 * i + c] = sys->emission[3 * i + c] / (1.0 - sys->reflectance[3 * i + c] * fii);
            g.residual[k] = 0.0;
        } else if (!(g.emitted[k] > 0.0)) {
            for (size_t s = g.start[k]; s < g.start[k + 1]; s++)
                for (int c = 0; c < 3; c++)
                    B[3 * g.members[s] + c] = sys->emission[3 * g.members[s] + c];
            g.residual[k] = 0.0;
        }
    }

    rad_result result = RAD_OK;
    int steps = 0, most_iterations = 0;
    double unshot = 0.0, ambient[3] = {0.0, 0.0, 0.0}, area_total = 0.0;
    bool any_unshot = false;
    for (size_t i = 0; i < n; i++)
        area_total += sys->area[i];
    for (size_t k = 0; k < g.count && result == RAD_OK; k++) {
        size_t m = g.start[k + 1] - g.start[k];
        const size_t *members = g.members + g.start[k];
        if (m == 1 || !(g.emitted[k] > 0.0))
            continue;
        double group_area = 0.0;
        for (size_t a = 0; a < m; a++) {
            size_t i = members[a];
            const double *Fi = sys->F + i * n;
            double *Fa = F_sub + a * m;
            for (size_t b = 0; b < m; b++)
                Fa[b] = Fi[members[b]];
            area[a] = sys->area[i];
            group_area += area[a];
            memcpy(reflectance + 3 * a, sys->reflectance + 3 * i, 3 * sizeof *reflectance);
            memcpy(emission + 3 * a, sys->emission + 3 * i, 3 * sizeof *emission);
            memcpy(B_sub + 3 * a, B + 3 * i, 3 * sizeof *B_sub);
        }
        rad_system sub = *sys;
        sub.n = m;
        sub.F = F_sub;
        sub.area = area;
        sub.reflectance = reflectance;
        sub.emission = emission;

        double others_residual = 0.0, others_unshot = 0.0;
        for (size_t o = 0; o < g.count; o++) {
            if (o == k)
                continue;
            others_residual += g.residual[o];
            others_unshot += o > k ? g.emitted[o] : 0.0; /* pending: all unshot */
        }
        others_unshot += unshot;
        group_monitor gm = {p, B, members, m, steps, t0, g.emitted[k], emitted_total, others_residual,
                            others_unshot};
        rad_solve_params sub_p = *p;
        if (p->monitor) {
            sub_p.monitor = group_step;
            sub_p.monitor_user = &gm;
        }
        rad_solve_stats sub_stats;
        memset(&sub_stats, 0, sizeof sub_stats);
        sub_stats.method = stats->method;
        sub_stats.unshot = NAN;
        sub_stats.absorbed = NAN;
        result = solver->solve(ctx, &sub, &sub_p, B_sub, &sub_stats);
        for (size_t a = 0; a < m; a++)
            memcpy(B + 3 * members[a], B_sub + 3 * a, 3 * sizeof *B);

        g.residual[k] = sub_stats.residual * g.emitted[k];
        steps += sub_stats.iterations;
        most_iterations = sub_stats.iterations > most_iterations ? sub_stats.iterations : most_iterations;
        stats->iteration_limit = fmax(stats->iteration_limit, sub_stats.iteration_limit);
        if (!stats->warning[0] && sub_stats.warning[0]) /* the first group that fell short */
            snprintf(stats->warning, sizeof stats->warning, "group %zu of %zu: %.260s", k + 1, g.count,
                     sub_stats.warning);
        if (!isnan(sub_stats.unshot)) {
            any_unshot = true;
            unshot += sub_stats.unshot * g.emitted[k];
        }
        for (int c = 0; c < 3; c++)
            ambient[c] += sub_stats.ambient[c] * group_area / area_total;
    }
    stats->components = g.count;
    stats->components_lit = 0;
    for (size_t k = 0; k < g.count; k++)
        stats->components_lit += g.start[k + 1] - g.start[k] > 1 && g.emitted[k] > 0.0;
    stats->iterations = most_iterations;
    stats->residual = rad_residual_in(sys, B, row);
    rad_free(F_sub);
    rad_free(vectors);
    rad_free(row);
    stats->converged = result == RAD_OK && stats->residual <= p->tolerance;
    if (stats->converged || result != RAD_OK)
        stats->warning[0] = '\0';
    else if (!stats->warning[0]) /* every group converged; their sum did not */
        snprintf(stats->warning, sizeof stats->warning,
                 "%s: the groups converged, but the whole system's residual is %.3g, above the tolerance %.3g",
                 solver->name, stats->residual, p->tolerance);
    memcpy(stats->ambient, ambient, sizeof ambient);
    if (any_unshot)
        stats->unshot = unshot / emitted_total;
    groups_free(&g);
    return result;
}
