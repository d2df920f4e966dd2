/*
 * bench_hier_steps.c -- the cost of the hierarchical solver's progressive
 * display (docs/hierarchical.md, "Progressive display"): the Cornell box,
 * default options, one thread, solved once without rad_options.on_step
 * (the default solve: no leaf meshes made per round) or, with `step`, with
 * an on_step that does nothing (a leaf mesh per refinement round, the
 * leaves' values per sweep).  Meant for instruction counts:
 *
 *   valgrind --tool=callgrind build/bench/bench_hier_steps [step]
 *
 * Prints the leaves, links and steps.
 */
#include <stdio.h>
#include <string.h>

#include "radiosity.h"

static int on_step(void *user, rad_solution *s, const rad_solve_step *step)
{
    (void)s, (void)step;
    ++*(int *)user;
    return 0;
}

int main(int argc, char **argv)
{
    int with = argc > 1 && strcmp(argv[1], "step") == 0, steps = 0;
    rad_context_options co = {.threads = 1};
    rad_context *ctx = NULL;
    rad_scene *scene = NULL;
    rad_solution *s = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    rad_options o = {.solver = "hierarchical"};
    if (with) {
        o.on_step = on_step;
        o.on_step_user = &steps;
    }
    int status = 1;
    if (rad_scene_create_cornell_box(ctx, &scene) == RAD_OK && rad_solution_create(ctx, scene, &o, &s) == RAD_OK &&
        rad_solution_solve(ctx, s) == RAD_OK) {
        printf("%s: %zu leaves, %zu links, %d steps\n", with ? "on_step" : "no on_step",
               rad_solution_element_count(s), rad_solution_link_count(s), steps);
        status = 0;
    } else {
        fprintf(stderr, "bench_hier_steps: %s\n", rad_context_error(ctx));
    }
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return status;
}
