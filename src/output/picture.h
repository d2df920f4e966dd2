/*
 * picture.h -- what the two picture writers share (falsecolour.c, plot.c):
 * the colour map, the scale that puts a value on it, the legend drawn with
 * cairo, and the atomic PNG writer of a cairo surface.  Internal to
 * output/: only these two files and the tests include cairo.
 *
 *   value --scale--> position t in [0, 1] --map--> one of 256 sRGB colours
 *
 *   +---------------------------+----------+
 *   |                           |   lx     |  the unit
 *   |   picture (false colour   |  ##-500  |  the bar, bottom = min,
 *   |   or plan of a grid)      |  ##-250  |  top = max, ticks at the
 *   |                           |  ##-0    |  rule's values
 *   +---------------------------+----------+
 */
#ifndef RAD_PICTURE_H
#define RAD_PICTURE_H

#include "output/output.h"

#include <cairo.h>

/* The map's resolution: colours per scale (docs/lighting.md, "Pictures"). */
#define RAD_COLOUR_LEVELS 256
/* Most ticks the rule gives (a log scale of many decades keeps decades). */
#define RAD_LEGEND_MAX_TICKS 24

typedef struct rad_colour_map {
    unsigned char rgb[RAD_COLOUR_LEVELS][3]; /* 8-bit sRGB, level 0 = the scale's min */
} rad_colour_map;

/* The map, computed (no table): CIE L*a*b* (D65) along a path whose
 * lightness rises linearly, L* = RAD_MAP_L0 .. RAD_MAP_L1, while the hue
 * turns from violet-blue through cyan and green to yellow, the chroma cut
 * to the sRGB gamut where it leaves it.  Cannot fail. */
void rad_colour_map_make(rad_colour_map *map);
#define RAD_MAP_L0 15.0
#define RAD_MAP_L1 88.0
/* The map's linear sRGB at t in [0, 1] before 8-bit encoding (each in
 * [0, 1]).  Cannot fail. */
void rad_colour_map_linear(double t, double rgb[3]);
/* CIE L* of a linear sRGB colour (D65).  Cannot fail. */
double rad_srgb_lightness(const double rgb[3]);

/* A scale: [min, max], linear or logarithmic. */
typedef struct rad_colour_scale {
    bool log;
    double min, max;
} rad_colour_scale;

/* The value's position: (v - min) / (max - min), or in log10 for a log
 * scale, clamped to [0, 1] (a log scale's v <= 0 is 0).  Cannot fail. */
double rad_scale_position(const rad_colour_scale *scale, double value);
/* The map level of a value: round(position x (levels - 1)). */
int rad_scale_level(const rad_colour_scale *scale, double value);

/* The automatic range of `count` values (NaN ones left out; docs/lighting.md
 * "Pictures"): the top is the 99th percentile (nearest rank) rounded up to
 * a nice number (1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 x 10^k); linear from 0,
 * log from top / 1000.  Fails only for memory. */
rad_result rad_scale_automatic(rad_context *ctx, bool log, const float *values, size_t count,
                               rad_colour_scale *scale);

/* The legend's tick values in ticks[] (at most RAD_LEGEND_MAX_TICKS), the
 * count returned: linear, the multiples of the nicest step (1, 2, 2.5, 5 x
 * 10^k) that gives at most 8 intervals over the range; log, the values
 * m x 10^k in the range for m in {1, 2, 5}, or {1, ..., 9} when that gives
 * fewer than 3, or {1} when more than 12.  Cannot fail. */
size_t rad_legend_ticks(const rad_colour_scale *scale, double *ticks);
/* A number as the legend and the plots print it: three significant
 * figures below 100, an integer above, at most 6 decimals, trailing zeros
 * dropped (1234, 56.8, 0.75, 0; docs/lighting.md).  Cannot fail. */
void rad_format_value(double value, char *text, size_t size);

/* Where the legend goes on a canvas of height `height` with the picture
 * `picture_width` wide: the bar's box and the text size. */
typedef struct rad_legend_layout {
    int x;                  /* the legend's left edge: picture_width */
    int width;              /* px */
    int bar_x, bar_width;   /* px */
    int bar_top, bar_bottom;/* px: rows of the max and of the min (exclusive bottom) */
    double font_size;       /* px */
    size_t tick_count;
    double ticks[RAD_LEGEND_MAX_TICKS];
    double tick_y[RAD_LEGEND_MAX_TICKS];          /* px: the tick's row centre */
    char labels[RAD_LEGEND_MAX_TICKS][24];        /* as drawn, rad_format_value */
} rad_legend_layout;

void rad_legend_layout_make(const rad_colour_scale *scale, int picture_width, int height,
                            rad_legend_layout *layout);
/* The same with the text size given (px) instead of taken from the height. */
void rad_legend_layout_make_font(const rad_colour_scale *scale, int picture_width, int height, double font,
                                 rad_legend_layout *layout);
/* The legend's text size (px) and width for a canvas of `height` (px). */
double rad_legend_font(int height);
int rad_legend_width(int height);
/* The colour level of bar row y (bar_top <= y < bar_bottom). */
int rad_legend_row_level(const rad_legend_layout *layout, int y);
/* Draw it: the bar, ticks, labels and the unit (UTF-8) above. */
void rad_legend_draw(cairo_t *cr, const rad_legend_layout *layout, const rad_colour_map *map, const char *unit);

/* A cairo RGB24 pixel of an 8-bit sRGB colour. */
static inline uint32_t rad_cairo_pixel(const unsigned char rgb[3])
{
    return (uint32_t)rgb[0] << 16 | (uint32_t)rgb[1] << 8 | (uint32_t)rgb[2];
}

/* The surface as PNG written atomically at `path` (a temporary renamed
 * over it; nothing there on failure).  RAD_ERROR_IO naming the path,
 * RAD_ERROR_OUT_OF_MEMORY when cairo failed to draw or encode. */
rad_result rad_write_cairo_png(rad_context *ctx, cairo_surface_t *surface, const char *path);

/* Where a grid plot puts things (plot.c): the canvas, the plan's frame
 * and scale, the cells and the labels' font. */
typedef struct rad_plot_layout {
    int width, height;        /* px: the canvas */
    double x0m, y1m;          /* m: the plan's left edge (u) and top edge (v) */
    double metres_w, metres_h;/* m: the plan's extent */
    double px0, py0;          /* px: where the plan's top-left corner is drawn */
    double pixels_per_metre;
    double du, dv;            /* m: a cell (regular grids; free points: the margin x 2) */
    double title_font, font;  /* px */
    bool labelled;            /* font >= RAD_PLOT_MIN_FONT */
    rad_colour_scale scale;   /* the range used */
} rad_plot_layout;

/* The layout of `grid` with `options` (checked: RAD_ERROR_INVALID_ARGUMENT
 * as rad_plot_grid_write says; `path` names the output in messages).
 * Fails also for memory (the automatic range). */
rad_result rad_plot_layout_make(rad_context *ctx, const rad_plot_grid *grid, const rad_plot_options *options,
                                const char *path, rad_plot_layout *layout);
/* The pixel (x right, y down) of plan point (u, v).  Cannot fail. */
void rad_plot_pixel(const rad_plot_layout *layout, double u, double v, double *x, double *y);

/* Font family for every text (fontconfig picks what is installed). */
#define RAD_PICTURE_FONT "DejaVu Sans"

#endif /* RAD_PICTURE_H */
