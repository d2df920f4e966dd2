/*
 * formfactor.h -- element-to-element form factors behind one small table.
 *
 *     F_ij = 1/A_i  int_{A_i} int_{A_j} cos(theta_i) cos(theta_j) V / (pi r^2) dA_j dA_i
 *
 * the fraction of the power leaving element i that arrives directly at
 * element j.  A method supplies a kernel for one pair of elements or one
 * row (factors FROM element i); formfactor.c owns the rest: the memory
 * check, the parallel loop that fills the dense n x n matrix, and the
 * diagnostics every method reports (row sums, reciprocity error, F_ii).
 */
#ifndef RAD_FORMFACTOR_H
#define RAD_FORMFACTOR_H

#include "vis/vis.h"

typedef struct rad_ff_request {
    const rad_mesh *mesh;
    const rad_vis *vis;       /* NULL: treat everything as mutually visible */
    uint64_t seed;
    int shadow_rays;          /* rays per pair for the visibility fraction; 0 = 4 */
    int hemicube_resolution;  /* pixels along a full hemicube face; 0 = 256 */
    int samples;              /* hemisphere: rays per element; montecarlo: point pairs
                                 per element pair; 0 = the method's default */
    double near_field;        /* hybrid: exact method below this many element sizes; 0 = 3 */
    /* With the closure correction: per element the fraction of its rays that
     * escape (rad_ff_escape_rays), to refuse an open scene once F shows what
     * sees something; NULL: not checked.  `source` names the scene. */
    const double *escape;
    const char *source;
    bool raw;                 /* keep a sampled method's F as estimated: no reciprocity and
                                 closure step (rad_ff_balance) */
} rad_ff_request;

typedef struct rad_ff_stats {
    const char *method;
    double seconds;
    uint64_t rays;            /* shadow / visibility rays cast */
    uint64_t pairs;           /* element pairs evaluated (not culled) */
    double row_sum_min, row_sum_max, row_sum_mean;
    double reciprocity_max;   /* max |A_i F_ij - A_j F_ji| / max(A_i F_ij, A_j F_ji) */
    double diagonal_max;      /* max F_ii */
    double std_error_max;     /* methods with RAD_FF_VARIANCE: largest standard error of an F_ij */
    uint64_t near_pairs;      /* hybrid: pairs given to the exact method */
    bool closure_corrected;   /* the symmetric closure correction was applied */
    double escaped;           /* with the closure correction: the light escaping the scene
                                 (rad_ff_escaped), else 0 */
    bool balanced;            /* rad_ff_balance restored reciprocity and closure */
    double raw_reciprocity_max, raw_row_sum_max; /* balanced: as the method estimated F */
    double closure_scale_min, closure_scale_max; /* balanced: range of balanced over raw row sums */
} rad_ff_stats;

/* Method flags. */
enum {
    RAD_FF_VARIANCE = 1u << 0, /* the kernel also estimates the variance of each F_ij */
    RAD_FF_BALANCE = 1u << 1   /* sampled: rad_ff_balance runs after it unless req->raw */
};

/* What the kernels count while they run: per thread, summed by the loop. */
typedef struct rad_ff_tally {
    uint64_t rays;            /* shadow / visibility rays cast */
    uint64_t pairs;           /* row methods: element pairs evaluated (the pair loop counts its own) */
    uint64_t near_pairs;      /* hybrid: pairs given to the exact method */
} rad_ff_tally;

/* One unordered pair's factors as a pair kernel returns them.  Both
 * directions: each method has its own exact form of A_i F_ij = A_j F_ji. */
typedef struct rad_ff_pair {
    double F_ij, F_ji;
    double var_ij, var_ji;    /* RAD_FF_VARIANCE methods: their estimated variances */
} rad_ff_pair;

/* A method is physics only: formfactor.c owns the loop over element rows
 * (OpenMP, dynamic schedule, cancellation, progress, counting) and calls
 * one of two kernels.  Pair methods see each unordered pair i < j once,
 * after the loop has culled the pairs that do not face each other
 * (rad_ff_facing); the loop writes F_ij and F_ji.  Row methods (a hemicube
 * or rays shot from element i) fill row i themselves.  Kernels cannot fail,
 * allocate nothing and take their random numbers from keys of (seed,
 * elements), so F does not depend on the thread count. */
typedef struct rad_ff_method {
    const char *name;
    const char *description; /* one line: idea, cost, accuracy */
    unsigned flags;
    /* Optional.  Check the request and build what every kernel call
     * reads (settings, per-element tables) as one block of the context's
     * (rad_alloc) in *shared, which the caller frees; fail through
     * rad_fail. */
    rad_result (*prepare)(rad_context *ctx, const rad_ff_request *req, void **shared);
    /* Optional.  The bytes of one thread's scratch memory; with `block`
     * (that many bytes, zeroed, 16-byte aligned) also lay it out there
     * (pointers into it).  The loop allocates every thread's block before
     * its parallel region and hands `block` to the kernels.  Cannot fail. */
    size_t (*scratch)(const rad_ff_request *req, const void *shared, void *block);
    /* Exactly one of these.  pair: the factors of elements i < j into
     * *out (zeroed by the caller).  row: row i of F into F_row (n doubles,
     * zeroed) and, when variance_row is not NULL, of the variances. */
    void (*pair)(const rad_ff_request *req, const void *shared, void *scratch, uint32_t i,
                 uint32_t j, rad_ff_pair *out, rad_ff_tally *tally);
    void (*row)(const rad_ff_request *req, const void *shared, void *scratch, uint32_t i,
                double *F_row, double *variance_row, rad_ff_tally *tally);
    /* Optional, row methods with RAD_FF_BALANCE: the samples per m^2 behind
     * row i (after the loop, before `shared` is freed): how much element i's
     * estimate of a pair weighs against the other's.  Its rows sum to the
     * closure it measured.  NULL: reciprocal by construction. */
    double (*density)(const rad_ff_request *req, const void *shared, uint32_t i);
} rad_ff_method;

extern const rad_ff_method *const rad_ff_methods[]; /* NULL-terminated */
const rad_ff_method *rad_ff_find(const char *name);

/* Allocate F (and the variance for RAD_FF_VARIANCE methods; *variance_out
 * may be NULL to decline it), checking `max_memory` first; run the method
 * over all rows in parallel (ctx->threads), polling rad_cancelled(ctx)
 * (then RAD_ERROR_INTERRUPTED, with the rows done so far) and reporting
 * progress with rad_progress(ctx, "form factors", ...); optionally apply
 * the closure correction; fill the diagnostics. */
rad_result rad_form_factors(rad_context *ctx, const rad_ff_method *method,
                            const rad_ff_request *req, double max_memory, bool close,
                            double **F_out, double **variance_out, rad_ff_stats *stats);

/* The default step after a RAD_FF_BALANCE method (reciprocity.c): the two
 * estimates of each pair combined by method->density (row methods), then
 * rows brought to their closure (measured by the row methods and rescaled
 * symmetrically; for pair methods, with req->vis and var, measured by
 * cosine rays and adjusted by least squares with the variances) and none
 * left above 1.  F (and var, if not NULL) n x n, changed in place; fills
 * the stats' balance fields.  Polls rad_cancelled (RAD_ERROR_INTERRUPTED);
 * fails otherwise only for memory (F then unchanged). */
rad_result rad_ff_balance(rad_context *ctx, const rad_ff_method *method, const rad_ff_request *req,
                          const void *shared, double *F, double *var, rad_ff_stats *stats);

/* ---- the plane tolerance and the facing test (formfactor.c): every
 * method, and the hierarchical links ---- */

/* Plane distances within this fraction of the scene's size count as 0:
 * far above the rounding that leaves coplanar elements, or an edge shared
 * with a plane, a few 1e-16 off it, far below any gap the mesh resolves
 * (the shadow-ray offset is 1e-5 of the scene). */
#define RAD_FF_PLANE_TOLERANCE 1e-9

/* RAD_FF_PLANE_TOLERANCE x the extent of the mesh's vertices, m.  Cannot
 * fail. */
double rad_ff_plane_tolerance(const rad_mesh *mesh);

/* True when one of the points lies in front of the plane through `origin`
 * with unit `normal` by more than `tol`: what lies wholly on or behind a
 * surface's plane exchanges no light with it.  Cannot fail. */
bool rad_ff_in_front(const vec3 *point, size_t count, vec3 origin, vec3 normal, double tol);

/* Elements i and j face each other: each reaches in front of the other's
 * plane (through its centroid) by more than plane_tol (rad_ff_in_front);
 * else their factors vanish.  Cannot fail. */
bool rad_ff_facing(const rad_mesh *mesh, uint32_t i, uint32_t j, double plane_tol);

/* Reciprocity-preserving closure correction for closed scenes: find x > 0
 * with sum_j x_i x_j A_i F_ij = A_i (symmetric Sinkhorn scaling of the
 * power-coupling matrix G = A F), then F_ij <- x_i x_j F_ij.  Keeps zeros,
 * positivity and A_i F_ij = A_j F_ji; rows that see nothing stay 0.
 * Fails only for memory (2n doubles), F then unchanged. */
rad_result rad_ff_close(rad_context *ctx, const rad_mesh *mesh, double *F);

/* Is the scene closed?  Per element, the fraction of the light leaving it
 * that escapes the scene, into fraction[n]: cosine-distributed rays from
 * stratified points of the element, counted when they meet nothing.  A ray
 * that meets the back of a surface has not escaped (it starts inside a
 * solid, or went through a crack into one).  Unlike the row sums of F this
 * does not depend on the form-factor method, and elements partly buried in
 * a solid resting on them (a block on a floor: row sums of 0 to 1) do not
 * read as open.  2^18 rays in all (16 to 4096 per element), keyed on
 * (seed, element): thread-count independent.  Polls rad_cancelled (then
 * RAD_ERROR_INTERRUPTED); fails otherwise only for memory. */
rad_result rad_ff_escape_rays(rad_context *ctx, const rad_mesh *mesh, const rad_vis *vis, uint64_t seed,
                              double *fraction);

/* The light escaping a scene of uniform radiosity: the area-weighted mean
 * of fraction[] over the elements that see something, those with a row of
 * F above 0 (F given), else those with a ray that met something.  For an
 * opening of area A_o in a closed box of surface area A it is A_o / A, by
 * reciprocity (sum_i A_i F_io = A_o).  What sees nothing is left out: the
 * closure correction leaves its row at 0, and it is mostly faces pressed
 * against others (a box's bottom on a floor, whose rays start below the
 * floor and escape).  0 when nothing sees anything.  Cannot fail. */
double rad_ff_escaped(const rad_mesh *mesh, const double *fraction, const double *F);

/* The refusal of the closure correction on an open scene (`escaped` of the
 * light escapes), naming the scene `source`: RAD_ERROR_INVALID_ARGUMENT. */
rad_result rad_ff_refuse_open(rad_context *ctx, const char *source, double escaped);

/* Openings through which more than this fraction of the light escapes make
 * a scene open: the closure correction, which would put that light back on
 * the surfaces, is refused there.  Below it, the escape is taken as the
 * cracks of a closed model (a box of six quads with a 3 mm gap around its
 * floor: 0.2%; the generated offices: 0, 0.4-0.6% before the faces pressed
 * against others were left out); above it, as an opening the
 * physics must keep (one side of a box missing: 1/5 of the other five's
 * area, 20%; a hole of 3% of a box's area: 3%). */
#define RAD_FF_OPEN_SCENE_ESCAPE 0.01

/* ---- shared kernels (polygon.c) ---- */

/* Sutherland-Hodgman: the part of polygon poly[0, n) where
 * normal . (y - x) >= 0, into out; returns its corner count.  A convex
 * polygon gains at most one vertex, but corners within rounding of the
 * plane can alternate sides (a piece of a source clipped by several
 * blockers, occluders.c), each edge then giving two: `out` holds up to
 * 2 n vertices.  Cannot fail. */
size_t rad_polygon_clip(const vec3 *poly, size_t n, vec3 x, vec3 normal, vec3 *out);

/* Unoccluded point-to-polygon form factor F_{dA -> polygon} (Lambert's
 * contour formula, Baum, Rushmeier & Winget 1989): the polygon is first
 * clipped to the half-space in front of the point's tangent plane.  The
 * polygon's own orientation is honoured: a polygon seen from its back gives
 * 0.  n <= 8 vertices. */
double rad_point_polygon_ff(vec3 point, vec3 normal, const vec3 *poly, size_t n);
/* The same for a point known to lie in front of the polygon (no test of
 * the polygon's own orientation, so collinear leading corners are fine).
 * Cannot fail. */
double rad_point_polygon_ff_front(vec3 point, vec3 normal, const vec3 *poly, size_t n);

/* How far a point sampled on element e (bilinear, rad_element_sample) can
 * lie from the flat pieces a ray backend builds over it, m: 0 for triangles
 * and flat quads; for a bent quad, its corners' spread about its plane.
 * Ray end points on e are lifted by rad_vis_epsilon plus this, so that a
 * ray never starts behind the surface it leaves.  Cannot fail. */
double rad_element_bend(const rad_mesh *mesh, const rad_element *e);

/* Shadow rays for the part of element e that a point p (normal n) does
 * not see: k x k stratified points y of e (jittered by rng, lifted by
 * `lift` along e's normal), each a ray from `origin` to y and a weight, the
 * point-to-point kernel cos cos / (pi r^2) x A_e x sample weight / k^2,
 * so that the weights of the blocked rays estimate the hidden part of
 * F(p -> e).  Points the kernel gives nothing are skipped.  Returns the
 * rays made (at most k^2).  Cannot fail. */
int rad_element_kernel_rays(const rad_mesh *mesh, const rad_element *e, vec3 p, vec3 n, vec3 origin, double lift,
                            int k, rad_rng *rng, rad_ray *ray, double *weight);
/* The visible part of F(p -> e) from those rays once traced: F times the
 * kernel-weighted share of the clear ones,
 *
 *     F V = F sum_clear w_k / sum_all w_k,
 *
 * exact where the element is wholly seen or wholly hidden (an element
 * behind a wall gives nothing, whatever its samples; the control variate
 * F - sum_blocked w_k, clamped to [0, F], let F - w through when one far
 * ray was blocked: +0.6 to +1.1% on the office's grid means, bench_gather),
 * and consistent between.  F where no ray was made. */
double rad_element_seen(double F, const double *weight, const uint8_t *blocked, int count);

/* An orthonormal tangent pair (u, v) with u x v = n (unit): the frame of
 * the hemicube's faces and of the hemisphere's directions.  Cannot fail. */
void rad_tangent_frame(vec3 n, vec3 *u, vec3 *v);

/* Rays first .. first + count - 1 of a bundle leaving element e by the
 * cosine law (Malley): ray k's direction in cell k mod side^2 of a side x
 * side stratification of the unit disk, lifted to the hemisphere about
 * e's normal; its origin uniform on e (rad_element_sample), independent of
 * the direction, lifted by `lift` (m) along the normal; tnear 0, tfar
 * infinite.  Four draws from rng per ray.  Cannot fail. */
void rad_element_cosine_rays(const rad_mesh *mesh, const rad_element *e, double lift, int side, int first,
                             int count, rad_rng *rng, rad_ray *ray);

/* The order x order Gauss-Legendre product rule over element e (order 1
 * to 4): points into point[], weights (m^2, the rule's weight times the
 * Jacobian of the bilinear map, or of the square collapsed onto a
 * triangle) into weight[], summing to the element's area for flat quads
 * and triangles.  Returns order^2.  Cannot fail. */
int rad_element_gauss(const rad_mesh *mesh, const rad_element *e, int order, vec3 *point, double *weight);

/* The four children of a quad (bilinear midpoints) or a triangle (midpoint
 * subdivision, the middle child last), same orientation as the parent:
 * the adaptive quadratures' refinement step (analytic, hemicube).  A
 * triangle's children use corners 0-2 of each sub[k].  Cannot fail. */
void rad_ff_split4(const vec3 *region, uint32_t corners, vec3 sub[4][4]);

/* ---- extended form factors through ideal mirrors (ff_mirror.c) ---- */

typedef struct rad_ff_mirror_stats {
    size_t mirror_patches;    /* patches of mirror materials */
    uint64_t pairs;           /* (receiver, source) pairs tried per mirror patch, summed */
    uint64_t rays;            /* visibility rays through the mirrors */
    double seconds;
} rad_ff_mirror_stats;

/* True when some patch's material (materials[], the scene's) is an ideal
 * mirror.  Cannot fail. */
bool rad_mesh_has_mirror(const rad_mesh *mesh, const rad_material *materials);

/* F_ext = F + for each mirror patch, rho_s (its channels' mean) x the
 * factor from each element to each other's mirror image, visibility
 * through the mirror included (the file's header): a new n x n matrix into
 * *F_ext_out (the caller's, rad_free).  Deterministic, parallel on the
 * context's threads; polls rad_cancelled (RAD_ERROR_INTERRUPTED); fails
 * otherwise only for memory.  *F_ext_out is NULL on failure. */
rad_result rad_ff_mirror_images(rad_context *ctx, const rad_mesh *mesh, const rad_vis *vis,
                                const rad_material *materials, const double *F, double **F_ext_out,
                                rad_ff_mirror_stats *stats);

/* ---- the hemicube's delta form factors (ff_hemicube.c) ---- */

/* Fill delta[] with the form factor of each pixel of a unit hemicube with
 * `resolution` pixels along a full face (even, >= 2), seen from its centre:
 * the top face (resolution^2 pixels, row-major) and then the four side
 * faces (resolution/2 rows from the base up, resolution columns each), so
 * 3 * resolution^2 values.  Each is dF = dA / (pi (x^2+y^2+1)^2) (top) or
 * z dA / (pi (y^2+z^2+1)^2) (sides) integrated exactly over the pixel.
 * Returns their sum, 1 up to rounding.  Cannot fail. */
double rad_hemicube_deltas(int resolution, double *delta);

/* ---- shadow-ray visibility (visibility.c): analytic, contour, hybrid ---- */

enum {
    RAD_FF_MAX_RAYS = 256,     /* rays in one rad_ff_rays batch */
    RAD_FF_MAX_BASE_RAYS = 48  /* first-round rays per pair: 4x more follow, within one batch */
};

/* One end of a bundle of shadow rays: an element, or a piece of one. */
typedef struct rad_ff_end {
    vec3 corner[4];           /* m, counter-clockwise; corner[3] unused for triangles */
    uint32_t corners;         /* 3 or 4 */
    vec3 normal;              /* unit */
    double lift;              /* m: end points move this far along the normal and inward */
} rad_ff_end;

/* Element e as a ray end, lifted by eps (rad_vis_epsilon) plus its bend.
 * Cannot fail. */
void rad_ff_end_element(const rad_mesh *mesh, uint32_t e, double eps, rad_ff_end *end);

/* Draw `count` (<= RAD_FF_MAX_RAYS) stratified pairs of random points of a
 * and b (bilinear on quads, as rad_element_sample) from `rng`, and cast the
 * rays of the pairs that face each other (each end in front of the other's
 * plane); *facing = how many were cast (also added to *rays_cast).
 * Returns how many pass.  Cannot fail. */
/* The rays of rad_ff_rays without casting them: fills rays[] (room for
 * RAD_FF_MAX_RAYS) with the facing pairs, ray k from a's point to b's
 * (tnear 0, tfar 1), and returns how many.  Cannot fail. */
int rad_ff_pairs(const rad_ff_end *a, const rad_ff_end *b, int count, rad_rng *rng, rad_ray *rays);

int rad_ff_rays(const rad_vis *vis, const rad_ff_end *a, const rad_ff_end *b, int count,
                rad_rng *rng, uint64_t *rays_cast, int *facing);

/* Visibility fraction of elements i and j: base_rays (<= RAD_FF_MAX_BASE_RAYS)
 * rays keyed on (req->seed, i, j); if they disagree (or none faces), 4 x
 * base_rays more and the fraction of all cast.  1 when req->vis is NULL or
 * no ray faces.  Cannot fail. */
double rad_ff_visibility(const rad_ff_request *req, uint32_t i, uint32_t j, double eps,
                         int base_rays, uint64_t *rays_cast);

/* ---- which pairs need shadow rays (occluders.c) ---- */

/* Distinct planes of the ray primitives that the classification handles:
 * a scene with more (a tessellated curved surface) is not classified. */
#define RAD_FF_OCCLUDER_PLANES 1024

typedef enum rad_ff_verdict {
    RAD_FF_CLEAR,   /* no primitive can meet a segment between the pair: V = 1 */
    RAD_FF_BLOCKED, /* one primitive meets every segment: V = 0 */
    RAD_FF_PARTIAL  /* neither shown: shadow rays */
} rad_ff_verdict;

typedef struct rad_ff_occluders rad_ff_occluders;

enum { RAD_FF_MAX_BLOCKERS = 8 };

/* The primitives that may block part of a partial pair, as flat convex
 * polygons (counter-clockwise about their normals). */
typedef struct rad_ff_blockers {
    vec3 corner[RAD_FF_MAX_BLOCKERS][8]; /* m (4 as listed; up to 6 once trimmed) */
    uint32_t corners[RAD_FF_MAX_BLOCKERS];
    double top[RAD_FF_MAX_BLOCKERS]; /* trimmed: highest corner above the source's plane, m */
    int count;
    bool complete;        /* false: more may block than are listed (use rays) */
    bool trimmed;         /* rad_ff_blockers_trim ran */
} rad_ff_blockers;

/* Cut each blocker to its part strictly in front of the source's plane
 * (through src0, unit src_normal) and in front of the receiver's plane
 * (through recv0, unit recv_normal), once per pair, so that
 * rad_point_polygon_ff_visible, for points of that receiver, need not.
 * Cannot fail. */
void rad_ff_blockers_trim(rad_ff_blockers *b, vec3 src0, vec3 src_normal, vec3 recv0, vec3 recv_normal);

/* Allocate one block (rad_alloc, the caller frees it with rad_free) of
 * `header` bytes for the caller, zeroed, followed by the occluder tables of
 * the mesh's ray primitives (rad_vis_primitives): *occ points into it, or
 * is NULL when the scene is not classified (over RAD_FF_OCCLUDER_PLANES
 * planes, or a primitive not flat to the plane tolerance; the block is
 * then just the header).  Fails only for memory (*block NULL). */
rad_result rad_ff_occluders_build(rad_context *ctx, const rad_mesh *mesh, size_t header, void **block,
                                  const rad_ff_occluders **occ);

/* Elements i and j: clear, blocked or partial (occluders.c's header says
 * how).  Exact where it answers clear or blocked, up to sets of segments of
 * measure zero.  With `blockers` (may be NULL), a partial pair's list of
 * the primitives that may block it.  Thread-safe; cannot fail. */
rad_ff_verdict rad_ff_occluders_classify(const rad_ff_occluders *occ, uint32_t i, uint32_t j,
                                         rad_ff_blockers *blockers);

/* The unoccluded factor of rad_point_polygon_ff from the point to the part
 * of the source polygon (n <= 4 corners, unit normal src_normal) that no
 * listed blocker hides from it: the blockers' parts between the point and
 * the source's plane projected from the point onto that plane and cut out
 * of the source (convex pieces, then Lambert's formula on each; trimmed
 * blockers must have been trimmed for this point's receiver).  Exact
 * for any number of flat convex blockers.  Returns -1 when the pieces
 * outgrow the fixed room (more than 32 pieces or 8 corners): the caller
 * falls back to rays.  Cannot fail otherwise. */
double rad_point_polygon_ff_visible(vec3 point, vec3 normal, const vec3 *src, size_t n, vec3 src_normal,
                                    const rad_ff_blockers *blockers);

/* ---- the contour kernel (ff_contour.c): contour, hybrid ---- */

/* The unoccluded power coupling A_i F_ij = A_j F_ji (m^2) of two planar
 * convex polygons (3 or 4 vertices, counter-clockwise about their unit
 * normals), each first clipped to the front of the other's plane, by the
 * double contour integral.  Plane distances within plane_tol count as 0.
 * Cannot fail; 0 for polygons that do not face each other. */
double rad_polygon_coupling(const vec3 *poly_i, size_t n_i, vec3 normal_i, const vec3 *poly_j,
                            size_t n_j, vec3 normal_j, double plane_tol);
/* As rad_polygon_coupling, with the outer quadrature's pieces no shorter
 * than rel x their edge (rad_polygon_coupling: 1e-7): near a shared
 * vertex, where the integrand is singular, the last piece's error is about
 * rel ln(1/rel) of the edge's share.  Cannot fail. */
double rad_polygon_coupling_to(const vec3 *poly_i, size_t n_i, vec3 normal_i, const vec3 *poly_j,
                               size_t n_j, vec3 normal_j, double plane_tol, double rel);

/* rad_polygon_coupling of elements i and j of the mesh.  Cannot fail. */
double rad_element_coupling(const rad_mesh *mesh, uint32_t i, uint32_t j, double plane_tol);

/* Enclosure smoothing (smooth.c): rad_view_factors_smooth's work.  The
 * rows are brought to 1 (`enclosure`) or to their own sums held to [0, 1],
 * taken before the pairs whose two factors are both below
 * sparse_threshold (0: none) are dropped; *dropped (may be NULL) = the
 * largest row's mass dropped.  On failure F is unchanged but for the
 * dropped pairs. */
rad_result rad_ff_smooth(rad_context *ctx, size_t n, const double *area, double *F, bool enclosure,
                         double sparse_threshold, double *dropped, rad_smooth_report *report);

/* ---- rows in blocks, without the n x n matrix (rows.c) ---- */

/* What one block of rows cost and what its pairs say. */
typedef struct rad_ff_block_stats {
    uint64_t rays;            /* shadow / visibility rays cast */
    uint64_t pairs;           /* pairs (i < j) evaluated for the first time: summed over the
                                 blocks, the dense loop's count */
    uint64_t pairs_again;     /* pair methods: pairs (j < r0 <= i) evaluated again for the
                                 lower triangle, which an earlier block evaluated too */
    uint64_t near_pairs;      /* hybrid: pairs given to the exact method */
    double reciprocity_max;   /* as rad_ff_stats, over the pairs this block evaluated (pair
                                 methods: all its pairs i < j; row methods: both ends in it) */
} rad_ff_block_stats;

typedef struct rad_ff_rows rad_ff_rows;

/* Can `method` stream under `req` (close: the closure correction asked)?
 * A sampled method's balance step (unless req->raw) and the closure
 * correction rescale every row by all the others: both need the whole
 * matrix, so both are refused (RAD_ERROR_INVALID_ARGUMENT, naming the
 * way out, the message ending with `why`).  Cannot fail otherwise. */
rad_result rad_ff_rows_check(rad_context *ctx, const rad_ff_method *method, const rad_ff_request *req,
                             bool close, const char *why);

/* Prepare `method` for blocks of rows (its shared tables, every thread's
 * scratch).  req must outlive *out.  Fails for memory (*out NULL). */
rad_result rad_ff_rows_create(rad_context *ctx, const rad_ff_method *method, const rad_ff_request *req,
                              rad_ff_rows **out);
void rad_ff_rows_destroy(rad_ff_rows *rows);

/* Rows [r0, r1) of F into block ((r1 - r0) x n doubles, row-major; zeroed
 * here), bit for bit the rows rad_form_factors makes without the balance
 * and closure steps: a pair method's kernel is always called as (i < j),
 * with that pair's own random numbers, so a pair seen from two blocks
 * gives the same factors and A_i F_ij = A_j F_ji holds across blocks as
 * in the dense matrix.  Pairs with both rows in the block are evaluated
 * once; a pair (j < r0, i) is evaluated again (its row j went out with
 * an earlier block): over many blocks about twice the dense loop's pair
 * evaluations.  Rows in parallel (ctx->threads); polls rad_cancelled
 * (RAD_ERROR_INTERRUPTED, the block incomplete); reports progress as
 * `done` + rows finished of `total`.  Cannot fail otherwise. */
rad_result rad_ff_rows_block(rad_context *ctx, rad_ff_rows *rows, size_t r0, size_t r1, double *block,
                             uint64_t done, uint64_t total, rad_ff_block_stats *stats);

#endif /* RAD_FORMFACTOR_H */
