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

/* The same mean over a planar polygon: `corners` (3 or 4) points,
 * counter-clockwise about the unit normal `normal` (a hierarchical node's,
 * which is no element of `mesh`; mesh only scales the rays' lift).  When
 * deviation is not NULL it gets the largest difference, over the channels
 * and the points the cubature evaluated, between the irradiance there and
 * the mean (W/m^2): how far the light varies across the polygon (a shadow
 * edge crossing it gives about the step's size).  A degenerate polygon
 * gives zeros.  `set`: the luminaires let in (below; NULL: all).
 * `depth`: levels of the cubature's refinement at most (0: all four; 2 is
 * enough to see that the light varies, at a sixteenth of the points on a
 * shadow edge).  Thread-safe, deterministic. */
struct rad_light_among;
void rad_light_polygon_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis,
                                  const vec3 *corner, uint32_t corners, vec3 normal,
                                  const struct rad_light_among *set, int depth, double out[3],
                                  double *deviation);

/* Which luminaires a caller lets light a point, and which did (bit k of
 * word k / 64: luminaire k of scene->luminaires).  `among` NULL: all of
 * them; `reached`, when not NULL, gets the bits of those whose light
 * reached some point asked (a clear shadow ray, in front of the surface).
 * The hierarchy asks its roots with reached, then their nodes among what
 * their root saw (hier/direct.c).  Daylight is not a luminaire: always. */
typedef struct rad_light_among {
    const uint64_t *among;
    uint64_t *reached;
} rad_light_among;
/* Words of a luminaire mask for the scene. */
size_t rad_light_mask_words(const rad_scene *scene);
/* rad_light_irradiance for the luminaires `set` lets in (NULL: all). */
void rad_light_irradiance_among(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                                vec3 n, const rad_light_among *set, double out[3]);
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
