/*
 * ff_hemisphere.c -- form factors by rays shot over the hemisphere of each
 * element (the lecture notes' "Form Factor - Hemisphere"): a Monte Carlo
 * estimate of the element-to-environment factors, one row at a time.
 *
 *     F_ij = 1/A_i  int_{A_i} int_{H(x)} cos(theta)/pi [ray(x, w) first hits
 *                                                        the front of j] dw dA
 *
 * Origins x are uniform over the element and directions w are drawn with
 * density cos(theta)/pi, so every ray weighs 1/N (times the origin's
 * density correction, rad_element_sample_weight: 1 on parallelograms) and
 * F_ij is the fraction of the N rays that first hit j: a multinomial count,
 * whose variance is
 *
 *     var F_ij ~= F_ij (1 - F_ij) / N
 *
 * (reported; stratification makes the true variance smaller: on the test
 * cases the error is at most 1 reported standard error).  Small targets
 * need many rays: the Cornell box's light gets ~0.5% of each floor
 * element's rays, so at 8192 rays per element the floor's irradiance has a
 * 1.2% standard error.
 *
 *          n                 Malley's method (Malley 1988; Pharr, Jakob &
 *          ^   . hit j       Humphreys, PBR 3rd ed. 13.6.3): a uniform point
 *          |  /              on the unit disk, lifted to the hemisphere, is
 *      ____|_/____           cosine distributed.  The disk point comes from a
 *        / x  \   disk       stratified (u, v) by the concentric map (Shirley
 *       '------'             & Chiu 1997), which keeps the strata compact.
 *
 * sqrt(N) x sqrt(N) jittered strata in direction, and as many over the
 * element for the origins, paired by a random permutation; rays beyond the
 * largest square (when N is not one) are unstratified.  Origins are lifted
 * off the surface by rad_vis_epsilon (plus the element's bend); the closest
 * hit's patch and patch parameters locate the element in O(1); a hit on a
 * patch's back (one-sided surfaces) or into the void counts for nothing.
 * Rays are keyed on (seed, element): results do not depend on the thread
 * count.  Cost: N n rays.  Reciprocity holds only statistically in the
 * raw counts: by default rad_ff_balance (reciprocity.c) combines the two
 * counts of each pair, weighted by rays per m^2, and holds each row to the
 * fraction of its element's rays that met a front.
 */
#include "formfactor/formfactor.h"

#include <stdlib.h>
#include <string.h>

enum { BATCH = 64 }; /* rays per intersect call */

/* What every row reads. */
typedef struct hs_shared {
    int N;            /* rays per element */
    double eps;       /* m: the ray-origin lift, rad_vis_epsilon */
} hs_shared;

/* Per-thread buffers, allocated once per thread. */
typedef struct hs_scratch {
    int *perm;        /* origin stratum of each direction stratum */
    double *sum;      /* n accumulators for the current row */
    rad_ray rays[BATCH];
    rad_hit hits[BATCH];
    double weight[BATCH]; /* each ray's weight: 1/N times the origin density correction */
} hs_scratch;

/* Shirley & Chiu's concentric map of [0,1)^2 onto the unit disk. */
static void concentric_disk(double u, double v, double *x, double *y)
{
    double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0;
    if (a == 0.0 && b == 0.0) {
        *x = *y = 0.0;
        return;
    }
    double r, phi;
    if (fabs(a) > fabs(b)) {
        r = a;
        phi = (M_PI / 4.0) * (b / a);
    } else {
        r = b;
        phi = (M_PI / 2.0) - (M_PI / 4.0) * (a / b);
    }
    *x = r * cos(phi);
    *y = r * sin(phi);
}

/* Cast one batch and add each hit's weight to the element it lands on. */
static void trace_batch(const rad_ff_request *req, hs_scratch *s, size_t count, size_t i)
{
    const rad_mesh *mesh = req->mesh;
    req->vis->backend->intersect(req->vis->state, s->rays, count, s->hits);
    for (size_t k = 0; k < count; k++) {
        if (!isfinite(s->hits[k].t))
            continue; /* into the void */
        const rad_patch *patch = &mesh->patches[s->hits[k].patch];
        if (v3_dot(s->rays[k].direction, patch->normal) > 0.0)
            continue; /* the back of a one-sided surface */
        vec3 h = v3_mad(s->rays[k].origin, s->rays[k].direction, s->hits[k].t);
        double ps, pt, ls, lt;
        rad_patch_parameters(patch, h, &ps, &pt);
        uint32_t j = rad_patch_locate(patch, ps, pt, &ls, &lt);
        if (j != i)
            s->sum[j] += s->weight[k];
    }
}

/* Row i of F (and of the variance); counts its rays and the elements it
 * hit. */
static void hemisphere_row(const rad_ff_request *req, const void *shared, void *scratch, uint32_t i,
                           double *F_row, double *variance_row, rad_ff_tally *tally)
{
    const hs_shared *h = shared;
    hs_scratch *s = scratch;
    int N = h->N;
    double eps = h->eps;
    const rad_mesh *mesh = req->mesh;
    size_t n = mesh->element_count;
    const rad_element *e = &mesh->elements[i];
    int side = (int)floor(sqrt((double)N));
    while ((side + 1) * (side + 1) <= N) /* sqrt rounding */
        side++;
    int strata = side * side;
    rad_rng rng = rad_rng_keyed(req->seed, i, 0x68656d69ULL /* "hemi" */);
    rad_rng_shuffle(&rng, s->perm, strata);
    memset(s->sum, 0, n * sizeof *s->sum);
    vec3 nz = e->normal, ux, uy;
    rad_tangent_frame(nz, &ux, &uy);
    double lift = eps + rad_element_bend(mesh, e);
    size_t batch = 0;
    for (int k = 0; k < N; k++) {
        double du, dv, ou, ov;
        if (k < strata) {
            int o = s->perm[k];
            du = ((k % side) + rad_rng_uniform(&rng)) / side;
            dv = ((k / side) + rad_rng_uniform(&rng)) / side;
            ou = ((o % side) + rad_rng_uniform(&rng)) / side;
            ov = ((o / side) + rad_rng_uniform(&rng)) / side;
        } else {
            du = rad_rng_uniform(&rng);
            dv = rad_rng_uniform(&rng);
            ou = rad_rng_uniform(&rng);
            ov = rad_rng_uniform(&rng);
        }
        double x, y;
        concentric_disk(du, dv, &x, &y);
        double z = sqrt(fmax(0.0, 1.0 - x * x - y * y));
        rad_ray *ray = &s->rays[batch];
        ray->origin = v3_mad(rad_element_sample(mesh, e, ou, ov), nz, lift);
        ray->direction = v3_add(v3_add(v3_scale(ux, x), v3_scale(uy, y)), v3_scale(nz, z));
        ray->tnear = 0.0;
        ray->tfar = INFINITY;
        s->weight[batch] = rad_element_sample_weight(mesh, e, ou, ov) / N;
        if (++batch == BATCH) {
            trace_batch(req, s, batch, i);
            batch = 0;
        }
    }
    if (batch)
        trace_batch(req, s, batch, i);
    for (size_t j = 0; j < n; j++) {
        double f = s->sum[j];
        tally->pairs += f > 0.0;
        F_row[j] = f;
        if (variance_row) {
            double p = fmin(fmax(f, 0.0), 1.0);
            variance_row[j] = p * (1.0 - p) / N;
        }
    }
    tally->rays += (uint64_t)N;
}

static rad_result hemisphere_prepare(rad_context *ctx, const rad_ff_request *req, void **shared)
{
    if (!req->vis)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "hemisphere form factors need a ray backend (visibility)");
    hs_shared *h = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, 1, sizeof *h, "form factors: settings");
    if (!h)
        return RAD_ERROR_OUT_OF_MEMORY;
    h->N = req->samples > 0 ? req->samples : 1024;
    h->eps = rad_vis_epsilon(req->mesh);
    *shared = h;
    return RAD_OK;
}

/* One block: the struct, then the n accumulators, then the N strata. */
static size_t hemisphere_scratch(const rad_ff_request *req, const void *shared, void *block)
{
    const hs_shared *h = shared;
    size_t n = req->mesh->element_count;
    hs_scratch *s = block;
    if (s) {
        s->sum = (double *)(s + 1);
        s->perm = (int *)(s->sum + n);
    }
    return sizeof *s + n * sizeof *s->sum + (size_t)h->N * sizeof *s->perm;
}

/* N rays from each element: N / A_i per m^2 (rad_ff_balance's weight). */
static double hemisphere_density(const rad_ff_request *req, const void *shared, uint32_t i)
{
    const hs_shared *h = shared;
    return h->N / req->mesh->elements[i].area;
}

const rad_ff_method rad_ff_hemisphere = {
    "hemisphere",
    "cosine-distributed rays from stratified points of each element (Malley's method), "
    "closest hit; unbiased, std error sqrt(F(1-F)/N) per factor, N n rays",
    RAD_FF_VARIANCE | RAD_FF_BALANCE,
    hemisphere_prepare,
    hemisphere_scratch,
    NULL,
    hemisphere_row,
    hemisphere_density,
};
