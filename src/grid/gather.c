/*
 * gather.c -- the illuminance at calculation points, computed at each
 * point from a solved view:
 *
 *   H(x, n) = H_light(x, n)                      luminaires, daylight (light.h)
 *           + sum_j B_j F(x -> j) V(x, j)        every element's radiosity
 *
 * F(x -> j) is the exact unoccluded point-to-polygon factor (Lambert's
 * formula with the polygon clipped to the point's hemisphere, polygon.c:
 * light from behind the point's normal counts zero, so a point in free
 * space is lit from its normal's side only).  F V is the visible part:
 *
 *   - a point on a surface (a ray along -n meets a patch facing n within
 *     a few rad_vis_epsilon) takes that element as its receiver: the
 *     occluder classification of the pair (receiver, j) holds for every
 *     point of the receiver (occluders.c), so clear pairs need no ray,
 *     blocked ones count zero and partial ones with their blockers listed
 *     get the exact factor of the source less the blockers' shadows
 *     (rad_point_polygon_ff_visible).  The surface's own elements in the
 *     point's plane are left out (their factor is zero);
 *   - otherwise (free points, work planes in the air, partial pairs the
 *     classification cannot list) shadow rays to stratified points y_k of
 *     the element give its visible share:  F V = F sum_clear k(y_k) /
 *     sum_k k(y_k),  k(y) = cos cos A_j / (pi r^2) (rad_element_seen:
 *     exact when nothing or everything blocks, consistent between); N =
 *     1, 4 or 16 by the element's size over its distance.
 *
 * The sum splits in the emitters' self-emission E_j (their direct light)
 * and the rest, B_j - E_j (the interreflection, luminaires' and daylight's
 * first reflection included).  Parallel over points: each point's sum is
 * made in one thread in element order, and its rays are keyed on (seed,
 * point, element), so the numbers do not depend on the thread count.
 *
 * RAD_GRID_GATHER_TREE walks cluster.c's tree instead of the element list
 * (gather_tree): far groups count as one source (Barnes & Hut 1986's
 * opening criterion; the visibility of a group by rays to its
 * representatives, as Walter et al. 2005's lightcuts), the elements it
 * reaches go through the same exact path.  The walk skips nodes beyond
 * the point's reach (vis.h's rad_vis_reach: the box a fan of
 * RAD_GRID_REACH_FAN rays from the point reaches, widened by the fan's
 * spacing), so that a building's other rooms cost nothing.  The default from
 * RAD_GRID_GATHER_TREE_MIN elements (grid.h; docs/performance.md).
 */
#include "grid/grid.h"

#include "formfactor/formfactor.h"
#include "light/light.h"

#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* Rays gathered before one occlusion query (Embree's packets are 16). */
enum { BATCH = 256 };

typedef struct gather_shared {
    const rad_solution_view *view;
    const rad_grid_set *set;
    const rad_ff_occluders *occ;  /* NULL: no classification (rays) */
    const double *self;           /* 3n: self-emission E_j (W/m^2) */
    const float *diameter;        /* n: element diameter, m */
    const double *lift;           /* n: the rays' lift at the element, m (eps + its bend) */
    const int64_t *recv;          /* per point: the element it lies on, or -1 (receiver_of) */
    double eps, plane_tol;
    uint64_t seed;
    const rad_gather_tree *tree;  /* NULL: every element exactly */
    double theta;                 /* the tree's opening criterion, diameter / distance */
    int strata;                   /* > 0: k x k rays for every element; 0: by distance */
} gather_shared;

/* Per-thread pending rays, grouped by element: each element's visible
 * share is taken after the query (rad_element_seen). */
typedef struct ray_batch {
    rad_ray ray[BATCH];
    double weight[BATCH];         /* the kernel at its end / N (rad_element_seen's weights) */
    uint8_t blocked[BATCH];
    int count;
    uint32_t element[BATCH];      /* pending elements ... */
    double factor[BATCH];         /* ... their unoccluded factor */
    int first[BATCH + 1];         /* ... and their rays: first[e] .. first[e + 1] - 1 */
    int elements;
    uint64_t rays;
} ray_batch;

static void flush(const gather_shared *g, ray_batch *b, double direct[3], double indirect[3])
{
    if (b->elements == 0)
        return;
    const rad_vis *vis = g->view->vis;
    if (b->count > 0)
        vis->backend->occluded(vis->state, b->ray, (size_t)b->count, b->blocked);
    b->first[b->elements] = b->count;
    const double *B = g->view->radiosity;
    for (int e = 0; e < b->elements; e++) {
        int first = b->first[e];
        double seen = rad_element_seen(b->factor[e], b->weight + first, b->blocked + first, b->first[e + 1] - first);
        size_t j = b->element[e];
        for (int c = 0; c < 3; c++) {
            direct[c] += seen * g->self[3 * j + (size_t)c];
            indirect[c] += seen * (B[3 * j + (size_t)c] - g->self[3 * j + (size_t)c]);
        }
    }
    b->rays += (uint64_t)b->count;
    b->count = 0;
    b->elements = 0;
}

/* The element under point p facing n (the point lies on it), or -1. */
static int64_t receiver_of(const gather_shared *g, vec3 p, vec3 n)
{
    const rad_mesh *mesh = g->view->mesh;
    const rad_vis *vis = g->view->vis;
    if (!vis)
        return -1;
    rad_ray ray = {v3_mad(p, n, 2.0 * g->eps), v3_scale(n, -1.0), 0.0, 4.0 * g->eps};
    rad_hit hit;
    vis->backend->intersect(vis->state, &ray, 1, &hit);
    if (!isfinite(hit.t))
        return -1;
    const rad_patch *patch = &mesh->patches[hit.patch];
    /* Facing the point's way within 1e-6 of a radian squared. */
    if (patch->obstruction || patch->element_count == 0 || v3_dot(patch->normal, n) < 1.0 - 1e-6)
        return -1;
    double s, t, ls, lt;
    rad_patch_parameters(patch, p, &s, &t);
    s = fmin(fmax(s, 0.0), 1.0);
    t = fmin(fmax(t, 0.0), 1.0);
    return (int64_t)rad_mesh_locate(mesh, hit.patch, s, t, &ls, &lt);
}

/* What one point gathers: its position, normal, receiver, the rays' origin
 * and the running sums. */
typedef struct point_sums {
    size_t index;
    vec3 p, n, origin;
    int64_t recv;                 /* the element the point lies on, or -1 */
    vec3 reach_lo, reach_hi;      /* the box its view reaches (vis.h rad_vis_reach; the tree's walk) */
    const rad_element *re;
    double *direct, *indirect;    /* 3 each */
    uint64_t exact_pairs, ray_pairs, cluster_pairs, cluster_rays;
} point_sums;

/* Element j's radiosity at the point, exactly: the point-to-polygon factor
 * and the visibility of the file's header (occluders or keyed rays). */
static void gather_element(const gather_shared *g, point_sums *ps, size_t j, ray_batch *b)
{
    const rad_solution_view *view = g->view;
    const rad_mesh *mesh = view->mesh;
    const double *Bj = view->radiosity + 3 * j;
    vec3 p = ps->p, n = ps->n;
    const rad_element *re = ps->re;
    if (!(Bj[0] > 0.0 || Bj[1] > 0.0 || Bj[2] > 0.0))
        return;
    const rad_element *e = &mesh->elements[j];
    /* The point must be in front of the element's plane. */
    if (!(v3_dot(e->normal, v3_sub(p, e->centroid)) > g->plane_tol))
        return;
    if (re && e->surface == re->surface && fabs(v3_dot(e->normal, v3_sub(p, e->centroid))) <= g->plane_tol)
        return;
    vec3 corner[4];
    for (uint32_t k = 0; k < e->vertex_count; k++)
        corner[k] = mesh->vertices[e->vertex[k]];
    double F = rad_point_polygon_ff(p, n, corner, e->vertex_count);
    if (!(F > 0.0))
        return;
    double seen = F;
    bool rays = view->vis != NULL;
    if (re && g->occ && rays) {
        rad_ff_blockers blockers;
        blockers.count = 0;
        blockers.complete = false;
        rad_ff_verdict verdict = rad_ff_occluders_classify(g->occ, (uint32_t)ps->recv, (uint32_t)j, &blockers);
        if (verdict == RAD_FF_BLOCKED) {
            ps->exact_pairs++;
            return;
        }
        if (verdict == RAD_FF_CLEAR) {
            rays = false;
        } else if (blockers.complete && blockers.count > 0) {
            rad_ff_blockers_trim(&blockers, corner[0], e->normal, mesh->vertices[re->vertex[0]], re->normal);
            double f = rad_point_polygon_ff_visible(p, n, corner, e->vertex_count, e->normal, &blockers);
            if (f >= 0.0) {
                seen = fmin(f, F);
                rays = false;
            }
        }
        if (!rays)
            ps->exact_pairs++;
    }
    if (!rays) {
        for (int c = 0; c < 3; c++) {
            ps->direct[c] += seen * g->self[3 * j + (size_t)c];
            ps->indirect[c] += seen * (Bj[c] - g->self[3 * j + (size_t)c]);
        }
        return;
    }
    ps->ray_pairs++;
    /* N = k x k stratified rays: 1 beyond 4 diameters, 4 beyond one,
     * 16 nearer (the hidden part's error falls as the element looks
     * smaller: its kernel varies less over it). */
    double dist = v3_length(v3_sub(e->centroid, p)), diam = g->diameter[j];
    int k = g->strata > 0 ? g->strata : dist > 4.0 * diam ? 1 : dist > diam ? 2 : 4;
    if (b->count + k * k > BATCH || b->elements == BATCH)
        flush(g, b, ps->direct, ps->indirect);
    b->element[b->elements] = (uint32_t)j;
    b->factor[b->elements] = F;
    b->first[b->elements] = b->count;
    b->elements++;
    double lift = g->lift[j];
    rad_rng rng = rad_rng_keyed(g->seed, 0x67726964ULL + ps->index, j);
    b->count += (size_t)rad_element_kernel_rays(mesh, e, p, n, ps->origin, lift, k, &rng, b->ray + b->count,
                                                b->weight + b->count);
}

/* The rays of one visibility test, handed down the walk: a child's
 * representatives are among its parent's (cluster.c alternates them), and
 * the same ray from the same origin has the same answer, so a child casts
 * only those its parent did not. */
typedef struct known_rays {
    uint32_t element[RAD_GATHER_REPS];
    uint8_t blocked[RAD_GATHER_REPS];
    int count;
} known_rays;

/* A node's visibility from the point by rays to its representatives'
 * centroids (lifted as the element rays' ends): 1 all clear, 0 all
 * blocked, -1 mixed (the node is opened).  `clear_counts` false: the node
 * cannot count as clear (it is not one-sided or not far enough), so the
 * first clear ray ends the test (-1).  The rays cast are added to `known`
 * (those of `parent` reused).  Without a ray structure, 1. */
static int cluster_visible(const gather_shared *g, point_sums *ps, const rad_gather_node *node,
                           const known_rays *parent, bool clear_counts, known_rays *known)
{
    known->count = 0;
    const rad_vis *vis = g->view->vis;
    if (!vis)
        return 1;
    const rad_mesh *mesh = g->view->mesh;
    int clear = 0, hidden = 0;
    rad_ray ray[RAD_GATHER_REPS];
    uint32_t pending[RAD_GATHER_REPS];
    int count = 0;
    for (int k = 0; k < node->reps; k++) {
        uint32_t j = node->rep[k];
        int at = -1;
        for (int i = 0; parent && i < parent->count; i++)
            if (parent->element[i] == j)
                at = i;
        if (at >= 0) {
            known->element[known->count] = j;
            known->blocked[known->count++] = parent->blocked[at];
            parent->blocked[at] ? hidden++ : clear++;
            continue;
        }
        /* The point the exact path's single ray would aim at (its first
         * sample, keyed on the seed, the point and the element): where
         * every element of a node is far enough for one ray, the node's
         * verdict is the one its elements would get. */
        const rad_element *e = &mesh->elements[j];
        rad_rng rng = rad_rng_keyed(g->seed, 0x67726964ULL + ps->index, j);
        double u = rad_rng_uniform(&rng), v = rad_rng_uniform(&rng);
        vec3 y = v3_mad(rad_element_sample(mesh, e, u, v), e->normal, g->lift[j]);
        ray[count] = (rad_ray){ps->origin, v3_sub(y, ps->origin), 0.0, 1.0};
        pending[count++] = j;
    }
    /* Two at a time: a disagreement (or a clear ray where clear does not
     * count) ends the test without the others. */
    for (int first = 0; first < count; first += 2) {
        if ((clear > 0 && hidden > 0) || (clear > 0 && !clear_counts))
            break;
        int m = count - first < 2 ? count - first : 2;
        uint8_t blocked[2];
        vis->backend->occluded(vis->state, ray + first, (size_t)m, blocked);
        ps->cluster_rays += (uint64_t)m;
        for (int i = 0; i < m; i++) {
            known->element[known->count] = pending[first + i];
            known->blocked[known->count++] = blocked[i];
            blocked[i] ? hidden++ : clear++;
        }
    }
    if (clear > 0 && (hidden > 0 || !clear_counts))
        return -1;
    return hidden == 0 ? 1 : 0;
}

/* A far node as one source (cluster.c's header): per channel
 * (n . d)(-P . d) / (pi r^4), d = c - x, times (1 + k2), k2 the
 * second-order term of the kernel's Taylor expansion about the centre of
 * power c summed over the node's spread (its moment M, per unit weight),
 * the normals taken as the cone's axis m:
 *
 *   k2 = -2 tr M / r^2 + 12 d.Md / r^4
 *        + 4 (a m.Md - b n.Md) / (a b r^2) - n.Mm / (a b),
 *   a = n . d, b = -m . d
 *
 * (the first-order term is zero about c).  A disc of radius R facing the
 * point on its axis at height h: k2 = -R^2 / h^2, the series of the exact
 * R^2 / (h^2 + R^2).  The error left is of third order in the size over
 * the distance. */
static void cluster_add(point_sums *ps, const rad_gather_node *node)
{
    vec3 n = ps->n, m = node->axis;
    vec3 d = v3_sub(node->centre, ps->p);
    double r2 = v3_dot(d, d), a = v3_dot(n, d), b = -v3_dot(m, d);
    ps->cluster_pairs++;
    if (!(a > 0.0 && b > 0.0 && r2 > 0.0 && node->weight > 0.0))
        return;
    const double *M = node->moment;
    double w = 1.0 / node->weight;
    vec3 Md = {w * (M[0] * d.x + M[3] * d.y + M[4] * d.z), w * (M[3] * d.x + M[1] * d.y + M[5] * d.z),
               w * (M[4] * d.x + M[5] * d.y + M[2] * d.z)};
    vec3 Mm = {w * (M[0] * m.x + M[3] * m.y + M[4] * m.z), w * (M[3] * m.x + M[1] * m.y + M[5] * m.z),
               w * (M[4] * m.x + M[5] * m.y + M[2] * m.z)};
    double trace = w * (M[0] + M[1] + M[2]);
    double k2 = -2.0 * trace / r2 + 12.0 * v3_dot(d, Md) / (r2 * r2) +
                4.0 * (a * v3_dot(m, Md) - b * v3_dot(n, Md)) / (a * b * r2) - v3_dot(n, Mm) / (a * b);
    double scale = a * fmax(0.0, 1.0 + k2) / (M_PI * r2 * r2);
    for (int c = 0; c < 3; c++) {
        ps->direct[c] += fmax(0.0, -v3_dot(node->power_self[c], d)) * scale;
        ps->indirect[c] += fmax(0.0, -v3_dot(node->power_rest[c], d)) * scale;
    }
}

/* The tree's walk for one point (cluster.c's header has the summary):
 *
 *   - a node whose box lies wholly behind or in the point's plane, or
 *     whose elements all face away (the cone of normals against the cone
 *     of directions to its bounding sphere), sends nothing: skipped;
 *   - a node far enough, diameter / distance < theta (Barnes & Hut's
 *     opening criterion), is tested by rays to its representatives: all
 *     blocked, it sends nothing; all clear, with every element facing the
 *     point and the point facing every corner of its box, it counts as one
 *     source, (n . d) (-P . d) / (pi |d|^4) per channel; else it is opened;
 *   - a leaf reached (a near element, or a far one whose parent the rays
 *     or the orientation opened) is gathered exactly (gather_element).
 *
 * Children are visited in a fixed order, so the sums do not depend on the
 * thread. */
static void gather_tree(const gather_shared *g, point_sums *ps, ray_batch *b)
{
    const rad_gather_tree *tree = g->tree;
    if (tree->root == RAD_GATHER_LEAF)
        return;
    /* Depth-first; each entry with the rays its parent cast.  The stack
     * holds at most the tree's depth + 1 entries: median splits make it
     * ceil(log2 n) + 3 (the bins joined), 36 for 2^32 elements. */
    enum { DEPTH = 64 };
    uint32_t stack[DEPTH];
    known_rays rays[DEPTH];
    int top = 0;
    stack[top] = tree->root;
    rays[top++].count = 0;
    vec3 p = ps->p, n = ps->n, rlo = ps->reach_lo, rhi = ps->reach_hi;
    while (top > 0) {
        --top;
        const rad_gather_node *node = &tree->nodes[stack[top]];
        known_rays parent = rays[top], mine;
        mine.count = 0;
        /* Beyond the point's reach: nothing of it is seen. */
        if (!v3_boxes_meet(node->lo, node->hi, rlo, rhi))
            continue;
        vec3 centre = v3_scale(v3_add(node->lo, node->hi), 0.5), half = v3_scale(v3_sub(node->hi, node->lo), 0.5);
        double mid = v3_dot(n, v3_sub(centre, p));
        double ext = fabs(n.x) * half.x + fabs(n.y) * half.y + fabs(n.z) * half.z;
        if (mid + ext <= 0.0)
            continue;
        bool leaf = node->child[1] == RAD_GATHER_LEAF;
        vec3 w = v3_sub(p, centre);
        double dist = v3_length(w), radius = v3_length(half);
        if (dist > radius) {
            double beta = asin(radius / dist);
            double gamma = acos(fmin(fmax(v3_dot(node->axis, w) / dist, -1.0), 1.0));
            if (gamma - node->spread - beta >= 0.5 * M_PI)
                continue;
            if (!leaf && 2.0 * radius < g->theta * dist) {
                /* Counted as one source: not emitters (their self-emission
                 * is the direct part: a cluster of them may be found
                 * blocked, never summed), every element facing the point
                 * and the point facing all the box, and small against the
                 * distance times both cosines, since the expansion is in
                 * size over distance divided by the cosines (a grazing
                 * wall beside the point is opened). */
                double facing = cos(fmin(gamma + node->spread, 0.5 * M_PI));
                bool one_sided = !node->emits && mid - ext > 0.0 && gamma + node->spread + beta < 0.5 * M_PI &&
                                 2.0 * radius < g->theta * fmin(mid, dist * facing);
                int seen = cluster_visible(g, ps, node, &parent, one_sided, &mine);
                /* Found blocked, it sends nothing, as the exact path where
                 * that casts a ray or so per element.  On a surface the exact path's
                 * visibility is exact (occluders.c), so only a node whose
                 * rays sample eight distinct elements is taken as blocked:
                 * a few elements' centres hidden by a block's edge do not
                 * hide their area (tree_cornell). */
                if (seen == 0 && (!ps->re || node->reps == RAD_GATHER_REPS)) {
                    ps->cluster_pairs++;
                    continue;
                }
                if (seen == 1) {
                    cluster_add(ps, node);
                    continue;
                }
            }
        }
        if (leaf) {
            gather_element(g, ps, node->child[0], b);
            continue;
        }
        stack[top] = node->child[1];
        rays[top++] = mine.count ? mine : parent;
        stack[top] = node->child[0];
        rays[top++] = mine.count ? mine : parent;
    }
}

static void gather_point(const gather_shared *g, size_t index, ray_batch *b, double direct[3],
                         double indirect[3], uint64_t counts[4], double *light_seconds)
{
    const rad_solution_view *view = g->view;
    const rad_mesh *mesh = view->mesh;
    point_sums ps;
    memset(&ps, 0, sizeof ps);
    ps.index = index;
    ps.p = g->set->position[index];
    ps.n = g->set->normal[index];
    ps.direct = direct;
    ps.indirect = indirect;
    double t0 = rad_seconds();
    rad_light_among reach = {NULL, 0, view->light_reach};
    rad_light_irradiance_among(view->scene, mesh, view->vis, ps.p, ps.n, &reach, direct);
    *light_seconds += rad_seconds() - t0;
    indirect[0] = indirect[1] = indirect[2] = 0.0;
    ps.recv = g->recv[index];
    ps.re = ps.recv >= 0 ? &mesh->elements[ps.recv] : NULL;
    ps.origin = v3_mad(ps.p, ps.n, g->eps);
    if (g->tree) {
        if (view->vis)
            rad_vis_reach(view->vis, ps.origin, 0.0, RAD_GRID_REACH_FAN, 4.0 * g->eps, &ps.reach_lo, &ps.reach_hi);
        else
            ps.reach_lo = v3(-INFINITY, -INFINITY, -INFINITY), ps.reach_hi = v3(INFINITY, INFINITY, INFINITY);
        gather_tree(g, &ps, b);
    }
    else
        for (size_t j = 0; j < view->n; j++)
            gather_element(g, &ps, j, b);
    flush(g, b, direct, indirect);
    counts[0] += ps.exact_pairs;
    counts[1] += ps.ray_pairs;
    counts[2] += ps.cluster_pairs;
    counts[3] += ps.cluster_rays;
}

rad_result rad_grid_gather(rad_context *ctx, const rad_solution_view *view, const rad_grid_set *set,
                           rad_grid_gather_method method, double *direct, double *indirect,
                           rad_grid_gather_stats *stats)
{
    return rad_grid_gather_tuned(ctx, view, set, method, 0.0, 0, direct, indirect, stats);
}

rad_result rad_grid_gather_tuned(rad_context *ctx, const rad_solution_view *view, const rad_grid_set *set,
                                 rad_grid_gather_method method, double theta, int strata, double *direct,
                                 double *indirect, rad_grid_gather_stats *stats)
{
    memset(stats, 0, sizeof *stats);
    double t0 = rad_seconds();
    size_t n = view->n, points = set->point_count;
    const rad_mesh *mesh = view->mesh;
    int threads = view->threads > 0 ? view->threads : 1;
    double *self = rad_alloc(ctx, RAD_MEM_RENDER, 3 * n + 1, sizeof *self, "illuminance: self-emission");
    float *diameter = rad_alloc(ctx, RAD_MEM_RENDER, n + 1, sizeof *diameter, "illuminance: element sizes");
    double *lift = rad_alloc(ctx, RAD_MEM_RENDER, n + 1, sizeof *lift, "illuminance: element sizes");
    int64_t *recv = rad_alloc(ctx, RAD_MEM_RENDER, points + 1, sizeof *recv, "illuminance: the points' surfaces");
    ray_batch *batches = rad_alloc(ctx, RAD_MEM_RENDER, (size_t)threads, sizeof *batches, "illuminance: rays");
    void *block = NULL;
    const rad_ff_occluders *occ = NULL;
    rad_result r = self && diameter && lift && recv && batches ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
    /* The points on surfaces first: the occluder classification serves
     * only them, so a grid of work planes in the air does without it. */
    int on_surfaces = 0;
    gather_shared probe = {.view = view, .eps = rad_vis_epsilon(mesh)};
    if (r == RAD_OK) {
#pragma omp parallel for schedule(static) num_threads(threads) reduction(+ : on_surfaces)
        for (size_t k = 0; k < points; k++) {
            recv[k] = receiver_of(&probe, set->position[k], set->normal[k]);
            on_surfaces += recv[k] >= 0;
        }
    }
    if (r == RAD_OK && view->vis && on_surfaces > 0)
        r = rad_ff_occluders_build(ctx, mesh, 0, &block, &occ);
    if (r != RAD_OK) {
        rad_free(self);
        rad_free(diameter);
        rad_free(lift);
        rad_free(recv);
        rad_free(batches);
        rad_free(block);
        return r;
    }
    /* Self-emission: the element's emission less the first reflection of
     * the direct light the strategies added to it (strategy.h). */
    for (size_t j = 0; j < n; j++) {
        for (int c = 0; c < 3; c++) {
            size_t at = 3 * j + (size_t)c;
            self[at] = view->emission[at] - (view->direct ? view->reflectance[at] * view->direct[at] : 0.0);
            if (self[at] < 0.0)
                self[at] = 0.0;
        }
        const rad_element *e = &mesh->elements[j];
        double d = 0.0;
        for (uint32_t a = 0; a < e->vertex_count; a++)
            for (uint32_t b = a + 1; b < e->vertex_count; b++)
                d = fmax(d, v3_length(v3_sub(mesh->vertices[e->vertex[a]], mesh->vertices[e->vertex[b]])));
        diameter[j] = (float)d;
        lift[j] = probe.eps + rad_element_bend(mesh, e);
    }
    bool use_tree = method == RAD_GRID_GATHER_TREE ||
                    (method == RAD_GRID_GATHER_AUTO && view->n >= RAD_GRID_GATHER_TREE_MIN);
    rad_gather_tree *tree = NULL;
    if (use_tree && (r = rad_gather_tree_build(ctx, view, self, &tree)) != RAD_OK) {
        rad_free(self);
        rad_free(diameter);
        rad_free(lift);
        rad_free(recv);
        rad_free(batches);
        rad_free(block);
        return r;
    }
    gather_shared g = {view, set, occ, self, diameter, lift, recv, rad_vis_epsilon(mesh),
                       rad_ff_plane_tolerance(mesh), view->options ? view->options->seed : 0, tree,
                       theta > 0.0 ? theta : RAD_GRID_GATHER_THETA, strata > 0 ? strata : 0};
    int done = 0, skipped = 0;
    uint64_t exact = 0, by_rays = 0, clusters = 0, cluster_rays = 0;
    double light = 0.0, busy = 0.0;
    rad_progress(ctx, "illuminance", 0, (uint64_t)points);
#pragma omp parallel num_threads(threads) reduction(+ : exact, by_rays, clusters, cluster_rays, light, busy)
    {
        int thread = 0;
#ifdef _OPENMP
        thread = omp_get_thread_num();
#endif
        ray_batch *b = &batches[thread];
        double start = rad_seconds();
#pragma omp for schedule(dynamic, 4) nowait
        for (size_t k = 0; k < points; k++) {
            if (rad_cancelled(ctx)) {
#pragma omp atomic update
                skipped++;
                continue;
            }
            uint64_t counts[4] = {0, 0, 0, 0};
            gather_point(&g, k, b, direct + 3 * k, indirect + 3 * k, counts, &light);
            exact += counts[0];
            by_rays += counts[1];
            clusters += counts[2];
            cluster_rays += counts[3];
            int now;
#pragma omp atomic capture
            now = ++done;
            if (thread == 0)
                rad_progress(ctx, "illuminance", (uint64_t)now, (uint64_t)points);
        }
        busy += rad_seconds() - start;
    }
    rad_progress(ctx, "illuminance", (uint64_t)done, (uint64_t)points);
    for (int t = 0; t < threads; t++)
        stats->rays += batches[t].rays;
    stats->rays += cluster_rays;
    stats->exact_pairs = exact;
    stats->ray_pairs = by_rays;
    stats->cluster_pairs = clusters;
    stats->cluster_rays = cluster_rays;
    stats->tree = tree != NULL;
    stats->seconds = rad_seconds() - t0;
    stats->light_seconds = light;
    stats->thread_seconds = busy;
    rad_free(self);
    rad_free(diameter);
    rad_free(lift);
    rad_free(recv);
    rad_free(batches);
    rad_free(block);
    rad_gather_tree_destroy(tree);
    if (skipped > 0)
        return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "illuminance: interrupted after %d of %zu points", done, points);
    return RAD_OK;
}
