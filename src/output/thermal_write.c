/*
 * thermal_write.c -- the heat exchange's figures and Gebhart factors as CSV
 * or JSON (docs/thermal.md), atomically, names carried as stats.c carries
 * them (valid UTF-8; CSV fields quoted per RFC 4180, JSON by cJSON).
 */
#include "output/output.h"
#include "thermal/thermal.h"

#include <cjson/cJSON.h>
#include <string.h>

static const char *condition_name(rad_thermal_condition c)
{
    switch (c) {
    case RAD_THERMAL_TEMPERATURE: return "temperature";
    case RAD_THERMAL_HEAT_FLUX: return "heat_flux";
    case RAD_THERMAL_ADIABATIC: return "adiabatic";
    case RAD_THERMAL_OBSTRUCTION: return "obstruction";
    case RAD_THERMAL_UNSET: break;
    }
    return "none";
}

/* The columns after the names, in CSV and JSON alike. */
static const char *const COLUMNS[] = {"area_m2", "emissivity", "temperature_K", "radiosity_W_m2",
                                      "irradiation_W_m2", "heat_flux_W_m2", "heat_W"};
enum { COLUMN_COUNT = sizeof COLUMNS / sizeof COLUMNS[0] };

static void columns_of(const rad_thermal_values *v, double out[COLUMN_COUNT])
{
    out[0] = v->area, out[1] = v->emissivity, out[2] = v->temperature, out[3] = v->radiosity;
    out[4] = v->irradiation, out[5] = v->heat_flux, out[6] = v->heat;
}

/* Each surface's name as valid UTF-8 (S strings, rad_free each and the
 * array); NULL when out of memory. */
static char **clean_names(rad_context *ctx, const rad_scene *scene)
{
    size_t S = scene->surface_count;
    char **names = rad_alloc(ctx, RAD_MEM_OUTPUT, S ? S : 1, sizeof *names, "outputs: names");
    for (size_t k = 0; names && k < S; k++) {
        names[k] = rad_utf8_clean(ctx, scene->surfaces[k].name);
        if (!names[k]) {
            for (size_t j = 0; j < k; j++)
                rad_free(names[j]);
            rad_free(names);
            names = NULL;
        }
    }
    return names;
}

static void free_names(char **names, size_t S)
{
    for (size_t k = 0; names && k < S; k++)
        rad_free(names[k]);
    rad_free(names);
}

static cJSON *values_object(const char *name, const rad_thermal_values *v)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "name", name);
    cJSON_AddStringToObject(o, "condition", condition_name(v->condition));
    double c[COLUMN_COUNT];
    columns_of(v, c);
    for (int k = 0; k < COLUMN_COUNT; k++)
        cJSON_AddNumberToObject(o, COLUMNS[k], c[k]);
    return o;
}

static rad_result write_thermal_json(rad_context *ctx, const rad_thermal *t, const char *path, bool elements,
                                     char **names)
{
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    char *scene = rad_utf8_clean(ctx, t->scene->source ? t->scene->source : "");
    if (!scene) {
        cJSON_Delete(root);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    cJSON_AddStringToObject(root, "scene", scene);
    rad_free(scene);
    cJSON_AddNumberToObject(root, "sigma_W_m2_K4", RAD_SIGMA);
    cJSON_AddNumberToObject(root, "environment_temperature_K", t->sys.environment_temperature);
    cJSON_AddStringToObject(root, "solver", t->solver->name);
    cJSON_AddNumberToObject(root, "residual", t->stats.residual);
    cJSON_AddNumberToObject(root, "elements", (double)t->sys.n);
    cJSON *b = cJSON_AddObjectToObject(root, "balance");
    cJSON_AddNumberToObject(b, "net_power_W", t->balance.net_power);
    cJSON_AddNumberToObject(b, "environment_power_W", t->balance.environment_power);
    cJSON_AddNumberToObject(b, "imbalance_W", t->balance.imbalance);
    cJSON_AddNumberToObject(b, "power_scale_W", t->balance.power_scale);
    cJSON_AddNumberToObject(b, "relative_imbalance", t->balance.relative_imbalance);
    cJSON *surfaces = cJSON_AddArrayToObject(root, "surfaces");
    for (size_t k = 0; k < t->scene->surface_count; k++)
        cJSON_AddItemToArray(surfaces, values_object(names[k], &t->surfaces[k]));
    if (elements) {
        cJSON *list = cJSON_AddArrayToObject(root, "elements_list");
        for (size_t i = 0; i < t->sys.n; i++) {
            rad_thermal_values v;
            rad_thermal_element_values(t, i, &v);
            cJSON *o = values_object(names[t->surface[i]], &v);
            const rad_element *e = &t->mesh->elements[i];
            double xyz[3] = {e->centroid.x, e->centroid.y, e->centroid.z};
            cJSON_AddItemToObject(o, "centroid_m", cJSON_CreateDoubleArray(xyz, 3));
            cJSON_AddItemToArray(list, o);
        }
    }
    rad_result r = rad_write_json(ctx, root, path);
    cJSON_Delete(root);
    return r;
}

static void csv_row(FILE *f, const rad_thermal_values *v)
{
    fprintf(f, ",%s", condition_name(v->condition));
    double c[COLUMN_COUNT];
    columns_of(v, c);
    for (int k = 0; k < COLUMN_COUNT; k++)
        fprintf(f, ",%.17g", c[k]);
    fputc('\n', f);
}

rad_result rad_write_thermal(rad_context *ctx, const rad_thermal *t, const char *path, bool elements)
{
    char ext[16];
    rad_path_extension(path, ext, sizeof ext);
    if (strcmp(ext, "json") != 0 && strcmp(ext, "csv") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: unknown heat-exchange format (use .csv or .json)",
                        path);
    size_t S = t->scene->surface_count;
    char **names = clean_names(ctx, t->scene);
    if (!names)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r;
    if (strcmp(ext, "json") == 0) {
        r = write_thermal_json(ctx, t, path, elements, names);
    } else {
        rad_atomic_file f;
        r = rad_atomic_open(ctx, path, &f);
        if (r == RAD_OK) {
            fputs(elements ? "element,surface,x_m,y_m,z_m,condition" : "surface,condition", f.file);
            for (int k = 0; k < COLUMN_COUNT; k++)
                fprintf(f.file, ",%s", COLUMNS[k]);
            fputc('\n', f.file);
            if (elements) {
                for (size_t i = 0; i < t->sys.n; i++) {
                    rad_thermal_values v;
                    rad_thermal_element_values(t, i, &v);
                    const rad_element *e = &t->mesh->elements[i];
                    fprintf(f.file, "%zu,", i);
                    rad_csv_field(f.file, names[t->surface[i]]);
                    fprintf(f.file, ",%.17g,%.17g,%.17g", e->centroid.x, e->centroid.y, e->centroid.z);
                    csv_row(f.file, &v);
                }
            } else {
                for (size_t k = 0; k < S; k++) {
                    rad_csv_field(f.file, names[k]);
                    csv_row(f.file, &t->surfaces[k]);
                }
            }
            r = rad_atomic_commit(ctx, &f);
        }
    }
    free_names(names, S);
    return r;
}

rad_result rad_write_gebhart(rad_context *ctx, const rad_thermal *t, const double *G, const char *path)
{
    char ext[16];
    rad_path_extension(path, ext, sizeof ext);
    if (strcmp(ext, "json") != 0 && strcmp(ext, "csv") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: unknown Gebhart-factor format (use .csv or .json)",
                        path);
    size_t S = t->scene->surface_count;
    char **names = clean_names(ctx, t->scene);
    if (!names)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r;
    if (strcmp(ext, "json") == 0) {
        cJSON *root = cJSON_CreateObject();
        cJSON *list = cJSON_AddArrayToObject(root, "surfaces");
        cJSON *rows = cJSON_AddArrayToObject(root, "G");
        for (size_t k = 0; k < S; k++) {
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "name", names[k]);
            cJSON_AddNumberToObject(o, "area_m2", t->surfaces[k].area);
            cJSON_AddNumberToObject(o, "emissivity", t->surfaces[k].emissivity);
            double sum = 0.0;
            for (size_t j = 0; j < S; j++)
                sum += G[k * S + j];
            cJSON_AddNumberToObject(o, "row_sum", sum);
            cJSON_AddItemToArray(list, o);
            cJSON_AddItemToArray(rows, cJSON_CreateDoubleArray(G + k * S, (int)S));
        }
        r = rad_write_json(ctx, root, path);
        cJSON_Delete(root);
    } else {
        rad_atomic_file f;
        r = rad_atomic_open(ctx, path, &f);
        if (r == RAD_OK) {
            fputs("from,area_m2,emissivity", f.file);
            for (size_t k = 0; k < S; k++) {
                fputc(',', f.file);
                rad_csv_field(f.file, names[k]);
            }
            fputc('\n', f.file);
            for (size_t k = 0; k < S; k++) {
                rad_csv_field(f.file, names[k]);
                fprintf(f.file, ",%.17g,%.17g", t->surfaces[k].area, t->surfaces[k].emissivity);
                for (size_t j = 0; j < S; j++)
                    fprintf(f.file, ",%.17g", G[k * S + j]);
                fputc('\n', f.file);
            }
            r = rad_atomic_commit(ctx, &f);
        }
    }
    free_names(names, S);
    return r;
}

/* The "thermal" object of the stats (docs/stats.md). */
static rad_result add_thermal(rad_context *ctx, cJSON *root, const void *user)
{
    (void)ctx;
    const rad_thermal *t = user;
    cJSON *o = cJSON_AddObjectToObject(root, "thermal");
    cJSON_AddStringToObject(o, "solver", t->solver->name);
    cJSON_AddNumberToObject(o, "residual", t->stats.residual);
    cJSON_AddNumberToObject(o, "iterations", t->stats.iterations);
    cJSON_AddBoolToObject(o, "converged", t->stats.converged);
    cJSON_AddNumberToObject(o, "seconds", t->stats.seconds);
    cJSON_AddNumberToObject(o, "environment_temperature_K", t->sys.environment_temperature);
    cJSON_AddNumberToObject(o, "net_power_W", t->balance.net_power);
    cJSON_AddNumberToObject(o, "environment_power_W", t->balance.environment_power);
    cJSON_AddNumberToObject(o, "imbalance_W", t->balance.imbalance);
    cJSON_AddNumberToObject(o, "power_scale_W", t->balance.power_scale);
    cJSON_AddNumberToObject(o, "relative_imbalance", t->balance.relative_imbalance);
    return RAD_OK;
}

rad_result rad_write_thermal_stats(rad_context *ctx, const rad_solution_view *view, const rad_thermal *t,
                                   const char *path)
{
    return rad_write_stats_extra(ctx, view, path, false, add_thermal, t);
}

/* ---- the public writers (radiosity.h) ---- */

rad_result rad_thermal_write(rad_context *ctx, const rad_thermal *t, const char *path, bool elements)
{
    rad_api_enter(ctx);
    if (!ctx || !t || !path)
        return rad_null_argument(ctx, __func__);
    return rad_write_thermal(ctx, t, path, elements);
}

rad_result rad_thermal_write_gebhart(rad_context *ctx, const rad_thermal *t, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !t || !path)
        return rad_null_argument(ctx, __func__);
    char ext[16];
    rad_path_extension(path, ext, sizeof ext);
    if (strcmp(ext, "json") != 0 && strcmp(ext, "csv") != 0) /* before the solves */
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: unknown Gebhart-factor format (use .csv or .json)",
                        path);
    size_t S = t->scene->surface_count;
    double *G = rad_alloc(ctx, RAD_MEM_OUTPUT, S ? S * S : 1, sizeof *G, "thermal: Gebhart factors");
    if (!G)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = rad_thermal_gebhart_factors(ctx, &t->sys, S, t->solver, &t->params, G);
    if (r == RAD_OK)
        r = rad_write_gebhart(ctx, t, G, path);
    rad_free(G);
    return r;
}

rad_result rad_thermal_write_stats(rad_context *ctx, const rad_thermal *t, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !t || !path)
        return rad_null_argument(ctx, __func__);
    rad_memory_limit_call(ctx, t->max_memory_bytes);
    return rad_write_thermal_stats(ctx, t->view, t, path);
}
