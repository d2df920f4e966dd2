/*
 * import_assimp.c -- OBJ(+MTL) and glTF 2.0 (JSON or binary) into a
 * rad_scene, from a file or from memory, through assimp.
 *
 *   bytes, read once (import_input.c) --format by content: OBJ, glTF, GLB-->
 *         pre-scan (OBJ, MTL: obj_prescan.c; GLB framing: gltf_fixes.c)-->
 *         assimp (no post-processing; the same bytes, from memory, through
 *         assimp_io.c) --node tree, transforms applied--> rad_scene_builder
 *         --> rad_scene
 *
 * A surface is a node (OBJ `o`/`g`, glTF node): its name, else its mesh's,
 * else "surface_N".  Polygons keep their vertex count (no
 * aiProcess_Triangulate): the builder splits only non-planar ones.
 *
 * assimp 5.2 falls short in a few places, each patched in one spot:
 *  - its OBJ parser reads "nan", garbage and out-of-range numbers
 *    leniently and reports no line numbers, so a light pre-scan of the OBJ
 *    and MTL text checks vertex coordinates, face indices and Kd/Ke first
 *    (obj_prescan.c);
 *  - it stores coordinates and colours as float (ai_real, as Debian builds
 *    it), so an OBJ coordinate 0.1234567891 would arrive with 7 digits:
 *    an OBJ's positions and its materials' Kd and Ke are read with strtod
 *    by the pre-scan instead, and assimp reads a text whose `v` statements
 *    hold each vertex's index (obj_prescan.c, import_obj_exact_positions),
 *    so that it still gives the structure (objects, groups, materials,
 *    faces) and every face corner finds its exact position; glTF
 *    positions and colours are floats by the spec, and decimal_of() maps
 *    them back to the decimal the file most likely held;
 *  - it ignores KHR_materials_emissive_strength, turns the glTF camera's
 *    yfov into an approximate horizontal angle and copies the camera node's
 *    translation into aiCamera::mPosition (counting it twice): the glTF
 *    JSON is read with cJSON for the strength (gltf_fixes.c), and the glTF
 *    camera is placed from it as the spec says (gltf_check.c: at its node's
 *    origin, looking down -Z with +Y up; an orthographic one, which the
 *    renderer does not draw, is replaced, with a warning);
 *  - it reads glTF node trees recursively (20,000 levels overflow the
 *    stack), copies a subtree for each parent that lists it, drops a
 *    triangle with an index out of range without a word and misreads
 *    accessors of the wrong type: the JSON and the buffers are checked
 *    before assimp sees them (gltf_check.c);
 *  - it keeps the vertex order of a mirrored node: a node whose world
 *    transform has a negative determinant has its polygons reversed here
 *    (glTF 2.0, "Instantiation": the determinant's sign defines the
 *    winding), and a triangle whose indices repeat (a triangle strip's
 *    stitches) is dropped: it has no area by construction.
 * The node tree is walked with an explicit stack: its depth is the file's.
 * MTL/glTF emissive colours are emitted RADIANCE: exitance E = pi * Ke.
 *
 * Memory: files are read through the context's allocator, and no more of
 * them than the limit allows assimp to import (IMPORT_ASSIMP_PEAK_PER_BYTE:
 * assimp's own memory is not the allocator's to count), so a stream
 * (a FIFO, /dev/zero) stops there (import_input.c).
 */
#include "import/import_internal.h"
#include "photometry/layout.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <cjson/cJSON.h>

#include <limits.h>
#include <stdlib.h>
#include <string.h>

/* ---- from assimp's float to double ---- */

/* assimp keeps coordinates and colours as float.  Map a float back to the
 * decimal of 6, 7 or 8 significant digits that rounds to it, if there is
 * one, so that 0.5528 in a file is 0.5528 here and not the float's
 * 0.55279999971; areas and emissions then match the file to double
 * precision.  Data that were floats to begin with (glTF buffers) move by
 * less than half a float ulp. */
static double decimal_of(ai_real value)
{
    if (sizeof(ai_real) != sizeof(float) || value == 0 || !isfinite(value))
        return (double)value;
    char text[32];
    for (int digits = 6; digits < 9; digits++) {
        snprintf(text, sizeof text, "%.*g", digits, (double)value);
        if (strtof(text, NULL) == (float)value)
            return strtod(text, NULL);
    }
    return (double)value;
}

/* An affine transform: assimp's row-major aiMatrix4x4 without its last row. */
typedef struct affine {
    double m[3][4];
} affine;

static affine affine_identity(void)
{
    affine t = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
    return t;
}

/* parent * child, child given as assimp's matrix. */
static affine affine_then(const affine *parent, const struct aiMatrix4x4 *child)
{
    const double c[3][4] = {{child->a1, child->a2, child->a3, child->a4},
                            {child->b1, child->b2, child->b3, child->b4},
                            {child->c1, child->c2, child->c3, child->c4}};
    affine t;
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 4; k++)
            t.m[r][k] = parent->m[r][0] * c[0][k] + parent->m[r][1] * c[1][k] +
                        parent->m[r][2] * c[2][k] + (k == 3 ? parent->m[r][3] : 0.0);
    return t;
}

static vec3 affine_point(const affine *t, vec3 p)
{
    return v3(t->m[0][0] * p.x + t->m[0][1] * p.y + t->m[0][2] * p.z + t->m[0][3],
              t->m[1][0] * p.x + t->m[1][1] * p.y + t->m[1][2] * p.z + t->m[1][3],
              t->m[2][0] * p.x + t->m[2][1] * p.y + t->m[2][2] * p.z + t->m[2][3]);
}

static vec3 affine_direction(const affine *t, vec3 d)
{
    return v3(t->m[0][0] * d.x + t->m[0][1] * d.y + t->m[0][2] * d.z,
              t->m[1][0] * d.x + t->m[1][1] * d.y + t->m[1][2] * d.z,
              t->m[2][0] * d.x + t->m[2][1] * d.y + t->m[2][2] * d.z);
}

static vec3 vec3_of(const struct aiVector3D *v)
{
    return v3(decimal_of(v->x), decimal_of(v->y), decimal_of(v->z));
}

/* ---- aiScene -> builder ---- */

typedef struct converter {
    rad_context *ctx;
    const char *name; /* file name for messages */
    const struct aiScene *ai;
    rad_scene_builder *builder;
    int *material_of;            /* aiMaterial index -> builder material; -1 = not yet */
    const cJSON *gltf_materials; /* the glTF "materials" array; NULL for other formats */
    vec3 *face;                  /* the face being converted */
    size_t face_capacity;
    import_notes *notes;         /* what the file says that is not used (unused.c) */
    int *note_of;                /* aiMaterial index -> its note; -1 = none; NULL: no notes */
    struct note_use *uses;       /* which surfaces use a noted material */
    size_t use_count, use_capacity;
    const import_obj_positions *positions;       /* OBJ: the exact positions; else NULL */
    const import_material_names *materials_exact; /* OBJ: exact Kd and Ke; else NULL */
    rad_input_log *log;        /* a file load's confinement; NULL from memory (no textures read) */
    bool *textured;              /* aiMaterial index -> it got a texture */
} converter;

/* A surface that uses a material with a note. */
typedef struct note_use {
    size_t note;
    int surface; /* the builder's index: the order of first use */
} note_use;

/* The reflectance texture of assimp material `index` (already the
 * builder's material_of[index]): MTL map_Kd / glTF baseColorTexture, an
 * external image beside the scene (confined like every file it names).
 * One that cannot be read fails the load naming the MTL file and line
 * (OBJ) or the material (glTF), unless the context says
 * missing_textures_flat: then a warning, and the flat colour stays.
 * Images embedded in a GLB, and any texture of a scene loaded from memory,
 * are not read (a warning: the flat colour). */
static rad_result convert_texture(converter *cv, unsigned index, const char *material_name,
                                  const import_material_name *exact)
{
    const struct aiMaterial *material = cv->ai->mMaterials[index];
    struct aiString file;
    file.length = 0;
    file.data[0] = '\0';
    if ((aiGetMaterialTexture(material, aiTextureType_DIFFUSE, 0, &file, NULL, NULL, NULL, NULL, NULL, NULL) !=
             aiReturn_SUCCESS ||
         file.length == 0) &&
        (aiGetMaterialTexture(material, aiTextureType_BASE_COLOR, 0, &file, NULL, NULL, NULL, NULL, NULL, NULL) !=
             aiReturn_SUCCESS ||
         file.length == 0))
        return RAD_OK;
    const char *statement = cv->gltf_materials ? "baseColorTexture" : "map_Kd";
    char where[600];
    if (exact && exact->map_kd_line > 0 && cv->materials_exact && exact->library < cv->materials_exact->library_count)
        snprintf(where, sizeof where, "%s:%d: material '%s'", cv->materials_exact->libraries[exact->library],
                 exact->map_kd_line, material_name);
    else
        snprintf(where, sizeof where, "%s: material '%s'", cv->name, material_name);
    if (!cv->log)
        return RAD_OK; /* from memory: no files read; the load's notes say it is not used */
    if (file.data[0] == '*') {
        rad_warn(cv->ctx, "%s: %s '%s' is an image embedded in the file, which is not read: its flat colour "
                 "is used", where, statement, file.data);
        return RAD_OK;
    }
    /* Relative to the scene file's folder. */
    char path[4096];
    const char *slash = strrchr(cv->name, '/');
    if (file.data[0] == '/' || !slash)
        snprintf(path, sizeof path, "%s", file.data);
    else
        snprintf(path, sizeof path, "%.*s/%s", (int)(slash - cv->name), cv->name, file.data);
    if (!rad_input_allowed(cv->log, path))
        return RAD_ERROR_IO; /* the refusal is the context's message */
    float *rgb = NULL;
    int width = 0, height = 0;
    char why[256] = "";
    rad_result r = import_texture_read(cv->ctx, path, &rgb, &width, &height, why, sizeof why);
    if (r != RAD_OK) {
        if (cv->ctx && cv->ctx->missing_textures_flat && r != RAD_ERROR_OUT_OF_MEMORY) {
            rad_warn(cv->ctx, "%s: %s '%s': cannot read %s: %s; its flat colour is used", where, statement,
                     file.data, path, why);
            return RAD_OK;
        }
        return rad_fail(cv->ctx, r, "%s: %s '%s': cannot read %s: %s%s", where, statement, file.data, path, why,
                        r == RAD_ERROR_OUT_OF_MEMORY ? "" : " (--missing-textures flat uses its flat colour)");
    }
    rad_input_log_add(cv->log, path);
    r = rad_scene_builder_texture(cv->builder, cv->material_of[index], file.data, rgb, width, height);
    if (r == RAD_OK)
        cv->textured[index] = true;
    return r;
}

/* An affine (u, v) map of a face's plane fitted to the texture
 * coordinates of its three vertices spanning the most area; false where
 * they are degenerate or not finite. */
static bool fit_uv_map(const vec3 *p, const struct aiVector3D *const uv[], unsigned n, rad_uv_map *map)
{
    unsigned a = 1, b = 2;
    double best = 0.0;
    for (unsigned i = 1; i + 1 < n; i++)
        for (unsigned j = i + 1; j < n; j++) {
            double area = v3_length(v3_cross(v3_sub(p[i], p[0]), v3_sub(p[j], p[0])));
            if (area > best)
                best = area, a = i, b = j;
        }
    vec3 e1 = v3_sub(p[a], p[0]), e2 = v3_sub(p[b], p[0]);
    double g11 = v3_dot(e1, e1), g12 = v3_dot(e1, e2), g22 = v3_dot(e2, e2), det = g11 * g22 - g12 * g12;
    if (!(best > 0.0) || !(det > 0.0))
        return false;
    for (int k = 0; k < 2; k++) {
        double t0 = k ? uv[0]->y : uv[0]->x, t1 = k ? uv[a]->y : uv[a]->x, t2 = k ? uv[b]->y : uv[b]->x;
        double d1 = t1 - t0, d2 = t2 - t0;
        /* gradient g = alpha e1 + beta e2 with g.e1 = d1, g.e2 = d2 */
        double alpha = (d1 * g22 - d2 * g12) / det, beta = (d2 * g11 - d1 * g12) / det;
        vec3 g = v3_add(v3_scale(e1, alpha), v3_scale(e2, beta));
        map->m[4 * k] = g.x;
        map->m[4 * k + 1] = g.y;
        map->m[4 * k + 2] = g.z;
        map->m[4 * k + 3] = t0 - v3_dot(g, p[0]);
    }
    for (int k = 0; k < 8; k++)
        if (!isfinite(map->m[k]))
            return false;
    return true;
}

/* The specular part an MTL material's statements give (docs/units.md
 * "Specular materials"): illum 3 or 5 with Ks is a reflector, an ideal
 * mirror from Ns RAD_MIRROR_SHININESS up (or without Ns), a Phong lobe of
 * exponent Ns below; illum 4, 6 or 7 is glass of index Ni (1.5 without
 * it), its transmitting part Tr, or 1 - d, or what Kd leaves (1 - the
 * largest of Kd).  Other illum
 * values (2: highlights) leave the material diffuse.  Errors name the
 * library's line of Ks (glass: Ni), or of newmtl without it. */
static rad_result mtl_specular(converter *cv, const import_material_name *exact, int material,
                               const double reflectance[3])
{
    int illum = isfinite(exact->illum) ? (int)exact->illum : -1;
    double specular[3] = {0.0, 0.0, 0.0};
    rad_specular_kind kind = RAD_SPECULAR_NONE;
    double shininess = isfinite(exact->ns) ? exact->ns : 0.0, ior = 1.0;
    if ((illum == 3 || illum == 5) && isfinite(exact->ks[0])) {
        memcpy(specular, exact->ks, sizeof specular);
        if (specular[0] > 0.0 || specular[1] > 0.0 || specular[2] > 0.0)
            kind = !isfinite(exact->ns) || exact->ns >= RAD_MIRROR_SHININESS ? RAD_SPECULAR_MIRROR
                                                                             : RAD_SPECULAR_GLOSSY;
    } else if (illum == 4 || illum == 6 || illum == 7) {
        double t = isfinite(exact->tr) ? exact->tr : isfinite(exact->d) ? 1.0 - exact->d
                                                                        : 1.0 - fmax(fmax(reflectance[0], reflectance[1]),
                                                                                     reflectance[2]);
        specular[0] = specular[1] = specular[2] = t;
        ior = isfinite(exact->ni) ? exact->ni : 1.5;
        if (t > 0.0)
            kind = RAD_SPECULAR_GLASS;
    }
    if (kind == RAD_SPECULAR_NONE)
        return RAD_OK;
    char where[1024];
    snprintf(where, sizeof where, "%s:%d", cv->materials_exact->libraries[exact->library],
             kind == RAD_SPECULAR_GLASS ? exact->ni_line : exact->ks_line);
    return rad_scene_builder_material_specular(cv->builder, material, where, kind, specular, shininess,
                                               ior);
}

/* The builder material for assimp material `index`, added on first use so
 * that materials no polygon uses are never validated. */
static int convert_material(converter *cv, unsigned index)
{
    if (index >= cv->ai->mNumMaterials) {
        rad_fail(cv->ctx, RAD_ERROR_PARSE, "%s: a mesh refers to material %u of %u", cv->name,
                 index, cv->ai->mNumMaterials);
        return -1;
    }
    if (cv->material_of[index] >= 0)
        return cv->material_of[index];
    const struct aiMaterial *material = cv->ai->mMaterials[index];
    struct aiString name;
    name.length = 0;
    name.data[0] = '\0';
    aiGetMaterialString(material, AI_MATKEY_NAME, &name);

    /* No colour at all: assimp's own default grey, so that a material
     * without Kd and a missing material look alike. */
    double reflectance[3] = {0.6, 0.6, 0.6}, emission[3] = {0.0, 0.0, 0.0};
    struct aiColor4D color;
    if (aiGetMaterialColor(material, AI_MATKEY_BASE_COLOR, &color) == aiReturn_SUCCESS ||
        aiGetMaterialColor(material, AI_MATKEY_COLOR_DIFFUSE, &color) == aiReturn_SUCCESS) {
        reflectance[0] = decimal_of(color.r);
        reflectance[1] = decimal_of(color.g);
        reflectance[2] = decimal_of(color.b);
    }
    if (aiGetMaterialColor(material, AI_MATKEY_COLOR_EMISSIVE, &color) == aiReturn_SUCCESS) {
        double strength = 1.0;
        ai_real intensity;
        unsigned one = 1;
        if (aiGetMaterialFloatArray(material, AI_MATKEY_EMISSIVE_INTENSITY, &intensity, &one) ==
            aiReturn_SUCCESS)
            strength = decimal_of(intensity); /* assimp versions that read the strength */
        else if (cv->gltf_materials)
            strength = import_gltf_emissive_strength(cv->gltf_materials, index, name.data);
        emission[0] = M_PI * decimal_of(color.r) * strength;
        emission[1] = M_PI * decimal_of(color.g) * strength;
        emission[2] = M_PI * decimal_of(color.b) * strength;
    }
    /* An MTL's Kd and Ke as the file writes them, not as assimp's floats. */
    const import_material_name *exact = import_material_find(cv->materials_exact, name.data);
    for (int c = 0; exact && c < 3; c++) {
        if (exact->has_kd)
            reflectance[c] = exact->kd[c];
        if (exact->has_ke)
            emission[c] = M_PI * exact->ke[c];
    }
    /* glTF: metals and transmission (their diffuse part first). */
    import_specular gltf;
    bool gltf_specular = cv->gltf_materials &&
                         import_gltf_specular(import_gltf_material(cv->gltf_materials, index, name.data),
                                              reflectance, &gltf);
    if (gltf_specular)
        memcpy(reflectance, gltf.reflectance, sizeof gltf.reflectance);
    cv->material_of[index] = rad_scene_builder_material(cv->builder, name.data, reflectance,
                                                        emission);
    if (cv->material_of[index] >= 0 && exact &&
        mtl_specular(cv, exact, cv->material_of[index], reflectance) != RAD_OK)
        cv->material_of[index] = -1;
    if (cv->material_of[index] >= 0 && gltf_specular &&
        rad_scene_builder_material_specular(cv->builder, cv->material_of[index], cv->name, gltf.kind,
                                            gltf.specular, gltf.shininess, gltf.ior) != RAD_OK)
        cv->material_of[index] = -1;
    if (cv->material_of[index] >= 0 && convert_texture(cv, index, name.data, exact) != RAD_OK)
        return -1;
    return cv->material_of[index];
}

/* The determinant of a transform's linear part: negative when it mirrors. */
static double affine_determinant(const affine *t)
{
    const double(*m)[4] = t->m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

/* A face of three corners with a repeated vertex index: no area whatever
 * the positions (a triangle strip's stitches, a fan's start). */
static bool face_repeats_index(const struct aiFace *face)
{
    const unsigned *v = face->mIndices;
    return face->mNumIndices == 3 && (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]);
}

/* ---- the surfaces of the materials with notes (unused.c) ---- */

/* A material's name in the notes, for sorting and searching. */
typedef struct noted_name {
    const char *name;
    size_t note;
} noted_name;

static int compare_noted_names(const void *a, const void *b)
{
    return strcmp(((const noted_name *)a)->name, ((const noted_name *)b)->name);
}

/* Find the assimp material of each note: a glTF's by its index (assimp
 * keeps the file's order, its default material last), an OBJ's by name. */
static rad_result notes_match(converter *cv)
{
    const import_notes *notes = cv->notes;
    unsigned materials = cv->ai->mNumMaterials;
    if (notes->count == 0 || materials == 0)
        return RAD_OK;
    cv->note_of = rad_alloc(cv->ctx, RAD_MEM_SCENE, materials, sizeof *cv->note_of, cv->name);
    noted_name *names = cv->note_of ? rad_alloc(cv->ctx, RAD_MEM_SCENE, notes->count,
                                                sizeof *names, cv->name)
                                    : NULL;
    if (!names)
        return RAD_ERROR_OUT_OF_MEMORY;
    size_t named = 0;
    for (unsigned k = 0; k < materials; k++)
        cv->note_of[k] = -1;
    for (size_t n = 0; n < notes->count; n++) {
        const import_note *note = &notes->items[n];
        if (note->material)
            names[named++] = (noted_name){note->material, n};
        else if (note->index < materials && note->index <= INT_MAX)
            cv->note_of[note->index] = (int)n;
    }
    if (named > 0) {
        qsort(names, named, sizeof *names, compare_noted_names);
        for (unsigned k = 0; k < materials; k++) {
            struct aiString name;
            name.length = 0;
            name.data[0] = '\0';
            aiGetMaterialString(cv->ai->mMaterials[k], AI_MATKEY_NAME, &name);
            noted_name key = {name.data, 0};
            const noted_name *found =
                bsearch(&key, names, named, sizeof *names, compare_noted_names);
            if (found && found->note <= INT_MAX)
                cv->note_of[k] = (int)found->note;
        }
    }
    rad_free(names);
    return RAD_OK;
}

/* Note that `surface` uses assimp material `material` (if it has a note). */
static rad_result note_use_add(converter *cv, unsigned material, int surface)
{
    if (!cv->note_of || cv->note_of[material] < 0)
        return RAD_OK;
    note_use use = {(size_t)cv->note_of[material], surface};
    if (cv->use_count > 0 && cv->uses[cv->use_count - 1].note == use.note &&
        cv->uses[cv->use_count - 1].surface == surface)
        return RAD_OK;
    if (cv->use_count == cv->use_capacity) {
        size_t grown = cv->use_capacity ? 2 * cv->use_capacity : 16;
        note_use *uses = rad_realloc(cv->ctx, RAD_MEM_SCENE, cv->uses, grown, sizeof *uses,
                                     cv->name);
        if (!uses)
            return RAD_ERROR_OUT_OF_MEMORY;
        cv->uses = uses;
        cv->use_capacity = grown;
    }
    cv->uses[cv->use_count++] = use;
    return RAD_OK;
}

static int compare_note_uses(const void *a, const void *b)
{
    const note_use *x = a, *y = b;
    if (x->note != y->note)
        return (x->note > y->note) - (x->note < y->note);
    return (x->surface > y->surface) - (x->surface < y->surface);
}

/* Give each note the surfaces that use its material (the first 3 in the
 * order they were met, and how many). */
static rad_result notes_name_surfaces(converter *cv)
{
    if (cv->use_count > 1)
        qsort(cv->uses, cv->use_count, sizeof *cv->uses, compare_note_uses);
    rad_result r = RAD_OK;
    for (size_t i = 0; i < cv->use_count && r == RAD_OK;) {
        const char *names[3];
        size_t total = 0, j = i;
        for (; j < cv->use_count && cv->uses[j].note == cv->uses[i].note; j++) {
            if (j > i && cv->uses[j].surface == cv->uses[j - 1].surface)
                continue;
            if (total < 3)
                names[total] = rad_scene_builder_surface_name(cv->builder, cv->uses[j].surface);
            total++;
        }
        r = import_note_set_surfaces(cv->ctx, &cv->notes->items[cv->uses[i].note], names,
                                     total < 3 ? total : 3, total);
        i = j;
    }
    return r;
}

/* A vertex of assimp's mesh as a position: for an OBJ the exact one whose
 * index assimp carries in its coordinates (import_obj_exact_positions);
 * false if it carries none (which the rewritten text rules out). */
static bool exact_position(const converter *cv, const struct aiVector3D *vertex, vec3 *position)
{
    if (!cv->positions) {
        *position = vec3_of(vertex);
        return true;
    }
    double low = vertex->x, high = vertex->y, limit = (double)(1u << IMPORT_OBJ_INDEX_BITS);
    if (!(low >= 0.0 && low < limit && high >= 0.0 && high < limit && low == floor(low) &&
          high == floor(high) && vertex->z == 0))
        return false;
    size_t k = (size_t)low + ((size_t)high << IMPORT_OBJ_INDEX_BITS);
    if (k >= cv->positions->count)
        return false;
    const double *xyz = &cv->positions->xyz[3 * k];
    *position = v3(xyz[0], xyz[1], xyz[2]);
    return true;
}

static rad_result convert_mesh(converter *cv, const struct aiNode *node, unsigned mesh_index,
                               const affine *world)
{
    const struct aiMesh *mesh = cv->ai->mMeshes[mesh_index];
    if (!mesh || !mesh->mVertices || !mesh->mFaces)
        return RAD_OK; /* no positions or faces: nothing to radiate */
    char fallback[32];
    snprintf(fallback, sizeof fallback, "surface_%u", mesh_index);
    const char *surface_name = node->mName.length   ? node->mName.data
                               : mesh->mName.length ? mesh->mName.data
                                                    : fallback;
    int surface = -1, material = -1; /* made on the first real polygon */
    bool mirrored = affine_determinant(world) < 0.0;
    for (unsigned f = 0; f < mesh->mNumFaces; f++) {
        const struct aiFace *face = &mesh->mFaces[f];
        if (face->mNumIndices < 3 || face_repeats_index(face))
            continue; /* points and lines; stitches */
        if (surface < 0) {
            surface = rad_scene_builder_surface(cv->builder, surface_name);
            material = surface < 0 ? -1 : convert_material(cv, mesh->mMaterialIndex);
            if (material < 0)
                return cv->ctx ? cv->ctx->last_result : RAD_ERROR_INVALID_SCENE;
            rad_result noted = note_use_add(cv, mesh->mMaterialIndex, surface);
            if (noted != RAD_OK)
                return noted;
        }
        if (face->mNumIndices > cv->face_capacity) {
            vec3 *grown = rad_realloc(cv->ctx, RAD_MEM_SCENE, cv->face, face->mNumIndices,
                                      sizeof *grown, cv->name);
            if (!grown)
                return RAD_ERROR_OUT_OF_MEMORY;
            cv->face = grown;
            cv->face_capacity = face->mNumIndices;
        }
        for (unsigned i = 0; i < face->mNumIndices; i++) {
            unsigned v = face->mIndices[i];
            if (v >= mesh->mNumVertices)
                return rad_fail(cv->ctx, RAD_ERROR_PARSE,
                                "%s: mesh '%s': face references vertex %u of %u", cv->name,
                                mesh->mName.data, v, mesh->mNumVertices);
            vec3 position;
            if (!exact_position(cv, &mesh->mVertices[v], &position))
                return rad_fail(cv->ctx, RAD_ERROR_PARSE,
                                "%s: mesh '%s': vertex %u is not one of the file's %zu", cv->name,
                                mesh->mName.data, v, cv->positions->count);
            cv->face[mirrored ? face->mNumIndices - 1 - i : i] = affine_point(world, position);
        }
        /* Texture coordinates where the material has a texture. */
        rad_result r = RAD_OK;
        if (mesh->mMaterialIndex < cv->ai->mNumMaterials && cv->textured[mesh->mMaterialIndex] &&
            mesh->mTextureCoords[0]) {
            const struct aiVector3D *uv[64];
            rad_uv_map map;
            bool fitted = face->mNumIndices <= 64;
            for (unsigned i = 0; fitted && i < face->mNumIndices; i++)
                uv[mirrored ? face->mNumIndices - 1 - i : i] = &mesh->mTextureCoords[0][face->mIndices[i]];
            fitted = fitted && fit_uv_map(cv->face, uv, face->mNumIndices, &map);
            r = rad_scene_builder_uv_map(cv->builder, fitted ? &map : NULL);
        } else {
            r = rad_scene_builder_uv_map(cv->builder, NULL);
        }
        if (r == RAD_OK)
            r = rad_scene_builder_polygon(cv->builder, surface, material, cv->face, face->mNumIndices, 0);
        if (r != RAD_OK)
            return r;
    }
    return RAD_OK;
}

/* A node to visit and its parent's world transform. */
typedef struct node_visit {
    const struct aiNode *node;
    affine parent;
} node_visit;

/* Push the children of `node` (world transform `world`) onto the stack,
 * the last first so that the first is visited next: the order of a
 * recursive walk, in memory the file cannot blow up (a tree 20,000 deep
 * is 20,000 entries, not 20,000 frames). */
static rad_result push_children(converter *cv, node_visit **stack, size_t *top, size_t *capacity,
                                const struct aiNode *node, const affine *world)
{
    if (node->mNumChildren > *capacity - *top) {
        size_t grown = *capacity * 2 + node->mNumChildren;
        node_visit *bigger = rad_realloc(cv->ctx, RAD_MEM_SCENE, *stack, grown, sizeof *bigger,
                                         cv->name);
        if (!bigger)
            return RAD_ERROR_OUT_OF_MEMORY;
        *stack = bigger;
        *capacity = grown;
    }
    for (unsigned c = node->mNumChildren; c-- > 0;) {
        (*stack)[*top].node = node->mChildren[c];
        (*stack)[*top].parent = *world;
        (*top)++;
    }
    return RAD_OK;
}

/* Every node's meshes, placed by its world transform, depth first. */
static rad_result convert_nodes(converter *cv, const struct aiNode *root)
{
    size_t top = 0, capacity = 0;
    node_visit *stack = NULL;
    affine identity = affine_identity();
    const struct aiNode *node = root;
    const affine *parent = &identity;
    rad_result r = RAD_OK;
    for (;;) {
        affine world = affine_then(parent, &node->mTransformation);
        for (unsigned k = 0; k < node->mNumMeshes && r == RAD_OK; k++) {
            if (node->mMeshes[k] >= cv->ai->mNumMeshes)
                r = rad_fail(cv->ctx, RAD_ERROR_PARSE, "%s: node '%s' refers to mesh %u of %u",
                             cv->name, node->mName.data, node->mMeshes[k], cv->ai->mNumMeshes);
            else
                r = convert_mesh(cv, node, node->mMeshes[k], &world);
        }
        if (r == RAD_OK)
            r = push_children(cv, &stack, &top, &capacity, node, &world);
        if (r != RAD_OK || top == 0)
            break;
        top--;
        node = stack[top].node;
        parent = &stack[top].parent;
    }
    rad_free(stack);
    return r;
}

/* The world transform of the first node called `name`, depth first; false
 * if there is none.  Cannot fail otherwise: out of memory, the search
 * stops. */
static bool find_node(converter *cv, const struct aiNode *root, const char *name, affine *world)
{
    size_t top = 0, capacity = 0;
    node_visit *stack = NULL;
    affine identity = affine_identity();
    const struct aiNode *node = root;
    const affine *parent = &identity;
    bool found = false;
    for (;;) {
        affine here = affine_then(parent, &node->mTransformation);
        if (strcmp(node->mName.data, name) == 0) {
            *world = here;
            found = true;
            break;
        }
        if (push_children(cv, &stack, &top, &capacity, node, &here) != RAD_OK || top == 0)
            break;
        top--;
        node = stack[top].node;
        parent = &stack[top].parent;
    }
    rad_free(stack);
    return found;
}

/* The first camera of a format other than glTF (whose camera
 * gltf_check.c places), placed by its node. */
static void convert_camera(converter *cv)
{
    const struct aiCamera *camera = cv->ai->mCameras[0];
    affine world = affine_identity();
    find_node(cv, cv->ai->mRootNode, camera->mName.data, &world);
    vec3 position = affine_point(&world, vec3_of(&camera->mPosition));
    vec3 direction = affine_direction(&world, vec3_of(&camera->mLookAt)); /* a direction */
    vec3 up = v3_normalize(affine_direction(&world, vec3_of(&camera->mUp)));
    /* Read as the full horizontal angle, as assimp's importers fill it. */
    double aspect = camera->mAspect > 0.0f ? (double)camera->mAspect : 1.0;
    double vfov = 2.0 * atan(tan(0.5 * (double)camera->mHorizontalFOV) / aspect);
    rad_camera c = {
        .position = {position.x, position.y, position.z},
        .look_at = {position.x + direction.x, position.y + direction.y, position.z + direction.z},
        .up = {up.x, up.y, up.z},
        .vfov_degrees = vfov * 180.0 / M_PI,
    };
    rad_scene_builder_camera(cv->builder, &c);
}

/* The JSON of a glTF (the file's bytes `data`), parsed into *json (the
 * caller's to cJSON_Delete) and checked (gltf_check.c) before assimp reads
 * it; JSON that does not parse is refused here, naming the line. */
static rad_result import_gltf_parse_and_check(rad_context *ctx, const char *name,
                                              const char *data, size_t size, bool glb,
                                              struct aiFileIO *io, cJSON **json,
                                              import_gltf_facts *facts)
{
    size_t stop;
    *json = import_gltf_json(data, size, glb, &stop);
    if (!*json && glb)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: the JSON chunk is not JSON (byte %zu)", name,
                        stop);
    if (!*json) {
        size_t line = 1, column = 1;
        for (size_t i = 0; i < stop && i < size; i++, column++)
            if (data[i] == '\n') {
                line++;
                column = 0;
            }
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu:%zu: not JSON", name, line, column);
    }
    rad_result r = import_gltf_check(ctx, name, data, size, glb, *json, io, facts);
    if (r != RAD_OK) {
        cJSON_Delete(*json);
        *json = NULL;
    }
    return r;
}

/* Import `in`, read from `name`, with assimp (through `io`). */
static rad_result import_scene(rad_context *ctx, const char *name, import_input *in,
                               struct aiFileIO *io, rad_scene **out)
{
    bool gltf = in->format != IMPORT_OBJ, glb = in->format == IMPORT_GLB;
    const char *data = in->data;
    size_t size = in->size;
    if (glb) {
        rad_result framing = import_glb_check_framing(ctx, name, data, size);
        if (framing != RAD_OK)
            return framing;
    }
    cJSON *json = NULL;
    import_gltf_facts facts = {0};
    if (gltf) {
        rad_result checked = import_gltf_parse_and_check(ctx, name, data, size, glb, io, &json,
                                                         &facts);
        if (checked == RAD_OK)
            checked = import_gltf_note_unused(ctx, name, json, &in->notes,
                                              ((const import_files *)(const void *)io->UserData)->log != NULL);
        if (checked != RAD_OK) {
            cJSON_Delete(json);
            rad_free(facts.luminaires);
            return checked;
        }
    }

    struct aiPropertyStore *properties = aiCreatePropertyStore();
    if (!properties) {
        cJSON_Delete(json);
        rad_free(facts.luminaires);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    /* A skeleton without meshes must not turn into stick-figure polygons. */
    aiSetImportPropertyInteger(properties, AI_CONFIG_IMPORT_NO_SKELETON_MESHES, 1);
    /* No post-processing: no triangulation, and nothing that merges or
     * drops meshes (aiProcess_ValidateDataStructure even rejects OBJ
     * files with a 2-vertex face beside polygons; the walk below checks
     * every index itself). */
    const struct aiScene *ai = aiImportFileExWithProperties(in->alias, 0, io, properties);
    aiReleasePropertyStore(properties);
    if (!ai) {
        const char *why = aiGetErrorString();
        cJSON_Delete(json);
        rad_free(facts.luminaires);
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s", name,
                        why && *why ? why : "assimp could not read it");
    }

    rad_result r = RAD_OK;
    converter cv = {.ctx = ctx, .name = name, .ai = ai, .notes = &in->notes};
    if (!gltf) {
        cv.positions = &in->positions;
        cv.materials_exact = &in->materials_exact;
    }
    cv.gltf_materials = cJSON_GetObjectItemCaseSensitive(json, "materials");
    if (!ai->mRootNode || ai->mNumMeshes == 0) {
        r = rad_fail(ctx, RAD_ERROR_INVALID_SCENE, "%s: scene is empty (no polygons)", name);
        goto done;
    }
    cv.builder = rad_scene_builder_create(ctx, name);
    cv.material_of = cv.builder ? rad_alloc(ctx, RAD_MEM_SCENE, ai->mNumMaterials, sizeof *cv.material_of, name)
                                : NULL;
    cv.textured = cv.material_of ? rad_alloc(ctx, RAD_MEM_SCENE, ai->mNumMaterials + 1, sizeof *cv.textured, name)
                                 : NULL;
    cv.log = ((const import_files *)(const void *)io->UserData)->log;
    if (!cv.textured) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    for (unsigned i = 0; i < ai->mNumMaterials; i++)
        cv.material_of[i] = -1;
    r = notes_match(&cv);
    if (r == RAD_OK)
        r = convert_nodes(&cv, ai->mRootNode);
    if (r == RAD_OK)
        r = notes_name_surfaces(&cv);
    if (r != RAD_OK)
        goto done;
    if (gltf && facts.has_camera)
        rad_scene_builder_camera(cv.builder, &facts.camera);
    else if (!gltf && ai->mNumCameras > 0 && ai->mCameras[0])
        convert_camera(&cv);
    else if (cv.positions && cv.positions->has_camera)
        rad_scene_builder_camera(cv.builder, &cv.positions->camera); /* an OBJ's camera comment */
    r = rad_scene_builder_finish(cv.builder, out);
    cv.builder = NULL;
    if (r == RAD_OK && facts.luminaire_count > 0) {
        /* Luminaires placed by nodes' extras (layout.c): their files are
         * read beside the glTF, so only when it was read from a file. */
        if (cv.log)
            r = rad_layout_place_gltf(ctx, &(*out)->luminaires, name, facts.luminaires, facts.luminaire_count,
                                      rad_layout_load_photometry, NULL);
        else
            rad_warn(ctx, "%s: %zu node%s place%s a luminaire (extras.luminaire), which only a glTF read "
                     "from a file places (its photometric files lie beside it)",
                     name, facts.luminaire_count, facts.luminaire_count == 1 ? "" : "s",
                     facts.luminaire_count == 1 ? "s" : "");
        if (r != RAD_OK) {
            rad_scene_destroy(*out);
            *out = NULL;
        }
    }

done:
    rad_scene_builder_destroy(cv.builder);
    rad_free(cv.material_of);
    rad_free(cv.textured);
    rad_free(cv.note_of);
    rad_free(cv.uses);
    rad_free(cv.face);
    aiReleaseImport(ai);
    cJSON_Delete(json);
    rad_free(facts.luminaires);
    return r;
}

/* ---- from a file ---- */

rad_result rad_import_assimp_file(rad_context *ctx, const char *path, rad_scene **out)
{
    *out = NULL;
    rad_input_log log = {0};
    rad_input_log_add(&log, path);
    if (rad_input_log_confine(ctx, &log, path) != RAD_OK) {
        rad_input_log_free(&log);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    import_input in;
    rad_result r = import_input_read_file(ctx, path, &log, &in);
    import_files files = {ctx, &in, &log, false};
    struct aiFileIO io;
    import_io(&io, &files);
    if (r == RAD_OK)
        r = import_scene(ctx, path, &in, &io, out);
    if (r == RAD_OK && files.out_of_memory) { /* the allocator named the file */
        rad_scene_destroy(*out);
        *out = NULL;
        r = RAD_ERROR_OUT_OF_MEMORY;
    }
    if (log.refused && (r == RAD_OK || r == RAD_ERROR_PARSE)) {
        /* The refusal is the cause (and the message kept); a scene that
         * loaded without the file is still refused: it asked for it. */
        if (r == RAD_OK)
            rad_scene_destroy(*out);
        *out = NULL;
        r = RAD_ERROR_IO;
    }
    if (r == RAD_OK && log.failed) {
        r = rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
        rad_scene_destroy(*out);
        *out = NULL;
    }
    if (r == RAD_OK) {
        rad_scene_set_inputs(*out, log.paths, log.count);
        log.paths = NULL;
        log.count = 0;
        import_notes_warn(ctx, path, &in.notes); /* said once the load stands */
    }
    rad_input_log_free(&log);
    import_input_free(&in);
    return r;
}

/* ---- from memory ---- */

rad_result rad_import_assimp_memory(rad_context *ctx, const char *name, const void *data,
                                    size_t size, const void *mtl, size_t mtl_size,
                                    rad_scene **out)
{
    *out = NULL;
    import_input in;
    rad_result r = import_input_from_memory(ctx, name, data, size, mtl, mtl_size, &in);
    if (r != RAD_OK)
        return r;
    import_files files = {ctx, &in, NULL, false};
    struct aiFileIO io;
    import_io(&io, &files);
    r = import_scene(ctx, name, &in, &io, out);
    if (r == RAD_OK && files.out_of_memory) { /* the allocator named the file */
        rad_scene_destroy(*out);
        *out = NULL;
        r = RAD_ERROR_OUT_OF_MEMORY;
    }
    if (r == RAD_OK)
        import_notes_warn(ctx, name, &in.notes); /* said once the load stands */
    import_input_free(&in);
    return r;
}
