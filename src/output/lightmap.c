/*
 * lightmap.c -- the solution baked into textures: every patch is a chart
 * in its own plane, the charts are packed into power-of-two atlases, and
 * each texel takes the radiosity (or irradiance) smooth shading gives at
 * its centre.
 *
 * Chart frame.  A patch is planar, so its corners have exact 2D
 * coordinates in a frame of its plane: u along its longest edge, v =
 * normal x u (so the corners stay counter-clockwise), both in metres, the
 * origin at the lower-left corner of their bounding box.  Times N texels
 * per metre, that box is the chart's box of w x h texels (at least 2 x 2);
 * the atlas reserves it with PADDING texels on every side:
 *
 *      +-------------------+   padded box (packed)
 *      | +---------------+ |
 *      | |   /\          | |   box: w x h texels, x = chart.x + u N,
 *      | |  /  \  chart  | |                      y = chart.y + v N
 *      | | /____\        | |
 *      | +---------------+ |
 *      +-------------------+
 *
 * Packing: shelves (Igarashi & Cosgrove, "Adaptive shadow maps", and the
 * usual texture-atlas shelf packer): padded boxes sorted by height, laid
 * left to right on shelves, a new shelf when the row is full, a new atlas
 * when the atlas is.  One atlas is tried first at every power-of-two side
 * up to the limit; its height is then cut to the power of two it needs.
 *
 * Filling, in three kinds of texel:
 *   inside    its centre lies in the chart: the value at the centre;
 *   border    its centre is outside but within half a texel diagonal of
 *             the chart (its square may touch it): the value at the
 *             chart's nearest point, so bilinear lookups at the edge read
 *             chart values;
 *   dilated   every other texel of the padded box: the value of its
 *             nearest filled texel of the same chart (a two-pass 8-point
 *             sequential Euclidean distance transform, Danielsson 1980).
 * The value at a point is the patch's element there with its vertex
 * values interpolated (interp/), as the renderer and
 * rad_solution_point_radiosity give it.
 */
#include "output/output.h"

#include <stdlib.h>
#include <string.h>

/* Texels around every chart's box: a bilinear lookup at a chart point reads
 * texels at most one texel beyond the box, and the second keeps it away
 * from the next chart's texels under mipmapping's first level. */
#define PADDING 2

/* ---- the chart frames ---- */

/* The chart of `patch`: its frame and box, unplaced.  Fails (invalid
 * argument) when the box exceeds `atlas_size` with its padding. */
static rad_result chart_frame(rad_context *ctx, const rad_patch *patch, uint32_t index, double texels_per_metre,
                              int atlas_size, rad_chart *c)
{
    memset(c, 0, sizeof *c);
    c->patch = index;
    uint32_t n = patch->corner_count, longest = 0;
    double longest_length = -1.0;
    for (uint32_t k = 0; k < n; k++) {
        double length = v3_length(v3_sub(patch->corner[(k + 1) % n], patch->corner[k]));
        if (length > longest_length)
            longest_length = length, longest = k;
    }
    c->axis_u = v3_normalize(v3_sub(patch->corner[(longest + 1) % n], patch->corner[longest]));
    c->axis_v = v3_normalize(v3_cross(patch->normal, c->axis_u));
    double umin = INFINITY, vmin = INFINITY, umax = -INFINITY, vmax = -INFINITY, u[4], v[4];
    for (uint32_t k = 0; k < n; k++) {
        vec3 d = v3_sub(patch->corner[k], patch->corner[0]);
        u[k] = v3_dot(d, c->axis_u), v[k] = v3_dot(d, c->axis_v);
        umin = fmin(umin, u[k]), umax = fmax(umax, u[k]);
        vmin = fmin(vmin, v[k]), vmax = fmax(vmax, v[k]);
    }
    c->origin = v3_mad(v3_mad(patch->corner[0], c->axis_u, umin), c->axis_v, vmin);
    c->corner_count = n;
    for (uint32_t k = 0; k < n; k++)
        c->corner_u[k] = (u[k] - umin) * texels_per_metre, c->corner_v[k] = (v[k] - vmin) * texels_per_metre;
    double w = fmax(2.0, ceil((umax - umin) * texels_per_metre)), h = fmax(2.0, ceil((vmax - vmin) * texels_per_metre));
    if (!(w + 2 * PADDING <= atlas_size && h + 2 * PADDING <= atlas_size))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "lightmap: patch %u (%.3g x %.3g m) needs %.0f x %.0f texels at %g texels per metre, "
                        "above the atlas limit of %d x %d with its padding; lower the texels per metre or "
                        "raise the atlas size",
                        index, umax - umin, vmax - vmin, w, h, texels_per_metre, atlas_size, atlas_size);
    c->width = (int)w, c->height = (int)h;
    return RAD_OK;
}

/* ---- packing ---- */

/* A chart's place in the packing order: its box's height, then width,
 * descending; then its patch.  (The sizes are copied in: qsort has no user
 * pointer, and a global would not let two bakes run at once.) */
typedef struct pack_key {
    int height, width;
    uint32_t chart;
} pack_key;

static int pack_key_cmp(const void *a, const void *b)
{
    const pack_key *x = a, *y = b;
    if (x->height != y->height)
        return x->height > y->height ? -1 : 1;
    if (x->width != y->width)
        return x->width > y->width ? -1 : 1;
    return x->chart < y->chart ? -1 : (x->chart > y->chart);
}

/* Shelf-pack the charts in `order` into atlases of side `side`, at most
 * `max_atlases` of them: sets each chart's atlas and box and each atlas's
 * used height in used_height[] (sized max_atlases).  Returns the atlases
 * used, or 0 when they do not fit.  Cannot fail otherwise. */
static size_t shelf_pack(rad_chart *charts, const pack_key *order, size_t count, int side, size_t max_atlases,
                         int *used_height)
{
    size_t atlas = 0;
    int x = 0, y = 0, shelf = 0; /* the shelf's left cursor, its bottom, its height */
    used_height[0] = 0;
    for (size_t k = 0; k < count; k++) {
        rad_chart *c = &charts[order[k].chart];
        int w = c->width + 2 * PADDING, h = c->height + 2 * PADDING;
        if (x + w > side) /* a new shelf */
            y += shelf, x = 0, shelf = 0;
        if (y + h > side) { /* a new atlas */
            if (++atlas == max_atlases)
                return 0;
            used_height[atlas] = 0;
            x = y = shelf = 0;
        }
        c->atlas = (uint32_t)atlas;
        c->x = x + PADDING, c->y = y + PADDING;
        x += w;
        if (h > shelf)
            shelf = h;
        if (y + shelf > used_height[atlas])
            used_height[atlas] = y + shelf;
    }
    return atlas + 1;
}

static int power_of_two_at_least(int n)
{
    int p = 1;
    while (p < n)
        p *= 2;
    return p;
}

/* ---- values at points ---- */

/* The nearest point of the convex polygon (x[k], y[k]), counter-clockwise,
 * to (px, py): the point itself when inside. */
static void nearest_in_polygon(const double *x, const double *y, uint32_t n, double px, double py, double *qx,
                               double *qy)
{
    bool inside = true;
    double best = INFINITY;
    *qx = px, *qy = py;
    for (uint32_t k = 0; k < n; k++) {
        uint32_t j = (k + 1) % n;
        double ex = x[j] - x[k], ey = y[j] - y[k], dx = px - x[k], dy = py - y[k];
        if (ex * dy - ey * dx < 0.0)
            inside = false;
        double len2 = ex * ex + ey * ey;
        double t = len2 > 0.0 ? fmin(fmax((ex * dx + ey * dy) / len2, 0.0), 1.0) : 0.0;
        double cx = x[k] + t * ex, cy = y[k] + t * ey, d = (px - cx) * (px - cx) + (py - cy) * (py - cy);
        if (d < best)
            best = d, *qx = cx, *qy = cy;
    }
    if (inside)
        *qx = px, *qy = py;
}

/* The lightmap's quantity at point p of patch `patch` (W/m^2): radiosity B
 * interpolated from the vertex values, or irradiance (B - E) / rho of the
 * element there, 0 where rho is 0 and clamped to >= 0.  Cannot fail. */
static void value_at(const rad_solution_view *view, const double *vertex_value, uint32_t patch_index, vec3 p,
                     int quantity, float out[3])
{
    const rad_mesh *mesh = view->mesh;
    const rad_patch *patch = &mesh->patches[patch_index];
    double s, t;
    rad_patch_parameters(patch, p, &s, &t);
    s = fmin(fmax(s, 0.0), 1.0), t = fmin(fmax(t, 0.0), 1.0);
    if (patch->corner_count == 3 && s + t > 1.0) {
        double excess = 0.5 * (s + t - 1.0);
        s = fmax(s - excess, 0.0);
        t = fmin(1.0 - s, fmax(t - excess, 0.0));
    }
    double ls, lt, rgb[3];
    uint32_t e = rad_mesh_locate(mesh, patch_index, s, t, &ls, &lt);
    rad_element_interpolate(mesh, &mesh->elements[e], vertex_value, ls, lt, rgb);
    for (int c = 0; c < 3; c++) {
        double value = rgb[c];
        if (quantity == RAD_LIGHTMAP_IRRADIANCE) {
            double rho = view->reflectance[3 * (size_t)e + (size_t)c];
            value = rho > 0.0 ? fmax(0.0, (rgb[c] - view->emission[3 * (size_t)e + (size_t)c]) / rho) : 0.0;
        }
        out[c] = (float)value;
    }
}

vec3 rad_chart_point(const rad_lightmap *lm, const rad_chart *c, double x, double y)
{
    double scale = 1.0 / lm->texels_per_metre;
    return v3_mad(v3_mad(c->origin, c->axis_u, (x - c->x) * scale), c->axis_v, (y - c->y) * scale);
}

void rad_chart_texel(const rad_lightmap *lm, const rad_chart *c, vec3 p, double *x, double *y)
{
    vec3 d = v3_sub(p, c->origin);
    *x = c->x + v3_dot(d, c->axis_u) * lm->texels_per_metre;
    *y = c->y + v3_dot(d, c->axis_v) * lm->texels_per_metre;
}

/* Fill chart `index`'s inside and border texels, then dilate into the
 * rest of its padded box.  `nearest` is scratch of 2 ints per texel of
 * the padded box.  Cannot fail. */
static void fill_chart(const rad_solution_view *view, const double *vertex_value, rad_lightmap *lm, uint32_t index,
                       int *nearest)
{
    const rad_chart *c = &lm->charts[index];
    rad_atlas *atlas = &lm->atlases[c->atlas];
    int x0 = c->x - PADDING, y0 = c->y - PADDING;
    int pw = c->width + 2 * PADDING, ph = c->height + 2 * PADDING;
    /* Half a texel's diagonal: a texel whose centre is this close may have
     * the chart inside its square. */
    const double reach = 0.5 * sqrt(2.0) * (1.0 + 1e-9);
    for (int j = 0; j < ph; j++)
        for (int i = 0; i < pw; i++) {
            size_t at = (size_t)(y0 + j) * (size_t)atlas->width + (size_t)(x0 + i);
            atlas->owner[at] = (int32_t)index;
            nearest[2 * ((size_t)j * (size_t)pw + (size_t)i)] = -1;
            double px = i - PADDING + 0.5, py = j - PADDING + 0.5, qx, qy;
            nearest_in_polygon(c->corner_u, c->corner_v, c->corner_count, px, py, &qx, &qy);
            double d = hypot(px - qx, py - qy);
            if (d > reach)
                continue;
            value_at(view, vertex_value, c->patch, rad_chart_point(lm, c, c->x + qx, c->y + qy), lm->quantity,
                     &atlas->texels[3 * at]);
            atlas->state[at] = d == 0.0 ? RAD_TEXEL_INSIDE : RAD_TEXEL_BORDER;
            nearest[2 * ((size_t)j * (size_t)pw + (size_t)i)] = i;
            nearest[2 * ((size_t)j * (size_t)pw + (size_t)i) + 1] = j;
        }
    /* Dilation: each texel learns its neighbours' nearest filled texel,
     * forward then backward (8SSEDT's two passes, each row both ways). */
    static const int forward[4][2] = {{-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
    for (int pass = 0; pass < 2; pass++) {
        int step = pass == 0 ? 1 : -1;
        for (int jj = 0; jj < ph; jj++) {
            int j = pass == 0 ? jj : ph - 1 - jj;
            for (int sweep = 0; sweep < 2; sweep++) {
                int dir = sweep == 0 ? step : -step;
                for (int ii = 0; ii < pw; ii++) {
                    int i = dir == 1 ? ii : pw - 1 - ii;
                    int *self = &nearest[2 * ((size_t)j * (size_t)pw + (size_t)i)];
                    double best = self[0] < 0 ? INFINITY : hypot(self[0] - i, self[1] - j);
                    for (int k = 0; k < (sweep == 0 ? 4 : 1); k++) {
                        int ni = sweep == 0 ? i + step * forward[k][0] : i - dir,
                            nj = sweep == 0 ? j + step * forward[k][1] : j;
                        if (ni < 0 || nj < 0 || ni >= pw || nj >= ph)
                            continue;
                        const int *n = &nearest[2 * ((size_t)nj * (size_t)pw + (size_t)ni)];
                        if (n[0] < 0)
                            continue;
                        double d = hypot(n[0] - i, n[1] - j);
                        if (d < best)
                            best = d, self[0] = n[0], self[1] = n[1];
                    }
                }
            }
        }
    }
    for (int j = 0; j < ph; j++)
        for (int i = 0; i < pw; i++) {
            size_t at = (size_t)(y0 + j) * (size_t)atlas->width + (size_t)(x0 + i);
            if (atlas->state[at] != RAD_TEXEL_EMPTY)
                continue;
            const int *n = &nearest[2 * ((size_t)j * (size_t)pw + (size_t)i)];
            size_t from = (size_t)(y0 + n[1]) * (size_t)atlas->width + (size_t)(x0 + n[0]);
            memcpy(&atlas->texels[3 * at], &atlas->texels[3 * from], 3 * sizeof(float));
            atlas->state[at] = RAD_TEXEL_DILATED;
        }
}

/* ---- the lightmap ---- */

void rad_lightmap_destroy(rad_lightmap *lm)
{
    if (!lm)
        return;
    for (size_t k = 0; k < lm->atlas_count; k++) {
        rad_free(lm->atlases[k].texels);
        rad_free(lm->atlases[k].owner);
        rad_free(lm->atlases[k].state);
    }
    rad_free(lm->atlases);
    rad_free(lm->charts);
    rad_free(lm);
}

rad_result rad_lightmap_bake(rad_context *ctx, const rad_solution_view *view, const rad_lightmap_options *options,
                             rad_lightmap **out)
{
    *out = NULL;
    double tpm = options->texels_per_metre > 0.0 ? options->texels_per_metre : 10.0;
    int limit = options->atlas_size > 0 ? options->atlas_size : 2048;
    if (!isfinite(tpm))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "lightmap: texels per metre must be finite and > 0, got %g",
                        options->texels_per_metre);
    if (limit < 8 || limit > 16384 || (limit & (limit - 1)) != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "lightmap: the atlas size must be a power of two from 8 to 16384, got %d", limit);
    if (options->quantity != RAD_LIGHTMAP_RADIOSITY && options->quantity != RAD_LIGHTMAP_IRRADIANCE)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "lightmap: unknown quantity %d", options->quantity);
    const rad_mesh *mesh = view->mesh;
    size_t n = mesh->patch_count;
    if (n == 0 || n > UINT32_MAX)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "lightmap: the solution has %zu patches", n);
    rad_lightmap *lm = rad_alloc(ctx, RAD_MEM_OUTPUT, 1, sizeof *lm, "lightmap");
    if (!lm)
        return RAD_ERROR_OUT_OF_MEMORY;
    lm->texels_per_metre = tpm;
    lm->quantity = options->quantity;
    lm->charts = rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *lm->charts, "lightmap: charts");
    pack_key *order = lm->charts ? rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *order, "lightmap: charts") : NULL;
    int *used = order ? rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *used, "lightmap: atlases") : NULL;
    double *vertex_value = used ? rad_alloc(ctx, RAD_MEM_OUTPUT, mesh->vertex_count, 3 * sizeof *vertex_value,
                                            "lightmap: vertex values")
                                : NULL;
    int *nearest = NULL;
    rad_result r = vertex_value ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
    if (r != RAD_OK)
        goto done;
    lm->chart_count = n;
    double area = 0.0;
    int widest = 0;
    for (size_t k = 0; k < n && r == RAD_OK; k++) {
        r = chart_frame(ctx, &mesh->patches[k], (uint32_t)k, tpm, limit, &lm->charts[k]);
        order[k] = (pack_key){lm->charts[k].height, lm->charts[k].width, (uint32_t)k};
        area += (double)(lm->charts[k].width + 2 * PADDING) * (double)(lm->charts[k].height + 2 * PADDING);
        lm->chart_texels += (double)lm->charts[k].width * (double)lm->charts[k].height;
        int side = (lm->charts[k].width > lm->charts[k].height ? lm->charts[k].width : lm->charts[k].height);
        if (side + 2 * PADDING > widest)
            widest = side + 2 * PADDING;
    }
    if (r != RAD_OK)
        goto done;
    /* Texels, an owner and a state each: 17 bytes a texel, at least the
     * padded charts' area. */
    double limit_bytes = view->options ? view->options->max_memory_bytes : 0.0;
    if (limit_bytes > 0.0 && 17.0 * area > limit_bytes) {
        r = rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                     "lightmap: %.0f texels at %g texels per metre need %.2f GiB, above the memory limit of "
                     "%.2f GiB (rad_options.max_memory_bytes); lower the texels per metre",
                     area, tpm, 17.0 * area / 1073741824.0, limit_bytes / 1073741824.0);
        goto done;
    }
    qsort(order, n, sizeof *order, pack_key_cmp);
    /* One atlas at the smallest side that holds everything, else as many
     * of the largest as it takes. */
    size_t atlases = 0;
    int side = power_of_two_at_least(widest);
    while (side < power_of_two_at_least((int)fmin(ceil(sqrt(area)), (double)limit)))
        side *= 2;
    for (; side <= limit && atlases == 0; side *= 2)
        atlases = shelf_pack(lm->charts, order, n, side, 1, used);
    side /= 2;
    if (atlases == 0)
        atlases = shelf_pack(lm->charts, order, n, side = limit, n, used);
    lm->atlases = rad_alloc(ctx, RAD_MEM_OUTPUT, atlases, sizeof *lm->atlases, "lightmap: atlases");
    if (!lm->atlases) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    lm->atlas_count = atlases;
    size_t largest = 0;
    for (size_t a = 0; a < atlases && r == RAD_OK; a++) {
        rad_atlas *atlas = &lm->atlases[a];
        atlas->width = side;
        atlas->height = power_of_two_at_least(used[a]);
        size_t texels = (size_t)atlas->width * (size_t)atlas->height;
        lm->atlas_texels += (double)texels;
        atlas->texels = rad_alloc(ctx, RAD_MEM_OUTPUT, texels, 3 * sizeof(float), "lightmap: texels");
        atlas->owner = atlas->texels ? rad_alloc(ctx, RAD_MEM_OUTPUT, texels, sizeof(int32_t), "lightmap: texels")
                                     : NULL;
        atlas->state = atlas->owner ? rad_alloc(ctx, RAD_MEM_OUTPUT, texels, 1, "lightmap: texels") : NULL;
        if (!atlas->state)
            r = RAD_ERROR_OUT_OF_MEMORY;
        else
            for (size_t i = 0; i < texels; i++)
                atlas->owner[i] = -1;
    }
    for (size_t k = 0; k < n; k++) {
        size_t box = (size_t)(lm->charts[k].width + 2 * PADDING) * (size_t)(lm->charts[k].height + 2 * PADDING);
        largest = box > largest ? box : largest;
    }
    nearest = r == RAD_OK ? rad_alloc(ctx, RAD_MEM_OUTPUT, largest, 2 * sizeof *nearest, "lightmap: dilation") : NULL;
    if (!nearest) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    r = rad_view_vertex_values(ctx, view, view->radiosity, vertex_value);
    for (size_t k = 0; k < n && r == RAD_OK; k++) {
        if ((k & 255) == 0 && rad_cancelled(ctx))
            r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "lightmap: interrupted");
        else
            fill_chart(view, vertex_value, lm, (uint32_t)k, nearest);
    }
done:
    rad_free(nearest);
    rad_free(vertex_value);
    rad_free(used);
    rad_free(order);
    if (r != RAD_OK)
        rad_lightmap_destroy(lm);
    else
        *out = lm;
    return r;
}
