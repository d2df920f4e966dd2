/*
 * import_assimp.c -- OBJ(+MTL) and glTF 2.0 (and whatever else assimp
 * reads) into a rad_scene, from a file or from memory.
 *
 *   bytes --pre-scan (OBJ, MTL)--> assimp (no post-processing)
 *         --node tree, transforms applied--> rad_scene_builder --> rad_scene
 *
 * A surface is a node (OBJ `o`/`g`, glTF node): its name, else its mesh's,
 * else "surface_N".  Polygons keep their vertex count (no
 * aiProcess_Triangulate): the builder splits only non-planar ones.
 *
 * assimp 5.2 falls short in a few places, each patched here in one spot:
 *  - its OBJ parser reads "nan", garbage and out-of-range numbers
 *    leniently and reports no line numbers, so a light pre-scan of the OBJ
 *    and MTL text checks vertex coordinates, face indices and Kd/Ke first;
 *  - it stores coordinates and colours as float (ai_real): decimal_of()
 *    maps them back to the decimal the file most likely held;
 *  - it ignores KHR_materials_emissive_strength, turns the glTF camera's
 *    yfov into an approximate horizontal angle and copies the camera node's
 *    translation into aiCamera::mPosition (counting it twice): the glTF
 *    JSON is read with cJSON for the strength and yfov, and a glTF camera
 *    is placed as the glTF 2.0 spec says (at its node's origin, looking
 *    down -Z with +Y up).
 * MTL/glTF emissive colours are emitted RADIANCE: exitance E = pi * Ke.
 * Loading from memory goes through an aiFileIO that serves the buffer under
 * its name and the MTL text under any *.mtl name the OBJ asks for.
 */
#include "scene/scene.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <cjson/cJSON.h>

#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* ---- reading text line by line (buffers need not end in NUL) ---- */

typedef struct text_lines {
    const char *next, *end;
    int number; /* 1-based number of the line last returned */
} text_lines;

static text_lines text_lines_of(const char *text, size_t size)
{
    text_lines t = {text, text + size, 0};
    return t;
}

/* The next line, without its end of line, in [*line, *line_end). */
static bool next_line(text_lines *t, const char **line, const char **line_end)
{
    if (t->next >= t->end)
        return false;
    const char *start = t->next;
    const char *newline = memchr(start, '\n', (size_t)(t->end - start));
    const char *stop = newline ? newline : t->end;
    t->next = newline ? newline + 1 : t->end;
    if (stop > start && stop[-1] == '\r')
        stop--;
    t->number++;
    *line = start;
    *line_end = stop;
    return true;
}

/* Copy the next blank-separated token of [*p, end) into `token` (cut to
 * TOKEN_SIZE - 1 characters) and return its full length; 0 at the end.
 * Blanks are spaces and tabs only, as assimp has them: a form feed or
 * vertical tab is part of a token, so "v\v1 2 3" is no vertex here either. */
enum { TOKEN_SIZE = 128 };

static bool is_blank(char c) { return c == ' ' || c == '\t'; }

static size_t next_token(const char **p, const char *end, char *token)
{
    const char *s = *p;
    while (s < end && is_blank(*s))
        s++;
    const char *e = s;
    while (e < end && !is_blank(*e))
        e++;
    size_t length = (size_t)(e - s);
    size_t copied = length < TOKEN_SIZE - 1 ? length : TOKEN_SIZE - 1;
    memcpy(token, s, copied);
    token[copied] = '\0';
    *p = e;
    return length;
}

/* The rest of the line, blanks trimmed, cut to `size` - 1 characters. */
static void rest_of_line(const char *p, const char *end, char *out, size_t size)
{
    while (p < end && isspace((unsigned char)*p))
        p++;
    while (end > p && isspace((unsigned char)end[-1]))
        end--;
    size_t length = (size_t)(end - p) < size - 1 ? (size_t)(end - p) : size - 1;
    memcpy(out, p, length);
    out[length] = '\0';
}

typedef enum number_kind { NUMBER_FINITE, NUMBER_NOT_FINITE, NUMBER_GARBAGE } number_kind;

/* A number as OBJ and MTL files write it: digits, sign, '.' and an
 * exponent ("1", "-0.5", ".5", "2e-3"); assimp misreads "0x1p3", so that
 * is garbage here.  "nan", "inf" and "1e999" are numbers that are not
 * finite. */
static number_kind parse_number(const char *token, size_t length, double *value)
{
    if (length == 0 || length >= TOKEN_SIZE)
        return NUMBER_GARBAGE;
    char *end;
    *value = strtod(token, &end);
    if (end != token + length)
        return NUMBER_GARBAGE;
    if (!isfinite(*value))
        return NUMBER_NOT_FINITE;
    return strspn(token, "0123456789+-.eE") == length ? NUMBER_FINITE : NUMBER_GARBAGE;
}

/* ---- pre-scan of OBJ and MTL text: line-numbered errors assimp omits ---- */

/* Statements of the OBJ format (Wavefront, "Object Files (.obj)", Appendix
 * B1 of the Advanced Visualizer manual); anything else means the text is
 * not an OBJ file. */
static const char *const obj_statements[] = {
    "v", "vt", "vn", "vp", "f", "fo", "l", "p", "g", "o", "s", "mg", "mtllib", "usemtl",
    "usemap", "maplib", "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm",
    "trim", "hole", "scrv", "sp", "end", "con", "bevel", "c_interp", "d_interp", "lod",
    "shadow_obj", "trace_obj", "ctech", "stech", "call", "csh",
};

static bool is_obj_statement(const char *token)
{
    for (size_t i = 0; i < sizeof obj_statements / sizeof obj_statements[0]; i++)
        if (strcmp(token, obj_statements[i]) == 0)
            return true;
    return false;
}

/* A line holding a NUL byte: assimp stops reading there, so the rest of
 * the file would be silently lost. */
static bool has_nul(const char *line, const char *end)
{
    /* A loop, not memchr: GCC 12 at -O3 misjudges memchr's bound here. */
    for (const char *c = line; c < end; c++)
        if (*c == '\0')
            return true;
    return false;
}

/* What the slots of a face vertex "v/vt/vn" index, and their statements. */
static const char *const face_slot_names[3] = {"vertex", "texture coordinate", "normal"};
static const char *const face_slot_statements[3] = {"v", "vt", "vn"};

static int face_slot_of(const char *statement)
{
    for (int k = 0; k < 3; k++)
        if (strcmp(statement, face_slot_statements[k]) == 0)
            return k;
    return -1;
}

/* Check one face vertex, "v", "v/vt", "v//vn" or "v/vt/vn": each index
 * in 1..total, or relative (-1 = the latest seen so far). */
static rad_result check_face_vertex(rad_context *ctx, const char *path, int line,
                                    const char *token, const size_t total[3],
                                    const size_t seen[3])
{
    const char *part = token;
    for (int slot = 0; slot < 3; slot++) {
        const char *slash = strchr(part, '/');
        size_t length = slash ? (size_t)(slash - part) : strlen(part);
        if (length > 0 || slot == 0) {
            char *after;
            errno = 0;
            long index = strtol(part, &after, 10);
            if (length == 0 || !strchr("0123456789+-", part[0]) || after != part + length)
                return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: face has a malformed vertex '%s'",
                                path, line, token);
            size_t available = index < 0 ? seen[slot] : total[slot];
            bool in_range = errno == 0 && index != 0 &&
                            (index > 0 ? (unsigned long)index <= available
                                       : (unsigned long)(-(index + 1)) < available);
            if (!in_range)
                return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: face references %s %ld of %zu",
                                path, line, face_slot_names[slot], index, available);
        }
        if (!slash)
            return RAD_OK;
        part = slash + 1;
    }
    return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: face has a malformed vertex '%s'", path, line,
                    token);
}

/* Check an OBJ where assimp would silently misread it or fail without a
 * line number: text without NUL bytes, known statements, none indented,
 * vertices of 3, 4 or 6 finite numbers (assimp drops other vertices and
 * divides by the 4th), face, line and point indices in range.  Writes
 * the first `mtllib` name (or "") and its line.  Not a parser: assimp
 * reads the file afterwards. */
static rad_result prescan_obj(rad_context *ctx, const char *path, const char *text, size_t size,
                              char *mtllib, size_t mtllib_size, int *mtllib_line)
{
    char token[TOKEN_SIZE];
    const char *p, *end;
    size_t total[3] = {0, 0, 0}; /* v, vt, vn in the whole file */
    mtllib[0] = '\0';
    *mtllib_line = 0;
    text_lines lines = text_lines_of(text, size);
    while (next_line(&lines, &p, &end)) {
        if (has_nul(p, end))
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: NUL byte in the text", path,
                            lines.number);
        bool indented = p < end && is_blank(*p);
        if (next_token(&p, end, token) == 0 || token[0] == '#')
            continue;
        if (indented) /* assimp skips such a line without a word */
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: statement '%s' is indented", path,
                            lines.number, token);
        int slot = face_slot_of(token);
        if (slot >= 0)
            total[slot]++;
        if (slot == 0) {
            size_t length;
            int coordinates = 0;
            double value = 1.0;
            while ((length = next_token(&p, end, token)) > 0) {
                number_kind kind = parse_number(token, length, &value);
                if (token[0] == '.') /* assimp does not count ".5" as a coordinate */
                    kind = NUMBER_GARBAGE;
                if (kind != NUMBER_FINITE)
                    return rad_fail(ctx,
                                    kind == NUMBER_GARBAGE ? RAD_ERROR_PARSE
                                                           : RAD_ERROR_INVALID_SCENE,
                                    "%s:%d: vertex coordinate '%s' is not a finite number", path,
                                    lines.number, token);
                coordinates++;
            }
            if (coordinates != 3 && coordinates != 4 && coordinates != 6)
                return rad_fail(ctx, RAD_ERROR_PARSE,
                                "%s:%d: vertex has %d numbers (3, 4 or 6 expected)", path,
                                lines.number, coordinates);
            if (coordinates == 4 && value == 0.0) /* x y z w: assimp divides by w */
                return rad_fail(ctx, RAD_ERROR_INVALID_SCENE, "%s:%d: vertex has weight w = 0",
                                path, lines.number);
        } else if (strcmp(token, "mtllib") == 0) {
            if (!mtllib[0]) {
                rest_of_line(p, end, mtllib, mtllib_size);
                *mtllib_line = lines.number;
            }
        } else if (!is_obj_statement(token)) {
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: unknown statement '%s'", path,
                            lines.number, token);
        }
    }

    /* Second pass: faces may name vertices defined later in the file;
     * relative (negative) indices count back from the latest one. */
    size_t seen[3] = {0, 0, 0};
    lines = text_lines_of(text, size);
    while (next_line(&lines, &p, &end)) {
        next_token(&p, end, token);
        int slot = face_slot_of(token);
        if (slot >= 0)
            seen[slot]++;
        /* assimp reads points and lines with the face code: check them too */
        if (strcmp(token, "f") != 0 && strcmp(token, "fo") != 0 && strcmp(token, "l") != 0 &&
            strcmp(token, "p") != 0)
            continue;
        while (next_token(&p, end, token) > 0) {
            rad_result r = check_face_vertex(ctx, path, lines.number, token, total, seen);
            if (r != RAD_OK)
                return r;
        }
    }
    return RAD_OK;
}

/* Check an MTL: nothing before the first newmtl; Kd (reflectance) and Ke
 * (emitted radiance) are 3 finite numbers, Kd in [0, 1) and Ke >= 0. */
static rad_result prescan_mtl(rad_context *ctx, const char *path, const char *text, size_t size)
{
    char token[TOKEN_SIZE], material[64] = "";
    const char *p, *end;
    bool seen_newmtl = false;
    text_lines lines = text_lines_of(text, size);
    while (next_line(&lines, &p, &end)) {
        if (has_nul(p, end))
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: NUL byte in the text", path,
                            lines.number);
        if (next_token(&p, end, token) == 0 || token[0] == '#')
            continue;
        if (strcmp(token, "newmtl") == 0) {
            rest_of_line(p, end, material, sizeof material);
            seen_newmtl = true;
            continue;
        }
        /* Every statement belongs to a material; assimp 5.2 dereferences a
         * null material for a texture map (map_Kd ...) before the first
         * newmtl (found by fuzz_mtl). */
        if (!seen_newmtl)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: '%s' before any 'newmtl'", path,
                            lines.number, token);
        bool is_kd = strcasecmp(token, "Kd") == 0, is_ke = strcasecmp(token, "Ke") == 0;
        if (!is_kd && !is_ke)
            continue;
        const char *key = is_kd ? "Kd" : "Ke";
        double values[3];
        int count = 0;
        size_t length;
        while ((length = next_token(&p, end, token)) > 0) {
            if (count == 3 || parse_number(token, length, &values[count]) != NUMBER_FINITE)
                return rad_fail(ctx, RAD_ERROR_PARSE,
                                "%s:%d: material '%s': %s value '%s' is not a finite number",
                                path, lines.number, material, key, token);
            count++;
        }
        if (count != 3) /* assimp reads "Kd 0.5" as (0.5, 0, 0) */
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: material '%s': %s needs 3 numbers",
                            path, lines.number, material, key);
        for (int c = 0; c < count; c++) {
            if (is_kd && !(values[c] >= 0.0 && values[c] < 1.0))
                return rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                                "%s:%d: material '%s': reflectance (Kd) %g is outside [0, 1)",
                                path, lines.number, material, values[c]);
            if (is_ke && values[c] < 0.0)
                return rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                                "%s:%d: material '%s': emission (Ke) %g is negative", path,
                                lines.number, material, values[c]);
        }
    }
    return RAD_OK;
}

/* ---- glTF JSON: what assimp 5.2 does not pass on ---- */

/* A little-endian 32-bit number, as GLB headers store them. */
static size_t le32(const unsigned char *p)
{
    return (size_t)p[0] | (size_t)p[1] << 8 | (size_t)p[2] << 16 | (size_t)p[3] << 24;
}

/* The JSON of a .gltf (all of it) or a .glb (its first chunk), parsed;
 * NULL if it is not JSON (assimp then reports the problem). */
static cJSON *gltf_json(const char *data, size_t size, bool binary)
{
    if (!binary)
        return cJSON_ParseWithLength(data, size);
    /* GLB: magic "glTF", version, length; then chunk length, "JSON", text. */
    const unsigned char *bytes = (const unsigned char *)data;
    if (size < 20 || memcmp(bytes, "glTF", 4) != 0 || memcmp(bytes + 16, "JSON", 4) != 0)
        return NULL;
    size_t length = le32(bytes + 12);
    if (length > size - 20)
        return NULL;
    return cJSON_ParseWithLength(data + 20, length);
}

/* Check the framing of a GLB file before assimp reads it: assimp 5.2
 * allocates what the header and chunk headers claim before comparing it
 * with the file's size, so a 40-byte file claiming a 4 GiB chunk costs
 * 4 GiB.  Header: magic "glTF", version, total length; then chunks of
 * (length, type, data), each within the file. */
static rad_result check_glb_framing(rad_context *ctx, const char *name, const char *data,
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
        offset += 8 + length;
    }
    return RAD_OK;
}

/* KHR_materials_emissive_strength of the glTF material assimp imported as
 * material `index` named `name`: assimp keeps the glTF order (and appends a
 * default material), so match by index, by name when the names differ. */
static double gltf_emissive_strength(const cJSON *materials, unsigned index, const char *name)
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
    const cJSON *extensions = cJSON_GetObjectItemCaseSensitive(match, "extensions");
    const cJSON *extension =
        cJSON_GetObjectItemCaseSensitive(extensions, "KHR_materials_emissive_strength");
    const cJSON *strength = cJSON_GetObjectItemCaseSensitive(extension, "emissiveStrength");
    return cJSON_IsNumber(strength) ? strength->valuedouble : 1.0;
}

/* The full vertical field of view (radians) of the first glTF camera, or 0. */
static double gltf_first_camera_yfov(const cJSON *root)
{
    const cJSON *cameras = cJSON_GetObjectItemCaseSensitive(root, "cameras");
    const cJSON *perspective =
        cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(cameras, 0), "perspective");
    const cJSON *yfov = cJSON_GetObjectItemCaseSensitive(perspective, "yfov");
    return cJSON_IsNumber(yfov) ? yfov->valuedouble : 0.0;
}

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
} converter;

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
            strength = gltf_emissive_strength(cv->gltf_materials, index, name.data);
        emission[0] = M_PI * decimal_of(color.r) * strength;
        emission[1] = M_PI * decimal_of(color.g) * strength;
        emission[2] = M_PI * decimal_of(color.b) * strength;
    }
    cv->material_of[index] = rad_scene_builder_material(cv->builder, name.data, reflectance,
                                                        emission);
    return cv->material_of[index];
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
    for (unsigned f = 0; f < mesh->mNumFaces; f++) {
        const struct aiFace *face = &mesh->mFaces[f];
        if (face->mNumIndices < 3)
            continue; /* points and lines */
        if (surface < 0) {
            surface = rad_scene_builder_surface(cv->builder, surface_name);
            material = surface < 0 ? -1 : convert_material(cv, mesh->mMaterialIndex);
            if (material < 0)
                return cv->ctx ? cv->ctx->last_result : RAD_ERROR_INVALID_SCENE;
        }
        if (face->mNumIndices > cv->face_capacity) {
            vec3 *grown = realloc(cv->face, face->mNumIndices * sizeof *grown);
            if (!grown)
                return rad_fail(cv->ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory",
                                cv->name);
            cv->face = grown;
            cv->face_capacity = face->mNumIndices;
        }
        for (unsigned i = 0; i < face->mNumIndices; i++) {
            unsigned v = face->mIndices[i];
            if (v >= mesh->mNumVertices)
                return rad_fail(cv->ctx, RAD_ERROR_PARSE,
                                "%s: mesh '%s': face references vertex %u of %u", cv->name,
                                mesh->mName.data, v, mesh->mNumVertices);
            cv->face[i] = affine_point(world, vec3_of(&mesh->mVertices[v]));
        }
        rad_result r = rad_scene_builder_polygon(cv->builder, surface, material, cv->face,
                                                 face->mNumIndices, 0);
        if (r != RAD_OK)
            return r;
    }
    return RAD_OK;
}

static rad_result convert_node(converter *cv, const struct aiNode *node, const affine *parent)
{
    affine world = affine_then(parent, &node->mTransformation);
    for (unsigned k = 0; k < node->mNumMeshes; k++) {
        if (node->mMeshes[k] >= cv->ai->mNumMeshes)
            return rad_fail(cv->ctx, RAD_ERROR_PARSE, "%s: node '%s' refers to mesh %u of %u",
                            cv->name, node->mName.data, node->mMeshes[k], cv->ai->mNumMeshes);
        rad_result r = convert_mesh(cv, node, node->mMeshes[k], &world);
        if (r != RAD_OK)
            return r;
    }
    for (unsigned c = 0; c < node->mNumChildren; c++) {
        rad_result r = convert_node(cv, node->mChildren[c], &world);
        if (r != RAD_OK)
            return r;
    }
    return RAD_OK;
}

/* The world transform of the node called `name`; false if there is none. */
static bool find_node(const struct aiNode *node, const char *name, const affine *parent,
                      affine *world)
{
    affine here = affine_then(parent, &node->mTransformation);
    if (strcmp(node->mName.data, name) == 0) {
        *world = here;
        return true;
    }
    for (unsigned c = 0; c < node->mNumChildren; c++)
        if (find_node(node->mChildren[c], name, &here, world))
            return true;
    return false;
}

/* The first camera, placed by its node.  `gltf_yfov` (radians, 0 if
 * unknown) overrides assimp's field of view for glTF. */
static void convert_camera(converter *cv, bool gltf, double gltf_yfov)
{
    const struct aiCamera *camera = cv->ai->mCameras[0];
    affine identity = affine_identity(), world = identity;
    find_node(cv->ai->mRootNode, camera->mName.data, &identity, &world);
    vec3 position = v3(0.0, 0.0, 0.0), direction = v3(0.0, 0.0, -1.0), up = v3(0.0, 1.0, 0.0);
    if (!gltf) {
        position = vec3_of(&camera->mPosition);
        direction = vec3_of(&camera->mLookAt); /* a direction, not a point */
        up = vec3_of(&camera->mUp);
    }
    position = affine_point(&world, position);
    direction = affine_direction(&world, direction);
    up = v3_normalize(affine_direction(&world, up));
    double vfov = gltf_yfov;
    if (!(vfov > 0.0)) {
        /* Read as the full horizontal angle, as assimp's importers fill it. */
        double aspect = camera->mAspect > 0.0f ? (double)camera->mAspect : 1.0;
        vfov = 2.0 * atan(tan(0.5 * (double)camera->mHorizontalFOV) / aspect);
    }
    rad_camera c = {
        .position = {position.x, position.y, position.z},
        .look_at = {position.x + direction.x, position.y + direction.y, position.z + direction.z},
        .up = {up.x, up.y, up.z},
        .vfov_degrees = vfov * 180.0 / M_PI,
    };
    rad_scene_builder_camera(cv->builder, &c);
}

/* Import `name` with assimp (through `io`, or the file system when NULL);
 * `data` holds the file's bytes when the caller has them (glTF needs them
 * for the JSON), else NULL. */
static rad_result import_scene(rad_context *ctx, const char *name, const char *data, size_t size,
                               struct aiFileIO *io, rad_scene **out)
{
    char extension[16];
    rad_path_extension(name, extension, sizeof extension);
    bool gltf = strcmp(extension, "gltf") == 0 || strcmp(extension, "glb") == 0;
    bool glb = strcmp(extension, "glb") == 0;
    if (glb && data) {
        rad_result framing = check_glb_framing(ctx, name, data, size);
        if (framing != RAD_OK)
            return framing;
    }
    cJSON *json = gltf && data ? gltf_json(data, size, glb) : NULL;

    struct aiPropertyStore *properties = aiCreatePropertyStore();
    if (!properties) {
        cJSON_Delete(json);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    /* A skeleton without meshes must not turn into stick-figure polygons. */
    aiSetImportPropertyInteger(properties, AI_CONFIG_IMPORT_NO_SKELETON_MESHES, 1);
    /* No post-processing: no triangulation, and nothing that merges or
     * drops meshes (aiProcess_ValidateDataStructure even rejects OBJ
     * files with a 2-vertex face beside polygons; the walk below checks
     * every index itself). */
    const struct aiScene *ai = aiImportFileExWithProperties(name, 0, io, properties);
    aiReleasePropertyStore(properties);
    if (!ai) {
        const char *why = aiGetErrorString();
        cJSON_Delete(json);
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s: %s", name,
                        why && *why ? why : "assimp could not read it");
    }

    rad_result r = RAD_OK;
    converter cv = {.ctx = ctx, .name = name, .ai = ai};
    cv.gltf_materials = cJSON_GetObjectItemCaseSensitive(json, "materials");
    if (!ai->mRootNode || ai->mNumMeshes == 0) {
        r = rad_fail(ctx, RAD_ERROR_INVALID_SCENE, "%s: scene is empty (no polygons)", name);
        goto done;
    }
    cv.builder = rad_scene_builder_create(ctx, name);
    cv.material_of = rad_alloc_array(ctx, ai->mNumMaterials, sizeof *cv.material_of, "materials");
    if (!cv.builder || !cv.material_of) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    for (unsigned i = 0; i < ai->mNumMaterials; i++)
        cv.material_of[i] = -1;
    affine identity = affine_identity();
    r = convert_node(&cv, ai->mRootNode, &identity);
    if (r != RAD_OK)
        goto done;
    if (ai->mNumCameras > 0 && ai->mCameras[0])
        convert_camera(&cv, gltf, gltf_first_camera_yfov(json));
    r = rad_scene_builder_finish(cv.builder, out);
    cv.builder = NULL;

done:
    rad_scene_builder_destroy(cv.builder);
    free(cv.material_of);
    free(cv.face);
    aiReleaseImport(ai);
    cJSON_Delete(json);
    return r;
}

/* ---- from a file ---- */

/* Read a whole file; RAD_ERROR_IO naming `what` (the path, or
 * "PATH:LINE: material library 'NAME'") when it cannot be read. */
static rad_result read_file(rad_context *ctx, const char *path, const char *what, char **text,
                            size_t *size)
{
    *text = NULL;
    *size = 0;
    FILE *file = fopen(path, "rb");
    if (!file)
        return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot open: %s", what, strerror(errno));
    size_t capacity = 1 << 16, length = 0;
    char *buffer = malloc(capacity);
    while (buffer) {
        length += fread(buffer + length, 1, capacity - length, file);
        if (length < capacity)
            break;
        char *grown = capacity <= SIZE_MAX / 2 ? realloc(buffer, capacity * 2) : NULL;
        if (!grown) {
            free(buffer);
            buffer = NULL;
            break;
        }
        buffer = grown;
        capacity *= 2;
    }
    if (!buffer) {
        fclose(file);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory reading it", what);
    }
    int failed = ferror(file), error = errno;
    fclose(file);
    if (failed) {
        free(buffer);
        return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot read: %s", what, strerror(error));
    }
    *text = buffer;
    *size = length;
    return RAD_OK;
}

/* Pre-scan the material library an OBJ file names, relative to its folder. */
static rad_result prescan_mtl_file(rad_context *ctx, const char *obj_path, const char *mtllib,
                                   int line)
{
    const char *slash = strrchr(obj_path, '/');
    size_t folder = mtllib[0] == '/' || !slash ? 0 : (size_t)(slash - obj_path) + 1;
    size_t length = folder + strlen(mtllib) + 1;
    char *path = malloc(length);
    if (!path)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", obj_path);
    memcpy(path, obj_path, folder);
    memcpy(path + folder, mtllib, length - folder);

    char what[512];
    snprintf(what, sizeof what, "%s:%d: material library '%s'", obj_path, line, mtllib);
    char *text;
    size_t size;
    rad_result r = read_file(ctx, path, what, &text, &size);
    if (r == RAD_OK)
        r = prescan_mtl(ctx, path, text, size);
    free(text);
    free(path);
    return r;
}

rad_result rad_import_assimp_file(rad_context *ctx, const char *path, rad_scene **out)
{
    *out = NULL;
    char extension[16];
    rad_path_extension(path, extension, sizeof extension);
    bool is_obj = strcmp(extension, "obj") == 0;
    bool wanted = is_obj || strcmp(extension, "gltf") == 0 || strcmp(extension, "glb") == 0;
    char *text = NULL;
    size_t size = 0;
    rad_result r = RAD_OK;
    if (wanted) {
        r = read_file(ctx, path, path, &text, &size);
    } else {
        /* Open and read a byte for the errno text assimp does not give
         * (a folder opens but cannot be read). */
        FILE *file = fopen(path, "rb");
        if (!file)
            return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
        int unreadable = fgetc(file) == EOF && ferror(file), error = errno;
        fclose(file);
        if (unreadable)
            return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot read: %s", path, strerror(error));
    }
    if (r == RAD_OK && is_obj) {
        char mtllib[256];
        int mtllib_line;
        r = prescan_obj(ctx, path, text, size, mtllib, sizeof mtllib, &mtllib_line);
        if (r == RAD_OK && mtllib[0])
            r = prescan_mtl_file(ctx, path, mtllib, mtllib_line);
    }
    if (r == RAD_OK)
        r = import_scene(ctx, path, text, size, NULL, out);
    free(text);
    return r;
}

/* ---- from memory: a one-file (plus MTL) file system for assimp ---- */

typedef struct memory_fs {
    const char *name; /* the main buffer's file name */
    const char *data;
    size_t size;
    const char *mtl; /* served under any *.mtl name; NULL if none */
    size_t mtl_size;
} memory_fs;

typedef struct memory_file {
    struct aiFile file;
    const char *data;
    size_t size, position;
} memory_file;

static memory_file *memory_file_of(struct aiFile *file)
{
    return (memory_file *)(void *)file->UserData;
}

static size_t memory_read(struct aiFile *file, char *buffer, size_t size, size_t count)
{
    memory_file *m = memory_file_of(file);
    if (size == 0 || m->position >= m->size)
        return 0;
    size_t whole = (m->size - m->position) / size;
    if (count > whole)
        count = whole;
    memcpy(buffer, m->data + m->position, count * size);
    m->position += count * size;
    return count;
}

static size_t memory_write(struct aiFile *file, const char *buffer, size_t size, size_t count)
{
    (void)file;
    (void)buffer;
    (void)size;
    (void)count;
    return 0; /* read-only */
}

static size_t memory_tell(struct aiFile *file) { return memory_file_of(file)->position; }

static size_t memory_size(struct aiFile *file) { return memory_file_of(file)->size; }

/* Offsets wrap like assimp's own MemoryIOStream: aiOrigin_END counts back
 * from the end, and a "negative" aiOrigin_CUR offset arrives as a huge
 * size_t that wraps around. */
static enum aiReturn memory_seek(struct aiFile *file, size_t offset, enum aiOrigin origin)
{
    memory_file *m = memory_file_of(file);
    size_t target = origin == aiOrigin_END   ? m->size - offset
                    : origin == aiOrigin_CUR ? m->position + offset
                                             : offset;
    if ((origin == aiOrigin_END && offset > m->size) || target > m->size)
        return aiReturn_FAILURE;
    m->position = target;
    return aiReturn_SUCCESS;
}

static void memory_flush(struct aiFile *file) { (void)file; }

static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/'), *backslash = strrchr(path, '\\');
    if (backslash && (!slash || backslash > slash))
        slash = backslash;
    return slash ? slash + 1 : path;
}

static struct aiFile *memory_open(struct aiFileIO *io, const char *path, const char *mode)
{
    const memory_fs *fs = (const memory_fs *)(void *)io->UserData;
    if (!path || !mode || strpbrk(mode, "wa+"))
        return NULL;
    char extension[16];
    rad_path_extension(path, extension, sizeof extension);
    const char *data;
    size_t size;
    if (strcmp(base_name(path), base_name(fs->name)) == 0) {
        data = fs->data;
        size = fs->size;
    } else if (fs->mtl && strcmp(extension, "mtl") == 0) {
        data = fs->mtl;
        size = fs->mtl_size;
    } else {
        return NULL;
    }
    memory_file *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    m->data = data;
    m->size = size;
    m->file.ReadProc = memory_read;
    m->file.WriteProc = memory_write;
    m->file.TellProc = memory_tell;
    m->file.FileSizeProc = memory_size;
    m->file.SeekProc = memory_seek;
    m->file.FlushProc = memory_flush;
    m->file.UserData = (aiUserData)(void *)m;
    return &m->file;
}

static void memory_close(struct aiFileIO *io, struct aiFile *file)
{
    (void)io;
    if (file)
        free(memory_file_of(file));
}

rad_result rad_import_assimp_memory(rad_context *ctx, const char *name, const void *data,
                                    size_t size, const void *mtl, size_t mtl_size,
                                    rad_scene **out)
{
    *out = NULL;
    char extension[16];
    rad_path_extension(name, extension, sizeof extension);
    if (strcmp(extension, "obj") == 0) {
        char mtllib[256];
        int mtllib_line;
        rad_result r = prescan_obj(ctx, name, data, size, mtllib, sizeof mtllib, &mtllib_line);
        if (r != RAD_OK)
            return r;
        if (mtl) {
            /* Messages name the library as the OBJ does, else as NAME.mtl. */
            char mtl_name[256];
            if (mtllib[0])
                snprintf(mtl_name, sizeof mtl_name, "%s", mtllib);
            else
                snprintf(mtl_name, sizeof mtl_name, "%.*s.mtl", (int)(strlen(name) - 4), name);
            r = prescan_mtl(ctx, mtl_name, mtl, mtl_size);
            if (r != RAD_OK)
                return r;
        }
    }
    memory_fs fs = {name, data, size, mtl, mtl_size};
    struct aiFileIO io = {memory_open, memory_close, (aiUserData)(void *)&fs};
    return import_scene(ctx, name, data, size, &io, out);
}
