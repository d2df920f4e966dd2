/*
 * triangulate.c -- polygon geometry for the scene: Newell's normal and ear
 * clipping of simple polygons.
 *
 * Newell's method (Sutherland, Sproull, Schumacker 1974) sums the
 * projections of the edges onto the three coordinate planes; for a planar
 * polygon the result is the normal times twice the area, and for a slightly
 * non-planar one it is the normal of a good best-fit plane.
 *
 * Ear clipping (Meisters 1975, "Polygons have ears"; Eberly, "Triangulation
 * by ear clipping") works in 2D: the polygon is projected onto the plane of
 * the given normal with a right-handed frame (u, v, n), so counter-clockwise
 * in (u, v) means "right-hand rule along n".  A vertex i is an ear when it is
 * strictly convex and the closed triangle (prev, i, next) holds no other
 * vertex; clipping it removes one vertex and emits one triangle:
 *
 *        prev o-------o next           prev o-------o next
 *              \     /          ->             ...
 *               \   /
 *                 o i   (ear)
 *
 * Straight (collinear) vertices are never clipped as ears, so every emitted
 * triangle has positive area and a simple n-gon gives exactly n - 2
 * triangles.  Simplicity is checked first (every pair of edges, O(n^2)),
 * so a self-intersecting polygon is refused rather than triangulated into
 * overlapping pieces.
 */
#include "scene/scene.h"

#include <float.h>
#include <stdlib.h>

vec3 rad_polygon_newell(const vec3 *vertices, size_t n)
{
    vec3 normal = v3(0.0, 0.0, 0.0);
    for (size_t i = 0; i < n; i++) {
        vec3 a = vertices[i], b = vertices[(i + 1) % n];
        normal.x += (a.y - b.y) * (a.z + b.z);
        normal.y += (a.z - b.z) * (a.x + b.x);
        normal.z += (a.x - b.x) * (a.y + b.y);
    }
    return normal;
}

typedef struct point2 {
    double x, y;
} point2;

/* Twice the signed area of (a, b, c): > 0 when counter-clockwise. */
static double orient2(point2 a, point2 b, point2 c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/* p lies in the bounding box of segment ab (used once p is known to be
 * collinear with it). */
static bool within_segment_box(point2 a, point2 b, point2 p)
{
    return p.x >= fmin(a.x, b.x) && p.x <= fmax(a.x, b.x) && p.y >= fmin(a.y, b.y) &&
           p.y <= fmax(a.y, b.y);
}

/* Segments ab and cd cross or touch; `eps` is the orientation tolerance. */
static bool segments_meet(point2 a, point2 b, point2 c, point2 d, double eps)
{
    double d1 = orient2(c, d, a), d2 = orient2(c, d, b);
    double d3 = orient2(a, b, c), d4 = orient2(a, b, d);
    if (((d1 > eps && d2 < -eps) || (d1 < -eps && d2 > eps)) &&
        ((d3 > eps && d4 < -eps) || (d3 < -eps && d4 > eps)))
        return true;
    return (fabs(d1) <= eps && within_segment_box(c, d, a)) ||
           (fabs(d2) <= eps && within_segment_box(c, d, b)) ||
           (fabs(d3) <= eps && within_segment_box(a, b, c)) ||
           (fabs(d4) <= eps && within_segment_box(a, b, d));
}

/* True if the closed polygon pts[0..n) is simple: no zero-length edge, no
 * spike (an edge doubling back on the previous one) and no two
 * non-adjacent edges that cross or touch. */
static bool polygon_is_simple(const point2 *pts, size_t n, double eps)
{
    for (size_t i = 0; i < n; i++) {
        point2 prev = pts[(i + n - 1) % n], p = pts[i], next = pts[(i + 1) % n];
        if (p.x == next.x && p.y == next.y)
            return false;
        double turn = orient2(prev, p, next);
        double along = (p.x - prev.x) * (next.x - p.x) + (p.y - prev.y) * (next.y - p.y);
        if (fabs(turn) <= eps && along < 0.0)
            return false;
    }
    for (size_t i = 0; i < n; i++) {
        /* Edge j = i + 1 shares a vertex with edge i; the last edge shares
         * one with edge 0. */
        for (size_t j = i + 2; j < n; j++) {
            if (i == 0 && j == n - 1)
                continue;
            if (segments_meet(pts[i], pts[i + 1], pts[j], pts[(j + 1) % n], eps))
                return false;
        }
    }
    return true;
}

/* Vertex i (between prev and next in the remaining polygon) is an ear. */
static bool is_ear(const point2 *pts, const uint32_t *next_of, uint32_t prev, uint32_t i,
                   uint32_t next, double sign, double eps)
{
    point2 a = pts[prev], b = pts[i], c = pts[next];
    if (sign * orient2(a, b, c) <= eps)
        return false; /* reflex or straight */
    for (uint32_t j = next_of[next]; j != prev; j = next_of[j]) {
        point2 p = pts[j];
        if (sign * orient2(a, b, p) >= -eps && sign * orient2(b, c, p) >= -eps &&
            sign * orient2(c, a, p) >= -eps)
            return false; /* p inside or on the triangle: clipping would touch it */
    }
    return true;
}

size_t rad_triangulate_polygon(const vec3 *vertices, size_t n, vec3 normal, void *scratch,
                               uint32_t *triangles)
{
    if (n < 3 || n >= UINT32_MAX || !v3_finite(normal) || v3_length(normal) == 0.0)
        return 0;
    vec3 axis_n = v3_normalize(normal);
    /* A right-handed frame (u, v, n): u is perpendicular to n and to the
     * coordinate axis least aligned with n. */
    vec3 helper = fabs(axis_n.x) <= fabs(axis_n.y) && fabs(axis_n.x) <= fabs(axis_n.z)
                      ? v3(1.0, 0.0, 0.0)
                      : (fabs(axis_n.y) <= fabs(axis_n.z) ? v3(0.0, 1.0, 0.0) : v3(0.0, 0.0, 1.0));
    vec3 axis_u = v3_normalize(v3_cross(helper, axis_n));
    vec3 axis_v = v3_cross(axis_n, axis_u);

    point2 *pts = scratch;
    uint32_t *prev_of = (uint32_t *)(pts + n);
    uint32_t *next_of = prev_of + n;
    size_t count = 0;

    double min_x = INFINITY, min_y = INFINITY, max_x = -INFINITY, max_y = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        vec3 d = v3_sub(vertices[i], vertices[0]);
        pts[i].x = v3_dot(d, axis_u);
        pts[i].y = v3_dot(d, axis_v);
        min_x = fmin(min_x, pts[i].x);
        max_x = fmax(max_x, pts[i].x);
        min_y = fmin(min_y, pts[i].y);
        max_y = fmax(max_y, pts[i].y);
    }
    double extent2 = (max_x - min_x) * (max_x - min_x) + (max_y - min_y) * (max_y - min_y);
    if (!isfinite(extent2))
        goto done;
    /* An orientation test on coordinates of size L carries a rounding error
     * of a few ulp of L^2; 64 ulp leaves a margin and still resolves
     * features a million times smaller than the polygon. */
    double eps = 64.0 * DBL_EPSILON * extent2;

    double twice_area = 0.0;
    for (size_t i = 0; i < n; i++)
        twice_area += orient2(pts[0], pts[i], pts[(i + 1) % n]);
    if (fabs(twice_area) <= eps)
        goto done; /* degenerate, or a figure-eight whose lobes cancel */
    double sign = twice_area > 0.0 ? 1.0 : -1.0; /* clockwise about `normal`: mirror the tests */
    if (!polygon_is_simple(pts, n, eps))
        goto done;

    for (uint32_t i = 0; i < (uint32_t)n; i++) {
        prev_of[i] = i == 0 ? (uint32_t)n - 1 : i - 1;
        next_of[i] = i + 1 == (uint32_t)n ? 0 : i + 1;
    }
    size_t remaining = n, misses = 0;
    uint32_t i = 0;
    while (remaining > 3) {
        uint32_t prev = prev_of[i], next = next_of[i];
        if (is_ear(pts, next_of, prev, i, next, sign, eps)) {
            triangles[3 * count + 0] = prev;
            triangles[3 * count + 1] = i;
            triangles[3 * count + 2] = next;
            count++;
            next_of[prev] = next;
            prev_of[next] = prev;
            remaining--;
            misses = 0;
            i = next;
        } else {
            i = next;
            if (++misses > remaining) { /* a full turn without an ear: not simple after all */
                count = 0;
                goto done;
            }
        }
    }
    if (sign * orient2(pts[prev_of[i]], pts[i], pts[next_of[i]]) <= eps) {
        count = 0;
        goto done;
    }
    triangles[3 * count + 0] = prev_of[i];
    triangles[3 * count + 1] = i;
    triangles[3 * count + 2] = next_of[i];
    count++;

done:
    return count;
}
