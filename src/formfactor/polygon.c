/*
 * polygon.c -- the unoccluded point-to-polygon form factor.
 *
 * Lambert's contour formula (Lambert 1760; in radiosity: Baum, Rushmeier &
 * Winget, SIGGRAPH 1989; Cohen & Wallace 1993, sec. 4.6):
 *
 *     F_{dA -> P} = 1/(2 pi)  sum_k  gamma_k  (n . (R_k x R_k+1)) / |R_k x R_k+1|
 *
 * with R_k the unit vectors from the point to the polygon's vertices and
 * gamma_k the angle between R_k and R_k+1.  The sum is the solid angle
 * projected onto the tangent plane, which is only the form factor when the
 * whole polygon lies in front of that plane: so the polygon is first clipped
 * to the half-space n . (y - x) >= 0 (Sutherland-Hodgman).
 *
 *          polygon
 *      R_k /‾‾‾‾‾‾\ R_k+1         gamma_k = atan2(|R_k x R_k+1|, R_k . R_k+1)
 *          \ gamma/              (atan2, not acos: accurate at tiny angles)
 *        n ^ \   /
 *          |  \ /
 *     -----x-------- tangent plane
 */
#include "formfactor/formfactor.h"

/* Clip to n.(y - x) >= 0.  `out` holds up to n + 1 vertices. */
static size_t clip_to_hemisphere(vec3 x, vec3 normal, const vec3 *poly, size_t n, vec3 *out)
{
    size_t m = 0;
    for (size_t k = 0; k < n; k++) {
        vec3 a = poly[k], b = poly[(k + 1) % n];
        double da = v3_dot(normal, v3_sub(a, x)), db = v3_dot(normal, v3_sub(b, x));
        if (da >= 0.0)
            out[m++] = a;
        if ((da >= 0.0) != (db >= 0.0)) {
            double t = da / (da - db);
            out[m++] = v3_lerp(a, b, t);
        }
    }
    return m;
}

double rad_point_polygon_ff(vec3 x, vec3 normal, const vec3 *poly, size_t n)
{
    vec3 clipped[9];
    if (n > 8)
        n = 8;
    /* Back side of the polygon (one-sided surfaces): nothing arrives. */
    vec3 pn = v3_cross(v3_sub(poly[1], poly[0]), v3_sub(poly[2], poly[0]));
    if (n == 4)
        pn = v3_add(pn, v3_cross(v3_sub(poly[2], poly[0]), v3_sub(poly[3], poly[0])));
    if (v3_dot(pn, v3_sub(x, poly[0])) <= 0.0)
        return 0.0;
    size_t m = clip_to_hemisphere(x, normal, poly, n, clipped);
    if (m < 3)
        return 0.0;
    double sum = 0.0;
    vec3 r0 = v3_normalize(v3_sub(clipped[0], x)), ra = r0;
    for (size_t k = 0; k < m; k++) {
        vec3 rb = k + 1 < m ? v3_normalize(v3_sub(clipped[k + 1], x)) : r0;
        vec3 c = v3_cross(ra, rb);
        double s = v3_length(c);
        if (s > 0.0)
            sum += atan2(s, v3_dot(ra, rb)) * v3_dot(normal, c) / s;
        ra = rb;
    }
    /* Vertices counter-clockwise about the polygon normal, seen from the
     * front: the contour runs clockwise seen from x, so the sum is negative. */
    double f = -sum / (2.0 * M_PI);
    return f > 0.0 ? f : 0.0;
}
