/*
 * ff_montecarlo.c -- area-to-area form factors by Monte Carlo over point
 * pairs (the lecture notes' "Form Factor - Ray Tracing"; Cohen & Wallace,
 * "Radiosity and Realistic Image Synthesis" 1993, sec. 4.10), with
 * shadow-ray visibility.
 *
 *     F_ij = 1/A_i  int_{A_i} int_{A_j} cos_i cos_j V(x, y) / (pi r^2) dA_y dA_x
 *
 *          ~= 1/N  sum_k  A_j cos_i cos_j V(x_k, y_k) / (pi r_k^2)
 *
 * with x_k uniform on element i and y_k uniform on element j:
 *
 *        x_k . ------- r_k ------- . y_k        V from one shadow ray per
 *      ____|__________        _____|_____     sample, its ends lifted off the
 *     i    n_i              j      n_j          surfaces by rad_vis_epsilon
 *                                               plus the element's bend
 *
 * Each unordered pair is sampled once (F_ji = F_ij A_i / A_j, so the matrix
 * is reciprocal by construction); pairs with one element wholly behind the
 * other's plane are skipped (rad_ff_facing).  The N point pairs are
 * stratified on both ends (sqrt(N) x sqrt(N) jittered strata on each,
 * matched by a random permutation; samples beyond the largest square are
 * unstratified), and each end carries rad_element_sample's density
 * correction, so the estimate is unbiased for any flat element.  The
 * variance of the mean is estimated as (sample variance) / N.  N >= 2,
 * since a variance needs two samples.
 *
 * Near pairs.  The kernel is singular (1/r^2) where elements touch, and
 * with y uniform the estimator, though unbiased, has INFINITE variance for
 * pairs that share an edge: a sample within rho of the edge at both ends
 * has probability ~rho^3 and value ~1/rho^2.  Measured on the unit cube, the
 * adjacent-face factors then missed by up to 6 reported standard errors,
 * and on the Cornell box single F_ij reached 2.2 (exact 0.2) at N = 16, so
 * rows summed to 2.8 and the solver diverged.  So for pairs closer than
 * twice their summed radii, half the samples of y are drawn instead from
 *
 *     q(y) = 1 / (pi L r^2)  on the disk of j's plane around the foot of x
 *                            (x at height h) through j's farthest corner
 *                            (radius R);  L = ln(1 + R^2/h^2)
 *
 * (rho = h sqrt(e^(u L) - 1), phi = 2 pi v; misses of j count as 0), and
 * every sample is weighted by the balance heuristic, 1 / (p_uniform/2 +
 * q/2) in place of A_j (Veach & Guibas 1995).  Then kernel / density <=
 * 2 cos_i cos_j L: only logarithmically singular, so the variance is finite
 * and the reported error means something (cube: within 3.5 standard
 * errors over 8 seeds).  Edge pairs remain the noisiest (the Cornell box's
 * rows reach 1.5 at N = 16, 1.15 at N = 64); ff_analytic.c is exact there.
 * Samples are keyed on (seed, pair): results do not depend on the thread
 * count.  Cost: about N rays per visible pair.
 */
#include "formfactor/formfactor.h"

#include <stdlib.h>
#include <string.h>

enum { CHUNK = 256 }; /* samples per occlusion batch */

/* Per-thread buffers, allocated once per thread. */
typedef struct mc_scratch {
    double kernel[CHUNK];     /* per sample of the chunk: the estimate of F_ij it gives */
    uint32_t sample[CHUNK];   /* per ray: the sample it tests */
    rad_ray rays[CHUNK];
    uint8_t blocked[CHUNK];
    int count, rays_count;    /* samples and rays in the chunk */
    double mean, m2;          /* Welford: running mean and sum of squared deviations */
    int seen;                 /* samples folded in */
    uint32_t perm[];          /* N: stratum on j of each stratum on i */
} mc_scratch;

/* Cast the chunk's shadow rays, zero what they find blocked, and fold the
 * chunk's samples into the running mean and variance. */
static void flush_chunk(const rad_ff_request *req, mc_scratch *s, uint64_t *rays_cast)
{
    if (s->rays_count) {
        req->vis->backend->occluded(req->vis->state, s->rays, (size_t)s->rays_count, s->blocked);
        *rays_cast += (uint64_t)s->rays_count;
        for (int r = 0; r < s->rays_count; r++)
            if (s->blocked[r])
                s->kernel[s->sample[r]] = 0.0;
    }
    for (int k = 0; k < s->count; k++) {
        double delta = s->kernel[k] - s->mean;
        s->mean += delta / ++s->seen;
        s->m2 += delta * (s->kernel[k] - s->mean);
    }
    s->count = s->rays_count = 0;
}

/* Element j as the near-pair sampler sees it: flat, its corners projected
 * onto the plane through its centroid, split into the fan (0,1,2), (0,2,3). */
typedef struct mc_target {
    vec3 corner[4];
    uint32_t corners;
    vec3 normal, e1, e2; /* unit normal and an orthonormal tangent pair */
    vec3 centroid;
    double area1, area;  /* first fan triangle, whole polygon, m^2 */
} mc_target;

static void target_init(const rad_mesh *mesh, const rad_element *e, mc_target *t)
{
    t->corners = e->vertex_count;
    t->normal = e->normal;
    t->centroid = e->centroid;
    for (uint32_t k = 0; k < e->vertex_count; k++) {
        vec3 p = mesh->vertices[e->vertex[k]];
        t->corner[k] = v3_mad(p, e->normal, -v3_dot(e->normal, v3_sub(p, e->centroid)));
    }
    vec3 a = fabs(e->normal.x) < 0.6 ? v3(1, 0, 0) : v3(0, 1, 0);
    t->e1 = v3_normalize(v3_sub(a, v3_scale(e->normal, v3_dot(a, e->normal))));
    t->e2 = v3_cross(e->normal, t->e1);
    t->area1 = 0.5 * v3_length(v3_cross(v3_sub(t->corner[1], t->corner[0]), v3_sub(t->corner[2], t->corner[0])));
    t->area = t->area1;
    if (t->corners == 4)
        t->area += 0.5 * v3_length(v3_cross(v3_sub(t->corner[2], t->corner[0]), v3_sub(t->corner[3], t->corner[0])));
}

/* A point uniform in area on the target, from (u, v) in [0,1)^2. */
static vec3 target_uniform(const mc_target *t, double u, double v)
{
    vec3 a = t->corner[0], b = t->corner[1], c = t->corner[2];
    double split = t->area1 / t->area;
    if (t->corners == 4 && u >= split) {
        u = (u - split) / (1.0 - split);
        b = t->corner[2];
        c = t->corner[3];
    } else if (t->corners == 4) {
        u /= split;
    }
    if (u + v > 1.0) {
        u = 1.0 - u;
        v = 1.0 - v;
    }
    return v3_add(a, v3_add(v3_scale(v3_sub(b, a), u), v3_scale(v3_sub(c, a), v)));
}

/* Is y (on the target's plane) inside it?  Corners are counter-clockwise
 * about the normal, and the polygon is convex. */
static bool target_contains(const mc_target *t, vec3 y)
{
    for (uint32_t k = 0; k < t->corners; k++) {
        vec3 a = t->corner[k], b = t->corner[(k + 1) % t->corners];
        if (v3_dot(t->normal, v3_cross(v3_sub(b, a), v3_sub(y, a))) < 0.0)
            return false;
    }
    return true;
}

/* Stratified numbers for sample k of m: (u1, v1) on i in stratum k and
 * (u2, v2) on j in stratum perm[k] of a side x side grid; samples past the
 * grid are unstratified. */
static void stratified(rad_rng *rng, const uint32_t *perm, int side, int k, double *u1, double *v1,
                       double *u2, double *v2)
{
    if (k < side * side) {
        int o = (int)perm[k];
        *u1 = ((k % side) + rad_rng_uniform(rng)) / side;
        *v1 = ((k / side) + rad_rng_uniform(rng)) / side;
        *u2 = ((o % side) + rad_rng_uniform(rng)) / side;
        *v2 = ((o / side) + rad_rng_uniform(rng)) / side;
    } else {
        *u1 = rad_rng_uniform(rng);
        *v1 = rad_rng_uniform(rng);
        *u2 = rad_rng_uniform(rng);
        *v2 = rad_rng_uniform(rng);
    }
}

/* A random permutation of the side x side strata; returns side. */
static int shuffle_strata(rad_rng *rng, uint32_t *perm, int m)
{
    int side = (int)floor(sqrt((double)m));
    while ((side + 1) * (side + 1) <= m) /* sqrt rounding */
        side++;
    int strata = side * side;
    for (int k = 0; k < strata; k++)
        perm[k] = (uint32_t)k;
    for (int k = strata - 1; k > 0; k--) { /* Fisher-Yates */
        int r = (int)(rad_rng_uniform(rng) * (k + 1));
        uint32_t t = perm[k];
        perm[k] = perm[r];
        perm[r] = t;
    }
    return side;
}

/* One pair: F_ij and the variance of its estimate.  `near`: half the
 * samples of y are drawn by the polar technique (file header), each
 * technique stratified on its own. */
static void estimate(const rad_ff_request *req, mc_scratch *s, uint32_t i, uint32_t j, int N, bool near,
                     double eps, double *F_ij, double *var_ij, uint64_t *rays_cast)
{
    const rad_mesh *mesh = req->mesh;
    const rad_element *ei = &mesh->elements[i], *ej = &mesh->elements[j];
    rad_rng rng = rad_rng_keyed(req->seed, i, j);
    mc_target tj;
    if (near)
        target_init(mesh, ej, &tj);
    int count_uniform = near ? (N + 1) / 2 : N, count_polar = N - count_uniform;
    double c_uniform = (double)count_uniform / N, c_polar = (double)count_polar / N;
    double lift_i = eps + rad_element_bend(mesh, ei), lift_j = eps + rad_element_bend(mesh, ej);
    s->count = s->rays_count = s->seen = 0;
    s->mean = s->m2 = 0.0;
    for (int pass = 0; pass < 2; pass++) {
        bool polar = pass == 1;
        int m = polar ? count_polar : count_uniform;
        if (m == 0)
            continue;
        int side = shuffle_strata(&rng, s->perm, m);
        for (int k = 0; k < m; k++) {
            double u1, v1, u2, v2;
            stratified(&rng, s->perm, side, k, &u1, &v1, &u2, &v2);
            if (s->count == CHUNK)
                flush_chunk(req, s, rays_cast);
            double *kernel = &s->kernel[s->count++];
            *kernel = 0.0;
            vec3 x = rad_element_sample(mesh, ei, u1, v1), y;
            double per_area; /* 1 / (density of y on j), m^2 */
            if (!near) {
                y = rad_element_sample(mesh, ej, u2, v2);
                per_area = ej->area * rad_element_sample_weight(mesh, ej, u2, v2);
            } else {
                double h = v3_dot(tj.normal, v3_sub(x, tj.centroid)); /* height of x over j */
                if (!(h > 0.0))
                    continue; /* behind j: cos_j <= 0 */
                vec3 foot = v3_mad(x, tj.normal, -h);
                double reach2 = 0.0;
                for (uint32_t c = 0; c < tj.corners; c++) {
                    vec3 d = v3_sub(tj.corner[c], foot);
                    reach2 = fmax(reach2, v3_dot(d, d));
                }
                double L = log1p(reach2 / (h * h));
                if (!polar) {
                    y = target_uniform(&tj, u2, v2);
                } else {
                    double rho = h * sqrt(expm1(u2 * L)), phi = 2.0 * M_PI * v2;
                    y = v3_add(foot, v3_add(v3_scale(tj.e1, rho * cos(phi)), v3_scale(tj.e2, rho * sin(phi))));
                    if (!target_contains(&tj, y))
                        continue; /* a miss: this sample estimates 0 */
                }
                vec3 d = v3_sub(y, x);
                double q = 1.0 / (M_PI * L * v3_dot(d, d)); /* polar density: h^2 + rho^2 = r^2 */
                per_area = 1.0 / (c_uniform / tj.area + c_polar * q);
            }
            vec3 d = v3_sub(y, x);
            double r2 = v3_dot(d, d), ci = v3_dot(ei->normal, d), cj = -v3_dot(ej->normal, d);
            if (!(ci > 0.0 && cj > 0.0 && r2 > 0.0))
                continue;
            *kernel = ci * cj / (M_PI * r2 * r2) * per_area * rad_element_sample_weight(mesh, ei, u1, v1);
            if (req->vis) {
                vec3 a = v3_mad(x, ei->normal, lift_i), b = v3_mad(y, ej->normal, lift_j);
                rad_ray *ray = &s->rays[s->rays_count];
                ray->origin = a;
                ray->direction = v3_sub(b, a);
                ray->tnear = 0.0;
                ray->tfar = 1.0;
                s->sample[s->rays_count++] = (uint32_t)(s->count - 1);
            }
        }
    }
    flush_chunk(req, s, rays_cast);
    *F_ij = s->mean;
    *var_ij = s->m2 / ((double)(N - 1) * N);
}

/* What every pair reads. */
typedef struct mc_shared {
    int N;              /* point pairs per element pair */
    double eps;         /* m: the ray-end lift, rad_vis_epsilon (0 without visibility) */
    double radius[];    /* per element: largest centroid-to-corner distance, m */
} mc_shared;

static rad_result montecarlo_prepare(rad_context *ctx, const rad_ff_request *req, void **shared)
{
    const rad_mesh *mesh = req->mesh;
    size_t n = mesh->element_count;
    mc_shared *m = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, 1, sizeof *m + n * sizeof m->radius[0], "form factors: element table");
    if (!m)
        return RAD_ERROR_OUT_OF_MEMORY;
    m->N = req->samples > 0 ? req->samples : 16;
    if (m->N < 2)
        m->N = 2;
    m->eps = req->vis ? rad_vis_epsilon(mesh) : 0.0;
    for (size_t i = 0; i < n; i++) {
        const rad_element *e = &mesh->elements[i];
        m->radius[i] = 0.0;
        for (uint32_t k = 0; k < e->vertex_count; k++)
            m->radius[i] = fmax(m->radius[i], v3_length(v3_sub(mesh->vertices[e->vertex[k]], e->centroid)));
    }
    *shared = m;
    return RAD_OK;
}

static size_t montecarlo_scratch(const rad_ff_request *req, const void *shared, void *block)
{
    (void)req, (void)block; /* nothing to lay out: the strata are the struct's last member */
    const mc_shared *m = shared;
    return sizeof(mc_scratch) + (size_t)m->N * sizeof(uint32_t);
}

/* F_ji = F_ij A_i / A_j: one estimate per pair, reciprocal by construction. */
static void montecarlo_pair(const rad_ff_request *req, const void *shared, void *scratch, uint32_t i,
                            uint32_t j, rad_ff_pair *out, rad_ff_tally *tally)
{
    const mc_shared *m = shared;
    const rad_element *ei = &req->mesh->elements[i], *ej = &req->mesh->elements[j];
    /* Near: closer than twice their summed radii, where the kernel's 1/r^2
     * makes uniform sampling's variance explode. */
    double reach = 2.0 * (m->radius[i] + m->radius[j]);
    vec3 gap = v3_sub(ej->centroid, ei->centroid);
    bool near = v3_dot(gap, gap) < reach * reach;
    double f, var;
    estimate(req, scratch, i, j, m->N, near, m->eps, &f, &var, &tally->rays);
    double ratio = ei->area / ej->area;
    out->F_ij = f;
    out->F_ji = f * ratio;
    out->var_ij = var;
    out->var_ji = var * ratio * ratio;
}

const rad_ff_method rad_ff_montecarlo = {
    "montecarlo",
    "area-to-area Monte Carlo: stratified point pairs (default 16 per pair), one shadow ray "
    "each, 1/r^2 sampling mixed in where elements touch; unbiased, variance reported; O(n^2 N)",
    RAD_FF_VARIANCE,
    montecarlo_prepare,
    montecarlo_scratch,
    montecarlo_pair,
    NULL,
};
