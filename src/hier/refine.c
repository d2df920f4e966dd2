/*
 * refine.c -- links of hierarchical radiosity: what one carries, whether the
 * two ends see each other, and when it must be split.
 *
 * A link r <- s carries k, the receiver's irradiance per unit of what the
 * source sends (V = visibility fraction; w = the link's direction, below):
 *
 *   surface <- surface   k = V F_rs, the exact unoccluded area-to-area
 *                        factor (contour integral, ff_contour.c); H_r += k B_s
 *   surface <- cluster   H_r += k f_s(-w), f_s the cluster's exitance bins
 *   cluster <- surface   bins_r += k B_s spread along w
 *   cluster <- cluster   bins_r += k f_s(-w) spread along w
 *
 * With a cluster end, k comes from T, the transfer between the two ends
 * estimated by Monte Carlo over point pairs (hr_transfer; a source cluster
 * sampled by power), and w is the direction T flows along: k = T / (g_r
 * g_s), g_r the receiver's area or projected area along w, g_s 1 or the
 * source's bins along -w, so that the gather moves exactly T.  A pair
 * whose ends barely face along w (under 5% of their weight) is split
 * instead: k would be ill-conditioned.
 *
 * The oracle estimates the error a link leaves in the power its receiver
 * reflects (rho_r A_r times an irradiance error: "BFA refinement",
 * Hanrahan, Salzman & Aupperle 1991, sec. 4) from three causes, and splits
 * the end responsible for the largest:
 *
 *   receiver too coarse   rho_r A_r B_s max_x |F(x -> s) - mean|, the exact
 *                         point factor at the receiver's Gauss points: how
 *                         much the irradiance varies over it
 *   source too coarse     10 rho_r A_r F_rs max_leaf |B_leaf - B_s|: the
 *                         source's radiosity varies below it (the weight:
 *                         HR_SOURCE_WEIGHT, hier.h; 0 for the classic
 *                         oracle, which stops here)
 *   uncertain visibility  rho_r A_r B_s F_unoccluded u, u from the pilot
 *                         rays (below), charged to the larger end
 *
 * Links with a cluster end share their transfer among the members by the
 * bins, not by how each member sees the other end; their error is taken as
 * their whole transfer, rho_r A_r B_s max(F_rs, F_sr) with the disc
 * estimates F_rs ~ A_s c_r c_s / (pi d^2 + A_s) (cosines at the centres, 1
 * for a cluster: geometric, so the decision does not depend on the
 * transfer's own samples), and the end with the larger estimate is split.
 * Ends whose bounding spheres overlap always split.  A node is split no
 * further below the minimum area.
 *
 * Visibility: a shaft test first (shaft.c); a clear shaft needs no rays,
 * for the pair or any pair of descendants.  Otherwise shadow rays between
 * random points of the two ends, keyed on (seed, r, s).  Two independent
 * sets: a pilot of a quarter of the rays decides whether visibility is
 * uncertain (4 V (1 - V), or 1 / (N + 2) when the pilot is unanimous), the
 * full set gives k.  Were one set used for both, the links refined would
 * be chosen by their own estimates, and the kept ones biased: a link whose
 * rays all happened to be blocked would stay dark for good.  For the same
 * reason links whose estimate is 0 are kept (they may be refined later);
 * the gather skips them and the final solve drops them (hier.c).
 *
 * Passes are level-synchronous: decide every link's fate in parallel,
 * subdivide nodes serially in link order, create the new links in parallel
 * into slots fixed by a prefix sum.  Node numbers, rays and links are then
 * the same for any thread count.
 */
#include "hier/hier.h"

#include <stdlib.h>
#include <string.h>

static const uint64_t HR_SALT = 0x4852414449554dULL;

/* The transfer between two nodes, at least one a cluster, by Monte Carlo:
 *
 *   T = sum over member pairs of  W_q int int cos_p cos_q V / (pi |pq|^2)
 *
 * from `count` pairs of points p on r, q on s.  The receiver's points are
 * drawn by area; a source cluster's by power (W_q = its patch's B / open,
 * hr_tree_set_power) when it has any, so a lamp in a cluster of dark
 * furniture is sampled in proportion to what it sends, else by area
 * (W_q = 1).  Latin-hypercube over the patches chosen.  Hidden parts of the
 * ends count as not sending and not receiving (their rays are blocked; the
 * gather scales sources by 1 / open to match).
 *
 * Why not a point estimate from the centres (1 / (pi d^2) times projected
 * areas): it is off by tens of per cent for ends a few radii apart, the
 * same way for a given layout, and summed over 10^5 cluster links it made
 * the power of a building drift by 7%.  Why weigh by power: the gather
 * shares a cluster's transfer among its members by their projected areas
 * along one direction, which is not how each member sees the receiver;
 * estimated for uniform radiosity, a lamp clustered with a chair lost a
 * quarter of its power so.  *by_power: the weighting used; *direction:
 * the transfer-weighted mean direction from r's points to s's (the
 * centres' direction when nothing passes). */
double hr_transfer(const hr_tree *t, const rad_vis *vis, uint32_t r, uint32_t s, int count, rad_rng *rng,
                   uint64_t *rays, bool *by_power, vec3 *direction, double quad[4])
{
    *direction = v3_normalize(v3_sub(t->nodes[s].center, t->nodes[r].center));
    enum { MAX = HR_SAMPLE_MAX };
    rad_ray ray[MAX];
    uint8_t hit[MAX];
    double g[MAX];
    int perm[MAX];
    if (count > MAX)
        count = MAX;
    double source_power = hr_cluster_power(t, s);
    *by_power = source_power > 0.0;
    rad_rng_shuffle(rng, perm, count);
    /* Point i: the patch at stratum i of r's and perm[i] of s's weights. */
    double ur[3 * MAX], us[3 * MAX];
    for (int i = 0; i < count; i++) {
        ur[3 * i + 2] = (i + rad_rng_uniform(rng)) / count;
        us[3 * i + 2] = (perm[i] + rad_rng_uniform(rng)) / count;
        for (int c = 0; c < 2; c++)
            ur[3 * i + c] = rad_rng_uniform(rng);
        for (int c = 0; c < 2; c++)
            us[3 * i + c] = rad_rng_uniform(rng);
    }
    vec3 pr[MAX], nr[MAX], ps[MAX], ns[MAX];
    double lr[MAX], ls[MAX];
    hr_sample(t, r, count, ur, false, pr, nr, lr);
    hr_sample(t, s, count, us, *by_power, ps, ns, ls);
    int m = 0;
    for (int i = 0; i < count; i++) {
        vec3 p = pr[i], q = ps[i], np = nr[i], nq = ns[i];
        double lp = lr[i], lq = ls[i];
        vec3 d = v3_sub(q, p);
        double d2 = v3_dot(d, d);
        double cp = v3_dot(np, d), cq = -v3_dot(nq, d);
        if (!(cp > 0.0 && cq > 0.0 && d2 > 0.0))
            continue;
        g[m] = cp * cq / (M_PI * d2 * d2);
        ray[m].origin = v3_mad(p, np, lp);
        ray[m].direction = v3_sub(v3_mad(q, nq, lq), ray[m].origin);
        ray[m].tnear = 0.0;
        ray[m].tfar = 1.0;
        m++;
    }
    if (m == 0)
        return 0.0;
    if (vis) {
        vis->backend->occluded(vis->state, ray, (size_t)m, hit);
        *rays += (uint64_t)m;
    } else {
        memset(hit, 0, (size_t)m);
    }
    double sum = 0.0, all = 0.0, qpass[4] = {0, 0, 0, 0}, qall[4] = {0, 0, 0, 0};
    vec3 flow = v3(0.0, 0.0, 0.0);
    hr_quarters fr = hr_quarters_of(&t->nodes[r]);
    for (int k = 0; k < m; k++) {
        all += g[k];
        if (quad) {
            int q = hr_quarter(&fr, ray[k].origin);
            qall[q] += g[k];
            qpass[q] += hit[k] ? 0.0 : g[k];
        }
        if (!hit[k]) {
            sum += g[k];
            flow = v3_mad(flow, v3_normalize(ray[k].direction), g[k]);
        }
    }
    for (int q = 0; quad && q < 4; q++)
        quad[q] = qall[q] > 0.0 ? qpass[q] / qall[q] : (all > 0.0 ? sum / all : 1.0);
    if (sum > 0.0 && v3_length(flow) > 0.0)
        *direction = v3_normalize(flow);
    return t->nodes[r].area * (*by_power ? source_power : t->nodes[s].area) * sum / count;
}

/* A surface node as a ray end (visibility.c), lifted by its patch's lift. */
static void end_of(const hr_tree *t, const hr_node *n, rad_ff_end *e)
{
    e->corners = n->corners;
    for (int c = 0; c < 4; c++)
        e->corner[c] = n->corner[c < n->corners ? c : 0];
    e->normal = n->normal;
    e->lift = t->lift[n->patch];
}

/* Visibility between two surface nodes from `count` stratified point pairs
 * (rad_ff_pairs): the fraction of the facing pairs that pass, each
 * weighted by its point-to-point kernel cos cos / d^2 (d^2 kept above a
 * sixteenth of the smaller node's area, so no pair dominates).  Weighting
 * by the kernel makes k V estimate int int K V / int int K, the visibility
 * the transfer needs: a plain fraction would misjudge pairs where the near,
 * strongly coupled points are the hidden ones.  *facing = pairs cast;
 * returns 0 when none faces. */
static double surface_visibility(const hr_tree *t, const rad_vis *vis, uint32_t r, uint32_t s, int count,
                                 rad_rng *rng, uint64_t *rays, int *facing, double quad[4], double squad[4])
{
    rad_ray ray[RAD_FF_MAX_RAYS];
    uint8_t hit[RAD_FF_MAX_RAYS];
    const hr_node *a = &t->nodes[r], *b = &t->nodes[s];
    rad_ff_end ea, eb;
    end_of(t, a, &ea);
    end_of(t, b, &eb);
    int m = rad_ff_pairs(&ea, &eb, count, rng, ray);
    *facing = m;
    if (m == 0)
        return 0.0; /* not even the facing parts face (visibility.c) */
    vis->backend->occluded(vis->state, ray, (size_t)m, hit);
    *rays += (uint64_t)m;
    double floor2 = fmin(a->area, b->area) / 16.0, pass = 0.0, all = 0.0;
    double qpass[4] = {0, 0, 0, 0}, qall[4] = {0, 0, 0, 0}, spass[4] = {0, 0, 0, 0}, sall[4] = {0, 0, 0, 0};
    hr_quarters fa = hr_quarters_of(a), fb = hr_quarters_of(b);
    for (int k = 0; k < m; k++) {
        vec3 d = ray[k].direction;
        double d2 = v3_dot(d, d);
        double w = v3_dot(a->normal, d) * -v3_dot(b->normal, d) / (d2 * fmax(d2, floor2));
        all += w;
        if (!hit[k])
            pass += w;
        if (quad) {
            int q = hr_quarter(&fa, ray[k].origin);
            qall[q] += w;
            qpass[q] += hit[k] ? 0.0 : w;
            q = hr_quarter(&fb, v3_add(ray[k].origin, ray[k].direction));
            sall[q] += w;
            spass[q] += hit[k] ? 0.0 : w;
        }
    }
    double v = all > 0.0 ? pass / all : 1.0;
    for (int q = 0; quad && q < 4; q++) {
        quad[q] = qall[q] > 0.0 ? qpass[q] / qall[q] : v;
        squad[q] = sall[q] > 0.0 ? spass[q] / sall[q] : v;
    }
    return v;
}

/* Does node x (a polygon, or a cluster's box) reach in front of surface
 * node p's plane?  The facing test of the form factors, rad_ff_in_front. */
static bool reaches_front(const hr_node *x, const hr_node *p, double tol)
{
    if (x->kind == HR_SURFACE)
        return rad_ff_in_front(x->corner, x->corners, p->center, p->normal, tol);
    vec3 box[8];
    for (int c = 0; c < 8; c++)
        box[c] = v3(c & 1 ? x->hi.x : x->lo.x, c & 2 ? x->hi.y : x->lo.y, c & 4 ? x->hi.z : x->lo.z);
    return rad_ff_in_front(box, 8, p->center, p->normal, tol);
}

/* The contour integral's shortest outer piece, relative to its edge: the
 * singular ends of edges meeting at a shared vertex (pieces cut along
 * contact lines meet block faces at every angle) cost most of the
 * refinement at 1e-7, and at 1e-2 a floor piece's factor to the wall it
 * touches moves by 2.5e-7 (far below the 1% the oracle asks). */
#define HR_CONTOUR_REL 1e-2

int hr_gauss_points(const hr_node *r, vec3 *point)
{
    double t = r->corners == 4 ? 0.5773502691896258 : 0.5;
    for (int c = 0; c < r->corners; c++)
        point[c] = v3_lerp(r->center, r->corner[c], t);
    return r->corners;
}

/* The mean over a receiver polygon of the exact point-to-polygon factor to
 * s at its Gauss points (hr_gauss_points).  *spread = the largest
 * deviation from the mean of the point value there or at the centre. */
static double gauss_factor(const hr_node *r, const hr_node *s, double *spread, double f[4])
{
    double mean = 0.0;
    vec3 x[4];
    hr_gauss_points(r, x);
    for (int c = 0; c < r->corners; c++) {
        f[c] = rad_point_polygon_ff(x[c], r->normal, s->corner, s->corners);
        mean += f[c];
    }
    mean /= r->corners;
    /* The centre too: on symmetric pairs the Gauss points all agree. */
    double centre = rad_point_polygon_ff(r->center, r->normal, s->corner, s->corners);
    if (r->corners == 3)
        f[3] = centre; /* a triangle's middle quarter (quarter_shape) */
    double dev = fabs(centre - mean);
    for (int c = 0; c < r->corners; c++)
        dev = fmax(dev, fabs(f[c] - mean));
    *spread = dev;
    return mean;
}

/* How the unoccluded factor from surface node a to s varies over a's
 * quarters (its children's order, rad_ff_split4): the exact point factor
 * at a point of each (the Gauss points of a quad; a triangle's three and
 * its centre for the middle one), over their largest.  False, f all 1,
 * where it varies by under 2% (the shares' 3 bits could not tell).
 * known: f holds the point factors already (surface_factor's). */
static bool quarter_shape(const hr_node *a, const hr_node *s, double f[4], bool known)
{
    if (!known) {
        vec3 x[4];
        if (hr_gauss_points(a, x) == 3)
            x[3] = a->center;
        for (int q = 0; q < 4; q++)
            f[q] = rad_point_polygon_ff(x[q], a->normal, s->corner, s->corners);
    }
    double most = 0.0, least = INFINITY;
    for (int q = 0; q < 4; q++) {
        most = fmax(most, f[q]);
        least = fmin(least, f[q]);
    }
    if (!(most > 0.0) || least >= 0.98 * most) {
        f[0] = f[1] = f[2] = f[3] = 1.0;
        return false;
    }
    for (int q = 0; q < 4; q++)
        f[q] /= most;
    return true;
}

/* Lowest signed distance of a surface node's corners from a plane. */
static double plane_low(const hr_node *x, vec3 o, vec3 n)
{
    double least = INFINITY;
    for (int c = 0; c < x->corners; c++)
        least = fmin(least, v3_dot(n, v3_sub(x->corner[c], o)));
    return least;
}

/* The unoccluded factor a surface <- surface link carries (k before its
 * visibility): the Gauss mean of the exact point factor where it varies by
 * less than 1% over r (far pairs: the rule's error is then far smaller);
 * else the exact area-to-area factor by the double contour integral
 * (ff_contour.c), which also holds for pairs sharing an edge: there a
 * fixed rule falls short (by 0.7% on a unit-cube face pair, always low,
 * and the shortfalls add up).  Pairs that straddle each other's planes
 * take it too: their factor drops to 0 inside r, which no fixed rule sees.
 * A pair seen from part of the receiver only whose mean comes out 0 gets
 * 1e-30, so that it is kept and refined.  f: the point factors at the
 * receiver's quarters (quarter_shape). */
static double surface_factor(const hr_tree *t, uint32_t r, uint32_t s, double tol, double *spread, double f[4])
{
    const hr_node *nr = &t->nodes[r], *ns = &t->nodes[s];
    double k = gauss_factor(nr, ns, spread, f);
    bool straddle = plane_low(nr, ns->center, ns->normal) < -tol || plane_low(ns, nr->center, nr->normal) < -tol;
    if ((straddle || *spread > 0.01 * k) && nr->area > 0.0)
        k = rad_polygon_coupling_to(nr->corner, nr->corners, nr->normal, ns->corner, ns->corners, ns->normal, tol,
                                    HR_CONTOUR_REL) /
            nr->area;
    if (!(k > 0.0) && *spread > 0.0)
        k = 1e-30;
    return k;
}

typedef struct link_ctx {
    const hr_tree *tree;
    const hr_refine_params *p;
} link_ctx;

/* Fill link r <- s (parent_flags from the link it refines); false when it
 * carries nothing (back to back, behind, hidden). */
static bool make_link(const link_ctx *lc, uint32_t r, uint32_t s, uint32_t parent_flags, hr_link *out,
                      uint64_t *rays, uint64_t *shafts, uint64_t *clear)
{
    const hr_tree *t = lc->tree;
    const hr_refine_params *p = lc->p;
    const hr_node *nr = &t->nodes[r], *ns = &t->nodes[s];
    if (r == s && nr->kind == HR_SURFACE)
        return false; /* a flat surface does not see itself */
    /* Each end must reach in front of the other's plane. */
    if (nr->kind == HR_SURFACE && !reaches_front(ns, nr, p->tol))
        return false;
    if (ns->kind == HR_SURFACE && !reaches_front(nr, ns, p->tol))
        return false;
    double k;
    double spread = 0.0, fr[4];
    if (nr->kind == HR_SURFACE && ns->kind == HR_SURFACE) {
        k = surface_factor(t, r, s, p->tol, &spread, fr);
    } else {
        /* A cluster's self-link carries nothing: it is always split. */
        if (r == s) {
            *out = (hr_link){r, s, 0.0f, 0.0f, 0.0f, 0};
            return true;
        }
        /* The transfer T, and the direction it flows along: the bins of
         * both ends are read along it, not along the line of centres, since
         * the members that carry it face that way.  Then k such that the
         * gather moves T: it multiplies k by the receiver's area (surface)
         * or projected area along u (cluster), and by what the source
         * sends along -u per unit of k: 1 for a surface (k multiplies its
         * B), else its bins, of power when it has any (hr_transfer then
         * samples it by power), of area if not. */
        rad_rng rng = rad_rng_keyed(p->seed ^ HR_SALT, r, s);
        bool by_power = false;
        vec3 u;
        double quad[4], ones[4] = {1.0, 1.0, 1.0, 1.0};
        double transfer = hr_transfer(t, p->vis, r, s, p->shadow_rays, &rng, rays, &by_power, &u,
                                      nr->kind == HR_SURFACE ? quad : NULL);
        vec3 back = v3_scale(u, -1.0);
        double gr = nr->kind == HR_SURFACE ? nr->area : hr_projected(t, r, u);
        double gs = ns->kind == HR_SURFACE ? 1.0
                    : by_power         ? hr_bins_eval(&t->power_bins[6 * (size_t)s], back)
                                       : hr_projected(t, s, back);
        uint32_t flags = u.z < 0.0 ? HR_LINK_ZNEG : 0;
        /* Each cluster end must face along u with at least a twentieth of
         * its weight: else k = T / (gr gs) is ill-conditioned (members that
         * barely face that way would carry the transfer), so split. */
        double wr = nr->kind == HR_SURFACE ? 0.0 : 0.05 * nr->area;
        double ws = ns->kind == HR_SURFACE ? 0.0 : 0.05 * (by_power ? hr_cluster_power(t, s) : ns->area);
        if (transfer > 0.0 && !(gr > wr && gs > ws))
            flags |= HR_LINK_SPLIT;
        /* A zero estimate is kept: its refinement may find what the
         * samples missed (see the visibility note above). */
        k = transfer > 0.0 && !(flags & HR_LINK_SPLIT) ? transfer / (gr * gs) : 0.0;
        /* A surface receiving from a cluster, partly hidden: its quarters'
         * shares (hier.h, HR_LINK_QUADS). */
        if (nr->kind == HR_SURFACE && k > 0.0 && (quad[0] < 1.0 || quad[1] < 1.0 || quad[2] < 1.0 || quad[3] < 1.0))
            flags |= hr_link_quads_encode(quad, ones) | HR_LINK_PARTLY;
        *out = (hr_link){r, s, (float)k, (float)u.x, (float)u.y, flags};
        return true;
    }
    if (!(k > 0.0))
        return false;
    double v = 1.0, uncertainty = 0.0;
    double quad[4] = {1.0, 1.0, 1.0, 1.0}, squad[4] = {1.0, 1.0, 1.0, 1.0};
    bool shaped = false;
    uint32_t flags = 0;
    if (parent_flags & HR_LINK_CLEAR) {
        flags = HR_LINK_CLEAR;
    } else if (p->vis) {
        (*shafts)++;
        if (hr_shaft_clear(t, r, s, p->tol)) {
            flags = HR_LINK_CLEAR;
            (*clear)++;
        } else {
            rad_rng rng = rad_rng_keyed(p->seed ^ HR_SALT, r, s);
            int facing = 0;
            int pilot_rays = p->shadow_rays / 4 > 4 ? p->shadow_rays / 4 : 4;
            double vp = surface_visibility(t, p->vis, r, s, pilot_rays, &rng, rays, &facing, NULL, NULL);
            if (facing > 0)
                uncertainty = vp > 0.0 && vp < 1.0 ? 4.0 * vp * (1.0 - vp) : 1.0 / (facing + 2);
            v = surface_visibility(t, p->vis, r, s, p->shadow_rays, &rng, rays, &facing, quad, squad);
            /* Partly hidden: which quarters of either end see the other. */
            shaped = v > 0.0 && v < 1.0;
            if (shaped)
                flags |= HR_LINK_PARTLY;
            else
                for (int q = 0; q < 4; q++)
                    quad[q] = squad[q] = 1.0;
        }
    }
    /* The quarters' shares (hier.h, HR_LINK_QUADS), for the gather to
     * share the light by: their visibility, times the factor's own shape
     * where it varies over an end.  A ceiling node along a wall gets less
     * of the floor's light on its wall side than the node's mean, and a
     * wall node sends more of it from its lit foot: the mean pushed down
     * alike put the ceiling's strip along the walls 20% over a path-traced
     * reference and the rest 2.5% under, the area mean right. */
    if (v > 0.0) {
        double fs[4];
        if (quarter_shape(nr, ns, fr, true))
            for (int q = 0; q < 4; q++)
                quad[q] *= fr[q], shaped = true;
        if (quarter_shape(ns, nr, fs, false))
            for (int q = 0; q < 4; q++)
                squad[q] *= fs[q], shaped = true;
        if (shaped) {
            double mr = fmax(fmax(quad[0], quad[1]), fmax(quad[2], quad[3]));
            double ms = fmax(fmax(squad[0], squad[1]), fmax(squad[2], squad[3]));
            for (int q = 0; q < 4; q++) {
                quad[q] = mr > 0.0 ? quad[q] / mr : 1.0;
                squad[q] = ms > 0.0 ? squad[q] / ms : 1.0;
            }
            flags |= hr_link_quads_encode(quad, squad);
        }
    }
    out->r = r;
    out->s = s;
    out->k = (float)(k * v);
    out->spread = (float)spread;
    out->vis_err = (float)(k * uncertainty);
    out->flags = flags;
    return true;
}

/* ---- the oracle ---- */

/* The power a partly hidden link's quarters move (HR_LINK_QUADS): the
 * gather shares its light by quarters, but within each the hidden part
 * is as uneven again (a pocket the node straddles: the ceiling over a
 * hanging luminaire's housing), so the shares' spread bounds what is
 * still misplaced below them: rho A (k B_s) sum_q |v_q / v - 1| / 4. */
static double quad_error(const hr_tree *t, const double *B, const hr_link *l)
{
    const hr_node *nr = &t->nodes[l->r];
    if (!(l->flags & HR_LINK_QUADS) || !(l->flags & HR_LINK_PARTLY) || nr->kind != HR_SURFACE)
        return 0.0;
    double v[4], mean = 0.0, moved = 0.0;
    for (int q = 0; q < 4; q++)
        mean += 0.25 * (v[q] = hr_link_quad(l->flags, 0, q));
    for (int q = 0; q < 4 && mean > 0.0; q++)
        moved += 0.25 * fabs(v[q] / mean - 1.0);
    const double *Bs = &B[3 * (size_t)l->s];
    return (double)nr->rho * nr->area * l->k * fmax(Bs[0], fmax(Bs[1], Bs[2])) * moved;
}

/* Which end to split given the two ends' errors (W): the end responsible
 * for the larger, if it may be split, else the other where its own error
 * is over epsilon too. */
static int choose_split(const hr_tree *t, const hr_refine_params *p, uint32_t r, uint32_t s, double e_r, double e_s)
{
    if (fmax(e_r, e_s) <= p->epsilon)
        return HR_KEEP;
    bool rs = hr_splittable(t, r), ss = hr_splittable(t, s);
    if (e_r >= e_s) {
        if (rs)
            return HR_SPLIT_R;
        return ss && e_s > p->epsilon ? HR_SPLIT_S : HR_KEEP;
    }
    if (ss)
        return HR_SPLIT_S;
    return rs && e_r > p->epsilon ? HR_SPLIT_R : HR_KEEP;
}

int hr_oracle_surfaces(const hr_tree *t, const hr_refine_params *p, uint32_t r, uint32_t s, double bs, double k,
                       double link_spread, double vis_err, double source_spread, double pocket)
{
    const hr_node *nr = &t->nodes[r], *ns = &t->nodes[s];
    double rho = nr->rho;
    if (!(rho > 0.0))
        return HR_KEEP; /* nothing reflected: the receiver's B is its E */
    double e_r = rho * bs * link_spread * nr->area;
    double e_s = p->source_weight * rho * k * source_spread * nr->area;
    double e_v = rho * bs * vis_err * nr->area;
    if (nr->area >= ns->area)
        e_r += e_v;
    else
        e_s += e_v;
    return choose_split(t, p, r, s, fmax(e_r, pocket), e_s);
}

static int decide(const hr_tree *t, const hr_refine_params *p, const double *B, const double *spread,
                  const double *node_quad, const hr_link *l)
{
    const hr_node *nr = &t->nodes[l->r], *ns = &t->nodes[l->s];
    if (l->r == l->s)
        return HR_SPLIT_BOTH; /* a cluster's self-link: its members' interactions */
    const double *Bs = &B[3 * (size_t)l->s];
    double bs = fmax(Bs[0], fmax(Bs[1], Bs[2]));
    /* What the quarters of all the receiver's partly hidden links leave
     * misplaced, summed (each alone is small; in a pocket they add up with
     * one sign): over epsilon, they are refined at the receiver. */
    double pocket = node_quad && (l->flags & HR_LINK_PARTLY) && node_quad[l->r] > p->epsilon ? node_quad[l->r] : 0.0;
    if (nr->kind == HR_SURFACE && ns->kind == HR_SURFACE)
        return hr_oracle_surfaces(t, p, l->r, l->s, bs, l->k, l->spread, l->vis_err, spread[l->s], pocket);
    double rho = nr->rho;
    if (!(rho > 0.0))
        return HR_KEEP;
    vec3 w = v3_sub(ns->center, nr->center);
    double d2 = v3_dot(w, w);
    double reach = nr->radius + ns->radius;
    if (d2 <= reach * reach || (l->flags & HR_LINK_SPLIT)) {
        /* Overlapping bounds, or a transfer the bins cannot carry: split
         * the larger end (a cluster if equal). */
        bool r_larger = nr->radius > ns->radius || (nr->radius == ns->radius && nr->kind == HR_CLUSTER);
        bool rs = hr_splittable(t, l->r), ss = hr_splittable(t, l->s);
        if (rs && (r_larger || !ss))
            return HR_SPLIT_R;
        return ss ? HR_SPLIT_S : HR_KEEP;
    }
    double d = sqrt(d2);
    vec3 u = v3_scale(w, 1.0 / d);
    double cr = nr->kind == HR_SURFACE ? fmax(0.0, v3_dot(nr->normal, u)) : 1.0;
    double cs = ns->kind == HR_SURFACE ? fmax(0.0, -v3_dot(ns->normal, u)) : 1.0;
    double g = rho * bs * cr * cs * nr->area;
    double e_s = g * ns->area / (M_PI * d2 + ns->area);
    double e_r = g * nr->area / (M_PI * d2 + nr->area);
    return choose_split(t, p, l->r, l->s, fmax(e_r, pocket), e_s);
}

/* ---- link lists ---- */

static rad_result links_reserve(rad_context *ctx, hr_links *l, size_t count)
{
    if (count <= l->capacity)
        return RAD_OK;
    hr_link *items = hr_grow(ctx, l->items, &l->capacity, count, sizeof *items,
                             "hierarchical: links (a larger rad_options.epsilon or rad_options.min_area makes fewer)");
    if (!items)
        return RAD_ERROR_OUT_OF_MEMORY;
    l->items = items;
    return RAD_OK;
}

rad_result hr_links_initial(rad_context *ctx, hr_tree *t, const hr_refine_params *p, hr_links *links,
                            hr_refine_stats *st)
{
    links->count = 0;
    if (t->clusters > 0) {
        rad_result r = links_reserve(ctx, links, 1);
        if (r != RAD_OK)
            return r;
        links->items[0] = (hr_link){0, 0, 0.0f, 0.0f, 0.0f, 0};
        links->count = 1;
        return RAD_OK;
    }
    /* Every ordered pair of root patches: row i in parallel into its slots. */
    size_t P = t->base->patch_count;
    if ((double)P * (double)P * sizeof(hr_link) > 0.5 * 1e12)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                        "hierarchical: %zu patches make too many initial links; turn clustering on "
                        "(rad_options.clustering)", P);
    hr_link *all = rad_alloc(ctx, RAD_MEM_HIERARCHY, P * P, sizeof *all, "hierarchical: initial links");
    uint8_t *keep = rad_alloc(ctx, RAD_MEM_HIERARCHY, P * P, 1, "hierarchical: initial links");
    rad_result r = !all || !keep ? RAD_ERROR_OUT_OF_MEMORY : RAD_OK;
    uint64_t rays = 0, shafts = 0, clear = 0;
    link_ctx lc = {t, p};
    if (r == RAD_OK) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(p->threads) reduction(+ : rays, shafts, clear)
        for (size_t i = 0; i < P; i++)
            for (size_t j = 0; j < P; j++) {
                uint32_t ri = t->root_of_patch[i], sj = t->root_of_patch[j];
                keep[i * P + j] = i != j && make_link(&lc, ri, sj, 0, &all[i * P + j], &rays, &shafts, &clear);
            }
        size_t m = 0;
        for (size_t q = 0; q < P * P; q++)
            m += keep[q];
        r = links_reserve(ctx, links, m);
        if (r == RAD_OK)
            for (size_t q = 0; q < P * P; q++)
                if (keep[q])
                    links->items[links->count++] = all[q];
    }
    st->rays += rays;
    st->shafts += shafts;
    st->shafts_clear += clear;
    st->links_created += links->count;
    rad_free(all);
    rad_free(keep);
    return r;
}

rad_result hr_refine_pass_start(rad_context *ctx, size_t links, uint8_t **action, size_t **first)
{
    if (rad_cancelled(ctx))
        return RAD_ERROR_INTERRUPTED;
    uint8_t *a = rad_realloc(ctx, RAD_MEM_HIERARCHY, *action, links, sizeof *a, "hierarchical: refinement");
    if (a)
        *action = a;
    size_t *f = a ? rad_realloc(ctx, RAD_MEM_HIERARCHY, *first, links + 1, sizeof *f, "hierarchical: refinement")
                  : NULL;
    if (!f)
        return RAD_ERROR_OUT_OF_MEMORY;
    *first = f;
    return RAD_OK;
}

rad_result hr_refine(rad_context *ctx, hr_tree *t, const hr_refine_params *p, const double *B,
                     const double *spread, hr_links *links, size_t *split, hr_refine_stats *st)
{
    *split = 0;
    uint8_t *action = NULL;
    size_t *first = NULL;
    hr_links next = {0}, done = {0};
    rad_result r = RAD_OK;
    /* B covers the nodes that existed when it was computed; new nodes take
     * their parent's value (children of a node average to it). */
    size_t known = t->count;
    double *Bx = NULL, *Sx = NULL, *node_quad = NULL;
    for (;;) {
        size_t L = links->count;
        if ((r = hr_refine_pass_start(ctx, L, &action, &first)) != RAD_OK)
            break;
        /* Values for nodes made in earlier passes of this call. */
        if (t->count > known) {
            double *nb = rad_realloc(ctx, RAD_MEM_HIERARCHY, Bx, 3 * t->count, sizeof *nb,
                                     "hierarchical: refinement");
            if (nb && !Bx)
                memcpy(nb, B, 3 * known * sizeof *nb);
            if (nb)
                Bx = nb;
            double *ns = nb ? rad_realloc(ctx, RAD_MEM_HIERARCHY, Sx, t->count, sizeof *ns, "hierarchical: refinement")
                            : NULL;
            if (ns && !Sx)
                memcpy(ns, spread, known * sizeof *ns);
            if (ns)
                Sx = ns;
            if (!nb || !ns) {
                r = RAD_ERROR_OUT_OF_MEMORY;
                break;
            }
            for (size_t k = known; k < t->count; k++) {
                for (int c = 0; c < 3; c++)
                    Bx[3 * k + (size_t)c] = Bx[3 * (size_t)t->nodes[k].parent + (size_t)c];
                Sx[k] = 0.0;
            }
            known = t->count;
        }
        const double *Bv = Bx ? Bx : B, *Sv = Sx ? Sx : spread;
        double *nq = rad_realloc(ctx, RAD_MEM_HIERARCHY, node_quad, t->count + 1, sizeof *nq,
                                 "hierarchical: refinement");
        if (!nq) {
            r = RAD_ERROR_OUT_OF_MEMORY;
            break;
        }
        node_quad = nq;
        memset(node_quad, 0, t->count * sizeof *node_quad);
        /* In link order: deterministic sums.  The classic oracle has F and
         * B F alone. */
        for (size_t i = 0; p->source_weight > 0.0 && i < L; i++)
            node_quad[links->items[i].r] += quad_error(t, Bv, &links->items[i]);
        size_t splits = 0;
#pragma omp parallel for schedule(static) num_threads(p->threads) reduction(+ : splits)
        for (size_t i = 0; i < L; i++) {
            action[i] = (uint8_t)decide(t, p, Bv, Sv, p->source_weight > 0.0 ? node_quad : NULL, &links->items[i]);
            splits += action[i] != HR_KEEP;
        }
        if (splits == 0)
            break;
        *split += splits;
        st->passes++;
        /* Serial: links kept are final for this call (B and the spreads do
         * not change within it), so they leave the active set; children are
         * made in link order (node numbers are deterministic). */
        size_t keep = L - splits;
        if ((r = links_reserve(ctx, &done, done.count + keep)) != RAD_OK)
            break;
        size_t total = 0;
        for (size_t i = 0; i < L && r == RAD_OK; i++) {
            const hr_link *l = &links->items[i];
            first[i] = total;
            if (action[i] == HR_KEEP) {
                done.items[done.count++] = *l;
                continue;
            }
            if (action[i] & HR_SPLIT_R)
                r = hr_subdivide(ctx, t, l->r);
            if (r == RAD_OK && (action[i] & HR_SPLIT_S))
                r = hr_subdivide(ctx, t, l->s);
            int cr = action[i] & HR_SPLIT_R ? hr_children(t, l->r) : 1;
            int cs = action[i] & HR_SPLIT_S ? hr_children(t, l->s) : 1;
            total += (size_t)(cr * cs);
        }
        first[L] = total;
        if (r != RAD_OK)
            break;
        if ((double)(total + done.count) * sizeof(hr_link) > p->max_memory ||
            (r = links_reserve(ctx, &next, total)) != RAD_OK) {
            if (r == RAD_OK)
                r = rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                             "hierarchical: %zu links need %.3g GB, over the limit of %.3g GB "
                             "(rad_options.max_memory_bytes); use a larger rad_options.epsilon or "
                             "rad_options.min_area",
                             total + done.count, (double)(total + done.count) * sizeof(hr_link) / 1e9,
                             p->max_memory / 1e9);
            break;
        }
        uint64_t rays = 0, shafts = 0, clear = 0, created = 0, dropped = 0;
        link_ctx lc = {t, p};
        hr_link *out = next.items;
#pragma omp parallel for schedule(dynamic, 64) num_threads(p->threads) \
    reduction(+ : rays, shafts, clear, created, dropped)
        for (size_t i = 0; i < L; i++) {
            const hr_link *l = &links->items[i];
            size_t o = first[i];
            if (action[i] == HR_KEEP)
                continue;
            int cr = action[i] & HR_SPLIT_R ? hr_children(t, l->r) : 1;
            int cs = action[i] & HR_SPLIT_S ? hr_children(t, l->s) : 1;
            for (int x = 0; x < cr; x++)
                for (int y = 0; y < cs; y++) {
                    uint32_t rr = action[i] & HR_SPLIT_R ? hr_child(t, l->r, x) : l->r;
                    uint32_t ss = action[i] & HR_SPLIT_S ? hr_child(t, l->s, y) : l->s;
                    hr_link nl;
                    if (make_link(&lc, rr, ss, l->flags, &nl, &rays, &shafts, &clear)) {
                        out[o] = nl;
                        created++;
                    } else {
                        out[o].r = HR_NONE;
                        dropped++;
                    }
                    o++;
                }
        }
        st->rays += rays;
        st->shafts += shafts;
        st->shafts_clear += clear;
        st->links_created += created;
        st->links_dropped += dropped;
        size_t m = 0;
        for (size_t i = 0; i < total; i++)
            if (out[i].r != HR_NONE)
                out[m++] = out[i];
        next.count = m;
        hr_links tmp = *links;
        *links = next;
        next = tmp;
    }
    /* The links still active are kept too; the result is all of them. */
    if (r == RAD_OK && (r = links_reserve(ctx, &done, done.count + links->count)) == RAD_OK) {
        if (links->count) /* done.items may be NULL: no offset from it (UB) */
            memcpy(done.items + done.count, links->items, links->count * sizeof *links->items);
        done.count += links->count;
        hr_links tmp = *links;
        *links = done;
        done = tmp;
    }
    rad_free(done.items);
    rad_free(next.items);
    rad_free(action);
    rad_free(first);
    rad_free(Bx);
    rad_free(Sx);
    rad_free(node_quad);
    return r;
}
