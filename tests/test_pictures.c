/*
 * test_pictures.c -- pictures people read (docs/lighting.md "Pictures"):
 * the colour map (monotone in CIE L*, its end colours), the scale, the
 * legend's tick rule and labels, false colour images of scenes with
 * closed-form values (a closed uniform box: L = 179 Y(E / (1 - rho)) / pi
 * everywhere; a floor under a square emitter: Lambert's point-to-rectangle
 * factor), grid plots (cell colours, printed values, title figures), bad
 * options through the library and the program, and atomic outputs.
 *
 * Pictures are read back with stb_image; every expected colour is the map's
 * entry for the closed-form value, so a wrong value, scale, map or legend
 * shows as a wrong pixel.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "cli_support.h"
#include "output/picture.h"
#include "photometry/photometry.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wcast-qual"
#pragma GCC diagnostic ignored "-Wmissing-prototypes"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#endif
#define STB_IMAGE_IMPLEMENTATION /* to read back what the writers wrote */
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

static char *work_path(const char *name)
{
    static char path[4][512];
    static int next;
    char *p = path[next++ % 4];
    snprintf(p, sizeof path[0], "%s/%s", test_workdir(), name);
    return p;
}

typedef struct picture {
    int width, height;
    unsigned char *rgb;
} picture;

static picture read_png(const char *path)
{
    picture p = {0};
    int channels = 0;
    p.rgb = stbi_load(path, &p.width, &p.height, &channels, 3);
    if (!p.rgb)
        fail_msg("%s: cannot read the PNG back", path);
    return p;
}

static const unsigned char *pixel_at(const picture *p, int x, int y)
{
    assert_true(x >= 0 && x < p->width && y >= 0 && y < p->height);
    return p->rgb + 3 * ((size_t)y * (size_t)p->width + (size_t)x);
}

static bool same_colour(const unsigned char *a, const unsigned char *b)
{
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

static void assert_colour(const unsigned char *got, const unsigned char *want, const char *what)
{
    if (!same_colour(got, want))
        fail_msg("%s: got #%02x%02x%02x, want #%02x%02x%02x", what, got[0], got[1], got[2], want[0], want[1],
                 want[2]);
}

/* The map level whose colour a pixel has, or -1. */
static int level_of(const rad_colour_map *map, const unsigned char *rgb)
{
    for (int i = 0; i < RAD_COLOUR_LEVELS; i++)
        if (same_colour(map->rgb[i], rgb))
            return i;
    return -1;
}

static bool is_white(const unsigned char *rgb) { return rgb[0] == 255 && rgb[1] == 255 && rgb[2] == 255; }

static size_t count_files(const char *folder)
{
    DIR *d = opendir(folder);
    assert_non_null(d);
    size_t n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (e->d_name[0] != '.' || (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0))
            n++;
    closedir(d);
    return n;
}

static double srgb_decode(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

/* ---- the colour map ---- */

static void test_colour_map(void **state)
{
    (void)state;
    rad_colour_map map;
    rad_colour_map_make(&map);
    double previous = -1.0, previous8 = -1.0;
    for (int i = 0; i < RAD_COLOUR_LEVELS; i++) {
        double t = (double)i / (RAD_COLOUR_LEVELS - 1), linear[3];
        rad_colour_map_linear(t, linear);
        /* The designed lightness, exactly (the gamut cut keeps L*)... */
        double L = rad_srgb_lightness(linear);
        assert_near(L, RAD_MAP_L0 + (RAD_MAP_L1 - RAD_MAP_L0) * t, 1e-4); /* the matrices' digits */
        assert_true(L > previous);
        previous = L;
        /* ...and the 8-bit colours within the encoding's rounding of it. */
        double decoded[3];
        for (int k = 0; k < 3; k++)
            decoded[k] = srgb_decode(map.rgb[i][k] / 255.0);
        double L8 = rad_srgb_lightness(decoded);
        assert_near(L8, L, 0.5);
        if (i % 4 == 0) { /* 4 levels = 1.2 L*, more than two roundings apart */
            assert_true(L8 > previous8);
            previous8 = L8;
        }
    }
    /* The end colours (docs/lighting.md): dark blue #002359, yellow #f9dd1b. */
    const unsigned char low[3] = {0x00, 0x23, 0x59}, high[3] = {0xf9, 0xdd, 0x1b};
    assert_colour(map.rgb[0], low, "map at the range's min");
    assert_colour(map.rgb[RAD_COLOUR_LEVELS - 1], high, "map at the range's max");
    /* The scale's ends take them: min and below, max and above. */
    rad_colour_scale lin = {false, 10.0, 510.0}, lg = {true, 1.0, 1000.0};
    assert_int_equal(rad_scale_level(&lin, 10.0), 0);
    assert_int_equal(rad_scale_level(&lin, -5.0), 0);
    assert_int_equal(rad_scale_level(&lin, 510.0), RAD_COLOUR_LEVELS - 1);
    assert_int_equal(rad_scale_level(&lin, 1e9), RAD_COLOUR_LEVELS - 1);
    assert_int_equal(rad_scale_level(&lin, 260.0), 128); /* 127.5 rounds up */
    assert_int_equal(rad_scale_level(&lg, 1.0), 0);
    assert_int_equal(rad_scale_level(&lg, 0.0), 0);
    assert_int_equal(rad_scale_level(&lg, 1000.0), RAD_COLOUR_LEVELS - 1);
    assert_near(rad_scale_position(&lg, 10.0), 1.0 / 3.0, 1e-12);
    assert_near(rad_scale_position(&lg, sqrt(1000.0)), 0.5, 1e-12);
}

/* ---- the scale's automatic range, the tick rule, the labels ---- */

static void assert_ticks(const rad_colour_scale *scale, const double *want, size_t count)
{
    double ticks[RAD_LEGEND_MAX_TICKS];
    size_t n = rad_legend_ticks(scale, ticks);
    if (n != count)
        fail_msg("%s [%g, %g]: %zu ticks, want %zu", scale->log ? "log" : "linear", scale->min, scale->max, n,
                 count);
    for (size_t i = 0; i < n; i++)
        assert_near(ticks[i], want[i], 1e-9 * fabs(want[i]));
}

static void test_ticks_and_labels(void **state)
{
    (void)state;
    const double t500[] = {0, 100, 200, 300, 400, 500};
    assert_ticks(&(rad_colour_scale){false, 0, 500}, t500, 6);
    const double t50[] = {0, 10, 20, 30, 40, 50};
    assert_ticks(&(rad_colour_scale){false, 0, 50}, t50, 6);
    const double t15[] = {0, 2, 4, 6, 8, 10, 12, 14};
    assert_ticks(&(rad_colour_scale){false, 0, 15}, t15, 8);
    const double t25[] = {0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0};
    assert_ticks(&(rad_colour_scale){false, 0.0, 2.0}, t25, 9);
    const double t04[] = {0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0};
    assert_ticks(&(rad_colour_scale){false, 0.4, 2.0}, t04, 9);
    const double tlog[] = {0.2, 0.5, 1, 2, 5, 10, 20, 50, 100, 200};
    assert_ticks(&(rad_colour_scale){true, 0.2, 200}, tlog, 10);
    const double tdecades[] = {1, 10, 100, 1e3, 1e4, 1e5, 1e6};
    assert_ticks(&(rad_colour_scale){true, 1, 1e6}, tdecades, 7);
    const double tnarrow[] = {30, 40, 50, 60};
    assert_ticks(&(rad_colour_scale){true, 30, 60}, tnarrow, 4);

    char text[32];
    const struct { double value; const char *text; } labels[] = {
        {0.0, "0"}, {100.0, "100"}, {1234.4, "1234"}, {56.78, "56.8"}, {2.5, "2.5"}, {0.0123, "0.0123"},
        {0.75, "0.75"}, {-0.0, "0"}, {5e-9, "0"}, {12.0, "12"}};
    for (size_t i = 0; i < sizeof labels / sizeof labels[0]; i++) {
        rad_format_value(labels[i].value, text, sizeof text);
        if (strcmp(text, labels[i].text) != 0)
            fail_msg("%g printed as '%s', want '%s'", labels[i].value, text, labels[i].text);
    }

    /* Automatic: the 99th percentile (nearest rank) rounded up nicely. */
    rad_context *ctx = test_context(2);
    float values[200];
    for (int i = 0; i < 200; i++)
        values[i] = (float)i; /* rank 198 of 200: 197 -> 200 */
    values[7] = NAN;          /* the background: left out (rank 197 of 199: 197) */
    rad_colour_scale s;
    assert_int_equal(rad_scale_automatic(ctx, false, values, 200, &s), RAD_OK);
    assert_false(s.log);
    assert_near(s.min, 0.0, 0.0);
    assert_near(s.max, 200.0, 1e-9);
    assert_int_equal(rad_scale_automatic(ctx, true, values, 200, &s), RAD_OK);
    assert_near(s.max, 200.0, 1e-9);
    assert_near(s.min, 0.2, 1e-12);
    float dark[3] = {0.0f, 0.0f, NAN};
    assert_int_equal(rad_scale_automatic(ctx, false, dark, 3, &s), RAD_OK);
    assert_near(s.max, 1.0, 0.0);
    float one[1] = {31.0f};
    assert_int_equal(rad_scale_automatic(ctx, false, one, 1, &s), RAD_OK);
    assert_near(s.max, 40.0, 1e-9);
    rad_context_destroy(ctx);
}

/* ---- the legend: its bar, its text ---- */

static void test_legend_and_contours(void **state)
{
    (void)state;
    rad_context *ctx = test_context(2);
    enum { W = 120, H = 300 };
    float *values = malloc(sizeof(float) * W * H);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            values[y * W + x] = x < 10 ? NAN : (float)(500.0 * (x - 10) / (W - 11)); /* a ramp, 0 to 500 */
    rad_colour_scale scale = {false, 0.0, 500.0};
    const char *path = work_path("legend.png");
    assert_int_equal(rad_false_colour_write(ctx, values, W, H, &scale, "lx", false, path), RAD_OK);
    rad_legend_layout legend;
    rad_legend_layout_make(&scale, W, H, &legend);
    picture p = read_png(path);
    assert_int_equal(p.width, W + legend.width);
    assert_int_equal(p.height, H);
    rad_colour_map map;
    rad_colour_map_make(&map);

    /* The background is white; the ramp's pixels are the map's. */
    assert_true(is_white(pixel_at(&p, 3, 100)));
    for (int x = 10; x < W; x += 7)
        assert_colour(pixel_at(&p, x, 150), map.rgb[rad_scale_level(&scale, values[150 * W + x])], "ramp pixel");
    /* The bar: every row the colour of its level, the ends the map's ends. */
    int bx = legend.bar_x + legend.bar_width / 2;
    for (int y = legend.bar_top; y < legend.bar_bottom; y++)
        assert_colour(pixel_at(&p, bx, y), map.rgb[rad_legend_row_level(&legend, y)], "bar row");
    assert_int_equal(rad_legend_row_level(&legend, legend.bar_top), RAD_COLOUR_LEVELS - 1);
    assert_int_equal(rad_legend_row_level(&legend, legend.bar_bottom - 1), 0);

    /* The rule's ticks, the labels as printed, and ink where each is. */
    const char *want[] = {"0", "100", "200", "300", "400", "500"};
    assert_int_equal(legend.tick_count, 6);
    int text_x0 = legend.bar_x + legend.bar_width + (int)(0.4 * legend.font_size);
    for (size_t i = 0; i < legend.tick_count; i++) {
        assert_string_equal(legend.labels[i], want[i]);
        int ink = 0;
        for (int y = (int)(legend.tick_y[i] - 0.5 * legend.font_size);
             y <= (int)(legend.tick_y[i] + 0.5 * legend.font_size); y++)
            for (int x = text_x0; x < p.width; x++)
                if (y >= 0 && y < H && !is_white(pixel_at(&p, x, y)))
                    ink++;
        if (ink < 8)
            fail_msg("label '%s': %d dark pixels where it is drawn", want[i], ink);
    }
    /* Halfway between two ticks, right of the tick marks: no text. */
    for (size_t i = 0; i + 1 < legend.tick_count; i++) {
        int y = (int)(0.5 * (legend.tick_y[i] + legend.tick_y[i + 1]));
        for (int x = text_x0; x < p.width; x++)
            assert_true(is_white(pixel_at(&p, x, y)));
    }
    /* The unit above the bar. */
    int ink = 0;
    for (int y = 0; y < legend.bar_top - 2; y++)
        for (int x = legend.x; x < p.width; x++)
            ink += !is_white(pixel_at(&p, x, y));
    assert_true(ink >= 8);
    stbi_image_free(p.rgb);

    /* Contours: black where the ramp crosses 100, 200, ... and nowhere else
     * (the columns between keep the map's colours). */
    assert_int_equal(rad_false_colour_write(ctx, values, W, H, &scale, "lx", true, path), RAD_OK);
    p = read_png(path);
    int black_columns = 0;
    for (int x = 10; x < W; x++) {
        const unsigned char *c = pixel_at(&p, x, 150);
        if (c[0] == 0 && c[1] == 0 && c[2] == 0) {
            black_columns++;
            double v = values[150 * W + x], next = values[150 * W + x + 1];
            assert_true(floor(v / 100.0) != floor(next / 100.0)); /* a tick lies between */
        } else {
            assert_colour(c, map.rgb[rad_scale_level(&scale, values[150 * W + x])], "between contours");
        }
    }
    assert_int_equal(black_columns, 5); /* 100, 200, 300, 400, 500 (the last column reaches 500) */
    stbi_image_free(p.rgb);
    free(values);
    rad_context_destroy(ctx);
}

/* ---- false colour of scenes with closed forms ---- */

/* Solve the OBJ scene at `path` with `solver` on elements of `mesh_size`. */
static rad_solution *solve_scene(rad_context *ctx, const char *path, const char *solver, double mesh_size,
                                 rad_scene **scene)
{
    assert_int_equal(rad_scene_load_file(ctx, path, scene), RAD_OK);
    rad_options o = {0};
    o.mesh_size = mesh_size;
    o.solver = solver;
    o.form_factors = "analytic";
    o.tolerance = 1e-10;
    if (strcmp(solver, "shooting") == 0) {
        o.form_factors = NULL;
        o.tolerance = 0.0;
    }
    rad_solution *sol = NULL;
    assert_int_equal(rad_solution_create(ctx, *scene, &o, &sol), RAD_OK);
    rad_result r = rad_solution_solve(ctx, sol);
    if (r != RAD_OK)
        fail_msg("solve: %s", rad_context_error(ctx));
    return sol;
}

/* A copy of a written scene's path that outlives its writer. */
static const char *scene_path(const char *path)
{
    static char kept[4][512];
    static int next;
    char *p = kept[next++ % 4];
    snprintf(p, sizeof kept[0], "%s", path);
    return p;
}

/* A closed cube, 1 m, every face reflectance rho and exitance E, normals in. */
static const char *write_uniform_box(double rho, double E)
{
    cli_scene_writer w;
    cli_scene_begin(&w, "uniform_box");
    cli_scene_material(&w, "wall", rho, E);
    const double faces[6][4][3] = {
        {{0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {0, 0, 0}}, /* floor, up */
        {{1, 1, 0}, {1, 1, 1}, {0, 1, 1}, {0, 1, 0}}, /* ceiling, down */
        {{0, 1, 0}, {0, 1, 1}, {0, 0, 1}, {0, 0, 0}}, /* x = 0, +x */
        {{1, 0, 1}, {1, 1, 1}, {1, 1, 0}, {1, 0, 0}}, /* x = 1, -x */
        {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 0}}, /* z = 0, +z */
        {{0, 1, 1}, {1, 1, 1}, {1, 0, 1}, {0, 0, 1}}, /* z = 1, -z */
    };
    const char *names[6] = {"floor", "ceiling", "west", "east", "north", "south"};
    for (int f = 0; f < 6; f++)
        cli_scene_polygon(&w, names[f], "wall", faces[f], 4);
    cli_scene_end(&w);
    return scene_path(w.obj_path);
}

/* The box's luminance picture on `scale` has the map's colour of the
 * closed form everywhere, and the legend's bar shows that very colour at
 * the value's row. */
static void check_box_picture(rad_context *ctx, rad_solution *sol, bool log, double min, double max, double lv)
{
    rad_camera camera = {{0.5, 0.5, 0.5}, {0.5, 0.5, 0.0}, {0.0, 1.0, 0.0}, 70.0};
    rad_render_options ro = {0};
    ro.width = 200;
    ro.height = 300;
    ro.camera = &camera;
    rad_false_colour_options fo = {RAD_FALSE_COLOUR_LUMINANCE, log, min, max, 0};
    const char *path = work_path(log ? "box_log.png" : "box_linear.png");
    assert_int_equal(rad_solution_write_false_colour(ctx, sol, &ro, &fo, path), RAD_OK);
    rad_colour_scale scale = {log, min, max};
    rad_colour_map map;
    rad_colour_map_make(&map);
    int level = rad_scale_level(&scale, lv);
    picture p = read_png(path);
    const int xs[] = {100, 5, 194, 40, 160}, ys[] = {150, 5, 294, 250, 30};
    for (int k = 0; k < 5; k++)
        assert_colour(pixel_at(&p, xs[k], ys[k]), map.rgb[level], "box pixel");
    rad_legend_layout legend;
    rad_legend_layout_make(&scale, 200, 300, &legend);
    int row = -1;
    for (int y = legend.bar_top; y < legend.bar_bottom && row < 0; y++)
        if (rad_legend_row_level(&legend, y) == level)
            row = y;
    assert_true(row >= 0); /* 264 rows: every level has one */
    assert_colour(pixel_at(&p, legend.bar_x + legend.bar_width / 2, row), pixel_at(&p, 100, 150),
                  "legend row of the box's luminance");
    stbi_image_free(p.rgb);
}

static void test_luminance_box(void **state)
{
    (void)state;
    const double rho = 0.5, E = 1.0;
    rad_context *ctx = test_context(2);
    rad_scene *scene = NULL;
    rad_solution *sol = solve_scene(ctx, write_uniform_box(rho, E), "direct", 0.25, &scene);
    /* B = E / (1 - rho) on every element, grey: Y(B) = B. */
    double lv = RAD_LUMINOUS_EFFICACY * (E / (1.0 - rho)) / M_PI; /* 113.95 cd/m^2 */
    /* Ranges that put the value on a level's centre: half a level (0.2 %)
     * either way is still that colour. */
    check_box_picture(ctx, sol, false, 0.0, lv * 255.0 / 160.0, lv);
    double decades = 3.0 * 100.0 / 255.0, low = lv / pow(10.0, decades);
    check_box_picture(ctx, sol, true, low, low * 1000.0, lv);
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* F from a point to an axis-aligned rectangle in a parallel plane at
 * height h, with one corner over the point, sides x and y (Lambert; the
 * standard differential-area-to-rectangle case, e.g. Howell's catalogue
 * B-3). */
static double corner_factor(double x, double y, double h)
{
    double X = x / h, Y = y / h, a = sqrt(1.0 + X * X), b = sqrt(1.0 + Y * Y);
    return (X / a * atan(Y / a) + Y / b * atan(X / b)) / (2.0 * M_PI);
}

/* The factor from floor point (x0, 0, 0) to the square |x|, |z| <= s at
 * height h (x0 >= 0). */
static double square_factor(double x0, double s, double h)
{
    double near = s - x0, far = s + x0; /* signed extents along x */
    double fx = corner_factor(far, s, h) + (near >= 0.0 ? corner_factor(near, s, h) : -corner_factor(-near, s, h));
    return 2.0 * fx; /* the two halves in z */
}

static const char *write_floor_scene(double rho_floor, double E, double s, double h)
{
    cli_scene_writer w;
    cli_scene_begin(&w, rho_floor > 0.0 ? "floor_lamp" : "black_floor_lamp");
    cli_scene_material(&w, "floor", rho_floor, 0.0);
    cli_scene_material(&w, "lamp", 0.0, E);
    const double floor[4][3] = {{-0.6, 0, -0.6}, {-0.6, 0, 0.6}, {0.6, 0, 0.6}, {0.6, 0, -0.6}};
    const double lamp[4][3] = {{-s, h, -s}, {s, h, -s}, {s, h, s}, {-s, h, s}};
    cli_scene_polygon(&w, "floor", "floor", floor, 4);
    cli_scene_polygon(&w, "lamp", "lamp", lamp, 4);
    cli_scene_end(&w);
    return scene_path(w.obj_path);
}

/* The illuminance picture of the floor, looked at from straight above at
 * 0.5 m (under the lamp, vfov 90: +-0.5 m), against 179 E F(point) at
 * chosen pixels: within one level of the map (0.4 % of the range). */
static void check_floor(const char *solver, double rho_floor, double tolerance_levels)
{
    const double E = 100.0, s = 0.25, h = 1.0, eye = 0.5;
    rad_context *ctx = test_context(2);
    rad_scene *scene = NULL;
    rad_solution *sol = solve_scene(ctx, write_floor_scene(rho_floor, E, s, h), solver, 0.05, &scene);
    enum { N = 101 };
    rad_camera camera = {{0.0, eye, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, 90.0};
    rad_render_options ro = {0};
    ro.width = N;
    ro.height = N;
    ro.camera = &camera;
    double centre = RAD_LUMINOUS_EFFICACY * E * square_factor(0.0, s, h);
    rad_false_colour_options fo = {RAD_FALSE_COLOUR_ILLUMINANCE, 0, 0.0, 2.0 * centre, 0};
    const char *path = work_path("floor.png");
    assert_int_equal(rad_solution_write_false_colour(ctx, sol, &ro, &fo, path), RAD_OK);
    rad_colour_scale scale = {false, 0.0, 2.0 * centre};
    rad_colour_map map;
    rad_colour_map_make(&map);
    picture p = read_png(path);
    const int xs[] = {50, 60, 75, 92, 5};
    for (int k = 0; k < 5; k++) {
        /* Pixel x's centre sees floor point x0 = eye tan(45) (2 (x + 0.5) / N - 1) (right = +x). */
        double x0 = eye * (2.0 * (xs[k] + 0.5) / N - 1.0);
        double lux = RAD_LUMINOUS_EFFICACY * E * square_factor(fabs(x0), s, h);
        int want = rad_scale_level(&scale, lux), got = level_of(&map, pixel_at(&p, xs[k], N / 2));
        if (got < 0 || abs(got - want) > tolerance_levels)
            fail_msg("%s, rho %g: pixel %d (x = %.3f m, %.2f lx) has level %d, the closed form's is %d", solver,
                     rho_floor, xs[k], x0, lux, got, want);
    }
    stbi_image_free(p.rgb);
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

static void test_illuminance_floor(void **state)
{
    (void)state;
    check_floor("direct", 0.5, 1);   /* H = (B - E) / rho */
    check_floor("direct", 0.0, 1);   /* black: sum_j F_ij B_j from the view's F */
    check_floor("shooting", 0.0, 1); /* black, no F: exact point factors from the centroid */
}

/* ---- grid plots ---- */

static void test_grid_plot(void **state)
{
    (void)state;
    rad_context *ctx = test_context(2);
    /* 3 x 2 cells of 1 m: the point iu + 3 iv at (0.5 + iu, 0.5 + iv). */
    const double u[6] = {0.5, 1.5, 2.5, 0.5, 1.5, 2.5}, v[6] = {0.5, 0.5, 0.5, 1.5, 1.5, 1.5};
    const double value[6] = {100.0, 250.0, 400.0, 12.345, 300.0, 0.5};
    rad_plot_grid grid = {"desk", 6, u, v, value, "lx", 3, 2, 0.0, 0.0};
    rad_plot_options po = {0, 0.0, 500.0, 900};
    const char *path = work_path("grid.png");
    assert_int_equal(rad_plot_grid_write(ctx, &grid, &po, path), RAD_OK);

    const char *want[6] = {"100", "250", "400", "12.3", "300", "0.5"};
    char text[256];
    for (size_t k = 0; k < 6; k++) {
        rad_plot_grid_label(&grid, k, text, sizeof text);
        assert_string_equal(text, want[k]);
    }
    /* avg = 1062.845 / 6 = 177.14; U0 = 0.5 / 177.14 = 0.0028 */
    rad_plot_grid_title(&grid, text, sizeof text);
    assert_string_equal(text, "desk: Eavg 177 lx, Emin 0.5 lx, Emax 400 lx, U0 0.00");

    rad_plot_layout lay;
    assert_int_equal(rad_plot_layout_make(ctx, &grid, &po, path, &lay), RAD_OK);
    assert_true(lay.labelled);
    picture p = read_png(path);
    assert_int_equal(p.width, lay.width);
    assert_int_equal(p.height, lay.height);
    rad_colour_map map;
    rad_colour_map_make(&map);
    rad_colour_scale scale = {false, 0.0, 500.0};
    double cell = lay.pixels_per_metre; /* 1 m cells */
    for (size_t k = 0; k < 6; k++) {
        double x, y;
        rad_plot_pixel(&lay, u[k], v[k], &x, &y);
        const unsigned char *c = map.rgb[rad_scale_level(&scale, value[k])];
        /* Away from the label and the edges: the cell's colour. */
        assert_colour(pixel_at(&p, (int)(x - 0.35 * cell), (int)(y - 0.35 * cell)), c, "cell corner");
        assert_colour(pixel_at(&p, (int)(x + 0.35 * cell), (int)(y + 0.35 * cell)), c, "cell corner");
        /* The label: other pixels than the cell's in its middle. */
        int ink = 0;
        for (int yy = (int)(y - 0.5 * lay.font); yy <= (int)(y + 0.5 * lay.font); yy++)
            for (int xx = (int)(x - 0.3 * cell); xx <= (int)(x + 0.3 * cell); xx++)
                ink += !same_colour(pixel_at(&p, xx, yy), c);
        if (ink < 10)
            fail_msg("cell %zu: no label drawn (%d pixels)", k, ink);
    }
    /* The title line has ink; the white margin under the plan has none. */
    int ink = 0;
    for (int y = 0; y < (int)lay.py0 - 2; y++)
        for (int x = 0; x < (int)(lay.px0 + lay.metres_w * cell); x++)
            ink += !is_white(pixel_at(&p, x, y));
    assert_true(ink > 50);
    stbi_image_free(p.rgb);

    /* A footprint: 3 x 2 cells of 1 m given, the last one off it (no
     * point): white, the others their colours. */
    rad_plot_grid foot = {"footprint", 5, u, v, value, "lx", 3, 2, 1.0, 1.0};
    const char *path3 = work_path("footprint.png");
    assert_int_equal(rad_plot_grid_write(ctx, &foot, &po, path3), RAD_OK);
    assert_int_equal(rad_plot_layout_make(ctx, &foot, &po, path3, &lay), RAD_OK);
    assert_near(lay.pixels_per_metre, cell, 1e-9); /* the same extent as the full grid */
    p = read_png(path3);
    for (size_t k = 0; k < 6; k++) {
        double x, y;
        rad_plot_pixel(&lay, u[k], v[k], &x, &y);
        const unsigned char *at = pixel_at(&p, (int)(x - 0.35 * cell), (int)(y - 0.35 * cell));
        if (k == 5)
            assert_true(is_white(at));
        else
            assert_colour(at, map.rgb[rad_scale_level(&scale, value[k])], "footprint cell");
    }
    stbi_image_free(p.rgb);

    /* Free points: labelled dots of their colour. */
    const double fu[3] = {0.0, 2.0, 4.0}, fv[3] = {0.0, 1.0, 0.5}, fval[3] = {50.0, 450.0, 250.0};
    rad_plot_grid points = {"points", 3, fu, fv, fval, "lx", 0, 0, 0.0, 0.0};
    const char *path2 = work_path("points.png");
    assert_int_equal(rad_plot_grid_write(ctx, &points, &po, path2), RAD_OK);
    assert_int_equal(rad_plot_layout_make(ctx, &points, &po, path2, &lay), RAD_OK);
    p = read_png(path2);
    for (size_t k = 0; k < 3; k++) {
        double x, y;
        rad_plot_pixel(&lay, fu[k], fv[k], &x, &y);
        assert_colour(pixel_at(&p, (int)x, (int)y), map.rgb[rad_scale_level(&scale, fval[k])], k == 0 ? "dot 0" : k == 1 ? "dot 1" : "dot 2");
        int label_ink = 0;
        for (int yy = (int)(y - 0.6 * lay.font); yy <= (int)(y + 0.6 * lay.font); yy++)
            for (int xx = (int)(x + lay.font); xx < (int)(x + 3.0 * lay.font) && xx < p.width; xx++)
                label_ink += !is_white(pixel_at(&p, xx, yy));
        assert_true(label_ink > 5);
    }
    stbi_image_free(p.rgb);
    rad_context_destroy(ctx);
}

/* ---- bad options, atomic outputs ---- */

static void expect_refused(rad_context *ctx, const rad_false_colour_options *o, const char *words)
{
    assert_int_equal(rad_false_colour_check(ctx, o), RAD_ERROR_INVALID_ARGUMENT);
    if (!strstr(rad_context_error(ctx), words))
        fail_msg("message '%s' lacks '%s'", rad_context_error(ctx), words);
}

static void test_bad_options(void **state)
{
    (void)state;
    rad_context *ctx = test_context(2);
    assert_int_equal(rad_false_colour_check(ctx, NULL), RAD_OK);
    assert_int_equal(rad_false_colour_check(ctx, &(rad_false_colour_options){0}), RAD_OK);
    expect_refused(ctx, &(rad_false_colour_options){RAD_FALSE_COLOUR_LUMINANCE, 0, 5.0, 2.0, 0},
                   "range min 5 must be below max 2");
    expect_refused(ctx, &(rad_false_colour_options){RAD_FALSE_COLOUR_LUMINANCE, 0, 3.0, 3.0, 0}, "below max");
    expect_refused(ctx, &(rad_false_colour_options){RAD_FALSE_COLOUR_ILLUMINANCE, 1, 0.0, 10.0, 0},
                   "log scale needs range min > 0");
    expect_refused(ctx, &(rad_false_colour_options){RAD_FALSE_COLOUR_ILLUMINANCE, 1, -1.0, 10.0, 0}, "log");
    expect_refused(ctx, &(rad_false_colour_options){(rad_false_colour_quantity)7, 0, 0.0, 0.0, 0},
                   "unknown quantity 7");
    expect_refused(ctx, &(rad_false_colour_options){RAD_FALSE_COLOUR_LUMINANCE, 0, 0.0, NAN, 0}, "not finite");

    /* Grid plots: each refusal leaves no file. */
    const double u[2] = {0, 1}, v[2] = {0, 0}, good[2] = {1, 2}, bad[2] = {1, NAN};
    const double u3[3] = {0, 1, 2}, v3[3] = {0, 0, 0}, good3[3] = {1, 2, 3};
    const char *path = work_path("bad_grid.png");
    size_t before = count_files(test_workdir());
    rad_api_enter(ctx); /* the internal calls below keep the first error otherwise */
    rad_plot_grid g = {"g", 3, u3, v3, good3, "lx", 2, 1, 0.0, 0.0};
    assert_int_equal(rad_plot_grid_write(ctx, &g, NULL, path), RAD_ERROR_INVALID_ARGUMENT);
    if (!strstr(rad_context_error(ctx), "2 x 1 cells for 3 points"))
        fail_msg("message: %s", rad_context_error(ctx));
    rad_api_enter(ctx);
    g = (rad_plot_grid){"g", 2, u, v, good, "lx", 2, 1, -1.0, 0.0};
    assert_int_equal(rad_plot_grid_write(ctx, &g, NULL, path), RAD_ERROR_INVALID_ARGUMENT);
    rad_api_enter(ctx);
    g = (rad_plot_grid){"g", 2, u, v, bad, "lx", 0, 0, 0.0, 0.0};
    assert_int_equal(rad_plot_grid_write(ctx, &g, NULL, path), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "not finite"));
    rad_api_enter(ctx);
    g = (rad_plot_grid){"g", 0, u, v, good, "lx", 0, 0, 0.0, 0.0};
    assert_int_equal(rad_plot_grid_write(ctx, &g, NULL, path), RAD_ERROR_INVALID_ARGUMENT);
    rad_api_enter(ctx);
    g = (rad_plot_grid){"g", 2, u, v, good, "lx", 0, 0, 0.0, 0.0};
    assert_int_equal(rad_plot_grid_write(ctx, &g, &(rad_plot_options){1, 0.0, 10.0, 0}, path),
                     RAD_ERROR_INVALID_ARGUMENT);
    rad_api_enter(ctx);
    assert_int_equal(rad_plot_grid_write(ctx, &g, &(rad_plot_options){0, 10.0, 1.0, 0}, path),
                     RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(count_files(test_workdir()), before);
    rad_context_destroy(ctx);

    /* The program: usage errors (exit 2) before any work, no output. */
    const char *out = work_path("cli.png"), *errors = work_path("cli.err");
    const struct { const char *flags, *message; } cases[] = {
        {"--false-colour illuminance --range 5:2", "range min 5 must be below max 2"},
        {"--false-colour luminance --scale log --range 0:10", "log scale needs range min > 0"},
        {"--false-colour brightness", "--false-colour"},
        {"--false-colour luminance --range 1:x", "expected MIN:MAX"},
        {"--range 1:2", "only with --false-colour"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int status = cli_run_capture(errors, "render %s -o %s", cases[i].flags, out);
        char *text = test_read_file(errors, NULL);
        assert_non_null(text);
        if (status != 2 || !strstr(text, cases[i].message))
            fail_msg("'%s': exit %d, message '%s' (want 2 and '%s')", cases[i].flags, status, text,
                     cases[i].message);
        free(text);
        assert_int_not_equal(access(out, F_OK), 0);
    }
    const char *hdr = work_path("cli.hdr");
    assert_int_equal(cli_run_capture(errors, "render --false-colour luminance -o %s", hdr), 2);
    assert_int_not_equal(access(hdr, F_OK), 0);
}

static void test_atomic(void **state)
{
    (void)state;
    rad_context *ctx = test_context(2);
    rad_scene *scene = NULL;
    rad_solution *sol = solve_scene(ctx, write_uniform_box(0.5, 1.0), "direct", 0.5, &scene);
    rad_render_options ro = {0};
    ro.width = 32;
    ro.height = 32;
    rad_false_colour_options fo = {RAD_FALSE_COLOUR_ILLUMINANCE, 0, 0.0, 0.0, 0};
    /* An old picture stays whole when the new one fails: interrupted... */
    const char *path = work_path("kept.png");
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("old", f);
    fclose(f);
    size_t before = count_files(test_workdir());
    rad_context_cancel(ctx, true);
    assert_int_equal(rad_solution_write_false_colour(ctx, sol, &ro, &fo, path), RAD_ERROR_INTERRUPTED);
    rad_context_cancel(ctx, false);
    char *text = test_read_file(path, NULL);
    assert_string_equal(text, "old");
    free(text);
    assert_int_equal(count_files(test_workdir()), before);
    /* ...or unwritable (a folder under a file). */
    const char *under = work_path("kept.png/x.png");
    assert_int_not_equal(rad_solution_write_false_colour(ctx, sol, &ro, &fo, under), RAD_OK);
    assert_int_equal(count_files(test_workdir()), before);
    /* And it succeeds in place of the old file. */
    assert_int_equal(rad_solution_write_false_colour(ctx, sol, &ro, &fo, path), RAD_OK);
    picture p = read_png(path);
    assert_true(p.width > 32);
    stbi_image_free(p.rgb);
    assert_int_equal(count_files(test_workdir()), before);
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* The program end to end: a false colour PNG of the box with its legend. */
static void test_cli_false_colour(void **state)
{
    (void)state;
    const char *scene = write_uniform_box(0.5, 1.0);
    const char *out = work_path("cli_box.png");
    assert_int_equal(cli_run("render %s --solver direct --mesh-size 0.5 --false-colour luminance --range 0:200 "
                             "--camera 0.5,0.5,0.5,0.5,0.5,0 --width 60 --height 240 -o %s",
                             scene, out),
                     0);
    picture p = read_png(out);
    assert_int_equal(p.height, 240);
    assert_true(p.width > 60);
    rad_colour_map map;
    rad_colour_map_make(&map);
    rad_colour_scale scale = {false, 0.0, 200.0};
    double lv = RAD_LUMINOUS_EFFICACY * 2.0 / M_PI;
    int got = level_of(&map, pixel_at(&p, 30, 120)), want = rad_scale_level(&scale, lv);
    assert_true(got >= 0 && abs(got - want) <= 1);
    stbi_image_free(p.rgb);
}

/* `radiosity illuminance ... -o plan.png`: one plan per grid, named
 * plan_NAME.png, in the closed uniform box where every point's illuminance
 * is 179 E / (1 - rho) lx (H = B there): every cell that colour. */
static void test_cli_grid_plots(void **state)
{
    (void)state;
    const char *scene = write_uniform_box(0.5, 1.0);
    const char *grid = work_path("grids.json");
    FILE *f = fopen(grid, "w");
    assert_non_null(f);
    fputs("{\"up\": \"y\", \"grids\": [{\"name\": \"work plane\", \"rectangle\": {\"origin\": [0.1, 0.5, 0.1], "
          "\"u\": [0, 0, 0.8], \"v\": [0.8, 0, 0]}, \"facing\": \"up\", \"spacing\": 0.2, \"border\": 0}], "
          "\"points\": [{\"name\": \"p\", \"position\": [0.3, 0.2, 0.4]}, {\"name\": \"q\", \"position\": [0.7, 0.6, 0.5]}]}",
          f);
    fclose(f);
    const char *csv = work_path("E.csv"), *plan = work_path("plan.png");
    int status = cli_run("illuminance %s --grid %s --solver direct --mesh-size 0.25 --range 0:500 -o %s -o %s", scene,
                         grid, csv, plan);
    assert_int_equal(status, 0);
    assert_int_not_equal(access(plan, F_OK), 0); /* the name given is the stem */
    double lux = RAD_LUMINOUS_EFFICACY * 1.0 / (1.0 - 0.5);
    rad_colour_map map;
    rad_colour_map_make(&map);
    rad_colour_scale scale = {false, 0.0, 500.0};
    int want = rad_scale_level(&scale, lux);
    const char *names[2] = {"plan_work_plane.png", "plan_points.png"};
    for (int k = 0; k < 2; k++) {
        picture p = read_png(work_path(names[k]));
        /* The map's colour of the closed form, within a level (the
         * gathering's error, 1e-5, is far below one). */
        int found = 0;
        for (int y = 0; y < p.height; y++)
            for (int x = 0; x < p.width * 3 / 4; x++) { /* left of the legend */
                int level = level_of(&map, pixel_at(&p, x, y));
                found += level >= 0 && abs(level - want) <= 1;
            }
        assert_true(found > (k == 0 ? 10000 : 20)); /* the cells (16 of them) or the two dots */
        stbi_image_free(p.rgb);
    }
    /* --scale and --range are for .png outputs only, and checked first. */
    const char *errors = work_path("plots.err");
    assert_int_equal(cli_run_capture(errors, "illuminance %s --grid %s --range 0:500 -o %s", scene, grid, csv), 2);
    assert_int_equal(cli_run_capture(errors, "illuminance %s --grid %s --scale log --range 0:5 -o %s", scene, grid,
                                     plan),
                     2);
    char *text = test_read_file(errors, NULL);
    assert_non_null(strstr(text, "log scale needs range min > 0"));
    free(text);
}

static int setup(void **state)
{
    (void)state;
    return cli_setup("pictures");
}

static int teardown(void **state)
{
    (void)state;
    return cli_teardown();
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_pictures RADIOSITY_BINARY\n");
        return 2;
    }
    cli_set_binary(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_colour_map),
        cmocka_unit_test(test_ticks_and_labels),
        cmocka_unit_test(test_legend_and_contours),
        cmocka_unit_test(test_luminance_box),
        cmocka_unit_test(test_illuminance_floor),
        cmocka_unit_test(test_grid_plot),
        cmocka_unit_test(test_bad_options),
        cmocka_unit_test(test_atomic),
        cmocka_unit_test(test_cli_false_colour),
        cmocka_unit_test(test_cli_grid_plots),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
