/*
 * mesh.c -- scene polygons -> patches -> structured grids of elements, with
 * vertices welded across patches of one surface and T-vertices recorded.
 *
 * Patches.  A planar convex quad stays a quad (bilinear parametrisation);
 * a triangle stays a triangle; a convex polygon of more vertices becomes a
 * fan of triangles about its centroid (no slivers, unlike a fan from a
 * vertex); a non-convex one is ear-clipped.
 *
 * Grids.  A quad patch with edges of length up to L_u (c0->c1 and c3->c2)
 * and L_v is cut into ceil(L_u/h) x ceil(L_v/h) cells at uniform parameter
 * steps; a triangle with longest edge L into k^2 cells, k = ceil(L/h).
 * Every element edge is then at most h long.  When only a target element
 * count is given, h is found by bisection on the exact count.
 *
 * Welding.  Grid points are merged when they lie within 1e-6 x the scene
 * diagonal of each other (less for slivers: weld_tolerance), belong to the
 * same surface, and their patches' normals differ by less than the crease
 * angle: shading is then smooth within a surface but keeps the physical
 * discontinuity at corners.
 */
#include "mesh/mesh.h"

#include <stdlib.h>
#include <string.h>

/* ---- patch parametrisation ---- */

vec3 rad_patch_point(const rad_patch *p, double s, double t)
{
    if (p->corner_count == 3)
        return v3_add(p->corner[0], v3_add(v3_scale(v3_sub(p->corner[1], p->corner[0]), s),
                                           v3_scale(v3_sub(p->corner[2], p->corner[0]), t)));
    vec3 a = v3_lerp(p->corner[0], p->corner[1], s);
    vec3 b = v3_lerp(p->corner[3], p->corner[2], s);
    return v3_lerp(a, b, t);
}

/* Coordinates of p in an orthonormal frame of the patch plane. */
static void plane_coords(const rad_patch *p, vec3 q, double *x, double *y)
{
    vec3 u = v3_normalize(v3_sub(p->corner[1], p->corner[0]));
    vec3 w = v3_cross(p->normal, u);
    vec3 d = v3_sub(q, p->corner[0]);
    *x = v3_dot(d, u);
    *y = v3_dot(d, w);
}

static double cross2(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

void rad_patch_parameters(const rad_patch *p, vec3 q, double *s, double *t)
{
    if (p->corner_count == 3) {
        /* Barycentrics by least squares in the plane (robust for any point). */
        vec3 e1 = v3_sub(p->corner[1], p->corner[0]), e2 = v3_sub(p->corner[2], p->corner[0]);
        vec3 d = v3_sub(q, p->corner[0]);
        double a11 = v3_dot(e1, e1), a12 = v3_dot(e1, e2), a22 = v3_dot(e2, e2);
        double b1 = v3_dot(d, e1), b2 = v3_dot(d, e2);
        double det = a11 * a22 - a12 * a12;
        *s = det != 0.0 ? (b1 * a22 - b2 * a12) / det : 0.0;
        *t = det != 0.0 ? (a11 * b2 - a12 * b1) / det : 0.0;
        return;
    }
    /* Inverse bilinear map of a planar convex quad: solve
     * q = c0 + s e + t g + s t h  in 2D for (s, t), a quadratic in t. */
    double px, py, bx, by, cx, cy, dx, dy;
    plane_coords(p, q, &px, &py);
    plane_coords(p, p->corner[1], &bx, &by);
    plane_coords(p, p->corner[2], &cx, &cy);
    plane_coords(p, p->corner[3], &dx, &dy);
    double ex = bx, ey = by;                       /* c1 - c0 */
    double gx = dx, gy = dy;                       /* c3 - c0 */
    double hx = cx - bx - dx, hy = cy - by - dy;   /* c0 - c1 + c2 - c3 */
    /* p = s e + t g + s t h; crossing with (e + t h) eliminates s:
     * cross(g,h) t^2 + (cross(g,e) + cross(h,p)) t + cross(e,p) = 0. */
    double k2 = cross2(gx, gy, hx, hy);
    double k1 = cross2(gx, gy, ex, ey) + cross2(hx, hy, px, py);
    double k0 = cross2(ex, ey, px, py);
    double tt;
    if (fabs(k2) <= 1e-12 * fabs(k1)) {
        tt = -k0 / k1;
    } else {
        double disc = k1 * k1 - 4.0 * k0 * k2;
        disc = disc > 0.0 ? sqrt(disc) : 0.0;
        double t1 = (-k1 - disc) / (2.0 * k2), t2 = (-k1 + disc) / (2.0 * k2);
        tt = fabs(t1 - 0.5) <= fabs(t2 - 0.5) ? t1 : t2; /* the root inside the quad */
    }
    double denx = ex + hx * tt, deny = ey + hy * tt;
    double ss = fabs(denx) > fabs(deny) ? (px - gx * tt) / denx : (py - gy * tt) / deny;
    *s = ss;
    *t = tt;
}

static uint32_t clamp_index(double x, uint32_t n)
{
    if (!(x > 0.0))
        return 0;
    if (x >= (double)n)
        return n - 1;
    return (uint32_t)x;
}

uint32_t rad_patch_locate(const rad_patch *p, double s, double t, double *ls, double *lt)
{
    if (p->corner_count == 4) {
        double x = s * p->nu, y = t * p->nv;
        uint32_t i = clamp_index(x, p->nu), j = clamp_index(y, p->nv);
        *ls = fmin(fmax(x - i, 0.0), 1.0);
        *lt = fmin(fmax(y - j, 0.0), 1.0);
        return p->first_element + j * p->nu + i;
    }
    uint32_t k = p->nu;
    double x = s * k, y = t * k;
    uint32_t row = clamp_index(y, k);
    double fy = fmin(fmax(y - row, 0.0), 1.0);
    uint32_t col = clamp_index(x, k - row);
    double fx = fmin(fmax(x - col, 0.0), 1.0);
    uint32_t row_start = row * (2 * k - row);
    if (fx + fy <= 1.0 || col + 1 >= k - row) {
        if (fx + fy > 1.0) { /* outside the last upward cell: project back */
            double excess = 0.5 * (fx + fy - 1.0);
            fx -= excess;
            fy -= excess;
        }
        *ls = fmax(fx, 0.0);
        *lt = fmax(fy, 0.0);
        return p->first_element + row_start + col;
    }
    /* Downward cell: v0 = (col+1, row), v1 = (col+1, row+1), v2 = (col, row+1),
     * so x = col + 1 - t and y = row + s + t. */
    *ls = fx + fy - 1.0;
    *lt = 1.0 - fx;
    return p->first_element + row_start + (k - row) + col;
}

uint32_t rad_mesh_locate(const rad_mesh *mesh, uint32_t patch, double s, double t, double *ls,
                         double *lt)
{
    const rad_patch *p = &mesh->patches[patch];
    if (!mesh->tree)
        return rad_patch_locate(p, s, t, ls, lt);
    /* Descend the quadtree with the point's coordinates relative to the
     * current node (hier/tree.c gives the children's layout). */
    double x = s, y = t;
    uint32_t entry = p->tree_root;
    for (int depth = 0; !(entry & RAD_TREE_LEAF) && depth < 64; depth++) {
        const uint32_t *child = &mesh->tree[4 * (size_t)entry];
        int c;
        if (p->corner_count == 4) {
            int i = x >= 0.5, j = y >= 0.5;
            c = j ? (i ? 2 : 3) : (i ? 1 : 0);
            x = 2.0 * x - i;
            y = 2.0 * y - j;
        } else if (x + y < 0.5) {
            c = 0, x = 2.0 * x, y = 2.0 * y;
        } else if (x >= 0.5) {
            c = 1, x = 2.0 * x - 1.0, y = 2.0 * y;
        } else if (y >= 0.5) {
            c = 2, x = 2.0 * x, y = 2.0 * y - 1.0;
        } else { /* the medial child (m01, m12, m20) */
            double lx = 2.0 * x + 2.0 * y - 1.0, ly = 1.0 - 2.0 * x;
            c = 3, x = lx, y = ly;
        }
        entry = child[c];
    }
    *ls = fmin(fmax(x, 0.0), 1.0);
    *lt = fmin(fmax(y, 0.0), 1.0);
    return entry & ~RAD_TREE_LEAF;
}

vec3 rad_element_sample(const rad_mesh *mesh, const rad_element *e, double u, double v)
{
    const vec3 *P = mesh->vertices;
    if (e->vertex_count == 3) {
        if (u + v > 1.0) {
            u = 1.0 - u;
            v = 1.0 - v;
        }
        vec3 a = P[e->vertex[0]];
        return v3_add(a, v3_add(v3_scale(v3_sub(P[e->vertex[1]], a), u),
                                v3_scale(v3_sub(P[e->vertex[2]], a), v)));
    }
    vec3 a = v3_lerp(P[e->vertex[0]], P[e->vertex[1]], u);
    vec3 b = v3_lerp(P[e->vertex[3]], P[e->vertex[2]], u);
    return v3_lerp(a, b, v);
}

/* ---- polygons -> patches ---- */

typedef struct patch_list {
    rad_patch *items;
    size_t count, capacity;
} patch_list;

static bool patch_push(patch_list *l, const rad_patch *p)
{
    if (l->count == l->capacity) {
        size_t cap = l->capacity ? 2 * l->capacity : 64;
        rad_patch *n = realloc(l->items, cap * sizeof *n);
        if (!n)
            return false;
        l->items = n;
        l->capacity = cap;
    }
    l->items[l->count++] = *p;
    return true;
}

static bool push_triangle(patch_list *l, const rad_polygon *poly, uint32_t index, vec3 a, vec3 b, vec3 c)
{
    rad_patch p = {0};
    p.polygon = index;
    p.surface = poly->surface;
    p.material = poly->material;
    p.corner_count = 3;
    p.corner[0] = a;
    p.corner[1] = b;
    p.corner[2] = c;
    vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
    if (!(v3_length(n) > 0.0))
        return true; /* a degenerate piece of a valid polygon: no area, no patch */
    p.normal = v3_normalize(n);
    return patch_push(l, &p);
}

static bool convex_about(const vec3 *v, size_t n, vec3 normal)
{
    for (size_t i = 0; i < n; i++) {
        vec3 e0 = v3_sub(v[(i + 1) % n], v[i]);
        vec3 e1 = v3_sub(v[(i + 2) % n], v[(i + 1) % n]);
        if (v3_dot(v3_cross(e0, e1), normal) <= 0.0)
            return false;
    }
    return true;
}

static rad_result make_patches(rad_context *ctx, const rad_scene *scene, patch_list *out)
{
    for (size_t pi = 0; pi < scene->polygon_count; pi++) {
        const rad_polygon *poly = &scene->polygons[pi];
        size_t n = poly->vertex_count;
        vec3 stack_v[16];
        vec3 *v = n <= 16 ? stack_v : malloc(n * sizeof *v);
        if (!v)
            return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "mesh: out of memory");
        for (size_t k = 0; k < n; k++)
            v[k] = scene->positions[scene->indices[poly->first_index + k]];
        bool ok = true;
        bool convex = convex_about(v, n, poly->normal);
        if (n == 3) {
            ok = push_triangle(out, poly, (uint32_t)pi, v[0], v[1], v[2]);
        } else if (n == 4 && convex) {
            rad_patch p = {0};
            p.polygon = (uint32_t)pi;
            p.surface = poly->surface;
            p.material = poly->material;
            p.corner_count = 4;
            memcpy(p.corner, v, 4 * sizeof *v);
            p.normal = poly->normal;
            ok = patch_push(out, &p);
        } else if (convex) {
            vec3 c = v3(0, 0, 0);
            for (size_t k = 0; k < n; k++)
                c = v3_add(c, v[k]);
            c = v3_scale(c, 1.0 / (double)n);
            for (size_t k = 0; k < n && ok; k++)
                ok = push_triangle(out, poly, (uint32_t)pi, c, v[k], v[(k + 1) % n]);
        } else {
            uint32_t *tri = malloc(3 * n * sizeof *tri);
            size_t nt = tri ? rad_triangulate_polygon(v, n, poly->normal, tri) : 0;
            if (!tri)
                ok = false;
            else if (nt == 0) {
                free(tri);
                if (v != stack_v)
                    free(v);
                return rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                                "%s: polygon %zu of surface '%s' cannot be triangulated "
                                "(self-intersecting?)",
                                scene->source, pi, scene->surfaces[poly->surface].name);
            }
            for (size_t k = 0; k < nt && ok; k++)
                ok = push_triangle(out, poly, (uint32_t)pi, v[tri[3 * k]], v[tri[3 * k + 1]],
                                   v[tri[3 * k + 2]]);
            free(tri);
        }
        if (v != stack_v)
            free(v);
        if (!ok)
            return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "mesh: out of memory");
    }
    return RAD_OK;
}

/* Merge consecutive triangle patches of one surface and material that share
 * an edge, are coplanar within 2 degrees and together form a convex quad:
 * exporters write quads as triangle pairs (the Cornell box's red wall), and
 * a quad grid shades without the diamond artefacts of Gouraud triangles. */
static void merge_triangle_pairs(patch_list *l)
{
    const double cos_max = cos(2.0 * M_PI / 180.0);
    size_t out = 0;
    for (size_t i = 0; i < l->count; i++) {
        rad_patch *p = &l->items[i];
        if (i + 1 < l->count && p->corner_count == 3 && l->items[i + 1].corner_count == 3) {
            const rad_patch *q = &l->items[i + 1];
            if (q->surface == p->surface && q->material == p->material &&
                v3_dot(p->normal, q->normal) >= cos_max) {
                /* Find q's vertex not shared with p; it must be exactly one. */
                int shared = 0, lone = -1;
                for (int k = 0; k < 3; k++) {
                    bool found = false;
                    for (int m = 0; m < 3; m++)
                        found |= v3_length(v3_sub(q->corner[k], p->corner[m])) <= 1e-12 * (1.0 + v3_length(p->corner[m]));
                    if (found)
                        shared++;
                    else
                        lone = k;
                }
                if (shared == 2 && lone >= 0) {
                    /* Rotate p so the shared edge runs p2 -> p0; the quad is p0 p1 p2 d. */
                    vec3 d = q->corner[lone];
                    vec3 c[3] = {p->corner[0], p->corner[1], p->corner[2]};
                    for (int r = 0; r < 3; r++) {
                        vec3 q0 = q->corner[(lone + 1) % 3], q1 = q->corner[(lone + 2) % 3];
                        /* q's shared edge runs q0 -> q1 in q's order, i.e. c0 -> c2 reversed */
                        if (v3_length(v3_sub(q0, c[0])) < 1e-12 * (1.0 + v3_length(c[0])) &&
                            v3_length(v3_sub(q1, c[2])) < 1e-12 * (1.0 + v3_length(c[2])))
                            break;
                        vec3 t = c[0];
                        c[0] = c[1];
                        c[1] = c[2];
                        c[2] = t;
                    }
                    vec3 quad[4] = {c[0], c[1], c[2], d};
                    vec3 n = v3_normalize(v3_add(v3_cross(v3_sub(c[1], c[0]), v3_sub(c[2], c[0])),
                                                 v3_cross(v3_sub(c[2], c[0]), v3_sub(d, c[0]))));
                    if (v3_length(v3_sub(q->corner[(lone + 1) % 3], c[0])) < 1e-12 * (1.0 + v3_length(c[0])) &&
                        convex_about(quad, 4, n)) {
                        rad_patch merged = *p;
                        merged.corner_count = 4;
                        memcpy(merged.corner, quad, sizeof quad);
                        merged.normal = n;
                        l->items[out++] = merged;
                        i++;
                        continue;
                    }
                }
            }
        }
        l->items[out++] = *p;
    }
    l->count = out;
}

/* ---- grid sizes ---- */

static uint32_t cells_for(double length, double h)
{
    double c = ceil(length / h - 1e-9);
    if (c < 1.0)
        c = 1.0;
    if (c > 65535.0)
        c = 65535.0;
    return (uint32_t)c;
}

static void size_patch(rad_patch *p, double h)
{
    if (p->corner_count == 4) {
        double lu = fmax(v3_length(v3_sub(p->corner[1], p->corner[0])),
                         v3_length(v3_sub(p->corner[2], p->corner[3])));
        double lv = fmax(v3_length(v3_sub(p->corner[3], p->corner[0])),
                         v3_length(v3_sub(p->corner[2], p->corner[1])));
        p->nu = cells_for(lu, h);
        p->nv = cells_for(lv, h);
        p->element_count = p->nu * p->nv;
    } else {
        double l = fmax(v3_length(v3_sub(p->corner[1], p->corner[0])),
                        fmax(v3_length(v3_sub(p->corner[2], p->corner[1])),
                             v3_length(v3_sub(p->corner[0], p->corner[2]))));
        p->nu = p->nv = cells_for(l, h);
        p->element_count = p->nu * p->nu;
    }
}

static double count_elements(rad_patch *patches, size_t count, double h)
{
    double total = 0.0;
    for (size_t i = 0; i < count; i++) {
        size_patch(&patches[i], h);
        total += (double)patches[i].element_count;
    }
    return total;
}

/* The element edge length h giving about `target` elements: the count
 * falls monotonically with h, so bisect on log h. */
static double size_for_target(rad_patch *patches, size_t count, double total_area, double target)
{
    double lo = sqrt(total_area / target) * 0.05, hi = sqrt(total_area / target) * 20.0;
    /* Long thin patches need h up to their length: one element each (the
     * fewest there can be) is reached at the longest patch edge. */
    for (size_t i = 0; i < count; i++)
        for (uint32_t k = 0; k < patches[i].corner_count; k++)
            hi = fmax(hi, 1.01 * v3_length(v3_sub(patches[i].corner[(k + 1) % patches[i].corner_count],
                                                  patches[i].corner[k])));
    for (int it = 0; it < 60; it++) {
        double mid = sqrt(lo * hi);
        if (count_elements(patches, count, mid) > target)
            lo = mid;
        else
            hi = mid;
    }
    /* Of the two brackets, take the count closer to the target. */
    double nlo = count_elements(patches, count, lo), nhi = count_elements(patches, count, hi);
    return fabs(nlo - target) < fabs(nhi - target) ? lo : hi;
}

/* ---- spatial hashing by sorting: (cell key, item) pairs ---- */

typedef struct cell_entry {
    uint64_t key;
    uint32_t item;
} cell_entry;

static uint64_t cell_key(int64_t x, int64_t y, int64_t z)
{
    return rad_mix64((uint64_t)x * 0x9e3779b97f4a7c15ULL ^ rad_mix64((uint64_t)y) ^
                     rad_mix64((uint64_t)z * 0xc2b2ae3d27d4eb4fULL));
}

/* The grid cell of coordinate x for cells 1/inv wide.  Clamped to +-2^62
 * so that a coordinate far from the cell size (a tiny weld tolerance in a
 * scene far from the origin) never overflows the conversion. */
static int64_t cell_of(double x, double inv)
{
    double c = floor(x * inv);
    if (!(c > -4.6e18))
        return c < 0.0 ? -(INT64_C(1) << 62) : 0; /* -inf, or NaN */
    return c < 4.6e18 ? (int64_t)c : (INT64_C(1) << 62);
}

static int cell_entry_cmp(const void *a, const void *b)
{
    const cell_entry *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->item < y->item ? -1 : (x->item > y->item);
}

/* A hash index over sorted entries: key -> first entry with that key, in
 * O(1) instead of a binary search (10^6 boundary vertices and 27 cells per
 * query made the searches the leaf mesh's bottleneck). */
typedef struct cell_index {
    uint64_t *key;
    uint32_t *first;      /* UINT32_MAX: empty slot */
    size_t mask;
} cell_index;

static bool cell_index_build(const cell_entry *e, size_t n, cell_index *ix)
{
    size_t size = 64;
    while (size < 2 * n)
        size *= 2;
    ix->key = malloc(size * sizeof *ix->key);
    ix->first = malloc(size * sizeof *ix->first);
    ix->mask = size - 1;
    if (!ix->key || !ix->first) {
        free(ix->key);
        free(ix->first);
        return false;
    }
    memset(ix->first, 0xff, size * sizeof *ix->first);
    for (size_t i = 0; i < n; i++) {
        if (i > 0 && e[i].key == e[i - 1].key)
            continue;
        size_t h = rad_mix64(e[i].key) & ix->mask;
        while (ix->first[h] != UINT32_MAX)
            h = (h + 1) & ix->mask;
        ix->key[h] = e[i].key;
        ix->first[h] = (uint32_t)i;
    }
    return true;
}

/* First index of `key` in the sorted entries, or n when absent. */
static size_t cell_index_find(const cell_index *ix, size_t n, uint64_t key)
{
    for (size_t h = rad_mix64(key) & ix->mask; ix->first[h] != UINT32_MAX; h = (h + 1) & ix->mask)
        if (ix->key[h] == key)
            return ix->first[h];
    return n;
}

static void cell_index_free(cell_index *ix)
{
    free(ix->key);
    free(ix->first);
}

/* ---- building ---- */

typedef struct raw_vertex {
    vec3 position;
    uint32_t patch;
} raw_vertex;

/* Raw (unwelded) grid-point index of the patch's local grid point. */
static uint32_t quad_point(const rad_patch *p, uint32_t base, uint32_t i, uint32_t j)
{
    return base + j * (p->nu + 1) + i;
}

static uint32_t tri_point(uint32_t k, uint32_t base, uint32_t a, uint32_t b)
{
    /* rows b = 0..k hold k+1-b points */
    return base + b * (k + 1) - b * (b - 1) / 2 + a;
}

static uint32_t patch_point_count(const rad_patch *p)
{
    return p->corner_count == 4 ? (p->nu + 1) * (p->nv + 1) : (p->nu + 1) * (p->nu + 2) / 2;
}

static void element_geometry(rad_element *e, const vec3 *P)
{
    vec3 a = P[e->vertex[0]], b = P[e->vertex[1]], c = P[e->vertex[2]];
    if (e->vertex_count == 3) {
        vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
        e->area = 0.5 * v3_length(n);
        e->normal = v3_normalize(n);
        e->centroid = v3_scale(v3_add(a, v3_add(b, c)), 1.0 / 3.0);
        return;
    }
    vec3 d = P[e->vertex[3]];
    vec3 n1 = v3_cross(v3_sub(b, a), v3_sub(c, a)), n2 = v3_cross(v3_sub(c, a), v3_sub(d, a));
    double a1 = 0.5 * v3_length(n1), a2 = 0.5 * v3_length(n2);
    e->area = a1 + a2;
    e->normal = v3_normalize(v3_add(n1, n2));
    vec3 c1 = v3_scale(v3_add(a, v3_add(b, c)), 1.0 / 3.0);
    vec3 c2 = v3_scale(v3_add(a, v3_add(c, d)), 1.0 / 3.0);
    e->centroid = e->area > 0.0 ? v3_scale(v3_add(v3_scale(c1, a1), v3_scale(c2, a2)), 1.0 / e->area)
                                : c1;
}

/* The distance within which grid points are one vertex: 1e-6 x the scene
 * diagonal (far above the round-off of grid points computed from
 * different patches), but below 1e-3 x the narrowest element, so that the
 * corners of a sliver's elements (a 1 km x 1 um strip) never merge into
 * zero-area elements.  The narrowest element is estimated per patch as
 * its width (2 x area / longest edge) or its shortest edge, whichever is
 * less, over its cells along the longest side. */
static double weld_tolerance(const rad_mesh *mesh, double diag)
{
    double narrowest = HUGE_VAL;
    for (size_t i = 0; i < mesh->patch_count; i++) {
        const rad_patch *p = &mesh->patches[i];
        vec3 n = p->corner_count == 4
                     ? v3_cross(v3_sub(p->corner[2], p->corner[0]), v3_sub(p->corner[3], p->corner[1]))
                     : v3_cross(v3_sub(p->corner[1], p->corner[0]), v3_sub(p->corner[2], p->corner[0]));
        double area = 0.5 * v3_length(n), longest = 0.0, shortest = HUGE_VAL;
        for (uint32_t k = 0; k < p->corner_count; k++) {
            double edge = v3_length(v3_sub(p->corner[(k + 1) % p->corner_count], p->corner[k]));
            longest = fmax(longest, edge);
            shortest = fmin(shortest, edge);
        }
        uint32_t cells = p->nu > p->nv ? p->nu : p->nv;
        if (longest > 0.0)
            narrowest = fmin(narrowest, fmin(shortest, 2.0 * area / longest) / (double)cells);
    }
    double tol = 1e-6 * diag;
    if (narrowest > 0.0 && 1e-3 * narrowest < tol)
        tol = 1e-3 * narrowest;
    return tol;
}

/* Weld raw grid points; fills weld[raw] = welded index and the positions. */
static rad_result weld(rad_context *ctx, const rad_mesh *mesh, const raw_vertex *raw, size_t nraw,
                       double tol, double cos_crease, uint32_t *weld_of, vec3 **positions,
                       size_t *count)
{
    cell_entry *cells = rad_alloc_array(ctx, nraw ? nraw : 1, sizeof *cells, "mesh: weld table");
    vec3 *pos = rad_alloc_array(ctx, nraw ? nraw : 1, sizeof *pos, "mesh: vertices");
    if (!cells || !pos) {
        free(cells);
        free(pos);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    double inv = 1.0 / tol;
    for (size_t r = 0; r < nraw; r++) {
        vec3 p = raw[r].position;
        cells[r].key = cell_key(cell_of(p.x, inv), cell_of(p.y, inv), cell_of(p.z, inv));
        cells[r].item = (uint32_t)r;
    }
    qsort(cells, nraw, sizeof *cells, cell_entry_cmp);
    cell_index cix;
    if (!cell_index_build(cells, nraw, &cix)) {
        free(cells);
        free(pos);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "mesh: out of memory for the weld index");
    }
    size_t nw = 0;
    for (size_t r = 0; r < nraw; r++) {
        vec3 p = raw[r].position;
        const rad_patch *pr = &mesh->patches[raw[r].patch];
        int64_t cx = cell_of(p.x, inv), cy = cell_of(p.y, inv), cz = cell_of(p.z, inv);
        uint32_t best = UINT32_MAX;
        for (int dz = -1; dz <= 1; dz++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    uint64_t key = cell_key(cx + dx, cy + dy, cz + dz);
                    for (size_t k = cell_index_find(&cix, nraw, key); k < nraw && cells[k].key == key; k++) {
                        uint32_t c = cells[k].item;
                        if (c >= r || c >= best)
                            continue;
                        const rad_patch *pc = &mesh->patches[raw[c].patch];
                        if (pc->surface != pr->surface || v3_dot(pc->normal, pr->normal) < cos_crease)
                            continue;
                        if (v3_length(v3_sub(raw[c].position, p)) <= tol)
                            best = c;
                    }
                }
        if (best != UINT32_MAX) {
            weld_of[r] = weld_of[best];
        } else {
            weld_of[r] = (uint32_t)nw;
            pos[nw++] = p;
        }
    }
    free(cells);
    cell_index_free(&cix);
    *positions = pos;
    *count = nw;
    return RAD_OK;
}

/* Find welded vertices lying inside boundary edges of elements of the same
 * surface (T-vertices).  Only vertices on boundary edges can be T-vertices,
 * so both sets are small; they are matched through a grid of cell size h. */
static rad_result find_tvertices(rad_context *ctx, rad_mesh *mesh, double tol, double h)
{
    typedef struct edge_rec {
        uint32_t a, b, element;
    } edge_rec;
    size_t ne = 0;
    for (size_t i = 0; i < mesh->element_count; i++)
        ne += mesh->elements[i].vertex_count;
    edge_rec *edges = rad_alloc_array(ctx, ne ? ne : 1, sizeof *edges, "mesh: edges");
    if (!edges)
        return RAD_ERROR_OUT_OF_MEMORY;
    size_t k = 0;
    for (size_t i = 0; i < mesh->element_count; i++) {
        const rad_element *e = &mesh->elements[i];
        for (uint32_t c = 0; c < e->vertex_count; c++) {
            uint32_t a = e->vertex[c], b = e->vertex[(c + 1) % e->vertex_count];
            edges[k].a = a < b ? a : b;
            edges[k].b = a < b ? b : a;
            edges[k].element = (uint32_t)i;
            k++;
        }
    }
    /* Sort edges by (a, b) to find those used once (boundary edges). */
    cell_entry *order = rad_alloc_array(ctx, ne ? ne : 1, sizeof *order, "mesh: edges");
    if (!order) {
        free(edges);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < ne; i++) {
        order[i].key = ((uint64_t)edges[i].a << 32) | edges[i].b;
        order[i].item = (uint32_t)i;
    }
    qsort(order, ne, sizeof *order, cell_entry_cmp);
    size_t nb = 0;
    uint8_t *on_boundary = rad_alloc_array(ctx, mesh->vertex_count ? mesh->vertex_count : 1, 1,
                                           "mesh: boundary flags");
    if (!on_boundary) {
        free(edges);
        free(order);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < ne;) {
        size_t j = i;
        while (j < ne && order[j].key == order[i].key)
            j++;
        if (j - i == 1) {
            order[nb++] = order[i]; /* compact: boundary edges first */
            on_boundary[edges[order[i].item].a] = on_boundary[edges[order[i].item].b] = 1;
        }
        i = j;
    }
    /* Vertex -> a surface and normal, from any element that uses it. */
    uint32_t *vsurf = rad_alloc_array(ctx, mesh->vertex_count ? mesh->vertex_count : 1,
                                      sizeof *vsurf, "mesh: vertex surfaces");
    size_t nbv = 0;
    for (size_t v = 0; v < mesh->vertex_count; v++)
        nbv += on_boundary[v];
    cell_entry *grid = rad_alloc_array(ctx, nbv ? nbv : 1, sizeof *grid, "mesh: vertex grid");
    if (!vsurf || !grid) {
        free(edges);
        free(order);
        free(on_boundary);
        free(vsurf);
        free(grid);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < mesh->element_count; i++)
        for (uint32_t c = 0; c < mesh->elements[i].vertex_count; c++)
            vsurf[mesh->elements[i].vertex[c]] = mesh->elements[i].surface;
    /* Cells as wide as the longest boundary edge, so that an edge spans at
     * most 2 cells a side: that is h, except where a patch reached the cap
     * on cells per side (cells_for) and its elements are longer. */
    double cell = h;
    for (size_t bi = 0; bi < nb; bi++) {
        const edge_rec *ed = &edges[order[bi].item];
        cell = fmax(cell, v3_length(v3_sub(mesh->vertices[ed->b], mesh->vertices[ed->a])));
    }
    double inv = 1.0 / cell;
    size_t g = 0;
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        if (!on_boundary[v])
            continue;
        vec3 p = mesh->vertices[v];
        grid[g].key = cell_key(cell_of(p.x, inv), cell_of(p.y, inv), cell_of(p.z, inv));
        grid[g].item = (uint32_t)v;
        g++;
    }
    qsort(grid, g, sizeof *grid, cell_entry_cmp);
    cell_index gix;
    if (!cell_index_build(grid, g, &gix)) {
        free(edges);
        free(order);
        free(on_boundary);
        free(vsurf);
        free(grid);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "mesh: out of memory for the T-vertex index");
    }

    size_t cap = 0;
    rad_result result = RAD_OK;
    for (size_t bi = 0; bi < nb && result == RAD_OK; bi++) {
        const edge_rec *ed = &edges[order[bi].item];
        const rad_element *el = &mesh->elements[ed->element];
        vec3 a = mesh->vertices[ed->a], b = mesh->vertices[ed->b];
        vec3 ab = v3_sub(b, a);
        double len2 = v3_dot(ab, ab);
        if (!(len2 > 0.0))
            continue;
        vec3 lo = v3_min(a, b), hi = v3_max(a, b);
        int64_t x0 = cell_of(lo.x - tol, inv), x1 = cell_of(hi.x + tol, inv);
        int64_t y0 = cell_of(lo.y - tol, inv), y1 = cell_of(hi.y + tol, inv);
        int64_t z0 = cell_of(lo.z - tol, inv), z1 = cell_of(hi.z + tol, inv);
        for (int64_t z = z0; z <= z1; z++)
            for (int64_t y = y0; y <= y1; y++)
                for (int64_t x = x0; x <= x1; x++) {
                    uint64_t key = cell_key(x, y, z);
                    for (size_t q = cell_index_find(&gix, g, key); q < g && grid[q].key == key; q++) {
                        uint32_t v = grid[q].item;
                        if (v == ed->a || v == ed->b || vsurf[v] != el->surface)
                            continue;
                        vec3 d = v3_sub(mesh->vertices[v], a);
                        double t = v3_dot(d, ab) / len2;
                        if (t <= 1e-9 || t >= 1.0 - 1e-9)
                            continue;
                        if (v3_length(v3_sub(d, v3_scale(ab, t))) > tol)
                            continue;
                        if (mesh->tvertex_count == cap) {
                            size_t nc = cap ? 2 * cap : 64;
                            rad_tvertex *nt = realloc(mesh->tvertices, nc * sizeof *nt);
                            if (!nt) {
                                result = rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "mesh: out of memory");
                                break;
                            }
                            mesh->tvertices = nt;
                            cap = nc;
                        }
                        rad_tvertex tv = {v, ed->a, ed->b, t};
                        mesh->tvertices[mesh->tvertex_count++] = tv;
                    }
                }
    }
    free(edges);
    free(order);
    free(on_boundary);
    free(vsurf);
    free(grid);
    cell_index_free(&gix);
    return result;
}

rad_result rad_mesh_build(rad_context *ctx, const rad_scene *scene, const rad_mesh_options *opt,
                          rad_mesh **out)
{
    return rad_mesh_build_within(ctx, scene, opt, 0.0, out);
}

rad_result rad_mesh_build_within(rad_context *ctx, const rad_scene *scene,
                                 const rad_mesh_options *opt, double max_memory_bytes,
                                 rad_mesh **out)
{
    *out = NULL;
    rad_mesh_options o = opt ? *opt : (rad_mesh_options){0};
    if (!(o.mesh_size >= 0.0) || !isfinite(o.mesh_size))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "rad_options.mesh_size must be a positive length in metres");
    if (o.target_elements == 0)
        o.target_elements = 2000;
    if (o.crease_angle_degrees == 0.0)
        o.crease_angle_degrees = 30.0;
    if (!(o.crease_angle_degrees > 0.0 && o.crease_angle_degrees <= 180.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "crease angle must be in (0, 180] degrees");

    rad_mesh *mesh = calloc(1, sizeof *mesh);
    if (!mesh)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "mesh: out of memory");
    patch_list pl = {0};
    rad_result r = make_patches(ctx, scene, &pl);
    if (r != RAD_OK) {
        free(pl.items);
        free(mesh);
        return r;
    }
    merge_triangle_pairs(&pl);
    mesh->patches = pl.items;
    mesh->patch_count = pl.count;

    double total_area = 0.0;
    for (size_t i = 0; i < scene->polygon_count; i++)
        total_area += scene->polygons[i].area;
    double h = o.mesh_size > 0.0 ? o.mesh_size
                                 : size_for_target(mesh->patches, mesh->patch_count, total_area,
                                                   (double)o.target_elements);
    double nelem = count_elements(mesh->patches, mesh->patch_count, h);
    if (nelem > (double)UINT32_MAX / 4) {
        rad_mesh_destroy(mesh);
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "mesh: %.3g elements exceed the limit of %u; use a larger rad_options.mesh_size",
                        nelem, UINT32_MAX / 4);
    }
    mesh->mesh_size = h;

    /* Elements and raw grid points, patch by patch.  The estimate counts
     * the elements, the raw grid points with their weld tables, and the
     * edge tables of the T-vertex search (4 edges of 2 x 16 bytes per
     * element), which all exist at once. */
    size_t nraw = 0;
    for (size_t i = 0; i < mesh->patch_count; i++)
        nraw += patch_point_count(&mesh->patches[i]);
    double bytes = nelem * ((double)sizeof(rad_element) + 4.0 * 32.0) +
                   (double)nraw * (double)(sizeof(raw_vertex) + sizeof(uint32_t) +
                                           sizeof(cell_entry) + sizeof(vec3));
    if (max_memory_bytes > 0.0 && bytes > max_memory_bytes) {
        rad_mesh_destroy(mesh);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                        "mesh: %.0f elements need about %.2f GiB, above the memory limit of "
                        "%.2f GiB (rad_options.max_memory_bytes); use a larger rad_options.mesh_size or fewer "
                        "rad_options.target_elements",
                        nelem, bytes / 1073741824.0, max_memory_bytes / 1073741824.0);
    }
    mesh->element_count = (size_t)nelem;
    mesh->elements = rad_alloc_array(ctx, mesh->element_count, sizeof *mesh->elements, "mesh: elements");
    raw_vertex *raw = rad_alloc_array(ctx, nraw, sizeof *raw, "mesh: grid points");
    uint32_t *weld_of = rad_alloc_array(ctx, nraw, sizeof *weld_of, "mesh: grid points");
    if (!mesh->elements || !raw || !weld_of) {
        free(raw);
        free(weld_of);
        rad_mesh_destroy(mesh);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    uint32_t base = 0, first = 0;
    for (size_t pi = 0; pi < mesh->patch_count; pi++) {
        rad_patch *p = &mesh->patches[pi];
        p->first_element = first;
        if (p->corner_count == 4) {
            for (uint32_t j = 0; j <= p->nv; j++)
                for (uint32_t i = 0; i <= p->nu; i++) {
                    raw_vertex *rv = &raw[quad_point(p, base, i, j)];
                    rv->position = rad_patch_point(p, (double)i / p->nu, (double)j / p->nv);
                    rv->patch = (uint32_t)pi;
                }
            for (uint32_t j = 0; j < p->nv; j++)
                for (uint32_t i = 0; i < p->nu; i++) {
                    rad_element *e = &mesh->elements[first + j * p->nu + i];
                    e->vertex_count = 4;
                    e->vertex[0] = quad_point(p, base, i, j);
                    e->vertex[1] = quad_point(p, base, i + 1, j);
                    e->vertex[2] = quad_point(p, base, i + 1, j + 1);
                    e->vertex[3] = quad_point(p, base, i, j + 1);
                }
        } else {
            uint32_t kk = p->nu;
            for (uint32_t b = 0; b <= kk; b++)
                for (uint32_t a = 0; a + b <= kk; a++) {
                    raw_vertex *rv = &raw[tri_point(kk, base, a, b)];
                    rv->position = rad_patch_point(p, (double)a / kk, (double)b / kk);
                    rv->patch = (uint32_t)pi;
                }
            for (uint32_t b = 0; b < kk; b++) {
                uint32_t row = first + b * (2 * kk - b);
                for (uint32_t a = 0; a + b < kk; a++) {
                    rad_element *e = &mesh->elements[row + a];
                    e->vertex_count = 3;
                    e->vertex[0] = tri_point(kk, base, a, b);
                    e->vertex[1] = tri_point(kk, base, a + 1, b);
                    e->vertex[2] = tri_point(kk, base, a, b + 1);
                }
                for (uint32_t a = 0; a + b + 1 < kk; a++) {
                    rad_element *e = &mesh->elements[row + (kk - b) + a];
                    e->vertex_count = 3;
                    e->vertex[0] = tri_point(kk, base, a + 1, b);
                    e->vertex[1] = tri_point(kk, base, a + 1, b + 1);
                    e->vertex[2] = tri_point(kk, base, a, b + 1);
                }
            }
        }
        for (uint32_t k = 0; k < p->element_count; k++) {
            rad_element *e = &mesh->elements[first + k];
            e->patch = (uint32_t)pi;
            e->surface = p->surface;
            e->material = p->material;
        }
        base += patch_point_count(p);
        first += p->element_count;
    }

    double diag = rad_scene_diagonal(scene);
    double tol = weld_tolerance(mesh, diag > 0.0 ? diag : 1.0);
    r = weld(ctx, mesh, raw, nraw, tol, cos(o.crease_angle_degrees * M_PI / 180.0), weld_of,
             &mesh->vertices, &mesh->vertex_count);
    if (r == RAD_OK) {
        for (size_t i = 0; i < mesh->element_count; i++) {
            rad_element *e = &mesh->elements[i];
            for (uint32_t c = 0; c < e->vertex_count; c++)
                e->vertex[c] = weld_of[e->vertex[c]];
            element_geometry(e, mesh->vertices);
        }
        /* The search grid: the edge length, or the typical element size
         * where that is smaller (a hierarchical base mesh asks for one
         * element per patch with an infinite edge length; one cell would
         * make the search quadratic). */
        double typical = mesh->element_count ? sqrt(total_area / (double)mesh->element_count) : h;
        double hg = fmax(fmin(h, typical), 10.0 * tol);
        r = find_tvertices(ctx, mesh, tol, hg);
    }
    free(raw);
    free(weld_of);
    if (r != RAD_OK) {
        rad_mesh_destroy(mesh);
        return r;
    }
    *out = mesh;
    return RAD_OK;
}

rad_result rad_mesh_from_leaves(rad_context *ctx, const rad_scene *scene, const rad_mesh *base,
                                const rad_mesh_leaf *leaves, size_t leaf_count, const uint32_t *tree,
                                size_t tree_count, const uint32_t *patch_root, double crease,
                                rad_mesh **out)
{
    *out = NULL;
    if (crease == 0.0)
        crease = 30.0;
    if (leaf_count >= RAD_TREE_LEAF || tree_count >= RAD_TREE_LEAF)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "mesh: %zu leaves exceed the limit of %u",
                        leaf_count, RAD_TREE_LEAF - 1);
    rad_mesh *mesh = calloc(1, sizeof *mesh);
    if (!mesh)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "mesh: out of memory");
    size_t nraw = 0;
    for (size_t i = 0; i < leaf_count; i++)
        nraw += leaves[i].corner_count;
    mesh->patch_count = base->patch_count;
    mesh->patches = rad_alloc_array(ctx, base->patch_count, sizeof *mesh->patches, "mesh: patches");
    mesh->elements = rad_alloc_array(ctx, leaf_count ? leaf_count : 1, sizeof *mesh->elements,
                                     "mesh: elements");
    mesh->tree = rad_alloc_array(ctx, 4 * tree_count + 1, sizeof *mesh->tree, "mesh: quadtree");
    raw_vertex *raw = rad_alloc_array(ctx, nraw ? nraw : 1, sizeof *raw, "mesh: leaf corners");
    uint32_t *weld_of = rad_alloc_array(ctx, nraw ? nraw : 1, sizeof *weld_of, "mesh: leaf corners");
    if (!mesh->patches || !mesh->elements || !mesh->tree || !raw || !weld_of) {
        free(raw);
        free(weld_of);
        rad_mesh_destroy(mesh);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memcpy(mesh->patches, base->patches, base->patch_count * sizeof *mesh->patches);
    memcpy(mesh->tree, tree, 4 * tree_count * sizeof *mesh->tree);
    mesh->tree_count = tree_count;
    mesh->element_count = leaf_count;
    for (size_t p = 0; p < mesh->patch_count; p++) {
        mesh->patches[p].tree_root = patch_root[p];
        mesh->patches[p].element_count = 0;
        mesh->patches[p].first_element = 0;
    }
    size_t k = 0;
    double area = 0.0;
    for (size_t i = 0; i < leaf_count; i++) {
        const rad_mesh_leaf *l = &leaves[i];
        rad_patch *p = &mesh->patches[l->patch];
        if (p->element_count++ == 0)
            p->first_element = (uint32_t)i;
        rad_element *e = &mesh->elements[i];
        e->patch = l->patch;
        e->surface = p->surface;
        e->material = p->material;
        e->vertex_count = l->corner_count;
        for (uint32_t c = 0; c < l->corner_count; c++) {
            raw[k].position = l->corner[c];
            raw[k].patch = l->patch;
            e->vertex[c] = (uint32_t)k++;
        }
    }
    double diag = rad_scene_diagonal(scene);
    double tol = 1e-6 * (diag > 0.0 ? diag : 1.0);
    rad_result r = weld(ctx, mesh, raw, nraw, tol, cos(crease * M_PI / 180.0), weld_of, &mesh->vertices,
                        &mesh->vertex_count);
    if (r == RAD_OK) {
        for (size_t i = 0; i < leaf_count; i++) {
            rad_element *e = &mesh->elements[i];
            for (uint32_t c = 0; c < e->vertex_count; c++)
                e->vertex[c] = weld_of[e->vertex[c]];
            element_geometry(e, mesh->vertices);
            area += e->area;
        }
        /* The T-vertex search grid: about the typical leaf size. */
        double h = leaf_count ? sqrt(area / (double)leaf_count) : 1.0;
        mesh->mesh_size = h;
        r = find_tvertices(ctx, mesh, tol, h > tol ? h : tol);
    }
    free(raw);
    free(weld_of);
    if (r != RAD_OK) {
        rad_mesh_destroy(mesh);
        return r;
    }
    *out = mesh;
    return RAD_OK;
}

void rad_mesh_destroy(rad_mesh *mesh)
{
    if (!mesh)
        return;
    free(mesh->patches);
    free(mesh->elements);
    free(mesh->vertices);
    free(mesh->tvertices);
    free(mesh->tree);
    free(mesh);
}
