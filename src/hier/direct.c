/*
 * direct.c -- luminaires and daylight in the hierarchy: each surface node's
 * direct irradiance H_d, the mean over its polygon from the light module
 * (rad_light_polygon_irradiance: adaptive cubature, shadow rays), computed
 * once when the node is made, and leaves split where that light varies.
 *
 * The light enters the solve as the dense strategies take it (E += rho H_d
 * per element, strategy/shared.c): a leaf's radiosity is
 *
 *     B = E + rho (H + H_d)          H: what its links and its ancestors' gather
 *
 * (hier.c, push_pull), so the first reflection of the direct light is exact
 * per leaf and the links carry only the interreflection.  Internal nodes
 * keep their own mean, which their leaves' area average equals to the
 * cubature's tolerance; the clusters' exitance follows through the pull.
 *
 * The oracle's direct term (Hanrahan, Salzman & Aupperle's receiver term,
 * with the light's irradiance in place of a link's): a leaf whose direct
 * light differs from its mean by up to dev somewhere reflects a power whose
 * distribution is off by up to rho A dev, charged against the same epsilon
 * (W) as the links.  Such a leaf is split (never below min_area, as any
 * split), its children get their own H_d, and so on: leaves follow
 * luminaires' shadows, the sun patch and a window's edge of light.  A leaf
 * the link refinement makes later gets its H_d then (hr_direct_update after
 * each round), and is tested alike.
 *
 *      floor under a luminaire, an obstacle's shadow edge ----/
 *      +-------+-------+---+-+-+-+
 *      |       |       |   |/| | |   the leaves the edge crosses split
 *      |       |       +---/-+-+-+   down to min_area; the lit and the
 *      |       |       |  /|   |     shadowed sides stay coarse
 *      +-------+-------+-/-+---+
 *
 * Which luminaires: those whose reach (light/reach.c: a box per luminaire
 * from a fan of rays) meets the node's patch, listed once per patch.  The
 * cost per node is its room's luminaires and its neighbours', not the
 * building's.
 *
 * Each node's cubature runs in two steps (light.h): _start, 16 to 20
 * points, tells the mean and how much the light varies; a node that
 * will split stops there (its children carry the light), the leaves
 * _finish from where _start left, to the cubature's tolerance or a tenth
 * of epsilon's share of reflected power, whichever is looser (the links'
 * own bound, refine.c, is epsilon: 10 rooms, 40 downlights, from 4.9 M
 * points to 0.65 M, per-room Eavg the same to 0.1%).  No point is
 * evaluated twice.
 *
 * Determinism: the values are computed in parallel, each node alone; nodes
 * are split serially in node order, so node numbers do not depend on the
 * thread count.  Without luminaires or daylight nothing here runs and no
 * memory is taken (H stays NULL).
 */
#include "hier/hier.h"

#include "light/light.h"

#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* Grow the per-node arrays to n nodes and the pending cubatures to the
 * nodes [done, n).  Fails for memory. */
static rad_result grow(rad_context *ctx, hr_direct *d, size_t n)
{
    if (n > d->capacity) {
        size_t cap = d->capacity ? d->capacity : 1024;
        while (cap < n)
            cap *= 2;
        double *H = rad_realloc(ctx, RAD_MEM_HIERARCHY, d->H, 3 * cap, sizeof *H,
                                "hierarchical: direct light of the nodes");
        if (H)
            d->H = H;
        float *dev = H ? rad_realloc(ctx, RAD_MEM_HIERARCHY, d->deviation, cap, sizeof *dev,
                                     "hierarchical: direct light of the nodes")
                       : NULL;
        if (dev)
            d->deviation = dev;
        if (!H || !dev)
            return RAD_ERROR_OUT_OF_MEMORY;
        d->capacity = cap;
    }
    if (n - d->done > d->pending_capacity) {
        size_t cap = n - d->done;
        rad_light_cubature *p = rad_realloc(ctx, RAD_MEM_HIERARCHY, d->pending, cap, sizeof *p,
                                            "hierarchical: direct light of the new nodes");
        if (!p)
            return RAD_ERROR_OUT_OF_MEMORY;
        d->pending = p;
        d->pending_capacity = cap;
    }
    return RAD_OK;
}

/* The luminaires node k asks (all without a reach): its patch's list, of
 * which a node below the root keeps those whose reach meets its own box
 * (a floor's list has the next room's luminaires, whose light comes
 * through the door; most of its nodes are out of that light), into this
 * thread's node_list. */
static rad_light_among among(const hr_tree *tree, const hr_direct *d, uint32_t k)
{
    if (!d->list_start)
        return (rad_light_among){NULL, 0, NULL};
    static const uint32_t nothing[1] = {0};
    const hr_node *nd = &tree->nodes[k];
    uint32_t from = d->list_start[nd->patch], to = d->list_start[nd->patch + 1];
    if (to == from)
        return (rad_light_among){nothing, 0, NULL};
    if (nd->level == 0)
        return (rad_light_among){d->list + from, to - from, NULL};
#ifdef _OPENMP
    uint32_t *mine = d->node_list + (size_t)omp_get_thread_num() * d->list_max;
#else
    uint32_t *mine = d->node_list;
#endif
    size_t m = 0;
    for (uint32_t i = from; i < to; i++)
        if (rad_light_reach_meets(d->reach, d->list[i], nd->lo, nd->hi))
            mine[m++] = d->list[i];
    return (rad_light_among){m ? mine : nothing, m, NULL};
}

/* Start the nodes [d->count, tree->count) in parallel: their coarse mean
 * in H, their deviation, their cubature kept pending.  Fails for memory or
 * cancellation. */
static rad_result start_new(rad_context *ctx, const hr_tree *tree, hr_direct *d)
{
    size_t from = d->count, n = tree->count;
    if (n == from)
        return RAD_OK;
    rad_result r = grow(ctx, d, n);
    if (r != RAD_OK)
        return r;
    volatile int stop = 0;
    /* Each node alone: its values do not depend on the schedule. */
#pragma omp parallel for schedule(dynamic, 16) num_threads(rad_context_threads(ctx))
    for (size_t k = from; k < n; k++) {
        const hr_node *nd = &tree->nodes[k];
        double *h = &d->H[3 * k], dev = 0.0;
        rad_light_cubature *cub = &d->pending[k - d->done];
        memset(cub, 0, sizeof *cub);
        h[0] = h[1] = h[2] = 0.0;
        if (!stop && nd->kind == HR_SURFACE) {
            rad_light_among set = among(tree, d, (uint32_t)k);
            rad_light_polygon_start(d->scene, d->base, d->vis, nd->corner, nd->corners, nd->normal, &set, cub, h,
                                    &dev);
        }
        d->deviation[k] = (float)dev;
        if (rad_cancelled(ctx))
            stop = 1;
    }
    if (stop)
        return RAD_ERROR_INTERRUPTED;
    d->count = n;
    return RAD_OK;
}

/* Whether leaf k's light varies more than epsilon (W) allows: split it. */
static bool varies(const hr_tree *tree, const hr_direct *d, size_t k, double epsilon)
{
    const hr_node *nd = &tree->nodes[k];
    return nd->kind == HR_SURFACE && nd->child[0] == 0 && (double)nd->rho * nd->area * d->deviation[k] > epsilon &&
           hr_splittable(tree, (uint32_t)k);
}

/* Finish the pending nodes that are leaves, in parallel (only leaves
 * read H_d: B = E + rho (H + H_d), hier.c's push_pull). */
static rad_result finish_pending(rad_context *ctx, const hr_tree *tree, hr_direct *d, double epsilon)
{
    size_t from = d->done, n = d->count;
    volatile int stop = 0;
#pragma omp parallel for schedule(dynamic, 16) num_threads(rad_context_threads(ctx))
    for (size_t k = from; k < n; k++) {
        const hr_node *nd = &tree->nodes[k];
        if (stop || nd->kind != HR_SURFACE || nd->child[0] != 0)
            continue;
        rad_light_among set = among(tree, d, (uint32_t)k);
        /* The integral to a tenth of epsilon's share of reflected power
         * (the deviation was read when the leaf was started: not again). */
        double tolerance = nd->rho > 0.0f ? 0.1 * epsilon / (double)nd->rho : INFINITY;
        rad_light_polygon_finish(d->scene, d->base, d->vis, nd->corner, nd->corners, nd->normal, &set, tolerance,
                                 &d->pending[k - from], &d->H[3 * k], NULL);
        if (rad_cancelled(ctx))
            stop = 1;
    }
    if (stop)
        return RAD_ERROR_INTERRUPTED;
    d->done = n;
    return RAD_OK;
}

/* The per-patch lists of luminaires whose reach meets the patch's box
 * (serial: a box test per patch and luminaire is cheap beside one shadow
 * ray), appended in patch order to a list grown by doubling. */
static rad_result patch_lists(rad_context *ctx, const hr_tree *tree, const rad_light_reach *reach, hr_direct *d)
{
    size_t patches = tree->base->patch_count, lums = tree->scene->luminaires.count;
    size_t total = 0, capacity = lums + 1;
    d->list_start = rad_alloc(ctx, RAD_MEM_HIERARCHY, patches + 1, sizeof *d->list_start,
                              "hierarchical: the luminaires each patch asks");
    d->list = d->list_start ? rad_alloc(ctx, RAD_MEM_HIERARCHY, capacity, sizeof *d->list,
                                        "hierarchical: the luminaires each patch asks")
                            : NULL;
    if (!d->list)
        return RAD_ERROR_OUT_OF_MEMORY;
    d->list_capacity = capacity;
    for (size_t p = 0; p < patches; p++) {
        if (total + lums > capacity) {
            capacity = 2 * capacity > total + lums ? 2 * capacity : total + lums;
            uint32_t *grown = rad_realloc(ctx, RAD_MEM_HIERARCHY, d->list, capacity, sizeof *grown,
                                          "hierarchical: the luminaires each patch asks");
            if (!grown)
                return RAD_ERROR_OUT_OF_MEMORY;
            d->list = grown;
            d->list_capacity = capacity;
        }
        const hr_node *root = &tree->nodes[tree->root_of_patch[p]];
        vec3 lo = root->corner[0], hi = root->corner[0];
        for (uint32_t c = 1; c < root->corners; c++) {
            lo = v3_min(lo, root->corner[c]);
            hi = v3_max(hi, root->corner[c]);
        }
        if (total > UINT32_MAX)
            return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "hierarchical: over 4 billion patch-luminaire pairs in reach");
        d->list_start[p] = (uint32_t)total;
        size_t listed = rad_light_reach_list(reach, lo, hi, d->list + total);
        total += listed;
        d->list_max = listed > d->list_max ? listed : d->list_max;
    }
    if (total > UINT32_MAX)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "hierarchical: over 4 billion patch-luminaire pairs in reach");
    d->list_start[patches] = (uint32_t)total;
    d->reach = reach;
    d->node_list = rad_alloc(ctx, RAD_MEM_HIERARCHY, (size_t)rad_context_threads(ctx) * d->list_max + 1,
                             sizeof *d->node_list, "hierarchical: the luminaires each node asks");
    return d->node_list ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
}

rad_result hr_direct_start(rad_context *ctx, const hr_tree *tree, const rad_vis *vis,
                           const rad_light_reach *reach, hr_direct *d, double *reflected)
{
    memset(d, 0, sizeof *d);
    *reflected = 0.0;
    if (!rad_light_present(tree->scene))
        return RAD_OK;
    d->scene = tree->scene;
    d->base = tree->base;
    d->vis = vis;
    rad_result r = reach ? patch_lists(ctx, tree, reach, d) : RAD_OK;
    if (r == RAD_OK)
        r = start_new(ctx, tree, d);
    if (r != RAD_OK)
        return r;
    /* The roots' first reflection, sum A rho H_d (channels summed), in node
     * order, from their coarse means (this only scales epsilon). */
    for (size_t k = tree->clusters; k < tree->count; k++) {
        const hr_node *nd = &tree->nodes[k];
        if (nd->kind != HR_SURFACE || (nd->parent != HR_NONE && tree->nodes[nd->parent].kind == HR_SURFACE))
            continue;
        const double *rho = hr_node_reflectance(tree, (uint32_t)k);
        for (int c = 0; c < 3; c++)
            *reflected += nd->area * rho[c] * d->H[3 * k + (size_t)c];
    }
    return RAD_OK;
}

rad_result hr_direct_update(rad_context *ctx, hr_tree *tree, hr_direct *d, double epsilon, size_t *split)
{
    *split = 0;
    if (!d->H)
        return RAD_OK;
    for (;;) {
        rad_result r = start_new(ctx, tree, d);
        if (r != RAD_OK)
            return r;
        /* The pending leaves whose light varies more than epsilon allows
         * are split, in node order (hr_subdivide appends their children,
         * started on the next pass); the other leaves are finished. */
        size_t made = 0;
        for (size_t k = d->done; k < d->count; k++) {
            if (!varies(tree, d, k, epsilon))
                continue;
            if ((r = hr_subdivide(ctx, tree, (uint32_t)k)) != RAD_OK)
                return r;
            made++;
        }
        if ((r = finish_pending(ctx, tree, d, epsilon)) != RAD_OK)
            return r;
        *split += made;
        if (made == 0)
            return RAD_OK;
    }
}

/* The leaves' H_d below node k in the leaf mesh's order (hier.c's encode:
 * depth first, children in order). */
static void leaf_walk(const hr_tree *tree, const hr_direct *d, uint32_t k, double *out, size_t *i)
{
    const hr_node *n = &tree->nodes[k];
    if (n->child[0] == 0) {
        memcpy(out + 3 * (*i)++, d->H + 3 * (size_t)k, 3 * sizeof *out);
        return;
    }
    for (uint32_t c = 0; c < 4; c++)
        leaf_walk(tree, d, n->child[0] + c, out, i);
}

rad_result hr_direct_leaves(rad_context *ctx, const hr_tree *tree, const hr_direct *d, size_t leaves,
                            double **out)
{
    *out = NULL;
    if (!d->H)
        return RAD_OK;
    double *H = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * leaves + 1, sizeof *H, "solution: direct light");
    if (!H)
        return RAD_ERROR_OUT_OF_MEMORY;
    size_t i = 0;
    for (size_t p = 0; p < tree->base->patch_count; p++)
        leaf_walk(tree, d, tree->root_of_patch[p], H, &i);
    *out = H;
    return RAD_OK;
}

double hr_direct_bytes(const hr_direct *d)
{
    return (double)d->capacity * (3.0 * sizeof(double) + sizeof(float)) +
           (double)d->pending_capacity * sizeof(rad_light_cubature) +
           (d->list_start ? (double)(d->base->patch_count + 1 + d->list_capacity) * sizeof(uint32_t) : 0.0) +
           (d->node_list ? (double)d->list_max * sizeof(uint32_t) : 0.0);
}

void hr_direct_free(hr_direct *d)
{
    rad_free(d->H);
    rad_free(d->deviation);
    rad_free(d->pending);
    rad_free(d->list_start);
    rad_free(d->list);
    rad_free(d->node_list);
    memset(d, 0, sizeof *d);
}
