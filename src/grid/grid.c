/*
 * grid.c -- the grid file (docs/lighting.md, "Calculation grids and
 * points"), read with cJSON, and the points it places:
 *
 *   {"up": "y",                                       the vertical axis: x, y or z (default y)
 *    "grids": [
 *      {"name": "desk", "rectangle": {"origin": [0, 0.8, 0], "u": [2, 0, 0], "v": [0, 0, 1]},
 *       "facing": "up", "spacing": 0.25, "border": 0},
 *      {"name": "room", "surface": "room0/floor", "height": 0.8, "spacing": "auto"}],
 *    "points": [{"name": "P1", "position": [1, 0.8, 1], "normal": [0, 1, 0]}]}
 *
 *   rectangle  origin + s u/|u| + t v/|v| (horizontal, vertical or inclined);
 *              its normal u x v ("facing": "front", the default), its
 *              opposite ("back"), the one of them pointing "up" or "down",
 *              or "normal": [...] as given.  Border 0 unless given.
 *   surface    the named surface's polygons projected along the up axis on
 *              the plane `height` m above their highest point; normal +up
 *              ("facing": "down": -up).  Border 0.5 m (EN 12464-1: the band
 *              by the walls), kept from the footprint's outline (the edges
 *              no other of its polygons shares).
 *
 *     v ^  +-------------------+      points at the centres of columns x rows
 *       |  | .   .   .   .   . |      cells; the smallest counts that keep
 *       |  | .   .   .   .   . |      each cell's side <= p (EN 12464-1:
 *       |  +-------------------+      p = 0.2 x 5^log10(d), d the longer side,
 *       +--------------------------> u   p <= 10 m), or the spacing given
 *
 * Every error names the file and the entry and key ("g.json:
 * grids[1].spacing: ..."); names are printed as the file gives them, up to
 * 200 bytes.
 */
#include "grid/grid.h"

#include <cjson/cJSON.h>
#include <float.h>
#include <stdlib.h>
#include <string.h>

double rad_grid_en12464_spacing(double d)
{
    return fmin(10.0, 0.2 * pow(5.0, log10(d)));
}

uint32_t rad_grid_point_count(double length, double p)
{
    /* ceil with a relative allowance, so that a side of exactly k cells of
     * p (2.0 m at 0.5 m) gives k, not k + 1 by rounding. */
    double n = ceil(length / p * (1.0 - 1e-12));
    return n < 1.0 ? 1u : n > 1e6 ? 1000000u : (uint32_t)n;
}

/* The largest grid a file may ask for (points in all): 10^7, about 1 GB of
 * point data and far beyond any lighting design's need; a larger one is a
 * mistake in the file (a spacing in mm). */
#define MAX_POINTS 10000000u

typedef struct builder {
    rad_context *ctx;
    const char *file;
    rad_grid_set *set;
    size_t capacity;
} builder;

void rad_grid_set_destroy(rad_grid_set *set)
{
    if (!set)
        return;
    for (size_t g = 0; g < set->grid_count; g++)
        rad_free(set->grids[g].name);
    for (size_t k = 0; k < set->point_count; k++)
        rad_free(set->point_name[k]);
    rad_free(set->grids);
    rad_free(set->position);
    rad_free(set->normal);
    rad_free(set->u);
    rad_free(set->v);
    rad_free(set->point_name);
    rad_free(set->source);
    rad_free(set);
}

static rad_result grow(builder *b, size_t more)
{
    rad_grid_set *s = b->set;
    if (s->point_count + more > MAX_POINTS)
        return rad_fail(b->ctx, RAD_ERROR_PARSE, "%s: more than %u points in all: give a larger spacing",
                        b->file, MAX_POINTS);
    if (s->point_count + more <= b->capacity)
        return RAD_OK;
    size_t cap = b->capacity ? b->capacity : 64;
    while (cap < s->point_count + more)
        cap *= 2;
    void *p;
#define GROW(field)                                                                                        \
    p = rad_realloc(b->ctx, RAD_MEM_SCENE, s->field, cap, sizeof *s->field, "grid: points");              \
    if (!p)                                                                                                \
        return RAD_ERROR_OUT_OF_MEMORY;                                                                    \
    s->field = p;
    GROW(position)
    GROW(normal)
    GROW(u)
    GROW(v)
    GROW(point_name)
#undef GROW
    b->capacity = cap;
    return RAD_OK;
}

static void add_point(builder *b, vec3 p, vec3 n, double u, double v)
{
    rad_grid_set *s = b->set;
    s->position[s->point_count] = p;
    s->normal[s->point_count] = n;
    s->u[s->point_count] = u;
    s->v[s->point_count] = v;
    s->point_name[s->point_count] = NULL;
    s->point_count++;
}

/* A 3-vector at `where`.`key`: three finite numbers. */
static rad_result read_vec3(builder *b, const char *where, const char *key, const cJSON *item, vec3 *out)
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3)
        return rad_fail(b->ctx, RAD_ERROR_PARSE, "%s: %s.%s: must be an array of 3 numbers", b->file, where, key);
    double x[3];
    for (int k = 0; k < 3; k++) {
        const cJSON *c = cJSON_GetArrayItem(item, k);
        if (!cJSON_IsNumber(c) || !isfinite(c->valuedouble))
            return rad_fail(b->ctx, RAD_ERROR_PARSE, "%s: %s.%s: must be an array of 3 finite numbers", b->file,
                            where, key);
        x[k] = c->valuedouble;
    }
    *out = v3(x[0], x[1], x[2]);
    return RAD_OK;
}

static vec3 axis(int k)
{
    return v3(k == 0, k == 1, k == 2);
}

static double coord(vec3 p, int k)
{
    return k == 0 ? p.x : k == 1 ? p.y : p.z;
}

/* The keys of one grid entry. */
typedef struct grid_keys {
    const cJSON *name, *rectangle, *surface, *height, *normal, *facing, *spacing, *border;
} grid_keys;

static rad_result read_keys(builder *b, const char *where, const cJSON *o, grid_keys *k)
{
    static const char *const names[] = {"name", "rectangle", "surface", "height",
                                        "normal", "facing", "spacing", "border"};
    const cJSON **slots[] = {&k->name, &k->rectangle, &k->surface, &k->height,
                             &k->normal, &k->facing, &k->spacing, &k->border};
    memset(k, 0, sizeof *k);
    for (const cJSON *item = o->child; item; item = item->next) {
        size_t m = 0;
        while (m < 8 && strcmp(item->string, names[m]) != 0)
            m++;
        if (m == 8)
            return rad_fail(b->ctx, RAD_ERROR_PARSE, "%s: %s.%.200s: unknown key (known: name, rectangle, surface, "
                            "height, normal, facing, spacing, border)", b->file, where, item->string);
        if (*slots[m])
            return rad_fail(b->ctx, RAD_ERROR_PARSE, "%s: %s.%s: given twice", b->file, where, names[m]);
        *slots[m] = item;
    }
    return RAD_OK;
}

/* spacing: a number > 0 (m) or "auto" (absent: "auto"); *p 0 for auto. */
static rad_result read_spacing(builder *b, const char *where, const cJSON *item, double *p)
{
    *p = 0.0;
    if (!item || (cJSON_IsString(item) && strcmp(item->valuestring, "auto") == 0))
        return RAD_OK;
    if (!cJSON_IsNumber(item) || !(item->valuedouble > 0.0) || !isfinite(item->valuedouble))
        return rad_fail(b->ctx, RAD_ERROR_PARSE, "%s: %s.spacing: must be a number of metres > 0 or \"auto\" "
                        "(EN 12464-1)", b->file, where);
    *p = item->valuedouble;
    return RAD_OK;
}

static rad_result read_length(builder *b, const char *where, const char *key, const cJSON *item, double fallback,
                              double *out)
{
    *out = fallback;
    if (!item)
        return RAD_OK;
    if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble) || item->valuedouble < 0.0)
        return rad_fail(b->ctx, RAD_ERROR_PARSE, "%s: %s.%s: must be a finite number of metres >= 0", b->file,
                        where, key);
    *out = item->valuedouble;
    return RAD_OK;
}

/* The spacing and counts of an area w x h after the border. */
static rad_result size_grid(builder *b, const char *where, rad_grid_def *g, double w, double h, double p)
{
    if (!(w > 0.0 && h > 0.0))
        return rad_fail(b->ctx, RAD_ERROR_PARSE, "%s: %s.border: %.6g m on each side leaves no area (the sides "
                        "are %.6g and %.6g m)", b->file, where, g->border, w + 2.0 * g->border, h + 2.0 * g->border);
    g->automatic = p == 0.0;
    if (g->automatic)
        p = rad_grid_en12464_spacing(fmax(w, h));
    g->width = w;
    g->height = h;
    g->columns = rad_grid_point_count(w, p);
    g->rows = rad_grid_point_count(h, p);
    g->spacing_u = w / g->columns;
    g->spacing_v = h / g->rows;
    if ((double)g->columns * g->rows > MAX_POINTS)
        return rad_fail(b->ctx, RAD_ERROR_PARSE, "%s: %s.spacing: %u x %u points, more than %u: give a larger "
                        "spacing", b->file, where, g->columns, g->rows, MAX_POINTS);
    return RAD_OK;
}

static rad_result rectangle_grid(builder *b, const char *where, const grid_keys *k, rad_grid_def *g, double p)
{
    rad_context *ctx = b->ctx;
    const cJSON *r = k->rectangle;
    if (!cJSON_IsObject(r))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.rectangle: must be an object {\"origin\": [x, y, z], \"u\": "
                        "[...], \"v\": [...]}", b->file, where);
    if (k->height)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.height: is for a surface's footprint, not a rectangle",
                        b->file, where);
    char at[256];
    snprintf(at, sizeof at, "%s.rectangle", where);
    const cJSON *o = NULL, *u = NULL, *v = NULL;
    for (const cJSON *item = r->child; item; item = item->next) {
        const cJSON **slot = strcmp(item->string, "origin") == 0 ? &o
                             : strcmp(item->string, "u") == 0    ? &u
                             : strcmp(item->string, "v") == 0    ? &v
                                                                 : NULL;
        if (!slot)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.%.200s: unknown key (known: origin, u, v)", b->file, at,
                            item->string);
        if (*slot)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.%s: given twice", b->file, at, item->string);
        *slot = item;
    }
    if (!o || !u || !v)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: needs \"%s\"", b->file, at, !o ? "origin" : !u ? "u" : "v");
    vec3 origin, eu, ev;
    rad_result res = read_vec3(b, at, "origin", o, &origin);
    if (res == RAD_OK)
        res = read_vec3(b, at, "u", u, &eu);
    if (res == RAD_OK)
        res = read_vec3(b, at, "v", v, &ev);
    if (res != RAD_OK)
        return res;
    double lu = v3_length(eu), lv = v3_length(ev);
    vec3 cross = v3_cross(eu, ev);
    /* Edges within 1e-6 rad of parallel (or of zero length) span no plane. */
    if (!(lu > 0.0 && lv > 0.0 && v3_length(cross) > 1e-6 * lu * lv) || !isfinite(lu * lv))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: u and v must be non-zero and not parallel", b->file, at);
    vec3 n = v3_normalize(cross);
    vec3 up = axis(b->set->up_axis);
    if (k->normal && k->facing)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: give \"normal\" or \"facing\", not both", b->file, where);
    if (k->normal) {
        res = read_vec3(b, where, "normal", k->normal, &n);
        if (res != RAD_OK)
            return res;
        if (!(v3_length(n) > 0.0))
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.normal: must not be zero", b->file, where);
        n = v3_normalize(n);
    } else if (k->facing) {
        const char *f = cJSON_IsString(k->facing) ? k->facing->valuestring : "";
        if (strcmp(f, "back") == 0)
            n = v3_scale(n, -1.0);
        else if (strcmp(f, "up") == 0 || strcmp(f, "down") == 0) {
            double c = v3_dot(n, up);
            /* A plane within 1e-9 of vertical has no up side. */
            if (fabs(c) < 1e-9)
                return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.facing: \"%s\" on a vertical rectangle (use "
                                "\"front\", \"back\" or \"normal\")", b->file, where, f);
            if ((c < 0.0) == (f[0] == 'u'))
                n = v3_scale(n, -1.0);
        } else if (strcmp(f, "front") != 0)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.facing: must be \"front\", \"back\", \"up\" or \"down\"",
                            b->file, where);
    }
    res = size_grid(b, where, g, lu - 2.0 * g->border, lv - 2.0 * g->border, p);
    if (res == RAD_OK)
        res = grow(b, (size_t)g->columns * g->rows);
    if (res != RAD_OK)
        return res;
    vec3 du = v3_scale(eu, 1.0 / lu), dv = v3_scale(ev, 1.0 / lv);
    for (uint32_t j = 0; j < g->rows; j++)
        for (uint32_t i = 0; i < g->columns; i++) {
            double s = g->border + (i + 0.5) * g->spacing_u, t = g->border + (j + 0.5) * g->spacing_v;
            add_point(b, v3_mad(v3_mad(origin, du, s), dv, t), n, s, t);
        }
    return RAD_OK;
}

/* Point q inside the projected polygon (a, b arrays of m corners; crossing
 * number). */
static bool inside(const double *a, const double *bb, size_t m, double qa, double qb)
{
    bool in = false;
    for (size_t i = 0, j = m - 1; i < m; j = i++)
        if ((bb[i] > qb) != (bb[j] > qb) && qa < (a[j] - a[i]) * (qb - bb[i]) / (bb[j] - bb[i]) + a[i])
            in = !in;
    return in;
}

static double segment_distance(double qa, double qb, double a0, double b0, double a1, double b1)
{
    double da = a1 - a0, db = b1 - b0, len2 = da * da + db * db;
    double t = len2 > 0.0 ? ((qa - a0) * da + (qb - b0) * db) / len2 : 0.0;
    t = fmin(fmax(t, 0.0), 1.0);
    double ea = a0 + t * da - qa, eb = b0 + t * db - qb;
    return sqrt(ea * ea + eb * eb);
}

static rad_result surface_grid(builder *b, const rad_scene *scene, const char *where, const grid_keys *k,
                               rad_grid_def *g, double p)
{
    rad_context *ctx = b->ctx;
    if (!cJSON_IsString(k->surface))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.surface: must be a surface's name", b->file, where);
    if (k->normal)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.normal: a footprint's normal is up (or \"facing\": "
                        "\"down\")", b->file, where);
    size_t surface = SIZE_MAX;
    for (size_t s = 0; s < scene->surface_count && surface == SIZE_MAX; s++)
        if (strcmp(scene->surfaces[s].name, k->surface->valuestring) == 0)
            surface = s;
    if (surface == SIZE_MAX)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.surface: the scene %s has no surface '%.200s'", b->file,
                        where, scene->source ? scene->source : "", k->surface->valuestring);
    double height;
    rad_result res = read_length(b, where, "height", k->height, 0.0, &height);
    if (res != RAD_OK)
        return res;
    int up = b->set->up_axis, ia = (up + 1) % 3, ib = (up + 2) % 3;
    vec3 n = axis(up);
    if (k->facing) {
        const char *f = cJSON_IsString(k->facing) ? k->facing->valuestring : "";
        if (strcmp(f, "down") == 0)
            n = v3_scale(n, -1.0);
        else if (strcmp(f, "up") != 0)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.facing: a footprint faces \"up\" or \"down\"", b->file,
                            where);
    }
    /* The footprint: polygons that are not vertical (projected area above
     * 1e-9 of their own). */
    size_t corners = 0, polygons = 0;
    double top = -INFINITY, lo_a = INFINITY, lo_b = INFINITY, hi_a = -INFINITY, hi_b = -INFINITY;
    for (size_t q = 0; q < scene->polygon_count; q++) {
        const rad_polygon *poly = &scene->polygons[q];
        if (poly->surface != surface || fabs(coord(poly->normal, up)) < 1e-9)
            continue;
        polygons++;
        corners += poly->vertex_count;
        for (uint32_t c = 0; c < poly->vertex_count; c++) {
            vec3 x = scene->positions[scene->indices[poly->first_index + c]];
            top = fmax(top, coord(x, up));
            lo_a = fmin(lo_a, coord(x, ia)), hi_a = fmax(hi_a, coord(x, ia));
            lo_b = fmin(lo_b, coord(x, ib)), hi_b = fmax(hi_b, coord(x, ib));
        }
    }
    if (polygons == 0)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.surface: '%.200s' has no footprint (all its polygons are "
                        "vertical to the up axis %c)", b->file, where, k->surface->valuestring, "xyz"[up]);
    res = read_length(b, where, "border", k->border, 0.5, &g->border);
    if (res == RAD_OK)
        res = size_grid(b, where, g, hi_a - lo_a - 2.0 * g->border, hi_b - lo_b - 2.0 * g->border, p);
    if (res != RAD_OK)
        return res;
    /* The projected corners, polygon after polygon. */
    double *pa = rad_alloc(ctx, RAD_MEM_SCENE, 2 * corners + 2 * polygons, sizeof *pa, "grid: footprint");
    if (!pa)
        return RAD_ERROR_OUT_OF_MEMORY;
    double *pb = pa + corners;
    size_t *start = (size_t *)(void *)(pb + corners); /* polygons + 1 offsets fit in 2 x polygons doubles */
    size_t m = 0, np = 0;
    for (size_t q = 0; q < scene->polygon_count; q++) {
        const rad_polygon *poly = &scene->polygons[q];
        if (poly->surface != surface || fabs(coord(poly->normal, up)) < 1e-9)
            continue;
        start[np++] = m;
        for (uint32_t c = 0; c < poly->vertex_count; c++) {
            vec3 x = scene->positions[scene->indices[poly->first_index + c]];
            pa[m] = coord(x, ia);
            pb[m] = coord(x, ib);
            m++;
        }
    }
    start[np] = m;
    /* Two projected corners within 1e-9 of the footprint's size are one. */
    double tol = 1e-9 * fmax(hi_a - lo_a, hi_b - lo_b);
    for (uint32_t j = 0; j < g->rows && res == RAD_OK; j++) {
        for (uint32_t i = 0; i < g->columns; i++) {
            double s = g->border + (i + 0.5) * g->spacing_u, t = g->border + (j + 0.5) * g->spacing_v;
            double qa = lo_a + s, qb = lo_b + t;
            bool in = false;
            for (size_t q = 0; q < np && !in; q++)
                in = inside(pa + start[q], pb + start[q], start[q + 1] - start[q], qa, qb);
            /* At least the border from every outline edge (one no other
             * footprint polygon shares). */
            for (size_t q = 0; q < np && in && g->border > 0.0; q++)
                for (size_t c = start[q]; c < start[q + 1] && in; c++) {
                    size_t d = c + 1 < start[q + 1] ? c + 1 : start[q];
                    bool shared = false;
                    for (size_t r = 0; r < np && !shared; r++)
                        for (size_t e = start[r]; e < start[r + 1] && !shared && r != q; e++) {
                            size_t f = e + 1 < start[r + 1] ? e + 1 : start[r];
                            shared = (fabs(pa[e] - pa[d]) <= tol && fabs(pb[e] - pb[d]) <= tol &&
                                      fabs(pa[f] - pa[c]) <= tol && fabs(pb[f] - pb[c]) <= tol) ||
                                     (fabs(pa[e] - pa[c]) <= tol && fabs(pb[e] - pb[c]) <= tol &&
                                      fabs(pa[f] - pa[d]) <= tol && fabs(pb[f] - pb[d]) <= tol);
                        }
                    if (!shared && segment_distance(qa, qb, pa[c], pb[c], pa[d], pb[d]) < g->border - tol)
                        in = false;
                }
            if (!in)
                continue;
            res = grow(b, 1);
            if (res != RAD_OK)
                break;
            vec3 x = v3(0, 0, 0);
            x = v3_mad(x, axis(up), top + height);
            x = v3_mad(x, axis(ia), qa);
            x = v3_mad(x, axis(ib), qb);
            add_point(b, x, n, s, t);
        }
    }
    rad_free(pa);
    if (res == RAD_OK && b->set->point_count == g->first_point)
        res = rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: no point of the grid lies on '%.200s' (border %.6g m)",
                       b->file, where, k->surface->valuestring, g->border);
    return res;
}

static rad_result read_grid(builder *b, const rad_scene *scene, size_t index, const cJSON *o)
{
    rad_context *ctx = b->ctx;
    char where[64];
    snprintf(where, sizeof where, "grids[%zu]", index);
    if (!cJSON_IsObject(o))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: must be an object with \"name\" and \"rectangle\" or "
                        "\"surface\"", b->file, where);
    grid_keys k;
    rad_result r = read_keys(b, where, o, &k);
    if (r != RAD_OK)
        return r;
    if (!k.name || !cJSON_IsString(k.name) || !k.name->valuestring[0])
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.name: needs a name (a non-empty string)", b->file, where);
    rad_grid_set *s = b->set;
    for (size_t g = 0; g < s->grid_count; g++)
        if (strcmp(s->grids[g].name, k.name->valuestring) == 0)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.name: '%.200s' names grids[%zu] already", b->file, where,
                            k.name->valuestring, g);
    if (!k.rectangle == !k.surface)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: give one of \"rectangle\" and \"surface\"", b->file, where);
    double p;
    r = read_spacing(b, where, k.spacing, &p);
    if (r != RAD_OK)
        return r;
    rad_grid_def *g = &s->grids[s->grid_count];
    memset(g, 0, sizeof *g);
    g->first_point = s->point_count;
    g->name = rad_strdup(ctx, RAD_MEM_SCENE, k.name->valuestring, "grid: name");
    if (!g->name)
        return RAD_ERROR_OUT_OF_MEMORY;
    s->grid_count++;
    if (k.rectangle) {
        r = read_length(b, where, "border", k.border, 0.0, &g->border);
        if (r == RAD_OK)
            r = rectangle_grid(b, where, &k, g, p);
    } else {
        r = surface_grid(b, scene, where, &k, g, p);
    }
    g->point_count = s->point_count - g->first_point;
    return r;
}

static rad_result read_points(builder *b, const cJSON *list)
{
    rad_context *ctx = b->ctx;
    if (!cJSON_IsArray(list))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: points: must be an array of {\"name\", \"position\", "
                        "\"normal\"}", b->file);
    rad_grid_set *s = b->set;
    rad_grid_def *g = &s->grids[s->grid_count];
    memset(g, 0, sizeof *g);
    g->first_point = s->point_count;
    g->points = true;
    g->name = rad_strdup(ctx, RAD_MEM_SCENE, "points", "grid: name");
    if (!g->name)
        return RAD_ERROR_OUT_OF_MEMORY;
    s->grid_count++;
    size_t index = 0;
    for (const cJSON *o = list->child; o; o = o->next, index++) {
        char where[64];
        snprintf(where, sizeof where, "points[%zu]", index);
        if (!cJSON_IsObject(o))
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: must be an object {\"name\", \"position\", \"normal\"}",
                            b->file, where);
        const cJSON *name = NULL, *pos = NULL, *nrm = NULL;
        for (const cJSON *item = o->child; item; item = item->next) {
            const cJSON **slot = strcmp(item->string, "name") == 0       ? &name
                                 : strcmp(item->string, "position") == 0 ? &pos
                                 : strcmp(item->string, "normal") == 0   ? &nrm
                                                                         : NULL;
            if (!slot)
                return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.%.200s: unknown key (known: name, position, normal)",
                                b->file, where, item->string);
            if (*slot)
                return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.%s: given twice", b->file, where, item->string);
            *slot = item;
        }
        if (!name || !cJSON_IsString(name) || !name->valuestring[0])
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.name: needs a name (a non-empty string)", b->file, where);
        if (!pos)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: needs \"position\"", b->file, where);
        vec3 p, n = axis(s->up_axis);
        rad_result r = read_vec3(b, where, "position", pos, &p);
        if (r == RAD_OK && nrm)
            r = read_vec3(b, where, "normal", nrm, &n);
        if (r != RAD_OK)
            return r;
        if (!(v3_length(n) > 0.0))
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.normal: must not be zero", b->file, where);
        r = grow(b, 1);
        if (r != RAD_OK)
            return r;
        char *copy = rad_strdup(ctx, RAD_MEM_SCENE, name->valuestring, "grid: point name");
        if (!copy)
            return RAD_ERROR_OUT_OF_MEMORY;
        add_point(b, p, v3_normalize(n), 0.0, 0.0);
        s->point_name[s->point_count - 1] = copy;
        g->point_count++;
    }
    if (g->point_count == 0)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: points: empty (leave it out)", b->file);
    return RAD_OK;
}

static rad_result parse_tree(builder *b, const rad_scene *scene, const cJSON *root)
{
    rad_context *ctx = b->ctx;
    if (!cJSON_IsObject(root))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: must be a JSON object with \"grids\" and/or \"points\"", b->file);
    const cJSON *up = NULL, *grids = NULL, *points = NULL;
    for (const cJSON *item = root->child; item; item = item->next) {
        const cJSON **slot = strcmp(item->string, "up") == 0      ? &up
                             : strcmp(item->string, "grids") == 0  ? &grids
                             : strcmp(item->string, "points") == 0 ? &points
                                                                   : NULL;
        if (!slot)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %.200s: unknown key (known: up, grids, points)", b->file,
                            item->string);
        if (*slot)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: given twice", b->file, item->string);
        *slot = item;
    }
    b->set->up_axis = 1;
    if (up) {
        const char *a = cJSON_IsString(up) ? up->valuestring : "";
        if (strlen(a) != 1 || !strchr("xyz", a[0]))
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: up: must be \"x\", \"y\" or \"z\"", b->file);
        b->set->up_axis = a[0] - 'x';
    }
    if (!grids && !points)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: neither \"grids\" nor \"points\": nothing to compute", b->file);
    if (grids && (!cJSON_IsArray(grids) || cJSON_GetArraySize(grids) == 0))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: grids: must be a non-empty array of grids", b->file);
    size_t count = (size_t)(grids ? cJSON_GetArraySize(grids) : 0) + 1;
    b->set->grids = rad_alloc(ctx, RAD_MEM_SCENE, count, sizeof *b->set->grids, "grid: grids");
    if (!b->set->grids)
        return RAD_ERROR_OUT_OF_MEMORY;
    size_t index = 0;
    for (const cJSON *o = grids ? grids->child : NULL; o; o = o->next, index++) {
        rad_result r = read_grid(b, scene, index, o);
        if (r != RAD_OK)
            return r;
    }
    return points ? read_points(b, points) : RAD_OK;
}

rad_result rad_grid_parse(rad_context *ctx, const rad_scene *scene, const char *name, const char *text,
                          size_t size, rad_grid_set **out)
{
    *out = NULL;
    rad_grid_set *set = rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *set, "grid: set");
    if (!set)
        return RAD_ERROR_OUT_OF_MEMORY;
    set->source = rad_strdup(ctx, RAD_MEM_SCENE, name, "grid: file name");
    if (!set->source) {
        rad_free(set);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    builder b = {ctx, name, set, 0};
    rad_result r;
    cJSON *root = NULL;
    r = rad_json_parse(ctx, name, text, size, &root);
    if (r == RAD_OK)
        r = parse_tree(&b, scene, root);
    cJSON_Delete(root);
    if (r != RAD_OK) {
        rad_grid_set_destroy(set);
        return r;
    }
    *out = set;
    return RAD_OK;
}
