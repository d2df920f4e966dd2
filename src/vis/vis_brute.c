/*
 * vis_brute.c -- the reference visibility backend: every ray is tested
 * against every patch, O(patches) per ray, in double precision.
 *
 * Quads are split along the c0-c2 diagonal into two triangles; each
 * triangle is tested with Moller & Trumbore's algorithm ("Fast, minimum
 * storage ray/triangle intersection", JGT 1997), two-sided.  Only for tests
 * and small scenes: it is the ground truth the Embree backend is checked
 * against, so it favours plainness over speed.
 *
 *     c3 +-------+ c2
 *        |     / |
 *        |   /   |     triangles (c0, c1, c2) and (c0, c2, c3)
 *        | /     |
 *     c0 +-------+ c1
 */
#include "vis/vis.h"

#include <stdlib.h>

typedef struct brute_triangle {
    vec3 v0, edge1, edge2;  /* m: v0, v1 - v0, v2 - v0 */
    uint32_t patch;
} brute_triangle;

typedef struct brute_state {
    brute_triangle *triangles;
    size_t triangle_count;
} brute_state;

static rad_result brute_create(rad_context *ctx, const rad_mesh *mesh, void **state)
{
    *state = NULL;
    brute_state *s = rad_alloc(ctx, RAD_MEM_VISIBILITY, 1, sizeof *s, "brute-force visibility");
    if (!s)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_vis_prim *prims = NULL;
    size_t nprims = 0;
    rad_result r = rad_vis_primitives(ctx, mesh, &prims, &nprims);
    if (r != RAD_OK) {
        rad_free(s);
        return r;
    }
    s->triangles = rad_alloc(ctx, RAD_MEM_VISIBILITY, nprims ? nprims : 1, 2 * sizeof *s->triangles,
                                   "brute-force visibility triangles");
    if (!s->triangles) {
        rad_free(prims);
        rad_free(s);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    /* Quads become triangles (0 1 2) and (0 2 3); primitives are flat
     * (vis.h), so the choice of diagonal does not matter. */
    for (size_t i = 0; i < nprims; i++) {
        const rad_vis_prim *p = &prims[i];
        for (uint32_t k = 0; k + 2 < p->corner_count && k < 2; k++) {
            brute_triangle *tri = &s->triangles[s->triangle_count++];
            tri->v0 = p->corner[0];
            tri->edge1 = v3_sub(p->corner[k + 1], p->corner[0]);
            tri->edge2 = v3_sub(p->corner[k + 2], p->corner[0]);
            tri->patch = p->patch;
        }
    }
    rad_free(prims);
    *state = s;
    return RAD_OK;
}

static void brute_destroy(void *state)
{
    brute_state *s = state;
    if (!s)
        return;
    rad_free(s->triangles);
    rad_free(s);
}

/* Moller-Trumbore: the ray parameter of the hit, or INFINITY if the ray's
 * line misses the triangle (edges included) or is parallel to it. */
static double brute_hit(const brute_triangle *tri, const rad_ray *ray)
{
    vec3 pvec = v3_cross(ray->direction, tri->edge2);
    double det = v3_dot(tri->edge1, pvec);
    /* Parallel (or degenerate): det is exactly zero only in the limit; any
     * non-zero det is usable in double, and a near-parallel hit is a
     * grazing one that no two backends need agree on. */
    if (det == 0.0)
        return INFINITY;
    double inv_det = 1.0 / det;
    vec3 tvec = v3_sub(ray->origin, tri->v0);
    double u = v3_dot(tvec, pvec) * inv_det;
    if (u < 0.0 || u > 1.0)
        return INFINITY;
    vec3 qvec = v3_cross(tvec, tri->edge1);
    double v = v3_dot(ray->direction, qvec) * inv_det;
    if (v < 0.0 || u + v > 1.0)
        return INFINITY;
    return v3_dot(tri->edge2, qvec) * inv_det;
}

static void brute_occluded(void *state, const rad_ray *rays, size_t count, uint8_t *occluded)
{
    const brute_state *s = state;
    for (size_t k = 0; k < count; k++) {
        occluded[k] = 0;
        double tnear = rays[k].tnear > 0.0 ? rays[k].tnear : 0.0; /* as Embree */
        for (size_t i = 0; i < s->triangle_count; i++) {
            double t = brute_hit(&s->triangles[i], &rays[k]);
            if (t > tnear && t < rays[k].tfar) {
                occluded[k] = 1;
                break;
            }
        }
    }
}

static void brute_intersect(void *state, const rad_ray *rays, size_t count, rad_hit *hits)
{
    const brute_state *s = state;
    for (size_t k = 0; k < count; k++) {
        hits[k].t = INFINITY;
        hits[k].patch = 0;
        double tnear = rays[k].tnear > 0.0 ? rays[k].tnear : 0.0; /* as Embree */
        for (size_t i = 0; i < s->triangle_count; i++) {
            double t = brute_hit(&s->triangles[i], &rays[k]);
            if (t > tnear && t < rays[k].tfar && t < hits[k].t) {
                hits[k].t = t;
                hits[k].patch = s->triangles[i].patch;
            }
        }
    }
}

const rad_vis_backend rad_vis_brute = {
    "brute",
    "every ray against every patch, double precision (reference for tests)",
    brute_create,
    brute_destroy,
    brute_occluded,
    brute_intersect,
};
