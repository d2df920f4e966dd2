/*
 * visibility.c -- the shadow-ray visibility fraction between two elements
 * (or pieces of them), shared by the methods that multiply an unoccluded
 * factor by it: analytic, contour, hybrid.
 *
 * Stratified rays join random points of the two ends; each end point is
 * lifted off its surface by the shadow-ray epsilon plus the element's bend
 * (rad_element_bend), so that a ray never starts behind the surface it
 * leaves, and pulled as far toward the element's centroid, so that it never
 * lies on a neighbouring surface.  A ray whose ends lie behind each other's
 * planes is not cast: its cosine weight is 0, and counting it as blocked
 * would dim pairs that straddle each other's planes (whose unoccluded
 * factors the methods compute for the facing parts only).  Both ends are
 * stratified on the unit square (side x side cells,
 * side = ceil(sqrt(count))), and the far end's strata are shuffled:
 *
 *     ray k:  stratum k of end a   ->   stratum perm[k] of end b
 *
 * Random numbers come from a stream keyed by (seed, i, j): results do not
 * depend on the thread count.
 */
#include "formfactor/formfactor.h"

void rad_ff_end_element(const rad_mesh *mesh, uint32_t e, double eps, rad_ff_end *end)
{
    const rad_element *el = &mesh->elements[e];
    end->corners = el->vertex_count;
    for (uint32_t k = 0; k < el->vertex_count; k++)
        end->corner[k] = mesh->vertices[el->vertex[k]];
    end->normal = el->normal;
    end->lift = eps + rad_element_bend(mesh, el);
}

/* A ray end point at unit-square parameters: the point of rad_element_sample
 * (bilinear on quads, the folded square on triangles), pulled toward the
 * centroid by `lift` and lifted by `lift` along the normal.  The pull keeps
 * ends that fall on an element's rim off the plane of a neighbouring
 * surface (a wall meeting the floor), which float rays would otherwise hit
 * at t = 1 about once in 10^7 rays. */
static vec3 end_point(const rad_ff_end *end, double u, double v)
{
    const vec3 *c = end->corner;
    vec3 p, centroid;
    if (end->corners == 3) {
        if (u + v > 1.0) {
            u = 1.0 - u;
            v = 1.0 - v;
        }
        p = v3_add(c[0], v3_add(v3_scale(v3_sub(c[1], c[0]), u), v3_scale(v3_sub(c[2], c[0]), v)));
        centroid = v3_scale(v3_add(c[0], v3_add(c[1], c[2])), 1.0 / 3.0);
    } else {
        p = v3_lerp(v3_lerp(c[0], c[1], u), v3_lerp(c[3], c[2], u), v);
        centroid = v3_scale(v3_add(v3_add(c[0], c[1]), v3_add(c[2], c[3])), 0.25);
    }
    vec3 in = v3_sub(centroid, p);
    double d = v3_length(in);
    p = d > end->lift ? v3_mad(p, in, end->lift / d) : centroid;
    return v3_mad(p, end->normal, end->lift);
}

/* The ray from p (on a) to q (on b) into *ray, when each end is in front
 * of the other's plane; returns 1 if written, else 0.  Ends behind each
 * other's planes carry no energy (a cosine is <= 0): they say nothing
 * about occlusion, so they are not cast. */
static int add_facing_ray(const rad_ff_end *a, const rad_ff_end *b, vec3 p, vec3 q, rad_ray *ray)
{
    vec3 d = v3_sub(q, p);
    if (!(v3_dot(a->normal, d) > 0.0 && v3_dot(b->normal, d) < 0.0))
        return 0;
    ray->origin = p;
    ray->direction = d;
    ray->tnear = 0.0;
    ray->tfar = 1.0;
    return 1;
}

/* The part of the polygon c[0..n) strictly in front of the plane through
 * o with normal `normal` (Sutherland-Hodgman); returns its corner count
 * (0 when nothing is in front). */
static int clip_front(const vec3 *c, int n, vec3 o, vec3 normal, vec3 *out)
{
    int m = 0;
    for (int k = 0; k < n; k++) {
        vec3 p = c[k], q = c[(k + 1) % n];
        double dp = v3_dot(normal, v3_sub(p, o)), dq = v3_dot(normal, v3_sub(q, o));
        if (dp > 0.0)
            out[m++] = p;
        if ((dp > 0.0) != (dq > 0.0) && dp != dq)
            out[m++] = v3_lerp(p, q, dp / (dp - dq));
    }
    return m >= 3 ? m : 0;
}

/* Points spread over the facing part of `end` (its part in front of the
 * other end's plane): the part's centroid, then half way from there to
 * each of its corners, lifted as end_point lifts.  Returns their count. */
static int facing_points(const rad_ff_end *end, const rad_ff_end *other, vec3 *pts)
{
    vec3 part[8];
    int n = clip_front(end->corner, (int)end->corners, other->corner[0], other->normal, part);
    if (n == 0)
        return 0;
    vec3 c = v3(0, 0, 0);
    for (int k = 0; k < n; k++)
        c = v3_add(c, part[k]);
    c = v3_scale(c, 1.0 / n);
    pts[0] = v3_mad(c, end->normal, end->lift);
    for (int k = 0; k < n; k++)
        pts[1 + k] = v3_mad(v3_lerp(c, part[k], 0.5), end->normal, end->lift);
    return 1 + n;
}

/* Rays between the facing parts of a and b, for pairs whose random
 * samples all fell behind the other's plane (elements that straddle each
 * other's planes, facing only along a strip): without them the pair had
 * no verdict and was taken as visible, which let two sealed rooms see each
 * other through such strips (F ~ 1e-7).  Returns the rays written. */
static int facing_part_rays(const rad_ff_end *a, const rad_ff_end *b, int count, rad_ray *rays)
{
    vec3 pa[9], pb[9];
    int na = facing_points(a, b, pa), nb = facing_points(b, a, pb), m = 0;
    if (na == 0 || nb == 0)
        return 0;
    int pairs = na * nb < count ? na * nb : count;
    for (int k = 0; k < pairs; k++)
        m += add_facing_ray(a, b, pa[k % na], pb[(k / na + k) % nb], &rays[m]);
    return m;
}

int rad_ff_pairs(const rad_ff_end *a, const rad_ff_end *b, int count, rad_rng *rng, rad_ray *rays)
{
    if (count <= 0)
        return 0;
    if (count > RAD_FF_MAX_RAYS)
        count = RAD_FF_MAX_RAYS;
    int side = (int)ceil(sqrt((double)count));
    /* Stratified on both ends, the far end's strata shuffled (Fisher-Yates):
     * pairing strata by a fixed rule would tie each ray's end to its start
     * and bias the estimate. */
    int perm[RAD_FF_MAX_RAYS], first[RAD_FF_MAX_RAYS];
    int cells = side * side;
    rad_rng_shuffle(rng, perm, cells);
    /* With fewer rays than cells (count not a square), the near end's
     * strata are a random subset too: a fixed subset would never sample
     * the cells left over, and bias the fraction. */
    if (count < cells)
        rad_rng_shuffle(rng, first, cells);
    else
        for (int k = 0; k < cells; k++)
            first[k] = k;
    int m = 0;
    for (int k = 0; k < count; k++) {
        int si = first[k], sj = perm[k];
        double u1 = ((si % side) + rad_rng_uniform(rng)) / side;
        double v1 = ((si / side) + rad_rng_uniform(rng)) / side;
        double u2 = ((sj % side) + rad_rng_uniform(rng)) / side;
        double v2 = ((sj / side) + rad_rng_uniform(rng)) / side;
        m += add_facing_ray(a, b, end_point(a, u1, v1), end_point(b, u2, v2), &rays[m]);
    }
    return m > 0 ? m : facing_part_rays(a, b, count, rays);
}

int rad_ff_rays(const rad_vis *vis, const rad_ff_end *a, const rad_ff_end *b, int count,
                rad_rng *rng, uint64_t *rays_cast, int *facing)
{
    rad_ray rays[RAD_FF_MAX_RAYS];
    uint8_t hit[RAD_FF_MAX_RAYS];
    int m = rad_ff_pairs(a, b, count, rng, rays);
    *facing = 0;
    if (m == 0)
        return 0;
    vis->backend->occluded(vis->state, rays, (size_t)m, hit);
    *rays_cast += (uint64_t)m;
    *facing = m;
    int pass = 0;
    for (int k = 0; k < m; k++)
        pass += !hit[k];
    return pass;
}

double rad_ff_visibility(const rad_ff_request *req, uint32_t i, uint32_t j, double eps,
                         int base_rays, uint64_t *rays_cast)
{
    if (!req->vis)
        return 1.0;
    if (base_rays > RAD_FF_MAX_BASE_RAYS)
        base_rays = RAD_FF_MAX_BASE_RAYS;
    rad_ff_end a, b;
    rad_ff_end_element(req->mesh, i, eps, &a);
    rad_ff_end_element(req->mesh, j, eps, &b);
    rad_rng rng = rad_rng_keyed(req->seed, i, j);
    /* A pilot of half the rays only chooses how many fresh rays estimate the
     * fraction: base_rays where it was unanimous, 4 x base_rays where it
     * disagreed (a partly visible pair).  The estimate never reuses the
     * pilot: taking a unanimous pilot as exactly 0 or 1 would pull every
     * partly visible pair toward the nearer extreme (a pair 90% visible
     * would average 0.95 with a 4-ray pilot), a bias of 1% on the Cornell
     * box's floor. */
    int pilot_cast, cast;
    int pilot_rays = base_rays / 2 > 0 ? base_rays / 2 : 1;
    int pilot = rad_ff_rays(req->vis, &a, &b, pilot_rays, &rng, rays_cast, &pilot_cast);
    bool partial = pilot_cast > 0 && pilot > 0 && pilot < pilot_cast;
    int pass = rad_ff_rays(req->vis, &a, &b, partial ? 4 * base_rays : base_rays, &rng, rays_cast, &cast);
    /* No facing ray even between the facing parts: nothing of one end is
     * in front of the other, or only a sliver thinner than the rays'
     * lift; no light passes. */
    return cast > 0 ? (double)pass / cast : 0.0;
}
