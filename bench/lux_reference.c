/*
 * lux_reference.c -- a converged reference for the illuminance at a grid
 * file's points, made without elements, form factors or a solver: Monte
 * Carlo path tracing from each point (Kajiya 1986), the luminaires' light
 * by next-event estimation at every vertex.
 *
 *   E(x) = H_lum(x) + E_ind(x)
 *   E_ind(x) = integral over x's hemisphere of B(y(w)) cos / pi dw
 *   B(y) = E_y + rho_y (H_lum(y) + E_ind(y))
 *
 * H_lum is the light module's (light.h: the luminaires' photometry, their
 * openings near by, shadow rays; checked against closed forms in
 * tests/test_luminaires.c), the same at the points as `radiosity
 * illuminance` takes; the interreflection E_ind, where the solvers differ,
 * is estimated here by cosine-distributed directions (pdf cos / pi, so
 * each path's estimate is B at its first hit), continued from each hit by
 * another such direction with weight rho, ended by Russian roulette after
 * the first bounce (survival max rho).  Surfaces are one-sided as in the
 * engine: a back side is black.  The luminaires asked at a vertex are
 * those whose reach holds it (light/reach.c; what it leaves out is light
 * through gaps narrower than the fan's spacing), so a building costs its
 * rooms, not rooms x luminaires.  Unbiased save for that and the float
 * geometry; each point's standard error is printed with it.
 *
 *   lux_reference SCENE --luminaires LAYOUT.json --grid GRID.json -o OUT.json
 *                 [--paths N] [--threads T] [--seed S] [--gather SOLVER]
 *
 * --gather SOLVER solves the scene with SOLVER at its defaults and takes,
 * in place of each path, the radiosity of the element its first ray meets:
 * the points' interreflection from that solution without the engine's
 * gathering, so that a gap to the reference is told to be the solve's or
 * the gathering's.
 *
 * OUT.json: {"grids": [{"name", "E_avg_lux", "E_avg_stderr_lux",
 * "values": [{"E_lux", "stderr_lux"}, ...]}]}, the layout of `radiosity
 * illuminance -o X.json` (bench/office_lit.py reads both).  Deterministic:
 * each path's random numbers are keyed on (seed, point, path), whatever
 * the thread count.
 */
#include "api/solution.h"
#include "grid/grid.h"
#include "light/light.h"
#include "mesh/mesh.h"
#include "photometry/photometry.h"
#include "vis/vis.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_DEPTH = 64 };

static double luminance(const double c[3]) { return 0.265 * c[0] + 0.670 * c[1] + 0.065 * c[2]; }

static vec3 cosine_direction(vec3 n, rad_rng *rng)
{
    vec3 u, v;
    rad_tangent_frame(n, &u, &v);
    double a = 2.0 * M_PI * rad_rng_uniform(rng), r2 = rad_rng_uniform(rng), r = sqrt(r2);
    return v3_add(v3_add(v3_scale(u, r * cos(a)), v3_scale(v, r * sin(a))), v3_scale(n, sqrt(fmax(0.0, 1.0 - r2))));
}

typedef struct tracer {
    const rad_scene *scene;
    const rad_mesh *mesh;
    const rad_vis *vis;
    const rad_light_reach *reach;
    double eps;
} tracer;

/* One path's estimate of E_ind at x (normal n), W/m^2 per channel. */
static void path(const tracer *t, vec3 x, vec3 n, rad_rng *rng, double out[3])
{
    double weight[3] = {1.0, 1.0, 1.0};
    out[0] = out[1] = out[2] = 0.0;
    rad_light_among reached = {NULL, 0, t->reach};
    for (int depth = 0; depth < MAX_DEPTH; depth++) {
        rad_ray ray = {v3_mad(x, n, t->eps), cosine_direction(n, rng), 0.0, INFINITY};
        rad_hit hit;
        t->vis->backend->intersect(t->vis->state, &ray, 1, &hit);
        if (!isfinite(hit.t))
            return;
        const rad_patch *p = &t->mesh->patches[hit.patch];
        if (v3_dot(p->normal, ray.direction) >= 0.0)
            return; /* a back side: black */
        const rad_material *m = &t->scene->materials[p->material];
        vec3 y = v3_mad(ray.origin, ray.direction, hit.t);
        double H[3];
        rad_light_irradiance_among(t->scene, t->mesh, t->vis, y, p->normal, &reached, H);
        for (int c = 0; c < 3; c++)
            out[c] += weight[c] * (m->emission[c] + m->reflectance[c] * H[c]);
        /* On: weight rho, past the first bounce by roulette. */
        double survive = 1.0;
        if (depth > 0) {
            survive = fmax(m->reflectance[0], fmax(m->reflectance[1], m->reflectance[2]));
            if (!(rad_rng_uniform(rng) < survive))
                return;
        }
        for (int c = 0; c < 3; c++)
            weight[c] *= m->reflectance[c] / survive;
        x = y;
        n = p->normal;
    }
}

static char *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = malloc((size_t)len + 1);
    if (text && fread(text, 1, (size_t)len, f) != (size_t)len) {
        free(text);
        text = NULL;
    }
    fclose(f);
    if (text)
        text[len] = '\0';
    *size = (size_t)len;
    return text;
}

static void usage(void)
{
    fprintf(stderr, "usage: lux_reference SCENE --luminaires LAYOUT.json --grid GRID.json -o OUT.json "
                    "[--paths N] [--threads T] [--seed S] [--gather SOLVER]\n");
    exit(2);
}

/* --gather SOLVER: one bounce from a solution instead of the paths: E_ind
 * = the mean of the B of the element each cosine ray first meets (the
 * solver's own radiosities, no rays of its gathering): tells the
 * gathering's error from the solve's. */
static double gather_solution(const rad_solution_view *v, const tracer *t, vec3 x, vec3 n, rad_rng *rng)
{
    rad_ray ray = {v3_mad(x, n, t->eps), cosine_direction(n, rng), 0.0, INFINITY};
    rad_hit hit;
    t->vis->backend->intersect(t->vis->state, &ray, 1, &hit);
    uint32_t e = rad_vis_front_element(v->mesh, &ray, &hit);
    return e == UINT32_MAX ? 0.0 : luminance(v->radiosity + 3 * (size_t)e);
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *layout = NULL, *grid_path = NULL, *out_path = NULL;
    long paths = 4096;
    int threads = 0;
    uint64_t seed = 1;
    const char *gather = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--gather") == 0 && i + 1 < argc) {
            gather = argv[++i];
            continue;
        }
        if (strcmp(argv[i], "--luminaires") == 0 && i + 1 < argc)
            layout = argv[++i];
        else if (strcmp(argv[i], "--grid") == 0 && i + 1 < argc)
            grid_path = argv[++i];
        else if (strcmp(argv[i], "-o") == 0 && i + 1 < argc)
            out_path = argv[++i];
        else if (strcmp(argv[i], "--paths") == 0 && i + 1 < argc)
            paths = atol(argv[++i]);
        else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc)
            seed = strtoull(argv[++i], NULL, 10);
        else if (argv[i][0] != '-' && !scene_path)
            scene_path = argv[i];
        else
            usage();
    }
    if (!scene_path || !grid_path || !out_path || paths < 1)
        usage();
    rad_context_options co = {.threads = threads};
    rad_context *ctx = NULL;
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_vis *vis = NULL;
    rad_light_reach *reach = NULL;
    rad_grid_set *set = NULL;
    size_t size = 0;
    char *text = read_all(grid_path, &size);
    if (!text) {
        fprintf(stderr, "lux_reference: cannot read %s\n", grid_path);
        return 1;
    }
    /* One element a patch: the mesh only carries the patches for the rays. */
    rad_mesh_options mo = {.mesh_size = 1e9};
    if (rad_context_create(&co, &ctx) != RAD_OK || rad_scene_load_file(ctx, scene_path, &scene) != RAD_OK ||
        (layout && rad_scene_load_luminaires(ctx, scene, layout) != RAD_OK) ||
        rad_mesh_build(ctx, scene, &mo, &mesh) != RAD_OK || rad_vis_create(ctx, "embree", mesh, &vis) != RAD_OK ||
        rad_light_reach_build(ctx, scene, mesh, vis, rad_context_threads(ctx), &reach) != RAD_OK ||
        rad_grid_parse(ctx, scene, grid_path, text, size, &set) != RAD_OK) {
        fprintf(stderr, "lux_reference: %s\n", ctx ? rad_context_error(ctx) : "no context");
        return 1;
    }
    free(text);
    rad_solution *sol = NULL;
    if (gather) {
        rad_options o = {.solver = gather};
        if (rad_solution_create(ctx, scene, &o, &sol) != RAD_OK || rad_solution_solve(ctx, sol) != RAD_OK) {
            fprintf(stderr, "lux_reference: %s\n", rad_context_error(ctx));
            return 1;
        }
    }
    tracer t = {scene, sol ? sol->view.mesh : mesh, sol ? sol->view.vis : vis, reach,
                rad_vis_epsilon(sol ? sol->view.mesh : mesh)};
    size_t n = set->point_count;
    double *E = calloc(n + 1, sizeof *E), *se = calloc(n + 1, sizeof *se);
    double t0 = rad_seconds();
#pragma omp parallel for schedule(dynamic, 1) num_threads(rad_context_threads(ctx))
    for (size_t k = 0; k < n; k++) {
        vec3 x = set->position[k], nx = set->normal[k];
        double H[3];
        rad_light_irradiance_among(scene, mesh, vis, x, nx, &(rad_light_among){NULL, 0, reach}, H);
        double sum = 0.0, sum2 = 0.0;
        for (long s = 0; s < paths; s++) {
            rad_rng rng = rad_rng_keyed(seed, k, (uint64_t)s);
            double ind[3], y;
            if (sol) {
                y = gather_solution(&sol->view, &t, x, nx, &rng);
            } else {
                path(&t, x, nx, &rng, ind);
                y = luminance(ind);
            }
            sum += y;
            sum2 += y * y;
        }
        double mean = sum / (double)paths, var = fmax(0.0, sum2 / (double)paths - mean * mean);
        E[k] = RAD_LUMINOUS_EFFICACY * (luminance(H) + mean);
        se[k] = RAD_LUMINOUS_EFFICACY * sqrt(var / (double)paths);
    }
    double seconds = rad_seconds() - t0;
    FILE *f = fopen(out_path, "w");
    if (!f) {
        fprintf(stderr, "lux_reference: cannot write %s\n", out_path);
        return 1;
    }
    fprintf(f, "{\"paths\": %ld, \"seed\": %llu, \"seconds\": %.3f, \"grids\": [", paths, (unsigned long long)seed,
            seconds);
    for (size_t g = 0; g < set->grid_count; g++) {
        const rad_grid_def *d = &set->grids[g];
        double avg = 0.0, var = 0.0;
        for (size_t i = 0; i < d->point_count; i++) {
            avg += E[d->first_point + i];
            var += se[d->first_point + i] * se[d->first_point + i];
        }
        double m = d->point_count ? (double)d->point_count : 1.0;
        fprintf(f, "%s\n {\"name\": \"%s\", \"E_avg_lux\": %.6f, \"E_avg_stderr_lux\": %.6f, \"values\": [",
                g ? "," : "", d->name, avg / m, sqrt(var) / m);
        for (size_t i = 0; i < d->point_count; i++)
            fprintf(f, "%s{\"E_lux\": %.6f, \"stderr_lux\": %.6f}", i ? ", " : "", E[d->first_point + i],
                    se[d->first_point + i]);
        fprintf(f, "]}");
    }
    fprintf(f, "\n]}\n");
    fclose(f);
    printf("lux_reference: %zu points, %ld paths each, %.1f s\n", n, paths, seconds);
    free(E);
    free(se);
    rad_solution_destroy(sol);
    rad_grid_set_destroy(set);
    rad_light_reach_destroy(reach);
    rad_vis_destroy(vis);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
