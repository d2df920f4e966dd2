/*
 * vis.h -- ray queries against the meshed scene's patches, behind one small
 * table so a brute-force reference can check the Embree backend.
 *
 * Geometry is the patches (not the elements): fewer primitives, and a hit's
 * patch parameters locate the element in O(1) (mesh.h).  Occlusion is
 * two-sided: every patch blocks rays from either side.
 */
#ifndef RAD_VIS_H
#define RAD_VIS_H

#include "mesh/mesh.h"

typedef struct rad_ray {
    vec3 origin;          /* m */
    vec3 direction;       /* need not be unit; t is in units of |direction| */
    double tnear, tfar;
} rad_ray;

typedef struct rad_hit {
    double t;             /* INFINITY if nothing was hit */
    uint32_t patch;       /* valid when t is finite */
} rad_hit;

typedef struct rad_vis_backend {
    const char *name;
    const char *description;
    /* Build over the mesh's patches.  The mesh must outlive the state. */
    rad_result (*create)(rad_context *ctx, const rad_mesh *mesh, void **state);
    void (*destroy)(void *state);
    /* Thread-safe batched queries: occluded[k] = 1 if anything lies on ray k
     * within (tnear, tfar). */
    void (*occluded)(void *state, const rad_ray *rays, size_t count, uint8_t *occluded);
    void (*intersect)(void *state, const rad_ray *rays, size_t count, rad_hit *hits);
} rad_vis_backend;

/* What the backends build over.  A flat patch is one primitive.  A patch
 * that is not flat (a quad merged from two triangles a few millimetres out
 * of plane) would differ from its own elements by more than the shadow-ray
 * epsilon, so its elements are the primitives instead: each is flat to
 * (bend / cells^2), far below the epsilon. */
typedef struct rad_vis_prim {
    vec3 corner[4];       /* m */
    uint32_t corner_count;/* 3 or 4 */
    uint32_t patch;
} rad_vis_prim;

/* The primitive list for a mesh (caller frees *out). */
rad_result rad_vis_primitives(rad_context *ctx, const rad_mesh *mesh, rad_vis_prim **out,
                              size_t *count);

/* The registry: a NULL-terminated array. */
extern const rad_vis_backend *const rad_vis_backends[];
const rad_vis_backend *rad_vis_find(const char *name);

/* A visibility handle: backend + state + counters. */
typedef struct rad_vis {
    const rad_vis_backend *backend;
    void *state;
    double build_seconds;
} rad_vis;

rad_result rad_vis_create(rad_context *ctx, const char *name, const rad_mesh *mesh, rad_vis **out);
void rad_vis_destroy(rad_vis *vis);

/* Offset for shadow-ray end points, m: 1e-5 x the scene diagonal
 * (mesh->diagonal, 1 m when 0).  Float rounding in Embree is ~1e-7
 * relative, so this is well clear of self-intersection yet far below any
 * element size we mesh to.  O(1); cannot fail. */
double rad_vis_epsilon(const rad_mesh *mesh);

/* The element of mesh that `ray`, cast with the result `hit`, meets on the
 * front of its patch (one-sided surfaces: the back absorbs), located from
 * the hit point's patch parameters (rad_mesh_locate); UINT32_MAX when the
 * ray left the scene or met a back side. */
uint32_t rad_vis_front_element(const rad_mesh *mesh, const rad_ray *ray, const rad_hit *hit);

/* Patches narrower than rad_vis_epsilon: shadow rays end that far off the
 * surfaces, so an occluder nearer than it to such a patch is not seen.
 * Returns their count; *narrowest (m) and *which (a patch) tell the
 * narrowest of them. */
size_t rad_vis_unresolved(const rad_mesh *mesh, double *narrowest, uint32_t *which);

/* The box a view from `origin` can reach (reach.c): a fan of `rays`
 * directions (a Fibonacci sphere) from origin, starting at tnear, to what
 * each first hits; the box holds the origin and every hit, each widened by
 * 2 sqrt(4 pi / rays) x its distance + pad, so that a line of sight from
 * origin stays in it unless it passes a gap the fan stepped over.  Returns
 * false (and an infinite box) when a ray hits nothing: the view leaves the
 * scene.  Thread-safe, deterministic; cannot fail. */
bool rad_vis_reach(const rad_vis *vis, vec3 origin, double tnear, size_t rays, double pad, vec3 *lo, vec3 *hi);
/* The same, and the box of each sector of the fan's directions (reach.c):
 * `bands` bands of z times `azimuths` azimuths, sector_lo/hi[band x
 * azimuths + azimuth] (room for bands x azimuths each), every one holding
 * the origin; all infinite when a ray hits nothing. */
bool rad_vis_reach_sectors(const rad_vis *vis, vec3 origin, double tnear, size_t rays, double pad, int bands,
                           int azimuths, vec3 *lo, vec3 *hi, vec3 *sector_lo, vec3 *sector_hi);

#endif /* RAD_VIS_H */
