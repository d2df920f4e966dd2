/*
 * luminaire.c -- PLACEHOLDER: the luminaires engineer writes the direct
 * light of placed luminaires here (goniometric point source beyond five
 * times the luminous size, area source nearer; shadow rays).
 */
#include "light/light.h"

void rad_luminaires_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                               vec3 n, double out[3])
{
    (void)scene, (void)mesh, (void)vis, (void)p, (void)n;
    out[0] = out[1] = out[2] = 0.0;
}
