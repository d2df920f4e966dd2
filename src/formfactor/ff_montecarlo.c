/*
 * ff_montecarlo.c -- area-to-area form factors by Monte Carlo over the
 * points of one element, with shadow rays for visibility (Cohen & Wallace,
 * "Radiosity and Realistic Image Synthesis" 1993, sec. 4.9-4.10: point
 * sampling of the outer integral; Nusselt / Lambert for the inner one).
 *
 *     F_sj = 1/A_s  int_{A_s} F(x) dA,   F(x) = 1/pi int_{Omega(x)} cos_x V(x, w) dw
 *
 * Near pairs (nearness (r_s + r_j) / d >= NEAR: summed centroid-to-corner
 * radii over the centroid distance).  Per sample x_k, uniform on element s
 * (with rad_element_sample's density correction):
 *
 *     f_k = P(x_k) V(x_k, w_k)
 *
 * with P(x) the unoccluded point-to-polygon factor of j's polygon clipped
 * to x's tangent half-space (Lambert's contour formula; Baum, Rushmeier &
 * Winget 1989) and w_k drawn with density cos_x / (pi P(x_k)) over that
 * polygon: uniform in solid angle (a fan triangle by its solid angle, then
 * Arvo, "Stratified sampling of spherical triangles", SIGGRAPH 1995), kept
 * with probability cos_x / cos_max (rejection).  One shadow ray tests w_k.
 * f_k lies in [0, P(x_k)], P <= 1: the variance is finite for every pair,
 * touching ones included (the 1/r^2 of area sampling made it infinite
 * where elements share an edge, and its reported errors then meant
 * nothing), and unoccluded pairs have no variance from the inner integral.
 *
 *        s  ___x_k___           j's polygon, clipped to x_k's hemisphere,
 *          |    |  \            seen from x_k: P exactly, and one ray along
 *          |    |   \ w_k       w_k, of density cos_x / (pi P)
 *               n_s  \______ j
 *
 * Far pairs sample a point y_k of j too: f_k = A_j cos_x cos_y V / (pi r^2)
 * (1/r^2 varies by a bounded factor there, and a point is 5-10x cheaper
 * than a contour).
 *
 * Which end: s is the smaller element of the pair (the lower index on a
 * tie), where F(x) varies least; F_js = F_sj A_s / A_j, so the matrix is
 * reciprocal by construction.  Stratification with an honest variance: the
 * N samples (N even) are two per stratum of an H = N/2 cell grid over s
 * (rows x columns, rows the largest divisor of H up to sqrt(H)), so
 *
 *     F = 1/N sum_k f_k,   var F = 1/H^2 sum_h (f_h1 - f_h2)^2 / 4
 *
 * is the unbiased variance of a stratified mean (Cochran, "Sampling
 * Techniques", 3rd ed., sec. 5.4); the sample variance / N ignored the
 * strata and read 4-5x the true error for separated pairs.  Directions and
 * points of j are independent within a stratum, as that estimator needs.
 * Measured over 100 seeds (tests/test_ff_stats.c): the z-scores of
 * separated and touching squares have deviations 0.91 to 1.0.
 *
 * Samples per pair: --ff-samples N for every pair, or by default 64 x
 * nearness^2 in [4, 256]: the six faces of a cube (one element each) get
 * 256 (adjacent) and 128 (opposite), most of a 2,000-element Cornell box's
 * pairs 4.  Samples are keyed on (seed, pair): results do not depend on
 * the thread count.  Cost: one shadow ray per sample; near samples also a
 * clip, a contour and one or two spherical triangles.  Each pair's
 * estimate is unbiased, but a row sums the noise of all its pairs: by
 * default rad_ff_balance (reciprocity.c) holds rows to their closure,
 * measured by rays, moving each factor by its share of its rows' variance
 * (least squares), and reduces the variances reported to match.
 */
#include "formfactor/formfactor.h"

#include <stdlib.h>
#include <string.h>

/* Pairs nearer than this (nearness(), below) integrate j's polygon exactly;
 * farther ones sample a point of j: there 1/r^2 varies over the pair by
 * (1 +- 1/2)^2 at most, and points are 5-10x cheaper than the contour. */
#define NEAR 0.5

enum {
    CHUNK = 256,        /* samples per occlusion batch (even: whole strata) */
    MIN_SAMPLES = 4,    /* default for far pairs: two strata */
    MAX_SAMPLES = 256,  /* default for the nearest pairs */
    /* Rejection sampling's tries; each keeps at least mean cos / max cos
     * over the polygon, so 64 misses is vanishingly rare, and the 64th
     * direction is then used. */
    MAX_ATTEMPTS = 64
};

/* Per-thread buffers, allocated once per thread. */
typedef struct mc_scratch {
    double value[CHUNK];      /* per sample of the chunk: f_k, visibility not yet applied */
    uint32_t sample[CHUNK];   /* per ray: the sample it tests */
    rad_ray rays[CHUNK];
    uint8_t blocked[CHUNK];
    int count, rays_count;    /* samples and rays in the chunk */
    double sum, spread;       /* sum of f_k; sum over strata of (f_h1 - f_h2)^2 */
} mc_scratch;

/* Cast the chunk's shadow rays, zero the samples they find blocked, and fold
 * the chunk's strata (samples 2h, 2h + 1) into the sums. */
static void flush_chunk(const rad_ff_request *req, mc_scratch *s, uint64_t *rays_cast)
{
    if (s->rays_count) {
        req->vis->backend->occluded(req->vis->state, s->rays, (size_t)s->rays_count, s->blocked);
        *rays_cast += (uint64_t)s->rays_count;
        for (int r = 0; r < s->rays_count; r++)
            if (s->blocked[r])
                s->value[s->sample[r]] = 0.0;
    }
    for (int k = 0; k + 1 < s->count; k += 2) {
        double d = s->value[k] - s->value[k + 1];
        s->sum += s->value[k] + s->value[k + 1];
        s->spread += d * d;
    }
    s->count = s->rays_count = 0;
}

/* Element j as the sampler sees it: flat, its corners projected onto the
 * plane through its centroid (counter-clockwise about its normal). */
typedef struct mc_target {
    vec3 corner[4];
    uint32_t corners;
    vec3 normal, centroid;
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
}

/* The solid angle of the spherical triangle of unit vectors a, b, c, sr
 * (Van Oosterom & Strackee 1983). */
static double triangle_solid_angle(vec3 a, vec3 b, vec3 c)
{
    double num = fabs(v3_dot(a, v3_cross(b, c)));
    double den = 1.0 + v3_dot(a, b) + v3_dot(b, c) + v3_dot(c, a);
    return 2.0 * atan2(num, den);
}

static double clamp1(double x) { return x < -1.0 ? -1.0 : x > 1.0 ? 1.0 : x; }

/* A direction uniform in solid angle over the spherical triangle (a, b, c)
 * of solid angle `area`, from (u1, u2) in [0,1)^2 (Arvo 1995: the
 * sub-triangle of area u1 * area first, then along its far edge).  Falls
 * back to the triangle's centre direction where it is too thin for the
 * formula's divisions. */
static vec3 sample_spherical_triangle(vec3 a, vec3 b, vec3 c, double area, double u1, double u2)
{
    vec3 nab = v3_normalize(v3_cross(a, b)), nac = v3_normalize(v3_cross(a, c));
    double alpha = acos(clamp1(v3_dot(nab, nac)));
    double s = sin(u1 * area - alpha), t = cos(u1 * area - alpha);
    double u = t - cos(alpha), v = s + sin(alpha) * v3_dot(a, b);
    double q = ((v * t - u * s) * cos(alpha) - v) / ((v * s + u * t) * sin(alpha));
    vec3 c_perp = v3_normalize(v3_sub(c, v3_scale(a, v3_dot(c, a))));
    q = clamp1(q);
    vec3 c_hat = v3_add(v3_scale(a, q), v3_scale(c_perp, sqrt(fmax(0.0, 1.0 - q * q))));
    double z = clamp1(1.0 - u2 * (1.0 - v3_dot(c_hat, b)));
    vec3 b_perp = v3_normalize(v3_sub(c_hat, v3_scale(b, v3_dot(c_hat, b))));
    vec3 w = v3_add(v3_scale(b, z), v3_scale(b_perp, sqrt(fmax(0.0, 1.0 - z * z))));
    if (!(isfinite(w.x) && isfinite(w.y) && isfinite(w.z)))
        w = v3_normalize(v3_add(a, v3_add(b, c)));
    return w;
}

/* The largest n . w over the convex spherical polygon dir[0..m-1]: 1 when
 * n points into it, else the largest over its edges (great-circle arcs:
 * at an end, or where n's projection on the arc's plane falls inside). */
static double polygon_cos_max(const vec3 *dir, int m, vec3 n)
{
    vec3 centre = v3(0, 0, 0);
    for (int c = 0; c < m; c++)
        centre = v3_add(centre, dir[c]);
    bool inside = true;
    double best = -1.0;
    for (int c = 0; c < m; c++) {
        vec3 a = dir[c], b = dir[(c + 1) % m], edge = v3_cross(a, b);
        inside &= (v3_dot(edge, n) >= 0.0) == (v3_dot(edge, centre) >= 0.0);
        best = fmax(best, v3_dot(n, a));
        double l = v3_length(edge);
        if (!(l > 0.0))
            continue;
        edge = v3_scale(edge, 1.0 / l);
        vec3 p = v3_sub(n, v3_scale(edge, v3_dot(n, edge)));
        if (v3_dot(v3_cross(a, p), edge) >= 0.0 && v3_dot(v3_cross(p, b), edge) >= 0.0)
            best = fmax(best, v3_length(p));
    }
    return inside ? 1.0 : best;
}

/* The shadow ray of the chunk's last sample, from a to b: blocked, the
 * sample counts 0. */
static void add_ray(mc_scratch *sc, vec3 a, vec3 b)
{
    rad_ray *ray = &sc->rays[sc->rays_count];
    ray->origin = a;
    ray->direction = v3_sub(b, a);
    ray->tnear = 0.0;
    ray->tfar = 1.0;
    sc->sample[sc->rays_count++] = (uint32_t)(sc->count - 1);
}

/* The rows x columns grid of H strata: rows the largest divisor of H up to
 * sqrt(H). */
static int strata_rows(int H)
{
    int rows = (int)floor(sqrt((double)H));
    while (rows > 1 && H % rows != 0)
        rows--;
    return rows < 1 ? 1 : rows;
}

/* F from element s to element j (s's points sampled, j's polygon exact)
 * with N samples, and the variance of that estimate. */
static void estimate(const rad_ff_request *req, mc_scratch *sc, uint32_t s, uint32_t j, int N, bool near,
                     double eps, double *F_sj, double *var_sj, uint64_t *rays_cast)
{
    const rad_mesh *mesh = req->mesh;
    const rad_element *es = &mesh->elements[s], *ej = &mesh->elements[j];
    rad_rng rng = rad_rng_keyed(req->seed, s < j ? s : j, s < j ? j : s);
    mc_target tj;
    target_init(mesh, ej, &tj);
    double lift_s = eps + rad_element_bend(mesh, es), lift_j = eps + rad_element_bend(mesh, ej);
    int H = N / 2, rows = strata_rows(H), cols = H / rows;
    sc->count = sc->rays_count = 0;
    sc->sum = sc->spread = 0.0;
    for (int k = 0; k < N; k++) {
        int h = k / 2;
        double u = ((h % cols) + rad_rng_uniform(&rng)) / cols;
        double v = ((h / cols) + rad_rng_uniform(&rng)) / rows;
        if (sc->count == CHUNK)
            flush_chunk(req, sc, rays_cast);
        double *value = &sc->value[sc->count++];
        *value = 0.0;
        vec3 x = rad_element_sample(mesh, es, u, v);
        double weight = rad_element_sample_weight(mesh, es, u, v);
        if (!near) {
            /* Far: y uniform on j, f_k = A_j cos_x cos_y V / (pi r^2). */
            double u2 = rad_rng_uniform(&rng), v2 = rad_rng_uniform(&rng);
            vec3 y = rad_element_sample(mesh, ej, u2, v2), d = v3_sub(y, x);
            double r2 = v3_dot(d, d), cx = v3_dot(es->normal, d), cy = -v3_dot(ej->normal, d);
            if (!(cx > 0.0 && cy > 0.0 && r2 > 0.0))
                continue;
            *value = cx * cy / (M_PI * r2 * r2) * ej->area * weight * rad_element_sample_weight(mesh, ej, u2, v2);
            if (req->vis)
                add_ray(sc, v3_mad(x, es->normal, lift_s), v3_mad(y, ej->normal, lift_j));
            continue;
        }
        double height = v3_dot(tj.normal, v3_sub(x, tj.centroid)); /* x over j's plane */
        if (!(height > 0.0))
            continue; /* behind j: F(x) = 0 */
        /* j clipped to x's hemisphere (Sutherland-Hodgman), seen from x. */
        vec3 dir[5];
        int m = 0;
        for (uint32_t c = 0; c < tj.corners; c++) {
            vec3 pa = tj.corner[c], pb = tj.corner[(c + 1) % tj.corners];
            double da = v3_dot(es->normal, v3_sub(pa, x)), db = v3_dot(es->normal, v3_sub(pb, x));
            if (da >= 0.0)
                dir[m++] = v3_sub(pa, x);
            if ((da >= 0.0) != (db >= 0.0))
                dir[m++] = v3_sub(v3_lerp(pa, pb, da / (da - db)), x);
        }
        if (m < 3)
            continue;
        bool degenerate = false;
        for (int c = 0; c < m; c++) {
            double l = v3_length(dir[c]);
            degenerate |= !(l > 0.0);
            dir[c] = v3_scale(dir[c], 1.0 / l);
        }
        if (degenerate)
            continue; /* x on a corner of j (probability 0) */
        /* P(x) by Lambert's contour formula: the vertices run clockwise
         * seen from x, so the sum is negative. */
        double contour = 0.0;
        for (int c = 0; c < m; c++) {
            vec3 cr = v3_cross(dir[c], dir[(c + 1) % m]);
            double l = v3_length(cr);
            if (l > 0.0)
                contour += atan2(l, v3_dot(dir[c], dir[(c + 1) % m])) * v3_dot(es->normal, cr) / l;
        }
        double P = -contour / (2.0 * M_PI);
        if (!(P > 0.0))
            continue;
        *value = P * weight;
        if (!req->vis)
            continue;
        /* One direction with density cos_x / (pi P(x)) over the polygon:
         * uniform in solid angle (a fan triangle by its solid angle, then
         * Arvo within it), kept with probability cos_x / cos_max. */
        double omega[3], total = 0.0;
        for (int c = 1; c + 1 < m; c++)
            total += omega[c - 1] = triangle_solid_angle(dir[0], dir[c], dir[c + 1]);
        double cos_max = polygon_cos_max(dir, m, es->normal);
        if (!(total > 0.0 && cos_max > 0.0))
            continue;
        vec3 w = es->normal;
        for (int attempt = 0; attempt < MAX_ATTEMPTS; attempt++) {
            int tri = 0;
            double at = rad_rng_uniform(&rng) * total;
            while (tri < m - 3 && at >= omega[tri])
                at -= omega[tri++];
            double w1 = rad_rng_uniform(&rng), w2 = rad_rng_uniform(&rng);
            w = sample_spherical_triangle(dir[0], dir[tri + 1], dir[tri + 2], omega[tri], w1, w2);
            if (rad_rng_uniform(&rng) * cos_max < v3_dot(es->normal, w))
                break;
        }
        double cos_x = v3_dot(es->normal, w), toward = -v3_dot(tj.normal, w);
        if (!(cos_x > 0.0 && toward > 0.0))
            continue;
        vec3 y = v3_mad(x, w, height / toward);
        add_ray(sc, v3_mad(x, es->normal, lift_s), v3_mad(y, tj.normal, lift_j));
    }
    flush_chunk(req, sc, rays_cast);
    *F_sj = sc->sum / N;
    *var_sj = sc->spread / (4.0 * (double)H * (double)H);
}

/* What every pair reads. */
typedef struct mc_shared {
    int N;              /* samples per element pair; 0: by distance (file header) */
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
    /* Two samples per stratum: an even count, at least 2. */
    m->N = req->samples > 0 ? req->samples + (req->samples & 1) : 0;
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
    (void)req, (void)shared, (void)block; /* fixed size, nothing to lay out */
    return sizeof(mc_scratch);
}

/* How near a pair is: (r_i + r_j) / d, the summed centroid-to-corner
 * radii over the centroid distance (infinite for coincident centroids). */
static double nearness(const mc_shared *m, const rad_element *ei, const rad_element *ej, uint32_t i, uint32_t j)
{
    vec3 gap = v3_sub(ej->centroid, ei->centroid);
    double d = v3_length(gap);
    return d > 0.0 ? (m->radius[i] + m->radius[j]) / d : INFINITY;
}

/* The samples of a pair by default: 64 x nearness^2, even, in
 * [MIN_SAMPLES, MAX_SAMPLES]. */
static int default_samples(double near)
{
    double want = 64.0 * near * near;
    if (!(want < MAX_SAMPLES))
        return MAX_SAMPLES;
    int N = (int)ceil(want);
    N += N & 1;
    return N < MIN_SAMPLES ? MIN_SAMPLES : N;
}

/* One estimate per pair, from the smaller element: reciprocal by
 * construction. */
static void montecarlo_pair(const rad_ff_request *req, const void *shared, void *scratch, uint32_t i,
                            uint32_t j, rad_ff_pair *out, rad_ff_tally *tally)
{
    const mc_shared *m = shared;
    const rad_element *ei = &req->mesh->elements[i], *ej = &req->mesh->elements[j];
    double near = nearness(m, ei, ej, i, j);
    int N = m->N > 0 ? m->N : default_samples(near);
    bool from_i = ei->area <= ej->area;
    uint32_t s = from_i ? i : j, o = from_i ? j : i;
    double f, var;
    estimate(req, scratch, s, o, N, near >= NEAR, m->eps, &f, &var, &tally->rays);
    double ratio = req->mesh->elements[s].area / req->mesh->elements[o].area; /* F_os = F_so ratio */
    double f_other = f * ratio, var_other = var * ratio * ratio;
    out->F_ij = from_i ? f : f_other;
    out->F_ji = from_i ? f_other : f;
    out->var_ij = from_i ? var : var_other;
    out->var_ji = from_i ? var_other : var;
}

const rad_ff_method rad_ff_montecarlo = {
    "montecarlo",
    "stratified points of the smaller element of each pair, the other's polygon exact (Lambert), "
    "one shadow ray each uniform in its solid angle; unbiased, stratified variance reported; "
    "4 to 256 points per pair by distance; O(n^2 N)",
    RAD_FF_VARIANCE | RAD_FF_BALANCE,
    montecarlo_prepare,
    montecarlo_scratch,
    montecarlo_pair,
    NULL,
    NULL,
};
