/*
 * stats.c -- machine-readable results: the stats JSON (schema in
 * docs/stats.md) and surface-level view factors (JSON or CSV; docs/formats.md).
 * Both are written atomically (temporary file, then rename).
 */
#include "api/solution.h"

#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>

static cJSON *rgb_array(const double v[3])
{
    return cJSON_CreateDoubleArray(v, 3);
}

/* Write a cJSON tree atomically. */
static rad_result write_json(rad_context *ctx, cJSON *root, const char *path)
{
    char *text = root ? cJSON_Print(root) : NULL;
    if (!text)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory building JSON", path);
    rad_atomic_file f;
    rad_result r = rad_atomic_open(ctx, path, &f);
    if (r == RAD_OK) {
        fputs(text, f.file);
        fputc('\n', f.file);
        r = rad_atomic_commit(ctx, &f);
    }
    free(text);
    return r;
}

/* Area-weighted material figures of one surface, over its elements. */
static void surface_materials(const rad_solution *s, size_t surface, double rho[3], double E[3])
{
    double area = 0.0;
    for (int c = 0; c < 3; c++)
        rho[c] = E[c] = 0.0;
    for (size_t i = 0; i < s->mesh->element_count; i++) {
        if (s->mesh->elements[i].surface != surface)
            continue;
        area += s->area[i];
        for (int c = 0; c < 3; c++) {
            rho[c] += s->area[i] * s->reflectance[3 * i + c];
            E[c] += s->area[i] * s->emission[3 * i + c];
        }
    }
    for (int c = 0; c < 3; c++) {
        rho[c] = area > 0.0 ? rho[c] / area : 0.0;
        E[c] = area > 0.0 ? E[c] / area : 0.0;
    }
}

rad_result rad_solution_write_stats(rad_context *ctx, const rad_solution *s, const char *path,
                                    int partial)
{
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    size_t n = s->mesh->element_count;
    cJSON_AddStringToObject(root, "version", RAD_VERSION_STRING);
    cJSON_AddBoolToObject(root, "partial", partial != 0);
    cJSON_AddStringToObject(root, "scene", s->scene->source);
    cJSON_AddNumberToObject(root, "threads", rad_context_threads(ctx));
    cJSON_AddNumberToObject(root, "seed", (double)s->options.seed);

    cJSON *mesh = cJSON_AddObjectToObject(root, "mesh");
    cJSON_AddNumberToObject(mesh, "elements", (double)n);
    cJSON_AddNumberToObject(mesh, "patches", (double)s->mesh->patch_count);
    cJSON_AddNumberToObject(mesh, "vertices", (double)s->mesh->vertex_count);
    cJSON_AddNumberToObject(mesh, "t_vertices", (double)s->mesh->tvertex_count);
    cJSON_AddNumberToObject(mesh, "mesh_size_m", s->mesh->mesh_size);
    cJSON_AddNumberToObject(root, "elements", (double)n);

    cJSON *ff = cJSON_AddObjectToObject(root, "form_factors");
    cJSON_AddStringToObject(ff, "method", s->ff_stats.method ? s->ff_stats.method : "");
    cJSON_AddStringToObject(ff, "visibility", s->options.visibility);
    cJSON_AddNumberToObject(ff, "shadow_rays", s->options.shadow_rays);
    cJSON_AddNumberToObject(ff, "rays", (double)s->ff_stats.rays);
    cJSON_AddNumberToObject(ff, "pairs", (double)s->ff_stats.pairs);
    cJSON_AddNumberToObject(ff, "row_sum_min", s->ff_stats.row_sum_min);
    cJSON_AddNumberToObject(ff, "row_sum_max", s->ff_stats.row_sum_max);
    cJSON_AddNumberToObject(ff, "row_sum_mean", s->ff_stats.row_sum_mean);
    cJSON_AddNumberToObject(ff, "reciprocity_max", s->ff_stats.reciprocity_max);
    cJSON_AddNumberToObject(ff, "diagonal_max", s->ff_stats.diagonal_max);
    cJSON_AddNumberToObject(ff, "seconds", s->ff_stats.seconds);

    cJSON *so = cJSON_AddObjectToObject(root, "solver");
    cJSON_AddStringToObject(so, "method", s->options.solver);
    cJSON_AddBoolToObject(so, "solved", s->solved);
    cJSON_AddBoolToObject(so, "converged", s->solve_stats.converged);
    cJSON_AddNumberToObject(so, "iterations", s->solve_stats.iterations);
    cJSON_AddNumberToObject(so, "residual", s->solve_stats.residual);
    cJSON_AddNumberToObject(so, "tolerance", s->options.tolerance);
    cJSON_AddItemToObject(so, "ambient", rgb_array(s->solve_stats.ambient));
    cJSON_AddNumberToObject(so, "seconds", s->solve_stats.seconds);

    double emitted, absorbed;
    rad_solution_power(s, &emitted, &absorbed);
    cJSON *power = cJSON_AddObjectToObject(root, "power_W");
    cJSON_AddNumberToObject(power, "emitted", emitted);
    cJSON_AddNumberToObject(power, "absorbed", absorbed);
    cJSON_AddNumberToObject(power, "escaped", emitted - absorbed);

    cJSON *surfaces = cJSON_AddArrayToObject(root, "surfaces");
    for (size_t k = 0; k < s->scene->surface_count; k++) {
        cJSON *o = cJSON_CreateObject();
        double rho[3], E[3], B[3];
        surface_materials(s, k, rho, E);
        rad_solution_surface_radiosity(s, k, B);
        cJSON_AddStringToObject(o, "name", s->scene->surfaces[k].name);
        cJSON_AddNumberToObject(o, "area", s->scene->surfaces[k].area);
        cJSON_AddItemToObject(o, "reflectance", rgb_array(rho));
        cJSON_AddItemToObject(o, "emission", rgb_array(E));
        cJSON_AddItemToObject(o, "radiosity", rgb_array(B));
        cJSON_AddItemToArray(surfaces, o);
    }

    cJSON *sec = cJSON_AddObjectToObject(root, "seconds");
    cJSON_AddNumberToObject(sec, "load", s->seconds.load);
    cJSON_AddNumberToObject(sec, "mesh", s->seconds.mesh);
    cJSON_AddNumberToObject(sec, "visibility_build", s->seconds.visibility);
    cJSON_AddNumberToObject(sec, "form_factors", s->seconds.form_factors);
    cJSON_AddNumberToObject(sec, "solve", s->seconds.solve);
    cJSON_AddNumberToObject(sec, "render", s->seconds.render);

    cJSON *rays = cJSON_AddObjectToObject(root, "rays");
    cJSON_AddNumberToObject(rays, "form_factors", (double)s->ff_stats.rays);
    cJSON_AddNumberToObject(rays, "render", (double)s->render_rays);

    cJSON *mem = cJSON_AddObjectToObject(root, "memory_bytes");
    cJSON_AddNumberToObject(mem, "peak_resident", (double)rad_peak_memory_bytes());
    cJSON_AddNumberToObject(mem, "form_factor_matrix", (double)n * (double)n * sizeof(float));
    cJSON_AddNumberToObject(mem, "limit", s->options.max_memory_bytes);

    rad_result r = write_json(ctx, root, path);
    cJSON_Delete(root);
    return r;
}

rad_result rad_solution_write_view_factors(rad_context *ctx, const rad_solution *s, const char *path)
{
    size_t S = s->scene->surface_count;
    char ext[16];
    rad_path_extension(path, ext, sizeof ext);
    if (strcmp(ext, "json") != 0 && strcmp(ext, "csv") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: unknown view-factor format (use .json or .csv)", path);
    double *F = rad_alloc_array(ctx, S * S, sizeof *F, "view factors");
    if (!F)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_solution_surface_view_factors(s, F);
    rad_result r;
    if (strcmp(ext, "json") == 0) {
        cJSON *root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", s->scene->source);
        cJSON_AddStringToObject(root, "method", s->options.form_factors);
        cJSON_AddNumberToObject(root, "elements", (double)s->mesh->element_count);
        cJSON *surfaces = cJSON_AddArrayToObject(root, "surfaces");
        cJSON *rows = cJSON_AddArrayToObject(root, "F");
        for (size_t a = 0; a < S; a++) {
            double sum = 0.0;
            for (size_t b = 0; b < S; b++)
                sum += F[a * S + b];
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "name", s->scene->surfaces[a].name);
            cJSON_AddNumberToObject(o, "area", s->scene->surfaces[a].area);
            cJSON_AddNumberToObject(o, "row_sum", sum);
            cJSON_AddItemToArray(surfaces, o);
            cJSON_AddItemToArray(rows, cJSON_CreateDoubleArray(F + a * S, (int)S));
        }
        r = write_json(ctx, root, path);
        cJSON_Delete(root);
    } else {
        rad_atomic_file f;
        r = rad_atomic_open(ctx, path, &f);
        if (r == RAD_OK) {
            /* Header: from,area,<to names...>; one row per emitting surface. */
            fputs("from,area_m2", f.file);
            for (size_t b = 0; b < S; b++)
                fprintf(f.file, ",%s", s->scene->surfaces[b].name);
            fputc('\n', f.file);
            for (size_t a = 0; a < S; a++) {
                fprintf(f.file, "%s,%.17g", s->scene->surfaces[a].name, s->scene->surfaces[a].area);
                for (size_t b = 0; b < S; b++)
                    fprintf(f.file, ",%.17g", F[a * S + b]);
                fputc('\n', f.file);
            }
            r = rad_atomic_commit(ctx, &f);
        }
    }
    free(F);
    return r;
}
