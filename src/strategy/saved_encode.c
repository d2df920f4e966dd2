/*
 * saved_encode.c -- the solution file's encoding (saved.h has the layout):
 * FNV-1a, the little-endian byte buffer, the scene's checksum, the scene
 * and mesh arrays and the light as the writer (output/solution_file.c)
 * puts them and saved.c reads them back.
 */
#include "strategy/saved.h"

#include "photometry/photometry.h"
#include "scene/daylight.h"

#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>

uint64_t rad_fnv1a(uint64_t hash, const void *data, size_t size)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < size; i++) {
        hash ^= p[i];
        hash *= 0x100000001b3ull;
    }
    return hash;
}

static void bytes_reserve(rad_bytes *b, size_t more)
{
    if (b->failed || b->size + more <= b->capacity)
        return;
    size_t capacity = b->capacity ? b->capacity : 4096;
    while (capacity < b->size + more)
        capacity *= 2;
    unsigned char *grown = rad_realloc(b->ctx, RAD_MEM_OUTPUT, b->data, capacity, 1, "solution file");
    if (!grown) {
        b->failed = true;
        return;
    }
    b->data = grown;
    b->capacity = capacity;
}

void rad_bytes_raw(rad_bytes *b, const void *data, size_t size)
{
    bytes_reserve(b, size);
    if (b->failed)
        return;
    memcpy(b->data + b->size, data, size);
    b->size += size;
}

void rad_bytes_u32(rad_bytes *b, uint32_t v)
{
    unsigned char le[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                           (unsigned char)(v >> 24)};
    rad_bytes_raw(b, le, 4);
}

void rad_bytes_f64(rad_bytes *b, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    unsigned char le[8];
    for (int k = 0; k < 8; k++)
        le[k] = (unsigned char)(u >> (8 * k));
    rad_bytes_raw(b, le, 8);
}

void rad_bytes_free(rad_bytes *b)
{
    rad_free(b->data);
    b->data = NULL;
    b->size = b->capacity = 0;
}

static void put_vec3(rad_bytes *b, vec3 v)
{
    rad_bytes_f64(b, v.x);
    rad_bytes_f64(b, v.y);
    rad_bytes_f64(b, v.z);
}

/* The hash of a value in its little-endian encoding. */
static uint64_t hash_u32(uint64_t h, uint32_t v)
{
    unsigned char le[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                           (unsigned char)(v >> 24)};
    return rad_fnv1a(h, le, 4);
}

static uint64_t hash_f64(uint64_t h, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    unsigned char le[8];
    for (int k = 0; k < 8; k++)
        le[k] = (unsigned char)(u >> (8 * k));
    return rad_fnv1a(h, le, 8);
}

uint64_t rad_saved_scene_checksum(const rad_scene *scene)
{
    uint64_t h = RAD_FNV_OFFSET;
    for (size_t i = 0; i < scene->polygon_count; i++) {
        const rad_polygon *p = &scene->polygons[i];
        h = hash_u32(h, p->vertex_count);
        h = hash_u32(h, p->surface);
        h = hash_u32(h, p->material);
        for (uint32_t k = 0; k < p->vertex_count; k++) {
            vec3 v = scene->positions[scene->indices[p->first_index + k]];
            h = hash_f64(hash_f64(hash_f64(h, v.x), v.y), v.z);
        }
    }
    for (size_t s = 0; s < scene->surface_count; s++)
        h = rad_fnv1a(h, scene->surfaces[s].name, strlen(scene->surfaces[s].name) + 1);
    for (size_t m = 0; m < scene->material_count; m++) {
        const rad_material *mat = &scene->materials[m];
        h = rad_fnv1a(h, mat->name, strlen(mat->name) + 1);
        for (int c = 0; c < 3; c++)
            h = hash_f64(hash_f64(h, mat->reflectance[c]), mat->emission[c]);
    }
    return h;
}

void rad_saved_put_scene_and_mesh(rad_bytes *b, const rad_scene *scene, const rad_mesh *mesh,
                                  cJSON *counts)
{
    /* The scene: each polygon's own vertices, as the builder stores them. */
    size_t corners = 0;
    for (size_t i = 0; i < scene->polygon_count; i++)
        corners += scene->polygons[i].vertex_count;
    for (size_t i = 0; i < scene->polygon_count; i++) {
        const rad_polygon *p = &scene->polygons[i];
        for (uint32_t k = 0; k < p->vertex_count; k++)
            put_vec3(b, scene->positions[scene->indices[p->first_index + k]]);
    }
    for (size_t i = 0; i < scene->polygon_count; i++) {
        const rad_polygon *p = &scene->polygons[i];
        rad_bytes_u32(b, p->vertex_count);
        rad_bytes_u32(b, p->surface);
        rad_bytes_u32(b, p->material);
        rad_bytes_u32(b, 0);
    }
    /* Materials and camera as doubles here, not in the JSON: cJSON prints
     * 15 digits where they read back within an ulp, and every bit counts
     * (the scene's checksum, the same picture again). */
    for (size_t m = 0; m < scene->material_count; m++)
        for (int c = 0; c < 3; c++) {
            rad_bytes_f64(b, scene->materials[m].reflectance[c]);
            rad_bytes_f64(b, scene->materials[m].emission[c]);
        }
    rad_bytes_u32(b, scene->has_camera ? 1u : 0u);
    rad_bytes_u32(b, 0);
    const double *camera[3] = {scene->camera.position, scene->camera.look_at, scene->camera.up};
    for (int k = 0; k < 3; k++)
        for (int c = 0; c < 3; c++)
            rad_bytes_f64(b, scene->has_camera ? camera[k][c] : 0.0);
    rad_bytes_f64(b, scene->has_camera ? scene->camera.vfov_degrees : 0.0);
    for (size_t i = 0; i < mesh->patch_count; i++) {
        const rad_patch *p = &mesh->patches[i];
        const uint32_t fields[9] = {p->polygon, p->surface, p->material, p->corner_count, p->nu,
                                    p->nv, p->first_element, p->element_count, p->tree_root};
        for (int k = 0; k < 9; k++)
            rad_bytes_u32(b, fields[k]);
        rad_bytes_u32(b, 0);
        for (int c = 0; c < 4; c++)
            put_vec3(b, p->corner[c]);
        put_vec3(b, p->normal);
    }
    for (size_t i = 0; i < mesh->element_count; i++) {
        const rad_element *e = &mesh->elements[i];
        const uint32_t fields[8] = {e->patch, e->surface, e->material, e->vertex_count,
                                    e->vertex[0], e->vertex[1], e->vertex[2], e->vertex[3]};
        for (int k = 0; k < 8; k++)
            rad_bytes_u32(b, fields[k]);
        put_vec3(b, e->centroid);
        put_vec3(b, e->normal);
        rad_bytes_f64(b, e->area);
    }
    for (size_t i = 0; i < mesh->vertex_count; i++)
        put_vec3(b, mesh->vertices[i]);
    for (size_t i = 0; i < mesh->tvertex_count; i++) {
        const rad_tvertex *t = &mesh->tvertices[i];
        rad_bytes_u32(b, t->vertex);
        rad_bytes_u32(b, t->a);
        rad_bytes_u32(b, t->b);
        rad_bytes_u32(b, 0);
        rad_bytes_f64(b, t->t);
    }
    for (size_t i = 0; i < 4 * mesh->tree_count; i++)
        rad_bytes_u32(b, mesh->tree[i]);
    cJSON_AddNumberToObject(counts, "corners", (double)corners);
    cJSON_AddNumberToObject(counts, "polygons", (double)scene->polygon_count);
    cJSON_AddNumberToObject(counts, "materials", (double)scene->material_count);
    cJSON_AddNumberToObject(counts, "patches", (double)mesh->patch_count);
    cJSON_AddNumberToObject(counts, "elements", (double)mesh->element_count);
    cJSON_AddNumberToObject(counts, "vertices", (double)mesh->vertex_count);
    cJSON_AddNumberToObject(counts, "tvertices", (double)mesh->tvertex_count);
    cJSON_AddNumberToObject(counts, "tree_nodes", (double)mesh->tree_count);
}

cJSON *rad_saved_put_light(rad_bytes *b, const rad_scene *scene, const double *direct, size_t n)
{
    cJSON *light = cJSON_CreateObject(), *ph = cJSON_AddArrayToObject(light, "photometries");
    cJSON *lu = cJSON_AddArrayToObject(light, "luminaires");
    if (!light || !ph || !lu) {
        cJSON_Delete(light);
        return NULL;
    }
    bool ok = true;
    for (size_t k = 0; k < scene->luminaires.photometry_count; k++) {
        const rad_photometry *p = scene->luminaires.photometries[k];
        cJSON *o = cJSON_CreateObject();
        ok = ok && o && cJSON_AddItemToArray(ph, o) && cJSON_AddStringToObject(o, "source", p->source ? p->source : "") &&
             cJSON_AddNumberToObject(o, "c_count", (double)p->c_count) &&
             cJSON_AddNumberToObject(o, "gamma_count", (double)p->gamma_count) &&
             cJSON_AddNumberToObject(o, "shape", (double)p->shape);
        rad_bytes_f64(b, p->width);
        rad_bytes_f64(b, p->length);
        rad_bytes_f64(b, p->height);
        for (size_t i = 0; i < p->c_count; i++)
            rad_bytes_f64(b, p->c_angles[i]);
        for (size_t i = 0; i < p->gamma_count; i++)
            rad_bytes_f64(b, p->gamma_angles[i]);
        for (size_t i = 0; i < p->c_count * p->gamma_count; i++)
            rad_bytes_f64(b, p->candela[i]);
    }
    for (size_t k = 0; k < scene->luminaires.count; k++) {
        const rad_luminaire *L = &scene->luminaires.items[k];
        cJSON *o = cJSON_CreateObject();
        ok = ok && o && cJSON_AddItemToArray(lu, o) && cJSON_AddStringToObject(o, "name", L->name) &&
             cJSON_AddNumberToObject(o, "photometry", (double)L->photometry);
        put_vec3(b, L->position);
        for (int a = 0; a < 3; a++)
            put_vec3(b, L->axis[a]);
        rad_bytes_f64(b, L->multiplier);
    }
    for (size_t i = 0; i < 3 * n; i++)
        rad_bytes_f64(b, direct ? direct[i] : 0.0);
    if (!ok) {
        cJSON_Delete(light);
        return NULL;
    }
    return light;
}


cJSON *rad_saved_put_daylight(rad_bytes *b, const rad_daylight *d, const double *direct, size_t n)
{
    cJSON *day = cJSON_CreateObject(), *names = cJSON_AddArrayToObject(day, "opening_names");
    bool ok = day && names && cJSON_AddStringToObject(day, "source", d->source ? d->source : "") &&
              cJSON_AddNumberToObject(day, "model", (double)d->sky.model) &&
              cJSON_AddNumberToObject(day, "type", (double)d->sky.type) &&
              cJSON_AddBoolToObject(day, "ground", d->ground) &&
              cJSON_AddNumberToObject(day, "openings", (double)d->opening_count) &&
              cJSON_AddBoolToObject(day, "direct", direct != NULL);
    for (size_t k = 0; ok && k < d->opening_name_count; k++)
        ok = cJSON_AddItemToArray(names, cJSON_CreateString(d->opening_names[k]));
    if (!ok) {
        cJSON_Delete(day);
        return NULL;
    }
    /* The sky as prepared (rad_sky_prepare's scale included): the loaded
     * daylight gives the same numbers to the bit. */
    const rad_sky *k = &d->sky;
    const double sky[10] = {k->a, k->b, k->c, k->d, k->e, k->sun_zenith, k->sun_azimuth, k->norm,
                            k->zenith_radiance, k->horizontal};
    for (int i = 0; i < 10; i++)
        rad_bytes_f64(b, sky[i]);
    put_vec3(b, k->up);
    put_vec3(b, k->north);
    put_vec3(b, k->east);
    put_vec3(b, k->sun);
    const double rest[6] = {d->sun_normal, d->ground_reflectance, d->ground_radiance, d->zenith_luminance,
                            d->diffuse_illuminance, d->tolerance};
    for (int i = 0; i < 6; i++)
        rad_bytes_f64(b, rest[i]);
    for (size_t i = 0; i < d->opening_count; i++) {
        const rad_opening *o = &d->openings[i];
        rad_bytes_u32(b, o->corner_count);
        rad_bytes_u32(b, o->surface);
        for (int c = 0; c < 4; c++)
            put_vec3(b, o->corner[c]);
        put_vec3(b, o->normal);
        rad_bytes_f64(b, o->area);
    }
    for (size_t i = 0; direct && i < 3 * n; i++)
        rad_bytes_f64(b, direct[i]);
    return day;
}
