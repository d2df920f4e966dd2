/*
 * photometry_internal.h -- what the photometric readers (ies.c,
 * eulumdat.c) share with photometry.c: a number reader that knows its
 * line, the expansion of a file's symmetric planes to the full table, and
 * the summary fields.  Not API; scene/ only.
 */
#ifndef RAD_PHOTOMETRY_INTERNAL_H
#define RAD_PHOTOMETRY_INTERNAL_H

#include "photometry/photometry.h"

#include <stdbool.h>

/* Text being read: numbers separated by blanks (and commas where
 * `comma_separates`), over any lines; `line` is the 1-based line of `at`. */
typedef struct ph_text {
    rad_context *ctx;
    const char *name;     /* the file, for messages */
    const char *data;
    size_t size, at, line;
    bool comma_separates; /* IES: ',' separates numbers; EULUMDAT: ',' is a decimal point */
    size_t token_line;    /* the line of the last number read (0: none yet) */
} ph_text;

/* The next line's text (without its end of line) in *start, *length;
 * false at the end of the data.  *line_number: the line it is on. */
bool ph_next_line(ph_text *t, const char **start, size_t *length, size_t *line_number);

/* Checks ph_read_numbers makes as it reads. */
enum { PH_NONNEGATIVE = 1, PH_INCREASING = 2 };

/* Read `count` numbers into out[]; `what` names them in the message
 * ("vertical angles"): "lamp.ies:12: expected 37 vertical angles, found 12
 * (the file ends)".  Non-finite numbers are refused, and with `checks`
 * negative ones or ones not above the one before, at their line.
 * RAD_ERROR_PARSE. */
rad_result ph_read_numbers(ph_text *t, size_t count, double *out, const char *what, int checks);

/* One number: the line it was on in *line when line is not NULL. */
rad_result ph_read_number(ph_text *t, const char *what, double *value, size_t *line);

/* A whole number from `lo` to `hi` (a count, an enumeration). */
rad_result ph_read_whole(ph_text *t, const char *what, long lo, long hi, long *value);

/* Whether anything but blanks (and commas) is left. */
bool ph_text_left(ph_text *t);

/* A file's lateral symmetry: which planes it gives, how the rest follow. */
typedef enum ph_symmetry {
    PH_ROTATIONAL,  /* one plane for all C */
    PH_FULL,        /* C from 0 to 360 (360 itself optional: it repeats 0) */
    PH_QUADRANT,    /* C 0..90, mirrored about the C 0-180 and C 90-270 planes */
    PH_BILATERAL_0, /* C 0..180, mirrored about the C 0-180 plane */
    PH_BILATERAL_90 /* C 90..270, mirrored about the C 90-270 plane */
} ph_symmetry;

/* Fill p's table from the file's planes: `c[nc]` increasing, as the
 * symmetry requires (the caller checked it: they start and end on the
 * symmetry's planes), `g[ng]` increasing within [0, 180] (ng >= 2),
 * cd[ic * ng + ig] candela >= 0.  Gamma outside the file's range is 0 cd
 * (a step at the edge).  Integrates the flux.  Fails only for memory. */
rad_result ph_expand(rad_context *ctx, rad_photometry *p, ph_symmetry symmetry, size_t nc,
                     const double *c, size_t ng, const double *g, const double *cd);

/* A distribution with the source and label set, summary fields neutral,
 * no table yet (NULL when out of memory). */
rad_photometry *ph_new(rad_context *ctx, const char *source, const char *label, size_t label_length);

/* Install a tilt table (copied). */
rad_result ph_set_tilt(rad_context *ctx, rad_photometry *p, int geometry, size_t count,
                       const double *angles, const double *factors);

/* The flux of p's table (lm), exact for the bilinear surface. */
double ph_flux(const rad_photometry *p);

/* The largest value a count may have in a file of `size` bytes: each
 * number takes a character and a separator. */
static inline size_t ph_count_bound(size_t size) { return size / 2 + 1; }

rad_result ph_parse_ies(rad_context *ctx, const char *name, const char *folder, const char *data,
                        size_t size, rad_photometry **out);
rad_result ph_parse_ldt(rad_context *ctx, const char *name, const char *data, size_t size,
                        rad_photometry **out);

#endif
