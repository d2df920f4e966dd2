/*
 * solution_file.c -- write a solved solution to its file (the layout is in
 * strategy/saved.h, the reader in strategy/saved.c, the format for users
 * in docs/formats.md).
 *
 * The header is JSON, so a person can read what a file holds with `head
 * -c 4096`; the arrays are binary, little-endian doubles and 32-bit
 * integers, so a solution of 10^6 elements is written and read in well
 * under a second, and every value comes back to the last bit.  The file
 * goes through the temporary-and-rename path of every output.
 */
#include "output/output.h"

#include "strategy/saved.h"

#include <cjson/cJSON.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

static cJSON *numbers(const double *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int k = 0; a && k < n; k++)
        cJSON_AddItemToArray(a, cJSON_CreateNumber(v[k]));
    return a;
}

/* Every field of the option table, by its type: what the reader gives
 * rad_options_resolve again. */
static cJSON *options_json(const rad_options *o)
{
    cJSON *json = cJSON_CreateObject();
    for (size_t i = 0; json; i++) {
        const rad_option_info *row = rad_option_info_get(RAD_OPTION_SET_SOLUTION, i);
        if (!row)
            break;
        const char *field = (const char *)o + row->offset;
        switch (row->type) {
        case RAD_OPTION_INT:
        case RAD_OPTION_FLAG:
        case RAD_OPTION_ENUM: {
            int v;
            memcpy(&v, field, sizeof v);
            cJSON_AddNumberToObject(json, row->name, v);
            break;
        }
        case RAD_OPTION_SIZE: {
            size_t v;
            memcpy(&v, field, sizeof v);
            cJSON_AddNumberToObject(json, row->name, (double)v);
            break;
        }
        case RAD_OPTION_UINT64: {
            uint64_t v;
            memcpy(&v, field, sizeof v);
            char digits[24];
            snprintf(digits, sizeof digits, "%" PRIu64, v);
            cJSON_AddStringToObject(json, row->name, digits);
            break;
        }
        case RAD_OPTION_DOUBLE:
        case RAD_OPTION_BYTES: {
            double v;
            memcpy(&v, field, sizeof v);
            if (isfinite(v))
                cJSON_AddNumberToObject(json, row->name, v);
            break;
        }
        case RAD_OPTION_METHOD: {
            const char *v;
            memcpy(&v, field, sizeof v);
            if (v)
                cJSON_AddStringToObject(json, row->name, v);
            break;
        }
        case RAD_OPTION_STRING:
            break;
        }
    }
    return json;
}

static cJSON *scene_json(const rad_scene *scene)
{
    cJSON *json = cJSON_CreateObject(), *surfaces = cJSON_CreateArray(), *materials = cJSON_CreateArray();
    if (!json || !surfaces || !materials) {
        cJSON_Delete(json);
        cJSON_Delete(surfaces);
        cJSON_Delete(materials);
        return NULL;
    }
    char hex[17];
    snprintf(hex, sizeof hex, "%016" PRIx64, rad_saved_scene_checksum(scene));
    cJSON_AddStringToObject(json, "source", scene->source);
    cJSON_AddStringToObject(json, "checksum", hex);
    for (size_t s = 0; s < scene->surface_count; s++)
        cJSON_AddItemToArray(surfaces, cJSON_CreateString(scene->surfaces[s].name));
    for (size_t m = 0; m < scene->material_count; m++) {
        cJSON *mat = cJSON_CreateObject();
        cJSON_AddItemToArray(materials, mat);
        cJSON_AddStringToObject(mat, "name", scene->materials[m].name);
        cJSON_AddItemToObject(mat, "reflectance", numbers(scene->materials[m].reflectance, 3));
        cJSON_AddItemToObject(mat, "emission", numbers(scene->materials[m].emission, 3));
    }
    cJSON_AddItemToObject(json, "surfaces", surfaces);
    cJSON_AddItemToObject(json, "materials", materials);
    if (scene->has_camera) {
        cJSON *camera = cJSON_CreateObject();
        cJSON_AddItemToObject(camera, "position", numbers(scene->camera.position, 3));
        cJSON_AddItemToObject(camera, "look_at", numbers(scene->camera.look_at, 3));
        cJSON_AddItemToObject(camera, "up", numbers(scene->camera.up, 3));
        cJSON_AddNumberToObject(camera, "vfov_degrees", scene->camera.vfov_degrees);
        cJSON_AddItemToObject(json, "camera", camera);
    }
    return json;
}

/* The solve's figures that a loaded solution reports again. */
static cJSON *solution_json(rad_context *ctx, const rad_solution_view *v, rad_result *r)
{
    double emitted = NAN, absorbed = NAN;
    *r = rad_view_power(ctx, v, &emitted, &absorbed);
    cJSON *json = cJSON_CreateObject();
    if (!json)
        return NULL;
    cJSON_AddStringToObject(json, "method", v->solve->method ? v->solve->method : "unknown");
    cJSON_AddStringToObject(json, "form_factors", v->ff->method ? v->ff->method : "unknown");
    cJSON_AddNumberToObject(json, "iterations", v->solve->iterations);
    if (isfinite(v->solve->iteration_limit))
        cJSON_AddNumberToObject(json, "iteration_limit", v->solve->iteration_limit);
    if (isfinite(v->solve->residual))
        cJSON_AddNumberToObject(json, "residual", v->solve->residual);
    cJSON_AddBoolToObject(json, "converged", v->solve->converged && !v->ended_early);
    if (isfinite(v->solve->unshot))
        cJSON_AddNumberToObject(json, "unshot", v->solve->unshot);
    cJSON_AddItemToObject(json, "ambient", numbers(v->solve->ambient, 3));
    cJSON_AddNumberToObject(json, "emitted_W", emitted);
    cJSON_AddNumberToObject(json, "absorbed_W", absorbed);
    cJSON_AddStringToObject(json, "warning", v->ended_early ? v->ended_early : v->solve->warning);
    return json;
}

rad_result rad_write_solution(rad_context *ctx, const rad_solution_view *v, const double *vertex_radiosity,
                              const char *path)
{
    if (!v->solved)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: the solution is not solved: nothing to save", path);
    rad_bytes payload = {.ctx = ctx};
    cJSON *header = cJSON_CreateObject(), *counts = cJSON_CreateObject(), *payload_json = cJSON_CreateObject();
    rad_result r = RAD_OK;
    cJSON *solution = header ? solution_json(ctx, v, &r) : NULL;
    if (!header || !counts || !payload_json || !solution || r != RAD_OK) {
        cJSON_Delete(header);
        cJSON_Delete(counts);
        cJSON_Delete(payload_json);
        cJSON_Delete(solution);
        return r != RAD_OK ? r : rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory building the header", path);
    }
    rad_saved_put_scene_and_mesh(&payload, v->scene, v->mesh, counts);
    for (size_t i = 0; i < 3 * v->n; i++)
        rad_bytes_f64(&payload, v->radiosity[i]);
    for (size_t i = 0; i < 3 * v->mesh->vertex_count; i++)
        rad_bytes_f64(&payload, vertex_radiosity[i]);
    /* The luminaires (saved.h "light"): their tables and placements, then
     * each element's direct irradiance, so a loaded solution has its light. */
    cJSON *light = v->scene->luminaires.count > 0 ? rad_saved_put_light(&payload, v->scene, v->direct, v->n) : NULL;
    if (v->scene->luminaires.count > 0 && !light)
        payload.failed = true;
    /* The daylight likewise (saved.h "daylight"), the direct irradiance
     * with it when no luminaire part holds it. */
    const struct rad_daylight *day = v->scene->daylight;
    cJSON *daylight = day ? rad_saved_put_daylight(&payload, day, light ? NULL : v->direct, v->n) : NULL;
    if (day && !daylight)
        payload.failed = true;
    char hex[17];
    snprintf(hex, sizeof hex, "%016" PRIx64, rad_fnv1a(RAD_FNV_OFFSET, payload.data, payload.size));
    cJSON_AddStringToObject(header, "format", "radiosity solution");
    cJSON_AddNumberToObject(header, "version", RAD_SAVED_VERSION);
    cJSON_AddStringToObject(header, "engine", RAD_VERSION_STRING);
    cJSON_AddNumberToObject(payload_json, "bytes", (double)payload.size);
    cJSON_AddStringToObject(payload_json, "fnv1a64", hex);
    cJSON_AddItemToObject(header, "payload", payload_json);
    cJSON_AddItemToObject(header, "counts", counts);
    cJSON_AddItemToObject(header, "scene", scene_json(v->scene));
    cJSON_AddItemToObject(header, "options", options_json(v->options));
    cJSON_AddItemToObject(header, "solution", solution);
    if (light)
        cJSON_AddItemToObject(header, "light", light);
    if (daylight)
        cJSON_AddItemToObject(header, "daylight", daylight);
    char *text = cJSON_Print(header);
    cJSON_Delete(header);
    if (!text || payload.failed) {
        cJSON_free(text);
        rad_bytes_free(&payload);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory writing the solution", path);
    }
    size_t header_size = strlen(text);
    rad_bytes head = {.ctx = ctx};
    rad_bytes_raw(&head, RAD_SAVED_MAGIC, RAD_SAVED_MAGIC_SIZE);
    rad_bytes_u32(&head, (uint32_t)header_size);
    rad_bytes_raw(&head, text, header_size);
    static const unsigned char zeros[8] = {0};
    rad_bytes_raw(&head, zeros, (8 - head.size % 8) % 8);
    cJSON_free(text);
    if (head.failed || header_size > UINT32_MAX) {
        rad_bytes_free(&head);
        rad_bytes_free(&payload);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory writing the solution", path);
    }
    rad_atomic_file f;
    r = rad_atomic_open(ctx, path, &f);
    if (r == RAD_OK) {
        if (fwrite(head.data, 1, head.size, f.file) != head.size ||
            fwrite(payload.data, 1, payload.size, f.file) != payload.size) {
            rad_atomic_abort(&f);
            r = rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write", path);
        } else {
            r = rad_atomic_commit(ctx, &f);
        }
    }
    rad_bytes_free(&head);
    rad_bytes_free(&payload);
    return r;
}
