/*
 * thermal.h -- radiative heat exchange between grey, diffuse surfaces: the
 * net-radiation method (Hottel; Modest, "Radiative Heat Transfer", 3rd ed.,
 * ch. 5; Incropera et al., "Fundamentals of Heat and Mass Transfer", ch. 13)
 * on the engine's form factors, solved by the engine's linear solvers.
 *
 * Every element i has an emissivity eps_i in (0, 1] and either a known
 * temperature T_i or a known net heat flux q_i (adiabatic: q_i = 0).  Its
 * radiosity J_i (W/m^2) and irradiation G_i satisfy
 *
 *     G_i = sum_j F_ij J_j + (1 - S_i) sigma T_env^4,   S_i = sum_j F_ij
 *
 *     known T:  J_i = eps_i sigma T_i^4 + (1 - eps_i) G_i
 *     known q:  J_i = q_i + G_i
 *
 * (what escapes an open scene meets an environment at T_env).  Both rows
 * are the engine's B = E + rho F B (solve.h) with
 *
 *     known T:  rho_i = 1 - eps_i,  E_i = eps_i sigma T_i^4 + (1 - eps_i)(1 - S_i) sigma T_env^4
 *     known q:  rho_i = 1,          E_i = q_i + (1 - S_i) sigma T_env^4
 *
 * so any solver of the table solves it.  E may be negative (a surface
 * cooled from outside); the solvers' residual is relative to sum A_i E_i,
 * so the system is solved as two by linearity, J = J+ - J-, with
 * E+ = max(E, 0) in channel 0 and E- = max(-E, 0) in channel 1: the
 * residual is then relative to sum A_i |E_i|.  Afterwards
 *
 *     q_i = J_i - G_i,  Q_i = A_i q_i (W, leaving the surface),
 *     sigma T_i^4 = q_i / eps_i + G_i    for the known-q rows.
 *
 * A group of elements that exchange radiation (connected through F) with
 * no known temperature and no way out is singular (the q must sum to zero
 * and any common T fits): refused, naming its surfaces.
 *
 * Energy: with reciprocal F (A_i F_ij = A_j F_ji),
 *
 *     sum_i Q_i = sum_i A_i (1 - S_i) (J_i - sigma T_env^4),
 *
 * the net power to the environment (0 in a closed enclosure); the
 * difference, `imbalance`, measures F's reciprocity and the solve.
 *
 * Gebhart factors (Gebhart 1961): G_ij, the fraction of i's emission
 * absorbed by j after any number of diffuse reflections,
 *
 *     G = (I - F diag(1 - eps))^-1 F diag(eps),
 *
 * found per emitting surface s by the same solvers: J = eps 1_s + (1 - eps) F J
 * is the radiosity of unit emissive power on s, and the power absorbed by
 * surface t is sum_{j in t} A_j eps_j (F J)_j, divided by s's emission
 * sum_{i in s} A_i eps_i.  Rows sum to 1 in a closed enclosure, and
 * eps_s A_s G_st = eps_t A_t G_ts.
 */
#ifndef RAD_THERMAL_H
#define RAD_THERMAL_H

#include "solve/solve.h"

/* sigma: RAD_SIGMA (radiosity.h). */

/* A group of elements with heat fluxes only is refused as closed when less
 * than this fraction of its area-weighted radiation escapes (sum_i A_i
 * (1 - S_i) / sum_i A_i): the form factors of a closed scene miss closure
 * by about 1e-4 to 1e-3 (docs/methods.md), and the temperatures such a leak
 * would set are the factors' error, not the physics. */
#define RAD_THERMAL_CLOSED_ESCAPE 1e-3

typedef struct rad_thermal_system {
    size_t n;                       /* elements */
    const double *F;                /* n x n, row i = factors from i */
    const double *area;             /* n, m^2 */
    const double *emissivity;       /* n, in (0, 1] */
    const unsigned char *known_temperature; /* n: 1 = value is T (K), 0 = value is q (W/m^2) */
    const double *value;            /* n: K or W/m^2 */
    double environment_temperature; /* K, >= 0 */
    /* n, or NULL (none): 1 = part of the environment (an obstruction-only
     * surface: black, at the environment temperature, given so in
     * known_temperature, value and emissivity); its Q is not summed, and
     * what others send it counts as reaching the environment. */
    const unsigned char *environment;
    /* For messages: the surface of each element and the surfaces' names
     * (either may be NULL: elements are then named by number). */
    const uint32_t *surface;
    const char *const *surface_names;
    const char *source;             /* the conditions' file, or NULL: prefixes messages */
    int threads;
    double max_memory;              /* bytes the solver may hold; 0 = the context's limit */
} rad_thermal_system;

/* Per element, n each, allocated by the caller. */
typedef struct rad_thermal_fields {
    double *radiosity;              /* J, W/m^2 */
    double *irradiation;            /* G, W/m^2 */
    double *heat_flux;              /* q = J - G, W/m^2, leaving the surface */
    double *temperature;            /* K: given, or found for the known-q rows */
} rad_thermal_fields;

/* The balance: rad_thermal_balance (radiosity.h). */

/* Solve the system with `solver` (NULL = "direct") under `p` into `out`;
 * `balance` and `stats` (either may be NULL) receive the figures.  Fails
 * with RAD_ERROR_INVALID_ARGUMENT (a closed group with heat fluxes only; a
 * heat flux that would need a negative T^4: more cooling than the surface
 * can radiate away), RAD_ERROR_OUT_OF_MEMORY, RAD_ERROR_INTERRUPTED or as
 * the solver fails.  Checks nothing else: the caller validates emissivities
 * and values. */
rad_result rad_thermal_solve_system(rad_context *ctx, const rad_thermal_system *sys, const rad_solver *solver,
                                    const rad_solve_params *p, rad_thermal_fields *out,
                                    rad_thermal_balance *balance, rad_solve_stats *stats);

/* Gebhart factors between S surfaces (G[s * S + t]) of the elements of
 * `sys` (sys->surface is required; values and known_temperature are not
 * read, T_env neither: radiation that escapes is lost), three emitting
 * surfaces per solve.  A surface of no element gets a zero row.  Fails
 * with RAD_ERROR_OUT_OF_MEMORY, RAD_ERROR_INTERRUPTED, or as the solver. */
rad_result rad_thermal_gebhart_factors(rad_context *ctx, const rad_thermal_system *sys, size_t S, const rad_solver *solver,
                               const rad_solve_params *p, double *G);

/* ---- the objects behind the public handles (radiosity.h) ---- */

struct rad_thermal_conditions {
    rad_context *ctx;               /* made in: its memory is accounted there */
    const rad_scene *scene;         /* borrowed */
    size_t surface_count;
    rad_thermal_surface *surfaces;  /* surface_count */
    double environment_temperature; /* K */
    char *source;                   /* the file's name, or NULL when set by calls */
};

/* Parse a boundary-condition file's text (conditions.c; docs/thermal.md)
 * into *out.  Errors name `name` and the key; RAD_ERROR_PARSE. */
rad_result rad_thermal_conditions_parse(rad_context *ctx, const rad_scene *scene, const char *name,
                                        const char *text, size_t size, rad_thermal_conditions **out);

/* Whether a condition is acceptable; on failure *why says what (for the
 * caller's message, which names where it came from). */
bool rad_thermal_surface_valid(const rad_thermal_surface *s, char *why, size_t size);

struct rad_thermal {
    rad_context *ctx;               /* made in */
    const struct rad_solution_view *view; /* the solution's, borrowed: it must outlive this */
    double max_memory_bytes;        /* the solution's memory limit, for the writers */
    const rad_scene *scene;         /* the solution's, borrowed */
    const struct rad_mesh *mesh;    /* the solution's elements, borrowed */
    const double *F;                /* the solution's n x n factors, borrowed */
    rad_thermal_system sys;         /* its arrays below, F borrowed */
    const rad_solver *solver;
    rad_solve_params params;
    rad_solve_stats stats;
    double *emissivity, *value;     /* n */
    unsigned char *known_temperature; /* n */
    uint32_t *surface;              /* n */
    const char **surface_names;     /* S, the scene's */
    rad_thermal_fields fields;      /* n each */
    rad_thermal_values *surfaces;   /* S */
    rad_thermal_condition *element_condition; /* n */
    unsigned char *environment;           /* n: obstruction-only elements (rad_thermal_system.environment) */
    rad_thermal_balance balance;
};

#endif /* RAD_THERMAL_H */
