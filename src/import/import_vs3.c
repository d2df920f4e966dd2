/*
 * import_vs3.c -- View3D's vertex/surface input (.vs3, "F 3") as a scene,
 * so a thermal engineer's existing View3D model runs unchanged.
 *
 * The format is NIST View3D 3.x's (G. N. Walton, NISTIR 6925; the View3D
 * user manual, "Input File Format"): one record a line, its kind the first
 * character, comments from '!' or '/' to the end of the line.
 *
 *     T title                      C eps=1e-4 encl=1 out=0 ...
 *     F 3                          V n x y z
 *     S n v1 v2 v3 v4 base cmb emit name     (v4 = 0: a triangle)
 *     M / N (mask / null)  O n v1 v2 v3 v4 [0 0 emit name] (obstruction)
 *     E  (or "End of data", '*'): the rest of the file is not read
 *
 * Vertices are listed counter-clockwise seen from the front, so the
 * right-hand normal points to the front, as in the engine.  What each kind
 * of surface becomes (docs/formats.md "View3D"):
 *
 *     S, base 0        a named surface, reflectance rho = 1 - emit (grey)
 *     S, base b        its own surface; cut out of surface b (a hole there):
 *                      View3D reports the base without the sub-surface's area
 *     N, base b        a hole in surface b, no surface of its own
 *     S, cmb c         its polygon added to surface c: one output surface
 *     C emit=1         the .vf holds Hottel's script-F factors (output/view3d.c)
 *     O                a surface flagged obstruction-only: it blocks rays,
 *                      the view-factor outputs leave it out
 *     M, base b        a hole in surface b, filled by the mask's polygon
 *                      (it blocks rays, one element); the outputs report
 *                      b with its whole area and the mask as View3D does:
 *                      F(mask, b) = 1, F(b, mask) = A_mask / A_b, nothing
 *                      else sees the mask (output/view3d.c)
 *
 *   A hole H (convex) in a convex piece P is cut as P minus H = the union of
 *   P clipped inside edges 0..k-1 of H and outside edge k, k = 0..m-1:
 *   disjoint convex pieces that tile P \ H exactly.
 *
 *         +-----------+          piece 0: outside e0 (below H)
 *         |  2  e2    |          piece 1: above e0, outside e1 (right)
 *         |   +---+   |          piece 2: ..., outside e2 (top)
 *         | 3 |H  | 1 |          piece 3: ..., outside e3 (left)
 *         |   +---+   |
 *         |  0  e0    |
 *         +-----------+
 *
 * Every malformed record is an error naming the file and line.
 */
#include "import/import.h"

#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

enum { VS3_RADIATING, VS3_MASK, VS3_NULL, VS3_OBSTRUCTION };

/* Pieces of one surface after its holes are cut: convex polygons.  A
 * convex piece clipped by the m <= 4 half-planes of one hole gains at most
 * m corners, so VS3_PIECE_MAX bounds a base with many overlapping holes;
 * past it the file is refused (no View3D model comes near). */
#define VS3_PIECE_MAX 32

typedef struct vs3_piece {
    vec3 v[VS3_PIECE_MAX];
    int n;                 /* VS3_PIECE_MAX + 1: too many corners */
} vs3_piece;

typedef struct vs3_surface {
    int kind;
    int line;
    int vertex_count;      /* 3 or 4 */
    int vertex[4];         /* 1-based, into the V records */
    int base, combine;     /* 0 or a 1-based surface number */
    double emissivity;     /* (0, 1]; obstructions: 1 unless given */
    char name[128];
    vec3 normal;           /* unit, right-hand over the vertices */
    vs3_piece *pieces;
    int piece_count, piece_capacity;
    int scene_surface;     /* builder index, -1 for null surfaces */
} vs3_surface;

typedef struct vs3_reader {
    rad_context *ctx;
    const char *name;
    vec3 *vertices;
    int vertex_count, vertex_capacity;
    vs3_surface *surfaces;
    int surface_count, surface_capacity;
    rad_view3d_control control;
    bool have_format;
} vs3_reader;

static rad_result parse_error(vs3_reader *r, int line, const char *fmt, ...)
{
    char message[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    return rad_fail(r->ctx, RAD_ERROR_PARSE, "%s:%d: %s", r->name, line, message);
}

/* Up to `most` whitespace-separated words of a line (comments already cut);
 * returns how many there are (may exceed `most`). */
static int split_words(char *text, char **words, int most)
{
    int count = 0;
    char *save = NULL;
    for (char *w = strtok_r(text, " \t\r\f\v", &save); w; w = strtok_r(NULL, " \t\r\f\v", &save)) {
        if (count < most)
            words[count] = w;
        count++;
    }
    return count;
}

static bool parse_int(const char *text, long lo, long hi, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (end == text || *end || errno || v < lo || v > hi)
        return false;
    *out = (int)v;
    return true;
}

/* A finite number, all of the word. */
static bool parse_double(const char *text, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end || !isfinite(v))
        return false;
    *out = v;
    return true;
}

static rad_result parse_control(vs3_reader *r, char *text, int line)
{
    char *save = NULL;
    for (char *key = strtok_r(text, " \t\r=,", &save); key; key = strtok_r(NULL, " \t\r=,", &save)) {
        char *value = strtok_r(NULL, " \t\r=,", &save);
        if (!value)
            return parse_error(r, line, "control '%s' has no value (C name=value ...)", key);
        int i;
        double d;
        /* The integrator's own controls: View3D's accuracy knobs, accepted
         * and checked; the engine's form-factor method sets its accuracy. */
        if (strcasecmp(key, "eps") == 0) {
            if (!parse_double(value, &d) || d <= 0.0)
                return parse_error(r, line, "eps '%s' is not a positive number", value);
        } else if (strcasecmp(key, "maxU") == 0 || strcasecmp(key, "maxO") == 0 ||
                   strcasecmp(key, "minO") == 0 || strcasecmp(key, "list") == 0 ||
                   strcasecmp(key, "maxV") == 0 || strcasecmp(key, "prjD") == 0) {
            if (!parse_int(value, 0, 1000000, &i))
                return parse_error(r, line, "%s '%s' is not a non-negative integer", key, value);
        } else if (strcasecmp(key, "row") == 0 || strcasecmp(key, "col") == 0) {
            if (!parse_int(value, 0, INT32_MAX, &i))
                return parse_error(r, line, "%s '%s' is not a non-negative integer", key, value);
            if (i != 0)
                return parse_error(r, line, "%s=%d (one row or column of the matrix) is not supported: "
                                            "the whole matrix is computed; use %s=0", key, i, key);
        } else if (strcasecmp(key, "encl") == 0) {
            if (!parse_int(value, 0, 1, &i))
                return parse_error(r, line, "encl '%s' is not 0 or 1", value);
            r->control.enclosure = i;
        } else if (strcasecmp(key, "emit") == 0) {
            if (!parse_int(value, 0, 1, &i))
                return parse_error(r, line, "emit '%s' is not 0 or 1", value);
            r->control.emittances = i;
        } else if (strcasecmp(key, "out") == 0) {
            if (!parse_int(value, 0, 1, &i))
                return parse_error(r, line, "out '%s' is not 0 (text) or 1 (binary)", value);
            r->control.out_format = i;
        } else {
            return parse_error(r, line, "unknown control '%s' (eps, maxU, maxO, minO, row, col, encl, "
                                        "emit, out, list)", key);
        }
    }
    return RAD_OK;
}

static bool grow(vs3_reader *r, void **array, int *capacity, int wanted, size_t size)
{
    if (wanted <= *capacity)
        return true;
    int bigger = *capacity ? 2 * *capacity : 16;
    while (bigger < wanted)
        bigger *= 2;
    void *p = rad_realloc(r->ctx, RAD_MEM_SCENE, *array, (size_t)bigger, size, r->name);
    if (!p)
        return false;
    *array = p;
    *capacity = bigger;
    return true;
}

static rad_result parse_vertex(vs3_reader *r, char **w, int count, int line)
{
    if (count != 5)
        return parse_error(r, line, "a vertex needs 'V number x y z' (%d fields)", count);
    int number;
    if (!parse_int(w[1], 1, INT32_MAX - 1, &number) || number != r->vertex_count + 1)
        return parse_error(r, line, "vertex number '%s' out of sequence (expected %d)", w[1],
                           r->vertex_count + 1);
    vec3 p;
    if (!parse_double(w[2], &p.x) || !parse_double(w[3], &p.y) || !parse_double(w[4], &p.z))
        return parse_error(r, line, "vertex %d: a coordinate is not a finite number", number);
    if (fabs(p.x) > RAD_MAX_COORDINATE || fabs(p.y) > RAD_MAX_COORDINATE || fabs(p.z) > RAD_MAX_COORDINATE)
        return parse_error(r, line, "vertex %d: a coordinate is beyond %g m", number, RAD_MAX_COORDINATE);
    if (!grow(r, (void **)&r->vertices, &r->vertex_capacity, r->vertex_count + 1, sizeof *r->vertices))
        return RAD_ERROR_OUT_OF_MEMORY;
    r->vertices[r->vertex_count++] = p;
    return RAD_OK;
}

static rad_result parse_surface(vs3_reader *r, int kind, char **w, int count, int line)
{
    bool short_obstruction = kind == VS3_OBSTRUCTION && count == 6;
    if (count != 10 && !short_obstruction)
        return parse_error(r, line, "a surface needs '%c number v1 v2 v3 v4 base cmb emit name'%s (%d fields)",
                           w[0][0], kind == VS3_OBSTRUCTION ? " or 'O number v1 v2 v3 v4'" : "", count);
    if (!grow(r, (void **)&r->surfaces, &r->surface_capacity, r->surface_count + 1, sizeof *r->surfaces))
        return RAD_ERROR_OUT_OF_MEMORY;
    vs3_surface *s = &r->surfaces[r->surface_count];
    memset(s, 0, sizeof *s);
    s->kind = kind;
    s->line = line;
    s->scene_surface = -1;
    int number;
    if (!parse_int(w[1], 1, INT32_MAX - 1, &number) || number != r->surface_count + 1)
        return parse_error(r, line, "surface number '%s' out of sequence (expected %d)", w[1],
                           r->surface_count + 1);
    s->vertex_count = 4;
    for (int k = 0; k < 4; k++) {
        if (!parse_int(w[2 + k], 0, INT32_MAX, &s->vertex[k]))
            return parse_error(r, line, "surface %d: vertex '%s' is not a vertex number", number, w[2 + k]);
        if (s->vertex[k] > r->vertex_count)
            return parse_error(r, line, "surface %d: vertex %d of %d (vertices come before surfaces)",
                               number, s->vertex[k], r->vertex_count);
        if (s->vertex[k] == 0 && k < 3)
            return parse_error(r, line, "surface %d: vertex %d is 0 (only the fourth may be 0: a triangle)",
                               number, k + 1);
    }
    if (s->vertex[3] == 0)
        s->vertex_count = 3;
    for (int a = 0; a < s->vertex_count; a++)
        for (int b = a + 1; b < s->vertex_count; b++)
            if (s->vertex[a] == s->vertex[b])
                return parse_error(r, line, "surface %d repeats vertex %d", number, s->vertex[a]);
    s->emissivity = 1.0;
    if (short_obstruction) {
        snprintf(s->name, sizeof s->name, "obstruction-%d", number);
    } else {
        if (!parse_int(w[6], 0, INT32_MAX, &s->base))
            return parse_error(r, line, "surface %d: base '%s' is not a surface number", number, w[6]);
        if (!parse_int(w[7], 0, INT32_MAX, &s->combine))
            return parse_error(r, line, "surface %d: cmb '%s' is not a surface number", number, w[7]);
        if (!parse_double(w[8], &s->emissivity) || !(s->emissivity > 0.0 && s->emissivity <= 1.0))
            return parse_error(r, line, "surface %d: emissivity '%s' is not in (0, 1]", number, w[8]);
        if (strlen(w[9]) >= sizeof s->name)
            return parse_error(r, line, "surface %d: name longer than %zu characters", number,
                               sizeof s->name - 1);
        strcpy(s->name, w[9]);
    }
    if (kind == VS3_OBSTRUCTION && (s->base || s->combine))
        return parse_error(r, line, "obstruction surface %d: base and cmb must be 0", number);
    if ((kind == VS3_NULL || kind == VS3_MASK) && s->base == 0)
        return parse_error(r, line, "%s surface %d needs a base surface", kind == VS3_NULL ? "null" : "mask",
                           number);
    if (kind != VS3_OBSTRUCTION && r->surface_count > 0 &&
        r->surfaces[r->surface_count - 1].kind == VS3_OBSTRUCTION)
        return parse_error(r, line, "surface %d follows an obstruction surface: obstruction surfaces (O) "
                                    "come after all others", number);
    r->surface_count++;
    return RAD_OK;
}

/* The corners of surface s, its Newell normal, and the checks View3D
 * makes of a polygon: non-degenerate, planar (quads), convex. */
static rad_result check_polygon(vs3_reader *r, vs3_surface *s, int number)
{
    vec3 p[4];
    for (int k = 0; k < s->vertex_count; k++)
        p[k] = r->vertices[s->vertex[k] - 1];
    vec3 newell = rad_polygon_newell(p, (size_t)s->vertex_count);
    double size = 0.0;
    for (int k = 0; k < s->vertex_count; k++)
        size = fmax(size, v3_length(v3_sub(p[(k + 1) % s->vertex_count], p[k])));
    double area = 0.5 * v3_length(newell);
    /* 1e-12 of the square of its longest edge: a sliver no factor can be had for. */
    if (!(size > RAD_MIN_LENGTH) || !(area > 1e-12 * size * size))
        return parse_error(r, s->line, "surface %d has no area (repeated or collinear vertices)", number);
    s->normal = v3_scale(newell, 1.0 / (2.0 * area));
    for (int k = 0; k < s->vertex_count; k++) {
        vec3 a = p[k], b = p[(k + 1) % s->vertex_count], c = p[(k + 2) % s->vertex_count];
        /* 1e-6 of its size: View3D's quads are flat to single precision. */
        if (fabs(v3_dot(v3_sub(a, p[0]), s->normal)) > 1e-6 * size)
            return parse_error(r, s->line, "surface %d is not planar (vertex %d is %g m off its plane)",
                               number, s->vertex[k], fabs(v3_dot(v3_sub(a, p[0]), s->normal)));
        if (v3_dot(v3_cross(v3_sub(b, a), v3_sub(c, b)), s->normal) <= 1e-12 * size * size)
            return parse_error(r, s->line, "surface %d is not convex at vertex %d (View3D takes convex "
                                           "quadrilaterals and triangles)", number, s->vertex[(k + 1) % s->vertex_count]);
    }
    s->pieces = rad_alloc(r->ctx, RAD_MEM_SCENE, 1, sizeof *s->pieces, r->name);
    if (!s->pieces)
        return RAD_ERROR_OUT_OF_MEMORY;
    s->piece_capacity = 1;
    s->piece_count = 1;
    s->pieces[0].n = s->vertex_count;
    memcpy(s->pieces[0].v, p, (size_t)s->vertex_count * sizeof *p);
    return RAD_OK;
}

/* Clip convex polygon `in` to the side of the plane through `a` with unit
 * normal `side` where dot(x - a, side) >= 0.  Corners within `tol` (m) of
 * the plane count as on it, and a corner within `tol` of the one before is
 * dropped: holes sharing an edge line (two windows in a row) would
 * otherwise leave doubled corners that the scene refuses as a polygon
 * touching itself. */
static void clip(const vs3_piece *in, vec3 a, vec3 side, double tol, vs3_piece *out)
{
    out->n = 0;
    vec3 v[2 * VS3_PIECE_MAX];
    int n = 0;
    for (int k = 0; k < in->n; k++) {
        vec3 p = in->v[k], q = in->v[(k + 1) % in->n];
        double dp = v3_dot(v3_sub(p, a), side), dq = v3_dot(v3_sub(q, a), side);
        if (fabs(dp) <= tol)
            dp = 0.0;
        if (fabs(dq) <= tol)
            dq = 0.0;
        if (dp >= 0.0)
            v[n++] = p;
        if ((dp > 0.0 && dq < 0.0) || (dp < 0.0 && dq > 0.0))
            v[n++] = v3_lerp(p, q, dp / (dp - dq));
    }
    for (int k = 0; k < n; k++) {
        vec3 prev = out->n ? out->v[out->n - 1] : v[n - 1];
        if (v3_length(v3_sub(v[k], prev)) <= tol && (out->n || n > 1))
            continue;
        if (out->n == VS3_PIECE_MAX) { /* more corners than a piece holds: refused by the caller */
            out->n = VS3_PIECE_MAX + 1;
            return;
        }
        out->v[out->n++] = v[k];
    }
    while (out->n > 1 && v3_length(v3_sub(out->v[out->n - 1], out->v[0])) <= tol)
        out->n--;
}

static double piece_area(const vs3_piece *p)
{
    return p->n >= 3 ? 0.5 * v3_length(rad_polygon_newell(p->v, (size_t)p->n)) : 0.0;
}

/* Surface `hole` (a sub-surface or null surface) checked against its base
 * (in its plane, facing its way for a sub-surface, inside it) and cut out
 * of the base's pieces. */
static rad_result cut_hole(vs3_reader *r, int hole_number)
{
    vs3_surface *h = &r->surfaces[hole_number - 1];
    vs3_surface *base = &r->surfaces[h->base - 1];
    vec3 bp[4];
    for (int k = 0; k < base->vertex_count; k++)
        bp[k] = r->vertices[base->vertex[k] - 1];
    double size = 0.0;
    for (int k = 0; k < base->vertex_count; k++)
        size = fmax(size, v3_length(v3_sub(bp[(k + 1) % base->vertex_count], bp[k])));
    double tol = 1e-6 * size; /* as the planarity test */
    /* 1e-9 of the base's size: corners this near a cut are on it (rounding
     * of the cuts before), far below any hole View3D's floats can place. */
    double clip_tol = 1e-9 * size;
    if (h->kind == VS3_RADIATING && v3_dot(h->normal, base->normal) <= 0.0)
        return parse_error(r, h->line, "sub-surface %d faces away from its base %d (it must face the same way)",
                           hole_number, h->base);
    if (h->kind == VS3_MASK && v3_dot(h->normal, base->normal) >= 0.0)
        return parse_error(r, h->line, "mask surface %d must face its base %d (the opposite way to it)",
                           hole_number, h->base);
    vec3 hp[4];
    for (int k = 0; k < h->vertex_count; k++) {
        hp[k] = r->vertices[h->vertex[k] - 1];
        if (fabs(v3_dot(v3_sub(hp[k], bp[0]), base->normal)) > tol)
            return parse_error(r, h->line, "surface %d is not in the plane of its base %d", hole_number, h->base);
        for (int e = 0; e < base->vertex_count; e++) {
            vec3 a = bp[e], b = bp[(e + 1) % base->vertex_count];
            vec3 inward = v3_normalize(v3_cross(base->normal, v3_sub(b, a)));
            if (v3_dot(v3_sub(hp[k], a), inward) < -tol)
                return parse_error(r, h->line, "surface %d is not inside its base %d (vertex %d is outside)",
                                   hole_number, h->base, h->vertex[k]);
        }
    }
    /* The hole's corners in the base's orientation (a null surface may
     * face either way), with its edges' inward normals. */
    int m = h->vertex_count;
    bool reversed = v3_dot(h->normal, base->normal) < 0.0;
    vec3 corner[4], inward[4];
    for (int e = 0; e < m; e++)
        corner[e] = hp[reversed ? m - 1 - e : e];
    for (int e = 0; e < m; e++)
        inward[e] = v3_normalize(v3_cross(base->normal, v3_sub(corner[(e + 1) % m], corner[e])));
    double base_area = piece_area(&(vs3_piece){.n = base->vertex_count,
                                               .v = {bp[0], bp[1], bp[2], bp[base->vertex_count - 1]}});
    int count = base->piece_count;
    for (int p = 0; p < count; p++) {
        vs3_piece inside = base->pieces[p];
        bool first = true;
        for (int e = 0; e < m; e++) {
            vs3_piece out;
            clip(&inside, corner[e], v3_scale(inward[e], -1.0), clip_tol, &out);
            if (out.n > VS3_PIECE_MAX)
                return parse_error(r, h->line, "base surface %d is cut by too many sub-surfaces", h->base);
            /* 1e-12 of the base: slivers of the clipping's rounding. */
            if (piece_area(&out) > 1e-12 * base_area) {
                if (first) {
                    base->pieces[p] = out;
                    first = false;
                } else {
                    if (!grow(r, (void **)&base->pieces, &base->piece_capacity, base->piece_count + 1,
                              sizeof *base->pieces))
                        return RAD_ERROR_OUT_OF_MEMORY;
                    base->pieces[base->piece_count++] = out;
                }
            }
            vs3_piece next;
            clip(&inside, corner[e], inward[e], clip_tol, &next);
            if (next.n > VS3_PIECE_MAX)
                return parse_error(r, h->line, "base surface %d is cut by too many sub-surfaces", h->base);
            inside = next;
        }
        if (first) /* the piece lies inside the hole */
            base->pieces[p].n = 0;
    }
    return RAD_OK;
}

/* The relations between surfaces (View3D's GetSrfD rules) and the holes. */
static rad_result check_relations(vs3_reader *r)
{
    int n = r->surface_count;
    for (int i = 1; i <= n; i++) {
        vs3_surface *s = &r->surfaces[i - 1];
        if (s->base) {
            if (s->base > n || s->base == i)
                return parse_error(r, s->line, "surface %d: base %d is not another surface (1 to %d)", i,
                                   s->base, n);
            vs3_surface *b = &r->surfaces[s->base - 1];
            if (b->kind == VS3_NULL || b->kind == VS3_MASK)
                return parse_error(r, s->line, "surface %d: base %d is a %s surface", i, s->base,
                                   b->kind == VS3_NULL ? "null" : "mask");
            if ((s->kind == VS3_NULL || s->kind == VS3_MASK) && (b->kind != VS3_RADIATING || s->base > i))
                return parse_error(r, s->line, "%s surface %d: its base must be an earlier S surface",
                                   s->kind == VS3_NULL ? "null" : "mask", i);
            if (b->kind == VS3_RADIATING && s->base > i)
                return parse_error(r, s->line, "sub-surface %d must come after its base %d", i, s->base);
        }
        if (s->combine) {
            if (s->combine >= i)
                return parse_error(r, s->line, "surface %d: cmb %d must be an earlier surface", i, s->combine);
            vs3_surface *c = &r->surfaces[s->combine - 1];
            if (s->kind != VS3_RADIATING || c->kind != VS3_RADIATING)
                return parse_error(r, s->line, "surface %d: only S surfaces combine", i);
            if (c->combine)
                return parse_error(r, s->line, "surface %d: cmb %d is itself combined (combine every part "
                                               "with the lowest-numbered one)", i, s->combine);
            if (r->control.emittances && s->emissivity != c->emissivity)
                return parse_error(r, s->line, "surface %d: emissivity %g differs from that of surface %d (%g) "
                                               "it is combined with: with emit=1 a surface has one emissivity",
                                   i, s->emissivity, s->combine, c->emissivity);
        }
    }
    /* Names are the output's labels: one each (null surfaces have none). */
    for (int i = 1; i <= n; i++) {
        vs3_surface *s = &r->surfaces[i - 1];
        if (s->kind == VS3_NULL || s->combine)
            continue;
        for (int j = 1; j < i; j++) {
            const vs3_surface *t = &r->surfaces[j - 1];
            if (t->kind != VS3_NULL && !t->combine && strcmp(t->name, s->name) == 0)
                return parse_error(r, s->line, "surface %d: name '%s' is already surface %d's (line %d)", i,
                                   s->name, j, t->line);
        }
    }
    for (int i = 1; i <= n; i++) {
        rad_result res = r->surfaces[i - 1].base ? cut_hole(r, i) : RAD_OK;
        if (res != RAD_OK)
            return res;
    }
    return RAD_OK;
}

static rad_result build_scene(vs3_reader *r, rad_scene **out)
{
    rad_scene_builder *b = rad_scene_builder_create(r->ctx, r->name);
    if (!b)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result res = RAD_OK;
    for (int i = 1; i <= r->surface_count && res == RAD_OK; i++) {
        vs3_surface *s = &r->surfaces[i - 1];
        if (s->kind == VS3_NULL)
            continue;
        vs3_surface *owner = s->combine ? &r->surfaces[s->combine - 1] : s;
        if (!s->combine) {
            s->scene_surface = rad_scene_builder_surface(b, s->name);
            if (s->scene_surface < 0) {
                res = RAD_ERROR_OUT_OF_MEMORY;
                break;
            }
            if (s->kind == VS3_OBSTRUCTION)
                rad_scene_builder_surface_obstruction(b, s->scene_surface);
            if (s->kind == VS3_MASK) {
                const vs3_surface *base = &r->surfaces[s->base - 1];
                rad_scene_builder_surface_mask(
                    b, s->scene_surface,
                    base->combine ? r->surfaces[base->combine - 1].scene_surface : base->scene_surface);
            }
        }
        double rho = 1.0 - s->emissivity;
        double reflectance[3] = {rho, rho, rho}, emission[3] = {0.0, 0.0, 0.0};
        char material[192];
        snprintf(material, sizeof material, "%s (emissivity %.17g)", s->name, s->emissivity);
        int mat = rad_scene_builder_material(b, material, reflectance, emission);
        if (mat < 0) { /* rho is in [0, 1): only memory can fail */
            res = RAD_ERROR_OUT_OF_MEMORY;
            break;
        }
        int pieces = 0;
        for (int p = 0; p < s->piece_count && res == RAD_OK; p++) {
            if (s->pieces[p].n < 3)
                continue;
            pieces++;
            res = rad_scene_builder_polygon(b, owner->scene_surface, mat, s->pieces[p].v,
                                            (size_t)s->pieces[p].n, s->line);
        }
        if (res == RAD_OK && pieces == 0)
            res = parse_error(r, s->line, "surface %d is entirely covered by its sub-surfaces", i);
    }
    if (res != RAD_OK) {
        rad_scene_builder_destroy(b);
        return res;
    }
    res = rad_scene_builder_finish(b, out);
    if (res == RAD_OK) {
        (*out)->view3d = r->control;
        (*out)->view3d.present = true;
    }
    return res;
}

static rad_result parse(vs3_reader *r, const char *text, size_t size)
{
    char buffer[4096];
    int line = 0;
    bool ended = false;
    for (size_t at = 0; at < size && !ended;) {
        const char *start = text + at;
        const char *nl = memchr(start, '\n', size - at);
        size_t length = nl ? (size_t)(nl - start) : size - at;
        at += length + 1;
        line++;
        if (memchr(start, '\0', length))
            return parse_error(r, line, "NUL byte in the text");
        if (length >= sizeof buffer)
            return parse_error(r, line, "line longer than %zu characters", sizeof buffer - 1);
        memcpy(buffer, start, length);
        buffer[length] = '\0';
        char *c = buffer;
        while (*c && strchr(" \t\r\f\v", *c)) /* the blanks split_words splits at */
            c++;
        if (!*c || *c == '!' || *c == '/')
            continue;
        char kind = (char)toupper((unsigned char)*c);
        if (kind == 'T')
            continue; /* the title: View3D's output does not carry it */
        if (kind == 'E' || kind == '*') {
            ended = true;
            break;
        }
        /* A comment may follow the data. */
        char *comment = strpbrk(c, "!/");
        if (comment)
            *comment = '\0';
        if (kind == 'C') {
            if (c[1] && c[1] != ' ' && c[1] != '\t')
                return parse_error(r, line, "unknown record '%.20s'", c);
            rad_result res = parse_control(r, c + 1, line);
            if (res != RAD_OK)
                return res;
            continue;
        }
        char *w[12];
        int count = split_words(c, w, 12);
        if (count == 0 || strlen(w[0]) != 1)
            return parse_error(r, line, "unknown record '%.20s'", count ? w[0] : c);
        rad_result res = RAD_OK;
        switch (kind) {
        case 'F':
            if (count != 2 || strcmp(w[1], "3") != 0)
                return parse_error(r, line, "geometry 'F %s' is not supported: only F 3 (vertices and "
                                            "surfaces; not 2-D, 3a or 1-D)", count > 1 ? w[1] : "");
            if (r->vertex_count || r->surface_count)
                return parse_error(r, line, "the F line must come before vertices and surfaces");
            r->have_format = true;
            break;
        case 'X': /* View3D reads and ignores coordinate transformations in F 3 */
            break;
        case 'V':
            res = parse_vertex(r, w, count, line);
            break;
        case 'S':
            res = parse_surface(r, VS3_RADIATING, w, count, line);
            break;
        case 'M':
            res = parse_surface(r, VS3_MASK, w, count, line);
            break;
        case 'N':
            res = parse_surface(r, VS3_NULL, w, count, line);
            break;
        case 'O':
            res = parse_surface(r, VS3_OBSTRUCTION, w, count, line);
            break;
        default:
            return parse_error(r, line, "unknown record '%c' (T, C, F, V, S, M, N, O, E)", *c);
        }
        if (res != RAD_OK)
            return res;
    }
    if (!r->have_format)
        return rad_fail(r->ctx, RAD_ERROR_PARSE, "%s: no 'F 3' geometry line", r->name);
    int radiating = 0;
    for (int i = 0; i < r->surface_count; i++)
        radiating += r->surfaces[i].kind == VS3_RADIATING;
    if (!radiating)
        return rad_fail(r->ctx, RAD_ERROR_PARSE, "%s: no surfaces (S lines)", r->name);
    for (int i = 0; i < r->surface_count; i++) {
        rad_result res = check_polygon(r, &r->surfaces[i], i + 1);
        if (res != RAD_OK)
            return res;
    }
    return check_relations(r);
}

rad_result rad_import_vs3_memory(rad_context *ctx, const char *name, const char *text, size_t size,
                                 rad_scene **out)
{
    *out = NULL;
    vs3_reader r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    r.name = name;
    rad_result res = parse(&r, text, size);
    if (res == RAD_OK)
        res = build_scene(&r, out);
    for (int i = 0; i < r.surface_count; i++)
        rad_free(r.surfaces[i].pieces);
    rad_free(r.surfaces);
    rad_free(r.vertices);
    return res;
}

bool rad_vs3_detect(const char *name, const char *text, size_t size)
{
    size_t len = name ? strlen(name) : 0;
    if (len >= 4 && strcasecmp(name + len - 4, ".vs3") == 0)
        return true;
    /* The first record, past blank and comment lines: a View3D title or
     * control line.  No OBJ or glTF begins so ("T"/"C" are not OBJ keywords). */
    size_t at = 0;
    while (at < size && text) {
        while (at < size && (text[at] == ' ' || text[at] == '\t' || text[at] == '\r'))
            at++;
        if (at < size && (text[at] == '!' || text[at] == '\n')) {
            while (at < size && text[at] != '\n')
                at++;
            at++;
            continue;
        }
        if (at + 1 < size && (text[at] == 'T' || text[at] == 'C' || text[at] == 't' || text[at] == 'c') &&
            (text[at + 1] == ' ' || text[at + 1] == '\t'))
            return true;
        return false;
    }
    return false;
}

rad_result rad_import_vs3_file(rad_context *ctx, const char *path, rad_scene **out)
{
    *out = NULL;
    unsigned char *text = NULL;
    size_t length = 0;
    rad_result res = rad_read_whole_file(ctx, path, &text, &length);
    if (res == RAD_OK)
        res = rad_import_vs3_memory(ctx, path, (const char *)text, length, out);
    rad_free(text);
    if (res == RAD_OK) {
        char **inputs = rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *inputs, path);
        char *copy = inputs ? rad_strdup(ctx, RAD_MEM_SCENE, path, path) : NULL;
        if (!copy) {
            rad_free(inputs);
            rad_scene_destroy(*out);
            *out = NULL;
            return RAD_ERROR_OUT_OF_MEMORY;
        }
        inputs[0] = copy;
        rad_scene_set_inputs(*out, inputs, 1);
    }
    return res;
}
