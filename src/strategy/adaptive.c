/*
 * adaptive.c -- adaptive subdivision of the dense strategy's mesh: solve,
 * split the elements the solution says are too coarse, couple and solve
 * again, a few rounds (Cohen, Greenberg, Immel & Brock 1986, "An efficient
 * radiosity approach for realistic image synthesis"; Cohen & Wallace 1993,
 * ch. 6, "Domain subdivision").
 *
 * Each patch is a quadtree whose leaves are the elements (the leaf meshes
 * of hierarchical radiosity, mesh.h: quads split at their parameter
 * midpoints, triangles into three corner triangles and the medial one,
 * rad_ff_split4).  It starts uniform, at the depth whose element count is
 * nearest the patch's grid at the mesh size.  After each solve a leaf is
 * split where
 *
 *   gradient     its radiosity differs from the mean of its corners' vertex
 *                values (area-weighted means of the elements around each)
 *                by more than `threshold` times the scene's radiosity scale
 *                (the area-weighted mean B of the elements that do not
 *                emit): zero for a linear change, large at a kink or jump;
 *   visibility   the shadow rays from its corners and centre to the corners
 *                and centre of emitting elements disagree, and those
 *                emitters' unoccluded share of its radiosity would add up
 *                to more than `threshold` times the scale: a shadow edge
 *                crosses it.  Those emitters are split too: the form factors
 *                estimate visibility by a few rays per element pair, so a
 *                large emitter leaves a penumbra noisy however fine its
 *                receivers.
 *
 * Most important first (the score: how many thresholds past), within the
 * element budget, of which each round may use its share of what is left
 * (the first round's many small gains would otherwise use up what the
 * deepest levels at the shadow edges need).  A leaf is not split more than
 * `levels` below its starting depth, nor below 100 shadow-ray tolerances
 * across.  Each split ripples (Samet 1990): the quadtrees stay restricted
 * (leaves sharing an edge within a patch differ by at most one level), so
 * every T-vertex lies at the middle of its neighbour's edge and is
 * constrained there (interp/vertex.c): no cracks in the image.
 *
 *      +-------+---+---+      the coarse leaf's edge midpoint m is a
 *      |       |   |   |      T-vertex of the two small ones: its value is
 *      |       m---+---+      the mean of the coarse edge's ends
 *      |       |   |   |
 *      +-------+---+---+
 *
 * Nothing is coarsened.  The form factors are computed anew for the whole
 * new mesh (the dense strategy's coupling hook), and the system solved
 * again from B = E; so a run costs about the form factors of its final
 * mesh plus those of the rounds before (each a quarter or less of that).
 * Across patches the trees are not balanced: their T-vertices are
 * constrained all the same (weld.c finds them), at any ratio.
 */
#include "strategy/strategy.h"

#include <stdlib.h>
#include <string.h>

typedef struct ad_node {
    vec3 corner[4];          /* m, counter-clockwise as the patch */
    vec3 param[4];           /* the corners' patch parameters (s, t, 0) */
    uint32_t patch;
    uint32_t first_child;    /* 4 consecutive nodes; 0 = leaf */
    uint8_t corners;         /* 3 or 4 */
    uint8_t level;           /* splits below the patch */
    uint8_t max_level;       /* the deepest it may be split to */
} ad_node;

struct rad_adaptive {
    rad_mesh *base;          /* the grid mesh: its patches are the roots' */
    ad_node *nodes;
    size_t count, capacity;
    uint32_t *root;          /* per patch, its root node */
    uint32_t *leaf_node;     /* per element of the current mesh, its node */
    uint32_t *stack;         /* leaves to check while balancing */
    size_t stack_count, stack_capacity;
    size_t leaves;
    rad_adaptive_stats stats;
};

static rad_result grow(rad_context *ctx, rad_adaptive *a, size_t extra)
{
    if (a->count + extra <= a->capacity)
        return RAD_OK;
    if (a->count + extra >= RAD_TREE_LEAF)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "adaptive: more than %u quadtree nodes",
                        RAD_TREE_LEAF - 1);
    size_t cap = a->capacity ? a->capacity : 1024;
    while (cap < a->count + extra)
        cap *= 2;
    ad_node *nodes = rad_realloc(ctx, RAD_MEM_MESH, a->nodes, cap, sizeof *nodes, "adaptive: quadtree");
    if (!nodes)
        return RAD_ERROR_OUT_OF_MEMORY;
    a->nodes = nodes;
    a->capacity = cap;
    return RAD_OK;
}

/* Give leaf k its four children.  May move a->nodes.  Fails only for memory. */
static rad_result split(rad_context *ctx, rad_adaptive *a, uint32_t k)
{
    rad_result r = grow(ctx, a, 4);
    if (r != RAD_OK)
        return r;
    ad_node parent = a->nodes[k];
    vec3 q[4][4], u[4][4];
    rad_ff_split4(parent.corner, parent.corners, q);
    rad_ff_split4(parent.param, parent.corners, u);
    uint32_t first = (uint32_t)a->count;
    for (int c = 0; c < 4; c++) {
        ad_node *n = &a->nodes[first + (uint32_t)c];
        *n = parent;
        memcpy(n->corner, q[c], sizeof n->corner);
        memcpy(n->param, u[c], sizeof n->param);
        n->first_child = 0;
        n->level = (uint8_t)(parent.level + 1);
    }
    a->nodes[k].first_child = first;
    a->count += 4;
    a->leaves += 3;
    return RAD_OK;
}

/* The leaf of patch p's tree holding parameters (s, t), by the descent of
 * rad_mesh_locate (grid.c). */
static uint32_t locate(const rad_adaptive *a, uint32_t p, double s, double t)
{
    uint32_t k = a->root[p];
    while (a->nodes[k].first_child) {
        int c;
        if (a->nodes[k].corners == 4) {
            int i = s >= 0.5, j = t >= 0.5;
            c = j ? (i ? 2 : 3) : (i ? 1 : 0);
            s = 2.0 * s - i;
            t = 2.0 * t - j;
        } else if (s + t < 0.5) {
            c = 0, s = 2.0 * s, t = 2.0 * t;
        } else if (s >= 0.5) {
            c = 1, s = 2.0 * s - 1.0, t = 2.0 * t;
        } else if (t >= 0.5) {
            c = 2, s = 2.0 * s, t = 2.0 * t - 1.0;
        } else {
            double ls = 2.0 * s + 2.0 * t - 1.0, lt = 1.0 - 2.0 * s;
            c = 3, s = ls, t = lt;
        }
        k = a->nodes[k].first_child + (uint32_t)c;
    }
    return k;
}

/* The leaf across edge c (corner c to c + 1) of leaf k, in k's patch,
 * when it is two or more levels coarser than k; else UINT32_MAX.  A
 * coarser neighbour holds the whole edge, so the point just past the
 * edge's midpoint finds it. */
static uint32_t coarse_neighbour(const rad_adaptive *a, uint32_t k, int c)
{
    const ad_node *n = &a->nodes[k];
    vec3 centre = {0, 0, 0};
    for (int i = 0; i < n->corners; i++)
        centre = v3_add(centre, n->param[i]);
    centre = v3_scale(centre, 1.0 / n->corners);
    vec3 mid = v3_scale(v3_add(n->param[c], n->param[(c + 1) % n->corners]), 0.5);
    /* 1% of the way from the centre to the edge past it: inside the
     * neighbour, whatever its size (>= this leaf's). */
    vec3 out = v3_add(mid, v3_scale(v3_sub(mid, centre), 0.01));
    bool inside = n->corners == 4 ? out.x > 0.0 && out.x < 1.0 && out.y > 0.0 && out.y < 1.0
                                  : out.x > 0.0 && out.y > 0.0 && out.x + out.y < 1.0;
    if (!inside)
        return UINT32_MAX;
    uint32_t m = locate(a, n->patch, out.x, out.y);
    return a->nodes[m].level + 1 < n->level ? m : UINT32_MAX;
}

static rad_result push(rad_context *ctx, rad_adaptive *a, uint32_t k)
{
    if (a->stack_count == a->stack_capacity) {
        size_t cap = a->stack_capacity ? 2 * a->stack_capacity : 256;
        uint32_t *stack = rad_realloc(ctx, RAD_MEM_MESH, a->stack, cap, sizeof *stack, "adaptive: balancing");
        if (!stack)
            return RAD_ERROR_OUT_OF_MEMORY;
        a->stack = stack;
        a->stack_capacity = cap;
    }
    a->stack[a->stack_count++] = k;
    return RAD_OK;
}

/* Split leaf k and keep its patch's quadtree restricted: every leaf whose
 * edge neighbour is now two levels finer is split too, rippling outward
 * (Samet 1990; the balanced quadtrees of Baum et al. 1991).  Adds
 * *balanced the ripple's splits.  Fails only for memory. */
static rad_result split_balanced(rad_context *ctx, rad_adaptive *a, uint32_t k, size_t *balanced)
{
    rad_result r = split(ctx, a, k);
    a->stack_count = 0;
    for (uint32_t c = 0; r == RAD_OK && c < 4; c++)
        r = push(ctx, a, a->nodes[k].first_child + c);
    while (r == RAD_OK && a->stack_count > 0) {
        uint32_t x = a->stack[--a->stack_count];
        for (int c = 0; r == RAD_OK && c < a->nodes[x].corners; c++) {
            uint32_t m = coarse_neighbour(a, x, c);
            if (m == UINT32_MAX)
                continue;
            r = split(ctx, a, m);
            ++*balanced;
            /* m's children may be too fine for their other neighbours, and
             * x may still be two levels below m's child. */
            for (uint32_t i = 0; r == RAD_OK && i < 4; i++)
                r = push(ctx, a, a->nodes[m].first_child + i);
            if (r == RAD_OK)
                r = push(ctx, a, x);
            break;
        }
    }
    return r;
}

/* ---- the leaves as the mesh ---- */

typedef struct encoder {
    rad_adaptive *a;
    rad_mesh_leaf *leaves;
    size_t leaf_count;
    uint32_t *tree;
    size_t tree_count;
} encoder;

static uint32_t encode(encoder *en, uint32_t k)
{
    const ad_node *n = &en->a->nodes[k];
    if (!n->first_child) {
        size_t i = en->leaf_count++;
        en->leaves[i].patch = n->patch;
        en->leaves[i].corner_count = n->corners;
        memcpy(en->leaves[i].corner, n->corner, sizeof n->corner);
        en->a->leaf_node[i] = k;
        return (uint32_t)i | RAD_TREE_LEAF;
    }
    size_t slot = en->tree_count++;
    for (uint32_t c = 0; c < 4; c++) {
        uint32_t e = encode(en, n->first_child + c);
        en->tree[4 * slot + c] = e;
    }
    return (uint32_t)slot;
}

/* Replace m's mesh, ray structure and element arrays by the current
 * leaves'.  On failure m keeps its old ones. */
static rad_result remesh(rad_context *ctx, rad_adaptive *a, rad_meshed *m)
{
    size_t internal = (a->count - a->leaves) + 1, P = a->base->patch_count;
    encoder en = {a, NULL, 0, NULL, 0};
    en.leaves = rad_alloc(ctx, RAD_MEM_MESH, a->leaves, sizeof *en.leaves, "adaptive: leaves");
    en.tree = rad_alloc(ctx, RAD_MEM_MESH, 4 * internal, sizeof *en.tree, "adaptive: leaves");
    uint32_t *root = rad_alloc(ctx, RAD_MEM_MESH, P ? P : 1, sizeof *root, "adaptive: leaves");
    uint32_t *leaf_node = rad_realloc(ctx, RAD_MEM_MESH, a->leaf_node, a->leaves, sizeof *leaf_node,
                                      "adaptive: leaves");
    if (leaf_node)
        a->leaf_node = leaf_node;
    rad_result r = RAD_ERROR_OUT_OF_MEMORY;
    rad_mesh *mesh = NULL;
    rad_vis *vis = NULL;
    rad_elements elements;
    memset(&elements, 0, sizeof elements);
    double t0 = rad_seconds();
    if (en.leaves && en.tree && root && leaf_node) {
        for (size_t p = 0; p < P; p++) /* leaves grouped by patch, in patch order */
            root[p] = encode(&en, a->root[p]);
        r = rad_mesh_from_leaves(ctx, m->scene, a->base, en.leaves, en.leaf_count, en.tree, en.tree_count, root,
                                 m->options->crease_angle_degrees, &mesh);
    }
    double t1 = rad_seconds();
    if (r == RAD_OK)
        r = rad_vis_create(ctx, m->options->visibility, mesh, &vis);
    if (r == RAD_OK)
        r = rad_elements_create(ctx, m->scene, mesh, &elements);
    if (r == RAD_OK) {
        r = rad_elements_add_light(ctx, m->scene, mesh, vis, &elements);
        if (r != RAD_OK)
            rad_elements_free(&elements);
    }
    rad_free(en.leaves);
    rad_free(en.tree);
    rad_free(root);
    if (r != RAD_OK) {
        rad_vis_destroy(vis);
        rad_mesh_destroy(mesh);
        return r;
    }
    rad_vis_destroy(m->vis);
    rad_mesh_destroy(m->mesh);
    rad_elements_free(&m->elements);
    m->mesh = mesh;
    m->vis = vis;
    m->elements = elements;
    m->seconds.mesh += t1 - t0;
    m->seconds.visibility += vis->build_seconds;
    m->solved = false;
    return RAD_OK;
}

void rad_adaptive_destroy(rad_adaptive *a)
{
    if (!a)
        return;
    rad_mesh_destroy(a->base);
    rad_free(a->nodes);
    rad_free(a->root);
    rad_free(a->leaf_node);
    rad_free(a->stack);
    rad_free(a);
}

rad_result rad_adaptive_create(rad_context *ctx, rad_meshed *m, rad_adaptive **out)
{
    *out = NULL;
    rad_adaptive *a = rad_alloc(ctx, RAD_MEM_MESH, 1, sizeof *a, "adaptive");
    if (!a)
        return RAD_ERROR_OUT_OF_MEMORY;
    memset(a, 0, sizeof *a);
    size_t P = m->mesh->patch_count;
    a->root = rad_alloc(ctx, RAD_MEM_MESH, P ? P : 1, sizeof *a->root, "adaptive: roots");
    rad_result r = a->root ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
    int levels = m->options->adaptive_levels;
    for (size_t p = 0; r == RAD_OK && p < P; p++) {
        const rad_patch *pa = &m->mesh->patches[p];
        if ((r = grow(ctx, a, 1)) != RAD_OK)
            break;
        ad_node *n = &a->nodes[a->count];
        memset(n, 0, sizeof *n);
        memcpy(n->corner, pa->corner, sizeof n->corner);
        n->param[1] = (vec3){1, 0, 0};
        n->param[pa->corner_count == 4 ? 3 : 2] = (vec3){0, 1, 0};
        if (pa->corner_count == 4)
            n->param[2] = (vec3){1, 1, 0};
        n->patch = (uint32_t)p;
        n->corners = (uint8_t)pa->corner_count;
        /* The depth whose 4^d leaves are nearest the grid's count, in log. */
        int depth = (int)lround(0.5 * log2(fmax((double)pa->element_count, 1.0)));
        if (depth > 16)
            depth = 16;
        n->max_level = (uint8_t)(depth + levels);
        a->root[p] = (uint32_t)a->count++;
        a->leaves++;
        /* Uniform to that depth: the node's subtree, breadth first. */
        for (int d = 0; r == RAD_OK && d < depth; d++)
            for (size_t k = a->root[p]; r == RAD_OK && k < a->count; k++)
                if (!a->nodes[k].first_child && a->nodes[k].level == d)
                    r = split(ctx, a, (uint32_t)k);
    }
    if (r != RAD_OK) {
        rad_adaptive_destroy(a);
        return r;
    }
    /* The grid mesh stays as the base whose patches the leaf meshes copy. */
    a->base = m->mesh;
    m->mesh = NULL;
    r = remesh(ctx, a, m);
    if (r != RAD_OK) {
        m->mesh = a->base;
        a->base = NULL;
        rad_adaptive_destroy(a);
        return r;
    }
    a->stats.initial_elements = a->leaves;
    a->stats.elements = a->leaves;
    *out = a;
    return RAD_OK;
}

/* ---- where to split ---- */

enum { AD_POINTS = 5 }; /* corners (up to 4) and the centre */

/* An element's corners pulled 1% toward its centre (a shadow ray from the
 * exact corner would graze the neighbouring surface), then the centre. */
static int element_points(const rad_mesh *mesh, const rad_element *e, vec3 *point)
{
    for (uint32_t c = 0; c < e->vertex_count; c++)
        point[c] = v3_lerp(mesh->vertices[e->vertex[c]], e->centroid, 0.01);
    point[e->vertex_count] = e->centroid;
    return (int)e->vertex_count + 1;
}

static double mean3(const double *x) { return (x[0] + x[1] + x[2]) / 3.0; }

/* Do the shadow rays from receiver i's points to emitter j's points
 * disagree?  Pairs whose ends face away from each other are left out: the
 * kernel goes to zero continuously at a horizon, so it is no edge. */
static bool visibility_varies(const rad_meshed *m, size_t i, size_t j, double lift)
{
    const rad_mesh *mesh = m->mesh;
    const rad_element *ei = &mesh->elements[i], *ej = &mesh->elements[j];
    vec3 p[AD_POINTS], q[AD_POINTS];
    int np = element_points(mesh, ei, p), nq = element_points(mesh, ej, q);
    rad_ray rays[AD_POINTS * AD_POINTS];
    uint8_t hit[AD_POINTS * AD_POINTS];
    bool facing[AD_POINTS * AD_POINTS];
    int count = 0;
    for (int a = 0; a < np; a++)
        for (int b = 0; b < nq; b++) {
            vec3 from = v3_add(p[a], v3_scale(ei->normal, lift));
            vec3 to = v3_add(q[b], v3_scale(ej->normal, lift));
            vec3 d = v3_sub(to, from);
            int k = a * nq + b;
            facing[k] = v3_dot(ei->normal, d) > 0.0 && v3_dot(ej->normal, d) < 0.0;
            rays[k] = (rad_ray){from, d, 0.0, 1.0};
            count++;
        }
    m->vis->backend->occluded(m->vis->state, rays, (size_t)count, hit);
    /* Seen from each emitter point, the receiver's points must agree. */
    for (int b = 0; b < nq; b++) {
        int seen = 0, hidden = 0;
        for (int a = 0; a < np; a++) {
            int k = a * nq + b;
            if (facing[k])
                *(hit[k] ? &hidden : &seen) += 1;
        }
        if (seen && hidden)
            return true;
    }
    return false;
}

/* Element i's own emission (mean over RGB): its emission without the
 * first reflection of luminaires' and daylight's direct light, which
 * makes a lit surface no emitter. */
static double self_emission(const rad_elements *el, size_t i)
{
    double e = mean3(&el->emission[3 * i]);
    if (el->direct)
        for (int c = 0; c < 3; c++)
            e -= el->reflectance[3 * i + (size_t)c] * el->direct[3 * i + (size_t)c] / 3.0;
    return e > 1e-12 * mean3(&el->emission[3 * i]) ? e : 0.0;
}

/* What emitter j would add to element i's radiosity per unit of i's
 * reflectance, unoccluded: E_j times the centre-to-centre kernel, at most
 * E_j.  Pairs straddling each other's planes (a cosine <= 0 at the
 * centres) may still be lit at some points: they are weighed face on. */
static double emitter_share(const rad_elements *el, const rad_element *E, size_t i, size_t j)
{
    vec3 d = v3_sub(E[j].centroid, E[i].centroid);
    double r2 = v3_dot(d, d);
    double ci = v3_dot(E[i].normal, d), cj = -v3_dot(E[j].normal, d);
    if (!(ci > 0.0 || cj > 0.0) || !(r2 > 0.0))
        return 0.0;
    double kernel = fmax(ci, 0.0) * fmax(cj, 0.0) * E[j].area / (M_PI * r2 * r2);
    if (kernel == 0.0)
        kernel = E[j].area / (M_PI * r2);
    return self_emission(el, j) * fmin(kernel, 1.0);
}

enum { AD_MARKED = 64 }; /* emitters one receiver marks for splitting, at most */

/* score[i]: how far element i is past the threshold (>= 1: split it; 0: not
 * wanted or not allowed). */
static rad_result score_elements(rad_context *ctx, const rad_adaptive *a, const rad_meshed *m, double *score)
{
    const rad_mesh *mesh = m->mesh;
    const rad_elements *el = &m->elements;
    size_t n = mesh->element_count, V = mesh->vertex_count;
    double threshold = m->options->adaptive_threshold;
    /* The radiosity scale: the area-weighted mean of the elements that do
     * not emit (an emitter's E would swamp the light it receives). */
    double sum = 0.0, area = 0.0;
    size_t emitters = 0;
    for (size_t i = 0; i < n; i++) {
        if (self_emission(el, i) > 0.0) {
            emitters++;
            continue;
        }
        sum += el->area[i] * mean3(&el->radiosity[3 * i]);
        area += el->area[i];
    }
    memset(score, 0, n * sizeof *score);
    double scale = area > 0.0 ? sum / area : 0.0;
    if (!(scale > 0.0))
        return RAD_OK;
    /* Elements around each vertex (CSR). */
    uint32_t *start = rad_alloc(ctx, RAD_MEM_MESH, V + 1, sizeof *start, "adaptive: vertex adjacency");
    uint32_t *around = rad_alloc(ctx, RAD_MEM_MESH, 4 * n + 1, sizeof *around, "adaptive: vertex adjacency");
    uint32_t *emitter = rad_alloc(ctx, RAD_MEM_MESH, emitters + 1, sizeof *emitter, "adaptive: emitters");
    double *emitter_score = rad_alloc(ctx, RAD_MEM_MESH, emitters + 1, sizeof *emitter_score, "adaptive: emitters");
    double *vertex_value = rad_alloc(ctx, RAD_MEM_MESH, V + 1, sizeof *vertex_value, "adaptive: vertex values");
    if (!start || !around || !emitter || !emitter_score || !vertex_value) {
        rad_free(emitter_score);
        rad_free(vertex_value);
        rad_free(start);
        rad_free(around);
        rad_free(emitter);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memset(start, 0, (V + 1) * sizeof *start);
    for (size_t i = 0; i < n; i++)
        for (uint32_t c = 0; c < mesh->elements[i].vertex_count; c++)
            start[mesh->elements[i].vertex[c] + 1]++;
    for (size_t v = 0; v < V; v++)
        start[v + 1] += start[v];
    for (size_t i = 0, k = 0; i < n; i++) {
        for (uint32_t c = 0; c < mesh->elements[i].vertex_count; c++)
            around[start[mesh->elements[i].vertex[c]]++] = (uint32_t)i;
        if (self_emission(el, i) > 0.0)
            emitter[k++] = (uint32_t)i;
    }
    for (size_t v = V; v > 0; v--)
        start[v] = start[v - 1];
    start[0] = 0;
    for (size_t v = 0; v < V; v++) {
        double area_sum = 0.0, weighted = 0.0;
        for (uint32_t k = start[v]; k < start[v + 1]; k++) {
            area_sum += el->area[around[k]];
            weighted += el->area[around[k]] * mean3(&el->radiosity[3 * (size_t)around[k]]);
        }
        vertex_value[v] = area_sum > 0.0 ? weighted / area_sum : 0.0;
    }
    double lift = rad_vis_epsilon(mesh);
    /* 100 shadow-ray tolerances: finer than that the rays cannot tell the
     * element's points apart from its neighbours'. */
    double narrowest = 100.0 * lift;
    const rad_element *E = mesh->elements;
#pragma omp parallel for schedule(dynamic, 16) num_threads(m->threads)
    for (size_t i = 0; i < n; i++) {
        const ad_node *node = &a->nodes[a->leaf_node[i]];
        if (node->level >= node->max_level || self_emission(el, i) > 0.0)
            continue;
        vec3 corner[4];
        for (uint32_t c = 0; c < E[i].vertex_count; c++)
            corner[c] = mesh->vertices[E[i].vertex[c]];
        if (rad_corners_width(corner, E[i].vertex_count) < 2.0 * narrowest)
            continue;
        /* Gradient: the element's value against the mean of its corners'
         * vertex values (each the area-weighted mean of the elements
         * around it, as interp/vertex.c makes them inside a surface).  A
         * linear change of B leaves them equal; a kink or a jump does
         * not, and that is what smooth shading gets wrong. */
        double corners_mean = 0.0;
        for (uint32_t c = 0; c < E[i].vertex_count; c++)
            corners_mean += vertex_value[E[i].vertex[c]];
        double best = fabs(mean3(&el->radiosity[3 * i]) - corners_mean / E[i].vertex_count);
        best /= threshold * scale;
        /* Visibility: the emitters whose shadow rays disagree across the
         * element, weighed by what they would add unoccluded.  Their sum,
         * not each one, is the jump a shadow edge can make: a large
         * emitter split into pieces shares it among them. */
        double rho = mean3(&el->reflectance[3 * i]), potential = 0.0;
        for (size_t k = 0; k < emitters && rho > 0.0; k++)
            potential += emitter_share(el, E, i, emitter[k]);
        potential *= rho / (threshold * scale);
        if (potential >= 1.0) {
            double varying = 0.0;
            uint32_t varied[AD_MARKED];
            int marked = 0;
            for (size_t k = 0; k < emitters; k++) {
                double share = rho * emitter_share(el, E, i, emitter[k]) / (threshold * scale);
                /* 1e-3 of the total: pieces that cannot move it. */
                if (share < 1e-3 * potential || !visibility_varies(m, i, emitter[k], lift))
                    continue;
                varying += share;
                if (marked < AD_MARKED)
                    varied[marked++] = (uint32_t)k;
            }
            if (varying >= 1.0) {
                best = fmax(best, varying);
                /* The emitters too: what one element pair's shadow rays
                 * estimate (rad_ff_rays: a few per pair) is the visible
                 * part of the whole emitter element, so a large emitter
                 * leaves the penumbra noisy however fine its receivers.
                 * (A max, so the order is free; unnamed, because a named
                 * critical section is a symbol the library would export.) */
#pragma omp critical
                for (int k = 0; k < marked; k++)
                    emitter_score[varied[k]] = fmax(emitter_score[varied[k]], varying);
            }
        }
        score[i] = best >= 1.0 ? best : 0.0;
    }
    for (size_t k = 0; k < emitters; k++) {
        const ad_node *node = &a->nodes[a->leaf_node[emitter[k]]];
        if (node->level < node->max_level)
            score[emitter[k]] = emitter_score[k];
    }
    rad_free(start);
    rad_free(around);
    rad_free(emitter);
    rad_free(emitter_score);
    rad_free(vertex_value);
    return RAD_OK;
}

typedef struct candidate {
    double score;
    uint32_t element;
} candidate;

static int by_score(const void *pa, const void *pb)
{
    const candidate *x = pa, *y = pb;
    if (x->score != y->score)
        return x->score > y->score ? -1 : 1;
    return x->element < y->element ? -1 : x->element > y->element;
}

rad_result rad_adaptive_refine(rad_context *ctx, rad_adaptive *a, rad_meshed *m, const rad_adaptive_hooks *h,
                               const rad_step_hook *hook)
{
    const rad_options *o = m->options;
    size_t budget = o->adaptive_max_elements ? o->adaptive_max_elements : 4 * a->stats.initial_elements;
    /* Within the memory limit: a matrix of n^2 doubles and as many
     * variances (16 n^2 bytes, the most any form-factor method keeps), so a
     * refinement that cannot be coupled is not made and the last solution
     * stays. */
    double fits = floor(sqrt(o->max_memory_bytes / 16.0));
    if (fits < (double)budget)
        budget = (size_t)fits;
    double ff_seconds = m->seconds.form_factors, solve_seconds = m->seconds.solve;
    rad_result r = RAD_OK;
    a->stats.rounds = 0;
    for (int round = 0; round < o->adaptive_levels; round++) {
        size_t n = m->mesh->element_count;
        double *score = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *score, "adaptive: scores");
        candidate *cand = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *cand, "adaptive: scores");
        r = score && cand ? score_elements(ctx, a, m, score) : RAD_ERROR_OUT_OF_MEMORY;
        size_t count = 0;
        for (size_t i = 0; r == RAD_OK && i < n; i++)
            if (score[i] > 0.0)
                cand[count++] = (candidate){score[i], (uint32_t)i};
        if (r == RAD_OK)
            qsort(cand, count, sizeof *cand, by_score);
        /* The budget left is shared among the rounds left, so that the
         * first round's many small gains do not use up what the deepest
         * levels at the shadow edges need. */
        size_t allowed = a->leaves + (budget > a->leaves ? budget - a->leaves : 0) /
                                         (size_t)(o->adaptive_levels - round);
        size_t split_count = 0, balanced = 0;
        for (size_t k = 0; r == RAD_OK && k < count && a->leaves + 3 <= allowed; k++) {
            uint32_t node = a->leaf_node[cand[k].element];
            if (a->nodes[node].first_child) /* split already by balancing */
                continue;
            r = split_balanced(ctx, a, node, &balanced);
            split_count++;
        }
        rad_free(score);
        rad_free(cand);
        if (r == RAD_OK && split_count == 0)
            break;
        if (r == RAD_OK && rad_cancelled(ctx))
            r = RAD_ERROR_INTERRUPTED;
        if (r == RAD_OK)
            r = remesh(ctx, a, m);
        if (r == RAD_OK) {
            a->stats.rounds++;
            a->stats.split += split_count;
            a->stats.balanced += balanced;
            a->stats.elements = a->leaves;
            r = h->couple(ctx, h->state);
            ff_seconds += m->seconds.form_factors;
            m->seconds.form_factors = ff_seconds;
        }
        if (r == RAD_OK) {
            r = h->solve(ctx, h->state, hook);
            solve_seconds += m->seconds.solve;
            m->seconds.solve = solve_seconds;
        }
        if (r != RAD_OK)
            break;
    }
    return r;
}

const rad_adaptive_stats *rad_adaptive_get_stats(const rad_adaptive *a) { return a ? &a->stats : NULL; }
