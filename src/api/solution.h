/*
 * solution.h -- the solution object behind the public rad_solution handle:
 * the strategy that makes it (strategy/), the options it was made with,
 * and what the api adds: the convergence history, vertex values for
 * rendering, the seconds of loading and rendering.
 */
#ifndef RAD_SOLUTION_H
#define RAD_SOLUTION_H

#include "strategy/options.h"
#include "output/output.h"
#include "strategy/strategy.h"

struct rad_solution {
    rad_context *ctx;              /* made in: its memory is accounted there (must outlive it) */
    const rad_scene *scene;        /* borrowed: must outlive the solution */
    rad_options options;           /* resolved defaults */
    rad_method_names names;        /* what options' method names point to */
    int threads;                   /* the context's, for parallel passes */
    const rad_strategy *strategy;
    void *state;                   /* the strategy's: mesh, unknowns, stats */
    rad_solution_view view;        /* read-only view, refreshed after create and every solve */
    rad_solve_step *history;       /* the last solve's steps */
    size_t history_count, history_capacity;
    bool history_failed;           /* the history could not grow (out of memory) */
    double *vertex_radiosity;      /* 3 per vertex of view.mesh, computed on demand: what is
                                      displayed (a partial shooting solution's ambient added) */
    bool finish_asked;             /* on_step returned RAD_STEP_FINISH in this solve */
    bool finished_early;           /* ...and the solve ended there: the iterate is the solution */
    char finish_warning[192];      /* rad_solution_warning then */
    double *point_values;          /* 3 per vertex: the radiosity itself, for point queries
                                      (computed on the first one after a solve) */
};

#endif /* RAD_SOLUTION_H */
