/*
 * daylight.h -- the daylight of a scene (docs/lighting.md "Daylight"): a
 * CIE sky, optionally the sun as parallel light, optionally a uniform
 * ground below the horizon, and the openings through which they enter.
 *
 * This is the model; the daylight file (light/daylight_file.c) is read against a loaded scene: the
 * surfaces it marks as openings (by name, or by material) leave the scene
 * -- they are holes, meshed by nothing and blocking no ray -- and are kept
 * here, split into triangles and quads, for the integration of the sky
 * over them (light/daylight.c).  The sky's luminance is evaluated by
 * light/sky.c; rad_sky_prepare (there) sets its absolute scale.
 *
 *        sky (L(d), above the horizon)      sun (direction s, E_n)
 *              \   |   /                      \
 *      ---------[opening]------- roof          \  parallel rays
 *              /   |   \                        \
 *             p  (room)            ground (rho_g E_h,global / pi) below
 */
#ifndef RAD_SCENE_DAYLIGHT_H
#define RAD_SCENE_DAYLIGHT_H

#include "scene/scene.h"

/* The sky's luminance model. */
typedef enum rad_sky_model {
    RAD_SKY_CIE_GENERAL = 0,  /* CIE S 011/E:2003 (ISO 15469:2004) standard general sky, types 1-15 */
    RAD_SKY_CIE_OVERCAST      /* the traditional CIE overcast sky (Moon & Spencer 1942):
                                 L = Lz (1 + 2 cos Z) / 3 */
} rad_sky_model;

typedef struct rad_sky {
    rad_sky_model model;
    int type;                 /* general sky: 1..15 (CIE S 011 Table 1); 0 for the overcast model */
    double a, b, c, d, e;     /* the general sky's gradation (a, b) and indicatrix (c, d, e) */
    vec3 up, north, east;     /* unit, world: zenith, north and east directions (east = north x up) */
    vec3 sun;                 /* unit, world: toward the sun (also for skies that ignore it) */
    double sun_zenith;        /* rad, Zs in [0, pi/2) */
    double sun_azimuth;       /* rad, from north through east */
    double norm;              /* 1 / (f(Zs) phi(0)): the general sky's relative-luminance divisor */
    double zenith_radiance;   /* W/(m^2 sr) on each channel: Lz (cd/m^2) / 179 */
    double horizontal;        /* W/m^2 on each channel: the unobstructed sky's horizontal irradiance */
} rad_sky;

/* One piece of an opening: a triangle or a convex quad of the polygon the
 * file marked. */
typedef struct rad_opening {
    vec3 corner[4];           /* m */
    uint32_t corner_count;    /* 3 or 4 */
    vec3 normal;              /* unit, as the scene's polygon had it */
    double area;              /* m^2 */
    uint32_t surface;         /* index into rad_daylight.opening_names */
} rad_opening;

struct rad_daylight {
    char *source;             /* the daylight file's name, for messages */
    rad_sky sky;
    double sun_normal;        /* W/m^2 on each channel: the sun's direct normal illuminance / 179;
                                 0: no sun (the sky may still depend on its position) */
    bool ground;              /* directions below the horizon see a uniform ground */
    double ground_reflectance;/* rho_g, [0, 1] */
    double ground_radiance;   /* W/(m^2 sr): rho_g (E_h,sky + E_n cos Zs) / pi, set by rad_sky_prepare */
    double zenith_luminance;  /* cd/m^2 as the file gives it; 0: scaled by diffuse_illuminance */
    double diffuse_illuminance; /* lux: the sky's horizontal illuminance as the file gives it */
    double tolerance;         /* relative accuracy of the integrations, (0, 0.1] */
    rad_opening *openings;
    size_t opening_count;
    char **opening_names;     /* the surfaces that became openings */
    size_t opening_name_count;
    uint8_t *marked;          /* per scene polygon, 1: an opening's; freed once attached */
    size_t marked_count;
};

typedef struct rad_daylight rad_daylight;

/* Free the daylight and what it holds (scene/daylight.c).  NULL: no-op. */
void rad_daylight_free(rad_daylight *daylight);

#endif
