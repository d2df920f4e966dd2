/*
 * photometry.h -- a luminaire's luminous intensity distribution, as read
 * from a photometric file (IES LM-63 1995/2002/2019, EULUMDAT), expanded to
 * the whole sphere and evaluated in any direction.
 *
 * Frame (docs/lighting.md, "Photometric files"): the luminaire's own axes
 * are x (photometric C = 0, the luminaire's length), y (C = 90, counter-
 * clockwise seen from above) and z (up); the nadir, where a type C file's
 * gamma = 0, is -z.  Type B and A files (floodlights) measure about their
 * photometric axis (H = V = 0), which is the nadir -z here; type B's polar
 * axis (H = 90) is +y, type A's (V = 90) is +x.  The readers convert every
 * type to one table over (C, gamma) so that evaluation is one bilinear
 * lookup.
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

/* Where a distribution came from (rad_photometry.format). */
typedef enum rad_photometric_format {
    RAD_PHOTOMETRY_TABLE = 0, /* rad_photometry_from_table */
    RAD_PHOTOMETRY_IES = 1,   /* IES LM-63 (.ies) */
    RAD_PHOTOMETRY_LDT = 2    /* EULUMDAT (.ldt) */
} rad_photometric_format;

/* The luminous opening's shape (docs/lighting.md, "Photometric files"),
 * from the signs of an IES file's width, length and height (LM-63-2019's
 * table of luminous shapes; the same signs in earlier versions) or from
 * an EULUMDAT file's zero width (round).  width, length and height of
 * rad_photometry are always >= 0: the extents of the shape's bounding box
 * along y, x and z (a diameter where the shape is round). */
typedef enum rad_luminous_shape {
    RAD_OPENING_POINT = 0,          /* 0 0 0 */
    RAD_OPENING_RECTANGLE,          /* W > 0, L > 0, H = 0: horizontal, facing down */
    RAD_OPENING_BOX,                /* W, L, H >= 0 otherwise: rectangle with luminous sides */
    RAD_OPENING_ELLIPSE,            /* W < 0, L < 0, H = 0: horizontal disc (circle when W = L) */
    RAD_OPENING_VERTICAL_CYLINDER,  /* W < 0, L < 0, H > 0: axis z, diameters W (y) and L (x) */
    RAD_OPENING_ELLIPSOID,          /* W < 0, L < 0, H < 0: sphere when all equal */
    RAD_OPENING_CYLINDER_X,         /* W < 0, L > 0, H < 0: axis x (length L), diameters W, H */
    RAD_OPENING_CYLINDER_Y,         /* W > 0, L < 0, H < 0: axis y (length W), diameters L, H */
    RAD_OPENING_VERTICAL_ELLIPSE_X, /* W < 0, L = 0, H < 0: vertical disc facing +-x */
    RAD_OPENING_VERTICAL_ELLIPSE_Y  /* W = 0, L < 0, H < 0: vertical disc facing +-y */
} rad_luminous_shape;

typedef struct rad_photometry {
    char *source;              /* the file as named */
    char *label;               /* the luminaire's name from the file ([LUMINAIRE], EULUMDAT name), may be "" */
    rad_photometric_type type; /* as the file says; the table below is type C whatever it was */
    /* The table over the whole sphere after symmetry expansion and type
     * conversion: C in [0, 360] degrees (c_count >= 1; one plane =
     * rotationally symmetric), C strictly increasing from 0 to 360; gamma
     * in [0, 180] degrees from nadir, non-decreasing: two equal gamma
     * angles in a row are a step (the edge of a hemisphere a file leaves
     * out, whose candela are 0), never three.  The readers' tables run
     * from 0 to 180; a table that stops short of a pole holds its end
     * values beyond (evaluation and flux alike).
     * candela[ic * gamma_count + ig]. */
    size_t c_count, gamma_count;
    double *c_angles, *gamma_angles;
    double *candela;           /* cd, multipliers applied, tilt not applied */
    double flux;               /* lm: the table integrated over the sphere (exactly, the
                                  bilinear surface times sin gamma in closed form) */
    double rated_lumens;       /* lm: the lamps' rated flux (lamp lumens x count), 0 if
                                  absolute photometry (IES -1, EULUMDAT negative lamp count) */
    /* Luminous opening, m (docs/lighting.md): width along y, length along x,
     * height along z; 0 0 0 = a point.  Always >= 0: the extents of the
     * opening's bounding box; `shape` says what fills it (a round opening
     * has its diameters here). */
    double width, length, height;
    /* IES TILT=INCLUDE or file: lamp-to-luminaire geometry and the
     * multiplier at each tilt angle (degrees); tilt_count 0 = none. */
    int tilt_geometry;
    size_t tilt_count;
    double *tilt_angles, *tilt_factors;

    /* ---- what the file said, for summaries (the table above is what
     * evaluation uses) ---- */
    rad_photometric_format format;
    char version[24];          /* "LM-63-2002", "LM-63-1986", "EULUMDAT", "table" */
    char symmetry[64];         /* "rotational", "quadrant (C 0-90)", ... */
    rad_luminous_shape shape;
    size_t file_horizontal_count, file_vertical_count; /* angle counts as in the file (LDT: C, gamma) */
    double file_horizontal_min, file_horizontal_max;   /* degrees, as in the file */
    double file_vertical_min, file_vertical_max;       /* degrees, as in the file */
    double multiplier;         /* 1: the product applied to the file's values to make candela */
    double input_watts;        /* W: the file's input power (0 if not given) */
    double stated_lor;         /* 1: the file's light output ratio (EULUMDAT LORL / 100); -1 none */
    char tilt_source[64];      /* "none", "include" or the tilt file's name as written */
} rad_photometry;

/* The light output ratio: flux / rated_lumens (0 without rated lumens). */
double rad_photometry_lor(const rad_photometry *p);

/* The largest candela of the table and its direction (C, gamma in degrees
 * of the table's frame); the maximum of a bilinear table is at a node.
 * Cannot fail. */
double rad_photometry_max(const rad_photometry *p, double *c_degrees, double *gamma_degrees);

/* Candela in direction `d` of the luminaire's frame (need not be unit; a
 * zero vector gives 0): bilinear in (C, gamma) over the table.
 * Thread-safe. */
double rad_photometry_intensity(const rad_photometry *p, vec3 d);

/* The TILT multiplier for a luminaire tilted `degrees` from its
 * photometric orientation (1 without tilt data). */
double rad_photometry_tilt_factor(const rad_photometry *p, double degrees);

/* A distribution from a full table (type C, C in [0, 360] or one plane,
 * gamma in [0, 180], as the struct's comment says, steps allowed); copies
 * the arrays; flux is integrated; the summary fields say "table".  For
 * tests and for the readers.  NULL when out of memory or the table is not valid
 * (RAD_ERROR_INVALID_ARGUMENT in *err when err is not NULL). */
rad_photometry *rad_photometry_from_table(rad_context *ctx, const char *source, size_t c_count,
                                          const double *c_angles, size_t gamma_count,
                                          const double *gamma_angles, const double *candela,
                                          rad_result *err);

/* Read an IES LM-63 (.ies) or EULUMDAT (.ldt) file, told by content
 * (an IES file's first line, or its TILT= line; else EULUMDAT).  Errors
 * name the file and line (the context's error message), RAD_ERROR_PARSE
 * for malformed content, RAD_ERROR_IO when unreadable; *out NULL then.
 * A file's lumens that disagree with its stated light output ratio are a
 * warning (rad_warn), not a failure. */
rad_result rad_photometry_load(rad_context *ctx, const char *path, rad_photometry **out);

/* The same from memory: `name` names it in messages; `folder` is where an
 * IES TILT=<file> is looked for (NULL: such a file is refused). */
rad_result rad_photometry_parse(rad_context *ctx, const char *name, const char *folder,
                                const char *data, size_t size, rad_photometry **out);

void rad_photometry_free(rad_photometry *p);

#endif
