/*
 * gltf_fixes.c -- what the glTF path needs besides assimp 5.2.
 *
 * Before assimp: the framing of a GLB file is checked, because assimp
 * allocates what the header and chunk headers claim before comparing it
 * with the file's size.  After assimp: it ignores
 * KHR_materials_emissive_strength, so the glTF JSON (all of a .gltf, the
 * first chunk of a .glb) is read with cJSON for it (and for the checks of
 * gltf_check.c).
 *
 *    GLB:  "glTF" version length | chunk length "JSON" text | chunk length "BIN\0" data
 *
 * (Khronos, glTF 2.0 specification, section "Binary glTF Layout".)
 */
#include "import/import_internal.h"

#include <cjson/cJSON.h>

#include <string.h>

/* A little-endian 32-bit number, as GLB headers store them. */
static size_t le32(const unsigned char *p)
{
    return (size_t)p[0] | (size_t)p[1] << 8 | (size_t)p[2] << 16 | (size_t)p[3] << 24;
}

/* The JSON of a .gltf (all of it) or a .glb (its first chunk), parsed;
 * NULL if it is not JSON, with the offset in the file where parsing
 * stopped. */
cJSON *import_gltf_json(const char *data, size_t size, bool binary, size_t *error_offset)
{
    *error_offset = 0;
    size_t start = 0, length = size;
    if (binary) {
        /* GLB: magic "glTF", version, length; then chunk length, "JSON", text. */
        const unsigned char *bytes = (const unsigned char *)data;
        if (size < 20 || memcmp(bytes, "glTF", 4) != 0 || memcmp(bytes + 16, "JSON", 4) != 0)
            return NULL;
        length = le32(bytes + 12);
        if (length > size - 20)
            return NULL;
        start = 20;
    }
    const char *end = NULL;
    cJSON *json = cJSON_ParseWithLengthOpts(data + start, length, &end, false);
    if (!json)
        *error_offset = start + (end && end >= data + start ? (size_t)(end - (data + start)) : 0);
    return json;
}

/* Check the framing of a GLB file before assimp reads it: assimp 5.2
 * allocates what the header and chunk headers claim before comparing it
 * with the file's size, so a 40-byte file claiming a 4 GiB chunk costs
 * 4 GiB.  Header: magic "glTF", version, total length; then chunks of
 * (length, type, data), each within the file. */
rad_result import_glb_check_framing(rad_context *ctx, const char *name, const char *data,
                                     size_t size)
{
    const unsigned char *bytes = (const unsigned char *)data;
    if (size < 12 || memcmp(bytes, "glTF", 4) != 0)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: not a binary glTF file (no 'glTF' header)",
                        name);
    size_t declared = le32(bytes + 8);
    if (declared > size)
        return rad_fail(ctx, RAD_ERROR_PARSE,
                        "%s: GLB header claims %zu bytes, the file has %zu", name, declared, size);
    size_t offset = 12;
    for (int chunk = 0; offset < declared; chunk++) {
        if (declared - offset < 8)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s: GLB chunk %d is cut short at byte %zu",
                            name, chunk, offset);
        size_t length = le32(bytes + offset);
        if (length > declared - offset - 8)
            return rad_fail(ctx, RAD_ERROR_PARSE,
                            "%s: GLB chunk %d claims %zu bytes, %zu are left in the file", name,
                            chunk, length, declared - offset - 8);
        /* Chunks start and end on 4-byte boundaries; assimp rounds the
         * JSON chunk up to one to find the next, so a JSON chunk of
         * another length would hide its BIN chunk from the checks. */
        if (chunk == 0 && length % 4 != 0)
            return rad_fail(ctx, RAD_ERROR_PARSE,
                            "%s: GLB JSON chunk of %zu bytes, not a multiple of 4", name, length);
        offset += 8 + length;
    }
    return RAD_OK;
}

/* KHR_materials_emissive_strength of the glTF material assimp imported as
 * material `index` named `name`: assimp keeps the glTF order (and appends a
 * default material), so match by index, by name when the names differ. */
const cJSON *import_gltf_material(const cJSON *materials, unsigned index, const char *name)
{
    const cJSON *match = NULL, *item;
    unsigned i = 0;
    cJSON_ArrayForEach(item, materials) {
        const cJSON *item_name = cJSON_GetObjectItemCaseSensitive(item, "name");
        bool same_name = !cJSON_IsString(item_name) || strcmp(item_name->valuestring, name) == 0;
        if (i++ == index && same_name) {
            match = item;
            break;
        }
        if (!match && cJSON_IsString(item_name) && strcmp(item_name->valuestring, name) == 0)
            match = item;
    }
    return match;
}

/* The number at object.key (objects only), or `fallback`. */
static double number_at(const cJSON *object, const char *key, double fallback)
{
    const cJSON *value = cJSON_IsObject(object) ? cJSON_GetObjectItemCaseSensitive(object, key) : NULL;
    return cJSON_IsNumber(value) ? value->valuedouble : fallback;
}

static const cJSON *object_at(const cJSON *object, const char *key)
{
    return cJSON_IsObject(object) ? cJSON_GetObjectItemCaseSensitive(object, key) : NULL;
}

double import_gltf_emissive_strength(const cJSON *materials, unsigned index, const char *name)
{
    const cJSON *extensions = object_at(import_gltf_material(materials, index, name), "extensions");
    return number_at(object_at(extensions, "KHR_materials_emissive_strength"), "emissiveStrength", 1.0);
}

bool import_gltf_specular(const cJSON *material, const double base[3], import_specular *out)
{
    const cJSON *pbr = object_at(material, "pbrMetallicRoughness");
    const cJSON *extensions = object_at(material, "extensions");
    double t = number_at(object_at(extensions, "KHR_materials_transmission"), "transmissionFactor", 0.0);
    double metallic = number_at(pbr, "metallicFactor", 0.0); /* written only: unused.c says why */
    double roughness = number_at(pbr, "roughnessFactor", 1.0);
    if (t > 0.0 && t <= 1.0) {
        out->kind = RAD_SPECULAR_GLASS;
        out->ior = number_at(object_at(extensions, "KHR_materials_ior"), "ior", 1.5);
        out->shininess = 0.0;
        for (int c = 0; c < 3; c++) {
            out->reflectance[c] = (1.0 - t) * base[c];
            out->specular[c] = t;
        }
        return true;
    }
    if (!(metallic > 0.0 && metallic <= 1.0 && roughness >= 0.0 && roughness <= IMPORT_GLTF_MAX_ROUGHNESS))
        return false;
    /* Roughness r as a Phong exponent: alpha = r^2, Ns = 2 / alpha^2 - 2
     * (Walter et al. 2007's match of the Beckmann and Blinn-Phong lobes). */
    double alpha = roughness * roughness;
    out->shininess = alpha > 0.0 ? 2.0 / (alpha * alpha) - 2.0 : RAD_MIRROR_SHININESS;
    out->kind = out->shininess >= RAD_MIRROR_SHININESS ? RAD_SPECULAR_MIRROR : RAD_SPECULAR_GLOSSY;
    out->ior = 1.0;
    for (int c = 0; c < 3; c++) {
        out->reflectance[c] = (1.0 - metallic) * base[c];
        out->specular[c] = metallic * base[c];
    }
    return true;
}
