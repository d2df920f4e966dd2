/*
 * vpl.h -- instant radiosity (Keller 1997): the light that has bounced at
 * least once, represented by virtual point lights (VPLs) placed along
 * quasi-random light paths from the emitters, and gathered with shadow
 * rays; the emitters' own light is gathered exactly (point-to-polygon
 * factors and shadow rays).  The instant-radiosity strategy gathers per
 * element (view-independent), the renderer per pixel (view-dependent).
 *
 * Conventions of docs/methods.md, "Instant radiosity": a VPL of power Phi
 * (W) at y, normal n_y, is a cosine-weighted (Lambertian) point source: it
 * gives a point x of normal n_x the irradiance
 *
 *     H = Phi cos(theta_x) cos(theta_y) / (pi max(r^2, r_c^2)) V(x, y)
 *
 * where r_c, the clamping radius, bounds the 1/r^2 singularity.  The
 * clamp removes the fraction 1 - r^2 / r_c^2 of what a VPL nearer than r_c
 * gives: a bias (energy lost) that the gathers measure and that the
 * strategy (strategy/instant.c) and the renderer recover from rays into
 * the near field.
 */
#ifndef RAD_VPL_H
#define RAD_VPL_H

#include "mesh/mesh.h"
#include "vis/vis.h"

typedef struct rad_vpl {
    vec3 position;            /* m, lifted off its surface by the ray epsilon */
    vec3 normal;              /* unit */
    double power[3];          /* W, RGB: the power it reflects */
} rad_vpl;

/* The virtual point lights of one seed and path count, and the emitters
 * whose direct light is gathered exactly. */
typedef struct rad_vpl_set {
    rad_vpl *lights;
    size_t count;             /* VPLs (about paths / (1 - mean reflectance) - paths) */
    size_t paths;             /* light paths traced from the emitters */
    uint32_t *emitter_patches;/* patches holding emission (an emitter's elements share its value; a
                                 residual source's may not, rad_vpl_direct) */
    size_t emitter_count;
    double clamp_radius;      /* r_c, m: sqrt(total area / (pi count)), the radius of the
                                 disk of surface one VPL stands for */
    double emitted;           /* W, mean over RGB */
    uint64_t rays;            /* rays cast to place the VPLs */
} rad_vpl_set;

/* Trace `paths` light paths from the emitting elements (chosen by power,
 * points and directions from a Halton sequence rotated by `seed`), one VPL
 * at each diffuse bounce, Russian roulette by the largest reflectance,
 * systematic over each generation of paths (vpl.c).  Arrays
 * are per element (3n RGB), as the strategies hold them.  Deterministic
 * for a seed.  On failure *out is zeroed and nothing leaks. */
rad_result rad_vpl_create(rad_context *ctx, const rad_mesh *mesh, const rad_vis *vis, const double *reflectance,
                          const double *emission, size_t paths, uint64_t seed, rad_vpl_set *out);
void rad_vpl_free(rad_vpl_set *set);

/* Irradiance (W/m^2, RGB) at point x (normal n, on the front of its
 * surface, already lifted off it) from the emitters directly: the exact
 * point-to-polygon factor of each emitter less the part `shadow_rays`
 * rays to random points of it find blocked (unbiased; exact where nothing
 * blocks; a single point in deep shadow may come out slightly negative,
 * its expectation is not).  `emission` is the per-element array, signed
 * and varying over a patch as the control variate's residual source may
 * be (the variation is estimated by the same rays).  Cannot fail. */
void rad_vpl_direct(const rad_vpl_set *set, const rad_mesh *mesh, const rad_vis *vis, const double *emission,
                    vec3 x, vec3 n, int shadow_rays, rad_rng *rng, double H[3]);

/* The shadow ray from x (normal n, lifted) to VPL `l`, and its kernels
 * cos cos / (pi max(r^2, r_c^2)) into *g and cos cos / (pi r^2) into
 * *g_raw (1/m^2).  False (no ray) where either side faces away. */
bool rad_vpl_ray(const rad_vpl_set *set, const rad_vpl *l, vec3 x, vec3 n, rad_ray *ray, double *g, double *g_raw);

/* Irradiance (W/m^2, RGB) at x (normal n, lifted) from VPLs [first,
 * first + count): clamped into H, unclamped into H_raw.  `rays` holds
 * count rays and `blocked` count flags (the caller's scratch).  Cannot
 * fail. */
void rad_vpl_gather(const rad_vpl_set *set, const rad_vis *vis, vec3 x, vec3 n, size_t first, size_t count,
                    rad_ray *rays, uint8_t *blocked, double H[3], double H_raw[3]);

#endif /* RAD_VPL_H */
