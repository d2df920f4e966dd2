/*
 * light.h -- direct light from sources that are not elements: luminaires
 * (goniometric point sources, area sources near their opening) and
 * daylight (the CIE sky and the sun, through openings).
 *
 * The pipeline asks two questions of a scene's light (docs/lighting.md):
 *
 *   rad_light_irradiance          direct irradiance at a point with a normal
 *                                 (calculation points; exact: candela,
 *                                 inverse square, cosine, shadow rays)
 *   rad_light_element_irradiance  its mean over an element, which the
 *                                 strategies add to the element's emission
 *                                 as its first reflection, E += rho H
 *
 * so the interreflection is the radiosity solution and calculation points
 * get the direct part exactly.  Units: W/m^2 per channel, the engine's
 * (docs/units.md "Photometry": lux = 179 x Y).
 *
 * Folder order: core -> scene -> mesh -> vis -> formfactor -> light -> solve.
 */
#ifndef RAD_LIGHT_H
#define RAD_LIGHT_H

#include "scene/scene.h"
#include "mesh/mesh.h"
#include "vis/vis.h"

/* Whether the scene has light besides its emitting surfaces. */
bool rad_light_present(const rad_scene *scene);

/* Direct irradiance (W/m^2 RGB) at point p, on a surface of unit normal n
 * (light from behind it counts zero), from every luminaire and from the
 * daylight of `scene`; shadow rays through vis (built over mesh; vis NULL:
 * no shadows).  p lies on a surface or in free space; rays start
 * rad_vis_epsilon(mesh) off it along n (mesh NULL: on it).  Thread-safe,
 * deterministic. */
void rad_light_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                          vec3 n, double out[3]);

/* The mean of rad_light_irradiance over element `element` of mesh
 * (adaptive cubature over its polygon).  Thread-safe, deterministic. */
void rad_light_element_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis,
                                  size_t element, double out[3]);

/* Which luminaires a caller lets light a point (daylight is not a
 * luminaire: always).  `list`: these `count` luminaires only (indices into
 * scene->luminaires); else, with `reach`: those whose reach holds the point
 * (below); else all of them.  The hierarchy asks each node among its
 * patch's list, the grid's points by the reach (hier/direct.c,
 * grid/gather.c). */
typedef struct rad_light_reach rad_light_reach;
typedef struct rad_light_among {
    const uint32_t *list;
    size_t count;
    const rad_light_reach *reach;
} rad_light_among;
/* rad_light_irradiance for the luminaires `set` lets in (NULL: all). */
void rad_light_irradiance_among(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                                vec3 n, const rad_light_among *set, double out[3]);

/* The same mean over a planar polygon: `corners` (3 or 4) points,
 * counter-clockwise about the unit normal `normal` (a hierarchical node's,
 * which is no element of `mesh`; mesh only scales the rays' lift).  When
 * deviation is not NULL it gets the largest difference, over the channels
 * and the points the cubature evaluated, between the irradiance there and
 * the mean (W/m^2): how far the light varies across the polygon (a shadow
 * edge crossing it gives about the step's size).  A degenerate polygon
 * gives zeros.  `set`: the luminaires let in (above; NULL: all).
 * Thread-safe, deterministic. */
void rad_light_polygon_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis,
                                  const vec3 *corner, uint32_t corners, vec3 normal,
                                  const rad_light_among *set, double out[3], double *deviation);

/* The same cubature in two steps, for a caller that may split the polygon
 * before it needs the mean to the full tolerance (the hierarchy: a node
 * whose light varies is split, and its children carry the light).
 * _start evaluates the fixed rule over the polygon and over its four
 * children (rad_ff_split4), 16 to 20 points: `mean` and `deviation` from
 * those; _finish refines from there where the children disagree, as
 * rad_light_polygon_irradiance does, without evaluating a point twice (the
 * same result as the one call), until the children agree within 1e-3 of
 * the polygon's light or within `tolerance` (W per channel, of the
 * integral over the polygon), whichever is looser.  `cub` holds what lies between. */
typedef struct rad_light_cubature {
    double whole[3];      /* W per channel: the fixed rule over the polygon */
    double part[4][3];    /* W: over its children */
    double area;          /* m^2; 0: degenerate, nothing to refine */
    double lo[3], hi[3];  /* W/m^2: the range of the values at the points */
} rad_light_cubature;
void rad_light_polygon_start(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis,
                             const vec3 *corner, uint32_t corners, vec3 normal, const rad_light_among *set,
                             rad_light_cubature *cub, double mean[3], double *deviation);
void rad_light_polygon_finish(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis,
                              const vec3 *corner, uint32_t corners, vec3 normal, const rad_light_among *set,
                              double tolerance, rad_light_cubature *cub, double mean[3], double *deviation);

/* Where each luminaire's light can arrive (reach.c): a box per luminaire,
 * the bounds of a fan of rays from its centre to what they first hit,
 * widened by the fan's angular spacing times the distance and by the
 * luminaire's size; everywhere for a luminaire some ray of whose fan
 * leaves the scene.  A point outside a luminaire's box gets none of its
 * light save through a gap the fan passed between (docs/lighting.md
 * "Reach").  So a building's rooms ask their own and their neighbours'
 * luminaires, not all of them.  Fails for memory or cancellation. */
rad_result rad_light_reach_build(rad_context *ctx, const rad_scene *scene, const rad_mesh *mesh,
                                 const rad_vis *vis, int threads, rad_light_reach **out);
void rad_light_reach_destroy(rad_light_reach *reach);
/* Whether luminaire k's reach holds p / meets the box [lo, hi]. */
bool rad_light_reach_holds(const rad_light_reach *reach, size_t k, vec3 p);
bool rad_light_reach_meets(const rad_light_reach *reach, size_t k, vec3 lo, vec3 hi);
/* The luminaires whose box meets [lo, hi], in index order, into out (room
 * for all of them); returns how many. */
size_t rad_light_reach_list(const rad_light_reach *reach, vec3 lo, vec3 hi, uint32_t *out);
/* Luminaires whose box is everywhere. */
size_t rad_light_reach_everywhere(const rad_light_reach *reach);

/* The parts, one file each. */
void rad_luminaires_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                               vec3 n, double out[3]);
void rad_luminaires_irradiance_among(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                                     vec3 n, const rad_light_among *set, double out[3]);           /* light/luminaire.c */
void rad_daylight_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                             vec3 n, double out[3]);             /* light/daylight.c */

/* The horizontal irradiance (W/m^2 RGB) outdoors under the unobstructed sky
 * of the scene's daylight, the sun excluded: the daylight factor's
 * denominator.  Zero without daylight.  (light/daylight.c) */
void rad_daylight_sky_horizontal(const rad_scene *scene, double out[3]);

#endif
