/*
 * daylight.c -- PLACEHOLDER: the daylight engineer writes the CIE sky and
 * the sun through the scene's openings here.
 */
#include "light/light.h"

void rad_daylight_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                             vec3 n, double out[3])
{
    (void)scene, (void)mesh, (void)vis, (void)p, (void)n;
    out[0] = out[1] = out[2] = 0.0;
}

void rad_daylight_sky_horizontal(const rad_scene *scene, double out[3])
{
    (void)scene;
    out[0] = out[1] = out[2] = 0.0;
}
