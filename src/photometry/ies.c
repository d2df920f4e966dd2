/*
 * ies.c -- the IES LM-63 photometric file (.ies), every version: 1986 (no
 * first line), 1991 ("IESNA91"), 1995 ("IESNA:LM-63-1995"), 2002
 * ("IESNA:LM-63-2002"), 2019 ("IES:LM-63-2019").
 *
 *     IESNA:LM-63-2002                    version (absent in 1986)
 *     [LUMINAIRE] ...                     keyword lines (free text in 1986)
 *     TILT=NONE | INCLUDE | file          INCLUDE: geometry, N, N angles, N factors
 *     lamps lumens/lamp multiplier nV nH type units width length height   ("line 10")
 *     ballast-factor  ballast-lamp-factor|future|generation-type  watts   ("line 11")
 *     nV vertical angles, nH horizontal angles, nH x nV candela (per horizontal angle)
 *
 * After the TILT line the numbers may be split by blanks or commas over
 * any lines.  Candela = file value x candela multiplier x ballast factor
 * (x the ballast-lamp photometric factor of 1986 to 1995; 2002 made that
 * field "future use", 2019 the file generation type).  Lumens per lamp -1
 * is absolute photometry: no rated lumens.  Dimensions in feet (units 1)
 * or metres (2); negative ones describe round shapes (LM-63-2019 table of
 * luminous opening shapes, docs/lighting.md).
 *
 * Type C files expand by their horizontal angles' range (0; 0-90; 0-180;
 * 90-270; 0 to above 180) to the full sphere; types B and A are resampled
 * onto a type C grid at least as fine as the file's angles (down to 0.25
 * degrees), the photometric axis on the nadir (photometry.h, "Frame").
 */
#include "photometry/photometry_internal.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const double DEG = M_PI / 180.0;
static const double FOOT = 0.3048; /* m, exactly (the international foot) */

/* ---- the tilt block ---- */

static rad_result read_tilt(ph_text *t, rad_photometry *p)
{
    long geometry, count;
    rad_result r = ph_read_whole(t, "lamp-to-luminaire geometry", 1, 3, &geometry);
    if (r == RAD_OK)
        r = ph_read_whole(t, "number of tilt angles", 1, (long)ph_count_bound(t->size), &count);
    if (r != RAD_OK)
        return r;
    double *angles = rad_alloc(t->ctx, RAD_MEM_SCENE, 2 * (size_t)count, sizeof *angles, "photometry: tilt");
    if (!angles)
        return RAD_ERROR_OUT_OF_MEMORY;
    double *factors = angles + count;
    r = ph_read_numbers(t, (size_t)count, angles, "tilt angles", PH_INCREASING);
    if (r == RAD_OK)
        r = ph_read_numbers(t, (size_t)count, factors, "tilt multiplying factors", PH_NONNEGATIVE);
    if (r == RAD_OK && (angles[0] < 0.0 || angles[count - 1] > 180.0))
        r = rad_fail(t->ctx, RAD_ERROR_PARSE, "%s:%zu: tilt angles from %g to %g: expected 0 to 180 degrees",
                     t->name, t->line, angles[0], angles[count - 1]);
    if (r == RAD_OK)
        r = ph_set_tilt(t->ctx, p, (int)geometry, (size_t)count, angles, factors);
    rad_free(angles);
    return r;
}

/* TILT=<file>: the file beside the .ies (confined to its folder unless
 * the context allows reading outside it, as a scene's textures are). */
static rad_result read_tilt_file(rad_context *ctx, const char *name, size_t line, const char *folder,
                                 const char *file, rad_photometry *p)
{
    if (!folder)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: TILT=%s: a tilt file cannot be read for data in memory",
                        name, line, file);
    size_t n = strlen(folder) + strlen(file) + 2;
    char *path = rad_alloc(ctx, RAD_MEM_SCENE, n, 1, "photometry: tilt file name");
    if (!path)
        return RAD_ERROR_OUT_OF_MEMORY;
    snprintf(path, n, "%s/%s", folder, file);
    rad_input_log log;
    memset(&log, 0, sizeof log);
    rad_result r = rad_input_log_confine(ctx, &log, name);
    if (r == RAD_OK && !rad_input_allowed(&log, path))
        r = RAD_ERROR_IO;
    rad_input_log_free(&log);
    /* A tilt file is a few lines: 1 MiB is generous. */
    char what[256];
    snprintf(what, sizeof what, "%s:%zu: TILT=%.160s", name, line, file);
    unsigned char *bytes = NULL;
    size_t size = 0;
    if (r == RAD_OK)
        r = rad_read_file(ctx, path, what, 1u << 20, "tilt file", &bytes, &size);
    const char *data = (const char *)bytes;
    if (r == RAD_OK) {
        ph_text tt = {ctx, path, data, size, 0, 1, true, 0};
        r = read_tilt(&tt, p);
    }
    rad_free(bytes);
    rad_free(path);
    return r;
}

/* ---- the luminous opening ---- */

static rad_luminous_shape opening_shape(double w, double l, double h, bool *known)
{
    *known = true;
    if (w == 0.0 && l == 0.0 && h == 0.0)
        return RAD_OPENING_POINT;
    if (w >= 0.0 && l >= 0.0 && h >= 0.0)
        return w > 0.0 && l > 0.0 && h == 0.0 ? RAD_OPENING_RECTANGLE : RAD_OPENING_BOX;
    if (w < 0.0 && l < 0.0)
        return h == 0.0 ? RAD_OPENING_ELLIPSE : h > 0.0 ? RAD_OPENING_VERTICAL_CYLINDER : RAD_OPENING_ELLIPSOID;
    if (w < 0.0 && l > 0.0 && h < 0.0)
        return RAD_OPENING_CYLINDER_X;
    if (w > 0.0 && l < 0.0 && h < 0.0)
        return RAD_OPENING_CYLINDER_Y;
    if (w < 0.0 && l == 0.0 && h < 0.0)
        return RAD_OPENING_VERTICAL_ELLIPSE_X;
    if (w == 0.0 && l < 0.0 && h < 0.0)
        return RAD_OPENING_VERTICAL_ELLIPSE_Y;
    *known = false;
    return RAD_OPENING_BOX;
}

/* ---- types B and A: resampled onto type C ---- */

/* The file's candela at (H, V) degrees, bilinear; 0 outside its angles.
 * A file whose horizontal angles start at 0 is mirrored: I(-H) = I(H). */
static double web(const double *h, size_t nh, const double *v, size_t nv, const double *cd, double hx,
                  double vx)
{
    if (h[0] == 0.0)
        hx = fabs(hx);
    if (hx < h[0] - 1e-9 || hx > h[nh - 1] + 1e-9 || vx < v[0] - 1e-9 || vx > v[nv - 1] + 1e-9)
        return 0.0;
    size_t ih = 0, iv = 0;
    double th = 0.0, tv = 0.0;
    if (nh > 1) {
        while (ih + 2 < nh && h[ih + 1] < hx)
            ih++;
        th = fmin(1.0, fmax(0.0, (hx - h[ih]) / (h[ih + 1] - h[ih])));
    }
    if (nv > 1) {
        size_t lo = 0, hi = nv - 1;
        while (hi - lo > 1) {
            size_t mid = lo + (hi - lo) / 2;
            if (v[mid] < vx)
                lo = mid;
            else
                hi = mid;
        }
        iv = lo;
        tv = fmin(1.0, fmax(0.0, (vx - v[iv]) / (v[iv + 1] - v[iv])));
    }
    const double *a = cd + ih * nv, *b = nh > 1 ? a + nv : a;
    double va = nv > 1 ? (1.0 - tv) * a[iv] + tv * a[iv + 1] : a[0];
    double vb = nv > 1 ? (1.0 - tv) * b[iv] + tv * b[iv + 1] : b[0];
    return (1.0 - th) * va + th * vb;
}

/* Type B: polar axis +y (H = 90), H the angle toward it, V the rotation
 * about it from the axis -z toward +x.  Type A: polar axis +x (V = 90), V
 * the angle toward it, H the rotation about it from -z toward +y.  The grid
 * is uniform in C and gamma with a step no coarser than the file's finest
 * (clamped to [0.25, 5] degrees); the back hemisphere (gamma > 90) is 0. */
static rad_result resample_ab(rad_context *ctx, rad_photometry *p, rad_photometric_type type, const double *h,
                              size_t nh, const double *v, size_t nv, const double *cd)
{
    double finest = 90.0;
    for (size_t i = 1; i < nh; i++)
        finest = fmin(finest, h[i] - h[i - 1]);
    for (size_t i = 1; i < nv; i++)
        finest = fmin(finest, v[i] - v[i - 1]);
    double steps = ceil(90.0 / finest - 1e-9);
    size_t n = steps < 18.0 ? 18 : steps > 360.0 ? 360 : (size_t)steps; /* gamma steps over 0..90 */
    size_t nc = 4 * n + 1, ng = n + 3;
    p->c_angles = rad_alloc(ctx, RAD_MEM_SCENE, nc, sizeof *p->c_angles, "photometry: C angles");
    p->gamma_angles = rad_alloc(ctx, RAD_MEM_SCENE, ng, sizeof *p->gamma_angles, "photometry: angles");
    p->candela = rad_alloc(ctx, RAD_MEM_SCENE, nc * ng, sizeof *p->candela, "photometry: candela");
    if (!p->c_angles || !p->gamma_angles || !p->candela)
        return RAD_ERROR_OUT_OF_MEMORY;
    p->c_count = nc;
    p->gamma_count = ng;
    for (size_t i = 0; i < nc; i++)
        p->c_angles[i] = i + 1 == nc ? 360.0 : 360.0 * (double)i / (double)(nc - 1);
    for (size_t i = 0; i <= n; i++)
        p->gamma_angles[i] = i == n ? 90.0 : 90.0 * (double)i / (double)n;
    p->gamma_angles[n + 1] = 90.0; /* the step to the back hemisphere's 0 */
    p->gamma_angles[n + 2] = 180.0;
    for (size_t ic = 0; ic < nc; ic++) {
        double c = p->c_angles[ic] * DEG;
        double *col = p->candela + ic * ng;
        for (size_t ig = 0; ig <= n; ig++) {
            double g = p->gamma_angles[ig] * DEG;
            double dx = sin(g) * cos(c), dy = sin(g) * sin(c), down = cos(g); /* down = -dz */
            double hx, vx;
            if (type == RAD_PHOTOMETRY_B) {
                hx = asin(fmax(-1.0, fmin(1.0, dy))) / DEG;
                vx = atan2(dx, down) / DEG;
            } else {
                vx = asin(fmax(-1.0, fmin(1.0, dx))) / DEG;
                hx = atan2(dy, down) / DEG;
            }
            col[ig] = web(h, nh, v, nv, cd, hx, vx);
        }
        col[n + 1] = col[n + 2] = 0.0;
    }
    p->flux = ph_flux(p);
    return RAD_OK;
}

/* ---- the file ---- */

typedef struct ies_version {
    const char *first_line; /* prefix of the first line */
    const char *name;
    bool lamp_factor;       /* line 11's second value is the ballast-lamp photometric factor */
} ies_version;

static const ies_version VERSIONS[] = {
    {"IESNA:LM-63-1995", "LM-63-1995", true},
    {"IESNA:LM-63-2002", "LM-63-2002", false},
    {"IES:LM-63-2019", "LM-63-2019", false},
    {"IESNA:LM-63-1991", "LM-63-1991", true},
    {"IESNA91", "LM-63-1991", true},
};

static bool starts_with(const char *s, size_t n, const char *prefix)
{
    size_t k = strlen(prefix);
    return n >= k && strncmp(s, prefix, k) == 0;
}

static const char *skip_space(const char *s, size_t *n)
{
    while (*n > 0 && (*s == ' ' || *s == '\t'))
        s++, (*n)--;
    return s;
}

rad_result ph_parse_ies(rad_context *ctx, const char *name, const char *folder, const char *data,
                        size_t size, rad_photometry **out)
{
    *out = NULL;
    ph_text t = {ctx, name, data, size, 0, 1, true, 0};
    const char *line, *label = "";
    size_t length, number, label_length = 0;
    const ies_version *version = NULL;
    static const ies_version V1986 = {NULL, "LM-63-1986", true};

    /* the version line, keywords, TILT= */
    if (!ph_next_line(&t, &line, &length, &number))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s:1: empty file", name);
    size_t n0 = length;
    const char *first = skip_space(line, &n0);
    for (size_t k = 0; k < sizeof VERSIONS / sizeof VERSIONS[0]; k++)
        if (starts_with(first, n0, VERSIONS[k].first_line))
            version = &VERSIONS[k];
    if (!version && (starts_with(first, n0, "IESNA") || starts_with(first, n0, "IES:")))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: unknown LM-63 version '%.*s' (known: 1986, 1991, "
                        "1995, 2002, 2019)", name, number, (int)(n0 < 40 ? n0 : 40), first);
    bool have_line = !version; /* 1986: the first line is already text (or TILT=) */
    if (!version)
        version = &V1986;
    const char *tilt = NULL;
    size_t tilt_length = 0, tilt_line = 0;
    for (;;) {
        if (!have_line && !ph_next_line(&t, &line, &length, &number))
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: no TILT= line", name, t.line);
        have_line = false;
        size_t n = length;
        const char *s = skip_space(line, &n);
        if (starts_with(s, n, "TILT=")) {
            tilt = skip_space(s + 5, &(size_t){n - 5});
            tilt_length = n - (size_t)(tilt - s);
            tilt_line = number;
            break;
        }
        if (starts_with(s, n, "[LUMINAIRE]") && label_length == 0) {
            size_t m = n - 11;
            label = skip_space(s + 11, &m);
            label_length = m;
        } else if (version == &V1986 && label_length == 0 && n > 0 && s[0] != '[') {
            label = s, label_length = n; /* 1986: free text, the first line names it */
        }
    }
    for (size_t i = 0; i < label_length; i++)
        if ((unsigned char)label[i] < 32)
            label_length = i; /* keep the name on one line */
    rad_photometry *p = ph_new(ctx, name, label, label_length);
    if (!p)
        return RAD_ERROR_OUT_OF_MEMORY;
    p->format = RAD_PHOTOMETRY_IES;
    snprintf(p->version, sizeof p->version, "%s", version->name);
    rad_result r = RAD_OK;
    if (tilt_length == 4 && strncasecmp(tilt, "NONE", 4) == 0) {
        strcpy(p->tilt_source, "none");
    } else if (tilt_length == 7 && strncasecmp(tilt, "INCLUDE", 7) == 0) {
        strcpy(p->tilt_source, "include");
        r = read_tilt(&t, p);
    } else if (tilt_length == 0) {
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: TILT= names nothing (NONE, INCLUDE or a file)", name,
                     tilt_line);
    } else {
        char file[256];
        if (tilt_length >= sizeof file || memchr(tilt, '\0', tilt_length))
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: TILT=: not a file name", name, tilt_line);
        else {
            memcpy(file, tilt, tilt_length);
            file[tilt_length] = '\0';
            snprintf(p->tilt_source, sizeof p->tilt_source, "%.63s", file);
            r = read_tilt_file(ctx, name, tilt_line, folder, file, p);
        }
    }

    /* line 10 and line 11 */
    long lamps = 0, nv = 0, nh = 0, type = 0, units = 0;
    double lumens = 0, multiplier = 0, w = 0, l = 0, h = 0, ballast = 0, lamp_factor = 0, watts = 0;
    size_t at_line = 0;
    long bound = (long)ph_count_bound(size);
    if (r == RAD_OK)
        r = ph_read_whole(&t, "number of lamps", 1, 1000000, &lamps);
    if (r == RAD_OK)
        r = ph_read_number(&t, "lumens per lamp", &lumens, &at_line);
    if (r == RAD_OK && !(lumens > 0.0 || lumens == -1.0))
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: lumens per lamp %g: expected a positive number, or -1 "
                     "(absolute photometry)", name, at_line, lumens);
    if (r == RAD_OK)
        r = ph_read_number(&t, "candela multiplier", &multiplier, &at_line);
    if (r == RAD_OK && !(multiplier > 0.0))
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: candela multiplier %g: expected a positive number", name,
                     at_line, multiplier);
    if (r == RAD_OK)
        r = ph_read_whole(&t, "number of vertical angles", 2, bound, &nv);
    if (r == RAD_OK)
        r = ph_read_whole(&t, "number of horizontal angles", 1, bound, &nh);
    if (r == RAD_OK)
        r = ph_read_whole(&t, "photometric type (1 C, 2 B, 3 A)", 1, 3, &type);
    if (r == RAD_OK)
        r = ph_read_whole(&t, "units type (1 feet, 2 metres)", 1, 2, &units);
    if (r == RAD_OK)
        r = ph_read_number(&t, "width", &w, NULL);
    if (r == RAD_OK)
        r = ph_read_number(&t, "length", &l, NULL);
    if (r == RAD_OK)
        r = ph_read_number(&t, "height", &h, NULL);
    if (r == RAD_OK)
        r = ph_read_number(&t, "ballast factor", &ballast, &at_line);
    if (r == RAD_OK && !(ballast > 0.0))
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: ballast factor %g: expected a positive number", name, at_line,
                     ballast);
    if (r == RAD_OK)
        r = ph_read_number(&t, version->lamp_factor ? "ballast-lamp photometric factor" : "line 11's second value",
                           &lamp_factor, &at_line);
    if (r == RAD_OK && version->lamp_factor && !(lamp_factor > 0.0))
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: ballast-lamp photometric factor %g: expected a positive "
                     "number", name, at_line, lamp_factor);
    if (r == RAD_OK)
        r = ph_read_number(&t, "input watts", &watts, &at_line);
    if (r == RAD_OK && watts < 0.0)
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: input watts %g: negative", name, at_line, watts);
    if (r == RAD_OK && (double)nv * (double)nh > (double)bound)
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: %ld x %ld candela values cannot fit in a file of %zu bytes",
                     name, t.line, nh, nv, size);
    if (r != RAD_OK) {
        rad_photometry_free(p);
        return r;
    }

    /* the angles and the candela */
    size_t cv = (size_t)nv, ch = (size_t)nh;
    double *v = rad_alloc(ctx, RAD_MEM_SCENE, cv + ch + cv * ch, sizeof *v, "photometry: the file's values");
    if (!v) {
        rad_photometry_free(p);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    double *hz = v + cv, *cd = hz + ch;
    r = ph_read_numbers(&t, cv, v, "vertical angles", PH_INCREASING);
    size_t v_line = t.line;
    if (r == RAD_OK)
        r = ph_read_numbers(&t, ch, hz, "horizontal angles", PH_INCREASING);
    size_t h_line = t.line;
    if (r == RAD_OK)
        r = ph_read_numbers(&t, cv * ch, cd, "candela values", PH_NONNEGATIVE);
    ph_symmetry symmetry = PH_FULL;
    if (r == RAD_OK && type == RAD_PHOTOMETRY_C) {
        double h0 = hz[0], hl = hz[ch - 1];
        if (v[0] < 0.0 || v[cv - 1] > 180.0)
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: vertical angles from %g to %g: type C needs 0 to 180",
                         name, v_line, v[0], v[cv - 1]);
        else if (ch == 1)
            symmetry = PH_ROTATIONAL, strcpy(p->symmetry, "rotational (C 0)");
        else if (h0 == 0.0 && hl == 90.0)
            symmetry = PH_QUADRANT, strcpy(p->symmetry, "quadrant (C 0-90)");
        else if (h0 == 0.0 && hl == 180.0)
            symmetry = PH_BILATERAL_0, strcpy(p->symmetry, "bilateral (C 0-180)");
        else if (h0 == 90.0 && hl == 270.0)
            symmetry = PH_BILATERAL_90, strcpy(p->symmetry, "bilateral (C 90-270)");
        else if (h0 == 0.0 && hl > 180.0 && hl <= 360.0)
            symmetry = PH_FULL, strcpy(p->symmetry, hl == 360.0 ? "none (C 0-360)" : "none (C 0 to below 360)");
        else
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: horizontal angles from %g to %g: not a symmetry of "
                         "LM-63 (0; 0 to 90; 0 to 180; 90 to 270; 0 to more than 180, at most 360)",
                         name, h_line, h0, hl);
        if (r == RAD_OK)
            r = ph_expand(ctx, p, symmetry, ch, hz, cv, v, cd);
    } else if (r == RAD_OK) {
        if (v[0] < -90.0 || v[cv - 1] > 90.0)
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: vertical angles from %g to %g: type %s needs -90 to 90",
                         name, v_line, v[0], v[cv - 1], type == RAD_PHOTOMETRY_B ? "B" : "A");
        else if (!((hz[0] == 0.0 || hz[0] == -90.0) && hz[ch - 1] == 90.0))
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: horizontal angles from %g to %g: type %s needs -90 to 90, "
                         "or 0 to 90 (symmetric)", name, h_line, hz[0], hz[ch - 1],
                         type == RAD_PHOTOMETRY_B ? "B" : "A");
        else {
            snprintf(p->symmetry, sizeof p->symmetry, "%s", hz[0] == 0.0 ? "left-right (H 0 to 90)" : "none (H -90 to 90)");
            r = resample_ab(ctx, p, (rad_photometric_type)type, hz, ch, v, cv, cd);
        }
    }
    if (r == RAD_OK) {
        p->type = (rad_photometric_type)type;
        p->file_vertical_count = cv, p->file_horizontal_count = ch;
        p->file_vertical_min = v[0], p->file_vertical_max = v[cv - 1];
        p->file_horizontal_min = hz[0], p->file_horizontal_max = hz[ch - 1];
    }
    rad_free(v);
    if (r != RAD_OK) {
        rad_photometry_free(p);
        return r;
    }
    if (ph_text_left(&t))
        rad_warn(ctx, "%s:%zu: ignored what follows the %zu candela values", name, t.line, cv * ch);

    /* multipliers, lumens, the opening */
    double m = multiplier * ballast * (version->lamp_factor ? lamp_factor : 1.0);
    for (size_t i = 0; i < p->c_count * p->gamma_count; i++)
        p->candela[i] *= m;
    p->flux = ph_flux(p);
    p->multiplier = m;
    p->rated_lumens = lumens > 0.0 ? (double)lamps * lumens : 0.0;
    p->input_watts = watts;
    bool known;
    p->shape = opening_shape(w, l, h, &known);
    if (!known)
        rad_warn(ctx, "%s: luminous opening %g %g %g: signs not in LM-63-2019's table of shapes; read as a box",
                 name, w, l, h);
    double unit = units == 1 ? FOOT : 1.0;
    p->width = fabs(w) * unit, p->length = fabs(l) * unit, p->height = fabs(h) * unit;
    *out = p;
    return RAD_OK;
}
