/*
 * ff_analytic.c -- element-to-element form factors by the exact
 * point-to-polygon formula, integrated over the receiving element by
 * adaptive Gauss quadrature, times a visibility fraction from shadow rays
 * (the lecture notes' "Form Factor - Polygonal"; Baum, Rushmeier & Winget,
 * "Improving radiosity solutions through the use of analytically determined
 * form-factors", SIGGRAPH 1989).
 *
 *     F_ij = V_ij / A_i  int_{A_i} F_{dA(x) -> A_j} dA(x)
 *
 * Each unordered pair is computed once, integrating over the SMALLER of the
 * two elements (the inner, analytic integral is exact over the larger), and
 * the other direction follows from reciprocity, A_i F_ij = A_j F_ji: so the
 * matrix is reciprocal to rounding and costs half.
 *
 * Quadrature.  The integrand is smooth except near the source, where it
 * varies on the scale of the distance d from the source; a q x q Gauss rule
 * on a region of diameter h errs like (h / 2d)^(2q).  Regions closer than
 * one diameter are split in four (to depth 4), then
 *
 *     d/h >= 2.5 : 2x2 Gauss          otherwise : 4x4 Gauss
 *
 * Measured on the reference cases (parallel and perpendicular squares, the
 * unit cube, coaxial 64-gons) at 300 to 8000 elements, the worst relative
 * error is 3e-6; a 1-point rule anywhere biases results by 1e-4 to 1e-3
 * (the midpoint rule underestimates the convex 1/r^2 falloff).  Near
 * regions had a 3x3 rule while F was stored as float: on the unit cube at
 * 2x2 and 3x3 elements a face that left single factors 1.3e-5 off and the
 * radiosity 2.8e-6 off the closed form; 4x4 gives 1e-6 and 1.2e-7
 * (test_mesh_ff_solve, test_cube_every_digit), for 5% more time on a
 * 2,000-element Cornell box (`radiosity viewfactors --elements 2000
 * --threads 1`: 2.41-2.52 s user before, 2.57-2.64 s after).
 *
 * Far pairs (centroids FAR_RATIO larger diameters apart, each wholly in
 * front of the other) take 2x2 x 2x2 Gauss on the point kernel instead:
 * symmetric, so reciprocal too.
 *
 * Visibility without rays.  occluders.c classifies each pair from the ray
 * primitives' planes: clear (the unoccluded factor), blocked (0), or
 * partial with the list of primitives that may block it; then each Gauss
 * point (4x4: the integrand has kinks where shadow edges cross the
 * receiver) gets the exact factor of the source minus the blockers'
 * shadows (rad_point_polygon_ff_visible).  The View3D box
 * (bench/view3d_box.sh, 5,406 elements) then casts no ray and its rows
 * sum to 1 within 9.7e-5 (1.3e-3 with rays).  Only pairs the classification
 * cannot decide (too many planes, bent primitives, too many blockers) take
 * the shadow rays below.
 *
 * Visibility by rays.  The unoccluded factor is multiplied by the fraction of
 * shadow rays that pass between stratified random points of the two
 * elements (rad_ff_rays, visibility.c; ends lifted off their surfaces).  A
 * pilot of shadow_rays / 2 rays decides how many fresh rays estimate the
 * fraction (shadow_rays, or 4x that where the pilot disagrees); the pilot is
 * never part of the estimate, which keeps it unbiased.  Where the pilot
 * disagrees, the source is split in four (to depth 2) and each piece gets
 * its own exact unoccluded factor and its own visibility: the product of a
 * mean factor and a mean visibility is only exact when the two do not vary
 * together across the pair, and splitting where visibility changes is what
 * makes them not.  Measured on the occluded squares (4 seeds, 500 to
 * 8,000 elements) the error is noise either way (rms 6e-5 at 2,000
 * elements, 2.5e-5 at 8,000) for 15-25% more rays: that case's kernel
 * barely varies across the shadow.  Nor does it on the Cornell box's floor
 * (elements partly under the blocks): at 1,000 elements the floor's
 * gathered irradiance is within 0.13% of a brute-force gather of 262,144
 * rays per element (docs/methods.md, issue #3).  Rays are keyed on (seed, pair): the result does
 * not depend on the thread count.
 */
#include "formfactor/formfactor.h"

#include <stdlib.h>
#include <string.h>

/* Gauss-Legendre nodes and weights on [0, 1], orders 1..4. */
static const double gauss_x[5][4] = {
    {0},
    {0.5},
    {0.21132486540518713, 0.78867513459481287},
    {0.11270166537925831, 0.5, 0.88729833462074169},
    {0.06943184420297371, 0.33000947820757187, 0.66999052179242813, 0.93056815579702629},
};
static const double gauss_w[5][4] = {
    {0},
    {1.0},
    {0.5, 0.5},
    {0.27777777777777778, 0.44444444444444444, 0.27777777777777778},
    {0.17392742256872693, 0.32607257743127307, 0.32607257743127307, 0.17392742256872693},
};

/* An element as the kernels see it. */
typedef struct elem_geom {
    vec3 corner[4];
    uint32_t corners;
    vec3 normal;
    vec3 centroid;
    double area;
    double radius;   /* max centroid-to-corner distance, m */
    double diameter; /* longest corner-to-corner distance, m */
    vec3 gauss_point[4];  /* the 2x2 Gauss rule over the element (far pairs) */
    double gauss_weight[4]; /* m^2: weight x Jacobian, summing to the area */
} elem_geom;

static void geom_init(elem_geom *g, const rad_mesh *mesh, const rad_element *e)
{
    g->corners = e->vertex_count;
    for (uint32_t k = 0; k < e->vertex_count; k++)
        g->corner[k] = mesh->vertices[e->vertex[k]];
    g->normal = e->normal;
    g->centroid = e->centroid;
    g->area = e->area;
    g->radius = 0.0;
    g->diameter = 0.0;
    for (uint32_t a = 0; a < g->corners; a++) {
        g->radius = fmax(g->radius, v3_length(v3_sub(g->corner[a], g->centroid)));
        for (uint32_t b = a + 1; b < g->corners; b++)
            g->diameter = fmax(g->diameter, v3_length(v3_sub(g->corner[a], g->corner[b])));
    }
    /* The 2x2 Gauss rule of integrate(), here over the whole element. */
    rad_element_gauss(mesh, e, 2, g->gauss_point, g->gauss_weight);
}

/* Every corner of a strictly in front of b's plane. */
static bool all_in_front(const elem_geom *a, const elem_geom *b)
{
    for (uint32_t k = 0; k < a->corners; k++)
        if (!(v3_dot(b->normal, v3_sub(a->corner[k], b->centroid)) > 0.0))
            return false;
    return true;
}

/* Pairs whose centroids are this many times the larger element's
 * diameter apart, each wholly in front of the other, are far: 2x2 x 2x2
 * Gauss on the point kernel instead of 2x2 Gauss over the receiver with
 * the exact point-to-polygon factor.  The closed unit box, faces 20 x 20
 * and 30 x 30 (bench/view3d_box.py without its cube): rows within 1.35e-5
 * of 1 (9.9e-6 with the exact inner integral everywhere; 4.2e-5 at 2),
 * for 2.7x less time on the pairs. */
#define FAR_RATIO 3.0

/* A partial pair seen through less than this fraction of its unoccluded
 * factor is hidden whole: the leaks measured on the generated offices were
 * 1e-16 to 1e-9 of it, a real gap that small is beyond any use. */
#define HIDDEN_WHOLE 1e-6

/* The power coupling A_i F_ij (m^2, unoccluded) of a far pair by the 2x2 x
 * 2x2 Gauss product rule on the point-to-point kernel
 * cos cos / (pi r^2); symmetric, so reciprocal by construction. */
static double far_coupling(const elem_geom *a, const elem_geom *b)
{
    double sum = 0.0;
    for (int p = 0; p < 4; p++)
        for (int q = 0; q < 4; q++) {
            vec3 r = v3_sub(b->gauss_point[q], a->gauss_point[p]);
            double r2 = v3_dot(r, r);
            sum += a->gauss_weight[p] * b->gauss_weight[q] * v3_dot(a->normal, r) * -v3_dot(b->normal, r) /
                   (r2 * r2);
        }
    return sum / M_PI;
}

/* int over the region (3 or 4 corners, a piece of the receiver) of
 * F_{dA -> source}.  Quads use the bilinear map with its Jacobian;
 * triangles the collapsed square (s, t) = (u, (1-u) v), Jacobian 2A(1-u). */
/* F_{dA(p) -> source}, unoccluded, or with `blockers` of the part no
 * blocker hides (-1 sets *failed). */
static double point_ff(vec3 p, vec3 normal, const elem_geom *src, const rad_ff_blockers *blockers,
                       bool *failed)
{
    if (!blockers)
        return rad_point_polygon_ff(p, normal, src->corner, src->corners);
    double f = rad_point_polygon_ff_visible(p, normal, src->corner, src->corners, src->normal, blockers);
    if (f < 0.0)
        *failed = true;
    return f;
}

static double integrate(const vec3 *region, uint32_t corners, vec3 normal, const elem_geom *src,
                        int depth, const rad_ff_blockers *blockers, bool *failed)
{
    vec3 c = v3(0, 0, 0);
    double diam = 0.0;
    for (uint32_t k = 0; k < corners; k++) {
        c = v3_add(c, region[k]);
        for (uint32_t m = k + 1; m < corners; m++)
            diam = fmax(diam, v3_length(v3_sub(region[k], region[m])));
    }
    c = v3_scale(c, 1.0 / corners);
    double d = v3_length(v3_sub(c, src->centroid)) - src->radius;
    double ratio = d / diam;
    if (ratio < 1.0 && depth < 4) {
        vec3 sub[4][4];
        rad_ff_split4(region, corners, sub);
        double sum = 0.0;
        for (int k = 0; k < 4; k++)
            sum += integrate(sub[k], corners, normal, src, depth + 1, blockers, failed);
        return sum;
    }
    /* Where blockers hide part of the source the integrand has kinks (the
     * shadow's edges cross the region): 4x4 there (the View3D box at
     * 2,406 elements: rows within 1.7e-4 of 1; 2x2: 6.1e-4). */
    int q = ratio >= 2.5 && !blockers ? 2 : 4;
    double sum = 0.0;
    if (corners == 4) {
        vec3 e = v3_sub(region[1], region[0]), g = v3_sub(region[3], region[0]);
        vec3 h = v3_add(v3_sub(region[2], region[1]), v3_sub(region[0], region[3]));
        for (int a = 0; a < q; a++)
            for (int b = 0; b < q; b++) {
                double s = gauss_x[q][a], t = gauss_x[q][b];
                vec3 p = v3_add(region[0], v3_add(v3_scale(e, s), v3_add(v3_scale(g, t), v3_scale(h, s * t))));
                vec3 ds = v3_add(e, v3_scale(h, t)), dt = v3_add(g, v3_scale(h, s));
                double jac = v3_length(v3_cross(ds, dt));
                sum += gauss_w[q][a] * gauss_w[q][b] * jac * point_ff(p, normal, src, blockers, failed);
            }
    } else {
        vec3 e1 = v3_sub(region[1], region[0]), e2 = v3_sub(region[2], region[0]);
        double twice_area = v3_length(v3_cross(e1, e2));
        for (int a = 0; a < q; a++)
            for (int b = 0; b < q; b++) {
                double u = gauss_x[q][a], v = gauss_x[q][b];
                vec3 p = v3_add(region[0], v3_add(v3_scale(e1, u), v3_scale(e2, (1.0 - u) * v)));
                sum += gauss_w[q][a] * gauss_w[q][b] * twice_area * (1.0 - u) *
                       point_ff(p, normal, src, blockers, failed);
            }
    }
    return sum;
}


/* Source subdivision where visibility is partial (the notes: "If visibility
 * is not constant subdivide and recompute").  Returns A_recv F(recv -> piece)
 * with occlusion: the exact unoccluded integral over the receiver times the
 * fraction of fresh shadow rays that pass.  A pilot of half the base rays
 * decides first: where it disagrees and depth remains, the piece is split in
 * four and each child judged on its own; the estimate never reuses the
 * pilot (see visibility.c), so every leaf is unbiased. */
enum { SOURCE_SPLIT_DEPTH = 2 };

static double occluded_factor(const rad_ff_request *req, const elem_geom *recv,
                              const rad_ff_end *recv_end, const vec3 *piece, uint32_t corners,
                              const rad_ff_end *src_element, rad_rng *rng, int base_rays, int depth,
                              uint64_t *rays)
{
    elem_geom src;
    src.corners = corners;
    src.centroid = v3(0, 0, 0);
    for (uint32_t k = 0; k < corners; k++) {
        src.corner[k] = piece[k];
        src.centroid = v3_add(src.centroid, piece[k]);
    }
    src.centroid = v3_scale(src.centroid, 1.0 / corners);
    src.radius = 0.0;
    for (uint32_t k = 0; k < corners; k++)
        src.radius = fmax(src.radius, v3_length(v3_sub(piece[k], src.centroid)));
    double f = integrate(recv->corner, recv->corners, recv->normal, &src, 0, NULL, NULL);
    if (!(f > 0.0) || !req->vis)
        return f > 0.0 ? f : 0.0;
    rad_ff_end end = *src_element;
    memcpy(end.corner, piece, corners * sizeof *piece);
    int pilot_cast, cast;
    int pilot = rad_ff_rays(req->vis, recv_end, &end, base_rays / 2 > 0 ? base_rays / 2 : 1, rng, rays,
                            &pilot_cast);
    bool partial = pilot_cast > 0 && pilot > 0 && pilot < pilot_cast;
    if (partial && depth < SOURCE_SPLIT_DEPTH) {
        vec3 sub[4][4];
        rad_ff_split4(piece, corners, sub);
        double sum = 0.0;
        for (int k = 0; k < 4; k++)
            sum += occluded_factor(req, recv, recv_end, sub[k], corners, src_element, rng, base_rays,
                                   depth + 1, rays);
        return sum;
    }
    int pass = rad_ff_rays(req->vis, recv_end, &end, partial ? 4 * base_rays : base_rays, rng, rays, &cast);
    return cast > 0 ? f * pass / cast : 0.0; /* no facing ray, even between the facing parts (visibility.c) */
}

/* What every pair reads. */
typedef struct analytic_shared {
    int base_rays;       /* shadow rays per pair before the pilot's verdict */
    double eps;          /* m: the ray-end lift, rad_vis_epsilon (0 without visibility) */
    const rad_ff_occluders *occ; /* clear / blocked / partial pairs (in this block); NULL: all partial */
    elem_geom *geom;     /* per element (in this block) */
} analytic_shared;

static rad_result analytic_prepare(rad_context *ctx, const rad_ff_request *req, void **shared)
{
    const rad_mesh *mesh = req->mesh;
    size_t n = mesh->element_count;
    /* One block: this header, the element table, then the occluder
     * tables (with visibility). */
    size_t header = (sizeof(analytic_shared) + 15) / 16 * 16;
    void *block = NULL;
    const rad_ff_occluders *occ = NULL;
    rad_result r = req->vis ? rad_ff_occluders_build(ctx, mesh, header + n * sizeof(elem_geom), &block, &occ)
                            : RAD_OK;
    if (!req->vis)
        block = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, 1, header + n * sizeof(elem_geom), "form factors: element table");
    if (r != RAD_OK || !block)
        return RAD_ERROR_OUT_OF_MEMORY;
    analytic_shared *a = block;
    a->occ = occ;
    a->geom = (elem_geom *)((unsigned char *)block + header);
    a->base_rays = req->shadow_rays > 0 ? req->shadow_rays : 4;
    if (a->base_rays > RAD_FF_MAX_BASE_RAYS)
        a->base_rays = RAD_FF_MAX_BASE_RAYS;
    a->eps = req->vis ? rad_vis_epsilon(mesh) : 0.0;
    for (size_t i = 0; i < n; i++)
        geom_init(&a->geom[i], mesh, &mesh->elements[i]);
    *shared = a;
    return RAD_OK;
}

/* Integrate over the smaller element, the source is the larger; the other
 * direction by reciprocity. */
static void analytic_pair(const rad_ff_request *req, const void *shared, void *scratch, uint32_t i,
                          uint32_t j, rad_ff_pair *out, rad_ff_tally *tally)
{
    (void)scratch;
    const analytic_shared *a = shared;
    const elem_geom *gi = &a->geom[i], *gj = &a->geom[j];
    const elem_geom *recv = gi, *src = gj;
    if (gj->area < gi->area) {
        recv = gj;
        src = gi;
    }
    uint32_t ri = recv == gi ? i : j, si = recv == gi ? j : i;
    rad_ff_blockers blockers;
    blockers.count = 0;
    blockers.complete = false;
    rad_ff_verdict verdict = a->occ ? rad_ff_occluders_classify(a->occ, i, j, &blockers) : RAD_FF_PARTIAL;
    if (verdict == RAD_FF_BLOCKED)
        return;
    bool failed = false;
    bool exact = verdict == RAD_FF_CLEAR || !req->vis || (blockers.complete && blockers.count > 0);
    if (verdict == RAD_FF_PARTIAL && exact && req->vis)
        rad_ff_blockers_trim(&blockers, src->corner[0], src->normal, recv->corner[0], recv->normal);
    double f = 0.0;
    if (exact && (verdict == RAD_FF_CLEAR || !req->vis) &&
        v3_length(v3_sub(gi->centroid, gj->centroid)) >= FAR_RATIO * fmax(gi->diameter, gj->diameter) &&
        all_in_front(gi, gj) && all_in_front(gj, gi))
        f = far_coupling(gi, gj) / recv->area;
    else if (exact && (verdict == RAD_FF_CLEAR || !req->vis))
        f = integrate(recv->corner, recv->corners, recv->normal, src, 0, NULL, &failed) / recv->area;
    else if (exact) {
        f = integrate(recv->corner, recv->corners, recv->normal, src, 0, &blockers, &failed) / recv->area;
        /* What is left below HIDDEN_WHOLE of the unoccluded factor is the
         * rounding of shadows cut edge to edge (walls of several polygons,
         * desks on legs): such pairs are hidden whole, as every ray would
         * say; left in, ten sealed offices lit each other (test_hostile). */
        double gap = v3_length(v3_sub(gi->centroid, gj->centroid)) - gi->radius - gj->radius;
        double bound = gap > 0.0 ? src->area / (M_PI * gap * gap) : 1.0; /* >= the unoccluded factor */
        if (f > 0.0 && f < HIDDEN_WHOLE * fmin(bound, 1.0) &&
            f < HIDDEN_WHOLE * integrate(recv->corner, recv->corners, recv->normal, src, 0, NULL, &failed) /
                    recv->area)
            f = 0.0;
    }
    if (exact && !failed) {
        if (!(f > 0.0))
            return;
        double fs = f * recv->area / src->area;
        out->F_ij = recv == gi ? f : fs;
        out->F_ji = recv == gi ? fs : f;
        return;
    }
    rad_ff_end recv_end, src_end;
    rad_ff_end_element(req->mesh, ri, a->eps, &recv_end);
    rad_ff_end_element(req->mesh, si, a->eps, &src_end);
    rad_rng rng = rad_rng_keyed(req->seed, i, j);
    double fr = occluded_factor(req, recv, &recv_end, src->corner, src->corners, &src_end, &rng,
                                a->base_rays, 0, &tally->rays) /
                recv->area;
    if (!(fr > 0.0))
        return;
    double fs = fr * recv->area / src->area; /* reciprocity */
    out->F_ij = recv == gi ? fr : fs;
    out->F_ji = recv == gi ? fs : fr;
}

const rad_ff_method rad_ff_analytic = {
    "analytic",
    "exact point-to-polygon factor (Baum et al. 1989), adaptive Gauss over the receiver, "
    "visibility from the scene's planes (shadows cut out of the source) or shadow rays; "
    "~1e-8 unoccluded, ~1e-4 occluded, O(n^2)",
    0,
    analytic_prepare,
    NULL,
    analytic_pair,
    NULL,
    NULL,
};
