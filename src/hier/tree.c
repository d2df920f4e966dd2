/*
 * tree.c -- the node hierarchy of hierarchical radiosity.
 *
 * Roots.  Every base patch (a planar quad or triangle, mesh.h) is the root
 * of a quadtree of surface nodes.  A quad splits at its edge midpoints and
 * bilinear centre into the four parameter quadrants; a triangle into its
 * three corner triangles and the medial one:
 *
 *     c3 +----m23----+ c2          c2
 *        |  3  |  2  |               |\
 *    m30 +----mc-----+ m12       m20 +--+ m12      children: 0 (c0 m01 m20)
 *        |  0  |  1  |               |\3|\                   1 (m01 c1 m12)
 *     c0 +----m01----+ c1         c0 +--+--+ c1              2 (m20 m12 c2)
 *                                      m01                   3 (m01 m12 m20)
 *
 * (rad_ff_split4, the quadratures' refinement step), so a child's
 * parameters follow from its parent's (mesh/grid.c locates leaves the same way).  Children are created on demand, four consecutive nodes,
 * always after their parent: index order is a topological order.
 *
 * Clusters.  With clustering, a binary bounding-volume hierarchy is built
 * over the patches (median split of the centroids along the longest axis of
 * their bounds; ties broken by patch index, so it is deterministic).  Its
 * P - 1 clusters come first, in pre-order (node 0 is the top), then the P
 * roots in cluster order, so every cluster's patches are one range of
 * order[].
 */
#include "hier/hier.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static void surface_geometry(hr_node *n)
{
    vec3 a = n->corner[0], b = n->corner[1], c = n->corner[2];
    vec3 lo = v3_min(a, v3_min(b, c)), hi = v3_max(a, v3_max(b, c));
    if (n->corners == 3) {
        n->area = 0.5 * v3_length(v3_cross(v3_sub(b, a), v3_sub(c, a)));
        n->center = v3_scale(v3_add(a, v3_add(b, c)), 1.0 / 3.0);
    } else {
        vec3 d = n->corner[3];
        lo = v3_min(lo, d);
        hi = v3_max(hi, d);
        double a1 = 0.5 * v3_length(v3_cross(v3_sub(b, a), v3_sub(c, a)));
        double a2 = 0.5 * v3_length(v3_cross(v3_sub(c, a), v3_sub(d, a)));
        n->area = a1 + a2;
        vec3 c1 = v3_scale(v3_add(a, v3_add(b, c)), 1.0 / 3.0);
        vec3 c2 = v3_scale(v3_add(a, v3_add(c, d)), 1.0 / 3.0);
        n->center = n->area > 0.0 ? v3_scale(v3_add(v3_scale(c1, a1), v3_scale(c2, a2)), 1.0 / n->area)
                                  : c1;
    }
    n->lo = lo;
    n->hi = hi;
    double r = 0.0;
    for (int k = 0; k < n->corners; k++)
        r = fmax(r, v3_length(v3_sub(n->corner[k], n->center)));
    n->radius = r;
}

void *hr_grow(rad_context *ctx, void *items, size_t *capacity, size_t count, size_t size, const char *what)
{
    size_t cap = *capacity ? *capacity : 1024;
    while (cap < count)
        cap *= 2;
    void *grown = rad_realloc(ctx, RAD_MEM_HIERARCHY, items, cap, size, what);
    if (grown)
        *capacity = cap;
    return grown;
}

static rad_result reserve(rad_context *ctx, hr_tree *t, size_t extra)
{
    if (t->count + extra <= t->capacity)
        return RAD_OK;
    hr_node *nodes = hr_grow(ctx, t->nodes, &t->capacity, t->count + extra, sizeof *nodes,
                             "hierarchical: nodes (a larger rad_options.min_area or rad_options.epsilon makes fewer)");
    if (!nodes)
        return RAD_ERROR_OUT_OF_MEMORY;
    t->nodes = nodes;
    if (t->scene->texture_count > 0) {
        double *rgb = hr_grow(ctx, t->reflectance, &t->reflectance_capacity, 3 * t->capacity, sizeof *rgb,
                              "hierarchical: textured reflectance of the nodes");
        if (!rgb)
            return RAD_ERROR_OUT_OF_MEMORY;
        t->reflectance = rgb;
    }
    return RAD_OK;
}

/* Surface node n's reflectance into rgb (3 doubles): its material's, or
 * with a texture the texels' mean over the node; n->rho its largest
 * channel, plus a mirror's rho_s (what it sends on through the mirror
 * links, hier/mirror.c: the oracle refines what reaches a mirror as what
 * reaches a white wall).  rgb may be NULL where the scene has no texture. */
static void surface_reflectance(hr_tree *t, hr_node *n, double *rgb)
{
    const rad_patch *pa = &t->base->patches[n->patch];
    const rad_material *m = &t->scene->materials[pa->material];
    const double *rho = m->reflectance;
    if (rgb) {
        memcpy(rgb, rho, 3 * sizeof *rgb);
        rad_texture_mean(t->scene, pa->polygon, n->corner, n->corners, n->area, rgb);
        rho = rgb;
    }
    double most = fmax(rho[0], fmax(rho[1], rho[2]));
    if (m->specular_kind == RAD_SPECULAR_MIRROR)
        most += (m->specular[0] + m->specular[1] + m->specular[2]) / 3.0;
    n->rho = (float)most;
    t->rho_max = fmaxf(t->rho_max, n->rho);
}

double hr_projected(const hr_tree *t, uint32_t k, vec3 d)
{
    const hr_node *n = &t->nodes[k];
    if (n->kind == HR_SURFACE)
        return n->area * fmax(0.0, v3_dot(n->normal, d));
    return hr_bins_eval(&t->cluster_bins[6 * (size_t)k], d);
}

/* ---- the cluster hierarchy ---- */

typedef struct sort_item {
    double key;
    uint32_t patch;
} sort_item;

static int sort_item_cmp(const void *pa, const void *pb)
{
    const sort_item *a = pa, *b = pb;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    return (a->patch > b->patch) - (a->patch < b->patch);
}

typedef struct bvh_builder {
    hr_tree *tree;
    hr_node *roots;           /* per patch, placed after the build */
    sort_item *scratch;
    uint32_t next_cluster;    /* pre-order counter */
    uint32_t first_root;      /* P - 1 */
} bvh_builder;

/* A node being built: a cluster, or (index >= first_root) the root at that
 * position of order[]. */
static const hr_node *bvh_node(const bvh_builder *b, uint32_t index)
{
    if (index >= b->first_root)
        return &b->roots[b->tree->order[index - b->first_root]];
    return &b->tree->nodes[index];
}

/* Build the subtree over order[first, first + count); returns its node. */
static uint32_t bvh_build(bvh_builder *b, uint32_t parent, uint32_t first, uint32_t count)
{
    hr_tree *t = b->tree;
    if (count == 1) {
        b->roots[t->order[first]].parent = parent;
        return b->first_root + first;
    }
    uint32_t k = b->next_cluster++;
    vec3 clo = v3(INFINITY, INFINITY, INFINITY), chi = v3(-INFINITY, -INFINITY, -INFINITY);
    for (uint32_t i = first; i < first + count; i++) {
        vec3 c = b->roots[t->order[i]].center;
        clo = v3_min(clo, c);
        chi = v3_max(chi, c);
    }
    vec3 ext = v3_sub(chi, clo);
    int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    for (uint32_t i = 0; i < count; i++) {
        uint32_t p = t->order[first + i];
        vec3 c = b->roots[p].center;
        b->scratch[i].key = axis == 0 ? c.x : (axis == 1 ? c.y : c.z);
        b->scratch[i].patch = p;
    }
    qsort(b->scratch, count, sizeof *b->scratch, sort_item_cmp);
    for (uint32_t i = 0; i < count; i++)
        t->order[first + i] = b->scratch[i].patch;
    uint32_t half = count / 2;
    uint32_t c0 = bvh_build(b, k, first, half);
    uint32_t c1 = bvh_build(b, k, first + half, count - half);
    const hr_node *a = bvh_node(b, c0), *d = bvh_node(b, c1);
    hr_node *n = &t->nodes[k];
    memset(n, 0, sizeof *n);
    n->kind = HR_CLUSTER;
    n->parent = parent;
    n->patch = first;
    n->patch_count = count;
    n->child[0] = c0;
    n->child[1] = c1;
    n->lo = v3_min(a->lo, d->lo);
    n->hi = v3_max(a->hi, d->hi);
    n->center = v3_scale(v3_add(n->lo, n->hi), 0.5);
    n->radius = 0.5 * v3_length(v3_sub(n->hi, n->lo));
    n->area = a->area + d->area;
    n->rho = fmaxf(a->rho, d->rho);
    return k;
}

rad_result hr_tree_build(rad_context *ctx, const rad_mesh *base, const rad_scene *scene, bool clustered,
                         double min_area, double eps, hr_tree *t)
{
    memset(t, 0, sizeof *t);
    t->base = base;
    t->scene = scene;
    t->min_area = min_area;
    size_t P = base->patch_count;
    if (P == 0 || P > (size_t)(UINT32_MAX / 8))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "hierarchical: %zu patches (1 to %u allowed)", P,
                        UINT32_MAX / 8);
    if (P < 2)
        clustered = false;
    size_t clusters = clustered ? P - 1 : 0;
    t->root_of_patch = rad_alloc(ctx, RAD_MEM_HIERARCHY, P, sizeof *t->root_of_patch, "hierarchical: roots");
    t->order = rad_alloc(ctx, RAD_MEM_HIERARCHY, P, sizeof *t->order, "hierarchical: cluster order");
    t->order_area = rad_alloc(ctx, RAD_MEM_HIERARCHY, P + 1, sizeof *t->order_area, "hierarchical: cluster order");
    t->lift = rad_alloc(ctx, RAD_MEM_HIERARCHY, P, sizeof *t->lift, "hierarchical: lifts");
    hr_node *roots = rad_alloc(ctx, RAD_MEM_HIERARCHY, P, sizeof *roots, "hierarchical: roots");
    sort_item *scratch = clustered ? rad_alloc(ctx, RAD_MEM_HIERARCHY, P, sizeof *scratch, "hierarchical: sort") : NULL;
    double *root_rgb = scene->texture_count > 0
                           ? rad_alloc(ctx, RAD_MEM_HIERARCHY, 3 * P, sizeof *root_rgb, "hierarchical: roots")
                           : NULL;
    rad_result r = RAD_OK;
    if (!t->root_of_patch || !t->order || !t->order_area || !t->lift || !roots ||
        (clustered && !scratch) || (scene->texture_count > 0 && !root_rgb) ||
        (r = reserve(ctx, t, clusters + P)) != RAD_OK) {
        rad_free(roots);
        rad_free(scratch);
        rad_free(root_rgb);
        hr_tree_free(t);
        return r != RAD_OK ? r : RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t p = 0; p < P; p++) {
        const rad_patch *pa = &base->patches[p];
        const rad_element *e = &base->elements[pa->first_element];
        t->lift[p] = eps + rad_element_bend(base, e);
        t->order[p] = (uint32_t)p;
        hr_node *n = &roots[p];
        memset(n, 0, sizeof *n);
        n->kind = HR_SURFACE;
        n->corners = (uint8_t)pa->corner_count;
        for (uint32_t c = 0; c < pa->corner_count; c++)
            n->corner[c] = pa->corner[c];
        n->normal = pa->normal;
        n->patch = (uint32_t)p;
        n->parent = HR_NONE;
        surface_geometry(n);
        surface_reflectance(t, n, root_rgb ? &root_rgb[3 * p] : NULL);
    }
    if (clustered) {
        bvh_builder b = {t, roots, scratch, 0, (uint32_t)clusters};
        bvh_build(&b, HR_NONE, 0, (uint32_t)P);
    }
    /* Roots after the clusters, in order[] order. */
    for (size_t i = 0; i < P; i++) {
        t->nodes[clusters + i] = roots[t->order[i]];
        t->root_of_patch[t->order[i]] = (uint32_t)(clusters + i);
        if (root_rgb)
            memcpy(&t->reflectance[3 * (clusters + i)], &root_rgb[3 * (size_t)t->order[i]], 3 * sizeof *root_rgb);
    }
    rad_free(root_rgb);
    t->count = clusters + P;
    t->clusters = clusters;
    /* Projected-area bins, bottom-up (children follow their parent). */
    t->cluster_bins = rad_alloc(ctx, RAD_MEM_HIERARCHY, 6 * clusters + 1, sizeof *t->cluster_bins, "hierarchical: cluster bins");
    t->power_bins = rad_alloc(ctx, RAD_MEM_HIERARCHY, 6 * clusters + 1, sizeof *t->power_bins, "hierarchical: cluster bins");
    t->order_power = rad_alloc(ctx, RAD_MEM_HIERARCHY, P + 1, sizeof *t->order_power, "hierarchical: cluster order");
    if (!t->cluster_bins || !t->power_bins || !t->order_power) {
        rad_free(roots);
        rad_free(scratch);
        hr_tree_free(t);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memset(t->power_bins, 0, (6 * clusters + 1) * sizeof *t->power_bins);
    memset(t->order_power, 0, (P + 1) * sizeof *t->order_power);
    hr_tree_set_open(t, NULL);
    t->order_area[0] = 0.0;
    for (size_t i = 0; i < P; i++)
        t->order_area[i + 1] = t->order_area[i] + roots[t->order[i]].area;
    rad_free(roots);
    rad_free(scratch);
    return RAD_OK;
}

void hr_tree_free(hr_tree *t)
{
    rad_free(t->nodes);
    rad_free(t->root_of_patch);
    rad_free(t->order);
    rad_free(t->order_area);
    rad_free(t->lift);
    rad_free(t->cluster_bins);
    rad_free(t->power_bins);
    rad_free(t->order_power);
    rad_free(t->reflectance);
    memset(t, 0, sizeof *t);
}

int hr_children(const hr_tree *t, uint32_t k)
{
    const hr_node *n = &t->nodes[k];
    if (n->kind == HR_CLUSTER)
        return 2;
    return n->child[0] ? 4 : 0;
}

bool hr_splittable(const hr_tree *t, uint32_t k)
{
    const hr_node *n = &t->nodes[k];
    if (n->kind == HR_CLUSTER)
        return true;
    return n->child[0] != 0 || (n->level < 40 && 0.25 * n->area >= t->min_area);
}

uint32_t hr_child(const hr_tree *t, uint32_t k, int c)
{
    const hr_node *n = &t->nodes[k];
    return n->kind == HR_CLUSTER ? n->child[c] : n->child[0] + (uint32_t)c;
}

rad_result hr_subdivide(rad_context *ctx, hr_tree *t, uint32_t k)
{
    if (t->nodes[k].kind != HR_SURFACE || t->nodes[k].child[0])
        return RAD_OK;
    if (t->count + 4 > (size_t)UINT32_MAX - 1)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                        "hierarchical: more than %u nodes; use a larger rad_options.min_area or "
                        "rad_options.epsilon",
                        UINT32_MAX - 1);
    rad_result r = reserve(ctx, t, 4);
    if (r != RAD_OK)
        return r;
    hr_node parent = t->nodes[k];
    uint32_t first = (uint32_t)t->count;
    vec3 q[4][4];
    rad_ff_split4(parent.corner, parent.corners, q);
    for (int i = 0; i < 4; i++) {
        hr_node *n = &t->nodes[first + (uint32_t)i];
        memset(n, 0, sizeof *n);
        n->kind = HR_SURFACE;
        n->corners = parent.corners;
        memcpy(n->corner, q[i], sizeof n->corner);
        n->normal = parent.normal;
        n->patch = parent.patch;
        n->parent = k;
        n->level = (uint8_t)(parent.level + 1);
        surface_geometry(n);
        surface_reflectance(t, n, t->reflectance ? &t->reflectance[3 * (size_t)(first + (uint32_t)i)] : NULL);
    }
    t->nodes[k].child[0] = first;
    t->count += 4;
    return RAD_OK;
}

/* Per-cluster bins (6 each) summed up the clusters: children follow their
 * parent in pre-order, so one backward loop. */
static void bins_up(const hr_tree *t, double *bins)
{
    for (size_t k = t->clusters; k-- > 1;)
        for (int q = 0; q < 6; q++)
            bins[6 * (size_t)t->nodes[k].parent + (size_t)q] += bins[6 * k + (size_t)q];
}

void hr_tree_set_power(hr_tree *t, const double *B, const float *send)
{
    size_t P = t->base->patch_count, C = t->clusters;
    if (C == 0)
        return;
    memset(t->power_bins, 0, 6 * C * sizeof *t->power_bins);
    t->order_power[0] = 0.0;
    for (size_t i = 0; i < P; i++) {
        uint32_t k = t->root_of_patch[t->order[i]];
        const double *b = &B[3 * (size_t)k];
        double power = t->nodes[k].area * (b[0] + b[1] + b[2]) * send[k];
        t->order_power[i + 1] = t->order_power[i] + power;
        hr_bins_add(&t->power_bins[6 * (size_t)t->nodes[k].parent], t->nodes[k].normal, power);
    }
    bins_up(t, t->power_bins);
}

void hr_tree_set_open(hr_tree *t, const float *open)
{
    size_t P = t->base->patch_count, C = t->clusters;
    if (C == 0)
        return;
    memset(t->cluster_bins, 0, 6 * C * sizeof *t->cluster_bins);
    for (size_t i = 0; i < P; i++) {
        uint32_t k = t->root_of_patch[i];
        hr_bins_add(&t->cluster_bins[6 * (size_t)t->nodes[k].parent], t->nodes[k].normal,
                    t->nodes[k].area * (open ? (double)open[k] : 1.0));
    }
    bins_up(t, t->cluster_bins);
}

double hr_cluster_power(const hr_tree *t, uint32_t k)
{
    const hr_node *n = &t->nodes[k];
    if (n->kind != HR_CLUSTER)
        return 0.0;
    return t->order_power[n->patch + n->patch_count] - t->order_power[n->patch];
}

void hr_sample(const hr_tree *t, uint32_t k, int count, const double *uvw, bool by_power, vec3 *point,
               vec3 *normal, double *lift)
{
    const hr_node *n = &t->nodes[k];
    uint32_t at[HR_SAMPLE_MAX];
    if (count > HR_SAMPLE_MAX)
        count = HR_SAMPLE_MAX;
    if (n->kind == HR_CLUSTER) {
        /* A patch of the cluster's range, order[first, first + width),
         * chosen by area or power: for each point the last patch whose
         * prefix sum is <= its target.  The searches halve the same width
         * in lockstep, so their memory loads overlap instead of waiting on
         * each other (a building's top clusters span 10^5 patches). */
        const double *sum = by_power ? t->order_power : t->order_area;
        uint32_t first = n->patch, width = n->patch_count;
        double target[HR_SAMPLE_MAX];
        for (int i = 0; i < count; i++) {
            at[i] = first;
            target[i] = sum[first] + uvw[3 * i + 2] * (sum[first + width] - sum[first]);
        }
        while (width > 1) {
            uint32_t half = width / 2;
            for (int i = 0; i < count; i++)
                at[i] = sum[at[i] + half] <= target[i] ? at[i] + half : at[i];
            width -= half;
        }
    }
    for (int i = 0; i < count; i++) {
        const hr_node *m = n->kind == HR_CLUSTER ? &t->nodes[t->root_of_patch[t->order[at[i]]]] : n;
        point[i] = rad_corners_sample(m->corner, m->corners, uvw[3 * i], uvw[3 * i + 1]);
        normal[i] = m->normal;
        lift[i] = t->lift[m->patch];
    }
}

hr_quarters hr_quarters_of(const hr_node *a)
{
    const vec3 *c = a->corner;
    hr_quarters f;
    f.n = a->normal;
    f.corners = a->corners;
    if (a->corners == 4) {
        /* The quad's mid-lines (straight: the bilinear map's iso-lines at
         * one half), oriented so that corner 0 lies on their low side. */
        vec3 m01 = v3_lerp(c[0], c[1], 0.5), m23 = v3_lerp(c[2], c[3], 0.5);
        vec3 m30 = v3_lerp(c[3], c[0], 0.5), m12 = v3_lerp(c[1], c[2], 0.5);
        f.o[0] = m01;
        f.o[1] = m30;
        f.e[0] = v3_cross(f.n, v3_sub(m23, m01)); /* in plane, across the u = 1/2 line */
        f.e[1] = v3_cross(f.n, v3_sub(m12, m30));
        for (int k = 0; k < 2; k++)
            if (v3_dot(f.e[k], v3_sub(c[0], f.o[k])) > 0.0)
                f.e[k] = v3_scale(f.e[k], -1.0);
        return f;
    }
    /* Triangles: barycentric of corner k = (distance from the opposite
     * edge) / (corner k's): o[k] on that edge, e[k] the scaled normal. */
    for (int k = 0; k < 3; k++) {
        vec3 b = c[(k + 1) % 3], d = c[(k + 2) % 3];
        vec3 across = v3_cross(f.n, v3_sub(d, b));
        double h = v3_dot(across, v3_sub(c[k], b));
        f.o[k] = b;
        f.e[k] = fabs(h) > 0.0 ? v3_scale(across, 1.0 / h) : v3(0, 0, 0);
    }
    return f;
}

int hr_quarter(const hr_quarters *f, vec3 p)
{
    if (f->corners == 4) {
        bool u_low = v3_dot(f->e[0], v3_sub(p, f->o[0])) <= 0.0;
        bool v_low = v3_dot(f->e[1], v3_sub(p, f->o[1])) <= 0.0;
        return u_low ? (v_low ? 0 : 3) : (v_low ? 1 : 2);
    }
    /* The corner children where p's barycentric of that corner is at
     * least one half, else the middle one. */
    for (int k = 0; k < 3; k++)
        if (v3_dot(f->e[k], v3_sub(p, f->o[k])) >= 0.5)
            return k;
    return 3;
}
