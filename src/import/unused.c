/*
 * unused.c -- what a scene file's materials say that the engine does not
 * use, said once per load as warnings.
 *
 * A material is its reflectance rho (MTL Kd, glTF baseColorFactor), its
 * emitted radiance (MTL Ke, glTF emissiveFactor x
 * KHR_materials_emissive_strength) and, from MTL, its specular part
 * (mirrors and glossy reflectors: illum 3 or 5 with Ks and Ns; glass:
 * illum 4, 6 or 7 with Ni, d, Tr; import_assimp.c mtl_specular).
 * Highlights (illum 2), glTF metals and transmission, textures and vertex
 * colours would change the picture, and were dropped without a word.  Now:
 *
 *    pre-scan (MTL: obj_prescan.c; glTF JSON: here) --notes--> assimp, the
 *    builder --which surfaces use each material (import_assimp.c)--> a load
 *    that succeeds says them, one line a material:
 *
 *    scene.mtl: material 'shiny' (surfaces 'desk', 'shelf'): Ks, Ns and
 *    illum 2 are not used (the engine reads Kd and Ke, and the specular
 *    keys with illum 3 to 7)
 *
 * Values that change nothing are not said (Ks 0 0 0, d 1, an explicit
 * metallicFactor 0, alphaMode BLEND with nothing transparent), nor
 * materials no surface uses.  At most IMPORT_NOTES_MAX_LINES lines a load,
 * then one line counting the rest: a file of 500 textured materials says
 * so in 11 lines, not 500.
 */
#include "import/import_internal.h"

#include <cjson/cJSON.h>

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* ---- the notes ---- */

/* A copy of `text` in a block of the context; NULL when out of memory
 * (or when `text` is NULL). */
static char *copy_of(rad_context *ctx, const char *text)
{
    return text ? rad_strdup(ctx, RAD_MEM_SCENE, text, "material notes") : NULL;
}

rad_result import_notes_add(rad_context *ctx, import_notes *notes, const char *subject,
                            const char *material, size_t index, const char *what)
{
    if (notes->count == notes->capacity) {
        size_t grown = notes->capacity ? 2 * notes->capacity : 8;
        import_note *items = rad_realloc(ctx, RAD_MEM_SCENE, notes->items, grown, sizeof *items,
                                         "material notes");
        if (!items)
            return RAD_ERROR_OUT_OF_MEMORY;
        notes->items = items;
        notes->capacity = grown;
    }
    import_note note = {copy_of(ctx, subject), copy_of(ctx, what), copy_of(ctx, material), index,
                        NULL};
    if (!note.subject || !note.what || (material && !note.material)) {
        rad_free(note.subject);
        rad_free(note.what);
        rad_free(note.material);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    notes->items[notes->count++] = note;
    return RAD_OK;
}

void import_notes_free(import_notes *notes)
{
    for (size_t i = 0; i < notes->count; i++) {
        rad_free(notes->items[i].subject);
        rad_free(notes->items[i].what);
        rad_free(notes->items[i].material);
        rad_free(notes->items[i].surfaces);
    }
    rad_free(notes->items);
    memset(notes, 0, sizeof *notes);
}

/* Append to `text` (`*used` bytes of `size` so far), cut at its end. */
static void append(char *text, size_t size, size_t *used, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static void append(char *text, size_t size, size_t *used, const char *fmt, ...)
{
    if (*used + 1 >= size)
        return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(text + *used, size - *used, fmt, ap);
    va_end(ap);
    if (n > 0)
        *used = *used + (size_t)n < size ? *used + (size_t)n : size - 1;
}

void import_join_items(char *text, size_t size, const char *const *items, size_t count)
{
    size_t used = 0;
    text[0] = '\0';
    for (size_t i = 0; i < count; i++)
        append(text, size, &used, "%s%s", i == 0 ? "" : i + 1 == count ? " and " : ", ",
               items[i]);
}

rad_result import_note_set_surfaces(rad_context *ctx, import_note *note,
                                    const char *const *names, size_t shown, size_t total)
{
    char text[320];
    size_t used = 0;
    append(text, sizeof text, &used, "%s ", total == 1 ? "surface" : "surfaces");
    for (size_t i = 0; i < shown; i++) /* a name is cut at 64 bytes: the line stays readable */
        append(text, sizeof text, &used, "%s'%.64s'", i ? ", " : "", names[i]);
    if (total > shown)
        append(text, sizeof text, &used, " and %zu more", total - shown);
    rad_free(note->surfaces);
    note->surfaces = copy_of(ctx, text);
    return note->surfaces ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
}

void import_notes_warn(rad_context *ctx, const char *name, const import_notes *notes)
{
    size_t lines = 0, left = 0;
    for (int pass = 0; pass < 2; pass++) /* the whole file's notes first */
        for (size_t i = 0; i < notes->count; i++) {
            const import_note *note = &notes->items[i];
            bool file = note->index == IMPORT_NOTE_FILE;
            if (file != (pass == 0) || (!file && !note->surfaces))
                continue;
            if (lines == IMPORT_NOTES_MAX_LINES) {
                left++;
            } else if (file) {
                rad_warn(ctx, "%s: %s", note->subject, note->what);
                lines++;
            } else {
                rad_warn(ctx, "%s (%s): %s", note->subject, note->surfaces, note->what);
                lines++;
            }
        }
    if (left > 0)
        rad_warn(ctx, "%s: ... and %zu more material%s with unused properties", name, left,
                 left == 1 ? "" : "s");
}

/* ---- glTF ---- */

/* Extensions the loader reads (gltf_fixes.c). */
static const char *const gltf_read_extensions[] = {"KHR_materials_emissive_strength",
                                                   "KHR_materials_transmission", "KHR_materials_ior"};

static bool extension_is_read(const char *extension)
{
    for (size_t i = 0; i < sizeof gltf_read_extensions / sizeof gltf_read_extensions[0]; i++)
        if (strcmp(extension, gltf_read_extensions[i]) == 0)
            return true;
    return false;
}

static const cJSON *member(const cJSON *object, const char *key)
{
    return cJSON_IsObject(object) ? cJSON_GetObjectItemCaseSensitive(object, key) : NULL;
}

/* `item` if it is an array (objects: an object), else NULL: what
 * cJSON_ArrayForEach may walk. */
static const cJSON *array_or_null(const cJSON *item)
{
    return cJSON_IsArray(item) ? item : NULL;
}

static const cJSON *object_or_null(const cJSON *item)
{
    return cJSON_IsObject(item) ? item : NULL;
}

/* Item `index` of `array`, or NULL. */
static const cJSON *item_at(const cJSON *array, const cJSON *index)
{
    if (!cJSON_IsArray(array) || !cJSON_IsNumber(index) || index->valuedouble < 0.0 ||
        index->valuedouble >= (double)cJSON_GetArraySize(array))
        return NULL;
    return cJSON_GetArrayItem(array, (int)index->valuedouble);
}

/* "baseColorTexture 'wood.png'": a texture by its image's file (not a data
 * URI) or name, else by its index. */
static void texture_item(const cJSON *root, const char *key, const cJSON *info, char *text,
                         size_t size)
{
    const cJSON *index = member(info, "index");
    const cJSON *image =
        item_at(member(root, "images"), member(item_at(member(root, "textures"), index), "source"));
    const cJSON *uri = member(image, "uri"), *name = member(image, "name");
    if (cJSON_IsString(uri) && strncmp(uri->valuestring, "data:", 5) != 0)
        snprintf(text, size, "%s '%.64s'", key, uri->valuestring);
    else if (cJSON_IsString(name))
        snprintf(text, size, "%s '%.64s'", key, name->valuestring);
    else if (cJSON_IsNumber(index))
        snprintf(text, size, "%s (texture %.0f)", key, index->valuedouble);
    else
        snprintf(text, size, "%s", key);
}

/* "0.5 0.4 0.3": the first three numbers of `array`, else `fallback`. */
static void colour_text(const cJSON *array, const char *fallback, char *text, size_t size)
{
    double c[3];
    int n = 0;
    const cJSON *item;
    cJSON_ArrayForEach(item, array_or_null(array))
    {
        if (n < 3 && cJSON_IsNumber(item))
            c[n++] = item->valuedouble;
    }
    if (n == 3)
        snprintf(text, size, "%g %g %g", c[0], c[1], c[2]);
    else
        snprintf(text, size, "%s", fallback);
}

enum { GLTF_ITEMS = 12, ITEM_SIZE = 160 };

/* A material's list of items, the last "N more" when they overflow. */
typedef struct item_list {
    char items[GLTF_ITEMS][ITEM_SIZE];
    size_t count, more;
} item_list;

static char *next_item(item_list *l)
{
    if (l->count == GLTF_ITEMS - 1 || l->more > 0) {
        l->more++;
        return NULL;
    }
    return l->items[l->count++];
}

/* "a, b and c are not used" (with "is" for one). */
static void items_sentence(item_list *l, char *text, size_t size)
{
    if (l->more > 0)
        snprintf(l->items[l->count++], ITEM_SIZE, "%zu more", l->more);
    const char *items[GLTF_ITEMS];
    for (size_t i = 0; i < l->count; i++)
        items[i] = l->items[i];
    import_join_items(text, size, items, l->count);
    size_t used = strlen(text);
    snprintf(text + used, size - used, " %s not used", l->count == 1 ? "is" : "are");
}

/* Note material `index` of the glTF; `colours`: some primitive of it has
 * vertex colours. */
static rad_result gltf_note_material(rad_context *ctx, const char *name, const cJSON *root,
                                     const cJSON *material, size_t index, bool colours, bool textures_read,
                                     import_notes *notes)
{
    item_list l = {.count = 0};
    char *item;
    const cJSON *pbr = member(material, "pbrMetallicRoughness");
    const cJSON *base = textures_read ? NULL : member(pbr, "baseColorTexture"),
                *emissive = member(material, "emissiveTexture");
    if (base && (item = next_item(&l)))
        texture_item(root, "baseColorTexture", base, item, ITEM_SIZE);
    const cJSON *metallic = member(pbr, "metallicFactor");
    /* Only a factor written: the spec's default is 1, but files that omit
     * it mean a plain colour nearly always, and the base colour is read so. */
    /* A smooth metal is read (import_gltf_specular); a rough one is not. */
    const cJSON *roughness = member(pbr, "roughnessFactor");
    bool smooth = cJSON_IsNumber(roughness) && roughness->valuedouble >= 0.0 &&
                  roughness->valuedouble <= IMPORT_GLTF_MAX_ROUGHNESS;
    if (cJSON_IsNumber(metallic) && metallic->valuedouble > 0.0 && !smooth && (item = next_item(&l)))
        snprintf(item, ITEM_SIZE, "metallicFactor %g", metallic->valuedouble);
    static const char *const textures[] = {"metallicRoughnessTexture", "normalTexture",
                                           "occlusionTexture", "emissiveTexture"};
    for (size_t t = 0; t < sizeof textures / sizeof textures[0]; t++) {
        const cJSON *info = t == 0 ? member(pbr, textures[t]) : member(material, textures[t]);
        if (info && (item = next_item(&l)))
            texture_item(root, textures[t], info, item, ITEM_SIZE);
    }
    /* Blending and masking show only where something is transparent. */
    const cJSON *mode = member(material, "alphaMode"), *cutoff = member(material, "alphaCutoff");
    const cJSON *factor = member(pbr, "baseColorFactor");
    const cJSON *alpha_item = cJSON_GetArraySize(factor) == 4 ? cJSON_GetArrayItem(factor, 3) : NULL;
    double alpha = cJSON_IsNumber(alpha_item) ? alpha_item->valuedouble : 1.0;
    double threshold = cJSON_IsNumber(cutoff) ? cutoff->valuedouble : 0.5;
    if (cJSON_IsString(mode) &&
        ((strcmp(mode->valuestring, "BLEND") == 0 && (member(pbr, "baseColorTexture") || alpha < 1.0)) ||
         (strcmp(mode->valuestring, "MASK") == 0 && (member(pbr, "baseColorTexture") || alpha < threshold))) &&
        (item = next_item(&l)))
        snprintf(item, ITEM_SIZE, "alphaMode %s", mode->valuestring);
    const cJSON *extension;
    cJSON_ArrayForEach(extension, object_or_null(member(material, "extensions")))
    {
        if (extension->string && !extension_is_read(extension->string) && (item = next_item(&l)))
            snprintf(item, ITEM_SIZE, "%.64s", extension->string);
    }
    if (colours && (item = next_item(&l)))
        snprintf(item, ITEM_SIZE, "vertex colours (COLOR_0)");
    if (l.count == 0)
        return RAD_OK;

    char what[1024], colour[96];
    items_sentence(&l, what, sizeof what);
    size_t used = strlen(what);
    if (base || emissive) {
        colour_text(factor, "1 1 1", colour, sizeof colour);
        if (base)
            used += (size_t)snprintf(what + used, sizeof what - used,
                                     ": its reflectance is baseColorFactor (%s)", colour);
        colour_text(member(material, "emissiveFactor"), "0 0 0", colour, sizeof colour);
        if (emissive && used < sizeof what)
            snprintf(what + used, sizeof what - used, "%s its emission is emissiveFactor (%s)",
                     base ? "," : ":", colour);
    } else {
        snprintf(what + used, sizeof what - used,
                 " (the engine is diffuse: baseColorFactor and emissiveFactor only)");
    }
    char subject[256];
    const cJSON *material_name = member(material, "name");
    if (cJSON_IsString(material_name))
        snprintf(subject, sizeof subject, "%s: material '%.64s'", name,
                 material_name->valuestring);
    else
        snprintf(subject, sizeof subject, "%s: material %zu", name, index);
    return import_notes_add(ctx, notes, subject, NULL, index, what);
}

/* Whether some material of `materials` has extension `extension`. */
static bool material_has_extension(const cJSON *materials, const char *extension)
{
    const cJSON *material;
    cJSON_ArrayForEach(material, array_or_null(materials))
    {
        if (member(member(material, "extensions"), extension))
            return true;
    }
    return false;
}

rad_result import_gltf_note_unused(rad_context *ctx, const char *name, const cJSON *root,
                                   import_notes *notes, bool textures_read)
{
    /* The extensions the file uses that nothing reads and no material
     * lists: one line for the whole file (KHR_lights_punctual's lights do
     * not light the scene; KHR_texture_transform moves textures unread). */
    const cJSON *materials = member(root, "materials"), *used = member(root, "extensionsUsed");
    item_list l = {.count = 0};
    const cJSON *extension;
    cJSON_ArrayForEach(extension, array_or_null(used))
    {
        char *item;
        if (cJSON_IsString(extension) && !extension_is_read(extension->valuestring) &&
            !material_has_extension(materials, extension->valuestring) && (item = next_item(&l)))
            snprintf(item, ITEM_SIZE, "%.64s", extension->valuestring);
    }
    rad_result r = RAD_OK;
    if (l.count > 0) {
        char list[960], what[1024];
        bool one = l.count == 1 && l.more == 0;
        items_sentence(&l, list, sizeof list);
        snprintf(what, sizeof what, "extension%s %s", one ? "" : "s", list);
        r = import_notes_add(ctx, notes, name, NULL, IMPORT_NOTE_FILE, what);
    }

    /* Which materials have primitives with vertex colours.  Primitives
     * that name none get assimp's default material, white, which the
     * builder refuses (reflectance 1): nothing to note for them. */
    size_t count = cJSON_IsArray(materials) ? (size_t)cJSON_GetArraySize(materials) : 0;
    unsigned char *colours = r == RAD_OK ? rad_alloc(ctx, RAD_MEM_SCENE, count + 1, 1, name)
                                         : NULL;
    if (!colours)
        return RAD_ERROR_OUT_OF_MEMORY;
    const cJSON *mesh, *primitive;
    cJSON_ArrayForEach(mesh, array_or_null(member(root, "meshes")))
    {
        cJSON_ArrayForEach(primitive, array_or_null(member(mesh, "primitives")))
        {
            if (!member(member(primitive, "attributes"), "COLOR_0"))
                continue;
            const cJSON *m = member(primitive, "material");
            if (item_at(materials, m))
                colours[(size_t)m->valuedouble] = 1;
        }
    }
    size_t index = 0;
    const cJSON *material;
    cJSON_ArrayForEach(material, array_or_null(materials))
    {
        if (r == RAD_OK)
            r = gltf_note_material(ctx, name, root, material, index, colours[index], textures_read, notes);
        index++;
    }
    rad_free(colours);
    return r;
}
