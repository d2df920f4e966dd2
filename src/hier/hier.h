/*
 * hier.h -- hierarchical radiosity (Hanrahan, Salzman & Aupperle, SIGGRAPH
 * 1991; the lecture notes' "Multi-Resolution Approach"), with clusters for
 * scenes of many small polygons (after Smits, Arvo & Greenberg, SIGGRAPH
 * 1994, and Sillion, IEEE TVCG 1995).
 *
 * Instead of an n x n matrix between equal elements, energy moves along
 * LINKS between nodes of a hierarchy, each link at the coarsest level whose
 * estimated transport error is below epsilon:
 *
 *          cluster (box around patches)            o top cluster
 *            /            \                       / \
 *        cluster        patch (root)             o   P1 ---link--- P7.2.0
 *         /   \          quadtree of             |                (a child
 *       P4    P9         surface nodes           P4 --link-- o     of P7)
 *
 * Pipeline of one solve (hier.c):
 *
 *   tree.c    base patches -> root surface nodes; a bounding-volume
 *             hierarchy of clusters over them (or root pairs without);
 *             on-demand quadtree subdivision (quads into 4, triangles
 *             into 4)
 *   refine.c  links: transfer coefficient, visibility (shaft culling, then
 *             shadow rays), the error oracle (F and B F), level-synchronous
 *             refinement passes
 *   hier.c    gather along links, push-pull, Jacobi sweeps; B F refinement
 *             rounds as the radiosity converges; the leaves as a mesh
 *   shaft.c   shaft culling (Haines & Wallace 1994)
 *   direct.c  luminaires' and daylight's direct irradiance per node (the
 *             light module's polygon mean), and leaves split where it
 *             varies
 *
 * Clusters exchange energy through six-direction distributions (one value
 * per signed axis): a cluster's exitance toward direction w is
 * sum_a |w_a| C[a, sign w_a] with C[a, +-] = sum_m A_m B_m max(0, +-n_m.a),
 * and what it receives from direction u is spread as |u_a| into the same
 * bins and read back by a member of normal n as sum_a |n_a| H[a, sign n_a].
 * Both are exact when the members' normals lie along the axes, and exact
 * for any normal whose octant matches the direction's.  How much a link
 * through a cluster carries is a Monte Carlo estimate of the transfer
 * between its ends (refine.c, hr_transfer), so no power is made or lost on
 * the way; the bins only share it among the members.  Links through
 * clusters are kept only where the oracle says their transfer is small.
 */
#ifndef RAD_HIER_H
#define RAD_HIER_H

#include "formfactor/formfactor.h"
#include "light/light.h"
#include "solve/solve.h"

/* ---- nodes (tree.c) ---- */

enum { HR_SURFACE = 0, HR_CLUSTER = 1 };
#define HR_NONE UINT32_MAX

typedef struct hr_node {
    vec3 corner[4];       /* surface: the polygon, counter-clockwise */
    vec3 center;          /* surface: centroid; cluster: box centre */
    vec3 normal;          /* surface: unit normal */
    vec3 lo, hi;          /* bounding box */
    double area;          /* m^2; cluster: its patches' total */
    double radius;        /* bounding sphere about center */
    uint32_t parent;      /* HR_NONE for a top node */
    uint32_t child[2];    /* surface: child[0] = first of 4 consecutive (0 = leaf);
                             cluster: its two children */
    uint32_t patch;       /* surface: base patch; cluster: first entry in order[] */
    uint32_t patch_count; /* cluster: entries in order[] */
    uint8_t kind;         /* HR_SURFACE or HR_CLUSTER */
    uint8_t corners;      /* 3 or 4 */
    uint8_t level;        /* subdivisions below the patch */
    uint8_t pad;
    float rho;            /* surface: its largest reflectance (any channel; the textured mean
                             where textured; a mirror's rho_s added); cluster: the largest
                             below it */
} hr_node;

typedef struct hr_tree {
    const rad_mesh *base;      /* one element per patch */
    const rad_scene *scene;
    hr_node *nodes;
    size_t count, capacity;
    size_t clusters;           /* nodes [0, clusters) are clusters (0 = top), or 0 */
    uint32_t *root_of_patch;   /* patch -> its root surface node */
    uint32_t *order;           /* patches in cluster order */
    double *order_area;        /* prefix sums of patch areas along order[] */
    double *lift;              /* per patch: shadow-ray lift, m (epsilon + bend) */
    double *cluster_bins;      /* 6 per cluster: sum A |n_a| of its patches, by signed axis (their
                                  open parts once measured, hr_tree_set_open) */
    double *order_power;       /* prefix sums of patch power along order[] (hr_tree_set_power) */
    double *power_bins;        /* 6 per cluster: its patches' power A B / open as bins */
    double min_area;           /* m^2: no child smaller than this */
    double *reflectance;       /* 3 per node: a surface node's reflectance, its texture (times Kd)
                                  averaged over it (rad_texture_mean), made with the node; NULL when
                                  the scene has no texture: the materials' (hr_node_reflectance) */
    size_t reflectance_capacity;
    float rho_max;             /* the largest rho of any surface node made */
} hr_tree;

/* Surface node k's reflectance (RGB): its own textured mean, or its
 * patch's material's.  Cannot fail. */
static inline const double *hr_node_reflectance(const hr_tree *tree, uint32_t k)
{
    if (tree->reflectance)
        return &tree->reflectance[3 * (size_t)k];
    return tree->scene->materials[tree->base->patches[tree->nodes[k].patch].material].reflectance;
}

/* Root surface nodes for every base patch, and (clustered) a binary
 * bounding-volume hierarchy over them with median splits along the longest
 * axis.  Deterministic.  Fails only for memory. */
rad_result hr_tree_build(rad_context *ctx, const rad_mesh *base, const rad_scene *scene,
                         bool clustered, double min_area, double eps, hr_tree *tree);
void hr_tree_free(hr_tree *tree);

/* Grow an array of `size`-byte items, capacity *capacity < count, to hold
 * `count` (doubling from 1024), in the hierarchy's memory of ctx: the new
 * array, or NULL when out of memory (the error names `what`; the old array
 * and *capacity then unchanged). */
void *hr_grow(rad_context *ctx, void *items, size_t *capacity, size_t count, size_t size, const char *what);

/* Projected area of node k toward unit direction d: A max(0, n.d) for a
 * surface; a cluster's members' as its area bins see it (exact for
 * axis-aligned members). */
double hr_projected(const hr_tree *tree, uint32_t k, vec3 d);

/* Number of children of node k (0, 2 or 4) and whether it may be split. */
int hr_children(const hr_tree *tree, uint32_t k);
bool hr_splittable(const hr_tree *tree, uint32_t k);
/* Give surface node k its 4 children (no-op if it has them).  Serial only:
 * it may move tree->nodes.  Fails only for memory. */
rad_result hr_subdivide(rad_context *ctx, hr_tree *tree, uint32_t k);
/* The c-th child of node k. */
uint32_t hr_child(const hr_tree *tree, uint32_t k, int c);

/* The power each patch sends, A B / open (B: 3 per node, summed over the
 * channels; open: per node, see hier.c), for sampling source clusters by
 * power and for their exitance bins. */
void hr_tree_set_power(hr_tree *tree, const double *B, const float *send);
/* The clusters' projected-area bins (hr_projected) of their patches' open
 * parts, A open (open: per node, see hier.c, measure_open; NULL: all
 * open, as the tree is built): what a cluster shares among its members is
 * theirs by the area that can receive it. */
void hr_tree_set_open(hr_tree *tree, const float *open);
/* Total power below cluster k (0 for a surface or before set_power). */
double hr_cluster_power(const hr_tree *tree, uint32_t k);

/* `count` (<= HR_SAMPLE_MAX) random points on the surfaces below node k,
 * their normals and ray lifts, from three uniform numbers each (uvw[3 i ..
 * 3 i + 2]: u, v on the patch; w picks the patch of a cluster, by area or
 * by power). */
enum { HR_SAMPLE_MAX = 64 };
void hr_sample(const hr_tree *tree, uint32_t k, int count, const double *uvw, bool by_power, vec3 *point,
               vec3 *normal, double *lift);

/* ---- shaft culling (shaft.c) ---- */

/* The transfer between nodes r and s by Monte Carlo (refine.c): the power r
 * receives from s per unit of the source's radiosity (surface source), or
 * per unit of the source cluster's power weights (*by_power) or area; and
 * the direction it flows along (transfer-weighted, from r toward s); with quad
 * (a surface r), how much of s each quarter of r sees (HR_LINK_QUADS). */
double hr_transfer(const hr_tree *tree, const rad_vis *vis, uint32_t r, uint32_t s, int count, rad_rng *rng,
                   uint64_t *rays, bool *by_power, vec3 *direction, double quad[4]);


/* Is the region between the boxes of nodes a and b free of every patch
 * (other than those of a and b)?  Conservative: false means "maybe not".
 * Walks the cluster hierarchy, or all patches without one. */
bool hr_shaft_clear(const hr_tree *tree, uint32_t a, uint32_t b, double tol);

/* ---- links (refine.c) ---- */

enum {
    HR_LINK_CLEAR = 1, /* the shaft is empty; so are the children's */
    HR_LINK_SPLIT = 2, /* a cluster link the bins cannot carry: must be split */
    HR_LINK_ZNEG = 4,  /* a cluster link's direction has z < 0 (hr_link_direction) */
    HR_LINK_QUADS = 8, /* surface <- surface, partly hidden or its factor uneven over an
                          end: bits 8..31 hold each quarter's share (below) */
    HR_LINK_PARTLY = 16 /* surface <- surface, partly hidden (0 < visibility < 1) */
};

/* Which quarter of surface node a (its children's order, rad_ff_split4)
 * holds a point on it: hr_quarter(&frame, p), frame = hr_quarters_of(a)
 * made once per node (tree.c). */
typedef struct hr_quarters {
    vec3 n, o[3], e[3];
    int corners;
} hr_quarters;
hr_quarters hr_quarters_of(const hr_node *a);
int hr_quarter(const hr_quarters *frame, vec3 p);

/* A partly hidden link's visibility from each quarter of its receiver and
 * to each quarter of its source (the kernel-weighted share of its shadow
 * rays that pass, among those from or to that quarter; 3 bits each), so
 * that the gather gives the light to the receiver's quarters that see the
 * source and takes it from the source's quarters seen, not the ends' area
 * means: a pocket that a node straddles (the ceiling over a hanging
 * luminaire's housing, the housing's top under it) gets and gives its
 * share, not the mean.  The link's power is kept (hier.c, gather).  end:
 * 0 receiver, 1 source. */
static inline uint32_t hr_link_quads_encode(const double receiver[4], const double source[4])
{
    uint32_t bits = HR_LINK_QUADS;
    for (int q = 0; q < 4; q++) {
        bits |= (uint32_t)round(7.0 * fmin(fmax(receiver[q], 0.0), 1.0)) << (8 + 3 * q);
        bits |= (uint32_t)round(7.0 * fmin(fmax(source[q], 0.0), 1.0)) << (20 + 3 * q);
    }
    return bits;
}
static inline double hr_link_quad(uint32_t flags, int end, int q)
{
    return (double)((flags >> (8 + 12 * end + 3 * q)) & 7u) / 7.0;
}

typedef struct hr_link {
    uint32_t r, s;        /* receiver and source nodes */
    float k;              /* transfer coefficient, visibility included (kinds: refine.c) */
    float spread;         /* surface <- surface: how much the unoccluded factor varies
                             over the receiver (max |F(x) - F(centre)|);
                             with a cluster end: x of the direction (below) */
    float vis_err;        /* surface <- surface: unoccluded factor x the visibility's
                             uncertainty, from pilot rays independent of k's;
                             with a cluster end: y of the direction */
    uint32_t flags;
} hr_link;

/* A link with a cluster end carries energy along one direction, from the
 * receiver toward the source: the mean direction of the point pairs that
 * carry its transfer (hr_transfer), kept as x, y and the sign of z. */
static inline vec3 hr_link_direction(const hr_link *l)
{
    double x = l->spread, y = l->vis_err, z = sqrt(fmax(0.0, 1.0 - x * x - y * y));
    return v3(x, y, (l->flags & HR_LINK_ZNEG) ? -z : z);
}

typedef struct hr_links {
    hr_link *items;
    size_t count, capacity;
} hr_links;

/* The weight of the oracle's source term (refine.c).  rho_r F_rs max|B_leaf
 * - B_s| bounds the error of a link that uses the source's mean, but the
 * errors it measures add up with one sign: the parts of a floor under a
 * light are both brighter and better seen from the ceiling than its edges,
 * at every level.  On the Cornell box, weighting it 10x cuts the worst
 * per-surface error from 1.7-2.2% (no term, the classic oracle) to
 * 0.4-0.7% (docs/hierarchical.md). */
#define HR_SOURCE_WEIGHT 10.0

typedef struct hr_refine_params {
    const rad_vis *vis;
    uint64_t seed;
    int shadow_rays;      /* per link whose shaft is not empty */
    double epsilon;       /* power error allowed per link, W */
    double source_weight; /* of the oracle's source term (refine.c); 0: classic */
    double tol;           /* m: rad_ff_plane_tolerance, for plane and shaft tests */
    double max_memory;    /* bytes the link lists may take */
    int threads;
} hr_refine_params;

typedef struct hr_refine_stats {
    uint64_t rays, shafts, shafts_clear, links_created, links_dropped;
    int passes;
} hr_refine_stats;

/* The initial links: one self-link of the top cluster, or every pair of
 * root patches that face each other. */
rad_result hr_links_initial(rad_context *ctx, hr_tree *tree, const hr_refine_params *p,
                            hr_links *links, hr_refine_stats *st);

/* Refine until no link's error (given B, the per-node radiosity, 3 per
 * node, area-averaged; and spread, per node the largest difference between
 * a child's radiosity and its own) exceeds epsilon.
 * Returns the number of links split via *split.  Level-synchronous passes:
 * decide in parallel, subdivide in order, create the children's links in
 * parallel: the result does not depend on the thread count. */
rad_result hr_refine(rad_context *ctx, hr_tree *tree, const hr_refine_params *p, const double *B,
                     const double *spread, hr_links *links, size_t *split, hr_refine_stats *st);

/* What the oracle asks of a link (refine.c): keep it, or split its
 * receiver, its source or both. */
enum { HR_KEEP = 0, HR_SPLIT_R = 1, HR_SPLIT_S = 2, HR_SPLIT_BOTH = 3 };

/* The oracle of a link between surface nodes r <- s (refine.c): bs the
 * source's largest channel of B, k the link's coefficient, link_spread
 * how much its point factor varies over r, vis_err its visibility's
 * uncertainty (both as hr_link's), source_spread the source's
 * max |B_leaf - B_s|, pocket a floor under the receiver's error (the
 * quarters' term, refine.c; 0 for none).  Cannot fail. */
int hr_oracle_surfaces(const hr_tree *tree, const hr_refine_params *p, uint32_t r, uint32_t s, double bs, double k,
                       double link_spread, double vis_err, double source_spread, double pocket);

/* The receiver points of a surface node at which links take their
 * factors: the 2 x 2 Gauss rule on quads (1/sqrt(3) of the way from the
 * centre to the corners) or the 3-point rule exact for quadratics on
 * triangles (half way); returns their count (r->corners). */
int hr_gauss_points(const hr_node *r, vec3 *point);

/* The start of a refinement pass over `links` links (refine.c, mirror.c):
 * RAD_ERROR_INTERRUPTED when cancelled, else the per-link scratch grown
 * (action: 1 byte, first: links + 1 slots).  Fails for memory. */
rad_result hr_refine_pass_start(rad_context *ctx, size_t links, uint8_t **action, size_t **first);

/* Six-direction bins: index of signed axis (a, sign) = 2a + (sign < 0). */
static inline double hr_bins_eval(const double *bins, vec3 d)
{
    return fabs(d.x) * bins[d.x >= 0.0 ? 0 : 1] + fabs(d.y) * bins[d.y >= 0.0 ? 2 : 3] +
           fabs(d.z) * bins[d.z >= 0.0 ? 4 : 5];
}
static inline void hr_bins_add(double *bins, vec3 d, double value)
{
    bins[d.x >= 0.0 ? 0 : 1] += fabs(d.x) * value;
    bins[d.y >= 0.0 ? 2 : 3] += fabs(d.y) * value;
    bins[d.z >= 0.0 ? 4 : 5] += fabs(d.z) * value;
}

/* ---- light through mirrors (mirror.c) ---- */

/* A mirror link r <- s through mirror patch `mirror`: r gathers k B_s,
 * the light that leaves s and reaches r by one reflection in the mirror. */
typedef struct hr_mirror_link {
    uint32_t r, s;        /* receiver and source surface nodes */
    uint32_t mirror;      /* the mirror's patch */
    uint32_t flags;       /* HR_LINK_CLEAR: both legs' shafts are empty, so are the children's */
    float k;              /* rho_s x the mean factor from r to s's image seen through the
                             mirror, visibility included */
    float spread;         /* rho_s x max |F(x) - mean| over r's points; where no point of r
                             sees the image but some part may, a bound on the factor */
    float vis_err;        /* rho_s x the unoccluded factor x the visibility's uncertainty */
} hr_mirror_link;

typedef struct hr_mirrors {
    uint32_t *patches;        /* the mirror patches carried (RAD_SPECULAR_MIRROR) */
    size_t count;             /* 0: nothing here runs */
    hr_mirror_link *items;
    size_t links, capacity;
    double *H;                /* 3 per node, W/m^2: irradiance by way of the mirrors, each
                                 node's own links' and its ancestors' (hr_mirrors_gather) */
    double *sent;             /* 3 per node: what sources send through mirrors, the leaves'
                                 scale x B, area means above */
    size_t H_capacity;        /* doubles, of H and sent each */
    float *scale;             /* per node (leaves): the balance's source scale (hr_mirrors_balance);
                                 NULL until then: 1 */
    size_t scale_count;
} hr_mirrors;

/* Zero *m, find the mirror patches and make the initial links between
 * the roots (every pair of patches that may see each other in a mirror).
 * Fails for memory. */
rad_result hr_mirrors_start(rad_context *ctx, const hr_tree *tree, const hr_refine_params *p, hr_mirrors *m,
                            hr_refine_stats *st);
/* Refine the mirror links against B and spread (as hr_refine: 3 and 1 per
 * node for the nodes [0, known); a later node takes its nearest such
 * ancestor's B and a spread of 0).  *split counts the links split.
 * Level-synchronous passes as hr_refine: the result does not depend on
 * the thread count.  Fails for memory or the memory limit. */
rad_result hr_mirrors_refine(rad_context *ctx, hr_tree *tree, const hr_refine_params *p, const double *B,
                             const double *spread, size_t known, hr_mirrors *m, size_t *split,
                             hr_refine_stats *st);
/* Drop the links that carry nothing (the final solve's). */
void hr_mirrors_drop_empty(hr_mirrors *m);
/* The balance of the mirror links, once they are final: leaf m sends
 * through them scale_m B_m, scale_m such that they deliver target[m] per
 * unit of its B and area (the rho_s part of what the ordinary links bring
 * the mirrors from it; hier.c), so that a mirror reflects exactly the
 * power that reaches it.  Scales outside [0.5, 2], and leaves whose target
 * is negative, are left at 1.  Fails only for memory. */
rad_result hr_mirrors_balance(rad_context *ctx, const hr_tree *tree, hr_mirrors *m, const float *send,
                              const double *target);
/* m->H for every node of the tree from the leaves' B (3 per node; times
 * their balance scale, area means above, scaled by send as the ordinary
 * gather does), pushed down the quadtrees.  Serial, in link order.  No-op
 * without mirrors.  Fails only for memory. */
rad_result hr_mirrors_gather(rad_context *ctx, const hr_tree *tree, hr_mirrors *m, const double *B,
                             const float *send);
/* Surface node k's specular reflectance rho_s (channels' mean) when its
 * patch is a mirror the links carry, else 0: the part of what it receives
 * that it neither absorbs nor reflects diffusely. */
double hr_mirrors_specular(const hr_tree *tree, const hr_mirrors *m, uint32_t k);
double hr_mirrors_bytes(const hr_mirrors *m);
void hr_mirrors_free(hr_mirrors *m);

/* ---- direct light (direct.c) ---- */

/* Luminaires' and daylight's direct irradiance of every surface node (0
 * for clusters), made when the node is: B_leaf = E + rho (H + H_d). */
typedef struct hr_direct {
    const rad_scene *scene;
    const rad_mesh *base;     /* the rays' lift is the base mesh's */
    const rad_vis *vis;
    double *H;                /* 3 per node, W/m^2; NULL when the scene has no light */
    float *deviation;         /* per node: max |H_d(x) - H_d| over the cubature's points, W/m^2 */
    size_t count, capacity;   /* nodes started; allocated */
    size_t done;              /* nodes whose H is final (finished, or split: their children carry it) */
    rad_light_cubature *pending; /* nodes [done, count): where their cubature's first step left */
    size_t pending_capacity;
    uint32_t *list_start, *list; /* per patch (list_start[p] .. [p + 1]): the luminaires whose
                                    reach meets it (light/reach.c); NULL without a reach: all */
    size_t list_capacity;
    const rad_light_reach *reach; /* NULL: every luminaire everywhere */
    uint32_t *node_list;      /* per thread, list_max entries: a node's own list (among) */
    size_t list_max;          /* the longest patch list */
} hr_direct;

/* Zero *d and, when the scene has luminaires or daylight, start every node
 * of the tree (its roots: call before any split; coarse values, finished
 * by hr_direct_update); *reflected = the roots' first reflection sum A rho
 * H_d, W with the channels summed (0 without light).  reach (NULL: every
 * luminaire everywhere) must outlive d.  Fails for memory or cancellation. */
rad_result hr_direct_start(rad_context *ctx, const hr_tree *tree, const rad_vis *vis,
                           const rad_light_reach *reach, hr_direct *d, double *reflected);
/* Start the nodes made since the last call, then split every pending leaf
 * where rho A max|H_d(x) - H_d| exceeds epsilon (W) and min_area allows,
 * and their children alike until none is split, finishing the others;
 * *split counts the leaves split.  Serial splits in node order:
 * deterministic.  No-op without light.  Fails for memory or cancellation. */
rad_result hr_direct_update(rad_context *ctx, hr_tree *tree, hr_direct *d, double epsilon, size_t *split);
/* The leaves' H_d (3 per leaf) in the leaf mesh's order, allocated for the
 * solution (RAD_MEM_SOLVER); *out NULL without light.  Fails for memory. */
rad_result hr_direct_leaves(rad_context *ctx, const hr_tree *tree, const hr_direct *d, size_t leaves,
                            double **out);
double hr_direct_bytes(const hr_direct *d);
void hr_direct_free(hr_direct *d);

/* ---- the solver (hier.c) ---- */

typedef struct rad_hier_params {
    const rad_scene *scene;
    const rad_mesh *base;      /* one element per patch */
    const rad_vis *vis;
    double epsilon;            /* relative: times the emitted power */
    double min_area;           /* m^2 */
    int clustering;            /* 1 on, -1 off, 0 automatic */
    bool classic_oracle;       /* no source term (refine.c) */
    bool closure_correction;   /* leaves send B / closure (closed scenes; hier.c) */
    uint64_t seed;
    int shadow_rays;
    double tolerance;          /* on the residual */
    int max_iterations;        /* Jacobi sweeps in the final solve; 0 = automatic */
    double max_memory;         /* bytes */
    double crease_angle_degrees;
    const rad_light_reach *light_reach; /* where each luminaire's light arrives (light.h); NULL: all */
    rad_solve_monitor_fn monitor; /* steps only (B is NULL) */
    void *monitor_user;
    /* Progressive display (NULL: none, and no cost): called after every
     * sweep, before the monitor, with the current leaves and their B (3 per
     * leaf, in the leaf mesh's order, valid during the call).  `mesh` is a
     * new leaf mesh, handed over (the callback frees it, also when it
     * fails), when the hierarchy has changed since the last call (the first
     * call and after each refinement round), else NULL: the leaves are those
     * of the last mesh handed over.  `leaves` counts them.  A result other
     * than RAD_OK ends the solve with it. */
    rad_result (*display)(void *user, rad_mesh *mesh, const double *radiosity, size_t leaves);
    void *display_user;
} rad_hier_params;

typedef struct rad_hier_stats {
    size_t patches;            /* the roots (set by the caller: strategy/hierarchical.c) */
    size_t nodes, clusters, leaves, links, initial_links;
    size_t mirror_links;       /* links through mirrors at the end (mirror.c) */
    size_t links_by_kind[4];   /* surface<-surface, surface<-cluster, cluster<-surface,
                                  cluster<-cluster (receiver<-source) */
    int refine_rounds, refine_passes;
    uint64_t rays, shafts, shafts_clear;
    double bytes;              /* nodes + links + per-node values at the end */
    double link_bytes;         /* bytes per link */
    double seconds_refine, seconds_solve, seconds_mesh;
    double seconds_direct;     /* of seconds_refine: the luminaires' and daylight's (direct.c) */
    double seconds_open;       /* of seconds_refine: the leaves' open fractions (measure_open) */
    double closure_mean;       /* link closure over leaves (measure_closure): area mean */
    double closure_min, closure_max;
    double closure_power;      /* ... weighted by A B */
    double epsilon_abs;        /* W: epsilon x the emitted power */
    double min_area;           /* m^2 */
    bool clustered;
    bool classic_oracle;
    size_t closure_corrected;  /* leaves whose sending was scaled by 1 / closure */
    int balance_iterations;    /* Sinkhorn steps of the balance (hier.c); 0: not balanced */
    size_t balanced_leaves;    /* leaves it held to sums of 1 (closed patches) */
    double balance_residual;   /* its largest relative row error at the end */
    double balance_scale_min, balance_scale_max; /* range of the leaves' scales */
} rad_hier_stats;

/* Solve; on success *leaf_mesh is the mesh of the leaves (patches as in
 * base, elements = leaves, located through the quadtree) and *radiosity
 * their B (3 per leaf), and with luminaires or daylight *direct their
 * direct irradiance H_d (3 per leaf; NULL without light), B including
 * rho H_d.  stats->iterations etc. go into *solve_stats. */
rad_result rad_hier_run(rad_context *ctx, const rad_hier_params *p, rad_mesh **leaf_mesh,
                        double **radiosity, double **direct, rad_solve_stats *solve_stats,
                        rad_hier_stats *stats);

#endif /* RAD_HIER_H */
