/*
 * hier.c -- the hierarchical radiosity solver: rounds of refinement and
 * Jacobi sweeps over the links, then the leaves as the solution's mesh.
 *
 * One sweep (Hanrahan, Salzman & Aupperle 1991, "Gather" and
 * "PushPullRad"):
 *
 *   gather     every node's irradiance H from its own links (in parallel
 *              over receivers; links are sorted by receiver)
 *   push       down the hierarchy, each node's total irradiance is its own
 *              plus its parent's (a surface under a cluster reads the
 *              cluster's six-direction bins with its normal); at a leaf,
 *              B = E + rho H
 *   pull       up the hierarchy, a node's B is the area average of its
 *              children's, and a cluster's exitance bins the sum of its
 *              members'
 *
 * Node numbers are a topological order (parents first), so push and pull
 * are two loops over the node array.  The residual of a sweep is the
 * change it made, sum_leaves A |B_new - B_old| / sum_leaves A E (channels
 * summed): the notes' residual of the hierarchical system.
 *
 * Rounds ("BF refinement" with multigridding): refine against the current
 * B (at first B = E: only links from emitters are refined), solve to 1e-3,
 * refine again with the better B, ... until a round splits under 1e-4 of
 * the links; then solve to the requested tolerance.  With
 * --closure-correction, each patch then sends B / its link closure
 * (correct_closure).
 */
#include "hier/hier.h"

#include <stdlib.h>
#include <string.h>

typedef struct hr_state {
    rad_context *ctx;
    const rad_hier_params *p;
    hr_tree tree;
    hr_links links;
    size_t *offset;       /* receiver k's links: [offset[k], offset[k + 1]) */
    size_t *live;         /* ... of which [offset[k], live[k]) carry something (k > 0):
                             the gather's; blocked links follow, kept for refinement */
    double *B, *H, *Ht;   /* 3 per node */
    double *Hq;           /* 3 per node: what its parent's partly hidden links give it by
                             the quarters' visibility (HR_LINK_QUADS; gather) */
    bool quads;           /* partly hidden links share by their quarters (off where the
                             balance holds; the factor's shape alone is kept) */
    double *spread;       /* per node: max |B_child - B| over children and channels */
    float *open;          /* per node: fraction of its area outside every solid; -1 for a
                             leaf not measured yet (see measure_open) */
    float *send;          /* per node: 1 / open (0 when closed): the gather's source scale */
    float *take;          /* per node: the part of its area that receives, open as send reads it
                             (1, open, or 0 when closed; internal nodes: area means): push */
    float *corr;          /* per leaf: the source scale y of the balance (balance()), or
                             1 / closure (--closure-correction); 1 until then */
    float *gain;          /* per leaf: the receiver scale x of the balance; 1 until then */
    uint8_t *escape;      /* per leaf: how many of measure_open's rays left the scene */
    double *Bsend;        /* 3 per node: what sources send, B with the leaves' corr
                             pulled up */
    double *bins_in;      /* 18 per cluster: [channel][signed axis] */
    double *bins_total;   /* 18 per cluster, pushed down */
    double *bins_exit;    /* 18 per cluster, pulled up: sum A B |n_a| */
    hr_direct direct;     /* luminaires' and daylight's H_d per node (direct.c) */
    hr_mirrors mirrors;   /* links through mirrors and their H per node (mirror.c) */
    size_t values;        /* nodes the arrays cover */
    double emitted;       /* sum_leaves A E, channels summed */
    double absorbed;      /* W, channels summed */
    double radiant;       /* sum_leaves A B, channels summed: the power leaving */
    double rho_max;       /* the largest reflectance of any channel of any patch */
    int sweeps;
    double start;
    /* progressive display (p->display): the leaves' B in mesh order, and
     * the node count when the last leaf mesh was handed over (the tree only
     * grows, so an unchanged count is an unchanged hierarchy) */
    double *display_B;
    size_t display_leaves, display_nodes;
    rad_hier_stats *hs;   /* links and leaves kept current for the display */
} hr_state;

static const double *node_emission(const hr_state *st, const hr_node *n)
{
    const rad_patch *pa = &st->tree.base->patches[n->patch];
    return st->tree.scene->materials[pa->material].emission;
}

#define VALUES_WHAT "hierarchical: node values (a larger rad_options.epsilon or rad_options.min_area makes fewer nodes)"

/* Grow the per-node arrays to the tree; new nodes start from their
 * parent's radiosity. */
static rad_result ensure_values(hr_state *st)
{
    size_t n = st->tree.count;
    if (n == st->values)
        return RAD_OK;
    double *B = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->B, 3 * n, sizeof *B, VALUES_WHAT);
    if (B)
        st->B = B;
    double *H = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->H, 3 * n, sizeof *H, VALUES_WHAT);
    if (H)
        st->H = H;
    double *Ht = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->Ht, 3 * n, sizeof *Ht, VALUES_WHAT);
    if (Ht)
        st->Ht = Ht;
    double *Hq = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->Hq, 3 * n, sizeof *Hq, VALUES_WHAT);
    if (Hq)
        st->Hq = Hq;
    double *sp = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->spread, n, sizeof *sp, VALUES_WHAT);
    if (sp)
        st->spread = sp;
    float *op = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->open, n, sizeof *op, VALUES_WHAT);
    if (op)
        st->open = op;
    float *se = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->send, n, sizeof *se, VALUES_WHAT);
    if (se)
        st->send = se;
    float *tk = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->take, n, sizeof *tk, VALUES_WHAT);
    if (tk)
        st->take = tk;
    double *Bs = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->Bsend, 3 * n, sizeof *Bs, VALUES_WHAT);
    if (Bs)
        st->Bsend = Bs;
    float *co = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->corr, n, sizeof *co, VALUES_WHAT);
    if (co)
        st->corr = co;
    float *ga = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->gain, n, sizeof *ga, VALUES_WHAT);
    if (ga)
        st->gain = ga;
    uint8_t *es = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->escape, n, 1, VALUES_WHAT);
    if (es)
        st->escape = es;
    if (!B || !H || !Ht || !Hq || !sp || !op || !se || !tk || !Bs || !co || !ga || !es)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (size_t k = st->values; k < n; k++) {
        const hr_node *nd = &st->tree.nodes[k];
        for (int c = 0; c < 3; c++) {
            st->B[3 * k + (size_t)c] = nd->parent != HR_NONE && st->tree.nodes[nd->parent].kind == HR_SURFACE
                                           ? st->B[3 * (size_t)nd->parent + (size_t)c]
                                           : (nd->kind == HR_SURFACE ? node_emission(st, nd)[c] : 0.0);
            st->H[3 * k + (size_t)c] = 0.0;
            st->Ht[3 * k + (size_t)c] = 0.0;
            st->Hq[3 * k + (size_t)c] = 0.0;
        }
        st->spread[k] = 0.0;
        st->open[k] = -1.0f;
        st->send[k] = 1.0f;
        st->take[k] = 1.0f;
        st->corr[k] = 1.0f;
        st->gain[k] = 1.0f;
        st->escape[k] = 0;
        for (int c = 0; c < 3; c++)
            st->Bsend[3 * k + (size_t)c] = st->B[3 * k + (size_t)c];
    }
    st->values = n;
    return RAD_OK;
}

/* Counting sort of the links by receiver, those that carry something
 * first (stable: the refinement order is kept within each part, so sums
 * are thread-count independent).  Links whose rays were all blocked (k =
 * 0) stay for refinement (refine.c) but the gather skips them: in a
 * building they are most of the links (76% of 4.4 M at 100 rooms). */
static rad_result sort_links(hr_state *st)
{
    size_t n = st->tree.count, L = st->links.count;
    size_t *off = rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->offset, n + 1, sizeof *off, "hierarchical: link offsets");
    if (off)
        st->offset = off;
    size_t *live = off ? rad_realloc(st->ctx, RAD_MEM_HIERARCHY, st->live, n, sizeof *live, "hierarchical: link offsets")
                       : NULL;
    if (live)
        st->live = live;
    hr_link *sorted = live ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, L, sizeof *sorted, "hierarchical: sorted links")
                           : NULL;
    size_t *fill = sorted ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, sizeof *fill, "hierarchical: sorted links") : NULL;
    if (!fill) {
        rad_free(sorted);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memset(off, 0, (n + 1) * sizeof *off);
    memset(live, 0, n * sizeof *live);
    for (size_t i = 0; i < L; i++) {
        off[st->links.items[i].r + 1]++;
        live[st->links.items[i].r] += st->links.items[i].k > 0.0f;
    }
    for (size_t k = 0; k < n; k++) {
        off[k + 1] += off[k];
        live[k] += off[k];
    }
    /* Carrying links fill [off, live), blocked ones [live, off[k + 1]). */
    memcpy(fill, off, n * sizeof *fill);
    for (size_t i = 0; i < L; i++)
        if (st->links.items[i].k > 0.0f)
            sorted[fill[st->links.items[i].r]++] = st->links.items[i];
    for (size_t i = 0; i < L; i++)
        if (!(st->links.items[i].k > 0.0f))
            sorted[fill[st->links.items[i].r]++] = st->links.items[i];
    rad_free(fill);
    rad_free(st->links.items);
    st->links.items = sorted;
    st->links.capacity = L ? L : 1;
    return RAD_OK;
}

/* The weights by which a partly hidden link shares its light among the
 * children of its end (end 0: the receiver r, 1: the source) by their
 * quarters' visibility (HR_LINK_QUADS, hier.h): each quarter's over their
 * area mean, so that sum_q A_q w_q = A and the link moves the power it
 * did.  Returns false (alike, the area mean) where that end has no
 * children, the link no quarters, or it is partly hidden where the
 * balance holds the scene's sums (st->quads off: balance(); the factor's
 * shape alone, from exact point factors, is kept). */
static bool quad_weights(const hr_state *st, uint32_t node, uint32_t flags, int end, double w[4])
{
    const hr_tree *t = &st->tree;
    const hr_node *nd = &t->nodes[node];
    if (!(flags & HR_LINK_QUADS) || (!st->quads && (flags & HR_LINK_PARTLY)) || nd->kind != HR_SURFACE ||
        !nd->child[0])
        return false;
    double area = 0.0, seen = 0.0;
    for (int q = 0; q < 4; q++) {
        double a = t->nodes[nd->child[0] + (uint32_t)q].area;
        w[q] = hr_link_quad(flags, end, q);
        area += a;
        seen += a * w[q];
    }
    if (!(seen > 0.0))
        return false;
    for (int q = 0; q < 4; q++)
        w[q] *= area / seen;
    return true;
}

/* Gather every receiver's links into H (surfaces) or bins_in (clusters);
 * a surface's partly hidden links into its children's Hq, by the
 * quarters' visibility (each node's Hq is written by its parent alone),
 * and a partly seen surface source's light from its quarters likewise. */
static void gather(hr_state *st)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    const hr_link *links = st->links.items;
    memset(st->bins_in, 0, 18 * t->clusters * sizeof *st->bins_in);
#pragma omp parallel for schedule(dynamic, 256) num_threads(rad_context_threads(st->ctx))
    for (size_t k = 0; k < n; k++) {
        const hr_node *nr = &t->nodes[k];
        double h[3] = {0.0, 0.0, 0.0}, hq[4][3] = {{0.0}};
        double *bins = nr->kind == HR_CLUSTER ? &st->bins_in[18 * k] : NULL;
        for (size_t i = st->offset[k]; i < st->live[k]; i++) {
            const hr_link *l = &links[i];
            const hr_node *ns = &t->nodes[l->s];
            double e[3], w4[4];
            if (ns->kind == HR_SURFACE) {
                double kk = l->k * st->send[l->s]; /* what it reflects leaves from its open part */
                const double *Bs = &st->Bsend[3 * (size_t)l->s];
                if (quad_weights(st, l->s, l->flags, 1, w4)) {
                    /* From the source's quarters by how much of each is seen. */
                    e[0] = e[1] = e[2] = 0.0;
                    for (int q = 0; q < 4; q++) {
                        uint32_t ch = ns->child[0] + (uint32_t)q;
                        double f = kk * w4[q] * t->nodes[ch].area / ns->area;
                        for (int c = 0; c < 3; c++)
                            e[c] += f * st->Bsend[3 * (size_t)ch + (size_t)c];
                    }
                } else {
                    for (int c = 0; c < 3; c++)
                        e[c] = kk * Bs[c];
                }
            } else {
                vec3 back = v3_scale(hr_link_direction(l), -1.0);
                for (int c = 0; c < 3; c++)
                    e[c] = l->k * hr_bins_eval(&st->bins_exit[18 * (size_t)l->s + 6 * (size_t)c], back);
            }
            if (bins) {
                vec3 w = hr_link_direction(l);
                for (int c = 0; c < 3; c++)
                    hr_bins_add(bins + 6 * c, w, e[c]);
            } else if (quad_weights(st, (uint32_t)k, l->flags, 0, w4)) {
                for (int q = 0; q < 4; q++)
                    for (int c = 0; c < 3; c++)
                        hq[q][c] += w4[q] * e[c];
            } else {
                for (int c = 0; c < 3; c++)
                    h[c] += e[c];
            }
        }
        for (int c = 0; c < 3; c++)
            st->H[3 * k + (size_t)c] = h[c];
        if (nr->kind == HR_SURFACE && nr->child[0])
            for (int q = 0; q < 4; q++)
                memcpy(&st->Hq[3 * (size_t)(nr->child[0] + (uint32_t)q)], hq[q], sizeof hq[q]);
    }
}

/* Push down: every surface node's total irradiance Ht is its own H plus
 * its parent's (read from a parent cluster's bins with its normal); the
 * clusters' bins_total likewise.  Parents come first in the node array. */
static void push(hr_state *st)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    for (size_t k = 0; k < n; k++) {
        const hr_node *nd = &t->nodes[k];
        uint32_t up = nd->parent;
        if (nd->kind == HR_CLUSTER) {
            for (int q = 0; q < 18; q++)
                st->bins_total[18 * k + (size_t)q] =
                    st->bins_in[18 * k + (size_t)q] + (up != HR_NONE ? st->bins_total[18 * (size_t)up + (size_t)q] : 0.0);
            continue;
        }
        double *ht = &st->Ht[3 * k];
        /* A parent's irradiance is its area mean, the part of it inside a
         * solid (measure_open) counted as receiving nothing: its children
         * get it in proportion to their open parts, so that a child under
         * a block receives nothing and does not absorb and reflect what
         * its open siblings should (an office of 10 rooms lost 0.2% of
         * its power so, the reflected part of what hidden leaves took). */
        double open_share = 1.0;
        if (up != HR_NONE && t->nodes[up].kind == HR_SURFACE && st->take[up] > 0.0f && st->take[up] < 1.0f)
            open_share = (double)st->take[k] / (double)st->take[up];
        for (int c = 0; c < 3; c++) {
            double from_parent = 0.0;
            if (up != HR_NONE) {
                if (t->nodes[up].kind == HR_CLUSTER) /* per unit of open area (hr_tree_set_open) */
                    from_parent = (double)st->take[k] *
                                  hr_bins_eval(&st->bins_total[18 * (size_t)up + 6 * (size_t)c], nd->normal);
                else
                    from_parent = open_share * st->Ht[3 * (size_t)up + (size_t)c];
            }
            ht[c] = st->H[3 * k + (size_t)c] + st->Hq[3 * k + (size_t)c] + from_parent;
        }
    }
}

/* What the sources send, from the leaves' values V (3 per node): the area
 * means of surface nodes, and the clusters' exitance bins (the root
 * surfaces' A V / open by their normals, summed up the cluster tree).
 * Children come after their parents, so one backward loop. */
static void pull_send(hr_state *st, double *V)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    memset(st->bins_exit, 0, 18 * t->clusters * sizeof *st->bins_exit);
    for (size_t k = n; k-- > 0;) {
        const hr_node *nd = &t->nodes[k];
        if (nd->kind == HR_SURFACE && nd->child[0]) {
            double sum[3] = {0.0, 0.0, 0.0}, area = 0.0;
            for (uint32_t c4 = 0; c4 < 4; c4++) {
                uint32_t ch = nd->child[0] + c4;
                double a = t->nodes[ch].area;
                area += a;
                for (int c = 0; c < 3; c++)
                    sum[c] += a * V[3 * (size_t)ch + (size_t)c];
            }
            for (int c = 0; c < 3; c++)
                V[3 * k + (size_t)c] = area > 0.0 ? sum[c] / area : 0.0;
        }
        if (nd->kind == HR_SURFACE && nd->parent != HR_NONE && t->nodes[nd->parent].kind == HR_CLUSTER) {
            double *bins = &st->bins_exit[18 * (size_t)nd->parent];
            for (int c = 0; c < 3; c++) /* from its open part, as for surface sources */
                hr_bins_add(bins + 6 * c, nd->normal, nd->area * V[3 * k + (size_t)c] * st->send[k]);
        }
        if (nd->kind == HR_CLUSTER && nd->parent != HR_NONE)
            for (int q = 0; q < 18; q++)
                st->bins_exit[18 * (size_t)nd->parent + (size_t)q] += st->bins_exit[18 * k + (size_t)q];
    }
}

/* Pull up: every surface node's B is the area mean of its children's, a
 * cluster's of its members'; what the leaves send (Bsend: B times the
 * balance's source scale, balance()) and the clusters' exitance bins
 * follow (pull_send). */
static void pull(hr_state *st)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    for (size_t k = n; k-- > 0;) {
        const hr_node *nd = &t->nodes[k];
        int m = nd->kind == HR_CLUSTER ? 2 : nd->child[0] ? 4 : 0;
        if (m == 0) {
            if (st->corr)
                for (int c = 0; c < 3; c++)
                    st->Bsend[3 * k + (size_t)c] = st->B[3 * k + (size_t)c] * st->corr[k];
            continue;
        }
        double sum[3] = {0.0, 0.0, 0.0}, area = 0.0;
        for (int q = 0; q < m; q++) {
            uint32_t ch = hr_child(t, (uint32_t)k, q);
            double a = t->nodes[ch].area;
            area += a;
            for (int c = 0; c < 3; c++)
                sum[c] += a * st->B[3 * (size_t)ch + (size_t)c];
        }
        if (nd->kind == HR_CLUSTER)
            area = nd->area;
        for (int c = 0; c < 3; c++)
            st->B[3 * k + (size_t)c] = area > 0.0 ? sum[c] / area : 0.0;
    }
    pull_send(st, st->Bsend);
}

/* Push down, update the leaves (B = E + rho x Ht, x the balance's
 * receiver scale), pull up.  Returns the residual. */
static double push_pull(hr_state *st)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    double change = 0.0, absorbed = 0.0, radiant = 0.0;
    push(st);
    for (size_t k = 0; k < n; k++) {
        const hr_node *nd = &t->nodes[k];
        if (nd->kind != HR_SURFACE || nd->child[0] != 0)
            continue;
        const double *E = node_emission(st, nd), *rho = hr_node_reflectance(t, (uint32_t)k);
        const double *hd = st->direct.H ? &st->direct.H[3 * k] : NULL; /* direct.c */
        const double *hm = st->mirrors.H ? &st->mirrors.H[3 * k] : NULL; /* mirror.c */
        double x = st->gain ? st->gain[k] : 1.0;
        /* A mirror's specular part leaves through the mirror links. */
        double rho_s = hr_mirrors_specular(t, &st->mirrors, (uint32_t)k);
        for (int c = 0; c < 3; c++) {
            double h = x * st->Ht[3 * k + (size_t)c];
            if (hm)
                h += hm[c];
            double b = E[c] + rho[c] * (hd ? h + hd[c] : h);
            change += nd->area * fabs(b - st->B[3 * k + (size_t)c]);
            absorbed += nd->area * (1.0 - rho[c] - rho_s) * h;
            radiant += nd->area * b;
            st->B[3 * k + (size_t)c] = b;
        }
    }
    pull(st);
    st->absorbed = absorbed;
    st->radiant = radiant;
    return st->emitted > 0.0 ? change / st->emitted : 0.0;
}

static rad_result build_leaf_mesh(hr_state *st, rad_mesh **mesh, double **radiosity, size_t *leaves_out);

/* The leaves' B below node k in the leaf mesh's order (encode's walk). */
static void leaf_values(const hr_state *st, uint32_t k, double *out, size_t *i)
{
    const hr_node *n = &st->tree.nodes[k];
    if (n->child[0] == 0) {
        memcpy(out + 3 * (*i)++, st->B + 3 * (size_t)k, 3 * sizeof *out);
        return;
    }
    for (uint32_t c = 0; c < 4; c++)
        leaf_values(st, n->child[0] + c, out, i);
}

/* Hand the current leaves to the display: a new mesh when the hierarchy
 * changed since the last call (once per refinement round), else only
 * their values (a walk of the quadtrees, O(nodes)). */
static rad_result display_leaves(hr_state *st)
{
    rad_mesh *mesh = NULL;
    if (st->tree.count != st->display_nodes || !st->display_B) {
        double *B = NULL;
        size_t leaves = 0;
        rad_result r = build_leaf_mesh(st, &mesh, &B, &leaves);
        if (r != RAD_OK)
            return r;
        rad_free(st->display_B);
        st->display_B = B;
        st->display_leaves = leaves;
        st->display_nodes = st->tree.count;
    } else {
        size_t i = 0;
        for (size_t p = 0; p < st->tree.base->patch_count; p++)
            leaf_values(st, st->tree.root_of_patch[p], st->display_B, &i);
    }
    st->hs->leaves = st->display_leaves;
    st->hs->links = st->links.count;
    st->hs->nodes = st->tree.count;
    return st->p->display(st->p->display_user, mesh, st->display_B, st->display_leaves);
}

/* Sweeps until the residual is below `tol` (or `cap` sweeps). */
static rad_result solve(hr_state *st, double tol, double cap, double *residual, bool *converged)
{
    *converged = false;
    *residual = INFINITY;
    for (double it = 0; it < cap; it++) {
        if (rad_cancelled(st->ctx))
            return RAD_ERROR_INTERRUPTED;
        gather(st);
        rad_result rm = hr_mirrors_gather(st->ctx, &st->tree, &st->mirrors, st->B, st->send);
        if (rm != RAD_OK)
            return rm;
        *residual = push_pull(st);
        st->sweeps++;
        if (st->p->display) {
            rad_result r = display_leaves(st);
            if (r != RAD_OK)
                return r;
        }
        if (st->p->monitor) {
            rad_solve_step step = {st->sweeps, rad_seconds() - st->start, *residual, NAN};
            if (st->p->monitor(st->p->monitor_user, &step, NULL, NULL))
                return RAD_ERROR_INTERRUPTED;
        }
        if (*residual < tol) {
            *converged = true;
            return RAD_OK;
        }
        /* Power conservation bounds what leaves the surfaces: each bounce
         * reflects at most rho_max of what arrives, so sum A B <= emitted /
         * (1 - rho_max) when no link delivers more than its source sends.
         * Links whose estimates make up power (overlapping or interpenetrating
         * polygons, found by fuzz_solve) can make the sweeps diverge to
         * infinity and NaN: four times the bound, or a value that is not
         * finite, stops the solve with an error instead. */
        double bound = 4.0 * st->emitted / (1.0 - st->rho_max);
        if (!(st->radiant <= bound) && st->rho_max < 1.0)
            return rad_fail(st->ctx, RAD_ERROR_NUMERICAL,
                            "hierarchical: the solution diverges after %d sweeps (the surfaces send %.3g W, "
                            "more than four times the %.3g W that conservation allows): the links make up "
                            "power, as overlapping or interpenetrating polygons can (a dense solver, "
                            "rad_options.solver \"gauss-seidel\", does not use links)",
                            st->sweeps, st->radiant / 3.0, st->emitted / 3.0 / (1.0 - st->rho_max));
    }
    return RAD_OK;
}

#define OPEN_RAYS 16 /* measure_open's rays a leaf */

/* A per-node fraction's internal values: their children's area means,
 * bottom-up (children follow their parents). */
static void area_means(const hr_tree *t, float *v)
{
    for (size_t k = t->count; k-- > 0;) {
        const hr_node *nd = &t->nodes[k];
        if (nd->kind != HR_SURFACE || !nd->child[0])
            continue;
        double a = 0.0, f = 0.0;
        for (uint32_t q = 0; q < 4; q++) {
            a += t->nodes[nd->child[0] + q].area;
            f += t->nodes[nd->child[0] + q].area * v[nd->child[0] + q];
        }
        v[k] = (float)(a > 0.0 ? f / a : 1.0);
    }
}

/* Contact lines.  A leaf that runs under a block resting on it is partly
 * inside a solid: its links' visibility is 0 from the hidden part, so what
 * it reflects, averaged over its whole area, would leave from the open part
 * only and the rest vanish (0.3% of the power for one box on a floor).  So
 * each leaf's open fraction is measured (cosine-weighted rays from random
 * points; a point is inside when its ray first meets the back of a
 * surface), and a source's radiosity is sent as B / open: the power it
 * reflects, from the part that can send it.  Internal nodes take the area
 * mean of their children's open fractions. */
static void measure_open(hr_state *st, const rad_vis *vis, uint64_t seed)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    enum { RAYS = OPEN_RAYS };
#pragma omp parallel for schedule(dynamic, 64) num_threads(rad_context_threads(st->ctx))
    for (size_t k = 0; k < n; k++) {
        const hr_node *nd = &t->nodes[k];
        if (nd->kind != HR_SURFACE || nd->child[0] || st->open[k] >= 0.0f)
            continue;
        if (!vis) {
            st->open[k] = 1.0f;
            continue;
        }
        rad_rng rng = rad_rng_keyed(seed ^ 0x4f50454eULL, k, 0);
        rad_ray ray[RAYS];
        rad_hit hit[RAYS];
        vec3 tn = v3_normalize(fabs(nd->normal.x) > 0.9 ? v3_cross(nd->normal, v3(0, 1, 0))
                                                        : v3_cross(nd->normal, v3(1, 0, 0)));
        vec3 bn = v3_cross(nd->normal, tn);
        for (int r = 0; r < RAYS; r++) {
            double u = ((r % 4) + rad_rng_uniform(&rng)) / 4.0, v = ((r / 4) + rad_rng_uniform(&rng)) / 4.0;
            vec3 p, normal;
            double uvw[3] = {0.0, 0.0, 0.0}, lift;
            uvw[0] = rad_rng_uniform(&rng); /* one statement each: initialisers are unsequenced */
            uvw[1] = rad_rng_uniform(&rng);
            hr_sample(t, (uint32_t)k, 1, uvw, false, &p, &normal, &lift);
            double rr = sqrt(u), phi = 2.0 * M_PI * v, z = sqrt(fmax(0.0, 1.0 - u));
            ray[r].origin = v3_mad(p, nd->normal, lift);
            ray[r].direction = v3_add(v3_add(v3_scale(tn, rr * cos(phi)), v3_scale(bn, rr * sin(phi))),
                                      v3_scale(nd->normal, z));
            ray[r].tnear = 0.0;
            ray[r].tfar = INFINITY;
        }
        vis->backend->intersect(vis->state, ray, RAYS, hit);
        int open = 0, escape = 0;
        for (int r = 0; r < RAYS; r++) {
            open += !(isfinite(hit[r].t) &&
                      v3_dot(ray[r].direction, t->base->patches[hit[r].patch].normal) > 0.0);
            escape += !isfinite(hit[r].t);
        }
        st->open[k] = (float)open / RAYS;
        st->escape[k] = (uint8_t)escape;
    }
    area_means(t, st->open);
    /* Patches are cut along contact lines (mesh/conform.c), so a leaf is
     * almost always wholly open or wholly inside; a measured fraction near
     * 0 or 1 is that, off by rays that graze a neighbour or slip out
     * through a seam.  Sending B / (15/16) from an open leaf, or 16 B from
     * one shut inside a shelf's board, made up power (a 4-room office
     * diverged); only a fraction well inside (1/4, 3/4) is a leaf partly
     * inside a solid. */
    for (size_t k = 0; k < n; k++) {
        float o = t->nodes[k].kind == HR_SURFACE ? st->open[k] : 1.0f;
        st->send[k] = o >= 0.75f ? 1.0f : o > 0.25f ? 1.0f / o : 0.0f;
        st->take[k] = o >= 0.75f ? 1.0f : o > 0.25f ? o : 0.0f;
    }
    area_means(t, st->take);
    hr_tree_set_open(&st->tree, st->take);
}

/* How much each node's radiosity varies below it, max over its leaves and
 * the channels of |B_leaf - B_node|: what the oracle charges a link for
 * using the node as one source.  Bottom-up over the leaves' ranges. */
static rad_result measure_spread(hr_state *st)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    double *lo = rad_alloc(st->ctx, RAD_MEM_HIERARCHY, 3 * n, sizeof *lo, "hierarchical: radiosity ranges");
    double *hi = lo ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, 3 * n, sizeof *hi, "hierarchical: radiosity ranges") : NULL;
    if (!hi) {
        rad_free(lo);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t k = n; k-- > 0;) {
        const hr_node *nd = &t->nodes[k];
        double *l = &lo[3 * k], *h = &hi[3 * k];
        if (nd->kind == HR_SURFACE && !nd->child[0]) {
            for (int c = 0; c < 3; c++)
                l[c] = h[c] = st->B[3 * k + (size_t)c];
        } else {
            for (int c = 0; c < 3; c++) {
                l[c] = INFINITY;
                h[c] = -INFINITY;
            }
            int m = nd->kind == HR_CLUSTER ? 2 : 4;
            for (int q = 0; q < m; q++) {
                size_t ch = hr_child(t, (uint32_t)k, q);
                for (int c = 0; c < 3; c++) {
                    l[c] = fmin(l[c], lo[3 * ch + (size_t)c]);
                    h[c] = fmax(h[c], hi[3 * ch + (size_t)c]);
                }
            }
        }
        double d = 0.0;
        for (int c = 0; c < 3; c++)
            d = fmax(d, fmax(h[c] - st->B[3 * k + (size_t)c], st->B[3 * k + (size_t)c] - l[c]));
        st->spread[k] = d;
    }
    rad_free(lo);
    rad_free(hi);
    return RAD_OK;
}

/* ---- closure ---- */

/* Six bins of a unit vector: |d_a| in the bin of d_a's sign. */
static void bins_of(vec3 d, double *out)
{
    for (int q = 0; q < 6; q++)
        out[q] = 0.0;
    hr_bins_add(out, d, 1.0);
}

/* Closure of the link set (the hierarchical counterpart of the row sums of
 * F): for every leaf m, the fraction of the power it sends, A_m B_m, that
 * its links and its ancestors' carry to some receiver.  1 in a closed
 * scene, less where power escapes (or is lost), more where it is made up.
 * A receiver's share is its area times k (surfaces), or k times its
 * members' projected area toward the source as the bins read it
 * (clusters); a leaf under a cluster source takes the share its normal
 * has in the cluster's exitance bins.  acc: n values, the closure of each
 * surface node (its ancestors' links included); the leaves' are the ones
 * that count.  O(links + nodes). */
static rad_result link_closure(const hr_state *st, double *acc, const double *X, const double *xbins, double *cl)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count, C = t->clusters;
    /* clusters: sum k P_r bins(-w), pushed down */
    double *x = rad_alloc(st->ctx, RAD_MEM_HIERARCHY, 6 * C + 1, sizeof *x, "hierarchical: closure");
    if (!x)
        return RAD_ERROR_OUT_OF_MEMORY;
    memset(acc, 0, n * sizeof *acc);
    if (cl)
        memset(cl, 0, n * sizeof *cl);
    for (size_t i = 0; i < st->links.count; i++) {
        const hr_link *l = &st->links.items[i];
        const hr_node *nr = &t->nodes[l->r], *ns = &t->nodes[l->s];
        vec3 w = nr->kind == HR_SURFACE && ns->kind == HR_SURFACE ? v3(0.0, 0.0, 1.0) : hr_link_direction(l);
        double share = nr->kind == HR_SURFACE ? (X ? X[l->r] : nr->area)
                       : xbins                ? hr_bins_eval(&xbins[6 * (size_t)l->r], w)
                                              : hr_projected(t, l->r, w);
        double qw[4];
        if (X && quad_weights(st, l->r, l->flags, 0, qw)) { /* as the gather shares it */
            share = 0.0;
            for (int q = 0; q < 4; q++)
                share += qw[q] * X[nr->child[0] + (uint32_t)q];
        }
        share *= l->k;
        if (ns->kind == HR_SURFACE && quad_weights(st, l->s, l->flags, 1, qw)) {
            /* Taken from the source's quarters as the gather takes it. */
            for (int q = 0; q < 4; q++)
                acc[ns->child[0] + (uint32_t)q] += share * st->send[l->s] * qw[q] / ns->area;
        } else if (ns->kind == HR_SURFACE) {
            acc[l->s] += share * st->send[l->s] / ns->area;
        } else {
            double d[6];
            bins_of(v3_scale(w, -1.0), d);
            for (int q = 0; q < 6; q++)
                x[6 * (size_t)l->s + (size_t)q] += share * d[q];
        }
    }
    for (size_t k = 0; k < n; k++) {
        const hr_node *nd = &t->nodes[k];
        uint32_t up = nd->parent;
        if (nd->kind == HR_CLUSTER) {
            if (up != HR_NONE)
                for (int q = 0; q < 6; q++)
                    x[6 * k + (size_t)q] += x[6 * (size_t)up + (size_t)q];
            continue;
        }
        if (up == HR_NONE)
            continue;
        if (t->nodes[up].kind == HR_CLUSTER) {
            double nb[6];
            bins_of(nd->normal, nb);
            double f = 0.0;
            for (int q = 0; q < 6; q++)
                f += nb[q] * x[6 * (size_t)up + (size_t)q];
            acc[k] += f * st->send[k];
            if (cl)
                cl[k] = f * st->send[k];
        } else {
            acc[k] += acc[up];
            if (cl)
                cl[k] = cl[up];
        }
    }
    rad_free(x);
    return RAD_OK;
}

static rad_result link_columns(hr_state *st, const float *x, double *X, double *xbins, double *acc, double *cl);

/* The closure's area-weighted mean and range over leaves, and its
 * power-weighted mean (weights A B, channels summed), into the stats: of
 * the operator the solve used, the balance's scales included. */
static rad_result measure_closure(hr_state *st, rad_hier_stats *hs)
{
    const hr_tree *t = &st->tree;
    double *acc = rad_alloc(st->ctx, RAD_MEM_HIERARCHY, t->count, sizeof *acc, "hierarchical: closure");
    double *X = acc ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, t->count, sizeof *X, "hierarchical: closure") : NULL;
    double *xb = X ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, 6 * t->clusters + 1, sizeof *xb, "hierarchical: closure")
                   : NULL;
    if (!xb) {
        rad_free(acc);
        rad_free(X);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    rad_result r = link_columns(st, st->gain, X, xb, acc, NULL);
    for (size_t k = 0; r == RAD_OK && k < t->count; k++)
        acc[k] *= st->corr[k];
    rad_free(X);
    rad_free(xb);
    double a_sum = 0.0, c_sum = 0.0, p_sum = 0.0, pc_sum = 0.0, lo = INFINITY, hi = -INFINITY;
    for (size_t k = 0; r == RAD_OK && k < t->count; k++) {
        const hr_node *nd = &t->nodes[k];
        if (nd->kind != HR_SURFACE || nd->child[0] != 0 || !(st->open[k] > 0.0f))
            continue;
        const double *B = &st->B[3 * k];
        double power = nd->area * (B[0] + B[1] + B[2]);
        a_sum += nd->area;
        c_sum += nd->area * acc[k];
        p_sum += power;
        pc_sum += power * acc[k];
        lo = fmin(lo, acc[k]);
        hi = fmax(hi, acc[k]);
    }
    hs->closure_mean = a_sum > 0.0 ? c_sum / a_sum : 1.0;
    hs->closure_power = p_sum > 0.0 ? pc_sum / p_sum : 1.0;
    hs->closure_min = isfinite(lo) ? lo : 1.0;
    hs->closure_max = isfinite(hi) ? hi : 1.0;
    rad_free(acc);
    return r;
}

/* correct_closure's mask: the leaves the balance holds, and those whose
 * rows go through a cluster, which it cannot. */
enum { HR_HELD = 3, HR_FIX_CLOSURE = 4 };

/* Closure correction: the leaves of a patch send B / c instead of B, c
 * the patch's closure (its leaves' closures weighted by the power they
 * send) over the closure it should have, so that the links deliver exactly
 * the power each patch reflects.  The closure it should have is what its
 * leaves' rays measured (measure_open): 1 less the share that left the
 * scene, 1 in a closed one.  The counterpart of the matrix methods' row
 * scaling (formfactor/): what the links' estimates lose (partial
 * visibility along contact edges runs low, docs/hierarchical.md; cluster
 * links' Monte Carlo transfers) is put back in proportion to what they
 * carry.  Per patch, not per leaf: a leaf's own closure mixes its own
 * factors (links made at its level) with its ancestors' means (links made
 * above it), so it is not 1 even when the patch's is: a corner leaf reads
 * high, its siblings low.  Closures outside [0.5, 2] are taken as a patch
 * that does not face a closed scene, and left alone.  Every patch with
 * --closure-correction (mask NULL); by default the patches whose rows go
 * through a cluster, which the balance cannot hold (mask, below). */
static rad_result correct_closure(hr_state *st, const uint8_t *mask, size_t *corrected)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    double *acc = rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, sizeof *acc, "hierarchical: closure correction");
    double *sum = acc ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, 2 * n + 1, sizeof *sum, "hierarchical: closure correction")
                      : NULL;
    uint32_t *root = sum ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, sizeof *root, "hierarchical: closure correction")
                         : NULL;
    uint8_t *root_mark = root ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, 1, "hierarchical: closure correction") : NULL;
    double *X = root_mark ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, sizeof *X, "hierarchical: closure correction") : NULL;
    double *xb = X ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, 6 * t->clusters + 1, sizeof *xb,
                               "hierarchical: closure correction")
                   : NULL;
    if (!xb) {
        rad_free(acc);
        rad_free(sum);
        rad_free(root);
        rad_free(root_mark);
        rad_free(X);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    /* The closures as the gather delivers (a cluster receiver's share from
     * its members' bins, the quarters' shares), before any source scale. */
    rad_result r = link_columns(st, st->gain, X, xb, acc, NULL);
    *corrected = 0;
    /* Parents come before their children. */
    for (size_t k = 0; r == RAD_OK && k < n; k++) {
        const hr_node *nd = &t->nodes[k];
        uint32_t up = nd->parent;
        root[k] = up == HR_NONE || t->nodes[up].kind == HR_CLUSTER ? (uint32_t)k : root[up];
        if (nd->kind != HR_SURFACE || nd->child[0] != 0 || !(st->open[k] > 0.0f))
            continue;
        const double *B = &st->B[3 * k];
        double power = nd->area * (B[0] + B[1] + B[2]);
        sum[2 * (size_t)root[k]] += power * acc[k];
        sum[2 * (size_t)root[k] + 1] += power * (1.0 - (double)st->escape[k] / OPEN_RAYS);
    }
    /* With a mask, only the patches with a leaf marked HR_FIX_CLOSURE and
     * none marked HR_HELD (the balance holds those). */
    for (size_t k = 0; r == RAD_OK && mask && k < n; k++)
        if (t->nodes[k].kind == HR_SURFACE && !t->nodes[k].child[0])
            root_mark[root[k]] |= mask[k];
    for (size_t k = 0; r == RAD_OK && mask && k < n; k++)
        if (root_mark[k] != HR_FIX_CLOSURE)
            sum[2 * k + 1] = NAN;
    for (size_t k = 0; r == RAD_OK && k < n; k++) {
        const hr_node *nd = &t->nodes[k];
        st->corr[k] = 1.0f;
        if (nd->kind != HR_SURFACE || nd->child[0] != 0)
            continue;
        double delivered = sum[2 * (size_t)root[k]], power = sum[2 * (size_t)root[k] + 1];
        double c = power > 0.0 ? delivered / power : 1.0;
        if (c >= 0.5 && c <= 2.0 && c != 1.0) {
            st->corr[k] = (float)(1.0 / c);
            (*corrected)++;
        }
    }
    rad_free(acc);
    rad_free(sum);
    rad_free(root);
    rad_free(root_mark);
    rad_free(X);
    rad_free(xb);
    return r;
}

/* ---- the balance: a link operator that conserves power exactly ----
 *
 * The links are exact factors between nodes (refine.c), but a leaf
 * receives through its ancestors' links too, with their area means: the
 * effective leaf-to-leaf operator K (K(r, m) = k of the link that covers
 * the pair, times m's share of its source) has the right sums over every
 * node that holds links, not over each leaf.  On a closed 1 x 2 x 3 m box
 * of 6 patches the leaves' row sums run from 0.87 to 1.15 around an area
 * mean of 1 - 2e-8: corner leaves read their walls' mean factor, not their
 * own.  Those errors are small per link (the oracle's epsilon) and add up
 * with one sign, so B = E / (1 - rho) came out 0.7% high at rho 0.8, and
 * the box absorbed 0.6% more than it emitted.
 *
 * Where the answer is known, the operator is made to hold it once the
 * links are final: leaf r's irradiance is scaled by x_r and leaf m's
 * sending by y_m (Bsend = y B),
 *
 *      K'(r, m) = x_r K(r, m) y_m,
 *
 * with x, y found by Sinkhorn's alternation (Sinkhorn & Knopp 1967) so
 * that every row sum (what a leaf receives per unit of radiosity
 * everywhere) and every column sum (the fraction of what it sends that
 * arrives, sum_r A_r K'(r, m) / A_m) is 1.  The answer is known in a
 * closed scene (no ray of measure_open left it), for the leaves wholly
 * outside the solids (every ray met a front face).  Then a furnace gives
 * B = E / (1 - rho) and a closed scene absorbs what it emits, to the
 * scales' float precision; the box's scales run from 0.74 to 1.21 and
 * settle in 11 iterations, each one gather and one adjoint pass over the
 * links.
 *
 * Left at scale 1:
 *   - open scenes: a leaf's true sum is 1 less what it sees of the
 *     opening, which varies over a patch.  Targets made of the leaves' own
 *     factors with their links' visibility (a link's visibility is its
 *     receiver's mean) made the open Cornell box's surfaces worse, 1.0%
 *     against 0.4% from the converged reference; a patch whose few rays
 *     missed a small view of the opening, held to 1, put its floor 0.2%
 *     high.
 *   - leaves partly inside a solid: they receive on their open part.
 *   - leaves whose row or column goes through a cluster: a cluster shares
 *     its transfer among its members by their normals, not by how each
 *     sees the other end, so a member's sums are not its own factor sums;
 *     held to 1 they needed scales of 0.004 to 22 in an office, and rows
 *     held to 1 without their columns made 2.6% of its power.  Their
 *     patches get the closure correction instead (correct_closure: the
 *     columns alone, per patch): the lit office of 10 rooms kept 99.0% of
 *     its power along its links without it, and its work planes' Eavg
 *     came 0.45% nearer the path-traced reference with it. */

/* Row sums of the operator with source scale y (per leaf): R[k] for every
 * leaf, what it receives per unit of radiosity everywhere, before its
 * receiver scale.  V: 3 per node, scratch. */
static void link_rows(hr_state *st, const float *y, double *V, double *R)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    for (size_t k = 0; k < n; k++) {
        bool leaf = t->nodes[k].kind == HR_SURFACE && !t->nodes[k].child[0];
        for (int c = 0; c < 3; c++)
            V[3 * k + (size_t)c] = leaf ? (double)y[k] : 0.0;
    }
    pull_send(st, V);
    double *keep = st->Bsend;
    st->Bsend = V;
    gather(st);
    st->Bsend = keep;
    push(st);
    for (size_t k = 0; k < n; k++)
        R[k] = st->Ht[3 * k];
}

/* Column sums of the operator with receiver scale x: acc[m] for every
 * leaf, the fraction of what it sends that arrives, before its source
 * scale.  X: n values, xbins: 6 per cluster, scratch. */
static rad_result link_columns(hr_state *st, const float *x, double *X, double *xbins, double *acc, double *cl)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    memset(xbins, 0, 6 * t->clusters * sizeof *xbins);
    for (size_t k = n; k-- > 0;) {
        const hr_node *nd = &t->nodes[k];
        if (nd->kind == HR_CLUSTER) {
            if (nd->parent != HR_NONE)
                for (int q = 0; q < 6; q++)
                    xbins[6 * (size_t)nd->parent + (size_t)q] += xbins[6 * k + (size_t)q];
            continue;
        }
        if (!nd->child[0]) {
            X[k] = nd->area * (double)x[k];
        } else {
            X[k] = 0.0;
            for (uint32_t q = 0; q < 4; q++)
                X[k] += X[nd->child[0] + q];
        }
        if (nd->parent != HR_NONE && t->nodes[nd->parent].kind == HR_CLUSTER) /* its open part receives */
            hr_bins_add(&xbins[6 * (size_t)nd->parent], nd->normal, X[k] * (double)st->take[k]);
    }
    return link_closure(st, acc, X, xbins, cl);
}

/* How many of measure_open's rays left the scene: 0 for a closed one. */
static size_t rays_escaped(const hr_state *st)
{
    const hr_tree *t = &st->tree;
    size_t escaped = 0;
    for (size_t k = 0; k < t->count; k++)
        if (t->nodes[k].kind == HR_SURFACE && !t->nodes[k].child[0])
            escaped += st->escape[k];
    return escaped;
}

/* Balance the operator (above): the leaves' gain (x) and corr (y).  The
 * iterations, the last row error and the scales' range go to the stats. */
static rad_result balance(hr_state *st, rad_hier_stats *hs)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    double *V = rad_alloc(st->ctx, RAD_MEM_HIERARCHY, 3 * n, sizeof *V, "hierarchical: balance");
    double *R = V ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, sizeof *R, "hierarchical: balance") : NULL;
    double *X = R ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, sizeof *X, "hierarchical: balance") : NULL;
    double *xb = X ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, 6 * t->clusters + 1, sizeof *xb, "hierarchical: balance")
                   : NULL;
    double *cl = xb ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, sizeof *cl, "hierarchical: balance") : NULL;
    uint8_t *role = cl ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, 1, "hierarchical: balance") : NULL;
    rad_result r = role ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
    for (size_t k = 0; r == RAD_OK && k < n; k++)
        st->corr[k] = st->gain[k] = 1.0f;
    /* Who takes part (above): in a closed scene (no ray of measure_open
     * left it), the leaves wholly outside the solids (every ray met a
     * front face) whose rows and columns go through no cluster. */
    enum { ROW = 1, COLUMN = 2 };
    _Static_assert((ROW | COLUMN) == HR_HELD, "the balance's roles and correct_closure's mask agree");
    if (r == RAD_OK)
        r = link_columns(st, st->gain, X, xb, R, cl);
    size_t escaped = r == RAD_OK ? rays_escaped(st) : 0;
    /* Rows through a cluster: a link with a cluster end at the leaf, an
     * ancestor or a cluster above it (flagged in role, pushed down). */
    for (size_t k = 0; r == RAD_OK && k < n; k++)
        role[k] = 0;
    for (size_t i = 0; r == RAD_OK && i < st->links.count; i++) {
        const hr_link *l = &st->links.items[i];
        if (t->nodes[l->r].kind == HR_CLUSTER || t->nodes[l->s].kind == HR_CLUSTER)
            role[l->r] = 1;
    }
    size_t rows = 0;
    for (size_t k = 0; r == RAD_OK && k < n; k++) {
        const hr_node *nd = &t->nodes[k];
        bool via_cluster = role[k] || (nd->parent != HR_NONE && role[nd->parent]);
        role[k] = via_cluster;
        if (nd->kind != HR_SURFACE || nd->child[0])
            continue;
        role[k] = via_cluster ? HR_FIX_CLOSURE : 0;
        if (escaped > 0 || via_cluster || st->open[k] != 1.0f || !(R[k] > 0.0) || cl[k] > 1e-9 * R[k])
            continue;
        role[k] = ROW | COLUMN;
        rows++;
    }
    /* The balance holds the sums where it applies (a closed scene without
     * clusters); the quarters' shares of a pair's two links, each from its
     * own rays, are less reciprocal than the pair, and the alternation
     * stalled earlier with them (a block on a box's floor: +0.22% against
     * -0.06%), so it works on the links' plain shares; those of the
     * factor's shape are kept (quad_weights): without them the ceiling
     * strip along a lit room's wall read 23% over the path-traced
     * reference and the middle 4.4% under. */
    if (rows > 0 && st->quads) {
        st->quads = false;
        if (r == RAD_OK)
            r = link_columns(st, st->gain, X, xb, R, cl);
    }
    /* The leaves the alternation cannot hold (rows through a cluster):
     * each patch sends B / its closure (correct_closure), so that its
     * links deliver all it sends and a closed scene absorbs what it emits.
     * The lit office of 10 rooms: the links' own closure 0.990 of the
     * power, corrected 1.000; its balance from 1.2% to 4.9e-5 (with push's
     * open shares), the work planes' Eavg 0.45% nearer the path-traced
     * reference (bench/office_lit.py --paths). */
    if (r == RAD_OK) {
        if ((r = correct_closure(st, role, &hs->closure_corrected)) == RAD_OK && rows > 0)
            r = link_columns(st, st->gain, X, xb, R, cl);
    }
    /* Alternate: rows to 1 with y fixed, columns to 1 with x fixed, until
     * the rows are off by under 1e-6 after a column step (the scales are
     * floats).  Leaves that receive or send nothing keep scale 1. */
    int it = 0;
    double worst = 0.0;
    const double tiny = 1e-12;
    double last = INFINITY;
    for (; r == RAD_OK && rows > 0 && it < 100; it++) {
        link_rows(st, st->corr, V, R);
        worst = 0.0;
        for (size_t k = 0; k < n; k++)
            if ((role[k] & ROW) && R[k] > tiny)
                worst = fmax(worst, fabs((double)st->gain[k] * R[k] - 1.0));
        /* Done; or stalled, left after a column step (the columns carry
         * the power balance): where the links' visibility is estimated, a
         * pair's two links are not reciprocal and sums of exactly 1 may
         * not exist.  On a closed box with a block on its floor the error
         * fell 0.31, 0.05, 0.008, 0.005, then 1.3% an iteration while the
         * scales drifted and the power balance worsened (-0.05% after 1
         * iteration, -0.2% after 40, +0.27% unbalanced). */
        if (worst < 1e-6 || (it >= 2 && worst > 0.7 * last))
            break;
        last = worst;
        for (size_t k = 0; k < n; k++)
            if ((role[k] & ROW) && R[k] > tiny)
                st->gain[k] = (float)(1.0 / R[k]);
        if ((r = link_columns(st, st->gain, X, xb, R, NULL)) != RAD_OK)
            break;
        for (size_t k = 0; k < n; k++) {
            if (!(role[k] & COLUMN) || !(R[k] > tiny))
                continue;
            st->corr[k] = (float)(1.0 / R[k]);
        }
    }
    if (r == RAD_OK) {
        double lo = INFINITY, hi = -INFINITY;
        for (size_t k = 0; k < n; k++)
            if (t->nodes[k].kind == HR_SURFACE && !t->nodes[k].child[0]) {
                lo = fmin(lo, fmin(st->gain[k], st->corr[k]));
                hi = fmax(hi, fmax(st->gain[k], st->corr[k]));
            }
        hs->balance_iterations = it;
        hs->balanced_leaves = rows;
        hs->balance_residual = worst;
        hs->balance_scale_min = isfinite(lo) ? lo : 1.0;
        hs->balance_scale_max = isfinite(hi) ? hi : 1.0;
        pull(st);
    }
    rad_free(V);
    rad_free(R);
    rad_free(X);
    rad_free(xb);
    rad_free(cl);
    rad_free(role);
    return r;
}

/* The mirror links' balance (mirror.c, hr_mirrors_balance), in a closed
 * scene, where all that a mirror reflects lands somewhere: for every leaf
 * m, the power the ordinary links bring the mirrors from it per unit of
 * its B and area, times the mirrors' rho_s (the column sums of the
 * operator with receiver scale rho_s x the balance's gain on the mirror
 * leaves and 0 elsewhere), times m's own source scale.  The mirror links
 * then send that power on: a closed scene with mirrors absorbs what it
 * emits as one without (their geometry alone left the Gauss rule's and
 * the sources' means' shortfall, 0.9% of what a mirror floor reflects in
 * a closed box, and the ordinary links' own error at the mirror).  Leaves
 * partly inside a solid keep scale 1, as in the balance.  In an open
 * scene part of a mirror's light leaves it: nothing to hold. */
static rad_result balance_mirrors(hr_state *st)
{
    const hr_tree *t = &st->tree;
    size_t n = t->count;
    if (st->mirrors.links == 0 || rays_escaped(st) > 0)
        return RAD_OK;
    float *x = rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, sizeof *x, "hierarchical: mirror balance");
    double *X = x ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, sizeof *X, "hierarchical: mirror balance") : NULL;
    double *xb = X ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, 6 * t->clusters + 1, sizeof *xb, "hierarchical: mirror balance")
                   : NULL;
    double *target = xb ? rad_alloc(st->ctx, RAD_MEM_HIERARCHY, n, sizeof *target, "hierarchical: mirror balance") : NULL;
    rad_result r = target ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
    for (size_t k = 0; r == RAD_OK && k < n; k++) {
        bool leaf = t->nodes[k].kind == HR_SURFACE && !t->nodes[k].child[0];
        x[k] = leaf ? (float)(hr_mirrors_specular(t, &st->mirrors, (uint32_t)k) * st->gain[k]) : 0.0f;
    }
    if (r == RAD_OK)
        r = link_columns(st, x, X, xb, target, NULL);
    for (size_t k = 0; r == RAD_OK && k < n; k++)
        target[k] = st->open[k] == 1.0f ? target[k] * st->corr[k] : -1.0; /* -1: scale 1 */
    if (r == RAD_OK)
        r = hr_mirrors_balance(st->ctx, t, &st->mirrors, st->send, target);
    rad_free(x);
    rad_free(X);
    rad_free(xb);
    rad_free(target);
    return r;
}

/* The largest reflectance of any channel of any patch, with what a
 * carried mirror reflects specularly, and with textures the nodes' means:
 * the most a bounce can reflect of what arrives. */
static double reflectance_bound(const hr_state *st)
{
    const rad_mesh *base = st->tree.base;
    double most = st->tree.reflectance ? st->tree.rho_max : 0.0;
    for (size_t i = 0; i < base->element_count; i++) {
        const rad_material *m = &st->tree.scene->materials[base->elements[i].material];
        double specular = st->mirrors.count > 0 && m->specular_kind == RAD_SPECULAR_MIRROR
                              ? (m->specular[0] + m->specular[1] + m->specular[2]) / 3.0
                              : 0.0;
        for (int c = 0; c < 3; c++)
            most = fmax(most, m->reflectance[c] + specular);
    }
    return most;
}

/* q of the links (solve.h): rho_max times the largest closure of a leaf
 * (link_closure; its links may deliver more than it sends: 1.2 on a
 * uniform box), at least rho_max.  Fails only for memory. */
static rad_result links_contraction(hr_state *st, double rho_max, double *q)
{
    const hr_tree *t = &st->tree;
    double *acc = rad_alloc(st->ctx, RAD_MEM_HIERARCHY, t->count, sizeof *acc, "hierarchical: closure");
    if (!acc)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = link_closure(st, acc, NULL, NULL, NULL);
    double most = 1.0;
    for (size_t k = 0; r == RAD_OK && k < t->count; k++)
        if (t->nodes[k].kind == HR_SURFACE && t->nodes[k].child[0] == 0)
            most = fmax(most, acc[k]);
    rad_free(acc);
    *q = rho_max * most;
    return r;
}

/* ---- the leaves as a mesh ---- */

typedef struct leaf_builder {
    const hr_state *st;
    rad_mesh_leaf *leaves;
    double *radiosity;
    size_t leaf_count;
    uint32_t *tree;
    size_t tree_count;
} leaf_builder;

static uint32_t encode(leaf_builder *lb, uint32_t k)
{
    const hr_node *n = &lb->st->tree.nodes[k];
    if (n->child[0] == 0) {
        size_t i = lb->leaf_count++;
        rad_mesh_leaf *l = &lb->leaves[i];
        l->patch = n->patch;
        l->corner_count = n->corners;
        memcpy(l->corner, n->corner, sizeof l->corner);
        for (int c = 0; c < 3; c++)
            lb->radiosity[3 * i + (size_t)c] = lb->st->B[3 * (size_t)k + (size_t)c];
        return (uint32_t)i | RAD_TREE_LEAF;
    }
    size_t slot = lb->tree_count++;
    for (uint32_t c = 0; c < 4; c++) {
        uint32_t e = encode(lb, n->child[0] + c);
        lb->tree[4 * slot + c] = e;
    }
    return (uint32_t)slot;
}

static rad_result build_leaf_mesh(hr_state *st, rad_mesh **mesh, double **radiosity, size_t *leaves_out)
{
    const hr_tree *t = &st->tree;
    size_t leaves = 0, internal = 0;
    for (size_t k = t->clusters; k < t->count; k++) {
        if (t->nodes[k].kind != HR_SURFACE)
            continue;
        if (t->nodes[k].child[0])
            internal++;
        else
            leaves++;
    }
    leaf_builder lb = {st, NULL, NULL, 0, NULL, 0};
    lb.leaves = rad_alloc(st->ctx, RAD_MEM_HIERARCHY, leaves, sizeof *lb.leaves, "hierarchical: leaves");
    lb.radiosity = rad_alloc(st->ctx, RAD_MEM_HIERARCHY, 3 * leaves, sizeof *lb.radiosity, "hierarchical: leaves");
    lb.tree = rad_alloc(st->ctx, RAD_MEM_HIERARCHY, 4 * internal + 1, sizeof *lb.tree, "hierarchical: leaves");
    size_t P = t->base->patch_count;
    uint32_t *root = rad_alloc(st->ctx, RAD_MEM_HIERARCHY, P, sizeof *root, "hierarchical: leaves");
    rad_result r = RAD_ERROR_OUT_OF_MEMORY;
    if (lb.leaves && lb.radiosity && lb.tree && root) {
        for (size_t p = 0; p < P; p++)
            root[p] = encode(&lb, t->root_of_patch[p]);
        r = rad_mesh_from_leaves(st->ctx, t->scene, t->base, lb.leaves, lb.leaf_count, lb.tree, lb.tree_count,
                                 root, st->p->crease_angle_degrees, mesh);
    }
    rad_free(lb.leaves);
    rad_free(lb.tree);
    rad_free(root);
    if (r != RAD_OK) {
        rad_free(lb.radiosity);
        return r;
    }
    *radiosity = lb.radiosity;
    *leaves_out = leaves;
    return RAD_OK;
}

/* ---- the driver ---- */

static double bytes_in_use(const hr_state *st)
{
    return (double)st->tree.capacity * sizeof(hr_node) + (double)st->links.capacity * sizeof(hr_link) +
           (double)st->values * (13.0 * sizeof(double) + 3.0 * sizeof(float)) +
           (double)st->tree.clusters * 54.0 * sizeof(double) +
           2.0 * (double)(st->tree.count + 1) * sizeof(size_t) +
           (st->corr ? (double)st->values * (3.0 * sizeof(double) + sizeof(float)) : 0.0) +
           hr_direct_bytes(&st->direct) + hr_mirrors_bytes(&st->mirrors) +
           (double)st->tree.reflectance_capacity * sizeof(double);
}

rad_result rad_hier_run(rad_context *ctx, const rad_hier_params *p, rad_mesh **leaf_mesh, double **radiosity,
                        double **direct, rad_solve_stats *ss, rad_hier_stats *hs)
{
    *leaf_mesh = NULL;
    *radiosity = NULL;
    *direct = NULL;
    memset(hs, 0, sizeof *hs);
    hr_state st = {0};
    st.ctx = ctx;
    st.p = p;
    st.hs = hs;
    st.start = rad_seconds();
    st.quads = true;
    const rad_mesh *base = p->base;
    const rad_scene *scene = p->scene;

    /* Scale: the emitted power, W (channels averaged); epsilon is relative to it. */
    double area = 0.0, power = 0.0;
    for (size_t i = 0; i < base->element_count; i++) {
        const rad_element *e = &base->elements[i];
        const double *E = scene->materials[e->material].emission;
        area += e->area;
        power += e->area * (E[0] + E[1] + E[2]) / 3.0;
    }
    double epsilon_abs = (p->epsilon > 0.0 ? p->epsilon : 1e-4) * power;
    /* Default: 1e-4 of the area, per 100 patches beyond the first 100, so
     * that a building of 10^5 polygons is not held to rooms' worth of area. */
    double patches = (double)base->patch_count;
    double min_area = p->min_area > 0.0 ? p->min_area : 1e-4 * area * fmin(1.0, 100.0 / patches);
    bool clustered = p->clustering > 0 || (p->clustering == 0 && base->patch_count > 64);
    hs->epsilon_abs = epsilon_abs;
    hs->min_area = min_area;

    double t0 = rad_seconds();
    rad_result r = hr_tree_build(ctx, base, scene, clustered, min_area, p->vis ? rad_vis_epsilon(base) : 0.0,
                                 &st.tree);
    if (r != RAD_OK)
        return r;
    hs->clustered = st.tree.clusters > 0;
    hs->classic_oracle = p->classic_oracle;
    hs->clusters = st.tree.clusters;
    st.bins_in = rad_alloc(ctx, RAD_MEM_HIERARCHY, 18 * st.tree.clusters + 1, sizeof(double), "hierarchical: cluster bins");
    st.bins_total = rad_alloc(ctx, RAD_MEM_HIERARCHY, 18 * st.tree.clusters + 1, sizeof(double), "hierarchical: cluster bins");
    st.bins_exit = rad_alloc(ctx, RAD_MEM_HIERARCHY, 18 * st.tree.clusters + 1, sizeof(double), "hierarchical: cluster bins");
    if (!st.bins_in || !st.bins_total || !st.bins_exit) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    if ((r = ensure_values(&st)) != RAD_OK)
        goto done;
    /* B = E, clusters pulled up; emitted power over the roots. */
    for (size_t k = st.tree.clusters; k < st.tree.count; k++) {
        const double *E = node_emission(&st, &st.tree.nodes[k]);
        for (int c = 0; c < 3; c++)
            st.emitted += st.tree.nodes[k].area * E[c];
    }
    {
        /* Luminaires and daylight (direct.c): every node's direct
         * irradiance; its first reflection counts as emission for epsilon
         * and the residual, as E += rho H_d does for the dense solvers. */
        double reflected = 0.0, td = rad_seconds();
        size_t grown = 0;
        r = hr_direct_start(ctx, &st.tree, p->vis, p->light_reach, &st.direct, &reflected);
        st.emitted += reflected;
        epsilon_abs += (p->epsilon > 0.0 ? p->epsilon : 1e-4) * reflected / 3.0;
        hs->epsilon_abs = epsilon_abs;
        if (r == RAD_OK)
            r = hr_direct_update(ctx, &st.tree, &st.direct, epsilon_abs, &grown);
        hs->seconds_direct += rad_seconds() - td;
        if (r == RAD_OK)
            r = ensure_values(&st);
        if (r != RAD_OK)
            goto done;
    }
    memset(st.bins_in, 0, 18 * st.tree.clusters * sizeof(double));
    memset(st.H, 0, 3 * st.tree.count * sizeof(double));
    push_pull(&st);

    hr_refine_params rp = {.vis = p->vis,
                           .seed = p->seed,
                           /* 4 x --shadow-rays (16 by default): a link's rays
                            * stand for all its descendants' */
                           .shadow_rays = p->shadow_rays > 0 ? (4 * p->shadow_rays < 64 ? 4 * p->shadow_rays : 64) : 16,
                           .epsilon = epsilon_abs,
                           .source_weight = p->classic_oracle ? 0.0 : HR_SOURCE_WEIGHT,
                           .tol = rad_ff_plane_tolerance(base),
                           .max_memory = p->max_memory,
                           .threads = rad_context_threads(ctx)};
    hr_refine_stats rs = {0};
    r = hr_links_initial(ctx, &st.tree, &rp, &st.links, &rs);
    if (r == RAD_OK)
        r = hr_mirrors_start(ctx, &st.tree, &rp, &st.mirrors, &rs);
    if (r != RAD_OK)
        goto done;
    hs->initial_links = st.links.count + st.mirrors.links;
    hs->seconds_refine += rad_seconds() - t0;

    rad_solve_bound bound = {0};
    double residual = INFINITY, tol = p->tolerance;
    bool converged = false;
    int rounds_solved = 0, round_sweeps = 0;
    const int max_rounds = 24;
    for (int round = 0; round < max_rounds; round++) {
        rad_progress(ctx, "hierarchical", (uint64_t)round, (uint64_t)max_rounds);
        double t1 = rad_seconds();
        size_t split = 0, grown = 0;
        r = measure_spread(&st);
        if (r == RAD_OK)
            hr_tree_set_power(&st.tree, st.B, st.send);
        if (r == RAD_OK)
            r = hr_refine(ctx, &st.tree, &rp, st.B, st.spread, &st.links, &split, &rs);
        if (r == RAD_OK) { /* against the same B: the nodes it covers (mirror.c) */
            size_t through_mirrors = 0;
            r = hr_mirrors_refine(ctx, &st.tree, &rp, st.B, st.spread, st.values, &st.mirrors, &through_mirrors, &rs);
            split += through_mirrors;
        }
        double td = rad_seconds();
        if (r == RAD_OK) /* the new leaves' direct light (direct.c) */
            r = hr_direct_update(ctx, &st.tree, &st.direct, epsilon_abs, &grown);
        hs->seconds_direct += rad_seconds() - td;
        if (r == RAD_OK)
            r = ensure_values(&st);
        td = rad_seconds();
        if (r == RAD_OK)
            measure_open(&st, p->vis, p->seed);
        hs->seconds_open += rad_seconds() - td;
        if (r == RAD_OK && (split > 0 || grown > 0))
            r = sort_links(&st);
        if (r == RAD_OK && bytes_in_use(&st) > p->max_memory)
            r = rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                         "hierarchical: %zu links and %zu nodes need %.3g GB, over the limit of %.3g GB "
                         "(rad_options.max_memory_bytes); use a larger rad_options.epsilon or rad_options.min_area",
                         st.links.count, st.tree.count, bytes_in_use(&st) / 1e9, p->max_memory / 1e9);
        hs->seconds_refine += rad_seconds() - t1;
        if (r != RAD_OK)
            goto done;
        hs->refine_rounds = round + 1;
        if (round == 0 && split == 0 && st.offset == NULL && (r = sort_links(&st)) != RAD_OK)
            goto done;
        /* Settled once a round splits under 1e-4 of the links (the ones it
         * split are kept; the final solve follows).  Measured on 100 rooms
         * at epsilon 1e-5: rounds 7 to 23 split 2 to 300 of 4.4 M links
         * each and took a quarter of the time; stopping at round 6 moved no
         * surface by more than 0.01%. */
        bool last = split == 0 || (double)split <= 1e-4 * (double)(st.links.count + st.mirrors.links) ||
                    round == max_rounds - 1;
        if (last) {
            hr_mirrors_drop_empty(&st.mirrors);
            /* Links whose rays were all blocked stay while they may be
             * refined (refine.c); the final solve needs only the others. */
            size_t m = 0;
            for (size_t i = 0; i < st.links.count; i++)
                if (st.links.items[i].k > 0.0f)
                    st.links.items[m++] = st.links.items[i];
            if (m < st.links.count) {
                st.links.count = m;
                if ((r = sort_links(&st)) != RAD_OK)
                    goto done;
            }
            r = p->closure_correction ? correct_closure(&st, NULL, &hs->closure_corrected) : balance(&st, hs);
            if (r == RAD_OK)
                r = balance_mirrors(&st);
            if (r != RAD_OK)
                goto done;
        }
        double t2 = rad_seconds();
        tol = last ? p->tolerance : fmax(p->tolerance, 1e-3);
        /* How many sweeps a solve may take (solve.h): each leaf reflects at
         * most rho_max of what it receives, and receives at most the largest
         * closure of what is sent (links_contraction). */
        double rho_max = reflectance_bound(&st);
        st.rho_max = rho_max;
        double q = rho_max;
        if ((r = links_contraction(&st, rho_max, &q)) != RAD_OK)
            goto done;
        bound = rad_solve_bound_make(last ? p->max_iterations : 0, q, 1.0, tol, 1.0);
        ss->iteration_limit = fmax(ss->iteration_limit, bound.limit);
        int sweeps_before = st.sweeps;
        r = solve(&st, tol, bound.limit, &residual, &converged);
        rounds_solved = round + 1;
        round_sweeps = st.sweeps - sweeps_before;
        hs->seconds_solve += rad_seconds() - t2;
        /* A round that cannot reach its tolerance: refining against its B
         * would not help the next one, which needs more. */
        if (r != RAD_OK || last || !converged)
            break;
    }
    rad_progress(ctx, "hierarchical", (uint64_t)max_rounds, (uint64_t)max_rounds);

    hs->nodes = st.tree.count;
    hs->links = st.links.count;
    hs->mirror_links = st.mirrors.links;
    for (size_t i = 0; i < st.links.count; i++) {
        const hr_link *l = &st.links.items[i];
        int kind = (st.tree.nodes[l->r].kind == HR_CLUSTER) * 2 + (st.tree.nodes[l->s].kind == HR_CLUSTER);
        hs->links_by_kind[kind]++;
    }
    hs->refine_passes = rs.passes;
    hs->rays = rs.rays;
    hs->shafts = rs.shafts;
    hs->shafts_clear = rs.shafts_clear;
    hs->bytes = bytes_in_use(&st);
    hs->link_bytes = sizeof(hr_link);
    ss->iterations = st.sweeps;
    ss->residual = residual;
    ss->converged = converged;
    if (r == RAD_OK && !converged) {
        char who[64];
        snprintf(who, sizeof who, "hierarchical (refinement round %d)", rounds_solved);
        rad_solve_warn(ss, who, &bound, round_sweeps, "sweeps", "residual", residual,
                       tol, "");
    }
    ss->rays = rs.rays;
    ss->absorbed = st.absorbed / 3.0;
    {
        /* The leaves as the solution's mesh, also after an interruption
         * (the current iterate is then what the caller writes). */
        rad_result rm;
        double t3 = rad_seconds();
        size_t leaves = 0;
        rm = build_leaf_mesh(&st, leaf_mesh, radiosity, &leaves);
        hs->leaves = leaves;
        hs->seconds_mesh = rad_seconds() - t3;
        if (rm == RAD_OK && r == RAD_OK)
            rm = measure_closure(&st, hs);
        if (rm == RAD_OK)
            rm = hr_direct_leaves(ctx, &st.tree, &st.direct, leaves, direct);
        if (rm != RAD_OK)
            r = rm;
    }
done:
    hr_tree_free(&st.tree);
    rad_free(st.links.items);
    rad_free(st.offset);
    rad_free(st.live);
    rad_free(st.B);
    rad_free(st.H);
    rad_free(st.Ht);
    rad_free(st.Hq);
    rad_free(st.spread);
    rad_free(st.open);
    rad_free(st.send);
    rad_free(st.take);
    rad_free(st.Bsend);
    rad_free(st.corr);
    rad_free(st.gain);
    rad_free(st.escape);
    rad_free(st.bins_in);
    rad_free(st.bins_total);
    rad_free(st.bins_exit);
    rad_free(st.display_B);
    hr_direct_free(&st.direct);
    hr_mirrors_free(&st.mirrors);
    if (!*leaf_mesh) { /* the leaves' light goes with the leaves */
        rad_free(*direct);
        *direct = NULL;
    }
    return r;
}
