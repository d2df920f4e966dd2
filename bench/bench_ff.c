/*
 * bench_ff.c -- every registered form-factor method (rad_ff_methods[], so
 * methods added later are included) on the analytic reference cases and on
 * the Cornell box: relative error of F_12 for the parallel, perpendicular
 * and occluded unit squares (tests/data/cases.json), and the seconds the
 * form-factor phase takes on the Cornell box at two element counts.
 *
 *   build/bench/bench_ff [--threads N] [--elements N] [--cornell N1,N2]
 *
 * Defaults: 2 threads, 2,000 elements for the cases (the engine's default
 * mesh), 1,000 and 4,000 for the Cornell box; seed 0 and the methods'
 * default settings, so figures are comparable across commits on the same
 * machine.  A method that fails prints its error in place of the figure.
 */
#include "api/solution.h"

#include <stdlib.h>
#include <string.h>

static void usage(void)
{
    fprintf(stderr, "usage: bench_ff [--threads N] [--elements N] [--cornell N1,N2]\n");
    exit(2);
}

/* The exact values of tests/data/cases.json. */
static const double exact_parallel = 0.199824895698;      /* par_rect_1x1_d1 */
static const double exact_perpendicular = 0.200043776075; /* perp_rect_1_1_1_cube */
static const double exact_occluded = 0.031402694248;      /* occluded_squares_blocker0.5 */

/* A unit-square case: A1 and A2 (and the blocker), one grey material; A1
 * emits so that the scene is a complete radiosity problem. */
typedef struct square_case {
    const char *name;
    vec3 a1[4], a2[4];
    bool blocker;
    double exact;
} square_case;

static const square_case cases[3] = {
    {"parallel", {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}},
     false, exact_parallel},
    {"perpendicular", {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}},
     false, exact_perpendicular},
    {"occluded", {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 0, 2}, {0, 1, 2}, {1, 1, 2}, {1, 0, 2}},
     true, exact_occluded},
};

static rad_scene *build_case(rad_context *ctx, const square_case *c)
{
    static const vec3 blocker[4] = {{0.25, 0.25, 1}, {0.75, 0.25, 1}, {0.75, 0.75, 1}, {0.25, 0.75, 1}};
    const double rho[3] = {0.5, 0.5, 0.5}, none[3] = {0, 0, 0}, light[3] = {1, 1, 1};
    rad_scene_builder *b = rad_scene_builder_create(ctx, c->name);
    if (!b)
        return NULL;
    int grey = rad_scene_builder_material(b, "grey", rho, none);
    int lamp = rad_scene_builder_material(b, "lamp", rho, light);
    rad_result r = rad_scene_builder_polygon(b, rad_scene_builder_surface(b, "A1"), lamp, c->a1, 4, 0);
    if (r == RAD_OK)
        r = rad_scene_builder_polygon(b, rad_scene_builder_surface(b, "A2"), grey, c->a2, 4, 0);
    if (r == RAD_OK && c->blocker)
        r = rad_scene_builder_polygon(b, rad_scene_builder_surface(b, "blocker"), grey, blocker, 4, 0);
    if (r != RAD_OK || grey < 0 || lamp < 0) {
        rad_scene_builder_destroy(b);
        return NULL;
    }
    rad_scene *scene = NULL;
    return rad_scene_builder_finish(b, &scene) == RAD_OK ? scene : NULL;
}

/* Relative error of F(A1 -> A2), or NAN (message printed) on failure. */
static double case_error(rad_context *ctx, const char *method, const square_case *c, size_t elements)
{
    rad_scene *scene = build_case(ctx, c);
    if (!scene) {
        fprintf(stderr, "%s: %s scene: %s\n", method, c->name, rad_context_error(ctx));
        return NAN;
    }
    rad_options o = {0};
    o.form_factors = method;
    o.target_elements = elements;
    rad_solution *sol = NULL;
    double err = NAN;
    if (rad_solution_create(ctx, scene, &o, &sol) == RAD_OK && sol->view.F) {
        size_t S = rad_scene_surface_count(scene);
        double *F = malloc(S * S * sizeof *F);
        if (F) {
            rad_solution_surface_view_factors(sol, F);
            err = fabs(F[0 * S + 1] / c->exact - 1.0); /* A1 and A2 are surfaces 0 and 1 */
            free(F);
        }
    } else {
        fprintf(stderr, "%s: %s: %s\n", method, c->name,
                sol ? "no form-factor matrix" : rad_context_error(ctx));
    }
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    return err;
}

/* Seconds of the form-factor phase on the Cornell box, or NAN. */
static double cornell_seconds(rad_context *ctx, const rad_scene *cornell, const char *method,
                              size_t elements, size_t *actual)
{
    rad_options o = {0};
    o.form_factors = method;
    o.target_elements = elements;
    rad_solution *sol = NULL;
    if (rad_solution_create(ctx, cornell, &o, &sol) != RAD_OK) {
        fprintf(stderr, "%s: Cornell box, %zu elements: %s\n", method, elements, rad_context_error(ctx));
        return NAN;
    }
    double s = sol->view.ff->seconds;
    *actual = sol->view.mesh->element_count;
    rad_solution_destroy(sol);
    return s;
}

int main(int argc, char **argv)
{
    int threads = 2;
    size_t case_elements = 2000, cornell[2] = {1000, 4000};
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--elements") == 0 && i + 1 < argc)
            case_elements = (size_t)atol(argv[++i]);
        else if (strcmp(argv[i], "--cornell") == 0 && i + 1 < argc) {
            char *end;
            cornell[0] = (size_t)strtoul(argv[++i], &end, 10);
            if (*end != ',')
                usage();
            cornell[1] = (size_t)strtoul(end + 1, NULL, 10);
        } else
            usage();
    }
    rad_context_options co = {0};
    co.threads = threads;
    rad_context *ctx;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    rad_scene *scene;
    if (rad_scene_create_cornell_box(ctx, &scene) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    printf("form factors: relative error of F(A1 -> A2) at %zu elements (tests/data/cases.json), and\n"
           "seconds of the form-factor phase on the Cornell box; seed 0, defaults, %d threads\n",
           case_elements, rad_context_threads(ctx));
    printf("%-12s %10s %10s %12s %8s %8s\n", "method", "err_par", "err_perp", "err_occluded", "s@1k",
           "s@4k");
    size_t actual[2] = {0, 0};
    for (size_t m = 0; rad_ff_methods[m]; m++) {
        const char *name = rad_ff_methods[m]->name;
        double err[3], sec[2];
        for (int c = 0; c < 3; c++)
            err[c] = case_error(ctx, name, &cases[c], case_elements);
        for (int k = 0; k < 2; k++)
            sec[k] = cornell_seconds(ctx, scene, name, cornell[k], &actual[k]);
        printf("%-12s %10.2e %10.2e %12.2e %8.3f %8.3f\n", name, err[0], err[1], err[2], sec[0], sec[1]);
        fflush(stdout);
    }
    printf("(Cornell box: %zu and %zu elements)\n", actual[0], actual[1]);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
