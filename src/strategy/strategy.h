/*
 * strategy.h -- the ways a solution is made, behind one small table.
 *
 * A strategy owns everything one run of the method needs, from the start:
 * its mesh, its ray structure, its unknowns (one B per element) and its
 * statistics.  The api layer creates one, asks it to solve, and reads the
 * result through a read-only view; it never looks inside.
 *
 *     strategy       couples elements by            solves with
 *     dense          the n x n form-factor matrix   a linear solver (solve.h table)
 *     matrix-free    nothing stored: rays per shot  progressive refinement (shooting)
 *     hierarchical   links between quadtree nodes   Jacobi sweeps + BF refinement
 *     galerkin       the kernel K per pair of basis  the Neumann series of M^-1 rho K
 *                    functions (constant, linear);   (Galerkin) or Jacobi (collocation)
 *                    the mass matrix M
 *
 * Each strategy answers to one or more solver names (rad_options.solver):
 * dense to every linear solver in the solver table, the others to their
 * own.  What it can do (mirrors, luminaires, adaptive subdivision, a
 * stored F, ...) is a set of rad_capability bits in its table line, which
 * the api, the option checks and the program test instead of its name.
 * Adding a strategy (Galerkin elements, instant radiosity) is one file and
 * one line in rad_strategies[] (strategy.c).
 *
 * The elements of a hierarchical solution are the leaves of its hierarchy:
 * the patches until it is solved, the refined leaves after; the view is
 * valid until the next solve.  Dense and matrix-free strategies keep their
 * elements for life.
 */
#ifndef RAD_STRATEGY_H
#define RAD_STRATEGY_H

#include "hier/hier.h"

/* Wall-clock seconds of each phase of a run. */
typedef struct rad_phase_seconds {
    double load, mesh, visibility, form_factors, solve, render;
} rad_phase_seconds;

/* A solution as downstream code (interpolation, output, the api's
 * accessors) reads it.  Every pointer is owned by the strategy (or, for
 * scene and options, by the solution) and valid until the next
 * solve or the solution's end. */
typedef struct rad_solution_view {
    const rad_scene *scene;
    const rad_options *options;     /* resolved: no zero means "default" left */
    int threads;                    /* for the parallel passes of the questions below */
    const rad_mesh *mesh;           /* the elements and their welded vertices */
    const rad_vis *vis;             /* closest-hit and occlusion queries */
    const struct rad_light_reach *light_reach; /* where each luminaire's light arrives (light.h), for
                                                  the points' direct light; NULL: every luminaire asked */
    size_t n;                       /* elements */
    const double *area;             /* n, m^2 */
    const double *reflectance;      /* 3n, RGB */
    const double *emission;         /* 3n, W/m^2: self-emitted, plus rho x direct (below) */
    const double *direct;           /* 3n, W/m^2: the mean direct irradiance from luminaires and
                                       daylight (light/light.h), whose first reflection is part
                                       of `emission`; NULL where the scene has none */
    const double *radiosity;        /* 3n, W/m^2: E before solving, the iterate during */
    /* 3 per mesh vertex, W/m^2: the strategy's own vertex values where they
     * are its unknowns (galerkin-linear, collocation), to be interpolated
     * with the basis as they are; NULL: derived from `radiosity` (interp/,
     * through rad_view_vertex_values in interp.h). */
    const double *vertex_radiosity;
    const double *F;                 /* n x n; NULL where the strategy stores none */
    const double *F_coupling;        /* the F the solve used: F with the mirror images' factors
                                        (ff_mirror.c) where the scene has mirrors, else NULL (= F) */
    const double *F_variance;        /* n x n for sampling methods that estimate it, else NULL */
    const rad_ff_stats *ff;
    const rad_solve_stats *solve;
    const rad_hier_stats *hier;     /* hierarchical only, else NULL */
    const struct rad_adaptive_stats *adaptive; /* dense with adaptive subdivision, else NULL */
    bool solved;
    const char *ended_early;        /* the solve was ended by on_step (RAD_STEP_FINISH): why, in
                                       place of solve->warning, and not converged; else NULL */
    rad_phase_seconds seconds;
    uint64_t render_rays;
} rad_solution_view;

/* Called by a strategy after each step; nonzero stops the solve (it then
 * returns RAD_ERROR_INTERRUPTED).  `displayable` is false where the view
 * does not show the current iterate (a hierarchy being refined). */
typedef int (*rad_step_fn)(void *user, const rad_solve_step *step, bool displayable);

typedef struct rad_step_hook {
    rad_step_fn fn;                 /* NULL: no steps wanted */
    void *user;
    bool display;                   /* the steps are displayed (rad_options.on_step): a
                                       strategy whose mesh changes as it solves (hierarchical)
                                       then keeps its view on the iterate, at a cost */
} rad_step_hook;

typedef struct rad_strategy {
    const char *name;
    const char *description;
    /* What the solvers it answers to can do: rad_capability bits
     * (radiosity.h), tested instead of names (rad_strategy_capabilities). */
    unsigned capabilities;
    /* The index-th solver name it answers to, and its one-line description;
     * false past the end. */
    bool (*solver_info)(size_t index, const char **name, const char **description);
    /* Mesh, visibility and couplings for `scene` (which must outlive the
     * state) under resolved options; B = E.  On failure *state is NULL and
     * nothing leaks; RAD_ERROR_INTERRUPTED when cancelled. */
    rad_result (*create)(rad_context *ctx, const rad_scene *scene, const rad_options *options,
                         void **state);
    /* Solve from B = E; steps go to `hook`.  The iterate is kept when
     * interrupted. */
    rad_result (*solve)(rad_context *ctx, void *state, const rad_step_hook *hook);
    /* Fill the strategy's part of *view: mesh, vis, arrays, stats, seconds
     * of mesh / visibility / form factors / solve, solved.  Cannot fail. */
    void (*view)(const void *state, rad_solution_view *view);
    void (*destroy)(void *state);
} rad_strategy;

extern const rad_strategy *const rad_strategies[]; /* NULL-terminated */

/* The strategy that answers to solver `name`; NULL if none does. */
const rad_strategy *rad_strategy_for_solver(const char *name);

/* The rad_capability bits of solver `name`: its strategy's, less
 * RAD_CAN_MIRRORS and with RAD_REFUSES_MIRRORS for a linear solver that
 * reads F through reciprocity (RAD_SOLVER_RECIPROCAL); 0 for an unknown
 * name.  rad_method_capabilities for solvers. */
unsigned rad_strategy_capabilities(const char *name);

/* The index-th solver name over all strategies, in table order; false past
 * the end (for --list-methods and rad_method_info). */
bool rad_strategy_solver_info(size_t index, const char **name, const char **description);

/* ---- what the strategies share (shared.c) ---- */

/* Per-element arrays of a mesh: area, reflectance and emission from the
 * scene's materials, radiosity = emission. */
typedef struct rad_elements {
    double *area;                   /* n */
    double *reflectance;            /* 3n */
    double *emission;               /* 3n */
    double *radiosity;              /* 3n */
    double *direct;                 /* 3n: direct irradiance from luminaires and daylight; NULL
                                       until rad_elements_add_light finds the scene has some */
} rad_elements;

/* Fill *out for `mesh`; nothing is allocated on failure (out of memory). */
rad_result rad_elements_create(rad_context *ctx, const rad_scene *scene, const rad_mesh *mesh,
                               rad_elements *out);
/* Where the scene has luminaires or daylight (rad_light_present): e->direct
 * = the mean direct irradiance over each element (light.h), and its first
 * reflection added, emission += rho x direct and radiosity = emission.
 * Parallel over elements with the context's threads, the same values
 * whatever their count; progress as "direct light".  Without light: RAD_OK,
 * nothing changed.  Fails for memory (e unchanged) or when cancelled
 * (RAD_ERROR_INTERRUPTED; e unchanged). */
rad_result rad_elements_add_light(rad_context *ctx, const rad_scene *scene, const rad_mesh *mesh,
                                  const rad_vis *vis, rad_elements *e);
void rad_elements_free(rad_elements *e);

/* Fill the view's element part from a mesh and its arrays. */
void rad_view_elements(rad_solution_view *view, const rad_mesh *mesh, const rad_elements *e);

/* Mesh and ray structure as every strategy builds them (timed); the mesh
 * within options->max_memory_bytes.  On failure both are NULL. */
rad_result rad_strategy_mesh_and_vis(rad_context *ctx, const rad_scene *scene, const rad_options *options,
                                     const rad_mesh_options *mesh_options, rad_mesh **mesh, rad_vis **vis,
                                     rad_phase_seconds *seconds);

/* With rad_options.closure_correction, the scene must be closed: the light
 * escaping it (rad_ff_escaped over the elements whose rays meet something)
 * at most RAD_FF_OPEN_SCENE_ESCAPE, else RAD_ERROR_INVALID_ARGUMENT naming
 * the scene and the fraction.  *escape receives the per-element fractions
 * (the caller rad_frees them; dense checks again once F is known) and
 * *escaped the light escaping.  Without the option: RAD_OK, *escape NULL,
 * *escaped 0.  Fails otherwise for memory or when interrupted. */
rad_result rad_strategy_check_closed(rad_context *ctx, const rad_scene *scene, const rad_options *options,
                                     const rad_mesh *mesh, const rad_vis *vis, double **escape, double *escaped);

/* The part of a strategy that meshes once and keeps its elements for life
 * (dense, matrix-free): a system of n elements solved in place. */
typedef struct rad_meshed {
    const rad_scene *scene;
    const rad_options *options;
    int threads;
    rad_mesh *mesh;
    rad_vis *vis;
    rad_elements elements;
    rad_ff_stats ff_stats;
    rad_solve_stats solve_stats;
    rad_phase_seconds seconds;
    bool solved;
    const rad_step_hook *hook;      /* during a solve */
} rad_meshed;

/* Mesh (options' mesh size or element count), ray structure and element
 * arrays.  On failure everything built is freed again. */
rad_result rad_meshed_init(rad_context *ctx, const rad_scene *scene, const rad_options *options,
                           rad_meshed *m);
void rad_meshed_free(rad_meshed *m);

/* Start a solve: B = E, stats cleared and named, *sys and *p filled from
 * the options (sys->F NULL: the caller sets it).  Steps reach `hook` with
 * the shooting ambient term kept for display. */
void rad_meshed_begin(rad_meshed *m, const char *method, const rad_step_hook *hook, rad_system *sys,
                      rad_solve_params *p);
/* End it: seconds and solved from the result `r` of a solve begun at `t0`. */
void rad_meshed_end(rad_meshed *m, rad_result r, double t0);

/* The view of a meshed strategy (F and F_variance left NULL). */
void rad_meshed_view(const rad_meshed *m, rad_solution_view *v);

/* ---- adaptive subdivision of a dense mesh (adaptive.c) ---- */

/* The quadtrees of an adaptive mesh and what the rounds did. */
typedef struct rad_adaptive rad_adaptive;

typedef struct rad_adaptive_stats {
    size_t initial_elements;        /* the uniform quadtrees' leaves */
    size_t elements;                /* leaves now */
    int rounds;                     /* refinements made (each followed by a coupling and a solve) */
    size_t split;                   /* leaves split for their gradient or visibility */
    size_t balanced;                /* leaves split to keep neighbours within one level */
} rad_adaptive_stats;

/* What adaptive.c asks of the strategy after each refinement: couplings
 * for the meshed base's new mesh (the old ones freed), and a solve on it
 * from B = E.  A failure ends the refinement with that result. */
typedef struct rad_adaptive_hooks {
    rad_result (*couple)(rad_context *ctx, void *state);
    rad_result (*solve)(rad_context *ctx, void *state, const rad_step_hook *hook);
    void *state;
} rad_adaptive_hooks;

/* Replace m's grid mesh (kept inside as the base) by uniform quadtrees of
 * its patches at about the grid's element count, with its ray structure
 * and element arrays (m->options->adaptive_levels > 0).  On failure *out is
 * NULL and m is as it was. */
rad_result rad_adaptive_create(rad_context *ctx, rad_meshed *m, rad_adaptive **out);
/* Up to adaptive_levels rounds after a solve: score the elements, split
 * the worst within the budget (adaptive_max_elements), balance, remesh,
 * couple and solve through `h`.  Ends early when nothing needs splitting.
 * On failure m holds the last complete mesh (RAD_ERROR_INTERRUPTED when
 * cancelled). */
rad_result rad_adaptive_refine(rad_context *ctx, rad_adaptive *a, rad_meshed *m, const rad_adaptive_hooks *h,
                               const rad_step_hook *hook);
void rad_adaptive_destroy(rad_adaptive *a);
/* NULL for NULL. */
const rad_adaptive_stats *rad_adaptive_get_stats(const rad_adaptive *a);

/* ---- questions answered from a view (view.c) ---- */

/* Power in W (means over RGB): emitted = sum A_i E_i; absorbed = sum A_i
 * (1 - rho_i) H_i from F where the view has it, else the strategy's own
 * count.  With direct light (view->direct), emitted counts the surfaces' own
 * emission and the direct light landing (E_i here being the self-emitted
 * part), absorbed the direct light absorbed at once as well.  Fails only
 * for memory (n doubles; then NAN, NAN). */
rad_result rad_view_power(rad_context *ctx, const rad_solution_view *view, double *emitted, double *absorbed);

/* Lumens of direct light (luminaires, daylight: view->direct) landing on
 * the elements, RAD_LUMINOUS_EFFICACY (179 lm/W, docs/units.md) times
 * sum A_i Y(direct_i); 0 without any.
 * Cannot fail. */
double rad_view_direct_lumens(const rad_solution_view *view);

/* Area-weighted mean radiosity of one surface. */
void rad_view_surface_radiosity(const rad_solution_view *view, size_t surface, double rgb[3]);

/* Surface-to-surface factors F[a * S + b] (S surfaces), zero without F.
 * Fails only for memory (S doubles; F is then NAN). */
rad_result rad_view_surface_view_factors(rad_context *ctx, const rad_solution_view *view, double *F);

/* ---- Galerkin elements and point collocation (galerkin.c) ---- */

/* The matrices of a galerkin strategy's state (rad_strategy_galerkin's
 * create), for tests and benches: read-only, valid until it is destroyed. */
typedef struct rad_galerkin_matrices {
    size_t unknowns;                /* elements (galerkin-constant) or mesh vertices */
    const double *K;                /* unknowns x unknowns, row-major: Galerkin int N_i int N_j G V (m^2),
                                       collocation int N_j G(x_i, .) V (1); no reflectance */
    const double *element_mass;     /* 16 per element: its mass matrix int N_a N_b (m^2), 4 x 4 row-major,
                                       over its nodes (1 for the constant basis, else its vertices) */
    const double *node_mass;        /* unknowns: int N_i (m^2) */
    const double *node_radiosity;   /* 3 x unknowns, W/m^2: the solution */
} rad_galerkin_matrices;

extern const rad_strategy rad_strategy_galerkin;

/* Cannot fail. */
void rad_galerkin_get_matrices(const void *state, rad_galerkin_matrices *out);

#endif /* RAD_STRATEGY_H */
