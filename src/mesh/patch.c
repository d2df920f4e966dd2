/*
 * patch.c -- scene polygons -> patches, and the patches' parametrisation.
 *
 * A planar convex quad stays a quad (bilinear parametrisation); a triangle
 * stays a triangle; a convex polygon of more vertices becomes a fan of
 * triangles about its centroid (no slivers, unlike a fan from a vertex); a
 * non-convex one is ear-clipped (scene/triangulate.c).  Consecutive
 * triangles that together form a planar convex quad are merged back into
 * one quad patch.
 *
 *    quad: P(s, t) = lerp(lerp(c0, c1, s), lerp(c3, c2, s), t)
 *    triangle: P(s, t) = c0 + s (c1 - c0) + t (c2 - c0)
 */
#include "mesh/mesh_internal.h"

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

/* ---- polygons -> patches ---- */

typedef struct patch_list {
    rad_context *ctx;
    rad_patch *items;
    size_t count, capacity;
} patch_list;

static bool patch_push(patch_list *l, const rad_patch *p)
{
    if (l->count == l->capacity) {
        size_t cap = l->capacity ? 2 * l->capacity : 64;
        rad_patch *n = rad_realloc(l->ctx, RAD_MEM_MESH, l->items, cap, sizeof *n, "mesh: patches");
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

/* Working space for one polygon of n vertices: its corners, its triangles
 * and the triangulation's scratch, grown as polygons need. */
typedef struct polygon_scratch {
    unsigned char *bytes;
    size_t capacity;
} polygon_scratch;

static bool polygon_scratch_fit(rad_context *ctx, polygon_scratch *s, size_t n, vec3 **v, uint32_t **tri,
                                void **work)
{
    /* vec3 and the triangulation's doubles first: every part stays 8-byte aligned. */
    size_t need = n * sizeof **v + RAD_TRIANGULATE_SCRATCH(n) + 3 * n * sizeof **tri;
    if (need > s->capacity) {
        rad_free(s->bytes);
        s->capacity = 0;
        s->bytes = rad_alloc(ctx, RAD_MEM_MESH, need, 1, "mesh: polygon corners");
        if (!s->bytes)
            return false;
        s->capacity = need;
    }
    *v = (vec3 *)(void *)s->bytes;
    *work = s->bytes + n * sizeof **v;
    *tri = (uint32_t *)(void *)(s->bytes + n * sizeof **v + RAD_TRIANGULATE_SCRATCH(n));
    return true;
}

static rad_result make_patches(rad_context *ctx, const rad_scene *scene, patch_list *out)
{
    polygon_scratch scratch = {NULL, 0};
    rad_result r = RAD_OK;
    for (size_t pi = 0; pi < scene->polygon_count && r == RAD_OK; pi++) {
        const rad_polygon *poly = &scene->polygons[pi];
        size_t n = poly->vertex_count;
        vec3 *v;
        uint32_t *tri;
        void *work;
        if (!polygon_scratch_fit(ctx, &scratch, n, &v, &tri, &work)) {
            r = RAD_ERROR_OUT_OF_MEMORY;
            break;
        }
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
            size_t nt = rad_triangulate_polygon(ctx, v, n, poly->normal, work, tri);
            if (nt == RAD_TRIANGULATE_INTERRUPTED) {
                r = rad_fail(ctx, RAD_ERROR_INTERRUPTED,
                             "%s: interrupted while triangulating polygon %zu of surface '%s'",
                             scene->source, pi, scene->surfaces[poly->surface].name);
                break;
            }
            if (nt == 0) {
                r = rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                             "%s: polygon %zu of surface '%s' cannot be triangulated "
                             "(self-intersecting?)",
                             scene->source, pi, scene->surfaces[poly->surface].name);
                break;
            }
            for (size_t k = 0; k < nt && ok; k++)
                ok = push_triangle(out, poly, (uint32_t)pi, v[tri[3 * k]], v[tri[3 * k + 1]],
                                   v[tri[3 * k + 2]]);
        }
        if (!ok)
            r = RAD_ERROR_OUT_OF_MEMORY; /* the allocator named what */
    }
    rad_free(scratch.bytes);
    return r;
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

rad_result mesh_patches_from_polygons(rad_context *ctx, const rad_scene *scene, rad_mesh *mesh)
{
    patch_list pl = {ctx, NULL, 0, 0};
    rad_result r = make_patches(ctx, scene, &pl);
    if (r != RAD_OK) {
        rad_free(pl.items);
        return r;
    }
    merge_triangle_pairs(&pl);
    /* Contact lines: the weld rule's distance (1e-6 of the scene, under
     * 1e-3 of the narrowest patch), and no less than the round-off of the
     * coordinates themselves (a float-imported room 10 km from the origin). */
    double diag = rad_scene_diagonal(scene), reach = 0.0, narrowest = HUGE_VAL;
    for (size_t i = 0; i < pl.count; i++) {
        const rad_patch *p = &pl.items[i];
        for (uint32_t k = 0; k < p->corner_count; k++)
            reach = fmax(reach, fmax(fabs(p->corner[k].x), fmax(fabs(p->corner[k].y), fabs(p->corner[k].z))));
        double width = rad_corners_width(p->corner, p->corner_count);
        if (width > 0.0)
            narrowest = fmin(narrowest, width);
    }
    double tol = fmin(1e-6 * (diag > 0.0 ? diag : 1.0), 1e-3 * narrowest);
    tol = fmax(tol, 1e-7 * reach);
    size_t cut = 0;
    r = mesh_conform_patches(ctx, tol, &pl.items, &pl.count, &cut, &mesh->contacts, &mesh->contact_count);
    if (r != RAD_OK) {
        rad_free(pl.items);
        return r;
    }
    mesh->patches = pl.items;
    mesh->patch_count = pl.count;
    mesh->contact_tol = tol;
    return RAD_OK;
}

/* As mesh.h says; the welding tolerance and the ray lift size by it. */
double rad_corners_width(const vec3 *corner, uint32_t count)
{
    vec3 n = count == 4 ? v3_cross(v3_sub(corner[2], corner[0]), v3_sub(corner[3], corner[1]))
                        : v3_cross(v3_sub(corner[1], corner[0]), v3_sub(corner[2], corner[0]));
    double area = 0.5 * v3_length(n), longest = 0.0, shortest = HUGE_VAL;
    for (uint32_t k = 0; k < count; k++) {
        double edge = v3_length(v3_sub(corner[(k + 1) % count], corner[k]));
        longest = fmax(longest, edge);
        shortest = fmin(shortest, edge);
    }
    return longest > 0.0 ? fmin(shortest, 2.0 * area / longest) : 0.0;
}
