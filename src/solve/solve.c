/*
 * solve.c -- the solver registry (what the solvers share is system.c's).
 */
#include "solve/solve.h"

#include <stdlib.h>
#include <string.h>

extern const rad_solver rad_solver_gauss_seidel;
extern const rad_solver rad_solver_southwell;
extern const rad_solver rad_solver_jacobi;
extern const rad_solver rad_solver_direct;
extern const rad_solver rad_solver_conjugate_gradient;

const rad_solver *const rad_solvers[] = {
    &rad_solver_gauss_seidel,
    &rad_solver_southwell,
    &rad_solver_jacobi,
    &rad_solver_direct,
    &rad_solver_conjugate_gradient,
    NULL,
};

const rad_solver *rad_solver_find(const char *name)
{
    for (size_t i = 0; rad_solvers[i]; i++)
        if (strcmp(rad_solvers[i]->name, name) == 0)
            return rad_solvers[i];
    return NULL;
}
