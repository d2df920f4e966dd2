/*
 * mirror.c -- light by way of ideal planar mirrors in the hierarchy: the
 * first pass of two-pass methods (Wallace, Cohen & Greenberg 1987; Sillion
 * & Puech 1989), carried by links of their own between hierarchy nodes
 * (Hanrahan, Salzman & Aupperle 1991) instead of the dense strategies'
 * extended factors between elements (formfactor/ff_mirror.c).
 *
 * A mirror link r <- s through mirror M carries the light that leaves
 * source node s, meets M once and lands on receiver node r:
 *
 *            s                          s' = s reflected across M's plane
 *             \                        /     (winding reversed: it faces r)
 *              \        M            /
 *   ------------+=======x==========+------- M's plane
 *              /       /
 *             r ------'   k = rho_s(M) x mean over r of F(x -> s' seen through M) x V
 *
 * F(x -> s' seen through M) is exact per point: s' is clipped to the
 * pyramid from x through M's polygon (and to behind its plane), then
 * Lambert's contour formula (rad_point_polygon_ff_front) gives the factor
 * of what is left.  The mean is taken at r's Gauss points, as the ordinary
 * links' (refine.c).  V, the share of the paths x -> mirror -> y that are
 * unoccluded on both legs, comes from shadow rays (a pilot quarter for the
 * oracle's uncertainty, the rest for V, as refine.c's; none where both
 * legs' shafts are empty, shaft.c).  rho_s is the mirror's channels' mean,
 * as the dense path's.
 *
 * The oracle is the ordinary surface links' (hr_oracle_surfaces): the
 * power r reflects may be off by rho_r A_r B_s times how much the point
 * factor varies over r, by rho_r A_r k max|B_leaf - B_s| where the source
 * varies, and by rho_r A_r B_s F u where visibility is uncertain; the end
 * responsible is split.  A pair that may see each other through M (the
 * segments between them cross M's plane inside M's bounds: conv(r, s')
 * meets the plane in the hull of its corner pairs' crossings) but whose
 * Gauss points all miss the image is kept with k = 0 and, as its receiver
 * error, a disc bound of the factor, so that it is split until the points
 * find the light or the bound is below epsilon.
 *
 * Where the links go: each sweep gathers them into H (per node, W/m^2) and
 * pushes H down the quadtrees; a leaf's B = E + rho (x H_links + H + H_d)
 * (hier.c's push_pull).  A mirror absorbs 1 - rho_d - rho_s of what it
 * receives: its rho_s part leaves through the links.  The balance of the
 * ordinary links (hier.c) is left to them: in a closed scene their rows
 * sum to 1 with the mirror as a diffuse surface, the mirror links come on
 * top.
 *
 * Left out, as in the dense path: images of images (light through two
 * mirrors), curved mirrors (every mirror is its planar patches).  Cost:
 * the initial links are every pair of root patches in front of a mirror
 * that faces it (O(M P^2) culls); above 4e7 pairs a mirror is left out
 * with a warning.  Determinism: rays keyed on (seed, mirror, r, s),
 * level-synchronous refinement, the gather serial in link order.
 */
#include "hier/hier.h"

#include <stdlib.h>
#include <string.h>

static const uint64_t HR_MIRROR_SALT = 0x4d4952524f52ULL;

/* More candidate pairs than this for one mirror: its light is left out
 * (a building's mirror facing 10^5 patches would take 10^10 culls). */
#define HR_MIRROR_MAX_PAIRS 4e7

/* Room for the polygons the clips below make: a quad cut by 5 planes
 * (rad_polygon_clip may double a polygon whose corners graze a plane). */
enum { POLY_MAX = 32 };

typedef struct mirror_geometry {
    const rad_patch *patch;
    uint32_t index;        /* its patch number */
    uint32_t root;         /* its root node */
    vec3 q, m;             /* a point of its plane, its unit normal (the reflecting side) */
    vec3 centre;
    vec3 e1, e2;           /* a frame of its plane */
    double lo[2], hi[2];   /* its bounds in that frame */
    double rho_s;          /* channels' mean */
    double lift;           /* m: ray ends on it */
} mirror_geometry;

static void mirror_geometry_of(const hr_tree *t, uint32_t patch, mirror_geometry *g)
{
    const rad_patch *pa = &t->base->patches[patch];
    const double *ks = t->scene->materials[pa->material].specular;
    g->patch = pa;
    g->index = patch;
    g->root = t->root_of_patch[patch];
    g->q = pa->corner[0];
    g->m = pa->normal;
    g->centre = t->nodes[g->root].center;
    g->e1 = v3_normalize(v3_sub(pa->corner[1], pa->corner[0]));
    g->e2 = v3_cross(g->m, g->e1);
    g->lo[0] = g->lo[1] = INFINITY;
    g->hi[0] = g->hi[1] = -INFINITY;
    for (uint32_t c = 0; c < pa->corner_count; c++) {
        vec3 d = v3_sub(pa->corner[c], g->q);
        double a = v3_dot(d, g->e1), b = v3_dot(d, g->e2);
        g->lo[0] = fmin(g->lo[0], a), g->hi[0] = fmax(g->hi[0], a);
        g->lo[1] = fmin(g->lo[1], b), g->hi[1] = fmax(g->hi[1], b);
    }
    g->rho_s = (ks[0] + ks[1] + ks[2]) / 3.0;
    g->lift = t->lift[patch];
}

static vec3 reflect_point(vec3 p, const mirror_geometry *g)
{
    return v3_mad(p, g->m, -2.0 * v3_dot(v3_sub(p, g->q), g->m));
}

static double height(vec3 p, const mirror_geometry *g) { return v3_dot(v3_sub(p, g->q), g->m); }

/* Node x's corners, its part in front of the mirror's plane. */
static int front_part(const hr_node *x, const mirror_geometry *g, vec3 *out)
{
    return (int)rad_polygon_clip(x->corner, x->corners, g->q, g->m, out);
}

/* Source s's image: its part in front of the mirror, reflected, the
 * winding reversed so that it faces where s's reflection faces. */
static int image_of(const hr_node *s, const mirror_geometry *g, vec3 *image)
{
    vec3 front[POLY_MAX];
    int n = front_part(s, g, front);
    for (int k = 0; k < n; k++)
        image[k] = reflect_point(front[n - 1 - k], g);
    return n;
}

/* May any segment from receiver r's front part to source s's image cross
 * the mirror's plane inside the mirror?  Those crossings fill the hull of
 * the crossings of the corner pairs (conv(r, s') cut by the plane), whose
 * bounds are tested against the mirror's.  Conservative. */
static bool aperture_meets(const hr_node *r, const vec3 *image, int n_image, const mirror_geometry *g, double tol)
{
    vec3 front[POLY_MAX];
    int n_front = front_part(r, g, front);
    if (n_front < 3 || n_image < 3)
        return false;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int i = 0; i < n_front; i++)
        for (int j = 0; j < n_image; j++) {
            double dx = height(front[i], g), dy = -height(image[j], g);
            vec3 z = dx + dy > 0.0 ? v3_lerp(front[i], image[j], dx / (dx + dy)) : front[i];
            vec3 d = v3_sub(z, g->q);
            double a = v3_dot(d, g->e1), b = v3_dot(d, g->e2);
            lo[0] = fmin(lo[0], a), hi[0] = fmax(hi[0], a);
            lo[1] = fmin(lo[1], b), hi[1] = fmax(hi[1], b);
        }
    return lo[0] < g->hi[0] + tol && hi[0] > g->lo[0] - tol && lo[1] < g->hi[1] + tol && hi[1] > g->lo[1] - tol;
}

/* The factor from point x (normal n) to the image seen through the
 * mirror: the image clipped to the pyramid from x through the mirror's
 * polygon (each edge's plane through x, the mirror's inside kept), then
 * Lambert's formula, by fans of at most 8 corners. */
static double factor_through(vec3 x, vec3 n, const vec3 *image, int n_image, const mirror_geometry *g)
{
    if (!(height(x, g) > 0.0))
        return 0.0;
    vec3 a[2 * POLY_MAX], b[2 * POLY_MAX];
    int m = n_image;
    memcpy(a, image, (size_t)m * sizeof *a);
    uint32_t corners = g->patch->corner_count;
    for (uint32_t c = 0; c < corners && m >= 3 && m <= POLY_MAX; c++) {
        vec3 p = g->patch->corner[c], q = g->patch->corner[(c + 1) % corners];
        vec3 side = v3_cross(v3_sub(p, x), v3_sub(q, x));
        if (v3_dot(side, v3_sub(g->centre, x)) < 0.0)
            side = v3_scale(side, -1.0);
        m = (int)rad_polygon_clip(a, (size_t)m, x, side, b);
        memcpy(a, b, (size_t)m * sizeof *a);
    }
    if (m < 3)
        return 0.0;
    double f = 0.0;
    for (int first = 1; first + 1 < m; first += 6) { /* fans of 8: corner 0 and 7 more */
        vec3 fan[8];
        int k = 0;
        fan[k++] = a[0];
        for (int i = first; i < m && k < 8; i++)
            fan[k++] = a[i];
        f += rad_point_polygon_ff_front(x, n, fan, (size_t)k);
    }
    return f;
}

/* The unoccluded mean factor from r to the image through the mirror at
 * r's Gauss points (hr_gauss_points) and the largest deviation from it
 * there or at the centre. */
static double mean_factor(const hr_node *r, const vec3 *image, int n_image, const mirror_geometry *g,
                          double *spread)
{
    vec3 x[4];
    double f[4], mean = 0.0;
    int count = hr_gauss_points(r, x);
    for (int c = 0; c < count; c++) {
        f[c] = factor_through(x[c], r->normal, image, n_image, g);
        mean += f[c];
    }
    mean /= count;
    double dev = fabs(factor_through(r->center, r->normal, image, n_image, g) - mean);
    for (int c = 0; c < count; c++)
        dev = fmax(dev, fabs(f[c] - mean));
    *spread = dev;
    return mean;
}

/* Visibility of the paths x -> mirror -> y from `count` pairs of
 * stratified points x on r and y on s (strata paired by a permutation):
 * the kernel-weighted share of the paths through the mirror whose two
 * legs are clear (as refine.c's surface_visibility, the kernel that of x
 * and y's image).  *through: paths cast; 1 when none passes the mirror. */
static double path_visibility(const hr_tree *t, const rad_vis *vis, const mirror_geometry *g, uint32_t r,
                              uint32_t s, int count, rad_rng *rng, uint64_t *rays, int *through)
{
    enum { MAX = HR_SAMPLE_MAX };
    const hr_node *a = &t->nodes[r], *b = &t->nodes[s];
    rad_ray ray[2 * MAX];
    uint8_t hit[2 * MAX];
    double w[MAX];
    int perm[MAX];
    if (count > MAX)
        count = MAX;
    int side = (int)ceil(sqrt((double)count));
    rad_rng_shuffle(rng, perm, count);
    double floor2 = fmin(a->area, b->area) / 16.0, lift_r = t->lift[a->patch], lift_s = t->lift[b->patch];
    vec3 image_normal = v3_mad(b->normal, g->m, -2.0 * v3_dot(b->normal, g->m));
    int m = 0;
    for (int i = 0; i < count; i++) {
        double u0 = (i % side + rad_rng_uniform(rng)) / side, v0 = (i / side % side + rad_rng_uniform(rng)) / side;
        double u1 = (perm[i] % side + rad_rng_uniform(rng)) / side;
        double v1 = (perm[i] / side % side + rad_rng_uniform(rng)) / side;
        vec3 x = rad_corners_sample(a->corner, a->corners, u0, v0);
        vec3 y = rad_corners_sample(b->corner, b->corners, u1, v1), y_image = reflect_point(y, g);
        double hx = height(x, g), hy = height(y, g);
        if (!(hx > 0.0 && hy > 0.0))
            continue;
        vec3 d = v3_sub(y_image, x);
        double d2 = v3_dot(d, d), cx = v3_dot(a->normal, d), cy = -v3_dot(image_normal, d);
        if (!(cx > 0.0 && cy > 0.0 && d2 > 0.0))
            continue;
        vec3 z = v3_mad(x, d, hx / (hx + hy)); /* where the path meets the mirror's plane */
        bool inside = true; /* the mirror's polygon */
        for (uint32_t c = 0; c < g->patch->corner_count && inside; c++) {
            vec3 p = g->patch->corner[c], q = g->patch->corner[(c + 1) % g->patch->corner_count];
            inside = v3_dot(v3_cross(v3_sub(q, p), v3_sub(z, p)), g->m) >= 0.0;
        }
        if (!inside)
            continue;
        w[m] = cx * cy / (d2 * fmax(d2, floor2));
        vec3 from = v3_mad(x, a->normal, lift_r), to = v3_mad(y, b->normal, lift_s);
        vec3 leg1 = v3_sub(z, from), leg2 = v3_sub(to, z);
        double l1 = v3_length(leg1), l2 = v3_length(leg2);
        /* Stop short of the mirror on the way in, leave it past its lift. */
        ray[2 * m] = (rad_ray){from, leg1, 0.0, l1 > 2.0 * g->lift ? 1.0 - g->lift / l1 : 0.0};
        ray[2 * m + 1] = (rad_ray){z, leg2, l2 > 2.0 * g->lift ? g->lift / l2 : 0.0, l2 > 2.0 * g->lift ? 1.0 : 0.0};
        m++;
    }
    *through = m;
    if (m == 0)
        return 1.0;
    vis->backend->occluded(vis->state, ray, 2 * (size_t)m, hit);
    *rays += 2 * (uint64_t)m;
    double pass = 0.0, all = 0.0;
    for (int k = 0; k < m; k++) {
        all += w[k];
        if (!hit[2 * k] && !hit[2 * k + 1])
            pass += w[k];
    }
    return all > 0.0 ? pass / all : 1.0;
}

typedef struct mirror_ctx {
    const hr_tree *tree;
    const hr_refine_params *p;
    const mirror_geometry *geometry; /* per mirror patch, by its index in hr_mirrors.patches */
    const hr_mirrors *m;
} mirror_ctx;

static const mirror_geometry *geometry_of(const mirror_ctx *mc, uint32_t patch)
{
    for (size_t i = 0; i < mc->m->count; i++)
        if (mc->m->patches[i] == patch)
            return &mc->geometry[i];
    return NULL;
}

/* Fill mirror link r <- s through g (parent_flags from the link it
 * refines); false when no light can pass (a side behind the mirror or
 * turned from it, the image behind r, every path outside the mirror). */
static bool make_link(const mirror_ctx *mc, const mirror_geometry *g, uint32_t r, uint32_t s,
                      uint32_t parent_flags, hr_mirror_link *out, uint64_t *rays, uint64_t *shafts,
                      uint64_t *clear)
{
    const hr_tree *t = mc->tree;
    const hr_refine_params *p = mc->p;
    const hr_node *nr = &t->nodes[r], *ns = &t->nodes[s];
    if (nr->kind != HR_SURFACE || ns->kind != HR_SURFACE || nr->patch == g->index || ns->patch == g->index)
        return false;
    const vec3 *mirror_corner = g->patch->corner;
    size_t mn = g->patch->corner_count;
    /* Both in front of the mirror and facing it. */
    if (!rad_ff_in_front(nr->corner, nr->corners, g->q, g->m, p->tol) ||
        !rad_ff_in_front(ns->corner, ns->corners, g->q, g->m, p->tol) ||
        !rad_ff_in_front(mirror_corner, mn, nr->center, nr->normal, p->tol) ||
        !rad_ff_in_front(mirror_corner, mn, ns->center, ns->normal, p->tol))
        return false;
    vec3 image[POLY_MAX];
    int n_image = image_of(ns, g, image);
    if (n_image < 3)
        return false;
    /* The image in front of r, r in front of the image. */
    vec3 image_normal = v3_mad(ns->normal, g->m, -2.0 * v3_dot(ns->normal, g->m));
    vec3 image_centre = reflect_point(ns->center, g);
    if (!rad_ff_in_front(image, (size_t)n_image, nr->center, nr->normal, p->tol) ||
        !rad_ff_in_front(nr->corner, nr->corners, image_centre, image_normal, p->tol) ||
        !aperture_meets(nr, image, n_image, g, p->tol))
        return false;
    double spread = 0.0;
    double f = mean_factor(nr, image, n_image, g, &spread);
    if (!(f > 0.0)) {
        /* Some path may pass where no Gauss point looks: a disc bound on
         * the factor (the image seen through the mirror is no larger
         * than either) keeps the pair for the oracle to split. */
        double a = fmin(ns->area, t->nodes[g->root].area);
        vec3 d = v3_sub(image_centre, nr->center);
        f = 0.0;
        spread = a / (M_PI * v3_dot(d, d) + a);
    }
    double v = 1.0, uncertainty = 0.0;
    uint32_t flags = 0;
    if (f > 0.0 && (parent_flags & HR_LINK_CLEAR)) {
        flags = HR_LINK_CLEAR;
    } else if (f > 0.0 && p->vis) {
        (*shafts)++;
        if (hr_shaft_clear(t, r, g->root, p->tol) && hr_shaft_clear(t, g->root, s, p->tol)) {
            flags = HR_LINK_CLEAR;
            (*clear)++;
        } else {
            rad_rng rng = rad_rng_keyed(p->seed ^ HR_MIRROR_SALT ^ ((uint64_t)g->index << 32), r, s);
            int through = 0;
            int pilot_rays = p->shadow_rays / 4 > 4 ? p->shadow_rays / 4 : 4;
            double vp = path_visibility(t, p->vis, g, r, s, pilot_rays, &rng, rays, &through);
            uncertainty = vp > 0.0 && vp < 1.0 ? 4.0 * vp * (1.0 - vp) : 1.0 / (through + 2);
            v = path_visibility(t, p->vis, g, r, s, p->shadow_rays, &rng, rays, &through);
        }
    }
    *out = (hr_mirror_link){r, s, g->index, flags, (float)(g->rho_s * f * v), (float)(g->rho_s * spread),
                            (float)(g->rho_s * f * uncertainty)};
    return true;
}

/* ---- the list ---- */

static rad_result reserve(rad_context *ctx, hr_mirror_link **items, size_t *capacity, size_t count)
{
    if (count <= *capacity)
        return RAD_OK;
    hr_mirror_link *grown = hr_grow(ctx, *items, capacity, count, sizeof *grown,
                                    "hierarchical: links through mirrors (a larger rad_options.epsilon or "
                                    "rad_options.min_area makes fewer)");
    if (!grown)
        return RAD_ERROR_OUT_OF_MEMORY;
    *items = grown;
    return RAD_OK;
}

/* The mirror geometry of every mirror patch (allocated; NULL for memory). */
static mirror_geometry *geometries(rad_context *ctx, const hr_tree *t, const hr_mirrors *m)
{
    mirror_geometry *g = rad_alloc(ctx, RAD_MEM_HIERARCHY, m->count + 1, sizeof *g, "hierarchical: mirrors");
    for (size_t i = 0; g && i < m->count; i++)
        mirror_geometry_of(t, m->patches[i], &g[i]);
    return g;
}

rad_result hr_mirrors_start(rad_context *ctx, const hr_tree *t, const hr_refine_params *p, hr_mirrors *m,
                            hr_refine_stats *st)
{
    memset(m, 0, sizeof *m);
    const rad_mesh *base = t->base;
    size_t P = base->patch_count;
    for (size_t q = 0; q < P; q++)
        m->count += t->scene->materials[base->patches[q].material].specular_kind == RAD_SPECULAR_MIRROR;
    if (m->count == 0)
        return RAD_OK;
    m->patches = rad_alloc(ctx, RAD_MEM_HIERARCHY, m->count, sizeof *m->patches, "hierarchical: mirrors");
    uint32_t *cand = m->patches ? rad_alloc(ctx, RAD_MEM_HIERARCHY, P, sizeof *cand, "hierarchical: mirrors") : NULL;
    mirror_geometry *geo = NULL;
    if (cand) {
        m->count = 0;
        for (size_t q = 0; q < P; q++)
            if (t->scene->materials[base->patches[q].material].specular_kind == RAD_SPECULAR_MIRROR)
                m->patches[m->count++] = (uint32_t)q;
        geo = geometries(ctx, t, m);
    }
    if (!geo) {
        rad_free(cand);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    mirror_ctx mc = {t, p, geo, m};
    rad_result r = RAD_OK;
    uint64_t rays = 0, shafts = 0, clear = 0;
    for (size_t i = 0; i < m->count && r == RAD_OK; i++) {
        const mirror_geometry *g = &geo[i];
        /* The patches in front of the mirror that face it. */
        size_t C = 0;
        for (size_t q = 0; q < P; q++) {
            const hr_node *n = &t->nodes[t->root_of_patch[q]];
            if (q != g->index && !base->patches[q].obstruction &&
                rad_ff_in_front(n->corner, n->corners, g->q, g->m, p->tol) &&
                rad_ff_in_front(g->patch->corner, g->patch->corner_count, n->center, n->normal, p->tol))
                cand[C++] = t->root_of_patch[q];
        }
        if ((double)C * (double)C > HR_MIRROR_MAX_PAIRS) {
            rad_warn(ctx,
                     "hierarchical: mirror in surface '%s' faces %zu patches; its %.3g pairs of links are "
                     "too many, so the light it reflects is left out (a dense solver, rad_options.solver "
                     "\"gauss-seidel\", carries it)",
                     t->scene->surfaces[g->patch->surface].name, C, (double)C * (double)C);
            continue;
        }
        /* Every ordered pair: blocks of rows, each row in parallel into its
         * slots, the kept ones appended in order (the scratch stays near
         * 2^20 pairs, 28 MB, however many patches face the mirror). */
        size_t rows = C > 0 ? (((size_t)1 << 20) + C - 1) / C : 1;
        hr_mirror_link *all = rad_alloc(ctx, RAD_MEM_HIERARCHY, rows * C + 1, sizeof *all, "hierarchical: mirror links");
        uint8_t *keep = all ? rad_alloc(ctx, RAD_MEM_HIERARCHY, rows * C + 1, 1, "hierarchical: mirror links") : NULL;
        if (!keep)
            r = RAD_ERROR_OUT_OF_MEMORY;
        for (size_t from = 0; r == RAD_OK && from < C; from += rows) {
            size_t to = from + rows < C ? from + rows : C;
#pragma omp parallel for schedule(dynamic, 1) num_threads(p->threads) reduction(+ : rays, shafts, clear)
            for (size_t a = from; a < to; a++)
                for (size_t b = 0; b < C; b++) {
                    size_t q = (a - from) * C + b;
                    keep[q] = make_link(&mc, g, cand[a], cand[b], 0, &all[q], &rays, &shafts, &clear);
                }
            size_t kept = 0;
            for (size_t q = 0; q < (to - from) * C; q++)
                kept += keep[q];
            r = reserve(ctx, &m->items, &m->capacity, m->links + kept);
            for (size_t q = 0; r == RAD_OK && q < (to - from) * C; q++)
                if (keep[q])
                    m->items[m->links++] = all[q];
        }
        rad_free(all);
        rad_free(keep);
    }
    st->rays += rays;
    st->shafts += shafts;
    st->shafts_clear += clear;
    st->links_created += m->links;
    rad_free(cand);
    rad_free(geo);
    return r;
}

/* ---- refinement ---- */

/* Node k's values for the oracle: its own where B covers it, else its
 * nearest ancestor's B (children average to their parent) and spread 0. */
static uint32_t known_node(const hr_tree *t, uint32_t k, size_t known)
{
    while (k >= known)
        k = t->nodes[k].parent;
    return k;
}

static int decide(const mirror_ctx *mc, const double *B, const double *spread, size_t known,
                  const hr_mirror_link *l)
{
    uint32_t s = known_node(mc->tree, l->s, known);
    const double *Bs = &B[3 * (size_t)s];
    double bs = fmax(Bs[0], fmax(Bs[1], Bs[2]));
    double source_spread = s == l->s ? spread[s] : 0.0;
    return hr_oracle_surfaces(mc->tree, mc->p, l->r, l->s, bs, l->k, l->spread, l->vis_err, source_spread, 0.0);
}

/* The ends a link's children join (1 where that end is not split). */
static int ends(const hr_tree *t, uint32_t node, bool split) { return split ? hr_children(t, node) : 1; }

rad_result hr_mirrors_refine(rad_context *ctx, hr_tree *t, const hr_refine_params *p, const double *B,
                             const double *spread, size_t known, hr_mirrors *m, size_t *split,
                             hr_refine_stats *st)
{
    *split = 0;
    if (m->links == 0)
        return RAD_OK;
    mirror_geometry *geo = geometries(ctx, t, m);
    uint8_t *action = NULL;
    size_t *first = NULL;
    hr_mirror_link *done = NULL, *next = NULL;
    size_t done_count = 0, done_capacity = 0, next_capacity = 0;
    rad_result r = geo ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
    mirror_ctx mc = {t, p, geo, m};
    while (r == RAD_OK) {
        size_t L = m->links;
        if ((r = hr_refine_pass_start(ctx, L, &action, &first)) != RAD_OK)
            break;
        /* Decide in parallel; split and count the children serially, in
         * link order (node numbers do not depend on the threads). */
        size_t splits = 0;
#pragma omp parallel for schedule(static) num_threads(p->threads) reduction(+ : splits)
        for (size_t i = 0; i < L; i++) {
            action[i] = (uint8_t)decide(&mc, B, spread, known, &m->items[i]);
            splits += action[i] != HR_KEEP;
        }
        if (splits == 0)
            break;
        *split += splits;
        size_t total = 0;
        for (size_t i = 0; i < L && r == RAD_OK; i++) {
            const hr_mirror_link *l = &m->items[i];
            first[i] = total;
            if (action[i] == HR_KEEP) {
                if ((r = reserve(ctx, &done, &done_capacity, done_count + 1)) == RAD_OK)
                    done[done_count++] = *l;
                continue;
            }
            if (action[i] & HR_SPLIT_R)
                r = hr_subdivide(ctx, t, l->r);
            if (r == RAD_OK && (action[i] & HR_SPLIT_S))
                r = hr_subdivide(ctx, t, l->s);
            total += (size_t)(ends(t, l->r, action[i] & HR_SPLIT_R) * ends(t, l->s, action[i] & HR_SPLIT_S));
        }
        first[L] = total;
        if (r == RAD_OK && (double)(total + done_count) * sizeof *done > p->max_memory)
            r = rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                         "hierarchical: %zu links through mirrors need %.3g GB, over the limit of %.3g GB "
                         "(rad_options.max_memory_bytes); use a larger rad_options.epsilon or rad_options.min_area",
                         total + done_count, (double)(total + done_count) * sizeof *done / 1e9, p->max_memory / 1e9);
        if (r == RAD_OK)
            r = reserve(ctx, &next, &next_capacity, total + 1);
        if (r != RAD_OK)
            break;
        /* The children's links in parallel, into the slots counted above. */
        uint64_t rays = 0, shafts = 0, clear = 0, created = 0, dropped = 0;
#pragma omp parallel for schedule(dynamic, 16) num_threads(p->threads) \
    reduction(+ : rays, shafts, clear, created, dropped)
        for (size_t i = 0; i < L; i++) {
            const hr_mirror_link *l = &m->items[i];
            if (action[i] == HR_KEEP)
                continue;
            const mirror_geometry *g = geometry_of(&mc, l->mirror);
            int cr = ends(t, l->r, action[i] & HR_SPLIT_R), cs = ends(t, l->s, action[i] & HR_SPLIT_S);
            size_t o = first[i];
            for (int x = 0; x < cr; x++)
                for (int y = 0; y < cs; y++, o++) {
                    uint32_t rr = cr > 1 ? hr_child(t, l->r, x) : l->r, ss = cs > 1 ? hr_child(t, l->s, y) : l->s;
                    bool made = make_link(&mc, g, rr, ss, l->flags, &next[o], &rays, &shafts, &clear);
                    if (!made)
                        next[o].r = HR_NONE;
                    created += made;
                    dropped += !made;
                }
        }
        st->rays += rays;
        st->shafts += shafts;
        st->shafts_clear += clear;
        st->links_created += created;
        st->links_dropped += dropped;
        size_t kept = 0;
        for (size_t i = 0; i < total; i++)
            if (next[i].r != HR_NONE)
                next[kept++] = next[i];
        hr_mirror_link *tmp = m->items;
        size_t tmp_capacity = m->capacity;
        m->items = next;
        m->capacity = next_capacity;
        m->links = kept;
        next = tmp;
        next_capacity = tmp_capacity;
    }
    /* The result: the links kept along the way, then those still active. */
    if (r == RAD_OK && (r = reserve(ctx, &done, &done_capacity, done_count + m->links + 1)) == RAD_OK) {
        memcpy(done + done_count, m->items, m->links * sizeof *done);
        done_count += m->links;
        rad_free(m->items);
        m->items = done;
        m->capacity = done_capacity;
        m->links = done_count;
        done = NULL;
    }
    rad_free(done);
    rad_free(next);
    rad_free(action);
    rad_free(first);
    rad_free(geo);
    return r;
}

void hr_mirrors_drop_empty(hr_mirrors *m)
{
    size_t kept = 0;
    for (size_t i = 0; i < m->links; i++)
        if (m->items[i].k > 0.0f)
            m->items[kept++] = m->items[i];
    m->links = kept;
}

/* ---- the sweep ---- */

/* Each surface node's mirror-link reach per unit of its radiosity: the
 * power its links and its ancestors' deliver per unit of B per unit of
 * area (a leaf's share of an ancestor's mean is its area), into reach[]
 * (n values).  Cannot fail. */
static void mirror_reach(const hr_tree *t, const hr_mirrors *m, const float *send, double *reach)
{
    size_t n = t->count;
    memset(reach, 0, n * sizeof *reach);
    for (size_t i = 0; i < m->links; i++) {
        const hr_mirror_link *l = &m->items[i];
        reach[l->s] += t->nodes[l->r].area * (double)l->k * send[l->s] / t->nodes[l->s].area;
    }
    for (size_t k = 0; k < n; k++) {
        uint32_t up = t->nodes[k].parent;
        if (t->nodes[k].kind == HR_SURFACE && up != HR_NONE && t->nodes[up].kind == HR_SURFACE)
            reach[k] += reach[up];
    }
}

rad_result hr_mirrors_balance(rad_context *ctx, const hr_tree *t, hr_mirrors *m, const float *send,
                              const double *target)
{
    if (m->links == 0)
        return RAD_OK;
    size_t n = t->count;
    double *reach = rad_alloc(ctx, RAD_MEM_HIERARCHY, n, sizeof *reach, "hierarchical: mirror balance");
    float *scale = reach ? rad_realloc(ctx, RAD_MEM_HIERARCHY, m->scale, n, sizeof *scale, "hierarchical: mirror balance")
                         : NULL;
    if (!scale) {
        rad_free(reach);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    m->scale = scale;
    m->scale_count = n;
    mirror_reach(t, m, send, reach);
    for (size_t k = 0; k < n; k++) {
        double z = reach[k] > 0.0 && target[k] >= 0.0 ? target[k] / reach[k] : 1.0;
        scale[k] = z >= 0.5 && z <= 2.0 ? (float)z : 1.0f;
    }
    rad_free(reach);
    return RAD_OK;
}

rad_result hr_mirrors_gather(rad_context *ctx, const hr_tree *t, hr_mirrors *m, const double *B, const float *send)
{
    if (m->count == 0)
        return RAD_OK;
    size_t n = t->count;
    if (3 * n > m->H_capacity) {
        double *H = hr_grow(ctx, m->H, &m->H_capacity, 3 * n, sizeof *H, "hierarchical: irradiance through mirrors");
        double *V = H ? rad_realloc(ctx, RAD_MEM_HIERARCHY, m->sent, m->H_capacity, sizeof *V,
                                    "hierarchical: irradiance through mirrors")
                      : NULL;
        if (H)
            m->H = H;
        if (!V)
            return RAD_ERROR_OUT_OF_MEMORY;
        m->sent = V;
    }
    /* What the sources send: the leaves' B times their scale, area means
     * up the quadtrees (children follow their parent). */
    for (size_t k = n; k-- > 0;) {
        const hr_node *nd = &t->nodes[k];
        double *v = &m->sent[3 * k];
        if (nd->kind != HR_SURFACE)
            continue;
        if (!nd->child[0]) {
            double z = m->scale && k < m->scale_count ? (double)m->scale[k] : 1.0;
            for (int c = 0; c < 3; c++)
                v[c] = z * B[3 * k + (size_t)c];
            continue;
        }
        double area = 0.0;
        v[0] = v[1] = v[2] = 0.0;
        for (uint32_t q = 0; q < 4; q++) {
            const double *w = &m->sent[3 * (size_t)(nd->child[0] + q)];
            double a = t->nodes[nd->child[0] + q].area;
            area += a;
            for (int c = 0; c < 3; c++)
                v[c] += a * w[c];
        }
        for (int c = 0; c < 3; c++)
            v[c] = area > 0.0 ? v[c] / area : 0.0;
    }
    memset(m->H, 0, 3 * n * sizeof *m->H);
    for (size_t i = 0; i < m->links; i++) {
        const hr_mirror_link *l = &m->items[i];
        double k = (double)l->k * send[l->s]; /* from the source's open part, as the ordinary gather */
        for (int c = 0; c < 3; c++)
            m->H[3 * (size_t)l->r + (size_t)c] += k * m->sent[3 * (size_t)l->s + (size_t)c];
    }
    /* Down the quadtrees: parents come first in the node array. */
    for (size_t k = 0; k < n; k++) {
        uint32_t up = t->nodes[k].parent;
        if (t->nodes[k].kind == HR_SURFACE && up != HR_NONE && t->nodes[up].kind == HR_SURFACE)
            for (int c = 0; c < 3; c++)
                m->H[3 * k + (size_t)c] += m->H[3 * (size_t)up + (size_t)c];
    }
    return RAD_OK;
}

double hr_mirrors_specular(const hr_tree *t, const hr_mirrors *m, uint32_t k)
{
    if (m->count == 0)
        return 0.0;
    const rad_material *mat = &t->scene->materials[t->base->patches[t->nodes[k].patch].material];
    if (mat->specular_kind != RAD_SPECULAR_MIRROR)
        return 0.0;
    return (mat->specular[0] + mat->specular[1] + mat->specular[2]) / 3.0;
}

double hr_mirrors_bytes(const hr_mirrors *m)
{
    return (double)m->capacity * sizeof(hr_mirror_link) + 2.0 * (double)m->H_capacity * sizeof(double) +
           (double)m->scale_count * sizeof(float) + (double)m->count * sizeof(uint32_t);
}

void hr_mirrors_free(hr_mirrors *m)
{
    rad_free(m->patches);
    rad_free(m->items);
    rad_free(m->H);
    rad_free(m->sent);
    rad_free(m->scale);
    memset(m, 0, sizeof *m);
}
