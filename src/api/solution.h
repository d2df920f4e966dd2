/*
 * solution.h -- the solution object behind the public rad_solution handle:
 * everything one run owns, and the seconds and bytes each phase took.
 */
#ifndef RAD_SOLUTION_H
#define RAD_SOLUTION_H

#include "api/options.h"
#include "formfactor/formfactor.h"
#include "hier/hier.h"
#include "output/output.h"
#include "solve/solve.h"

struct rad_solution {
    const rad_scene *scene;    /* borrowed: must outlive the solution */
    rad_options options;       /* resolved defaults */
    int threads;               /* the context's, for parallel passes */
    rad_method_names names;    /* what options' method names point to */
    rad_mesh *mesh;            /* hierarchical: the leaves, after solving */
    rad_mesh *hier_base;       /* hierarchical: the patches (one element each) vis is built on */
    rad_hier_stats hier_stats;
    rad_vis *vis;
    float *F;                  /* n x n; NULL for matrix-free solvers */
    float *F_variance;         /* n x n for methods that estimate it, else NULL */
    double *area;              /* n */
    double *reflectance;       /* 3n */
    double *emission;          /* 3n */
    double *radiosity;         /* 3n, W/m^2 */
    double *vertex_radiosity;  /* 3 per mesh vertex, computed on demand */
    rad_ff_stats ff_stats;
    rad_solve_stats solve_stats;
    bool solved;
    rad_solve_step *history;   /* the last solve's steps */
    size_t history_count, history_capacity;
    struct {
        double load, mesh, visibility, form_factors, solve, render;
    } seconds;
    double render_seconds_total;
    uint64_t render_rays;
};

#endif /* RAD_SOLUTION_H */
