/*
 * solve.h -- solvers of the radiosity system (I - P F) B = E behind one
 * small table (Cohen & Wallace 1993, ch. 5).  All work on RGB at once and
 * share the residual measure of the lecture notes:
 *
 *     r_i = B_i - E_i - rho_i sum_j F_ij B_j
 *     residual = sum_c sum_i A_i |r_ic|  /  sum_c sum_i A_i E_ic
 *
 * i.e. the power not yet accounted for, as a fraction of the emitted power.
 */
#ifndef RAD_SOLVE_H
#define RAD_SOLVE_H

#include "core/core.h"

struct rad_mesh;
struct rad_vis;

typedef struct rad_system {
    size_t n;
    const double *F;          /* n x n, row i = factors from i */
    const double *area;       /* n, m^2 */
    const double *reflectance;/* 3n, interleaved RGB */
    const double *emission;   /* 3n, W/m^2 */
    int threads;              /* for the O(n^2) passes that run in parallel */
    /* Matrix-free solvers (F == NULL) compute what they need on the fly: */
    const struct rad_mesh *mesh;
    const struct rad_vis *vis;
    uint64_t seed;
    int samples;              /* rays per shot; 0 = the solver's default */
    bool control_variate;     /* shooting: solve for B - beta (solve/control_variate.h) */
    double max_memory;        /* bytes a solver may allocate; 0 = the context's limit */
} rad_system;

/* Called after each iteration; a nonzero return stops the solve
 * (RAD_ERROR_INTERRUPTED).  `B` is the current iterate (3n); `ambient` is the
 * shooting ambient term (RGB, W/m^2) or NULL. */
typedef int (*rad_solve_monitor_fn)(void *user, const rad_solve_step *step, const double *B,
                                    const double *ambient);

typedef struct rad_solve_params {
    double tolerance;         /* on the residual */
    double unshot_tolerance;  /* on unshot / emitted power (shooting); 0 = unused */
    int max_iterations;       /* 0 = the solver's default */
    double relaxation;        /* omega; 1 = none */
    rad_solve_monitor_fn monitor; /* may be NULL */
    void *monitor_user;
} rad_solve_params;

typedef struct rad_solve_stats {
    const char *method;
    int iterations;           /* sweeps (gathering) or shots (shooting) */
    double residual;
    double seconds;
    bool converged;
    double ambient[3];        /* shooting: estimate of unshot light for display, W/m^2 */
    double unshot;            /* shooting: unshot power / emitted power at the end; else NAN */
    double absorbed;          /* matrix-free: power absorbed, W (mean over RGB); else NAN */
    uint64_t rays;            /* matrix-free: rays cast while solving */
    size_t components;        /* independent groups of elements solved separately (0 = not split) */
    size_t components_lit;    /* of those, the groups of two or more elements holding an emitter */
    double iteration_limit;   /* the most iterations it could take (rad_solve_bound) */
    /* instant radiosity (strategy/instant.c; vpl_lights 0 for the others): */
    size_t vpl_paths;         /* light paths traced */
    size_t vpl_lights;        /* VPLs placed */
    double vpl_clamp_radius;  /* m */
    double vpl_clamp_loss;    /* the VPL irradiance the clamp removed, as a fraction of it (area-weighted;
                                 the near-field estimate, instant.c) */
    double vpl_clamp_loss_unclamped; /* the same from the unclamped gather (unbiased, heavy-tailed) */
    bool vpl_compensated;     /* the loss was added back (solver instant-radiosity) */
    /* the control variate B = beta + B' (solve/control_variate.h; shooting and instant radiosity): */
    size_t cv_groups;         /* groups of elements it chose beta for; 0 where it was not used */
    size_t cv_groups_varied;  /* of those, the groups with beta != 0 */
    double cv_beta[3];        /* W/m^2, RGB: beta's area-weighted mean over the scene */
    uint64_t cv_rays;         /* rays it cast (counted in `rays` too) */
    char warning[320];        /* why it stopped short of its tolerance, one line; "" when
                                 it converged or was interrupted */
} rad_solve_stats;

/* What a linear solver reads of F (rad_solver.flags). */
enum {
    /* F_ji read as F_ij A_i / A_j (reciprocity) where a shot needs the
     * column: wrong for a coupling that is not reciprocal (F with the mirror
     * images' factors, ff_mirror.c) */
    RAD_SOLVER_RECIPROCAL = 1u << 0
};

typedef struct rad_solver {
    const char *name;
    const char *description;
    /* B (3n) holds the starting guess (E) and receives the answer. */
    rad_result (*solve)(rad_context *ctx, const rad_system *sys, const rad_solve_params *p,
                        double *B, rad_solve_stats *stats);
    unsigned flags;                 /* RAD_SOLVER_* */
} rad_solver;

/* The linear solvers: each works on a system with its matrix F (the dense
 * strategy runs them).  NULL-terminated. */
extern const rad_solver *const rad_solvers[];
const rad_solver *rad_solver_find(const char *name);

/* Progressive refinement without a matrix (solve_shooting.c): sys->F is
 * NULL and each shot samples its column with rays against sys->mesh and
 * sys->vis.  Not in rad_solvers: the matrix-free strategy runs it. */
extern const rad_solver rad_solver_shooting;


/* ---- how long an iterative solver may run (solve.c) ----
 *
 * Light loses at least 1 - q of its power at every bounce, q the largest
 * reflectance times the largest row sum of F (at most rho_max where rows
 * sum to 1 or less).  One Jacobi sweep multiplies the residual by rho F,
 * whose norm in the residual's own measure (area-weighted, solve.h) is at
 * most q by reciprocity (sum_i A_i rho_i F_ij <= q A_j), and the first
 * residual, rho F E, is at most q of the emitted power: so
 *
 *     k = ln(tolerance) / ln(q)      bounces
 *
 * take the residual below the tolerance.  Gauss-Seidel contracts at least
 * as fast (Stein-Rosenberg), shooting sends each bounce's unshot power on
 * in about n shots.  A solver may take 2 k + 10 bounces (room for its own
 * ordering, relaxation and rounding), and at most RAD_SOLVE_BOUNCE_CAP
 * unless the user's rad_options.max_iterations asks for more: at
 * rho = 0.999999 the default tolerance needs 1.4e7 bounces, and gathering
 * must stop, unconverged and saying so, rather than run for days. */

/* Bounces an automatic bound allows at most: enough for the default
 * tolerance 1e-6 up to q = 0.9972, for shooting's 1e-3 up to q = 0.9986
 * (2 k + 10 = 10^4). */
#define RAD_SOLVE_BOUNCE_CAP 10000.0

typedef enum rad_bound_reason {
    RAD_BOUND_PHYSICS = 0,    /* 2 k + 10 bounces */
    RAD_BOUND_CAP,            /* RAD_SOLVE_BOUNCE_CAP bounces: k is larger, or q >= 1 */
    RAD_BOUND_USER            /* rad_options.max_iterations */
} rad_bound_reason;

typedef struct rad_solve_bound {
    double limit;             /* iterations the solver may take (>= 1) */
    double bounces;           /* k above; INFINITY when q >= 1 */
    double contraction;       /* q */
    rad_bound_reason reason;  /* what set the limit */
    const char *k_units;      /* what k counts, for the warning; NULL = "bounces" */
} rad_solve_bound;

/* q of a system: its largest reflectance times its largest row sum (rows
 * of F in parallel; a matrix-free system's rays carry no more than they
 * were given: row sums 1).  Cannot fail. */
double rad_system_contraction(const rad_system *sys);

/* The bound for a solver whose iterations each carry light 1 / per_bounce
 * of a bounce (a sweep: 1; a shot: 1 / n), stopping below `goal`, with
 * relaxation omega (contraction |1 - w| + w q, that of weighted Jacobi) and
 * the user's cap (0 = none).  A user's cap above 2 k + 10 bounces is
 * lowered to it: beyond, iterations cannot help.  Cannot fail. */
rad_solve_bound rad_solve_bound_make(int max_iterations, double q, double relaxation, double goal,
                                     double per_bounce);

/* stats->warning for a solver `who` that stopped after `done` `units`
 * ("sweeps") with `measure` ("residual") at `value` above `goal`; `hint`
 * ("" or a way out) ends the line.  Cannot fail. */
void rad_solve_warn(rad_solve_stats *stats, const char *who, const rad_solve_bound *bound, double done,
                    const char *units, const char *measure, double value, double goal, const char *hint);

/* The hint of Gauss-Seidel, Jacobi and Southwell: conjugate gradients and
 * LU do not slow down as rho_max nears 1. */
#define RAD_SOLVE_FASTER_HINT "; conjugate-gradient or direct need far fewer iterations here"

/* Threads for one O(n^2) pass over F: the system's, or 1 below 256 x 256
 * entries, where starting the team costs more than the pass (10^4 Jacobi
 * sweeps of 216 elements: 1.5 s on one thread, 14.5 s on two of a loaded
 * 2-core machine).  Every pass sums in a fixed order, so the answer is the
 * same either way. */
static inline int rad_pass_threads(const rad_system *sys)
{
    return sys->n >= 256 && sys->threads > 1 ? sys->threads : 1;
}

/* Irradiance gathered by one row: g[c] = sum_j F_ij B_jc (B interleaved RGB). */
static inline void rad_gather(const double *F_row, const double *B, size_t n, double g[3])
{
    double g0 = 0.0, g1 = 0.0, g2 = 0.0;
    for (size_t j = 0; j < n; j++) {
        double f = F_row[j];
        g0 += f * B[3 * j];
        g1 += f * B[3 * j + 1];
        g2 += f * B[3 * j + 2];
    }
    g[0] = g0;
    g[1] = g1;
    g[2] = g2;
}

/* Union-find with path halving and union by size (Tarjan 1975), over
 * parent[] (each i its own set at first: parent[i] = i, size[i] = 1).
 * Root of i's set; cannot fail. */
size_t rad_union_find_root(size_t *parent, size_t i);

/* Join the sets of a and b; returns the new root, or SIZE_MAX if they
 * were one set already.  Cannot fail. */
size_t rad_union_find_join(size_t *parent, size_t *size, size_t a, size_t b);

/* Solve the independent groups of elements separately (components.c): the
 * graph with an edge i-j where F_ij > 0 or F_ji > 0 is split into connected
 * components (union-find, one O(n^2) scan of F); when two or more have more
 * than one element, each one's sub-system (a copy of its block of F, at
 * most the largest block's 4 n_k^2 bytes at a time) is solved with `solver`
 * and scattered back into B.  Monitor steps are renumbered 1, 2, ... over
 * the whole run, their residual and unshot rescaled to the whole system.
 * stats: iterations = the most any component took, residual measured on
 * the whole system at the end, components = the number of groups.  With
 * one group, a matrix-free solver (F == NULL), or no room for the copy
 * beside F under max_memory, it calls `solver` as is (components = 0).  Fails only as the solver does, or with
 * RAD_ERROR_OUT_OF_MEMORY for the copies; B then holds the current iterate. */
rad_result rad_solve_by_components(rad_context *ctx, const rad_solver *solver, const rad_system *sys,
                                   const rad_solve_params *p, double *B, rad_solve_stats *stats);

/* The residual measure above (O(n^2)) into *residual.  Fails only for
 * memory (n doubles of scratch). */
rad_result rad_residual(rad_context *ctx, const rad_system *sys, const double *B, double *residual);

/* The same with the caller's scratch `row` (n doubles), for solvers that
 * measure it every sweep.  Cannot fail. */
double rad_residual_in(const rad_system *sys, const double *B, double *row);

/* Its per-row numerators: row[i] = A_i sum_c |r_ic| (row holds n doubles).
 * Parallel, thread-count independent.  Cannot fail. */
void rad_residual_rows(const rad_system *sys, const double *B, double *row);

/* The ambient term of progressive refinement for unshot radiosity dB
 * (solve_southwell.c). */
void rad_southwell_ambient(const rad_system *sys, const double *dB, double ambient[3]);

#endif /* RAD_SOLVE_H */
