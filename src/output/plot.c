/*
 * plot.c -- the plan of one calculation grid as a PNG (cairo): cells
 * coloured by value through the false colour map (picture.h) with the
 * value printed in each, the grid's outline, the legend, and a title line
 * with the figures a lighting designer checks first: the average, the
 * minimum, the maximum and the uniformity U0 = min / avg (EN 12464-1's
 * definition over the grid's points).  Free points are labelled dots.
 *
 *   +--------------------------------------------+--------+
 *   | office: Eavg 412 lx, Emin 198 lx, ... U0 ..|   lx   |
 *   | +----+----+----+                           |  ##    |
 *   | |312 |405 |320 |   v                       |  ##    |
 *   | +----+----+----+   ^                       |  ##    |
 *   | |298 |390 |301 |   +--> u                  |        |
 *   | +----+----+----+                           |        |
 *   +--------------------------------------------+--------+
 *
 * The plan's scale is one metre to the same pixels in u and v (the room
 * keeps its shape); the labels' font is the largest that fits a cell
 * (never below RAD_PLOT_MIN_FONT px: smaller cells go unlabelled).
 */
#include "output/picture.h"

#include <stdlib.h>
#include <string.h>

void rad_plot_grid_label(const rad_plot_grid *grid, size_t k, char *text, size_t size)
{
    rad_format_value(grid->value[k], text, size);
}

/* Mean, minimum and maximum of the values. */
static void grid_figures(const rad_plot_grid *grid, double *avg, double *min, double *max)
{
    double sum = 0.0;
    *min = INFINITY;
    *max = -INFINITY;
    for (size_t k = 0; k < grid->count; k++) {
        sum += grid->value[k];
        *min = fmin(*min, grid->value[k]);
        *max = fmax(*max, grid->value[k]);
    }
    *avg = grid->count ? sum / (double)grid->count : 0.0;
}

void rad_plot_grid_title(const rad_plot_grid *grid, char *text, size_t size)
{
    double avg, min, max;
    grid_figures(grid, &avg, &min, &max);
    char a[32], lo[32], hi[32], u0[32];
    rad_format_value(avg, a, sizeof a);
    rad_format_value(min, lo, sizeof lo);
    rad_format_value(max, hi, sizeof hi);
    if (avg > 0.0)
        snprintf(u0, sizeof u0, "%.2f", min / avg);
    else
        snprintf(u0, sizeof u0, "-");
    const char *unit = grid->unit ? grid->unit : "";
    const char *symbol = strcmp(unit, "lx") == 0 ? "E" : "";
    snprintf(text, size, "%s: %savg %s %s, %smin %s %s, %smax %s %s, U0 %s", grid->name ? grid->name : "grid",
             symbol, a, unit, symbol, lo, unit, symbol, hi, unit, u0);
}

static rad_result check_grid(rad_context *ctx, const rad_plot_grid *grid, const rad_plot_options *o,
                             const char *path)
{
    if (grid->count == 0 || !grid->u || !grid->v || !grid->value)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: grid plot: the grid '%s' has no points", path,
                        grid->name ? grid->name : "");
    if ((grid->nu || grid->nv) && (grid->nu == 0 || grid->nv == 0 || grid->count / grid->nu > grid->nv ||
                                   grid->nu * grid->nv < grid->count))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: grid plot: %zu x %zu cells for %zu points", path, grid->nu, grid->nv, grid->count);
    if (!(grid->cell_u >= 0.0 && grid->cell_v >= 0.0 && isfinite(grid->cell_u) && isfinite(grid->cell_v)))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: grid plot: cell sides %g x %g m", path,
                        grid->cell_u, grid->cell_v);
    for (size_t k = 0; k < grid->count; k++)
        if (!isfinite(grid->u[k]) || !isfinite(grid->v[k]) || !isfinite(grid->value[k]))
            return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                            "%s: grid plot: point %zu of '%s' is not finite", path, k, grid->name ? grid->name : "");
    if (o->width != 0 && (o->width < 200 || o->width > 8192))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: grid plot: width %d outside [200, 8192]", path,
                        o->width);
    return RAD_OK;
}

/* Text centred on (x, y). */
static void centred_text(cairo_t *cr, double x, double y, const char *text)
{
    cairo_text_extents_t ext;
    cairo_text_extents(cr, text, &ext);
    cairo_move_to(cr, x - (ext.x_bearing + 0.5 * ext.width), y - (ext.y_bearing + 0.5 * ext.height));
    cairo_show_text(cr, text);
}

/* Black text on light colours, white on dark (L* of the colour). */
static void text_colour_for(cairo_t *cr, const unsigned char rgb[3])
{
    double linear[3];
    for (int k = 0; k < 3; k++) {
        double c = rgb[k] / 255.0;
        linear[k] = c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
    }
    double grey = rad_srgb_lightness(linear) > 55.0 ? 0.0 : 1.0;
    cairo_set_source_rgb(cr, grey, grey, grey);
}

void rad_plot_pixel(const rad_plot_layout *layout, double u, double v, double *x, double *y)
{
    *x = layout->px0 + (u - layout->x0m) * layout->pixels_per_metre;
    *y = layout->py0 + (layout->y1m - v) * layout->pixels_per_metre;
}

/* The characters of the longest value label. */
static size_t longest_label(const rad_plot_grid *grid)
{
    size_t longest = 1;
    char label[32];
    for (size_t k = 0; k < grid->count; k++) {
        rad_plot_grid_label(grid, k, label, sizeof label);
        longest = strlen(label) > longest ? strlen(label) : longest;
    }
    return longest;
}

rad_result rad_plot_layout_make(rad_context *ctx, const rad_plot_grid *grid, const rad_plot_options *options,
                                const char *path, rad_plot_layout *layout)
{
    memset(layout, 0, sizeof *layout);
    rad_plot_options o = options ? *options : (rad_plot_options){0};
    rad_result r = check_grid(ctx, grid, &o, path);
    if (r != RAD_OK)
        return r;
    bool regular = grid->nu > 0;
    /* The scale: given, or automatic over the values. */
    rad_colour_scale scale = {o.log_scale != 0, o.range_min, o.range_max};
    if (o.range_min == 0.0 && o.range_max == 0.0) {
        float *values = rad_alloc(ctx, RAD_MEM_OUTPUT, grid->count, sizeof *values, "grid plot: values");
        if (!values)
            return RAD_ERROR_OUT_OF_MEMORY;
        for (size_t k = 0; k < grid->count; k++)
            values[k] = (float)grid->value[k];
        r = rad_scale_automatic(ctx, scale.log, values, grid->count, &scale);
        rad_free(values);
        if (r != RAD_OK)
            return r;
    } else if (!isfinite(o.range_min) || !isfinite(o.range_max) || !(o.range_min < o.range_max) ||
               (o.log_scale && !(o.range_min > 0.0))) {
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: grid plot: range %g:%g must have min < max (and min > 0 on a log scale)", path,
                        o.range_min, o.range_max);
    }
    layout->scale = scale;

    /* The plan's extent in metres: the cells' (or points', with a margin). */
    double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY;
    for (size_t k = 0; k < grid->count; k++) {
        umin = fmin(umin, grid->u[k]);
        umax = fmax(umax, grid->u[k]);
        vmin = fmin(vmin, grid->v[k]);
        vmax = fmax(vmax, grid->v[k]);
    }
    double du, dv;
    if (regular) {
        du = grid->cell_u > 0.0 ? grid->cell_u : grid->nu > 1 ? (umax - umin) / (double)(grid->nu - 1) : 0.0;
        dv = grid->cell_v > 0.0 ? grid->cell_v : grid->nv > 1 ? (vmax - vmin) / (double)(grid->nv - 1) : 0.0;
        if (du == 0.0)
            du = dv > 0.0 ? dv : 1.0; /* one column: square cells (or 1 m) */
        if (dv == 0.0)
            dv = du;
    } else {
        double pad = 0.08 * fmax(fmax(umax - umin, vmax - vmin), 1e-3);
        du = dv = 2.0 * pad;
    }
    layout->du = du;
    layout->dv = dv;
    layout->x0m = umin - 0.5 * du;
    layout->y1m = vmax + 0.5 * dv;
    layout->metres_w = umax - umin + du;
    layout->metres_h = vmax - vmin + dv;

    int width = o.width ? o.width : 900;
    double title_font = fmin(fmax(width / 60.0, 10.0), 24.0);
    double margin = 1.5 * title_font, title_band = 2.4 * title_font;
    int legend_width = (int)lround(6.5 * title_font); /* the legend's text as large as the title's */
    double plan_w = width - legend_width - 2.0 * margin;
    double ppm = plan_w / layout->metres_w;
    if (layout->metres_h * ppm > 1.5 * plan_w) /* a tall grid: no taller than 1.5 x its width */
        ppm = 1.5 * plan_w / layout->metres_h;
    int height = (int)ceil(title_band + layout->metres_h * ppm + margin);
    layout->width = width;
    layout->height = height < 240 ? 240 : height;
    layout->px0 = margin;
    layout->py0 = title_band;
    layout->pixels_per_metre = ppm;
    layout->title_font = title_font;
    /* The labels' font: the largest that fits a cell (0.62 em a digit, a
     * DejaVu Sans figure's advance), at most 22 px. */
    double cell_w = du * ppm, cell_h = dv * ppm;
    layout->font = regular ? fmin(fmin(0.85 * cell_w / (0.62 * (double)longest_label(grid)), 0.45 * cell_h), 22.0)
                           : fmin(fmax(title_font * 0.8, RAD_PLOT_MIN_FONT), 18.0);
    layout->labelled = layout->font >= RAD_PLOT_MIN_FONT;
    return RAD_OK;
}

rad_result rad_plot_grid_write(rad_context *ctx, const rad_plot_grid *grid, const rad_plot_options *options,
                               const char *path)
{
    rad_plot_layout lay;
    rad_result r = rad_plot_layout_make(ctx, grid, options, path, &lay);
    if (r != RAD_OK)
        return r;
    bool regular = grid->nu > 0;
    int legend_width = (int)lround(6.5 * lay.title_font);
    rad_colour_map map;
    rad_colour_map_make(&map);
    rad_legend_layout legend;
    rad_legend_layout_make_font(&lay.scale, lay.width - legend_width, lay.height, lay.title_font, &legend);

    cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, lay.width, lay.height);
    cairo_t *cr = cairo_create(surface);
    cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
    cairo_paint(cr);
    cairo_select_font_face(cr, RAD_PICTURE_FONT, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);

    /* The title line. */
    char title[512];
    rad_plot_grid_title(grid, title, sizeof title);
    cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
    cairo_set_font_size(cr, lay.title_font);
    cairo_move_to(cr, lay.px0, 1.5 * lay.title_font);
    cairo_show_text(cr, title);

    double font = lay.font, cell_w = lay.du * lay.pixels_per_metre, cell_h = lay.dv * lay.pixels_per_metre;
    cairo_set_font_size(cr, font);
    char label[32];
    for (size_t k = 0; k < grid->count; k++) {
        double x, y;
        rad_plot_pixel(&lay, grid->u[k], grid->v[k], &x, &y);
        const unsigned char *c = map.rgb[rad_scale_level(&lay.scale, grid->value[k])];
        cairo_set_source_rgb(cr, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
        rad_plot_grid_label(grid, k, label, sizeof label);
        if (regular) {
            /* The cell, on whole pixels so that neighbours meet without seams. */
            double left = round(x - 0.5 * cell_w), right = round(x + 0.5 * cell_w);
            double top = round(y - 0.5 * cell_h), bottom = round(y + 0.5 * cell_h);
            cairo_save(cr);
            cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
            cairo_rectangle(cr, left, top, right - left, bottom - top);
            cairo_fill(cr);
            cairo_restore(cr);
            if (lay.labelled) {
                text_colour_for(cr, c);
                centred_text(cr, x, y, label);
            }
        } else {
            double radius = fmax(0.45 * font, 3.0);
            cairo_new_path(cr); /* no line from the last label's end */
            cairo_arc(cr, x, y, radius, 0.0, 2.0 * M_PI);
            cairo_fill_preserve(cr);
            cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
            cairo_set_line_width(cr, 1.0);
            cairo_stroke(cr);
            if (lay.labelled) {
                cairo_move_to(cr, x + radius + 0.3 * font, y + 0.35 * font);
                cairo_show_text(cr, label);
            }
        }
    }
    /* The outline: the grid's cells (free points: their frame). */
    cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
    cairo_set_line_width(cr, 1.5);
    cairo_rectangle(cr, round(lay.px0), round(lay.py0), round(lay.metres_w * lay.pixels_per_metre),
                    round(lay.metres_h * lay.pixels_per_metre));
    cairo_stroke(cr);

    rad_legend_draw(cr, &legend, &map, grid->unit ? grid->unit : "");
    cairo_destroy(cr);
    r = rad_write_cairo_png(ctx, surface, path);
    cairo_surface_destroy(surface);
    return r;
}
