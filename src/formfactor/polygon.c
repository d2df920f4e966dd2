/*
 * polygon.c -- the unoccluded point-to-polygon form factor; and the small
 * helpers the sampling methods share: the Gauss-Legendre product rule over
 * an element (analytic's and hybrid's far pairs), the bend of a quad (how
 * far ray end points must be lifted), the density of rad_element_sample,
 * the tangent frame of an element, its bundles of cosine-distributed rays
 * and the split of a region into four.
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

#include <string.h>

size_t rad_polygon_clip(const vec3 *poly, size_t n, vec3 x, vec3 normal, vec3 *out)
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
    if (n > 8)
        n = 8;
    /* Back side of the polygon (one-sided surfaces): nothing arrives. */
    vec3 pn = v3_cross(v3_sub(poly[1], poly[0]), v3_sub(poly[2], poly[0]));
    if (n == 4)
        pn = v3_add(pn, v3_cross(v3_sub(poly[2], poly[0]), v3_sub(poly[3], poly[0])));
    if (v3_dot(pn, v3_sub(x, poly[0])) <= 0.0)
        return 0.0;
    return rad_point_polygon_ff_front(x, normal, poly, n);
}

double rad_point_polygon_ff_front(vec3 x, vec3 normal, const vec3 *poly, size_t n)
{
    vec3 clipped[16];
    if (n > 8)
        n = 8;
    size_t m = rad_polygon_clip(poly, n, x, normal, clipped);
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

/* Summed distances of corners 1..3 from the plane through corner 0: an
 * upper bound on any sampled point's distance from the backend's pieces. */
double rad_element_bend(const rad_mesh *mesh, const rad_element *e)
{
    if (e->vertex_count != 4)
        return 0.0;
    vec3 o = mesh->vertices[e->vertex[0]];
    double bend = 0.0;
    for (int k = 1; k < 4; k++)
        bend += fabs(v3_dot(e->normal, v3_sub(mesh->vertices[e->vertex[k]], o)));
    return bend;
}

void rad_tangent_frame(vec3 n, vec3 *u, vec3 *v)
{
    vec3 a = fabs(n.x) < 0.6 ? v3(1, 0, 0) : v3(0, 1, 0);
    *u = v3_normalize(v3_sub(a, v3_scale(n, v3_dot(a, n))));
    *v = v3_cross(n, *u);
}

void rad_element_cosine_rays(const rad_mesh *mesh, const rad_element *e, double lift, int side, int first,
                             int count, rad_rng *rng, rad_ray *ray)
{
    vec3 n = e->normal;
    vec3 t = v3_normalize(fabs(n.x) > 0.9 ? v3_cross(n, v3(0, 1, 0)) : v3_cross(n, v3(1, 0, 0)));
    vec3 b = v3_cross(n, t);
    for (int k = 0; k < count; k++) {
        int cell = (first + k) % (side * side);
        double u = ((cell % side) + rad_rng_uniform(rng)) / side;
        double v = ((cell / side) + rad_rng_uniform(rng)) / side;
        double pu = rad_rng_uniform(rng), pv = rad_rng_uniform(rng);
        double r = sqrt(u), phi = 2.0 * M_PI * v, z = sqrt(fmax(0.0, 1.0 - u));
        ray[k].origin = v3_mad(rad_element_sample(mesh, e, pu, pv), n, lift);
        ray[k].direction = v3_add(v3_add(v3_scale(t, r * cos(phi)), v3_scale(b, r * sin(phi))), v3_scale(n, z));
        ray[k].tnear = 0.0;
        ray[k].tfar = INFINITY;
    }
}

void rad_ff_split4(const vec3 *region, uint32_t corners, vec3 sub[4][4])
{
    if (corners == 4) {
        vec3 m01 = v3_lerp(region[0], region[1], 0.5), m12 = v3_lerp(region[1], region[2], 0.5);
        vec3 m23 = v3_lerp(region[2], region[3], 0.5), m30 = v3_lerp(region[3], region[0], 0.5);
        vec3 mid = v3_lerp(m01, m23, 0.5);
        vec3 q[4][4] = {{region[0], m01, mid, m30}, {m01, region[1], m12, mid},
                        {mid, m12, region[2], m23}, {m30, mid, m23, region[3]}};
        memcpy(sub, q, sizeof q);
    } else {
        vec3 m01 = v3_lerp(region[0], region[1], 0.5), m12 = v3_lerp(region[1], region[2], 0.5);
        vec3 m20 = v3_lerp(region[2], region[0], 0.5);
        vec3 q[4][4] = {{region[0], m01, m20, m20}, {m01, region[1], m12, m12},
                        {m20, m12, region[2], region[2]}, {m01, m12, m20, m20}};
        memcpy(sub, q, sizeof q);
    }
}

/* ---- which pairs couple: the plane tolerance, the facing test (formfactor.h) ---- */

double rad_ff_plane_tolerance(const rad_mesh *mesh)
{
    vec3 lo = mesh->vertex_count ? mesh->vertices[0] : v3(0, 0, 0), hi = lo;
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        lo = v3_min(lo, mesh->vertices[v]);
        hi = v3_max(hi, mesh->vertices[v]);
    }
    return RAD_FF_PLANE_TOLERANCE * v3_length(v3_sub(hi, lo));
}

bool rad_ff_in_front(const vec3 *point, size_t count, vec3 origin, vec3 normal, double tol)
{
    for (size_t k = 0; k < count; k++)
        if (v3_dot(normal, v3_sub(point[k], origin)) > tol)
            return true;
    return false;
}

bool rad_ff_facing(const rad_mesh *mesh, uint32_t i, uint32_t j, double plane_tol)
{
    const rad_element *e[2] = {&mesh->elements[i], &mesh->elements[j]};
    for (int a = 0; a < 2; a++) {
        const rad_element *plane = e[a], *other = e[1 - a];
        vec3 corner[4];
        for (uint32_t k = 0; k < other->vertex_count; k++)
            corner[k] = mesh->vertices[other->vertex[k]];
        if (!rad_ff_in_front(corner, other->vertex_count, plane->centroid, plane->normal, plane_tol))
            return false;
    }
    return true;
}

/* Gauss-Legendre nodes and weights on [0, 1], orders 1..4. */
static const double gauss_node[5][4] = {
    {0},
    {0.5},
    {0.21132486540518713, 0.78867513459481287},
    {0.11270166537925831, 0.5, 0.88729833462074169},
    {0.06943184420297371, 0.33000947820757187, 0.66999052179242813, 0.93056815579702629},
};
static const double gauss_weight[5][4] = {
    {0},
    {1.0},
    {0.5, 0.5},
    {0.27777777777777778, 0.44444444444444444, 0.27777777777777778},
    {0.17392742256872693, 0.32607257743127307, 0.32607257743127307, 0.17392742256872693},
};

int rad_element_gauss(const rad_mesh *mesh, const rad_element *e, int order, vec3 *point, double *weight)
{
    const vec3 *v = mesh->vertices;
    vec3 r0 = v[e->vertex[0]], r1 = v[e->vertex[1]], r2 = v[e->vertex[2]];
    int q = 0;
    for (int a = 0; a < order; a++)
        for (int b = 0; b < order; b++, q++) {
            double s = gauss_node[order][a], t = gauss_node[order][b];
            double w = gauss_weight[order][a] * gauss_weight[order][b];
            if (e->vertex_count == 4) {
                vec3 r3 = v[e->vertex[3]];
                vec3 e1 = v3_sub(r1, r0), e3 = v3_sub(r3, r0);
                vec3 h = v3_add(v3_sub(r2, r1), v3_sub(r0, r3));
                point[q] = v3_add(r0, v3_add(v3_scale(e1, s), v3_add(v3_scale(e3, t), v3_scale(h, s * t))));
                vec3 ds = v3_add(e1, v3_scale(h, t)), dt = v3_add(e3, v3_scale(h, s));
                weight[q] = w * v3_length(v3_cross(ds, dt));
            } else { /* the square collapsed onto the triangle (Duffy) */
                vec3 e1 = v3_sub(r1, r0), e2 = v3_sub(r2, r0);
                point[q] = v3_add(r0, v3_add(v3_scale(e1, s), v3_scale(e2, (1.0 - s) * t)));
                weight[q] = w * v3_length(v3_cross(e1, e2)) * (1.0 - s);
            }
        }
    return q;
}

double rad_element_seen(double F, const double *weight, const uint8_t *blocked, int count)
{
    double all = 0.0, clear = 0.0;
    for (int k = 0; k < count; k++) {
        all += weight[k];
        clear += blocked[k] ? 0.0 : weight[k];
    }
    return all > 0.0 ? F * (clear / all) : F;
}

int rad_element_kernel_rays(const rad_mesh *mesh, const rad_element *e, vec3 p, vec3 n, vec3 origin, double lift,
                            int k, rad_rng *rng, rad_ray *ray, double *weight)
{
    double inv = 1.0 / (k * k);
    int count = 0;
    for (int a = 0; a < k; a++)
        for (int c = 0; c < k; c++) {
            double u = (a + rad_rng_uniform(rng)) / k, v = (c + rad_rng_uniform(rng)) / k;
            vec3 y = v3_mad(rad_element_sample(mesh, e, u, v), e->normal, lift);
            vec3 d = v3_sub(y, p);
            double r2 = v3_dot(d, d);
            double kernel = fmax(0.0, v3_dot(n, d)) * fmax(0.0, -v3_dot(e->normal, d)) / (M_PI * r2 * r2) *
                            e->area * rad_element_sample_weight(mesh, e, u, v);
            if (!(kernel > 0.0))
                continue;
            ray[count] = (rad_ray){origin, v3_sub(y, origin), 0.0, 1.0};
            weight[count++] = kernel * inv;
        }
    return count;
}
