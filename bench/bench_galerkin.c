/*
 * bench_galerkin.c -- error against unknowns for the galerkin strategy's
 * three solvers (galerkin-constant, galerkin-linear, collocation), and the
 * time each takes; the measured orders go to docs/ (bench/plot_galerkin.py
 * draws them).
 *
 *   floor   a unit square floor (or, with `triangle`, the triangle (0,0),
 *           (1,0), (0,1)), rho = 0.5, under a 0.2 m square emitter (E = 1
 *           W/m^2, rho = 0) 0.5 m above its middle.  The floor sees only
 *           the emitter, so B(x) = rho E F(x -> emitter), exactly (the
 *           point-to-polygon factor, Lambert's formula): the error is the
 *           relative L2 norm of B_h - B over the floor, by an 8 x 8 midpoint
 *           rule in every element, with B_h as the basis interpolates it.
 *   cornell the built-in Cornell box against tests/data/cornell_converged
 *           .json: the area-weighted mean over surfaces and channels of
 *           |B_s - B_ref| / B_ref (surface means).
 *
 * Usage: bench_galerkin floor|triangle|cornell [threads]
 * Prints one line per (method, mesh): unknowns, error, seconds, and the
 * element size used (m).
 */
#include "strategy/strategy.h"
#include "strategy/options.h"
#include "interp/interp.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static rad_context *ctx;

static rad_scene *floor_scene(bool triangle)
{
    rad_scene_builder *b = rad_scene_builder_create(ctx, triangle ? "triangle floor" : "floor");
    double rho[3] = {0.5, 0.5, 0.5}, none[3] = {0, 0, 0}, E[3] = {1, 1, 1};
    int floor_m = rad_scene_builder_material(b, "floor", rho, none);
    int light_m = rad_scene_builder_material(b, "light", none, E);
    int floor_s = rad_scene_builder_surface(b, "floor"), light_s = rad_scene_builder_surface(b, "light");
    const vec3 square[4] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}; /* normal +y */
    const vec3 tri[3] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}};
    const vec3 light[4] = {{0.4, 0.5, 0.4}, {0.6, 0.5, 0.4}, {0.6, 0.5, 0.6}, {0.4, 0.5, 0.6}}; /* normal -y */
    if (triangle)
        rad_scene_builder_polygon(b, floor_s, floor_m, tri, 3, 0);
    else
        rad_scene_builder_polygon(b, floor_s, floor_m, square, 4, 0);
    rad_scene_builder_polygon(b, light_s, light_m, light, 4, 0);
    rad_scene *scene = NULL;
    if (rad_scene_builder_finish(b, &scene) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        exit(1);
    }
    return scene;
}

/* Relative L2 error of the floor's B_h against rho E F(x -> light). */
static double floor_error(const rad_solution_view *v, const double *vertex_value)
{
    const rad_mesh *mesh = v->mesh;
    const vec3 light[4] = {{0.4, 0.5, 0.4}, {0.6, 0.5, 0.4}, {0.6, 0.5, 0.6}, {0.4, 0.5, 0.6}};
    enum { S = 8 };
    double err2 = 0.0, ref2 = 0.0;
    for (size_t e = 0; e < mesh->element_count; e++) {
        const rad_element *el = &mesh->elements[e];
        if (el->surface != 0)
            continue;
        vec3 c[4];
        for (uint32_t k = 0; k < el->vertex_count; k++)
            c[k] = mesh->vertices[el->vertex[k]];
        for (int a = 0; a < S; a++)
            for (int b = 0; b < S; b++) {
                double s = (a + 0.5) / S, t = (b + 0.5) / S, w;
                vec3 x;
                if (el->vertex_count == 3) {
                    if (s + t > 1.0) /* the cells above the diagonal, folded */
                        s = 1.0 - s, t = 1.0 - t;
                    x = v3_add(c[0], v3_add(v3_scale(v3_sub(c[1], c[0]), s), v3_scale(v3_sub(c[2], c[0]), t)));
                    w = el->area / (S * S);
                } else {
                    x = v3_add(v3_add(v3_scale(c[0], (1 - s) * (1 - t)), v3_scale(c[1], s * (1 - t))),
                               v3_add(v3_scale(c[2], s * t), v3_scale(c[3], (1 - s) * t)));
                    w = el->area / (S * S); /* the grid's cells are parallelograms */
                }
                double exact = 0.5 * rad_point_polygon_ff(x, el->normal, light, 4), rgb[3];
                if (vertex_value)
                    rad_element_interpolate(mesh, el, vertex_value, s, t, rgb);
                else
                    rgb[0] = v->radiosity[3 * e];
                err2 += w * (rgb[0] - exact) * (rgb[0] - exact);
                ref2 += w * exact * exact;
            }
    }
    return sqrt(err2 / ref2);
}

static cJSON *reference;

static double cornell_error(const rad_solution_view *v)
{
    const cJSON *surfaces = cJSON_GetObjectItem(reference, "surfaces");
    double err = 0.0, total = 0.0;
    for (size_t s = 0; s < v->scene->surface_count; s++) {
        const char *name = v->scene->surfaces[s].name;
        const cJSON *ref = NULL, *item;
        cJSON_ArrayForEach(item, surfaces)
            if (strcmp(cJSON_GetObjectItem(item, "name")->valuestring, name) == 0)
                ref = cJSON_GetObjectItem(item, "radiosity");
        if (!ref || strcmp(name, "light") == 0) /* the emitter: E plus a little */
            continue;
        double area = 0.0, rgb[3];
        for (size_t e = 0; e < v->n; e++)
            if (v->mesh->elements[e].surface == s)
                area += v->area[e];
        rad_view_surface_radiosity(v, s, rgb);
        for (int c = 0; c < 3; c++) {
            double r = cJSON_GetArrayItem(ref, c)->valuedouble;
            err += area * fabs(rgb[c] - r) / r;
            total += area;
        }
    }
    return err / total;
}

int main(int argc, char **argv)
{
    const char *which = argc > 1 ? argv[1] : "floor";
    int threads = argc > 2 ? atoi(argv[2]) : 1;
    rad_context_options co = {.threads = threads};
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    bool cornell = strcmp(which, "cornell") == 0;
    rad_scene *scene = NULL;
    if (cornell) {
        rad_scene_create_cornell_box(ctx, &scene);
        FILE *f = fopen(RAD_BENCH_DATA "/cornell_converged.json", "rb");
        static char text[1 << 20];
        size_t size = f ? fread(text, 1, sizeof text - 1, f) : 0;
        if (f)
            fclose(f);
        text[size] = 0;
        reference = cJSON_Parse(text);
        if (!reference) {
            fprintf(stderr, "bench_galerkin: cannot read %s/cornell_converged.json\n", RAD_BENCH_DATA);
            return 1;
        }
    } else {
        scene = floor_scene(strcmp(which, "triangle") == 0);
    }
    const char *methods[3] = {"galerkin-constant", "galerkin-linear", "collocation"};
    const double sizes[] = {0.5, 0.25, 0.125, 0.0625, 0.03125};
    const size_t counts[] = {50, 100, 200, 400, 800};
    printf("# %s: method unknowns error seconds h\n", which);
    for (int m = 0; m < 3; m++)
        for (int k = 0; k < 5; k++) {
            rad_options in = {0}, o;
            rad_method_names names;
            in.solver = methods[m];
            in.tolerance = 1e-10;
            if (cornell)
                in.target_elements = counts[k];
            else
                in.mesh_size = sizes[k];
            if (rad_options_resolve(ctx, &in, &o, &names) != RAD_OK)
                return 1;
            double t0 = rad_seconds();
            void *state = NULL;
            rad_step_hook hook = {0};
            if (rad_strategy_galerkin.create(ctx, scene, &o, &state) != RAD_OK ||
                rad_strategy_galerkin.solve(ctx, state, &hook) != RAD_OK) {
                fprintf(stderr, "%s\n", rad_context_error(ctx));
                return 1;
            }
            double seconds = rad_seconds() - t0;
            rad_solution_view v = {0};
            rad_strategy_galerkin.view(state, &v);
            v.scene = scene;
            rad_galerkin_matrices g;
            rad_galerkin_get_matrices(state, &g);
            double error = cornell ? cornell_error(&v) : floor_error(&v, v.vertex_radiosity);
            printf("%s %zu %.6e %.3f %.6g\n", methods[m], g.unknowns, error, seconds, v.mesh->mesh_size);
            fflush(stdout);
            rad_strategy_galerkin.destroy(state);
        }
    cJSON_Delete(reference);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
