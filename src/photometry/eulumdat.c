/*
 * eulumdat.c -- the EULUMDAT photometric file (.ldt), Stockmar's fixed
 * line layout (A. W. Stockmar, "EULUMDAT - ein Leuchtendatenformat fuer
 * den europaeischen Beleuchtungsplaner", Licht '90; "EULUMDAT/2", CIBSE
 * 1998; the layout as AGI32's Photometric Toolbox documents it,
 * docs.agi32.com/PhotometricToolbox/Content/Open_Tool/eulumdat_file_format.htm):
 *
 *      1  company / data bank / version      13-15 luminaire length (diameter), width, height, mm
 *      2  Ityp 0..3                          16-17 luminous area length (diameter), width (0: round), mm
 *      3  Isym 0..4                          18-21 luminous area height at C0, C90, C180, C270, mm
 *      4  Mc  number of C planes in 0..360   22 DFF %, 23 LORL %, 24 conversion factor CFLI,
 *      5  Dc  C step (0: not equidistant)    25 tilt during measurement, degrees
 *      6  Ng  number of gamma angles         26 n lamp sets, then per set: number of lamps
 *      7  Dg  gamma step                        (negative: absolute photometry), type, total
 *      8  measurement report                    lumens, colour, CRI, watts with ballast
 *      9  luminaire name                     27 ten direct ratios (room indices 0.6 .. 5)
 *     10  luminaire number                   28 Mc C angles, 29 Ng gamma angles
 *     11  file name, 12 date / user          30 cd/klm for the planes Mc1..Mc2, Ng each
 *
 * Stored planes (1-based, of the Mc listed): Isym 0: 1..Mc; 1: 1; 2: 1..Mc/2+1
 * (C 0..180); 3: 3Mc/4+1 .. 3Mc/4+1+Mc/2, wrapping past Mc (C 270..360/0..90);
 * 4: 1..Mc/4+1 (C 0..90).
 *
 * Intensities are cd per 1000 lm of the lamps: candela = value x (total
 * lumens of lamp set 1 / 1000) x CFLI (the conversion factor multiplies
 * the intensities as measured; AGI32's page above, and the same in
 * eulumdat readers of DIALux and Relux).  Lamp set 1 is the standard
 * lamping the distribution was measured with; further sets are
 * alternatives and only reported.  From line 27 on, numbers may share
 * lines; a decimal comma is read as a point.
 */
#include "photometry/photometry_internal.h"

#include <stdlib.h>
#include <string.h>

/* The next line as text; an error naming what was expected at the end. */
static rad_result text_line(ph_text *t, const char *what, const char **s, size_t *n, size_t *line)
{
    if (!ph_next_line(t, s, n, line))
        return rad_fail(t->ctx, RAD_ERROR_PARSE, "%s:%zu: the file ends before the %s", t->name, t->line, what);
    return RAD_OK;
}

/* A line that holds one number. */
static rad_result number_line(ph_text *t, const char *what, double *value, size_t *line)
{
    const char *s;
    size_t n;
    rad_result r = text_line(t, what, &s, &n, line);
    if (r != RAD_OK)
        return r;
    ph_text one = {t->ctx, t->name, s, n, 0, *line, false, 0};
    r = ph_read_number(&one, what, value, NULL);
    if (r == RAD_OK && ph_text_left(&one))
        r = rad_fail(t->ctx, RAD_ERROR_PARSE, "%s:%zu: %s: expected one number, found '%.*s'", t->name, *line,
                     what, (int)(n < 40 ? n : 40), s);
    return r;
}

static rad_result whole_line(ph_text *t, const char *what, long lo, long hi, long *value)
{
    double v;
    size_t line;
    rad_result r = number_line(t, what, &v, &line);
    if (r == RAD_OK && !(v >= (double)lo && v <= (double)hi && v == floor(v)))
        r = rad_fail(t->ctx, RAD_ERROR_PARSE, "%s:%zu: %s: expected a whole number from %ld to %ld, found %g",
                     t->name, line, what, lo, hi, v);
    if (r == RAD_OK)
        *value = (long)v;
    return r;
}

static const char *const SYMMETRY_NAMES[] = {"none (Isym 0)", "rotational (Isym 1)", "C0-C180 plane (Isym 2)",
                                             "C90-C270 plane (Isym 3)", "both planes (Isym 4)"};

rad_result ph_parse_ldt(rad_context *ctx, const char *name, const char *data, size_t size,
                        rad_photometry **out)
{
    *out = NULL;
    ph_text t = {ctx, name, data, size, 0, 1, false, 0};
    const char *s, *label = "";
    size_t n, line, label_length = 0;
    long ityp, isym, mc, ng, sets;
    double dc, dg, dims[9], dff, lorl, cfli, tilt;
    rad_result r = text_line(&t, "company line", &s, &n, &line);
    if (r == RAD_OK)
        r = whole_line(&t, "type indicator Ityp", 0, 3, &ityp);
    if (r == RAD_OK)
        r = whole_line(&t, "symmetry indicator Isym", 0, 4, &isym);
    if (r == RAD_OK)
        r = whole_line(&t, "number of C planes Mc", 1, (long)ph_count_bound(size), &mc);
    if (r == RAD_OK)
        r = number_line(&t, "C plane distance Dc", &dc, &line);
    if (r == RAD_OK)
        r = whole_line(&t, "number of gamma angles Ng", 2, (long)ph_count_bound(size), &ng);
    if (r == RAD_OK)
        r = number_line(&t, "gamma angle distance Dg", &dg, &line);
    static const char *const texts[] = {"measurement report", "luminaire name", "luminaire number", "file name",
                                        "date and user"};
    for (int k = 0; r == RAD_OK && k < 5; k++) {
        r = text_line(&t, texts[k], &s, &n, &line);
        if (k == 1)
            label = s, label_length = n;
    }
    static const char *const sizes[] = {"luminaire length", "luminaire width", "luminaire height",
                                        "luminous area length", "luminous area width", "luminous area height C0",
                                        "luminous area height C90", "luminous area height C180",
                                        "luminous area height C270"};
    for (int k = 0; r == RAD_OK && k < 9; k++) {
        r = number_line(&t, sizes[k], &dims[k], &line);
        if (r == RAD_OK && dims[k] < 0.0)
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: %s %g mm: negative", name, line, sizes[k], dims[k]);
    }
    if (r == RAD_OK)
        r = number_line(&t, "downward flux fraction DFF", &dff, &line);
    if (r == RAD_OK)
        r = number_line(&t, "light output ratio LORL", &lorl, &line);
    if (r == RAD_OK && !(lorl >= 0.0 && lorl <= 1000.0))
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: light output ratio %g %%: expected 0 to 1000", name, line, lorl);
    if (r == RAD_OK)
        r = number_line(&t, "conversion factor CFLI", &cfli, &line);
    if (r == RAD_OK && !(cfli > 0.0))
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: conversion factor %g: expected a positive number", name, line,
                     cfli);
    if (r == RAD_OK)
        r = number_line(&t, "tilt during measurement", &tilt, &line);
    if (r == RAD_OK)
        r = whole_line(&t, "number of lamp sets", 1, 1000, &sets);
    double lamps1 = 0.0, lumens1 = 0.0, watts1 = 0.0;
    for (long k = 0; r == RAD_OK && k < sets; k++) {
        double count, lumens, watts;
        r = number_line(&t, "number of lamps", &count, &line);
        if (r == RAD_OK && !(count == floor(count) && count != 0.0 && fabs(count) <= 1e6))
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: number of lamps %g: expected a whole number, not 0 "
                         "(negative: absolute photometry)", name, line, count);
        if (r == RAD_OK)
            r = text_line(&t, "lamp type", &s, &n, &line);
        if (r == RAD_OK)
            r = number_line(&t, "total lamp lumens", &lumens, &line);
        if (r == RAD_OK && !(lumens > 0.0))
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: total lamp lumens %g: expected a positive number", name,
                         line, lumens);
        if (r == RAD_OK)
            r = text_line(&t, "colour appearance", &s, &n, &line);
        if (r == RAD_OK)
            r = text_line(&t, "colour rendering", &s, &n, &line);
        if (r == RAD_OK)
            r = number_line(&t, "lamp watts", &watts, &line);
        if (r == RAD_OK && k == 0)
            lamps1 = count, lumens1 = lumens, watts1 = watts;
    }
    double ratios[10];
    if (r == RAD_OK)
        r = ph_read_numbers(&t, 10, ratios, "direct ratios", 0);
    if (r != RAD_OK)
        return r;

    /* the stored planes */
    size_t planes = isym == 0 ? (size_t)mc : isym == 1 ? 1 : isym == 2 ? (size_t)mc / 2 + 1 : isym == 3 ? (size_t)mc / 2 + 1 : (size_t)mc / 4 + 1;
    if ((isym == 2 && mc % 2 != 0) || ((isym == 3 || isym == 4) && mc % 4 != 0))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s:4: Mc = %ld C planes cannot hold symmetry Isym %ld (Mc must be "
                        "a multiple of %d)", name, mc, isym, isym == 2 ? 2 : 4);
    if ((double)planes * (double)ng > (double)ph_count_bound(size))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s:6: %zu x %ld intensities cannot fit in a file of %zu bytes", name,
                        planes, ng, size);
    size_t cm = (size_t)mc, cg = (size_t)ng;
    double *c = rad_alloc(ctx, RAD_MEM_SCENE, 2 * cm + cg + 2 * planes * cg, sizeof *c, "photometry: the file's values");
    if (!c)
        return RAD_ERROR_OUT_OF_MEMORY;
    double *g = c + cm, *cd = g + cg, *ordered = cd + planes * cg, *angles = ordered + planes * cg;
    r = ph_read_numbers(&t, cm, c, "C angles", PH_INCREASING);
    size_t c_line = t.line;
    if (r == RAD_OK && (c[0] != 0.0 || c[cm - 1] >= 360.0))
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: C angles from %g to %g: expected 0 to below 360", name, c_line,
                     c[0], c[cm - 1]);
    if (r == RAD_OK && ((isym == 2 && c[cm / 2] != 180.0) || (isym == 4 && c[cm / 4] != 90.0) ||
                        (isym == 3 && (c[cm / 4] != 90.0 || c[3 * cm / 4] != 270.0))))
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: the C angles do not put the planes of symmetry Isym %ld where "
                     "the stored planes end", name, c_line, isym);
    if (r == RAD_OK)
        r = ph_read_numbers(&t, cg, g, "gamma angles", PH_INCREASING);
    if (r == RAD_OK && (g[0] < 0.0 || g[cg - 1] > 180.0))
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: gamma angles from %g to %g: expected 0 to 180", name, t.line,
                     g[0], g[cg - 1]);
    if (r == RAD_OK)
        r = ph_read_numbers(&t, planes * cg, cd, "intensities (cd/klm)", PH_NONNEGATIVE);
    rad_photometry *p = NULL;
    if (r == RAD_OK) {
        for (size_t i = 0; i < label_length; i++)
            if ((unsigned char)label[i] < 32)
                label_length = i;
        p = ph_new(ctx, name, label, label_length);
        if (!p)
            r = RAD_ERROR_OUT_OF_MEMORY;
    }
    if (r == RAD_OK) {
        ph_symmetry symmetry;
        const double *use = cd;
        switch (isym) {
        case 0: symmetry = PH_FULL; break;
        case 1: symmetry = PH_ROTATIONAL; break;
        case 2: symmetry = PH_BILATERAL_0; break;
        case 4: symmetry = PH_QUADRANT; break;
        default:
            /* Isym 3 stores C 270 .. 360 = 0 .. 90; their mirrors in the
             * C90-C270 plane, 180 - C, run from 90 to 270 in reverse order:
             * the IES layout of the same symmetry */
            symmetry = PH_BILATERAL_90;
            for (size_t j = 0; j < planes; j++) {
                size_t from = planes - 1 - j;
                double a = c[(3 * cm / 4 + from) % cm];
                angles[j] = a <= 180.0 ? 180.0 - a : 540.0 - a;
                memcpy(ordered + j * cg, cd + from * cg, cg * sizeof *cd);
            }
            use = ordered;
            break;
        }
        if (isym != 3)
            memcpy(angles, c, planes * sizeof *c);
        r = ph_expand(ctx, p, symmetry, planes, angles, cg, g, use);
        snprintf(p->symmetry, sizeof p->symmetry, "%s", SYMMETRY_NAMES[isym]);
    }
    double c_min = c[0], c_max = c[cm - 1], g_min = g[0], g_max = g[cg - 1];
    rad_free(c);
    if (r != RAD_OK) {
        rad_photometry_free(p);
        return r;
    }
    if (ph_text_left(&t))
        rad_warn(ctx, "%s:%zu: ignored what follows the %zu intensities", name, t.line, planes * cg);

    p->format = RAD_PHOTOMETRY_LDT;
    strcpy(p->version, "EULUMDAT");
    p->file_horizontal_count = cm, p->file_vertical_count = cg;
    p->file_horizontal_min = c_min, p->file_horizontal_max = c_max;
    p->file_vertical_min = g_min, p->file_vertical_max = g_max;
    double m = lumens1 / 1000.0 * cfli;
    for (size_t i = 0; i < p->c_count * p->gamma_count; i++)
        p->candela[i] *= m;
    p->flux = ph_flux(p);
    p->multiplier = m;
    p->rated_lumens = lamps1 > 0.0 ? lumens1 : 0.0;
    p->input_watts = watts1;
    p->stated_lor = lorl / 100.0;
    /* the luminous area: length along C0 (x), width along C90 (y), 0 width
     * = round of diameter `length`; height: the largest of the four */
    double la = dims[3] / 1000.0, wa = dims[4] / 1000.0;
    double ha = fmax(fmax(dims[5], dims[6]), fmax(dims[7], dims[8])) / 1000.0;
    if (wa == 0.0 && la > 0.0) {
        p->shape = ha > 0.0 ? RAD_OPENING_VERTICAL_CYLINDER : RAD_OPENING_ELLIPSE;
        p->width = p->length = la;
    } else {
        p->shape = la == 0.0 && wa == 0.0 && ha == 0.0 ? RAD_OPENING_POINT
                   : ha == 0.0 && la > 0.0 && wa > 0.0 ? RAD_OPENING_RECTANGLE
                                                       : RAD_OPENING_BOX;
        p->width = wa, p->length = la;
    }
    p->height = ha;
    if (p->rated_lumens > 0.0 && lorl > 0.0) {
        double stated = p->stated_lor * p->rated_lumens;
        if (fabs(p->flux - stated) > 0.02 * stated)
            rad_warn(ctx, "%s: the intensities integrate to %.6g lm, LORL %g %% of %g lm is %.6g lm (%+.1f %%)", name,
                     p->flux, lorl, p->rated_lumens, stated, 100.0 * (p->flux / stated - 1.0));
    }
    *out = p;
    return RAD_OK;
}
