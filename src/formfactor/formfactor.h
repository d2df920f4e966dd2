/*
 * formfactor.h -- element-to-element form factors behind one small table.
 *
 *     F_ij = 1/A_i  int_{A_i} int_{A_j} cos(theta_i) cos(theta_j) V / (pi r^2) dA_j dA_i
 *
 * the fraction of the power leaving element i that arrives directly at
 * element j.  A method fills the dense n x n matrix (row i = factors FROM i)
 * and counts its rays; the registry wrapper (formfactor.c) checks memory
 * first and computes the diagnostics every method reports: row sums,
 * reciprocity error and F_ii.
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
} rad_ff_stats;

/* Method flags. */
enum {
    RAD_FF_VARIANCE = 1u << 0 /* compute() also estimates the variance of each F_ij */
};

typedef struct rad_ff_method {
    const char *name;
    const char *description; /* one line: idea, cost, accuracy */
    unsigned flags;
    /* Fill F (n*n floats, zeroed by the caller), and, for methods with
     * RAD_FF_VARIANCE, `variance` (n*n floats, zeroed; else NULL) with the
     * estimated variance of each F_ij.  Parallel (ctx->threads), polling
     * rad_cancelled(ctx) (then RAD_ERROR_INTERRUPTED), reporting progress
     * with rad_progress(ctx, "form factors", ...) from one thread. */
    rad_result (*compute)(rad_context *ctx, const rad_ff_request *req, float *F, float *variance,
                          rad_ff_stats *stats);
} rad_ff_method;

extern const rad_ff_method *const rad_ff_methods[]; /* NULL-terminated */
const rad_ff_method *rad_ff_find(const char *name);

/* Allocate F (and the variance for RAD_FF_VARIANCE methods; *variance_out
 * may be NULL to decline it), checking `max_memory` first; run the method;
 * optionally apply the closure correction; fill the diagnostics. */
rad_result rad_form_factors(rad_context *ctx, const rad_ff_method *method,
                            const rad_ff_request *req, double max_memory, bool close,
                            float **F_out, float **variance_out, rad_ff_stats *stats);

/* Reciprocity-preserving closure correction for closed scenes: find x > 0
 * with sum_j x_i x_j A_i F_ij = A_i (symmetric Sinkhorn scaling of the
 * power-coupling matrix G = A F), then F_ij <- x_i x_j F_ij.  Keeps zeros,
 * positivity and A_i F_ij = A_j F_ji; rows that see nothing stay 0. */
void rad_ff_close(const rad_mesh *mesh, float *F);

/* ---- shared kernels (polygon.c) ---- */

/* Unoccluded point-to-polygon form factor F_{dA -> polygon} (Lambert's
 * contour formula, Baum, Rushmeier & Winget 1989): the polygon is first
 * clipped to the half-space in front of the point's tangent plane.  The
 * polygon's own orientation is honoured: a polygon seen from its back gives
 * 0.  n <= 8 vertices. */
double rad_point_polygon_ff(vec3 point, vec3 normal, const vec3 *poly, size_t n);

#endif /* RAD_FORMFACTOR_H */
