/*
 * test_export.c -- the lit mesh (rad_solution_write_mesh) read back: the
 * Cornell box solved on a few hundred elements, written as .glb, .gltf and
 * .ply, then read by assimp (glTF: positions, colours, triangles, node
 * names), by the small readers below (glTF's _RADIOSITY and asset.extras,
 * PLY whole) and, where node and the npm package gltf-validator are
 * installed (scripts/setup.sh puts it in build/npm), by the Khronos
 * validator.  Checked against the solution through the public API: every
 * vertex where the solution has it (float precision), _RADIOSITY and PLY
 * radiosity equal to rad_solution_vertex_radiosity, COLOR_0 = min(1,
 * B/pi x exposure), the automatic exposure's rule, triangles covering each
 * surface's area (1e-6) and facing its normal, names kept.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "test_support.h"

#include "radiosity.h"
#include "gltf_support.h"

#include <assimp/cimport.h>
#include <assimp/scene.h>
#include <cjson/cJSON.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static rad_context *ctx;
static rad_scene *scene;
static rad_solution *solution;
static double *vertex_B;   /* rad_solution_vertex_radiosity: 3 per vertex, W/m^2 */
static size_t vertex_count;

/* What the writer promises for display: min(1, B/pi x exposure), B/pi
 * rounded to float first as the file's radiance is. */
static double display_value(double B, double exposure)
{
    double value = exposure * (double)(float)(B / M_PI);
    return value > 0.0 ? fmin(value, 1.0) : 0.0;
}

static double luminance(const double rgb[3]) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

/* The automatic exposure maps the 95th percentile of the lit vertices'
 * luminance (of B/pi) to 0.8: one vertex lands on 0.8, at least 95% at or
 * below it. */
static void assert_automatic_exposure(double exposure)
{
    size_t lit = 0, below = 0, on = 0;
    for (size_t v = 0; v < vertex_count; v++) {
        double L[3];
        for (int c = 0; c < 3; c++)
            L[c] = (double)(float)(vertex_B[3 * v + (size_t)c] / M_PI);
        double y = luminance(L) * exposure;
        if (!(y > 0.0))
            continue;
        lit++;
        below += y <= 0.8 * (1 + 1e-6);
        on += fabs(y - 0.8) < 1e-6;
    }
    assert_true(lit > 0);
    assert_true((double)below >= 0.95 * (double)(lit - 1));
    assert_true(on >= 1);
}

/* ---- fixture: the Cornell box, solved ---- */

static int setup(void **state)
{
    (void)state;
    if (test_workdir_make("export") != 0)
        return -1;
    if (rad_context_create(NULL, &ctx) != RAD_OK || rad_scene_create_cornell_box(ctx, &scene) != RAD_OK)
        return -1;
    rad_options options = {0};
    options.target_elements = 300;
    if (rad_solution_create(ctx, scene, &options, &solution) != RAD_OK || rad_solution_solve(ctx, solution) != RAD_OK)
        return -1;
    vertex_count = rad_solution_vertex_count(solution);
    vertex_B = malloc(3 * vertex_count * sizeof *vertex_B);
    return vertex_B && rad_solution_vertex_radiosity(ctx, solution, vertex_B) == RAD_OK ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    free(vertex_B);
    rad_solution_destroy(solution);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return test_workdir_remove();
}

/* The solution's vertices of `surface`'s elements, ascending: the vertices
 * of its glTF primitive, in order (the Cornell box has one material per
 * surface).  Returns their count; `out` holds vertex_count entries. */
static size_t surface_vertices(size_t surface, size_t *out)
{
    char *used = calloc(vertex_count, 1);
    assert_non_null(used);
    for (size_t e = 0; e < rad_solution_element_count(solution); e++) {
        size_t corner[4];
        int k = rad_solution_element_vertices(solution, e, corner);
        if (rad_solution_element_surface(solution, e) == surface)
            for (int c = 0; c < k; c++)
                used[corner[c]] = 1;
    }
    size_t n = 0;
    for (size_t v = 0; v < vertex_count; v++)
        if (used[v])
            out[n++] = v;
    free(used);
    return n;
}

static size_t surface_named(const char *name)
{
    for (size_t s = 0; s < rad_scene_surface_count(scene); s++)
        if (strcmp(rad_scene_surface_name(scene, s), name) == 0)
            return s;
    fail_msg("no surface named '%s'", name);
    return SIZE_MAX;
}

/* ---- glTF: the JSON and the buffer, read directly ---- */

typedef struct gltf_file {
    unsigned char *bytes;
    cJSON *json;
    unsigned char *buffer;   /* the buffer's bytes (in `bytes` for GLB, decoded for .gltf) */
    size_t buffer_size;
    bool decoded;
} gltf_file;

static int base64_value(char c)
{
    if (c >= 'A' && c <= 'Z')
        return c - 'A';
    if (c >= 'a' && c <= 'z')
        return c - 'a' + 26;
    if (c >= '0' && c <= '9')
        return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
}

static void gltf_open(const char *path, bool binary, gltf_file *g)
{
    size_t size;
    memset(g, 0, sizeof *g);
    g->bytes = (unsigned char *)test_read_file(path, &size);
    cJSON *buffer;
    if (binary) {
        /* header (magic, version 2, length), JSON chunk, BIN chunk */
        assert_true(size >= 28);
        assert_int_equal(support_le_u32(g->bytes), 0x46546C67u);
        assert_int_equal(support_le_u32(g->bytes + 4), 2);
        assert_int_equal(support_le_u32(g->bytes + 8), size);
        uint32_t json_length = support_le_u32(g->bytes + 12);
        assert_int_equal(support_le_u32(g->bytes + 16), 0x4E4F534Au);
        assert_int_equal(json_length % 4, 0);
        g->json = cJSON_ParseWithLength((const char *)g->bytes + 20, json_length);
        unsigned char *bin = g->bytes + 20 + json_length;
        assert_int_equal(support_le_u32(bin + 4), 0x004E4942u);
        g->buffer = bin + 8;
        g->buffer_size = support_le_u32(bin);
        assert_int_equal(20 + json_length + 8 + g->buffer_size, size);
        assert_non_null(g->json);
        buffer = cJSON_GetArrayItem(cJSON_GetObjectItem(g->json, "buffers"), 0);
        assert_null(cJSON_GetObjectItem(buffer, "uri"));
    } else {
        g->json = cJSON_Parse((const char *)g->bytes);
        assert_non_null(g->json);
        buffer = cJSON_GetArrayItem(cJSON_GetObjectItem(g->json, "buffers"), 0);
        const char *uri = cJSON_GetStringValue(cJSON_GetObjectItem(buffer, "uri"));
        const char *prefix = "data:application/octet-stream;base64,";
        assert_non_null(uri);
        assert_memory_equal(uri, prefix, strlen(prefix));
        const char *text = uri + strlen(prefix);
        size_t length = strlen(text);
        assert_int_equal(length % 4, 0);
        g->buffer = malloc(length / 4 * 3);
        g->decoded = true;
        for (size_t i = 0; i < length; i += 4) {
            uint32_t bits = 0;
            int pad = 0;
            for (int k = 0; k < 4; k++) {
                int v = text[i + (size_t)k] == '=' ? (pad++, 0) : base64_value(text[i + (size_t)k]);
                assert_true(v >= 0);
                bits = bits << 6 | (uint32_t)v;
            }
            for (int k = 0; k < 3 - pad; k++)
                g->buffer[g->buffer_size++] = (unsigned char)(bits >> (16 - 8 * k));
        }
    }
    assert_int_equal(cJSON_GetNumberValue(cJSON_GetObjectItem(buffer, "byteLength")), g->buffer_size);
}

static void gltf_close(gltf_file *g)
{
    if (g->decoded)
        free(g->buffer);
    cJSON_Delete(g->json);
    free(g->bytes);
}

static double json_number(const cJSON *object, const char *key)
{
    const cJSON *item = cJSON_GetObjectItem(object, key);
    assert_true(cJSON_IsNumber(item));
    return item->valuedouble;
}

/* Accessor `index` as float VEC3: its count, and its first value's bytes
 * with the stride between values. */
static const unsigned char *gltf_vec3(const gltf_file *g, int index, size_t *count, size_t *stride)
{
    const cJSON *accessor = cJSON_GetArrayItem(cJSON_GetObjectItem(g->json, "accessors"), index);
    assert_non_null(accessor);
    assert_int_equal(json_number(accessor, "componentType"), 5126);
    assert_string_equal(cJSON_GetStringValue(cJSON_GetObjectItem(accessor, "type")), "VEC3");
    const cJSON *view = cJSON_GetArrayItem(cJSON_GetObjectItem(g->json, "bufferViews"),
                                           (int)json_number(accessor, "bufferView"));
    size_t offset = (size_t)json_number(view, "byteOffset") + (size_t)json_number(accessor, "byteOffset");
    const cJSON *s = cJSON_GetObjectItem(view, "byteStride");
    *stride = s ? (size_t)s->valuedouble : 12;
    *count = (size_t)json_number(accessor, "count");
    assert_true(offset + (*count - 1) * *stride + 12 <= g->buffer_size);
    return g->buffer + offset;
}

/* ---- glTF checks ---- */

static void check_gltf(const char *path, bool binary, double exposure_given)
{
    gltf_file g;
    gltf_open(path, binary, &g);
    const cJSON *asset = cJSON_GetObjectItem(g.json, "asset");
    assert_string_equal(cJSON_GetStringValue(cJSON_GetObjectItem(asset, "version")), "2.0");
    const cJSON *extras = cJSON_GetObjectItem(cJSON_GetObjectItem(asset, "extras"), "radiosity");
    double exposure = json_number(extras, "exposure");
    assert_string_equal(cJSON_GetStringValue(cJSON_GetObjectItem(extras, "colour")),
                        "linear radiance B/pi times exposure, W/(m^2 sr)");
    if (exposure_given > 0.0)
        assert_true(exposure == exposure_given);
    else
        assert_automatic_exposure(exposure);
    assert_string_equal(cJSON_GetStringValue(cJSON_GetArrayItem(cJSON_GetObjectItem(g.json, "extensionsUsed"), 0)),
                        "KHR_materials_unlit");
    const cJSON *material;
    cJSON_ArrayForEach(material, cJSON_GetObjectItem(g.json, "materials")) {
        assert_non_null(cJSON_GetObjectItem(cJSON_GetObjectItem(material, "extensions"), "KHR_materials_unlit"));
        const cJSON *base = cJSON_GetObjectItem(cJSON_GetObjectItem(material, "pbrMetallicRoughness"), "baseColorFactor");
        for (int c = 0; c < 4; c++)
            assert_true(cJSON_GetArrayItem(base, c)->valuedouble == 1.0);
    }

    /* _RADIOSITY, which assimp does not read: the solution's B as float. */
    size_t *expected = malloc(vertex_count * sizeof *expected);
    assert_non_null(expected);
    const cJSON *mesh;
    size_t meshes = 0;
    cJSON_ArrayForEach(mesh, cJSON_GetObjectItem(g.json, "meshes")) {
        size_t surface = surface_named(cJSON_GetStringValue(cJSON_GetObjectItem(mesh, "name")));
        size_t n = surface_vertices(surface, expected);
        const cJSON *primitives = cJSON_GetObjectItem(mesh, "primitives");
        assert_int_equal(cJSON_GetArraySize(primitives), 1);
        const cJSON *attributes = cJSON_GetObjectItem(cJSON_GetArrayItem(primitives, 0), "attributes");
        size_t count, stride;
        const unsigned char *B = gltf_vec3(&g, (int)json_number(attributes, "_RADIOSITY"), &count, &stride);
        assert_int_equal(count, n);
        for (size_t j = 0; j < n; j++)
            for (int c = 0; c < 3; c++)
                assert_true(support_le_f32(B + j * stride + 4 * (size_t)c) == (float)vertex_B[3 * expected[j] + (size_t)c]);
        meshes++;
    }
    assert_int_equal(meshes, rad_scene_surface_count(scene));

    /* Through assimp: one node per surface, named after it, its vertices
     * the solution's, COLOR_0 the display values, the triangles tiling the
     * surface and facing its normal. */
    const struct aiScene *ai = aiImportFile(path, 0);
    if (!ai)
        fail_msg("assimp cannot read %s: %s", path, aiGetErrorString());
    size_t vertices = 0, clamped = 0;
    double total_area = 0.0;
    assert_int_equal(ai->mRootNode->mNumChildren, rad_scene_surface_count(scene));
    for (unsigned k = 0; k < ai->mRootNode->mNumChildren; k++) {
        const struct aiNode *node = ai->mRootNode->mChildren[k];
        size_t surface = surface_named(node->mName.data);
        size_t n = surface_vertices(surface, expected);
        assert_int_equal(node->mNumMeshes, 1);
        const struct aiMesh *m = ai->mMeshes[node->mMeshes[0]];
        assert_int_equal(m->mNumVertices, n);
        assert_non_null(m->mColors[0]);
        assert_non_null(m->mNormals);
        for (size_t j = 0; j < n; j++) {
            double xyz[3];
            assert_true(rad_solution_vertex_position(solution, expected[j], xyz));
            assert_true(m->mVertices[j].x == (float)xyz[0]);
            assert_true(m->mVertices[j].y == (float)xyz[1]);
            assert_true(m->mVertices[j].z == (float)xyz[2]);
            const double *B = &vertex_B[3 * expected[j]];
            float colour[3] = {m->mColors[0][j].r, m->mColors[0][j].g, m->mColors[0][j].b};
            for (int c = 0; c < 3; c++) {
                assert_true(fabs(colour[c] - display_value(B[c], exposure)) <= 1e-6);
                clamped += colour[c] == 1.0f;
            }
        }
        /* The surface's elements in the solution's order, each as its
         * triangles (a quad's two): their vector area, half the norm of the
         * sum of their cross products, is the element's area.  (The measured
         * box's walls are up to 3 mm off planar, so its quads are folded and
         * the two triangles' own areas exceed the element's by ~1e-5.) */
        double area = 0.0;
        unsigned f = 0;
        for (size_t e = 0; e < rad_solution_element_count(solution); e++) {
            size_t corner[4];
            int corners = rad_solution_element_vertices(solution, e, corner);
            if (rad_solution_element_surface(solution, e) != surface)
                continue;
            double vector_area[3] = {0, 0, 0};
            for (int t = 0; t < corners - 2; t++, f++) {
                assert_true(f < m->mNumFaces);
                assert_int_equal(m->mFaces[f].mNumIndices, 3);
                const unsigned *i = m->mFaces[f].mIndices;
                struct aiVector3D a = m->mVertices[i[0]], b = m->mVertices[i[1]], c = m->mVertices[i[2]];
                double u[3] = {b.x - a.x, b.y - a.y, b.z - a.z}, v[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
                double cross[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
                for (int d = 0; d < 3; d++)
                    vector_area[d] += 0.5 * cross[d];
                /* counter-clockwise about the normals, as the element */
                double normal[3];
                assert_true(rad_solution_element_geometry(solution, e, normal, NULL));
                assert_true(cross[0] * normal[0] + cross[1] * normal[1] + cross[2] * normal[2] > 0.0);
                struct aiVector3D n3 = m->mNormals[i[0]];
                assert_true(fabs(n3.x * normal[0] + n3.y * normal[1] + n3.z * normal[2] - 1.0) < 1e-3);
            }
            double element_area = sqrt(vector_area[0] * vector_area[0] + vector_area[1] * vector_area[1] +
                                       vector_area[2] * vector_area[2]);
            /* float corners: 1e-7 of the box's size on edges a tenth of it */
            assert_true(fabs(element_area - rad_solution_element_area(solution, e)) <=
                        1e-5 * rad_solution_element_area(solution, e));
            area += element_area;
        }
        assert_int_equal(f, m->mNumFaces);
        /* 1e-6 of each surface but the left wall, whose two triangles in
         * the measured data are 3 mm off coplanar and are meshed as one
         * quad patch: its elements keep the triangles' area, their corners
         * enclose 5.6e-6 less (the mesh's, not the file's: PLY agrees). */
        double tolerance = strcmp(node->mName.data, "left_wall") == 0 ? 1e-5 : 1e-6;
        if (!(fabs(area - rad_scene_surface_area(scene, surface)) <= tolerance * rad_scene_surface_area(scene, surface)))
            fail_msg("%s: triangles cover %.9g m^2 of %.9g", node->mName.data, area,
                     rad_scene_surface_area(scene, surface));
        total_area += area;
        vertices += n;
    }
    double scene_area = 0.0;
    for (size_t s = 0; s < rad_scene_surface_count(scene); s++)
        scene_area += rad_scene_surface_area(scene, s);
    assert_true(fabs(total_area - scene_area) <= 1e-6 * scene_area);
    /* One material per surface and no vertex shared by two surfaces: every
     * vertex is written once. */
    assert_int_equal(vertices, vertex_count);
    if (exposure_given >= 10.0)
        assert_true(clamped > 0); /* the lamp is far above 1 */
    aiReleaseImport(ai);
    free(expected);
    gltf_close(&g);
}

static void test_glb(void **state)
{
    (void)state;
    const char *path = test_path("lit.glb");
    assert_int_equal(rad_solution_write_mesh(ctx, solution, path, 0.0), RAD_OK);
    check_gltf(path, true, 0.0);
}

static void test_gltf(void **state)
{
    (void)state;
    const char *path = test_path("lit.gltf");
    assert_int_equal(rad_solution_write_mesh(ctx, solution, path, 10.0), RAD_OK);
    check_gltf(path, false, 10.0);
    /* Upper-case extensions are the same formats. */
    path = test_path("LIT.GLTF");
    assert_int_equal(rad_solution_write_mesh(ctx, solution, path, 0.0), RAD_OK);
    check_gltf(path, false, 0.0);
}

/* ---- PLY ---- */

static double srgb(double linear)
{
    return linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1.0 / 2.4) - 0.055;
}

static void check_ply(const char *path, double exposure_given)
{
    size_t size;
    unsigned char *bytes = (unsigned char *)test_read_file(path, &size);
    const char *end = strstr((const char *)bytes, "end_header\n");
    assert_non_null(end);
    size_t header_length = (size_t)(end - (const char *)bytes) + strlen("end_header\n");
    char *header = strndup((const char *)bytes, header_length);
    const char *expected_header_start = "ply\nformat binary_little_endian 1.0\ncomment ";
    assert_memory_equal(header, expected_header_start, strlen(expected_header_start));
    const char *at = strstr(header, "exposure ");
    assert_non_null(at);
    double exposure = strtod(at + strlen("exposure "), NULL);
    assert_non_null(strstr(header, "W/m^2"));
    if (exposure_given > 0.0)
        assert_true(exposure == exposure_given);
    else
        assert_automatic_exposure(exposure);
    char properties[1024];
    snprintf(properties, sizeof properties,
             "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
             "property float radiosity_r\nproperty float radiosity_g\nproperty float radiosity_b\n"
             "property uchar red\nproperty uchar green\nproperty uchar blue\n"
             "element face %zu\nproperty list uchar int vertex_indices\nend_header\n",
             vertex_count, rad_solution_element_count(solution));
    assert_non_null(strstr(header, properties));
    free(header);

    const unsigned char *p = bytes + header_length;
    for (size_t v = 0; v < vertex_count; v++, p += 27) {
        double xyz[3];
        assert_true(rad_solution_vertex_position(solution, v, xyz));
        for (int c = 0; c < 3; c++) {
            assert_true(support_le_f32(p + 4 * c) == (float)xyz[c]);
            double B = vertex_B[3 * v + (size_t)c];
            assert_true(support_le_f32(p + 12 + 4 * c) == (float)B);
            long byte = lround(255.0 * srgb(display_value(B, exposure)));
            assert_int_equal(p[24 + c], byte); /* the PNG writer's bytes */
        }
    }
    double area = 0.0, scene_area = 0.0;
    for (size_t e = 0; e < rad_solution_element_count(solution); e++) {
        size_t corner[4];
        int k = rad_solution_element_vertices(solution, e, corner);
        assert_int_equal(*p++, k);
        double v[4][3];
        for (int c = 0; c < k; c++, p += 4) {
            assert_int_equal(support_le_u32(p), corner[c]);
            float xyz[3] = {support_le_f32(bytes + header_length + 27 * corner[c]),
                            support_le_f32(bytes + header_length + 27 * corner[c] + 4),
                            support_le_f32(bytes + header_length + 27 * corner[c] + 8)};
            for (int d = 0; d < 3; d++)
                v[c][d] = xyz[d];
        }
        /* a planar polygon's area: half the norm of the sum of its edges' crosses */
        double sum[3] = {0, 0, 0};
        for (int c = 0; c < k; c++) {
            const double *a = v[c], *b = v[(c + 1) % k];
            sum[0] += a[1] * b[2] - a[2] * b[1];
            sum[1] += a[2] * b[0] - a[0] * b[2];
            sum[2] += a[0] * b[1] - a[1] * b[0];
        }
        area += 0.5 * sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
    }
    assert_true(p == bytes + size);
    for (size_t s = 0; s < rad_scene_surface_count(scene); s++)
        scene_area += rad_scene_surface_area(scene, s);
    assert_true(fabs(area - scene_area) <= 1e-6 * scene_area);
    free(bytes);
}

static void test_ply(void **state)
{
    (void)state;
    const char *path = test_path("lit.ply");
    assert_int_equal(rad_solution_write_mesh(ctx, solution, path, 0.0), RAD_OK);
    check_ply(path, 0.0);
    assert_int_equal(rad_solution_write_mesh(ctx, solution, path, 2.5), RAD_OK);
    check_ply(path, 2.5);
}

/* ---- refusals ---- */

static void test_refused(void **state)
{
    (void)state;
    const char *obj = test_path("lit.obj"), *glb = test_path("bad.glb");
    assert_int_equal(rad_solution_write_mesh(ctx, solution, obj, 0.0), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "unknown mesh format (use .glb, .gltf or .ply)"));
    assert_false(test_file_exists(obj));
    assert_int_equal(rad_solution_write_mesh(ctx, solution, glb, -1.0), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_write_mesh(ctx, solution, glb, NAN), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_write_mesh(ctx, solution, glb, INFINITY), RAD_ERROR_INVALID_ARGUMENT);
    assert_false(test_file_exists(glb));
    /* An output set refuses the extension before any work. */
    rad_output_set *set;
    const char *temp;
    assert_int_equal(rad_output_set_create(ctx, &set), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, obj, RAD_OUTPUT_MESH, &temp), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("set.ply"), RAD_OUTPUT_MESH, &temp), RAD_OK);
    rad_output_set_destroy(set);
}

/* ---- the Khronos validator, where it is installed ---- */

static void test_validator(void **state)
{
    (void)state;
    const char *glb = test_path("valid.glb"), *gltf = test_path("valid.gltf");
    assert_int_equal(rad_solution_write_mesh(ctx, solution, glb, 0.0), RAD_OK);
    assert_int_equal(rad_solution_write_mesh(ctx, solution, gltf, 10.0), RAD_OK);
    const char *paths[2] = {glb, gltf};
    support_validate_gltf(RAD_TEST_SOURCE, RAD_NPM_MODULES, paths, 2, NULL, test_path("report.txt"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_glb),
        cmocka_unit_test(test_gltf),
        cmocka_unit_test(test_ply),
        cmocka_unit_test(test_refused),
        cmocka_unit_test(test_validator),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
