/*
 * gltf_check.c -- a glTF 2.0 file checked on its JSON and its buffers
 * before assimp 5.2 reads it, and the camera the scene is seen through.
 *
 *   JSON (cJSON) --version-->  2.x only
 *                --nodes--->   disjoint strict trees, at most GLTF_MAX_DEPTH
 *                              levels; finite transforms
 *                --meshes-->   topology and counts; accessors inside their
 *                              views and buffers, sparse ones complete;
 *                              indices unsigned and below the vertex count;
 *                              positions finite float triples
 *                --memory-->   assimp's nodes, faces, vertices and buffers,
 *                              and our triangles after instancing, against
 *                              the memory limit
 *                --camera-->   the first perspective camera of the scene
 *
 * assimp 5.2 reads the node tree recursively (about 400 bytes of stack a
 * level: 20,000 nested nodes overflow an 8 MiB stack), copies a subtree for
 * every parent that lists it (ten parents a level: 10^8 copies from 1.8 KB),
 * drops a triangle whose index is out of range without a word, reads a
 * float index accessor as integers, a short POSITION as floats, allocates
 * 2^32 faces for a one-index triangle strip, and dereferences a sparse
 * accessor's missing buffer view.  Each is refused here, naming the file and
 * the node, mesh, primitive or accessor.
 *
 * Rules from the Khronos glTF 2.0 specification: "Nodes and Hierarchy" (the
 * hierarchy is a set of disjoint strict trees: no cycles, one parent at
 * most; a scene lists root nodes), "Accessors" (index component types,
 * sparse accessors: indices strictly increasing), "Meshes" (topologies and
 * their counts), "Cameras" (a camera looks down its node's -Z with +Y up).
 * Buffers are read through the import's file system (for a file import the
 * confined and logged one; a memory import has only its data: URIs and its
 * GLB chunk), a block at a time.
 */
#include "import/import_internal.h"
#include "photometry/layout.h"

#include <assimp/cfileio.h>
#include <cjson/cJSON.h>

#include <stdarg.h>
#include <stdint.h>
#include <string.h>

/* Levels of node nesting read: 1,000.  assimp 5.2 reads the tree with two
 * recursive calls a level, about 400 bytes of stack (measured: 1,000 levels
 * need between 256 and 512 KiB; 17,000 overflow the main thread's 8 MiB);
 * 1,000 levels leave room on any thread with 1 MiB or more, under the
 * sanitizers too, and are far deeper than any skeleton or assembly. */
#define GLTF_MAX_DEPTH 1000

/* What assimp 5.2 takes while importing, measured with its glTF reader
 * (peak resident set of an import less the process before it):
 *  - a node: 2.2 KiB (10^6 empty nodes, 2.2 GB: its aiNode with a 1 KiB
 *    name, the reader's node, the JSON tree of two parsers), 2.5 KiB here;
 *  - a face: 48 bytes (aiFace, its index array and their heap headers;
 *    10^6 triangles, 92 MB with their vertices and buffer);
 *  - a vertex: 12 bytes of position (its other attributes are copies of
 *    buffer bytes, counted with the buffers);
 *  - a buffer: its bytes, twice (the buffer, and the attributes copied out). */
#define ASSIMP_BYTES_PER_NODE 2560.0
#define ASSIMP_BYTES_PER_FACE 48.0
#define ASSIMP_BYTES_PER_VERTEX 12.0
#define ASSIMP_BUFFER_COPIES 2.0

/* The least the scene holds for one triangle of one instance: three
 * corners, their indices and the polygon (the builder keeps every corner). */
#define SCENE_BYTES_PER_TRIANGLE \
    (3.0 * sizeof(vec3) + 3.0 * sizeof(uint32_t) + (double)sizeof(rad_polygon))

#define GLTF_BLOCK 65536 /* bytes a stream reads at a time */
#define NONE SIZE_MAX

/* ---- JSON ---- */

static const cJSON *member(const cJSON *object, const char *key)
{
    return cJSON_IsObject(object) ? cJSON_GetObjectItemCaseSensitive(object, key) : NULL;
}

/* An index, count or offset: a whole JSON number in [0, 2^53). */
static bool json_whole(const cJSON *item, size_t *out)
{
    if (!cJSON_IsNumber(item))
        return false;
    double value = item->valuedouble;
    if (!(value >= 0.0 && value < 9007199254740992.0 && value <= (double)SIZE_MAX) ||
        value != floor(value))
        return false;
    *out = (size_t)value;
    return true;
}

/* An optional whole number: absent gives `fallback`; false if present and
 * not whole. */
static bool json_whole_or(const cJSON *object, const char *key, size_t fallback, size_t *out)
{
    const cJSON *item = member(object, key);
    *out = fallback;
    return !item || json_whole(item, out);
}

/* An array of `count` finite numbers into `values`; false otherwise. */
static bool json_numbers(const cJSON *array, int count, double *values)
{
    if (!cJSON_IsArray(array) || cJSON_GetArraySize(array) != count)
        return false;
    int i = 0;
    const cJSON *item;
    cJSON_ArrayForEach(item, array) {
        if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble))
            return false;
        values[i++] = item->valuedouble;
    }
    return true;
}

/* One top-level array of the glTF ("nodes", "accessors", ...) as a table,
 * so that items are found by index in O(1) (cJSON_GetArrayItem walks). */
typedef struct table {
    const cJSON **items;
    size_t count;
} table;

/* ---- the checker ---- */

enum buffer_kind { BUFFER_UNOPENED, BUFFER_BASE64, BUFFER_RAW, BUFFER_BIN, BUFFER_FILE };

typedef struct gltf_buffer {
    enum buffer_kind kind;
    const char *bytes;    /* base64 text, raw data or the BIN chunk */
    size_t declared;      /* byteLength */
    size_t available;     /* bytes its source holds */
    struct aiFile *file;  /* BUFFER_FILE: open until the check ends */
} gltf_buffer;

typedef struct checker {
    rad_context *ctx;
    const char *name;             /* the file, first in every message */
    struct aiFileIO *io;          /* opens external buffers */
    bool binary;                  /* a .glb */
    const char *bin;              /* its BIN chunk, or NULL */
    size_t bin_size;
    table nodes, meshes, accessors, views, buffers, cameras, scenes;
    gltf_buffer *buffer;          /* per buffer, opened on first use */
    double buffer_bytes;          /* the opened buffers' byteLengths */
    size_t *parent;               /* per node: its parent, or NONE */
    unsigned char *block[2];      /* two streams' blocks of GLTF_BLOCK bytes */
    unsigned char *positions_ok;  /* per accessor: its positions were found finite */
    unsigned char *indices_known; /* per accessor: index_max holds its largest index */
    uint64_t *index_max;
    size_t *index_max_at;         /* the element that holds it */
} checker;

/* Fail naming the file: "NAME: " then the formatted text. */
static rad_result fail(checker *c, rad_result code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static rad_result fail(checker *c, rad_result code, const char *fmt, ...)
{
    char text[900];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    return rad_fail(c->ctx, code, "%s: %s", c->name, text);
}

/* "node 'lamp' (3)", or "node 3" when it has no name. */
static const char *label(const table *t, size_t index, const char *kind, char *text, size_t size)
{
    const cJSON *name = index < t->count ? member(t->items[index], "name") : NULL;
    if (cJSON_IsString(name) && name->valuestring[0])
        snprintf(text, size, "%s '%.80s' (%zu)", kind, name->valuestring, index);
    else
        snprintf(text, size, "%s %zu", kind, index);
    return text;
}

/* The table of root[key]: absent is empty; not an array of objects fails. */
static rad_result table_of(checker *c, const cJSON *root, const char *key, table *t)
{
    const cJSON *array = member(root, key);
    t->items = NULL;
    t->count = 0;
    if (!array)
        return RAD_OK;
    if (!cJSON_IsArray(array))
        return fail(c, RAD_ERROR_PARSE, "'%s' is not an array", key);
    size_t count = (size_t)cJSON_GetArraySize(array);
    if (count == 0)
        return RAD_OK;
    t->items = rad_alloc(c->ctx, RAD_MEM_SCENE, count, sizeof *t->items, c->name);
    if (!t->items)
        return RAD_ERROR_OUT_OF_MEMORY;
    const cJSON *item;
    cJSON_ArrayForEach(item, array) {
        if (!cJSON_IsObject(item))
            return fail(c, RAD_ERROR_PARSE, "%s[%zu] is not an object", key, t->count);
        t->items[t->count++] = item;
    }
    return RAD_OK;
}

/* ---- buffers ---- */

static int base64_value(unsigned char ch)
{
    if (ch >= 'A' && ch <= 'Z')
        return ch - 'A';
    if (ch >= 'a' && ch <= 'z')
        return ch - 'a' + 26;
    if (ch >= '0' && ch <= '9')
        return ch - '0' + 52;
    return ch == '+' ? 62 : ch == '/' ? 63 : ch == '=' ? 0 : -1;
}

/* Bytes [offset, offset + length) of the base64 text (RFC 4648, section 4),
 * decoded a group of 4 characters (3 bytes) at a time; false on a
 * character outside the alphabet. */
static bool base64_read(const char *text, size_t offset, size_t length, unsigned char *out)
{
    size_t group = offset / 3, skip = offset % 3;
    while (length > 0) {
        const unsigned char *g = (const unsigned char *)text + 4 * group;
        int v[4];
        for (int k = 0; k < 4; k++)
            if ((v[k] = base64_value(g[k])) < 0)
                return false;
        unsigned char bytes[3] = {(unsigned char)(v[0] << 2 | v[1] >> 4),
                                  (unsigned char)((v[1] & 15) << 4 | v[2] >> 2),
                                  (unsigned char)((v[2] & 3) << 6 | v[3])};
        for (size_t k = skip; k < 3 && length > 0; k++, length--)
            *out++ = bytes[k];
        skip = 0;
        group++;
    }
    return true;
}

/* The folder of `name` with its slash ("" for a bare name), as assimp
 * joins a buffer's uri to it. */
static size_t folder_length(const char *name)
{
    const char *slash = strrchr(name, '/');
    return slash ? (size_t)(slash - name) + 1 : 0;
}

/* Count an opened buffer: assimp will hold it, and copies out of it; a
 * buffer that alone passes the memory limit is refused before a byte of it
 * is read. */
static rad_result buffer_count(checker *c, const gltf_buffer *b)
{
    c->buffer_bytes += (double)b->declared;
    double need = ASSIMP_BUFFER_COPIES * c->buffer_bytes, limit = rad_memory_limit(c->ctx);
    if (need <= limit)
        return RAD_OK;
    char need_text[32], limit_text[32];
    rad_format_bytes(need, need_text, sizeof need_text);
    rad_format_bytes(limit, limit_text, sizeof limit_text);
    return fail(c, RAD_ERROR_OUT_OF_MEMORY,
                "its buffers need about %s to import (%.0fx their size), above the memory "
                "limit of %s (rad_context_options.max_memory_bytes)",
                need_text, ASSIMP_BUFFER_COPIES, limit_text);
}

static rad_result buffer_open(checker *c, size_t index, gltf_buffer **out)
{
    gltf_buffer *b = &c->buffer[index];
    *out = b;
    if (b->kind != BUFFER_UNOPENED)
        return RAD_OK;
    char what[160];
    label(&c->buffers, index, "buffer", what, sizeof what);
    const cJSON *json = c->buffers.items[index];
    if (!json_whole(member(json, "byteLength"), &b->declared) || b->declared == 0)
        return fail(c, RAD_ERROR_PARSE, "%s: byteLength must be a whole number of at least 1",
                    what);
    const cJSON *uri = member(json, "uri");
    if (c->binary && index == 0) {
        /* assimp 5.2 reads a .glb's first buffer from its BIN chunk,
         * whatever its uri says */
        b->kind = BUFFER_BIN;
        b->bytes = c->bin;
        b->available = c->bin ? c->bin_size : 0;
        if (b->declared > b->available)
            return fail(c, RAD_ERROR_PARSE,
                        "%s: byteLength is %zu, but the BIN chunk has %zu bytes", what,
                        b->declared, b->available);
        return buffer_count(c, b);
    }
    if (!uri) {
        return fail(c, RAD_ERROR_PARSE,
                    "%s has no uri (only the first buffer of a .glb is its BIN chunk)", what);
    } else if (!cJSON_IsString(uri)) {
        return fail(c, RAD_ERROR_PARSE, "%s: uri is not a string", what);
    } else if (strncmp(uri->valuestring, "data:", 5) == 0) {
        /* data:[<media type>][;base64],<data> (RFC 2397) */
        const char *comma = strchr(uri->valuestring, ',');
        if (!comma)
            return fail(c, RAD_ERROR_PARSE, "%s: data URI without a ','", what);
        size_t header = (size_t)(comma - uri->valuestring), length = strlen(comma + 1);
        b->bytes = comma + 1;
        if (header >= 7 && memcmp(comma - 7, ";base64", 7) == 0) {
            size_t padding = length >= 1 && comma[length] == '=' ? 1 : 0;
            padding += length >= 2 && comma[length - 1] == '=' ? 1 : 0;
            if (length % 4 != 0)
                return fail(c, RAD_ERROR_PARSE,
                            "%s: base64 data of %zu characters (a multiple of 4 is needed)",
                            what, length);
            b->kind = BUFFER_BASE64;
            b->available = length / 4 * 3 - padding;
        } else {
            b->kind = BUFFER_RAW;
            b->available = length;
        }
    } else {
        size_t folder = folder_length(c->name), length = strlen(uri->valuestring);
        char *path = rad_alloc(c->ctx, RAD_MEM_SCENE, folder + length + 1, 1, c->name);
        if (!path)
            return RAD_ERROR_OUT_OF_MEMORY;
        memcpy(path, c->name, folder);
        memcpy(path + folder, uri->valuestring, length + 1);
        /* A refusal by the file system (outside the scene's folder) has
         * already named the file; this message is then not kept. */
        b->file = c->io->OpenProc(c->io, path, "rb");
        rad_free(path);
        if (!b->file)
            return fail(c, RAD_ERROR_IO, "%s: cannot open '%s'", what, uri->valuestring);
        b->kind = BUFFER_FILE;
        b->available = b->file->FileSizeProc(b->file);
    }
    if (b->declared > b->available)
        return fail(c, RAD_ERROR_PARSE, "%s: byteLength is %zu, but its data has %zu bytes", what,
                    b->declared, b->available);
    return buffer_count(c, b);
}

/* Bytes [offset, offset + length) of an opened buffer, within its
 * byteLength (the callers check). */
static rad_result buffer_read(checker *c, size_t index, size_t offset, size_t length,
                              unsigned char *out)
{
    gltf_buffer *b = &c->buffer[index];
    switch (b->kind) {
    case BUFFER_BASE64:
        if (!base64_read(b->bytes, offset, length, out))
            return fail(c, RAD_ERROR_PARSE, "buffer %zu: data URI is not base64", index);
        return RAD_OK;
    case BUFFER_RAW:
    case BUFFER_BIN:
        memcpy(out, b->bytes + offset, length);
        return RAD_OK;
    case BUFFER_FILE:
        if (b->file->SeekProc(b->file, offset, aiOrigin_SET) != aiReturn_SUCCESS ||
            b->file->ReadProc(b->file, (char *)out, 1, length) != length)
            return fail(c, RAD_ERROR_IO, "buffer %zu: cannot read bytes %zu to %zu", index, offset,
                        offset + length);
        return RAD_OK;
    default:
        return fail(c, RAD_ERROR_INTERNAL, "buffer %zu read before it was opened", index);
    }
}

/* Where `span` bytes from `offset` into buffer view `view` lie: the
 * buffer, the first byte in it, and the view's byteStride (0: none).
 * Fails, naming `what`, when the view or the bytes fall outside. */
static rad_result view_locate(checker *c, size_t view, size_t offset, size_t span,
                              const char *what, size_t *buffer, size_t *start, size_t *stride)
{
    if (view >= c->views.count)
        return fail(c, RAD_ERROR_PARSE, "%s refers to bufferView %zu of %zu", what, view,
                    c->views.count);
    const cJSON *json = c->views.items[view];
    size_t index, view_offset, length, view_stride;
    if (!json_whole(member(json, "buffer"), &index) || index >= c->buffers.count)
        return fail(c, RAD_ERROR_PARSE, "bufferView %zu refers to no buffer (%zu buffers)", view,
                    c->buffers.count);
    if (!json_whole_or(json, "byteOffset", 0, &view_offset) ||
        !json_whole(member(json, "byteLength"), &length) || length == 0 ||
        !json_whole_or(json, "byteStride", 0, &view_stride))
        return fail(c, RAD_ERROR_PARSE,
                    "bufferView %zu: byteOffset, byteLength and byteStride must be whole numbers "
                    "(byteLength at least 1)",
                    view);
    gltf_buffer *b;
    rad_result r = buffer_open(c, index, &b);
    if (r != RAD_OK)
        return r;
    if (length > b->declared || view_offset > b->declared - length)
        return fail(c, RAD_ERROR_PARSE,
                    "bufferView %zu (bytes %zu to %zu) lies outside buffer %zu of %zu bytes", view,
                    view_offset, view_offset + length, index, b->declared);
    if (offset > length || span > length - offset)
        return fail(c, RAD_ERROR_PARSE,
                    "%s needs bytes %zu to %zu of bufferView %zu, which has %zu", what, offset,
                    span > SIZE_MAX - offset ? SIZE_MAX : offset + span, view, length);
    *buffer = index;
    *start = view_offset + offset;
    *stride = view_stride;
    return RAD_OK;
}

/* ---- accessors ---- */

typedef struct accessor {
    size_t index;
    size_t count;         /* elements */
    int component_type;   /* 5120 ... 5126 */
    size_t components;    /* 1 for SCALAR, 3 for VEC3 ... */
    size_t element_size;  /* bytes */
    bool has_view;        /* false: zeros, unless sparse */
    size_t buffer, start, stride;
    size_t sparse_count;  /* 0: not sparse */
    size_t sparse_index_size;
    size_t sparse_buffer[2], sparse_start[2]; /* [0] indices, [1] values */
} accessor;

static size_t component_size(int type)
{
    switch (type) {
    case 5120: /* BYTE */
    case 5121: /* UNSIGNED_BYTE */
        return 1;
    case 5122: /* SHORT */
    case 5123: /* UNSIGNED_SHORT */
        return 2;
    case 5125: /* UNSIGNED_INT */
    case 5126: /* FLOAT */
        return 4;
    default:
        return 0;
    }
}

static size_t type_components(const char *type)
{
    static const struct {
        const char *name;
        size_t components;
    } types[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                 {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++)
        if (strcmp(type, types[i].name) == 0)
            return types[i].components;
    return 0;
}

/* Accessor `index` (for `what`, NULL if for nothing else, in messages)
 * checked and located: its
 * type, its elements inside its view and buffer, and a sparse part with
 * both views, inside them. */
static rad_result accessor_parse(checker *c, size_t index, const char *what, accessor *a)
{
    memset(a, 0, sizeof *a);
    a->index = index;
    if (index >= c->accessors.count)
        return fail(c, RAD_ERROR_PARSE, "%s refers to accessor %zu of %zu",
                    what ? what : "something", index, c->accessors.count);
    const cJSON *json = c->accessors.items[index];
    char accessor_what[200];
    if (what)
        snprintf(accessor_what, sizeof accessor_what, "%s: accessor %zu", what, index);
    else
        snprintf(accessor_what, sizeof accessor_what, "accessor %zu", index);
    const cJSON *type = member(json, "type"), *component = member(json, "componentType");
    size_t component_type = 0, offset, view;
    if (!json_whole(component, &component_type) || component_type > 5126 ||
        component_size((int)component_type) == 0)
        return fail(c, RAD_ERROR_PARSE, "%s has no valid componentType", accessor_what);
    a->component_type = (int)component_type;
    a->components = cJSON_IsString(type) ? type_components(type->valuestring) : 0;
    if (a->components == 0)
        return fail(c, RAD_ERROR_PARSE, "%s has no valid type", accessor_what);
    a->element_size = a->components * component_size(a->component_type);
    if (!json_whole(member(json, "count"), &a->count) || a->count == 0)
        return fail(c, RAD_ERROR_PARSE, "%s has count %s (at least 1 is needed)", accessor_what,
                    member(json, "count") ? "0 or not a whole number" : "missing");
    if (!json_whole_or(json, "byteOffset", 0, &offset))
        return fail(c, RAD_ERROR_PARSE, "%s: byteOffset is not a whole number", accessor_what);
    if (member(json, "bufferView")) {
        if (!json_whole(member(json, "bufferView"), &view))
            return fail(c, RAD_ERROR_PARSE, "%s: bufferView is not an index", accessor_what);
        size_t stride;
        /* its span: (count - 1) strides and one element, if that fits */
        rad_result r = view_locate(c, view, offset, 0, accessor_what, &a->buffer, &a->start,
                                   &stride);
        if (r != RAD_OK)
            return r;
        a->stride = stride ? stride : a->element_size;
        if (a->stride < a->element_size)
            return fail(c, RAD_ERROR_PARSE,
                        "%s: byteStride %zu of bufferView %zu is less than its %zu-byte elements",
                        accessor_what, a->stride, view, a->element_size);
        size_t span = a->count - 1 > (SIZE_MAX - a->element_size) / a->stride
                          ? SIZE_MAX
                          : (a->count - 1) * a->stride + a->element_size;
        r = view_locate(c, view, offset, span, accessor_what, &a->buffer, &a->start, &stride);
        if (r != RAD_OK)
            return r;
        a->has_view = true;
    }
    const cJSON *sparse = member(json, "sparse");
    if (sparse) {
        const cJSON *indices = member(sparse, "indices"), *values = member(sparse, "values");
        size_t type_of_index = 0, views[2], offsets[2], stride;
        if (!json_whole(member(sparse, "count"), &a->sparse_count) || a->sparse_count == 0 ||
            a->sparse_count > a->count)
            return fail(c, RAD_ERROR_PARSE, "%s: sparse count must be in [1, %zu]", accessor_what,
                        a->count);
        if (!json_whole(member(indices, "bufferView"), &views[0]) ||
            !json_whole(member(values, "bufferView"), &views[1]))
            return fail(c, RAD_ERROR_PARSE,
                        "%s: sparse indices and values each need a bufferView", accessor_what);
        if (!json_whole(member(indices, "componentType"), &type_of_index) ||
            (type_of_index != 5121 && type_of_index != 5123 && type_of_index != 5125))
            return fail(c, RAD_ERROR_PARSE,
                        "%s: sparse indices must be unsigned integers (componentType 5121, 5123 "
                        "or 5125)",
                        accessor_what);
        a->sparse_index_size = component_size((int)type_of_index);
        if (!json_whole_or(indices, "byteOffset", 0, &offsets[0]) ||
            !json_whole_or(values, "byteOffset", 0, &offsets[1]))
            return fail(c, RAD_ERROR_PARSE, "%s: sparse byteOffset is not a whole number",
                        accessor_what);
        size_t sizes[2] = {a->sparse_index_size, a->element_size};
        for (int k = 0; k < 2; k++) {
            size_t span = a->sparse_count > SIZE_MAX / sizes[k] ? SIZE_MAX
                                                                  : a->sparse_count * sizes[k];
            rad_result r = view_locate(c, views[k], offsets[k], span,
                                       accessor_what, &a->sparse_buffer[k], &a->sparse_start[k],
                                       &stride);
            if (r != RAD_OK)
                return r;
        }
    }
    return RAD_OK;
}

/* Elements read a block at a time: element k lies at start + k * stride. */
typedef struct stream {
    size_t buffer, start, stride, size, count;
    size_t first, loaded; /* elements [first, first + loaded) are in block */
    unsigned char *block;
} stream;

static stream stream_of(size_t buffer, size_t start, size_t stride, size_t size, size_t count,
                        unsigned char *block)
{
    stream s = {buffer, start, stride, size, count, 0, 0, block};
    return s;
}

static rad_result stream_element(checker *c, stream *s, size_t k, const unsigned char **element)
{
    if (k < s->first || k >= s->first + s->loaded) {
        size_t fit = s->stride >= GLTF_BLOCK ? 1 : (GLTF_BLOCK - s->size) / s->stride + 1;
        size_t n = s->count - k < fit ? s->count - k : fit;
        rad_result r = buffer_read(c, s->buffer, s->start + k * s->stride,
                                   (n - 1) * s->stride + s->size, s->block);
        if (r != RAD_OK)
            return r;
        s->first = k;
        s->loaded = n;
    }
    *element = s->block + (k - s->first) * s->stride;
    return RAD_OK;
}

/* A little-endian unsigned integer of 1, 2 or 4 bytes. */
static uint64_t unsigned_of(const unsigned char *p, size_t size)
{
    uint64_t value = 0;
    for (size_t k = size; k-- > 0;)
        value = value << 8 | p[k];
    return value;
}

/* The j-th sparse index, checked to increase and to stay below the count. */
static rad_result sparse_index(checker *c, const accessor *a, stream *indices, size_t j,
                               uint64_t previous, uint64_t *index)
{
    const unsigned char *p;
    rad_result r = stream_element(c, indices, j, &p);
    if (r != RAD_OK)
        return r;
    *index = unsigned_of(p, a->sparse_index_size);
    if (*index >= a->count || (j > 0 && *index <= previous))
        return fail(c, RAD_ERROR_PARSE,
                    "accessor %zu: sparse index %zu is %llu (they must increase and stay below "
                    "the count, %zu)",
                    a->index, j, (unsigned long long)*index, a->count);
    return RAD_OK;
}

typedef rad_result (*element_fn)(checker *c, void *user, size_t k, const unsigned char *element);

/* Call `visit` on every element of `a` as assimp will read it: the view's
 * elements that the sparse part does not replace, then the sparse values.
 * Elements no view holds are zeros, valid for every use here, and not
 * visited. */
static rad_result accessor_visit(checker *c, const accessor *a, element_fn visit, void *user)
{
    rad_result r = RAD_OK;
    if (a->has_view) {
        stream base = stream_of(a->buffer, a->start, a->stride, a->element_size, a->count,
                                c->block[0]);
        stream indices = stream_of(a->sparse_buffer[0], a->sparse_start[0], a->sparse_index_size,
                                   a->sparse_index_size, a->sparse_count, c->block[1]);
        /* replaced: the sparse index j, the next element the sparse part
         * replaces (UINT64_MAX past the last) */
        uint64_t replaced = UINT64_MAX;
        size_t j = 0;
        if (a->sparse_count > 0)
            r = sparse_index(c, a, &indices, 0, 0, &replaced);
        for (size_t k = 0; k < a->count && r == RAD_OK; k++) {
            while (replaced < k && r == RAD_OK) {
                if (++j < a->sparse_count)
                    r = sparse_index(c, a, &indices, j, replaced, &replaced);
                else
                    replaced = UINT64_MAX;
            }
            const unsigned char *element;
            if (r != RAD_OK || replaced == k)
                continue;
            r = stream_element(c, &base, k, &element);
            if (r == RAD_OK)
                r = visit(c, user, k, element);
        }
    }
    if (r == RAD_OK && a->sparse_count > 0) {
        stream values = stream_of(a->sparse_buffer[1], a->sparse_start[1], a->element_size,
                                  a->element_size, a->sparse_count, c->block[0]);
        stream indices = stream_of(a->sparse_buffer[0], a->sparse_start[0], a->sparse_index_size,
                                   a->sparse_index_size, a->sparse_count, c->block[1]);
        uint64_t index = 0;
        for (size_t j = 0; j < a->sparse_count && r == RAD_OK; j++) {
            const unsigned char *element;
            r = sparse_index(c, a, &indices, j, index, &index);
            if (r == RAD_OK)
                r = stream_element(c, &values, j, &element);
            if (r == RAD_OK)
                r = visit(c, user, (size_t)index, element);
        }
    }
    return r;
}

typedef struct index_scan {
    size_t size; /* bytes an index */
    uint64_t max;
    size_t at;
} index_scan;

static rad_result scan_index(checker *c, void *user, size_t k, const unsigned char *element)
{
    (void)c;
    index_scan *scan = user;
    uint64_t value = unsigned_of(element, scan->size);
    if (value > scan->max || scan->at == NONE) {
        scan->max = value;
        scan->at = k;
    }
    return RAD_OK;
}

typedef struct position_scan {
    const char *what;
} position_scan;

static rad_result scan_position(checker *c, void *user, size_t k, const unsigned char *element)
{
    float xyz[3];
    for (int i = 0; i < 3; i++) {
        uint32_t bits = (uint32_t)unsigned_of(element + 4 * i, 4);
        memcpy(&xyz[i], &bits, sizeof bits);
    }
    if (isfinite(xyz[0]) && isfinite(xyz[1]) && isfinite(xyz[2]))
        return RAD_OK;
    return fail(c, RAD_ERROR_INVALID_SCENE, "%s: vertex %zu (%g, %g, %g) is not finite",
                ((position_scan *)user)->what, k, (double)xyz[0], (double)xyz[1],
                (double)xyz[2]);
}

/* ---- meshes ---- */

typedef struct mesh_cost {
    double triangles; /* triangles of one instance */
    double faces;     /* assimp's faces (points, lines and triangles) */
    double vertices;  /* assimp's vertices: each primitive copies its own */
} mesh_cost;

static const char *const mode_names[] = {
    "points", "lines", "a line loop", "a line strip", "triangles", "a triangle strip",
    "a triangle fan"};

/* One primitive: its topology, its POSITION (finite float triples), its
 * indices (unsigned, below the vertex count) and its count for the mode. */
static rad_result check_primitive(checker *c, const cJSON *primitive, const char *what,
                                  mesh_cost *cost)
{
    size_t mode;
    if (!cJSON_IsObject(primitive))
        return fail(c, RAD_ERROR_PARSE, "%s is not an object", what);
    if (!json_whole_or(primitive, "mode", 4, &mode) || mode > 6)
        return fail(c, RAD_ERROR_PARSE, "%s: mode must be 0 to 6 (glTF topologies)", what);
    size_t position_index;
    if (!json_whole(member(member(primitive, "attributes"), "POSITION"), &position_index))
        return fail(c, RAD_ERROR_PARSE, "%s has no POSITION attribute", what);
    accessor position;
    rad_result r = accessor_parse(c, position_index, what, &position);
    if (r != RAD_OK)
        return r;
    if (position.components != 3 || position.component_type != 5126)
        return fail(c, RAD_ERROR_PARSE,
                    "%s: POSITION (accessor %zu) must be VEC3 of float (componentType 5126)",
                    what, position_index);
    if (!c->positions_ok[position_index]) {
        position_scan scan = {what};
        r = accessor_visit(c, &position, scan_position, &scan);
        if (r != RAD_OK)
            return r;
        c->positions_ok[position_index] = 1;
    }
    size_t vertices = position.count, count = vertices, index_index;
    if (member(primitive, "indices")) {
        if (!json_whole(member(primitive, "indices"), &index_index))
            return fail(c, RAD_ERROR_PARSE, "%s: indices is not an accessor index", what);
        accessor indices;
        r = accessor_parse(c, index_index, what, &indices);
        if (r != RAD_OK)
            return r;
        int type = indices.component_type;
        if (indices.components != 1 || (type != 5121 && type != 5123 && type != 5125))
            return fail(c, RAD_ERROR_PARSE,
                        "%s: indices (accessor %zu) must be SCALAR unsigned integers "
                        "(componentType 5121, 5123 or 5125), not componentType %d",
                        what, index_index, type);
        if (!c->indices_known[index_index]) {
            index_scan scan = {component_size(type), 0, NONE};
            r = accessor_visit(c, &indices, scan_index, &scan);
            if (r != RAD_OK)
                return r;
            if (scan.at == NONE) /* no view, no sparse: all zeros */
                scan.at = 0;
            c->index_max[index_index] = scan.max;
            c->index_max_at[index_index] = scan.at;
            c->indices_known[index_index] = 1;
        }
        if (c->index_max[index_index] >= vertices)
            return fail(c, RAD_ERROR_PARSE, "%s: index %zu refers to vertex %llu of %zu", what,
                        c->index_max_at[index_index],
                        (unsigned long long)c->index_max[index_index], vertices);
        count = indices.count;
    }
    size_t least = mode == 0 ? 1 : mode <= 3 ? 2 : 3;
    if (count < least)
        return fail(c, RAD_ERROR_PARSE, "%s: %s (mode %zu) of %zu %s (%zu or more are needed)",
                    what, mode_names[mode], mode, count,
                    member(primitive, "indices") ? (count == 1 ? "index" : "indices")
                                                 : (count == 1 ? "vertex" : "vertices"),
                    least);
    if (mode == 4 && count % 3 != 0)
        return fail(c, RAD_ERROR_PARSE,
                    "%s: triangles (mode 4) of %zu %s, not a multiple of 3", what, count,
                    member(primitive, "indices") ? "indices" : "vertices");
    double triangles = mode == 4 ? (double)(count / 3) : mode >= 5 ? (double)(count - 2) : 0.0;
    cost->triangles += triangles;
    cost->faces += mode >= 4 ? triangles : (double)count;
    cost->vertices += (double)vertices;
    return RAD_OK;
}

static rad_result check_mesh(checker *c, size_t index, mesh_cost *cost)
{
    const cJSON *primitives = member(c->meshes.items[index], "primitives");
    char mesh[160];
    label(&c->meshes, index, "mesh", mesh, sizeof mesh);
    if (!cJSON_IsArray(primitives))
        return fail(c, RAD_ERROR_PARSE, "%s has no primitives array", mesh);
    size_t p = 0;
    const cJSON *primitive;
    cJSON_ArrayForEach(primitive, primitives) {
        char what[200];
        snprintf(what, sizeof what, "%s primitive %zu", mesh, p++);
        rad_result r = check_primitive(c, primitive, what, cost);
        if (r != RAD_OK)
            return r;
    }
    return RAD_OK;
}

/* ---- nodes ---- */

/* A node's transform is finite, of the right lengths: translation 3,
 * rotation 4 (a quaternion, not zero), scale 3, or matrix 16. */
static rad_result check_transform(checker *c, size_t node, const char *what)
{
    static const struct {
        const char *key;
        int count;
    } parts[] = {{"translation", 3}, {"rotation", 4}, {"scale", 3}, {"matrix", 16}};
    for (size_t k = 0; k < 4; k++) {
        const cJSON *part = member(c->nodes.items[node], parts[k].key);
        double values[16];
        if (part && !json_numbers(part, parts[k].count, values))
            return fail(c, RAD_ERROR_PARSE, "%s: %s must be %d finite numbers", what,
                        parts[k].key, parts[k].count);
        if (part && k == 1 && values[0] == 0 && values[1] == 0 && values[2] == 0 && values[3] == 0)
            return fail(c, RAD_ERROR_PARSE, "%s: rotation is the zero quaternion", what);
    }
    return RAD_OK;
}

/* Parents, then depth from the roots (breadth first, no recursion): one
 * parent at most, no cycles, at most GLTF_MAX_DEPTH levels. */
static rad_result check_hierarchy(checker *c)
{
    size_t n = c->nodes.count;
    char what[160], other[160];
    for (size_t i = 0; i < n; i++)
        c->parent[i] = NONE;
    for (size_t p = 0; p < n; p++) {
        label(&c->nodes, p, "node", what, sizeof what);
        rad_result r = check_transform(c, p, what);
        if (r != RAD_OK)
            return r;
        size_t mesh, camera;
        const cJSON *json = c->nodes.items[p];
        if (member(json, "mesh") && (!json_whole(member(json, "mesh"), &mesh) ||
                                     mesh >= c->meshes.count))
            return fail(c, RAD_ERROR_PARSE, "%s refers to no mesh (%zu meshes)", what,
                        c->meshes.count);
        if (member(json, "camera") && (!json_whole(member(json, "camera"), &camera) ||
                                       camera >= c->cameras.count))
            return fail(c, RAD_ERROR_PARSE, "%s refers to no camera (%zu cameras)", what,
                        c->cameras.count);
        const cJSON *children = member(json, "children"), *child;
        if (children && !cJSON_IsArray(children))
            return fail(c, RAD_ERROR_PARSE, "%s: children is not an array", what);
        cJSON_ArrayForEach(child, children) {
            size_t k;
            if (!json_whole(child, &k) || k >= n)
                return fail(c, RAD_ERROR_PARSE, "%s: a child is not a node index (%zu nodes)",
                            what, n);
            if (k == p)
                return fail(c, RAD_ERROR_PARSE, "%s is its own child", what);
            if (c->parent[k] == p)
                return fail(c, RAD_ERROR_PARSE, "%s lists %s twice", what,
                            label(&c->nodes, k, "node", other, sizeof other));
            if (c->parent[k] != NONE) {
                char first[160];
                return fail(c, RAD_ERROR_PARSE,
                            "%s is a child of both %s and %s (a node has one parent at most)",
                            label(&c->nodes, k, "node", other, sizeof other),
                            label(&c->nodes, c->parent[k], "node", first, sizeof first), what);
            }
            c->parent[k] = p;
        }
    }
    /* Depth, breadth first from the roots (depth 1); a node never reached
     * (depth 0) lies on or under a cycle. */
    size_t *queue = rad_alloc(c->ctx, RAD_MEM_SCENE, n, 2 * sizeof *queue, c->name);
    if (!queue)
        return RAD_ERROR_OUT_OF_MEMORY;
    size_t *depth = queue + n, head = 0, tail = 0, deepest = NONE;
    for (size_t i = 0; i < n; i++)
        if (c->parent[i] == NONE) {
            depth[i] = 1;
            queue[tail++] = i;
        }
    while (head < tail) {
        size_t p = queue[head++];
        if (deepest == NONE || depth[p] > depth[deepest])
            deepest = p;
        const cJSON *child;
        cJSON_ArrayForEach(child, member(c->nodes.items[p], "children")) {
            size_t k = (size_t)child->valuedouble;
            depth[k] = depth[p] + 1;
            queue[tail++] = k;
        }
    }
    rad_result r = RAD_OK;
    if (tail < n) {
        /* Walk up n steps from a node not reached: that ends on its cycle. */
        size_t node = 0;
        while (depth[node] != 0)
            node++;
        for (size_t step = 0; step < n; step++)
            node = c->parent[node];
        r = fail(c, RAD_ERROR_PARSE, "%s is its own ancestor (the nodes form a cycle)",
                 label(&c->nodes, node, "node", what, sizeof what));
    } else if (deepest != NONE && depth[deepest] > GLTF_MAX_DEPTH) {
        r = fail(c, RAD_ERROR_PARSE,
                 "%s is nested %zu levels deep; at most %d levels are read (deeper trees "
                 "overflow the stack while assimp reads them)",
                 label(&c->nodes, deepest, "node", what, sizeof what), depth[deepest],
                 GLTF_MAX_DEPTH);
    }
    rad_free(queue);
    return r;
}

/* Every scene lists root nodes, each once; the one assimp loads ("scene",
 * default 0) is returned, or NONE when there is none. */
static rad_result check_scenes(checker *c, const cJSON *root, size_t *scene)
{
    *scene = NONE;
    size_t *listed = rad_alloc(c->ctx, RAD_MEM_SCENE, c->nodes.count + 1, sizeof *listed,
                               c->name);
    if (!listed)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = RAD_OK;
    char what[160], other[160], parent[160];
    for (size_t s = 0; s < c->scenes.count && r == RAD_OK; s++) {
        const cJSON *nodes = member(c->scenes.items[s], "nodes"), *item;
        label(&c->scenes, s, "scene", what, sizeof what);
        if (nodes && !cJSON_IsArray(nodes))
            r = fail(c, RAD_ERROR_PARSE, "%s: nodes is not an array", what);
        cJSON_ArrayForEach(item, nodes) {
            size_t k = 0;
            if (!json_whole(item, &k) || k >= c->nodes.count)
                r = fail(c, RAD_ERROR_PARSE, "%s lists something that is not a node index", what);
            else if (c->parent[k] != NONE)
                r = fail(c, RAD_ERROR_PARSE, "%s lists %s, a child of %s (a scene lists roots)",
                         what, label(&c->nodes, k, "node", other, sizeof other),
                         label(&c->nodes, c->parent[k], "node", parent, sizeof parent));
            else if (listed[k] == s + 1)
                r = fail(c, RAD_ERROR_PARSE, "%s lists %s twice", what,
                         label(&c->nodes, k, "node", other, sizeof other));
            if (r != RAD_OK)
                break;
            listed[k] = s + 1;
        }
    }
    rad_free(listed);
    if (r != RAD_OK)
        return r;
    size_t chosen;
    if (!json_whole_or(root, "scene", 0, &chosen) ||
        (member(root, "scene") && chosen >= c->scenes.count))
        return fail(c, RAD_ERROR_PARSE, "'scene' refers to no scene (%zu scenes)",
                    c->scenes.count);
    *scene = chosen < c->scenes.count ? chosen : NONE;
    return RAD_OK;
}

/* ---- the camera ---- */

/* A node's local transform, glTF's column vectors: T * R * S, or its matrix
 * (column-major).  The values were checked by check_transform. */
static void node_local(const cJSON *node, double m[3][4])
{
    double values[16];
    if (json_numbers(member(node, "matrix"), 16, values)) {
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 4; k++)
                m[r][k] = values[4 * k + r];
        return;
    }
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    json_numbers(member(node, "translation"), 3, t);
    json_numbers(member(node, "rotation"), 4, q);
    json_numbers(member(node, "scale"), 3, s);
    double norm = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    double x = q[0] / norm, y = q[1] / norm, z = q[2] / norm, w = q[3] / norm;
    const double rotation[3][3] = {
        {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
        {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
        {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++)
            m[r][k] = rotation[r][k] * s[k];
        m[r][3] = t[r];
    }
}

/* The world transform of `node`: its ancestors' locals, root first. */
static void node_world(const checker *c, size_t node, double world[3][4])
{
    double local[3][4], product[3][4];
    node_local(c->nodes.items[node], world);
    for (size_t p = c->parent[node]; p != NONE; p = c->parent[p]) {
        node_local(c->nodes.items[p], local);
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 4; k++)
                product[r][k] = local[r][0] * world[0][k] + local[r][1] * world[1][k] +
                                local[r][2] * world[2][k] + (k == 3 ? local[r][3] : 0.0);
        memcpy(world, product, sizeof product);
    }
}

static bool camera_is_orthographic(const cJSON *camera)
{
    const cJSON *type = member(camera, "type");
    return cJSON_IsString(type) && strcmp(type->valuestring, "orthographic") == 0;
}

/* The camera of `node` placed as the spec says: at the node's origin,
 * looking down its -Z with +Y up, yfov (default pi/2, as assimp's) the full
 * vertical angle. */
static rad_result place_camera(checker *c, size_t node, import_gltf_facts *facts)
{
    size_t index = (size_t)member(c->nodes.items[node], "camera")->valuedouble;
    const cJSON *yfov = member(member(c->cameras.items[index], "perspective"), "yfov");
    double vfov = M_PI / 2.0;
    char what[160];
    if (yfov && !(cJSON_IsNumber(yfov) && yfov->valuedouble > 0.0 && yfov->valuedouble < M_PI))
        return fail(c, RAD_ERROR_INVALID_SCENE, "%s: yfov must be in (0, pi) radians",
                    label(&c->cameras, index, "camera", what, sizeof what));
    if (yfov)
        vfov = yfov->valuedouble;
    double w[3][4];
    node_world(c, node, w);
    double position[3], direction[3], up[3];
    for (int r = 0; r < 3; r++) {
        position[r] = w[r][3];
        direction[r] = -w[r][2];
        up[r] = w[r][1];
    }
    /* unit directions, so that a node scaled by 1e-9 or 1e9 still looks
     * one metre ahead (a zero one stays zero: the builder refuses it) */
    double up_length = sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
    double length = sqrt(direction[0] * direction[0] + direction[1] * direction[1] +
                         direction[2] * direction[2]);
    rad_camera camera = {{0}, {0}, {0}, vfov * 180.0 / M_PI};
    for (int r = 0; r < 3; r++) {
        camera.position[r] = position[r];
        camera.look_at[r] = position[r] + (length > 0.0 ? direction[r] / length : 0.0);
        camera.up[r] = up_length > 0.0 ? up[r] / up_length : up[r];
    }
    facts->has_camera = true;
    facts->camera = camera;
    return RAD_OK;
}

/* ---- the whole file ---- */

/* Push the node indices of `array` (checked) so that the first is popped
 * first: pushed in order, then the pushed run reversed (cJSON_GetArrayItem
 * from the end would walk the list for each item). */
static void push_reversed(size_t *stack, size_t *top, const cJSON *array)
{
    size_t first = *top;
    const cJSON *item;
    cJSON_ArrayForEach(item, array)
        stack[(*top)++] = (size_t)item->valuedouble;
    for (size_t i = first, j = *top; i + 1 < j; i++, j--) {
        size_t swap = stack[i];
        stack[i] = stack[j - 1];
        stack[j - 1] = swap;
    }
}

/* Walk the chosen scene depth first (an explicit stack, roots in order):
 * count instances and their triangles, and pick the camera: the first camera
 * node, or, when its camera is orthographic (which the renderer does not
 * draw), the first perspective one, with a warning. */
static rad_result walk_scene(checker *c, size_t scene, const double *mesh_triangles,
                             double *instances, double *triangles, import_gltf_facts *facts)
{
    size_t n = c->nodes.count, top = 0;
    size_t *stack = rad_alloc(c->ctx, RAD_MEM_SCENE, n + 1, sizeof *stack, c->name);
    if (!stack)
        return RAD_ERROR_OUT_OF_MEMORY;
    push_reversed(stack, &top, member(c->scenes.items[scene], "nodes"));
    size_t first_camera = NONE, perspective = NONE;
    while (top > 0) {
        size_t node = stack[--top];
        const cJSON *json = c->nodes.items[node];
        *instances += 1.0;
        if (member(json, "mesh"))
            *triangles += mesh_triangles[(size_t)member(json, "mesh")->valuedouble];
        if (rad_gltf_extras_place_luminaire(member(json, "extras"))) {
            rad_gltf_luminaire *grown = rad_realloc(c->ctx, RAD_MEM_SCENE, facts->luminaires,
                                                    facts->luminaire_count + 1, sizeof *grown, c->name);
            if (!grown) {
                rad_free(stack);
                return RAD_ERROR_OUT_OF_MEMORY;
            }
            facts->luminaires = grown;
            rad_gltf_luminaire *l = &grown[facts->luminaire_count++];
            label(&c->nodes, node, "node", l->label, sizeof l->label);
            const cJSON *node_name = member(json, "name");
            if (cJSON_IsString(node_name) && node_name->valuestring[0])
                snprintf(l->name, sizeof l->name, "%.127s", node_name->valuestring);
            else
                snprintf(l->name, sizeof l->name, "node %zu", node);
            node_world(c, node, l->world);
            l->extras = member(json, "extras");
        }
        if (member(json, "camera")) {
            const cJSON *camera = c->cameras.items[(size_t)member(json, "camera")->valuedouble];
            if (first_camera == NONE)
                first_camera = node;
            if (perspective == NONE && !camera_is_orthographic(camera))
                perspective = node;
        }
        /* the first child is walked next; a tree holds each node once, so
         * the stack never holds more than n */
        push_reversed(stack, &top, member(json, "children"));
    }
    rad_free(stack);
    if (first_camera != NONE && first_camera != perspective) {
        char camera[160], node[160], other[160];
        size_t index = (size_t)member(c->nodes.items[first_camera], "camera")->valuedouble;
        label(&c->cameras, index, "camera", camera, sizeof camera);
        label(&c->nodes, first_camera, "node", node, sizeof node);
        if (perspective != NONE)
            rad_warn(c->ctx,
                     "%s: %s of %s is orthographic, which the renderer does not draw; using the "
                     "perspective camera of %s",
                     c->name, camera, node,
                     label(&c->nodes, perspective, "node", other, sizeof other));
        else
            rad_warn(c->ctx,
                     "%s: %s of %s is orthographic, which the renderer does not draw; the view "
                     "is framed automatically",
                     c->name, camera, node);
    }
    return perspective != NONE ? place_camera(c, perspective, facts) : RAD_OK;
}

/* The GLB's BIN chunk: the chunk after the JSON one, if it is there and of
 * type "BIN\0" (the framing, checked before, keeps it inside the file). */
static void find_bin_chunk(checker *c, const char *data, size_t size)
{
    const unsigned char *bytes = (const unsigned char *)data;
    if (size < 20)
        return;
    size_t json = (size_t)bytes[12] | (size_t)bytes[13] << 8 | (size_t)bytes[14] << 16 |
                  (size_t)bytes[15] << 24;
    if (json > size - 20 || size - 20 - json < 8)
        return;
    const unsigned char *chunk = bytes + 20 + json;
    size_t length = (size_t)chunk[0] | (size_t)chunk[1] << 8 | (size_t)chunk[2] << 16 |
                    (size_t)chunk[3] << 24;
    if (memcmp(chunk + 4, "BIN\0", 4) != 0 || length > size - 20 - json - 8)
        return;
    c->bin = (const char *)chunk + 8;
    c->bin_size = length;
}

static rad_result check_version(checker *c, const cJSON *root)
{
    const cJSON *version = member(member(root, "asset"), "version");
    if (!cJSON_IsString(version))
        return fail(c, RAD_ERROR_PARSE, "no asset.version (a glTF 2.0 file has \"2.0\")");
    if (strncmp(version->valuestring, "2.", 2) != 0)
        return fail(c, RAD_ERROR_PARSE, "glTF version '%.20s' is not read (2.0 is)",
                    version->valuestring);
    return RAD_OK;
}

rad_result import_gltf_check(rad_context *ctx, const char *name, const char *data, size_t size,
                             bool binary, const cJSON *root, struct aiFileIO *io,
                             import_gltf_facts *facts)
{
    memset(facts, 0, sizeof *facts);
    checker c = {.ctx = ctx, .name = name, .io = io, .binary = binary};
    if (binary)
        find_bin_chunk(&c, data, size);
    rad_result r = check_version(&c, root);
    const struct {
        const char *key;
        table *t;
    } tables[] = {{"nodes", &c.nodes},         {"meshes", &c.meshes},   {"accessors", &c.accessors},
                  {"bufferViews", &c.views},   {"buffers", &c.buffers}, {"cameras", &c.cameras},
                  {"scenes", &c.scenes}};
    for (size_t k = 0; k < sizeof tables / sizeof tables[0] && r == RAD_OK; k++)
        r = table_of(&c, root, tables[k].key, tables[k].t);
    size_t accessors = c.accessors.count + 1, meshes = c.meshes.count + 1;
    double *mesh_triangles = NULL;
    unsigned char *mesh_used = NULL;
    if (r == RAD_OK) {
        c.buffer = rad_alloc(ctx, RAD_MEM_SCENE, c.buffers.count + 1, sizeof *c.buffer, name);
        c.parent = rad_alloc(ctx, RAD_MEM_SCENE, c.nodes.count + 1, sizeof *c.parent, name);
        c.block[0] = rad_alloc(ctx, RAD_MEM_SCENE, 2, GLTF_BLOCK, name);
        c.positions_ok = rad_alloc(ctx, RAD_MEM_SCENE, accessors, 2, name);
        c.index_max = rad_alloc(ctx, RAD_MEM_SCENE, accessors, sizeof *c.index_max, name);
        c.index_max_at = rad_alloc(ctx, RAD_MEM_SCENE, accessors, sizeof *c.index_max_at, name);
        mesh_triangles = rad_alloc(ctx, RAD_MEM_SCENE, meshes, sizeof *mesh_triangles, name);
        mesh_used = rad_alloc(ctx, RAD_MEM_SCENE, meshes, 1, name);
        if (!c.buffer || !c.parent || !c.block[0] || !c.positions_ok || !c.index_max ||
            !c.index_max_at || !mesh_triangles || !mesh_used)
            r = RAD_ERROR_OUT_OF_MEMORY;
        else {
            c.block[1] = c.block[0] + GLTF_BLOCK;
            c.indices_known = c.positions_ok + accessors;
        }
    }
    if (r == RAD_OK)
        r = check_hierarchy(&c);
    size_t scene = NONE;
    if (r == RAD_OK)
        r = check_scenes(&c, root, &scene);

    /* Every accessor's sparse part complete and inside its views (assimp
     * reads any accessor a skin, an animation or a morph target names). */
    for (size_t a = 0; a < c.accessors.count && r == RAD_OK; a++) {
        accessor parsed;
        if (member(c.accessors.items[a], "sparse"))
            r = accessor_parse(&c, a, NULL, &parsed);
    }
    /* Meshes that some node uses (assimp reads no other). */
    mesh_cost cost = {0};
    for (size_t i = 0; i < c.nodes.count && r == RAD_OK; i++)
        if (member(c.nodes.items[i], "mesh"))
            mesh_used[(size_t)member(c.nodes.items[i], "mesh")->valuedouble] = 1;
    for (size_t m = 0; m < c.meshes.count && r == RAD_OK; m++) {
        if (!mesh_used[m])
            continue;
        mesh_cost one = {0};
        r = check_mesh(&c, m, &one);
        mesh_triangles[m] = one.triangles;
        cost.faces += one.faces;
        cost.vertices += one.vertices;
    }
    double instances = 0.0, triangles = 0.0;
    if (r == RAD_OK && scene != NONE)
        r = walk_scene(&c, scene, mesh_triangles, &instances, &triangles, facts);

    /* What the import will take, against the memory limit. */
    if (r == RAD_OK) {
        double buffers = c.buffer_bytes;
        double need = ASSIMP_BYTES_PER_NODE * (double)c.nodes.count +
                      ASSIMP_BYTES_PER_FACE * cost.faces +
                      ASSIMP_BYTES_PER_VERTEX * cost.vertices + ASSIMP_BUFFER_COPIES * buffers +
                      SCENE_BYTES_PER_TRIANGLE * triangles;
        double limit = rad_memory_limit(ctx);
        if (need > limit) {
            char need_text[32], limit_text[32], buffer_text[32];
            rad_format_bytes(need, need_text, sizeof need_text);
            rad_format_bytes(limit, limit_text, sizeof limit_text);
            rad_format_bytes(buffers, buffer_text, sizeof buffer_text);
            r = fail(&c, RAD_ERROR_OUT_OF_MEMORY,
                     "importing it needs about %s (%zu nodes; %.0f instances holding %.3g "
                     "triangles; %.3g faces and %.3g vertices in assimp; %s of buffers), above "
                     "the memory limit of %s (rad_context_options.max_memory_bytes)",
                     need_text, c.nodes.count, instances, triangles, cost.faces, cost.vertices,
                     buffer_text, limit_text);
        }
    }

    for (size_t b = 0; c.buffer && b < c.buffers.count; b++)
        if (c.buffer[b].file)
            io->CloseProc(io, c.buffer[b].file);
    rad_free(mesh_used);
    rad_free(mesh_triangles);
    rad_free(c.index_max_at);
    rad_free(c.index_max);
    rad_free(c.positions_ok);
    rad_free(c.block[0]);
    rad_free(c.parent);
    rad_free(c.buffer);
    for (size_t k = 0; k < sizeof tables / sizeof tables[0]; k++)
        rad_free(tables[k].t->items);
    if (r != RAD_OK)
        memset(facts, 0, sizeof *facts);
    return r;
}
