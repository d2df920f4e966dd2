/*
 * falsecolour.c -- false colour pictures: a value per pixel (luminance in
 * cd/m^2, illuminance in lux; docs/units.md "Photometry") coloured through
 * a perceptually ordered map, with a legend drawn by cairo, written as PNG
 * atomically.  Also the colour map, the scale and the legend that the grid
 * plots (plot.c) share (picture.h).
 *
 * The colour map is computed, not tabulated: a path through CIE L*a*b*
 * (CIE 15:2004, D65 white) whose lightness L* rises linearly from
 * RAD_MAP_L0 to RAD_MAP_L1 while the hue angle turns from 290 degrees
 * (violet-blue) down through cyan and green to 95 (yellow), with the
 * chroma cut back (bisection, the lightness and hue kept) wherever the
 * colour leaves the sRGB gamut (IEC 61966-2-1).  Lightness alone orders it,
 * so a reader ranks colours without the legend and a grey-scale print keeps
 * the order; the idea of a lightness-monotone hue sweep is that of
 * "cubehelix" (Green 2011) and of Radiance's falsecolor palettes, neither
 * of whose tables is used.
 *
 * Illuminance on surfaces (rad_view_illuminance): an element's irradiance
 * is what its radiosity reflects over its reflectance plus the direct
 * light that reached it, H = (B - E) / rho + H_direct (E includes
 * rho H_direct, strategy.h), channel by channel; a black channel gathers
 * sum_j F_ij B_j from the view's F, or without it the exact unoccluded
 * point-to-polygon factor from the element's centroid to each element
 * (Baum, Rushmeier & Winget 1989; formfactor/polygon.c) times the
 * visibility of that element's centroid.  Lux = 179 Y(H).
 */
#include "output/picture.h"
#include "formfactor/formfactor.h"
#include "photometry/photometry.h"

#include <stdlib.h>
#include <string.h>

/* ---- the colour map ---- */

#define MAP_HUE0 290.0   /* degrees at t = 0: violet-blue */
#define MAP_HUE1 95.0    /* degrees at t = 1: yellow */
#define MAP_CHROMA0 55.0 /* wanted chroma at t = 0 and 1 (the gamut may cut it) */
#define MAP_CHROMA1 85.0

/* CIE L*a*b* (D65) to linear sRGB. */
static void lab_to_linear_srgb(double L, double a, double b, double rgb[3])
{
    double fy = (L + 16.0) / 116.0, fx = fy + a / 500.0, fz = fy - b / 200.0;
    const double e = 6.0 / 29.0;
    double f[3] = {fx, fy, fz}, xyz[3];
    const double white[3] = {0.95047, 1.0, 1.08883};
    for (int k = 0; k < 3; k++)
        xyz[k] = white[k] * (f[k] > e ? f[k] * f[k] * f[k] : 3.0 * e * e * (f[k] - 4.0 / 29.0));
    /* XYZ -> linear sRGB (IEC 61966-2-1). */
    rgb[0] = 3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2];
    rgb[1] = -0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2];
    rgb[2] = 0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2];
}

double rad_srgb_lightness(const double rgb[3])
{
    double Y = 0.2126729 * rgb[0] + 0.7151522 * rgb[1] + 0.0721750 * rgb[2];
    const double e = 216.0 / 24389.0;
    double fy = Y > e ? cbrt(Y) : (24389.0 / 27.0 * Y + 16.0) / 116.0;
    return 116.0 * fy - 16.0;
}

static bool in_gamut(const double rgb[3])
{
    for (int k = 0; k < 3; k++)
        if (rgb[k] < 0.0 || rgb[k] > 1.0)
            return false;
    return true;
}

void rad_colour_map_linear(double t, double rgb[3])
{
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    double L = RAD_MAP_L0 + (RAD_MAP_L1 - RAD_MAP_L0) * t;
    double hue = (MAP_HUE0 + (MAP_HUE1 - MAP_HUE0) * t) * M_PI / 180.0;
    double chroma = MAP_CHROMA0 + (MAP_CHROMA1 - MAP_CHROMA0) * t;
    lab_to_linear_srgb(L, chroma * cos(hue), chroma * sin(hue), rgb);
    if (in_gamut(rgb))
        return;
    /* Grey (chroma 0) is inside: bisect on chroma; 40 halvings of < 100
     * leave < 1e-10 of chroma. */
    double lo = 0.0, hi = chroma, inside[3];
    lab_to_linear_srgb(L, 0.0, 0.0, inside);
    for (int k = 0; k < 40; k++) {
        double mid = 0.5 * (lo + hi), trial[3];
        lab_to_linear_srgb(L, mid * cos(hue), mid * sin(hue), trial);
        if (in_gamut(trial)) {
            lo = mid;
            memcpy(inside, trial, sizeof inside);
        } else {
            hi = mid;
        }
    }
    for (int k = 0; k < 3; k++)
        rgb[k] = inside[k] < 0.0 ? 0.0 : inside[k] > 1.0 ? 1.0 : inside[k];
}

void rad_colour_map_make(rad_colour_map *map)
{
    for (int i = 0; i < RAD_COLOUR_LEVELS; i++) {
        double rgb[3];
        rad_colour_map_linear((double)i / (RAD_COLOUR_LEVELS - 1), rgb);
        for (int k = 0; k < 3; k++)
            map->rgb[i][k] = (unsigned char)lround(255.0 * rad_srgb_encode(rgb[k]));
    }
}

/* ---- the scale ---- */

double rad_scale_position(const rad_colour_scale *scale, double value)
{
    double t;
    if (scale->log)
        t = value > 0.0 ? (log10(value) - log10(scale->min)) / (log10(scale->max) - log10(scale->min)) : 0.0;
    else
        t = (value - scale->min) / (scale->max - scale->min);
    if (!(t > 0.0))
        return 0.0;
    return t > 1.0 ? 1.0 : t;
}

int rad_scale_level(const rad_colour_scale *scale, double value)
{
    return (int)lround(rad_scale_position(scale, value) * (RAD_COLOUR_LEVELS - 1));
}

/* The smallest m x 10^k >= v, m from the nice mantissas. */
static double nice_ceiling(double v)
{
    static const double mantissa[] = {1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0};
    double decade = pow(10.0, floor(log10(v)));
    for (size_t i = 0; i < sizeof mantissa / sizeof *mantissa; i++)
        if (mantissa[i] * decade >= v * (1.0 - 1e-12))
            return mantissa[i] * decade;
    return 10.0 * decade;
}

static int compare_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

rad_result rad_scale_automatic(rad_context *ctx, bool log, const float *values, size_t count,
                               rad_colour_scale *scale)
{
    float *kept = rad_alloc(ctx, RAD_MEM_RENDER, count ? count : 1, sizeof *kept, "false colour: range");
    if (!kept)
        return RAD_ERROR_OUT_OF_MEMORY;
    size_t n = 0;
    for (size_t i = 0; i < count; i++)
        if (isfinite(values[i]))
            kept[n++] = values[i];
    double top = 0.0;
    if (n) {
        qsort(kept, n, sizeof *kept, compare_float);
        size_t rank = (size_t)ceil(0.99 * (double)n); /* nearest rank, 1-based */
        top = kept[rank > 0 ? rank - 1 : 0];
    }
    rad_free(kept);
    scale->log = log;
    scale->max = top > 0.0 ? nice_ceiling(top) : 1.0;
    scale->min = log ? scale->max / 1000.0 : 0.0;
    return RAD_OK;
}

size_t rad_legend_ticks(const rad_colour_scale *scale, double *ticks)
{
    size_t count = 0;
    const double slack = 1e-9;
    if (!scale->log) {
        double range = scale->max - scale->min, step = 0.0;
        static const double mantissa[] = {1.0, 2.0, 2.5, 5.0};
        for (double decade = pow(10.0, floor(log10(range / 8.0))); step == 0.0; decade *= 10.0)
            for (size_t i = 0; i < 4 && step == 0.0; i++)
                if (mantissa[i] * decade * 8.0 >= range * (1.0 - 1e-12))
                    step = mantissa[i] * decade;
        for (double k = ceil(scale->min / step - slack); k * step <= scale->max + slack * range &&
                                                          count < RAD_LEGEND_MAX_TICKS; k++)
            ticks[count++] = k * step == 0.0 ? 0.0 : k * step; /* no -0 */
        return count;
    }
    double lo = log10(scale->min), hi = log10(scale->max);
    static const double sets[3][9] = {{1, 2, 5}, {1, 2, 3, 4, 5, 6, 7, 8, 9}, {1}};
    static const size_t sizes[3] = {3, 9, 1};
    size_t chosen = 0;
    for (;;) {
        count = 0;
        for (double k = floor(lo) - 1.0; k <= ceil(hi); k++)
            for (size_t i = 0; i < sizes[chosen]; i++) {
                double v = sets[chosen][i] * pow(10.0, k), lv = log10(v);
                if (lv >= lo - slack && lv <= hi + slack && count < RAD_LEGEND_MAX_TICKS)
                    ticks[count++] = v;
            }
        if (chosen == 0 && count < 3)
            chosen = 1;          /* under a decade or so: every integer mantissa */
        else if (chosen == 0 && count > 12)
            chosen = 2;          /* many decades: the decades alone */
        else
            return count;
    }
}

void rad_format_value(double value, char *text, size_t size)
{
    if (!isfinite(value)) {
        snprintf(text, size, "-");
        return;
    }
    double magnitude = fabs(value);
    /* Three significant figures below 100, integers above. */
    int decimals = magnitude > 0.0 ? 2 - (int)floor(log10(magnitude)) : 0;
    decimals = decimals < 0 ? 0 : decimals > 6 ? 6 : decimals;
    /* ...and no more than the value needs (0.5, not 0.500). */
    snprintf(text, size, "%.*f", decimals, value);
    if (strchr(text, '.')) {
        size_t n = strlen(text);
        while (n > 0 && text[n - 1] == '0')
            text[--n] = '\0';
        if (n > 0 && text[n - 1] == '.')
            text[--n] = '\0';
    }
    if (strcmp(text, "-0") == 0)
        snprintf(text, size, "0");
}

/* ---- the legend ---- */

double rad_legend_font(int height)
{
    return fmin(fmax(height / 30.0, 10.0), 28.0);
}

int rad_legend_width(int height)
{
    return (int)lround(6.5 * rad_legend_font(height));
}

void rad_legend_layout_make(const rad_colour_scale *scale, int picture_width, int height,
                            rad_legend_layout *layout)
{
    rad_legend_layout_make_font(scale, picture_width, height, rad_legend_font(height), layout);
}

void rad_legend_layout_make_font(const rad_colour_scale *scale, int picture_width, int height, double font,
                                 rad_legend_layout *layout)
{
    memset(layout, 0, sizeof *layout);
    layout->font_size = font;
    layout->x = picture_width;
    layout->width = (int)lround(6.5 * font);
    layout->bar_x = picture_width + (int)lround(0.8 * font);
    layout->bar_width = (int)lround(1.4 * font);
    layout->bar_top = (int)lround(2.6 * font);
    layout->bar_bottom = height - (int)lround(1.0 * font);
    if (layout->bar_bottom <= layout->bar_top + 1)
        layout->bar_bottom = layout->bar_top + 2; /* a tiny canvas: the bar is clipped */
    layout->tick_count = rad_legend_ticks(scale, layout->ticks);
    double span = layout->bar_bottom - layout->bar_top;
    for (size_t i = 0; i < layout->tick_count; i++) {
        /* Row centres: the bottom row is the min, the top row the max. */
        double t = rad_scale_position(scale, layout->ticks[i]);
        layout->tick_y[i] = layout->bar_bottom - 0.5 - t * (span - 1.0);
        rad_format_value(layout->ticks[i], layout->labels[i], sizeof layout->labels[i]);
    }
}

int rad_legend_row_level(const rad_legend_layout *layout, int y)
{
    double span = layout->bar_bottom - layout->bar_top;
    double t = (layout->bar_bottom - 0.5 - (y + 0.5)) / (span - 1.0);
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    return (int)lround(t * (RAD_COLOUR_LEVELS - 1));
}

void rad_legend_draw(cairo_t *cr, const rad_legend_layout *layout, const rad_colour_map *map, const char *unit)
{
    /* The bar: one row per level band, set as pixels through rectangles
     * on the pixel grid (no antialiasing blur between rows). */
    cairo_save(cr);
    cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
    for (int y = layout->bar_top; y < layout->bar_bottom; y++) {
        const unsigned char *c = map->rgb[rad_legend_row_level(layout, y)];
        cairo_set_source_rgb(cr, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
        cairo_rectangle(cr, layout->bar_x, y, layout->bar_width, 1);
        cairo_fill(cr);
    }
    cairo_restore(cr);
    double font = layout->font_size;
    cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
    cairo_set_line_width(cr, 1.0);
    cairo_rectangle(cr, layout->bar_x - 0.5, layout->bar_top - 0.5, layout->bar_width + 1.0,
                    layout->bar_bottom - layout->bar_top + 1.0);
    cairo_stroke(cr);
    cairo_select_font_face(cr, RAD_PICTURE_FONT, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, font);
    double tick_end = layout->bar_x + layout->bar_width + 0.3 * font;
    for (size_t i = 0; i < layout->tick_count; i++) {
        double y = floor(layout->tick_y[i]) + 0.5;
        cairo_move_to(cr, layout->bar_x + layout->bar_width, y);
        cairo_line_to(cr, tick_end, y);
        cairo_stroke(cr);
        cairo_text_extents_t ext;
        cairo_text_extents(cr, layout->labels[i], &ext);
        cairo_move_to(cr, tick_end + 0.25 * font, y - (ext.y_bearing + 0.5 * ext.height));
        cairo_show_text(cr, layout->labels[i]);
    }
    cairo_set_font_size(cr, 1.1 * font);
    cairo_move_to(cr, layout->bar_x, 1.6 * font);
    cairo_show_text(cr, unit);
}

/* ---- the PNG, atomically ---- */

static cairo_status_t png_stream(void *closure, const unsigned char *data, unsigned int length)
{
    FILE *file = closure;
    return fwrite(data, 1, length, file) == length ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

rad_result rad_write_cairo_png(rad_context *ctx, cairo_surface_t *surface, const char *path)
{
    cairo_surface_flush(surface);
    if (cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: drawing failed: %s", path,
                        cairo_status_to_string(cairo_surface_status(surface)));
    rad_atomic_file file;
    rad_result r = rad_atomic_open(ctx, path, &file);
    if (r != RAD_OK)
        return r;
    cairo_status_t status = cairo_surface_write_to_png_stream(surface, png_stream, file.file);
    if (status != CAIRO_STATUS_SUCCESS) {
        rad_atomic_abort(&file);
        return status == CAIRO_STATUS_WRITE_ERROR
                   ? rad_fail(ctx, RAD_ERROR_IO, "%s: write failed", path)
                   : rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: PNG encoding failed: %s", path,
                              cairo_status_to_string(status));
    }
    return rad_atomic_commit(ctx, &file);
}

/* ---- the false colour picture ---- */

rad_result rad_false_colour_write(rad_context *ctx, const float *values, int width, int height,
                                  const rad_colour_scale *scale, const char *unit, bool contours,
                                  const char *path)
{
    rad_colour_map map;
    rad_colour_map_make(&map);
    rad_legend_layout legend;
    rad_legend_layout_make(scale, width, height, &legend);
    int total = width + legend.width;
    cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, total, height);
    cairo_t *cr = cairo_create(surface);
    cairo_set_source_rgb(cr, 1.0, 1.0, 1.0); /* the background: white */
    cairo_paint(cr);
    cairo_surface_flush(surface);
    unsigned char *data = cairo_image_surface_get_data(surface);
    int stride = cairo_image_surface_get_stride(surface);
    if (data) {
        for (int y = 0; y < height; y++) {
            uint32_t *row = (uint32_t *)(void *)(data + (size_t)y * (size_t)stride);
            const float *v = values + (size_t)y * (size_t)width;
            for (int x = 0; x < width; x++)
                if (isfinite(v[x]))
                    row[x] = rad_cairo_pixel(map.rgb[rad_scale_level(scale, v[x])]);
        }
        /* Isolines: a pixel whose value lies in another tick interval than
         * its right or lower neighbour's is drawn black. */
        if (contours && legend.tick_count > 0) {
            for (int y = 0; y < height; y++) {
                uint32_t *row = (uint32_t *)(void *)(data + (size_t)y * (size_t)stride);
                for (int x = 0; x < width; x++) {
                    float here = values[(size_t)y * (size_t)width + (size_t)x];
                    if (!isfinite(here))
                        continue;
                    size_t band = 0;
                    while (band < legend.tick_count && here >= legend.ticks[band])
                        band++;
                    float next[2] = {x + 1 < width ? values[(size_t)y * (size_t)width + (size_t)x + 1] : NAN,
                                     y + 1 < height ? values[(size_t)(y + 1) * (size_t)width + (size_t)x] : NAN};
                    for (int k = 0; k < 2; k++) {
                        if (!isfinite(next[k]))
                            continue;
                        size_t other = 0;
                        while (other < legend.tick_count && next[k] >= legend.ticks[other])
                            other++;
                        if (other != band)
                            row[x] = 0;
                    }
                }
            }
        }
        cairo_surface_mark_dirty(surface);
    }
    rad_legend_draw(cr, &legend, &map, unit);
    cairo_destroy(cr);
    rad_result r = rad_write_cairo_png(ctx, surface, path);
    cairo_surface_destroy(surface);
    return r;
}

/* ---- illuminance on the surfaces ---- */

/* gathered[c] = sum_j F_ij B_j for the channels where black[c]: from the
 * view's F, or without it the unoccluded factor from the lifted centroid
 * of i to each element j it faces, counted when the segment to j's lifted
 * centroid is clear (one ray a pair for all channels). */
static void gather(const rad_solution_view *view, size_t i, const bool black[3], double gathered[3])
{
    const rad_mesh *mesh = view->mesh;
    gathered[0] = gathered[1] = gathered[2] = 0.0;
    if (view->F) {
        const double *row = view->F + i * view->n;
        for (size_t j = 0; j < view->n; j++)
            for (int c = 0; c < 3; c++)
                if (black[c])
                    gathered[c] += row[j] * view->radiosity[3 * j + (size_t)c];
        return;
    }
    const rad_element *ei = &mesh->elements[i];
    double eps = rad_vis_epsilon(mesh);
    vec3 p = v3_mad(ei->centroid, ei->normal, eps);
    for (size_t j = 0; j < view->n; j++) {
        const double *B = &view->radiosity[3 * j];
        if (j == i || !((black[0] && B[0] != 0.0) || (black[1] && B[1] != 0.0) || (black[2] && B[2] != 0.0)))
            continue;
        const rad_element *ej = &mesh->elements[j];
        vec3 poly[4];
        for (uint32_t k = 0; k < ej->vertex_count; k++)
            poly[k] = mesh->vertices[ej->vertex[k]];
        double f = rad_point_polygon_ff(p, ei->normal, poly, ej->vertex_count);
        if (!(f > 0.0))
            continue;
        vec3 q = v3_mad(ej->centroid, ej->normal, eps);
        rad_ray ray = {p, v3_sub(q, p), 0.0, 1.0 - 1e-6}; /* stops short of j itself */
        uint8_t blocked = 0;
        view->vis->backend->occluded(view->vis->state, &ray, 1, &blocked);
        for (int c = 0; c < 3 && !blocked; c++)
            if (black[c])
                gathered[c] += f * B[c];
    }
}

rad_result rad_view_illuminance(rad_context *ctx, const rad_solution_view *view, double *lux)
{
    size_t n = view->n;
    int threads = view->threads > 0 ? view->threads : 1;
    int cancelled = 0;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 64)
    for (size_t i = 0; i < n; i++) {
        int stop;
#pragma omp atomic read
        stop = cancelled;
        if (stop || ((i & 255) == 0 && rad_cancelled(ctx))) {
#pragma omp atomic write
            cancelled = 1;
            continue;
        }
        double H[3], gathered[3] = {0.0, 0.0, 0.0};
        bool black[3];
        for (int c = 0; c < 3; c++)
            black[c] = !(view->reflectance[3 * i + (size_t)c] > 0.0);
        if (black[0] || black[1] || black[2])
            gather(view, i, black, gathered);
        for (int c = 0; c < 3; c++) {
            size_t k = 3 * i + (size_t)c;
            double direct = view->direct ? view->direct[k] : 0.0;
            double indirect = black[c] ? gathered[c] : (view->radiosity[k] - view->emission[k]) / view->reflectance[k];
            H[c] = fmax(indirect + direct, 0.0); /* round-off of B - E where nothing arrives */
        }
        lux[i] = RAD_LUMINOUS_EFFICACY * (RAD_Y_R * H[0] + RAD_Y_G * H[1] + RAD_Y_B * H[2]);
    }
    if (cancelled)
        return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "false colour: interrupted");
    return RAD_OK;
}
