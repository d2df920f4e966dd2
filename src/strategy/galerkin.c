/*
 * galerkin.c -- radiosity with higher-order elements: a basis function per
 * node, the weighted-residual equations of the lecture notes ("Galerkin
 * Method", "Point Collocation"; Cohen & Wallace 1993, ch. 3; Heckbert &
 * Winget 1991, "Finite element methods for global illumination"; Zatz 1993,
 * "Galerkin radiosity").
 *
 *     B(x) = sum_j B_j N_j(x)        N_j: one per node, sum_j N_j = 1
 *
 *     galerkin-constant  N = 1 on one element: a node per element
 *     galerkin-linear    a node per welded vertex: barycentric on
 *                        triangles, bilinear on quads (the render's own
 *                        interpolation, interp/vertex.c)
 *     collocation        the linear basis, the equation enforced at the
 *                        vertices instead of weighted over the surface
 *
 * Galerkin (weights = basis functions):
 *
 *     (M - R K) B = M E      M_ij = int N_i N_j dA        (consistent mass)
 *                            K_ij = int N_i(x) int N_j(y) G(x,y) V dy dx
 *                            G = cos(theta_x) cos(theta_y) / (pi r^2)
 *                            R = diag(rho at node i)
 *
 * With the constant basis M = diag(A) and K_ij = A_i F_ij: the classic
 * B = E + rho F B.  Collocation:
 *
 *     B_k = E(x_k) + rho(x_k) sum_j B_j C_kj,   C_kj = int N_j(y) G(x_k,y) V dy
 *
 * The inner integral over y, element f at a time, is the exact point-to-
 * polygon factor (Lambert's contour formula, polygon.c) times the mean of
 * the basis weighted by G:
 *
 *     int_f N_j G dy = F_{x->f} * (int_f N_j G / int_f G)
 *
 * where only the mean comes from quadrature (Gauss on f, f split toward x
 * where x is near).  So the magnitude is exact and the constant basis is
 * exact; for the linear basis the quadrature error enters through the
 * variation of N_j only.  The outer integral over x is Gauss quadrature on
 * e: one rule per element for all its pairs (outer_rule_of).  Visibility:
 * Galerkin, the element pair's shadow-ray fraction (pair_visibility, as
 * the analytic method's); collocation, the fraction of rays from the
 * point to f's Gauss points that pass (fixed points, no random numbers).
 *
 * rho must be one value around each vertex (true within a surface); E may
 * change between elements.  T-vertices (mesh.h) are unknowns of their own:
 * the linear space is non-conforming there (a jump of the order of the
 * approximation error along the coarse edge), and the partition of unity
 * holds in every element.
 *
 * Solving: K (no rho) is dense, dofs x dofs doubles; the iteration is the
 * Neumann series of the scaled system M^-1 R K (consistent mass, M solved
 * by conjugate gradients on its sparse element form): B <- M^-1 (M E +
 * R K B), which contracts by rho_max per step (G is symmetric with row
 * and column sums <= 1, so K's operator has L2 norm <= 1).  Collocation:
 * Jacobi, B <- E + R C B.
 */
#include "strategy/strategy.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

enum { GALERKIN_CONSTANT, GALERKIN_LINEAR, GALERKIN_COLLOCATION };

static const struct {
    const char *name, *description;
} galerkin_solvers[] = {
    {"galerkin-linear",
     "Galerkin elements, linear on triangles and bilinear on quads: the vertex values solve (M - rho K) B = M E"},
    {"galerkin-constant", "Galerkin with constant elements: M = diag(A), K = A F by quadrature; the classic system"},
    {"collocation", "point collocation: linear elements, the equation enforced at the vertices"},
};

typedef struct galerkin_state {
    rad_meshed base;           /* mesh, visibility, elements (element means), stats */
    int method;
    size_t dofs;               /* unknowns: elements (constant) or welded vertices */
    double *K;                 /* dofs x dofs, row-major, m^2 (Galerkin) or 1 (collocation); no rho */
    double *mass;              /* 16 per element: its consistent mass matrix (4 x 4, m^2) */
    double *node_mass;         /* dofs: int N_i dA, m^2 (the rows of M summed) */
    double *node_reflectance;  /* 3 dofs */
    double *load;              /* 3 dofs: (M E)_i, W (Galerkin) or E(x_k), W/m^2 (collocation) */
    double *node_radiosity;    /* 3 dofs, W/m^2: the solution */
    vec3 *point;               /* collocation: dofs points (vertices moved into their surface) */
    vec3 *point_normal;        /* collocation: dofs */
    vec3 *ray_origin;          /* collocation: dofs, where its shadow rays start (collocation_points) */
} galerkin_state;

/* ---- the basis on one element, in its parameters (u, v) ----
 *
 *   quad:     P = (1-u)(1-v) c0 + u(1-v) c1 + uv c2 + (1-u)v c3, (u,v) in [0,1]^2
 *   triangle: P = c0 + u (c1 - c0) + v (c2 - c0), u, v >= 0, u + v <= 1
 *
 * as rad_element_interpolate weights its vertices. */

typedef struct element_geometry {
    vec3 c[4];
    uint32_t corners;
    vec3 normal;
    vec3 centroid;
    double radius;             /* m: farthest corner from the centroid */
    double lift;               /* m: shadow-ray ends move this far off it (rad_ff_end_element) */
} element_geometry;

/* eps: rad_vis_epsilon of the mesh. */
static void geometry_of(const rad_mesh *mesh, uint32_t e, double eps, element_geometry *g)
{
    const rad_element *el = &mesh->elements[e];
    g->lift = eps + rad_element_bend(mesh, el);
    g->corners = el->vertex_count;
    g->normal = el->normal;
    g->centroid = el->centroid;
    g->radius = 0.0;
    for (uint32_t k = 0; k < el->vertex_count; k++) {
        g->c[k] = mesh->vertices[el->vertex[k]];
        g->radius = fmax(g->radius, v3_length(v3_sub(g->c[k], g->centroid)));
    }
}

static vec3 point_at(const element_geometry *g, double u, double v)
{
    const vec3 *c = g->c;
    if (g->corners == 3)
        return v3_add(c[0], v3_add(v3_scale(v3_sub(c[1], c[0]), u), v3_scale(v3_sub(c[2], c[0]), v)));
    return v3_add(v3_add(v3_scale(c[0], (1 - u) * (1 - v)), v3_scale(c[1], u * (1 - v))),
                  v3_add(v3_scale(c[2], u * v), v3_scale(c[3], (1 - u) * v)));
}

/* |dP/du x dP/dv|, m^2 per unit parameter area. */
static double jacobian_at(const element_geometry *g, double u, double v)
{
    const vec3 *c = g->c;
    if (g->corners == 3)
        return v3_length(v3_cross(v3_sub(c[1], c[0]), v3_sub(c[2], c[0])));
    vec3 du = v3_add(v3_scale(v3_sub(c[1], c[0]), 1 - v), v3_scale(v3_sub(c[2], c[3]), v));
    vec3 dv = v3_add(v3_scale(v3_sub(c[3], c[0]), 1 - u), v3_scale(v3_sub(c[2], c[1]), u));
    return v3_length(v3_cross(du, dv));
}

/* The basis functions of the element's nodes at (u, v); `nodes` is 1 for
 * the constant basis. */
static void basis_at(uint32_t corners, int nodes, double u, double v, double N[4])
{
    if (nodes == 1) {
        N[0] = 1.0;
        return;
    }
    if (corners == 3) {
        N[0] = 1.0 - u - v, N[1] = u, N[2] = v;
        return;
    }
    N[0] = (1 - u) * (1 - v), N[1] = u * (1 - v), N[2] = u * v, N[3] = (1 - u) * v;
}

/* A part of an element in its parameters: a rectangle (quads) or a
 * triangle (triangles), corners counter-clockwise as the element's. */
typedef struct region {
    double p[4][2];
} region;

static region whole_element(uint32_t corners)
{
    region r;
    if (corners == 3)
        r = (region){{{0, 0}, {1, 0}, {0, 1}, {0, 0}}};
    else
        r = (region){{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
    return r;
}

/* The four children: quads at the parameter midpoints, triangles into
 * their corner and medial triangles. */
static void split_region(uint32_t corners, const region *r, region child[4])
{
    if (corners == 4) {
        double u0 = r->p[0][0], v0 = r->p[0][1], u1 = r->p[2][0], v1 = r->p[2][1];
        double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1);
        double box[4][4] = {{u0, v0, um, vm}, {um, v0, u1, vm}, {um, vm, u1, v1}, {u0, vm, um, v1}};
        for (int k = 0; k < 4; k++)
            child[k] = (region){{{box[k][0], box[k][1]}, {box[k][2], box[k][1]}, {box[k][2], box[k][3]},
                                 {box[k][0], box[k][3]}}};
        return;
    }
    double m[3][2];
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 2; d++)
            m[k][d] = 0.5 * (r->p[k][d] + r->p[(k + 1) % 3][d]);
    /* m[0] on edge 0-1, m[1] on 1-2, m[2] on 2-0. */
    const double *tri[4][3] = {{r->p[0], m[0], m[2]}, {m[0], r->p[1], m[1]}, {m[2], m[1], r->p[2]}, {m[0], m[1], m[2]}};
    for (int k = 0; k < 4; k++) {
        memset(&child[k], 0, sizeof child[k]);
        for (int c = 0; c < 3; c++)
            child[k].p[c][0] = tri[k][c][0], child[k].p[c][1] = tri[k][c][1];
    }
}

/* Quadrature on a region: points (u, v) and weights in m^2 (the
 * Jacobian included).  Quads: Gauss-Legendre 2 x 2 or 3 x 3 (exact for
 * degree 3 / 5 in each parameter); triangles: 3 points (degree 2) or
 * Dunavant's 6 points (degree 4; Dunavant 1985).  Returns the count. */
enum { MAX_POINTS = 9 };

static int region_rule(const element_geometry *g, const region *r, bool fine, double uv[MAX_POINTS][2],
                       double w[MAX_POINTS])
{
    int n = 0;
    if (g->corners == 4) {
        static const double x2[2] = {0.21132486540518713, 0.78867513459481287}, w2[2] = {0.5, 0.5};
        static const double x3[3] = {0.11270166537925831, 0.5, 0.88729833462074169},
                            w3[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
        const double *x = fine ? x3 : x2, *wx = fine ? w3 : w2;
        int m = fine ? 3 : 2;
        double u0 = r->p[0][0], v0 = r->p[0][1], du = r->p[2][0] - u0, dv = r->p[2][1] - v0;
        for (int a = 0; a < m; a++)
            for (int b = 0; b < m; b++) {
                uv[n][0] = u0 + du * x[a];
                uv[n][1] = v0 + dv * x[b];
                w[n] = wx[a] * wx[b] * du * dv * jacobian_at(g, uv[n][0], uv[n][1]);
                n++;
            }
        return n;
    }
    /* Barycentric points (l0, l1, l2) on the region's corners. */
    static const double b3[3][3] = {{2.0 / 3, 1.0 / 6, 1.0 / 6}, {1.0 / 6, 2.0 / 3, 1.0 / 6}, {1.0 / 6, 1.0 / 6, 2.0 / 3}};
    static const double wb3 = 1.0 / 3;
    const double a = 0.445948490915965, wa = 0.223381589678011;
    const double b = 0.091576213509771, wb = 0.109951743655322;
    const double b6[6][3] = {{1 - 2 * a, a, a}, {a, 1 - 2 * a, a}, {a, a, 1 - 2 * a},
                             {1 - 2 * b, b, b}, {b, 1 - 2 * b, b}, {b, b, 1 - 2 * b}};
    const double w6[6] = {wa, wa, wa, wb, wb, wb};
    double e1u = r->p[1][0] - r->p[0][0], e1v = r->p[1][1] - r->p[0][1];
    double e2u = r->p[2][0] - r->p[0][0], e2v = r->p[2][1] - r->p[0][1];
    double param_area = 0.5 * fabs(e1u * e2v - e1v * e2u);
    double J = jacobian_at(g, 0, 0);
    int m = fine ? 6 : 3;
    for (int k = 0; k < m; k++) {
        const double *l = fine ? b6[k] : b3[k];
        uv[n][0] = l[0] * r->p[0][0] + l[1] * r->p[1][0] + l[2] * r->p[2][0];
        uv[n][1] = l[0] * r->p[0][1] + l[1] * r->p[1][1] + l[2] * r->p[2][1];
        w[n] = (fine ? w6[k] : wb3) * param_area * J;
        n++;
    }
    return n;
}

/* The region's corners in space (a flat quad's parameter lines are
 * straight, so the region is the polygon of its corners), their centroid
 * and its diameter. */
static void region_polygon(const element_geometry *g, const region *r, vec3 poly[4], vec3 *centre, double *size)
{
    *centre = (vec3){0, 0, 0};
    for (uint32_t k = 0; k < g->corners; k++) {
        poly[k] = point_at(g, r->p[k][0], r->p[k][1]);
        *centre = v3_add(*centre, poly[k]);
    }
    *centre = v3_scale(*centre, 1.0 / g->corners);
    *size = 0.0;
    for (uint32_t k = 0; k < g->corners; k++)
        *size = fmax(*size, 2.0 * v3_length(v3_sub(poly[k], *centre)));
}

/* Inner integral: a region of f is split while it is larger than
 * INNER_RATIO x its distance from the point: nearer, the kernel changes by
 * a large factor across it, and the fixed rule would miss the G-weighted
 * means of the basis.  (Only the means: the factor itself is exact.) */
#define INNER_RATIO 2.0
/* Split depths: the inner integral from an outer Gauss point (at least
 * 0.06 of a quarter element from an edge) needs ~8; a collocation point,
 * 1e-6 of an element from an edge (collocation_points), ~20. */
enum { INNER_DEPTH = 10, COLLOCATION_DEPTH = 24 };

/* Add int_f N_j(y) G(x, y) dy over region r of f into I[j] (unoccluded):
 * the exact factor of the region, times the G-weighted mean of each N_j
 * by the fine rule. */
static void inner_region(const element_geometry *f, int nodes, vec3 x, vec3 nx, const region *r, int depth,
                         int max_depth, double I[4])
{
    vec3 poly[4], centre;
    double size;
    region_polygon(f, r, poly, &centre, &size);
    double distance = v3_length(v3_sub(x, centre)) - 0.5 * size;
    if (depth < max_depth && size > INNER_RATIO * distance) {
        region child[4];
        split_region(f->corners, r, child);
        for (int k = 0; k < 4; k++)
            inner_region(f, nodes, x, nx, &child[k], depth + 1, max_depth, I);
        return;
    }
    double F = rad_point_polygon_ff(x, nx, poly, f->corners);
    if (!(F > 0.0))
        return;
    double uv[MAX_POINTS][2], w[MAX_POINTS], sum = 0.0, mean[4] = {0, 0, 0, 0}, N[4];
    int count = region_rule(f, r, true, uv, w);
    for (int q = 0; q < count; q++) {
        vec3 y = point_at(f, uv[q][0], uv[q][1]), d = v3_sub(y, x);
        double r2 = v3_dot(d, d);
        double G = fmax(v3_dot(nx, d), 0.0) * fmax(-v3_dot(f->normal, d), 0.0) / (r2 * r2);
        if (!(G > 0.0))
            continue;
        basis_at(f->corners, nodes, uv[q][0], uv[q][1], N);
        for (int j = 0; j < nodes; j++)
            mean[j] += w[q] * G * N[j];
        sum += w[q] * G;
    }
    if (!(sum > 0.0)) { /* every point behind x's plane: the region's centre stands for it */
        double cu = 0, cv = 0;
        uint32_t nc = f->corners;
        for (uint32_t k = 0; k < nc; k++)
            cu += r->p[k][0] / nc, cv += r->p[k][1] / nc;
        basis_at(f->corners, nodes, cu, cv, N);
        for (int j = 0; j < nodes; j++)
            I[j] += F * N[j];
        return;
    }
    for (int j = 0; j < nodes; j++)
        I[j] += F * mean[j] / sum;
}

/* int_f N_j(y) G(x, y) dy for f's nodes, unoccluded. */
static void inner_integral(const element_geometry *f, int nodes, vec3 x, vec3 nx, int max_depth, double I[4])
{
    I[0] = I[1] = I[2] = I[3] = 0.0;
    if (nodes == 1) { /* the constant basis: the factor itself */
        I[0] = rad_point_polygon_ff(x, nx, f->c, f->corners);
        return;
    }
    region whole = whole_element(f->corners);
    inner_region(f, nodes, x, nx, &whole, 0, max_depth, I);
}

/* Fraction of rays from `from` (a point lifted off its surface, normal
 * nx) to f's Gauss points (lifted by f's own lift, pulled toward its
 * centroid as rad_ff_end_element's ends) that pass; 1 without a ray
 * structure or when none faces. */
static double point_visibility(const galerkin_state *st, vec3 from, vec3 nx, const element_geometry *f,
                               uint64_t *rays)
{
    const rad_vis *vis = st->base.vis;
    if (!vis)
        return 1.0;
    double eps = f->lift;
    region whole = whole_element(f->corners);
    double uv[MAX_POINTS][2], w[MAX_POINTS];
    int count = region_rule(f, &whole, false, uv, w);
    rad_ray ray[MAX_POINTS];
    uint8_t occluded[MAX_POINTS];
    int cast = 0;
    for (int q = 0; q < count; q++) {
        vec3 y = point_at(f, uv[q][0], uv[q][1]);
        y = v3_add(v3_add(y, v3_scale(f->normal, eps)), v3_scale(v3_normalize(v3_sub(f->centroid, y)), eps));
        vec3 d = v3_sub(y, from);
        if (!(v3_dot(d, nx) > 0.0) || !(v3_dot(d, f->normal) < 0.0))
            continue;
        ray[cast++] = (rad_ray){from, d, 0.0, 1.0};
    }
    if (cast == 0)
        return 1.0;
    vis->backend->occluded(vis->state, ray, (size_t)cast, occluded);
    *rays += (uint64_t)cast;
    int pass = 0;
    for (int q = 0; q < cast; q++)
        pass += !occluded[q];
    return (double)pass / cast;
}

/* Element pair visibility (1 without a ray structure): the analytic
 * method's shadow-ray fraction (rad_ff_visibility), keyed on the
 * unordered pair, so that the constant basis gives the dense strategy's
 * own A F.  One value per pair, not per point: the per-point fractions
 * of a few rays were noise that the consistent mass amplified into a
 * checkerboard of +-0.2 W/m^2 on the Cornell box's floor. */
static double pair_visibility(const galerkin_state *st, uint32_t e, uint32_t f, uint64_t *rays)
{
    const rad_meshed *m = &st->base;
    if (!m->vis)
        return 1.0;
    rad_ff_request req = {.mesh = m->mesh, .vis = m->vis, .seed = m->options->seed};
    int base_rays = m->options->shadow_rays > 0 ? m->options->shadow_rays : 4;
    return rad_ff_visibility(&req, e < f ? e : f, e < f ? f : e, rad_vis_epsilon(m->mesh), base_rays, rays);
}

/* The outer rule of an element: the fine rule on each region of its
 * OUTER_LEVELS-fold split.  One rule for every element it is paired with,
 * so that at each point the factors to all elements add up to what the
 * point sees (1 in a closed scene): a row of K then sums to its node's
 * mass to rounding, and the power balance holds whatever the quadrature's
 * error on one pair (a rule chosen per pair, finer toward the pair, left
 * the rows 4e-6 off on a closed cube).  Near pairs (a shared edge, where
 * the factor has a d log d term) get no finer rule: that error falls as
 * the elements shrink, like the discretisation's. */
enum { OUTER_LEVELS = 1, OUTER_REGIONS = 4, OUTER_POINTS = OUTER_REGIONS * MAX_POINTS };

typedef struct outer_rule {
    int count;
    vec3 x[OUTER_POINTS];
    double w[OUTER_POINTS];          /* m^2 */
    double N[OUTER_POINTS][4];
} outer_rule;

static void outer_rule_of(const element_geometry *e, int nodes, outer_rule *rule)
{
    region whole = whole_element(e->corners), part[OUTER_REGIONS];
    split_region(e->corners, &whole, part);
    rule->count = 0;
    for (int k = 0; k < OUTER_REGIONS; k++) {
        double uv[MAX_POINTS][2], w[MAX_POINTS];
        int count = region_rule(e, &part[k], true, uv, w);
        for (int q = 0; q < count; q++) {
            int m = rule->count++;
            rule->x[m] = point_at(e, uv[q][0], uv[q][1]);
            rule->w[m] = w[q];
            basis_at(e->corners, nodes, uv[q][0], uv[q][1], rule->N[m]);
        }
    }
}

/* Kef[i][j] = int_e N_i(x) int_f N_j G dy dx (unoccluded) by e's outer
 * rule. */
static void outer_integral(const element_geometry *e, const outer_rule *rule, const element_geometry *f,
                           int nodes_e, int nodes_f, double Kef[4][4])
{
    double I[4];
    for (int q = 0; q < rule->count; q++) {
        inner_integral(f, nodes_f, rule->x[q], e->normal, INNER_DEPTH, I);
        for (int i = 0; i < nodes_e; i++)
            for (int j = 0; j < nodes_f; j++)
                Kef[i][j] += rule->w[q] * rule->N[q][i] * I[j];
    }
}

/* ---- setup: nodes, mass, the kernel ---- */

static int element_nodes(const galerkin_state *st, const rad_element *el)
{
    return st->method == GALERKIN_CONSTANT ? 1 : (int)el->vertex_count;
}

static uint32_t node_of(const galerkin_state *st, uint32_t e, int a)
{
    return st->method == GALERKIN_CONSTANT ? e : st->base.mesh->elements[e].vertex[a];
}

/* Local mass matrices (exact: 3 x 3 Gauss integrates the bilinear
 * N_a N_b J; the triangle's rule of degree 4 its quadratic N_a N_b), the
 * node masses, the load M E and the node reflectances.  Refuses a vertex
 * between elements of different reflectance. */
static rad_result assemble_mass(rad_context *ctx, galerkin_state *st)
{
    const rad_mesh *mesh = st->base.mesh;
    const rad_elements *el = &st->base.elements;
    size_t n = mesh->element_count;
    bool *seen = rad_alloc(ctx, RAD_MEM_SOLVER, st->dofs + 1, sizeof *seen, "galerkin: nodes seen");
    if (!seen)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (uint32_t e = 0; e < n; e++) {
        const rad_element *E = &mesh->elements[e];
        element_geometry g;
        geometry_of(mesh, e, 0.0, &g);
        int nodes = element_nodes(st, E);
        double *Me = st->mass + 16 * (size_t)e;
        region whole = whole_element(g.corners);
        double uv[MAX_POINTS][2], w[MAX_POINTS], N[4];
        int count = region_rule(&g, &whole, true, uv, w);
        for (int q = 0; q < count; q++) {
            basis_at(g.corners, nodes, uv[q][0], uv[q][1], N);
            for (int a = 0; a < nodes; a++)
                for (int b = 0; b < nodes; b++)
                    Me[4 * a + b] += w[q] * N[a] * N[b];
        }
        for (int a = 0; a < nodes; a++) {
            uint32_t i = node_of(st, e, a);
            double row = 0.0;
            for (int b = 0; b < nodes; b++)
                row += Me[4 * a + b];
            st->node_mass[i] += row;
            for (int c = 0; c < 3; c++)
                st->load[3 * (size_t)i + c] += row * el->emission[3 * (size_t)e + c];
            const double *rho = &el->reflectance[3 * (size_t)e];
            double *node_rho = &st->node_reflectance[3 * (size_t)i];
            if (!seen[i]) {
                seen[i] = true;
                memcpy(node_rho, rho, 3 * sizeof *rho);
            } else if (node_rho[0] != rho[0] || node_rho[1] != rho[1] || node_rho[2] != rho[2]) {
                vec3 p = mesh->vertices[i];
                rad_free(seen);
                return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                                "solver '%s': the vertex at (%g, %g, %g) joins elements of different "
                                "reflectance (surface '%s'); linear elements need one reflectance around "
                                "each vertex: split the surface by material",
                                st->base.options->solver, p.x, p.y, p.z,
                                st->base.scene->surfaces[E->surface].name);
            }
        }
    }
    rad_free(seen);
    /* Collocation enforces the equation at points: its load is E there,
     * the mass-weighted mean of the elements around the vertex. */
    if (st->method == GALERKIN_COLLOCATION)
        for (size_t i = 0; i < st->dofs; i++)
            for (int c = 0; c < 3; c++)
                st->load[3 * i + c] = st->node_mass[i] > 0.0 ? st->load[3 * i + c] / st->node_mass[i] : 0.0;
    return RAD_OK;
}

/* Elements coloured so that no two of one colour share a node: the rows
 * of K one element adds to are then its own within its colour, so the
 * colours run one after another, their elements in parallel, and every
 * entry sums its terms in the same order on any thread count.  Colours
 * past 63 (never on a grid mesh) are gathered in a last colour. */
enum { MAX_COLOURS = 64 };

static rad_result colour_elements(rad_context *ctx, const galerkin_state *st, uint32_t **order_out,
                                  size_t start[MAX_COLOURS + 2])
{
    const rad_mesh *mesh = st->base.mesh;
    size_t n = mesh->element_count;
    uint64_t *used = rad_alloc(ctx, RAD_MEM_SOLVER, st->dofs + 1, sizeof *used, "galerkin: colours");
    uint8_t *colour = rad_alloc(ctx, RAD_MEM_SOLVER, n + 1, sizeof *colour, "galerkin: colours");
    uint32_t *order = rad_alloc(ctx, RAD_MEM_SOLVER, n + 1, sizeof *order, "galerkin: colours");
    if (!used || !colour || !order) {
        rad_free(used);
        rad_free(colour);
        rad_free(order);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memset(start, 0, (MAX_COLOURS + 2) * sizeof *start);
    for (uint32_t e = 0; e < n; e++) {
        int nodes = element_nodes(st, &mesh->elements[e]);
        uint64_t mask = 0;
        for (int a = 0; a < nodes; a++)
            mask |= used[node_of(st, e, a)];
        int c = 0;
        while (c < MAX_COLOURS && (mask >> c & 1u))
            c++;
        colour[e] = (uint8_t)c;
        if (c < MAX_COLOURS)
            for (int a = 0; a < nodes; a++)
                used[node_of(st, e, a)] |= (uint64_t)1 << c;
        start[c + 1]++;
    }
    for (int c = 0; c <= MAX_COLOURS; c++)
        start[c + 1] += start[c];
    size_t fill[MAX_COLOURS + 1];
    memcpy(fill, start, sizeof fill);
    for (uint32_t e = 0; e < n; e++)
        order[fill[colour[e]]++] = e;
    rad_free(used);
    rad_free(colour);
    *order_out = order;
    return RAD_OK;
}

/* Galerkin: K_ij = sum over element pairs (e, f) of V_ef int_e N_i int_f N_j G. */
static rad_result assemble_galerkin(rad_context *ctx, galerkin_state *st)
{
    const rad_mesh *mesh = st->base.mesh;
    size_t n = mesh->element_count, dofs = st->dofs;
    uint32_t *order = NULL;
    size_t start[MAX_COLOURS + 2];
    rad_result r = colour_elements(ctx, st, &order, start);
    if (r != RAD_OK)
        return r;
    double plane_tol = rad_ff_plane_tolerance(mesh), eps = rad_vis_epsilon(mesh);
    uint64_t rays = 0, pairs = 0, done = 0;
    volatile int cancelled = 0; /* raised by any thread (formfactor.c's pattern) */
    for (int c = 0; c <= MAX_COLOURS && !cancelled; c++) {
        long count = (long)(start[c + 1] - start[c]);
        int threads = c < MAX_COLOURS ? st->base.threads : 1;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : rays, pairs)
        for (long k = 0; k < count; k++) {
            if (cancelled)
                continue;
            if (rad_cancelled(ctx)) {
                cancelled = 1;
                continue;
            }
            uint32_t e = order[start[c] + (size_t)k];
            element_geometry ge, gf;
            geometry_of(mesh, e, eps, &ge);
            int nodes = element_nodes(st, &mesh->elements[e]);
            outer_rule rule;
            outer_rule_of(&ge, nodes, &rule);
            for (uint32_t f = 0; f < n; f++) {
                if (f == e || !rad_ff_facing(mesh, e, f, plane_tol))
                    continue;
                pairs++;
                double V = pair_visibility(st, e, f, &rays);
                if (!(V > 0.0))
                    continue;
                geometry_of(mesh, f, eps, &gf);
                double Kef[4][4] = {{0}};
                int nodes_f = element_nodes(st, &mesh->elements[f]);
                outer_integral(&ge, &rule, &gf, nodes, nodes_f, Kef);
                for (int a = 0; a < nodes; a++) {
                    double *row = st->K + (size_t)node_of(st, e, a) * dofs;
                    for (int b = 0; b < nodes_f; b++)
                        row[node_of(st, f, b)] += V * Kef[a][b];
                }
            }
        }
        done += (uint64_t)count;
        rad_progress(ctx, "galerkin kernel", done, n);
    }
    rad_free(order);
    st->base.ff_stats.rays = rays;
    st->base.ff_stats.pairs = pairs;
    if (cancelled)
        return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "galerkin kernel: interrupted");
    return RAD_OK;
}

/* Collocation points: each vertex moved 1e-6 of the way to the mean of
 * its elements' centroids, and the mean of their normals.  At a crease
 * the kernel jumps (from the edge itself the other wall is seen edge-on,
 * a factor of 0; from any point inside, nearly 1/2 of it): the moved
 * point takes the surface's one-sided limit, as the elements' own
 * integrals do. */
static rad_result collocation_points(rad_context *ctx, galerkin_state *st)
{
    const rad_mesh *mesh = st->base.mesh;
    double *count = rad_alloc(ctx, RAD_MEM_SOLVER, st->dofs + 1, sizeof *count, "collocation: points");
    vec3 *centre = rad_alloc(ctx, RAD_MEM_SOLVER, st->dofs + 1, sizeof *centre, "collocation: points");
    double *lift = rad_alloc(ctx, RAD_MEM_SOLVER, st->dofs + 1, sizeof *lift, "collocation: points");
    if (!count || !centre || !lift) {
        rad_free(count);
        rad_free(centre);
        rad_free(lift);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (uint32_t e = 0; e < mesh->element_count; e++) {
        const rad_element *el = &mesh->elements[e];
        for (uint32_t a = 0; a < el->vertex_count; a++) {
            uint32_t i = el->vertex[a];
            count[i] += 1.0;
            centre[i] = v3_add(centre[i], el->centroid);
            st->point_normal[i] = v3_add(st->point_normal[i], el->normal);
            lift[i] = fmax(lift[i], rad_vis_epsilon(mesh) + rad_element_bend(mesh, el));
        }
    }
    for (size_t i = 0; i < st->dofs; i++) {
        vec3 v = mesh->vertices[i];
        if (count[i] > 0.0) {
            vec3 toward = v3_sub(v3_scale(centre[i], 1.0 / count[i]), v);
            st->point[i] = v3_add(v, v3_scale(toward, 1e-6));
            st->point_normal[i] = v3_normalize(st->point_normal[i]);
            /* Shadow rays start off the surface by the lift and twice that
             * into it: lifted only, a point beside an edge where the
             * surfaces meet at less than 90 degrees (a tetrahedron's 70.5)
             * would start behind the other surface. */
            /* Inside a surface the elements' centroids average to the
             * vertex itself, and `toward` is rounding: no pull there. */
            vec3 n = st->point_normal[i], along = v3_sub(toward, v3_scale(n, v3_dot(n, toward)));
            double d = v3_length(along);
            vec3 in = d > 1e-3 * lift[i] ? v3_scale(along, 2.0 * lift[i] / d) : (vec3){0, 0, 0};
            st->ray_origin[i] = v3_add(v3_add(st->point[i], v3_scale(st->point_normal[i], lift[i])), in);
        } else {
            st->point[i] = st->ray_origin[i] = v;
        }
    }
    rad_free(count);
    rad_free(centre);
    rad_free(lift);
    return RAD_OK;
}

/* Collocation: C_kj = sum over f of V(x_k, f) int_f N_j G(x_k, .).  Rows
 * are independent. */
static rad_result assemble_collocation(rad_context *ctx, galerkin_state *st)
{
    const rad_mesh *mesh = st->base.mesh;
    size_t n = mesh->element_count, dofs = st->dofs;
    rad_result r = collocation_points(ctx, st);
    if (r != RAD_OK)
        return r;
    double eps = rad_vis_epsilon(mesh);
    uint64_t rays = 0, pairs = 0;
    volatile int cancelled = 0; /* raised by any thread (formfactor.c's pattern) */
    /* The start reported from the calling thread: a cancellation asked at
     * this stage is seen by the first row of every thread, whichever rows
     * thread 0 (the one that reports within the loop) happens to get. */
    rad_progress(ctx, "collocation kernel", 0, dofs);
#pragma omp parallel for schedule(dynamic, 16) num_threads(st->base.threads) reduction(+ : rays, pairs)
    for (long k = 0; k < (long)dofs; k++) {
        if (cancelled)
            continue;
        if (rad_cancelled(ctx)) {
            cancelled = 1;
            continue;
        }
#ifdef _OPENMP
        if (omp_get_thread_num() == 0 && (k & 63) == 0)
#else
        if ((k & 63) == 0)
#endif
            rad_progress(ctx, "collocation kernel", (uint64_t)k, dofs);
        vec3 x = st->point[k], nx = st->point_normal[k];
        if (v3_length(nx) == 0.0) /* a vertex of no element */
            continue;
        double *row = st->K + (size_t)k * dofs;
        for (uint32_t f = 0; f < n; f++) {
            element_geometry gf;
            geometry_of(mesh, f, eps, &gf);
            const rad_element *fe = &mesh->elements[f];
            /* Only what lies in front of the point's plane, seen from the front. */
            if (!(v3_dot(v3_sub(x, gf.centroid), gf.normal) > 0.0))
                continue;
            double I[4];
            inner_integral(&gf, (int)fe->vertex_count, x, nx, COLLOCATION_DEPTH, I);
            if (!(I[0] + I[1] + I[2] + I[3] > 0.0))
                continue;
            pairs++;
            double V = point_visibility(st, st->ray_origin[k], nx, &gf, &rays);
            for (uint32_t b = 0; b < fe->vertex_count; b++)
                row[fe->vertex[b]] += V * I[b];
        }
    }
    st->base.ff_stats.rays = rays;
    st->base.ff_stats.pairs = pairs;
    if (cancelled)
        return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "collocation kernel: interrupted");
    return RAD_OK;
}

/* Row sums of K over the node masses (Galerkin) or as they are
 * (collocation): the fraction of the hemisphere each node sees, 1 in a
 * closed scene up to the quadrature, into the form-factor stats. */
static void kernel_stats(galerkin_state *st)
{
    rad_ff_stats *s = &st->base.ff_stats;
    double lo = INFINITY, hi = -INFINITY, sum = 0.0;
    size_t counted = 0;
    for (size_t i = 0; i < st->dofs; i++) {
        if (!(st->node_mass[i] > 0.0))
            continue;
        double row = 0.0;
        for (size_t j = 0; j < st->dofs; j++)
            row += st->K[i * st->dofs + j];
        if (st->method != GALERKIN_COLLOCATION)
            row /= st->node_mass[i];
        lo = fmin(lo, row), hi = fmax(hi, row), sum += row, counted++;
    }
    s->row_sum_min = counted ? lo : 0.0;
    s->row_sum_max = counted ? hi : 0.0;
    s->row_sum_mean = counted ? sum / (double)counted : 0.0;
}

static void galerkin_destroy(void *state)
{
    galerkin_state *st = state;
    if (!st)
        return;
    rad_meshed_free(&st->base);
    rad_free(st->K);
    rad_free(st->mass);
    rad_free(st->node_mass);
    rad_free(st->node_reflectance);
    rad_free(st->load);
    rad_free(st->node_radiosity);
    rad_free(st->point);
    rad_free(st->point_normal);
    rad_free(st->ray_origin);
    rad_free(st);
}

static bool galerkin_solver_info(size_t index, const char **name, const char **description)
{
    if (index >= sizeof galerkin_solvers / sizeof galerkin_solvers[0])
        return false;
    *name = galerkin_solvers[index].name;
    *description = galerkin_solvers[index].description;
    return true;
}

static rad_result galerkin_create(rad_context *ctx, const rad_scene *scene, const rad_options *o, void **out)
{
    *out = NULL;
    if (o->closure_correction)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "rad_options.closure_correction rescales form factors, and solver '%s' integrates "
                        "its kernel by quadrature: use a dense solver or hierarchical",
                        o->solver);
    galerkin_state *st = rad_alloc(ctx, RAD_MEM_SOLVER, 1, sizeof *st, "solution: galerkin state");
    if (!st)
        return RAD_ERROR_OUT_OF_MEMORY;
    st->method = strcmp(o->solver, "galerkin-constant") == 0 ? GALERKIN_CONSTANT
                 : strcmp(o->solver, "collocation") == 0     ? GALERKIN_COLLOCATION
                                                             : GALERKIN_LINEAR;
    rad_meshed *m = &st->base;
    rad_result r = rad_meshed_init(ctx, scene, o, m);
    if (r != RAD_OK) {
        rad_free(st);
        return r;
    }
    size_t n = m->mesh->element_count;
    st->dofs = st->method == GALERKIN_CONSTANT ? n : m->mesh->vertex_count;
    double bytes = 8.0 * (double)st->dofs * (double)st->dofs;
    if (bytes > o->max_memory_bytes) {
        r = rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                     "solver '%s': its kernel of %zu x %zu unknowns needs %.2f GiB, above the memory limit of "
                     "%.2f GiB (rad_options.max_memory_bytes); use fewer elements (--elements, --mesh-size)",
                     o->solver, st->dofs, st->dofs, bytes / 1073741824.0, o->max_memory_bytes / 1073741824.0);
        galerkin_destroy(st);
        return r;
    }
    size_t d = st->dofs + 1;
    st->K = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, st->dofs * st->dofs + 1, sizeof *st->K, "galerkin: kernel");
    st->mass = rad_alloc(ctx, RAD_MEM_SOLVER, 16 * n + 1, sizeof *st->mass, "galerkin: mass");
    st->node_mass = rad_alloc(ctx, RAD_MEM_SOLVER, d, sizeof *st->node_mass, "galerkin: node masses");
    st->node_reflectance = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * d, sizeof(double), "galerkin: node reflectance");
    st->load = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * d, sizeof *st->load, "galerkin: load");
    st->node_radiosity = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * d, sizeof(double), "galerkin: node radiosity");
    if (st->method == GALERKIN_COLLOCATION) {
        st->point = rad_alloc(ctx, RAD_MEM_SOLVER, d, sizeof *st->point, "collocation: points");
        st->point_normal = rad_alloc(ctx, RAD_MEM_SOLVER, d, sizeof *st->point_normal, "collocation: normals");
        st->ray_origin = rad_alloc(ctx, RAD_MEM_SOLVER, d, sizeof *st->ray_origin, "collocation: ray origins");
    }
    if (!st->K || !st->mass || !st->node_mass || !st->node_reflectance || !st->load || !st->node_radiosity ||
        (st->method == GALERKIN_COLLOCATION && (!st->point || !st->point_normal || !st->ray_origin))) {
        galerkin_destroy(st);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    m->ff_stats.method = st->method == GALERKIN_COLLOCATION ? "collocation kernel (exact point-polygon factors)"
                                                            : "galerkin kernel (exact point-polygon factors)";
    double t0 = rad_seconds();
    r = assemble_mass(ctx, st);
    if (r == RAD_OK)
        r = st->method == GALERKIN_COLLOCATION ? assemble_collocation(ctx, st) : assemble_galerkin(ctx, st);
    m->ff_stats.seconds = m->seconds.form_factors = rad_seconds() - t0;
    if (r != RAD_OK) {
        galerkin_destroy(st);
        return r;
    }
    kernel_stats(st);
    *out = st;
    return RAD_OK;
}

/* ---- solving ---- */

/* y = M x (3 channels), from the elements' local matrices. */
static void mass_apply(const galerkin_state *st, const double *x, double *y)
{
    const rad_mesh *mesh = st->base.mesh;
    memset(y, 0, 3 * st->dofs * sizeof *y);
    for (uint32_t e = 0; e < mesh->element_count; e++) {
        int nodes = element_nodes(st, &mesh->elements[e]);
        const double *Me = st->mass + 16 * (size_t)e;
        for (int a = 0; a < nodes; a++) {
            size_t i = node_of(st, e, a);
            for (int b = 0; b < nodes; b++) {
                size_t j = node_of(st, e, b);
                for (int c = 0; c < 3; c++)
                    y[3 * i + c] += Me[4 * a + b] * x[3 * j + c];
            }
        }
    }
}

/* Solve M x = b (3 channels at once, each its own conjugate-gradient
 * recurrence) from the guess in x, to 1e-14 of |b|: far below any
 * tolerance of the outer iteration.  work: 12 dofs doubles.  Nodes of no
 * element (mass 0) keep x = 0. */
static void mass_solve(const galerkin_state *st, const double *b, double *x, double *work)
{
    size_t n3 = 3 * st->dofs;
    double *r = work, *p = work + n3, *q = work + 2 * n3, *z = work + 3 * n3;
    mass_apply(st, x, q);
    double rr[3] = {0, 0, 0}, bb[3] = {0, 0, 0};
    for (size_t k = 0; k < n3; k++) {
        size_t i = k / 3;
        r[k] = st->node_mass[i] > 0.0 ? b[k] - q[k] : 0.0;
        /* Jacobi preconditioner by the lumped mass. */
        z[k] = st->node_mass[i] > 0.0 ? r[k] / st->node_mass[i] : 0.0;
        p[k] = z[k];
        rr[k % 3] += r[k] * z[k];
        bb[k % 3] += b[k] * b[k];
    }
    for (int it = 0; it < 500; it++) {
        bool done = true;
        for (int c = 0; c < 3; c++)
            done = done && !(rr[c] > 1e-28 * bb[c]);
        if (done)
            break;
        mass_apply(st, p, q);
        double pq[3] = {0, 0, 0};
        for (size_t k = 0; k < n3; k++)
            pq[k % 3] += p[k] * q[k];
        double alpha[3], rr_new[3] = {0, 0, 0};
        for (int c = 0; c < 3; c++)
            alpha[c] = pq[c] > 0.0 ? rr[c] / pq[c] : 0.0;
        for (size_t k = 0; k < n3; k++) {
            x[k] += alpha[k % 3] * p[k];
            r[k] -= alpha[k % 3] * q[k];
            z[k] = st->node_mass[k / 3] > 0.0 ? r[k] / st->node_mass[k / 3] : 0.0;
            rr_new[k % 3] += r[k] * z[k];
        }
        for (size_t k = 0; k < n3; k++) {
            int c = (int)(k % 3);
            p[k] = z[k] + (rr[c] > 0.0 ? rr_new[c] / rr[c] : 0.0) * p[k];
        }
        memcpy(rr, rr_new, sizeof rr);
    }
}

/* y = K x, 3 channels, rows in parallel (each row's sum in one order). */
static void kernel_apply(const galerkin_state *st, const double *x, double *y)
{
    size_t dofs = st->dofs;
#pragma omp parallel for schedule(static) num_threads(st->base.threads)
    for (long i = 0; i < (long)dofs; i++) {
        const double *row = st->K + (size_t)i * dofs;
        double s[3] = {0, 0, 0};
        for (size_t j = 0; j < dofs; j++) {
            s[0] += row[j] * x[3 * j];
            s[1] += row[j] * x[3 * j + 1];
            s[2] += row[j] * x[3 * j + 2];
        }
        memcpy(&y[3 * (size_t)i], s, sizeof s);
    }
}

/* Element means of the node values (the view's element radiosity):
 * B_e = sum_a B_a int_e N_a / A_e. */
static void element_means(galerkin_state *st)
{
    const rad_mesh *mesh = st->base.mesh;
    double *B = st->base.elements.radiosity;
    for (uint32_t e = 0; e < mesh->element_count; e++) {
        int nodes = element_nodes(st, &mesh->elements[e]);
        const double *Me = st->mass + 16 * (size_t)e;
        double sum[3] = {0, 0, 0}, area = 0.0;
        for (int a = 0; a < nodes; a++) {
            double m = 0.0;
            for (int b = 0; b < nodes; b++)
                m += Me[4 * a + b];
            area += m;
            for (int c = 0; c < 3; c++)
                sum[c] += m * st->node_radiosity[3 * (size_t)node_of(st, e, a) + c];
        }
        for (int c = 0; c < 3; c++)
            B[3 * (size_t)e + c] = area > 0.0 ? sum[c] / area : 0.0;
    }
}

static rad_result galerkin_solve(rad_context *ctx, void *state, const rad_step_hook *hook)
{
    galerkin_state *st = state;
    rad_meshed *m = &st->base;
    const rad_options *o = m->options;
    rad_system sys;
    rad_solve_params p;
    rad_meshed_begin(m, o->solver, hook, &sys, &p);
    double t0 = rad_seconds();
    size_t n3 = 3 * st->dofs;
    double *KB = rad_alloc(ctx, RAD_MEM_SOLVER, n3 + 1, sizeof *KB, "galerkin: iterate");
    double *rhs = rad_alloc(ctx, RAD_MEM_SOLVER, n3 + 1, sizeof *rhs, "galerkin: iterate");
    double *work = rad_alloc(ctx, RAD_MEM_SOLVER, 4 * n3 + 1, sizeof *work, "galerkin: iterate");
    if (!KB || !rhs || !work) {
        rad_free(KB);
        rad_free(rhs);
        rad_free(work);
        rad_meshed_end(m, RAD_ERROR_OUT_OF_MEMORY, t0);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    bool galerkin = st->method != GALERKIN_COLLOCATION;
    double rho_max = 0.0, emitted = 0.0;
    for (size_t k = 0; k < n3; k++) {
        rho_max = fmax(rho_max, st->node_reflectance[k]);
        emitted += galerkin ? fabs(st->load[k]) : st->node_mass[k / 3] * fabs(st->load[k]);
    }
    int max_iterations = o->max_iterations;
    if (max_iterations <= 0) { /* as the gathering solvers bound theirs (rad_solve_bound) */
        double bound = rho_max > 0.0 && rho_max < 1.0 ? 2.0 * log(o->tolerance) / log(rho_max) + 10.0 : 10.0;
        max_iterations = bound < 1e4 ? (int)ceil(bound) : 10000;
    }
    /* B_0: E (its projection for Galerkin). */
    memset(st->node_radiosity, 0, n3 * sizeof *st->node_radiosity);
    if (galerkin)
        mass_solve(st, st->load, st->node_radiosity, work);
    else
        memcpy(st->node_radiosity, st->load, n3 * sizeof *st->load);
    rad_result r = RAD_OK;
    double residual = INFINITY;
    int it = 0;
    for (;; it++) {
        /* rhs = M E + R K B (Galerkin) or E + R C B (collocation); the
         * residual of B is what it leaves unbalanced, over the power emitted. */
        kernel_apply(st, st->node_radiosity, KB);
        for (size_t k = 0; k < n3; k++)
            rhs[k] = st->load[k] + st->node_reflectance[k] * KB[k];
        if (galerkin)
            mass_apply(st, st->node_radiosity, work);
        double unbalanced = 0.0;
        for (size_t k = 0; k < n3; k++)
            unbalanced += galerkin ? fabs(rhs[k] - work[k])
                                   : st->node_mass[k / 3] * fabs(rhs[k] - st->node_radiosity[k]);
        residual = emitted > 0.0 ? unbalanced / emitted : 0.0;
        if (residual <= o->tolerance || it >= max_iterations)
            break;
        if (rad_cancelled(ctx)) {
            r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "%s: interrupted", o->solver);
            break;
        }
        if (galerkin)
            mass_solve(st, rhs, st->node_radiosity, work);
        else
            memcpy(st->node_radiosity, rhs, n3 * sizeof *rhs);
        element_means(st);
        if (hook->fn) {
            rad_solve_step step = {it + 1, rad_seconds() - t0, residual, NAN};
            if (hook->fn(hook->user, &step, true)) {
                r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "%s: stopped", o->solver);
                break;
            }
        }
    }
    element_means(st);
    /* Absorbed power: int (1 - rho) H over the surfaces, H = K B per node
     * (Galerkin: the node's share of the irradiance; collocation: the
     * irradiance at the point, times the node's mass). */
    kernel_apply(st, st->node_radiosity, KB);
    double absorbed = 0.0;
    for (size_t k = 0; k < n3; k++)
        absorbed += (1.0 - st->node_reflectance[k]) * KB[k] * (galerkin ? 1.0 : st->node_mass[k / 3]);
    m->solve_stats.absorbed = absorbed / 3.0;
    m->solve_stats.iterations = it;
    m->solve_stats.residual = residual;
    m->solve_stats.converged = residual <= o->tolerance;
    m->solve_stats.iteration_limit = max_iterations;
    if (r == RAD_OK && !m->solve_stats.converged)
        snprintf(m->solve_stats.warning, sizeof m->solve_stats.warning,
                 "%s: stopped at %d iterations with the residual at %.3g, above the tolerance %.3g", o->solver,
                 it, residual, o->tolerance);
    rad_free(KB);
    rad_free(rhs);
    rad_free(work);
    rad_meshed_end(m, r, t0);
    return r;
}

static void galerkin_view(const void *state, rad_solution_view *v)
{
    const galerkin_state *st = state;
    rad_meshed_view(&st->base, v);
    v->vertex_radiosity = st->method == GALERKIN_CONSTANT ? NULL : st->node_radiosity;
}

void rad_galerkin_get_matrices(const void *state, rad_galerkin_matrices *out)
{
    const galerkin_state *st = state;
    *out = (rad_galerkin_matrices){st->dofs, st->K, st->mass, st->node_mass, st->node_radiosity};
}

const rad_strategy rad_strategy_galerkin = {
    "galerkin",
    "basis functions per node (constant, or linear/bilinear per vertex): the Galerkin system "
    "(M - rho K) B = M E, or point collocation at the vertices",
    RAD_HAS_UNIFORM_MESH | RAD_CAN_LIGHTS | RAD_CAN_PROGRESS_IMAGES,
    galerkin_solver_info,
    galerkin_create,
    galerkin_solve,
    galerkin_view,
    galerkin_destroy,
};
