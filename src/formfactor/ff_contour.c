/*
 * ff_contour.c -- element-to-element form factors by Stokes' theorem: the
 * double area integral becomes a double integral over the two polygons'
 * edges (the lecture notes' "Form Factor - Numerical"; Goral, Torrance,
 * Greenberg & Battaile, "Modeling the interaction of light between diffuse
 * surfaces", SIGGRAPH 1984; Schroeder & Hanrahan, "On the form factor
 * between two polygons", SIGGRAPH 1993):
 *
 *     A_i F_ij = 1/(2 pi)  sum_p sum_q  (u_p . u_q)  int_p int_q  K(r)  ds dt
 *
 * over the edges p of polygon i and q of polygon j, with u_p, u_q their unit
 * directions (both polygons counter-clockwise about their own normals), r
 * the distance between the two running points and K = ln r in the papers.
 * Any constant may be added to K (its double contour integral vanishes), so
 * K = ln(r / r0) + 1 with r0 the centroids' distance: the +1 cancels the
 * inner integral's -length term, and r0 keeps K small, so that the edge
 * pairs' shares, which cancel down to (size / distance)^2 of themselves,
 * keep their digits.  Positions are kept relative to each polygon's own
 * centroid for the same reason.  The value is symmetric: one evaluation
 * gives F_ij and F_ji, and reciprocity is exact.
 *
 * The formula holds only where each point of one polygon sees the whole
 * other polygon in front of it, so each element is first clipped to the
 * half-space in front of the other's plane (a wall element reaching below
 * the floor keeps its part above).  Occlusion is a separate factor, the
 * shadow-ray visibility fraction shared with the analytic method
 * (visibility.c), cast between the facing parts only.
 *
 * Each edge pair, by its geometry:
 *
 *   perpendicular   u_p . u_q = 0: contributes nothing.
 *   parallel, near  both integrals in closed form (collinear and shared
 *                   edges included: the log singularity is integrated
 *                   exactly): with Phi'' = K(sqrt(v^2 + delta^2)), delta the
 *                   distance between the lines, v the offset along them,
 *                     int int = Phi(a1-b0) - Phi(a1-b1) - Phi(a0-b0) + Phi(a0-b1)
 *                     Phi(v) = (v^2 - delta^2)/4 ln((v^2 + delta^2)/r0^2) - v^2/4
 *                              + delta v atan(v / delta)
 *                   (farther than 4 edge lengths its terms would cancel by
 *                   (distance / edge)^2, so those go to quadrature);
 *   skew or far     the inner integral along p in closed form,
 *                     int_p K dt = [tau/2 ln((tau^2 + d^2)/r0^2) + d atan(tau/d)]
 *                   (d: the running point's distance from the line of p,
 *                   tau: along p), the outer one along q by Gauss-Legendre
 *                   quadrature.  The inner integral is analytic in s except
 *                   where the running point meets p itself, at complex
 *                   distance D = dist(piece of q, segment p), so a rule of
 *                   order m on a piece of length h errs like rho^(-2m) with
 *                   rho >= 2D/h + sqrt(1 + (2D/h)^2).  Pieces with D < h
 *                   are halved (toward a shared vertex or a crossing, down
 *                   to 1e-7 of the edge: the integrand is bounded there, so
 *                   what is left is ~1e-14 of the pair); the others get an
 *                   order from D/h:
 *
 *                   D/h  >= 24   8    3    1.5   1
 *                   order   3    4    5    6     8
 *
 *                        q ______________  piece h, distance D
 *                         /   /  /   /
 *                        /   /  /        halving toward the shared vertex
 *                       *------------ p
 *
 *                   On random triangle pairs these orders err < 3e-10
 *                   relative at distances of 1 to 16 sizes; rounding adds
 *                   ~1e-16 (distance / size)^2 (4e-9 at 128 sizes).
 *
 * Measured through `radiosity viewfactors` on the reference cases (parallel
 * and perpendicular squares, the cube's full matrix and row sums, coaxial
 * 64-gon disks, the perpendicular squares as fans of skew triangles) at one
 * element per surface, 16 per face, 2,000 and 8,000 elements: relative
 * error <= 3.3e-8, the float rounding of the stored factors.  Cost: about
 * 4 us per pair of quads on one core, 2.5 to 3x the analytic method.
 */
#include "formfactor/formfactor.h"

#include <stdlib.h>
#include <string.h>

/* Gauss-Legendre nodes and weights on [0, 1]; orders 3..8 are used. */
enum { GAUSS_MAX = 8 };
static const double gauss_x[GAUSS_MAX + 1][GAUSS_MAX] = {
    {0},
    {0},
    {0},
    {0.11270166537925831, 0.5, 0.88729833462074169},
    {0.069431844202973712, 0.33000947820757187, 0.66999052179242813, 0.93056815579702629},
    {0.046910077030668004, 0.23076534494715845, 0.5, 0.76923465505284155, 0.953089922969332},
    {0.033765242898423986, 0.16939530676686774, 0.38069040695840155, 0.61930959304159845,
     0.83060469323313226, 0.96623475710157601},
    {0.025446043828620738, 0.12923440720030278, 0.29707742431130142, 0.5, 0.70292257568869858,
     0.87076559279969722, 0.97455395617137926},
    {0.019855071751231884, 0.10166676129318663, 0.23723379504183551, 0.4082826787521751,
     0.5917173212478249, 0.76276620495816449, 0.89833323870681337, 0.98014492824876812},
};
static const double gauss_w[GAUSS_MAX + 1][GAUSS_MAX] = {
    {0},
    {0},
    {0},
    {0.27777777777777778, 0.44444444444444444, 0.27777777777777778},
    {0.17392742256872693, 0.32607257743127307, 0.32607257743127307, 0.17392742256872693},
    {0.11846344252809454, 0.23931433524968323, 0.28444444444444444, 0.23931433524968323,
     0.11846344252809454},
    {0.085662246189585172, 0.1803807865240693, 0.23395696728634552, 0.23395696728634552,
     0.1803807865240693, 0.085662246189585172},
    {0.064742483084434847, 0.13985269574463833, 0.19091502525255947, 0.20897959183673469,
     0.19091502525255947, 0.13985269574463833, 0.064742483084434847},
    {0.05061426814518813, 0.11119051722668724, 0.15685332293894364, 0.18134189168918099,
     0.18134189168918099, 0.15685332293894364, 0.11119051722668724, 0.05061426814518813},
};

/* An edge of a clipped polygon, relative to its polygon's centroid. */
typedef struct edge {
    vec3 a;      /* start - centroid, m */
    vec3 dir;    /* unit */
    double len;  /* m */
} edge;

/* The frame of a pair: positions are kept relative to each polygon's own
 * centroid, and only D joins them, so that a far pair's small offsets are
 * not lost beside the large distance. */
typedef struct pair_frame {
    vec3 D;            /* c_j - c_i, m */
    double inv_r0sq;   /* 1 / r0^2, 1/m^2 */
    double rel;        /* the outer quadrature's shortest piece, relative to its edge */
} pair_frame;

/* A convex element clipped by one plane has at most one vertex more. */
enum { POLY_MAX = 8 };

/* Outer pieces one edge pair may be split into; past this the pieces left
 * are integrated as they are.  A shared vertex needs ~70 (24 halvings), a
 * crossing twice that; only nearly collinear, overlapping edges (skewed by
 * more than 1e-9 rad, else they are taken as parallel) could ask for more. */
enum { PIECE_BUDGET = 2048 };

/* Clip a polygon to n . y >= offset.  Signed distances within `tol` of the
 * plane count as on it, so elements that share an edge with the plane (the
 * perpendicular squares) keep that edge exactly. */
static size_t clip_to_front(const vec3 *poly, size_t n, vec3 normal, double offset, double tol,
                            vec3 *out)
{
    double dist[POLY_MAX];
    for (size_t k = 0; k < n; k++) {
        dist[k] = v3_dot(normal, poly[k]) - offset;
        if (fabs(dist[k]) <= tol)
            dist[k] = 0.0;
    }
    size_t m = 0;
    for (size_t k = 0; k < n; k++) {
        size_t l = (k + 1) % n;
        if (dist[k] >= 0.0)
            out[m++] = poly[k];
        if ((dist[k] > 0.0 && dist[l] < 0.0) || (dist[k] < 0.0 && dist[l] > 0.0))
            out[m++] = v3_lerp(poly[k], poly[l], dist[k] / (dist[k] - dist[l]));
    }
    return m;
}

/* The edges of a polygon relative to `origin`, dropping those shorter than
 * `min_len` (clipping through a vertex repeats it): their share is
 * ~min_len / edge. */
static size_t make_edges(const vec3 *poly, size_t n, vec3 origin, double min_len, edge *out)
{
    size_t m = 0;
    for (size_t k = 0; k < n; k++) {
        vec3 d = v3_sub(poly[(k + 1) % n], poly[k]);
        double len = v3_length(d);
        if (len <= min_len)
            continue;
        out[m].a = v3_sub(poly[k], origin);
        out[m].dir = v3_scale(d, 1.0 / len);
        out[m].len = len;
        m++;
    }
    return m;
}

/* ln(|w - D|^2 / r0^2) with r0 = |D|: for a far pair w is small beside D
 * and the ratio is 1 + w.(w - 2D) / r0^2, whose log1p keeps every digit. */
static double log_ratio(vec3 w, const pair_frame *f)
{
    double x = v3_dot(w, v3_sub(w, v3_scale(f->D, 2.0))) * f->inv_r0sq;
    if (fabs(x) < 0.5)
        return log1p(x);
    vec3 r = v3_sub(w, f->D);
    return log(v3_dot(r, r) * f->inv_r0sq);
}

/* Phi - v^2/4, with Phi'' = ln(sqrt(v^2 + delta^2) / r0) + 1 the kernel K
 * (file header), for parallel edges at distance delta.  The polynomial part
 * is left to the caller (its second difference is exact), and constants
 * are dropped (they cancel in the difference). */
static double phi(double v, double delta, double inv_r0sq)
{
    double q = v * v + delta * delta;
    if (q <= 0.0)
        return 0.0;
    double f = 0.25 * (v * v - delta * delta) * log(q * inv_r0sq);
    if (delta > 0.0)
        f += delta * v * atan(v / delta);
    return f;
}

/* int over p of K = ln(|y - x| / r0) + 1 dt, exactly:
 * [tau/2 ln((tau^2 + d^2) / r0^2) + d atan(tau/d)] between the ends, where
 * the atan difference is the angle p subtends at x (atan2: accurate at any
 * d).  x is on the other polygon, relative to its centroid. */
static double inner_integral(vec3 x, const edge *p, const pair_frame *f)
{
    vec3 wa = v3_sub(p->a, x), wb = v3_mad(wa, p->dir, p->len);
    vec3 ra = v3_sub(wa, f->D), rb = v3_sub(wb, f->D); /* x -> the ends of p */
    double ta = v3_dot(ra, p->dir), tb = ta + p->len;
    double d = v3_length(v3_cross(ra, p->dir));
    double s = d * atan2(d * p->len, v3_dot(ra, rb));
    if (v3_dot(rb, rb) > 0.0)
        s += 0.5 * tb * log_ratio(wb, f);
    if (v3_dot(ra, ra) > 0.0)
        s -= 0.5 * ta * log_ratio(wa, f);
    return s;
}

/* Distance from x (on the other polygon, relative to its centroid) to p. */
static double point_segment_distance(vec3 x, const edge *p, const pair_frame *f)
{
    vec3 r = v3_add(v3_sub(x, p->a), f->D);
    double t = v3_dot(r, p->dir);
    t = t < 0.0 ? 0.0 : t > p->len ? p->len : t;
    return v3_length(v3_sub(r, v3_scale(p->dir, t)));
}

/* int over s in [s0, s1] of q of the inner integral along p; adaptive as in
 * the file header.  Pieces shorter than min_len, or past the budget, are
 * integrated as they are. */
static double outer_integral(const edge *q, double s0, double s1, const edge *p,
                             const pair_frame *f, double min_len, int *budget)
{
    double h = s1 - s0;
    vec3 mid = v3_mad(q->a, q->dir, 0.5 * (s0 + s1));
    /* A lower bound on dist(piece, p): the midpoint's distance less h/2. */
    double ratio = (point_segment_distance(mid, p, f) - 0.5 * h) / h;
    if (ratio < 1.0 && h > min_len && *budget > 0) {
        double sm = 0.5 * (s0 + s1);
        (*budget)--;
        double left = outer_integral(q, s0, sm, p, f, min_len, budget);
        return left + outer_integral(q, sm, s1, p, f, min_len, budget);
    }
    int order = ratio >= 24.0 ? 3 : ratio >= 8.0 ? 4 : ratio >= 3.0 ? 5 : ratio >= 1.5 ? 6 : 8;
    double sum = 0.0;
    for (int k = 0; k < order; k++) {
        vec3 x = v3_mad(q->a, q->dir, s0 + h * gauss_x[order][k]);
        sum += gauss_w[order][k] * inner_integral(x, p, f);
    }
    return sum * h;
}

/* (u_p . u_q) int_p int_q K, by the case analysis of the file header. */
static double edge_pair(const edge *p, const edge *q, const pair_frame *f)
{
    double c = v3_dot(p->dir, q->dir);
    /* 1e-12: below, the pair's share is below double rounding of the others'. */
    if (fabs(c) < 1e-12)
        return 0.0;
    double sine = v3_length(v3_cross(p->dir, q->dir));
    vec3 q_mid = v3_mad(q->a, q->dir, 0.5 * q->len);
    /* 1e-9: treating lines this close to parallel as parallel moves the
     * distance between them by 1e-9 of an edge, far below float rounding.
     * Parallel edges farther apart than 4 edge lengths go to quadrature:
     * the closed form's four terms would cancel by (distance / edge)^2. */
    if (sine < 1e-9 &&
        point_segment_distance(q_mid, p, f) - 0.5 * q->len < 4.0 * fmax(p->len, q->len)) {
        vec3 r = v3_add(v3_sub(q_mid, p->a), f->D);
        double delta = v3_length(v3_sub(r, v3_scale(p->dir, v3_dot(r, p->dir))));
        double b0 = v3_dot(v3_add(v3_sub(q->a, p->a), f->D), p->dir);
        double b1 = b0 + c * q->len;
        double a1 = p->len;
        /* sign(c) is carried by the orientation b0 -> b1; the last term is
         * the second difference of the dropped -v^2/4. */
        return phi(a1 - b0, delta, f->inv_r0sq) - phi(a1 - b1, delta, f->inv_r0sq) -
               phi(-b0, delta, f->inv_r0sq) + phi(-b1, delta, f->inv_r0sq) - 0.5 * a1 * (b1 - b0);
    }
    int budget = PIECE_BUDGET;
    return c * outer_integral(q, 0.0, q->len, p, f, f->rel * q->len, &budget);
}

double rad_polygon_coupling(const vec3 *poly_i, size_t n_i, vec3 normal_i, const vec3 *poly_j,
                            size_t n_j, vec3 normal_j, double plane_tol)
{
    return rad_polygon_coupling_to(poly_i, n_i, normal_i, poly_j, n_j, normal_j, plane_tol, 1e-7);
}

double rad_polygon_coupling_to(const vec3 *poly_i, size_t n_i, vec3 normal_i, const vec3 *poly_j,
                               size_t n_j, vec3 normal_j, double plane_tol, double rel)
{
    if (n_i < 3 || n_j < 3 || n_i > 4 || n_j > 4)
        return 0.0;
    vec3 ci = v3(0, 0, 0), cj = v3(0, 0, 0);
    for (size_t k = 0; k < n_i; k++)
        ci = v3_add(ci, poly_i[k]);
    for (size_t k = 0; k < n_j; k++)
        cj = v3_add(cj, poly_j[k]);
    ci = v3_scale(ci, 1.0 / (double)n_i);
    cj = v3_scale(cj, 1.0 / (double)n_j);
    vec3 clip_i[POLY_MAX], clip_j[POLY_MAX];
    size_t m_i = clip_to_front(poly_i, n_i, normal_j, v3_dot(normal_j, cj), plane_tol, clip_i);
    size_t m_j = clip_to_front(poly_j, n_j, normal_i, v3_dot(normal_i, ci), plane_tol, clip_j);
    if (m_i < 3 || m_j < 3)
        return 0.0;
    double scale = 0.0;
    for (size_t k = 0; k < n_i; k++)
        scale = fmax(scale, v3_length(v3_sub(poly_i[k], ci)));
    for (size_t k = 0; k < n_j; k++)
        scale = fmax(scale, v3_length(v3_sub(poly_j[k], cj)));
    /* 1e-12 of the pair's size: an edge this short is a repeated vertex. */
    edge e_i[POLY_MAX], e_j[POLY_MAX];
    size_t k_i = make_edges(clip_i, m_i, ci, 1e-12 * scale, e_i);
    size_t k_j = make_edges(clip_j, m_j, cj, 1e-12 * scale, e_j);
    /* K = ln(r / r0) + 1 instead of ln r: the two differ by a constant,
     * whose double contour integral vanishes, and with r0 the centroids'
     * distance K stays small, so that the edge pairs' shares, which cancel
     * down to ~ (size / distance)^2 of themselves, keep their digits (the
     * error grows like (distance / size)^2 x 1e-16, not its cube). */
    pair_frame f;
    f.rel = rel;
    f.D = v3_sub(cj, ci);
    double r0sq = v3_dot(f.D, f.D);
    f.inv_r0sq = r0sq > 0.0 ? 1.0 / r0sq : 1.0 / (scale * scale);
    double sum = 0.0;
    for (size_t p = 0; p < k_i; p++)
        for (size_t q = 0; q < k_j; q++)
            sum += edge_pair(&e_i[p], &e_j[q], &f);
    /* Contours counter-clockwise about normals that face each other run
     * opposite ways where they are closest (u_p . u_q < 0, ln r most
     * negative): the sum is positive. */
    double coupling = sum / (2.0 * M_PI);
    return coupling > 0.0 ? coupling : 0.0;
}

double rad_element_coupling(const rad_mesh *mesh, uint32_t i, uint32_t j, double plane_tol)
{
    const rad_element *ei = &mesh->elements[i], *ej = &mesh->elements[j];
    vec3 pi[4], pj[4];
    for (uint32_t k = 0; k < ei->vertex_count; k++)
        pi[k] = mesh->vertices[ei->vertex[k]];
    for (uint32_t k = 0; k < ej->vertex_count; k++)
        pj[k] = mesh->vertices[ej->vertex[k]];
    return rad_polygon_coupling(pi, ei->vertex_count, ei->normal, pj, ej->vertex_count, ej->normal,
                                plane_tol);
}

/* What every pair reads. */
typedef struct contour_shared {
    int base_rays;     /* shadow rays per pair before the pilot's verdict */
    double eps;        /* m: the ray-end lift, rad_vis_epsilon (0 without visibility) */
    double plane_tol;  /* m: rad_ff_plane_tolerance */
} contour_shared;

static rad_result contour_prepare(rad_context *ctx, const rad_ff_request *req, void **shared)
{
    contour_shared *c = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, 1, sizeof *c, "form factors: settings");
    if (!c)
        return RAD_ERROR_OUT_OF_MEMORY;
    c->base_rays = req->shadow_rays > 0 ? req->shadow_rays : 4;
    c->eps = req->vis ? rad_vis_epsilon(req->mesh) : 0.0;
    c->plane_tol = rad_ff_plane_tolerance(req->mesh);
    *shared = c;
    return RAD_OK;
}

/* One evaluation gives both directions: A_i F_ij = A_j F_ji exactly. */
static void contour_pair(const rad_ff_request *req, const void *shared, void *scratch, uint32_t i,
                         uint32_t j, rad_ff_pair *out, rad_ff_tally *tally)
{
    (void)scratch;
    const contour_shared *c = shared;
    const rad_mesh *mesh = req->mesh;
    double g = rad_element_coupling(mesh, i, j, c->plane_tol);
    if (!(g > 0.0))
        return;
    g *= rad_ff_visibility(req, i, j, c->eps, c->base_rays, &tally->rays);
    out->F_ij = g / mesh->elements[i].area;
    out->F_ji = g / mesh->elements[j].area;
}

const rad_ff_method rad_ff_contour = {
    "contour",
    "double contour integral of ln r (Stokes; Goral et al. 1984) on mutually clipped elements, "
    "closed-form inner and parallel-edge integrals, adaptive Gauss outer, shadow-ray "
    "visibility; ~1e-8 unoccluded, O(n^2)",
    0,
    contour_prepare,
    NULL,
    contour_pair,
    NULL,
    NULL,
};
