/*
 * pictures.c -- the false colour pictures (docs/lighting.md "Pictures"):
 * one value per pixel from a render of a solved view, then falsecolour.c
 * colours it and draws the legend.
 *
 *   luminance    the rendered radiance (the caller's render of the
 *                solution: textures, the second pass, all of
 *                rad_solution_render), 179 Y(L) cd/m^2 per pixel, over the
 *                pixels a second, flat render finds covered
 *   illuminance  each element's lux (rad_view_illuminance), smoothed to
 *                the vertices, rendered with the coverage in a second
 *                channel: one render gives both
 *
 * The plans of the calculation grids (rad_illuminance_write_plots): one
 * PNG per grid through plot.c, named STEM_NAME.png.
 *
 * A pixel is the background when fewer than half of its rays met the
 * front of a surface; else its value is the mean over those that did (the
 * pixel's sum over its coverage), so edges keep the surface's value.
 */
#include "output/picture.h"
#include "photometry/photometry.h"

#include <ctype.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>

rad_result rad_false_colour_check(rad_context *ctx, const rad_false_colour_options *o)
{
    rad_api_enter(ctx);
    if (!o)
        return RAD_OK;
    if (o->quantity != 0 && o->quantity != RAD_FALSE_COLOUR_LUMINANCE && o->quantity != RAD_FALSE_COLOUR_ILLUMINANCE)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "false colour: unknown quantity %d (luminance or illuminance)", (int)o->quantity);
    if (!isfinite(o->range_min) || !isfinite(o->range_max))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "false colour: the range %g:%g is not finite",
                        o->range_min, o->range_max);
    if (o->range_min == 0.0 && o->range_max == 0.0)
        return RAD_OK; /* automatic */
    if (!(o->range_min < o->range_max))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "false colour: range min %g must be below max %g",
                        o->range_min, o->range_max);
    if (o->log_scale && !(o->range_min > 0.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "false colour: a log scale needs range min > 0, got %g", o->range_min);
    return RAD_OK;
}

/* The camera rad_solution_render would use. */
static rad_camera chosen_camera(const rad_solution_view *view, const rad_render_options *o, int w, int h)
{
    rad_camera camera;
    if (o->camera)
        return *o->camera;
    if (!rad_scene_camera(view->scene, &camera))
        camera = rad_camera_frame(view->scene->bounds_min, view->scene->bounds_max, (double)w / h);
    return camera;
}

/* A render of per-element values `element` (3n) with their smooth vertex
 * values: no textures, no second pass, no VPLs. */
static rad_result render_values(rad_context *ctx, const rad_solution_view *view, const rad_render_options *o,
                                const double *element, rad_image **out)
{
    const rad_mesh *mesh = view->mesh;
    double *vertex = rad_alloc(ctx, RAD_MEM_RENDER, mesh->vertex_count ? mesh->vertex_count : 1,
                               3 * sizeof *vertex, "false colour: vertex values");
    if (!vertex)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = rad_vertex_values(ctx, mesh, element, vertex);
    if (r == RAD_OK) {
        int w = o->width > 0 ? o->width : 512, h = o->height > 0 ? o->height : 512;
        rad_render_input in = {0};
        in.mesh = mesh;
        in.vis = view->vis;
        in.element_radiosity = element;
        in.vertex_radiosity = vertex;
        in.camera = chosen_camera(view, o, w, h);
        in.seed = view->options->seed;
        rad_render_options plain = *o;
        plain.vpl_paths = 0;
        r = rad_render_image(ctx, &in, &plain, out);
    }
    rad_free(vertex);
    return r;
}

rad_result rad_write_false_colour_view(rad_context *ctx, const rad_solution_view *view,
                                       const rad_render_options *render, const rad_false_colour_options *options,
                                       const rad_image *radiance, const char *path)
{
    rad_false_colour_options fo = options ? *options : (rad_false_colour_options){0};
    bool illuminance = fo.quantity == RAD_FALSE_COLOUR_ILLUMINANCE;
    rad_render_options o = render ? *render : (rad_render_options){0};
    size_t n = view->mesh->element_count;

    /* Per element: (pi value, pi, 0) for illuminance, (0, pi, 0) for the
     * coverage of a luminance picture; the renderer divides by pi. */
    double *element = rad_alloc(ctx, RAD_MEM_RENDER, n ? n : 1, 3 * sizeof *element, "false colour: element values");
    if (!element)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = RAD_OK;
    rad_image *coverage = NULL;
    float *values = NULL;
    if (illuminance) {
        double *lux = rad_alloc(ctx, RAD_MEM_RENDER, n ? n : 1, sizeof *lux, "false colour: illuminance");
        r = lux ? rad_view_illuminance(ctx, view, lux) : RAD_ERROR_OUT_OF_MEMORY;
        for (size_t i = 0; i < n && r == RAD_OK; i++) {
            element[3 * i] = M_PI * lux[i];
            element[3 * i + 1] = M_PI;
            element[3 * i + 2] = 0.0;
        }
        rad_free(lux);
    } else {
        for (size_t i = 0; i < n; i++) {
            element[3 * i] = element[3 * i + 2] = 0.0;
            element[3 * i + 1] = M_PI;
        }
    }
    if (r == RAD_OK)
        r = render_values(ctx, view, &o, element, &coverage);
    rad_free(element);
    size_t pixels = 0;
    if (r == RAD_OK) {
        pixels = (size_t)coverage->width * (size_t)coverage->height;
        values = rad_alloc(ctx, RAD_MEM_RENDER, pixels, sizeof *values, "false colour: pixel values");
        if (!values)
            r = RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t p = 0; p < pixels && r == RAD_OK; p++) {
        const float *c = &coverage->pixels[3 * p];
        double covered = c[1];
        if (!(covered >= 0.5)) {
            values[p] = NAN;
            continue;
        }
        double value;
        if (illuminance) {
            value = c[0] / covered;
        } else {
            const float *L = &radiance->pixels[3 * p];
            value = RAD_LUMINOUS_EFFICACY * (RAD_Y_R * L[0] + RAD_Y_G * L[1] + RAD_Y_B * L[2]) / covered;
        }
        values[p] = (float)value;
    }
    rad_colour_scale scale = {fo.log_scale != 0, fo.range_min, fo.range_max};
    if (r == RAD_OK && fo.range_min == 0.0 && fo.range_max == 0.0)
        r = rad_scale_automatic(ctx, scale.log, values, pixels, &scale);
    if (r == RAD_OK)
        r = rad_false_colour_write(ctx, values, coverage->width, coverage->height, &scale,
                                   illuminance ? "lx" : "cd/m\xc2\xb2", fo.contours != 0, path);
    rad_free(values);
    rad_image_destroy(coverage);
    return r;
}

/* ---- plans of the calculation grids (rad_illuminance_write_plots) ---- */

/* The grid's name as it goes into a file name: letters, digits, '-', '.'
 * and '_' kept, anything else '_' (empty: "grid"). */
static void file_name_part(const char *name, char *out, size_t size)
{
    size_t n = 0;
    for (const char *c = name ? name : ""; *c && n + 1 < size; c++)
        out[n++] = (isalnum((unsigned char)*c) || *c == '-' || *c == '.' || *c == '_') ? *c : '_';
    out[n] = '\0';
    if (n == 0)
        snprintf(out, size, "grid");
}

size_t rad_illuminance_plot_path(const rad_illuminance *illuminance, const char *path, size_t grid, char *out,
                                 size_t size)
{
    if (size)
        out[0] = '\0';
    const rad_grid_result *g = rad_illuminance_grid(illuminance, grid);
    if (!g || !path)
        return 0;
    size_t stem = strlen(path);
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (dot && (!slash || dot > slash))
        stem = (size_t)(dot - path);
    char name[256], earlier[256];
    file_name_part(g->name, name, sizeof name);
    /* A name an earlier grid's already gives: its index added. */
    bool taken = false;
    for (size_t k = 0; k < grid && !taken; k++) {
        file_name_part(rad_illuminance_grid(illuminance, k)->name, earlier, sizeof earlier);
        taken = strcmp(earlier, name) == 0;
    }
    int n = taken ? snprintf(out, size, "%.*s_%s_%zu.png", (int)stem, path, name, grid)
                  : snprintf(out, size, "%.*s_%s.png", (int)stem, path, name);
    return n < 0 ? 0 : (size_t)n;
}

/* Grid g's points as a plot: grid points at their (u, v), free points
 * projected along their mean normal (the plan seen from the side it
 * faces). */
static rad_result plot_one(rad_context *ctx, const rad_grid_result *g, const rad_plot_options *po, const char *path)
{
    size_t n = g->point_count;
    double *uvw = rad_alloc(ctx, RAD_MEM_OUTPUT, n ? n : 1, 3 * sizeof *uvw, "grid plot: points");
    if (!uvw)
        return RAD_ERROR_OUT_OF_MEMORY;
    double *u = uvw, *v = uvw + n, *value = uvw + 2 * n;
    double mean[3] = {0.0, 0.0, 0.0};
    for (size_t k = 0; k < n; k++)
        for (int c = 0; c < 3; c++)
            mean[c] += g->points[k].normal[c];
    int axis = fabs(mean[0]) >= fabs(mean[1]) && fabs(mean[0]) >= fabs(mean[2]) ? 0 : fabs(mean[1]) >= fabs(mean[2]) ? 1 : 2;
    int b = (axis + 1) % 3, c = (axis + 2) % 3; /* b x c = the axis: seen from the normal's side */
    double flip = mean[axis] < 0.0 ? -1.0 : 1.0;
    for (size_t k = 0; k < n; k++) {
        const rad_grid_point_value *p = &g->points[k];
        u[k] = g->free_points ? flip * p->position[b] : p->u;
        v[k] = g->free_points ? p->position[c] : p->v;
        value[k] = p->illuminance;
    }
    rad_plot_grid plot = {g->name, n, u, v, value, "lx", g->free_points ? 0 : g->columns,
                          g->free_points ? 0 : g->rows, g->free_points ? 0.0 : g->spacing_u,
                          g->free_points ? 0.0 : g->spacing_v};
    rad_result r = rad_plot_grid_write(ctx, &plot, po, path);
    rad_free(uvw);
    return r;
}

rad_result rad_illuminance_write_plots(rad_context *ctx, const rad_illuminance *illuminance,
                                       const rad_false_colour_options *options, rad_output_set *set, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !illuminance || !path)
        return rad_null_argument(ctx, __func__);
    rad_result r = rad_false_colour_check(ctx, options);
    if (r != RAD_OK)
        return r;
    char ext[8];
    rad_path_extension(path, ext, sizeof ext);
    if (strcmp(ext, "png") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: grid plots are PNG: the path must end in .png", path);
    rad_plot_options po = {0};
    if (options) {
        po.log_scale = options->log_scale;
        po.range_min = options->range_min;
        po.range_max = options->range_max;
    }
    for (size_t g = 0; g < rad_illuminance_grid_count(illuminance) && r == RAD_OK; g++) {
        const rad_grid_result *grid = rad_illuminance_grid(illuminance, g);
        if (grid->point_count == 0)
            continue; /* nothing to draw */
        char name[PATH_MAX];
        if (rad_illuminance_plot_path(illuminance, path, g, name, sizeof name) >= sizeof name)
            return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: the plot's path is too long", path);
        const char *target = name;
        if (set)
            r = rad_output_set_add(ctx, set, name, RAD_OUTPUT_IMAGE, &target);
        if (r == RAD_OK)
            r = plot_one(ctx, grid, &po, target);
    }
    return r;
}
