/*
 * layout.c -- luminaires placed in a scene: the layout file (JSON, read
 * with cJSON) and glTF nodes whose extras name a photometric file
 * (docs/lighting.md "Luminaires").
 *
 *     {"up": [0, 0, 1],                         world up (default +z)
 *      "llf": 0.8,                              default light loss factor (1)
 *      "luminaires": [
 *        {"file": "downlight.ies",              relative to the layout's folder
 *         "position": [2, 3, 2.7],              m: the photometric centre
 *         "aim": [0, 0, -1],                    the nadir's direction (default -up)
 *         "spin": 90,                           degrees about the aim (turns C = 0)
 *         "llf": 0.9, "lumens": 3000, "multiplier": 2,
 *         "name": "row A",
 *         "array": {"count": [4, 2], "spacing": [1.5, 2]}}]}
 *
 * "aim_at": [x, y, z] aims the nadir at a point instead of "aim".  An
 * array repeats the entry count[0] x count[1] times, from `position` along
 * the luminaire's own x (C = 0, after the spin) and y (C = 90), named
 * "name[i,j]".  Each luminaire's multiplier on the file's candela is
 * llf x multiplier x (lumens / the file's flux, where lumens is given) x the
 * file's TILT factor at the angle between its aim and straight down.
 *
 * Every error names the file, the entry (cJSON keeps no lines) and the key;
 * the scene changes only when the whole layout is good.
 */
#include "photometry/layout.h"

#include "photometry/photometry.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double DEG = 3.14159265358979323846 / 180.0;

/* Luminaires one layout (or glTF) may place: 10^6 is a stadium's worth
 * many times over; an array's count beyond it is a typing error. */
#define MAX_LUMINAIRES 1000000

rad_result rad_layout_load_photometry(rad_context *ctx, const char *path, void *user, rad_photometry **out)
{
    (void)user;
    return rad_photometry_load(ctx, path, out);
}

/* ---- frames ---- */

static vec3 rotate(vec3 v, vec3 k, double c, double s)
{
    /* Rodrigues: v c + (k x v) s + k (k . v)(1 - c), k unit. */
    return v3_add(v3_add(v3_scale(v, c), v3_scale(v3_cross(k, v), s)), v3_scale(k, v3_dot(k, v) * (1.0 - c)));
}

void rad_layout_frame(vec3 aim, vec3 up, double spin_degrees, vec3 axis[3])
{
    aim = v3_normalize(aim);
    up = v3_normalize(up);
    /* The reference: the world axis least along up (x on ties), made
     * perpendicular to up. */
    vec3 world[3] = {v3(1, 0, 0), v3(0, 1, 0), v3(0, 0, 1)};
    int best = 0;
    for (int k = 1; k < 3; k++)
        if (fabs(v3_dot(world[k], up)) < fabs(v3_dot(world[best], up)) - 1e-12)
            best = k;
    vec3 x = v3_normalize(v3_mad(world[best], up, -v3_dot(world[best], up)));
    vec3 z = up, y = v3_cross(z, x);
    vec3 down = v3_scale(up, -1.0), k = v3_cross(down, aim);
    double s = v3_length(k), c = v3_dot(down, aim);
    if (s > 1e-12) {
        k = v3_scale(k, 1.0 / s);
        x = rotate(x, k, c, s), y = rotate(y, k, c, s), z = rotate(z, k, c, s);
    } else if (c < 0.0) { /* straight up: half a turn about the reference */
        y = v3_scale(y, -1.0), z = v3_scale(z, -1.0);
    }
    double cs = cos(spin_degrees * DEG), sn = sin(spin_degrees * DEG);
    axis[0] = v3_normalize(v3_add(v3_scale(x, cs), v3_scale(y, sn)));
    axis[2] = v3_normalize(z);
    axis[1] = v3_cross(axis[2], axis[0]);
}

double rad_layout_tilt_degrees(const vec3 axis[3], vec3 up)
{
    double c = v3_dot(axis[2], v3_normalize(up)); /* nadir . down = (-z) . (-up) */
    return acos(fmax(-1.0, fmin(1.0, c))) / DEG;
}

double rad_luminaire_flux(const rad_luminaire_set *set, size_t k)
{
    const rad_luminaire *L = &set->items[k];
    return set->photometries[L->photometry]->flux * L->multiplier;
}

void rad_luminaire_set_free(rad_luminaire_set *set)
{
    for (size_t k = 0; k < set->photometry_count; k++)
        rad_photometry_free(set->photometries[k]);
    rad_free(set->photometries);
    for (size_t k = 0; k < set->count; k++)
        rad_free(set->items[k].name);
    rad_free(set->items);
    memset(set, 0, sizeof *set);
}

/* ---- what a layout adds, kept aside until all of it is good ---- */

typedef struct additions {
    rad_context *ctx;
    rad_luminaire_set *set;
    const char *name;        /* the layout (or glTF), for messages */
    rad_photometry_loader load;
    void *user;
    rad_photometry **photometries; /* new ones */
    size_t photometry_count, photometry_capacity;
    rad_luminaire *luminaires;     /* new ones */
    size_t luminaire_count, luminaire_capacity;
} additions;

static void additions_free(additions *a)
{
    for (size_t k = 0; k < a->photometry_count; k++)
        rad_photometry_free(a->photometries[k]);
    rad_free(a->photometries);
    for (size_t k = 0; k < a->luminaire_count; k++)
        rad_free(a->luminaires[k].name);
    rad_free(a->luminaires);
    memset(a, 0, sizeof *a);
}

/* The index (in the scene's numbering) of the distribution of `path`,
 * loaded if new. */
static rad_result photometry_of(additions *a, const char *path, uint32_t *index)
{
    const rad_luminaire_set *s = a->set;
    for (size_t k = 0; k < s->photometry_count; k++)
        if (s->photometries[k]->source && strcmp(s->photometries[k]->source, path) == 0) {
            *index = (uint32_t)k;
            return RAD_OK;
        }
    for (size_t k = 0; k < a->photometry_count; k++)
        if (strcmp(a->photometries[k]->source, path) == 0) {
            *index = (uint32_t)(s->photometry_count + k);
            return RAD_OK;
        }
    if (a->photometry_count == a->photometry_capacity) {
        size_t capacity = a->photometry_capacity ? 2 * a->photometry_capacity : 4;
        rad_photometry **grown = rad_realloc(a->ctx, RAD_MEM_SCENE, a->photometries, capacity, sizeof *grown,
                                             "luminaires: photometries");
        if (!grown)
            return RAD_ERROR_OUT_OF_MEMORY;
        a->photometries = grown;
        a->photometry_capacity = capacity;
    }
    rad_photometry *p = NULL;
    rad_result r = a->load(a->ctx, path, a->user, &p);
    if (r != RAD_OK)
        return r;
    if (!p)
        return rad_fail(a->ctx, RAD_ERROR_IO, "%s: %s: no distribution read", a->name, path);
    if (!p->source || strcmp(p->source, path) != 0) {
        char *source = rad_strdup(a->ctx, RAD_MEM_SCENE, path, "photometry: name");
        if (!source) {
            rad_photometry_free(p);
            return RAD_ERROR_OUT_OF_MEMORY;
        }
        rad_free(p->source);
        p->source = source;
    }
    a->photometries[a->photometry_count++] = p;
    *index = (uint32_t)(s->photometry_count + a->photometry_count - 1);
    return RAD_OK;
}

static const rad_photometry *photometry_at(const additions *a, uint32_t index)
{
    return index < a->set->photometry_count ? a->set->photometries[index]
                                              : a->photometries[index - a->set->photometry_count];
}

static rad_result add_luminaire(additions *a, char *name, uint32_t photometry, vec3 position, const vec3 axis[3],
                                double multiplier)
{
    if (a->luminaire_count == a->luminaire_capacity) {
        size_t capacity = a->luminaire_capacity ? 2 * a->luminaire_capacity : 8;
        rad_luminaire *grown = rad_realloc(a->ctx, RAD_MEM_SCENE, a->luminaires, capacity, sizeof *grown,
                                           "luminaires");
        if (!grown) {
            rad_free(name);
            return RAD_ERROR_OUT_OF_MEMORY;
        }
        a->luminaires = grown;
        a->luminaire_capacity = capacity;
    }
    rad_luminaire *L = &a->luminaires[a->luminaire_count++];
    L->name = name;
    L->photometry = photometry;
    L->position = position;
    for (int k = 0; k < 3; k++)
        L->axis[k] = axis[k];
    L->multiplier = multiplier;
    return RAD_OK;
}

static int compare_names(const void *x, const void *y)
{
    return strcmp(*(const char *const *)x, *(const char *const *)y);
}

/* Names unique over the scene's luminaires and the new ones, then the new
 * ones appended to the scene. */
static rad_result commit(additions *a)
{
    rad_luminaire_set *s = a->set;
    size_t total = s->count + a->luminaire_count;
    const char **names = rad_alloc(a->ctx, RAD_MEM_SCENE, total + 1, sizeof *names, "luminaires: names");
    if (!names)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (size_t k = 0; k < s->count; k++)
        names[k] = s->items[k].name;
    for (size_t k = 0; k < a->luminaire_count; k++)
        names[s->count + k] = a->luminaires[k].name;
    qsort(names, total, sizeof *names, compare_names);
    for (size_t k = 1; k < total; k++)
        if (strcmp(names[k - 1], names[k]) == 0) {
            rad_result r = rad_fail(a->ctx, RAD_ERROR_PARSE, "%s: two luminaires are named '%.200s' (names must "
                                    "be unique in the scene)", a->name, names[k]);
            rad_free(names);
            return r;
        }
    rad_free(names);
    rad_photometry **ph = rad_realloc(a->ctx, RAD_MEM_SCENE, s->photometries,
                                      s->photometry_count + a->photometry_count + 1, sizeof *ph,
                                      "luminaires: photometries");
    if (!ph)
        return RAD_ERROR_OUT_OF_MEMORY;
    s->photometries = ph;
    rad_luminaire *lu = rad_realloc(a->ctx, RAD_MEM_SCENE, s->items, total + 1, sizeof *lu, "luminaires");
    if (!lu)
        return RAD_ERROR_OUT_OF_MEMORY;
    s->items = lu;
    memcpy(s->photometries + s->photometry_count, a->photometries, a->photometry_count * sizeof *ph);
    s->photometry_count += a->photometry_count;
    memcpy(s->items + s->count, a->luminaires, a->luminaire_count * sizeof *lu);
    s->count = total;
    rad_free(a->photometries);
    rad_free(a->luminaires);
    memset(a, 0, sizeof *a);
    return RAD_OK;
}

/* ---- JSON values ---- */

/* `count` finite numbers in a JSON array of exactly that length. */
static bool numbers(const cJSON *item, int count, double *out)
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != count)
        return false;
    int k = 0;
    for (const cJSON *v = item->child; v; v = v->next, k++) {
        if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble))
            return false;
        out[k] = v->valuedouble;
    }
    return k == count;
}

static bool vector(const cJSON *item, vec3 *out, bool nonzero)
{
    double v[3];
    if (!numbers(item, 3, v) || fabs(v[0]) > RAD_MAX_COORDINATE || fabs(v[1]) > RAD_MAX_COORDINATE ||
        fabs(v[2]) > RAD_MAX_COORDINATE)
        return false;
    *out = v3(v[0], v[1], v[2]);
    return !nonzero || v3_length(*out) > 0.0;
}

static bool number(const cJSON *item, double *out)
{
    if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble))
        return false;
    *out = item->valuedouble;
    return true;
}

/* The folder part of `name` joined with `file` (absolute files as they are). */
static char *resolve(rad_context *ctx, const char *name, const char *file)
{
    const char *slash = strrchr(name, '/');
    size_t folder = file[0] == '/' || !slash ? 0 : (size_t)(slash - name) + 1, length = strlen(file);
    char *path = rad_alloc(ctx, RAD_MEM_SCENE, folder + length + 1, 1, "luminaires: file name");
    if (!path)
        return NULL;
    memcpy(path, name, folder);
    memcpy(path + folder, file, length + 1);
    return path;
}

/* What one layout entry or glTF node says about the light. */
typedef struct light_keys {
    const char *file;
    double llf, lumens, multiplier;
    const char *name;
} light_keys;

/* The multiplier of a luminaire of distribution `p` in frame `axis`. */
static double luminaire_multiplier(const rad_photometry *p, const light_keys *keys, const vec3 axis[3], vec3 up)
{
    double m = keys->llf * keys->multiplier;
    if (keys->lumens > 0.0)
        m *= keys->lumens / p->flux;
    return m * rad_photometry_tilt_factor(p, rad_layout_tilt_degrees(axis, up));
}

/* Checks common to both: a lumens override needs a distribution with flux. */
static rad_result check_lumens(additions *a, const char *where, const rad_photometry *p, const light_keys *keys)
{
    if (keys->lumens > 0.0 && !(p->flux > 0.0))
        return rad_fail(a->ctx, RAD_ERROR_PARSE, "%s: %s.lumens: the distribution of '%.200s' sends no flux, so it "
                        "cannot be scaled to %.6g lm", a->name, where, keys->file, keys->lumens);
    return RAD_OK;
}

/* ---- the layout file ---- */

typedef struct layout_entry {
    light_keys light;
    vec3 position, aim, aim_at;
    bool has_aim, has_aim_at;
    double spin;
    long count[2];
    double spacing[2];
} layout_entry;

#define BAD(...) rad_fail(a->ctx, RAD_ERROR_PARSE, __VA_ARGS__)

static rad_result read_array(additions *a, const char *where, const cJSON *o, layout_entry *e)
{
    const char *name = a->name;
    if (!cJSON_IsObject(o))
        return BAD("%s: %s.array: must be an object such as {\"count\": [4, 2], \"spacing\": [1.5, 2]}", name, where);
    const cJSON *count = NULL, *spacing = NULL;
    for (const cJSON *item = o->child; item; item = item->next) {
        const cJSON **slot = strcmp(item->string, "count") == 0 ? &count : strcmp(item->string, "spacing") == 0 ? &spacing : NULL;
        if (!slot)
            return BAD("%s: %s.array.%.200s: unknown key (known: count, spacing)", name, where, item->string);
        if (*slot)
            return BAD("%s: %s.array.%s: given twice", name, where, item->string);
        *slot = item;
    }
    double c[2];
    if (!count || !numbers(count, 2, c) || c[0] != floor(c[0]) || c[1] != floor(c[1]) || c[0] < 1 || c[1] < 1 ||
        c[0] > MAX_LUMINAIRES || c[1] > MAX_LUMINAIRES || c[0] * c[1] > MAX_LUMINAIRES)
        return BAD("%s: %s.array.count: must be two whole numbers >= 1, [along x, along y], at most %d "
                   "luminaires", name, where, MAX_LUMINAIRES);
    if (!spacing || !numbers(spacing, 2, e->spacing) || fabs(e->spacing[0]) > RAD_MAX_COORDINATE ||
        fabs(e->spacing[1]) > RAD_MAX_COORDINATE)
        return BAD("%s: %s.array.spacing: must be two finite numbers, m, [along x, along y]", name, where);
    e->count[0] = (long)c[0], e->count[1] = (long)c[1];
    return RAD_OK;
}

static rad_result read_entry(additions *a, const char *where, const cJSON *o, double default_llf, layout_entry *e)
{
    const char *name = a->name;
    if (!cJSON_IsObject(o))
        return BAD("%s: %s: must be an object such as {\"file\": \"a.ies\", \"position\": [0, 0, 3]}", name, where);
    static const char *const keys[] = {"file", "position", "aim", "aim_at", "spin", "llf",
                                       "lumens", "multiplier", "name", "array"};
    enum { NKEYS = sizeof keys / sizeof keys[0] };
    const cJSON *seen[NKEYS] = {0};
    for (const cJSON *item = o->child; item; item = item->next) {
        size_t k = 0;
        while (k < NKEYS && strcmp(item->string, keys[k]) != 0)
            k++;
        if (k == NKEYS)
            return BAD("%s: %s.%.200s: unknown key (known: file, position, aim, aim_at, spin, llf, lumens, "
                       "multiplier, name, array)", name, where, item->string);
        if (seen[k])
            return BAD("%s: %s.%s: given twice", name, where, keys[k]);
        seen[k] = item;
    }
    memset(e, 0, sizeof *e);
    e->light.llf = default_llf;
    e->light.multiplier = 1.0;
    e->count[0] = e->count[1] = 1;
    if (!seen[0] || !cJSON_IsString(seen[0]) || !seen[0]->valuestring[0])
        return BAD("%s: %s.file: %s", name, where, seen[0] ? "must be a non-empty string: a photometric file (.ies, .ldt)"
                                                         : "missing: the photometric file (.ies, .ldt)");
    e->light.file = seen[0]->valuestring;
    if (!seen[1] || !vector(seen[1], &e->position, false))
        return BAD("%s: %s.position: %s", name, where, seen[1] ? "must be 3 finite numbers, m" : "missing: [x, y, z] in m");
    if (seen[2] && seen[3])
        return BAD("%s: %s: both aim and aim_at given; give one", name, where);
    if (seen[2] && !vector(seen[2], &e->aim, true))
        return BAD("%s: %s.aim: must be 3 finite numbers, not all 0 (the nadir's direction)", name, where);
    e->has_aim = seen[2] != NULL;
    if (seen[3]) {
        if (!vector(seen[3], &e->aim_at, false))
            return BAD("%s: %s.aim_at: must be 3 finite numbers, m (a point)", name, where);
        if (!(v3_length(v3_sub(e->aim_at, e->position)) > 0.0))
            return BAD("%s: %s.aim_at: the point is the luminaire's position: no direction", name, where);
        e->has_aim_at = true;
    }
    if (seen[4] && !number(seen[4], &e->spin))
        return BAD("%s: %s.spin: must be a finite number, degrees", name, where);
    if (seen[5] && (!number(seen[5], &e->light.llf) || !(e->light.llf > 0.0)))
        return BAD("%s: %s.llf: must be a number > 0 (the light loss factor)", name, where);
    if (seen[6] && (!number(seen[6], &e->light.lumens) || !(e->light.lumens > 0.0)))
        return BAD("%s: %s.lumens: must be a number > 0, lm", name, where);
    if (seen[7] && (!number(seen[7], &e->light.multiplier) || !(e->light.multiplier >= 0.0)))
        return BAD("%s: %s.multiplier: must be a finite number >= 0", name, where);
    if (seen[8] && (!cJSON_IsString(seen[8]) || !seen[8]->valuestring[0]))
        return BAD("%s: %s.name: must be a non-empty string", name, where);
    e->light.name = seen[8] ? seen[8]->valuestring : NULL;
    if (seen[9])
        return read_array(a, where, seen[9], e);
    return RAD_OK;
}

static rad_result place_entry(additions *a, const char *where, size_t index, const layout_entry *e, vec3 up)
{
    char *path = resolve(a->ctx, a->name, e->light.file);
    if (!path)
        return RAD_ERROR_OUT_OF_MEMORY;
    uint32_t ph;
    rad_result r = photometry_of(a, path, &ph);
    rad_free(path);
    if (r != RAD_OK)
        return r;
    const rad_photometry *p = photometry_at(a, ph);
    r = check_lumens(a, where, p, &e->light);
    if (r != RAD_OK)
        return r;
    vec3 aim = e->has_aim ? e->aim : e->has_aim_at ? v3_sub(e->aim_at, e->position) : v3_scale(up, -1.0);
    vec3 axis[3];
    rad_layout_frame(aim, up, e->spin, axis);
    double multiplier = luminaire_multiplier(p, &e->light, axis, up);
    if (a->luminaire_count + (size_t)(e->count[0] * e->count[1]) > MAX_LUMINAIRES)
        return BAD("%s: %s: more than %d luminaires in one layout", a->name, where, MAX_LUMINAIRES);
    bool single = e->count[0] == 1 && e->count[1] == 1;
    for (long j = 0; j < e->count[1]; j++)
        for (long i = 0; i < e->count[0]; i++) {
            char text[300];
            if (e->light.name && single)
                snprintf(text, sizeof text, "%s", e->light.name);
            else if (e->light.name)
                snprintf(text, sizeof text, "%s[%ld,%ld]", e->light.name, i, j);
            else if (single)
                snprintf(text, sizeof text, "luminaire %zu", index + 1);
            else
                snprintf(text, sizeof text, "luminaire %zu[%ld,%ld]", index + 1, i, j);
            char *copy = rad_strdup(a->ctx, RAD_MEM_SCENE, text, "luminaires: names");
            if (!copy)
                return RAD_ERROR_OUT_OF_MEMORY;
            vec3 at = v3_add(e->position, v3_add(v3_scale(axis[0], (double)i * e->spacing[0]),
                                                 v3_scale(axis[1], (double)j * e->spacing[1])));
            if (!v3_finite(at) || fabs(at.x) > RAD_MAX_COORDINATE || fabs(at.y) > RAD_MAX_COORDINATE ||
                fabs(at.z) > RAD_MAX_COORDINATE) {
                rad_free(copy);
                return BAD("%s: %s.array: luminaire [%ld,%ld] lies beyond %g m", a->name, where, i, j,
                           RAD_MAX_COORDINATE);
            }
            r = add_luminaire(a, copy, ph, at, axis, multiplier);
            if (r != RAD_OK)
                return r;
        }
    return RAD_OK;
}

static rad_result parse_layout(additions *a, const cJSON *root)
{
    const char *name = a->name;
    if (!cJSON_IsObject(root))
        return BAD("%s: must be a JSON object with \"luminaires\"", name);
    const cJSON *up_item = NULL, *llf_item = NULL, *list = NULL;
    for (const cJSON *item = root->child; item; item = item->next) {
        const cJSON **slot = strcmp(item->string, "up") == 0           ? &up_item
                             : strcmp(item->string, "llf") == 0        ? &llf_item
                             : strcmp(item->string, "luminaires") == 0 ? &list
                                                                       : NULL;
        if (!slot)
            return BAD("%s: %.200s: unknown key (known: up, llf, luminaires)", name, item->string);
        if (*slot)
            return BAD("%s: %s: given twice", name, item->string);
        *slot = item;
    }
    vec3 up = v3(0, 0, 1);
    if (up_item && !vector(up_item, &up, true))
        return BAD("%s: up: must be 3 finite numbers, not all 0 (the world's up)", name);
    up = v3_normalize(up);
    double llf = 1.0;
    if (llf_item && (!number(llf_item, &llf) || !(llf > 0.0)))
        return BAD("%s: llf: must be a number > 0 (the light loss factor)", name);
    if (!list)
        return BAD("%s: luminaires: missing: a list of luminaires", name);
    if (!cJSON_IsArray(list))
        return BAD("%s: luminaires: must be a list of luminaires", name);
    size_t index = 0;
    for (const cJSON *item = list->child; item; item = item->next, index++) {
        char where[64];
        snprintf(where, sizeof where, "luminaires[%zu]", index);
        layout_entry e;
        rad_result r = read_entry(a, where, item, llf, &e);
        if (r == RAD_OK)
            r = place_entry(a, where, index, &e, up);
        if (r != RAD_OK)
            return r;
    }
    return RAD_OK;
}

rad_result rad_layout_parse(rad_context *ctx, rad_luminaire_set *set, const char *name, const char *text, size_t size,
                            rad_photometry_loader load, void *user)
{
    additions add = {ctx, set, name, load, user, NULL, 0, 0, NULL, 0, 0};
    additions *a = &add;
    rad_result r;
    cJSON *root = NULL;
    r = rad_json_parse(ctx, name, text, size, &root);
    if (r == RAD_OK)
        r = parse_layout(a, root);
    cJSON_Delete(root);
    if (r == RAD_OK)
        r = commit(a);
    additions_free(a);
    return r;
}

/* ---- glTF nodes ---- */

bool rad_gltf_extras_place_luminaire(const cJSON *extras)
{
    return cJSON_IsObject(extras) && cJSON_GetObjectItemCaseSensitive(extras, "luminaire") != NULL;
}

static rad_result read_extras(additions *a, const rad_gltf_luminaire *node, light_keys *keys)
{
    const char *name = a->name, *where = node->label;
    memset(keys, 0, sizeof *keys);
    keys->llf = keys->multiplier = 1.0;
    static const char *const known[] = {"luminaire", "llf", "lumens", "multiplier", "name"};
    const cJSON *seen[5] = {0};
    for (const cJSON *item = node->extras->child; item; item = item->next) {
        size_t k = 0;
        while (k < 5 && strcmp(item->string, known[k]) != 0)
            k++;
        if (k == 5)
            continue; /* extras are the modeller's: other keys are not ours */
        if (seen[k])
            return BAD("%s: %s: extras.%s: given twice", name, where, known[k]);
        seen[k] = item;
    }
    if (!cJSON_IsString(seen[0]) || !seen[0]->valuestring[0])
        return BAD("%s: %s: extras.luminaire: must be a non-empty string: a photometric file (.ies, .ldt)", name,
                   where);
    keys->file = seen[0]->valuestring;
    if (seen[1] && (!number(seen[1], &keys->llf) || !(keys->llf > 0.0)))
        return BAD("%s: %s: extras.llf: must be a number > 0 (the light loss factor)", name, where);
    if (seen[2] && (!number(seen[2], &keys->lumens) || !(keys->lumens > 0.0)))
        return BAD("%s: %s: extras.lumens: must be a number > 0, lm", name, where);
    if (seen[3] && (!number(seen[3], &keys->multiplier) || !(keys->multiplier >= 0.0)))
        return BAD("%s: %s: extras.multiplier: must be a finite number >= 0", name, where);
    if (seen[4] && (!cJSON_IsString(seen[4]) || !seen[4]->valuestring[0]))
        return BAD("%s: %s: extras.name: must be a non-empty string", name, where);
    keys->name = seen[4] ? seen[4]->valuestring : NULL;
    return RAD_OK;
}

rad_result rad_layout_place_gltf(rad_context *ctx, rad_luminaire_set *set, const char *name,
                                 const rad_gltf_luminaire *nodes, size_t count, rad_photometry_loader load,
                                 void *user)
{
    additions add = {ctx, set, name, load, user, NULL, 0, 0, NULL, 0, 0};
    additions *a = &add;
    rad_result r = RAD_OK;
    const vec3 up = v3(0, 1, 0); /* glTF is +y up */
    for (size_t k = 0; k < count && r == RAD_OK; k++) {
        const rad_gltf_luminaire *node = &nodes[k];
        light_keys keys;
        r = read_extras(a, node, &keys);
        if (r != RAD_OK)
            break;
        vec3 position = v3(node->world[0][3], node->world[1][3], node->world[2][3]);
        vec3 x = v3(node->world[0][0], node->world[1][0], node->world[2][0]);
        vec3 z = v3(node->world[0][2], node->world[1][2], node->world[2][2]);
        vec3 axis[3];
        axis[2] = v3_normalize(z);
        axis[0] = v3_mad(x, axis[2], -v3_dot(x, axis[2]));
        if (!v3_finite(position) || !(v3_length(axis[0]) > 0.0) || !(v3_length(axis[2]) > 0.0)) {
            r = BAD("%s: %s: its transform places no luminaire (a zero scale, or x along z)", name, node->label);
            break;
        }
        axis[0] = v3_normalize(axis[0]);
        axis[1] = v3_cross(axis[2], axis[0]);
        char *path = resolve(ctx, name, keys.file);
        if (!path) {
            r = RAD_ERROR_OUT_OF_MEMORY;
            break;
        }
        uint32_t ph;
        r = photometry_of(a, path, &ph);
        rad_free(path);
        if (r == RAD_OK)
            r = check_lumens(a, node->label, photometry_at(a, ph), &keys);
        if (r != RAD_OK)
            break;
        const char *label = keys.name ? keys.name : node->name;
        char *copy = rad_strdup(ctx, RAD_MEM_SCENE, label, "luminaires: names");
        if (!copy) {
            r = RAD_ERROR_OUT_OF_MEMORY;
            break;
        }
        r = add_luminaire(a, copy, ph, position, axis, luminaire_multiplier(photometry_at(a, ph), &keys, axis, up));
    }
    if (r == RAD_OK)
        r = commit(a);
    additions_free(a);
    return r;
}
