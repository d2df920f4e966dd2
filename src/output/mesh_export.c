/*
 * mesh_export.c -- the solution as a lit mesh: glTF 2.0 (.glb, or .gltf
 * with its buffer inside as a base64 data URI, so one file either way) or
 * binary little-endian PLY.
 *
 * The mesh is the solution's own: its welded vertices and its elements
 * (glTF splits each quad into two triangles; PLY keeps it whole).  Every
 * vertex carries the radiosity smooth shading interpolates (interp/), twice:
 *
 *     exact     B, W/m^2, float RGB          glTF _RADIOSITY, PLY radiosity_r/g/b
 *     display   min(1, B/pi x exposure)      glTF COLOR_0 (linear, as the spec
 *                                            asks), PLY red/green/blue (sRGB,
 *                                            8 bits, as the PNG writer does)
 *
 * The exposure is the caller's, or the images' automatic rule (image.c,
 * rad_radiance_exposure) applied to the vertices' radiances B/pi.
 *
 * glTF layout.  One node and one mesh per surface, both named after it
 * (the importer names surfaces by glTF nodes, so names survive); one
 * primitive per material of the surface, holding the vertices its
 * elements use, in the solution's order (a vertex of a surface's two
 * materials is written once for each; welding never joins surfaces, so
 * otherwise every vertex is written once).  Materials are unlit
 * (KHR_materials_unlit) with base colour 1, so viewers show COLOR_0 as
 * solved.  One buffer, five views; a primitive's accessors are ranges of
 * the shared views (hence their byteStride, which the spec requires of a
 * view that several vertex accessors use):
 *
 *     view 0  POSITION    float VEC3, every primitive's vertices in turn,
 *     view 1  NORMAL      the mean of the normals of the elements around
 *     view 2  COLOR_0     the vertex (area-weighted: one surface within
 *     view 3  _RADIOSITY  the crease angle, so they nearly agree)
 *     view 4  indices     uint32, every primitive's triangles in turn
 *     view 5  TEXCOORD_1  with lightmaps (rad_write_mesh_baked, bake.c):
 *                         float VEC2, the vertex's atlas coordinates
 *
 * With lightmaps a vertex is written once per chart (patch) it is on, as
 * two charts put it at different atlas coordinates; primitives are also
 * split by atlas, and each (material, atlas) is a material whose
 * MOZ_lightmap names that atlas's texture (TEXCOORD_0 is the same
 * accessor: glTF numbers coordinate sets without gaps).
 *
 * References: the glTF 2.0 specification (Khronos Group, 2021): meshes and
 * attributes (3.7.2, POSITION's min/max, COLOR_0 in [0, 1], application
 * attributes beginning with '_'), buffers and data URIs (3.6), binary glTF
 * (4.4); the KHR_materials_unlit extension; the PLY format (Turk, 1994).
 */
#include "output/output.h"

#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>

/* ---- the vertices' values ---- */

typedef struct lit_vertices {
    size_t count;          /* the solution's vertices */
    double *radiosity;     /* 3 per vertex, W/m^2 */
    float *radiance;       /* 3 per vertex, B / pi, W/(m^2 sr) */
    double exposure;       /* the multiplier on radiance used for display */
} lit_vertices;

static void lit_vertices_free(lit_vertices *lit)
{
    rad_free(lit->radiosity);
    rad_free(lit->radiance);
}

/* Vertex radiosities as rad_solution_vertex_radiosity gives them, and the
 * exposure (`exposure`, or automatic when 0).  Fails only for memory. */
static rad_result lit_vertices_make(rad_context *ctx, const rad_solution_view *view, double exposure,
                                    lit_vertices *lit)
{
    memset(lit, 0, sizeof *lit);
    lit->count = view->mesh->vertex_count;
    lit->radiosity = rad_alloc(ctx, RAD_MEM_OUTPUT, lit->count, 3 * sizeof(double), "lit mesh: vertex values");
    lit->radiance = lit->radiosity ? rad_alloc(ctx, RAD_MEM_OUTPUT, lit->count, 3 * sizeof(float),
                                               "lit mesh: vertex values")
                                   : NULL;
    rad_result r = lit->radiance ? rad_view_vertex_values(ctx, view, view->radiosity, lit->radiosity)
                                 : RAD_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; r == RAD_OK && i < 3 * lit->count; i++)
        lit->radiance[i] = (float)(lit->radiosity[i] / M_PI);
    lit->exposure = exposure;
    if (r == RAD_OK && exposure == 0.0)
        r = rad_radiance_exposure(ctx, lit->radiance, lit->count, &lit->exposure);
    if (r != RAD_OK)
        lit_vertices_free(lit);
    return r;
}

/* The display value of a radiance: exposed and clamped to [0, 1] (NaN: 0). */
static double display(const lit_vertices *lit, float radiance)
{
    double value = lit->exposure * (double)radiance;
    return value > 0.0 ? (value < 1.0 ? value : 1.0) : 0.0;
}

/* ---- little-endian bytes ---- */

static unsigned char *put_u32(unsigned char *p, uint32_t v)
{
    for (int b = 0; b < 4; b++)
        p[b] = (unsigned char)(v >> (8 * b));
    return p + 4;
}

static unsigned char *put_f32(unsigned char *p, float v)
{
    uint32_t bits;
    memcpy(&bits, &v, 4);
    return put_u32(p, bits);
}

/* ---- PLY ---- */

static rad_result write_ply(rad_context *ctx, const rad_solution_view *view, const lit_vertices *lit,
                            const char *path, FILE *f)
{
    const rad_mesh *mesh = view->mesh;
    if (mesh->vertex_count > INT32_MAX)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: %zu vertices do not fit PLY's int indices; use .glb", path, mesh->vertex_count);
    int failed = fprintf(f,
                         "ply\nformat binary_little_endian 1.0\n"
                         "comment radiosity %s lit mesh: exposure %.17g; radiosity_r/g/b: vertex radiosity "
                         "B, W/m^2; red/green/blue: radiance B/pi, W/(m^2 sr), times the exposure, "
                         "clamped to [0, 1], sRGB-encoded\n"
                         "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
                         "property float radiosity_r\nproperty float radiosity_g\nproperty float radiosity_b\n"
                         "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                         "element face %zu\nproperty list uchar int vertex_indices\nend_header\n",
                         RAD_VERSION_STRING, lit->exposure, mesh->vertex_count, mesh->element_count) < 0;
    unsigned char record[27];
    for (size_t v = 0; v < mesh->vertex_count && !failed; v++) {
        vec3 p = mesh->vertices[v];
        unsigned char *q = put_f32(put_f32(put_f32(record, (float)p.x), (float)p.y), (float)p.z);
        for (int c = 0; c < 3; c++)
            q = put_f32(q, (float)lit->radiosity[3 * v + (size_t)c]);
        for (int c = 0; c < 3; c++)
            *q++ = (unsigned char)lround(255.0 * rad_srgb_encode(display(lit, lit->radiance[3 * v + (size_t)c])));
        failed = fwrite(record, 1, sizeof record, f) != sizeof record;
    }
    for (size_t i = 0; i < mesh->element_count && !failed; i++) {
        const rad_element *e = &mesh->elements[i];
        record[0] = (unsigned char)e->vertex_count;
        unsigned char *q = record + 1;
        for (uint32_t k = 0; k < e->vertex_count; k++)
            q = put_u32(q, e->vertex[k]);
        failed = fwrite(record, 1, (size_t)(q - record), f) != (size_t)(q - record);
    }
    return failed ? rad_fail(ctx, RAD_ERROR_IO, "%s: write failed", path) : RAD_OK;
}

/* ---- glTF: the elements grouped into primitives ---- */

/* An element's place in the order of primitives: surface, material,
 * atlas (0 without lightmaps), element. */
typedef struct element_key {
    uint32_t surface, material, atlas, element;
} element_key;

static int element_key_cmp(const void *a, const void *b)
{
    const element_key *x = a, *y = b;
    if (x->surface != y->surface)
        return x->surface < y->surface ? -1 : 1;
    if (x->material != y->material)
        return x->material < y->material ? -1 : 1;
    if (x->atlas != y->atlas)
        return x->atlas < y->atlas ? -1 : 1;
    return x->element < y->element ? -1 : (x->element > y->element);
}

static int u64_cmp(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : (x > y);
}

/* A written vertex: the solution's vertex, and with lightmaps the patch
 * (chart) it is written for in the high half, so that a vertex of two
 * charts is written once for each. */
static uint64_t vertex_key(const rad_element *e, uint32_t corner, bool split)
{
    return (split ? (uint64_t)e->patch << 32 : 0) | e->vertex[corner];
}

/* One primitive: the elements of one material of one surface (and of one
 * atlas, with lightmaps). */
typedef struct primitive {
    uint32_t surface, material, atlas;
    size_t first_key, key_count;        /* its elements, in `keys` */
    size_t first_vertex, vertex_count;  /* its vertices, in `source` */
    size_t first_index, index_count;    /* its triangles' corners */
    float min[3], max[3];               /* of its positions, as written */
} primitive;

typedef struct primitives {
    element_key *keys;       /* n, sorted */
    primitive *list;
    size_t count;
    uint64_t *source;        /* written vertex -> its key (vertex_key), sorted in each primitive */
    size_t vertex_count;     /* written vertices */
    size_t index_count;
} primitives;

static void primitives_free(primitives *p)
{
    rad_free(p->keys);
    rad_free(p->list);
    rad_free(p->source);
}

/* Sort the elements into primitives and list each one's vertices in the
 * solution's order (with a lightmap, split per chart and grouped by atlas).
 * Fails only for memory. */
static rad_result primitives_make(rad_context *ctx, const rad_mesh *mesh, const rad_lightmap *lightmap,
                                  primitives *p)
{
    memset(p, 0, sizeof *p);
    size_t n = mesh->element_count, corners = 0;
    p->keys = rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *p->keys, "lit mesh: primitives");
    if (!p->keys)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < n; i++) {
        const rad_element *e = &mesh->elements[i];
        p->keys[i] = (element_key){e->surface, e->material, lightmap ? lightmap->charts[e->patch].atlas : 0,
                                   (uint32_t)i};
        corners += e->vertex_count;
        p->index_count += 3 * (e->vertex_count - 2);
    }
    qsort(p->keys, n, sizeof *p->keys, element_key_cmp);
    for (size_t i = 0; i < n; i++)
        if (i == 0 || p->keys[i].surface != p->keys[i - 1].surface ||
            p->keys[i].material != p->keys[i - 1].material || p->keys[i].atlas != p->keys[i - 1].atlas)
            p->count++;
    p->list = rad_alloc(ctx, RAD_MEM_OUTPUT, p->count, sizeof *p->list, "lit mesh: primitives");
    p->source = p->list ? rad_alloc(ctx, RAD_MEM_OUTPUT, corners, sizeof *p->source, "lit mesh: vertices") : NULL;
    if (!p->source) {
        primitives_free(p);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    size_t k = 0, index = 0;
    for (size_t g = 0; g < p->count; g++) {
        primitive *prim = &p->list[g];
        prim->surface = p->keys[k].surface;
        prim->material = p->keys[k].material;
        prim->atlas = p->keys[k].atlas;
        prim->first_key = k;
        prim->first_vertex = p->vertex_count;
        prim->first_index = index;
        /* Its elements' corners, then sorted and made unique in place. */
        uint64_t *v = &p->source[p->vertex_count];
        size_t used = 0;
        for (; k < n && p->keys[k].surface == prim->surface && p->keys[k].material == prim->material &&
               p->keys[k].atlas == prim->atlas;
             k++) {
            const rad_element *e = &mesh->elements[p->keys[k].element];
            for (uint32_t c = 0; c < e->vertex_count; c++)
                v[used++] = vertex_key(e, c, lightmap != NULL);
            index += 3 * (e->vertex_count - 2);
        }
        prim->key_count = k - prim->first_key;
        prim->index_count = index - prim->first_index;
        qsort(v, used, sizeof *v, u64_cmp);
        size_t unique = 0;
        for (size_t i = 0; i < used; i++)
            if (unique == 0 || v[i] != v[unique - 1])
                v[unique++] = v[i];
        prim->vertex_count = unique;
        p->vertex_count += unique;
    }
    return RAD_OK;
}

/* ---- glTF: the binary buffer ---- */

enum { VIEW_POSITION, VIEW_NORMAL, VIEW_COLOUR, VIEW_RADIOSITY, VIEW_INDICES, VIEW_TEXCOORD, VIEW_COUNT };

/* Where view k begins: four float VEC3 views, the indices, then (with
 * lightmaps) float VEC2 texture coordinates; each a multiple of 4 bytes. */
static size_t view_offset(const primitives *p, int k)
{
    return k <= VIEW_INDICES ? (size_t)k * 12 * p->vertex_count : 48 * p->vertex_count + 4 * p->index_count;
}

static size_t view_length(const primitives *p, int k)
{
    return k == VIEW_INDICES ? 4 * p->index_count : k == VIEW_TEXCOORD ? 8 * p->vertex_count : 12 * p->vertex_count;
}

/* The written vertex of element e's corner c in primitive `prim`. */
static uint32_t local_index(const primitives *p, const primitive *prim, const rad_element *e, uint32_t c,
                            bool split)
{
    uint64_t key = vertex_key(e, c, split);
    const uint64_t *found = bsearch(&key, &p->source[prim->first_vertex], prim->vertex_count, sizeof key, u64_cmp);
    return (uint32_t)(found - &p->source[prim->first_vertex]);
}

/* Fill the buffer (layout above) and each primitive's bounds.  `normal`
 * (3 per written vertex) is scratch.  Cannot fail. */
static void fill_buffer(const rad_mesh *mesh, const lit_vertices *lit, const rad_lightmap *lightmap, primitives *p,
                        unsigned char *buffer, double *normal)
{
    unsigned char *view[VIEW_COUNT];
    for (int k = 0; k < VIEW_COUNT; k++)
        view[k] = buffer + view_offset(p, k);
    bool split = lightmap != NULL;
    for (size_t g = 0; g < p->count; g++) {
        primitive *prim = &p->list[g];
        const uint64_t *source = &p->source[prim->first_vertex];
        /* Area-weighted normals of the elements around each vertex; the
         * triangles, as local indices, counter-clockwise as the elements. */
        double *nsum = &normal[3 * prim->first_vertex];
        memset(nsum, 0, 3 * prim->vertex_count * sizeof *nsum);
        unsigned char *q = view[VIEW_INDICES] + 4 * prim->first_index;
        for (size_t k = prim->first_key; k < prim->first_key + prim->key_count; k++) {
            const rad_element *e = &mesh->elements[p->keys[k].element];
            uint32_t local[4];
            for (uint32_t c = 0; c < e->vertex_count; c++) {
                local[c] = local_index(p, prim, e, c, split);
                double *s = &nsum[3 * local[c]];
                s[0] += e->area * e->normal.x, s[1] += e->area * e->normal.y, s[2] += e->area * e->normal.z;
            }
            for (uint32_t t = 1; t + 1 < e->vertex_count; t++) {
                q = put_u32(q, local[0]);
                q = put_u32(q, local[t]);
                q = put_u32(q, local[t + 1]);
            }
        }
        for (size_t j = 0; j < prim->vertex_count; j++) {
            size_t at = 12 * (prim->first_vertex + j), v = (uint32_t)source[j];
            vec3 pos = mesh->vertices[v];
            float xyz[3] = {(float)pos.x, (float)pos.y, (float)pos.z};
            vec3 nrm = v3_normalize(v3(nsum[3 * j], nsum[3 * j + 1], nsum[3 * j + 2]));
            float n3[3] = {(float)nrm.x, (float)nrm.y, (float)nrm.z};
            for (int c = 0; c < 3; c++) {
                if (j == 0 || xyz[c] < prim->min[c])
                    prim->min[c] = xyz[c];
                if (j == 0 || xyz[c] > prim->max[c])
                    prim->max[c] = xyz[c];
                size_t off = at + 4 * (size_t)c;
                put_f32(view[VIEW_POSITION] + off, xyz[c]);
                put_f32(view[VIEW_NORMAL] + off, n3[c]);
                put_f32(view[VIEW_COLOUR] + off, (float)display(lit, lit->radiance[3 * v + (size_t)c]));
                put_f32(view[VIEW_RADIOSITY] + off, (float)lit->radiosity[3 * v + (size_t)c]);
            }
            if (split) {
                /* The chart's atlas coordinates, as fractions of the atlas
                 * (glTF's (0, 0) is the image's first texel's corner). */
                const rad_chart *chart = &lightmap->charts[source[j] >> 32];
                const rad_atlas *atlas = &lightmap->atlases[chart->atlas];
                double x, y;
                rad_chart_texel(lightmap, chart, pos, &x, &y);
                unsigned char *t = view[VIEW_TEXCOORD] + 8 * (prim->first_vertex + j);
                put_f32(put_f32(t, (float)(x / atlas->width)), (float)(y / atlas->height));
            }
        }
    }
}

/* ---- glTF: the JSON ---- */

/* Building JSON: every add goes through these, which note a failure
 * (cJSON out of memory) in *ok instead of losing the member. */
static cJSON *add_item(cJSON *parent, const char *key, cJSON *item, bool *ok)
{
    if (!item || !parent) {
        cJSON_Delete(item);
        *ok = false;
        return NULL;
    }
    if (key ? !cJSON_AddItemToObject(parent, key, item) : !cJSON_AddItemToArray(parent, item)) {
        cJSON_Delete(item);
        *ok = false;
        return NULL;
    }
    return item;
}

static void add_number(cJSON *parent, const char *key, double value, bool *ok)
{
    add_item(parent, key, cJSON_CreateNumber(value), ok);
}

static void add_string(cJSON *parent, const char *key, const char *text, bool *ok)
{
    add_item(parent, key, cJSON_CreateString(text), ok);
}

/* A name from the user's files, as valid UTF-8 (JSON must be). */
static void add_name(rad_context *ctx, cJSON *parent, const char *name, bool *ok)
{
    char *clean = rad_utf8_clean(ctx, name ? name : "");
    if (!clean) {
        *ok = false;
        return;
    }
    add_string(parent, "name", clean, ok);
    rad_free(clean);
}

static void add_vec3(cJSON *parent, const char *key, const float v[3], bool *ok)
{
    cJSON *array = add_item(parent, key, cJSON_CreateArray(), ok);
    for (int c = 0; c < 3; c++)
        add_number(array, NULL, (double)v[c], ok);
}

/* glTF's component types and buffer-view targets. */
enum { GLTF_UNSIGNED_INT = 5125, GLTF_FLOAT = 5126, GLTF_ARRAY_BUFFER = 34962, GLTF_ELEMENT_ARRAY_BUFFER = 34963,
       GLTF_LINEAR = 9729, GLTF_CLAMP_TO_EDGE = 33071 };

/* An accessor of view `view`: uint32 scalars (the indices), else floats
 * of `type`. */
static int add_accessor(cJSON *accessors, int view, size_t offset, size_t count, const char *type, bool *ok)
{
    cJSON *a = add_item(accessors, NULL, cJSON_CreateObject(), ok);
    add_number(a, "bufferView", view, ok);
    add_number(a, "byteOffset", (double)offset, ok);
    add_number(a, "componentType", view == VIEW_INDICES ? GLTF_UNSIGNED_INT : GLTF_FLOAT, ok);
    add_number(a, "count", (double)count, ok);
    add_string(a, "type", type, ok);
    return cJSON_GetArraySize(accessors) - 1;
}

/* The lightmaps' part of asset.extras.radiosity, images, textures and the
 * sampler (bilinear, clamped: the padding is dilated for it). */
static void add_lightmaps(cJSON *root, cJSON *extras, const rad_mesh_lightmaps *maps, bool *ok)
{
    const rad_lightmap *lm = maps->lightmap;
    cJSON *info = add_item(extras, "lightmap", cJSON_CreateObject(), ok);
    add_string(info, "quantity",
               lm->quantity == RAD_LIGHTMAP_IRRADIANCE ? "irradiance H = (B - E)/rho, as H/pi, W/(m^2 sr)"
                                                       : "radiosity B, as radiance B/pi, W/(m^2 sr)",
               ok);
    add_number(info, "texels_per_metre", lm->texels_per_metre, ok);
    add_number(info, "rgbm_range", maps->rgbm_range, ok);
    add_string(info, "png", "RGBM: value = (R, G, B) x A x rgbm_range, each channel / 255, linear", ok);
    cJSON *hdr = add_item(info, "hdr", cJSON_CreateArray(), ok);
    cJSON *images = add_item(root, "images", cJSON_CreateArray(), ok);
    cJSON *textures = add_item(root, "textures", cJSON_CreateArray(), ok);
    for (size_t a = 0; a < lm->atlas_count; a++) {
        add_string(hdr, NULL, maps->hdr_names[a], ok);
        cJSON *image = add_item(images, NULL, cJSON_CreateObject(), ok);
        add_string(image, "uri", maps->png_uris[a], ok);
        cJSON *texture = add_item(textures, NULL, cJSON_CreateObject(), ok);
        add_number(texture, "sampler", 0, ok);
        add_number(texture, "source", (double)a, ok);
    }
    cJSON *sampler = add_item(add_item(root, "samplers", cJSON_CreateArray(), ok), NULL, cJSON_CreateObject(), ok);
    add_number(sampler, "magFilter", GLTF_LINEAR, ok);
    add_number(sampler, "minFilter", GLTF_LINEAR, ok);
    add_number(sampler, "wrapS", GLTF_CLAMP_TO_EDGE, ok);
    add_number(sampler, "wrapT", GLTF_CLAMP_TO_EDGE, ok);
}

/* The glTF document for `p` over a buffer of `bytes`, its buffer last, with
 * an empty "uri" when `uri` (the .gltf writer fills it in).  NULL when out
 * of memory. */
static cJSON *gltf_json(rad_context *ctx, const rad_solution_view *view, const lit_vertices *lit,
                        const primitives *p, const rad_mesh_lightmaps *maps, size_t bytes, bool uri)
{
    const rad_scene *scene = view->scene;
    bool ok = true;
    cJSON *root = cJSON_CreateObject();
    cJSON *asset = add_item(root, "asset", cJSON_CreateObject(), &ok);
    add_string(asset, "version", "2.0", &ok);
    add_string(asset, "generator", "radiosity " RAD_VERSION_STRING, &ok);
    cJSON *extras = add_item(add_item(asset, "extras", cJSON_CreateObject(), &ok), "radiosity",
                             cJSON_CreateObject(), &ok);
    add_number(extras, "exposure", lit->exposure, &ok);
    add_string(extras, "colour", "linear radiance B/pi times exposure, W/(m^2 sr)", &ok);
    add_string(extras, "_RADIOSITY", "vertex radiosity B, W/m^2", &ok);
    cJSON *used = add_item(root, "extensionsUsed", cJSON_CreateArray(), &ok);
    add_item(used, NULL, cJSON_CreateString("KHR_materials_unlit"), &ok);
    if (maps)
        add_item(used, NULL, cJSON_CreateString("MOZ_lightmap"), &ok);
    add_number(root, "scene", 0, &ok);
    cJSON *scenes = add_item(root, "scenes", cJSON_CreateArray(), &ok);
    cJSON *scene0 = add_item(scenes, NULL, cJSON_CreateObject(), &ok);
    add_name(ctx, scene0, scene->source, &ok);
    cJSON *roots = add_item(scene0, "nodes", cJSON_CreateArray(), &ok);
    cJSON *nodes = add_item(root, "nodes", cJSON_CreateArray(), &ok);
    cJSON *meshes = add_item(root, "meshes", cJSON_CreateArray(), &ok);
    cJSON *materials = add_item(root, "materials", cJSON_CreateArray(), &ok);
    cJSON *accessors = add_item(root, "accessors", cJSON_CreateArray(), &ok);

    /* The scene's materials that primitives use, numbered as first used;
     * with lightmaps, one for each atlas it is on. */
    size_t atlases = maps ? maps->lightmap->atlas_count : 1;
    int *material_index = rad_alloc(ctx, RAD_MEM_OUTPUT, (scene->material_count + 1) * atlases,
                                    sizeof *material_index, "lit mesh: materials");
    if (!material_index) {
        cJSON_Delete(root);
        return NULL;
    }
    int material_count = 0;
    cJSON *primitive_list = NULL;
    for (size_t g = 0; g < p->count && ok; g++) {
        const primitive *prim = &p->list[g];
        if (g == 0 || prim->surface != p->list[g - 1].surface) {
            int mesh_index = cJSON_GetArraySize(meshes);
            add_number(roots, NULL, mesh_index, &ok);
            cJSON *node = add_item(nodes, NULL, cJSON_CreateObject(), &ok);
            add_name(ctx, node, scene->surfaces[prim->surface].name, &ok);
            add_number(node, "mesh", mesh_index, &ok);
            cJSON *mesh = add_item(meshes, NULL, cJSON_CreateObject(), &ok);
            add_name(ctx, mesh, scene->surfaces[prim->surface].name, &ok);
            primitive_list = add_item(mesh, "primitives", cJSON_CreateArray(), &ok);
        }
        size_t material_key = (size_t)prim->material * atlases + prim->atlas;
        if (material_index[material_key] == 0) {
            material_index[material_key] = ++material_count;
            cJSON *m = add_item(materials, NULL, cJSON_CreateObject(), &ok);
            add_name(ctx, m, prim->material < scene->material_count ? scene->materials[prim->material].name : "",
                     &ok);
            cJSON *pbr = add_item(m, "pbrMetallicRoughness", cJSON_CreateObject(), &ok);
            cJSON *base = add_item(pbr, "baseColorFactor", cJSON_CreateArray(), &ok);
            for (int c = 0; c < 4; c++)
                add_number(base, NULL, 1.0, &ok);
            add_number(pbr, "metallicFactor", 0.0, &ok);
            add_number(pbr, "roughnessFactor", 1.0, &ok);
            cJSON *extensions = add_item(m, "extensions", cJSON_CreateObject(), &ok);
            add_item(extensions, "KHR_materials_unlit", cJSON_CreateObject(), &ok);
            if (maps) {
                /* As three.js's GLTFLoader plugin for it reads it. */
                cJSON *lightmap = add_item(extensions, "MOZ_lightmap", cJSON_CreateObject(), &ok);
                cJSON *texture = add_item(lightmap, "texture", cJSON_CreateObject(), &ok);
                add_number(texture, "index", prim->atlas, &ok);
                add_number(texture, "texCoord", 1, &ok);
                add_number(lightmap, "intensity", 1, &ok);
            }
        }
        cJSON *prim_json = add_item(primitive_list, NULL, cJSON_CreateObject(), &ok);
        cJSON *attributes = add_item(prim_json, "attributes", cJSON_CreateObject(), &ok);
        static const char *const names[4] = {"POSITION", "NORMAL", "COLOR_0", "_RADIOSITY"};
        for (int k = 0; k < 4; k++) {
            int a = add_accessor(accessors, k, 12 * prim->first_vertex, prim->vertex_count, "VEC3", &ok);
            add_number(attributes, names[k], a, &ok);
            if (k == VIEW_POSITION) {
                cJSON *position = cJSON_GetArrayItem(accessors, a);
                add_vec3(position, "min", prim->min, &ok);
                add_vec3(position, "max", prim->max, &ok);
            }
        }
        if (maps) {
            /* glTF numbers texture coordinates from 0 without gaps: set 0 is
             * the same accessor (no texture of ours reads it). */
            int a = add_accessor(accessors, VIEW_TEXCOORD, 8 * prim->first_vertex, prim->vertex_count, "VEC2", &ok);
            add_number(attributes, "TEXCOORD_0", a, &ok);
            add_number(attributes, "TEXCOORD_1", a, &ok);
        }
        add_number(prim_json, "indices",
                   add_accessor(accessors, VIEW_INDICES, 4 * prim->first_index, prim->index_count, "SCALAR", &ok),
                   &ok);
        add_number(prim_json, "material", material_index[material_key] - 1, &ok);
        add_number(prim_json, "mode", 4, &ok); /* triangles */
    }
    rad_free(material_index);

    cJSON *views = add_item(root, "bufferViews", cJSON_CreateArray(), &ok);
    for (int k = 0; k < (maps ? VIEW_COUNT : VIEW_TEXCOORD); k++) {
        cJSON *v = add_item(views, NULL, cJSON_CreateObject(), &ok);
        add_number(v, "buffer", 0, &ok);
        add_number(v, "byteOffset", (double)view_offset(p, k), &ok);
        add_number(v, "byteLength", (double)view_length(p, k), &ok);
        if (k != VIEW_INDICES)
            add_number(v, "byteStride", k == VIEW_TEXCOORD ? 8 : 12, &ok);
        add_number(v, "target", k == VIEW_INDICES ? GLTF_ELEMENT_ARRAY_BUFFER : GLTF_ARRAY_BUFFER, &ok);
    }
    if (maps)
        add_lightmaps(root, extras, maps, &ok);
    /* Last, so that the .gltf writer finds the empty uri at the end. */
    cJSON *buffer = add_item(add_item(root, "buffers", cJSON_CreateArray(), &ok), NULL, cJSON_CreateObject(), &ok);
    add_number(buffer, "byteLength", (double)bytes, &ok);
    if (uri)
        add_string(buffer, "uri", "", &ok);
    if (!ok) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

/* ---- glTF: the files ---- */

/* RFC 4648 base64 of `size` bytes, streamed. */
static int write_base64(FILE *f, const unsigned char *data, size_t size)
{
    static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char chunk[4096];
    size_t n = 0;
    for (size_t i = 0; i < size; i += 3) {
        uint32_t b = (uint32_t)data[i] << 16;
        if (i + 1 < size)
            b |= (uint32_t)data[i + 1] << 8;
        if (i + 2 < size)
            b |= data[i + 2];
        chunk[n++] = alphabet[(b >> 18) & 63];
        chunk[n++] = alphabet[(b >> 12) & 63];
        chunk[n++] = i + 1 < size ? alphabet[(b >> 6) & 63] : '=';
        chunk[n++] = i + 2 < size ? alphabet[b & 63] : '=';
        if (n == sizeof chunk || i + 3 >= size) {
            if (fwrite(chunk, 1, n, f) != n)
                return -1;
            n = 0;
        }
    }
    return 0;
}

static rad_result write_gltf(rad_context *ctx, const rad_solution_view *view, const lit_vertices *lit,
                             const rad_mesh_lightmaps *maps, const char *path, bool binary, FILE *f)
{
    primitives p;
    const rad_lightmap *lightmap = maps ? maps->lightmap : NULL;
    rad_result r = primitives_make(ctx, view->mesh, lightmap, &p);
    if (r != RAD_OK)
        return r;
    /* Four float VEC3 (and with lightmaps a VEC2) per vertex, a uint32 per
     * corner: a multiple of 4. */
    size_t bytes = view_offset(&p, VIEW_TEXCOORD) + (lightmap ? view_length(&p, VIEW_TEXCOORD) : 0);
    unsigned char *buffer = rad_alloc(ctx, RAD_MEM_OUTPUT, bytes, 1, "lit mesh: buffer");
    double *normal = buffer ? rad_alloc(ctx, RAD_MEM_OUTPUT, p.vertex_count, 3 * sizeof *normal,
                                        "lit mesh: normals")
                            : NULL;
    cJSON *root = NULL;
    char *text = NULL;
    if (!normal) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    fill_buffer(view->mesh, lit, lightmap, &p, buffer, normal);
    root = gltf_json(ctx, view, lit, &p, maps, bytes, !binary);
    text = root ? cJSON_PrintUnformatted(root) : NULL;
    if (!text) {
        r = rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory building JSON", path);
        goto done;
    }
    size_t length = strlen(text);
    int failed;
    if (binary) {
        /* 12-byte header, then chunks of (length, type, data), each padded
         * to 4 bytes: the JSON with blanks, the buffer with zeros. */
        size_t json_padded = (length + 3) & ~(size_t)3;
        size_t total = 12 + 8 + json_padded + 8 + bytes;
        if (total > UINT32_MAX) {
            r = rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                         "%s: the mesh needs %zu bytes, above binary glTF's 4 GiB; use fewer elements "
                         "(rad_options.target_elements)", path, total);
            goto done;
        }
        unsigned char head[20];
        unsigned char *q = put_u32(put_u32(put_u32(head, 0x46546C67u), 2), (uint32_t)total); /* "glTF" */
        put_u32(put_u32(q, (uint32_t)json_padded), 0x4E4F534Au);                              /* "JSON" */
        failed = fwrite(head, 1, 20, f) != 20 || fwrite(text, 1, length, f) != length;
        for (size_t k = length; k < json_padded && !failed; k++)
            failed = fputc(' ', f) == EOF;
        put_u32(put_u32(head, (uint32_t)bytes), 0x004E4942u); /* "BIN\0" */
        failed = failed || fwrite(head, 1, 8, f) != 8 || fwrite(buffer, 1, bytes, f) != bytes;
    } else {
        /* The document ends with the buffer's empty uri: put the data there. */
        static const char tail[] = "\"uri\":\"\"}]}";
        size_t tail_length = sizeof tail - 1;
        if (length < tail_length || strcmp(text + length - tail_length, tail) != 0) {
            r = rad_fail(ctx, RAD_ERROR_INTERNAL, "%s: unexpected glTF layout", path);
            goto done;
        }
        failed = fwrite(text, 1, length - 4, f) != length - 4 ||
                 fputs("data:application/octet-stream;base64,", f) == EOF || write_base64(f, buffer, bytes) != 0 ||
                 fputs("\"}]}\n", f) == EOF;
    }
    if (failed)
        r = rad_fail(ctx, RAD_ERROR_IO, "%s: write failed", path);
done:
    cJSON_free(text);
    cJSON_Delete(root);
    rad_free(normal);
    rad_free(buffer);
    primitives_free(&p);
    return r;
}

/* ---- the writers ---- */

static rad_result write_mesh(rad_context *ctx, const rad_solution_view *view, const char *path, double exposure,
                             const rad_mesh_lightmaps *maps)
{
    char ext[8];
    rad_path_extension(path, ext, sizeof ext);
    bool glb = strcmp(ext, "glb") == 0, gltf = strcmp(ext, "gltf") == 0, ply = strcmp(ext, "ply") == 0;
    if (!glb && !gltf && (!ply || maps))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: unknown mesh format (use .glb, .gltf%s)", path,
                        maps ? "" : " or .ply");
    if (!(exposure >= 0.0) || !isfinite(exposure))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: exposure must be >= 0, got %g", path, exposure);
    if (view->mesh->element_count == 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: the solution has no elements", path);
    lit_vertices lit;
    rad_result r = lit_vertices_make(ctx, view, exposure, &lit);
    if (r != RAD_OK)
        return r;
    rad_atomic_file file;
    r = rad_atomic_open(ctx, path, &file);
    if (r == RAD_OK) {
        r = ply ? write_ply(ctx, view, &lit, path, file.file)
                : write_gltf(ctx, view, &lit, maps, path, glb, file.file);
        if (r == RAD_OK)
            r = rad_atomic_commit(ctx, &file);
        else
            rad_atomic_abort(&file);
    }
    lit_vertices_free(&lit);
    return r;
}

rad_result rad_write_mesh(rad_context *ctx, const rad_solution_view *view, const char *path, double exposure)
{
    return write_mesh(ctx, view, path, exposure, NULL);
}

rad_result rad_write_mesh_baked(rad_context *ctx, const rad_solution_view *view, const char *path, double exposure,
                                const rad_mesh_lightmaps *maps)
{
    return write_mesh(ctx, view, path, exposure, maps);
}
