/*
 * bench_adaptive.c -- adaptive subdivision against uniform meshes
 * (docs/methods.md, "Adaptive subdivision"):
 *
 *   1. the sharp shadow of tests/data/plate_shadow.obj: elements, seconds
 *      and the floor's error (RMS and max, relative to its brightest
 *      value) against its closed form (direct light only: rho E times the
 *      factor to the part of the light the plate leaves visible) at the
 *      centres of a 128 x 128 grid, read as element values and as smooth
 *      shading, for uniform meshes and for adaptive ones from a 0.125 m
 *      mesh at several levels, thresholds and budgets;
 *   2. the default Cornell box (2,000 elements), uniform and adaptive
 *      (3 levels, default threshold and budget): elements, rounds, seconds
 *      of form factors and in all, and the worst per-surface error
 *      against the uniform 16k-element solution.
 *
 *   ./build/bench/bench_adaptive [--threads N] [--shadow-only]
 *
 * Fixed scenes and options: the counts are reproducible, the seconds are
 * this machine's.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/solution.h"

static rad_context *ctx;

static size_t surface_named(const rad_scene *scene, const char *name)
{
    for (size_t k = 0; k < scene->surface_count; k++)
        if (strcmp(scene->surfaces[k].name, name) == 0)
            return k;
    return SIZE_MAX;
}

/* The value of the element of s holding point p of surface `surface`. */
static double flat_value(const rad_solution *s, size_t surface, vec3 p)
{
    const rad_mesh *mesh = s->view.mesh;
    for (uint32_t k = 0; k < mesh->patch_count; k++) {
        if (mesh->patches[k].surface != surface)
            continue;
        double u, v, ls, lt;
        rad_patch_parameters(&mesh->patches[k], p, &u, &v);
        return s->view.radiosity[3 * (size_t)rad_mesh_locate(mesh, k, u, v, &ls, &lt)];
    }
    return NAN;
}

/* The factor from a floor point to the rectangle [x0, x1] x [y0, y1] at
 * height c above it, parallel to the floor: the corner formula (Howell's
 * catalogue, case B-3) G(X, Y) = (X / sqrt(1 + X^2) atan(Y / sqrt(1 + X^2))
 * + Y / sqrt(1 + Y^2) atan(X / sqrt(1 + Y^2))) / (2 pi), odd in X and Y, so
 * any rectangle is four signed corners. */
static double corner_factor(double X, double Y)
{
    double a = sqrt(1.0 + X * X), b = sqrt(1.0 + Y * Y);
    return (X / a * atan(Y / a) + Y / b * atan(X / b)) / (2.0 * M_PI);
}

static double rectangle_factor(double x0, double x1, double y0, double y1, double c)
{
    if (!(x1 > x0 && y1 > y0))
        return 0.0;
    return corner_factor(x1 / c, y1 / c) - corner_factor(x0 / c, y1 / c) - corner_factor(x1 / c, y0 / c) +
           corner_factor(x0 / c, y0 / c);
}

/* The exact floor radiosity of plate_shadow.obj at (x, y): direct light
 * only, rho E times the factor to the light less the part the plate
 * hides (the plate seen from (x, y) covers, in the light's plane, the
 * plate's square scaled by 1.5 / (1.5 - 0.5) about the point). */
static double exact_floor(double x, double y)
{
    const double L = 0.05, P = 0.3, zl = 1.5, zp = 0.5, k = zl / zp;
    double sx0 = x + k * (-P - x), sx1 = x + k * (P - x), sy0 = y + k * (-P - y), sy1 = y + k * (P - y);
    double F = rectangle_factor(-L - x, L - x, -L - y, L - y, zl);
    F -= rectangle_factor(fmax(-L, sx0) - x, fmin(L, sx1) - x, fmax(-L, sy0) - y, fmin(L, sy1) - y, zl);
    return 0.5 * 40.0 * M_PI * F;
}

/* RMS and max of s's floor against the exact one, at the centres of a
 * 128 x 128 grid on it, relative to its brightest value: s's element values
 * (flat), or s's smooth shading (rad_solution_point_radiosity). */
static void floor_error(rad_solution *s, bool smooth, double *rms, double *max)
{
    size_t floor = surface_named(s->scene, "floor");
    const int N = 128;
    double top = 0.0, sum = 0.0, worst = 0.0;
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++)
            top = fmax(top, exact_floor(-1.0 + (i + 0.5) * 2.0 / N, -1.0 + (j + 0.5) * 2.0 / N));
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            vec3 p = {-1.0 + (i + 0.5) * 2.0 / N, -1.0 + (j + 0.5) * 2.0 / N, 0.0};
            double value = flat_value(s, floor, p);
            if (smooth) {
                double q[3] = {p.x, p.y, p.z}, rgb[3];
                rad_solution_point_radiosity(ctx, s, floor, q, rgb);
                value = rgb[0];
            }
            double d = value - exact_floor(p.x, p.y);
            sum += d * d;
            worst = fmax(worst, fabs(d));
        }
    *rms = sqrt(sum / (N * N)) / top;
    *max = worst / top;
}

static rad_solution *solve(const rad_scene *scene, rad_options o, double *seconds)
{
    double t = rad_seconds();
    rad_solution *s = NULL;
    if (rad_solution_create(ctx, scene, &o, &s) != RAD_OK || rad_solution_solve(ctx, s) != RAD_OK) {
        fprintf(stderr, "bench_adaptive: %s\n", rad_context_error(ctx));
        exit(1);
    }
    *seconds = rad_seconds() - t;
    return s;
}

static void row(const char *what, rad_solution *s, double seconds)
{
    double rms, max, rms_smooth, max_smooth;
    floor_error(s, false, &rms, &max);
    floor_error(s, true, &rms_smooth, &max_smooth);
    const rad_adaptive_stats *a = s->view.adaptive;
    printf("%-36s %7zu %6d %8.4f %8.4f %9.4f %9.4f %8.3f\n", what, s->view.n, a ? a->rounds : 0, rms, max,
           rms_smooth, max_smooth, seconds);
}

/* `radiosity render --elements 16000 --stats s.json` (tests/test_hier.c). */
static const struct {
    const char *name;
    double B[3];
} CORNELL_16K[] = {
    {"floor", {0.341265, 0.230563, 0.054476}},       {"ceiling", {0.296770, 0.189049, 0.040970}},
    {"back_wall", {0.516638, 0.345292, 0.081467}},   {"right_wall", {0.067887, 0.204937, 0.010718}},
    {"left_wall", {0.320233, 0.020442, 0.005289}},   {"short_block", {0.340573, 0.245550, 0.055724}},
    {"tall_block", {0.482032, 0.297611, 0.072377}},
};

static double cornell_error(const rad_solution *s)
{
    double worst = 0.0;
    for (size_t i = 0; i < sizeof CORNELL_16K / sizeof CORNELL_16K[0]; i++) {
        size_t k = surface_named(s->scene, CORNELL_16K[i].name);
        double B[3];
        rad_solution_surface_radiosity(s, k, B);
        for (int c = 0; c < 3; c++)
            worst = fmax(worst, fabs(B[c] - CORNELL_16K[i].B[c]) / CORNELL_16K[i].B[c]);
    }
    return worst;
}

int main(int argc, char **argv)
{
    rad_context_options co = {0};
    bool shadow_only = false;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            co.threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--shadow-only") == 0)
            shadow_only = true;
    }
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    rad_scene *scene = NULL;
    if (rad_scene_load_file(ctx, RAD_BENCH_DATA "/plate_shadow.obj", &scene) != RAD_OK) {
        fprintf(stderr, "bench_adaptive: %s\n", rad_context_error(ctx));
        return 1;
    }
    double t;
    printf("plate_shadow.obj: the floor against its closed form at the centres of a 128 x 128 grid\n"
           "(element values; smooth: vertex-interpolated), relative to its brightest value\n");
    printf("%-36s %7s %6s %8s %8s %9s %9s %8s\n", "mesh", "elems", "rounds", "rms", "max", "rms sm", "max sm",
           "seconds");
    const double sizes[] = {0.125, 0.0625, 0.05, 0.04, 0.03};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        rad_solution *s = solve(scene, (rad_options){.mesh_size = sizes[k]}, &t);
        char what[64];
        snprintf(what, sizeof what, "uniform %.4g m", sizes[k]);
        row(what, s, t);
        rad_solution_destroy(s);
    }
    const struct {
        int levels;
        double threshold;
        size_t budget;
    } runs[] = {{2, 0.1, 0}, {3, 0.05, 0}, {3, 0.1, 0}, {3, 0.2, 0}, {3, 0.1, 100000}, {4, 0.1, 0}, {4, 0.1, 100000}};
    for (size_t k = 0; k < sizeof runs / sizeof runs[0]; k++) {
        rad_options o = {.mesh_size = 0.125, .adaptive_levels = runs[k].levels,
                         .adaptive_threshold = runs[k].threshold, .adaptive_max_elements = runs[k].budget};
        rad_solution *s = solve(scene, o, &t);
        char what[64];
        snprintf(what, sizeof what, "0.125 m, %d levels, %.2g, %s", runs[k].levels, runs[k].threshold,
                 runs[k].budget ? "no budget" : "4x budget");
        row(what, s, t);
        rad_solution_destroy(s);
    }
    rad_scene_destroy(scene);

    if (shadow_only)
        return 0;
    if (rad_scene_create_cornell_box(ctx, &scene) != RAD_OK) {
        fprintf(stderr, "bench_adaptive: %s\n", rad_context_error(ctx));
        return 1;
    }
    printf("\nCornell box, 2,000 elements to start: worst per-surface error against 16k uniform\n");
    printf("%-36s %7s %6s %8s %8s %8s\n", "mesh", "elems", "rounds", "surface", "ff s", "seconds");
    for (int levels = 0; levels <= 3; levels += 3) {
        rad_solution *s = solve(scene, (rad_options){.adaptive_levels = levels}, &t);
        printf("%-36s %7zu %6d %8.4f %8.3f %8.3f\n", levels ? "adaptive 3 levels, defaults" : "uniform",
               s->view.n, s->view.adaptive ? s->view.adaptive->rounds : 0, cornell_error(s),
               s->view.seconds.form_factors, t);
        rad_solution_destroy(s);
    }
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
