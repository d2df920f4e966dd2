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

/* ---- the daylight file (daylight_file.c) ---- */

/* The general sky's parameters (a, b, c, d, e) of type 1..15 into p[5];
 * false for another type.  Cannot fail otherwise. */
bool rad_sky_type_parameters(int type, double p[5]);

/* The sun's position by the NOAA solar calculator's formulas (Spencer's
 * 1971 series for the declination and the equation of time): latitude
 * (deg, north > 0), longitude (deg, east > 0), day of year 1..366, local
 * clock time in hours, time zone in hours east of UTC.  Out: the zenith
 * angle and the azimuth from north through east, rad.  Cannot fail. */
void rad_sun_position(double latitude, double longitude, int day_of_year, double hours, double timezone,
                      double *zenith, double *azimuth);

/* Read a daylight file's text against `scene` (name: the file, for
 * messages) into a new rad_daylight (*out), the sky not yet scaled
 * (rad_sky_prepare).  The scene is not changed.  Fails with
 * RAD_ERROR_PARSE, a one-line message naming the file and the key;
 * RAD_ERROR_OUT_OF_MEMORY.  On failure *out is NULL. */
rad_result rad_daylight_parse(rad_context *ctx, const rad_scene *scene, const char *name, const char *text,
                              size_t size, rad_daylight **out);

/* Move the openings out of `scene` into `daylight` and attach it
 * (scene->daylight; a previous one is freed, its openings carried over
 * into `daylight`): the marked polygons leave
 * the scene, surfaces left with none are removed (the others renumbered),
 * the bounds are recomputed, the file is added to the scene's inputs.
 * Fails with RAD_ERROR_INVALID_SCENE when nothing would be left,
 * RAD_ERROR_OUT_OF_MEMORY; on failure the scene is unchanged and
 * `daylight` is freed. */
rad_result rad_scene_attach_daylight(rad_context *ctx, rad_scene *scene, rad_daylight *daylight,
                                     const char *path);

#endif
