/*
 * grid_write.c -- the illuminance at calculation points as CSV (one row per
 * point) or JSON (per grid: the statistics EN 12464-1 asks for, Eavg, Emin,
 * Emax, U0 = Emin / Eavg, Emin / Emax, and every point), atomically; names
 * carried as the other writers carry them (valid UTF-8; CSV fields quoted
 * per RFC 4180, JSON by cJSON): rad_illuminance_write.  docs/lighting.md,
 * "Calculation grids and points".
 */
#include "grid/grid.h"
#include "output/output.h"

#include <cjson/cJSON.h>
#include <string.h>

static cJSON *point_object(const rad_grid_point_value *p, size_t index, const char *name, bool daylight)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "index", (double)index);
    if (name)
        cJSON_AddStringToObject(o, "name", name);
    cJSON_AddItemToObject(o, "position_m", cJSON_CreateDoubleArray(p->position, 3));
    cJSON_AddItemToObject(o, "normal", cJSON_CreateDoubleArray(p->normal, 3));
    cJSON_AddNumberToObject(o, "u_m", p->u);
    cJSON_AddNumberToObject(o, "v_m", p->v);
    cJSON_AddNumberToObject(o, "E_lux", p->illuminance);
    cJSON_AddNumberToObject(o, "E_direct_lux", p->direct);
    cJSON_AddNumberToObject(o, "E_indirect_lux", p->indirect);
    if (daylight)
        cJSON_AddNumberToObject(o, "daylight_factor_pct", p->daylight_factor);
    return o;
}

static rad_result write_json(rad_context *ctx, const rad_grid_result *grids, size_t count, bool daylight,
                             const char *path)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "unit", "lux");
    cJSON *list = cJSON_AddArrayToObject(root, "grids");
    bool failed = !root || !list;
    for (size_t g = 0; g < count && !failed; g++) {
        const rad_grid_result *r = &grids[g];
        cJSON *o = cJSON_CreateObject();
        char *name = rad_utf8_clean(ctx, r->name);
        failed = !o || !name;
        if (failed) {
            cJSON_Delete(o);
            rad_free(name);
            break;
        }
        cJSON_AddStringToObject(o, "name", name);
        rad_free(name);
        cJSON_AddStringToObject(o, "kind", r->free_points ? "points" : "grid");
        cJSON_AddNumberToObject(o, "points", (double)r->point_count);
        if (!r->free_points) {
            cJSON_AddNumberToObject(o, "columns", r->columns);
            cJSON_AddNumberToObject(o, "rows", r->rows);
            cJSON_AddNumberToObject(o, "spacing_u_m", r->spacing_u);
            cJSON_AddNumberToObject(o, "spacing_v_m", r->spacing_v);
            cJSON_AddNumberToObject(o, "width_m", r->width);
            cJSON_AddNumberToObject(o, "height_m", r->height);
            cJSON_AddNumberToObject(o, "border_m", r->border);
            cJSON_AddStringToObject(o, "spacing_rule", r->automatic ? "EN 12464-1" : "given");
        }
        cJSON_AddNumberToObject(o, "E_avg_lux", r->average);
        cJSON_AddNumberToObject(o, "E_min_lux", r->minimum);
        cJSON_AddNumberToObject(o, "E_max_lux", r->maximum);
        cJSON_AddNumberToObject(o, "U0", r->uniformity);
        cJSON_AddNumberToObject(o, "E_min_over_E_max", r->min_over_max);
        cJSON *values = cJSON_AddArrayToObject(o, "values");
        for (size_t k = 0; k < r->point_count && !failed; k++) {
            char *pname = r->points[k].name ? rad_utf8_clean(ctx, r->points[k].name) : NULL;
            failed = r->points[k].name && !pname;
            if (!failed)
                cJSON_AddItemToArray(values, point_object(&r->points[k], k, pname, daylight));
            rad_free(pname);
        }
        cJSON_AddItemToArray(list, o);
    }
    if (failed) {
        cJSON_Delete(root);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    rad_result res = rad_write_json(ctx, root, path);
    cJSON_Delete(root);
    return res;
}

/* .csv, one row per point, or .json, per grid its statistics and points;
 * the daylight factor's column only when `daylight`.  RAD_ERROR_IO,
 * RAD_ERROR_OUT_OF_MEMORY, RAD_ERROR_INVALID_ARGUMENT (another extension). */
static rad_result write_illuminance(rad_context *ctx, const rad_grid_result *grids, size_t count, bool daylight,
                                   const char *path)
{
    char ext[16];
    rad_path_extension(path, ext, sizeof ext);
    if (strcmp(ext, "json") == 0)
        return write_json(ctx, grids, count, daylight, path);
    if (strcmp(ext, "csv") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: unknown illuminance format (use .csv or .json)",
                        path);
    rad_atomic_file f;
    rad_result r = rad_atomic_open(ctx, path, &f);
    if (r != RAD_OK)
        return r;
    fputs("grid,index,name,x_m,y_m,z_m,nx,ny,nz,u_m,v_m,E_lux,E_direct_lux,E_indirect_lux", f.file);
    fputs(daylight ? ",daylight_factor_pct\n" : "\n", f.file);
    for (size_t g = 0; g < count && r == RAD_OK; g++) {
        char *name = rad_utf8_clean(ctx, grids[g].name);
        if (!name) {
            r = RAD_ERROR_OUT_OF_MEMORY;
            break;
        }
        for (size_t k = 0; k < grids[g].point_count; k++) {
            const rad_grid_point_value *p = &grids[g].points[k];
            rad_csv_field(f.file, name);
            fprintf(f.file, ",%zu,", k);
            if (p->name) {
                char *pname = rad_utf8_clean(ctx, p->name);
                if (!pname) {
                    r = RAD_ERROR_OUT_OF_MEMORY;
                    break;
                }
                rad_csv_field(f.file, pname);
                rad_free(pname);
            }
            fprintf(f.file, ",%.10g,%.10g,%.10g,%.8g,%.8g,%.8g,%.10g,%.10g,%.10g,%.10g,%.10g", p->position[0],
                    p->position[1], p->position[2], p->normal[0], p->normal[1], p->normal[2], p->u, p->v,
                    p->illuminance, p->direct, p->indirect);
            if (daylight)
                fprintf(f.file, ",%.8g", p->daylight_factor);
            fputc('\n', f.file);
        }
        rad_free(name);
    }
    if (r != RAD_OK) {
        rad_atomic_abort(&f);
        return r;
    }
    return rad_atomic_commit(ctx, &f);
}

rad_result rad_illuminance_write(rad_context *ctx, const rad_illuminance *il, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !il || !path)
        return rad_null_argument(ctx, __func__);
    return write_illuminance(ctx, il->grids, il->set->grid_count, il->daylight, path);
}
