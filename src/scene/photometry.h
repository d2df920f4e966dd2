/*
 * photometry.h -- a luminaire's luminous intensity distribution, as read
 * from a photometric file (IES LM-63 1995/2002/2019, EULUMDAT), expanded to
 * the whole sphere and evaluated in any direction.
 *
 * Frame (docs/lighting.md, "Luminaires"): the luminaire's own axes are
 * x (photometric C = 0, the luminaire's length), y (C = 90, counter-
 * clockwise seen from above) and z (up); the nadir, where a type C file's
 * gamma = 0, is -z.  Type B files (floodlights) measure from +x as their
 * axis of symmetry... the readers convert every type to one table over
 * (C, gamma) so that evaluation is one bilinear lookup.
 *
 * Units: candela, as the file gives them times its multipliers; the
 * engine's W/sr per channel are candela / RAD_LUMINOUS_EFFICACY on all three
 * channels (docs/units.md, "Photometry").
 */
#ifndef RAD_PHOTOMETRY_H
#define RAD_PHOTOMETRY_H

#include "core/core.h"

/* lm/W: radiometric W/m^2 of the engine's RGB times this times the
 * luminance weights below is lux (Radiance's white efficacy). */
#define RAD_LUMINOUS_EFFICACY 179.0
/* Y = RAD_Y_R R + RAD_Y_G G + RAD_Y_B B (Radiance's primaries; sum 1). */
#define RAD_Y_R 0.265
#define RAD_Y_G 0.670
#define RAD_Y_B 0.065

typedef enum rad_photometric_type {
    RAD_PHOTOMETRY_C = 1,  /* vertical angle from nadir, C planes about the vertical axis */
    RAD_PHOTOMETRY_B = 2,  /* horizontal axis (floodlights) */
    RAD_PHOTOMETRY_A = 3   /* horizontal axis (automotive) */
} rad_photometric_type;

typedef struct rad_photometry {
    char *source;              /* the file as named */
    char *label;               /* the luminaire's name from the file ([LUMINAIRE], EULUMDAT name), may be "" */
    rad_photometric_type type; /* as the file says; the table below is type C whatever it was */
    /* The table over the whole sphere after symmetry expansion and type
     * conversion: C in [0, 360] degrees (c_count >= 1; one plane =
     * rotationally symmetric), gamma in [0, 180] degrees from nadir, both
     * increasing; candela[ic * gamma_count + ig]. */
    size_t c_count, gamma_count;
    double *c_angles, *gamma_angles;
    double *candela;           /* cd, multipliers applied, tilt not applied */
    double flux;               /* lm: the table integrated over the sphere */
    double rated_lumens;       /* lm: the lamps' rated flux (lamp lumens x count), 0 if
                                  absolute photometry (IES -1) */
    /* Luminous opening, m (docs/lighting.md): width along y, length along x,
     * height along z; 0 0 0 = a point.  Negative IES values (round shapes)
     * are kept as the reader documents. */
    double width, length, height;
    /* IES TILT=INCLUDE or file: lamp-to-luminaire geometry and the
     * multiplier at each tilt angle (degrees); tilt_count 0 = none. */
    int tilt_geometry;
    size_t tilt_count;
    double *tilt_angles, *tilt_factors;
} rad_photometry;

/* Candela in direction `d` of the luminaire's frame (need not be unit; a
 * zero vector gives 0): bilinear in (C, gamma) over the table.
 * Thread-safe. */
double rad_photometry_intensity(const rad_photometry *p, vec3 d);

/* The TILT multiplier for a luminaire tilted `degrees` from its
 * photometric orientation (1 without tilt data). */
double rad_photometry_tilt_factor(const rad_photometry *p, double degrees);

/* A distribution from a full table (type C, C in [0, 360] or one plane,
 * gamma in [0, 180]); copies the arrays; flux is integrated.  For tests and
 * for the readers.  NULL when out of memory or the table is not valid
 * (RAD_ERROR_INVALID_ARGUMENT in *err when err is not NULL). */
rad_photometry *rad_photometry_from_table(rad_context *ctx, const char *source, size_t c_count,
                                          const double *c_angles, size_t gamma_count,
                                          const double *gamma_angles, const double *candela,
                                          rad_result *err);

/* Read an IES LM-63 (.ies) or EULUMDAT (.ldt) file, told by content.
 * Errors name the file and line (the context's error message). */
rad_result rad_photometry_load(rad_context *ctx, const char *path, rad_photometry **out);

void rad_photometry_free(rad_photometry *p);

#endif
