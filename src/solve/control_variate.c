/*
 * control_variate.c -- the constant control variate of the Monte Carlo
 * solvers (control_variate.h): B = beta + B', only B' estimated by rays.
 *
 * Why it works.  In B = E + rho F B, write B = beta + B' with beta a
 * function whose transport T = F beta is known; then
 *
 *     B' = E' + rho F B',    E'_i = E_i + rho_i T_i - beta_i,
 *
 * the same system with a residual source (Bekaert 1999, the stochastic
 * Jacobi chapter's control variates; Neumann et al. 1995).  A shooter or a
 * light tracer then carries the power of B' instead of B, and its noise
 * scales with that power: in the closed furnace (E, rho uniform) beta =
 * E / (1 - rho) leaves E' = 0, so nothing is shot and B = beta on every
 * element to rounding.  E' may be negative: the solvers are linear, so a
 * shooter shoots negative power and a light path carries signed power.
 *
 * The groups.  beta is one constant per group of elements light can join
 * (GROUP_RAYS cosine rays from every element, union-find over what they
 * reach), per channel: a sealed room is its own group, and a room with no
 * emitter gets beta = 0, so its E' = 0 and it stays exactly dark
 * (test_hostile's sealed partition).  The groups only choose beta: a
 * coupling these few rays miss costs variance, not bias, as T is
 * estimated by other rays.
 *
 * The choice of beta.  A shooting step's variance grows with the absolute
 * power it shoots, so beta is the value that makes the residual source
 * smallest in absolute power, taking the group as closed (T = beta):
 *
 *     beta = argmin sum_i A_i |E_i - (1 - rho_i) beta|
 *          = the weighted median of E_i / (1 - rho_i), weights A_i (1 - rho_i)
 *
 * (the first step of Bekaert's choice, which minimises the absolute power
 * of B - beta as the iteration goes on; here fixed before any ray, from
 * E, rho and A, so beta does not depend on the rays that estimate T).  In
 * the furnace it is E / (1 - rho) exactly.  Where the emitters hold less
 * than half the weight, as in a room lit by lamps (the Cornell box: its
 * light is 1% of the weight), it is 0 and the solvers run as without it:
 * a uniform beta there (the mean <E> / (1 - <rho>)) shoots a negative
 * source from every wall on top of the lamp's positive one, for no gain
 * in the noise of the direct light (docs/methods.md has the figures).
 *
 * The transport without bias.  T_i = sum_j F_ij beta_j is the mean of
 * beta over where cosine rays from element i arrive (0 where they escape
 * or meet a back side): transport_rays such rays, independent of those
 * that made the groups, estimate it without bias.  In a closed group
 * every ray arrives in it, so T_i = beta exactly with any number of rays;
 * in an open one the estimate's noise, rho_i beta sqrt(c (1 - c) / rays)
 * for a closure c, enters E', and E' then varies from element to element
 * of a patch.  That did not pay: in the furnace box without its top (600
 * elements, 256 rays) shooting's per-surface rms rose from 5.8e-4 to
 * 9.1e-4, and instant radiosity's direct gather of a varying source,
 * whose point-to-point kernel is unbounded near a patch's edges, put an
 * element at B = -1.6 where B ~ 2.  So a group that some grouping ray
 * leaves (escaping, or onto a back side) keeps beta = 0: the control
 * variate serves closed groups, where T = beta.  The choice rests on the
 * grouping rays only, so T, from other rays, stays unbiased where a leak
 * is too small for them to find.  Cost: GROUP_RAYS rays per element
 * always (with an emitter), transport_rays more per element where some
 * beta is not 0.
 */
#include "solve/control_variate.h"
#include "solve/solve.h"
#include "formfactor/formfactor.h"

#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

enum {
    GROUP_RAYS = 16,   /* rays per element for the groups: 4 x 4 strata of the disk */
    RAY_BLOCK = 64,    /* rays per backend call */
    CHUNK = 4096       /* elements whose grouping hits are held at once */
};

/* Rays first .. first + count - 1 (count <= RAY_BLOCK) of a stratified
 * cosine bundle from element e: the element each reaches on its front
 * side into out[], UINT32_MAX where it escapes or meets a back side. */
static void bundle_hits(const rad_mesh *mesh, const rad_vis *vis, const rad_element *e, double lift, int side,
                        int first, int count, rad_rng *rng, rad_ray *rays, rad_hit *hits, uint32_t *out)
{
    rad_element_cosine_rays(mesh, e, lift, side, first, count, rng, rays);
    vis->backend->intersect(vis->state, rays, (size_t)count, hits);
    for (int k = 0; k < count; k++)
        out[k] = rad_vis_front_element(mesh, &rays[k], &hits[k]);
}

static int side_of(int rays)
{
    int side = (int)sqrt((double)rays);
    return side < 1 ? 1 : side;
}

typedef struct weighted {
    double value, weight;
} weighted;

static int weighted_order(const void *a, const void *b)
{
    double x = ((const weighted *)a)->value, y = ((const weighted *)b)->value;
    return (x > y) - (x < y);
}

/* The lower weighted median of v[0 .. count-1] (sorted here); 0 when the
 * weights sum to 0.  Cannot fail. */
static double weighted_median(weighted *v, size_t count)
{
    double total = 0.0;
    for (size_t k = 0; k < count; k++)
        total += v[k].weight;
    if (!(total > 0.0))
        return 0.0;
    qsort(v, count, sizeof *v, weighted_order);
    double sum = 0.0;
    for (size_t k = 0; k < count; k++) {
        sum += v[k].weight;
        if (sum >= 0.5 * total)
            return v[k].value;
    }
    return v[count - 1].value;
}

void rad_control_variate_free(rad_control_variate *cv)
{
    rad_free(cv->beta);
    rad_free(cv->source);
    rad_free(cv->transport);
    memset(cv, 0, sizeof *cv);
}

rad_result rad_control_variate_make(rad_context *ctx, const rad_mesh *mesh, const rad_vis *vis, const double *area,
                                    const double *reflectance, const double *emission, uint64_t seed,
                                    int transport_rays, int threads, rad_control_variate *out)
{
    memset(out, 0, sizeof *out);
    size_t n = mesh->element_count;
    if (threads < 1)
        threads = 1;
    if (transport_rays < 1)
        transport_rays = 1;
    rad_control_variate cv = {0};
    cv.beta = rad_alloc(ctx, RAD_MEM_SOLVER, n + 1, 3 * sizeof *cv.beta, "control variate: beta");
    cv.source = rad_alloc(ctx, RAD_MEM_SOLVER, n + 1, 3 * sizeof *cv.source, "control variate: source");
    cv.transport = rad_alloc(ctx, RAD_MEM_SOLVER, n + 1, 3 * sizeof *cv.transport, "control variate: transport");
    if (!cv.beta || !cv.source || !cv.transport) {
        rad_control_variate_free(&cv);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memset(cv.beta, 0, 3 * n * sizeof *cv.beta);
    memset(cv.transport, 0, 3 * n * sizeof *cv.transport);
    memcpy(cv.source, emission, 3 * n * sizeof *cv.source);
    bool lit = false;
    for (size_t k = 0; k < 3 * n && !lit; k++)
        lit = emission[k] > 0.0;
    if (!lit) {
        *out = cv; /* nothing emits: beta = 0 everywhere, nothing to cast */
        return RAD_OK;
    }

    size_t *parent = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *parent, "control variate: groups");
    size_t *size = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *size, "control variate: groups");
    size_t *label = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *label, "control variate: groups");
    size_t *first = rad_alloc(ctx, RAD_MEM_SOLVER, n + 1, sizeof *first, "control variate: groups");
    size_t *order = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *order, "control variate: groups");
    weighted *values = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *values, "control variate: groups");
    bool *leaky = rad_alloc(ctx, RAD_MEM_SOLVER, n + 1, sizeof *leaky, "control variate: groups");
    uint32_t *held = rad_alloc(ctx, RAD_MEM_SOLVER, (size_t)CHUNK * GROUP_RAYS, sizeof *held,
                               "control variate: grouping hits");
    rad_ray *rays = rad_alloc(ctx, RAD_MEM_SOLVER, (size_t)threads * RAY_BLOCK, sizeof *rays, "control variate: rays");
    rad_hit *hits = rad_alloc(ctx, RAD_MEM_SOLVER, (size_t)threads * RAY_BLOCK, sizeof *hits, "control variate: rays");
    uint32_t *reached = rad_alloc(ctx, RAD_MEM_SOLVER, (size_t)threads * RAY_BLOCK, sizeof *reached,
                                  "control variate: rays");
    rad_result result = RAD_OK;
    if (!parent || !size || !label || !first || !order || !values || !leaky || !held || !rays || !hits || !reached) {
        result = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    double eps = rad_vis_epsilon(mesh);

    /* 1. The groups: GROUP_RAYS rays a element, cast in parallel a chunk
     * at a time and joined in element order (deterministic). */
    for (size_t i = 0; i < n; i++) {
        parent[i] = i;
        size[i] = 1;
    }
    for (size_t start = 0; start < n && result == RAD_OK; start += CHUNK) {
        size_t end = n - start < CHUNK ? n : start + CHUNK;
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads)
        for (size_t i = start; i < end; i++) {
            int tid = 0;
#ifdef _OPENMP
            tid = omp_get_thread_num();
#endif
            const rad_element *e = &mesh->elements[i];
            rad_rng rng = rad_rng_keyed(seed, 0x43565f47u, i); /* "CV_G" */
            bundle_hits(mesh, vis, e, eps + rad_element_bend(mesh, e), side_of(GROUP_RAYS), 0, GROUP_RAYS, &rng,
                        rays + (size_t)tid * RAY_BLOCK, hits + (size_t)tid * RAY_BLOCK,
                        held + (i - start) * GROUP_RAYS);
        }
        for (size_t i = start; i < end; i++) {
            leaky[i] = false;
            for (int k = 0; k < GROUP_RAYS; k++)
                if (held[(i - start) * GROUP_RAYS + k] != UINT32_MAX)
                    rad_union_find_join(parent, size, i, held[(i - start) * GROUP_RAYS + k]);
                else
                    leaky[i] = true;
        }
        cv.rays += (uint64_t)(end - start) * GROUP_RAYS;
        if (rad_cancelled(ctx))
            result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: interrupted finding the control variate's groups");
    }
    if (result != RAD_OK)
        goto done;

    /* Groups numbered in order of their first element, members listed by
     * group (a counting sort). */
    size_t groups = 0;
    for (size_t i = 0; i < n; i++)
        size[i] = SIZE_MAX; /* reused: root -> group number */
    for (size_t i = 0; i < n; i++) {
        size_t r = rad_union_find_root(parent, i);
        if (size[r] == SIZE_MAX)
            size[r] = groups++;
        label[i] = size[r];
    }
    memset(first, 0, (groups + 1) * sizeof *first);
    for (size_t i = 0; i < n; i++)
        first[label[i] + 1]++;
    for (size_t g = 0; g < groups; g++)
        first[g + 1] += first[g];
    for (size_t i = 0; i < n; i++)
        order[first[label[i]]++] = i;
    for (size_t g = groups; g > 0; g--)
        first[g] = first[g - 1];
    first[0] = 0;
    cv.groups = groups;

    /* 2. beta per group and channel: the weighted median (file header). */
    for (size_t g = 0; g < groups; g++) {
        bool varied = false, open = false;
        for (size_t k = first[g]; k < first[g + 1]; k++)
            open |= leaky[order[k]];
        if (open)
            continue; /* beta = 0 (file header) */
        for (int c = 0; c < 3; c++) {
            size_t count = 0;
            for (size_t k = first[g]; k < first[g + 1]; k++) {
                size_t i = order[k];
                double rho = reflectance[3 * i + c], E = emission[3 * i + c];
                if (!(rho < 1.0) || !(area[i] > 0.0))
                    continue; /* a perfect reflector: no weight, any beta balances it */
                values[count++] = (weighted){E / (1.0 - rho), area[i] * (1.0 - rho)};
            }
            double beta = weighted_median(values, count);
            if (!(beta > 0.0) || !isfinite(beta))
                beta = 0.0;
            for (size_t k = first[g]; k < first[g + 1]; k++)
                cv.beta[3 * order[k] + c] = beta;
            varied |= beta > 0.0;
        }
        cv.groups_varied += varied;
    }
    cv.active = cv.groups_varied > 0;
    if (!cv.active)
        goto done;

    /* 3. T_i from transport_rays fresh rays per element: beta of the group
     * each arrives in, counted per group so that a closed group's T is beta
     * to the last bit. */
    int side = side_of(transport_rays);
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads)
    for (size_t i = 0; i < n; i++) {
        int tid = 0;
#ifdef _OPENMP
        tid = omp_get_thread_num();
#endif
        if (rad_cancelled(ctx))
            continue;
        const rad_element *e = &mesh->elements[i];
        double lift = eps + rad_element_bend(mesh, e);
        rad_rng rng = rad_rng_keyed(seed, 0x43565f54u, i); /* "CV_T" */
        uint32_t *to = reached + (size_t)tid * RAY_BLOCK;
        double own = 0.0, other[3] = {0, 0, 0};
        for (int f = 0; f < transport_rays; f += RAY_BLOCK) {
            int count = transport_rays - f < RAY_BLOCK ? transport_rays - f : RAY_BLOCK;
            bundle_hits(mesh, vis, e, lift, side, f, count, &rng, rays + (size_t)tid * RAY_BLOCK,
                        hits + (size_t)tid * RAY_BLOCK, to);
            for (int k = 0; k < count; k++) {
                if (to[k] == UINT32_MAX)
                    continue;
                if (label[to[k]] == label[i])
                    own += 1.0;
                else
                    for (int c = 0; c < 3; c++)
                        other[c] += cv.beta[3 * (size_t)to[k] + c];
            }
        }
        for (int c = 0; c < 3; c++) {
            double beta = cv.beta[3 * i + c], rho = reflectance[3 * i + c], E = emission[3 * i + c];
            double T = (beta * own + other[c]) / transport_rays;
            double residual = E + rho * T - beta;
            /* E + rho beta - beta rounds to a few ulp of beta where the
             * group is closed and uniform (the furnace): below 1e-12 of the
             * terms it is that rounding, not light to shoot. */
            if (fabs(residual) <= 1e-12 * (fabs(E) + rho * fabs(T) + fabs(beta)))
                residual = 0.0;
            cv.transport[3 * i + c] = T;
            cv.source[3 * i + c] = residual;
        }
    }
    cv.rays += (uint64_t)n * (uint64_t)transport_rays;
    if (rad_cancelled(ctx)) {
        result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: interrupted estimating the control variate");
        goto done;
    }
    double total = 0.0;
    for (size_t i = 0; i < n; i++) {
        total += area[i];
        for (int c = 0; c < 3; c++)
            cv.beta_mean[c] += area[i] * cv.beta[3 * i + c];
    }
    for (int c = 0; c < 3; c++)
        cv.beta_mean[c] = total > 0.0 ? cv.beta_mean[c] / total : 0.0;

done:
    rad_free(parent);
    rad_free(size);
    rad_free(label);
    rad_free(first);
    rad_free(order);
    rad_free(values);
    rad_free(leaky);
    rad_free(held);
    rad_free(rays);
    rad_free(hits);
    rad_free(reached);
    if (result != RAD_OK) {
        rad_control_variate_free(&cv);
        return result;
    }
    *out = cv;
    return RAD_OK;
}
