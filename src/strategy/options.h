/*
 * options.h -- validation and defaults of the public rad_options, driven by
 * the option table (options.c; the table's API is in radiosity.h).
 */
#ifndef RAD_API_OPTIONS_H
#define RAD_API_OPTIONS_H

#include "core/core.h"

/* Copies of the method names, so resolved options do not point into the
 * caller's strings. */
typedef struct rad_method_names {
    char form_factors[32];
    char solver[32];
    char visibility[32];
} rad_method_names;

/* The solver taken when o->solver is NULL: the table's default
 * (hierarchical), unless it lacks a capability (rad_capability) that
 * `needs` asks or that o's fields ask for (mesh_size or target_elements: a
 * uniform mesh; form_factors: a form-factor matrix; the adaptive fields:
 * adaptive subdivision; the default would ignore them); then gauss-seidel,
 * which has them all.  Cannot fail. */
const char *rad_options_default_solver(const rad_options *o, unsigned needs);

/* Fill in the defaults of `in` (NULL = all defaults) and check every field
 * against its row of the option table; on success *out holds the resolved
 * options, whose method names point into *names (which must outlive them).
 * On failure the context names the field: "rad_options.tolerance must be
 * in (0, 1), got 2". */
rad_result rad_options_resolve(rad_context *ctx, const rad_options *in, rad_options *out,
                               rad_method_names *names);

#endif
