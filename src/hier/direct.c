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
 * Which luminaires: a root asks every one and keeps the mask of those that
 * lit one of its cubature points; the nodes below it ask only those.  A
 * node is lit by what lights its patch, and the cost per node is its room's
 * luminaires, not the building's (10 rooms, 40 downlights: 42 s -> 15 s on
 * one thread, Eavg the same to 1e-6; docs/hierarchical.md "Cost").
 *
 * Determinism: the values are computed in parallel, each node alone; nodes
 * are split serially in node order, so node numbers do not depend on the
 * thread count.  Without luminaires or daylight nothing here runs and no
 * memory is taken (H stays NULL).
 */
#include "hier/hier.h"

#include "light/light.h"

#include <string.h>

/* Grow the arrays to the tree and fill the values of nodes [d->count,
 * tree->count) in parallel; those the oracle will split (light varying by
 * more than epsilon allows, hr_direct_update) from a coarser cubature.
 * Fails for memory or cancellation. */
enum { COARSE_DEPTH = 2 };

static rad_result compute_new(rad_context *ctx, const hr_tree *tree, hr_direct *d, double epsilon)
{
    size_t from = d->count, n = tree->count;
    if (n == from)
        return RAD_OK;
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
    volatile int stop = 0;
    /* Each node alone: its values do not depend on the schedule. */
#pragma omp parallel for schedule(dynamic, 16) num_threads(rad_context_threads(ctx))
    for (size_t k = from; k < n; k++) {
        const hr_node *nd = &tree->nodes[k];
        double *h = &d->H[3 * k];
        double dev = 0.0;
        h[0] = h[1] = h[2] = 0.0;
        if (!stop && nd->kind == HR_SURFACE) {
            /* A root asks every luminaire and keeps those that lit it;
             * the nodes below ask only those (above). */
            bool root = nd->parent == HR_NONE || tree->nodes[nd->parent].kind == HR_CLUSTER;
            uint64_t *mask = d->reached + (size_t)nd->patch * d->words;
            rad_light_among set = {root ? NULL : mask, root ? mask : NULL};
            /* A node whose light varies enough to split it is only read for
             * that (its leaves carry the light): two levels of the cubature
             * tell it; the others get all four. */
            rad_light_polygon_irradiance(d->scene, d->base, d->vis, nd->corner, nd->corners, nd->normal, &set,
                                         COARSE_DEPTH, h, &dev);
            if (!((double)nd->rho * nd->area * dev > epsilon && hr_splittable(tree, (uint32_t)k)))
                rad_light_polygon_irradiance(d->scene, d->base, d->vis, nd->corner, nd->corners, nd->normal, &set, 0,
                                             h, &dev);
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

rad_result hr_direct_start(rad_context *ctx, const hr_tree *tree, const rad_vis *vis, hr_direct *d,
                           double *reflected)
{
    memset(d, 0, sizeof *d);
    *reflected = 0.0;
    if (!rad_light_present(tree->scene))
        return RAD_OK;
    d->scene = tree->scene;
    d->base = tree->base;
    d->vis = vis;
    d->words = rad_light_mask_words(tree->scene);
    d->reached = rad_alloc(ctx, RAD_MEM_HIERARCHY, tree->base->patch_count * d->words + 1, sizeof *d->reached,
                           "hierarchical: the luminaires each patch sees");
    if (!d->reached)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = compute_new(ctx, tree, d, INFINITY);
    if (r != RAD_OK)
        return r;
    /* The roots' first reflection, sum A rho H_d (channels summed), in node
     * order. */
    for (size_t k = tree->clusters; k < tree->count; k++) {
        const hr_node *nd = &tree->nodes[k];
        if (nd->kind != HR_SURFACE || (nd->parent != HR_NONE && tree->nodes[nd->parent].kind == HR_SURFACE))
            continue;
        const double *rho = tree->scene->materials[tree->base->patches[nd->patch].material].reflectance;
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
        size_t from = d->count;
        rad_result r = compute_new(ctx, tree, d, epsilon);
        if (r != RAD_OK)
            return r;
        /* The new leaves whose light varies more than epsilon allows, in
         * node order (hr_subdivide appends their children). */
        size_t end = tree->count, made = 0;
        for (size_t k = from; k < end; k++) {
            const hr_node *nd = &tree->nodes[k];
            if (nd->kind != HR_SURFACE || nd->child[0] || !hr_splittable(tree, (uint32_t)k))
                continue;
            if (!((double)nd->rho * nd->area * d->deviation[k] > epsilon))
                continue;
            if ((r = hr_subdivide(ctx, tree, (uint32_t)k)) != RAD_OK)
                return r;
            made++;
        }
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
           (d->reached ? (double)d->base->patch_count * (double)d->words * sizeof(uint64_t) : 0.0);
}

void hr_direct_free(hr_direct *d)
{
    rad_free(d->H);
    rad_free(d->deviation);
    rad_free(d->reached);
    memset(d, 0, sizeof *d);
}
