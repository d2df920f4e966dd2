/*
 * direct.c -- the scene's direct light (light.h): the sum over its kinds of
 * source at a point, and the mean over an element.
 */
#include "light/light.h"

#include <string.h>

bool rad_light_present(const rad_scene *scene)
{
    return scene && (scene->luminaire_count > 0 || scene->daylight != NULL);
}

void rad_light_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                          vec3 n, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    if (!rad_light_present(scene))
        return;
    double part[3];
    if (scene->luminaire_count > 0) {
        rad_luminaires_irradiance(scene, mesh, vis, p, n, part);
        for (int c = 0; c < 3; c++)
            out[c] += part[c];
    }
    if (scene->daylight) {
        rad_daylight_irradiance(scene, mesh, vis, p, n, part);
        for (int c = 0; c < 3; c++)
            out[c] += part[c];
    }
}

/* PLACEHOLDER (the luminaires engineer replaces it with adaptive cubature):
 * the value at the element's centroid. */
void rad_light_element_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis,
                                  size_t element, double out[3])
{
    const rad_element *e = &mesh->elements[element];
    rad_light_irradiance(scene, mesh, vis, e->centroid, e->normal, out);
}
