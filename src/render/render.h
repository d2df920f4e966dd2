/*
 * render.h -- what a picture needs beyond the solution's element values:
 * the final gather (docs/methods.md "The final gather").
 *
 * A solution's elements carry the radiosity as a mean over each element;
 * drawn by interpolation, a shadow edge is as sharp as the mesh under it,
 * and a hierarchical solution's leaves hold irradiance pushed down from
 * coarser links.  The picture splits the radiosity at the point x a camera
 * ray meets (element e) into
 *
 *   B(x) = R(x)              R_e = E_e + rho_e (direct_e + I_e), drawn smooth
 *        + rho_e D(x)        the emitters' direct light at x itself
 *
 * D(x) (direct.c) = sum over emitting sources j of E_j F(x -> visible part
 * of j), exact: the point-to-polygon factor of the source less the
 * blockers' shadows.  I_e (indirect.c) = the irradiance at e's centroid
 * gathered again from every element's reflected radiosity B_j - E_j, on a
 * uniform render mesh for hierarchical solutions, after two Jacobi sweeps
 * that give the sources the exact direct light; direct_e = the luminaires'
 * and daylight's light as the solution has it.  This is the final gather of
 * Reichert 1992 and Lischinski, Tampieri & Greenberg 1993: the shadows take
 * the pixel's resolution, the smooth light the render mesh's.
 */
#ifndef RAD_RENDER_H
#define RAD_RENDER_H

#include "formfactor/formfactor.h"
#include "interp/interp.h"

/* Beyond this many emitting elements the gather is not made (its cost is
 * per shading point and source; the picture then reads the elements). */
#define RAD_DIRECT_MAX_SOURCES 256

/* A source: an emitting patch whose elements all emit the same (one
 * polygon, one factor per point), or else one emitting element. */
typedef struct rad_direct_source {
    vec3 corner[4];               /* m, counter-clockwise about normal */
    uint32_t corner_count;
    vec3 normal;                  /* unit */
    vec3 centre;                  /* m: the corners' mean */
    double self[3];               /* self-emitted exitance E, W/m^2 */
    uint32_t first, count;        /* its elements: member[first .. first + count) */
} rad_direct_source;

/* What may cast a shadow: each patch as a flat convex polygon, a bent
 * quad (the Cornell box's blocks are 2 mm out of plane) as its two
 * triangles, which stand within its bend of the surface the rays meet. */
typedef struct rad_direct_blocker {
    vec3 corner[4];               /* m */
    uint32_t corner_count;
    uint32_t patch;
    vec3 normal;                  /* unit */
    double offset;                /* normal . x on its plane, m */
    vec3 lo, hi;                  /* box, m */
} rad_direct_blocker;

typedef struct rad_direct_light {
    const rad_mesh *mesh;
    const rad_vis *vis;
    rad_direct_blocker *blocker;
    size_t blocker_count;
    rad_direct_source *source;
    size_t source_count;
    uint32_t *member;             /* the emitting elements, by source */
    double eps, plane_tol;        /* m: the shadow rays' lift, the plane tolerance */
    uint64_t seed;
} rad_direct_light;

/* Per-thread memory of recent receivers: the classification of a
 * receiver element's pairs with every source, made once and kept in one
 * of RAD_DIRECT_CACHE_WAYS slots (by the element's index), since
 * neighbouring pixels see the same few elements. */
enum { RAD_DIRECT_CACHE_WAYS = 32 };
typedef struct rad_direct_cache {
    uint32_t receiver[RAD_DIRECT_CACHE_WAYS]; /* UINT32_MAX: none yet */
    rad_ff_verdict *verdict;      /* per slot and source */
    rad_ff_blockers *blockers;    /* per slot and source: trimmed for the receiver */
} rad_direct_cache;

/* The emitting elements of `mesh` (self-emitted exitance `self`, 3 per
 * element: the emission less rho x the luminaires' direct light) and the
 * occluder tables.  *out is zeroed, and left with no sources, when nothing
 * emits or more than RAD_DIRECT_MAX_SOURCES elements do (then
 * rad_direct_light_active is false).  Fails only for memory. */
rad_result rad_direct_light_create(rad_context *ctx, const rad_mesh *mesh, const rad_vis *vis,
                                   const double *self, uint64_t seed, rad_direct_light *out);
void rad_direct_light_free(rad_direct_light *d);
static inline bool rad_direct_light_active(const rad_direct_light *d) { return d->source_count > 0; }

/* Can blocker b hide any segment between the hull of v[0 .. nr) and that
 * of v[nr .. nv) (nv <= 8)?  Conservative: false only when it cannot
 * (direct.c).  Cannot fail. */
bool rad_direct_may_block(const rad_direct_blocker *b, const vec3 *v, int nr, int nv, double tol);

/* A cache for one thread (rad_direct_cache_free).  Fails only for memory. */
rad_result rad_direct_cache_init(rad_context *ctx, const rad_direct_light *d, rad_direct_cache *cache);
void rad_direct_cache_free(rad_direct_cache *cache);

/* Direct irradiance from the emitters (W/m^2 RGB) at point p of element
 * `receiver` (p on it, n its normal).  Shadow rays, where needed, are keyed
 * on `key`.  Thread-safe with one cache per thread; cannot fail. */
void rad_direct_at(const rad_direct_light *d, rad_direct_cache *cache, uint32_t receiver, vec3 p,
                   uint64_t key, double rgb[3]);

/* The mean of rad_direct_at over each element (3 x 3 midpoints), 3 per
 * element, W/m^2; parallel on `threads`.  Fails only for memory. */
rad_result rad_direct_means(rad_context *ctx, const rad_direct_light *d, int threads, double *mean);


/* The residual from a gather instead (indirect.c): residual_i = self_i +
 * rho_i (direct_i + I_i), I_i the irradiance at element i's centroid from
 * every element's reflected radiosity B_j - self_j (display: B, 3 per
 * element) through Lambert's factor (the point kernel beyond 3 diameters),
 * visibility from the blockers listed for the pair of patches (clear pairs:
 * none; else the segment between the centroids against each); direct: the
 * luminaires' and daylight's mean irradiance (NULL: none).  The solution's
 * elements are then only sources, where their errors average out.  *gathered
 * false (and nothing written) where the mesh has more than
 * RAD_INDIRECT_MAX_PATCHES patches or RAD_INDIRECT_MAX_ELEMENTS elements
 * (the gather is O(n^2): 8,192 elements take about 15 s on one core).
 * Fails only for memory. */
#define RAD_INDIRECT_MAX_PATCHES 512
#define RAD_INDIRECT_MAX_ELEMENTS 8192
/* The gathering factors are kept for the sweeps (render.h) up to this many
 * bytes (4,096 elements), and the sweeps made: */
#define RAD_INDIRECT_DENSE_BYTES (64.0 * 1024 * 1024)
#ifndef RAD_INDIRECT_SWEEPS
#define RAD_INDIRECT_SWEEPS 2
#endif
rad_result rad_indirect_residual(rad_context *ctx, const rad_direct_light *d, const double *display,
                                 const double *self, const double *reflectance, const double *direct, int threads,
                                 double *residual, bool *gathered);

/* The mesh a picture of a hierarchical solution is gathered on (its leaves
 * are as coarse as the links allowed: a block's face in indirect light can
 * be a few leaves, too few to draw the light across it): a uniform mesh of
 * about RAD_RENDER_MESH_ELEMENTS of the same patches (or as many as the
 * leaves, if more).  *out NULL (and RAD_OK) where the solved mesh is not a
 * leaf mesh, is beyond the gather's limits, or the patches would differ.
 * Fails only for memory (then *out NULL). */
#define RAD_RENDER_MESH_ELEMENTS 2000
rad_result rad_render_mesh_create(rad_context *ctx, const rad_scene *scene, const rad_mesh *solved,
                                  double crease_angle_degrees, rad_mesh **out);

/* The solved mesh's values at each element centroid of `mesh` (the same
 * patches): value (3 per element) interpolated from vertex_value as smooth
 * shading does, and out[a] (3 per element) the value of per_element[a] (3
 * per solved element; NULL: zeros) of the element holding the centroid.
 * Cannot fail. */
void rad_render_mesh_sample(const rad_mesh *solved, const double *vertex_value, const double *per_element[],
                            int arrays, const rad_mesh *mesh, double *value, double *out[]);

#endif /* RAD_RENDER_H */
