/*
 * photometry.c -- the intensity table of a luminaire: construction,
 * bilinear evaluation over (C, gamma), the flux integral, the tilt factor;
 * what the readers share (numbers with their line, the expansion of a
 * symmetric file to the full sphere); the readers are ies.c and
 * eulumdat.c, the loader that tells them apart load.c.
 *
 * The table is bilinear in the angles (C, gamma), as Radiance's
 * source.cal and most lighting programs interpolate a photometric web;
 * its flux is the integral of that same surface, in closed form per cell
 * (below), so the flux and the evaluation never disagree.
 */
#include "photometry/photometry_internal.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

static const double DEG = M_PI / 180.0;

void rad_photometry_free(rad_photometry *p)
{
    if (!p)
        return;
    rad_free(p->source);
    rad_free(p->label);
    rad_free(p->c_angles);
    rad_free(p->gamma_angles);
    rad_free(p->candela);
    rad_free(p->tilt_angles);
    rad_free(p->tilt_factors);
    rad_free(p);
}

/* The cell of a non-decreasing array that holds x: k with
 * a[k] <= x <= a[k + 1], a[k] < a[k + 1], and the weight of a[k + 1]; x
 * outside the array is clamped to its ends.  At a step (two equal
 * angles) x takes the value on the left (the first of the pair): the
 * search finds the first element >= x. */
static size_t bracket(const double *a, size_t n, double x, double *t)
{
    if (n < 2 || !(x > a[0])) {
        *t = 0.0;
        return 0;
    }
    if (x >= a[n - 1]) {
        /* the last cell of positive width */
        size_t k = n - 2;
        while (k > 0 && !(a[k + 1] > a[k]))
            k--;
        *t = 1.0;
        return k;
    }
    /* Most tables are evenly spaced, at least from their start (a table
     * of 0 to 90 degrees holds 90 to 180 as one more cell): guess the cell
     * from the first cell's width and check it and its neighbours (the
     * cell with a[k] < x <= a[k + 1] is unique, so a guess that passes is
     * the search's answer). */
    if (a[1] > a[0]) {
        double guess = (x - a[0]) / (a[1] - a[0]);
        size_t g = guess < (double)(n - 2) ? (size_t)guess : n - 2;
        for (size_t k = g > 0 ? g - 1 : 0; k <= g + 1 && k + 1 < n; k++)
            if (a[k] < x && x <= a[k + 1]) {
                *t = (x - a[k]) / (a[k + 1] - a[k]);
                return k;
            }
    }
    size_t lo = 0, hi = n - 1; /* a[lo] < x <= a[hi] */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (a[mid] < x)
            lo = mid;
        else
            hi = mid;
    }
    /* a[lo] < x <= a[hi] = a[lo + 1]: a cell of positive width */
    *t = (x - a[lo]) / (a[hi] - a[lo]);
    return lo;
}

static double column(const rad_photometry *p, size_t ic, double gamma)
{
    const double *col = p->candela + ic * p->gamma_count;
    double t;
    size_t k = bracket(p->gamma_angles, p->gamma_count, gamma, &t);
    return t == 0.0 ? col[k] : t == 1.0 ? col[k + 1] : (1.0 - t) * col[k] + t * col[k + 1];
}

double rad_photometry_intensity(const rad_photometry *p, vec3 d)
{
    double len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    if (!(len > 0.0) || !isfinite(len))
        return 0.0;
    /* gamma from the nadir (-z); C counter-clockwise from +x seen from above */
    double gamma = acos(fmax(-1.0, fmin(1.0, -d.z / len))) / DEG;
    if (p->c_count == 1)
        return column(p, 0, gamma);
    double c = atan2(d.y, d.x) / DEG;
    if (c < 0.0)
        c += 360.0;
    double t;
    size_t k = bracket(p->c_angles, p->c_count, c, &t);
    if (t == 0.0)
        return column(p, k, gamma);
    if (t == 1.0)
        return column(p, k + 1, gamma);
    return (1.0 - t) * column(p, k, gamma) + t * column(p, k + 1, gamma);
}

double rad_photometry_tilt_factor(const rad_photometry *p, double degrees)
{
    if (p->tilt_count == 0)
        return 1.0;
    if (p->tilt_count == 1)
        return p->tilt_factors[0];
    double t;
    size_t k = bracket(p->tilt_angles, p->tilt_count, degrees, &t);
    return (1.0 - t) * p->tilt_factors[k] + t * p->tilt_factors[k + 1];
}

double rad_photometry_lor(const rad_photometry *p)
{
    return p->rated_lumens > 0.0 ? p->flux / p->rated_lumens : 0.0;
}

double rad_photometry_max(const rad_photometry *p, double *c_degrees, double *gamma_degrees)
{
    double best = -1.0, bc = 0.0, bg = 0.0;
    for (size_t ic = 0; ic < p->c_count; ic++)
        for (size_t ig = 0; ig < p->gamma_count; ig++)
            if (p->candela[ic * p->gamma_count + ig] > best) {
                best = p->candela[ic * p->gamma_count + ig];
                bc = p->c_angles[ic];
                bg = p->gamma_angles[ig];
            }
    if (c_degrees)
        *c_degrees = bc;
    if (gamma_degrees)
        *gamma_degrees = bg;
    return best < 0.0 ? 0.0 : best;
}

/* The flux of the bilinear table.  On a cell [c0, c1] x [g0, g1] the
 * surface is linear in C, so its C integral is (c1 - c0) times the mean of
 * the cell's two columns; each column is linear in gamma,
 * v0 + (v1 - v0) s with s = (g - g0) / (g1 - g0), and
 *
 *   int_g0^g1 sin g dg     = cos g0 - cos g1            = 2 sin m sin h
 *   int_g0^g1 s sin g dg   = (sin g1 - sin g0 - (g1 - g0) cos g1) / (g1 - g0)
 *                          = (2 cos m (sin h - h cos h) + 2 h sin m sin h) / (2 h)
 *
 * with m the cell's middle and h its half width (radians); the second
 * forms lose nothing to cancellation on fine tables.  Exact for the
 * surface rad_photometry_intensity evaluates (a step's zero-width cell
 * holds nothing). */
double ph_flux(const rad_photometry *p)
{
    double total = 0.0;
    size_t cells = p->c_count == 1 ? 1 : p->c_count - 1;
    for (size_t ic = 0; ic < cells; ic++) {
        double width = p->c_count == 1 ? 2.0 * M_PI : (p->c_angles[ic + 1] - p->c_angles[ic]) * DEG;
        const double *a = p->candela + ic * p->gamma_count;
        const double *b = p->c_count == 1 ? a : a + p->gamma_count;
        double sum = 0.0;
        for (size_t ig = 0; ig + 1 < p->gamma_count; ig++) {
            double g0 = p->gamma_angles[ig] * DEG, g1 = p->gamma_angles[ig + 1] * DEG;
            if (!(g1 > g0))
                continue;
            double m = 0.5 * (g0 + g1), h = 0.5 * (g1 - g0);
            double whole = 2.0 * sin(m) * sin(h);
            double ramp = (cos(m) * (sin(h) - h * cos(h)) + h * sin(m) * sin(h)) / h;
            double v0 = 0.5 * (a[ig] + b[ig]), v1 = 0.5 * (a[ig + 1] + b[ig + 1]);
            sum += v0 * (whole - ramp) + v1 * ramp;
        }
        /* a table that stops short of a pole holds its end values there */
        size_t last = p->gamma_count - 1;
        double first_gamma = p->gamma_angles[0] * DEG, last_gamma = p->gamma_angles[last] * DEG;
        if (first_gamma > 0.0)
            sum += 0.5 * (a[0] + b[0]) * (1.0 - cos(first_gamma));
        if (last_gamma < M_PI)
            sum += 0.5 * (a[last] + b[last]) * (1.0 + cos(last_gamma));
        total += width * sum;
    }
    return total;
}

rad_photometry *ph_new(rad_context *ctx, const char *source, const char *label, size_t label_length)
{
    rad_photometry *p = rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *p, "photometry");
    if (!p)
        return NULL;
    memset(p, 0, sizeof *p);
    size_t sl = strlen(source ? source : "") + 1;
    p->source = rad_alloc(ctx, RAD_MEM_SCENE, sl, 1, "photometry: name");
    p->label = rad_alloc(ctx, RAD_MEM_SCENE, label_length + 1, 1, "photometry: label");
    if (!p->source || !p->label) {
        rad_photometry_free(p);
        return NULL;
    }
    memcpy(p->source, source ? source : "", sl);
    if (label_length)
        memcpy(p->label, label, label_length);
    p->label[label_length] = '\0';
    p->type = RAD_PHOTOMETRY_C;
    p->format = RAD_PHOTOMETRY_TABLE;
    strcpy(p->version, "table");
    strcpy(p->symmetry, "none");
    strcpy(p->tilt_source, "none");
    p->multiplier = 1.0;
    p->stated_lor = -1.0;
    return p;
}

rad_result ph_set_tilt(rad_context *ctx, rad_photometry *p, int geometry, size_t count,
                       const double *angles, const double *factors)
{
    p->tilt_angles = rad_alloc(ctx, RAD_MEM_SCENE, count, sizeof *angles, "photometry: tilt angles");
    p->tilt_factors = rad_alloc(ctx, RAD_MEM_SCENE, count, sizeof *factors, "photometry: tilt factors");
    if (!p->tilt_angles || !p->tilt_factors)
        return RAD_ERROR_OUT_OF_MEMORY;
    memcpy(p->tilt_angles, angles, count * sizeof *angles);
    memcpy(p->tilt_factors, factors, count * sizeof *factors);
    p->tilt_count = count;
    p->tilt_geometry = geometry;
    return RAD_OK;
}

/* Whether the table's angles are as the struct says. */
static bool table_valid(size_t c_count, const double *c_angles, size_t gamma_count, const double *gamma_angles)
{
    if (c_count < 1 || gamma_count < 2 || !(gamma_angles[0] >= 0.0) || !(gamma_angles[gamma_count - 1] <= 180.0) ||
        !(gamma_angles[gamma_count - 1] > gamma_angles[0]))
        return false;
    for (size_t i = 1; i < gamma_count; i++)
        if (!(gamma_angles[i] >= gamma_angles[i - 1]) ||
            (i > 1 && gamma_angles[i] == gamma_angles[i - 2]))
            return false;
    for (size_t i = 0; i < c_count; i++)
        if (!(c_angles[i] >= 0.0 && c_angles[i] <= 360.0) || (i > 0 && !(c_angles[i] > c_angles[i - 1])))
            return false;
    return c_count == 1 || (c_angles[0] == 0.0 && c_angles[c_count - 1] == 360.0);
}

rad_photometry *rad_photometry_from_table(rad_context *ctx, const char *source, size_t c_count,
                                          const double *c_angles, size_t gamma_count,
                                          const double *gamma_angles, const double *candela,
                                          rad_result *err)
{
    rad_result dummy;
    if (!err)
        err = &dummy;
    *err = RAD_ERROR_INVALID_ARGUMENT;
    if (!c_angles || !gamma_angles || !candela || !table_valid(c_count, c_angles, gamma_count, gamma_angles))
        return NULL;
    if (c_count > SIZE_MAX / sizeof(double) / gamma_count)
        return NULL;
    for (size_t i = 0; i < c_count * gamma_count; i++)
        if (!(candela[i] >= 0.0 && isfinite(candela[i])))
            return NULL;
    *err = RAD_ERROR_OUT_OF_MEMORY;
    rad_photometry *p = ph_new(ctx, source, "", 0);
    if (!p)
        return NULL;
    p->c_angles = rad_alloc(ctx, RAD_MEM_SCENE, c_count, sizeof *p->c_angles, "photometry: C angles");
    p->gamma_angles = rad_alloc(ctx, RAD_MEM_SCENE, gamma_count, sizeof *p->gamma_angles, "photometry: angles");
    p->candela = rad_alloc(ctx, RAD_MEM_SCENE, c_count * gamma_count, sizeof *p->candela, "photometry: candela");
    if (!p->c_angles || !p->gamma_angles || !p->candela) {
        rad_photometry_free(p);
        return NULL;
    }
    p->c_count = c_count;
    p->gamma_count = gamma_count;
    memcpy(p->c_angles, c_angles, c_count * sizeof *c_angles);
    memcpy(p->gamma_angles, gamma_angles, gamma_count * sizeof *gamma_angles);
    memcpy(p->candela, candela, c_count * gamma_count * sizeof *candela);
    p->flux = ph_flux(p);
    p->file_horizontal_count = c_count;
    p->file_vertical_count = gamma_count;
    p->file_horizontal_max = c_angles[c_count - 1];
    p->file_vertical_max = 180.0;
    *err = RAD_OK;
    return p;
}

/* ---- the expansion of a symmetric file ---- */

/* C folded into the range the file gives (docs/lighting.md, "Photometric
 * files": the mirror planes of each symmetry). */
static double fold(ph_symmetry symmetry, double c)
{
    switch (symmetry) {
    case PH_QUADRANT:
        if (c > 180.0)
            c = 360.0 - c;
        return c > 90.0 ? 180.0 - c : c;
    case PH_BILATERAL_0:
        return c > 180.0 ? 360.0 - c : c;
    case PH_BILATERAL_90:
        return c < 90.0 ? 180.0 - c : c > 270.0 ? 540.0 - c : c;
    default:
        return c;
    }
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

rad_result ph_expand(rad_context *ctx, rad_photometry *p, ph_symmetry symmetry, size_t nc,
                     const double *c, size_t ng, const double *g, const double *cd)
{
    /* gamma: the file's angles, with a step down to 0 cd at each end the
     * file does not reach */
    size_t before = g[0] > 0.0 ? 2 : 0, after = g[ng - 1] < 180.0 ? 2 : 0;
    size_t gamma_count = ng + before + after;
    /* C: the images of the file's planes under the symmetry's mirrors, the
     * mirror planes themselves, 0 and 360 */
    size_t most = symmetry == PH_ROTATIONAL ? 1 : 4 * nc + 6;
    double *angles = rad_alloc(ctx, RAD_MEM_SCENE, most, sizeof *angles, "photometry: C angles");
    if (!angles)
        return RAD_ERROR_OUT_OF_MEMORY;
    size_t count = 0;
    if (symmetry == PH_ROTATIONAL) {
        angles[count++] = 0.0;
    } else {
        angles[count++] = 0.0;
        angles[count++] = 360.0;
        for (size_t i = 0; i < nc; i++) {
            double a = c[i];
            switch (symmetry) {
            case PH_QUADRANT:
                angles[count++] = a, angles[count++] = 180.0 - a;
                angles[count++] = 180.0 + a, angles[count++] = 360.0 - a;
                break;
            case PH_BILATERAL_0:
                angles[count++] = a, angles[count++] = 360.0 - a;
                break;
            case PH_BILATERAL_90: /* a in [90, 270]: its mirror 180 - a, taken into [0, 360] */
                angles[count++] = a;
                angles[count++] = a <= 180.0 ? 180.0 - a : 540.0 - a;
                break;
            default:
                angles[count++] = a;
                break;
            }
        }
        if (symmetry == PH_QUADRANT || symmetry == PH_BILATERAL_90)
            angles[count++] = 90.0, angles[count++] = 270.0;
        if (symmetry != PH_FULL)
            angles[count++] = 180.0;
        qsort(angles, count, sizeof *angles, compare_double);
        /* merge angles within 1e-9 degrees (round-off of 360 - a) */
        size_t kept = 0;
        for (size_t i = 0; i < count; i++) {
            if (!(angles[i] >= 0.0 && angles[i] <= 360.0))
                continue;
            if (kept > 0 && angles[i] - angles[kept - 1] < 1e-9) {
                if (angles[i] == 360.0)
                    angles[kept - 1] = 360.0;
                continue;
            }
            angles[kept++] = angles[i];
        }
        count = kept;
    }
    if (count > SIZE_MAX / sizeof(double) / gamma_count) {
        rad_free(angles);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: table too large", p->source);
    }
    p->gamma_angles = rad_alloc(ctx, RAD_MEM_SCENE, gamma_count, sizeof *p->gamma_angles, "photometry: angles");
    p->candela = rad_alloc(ctx, RAD_MEM_SCENE, count * gamma_count, sizeof *p->candela, "photometry: candela");
    if (!p->gamma_angles || !p->candela) {
        rad_free(angles);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    p->c_angles = angles;
    p->c_count = count;
    p->gamma_count = gamma_count;
    size_t k = 0;
    if (before)
        p->gamma_angles[k++] = 0.0, p->gamma_angles[k++] = g[0];
    for (size_t i = 0; i < ng; i++)
        p->gamma_angles[k++] = g[i];
    if (after)
        p->gamma_angles[k++] = g[ng - 1], p->gamma_angles[k++] = 180.0;
    /* each column: the file's data at the folded C, linear between the
     * file's planes (for FULL, 360 is the plane at 0 when the file stops
     * short of it) */
    for (size_t ic = 0; ic < count; ic++) {
        double *col = p->candela + ic * gamma_count + before;
        if (symmetry == PH_ROTATIONAL || nc == 1) {
            memcpy(col, cd, ng * sizeof *cd);
            continue;
        }
        double x = fold(symmetry, p->c_angles[ic]);
        size_t lo = 0;
        double t = 0.0;
        const double *right;
        if (symmetry == PH_FULL && x > c[nc - 1]) {
            /* between the last plane and 360 = the first plane */
            lo = nc - 1;
            t = (x - c[nc - 1]) / (360.0 - c[nc - 1]);
            right = cd;
        } else {
            lo = bracket(c, nc, x, &t);
            right = cd + (lo + 1) * ng;
        }
        const double *left = cd + lo * ng;
        for (size_t ig = 0; ig < ng; ig++)
            col[ig] = t == 0.0 ? left[ig] : t == 1.0 ? right[ig] : (1.0 - t) * left[ig] + t * right[ig];
    }
    p->flux = ph_flux(p);
    return RAD_OK;
}

/* ---- numbers with their line ---- */

static bool is_blank(const ph_text *t, char ch)
{
    return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n' || ch == '\f' || ch == '\v' ||
           (ch == ',' && t->comma_separates);
}

static void skip_blanks(ph_text *t)
{
    while (t->at < t->size && is_blank(t, t->data[t->at])) {
        if (t->data[t->at] == '\n')
            t->line++;
        t->at++;
    }
}

bool ph_text_left(ph_text *t)
{
    skip_blanks(t);
    return t->at < t->size;
}

bool ph_next_line(ph_text *t, const char **start, size_t *length, size_t *line_number)
{
    if (t->at >= t->size)
        return false;
    const char *s = t->data + t->at;
    const char *nl = memchr(s, '\n', t->size - t->at);
    size_t n = nl ? (size_t)(nl - s) : t->size - t->at;
    *start = s;
    *line_number = t->line;
    t->at += n;
    if (nl) {
        t->at++;
        t->line++;
    }
    while (n > 0 && (s[n - 1] == '\r' || s[n - 1] == ' ' || s[n - 1] == '\t'))
        n--;
    *length = n;
    return true;
}

/* 1: a number; 0: the end; -1: a token that is not a finite number (its
 * first characters in `token`). */
static int next_number(ph_text *t, double *value, char *token, size_t token_size)
{
    skip_blanks(t);
    if (t->at >= t->size)
        return 0;
    size_t n = 0;
    while (t->at + n < t->size && !is_blank(t, t->data[t->at + n]))
        n++;
    size_t shown = n < token_size - 1 ? n : token_size - 1;
    for (size_t i = 0; i < shown; i++) {
        unsigned char ch = (unsigned char)t->data[t->at + i];
        token[i] = ch >= 32 && ch < 127 ? (char)ch : '?';
    }
    token[shown] = '\0';
    if (n >= token_size - 1)
        return -1; /* no number is that long */
    char buffer[64];
    memcpy(buffer, t->data + t->at, n);
    buffer[n] = '\0';
    if (!t->comma_separates)
        for (size_t i = 0; i < n; i++)
            if (buffer[i] == ',')
                buffer[i] = '.'; /* EULUMDAT written with a decimal comma */
    char *end;
    errno = 0;
    double v = strtod(buffer, &end);
    if (end == buffer || *end != '\0' || !isfinite(v))
        return -1;
    t->at += n;
    t->token_line = t->line;
    *value = v;
    return 1;
}

rad_result ph_read_numbers(ph_text *t, size_t count, double *out, const char *what, int checks)
{
    char token[40];
    for (size_t i = 0; i < count; i++) {
        int r = next_number(t, &out[i], token, sizeof token);
        if (r == 1) {
            if ((checks & PH_NONNEGATIVE) && out[i] < 0.0)
                return rad_fail(t->ctx, RAD_ERROR_PARSE, "%s:%zu: %s: %g is negative (value %zu of %zu)",
                                t->name, t->line, what, out[i], i + 1, count);
            if ((checks & PH_INCREASING) && i > 0 && !(out[i] > out[i - 1]))
                return rad_fail(t->ctx, RAD_ERROR_PARSE, "%s:%zu: %s not increasing: %g after %g", t->name,
                                t->line, what, out[i], out[i - 1]);
            continue;
        }
        if (r == 0)
            return rad_fail(t->ctx, RAD_ERROR_PARSE, "%s:%zu: expected %zu %s, found %zu (the file ends)",
                            t->name, t->token_line ? t->token_line : t->line, count, what, i);
        return rad_fail(t->ctx, RAD_ERROR_PARSE, "%s:%zu: expected %zu %s, found %zu, then '%s'", t->name,
                        t->line, count, what, i, token);
    }
    return RAD_OK;
}

rad_result ph_read_number(ph_text *t, const char *what, double *value, size_t *line)
{
    char token[40];
    int r = next_number(t, value, token, sizeof token);
    if (line)
        *line = t->line;
    if (r == 1)
        return RAD_OK;
    if (r == 0)
        return rad_fail(t->ctx, RAD_ERROR_PARSE, "%s:%zu: expected %s, found the end of the file", t->name,
                        t->token_line ? t->token_line : t->line, what);
    return rad_fail(t->ctx, RAD_ERROR_PARSE, "%s:%zu: expected %s (a number), found '%s'", t->name, t->line,
                    what, token);
}

rad_result ph_read_whole(ph_text *t, const char *what, long lo, long hi, long *value)
{
    double v;
    size_t line;
    rad_result r = ph_read_number(t, what, &v, &line);
    if (r != RAD_OK)
        return r;
    if (!(v >= (double)lo && v <= (double)hi && v == floor(v)))
        return rad_fail(t->ctx, RAD_ERROR_PARSE, "%s:%zu: %s: expected a whole number from %ld to %ld, found %g",
                        t->name, line, what, lo, hi, v);
    *value = (long)v;
    return RAD_OK;
}
