/*
 * conditions.c -- the boundary-condition file of the thermal command
 * (docs/thermal.md), read with cJSON and checked against the scene:
 *
 *     {"environment_temperature": 3,                        K, >= 0; default 0
 *      "default": {"emissivity": 0.9, "adiabatic": true},    any surface not named
 *      "surfaces": {"floor": {"emissivity": 0.8, "temperature": 1200},
 *                   "lid": {"heat_flux": -5000}}}           W/m^2 leaving
 *
 * Each condition holds at most one of temperature, heat_flux and
 * "adiabatic": true, and optionally an emissivity in (0, 1] (without one,
 * 1 - the scene's reflectance).  Every error names the file and the key
 * path ("bc.json: surfaces.floor.emissivity: ..."); names are printed as
 * the file gives them, up to 200 bytes.
 */
#include "thermal/thermal.h"

#include "scene/scene.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>

bool rad_thermal_surface_valid(const rad_thermal_surface *s, char *why, size_t size)
{
    if (!(s->emissivity == 0.0 || (s->emissivity > 0.0 && s->emissivity <= 1.0))) {
        snprintf(why, size, "emissivity: must be in (0, 1], got %.6g", s->emissivity);
        return false;
    }
    switch (s->condition) {
    case RAD_THERMAL_TEMPERATURE:
        if (!(isfinite(s->value) && s->value >= 0.0)) {
            snprintf(why, size, "temperature: must be finite and >= 0 K, got %.6g", s->value);
            return false;
        }
        return true;
    case RAD_THERMAL_HEAT_FLUX:
        if (!isfinite(s->value)) {
            snprintf(why, size, "heat_flux: must be finite, got %.6g", s->value);
            return false;
        }
        return true;
    case RAD_THERMAL_ADIABATIC: return true;
    case RAD_THERMAL_OBSTRUCTION: snprintf(why, size, "obstruction-only surfaces take no condition"); return false;
    case RAD_THERMAL_UNSET: break;
    }
    snprintf(why, size, "no condition: give temperature, heat_flux or \"adiabatic\": true");
    return false;
}

/* Read one condition object at `where` ("surfaces.floor" or "default"). */
static rad_result read_condition(rad_context *ctx, const char *name, const char *where, const cJSON *o,
                                 rad_thermal_surface *out)
{
    if (!cJSON_IsObject(o))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: must be an object such as {\"emissivity\": 0.8, "
                        "\"temperature\": 300}", name, where);
    rad_thermal_surface s = {RAD_THERMAL_UNSET, 0.0, 0.0};
    bool seen[4] = {false, false, false, false};
    static const char *const keys[4] = {"emissivity", "temperature", "heat_flux", "adiabatic"};
    for (const cJSON *item = o->child; item; item = item->next) {
        int k = 0;
        while (k < 4 && strcmp(item->string, keys[k]) != 0)
            k++;
        if (k == 4)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.%.200s: unknown key (known: emissivity, temperature, "
                            "heat_flux, adiabatic)", name, where, item->string);
        if (seen[k])
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.%s: given twice", name, where, keys[k]);
        seen[k] = true;
        if (k == 3 ? !cJSON_IsBool(item) : !cJSON_IsNumber(item))
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.%s: must be %s", name, where, keys[k],
                            k == 3 ? "true or false" : "a number");
        if (k == 0) {
            s.emissivity = item->valuedouble;
            if (!(s.emissivity > 0.0 && s.emissivity <= 1.0))
                return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s.emissivity: must be in (0, 1], got %.6g", name,
                                where, s.emissivity);
            continue;
        }
        if (k == 3 && !cJSON_IsTrue(item))
            continue; /* "adiabatic": false says nothing */
        if (s.condition != RAD_THERMAL_UNSET)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: more than one of temperature, heat_flux and "
                            "adiabatic given; give one", name, where);
        s.condition = k == 1 ? RAD_THERMAL_TEMPERATURE : k == 2 ? RAD_THERMAL_HEAT_FLUX : RAD_THERMAL_ADIABATIC;
        s.value = k == 3 ? 0.0 : item->valuedouble;
    }
    char why[160];
    if (!rad_thermal_surface_valid(&s, why, sizeof why))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s%s%s", name, where,
                        s.condition == RAD_THERMAL_UNSET ? ": " : ".", why);
    *out = s;
    return RAD_OK;
}

/* The index of the surface called `text`, or SIZE_MAX. */
static size_t surface_named(const rad_scene *scene, const char *text)
{
    for (size_t k = 0; k < scene->surface_count; k++)
        if (strcmp(scene->surfaces[k].name, text) == 0)
            return k;
    return SIZE_MAX;
}

static rad_result parse_tree(rad_context *ctx, const char *name, const cJSON *root, rad_thermal_conditions *c)
{
    const rad_scene *scene = c->scene;
    if (!cJSON_IsObject(root))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: must be a JSON object with \"surfaces\"", name);
    const cJSON *surfaces = NULL, *fallback = NULL, *env = NULL;
    for (const cJSON *item = root->child; item; item = item->next) {
        const cJSON **slot = strcmp(item->string, "surfaces") == 0                  ? &surfaces
                             : strcmp(item->string, "default") == 0                 ? &fallback
                             : strcmp(item->string, "environment_temperature") == 0 ? &env
                                                                                     : NULL;
        if (!slot)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %.200s: unknown key (known: environment_temperature, "
                            "default, surfaces)", name, item->string);
        if (*slot)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s: given twice", name, item->string);
        *slot = item;
    }
    if (env) {
        if (!cJSON_IsNumber(env) || !isfinite(env->valuedouble) || env->valuedouble < 0.0)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: environment_temperature: must be a finite number >= 0 K",
                            name);
        c->environment_temperature = env->valuedouble;
    }
    if (surfaces && !cJSON_IsObject(surfaces))
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: surfaces: must be an object of surface names", name);
    rad_thermal_surface def = {RAD_THERMAL_UNSET, 0.0, 0.0};
    if (fallback) {
        rad_result r = read_condition(ctx, name, "default", fallback, &def);
        if (r != RAD_OK)
            return r;
    }
    for (const cJSON *item = surfaces ? surfaces->child : NULL; item; item = item->next) {
        size_t k = surface_named(scene, item->string);
        if (k == SIZE_MAX)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: surfaces.%.200s: the scene %s has no surface of that name",
                            name, item->string, scene->source ? scene->source : "");
        if (c->surfaces[k].condition == RAD_THERMAL_OBSTRUCTION)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: surfaces.%.200s: an obstruction-only surface takes no "
                            "condition (it only blocks; what it intercepts reaches the environment)",
                            name, item->string);
        if (c->surfaces[k].condition != RAD_THERMAL_UNSET)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: surfaces.%.200s: given twice", name, item->string);
        char where[256];
        snprintf(where, sizeof where, "surfaces.%.200s", item->string);
        rad_result r = read_condition(ctx, name, where, item, &c->surfaces[k]);
        if (r != RAD_OK)
            return r;
    }
    for (size_t k = 0; k < scene->surface_count; k++) {
        if (c->surfaces[k].condition != RAD_THERMAL_UNSET)
            continue;
        if (!fallback)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: surfaces: the scene's surface '%.200s' has no condition "
                            "(name it, or give a \"default\")", name, scene->surfaces[k].name);
        c->surfaces[k] = def;
    }
    return RAD_OK;
}

rad_result rad_thermal_conditions_parse(rad_context *ctx, const rad_scene *scene, const char *name,
                                        const char *text, size_t size, rad_thermal_conditions **out)
{
    *out = NULL;
    rad_thermal_conditions *c = NULL;
    rad_result r = rad_thermal_conditions_create(ctx, scene, &c);
    if (r != RAD_OK)
        return r;
    c->source = rad_strdup(ctx, RAD_MEM_SCENE, name, "thermal: conditions' name");
    if (!c->source) {
        rad_thermal_conditions_destroy(c);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    cJSON *root = NULL;
    r = rad_json_parse(ctx, name, text, size, &root);
    if (r == RAD_OK)
        r = parse_tree(ctx, name, root, c);
    cJSON_Delete(root);
    if (r != RAD_OK) {
        rad_thermal_conditions_destroy(c);
        return r;
    }
    *out = c;
    return RAD_OK;
}

/* ---- the conditions handle (radiosity.h) ---- */

rad_result rad_thermal_conditions_create(rad_context *ctx, const rad_scene *scene, rad_thermal_conditions **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !scene || !out)
        return rad_null_argument(ctx, __func__);
    rad_thermal_conditions *c = rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *c, "thermal conditions");
    rad_thermal_surface *s = c ? rad_alloc(ctx, RAD_MEM_SCENE, scene->surface_count ? scene->surface_count : 1,
                                           sizeof *s, "thermal conditions")
                               : NULL;
    if (!s) {
        rad_free(c);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    c->ctx = ctx;
    c->scene = scene;
    c->surface_count = scene->surface_count;
    c->surfaces = s;
    for (size_t k = 0; k < scene->surface_count; k++)
        if (scene->surfaces[k].obstruction || scene->surfaces[k].mask)
            s[k].condition = RAD_THERMAL_OBSTRUCTION;
    *out = c;
    return RAD_OK;
}

void rad_thermal_conditions_destroy(rad_thermal_conditions *c)
{
    if (!c)
        return;
    rad_free(c->source);
    rad_free(c->surfaces);
    rad_free(c);
}

rad_result rad_thermal_conditions_load_memory(rad_context *ctx, const rad_scene *scene, const char *name,
                                              const void *data, size_t size, rad_thermal_conditions **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !scene || !name || !out || (!data && size))
        return rad_null_argument(ctx, __func__);
    return rad_thermal_conditions_parse(ctx, scene, name, data ? data : "", size, out);
}

rad_result rad_thermal_conditions_load_file(rad_context *ctx, const rad_scene *scene, const char *path,
                                            rad_thermal_conditions **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !scene || !path || !out)
        return rad_null_argument(ctx, __func__);
    unsigned char *data = NULL;
    size_t size = 0;
    rad_result r = rad_read_whole_file(ctx, path, &data, &size);
    if (r == RAD_OK)
        r = rad_thermal_conditions_parse(ctx, scene, path, (const char *)data, size, out);
    rad_free(data);
    return r;
}

rad_result rad_thermal_conditions_set(rad_context *ctx, rad_thermal_conditions *c, size_t surface,
                                      const rad_thermal_surface *s)
{
    rad_api_enter(ctx);
    if (!ctx || !c || !s)
        return rad_null_argument(ctx, __func__);
    if (surface >= c->surface_count)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: surface %zu of %zu", __func__, surface,
                        c->surface_count);
    if (c->surfaces[surface].condition == RAD_THERMAL_OBSTRUCTION)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: surface '%s' is obstruction-only: it takes no "
                        "condition", __func__, c->scene->surfaces[surface].name);
    char why[160];
    if (!rad_thermal_surface_valid(s, why, sizeof why))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: surface '%s': %s", __func__,
                        c->scene->surfaces[surface].name, why);
    c->surfaces[surface] = *s;
    return RAD_OK;
}

rad_result rad_thermal_conditions_set_environment(rad_context *ctx, rad_thermal_conditions *c, double kelvin)
{
    rad_api_enter(ctx);
    if (!ctx || !c)
        return rad_null_argument(ctx, __func__);
    if (!(isfinite(kelvin) && kelvin >= 0.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: the environment temperature must be finite and "
                        ">= 0 K, got %.6g", __func__, kelvin);
    c->environment_temperature = kelvin;
    return RAD_OK;
}

bool rad_thermal_conditions_get(const rad_thermal_conditions *c, size_t surface, rad_thermal_surface *out)
{
    if (!c || !out || surface >= c->surface_count)
        return false;
    *out = c->surfaces[surface];
    return true;
}

double rad_thermal_conditions_environment(const rad_thermal_conditions *c)
{
    return c ? c->environment_temperature : NAN;
}
