/*
 * cluster.c -- the gathering's hierarchy over the elements: a bounding
 * volume tree built once per gathering, whose nodes summarise what their
 * elements send, so that a far group counts as one source (gather.c;
 * Barnes & Hut 1986, "A hierarchical O(N log N) force-calculation
 * algorithm"; the same tree of light clusters as Walter et al. 2005,
 * "Lightcuts").
 *
 *                 root
 *            /          \            the top levels split by bin (the
 *        +x ... -z bins               dominant axis of the normal, six
 *        /    \                        bins, emitters apart: twelve), below
 *      ...    ...                      by the median of the centroids
 *     leaf = one element               along the longest side
 *
 * A node keeps, per RGB channel, the vector sum of area x radiosity x
 * normal of its elements (the self-emission and the rest apart):
 *
 *     P = sum_j A_j B_j n_j            W (per channel)
 *
 * Seen from a point x (normal n) far from the node, with every element
 * facing x and x facing every element, the elements' point-to-point
 * transfer is linear in n_j, so the node sends
 *
 *     sum_j B_j A_j cos_x cos_j / (pi r_j^2)  ~  (n . d) (-P . d) / (pi |d|^4),
 *     d = c - x, c the node's centre of power,
 *
 * with an error of second order in the node's size over |d| (c, the
 * power-weighted centroid, takes out the first-order term).  The bounds
 * that decide whether that holds: the box (the point's side, x's plane),
 * the cone of normals (axis, half-angle; the elements' side), the radius
 * of the sphere about the box's centre.  Representatives: up to eight
 * elements spread over the node (one from each of its children in turn)
 * whose centroids the gathering's visibility rays aim at.
 */
#include "grid/grid.h"

#include <stdlib.h>
#include <string.h>

typedef struct build_item {
    uint32_t element;
    vec3 centroid;
    double key;                     /* the coordinate sorted on */
} build_item;

typedef struct builder {
    const rad_solution_view *view;
    const double *self;             /* 3n, W/m^2 */
    rad_gather_tree *tree;
} builder;

static int by_key(const void *a, const void *b)
{
    const build_item *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    /* Ties by element: the order, so the tree, never depends on qsort's. */
    return x->element < y->element ? -1 : x->element > y->element;
}

static double axis_of(vec3 v, int a)
{
    return a == 0 ? v.x : a == 1 ? v.y : v.z;
}

/* The angle between unit vectors, in [0, pi]. */
static double angle(vec3 a, vec3 b)
{
    return acos(fmin(fmax(v3_dot(a, b), -1.0), 1.0));
}

/* m += w x x^T (the 6 distinct entries). */
static void add_outer(double m[6], vec3 x, double w)
{
    m[0] += w * x.x * x.x, m[1] += w * x.y * x.y, m[2] += w * x.z * x.z;
    m[3] += w * x.x * x.y, m[4] += w * x.x * x.z, m[5] += w * x.y * x.z;
}

/* The second moment about the centroid g of element e's area, times
 * weight / area: each triangle of its fan contributes (A_t / 12) sum
 * (v_i - g_t)(v_i - g_t)^T about its own centroid g_t, moved to g by
 * the parallel-axis rule (A_t (g_t - g)(g_t - g)^T). */
static void element_moment(const rad_mesh *mesh, const rad_element *e, double weight, double m[6])
{
    memset(m, 0, 6 * sizeof *m);
    if (!(e->area > 0.0) || !(weight > 0.0))
        return;
    double scale = weight / e->area;
    for (uint32_t k = 1; k + 1 < e->vertex_count; k++) {
        vec3 v[3] = {mesh->vertices[e->vertex[0]], mesh->vertices[e->vertex[k]], mesh->vertices[e->vertex[k + 1]]};
        double area = 0.5 * v3_length(v3_cross(v3_sub(v[1], v[0]), v3_sub(v[2], v[0])));
        vec3 gt = v3_scale(v3_add(v3_add(v[0], v[1]), v[2]), 1.0 / 3.0);
        for (int i = 0; i < 3; i++)
            add_outer(m, v3_sub(v[i], gt), scale * area / 12.0);
        add_outer(m, v3_sub(gt, e->centroid), scale * area);
    }
}

static uint32_t leaf(builder *bd, uint32_t j)
{
    rad_gather_tree *t = bd->tree;
    const rad_mesh *mesh = bd->view->mesh;
    const rad_element *e = &mesh->elements[j];
    rad_gather_node *node = &t->nodes[t->node_count];
    memset(node, 0, sizeof *node);
    node->lo = node->hi = mesh->vertices[e->vertex[0]];
    for (uint32_t k = 1; k < e->vertex_count; k++) {
        vec3 v = mesh->vertices[e->vertex[k]];
        node->lo = (vec3){fmin(node->lo.x, v.x), fmin(node->lo.y, v.y), fmin(node->lo.z, v.z)};
        node->hi = (vec3){fmax(node->hi.x, v.x), fmax(node->hi.y, v.y), fmax(node->hi.z, v.z)};
    }
    const double *B = bd->view->radiosity + 3 * (size_t)j, *S = bd->self + 3 * (size_t)j;
    for (int c = 0; c < 3; c++) {
        node->power_self[c] = v3_scale(e->normal, e->area * S[c]);
        node->power_rest[c] = v3_scale(e->normal, e->area * (B[c] - S[c]));
    }
    node->weight = e->area * (0.265 * B[0] + 0.670 * B[1] + 0.065 * B[2]);
    node->emits = S[0] > 0.0 || S[1] > 0.0 || S[2] > 0.0;
    node->centre = e->centroid;
    element_moment(mesh, e, node->weight, node->moment);
    node->axis = e->normal;
    node->spread = 0.0;
    node->child[0] = j;
    node->child[1] = RAD_GATHER_LEAF;
    node->rep[0] = j;
    node->reps = 1;
    return (uint32_t)t->node_count++;
}

/* The parent of nodes a and b (already built). */
static uint32_t join(builder *bd, uint32_t a, uint32_t b)
{
    rad_gather_tree *t = bd->tree;
    rad_gather_node *node = &t->nodes[t->node_count];
    const rad_gather_node *x = &t->nodes[a], *y = &t->nodes[b];
    memset(node, 0, sizeof *node);
    node->lo = (vec3){fmin(x->lo.x, y->lo.x), fmin(x->lo.y, y->lo.y), fmin(x->lo.z, y->lo.z)};
    node->hi = (vec3){fmax(x->hi.x, y->hi.x), fmax(x->hi.y, y->hi.y), fmax(x->hi.z, y->hi.z)};
    for (int c = 0; c < 3; c++) {
        node->power_self[c] = v3_add(x->power_self[c], y->power_self[c]);
        node->power_rest[c] = v3_add(x->power_rest[c], y->power_rest[c]);
    }
    node->weight = x->weight + y->weight;
    node->emits = x->emits || y->emits;
    /* The centre of power; halfway where neither child has any. */
    node->centre = node->weight > 0.0
                       ? v3_scale(v3_add(v3_scale(x->centre, x->weight), v3_scale(y->centre, y->weight)),
                                  1.0 / node->weight)
                       : v3_scale(v3_add(x->centre, y->centre), 0.5);
    /* The moments moved to the new centre (parallel-axis rule). */
    for (int k = 0; k < 6; k++)
        node->moment[k] = x->moment[k] + y->moment[k];
    add_outer(node->moment, v3_sub(x->centre, node->centre), x->weight);
    add_outer(node->moment, v3_sub(y->centre, node->centre), y->weight);
    /* The cone of normals: the children's axes averaged by weight (by
     * count where dark), the half-angle wide enough for both cones. */
    vec3 sum = v3_add(v3_scale(x->axis, x->weight > 0.0 ? x->weight : 1.0),
                      v3_scale(y->axis, y->weight > 0.0 ? y->weight : 1.0));
    double len = v3_length(sum);
    if (len > 1e-12) {
        node->axis = v3_scale(sum, 1.0 / len);
        node->spread = fmin(M_PI, fmax(angle(node->axis, x->axis) + x->spread, angle(node->axis, y->axis) + y->spread));
    } else {
        node->axis = x->axis;
        node->spread = M_PI;
    }
    node->child[0] = a;
    node->child[1] = b;
    /* Representatives alternately from each child: spread over the node. */
    for (int k = 0; k < 2 * RAD_GATHER_REPS && node->reps < RAD_GATHER_REPS; k++) {
        const rad_gather_node *from = (k & 1) ? y : x;
        if (k / 2 < from->reps)
            node->rep[node->reps++] = from->rep[k / 2];
    }
    return (uint32_t)t->node_count++;
}

/* The subtree over items[0 .. count-1] (count >= 1): median split along
 * the longest side of the centroids' box. */
static uint32_t build(builder *bd, build_item *items, size_t count)
{
    if (count == 1)
        return leaf(bd, items[0].element);
    vec3 lo = items[0].centroid, hi = lo;
    for (size_t k = 1; k < count; k++) {
        vec3 c = items[k].centroid;
        lo = (vec3){fmin(lo.x, c.x), fmin(lo.y, c.y), fmin(lo.z, c.z)};
        hi = (vec3){fmax(hi.x, c.x), fmax(hi.y, c.y), fmax(hi.z, c.z)};
    }
    vec3 side = v3_sub(hi, lo);
    int a = side.x >= side.y && side.x >= side.z ? 0 : side.y >= side.z ? 1 : 2;
    for (size_t k = 0; k < count; k++)
        items[k].key = axis_of(items[k].centroid, a);
    qsort(items, count, sizeof *items, by_key);
    size_t half = count / 2;
    uint32_t left = build(bd, items, half);
    uint32_t right = build(bd, items + half, count - half);
    return join(bd, left, right);
}

enum { BINS = 12 };

/* An element's bin: 2 x the dominant axis of its normal, +1 if negative;
 * +6 for an emitter (some self-emission), so that emitters and the rest
 * never share a node (gather.c never takes emitters as clusters). */
static int element_bin(vec3 n, const double self[3])
{
    double ax = fabs(n.x), ay = fabs(n.y), az = fabs(n.z);
    int a = ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
    bool emits = self[0] > 0.0 || self[1] > 0.0 || self[2] > 0.0;
    return 2 * a + (axis_of(n, a) < 0.0) + 6 * emits;
}

rad_result rad_gather_tree_build(rad_context *ctx, const rad_solution_view *view, const double *self,
                                 rad_gather_tree **out)
{
    *out = NULL;
    const rad_mesh *mesh = view->mesh;
    size_t n = view->n, lit = 0;
    rad_gather_tree *t = rad_alloc(ctx, RAD_MEM_RENDER, 1, sizeof *t, "illuminance: element tree");
    build_item *items = rad_alloc(ctx, RAD_MEM_RENDER, n + 1, sizeof *items, "illuminance: element tree");
    if (t)
        t->nodes = rad_alloc(ctx, RAD_MEM_RENDER, 2 * n + 6, sizeof *t->nodes, "illuminance: element tree");
    if (!t || !items || !t->nodes) {
        rad_free(items);
        rad_gather_tree_destroy(t);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    /* The elements that send light, grouped by bin (a counting sort,
     * element order kept within a bin). */
    size_t start[BINS + 1] = {0};
    for (size_t j = 0; j < n; j++) {
        const double *B = view->radiosity + 3 * j;
        if (B[0] > 0.0 || B[1] > 0.0 || B[2] > 0.0)
            start[element_bin(mesh->elements[j].normal, self + 3 * j) + 1]++;
    }
    for (int b = 0; b < BINS; b++)
        start[b + 1] += start[b];
    size_t fill[BINS];
    memcpy(fill, start, sizeof fill);
    for (size_t j = 0; j < n; j++) {
        const double *B = view->radiosity + 3 * j;
        if (!(B[0] > 0.0 || B[1] > 0.0 || B[2] > 0.0))
            continue;
        const rad_element *e = &mesh->elements[j];
        items[fill[element_bin(e->normal, self + 3 * j)]++] = (build_item){(uint32_t)j, e->centroid, 0.0};
        lit++;
    }
    builder bd = {view, self, t};
    uint32_t roots[BINS];
    int bins = 0;
    for (int b = 0; b < BINS; b++)
        if (start[b + 1] > start[b])
            roots[bins++] = build(&bd, items + start[b], start[b + 1] - start[b]);
    /* The bins joined pairwise into one root. */
    while (bins > 1) {
        int kept = 0;
        for (int b = 0; b + 1 < bins; b += 2)
            roots[kept++] = join(&bd, roots[b], roots[b + 1]);
        if (bins & 1)
            roots[kept++] = roots[bins - 1];
        bins = kept;
    }
    t->root = bins ? roots[0] : RAD_GATHER_LEAF;
    t->elements = lit;
    rad_free(items);
    *out = t;
    return RAD_OK;
}

void rad_gather_tree_destroy(rad_gather_tree *tree)
{
    if (!tree)
        return;
    rad_free(tree->nodes);
    rad_free(tree);
}
