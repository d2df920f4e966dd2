/*
 * strategy.c -- the strategy table, lookup by solver name, and the list of
 * every registry (rad_method_info).  What the strategies share is
 * shared.c's; the questions a view answers, view.c's.
 */
#include "strategy/strategy.h"

#include <string.h>

extern const rad_strategy rad_strategy_dense;
extern const rad_strategy rad_strategy_matrix_free;
extern const rad_strategy rad_strategy_hierarchical;
extern const rad_strategy rad_strategy_instant;

const rad_strategy *const rad_strategies[] = {
    &rad_strategy_dense,
    &rad_strategy_matrix_free,
    &rad_strategy_hierarchical,
    &rad_strategy_galerkin,
    &rad_strategy_instant,
    NULL,
};

const rad_strategy *rad_strategy_for_solver(const char *name)
{
    const char *solver, *description;
    for (size_t k = 0; rad_strategies[k]; k++)
        for (size_t i = 0; rad_strategies[k]->solver_info(i, &solver, &description); i++)
            if (strcmp(solver, name) == 0)
                return rad_strategies[k];
    return NULL;
}

unsigned rad_strategy_capabilities(const char *name)
{
    const rad_strategy *strategy = name ? rad_strategy_for_solver(name) : NULL;
    if (!strategy)
        return 0;
    unsigned capabilities = strategy->capabilities;
    /* The mirror images' factors (ff_mirror.c) break reciprocity: a linear
     * solver that relies on it cannot take them. */
    const rad_solver *linear = rad_solver_find(name);
    if (linear && (linear->flags & RAD_SOLVER_RECIPROCAL) && (capabilities & RAD_CAN_MIRRORS))
        capabilities = (capabilities & ~(unsigned)RAD_CAN_MIRRORS) | RAD_REFUSES_MIRRORS;
    return capabilities;
}

bool rad_strategy_solver_info(size_t index, const char **name, const char **description)
{
    for (size_t k = 0; rad_strategies[k]; k++) {
        size_t i = 0;
        while (rad_strategies[k]->solver_info(i, name, description)) {
            if (index == 0)
                return true;
            index--, i++;
        }
    }
    return false;
}

/* Every registry of the pipeline, for --list-methods and the option
 * table's method names (radiosity.h). */
bool rad_method_info(rad_method_kind kind, size_t index, const char **name, const char **description)
{
    size_t count = 0;
    const char *method_name = NULL, *method_description = NULL;
    switch (kind) {
    case RAD_METHOD_FORM_FACTOR:
        while (rad_ff_methods[count])
            count++;
        if (index >= count)
            return false;
        method_name = rad_ff_methods[index]->name;
        method_description = rad_ff_methods[index]->description;
        break;
    case RAD_METHOD_SOLVER:
        if (!rad_strategy_solver_info(index, &method_name, &method_description))
            return false;
        break;
    case RAD_METHOD_VISIBILITY:
        while (rad_vis_backends[count])
            count++;
        if (index >= count)
            return false;
        method_name = rad_vis_backends[index]->name;
        method_description = rad_vis_backends[index]->description;
        break;
    default:
        return false;
    }
    if (name)
        *name = method_name;
    if (description)
        *description = method_description;
    return true;
}

unsigned rad_method_capabilities(rad_method_kind kind, const char *name)
{
    return kind == RAD_METHOD_SOLVER ? rad_strategy_capabilities(name) : 0;
}
