/*
 * sky.h -- the luminance of the CIE skies and their absolute scale
 * (light/sky.c; the parameters are scene/daylight.h's rad_sky).
 */
#ifndef RAD_LIGHT_SKY_H
#define RAD_LIGHT_SKY_H

#include "scene/daylight.h"

/* The sky's luminance relative to its zenith's, L(d) / Lz, for a unit
 * world direction d; 0 at and below the horizon.  Cannot fail. */
double rad_sky_relative(const rad_sky *sky, vec3 d);

/* The sky's radiance W/(m^2 sr) (on each channel) in direction d; below
 * the horizon the daylight's ground (or 0).  Cannot fail. */
double rad_daylight_radiance(const rad_daylight *daylight, vec3 d);

/* The integral over the sky of rad_sky_relative(d) cos Z d(omega) (the
 * horizontal illuminance of a sky of unit zenith luminance), by product
 * Gauss-Legendre (`order` nodes towards the horizon, 4 x order azimuths,
 * trapezoidal, periodic) in polar coordinates about the sun, where the
 * indicatrix has its cusp: the integrand is smooth in them up to the
 * horizon.  order 0: 64, which agrees with 128 to 2.4e-11 for every type
 * (tests/test_daylight.c).  Cannot fail. */
double rad_sky_relative_horizontal(const rad_sky *sky, int order);

/* Set the absolute scale of daylight->sky from the file's zenith_luminance
 * (cd/m^2) when positive, else from its diffuse_illuminance (lux); then
 * the sky's horizontal irradiance and the ground's radiance.  Cannot fail. */
void rad_sky_prepare(rad_daylight *daylight);

#endif
