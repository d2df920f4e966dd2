/*
 * bench_solvers.c -- every solver on the same system: the built-in Cornell
 * box at about 4000 elements, form factors computed once (analytic, seed 0),
 * then each solver from B = E to the tolerance with its history recorded.
 *
 *   build/bench/bench_solvers [--elements N] [--tolerance X] [--threads N]
 *                             [--solvers a,b,...] [--out DIR]
 *
 * Prints one row per solver (iterations, seconds, final residual) and
 * writes DIR/bench_history_<solver>.csv (iteration,seconds,residual,unshot;
 * DIR is created if missing) for bench/plot_history.py.  Fixed scene, seed
 * and element target: the figures are comparable across commits on the
 * same machine.  Matrix-free solvers run too, on their own sampled factors.
 */
#include "api/solution.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static void usage(void)
{
    fprintf(stderr, "usage: bench_solvers [--elements N] [--tolerance X] [--threads N] "
                    "[--solvers a,b,...] [--out DIR]\n");
    exit(2);
}

/* Is `name` in the comma-separated `list` (NULL = every solver)? */
static bool listed(const char *list, const char *name)
{
    if (!list)
        return true;
    size_t len = strlen(name);
    for (const char *p = list; *p;) {
        const char *comma = strchr(p, ',');
        size_t n = comma ? (size_t)(comma - p) : strlen(p);
        if (n == len && strncmp(p, name, n) == 0)
            return true;
        p += n + (comma ? 1 : 0);
    }
    return false;
}

int main(int argc, char **argv)
{
    int threads = 0;
    size_t elements = 4000;
    double tolerance = 1e-9;
    const char *out = ".", *only = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--elements") == 0 && i + 1 < argc)
            elements = (size_t)atol(argv[++i]);
        else if (strcmp(argv[i], "--tolerance") == 0 && i + 1 < argc)
            tolerance = atof(argv[++i]);
        else if (strcmp(argv[i], "--solvers") == 0 && i + 1 < argc)
            only = argv[++i];
        else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc)
            out = argv[++i];
        else
            usage();
    }
    if (mkdir(out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "bench_solvers: %s: cannot create the folder\n", out);
        return 1;
    }
    rad_context_options co = {0};
    co.threads = threads;
    rad_context *ctx;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    rad_scene *scene;
    rad_solution *sol;
    rad_options o = {0};
    o.target_elements = elements;
    o.tolerance = tolerance;
    o.record_history = 1;
    if (rad_scene_create_cornell_box(ctx, &scene) != RAD_OK ||
        rad_solution_create(ctx, scene, &o, &sol) != RAD_OK) {
        fprintf(stderr, "bench_solvers: %s\n", rad_context_error(ctx));
        return 1;
    }
    printf("Cornell box, %zu elements, seed 0, %d threads, analytic form factors (%.1f s), "
           "tolerance %g\n",
           sol->view.mesh->element_count, rad_context_threads(ctx), sol->view.seconds.form_factors, tolerance);
    printf("%-20s %10s %10s %12s %12s  %s\n", "solver", "iterations", "seconds", "residual", "unshot",
           "converged");
    int status = 0;
    for (size_t k = 0; rad_solvers[k]; k++) {
        const rad_solver *solver = rad_solvers[k];
        if (!listed(only, solver->name))
            continue;
        snprintf(sol->names.solver, sizeof sol->names.solver, "%s", solver->name);
        sol->options.solver = sol->names.solver;
        rad_result r = rad_solution_solve(ctx, sol);
        if (r != RAD_OK) {
            printf("%-20s failed: %s\n", solver->name, rad_context_error(ctx));
            status = 1;
            continue;
        }
        const rad_solve_stats *st = sol->view.solve;
        printf("%-20s %10d %10.3f %12.3e %12.3e  %s\n", solver->name, st->iterations, st->seconds,
               st->residual, st->unshot, st->converged ? "yes" : "no");
        fflush(stdout);
        char path[1024];
        snprintf(path, sizeof path, "%s/bench_history_%s.csv", out, solver->name);
        if (rad_solution_write_history(ctx, sol, path) != RAD_OK) {
            fprintf(stderr, "bench_solvers: %s\n", rad_context_error(ctx));
            status = 1;
        }
    }
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return status;
}
