/*
 * control_variate.h -- a constant control variate for the Monte Carlo
 * solvers (shooting, instant radiosity): B = beta + B', where the
 * transport of beta is known, so that only B' is estimated by rays
 * (Bekaert 1999, "Hierarchical and stochastic algorithms for radiosity",
 * KU Leuven, the stochastic Jacobi chapter's control variates; Neumann et
 * al. 1995's stochastic ray method).  B' solves the same system with the
 * residual source
 *
 *     E'_i = E_i + rho_i T_i - beta_i,    T_i = sum_j F_ij beta_j
 *
 * and in a closed group of constant beta T_i = beta exactly: in the closed
 * furnace with beta = E / (1 - rho), E' = 0 and B = beta on every element,
 * with no noise.  control_variate.c has the choice of beta and how T is
 * estimated without bias in open scenes.
 */
#ifndef RAD_CONTROL_VARIATE_H
#define RAD_CONTROL_VARIATE_H

#include "mesh/mesh.h"
#include "vis/vis.h"

typedef struct rad_control_variate {
    double *beta;             /* 3n, W/m^2: the constant of element i's group (0 where none) */
    double *source;           /* 3n, W/m^2: the residual source E'_i (signed) */
    double *transport;        /* 3n, W/m^2: T_i, the irradiance beta gives element i */
    bool active;              /* some beta != 0; else beta = T = 0 and source = E */
    size_t groups;            /* groups of elements the grouping rays joined */
    size_t groups_varied;     /* of those, the groups with beta != 0 */
    double beta_mean[3];      /* W/m^2, RGB: beta's area-weighted mean over the scene */
    uint64_t rays;            /* rays cast for the groups and T */
} rad_control_variate;

/* Choose beta per group of elements light can join and channel, and
 * estimate T and E' (control_variate.c).  `transport_rays` rays per
 * element estimate T where some beta is not 0; a group some grouping ray
 * leaves (escaping, or onto a back side) gets beta = 0.  Arrays are per element
 * (area n, reflectance and emission 3n).  Deterministic for a seed,
 * whatever `threads`.  On failure *out is zeroed and nothing leaks. */
rad_result rad_control_variate_make(rad_context *ctx, const rad_mesh *mesh, const rad_vis *vis, const double *area,
                                    const double *reflectance, const double *emission, uint64_t seed,
                                    int transport_rays, int threads, rad_control_variate *out);
void rad_control_variate_free(rad_control_variate *cv);

#endif /* RAD_CONTROL_VARIATE_H */
