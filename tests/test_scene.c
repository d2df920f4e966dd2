/*
 * test_scene.c -- the scene module: the built-in Cornell box against its
 * published geometry, OBJ+MTL and glTF import (names, areas, reflectance,
 * emission E = pi * Ke, transforms, camera), the builder's validation, ear
 * clipping, and one test per kind of bad input (error code AND a message
 * naming the file, with the line where it is known).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "test_support.h"

#include "formfactor/formfactor.h"
#include "import/import_internal.h"
#include "scene/scene.h"

#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef RAD_TEST_DATA
#define RAD_TEST_DATA "tests/data"
#endif

static char temp_dir[] = "/tmp/rad_test_scene_XXXXXX";
static rad_context *ctx;

/* ---- helpers ---- */

static void check_close(double actual, double expected, double tolerance, const char *what,
                        const char *file, int line)
{
    if (!(fabs(actual - expected) <= tolerance)) {
        print_error("%s = %.17g, expected %.17g (tolerance %g)\n", what, actual, expected,
                    tolerance);
        _fail(file, line);
    }
}
#define assert_close(actual, expected, tolerance) \
    check_close((actual), (expected), (tolerance), #actual, __FILE__, __LINE__)
#define assert_close_relative(actual, expected, relative) \
    check_close((actual), (expected), (relative) * fabs(expected), #actual, __FILE__, __LINE__)

static void check_contains(const char *text, const char *part, const char *file, int line)
{
    if (!strstr(text, part)) {
        print_error("message \"%s\" does not contain \"%s\"\n", text, part);
        _fail(file, line);
    }
}
#define assert_contains(text, part) check_contains((text), (part), __FILE__, __LINE__)

/* Write `text` to temp_dir/name; returns the path (static, overwritten by
 * the next call). */
static const char *write_temp(const char *name, const char *text)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", temp_dir, name);
    FILE *file = fopen(path, "wb");
    assert_non_null(file);
    assert_int_equal(fwrite(text, 1, strlen(text), file), strlen(text));
    assert_int_equal(fclose(file), 0);
    return path;
}

static size_t surface_index(const rad_scene *scene, const char *name)
{
    for (size_t i = 0; i < rad_scene_surface_count(scene); i++)
        if (strcmp(rad_scene_surface_name(scene, i), name) == 0)
            return i;
    print_error("no surface '%s'\n", name);
    fail();
    return 0;
}

/* The material of the first polygon of a surface. */
static const rad_material *surface_material(const rad_scene *scene, size_t surface)
{
    for (size_t p = 0; p < scene->polygon_count; p++)
        if (scene->polygons[p].surface == surface)
            return &scene->materials[scene->polygons[p].material];
    fail();
    return NULL;
}

/* Twice the signed area of a 2D polygon (shoelace), for independent checks. */
static double shoelace(const double (*xy)[2], size_t n)
{
    double twice = 0.0;
    for (size_t i = 0; i < n; i++)
        twice += xy[i][0] * xy[(i + 1) % n][1] - xy[(i + 1) % n][0] * xy[i][1];
    return 0.5 * twice;
}

/* ---- the Cornell box ---- */

static void check_cornell_geometry(const rad_scene *scene)
{
    static const char *const names[] = {"floor",      "ceiling",   "light",       "back_wall",
                                        "right_wall", "left_wall", "short_block", "tall_block"};
    assert_int_equal(rad_scene_surface_count(scene), 8);
    for (size_t i = 0; i < 8; i++)
        assert_string_equal(rad_scene_surface_name(scene, i), names[i]);
    assert_null(rad_scene_surface_name(scene, 8));
    /* floor 1, ceiling 4 quads around the light, light 1, back 1, right 1,
     * left 2 triangles, blocks 5 faces each */
    assert_int_equal(rad_scene_polygon_count(scene), 20);

    /* The floor quad, (x, z) as published (in metres). */
    static const double floor_xz[4][2] = {
        {0.5528, 0.0}, {0.0, 0.0}, {0.0, 0.5592}, {0.5496, 0.5592}};
    assert_close(rad_scene_surface_area(scene, 0), fabs(shoelace(floor_xz, 4)), 1e-12);
    assert_close(rad_scene_surface_area(scene, 1), 0.556 * 0.5592 - 0.13 * 0.105, 1e-9);
    assert_close(rad_scene_surface_area(scene, 2), 0.13 * 0.105, 1e-12);

    const rad_material *light = surface_material(scene, 2);
    assert_close_relative(light->emission[0], M_PI * 17.1972, 1e-9);
    assert_close_relative(light->emission[1], M_PI * 11.4744, 1e-9);
    assert_close_relative(light->emission[2], M_PI * 3.0619, 1e-9);
    const rad_material *white = surface_material(scene, 0);
    assert_string_equal(white->name, "white");
    assert_close(white->reflectance[0], 0.7378, 1e-12);
    assert_close(white->reflectance[1], 0.7361, 1e-12);
    assert_close(white->reflectance[2], 0.7374, 1e-12);
    assert_close(white->emission[0], 0.0, 0.0);
    assert_true(rad_scene_has_emitter(scene));

    /* Winding: the floor faces up into the room, the light down into it. */
    for (size_t p = 0; p < scene->polygon_count; p++) {
        const rad_polygon *polygon = &scene->polygons[p];
        if (polygon->surface == 0)
            assert_close(polygon->normal.y, 1.0, 1e-12);
        if (polygon->surface == 2)
            assert_close(polygon->normal.y, -1.0, 1e-12);
    }
    assert_close(rad_scene_diagonal(scene), sqrt(0.556 * 0.556 + 0.5488 * 0.5488 +
                                                 0.5592 * 0.5592), 1e-12);
}

static void test_cornell_box(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    check_cornell_geometry(scene);
    assert_string_equal(scene->source, "cornell-box");

    rad_camera camera;
    assert_true(rad_scene_camera(scene, &camera));
    assert_close(camera.vfov_degrees, 39.3076, 1e-3);
    assert_close(camera.position[0], 0.278, 0.0);
    assert_close(camera.position[1], 0.273, 0.0);
    assert_close(camera.position[2], -0.8, 0.0);
    assert_close(camera.look_at[2] - camera.position[2], 0.8, 1e-15); /* looks along +z */
    assert_close(camera.up[1], 1.0, 0.0);
    rad_scene_destroy(scene);
}

/* The same box from the files on disk: the MTL is found next to the OBJ. */
static void test_cornell_box_file(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_file(ctx, RAD_TEST_DATA "/cornell_box.obj", &scene), RAD_OK);
    check_cornell_geometry(scene);
    rad_camera none;
    assert_false(rad_scene_camera(scene, &none));
    assert_true(scene->load_seconds >= 0.0);
    rad_scene_destroy(scene);
}

/* ---- OBJ + MTL from memory ---- */

static const char lamp_obj[] = "mtllib lamp.mtl\n"
                               "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\n"
                               "v 0 0 1\nv 1 0 1\nv 0 1 1\n"
                               "o panel\nusemtl grey\nf 1 2 3 4\n"
                               "o lamp\nusemtl glow\nf -3 -2 -1\n";
static const char lamp_mtl[] = "newmtl grey\nKd 0.5 0.25 0.125\n"
                               "newmtl glow\nKd 0.1 0.1 0.1\nKe 2 1 0.5\n";

/* The scene of lamp_obj and lamp_mtl, however it was read. */
static void check_lamp(rad_scene *scene)
{
    assert_non_null(scene);
    assert_int_equal(rad_scene_surface_count(scene), 2);
    size_t panel = surface_index(scene, "panel"), lamp = surface_index(scene, "lamp");
    assert_close(rad_scene_surface_area(scene, panel), 2.0, 1e-15);
    assert_close(rad_scene_surface_area(scene, lamp), 0.5, 1e-15);
    const rad_material *grey = surface_material(scene, panel);
    assert_close(grey->reflectance[0], 0.5, 0.0);
    assert_close(grey->reflectance[1], 0.25, 0.0);
    assert_close(grey->reflectance[2], 0.125, 0.0);
    assert_close(grey->emission[0], 0.0, 0.0);
    const rad_material *glow = surface_material(scene, lamp);
    assert_close(glow->emission[0], M_PI * 2.0, 1e-14);
    assert_close(glow->emission[1], M_PI * 1.0, 1e-14);
    assert_close(glow->emission[2], M_PI * 0.5, 1e-14);
    /* The lamp's relative indices -3 -2 -1 are vertices 5 6 7 at z = 1. */
    const rad_polygon *triangle = &scene->polygons[scene->polygons[0].surface == lamp ? 0 : 1];
    assert_int_equal(triangle->vertex_count, 3);
    assert_close(scene->positions[scene->indices[triangle->first_index]].z, 1.0, 0.0);
    rad_camera none;
    assert_false(rad_scene_camera(scene, &none));
    assert_true(rad_scene_has_emitter(scene));
    rad_scene_destroy(scene);
}

static void test_obj_from_memory(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "lamp.obj", lamp_obj, strlen(lamp_obj),
                                           lamp_mtl, strlen(lamp_mtl), &scene),
                     RAD_OK);
    check_lamp(scene);
}

/* `g` names a surface like `o`; with no name at all assimp says "defaultobject". */
static void test_obj_groups(void **state)
{
    (void)state;
    static const char obj[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                              "f 1 2 3\n"
                              "g wall\nf 1 3 4\n";
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "groups.obj", obj, strlen(obj), NULL, 0, &scene),
                     RAD_OK);
    assert_int_equal(rad_scene_surface_count(scene), 2);
    assert_string_equal(rad_scene_surface_name(scene, 0), "defaultobject");
    assert_string_equal(rad_scene_surface_name(scene, 1), "wall");
    assert_int_equal(rad_scene_polygon_count(scene), 2);
    assert_false(rad_scene_has_emitter(scene));
    rad_scene_destroy(scene);
}

static void remove_temp(const char *name);

/* The scene of test_obj_face_forms. */
static void check_face_forms(rad_scene *scene)
{
    assert_int_equal(rad_scene_surface_count(scene), 3); /* "lines" has no polygon */
    assert_close(rad_scene_surface_area(scene, surface_index(scene, "mixed")), 2.0, 1e-15);
    assert_close(rad_scene_surface_area(scene, surface_index(scene, "old")), 1.0, 1e-15);
    assert_close(rad_scene_surface_area(scene, surface_index(scene, "repeat")), 1.0, 1e-15);
    assert_int_equal(rad_scene_polygon_count(scene), 3);
    for (size_t p = 0; p < scene->polygon_count; p++) {
        const rad_polygon *polygon = &scene->polygons[p];
        if (polygon->surface == surface_index(scene, "repeat"))
            assert_int_equal(polygon->vertex_count, 3);
        /* every polygon starts at vertex 1 = (0, 0, 0), or 2 = (2, 0, 0) */
        vec3 first = scene->positions[scene->indices[polygon->first_index]];
        assert_true(first.y == 0.0 && first.z == 0.0 && (first.x == 0.0 || first.x == 2.0));
    }
    rad_scene_destroy(scene);
}

/* What loads besides plain faces: lines and points (no area: ignored, no
 * error), `fo`, faces mixing the v, v/vt, v//vn and v/vt/vn forms, a
 * vertex repeated next to itself (dropped), relative indices. */
static void test_obj_face_forms(void **state)
{
    (void)state;
    static const char obj[] = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                              "o lines\nl 1 2 3\nl 1 2\np 1 2 3 4\np 4\n"
                              "o mixed\nf 1/1 2//1 3/1/1 4\n"
                              "o old\nfo 1 2 3\n"
                              "o repeat\nf -4 -3 -3 -2\n";
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "forms.obj", obj, strlen(obj), NULL, 0, &scene),
                     RAD_OK);
    check_face_forms(scene);

    /* A UTF-8 byte order mark first is skipped (assimp 5.2 dropped the
     * first vertex with it, and every face then named the wrong ones). */
    char with_bom[sizeof obj + 3];
    snprintf(with_bom, sizeof with_bom, "\xEF\xBB\xBF%s", obj);
    scene = NULL;
    assert_int_equal(rad_scene_load_file(ctx, write_temp("bom.obj", with_bom), &scene), RAD_OK);
    check_face_forms(scene);
    remove_temp("bom.obj");
}

/* Every digit: OBJ coordinates and MTL Kd / Ke of 16-17 significant digits
 * reach the scene as strtod reads them, bit for bit (assimp alone keeps
 * floats: 7 digits), in every face form, through relative indices and a
 * homogeneous "v x y z w"; so the area of a rectangle and the factor from
 * a point under its corner to a parallel rectangle above it match their
 * closed forms in double to 1e-14 (with float coordinates: 1e-8). */
static void test_obj_exact_digits(void **state)
{
    (void)state;
    static const char *const x[2] = {"-0.12345678912345678", "1.2345678912345679"};
    static const char *const y[2] = {"0.31415926535897931", "2.7182818284590451"};
    static const char *const h = "0.98765432109876543";
    char obj[2048];
    snprintf(obj, sizeof obj,
             "mtllib digits.mtl\n"
             "v %s %s 0\nv %s %s 0\nv %s %s 0\nv %s %s 0\n"
             "v %s %s %s\nv %s %s %s\nv %s %s %s\n"
             "v %s %s 1.9753086421975308 2\n" /* (x0, y1, h) with w = 2: halved exactly */
             "vt 0 0\nvn 0 0 1\n"
             "o floor\nusemtl grey\nf 1/1 2//1 3/1/1 4\n"
             "o ceiling\nusemtl lamp\nf -1 -2 -3 -4\n",
             x[0], y[0], x[1], y[0], x[1], y[1], x[0], y[1],        /* floor, facing up */
             x[0], y[0], h, x[1], y[0], h, x[1], y[1], h,           /* ceiling, facing down */
             "-0.24691357824691357", "5.4365636569180900");
    static const char mtl[] = "newmtl grey\nKd 0.12345678901234567 0.5 0.66666666666666663\n"
                              "newmtl lamp\nKd 0 0 0\nKe 0.33333333333333331 1.4142135623730951 7\n";
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "digits.obj", obj, strlen(obj), mtl, strlen(mtl),
                                           &scene),
                     RAD_OK);
    double X[2] = {strtod(x[0], NULL), strtod(x[1], NULL)};
    double Y[2] = {strtod(y[0], NULL), strtod(y[1], NULL)};
    double H = strtod(h, NULL);
    /* Every corner is one of the file's positions, bit for bit. */
    size_t floor = surface_index(scene, "floor"), ceiling = surface_index(scene, "ceiling");
    const vec3 *ceiling_polygon = NULL;
    for (size_t p = 0; p < scene->polygon_count; p++) {
        const rad_polygon *polygon = &scene->polygons[p];
        assert_int_equal(polygon->vertex_count, 4);
        const vec3 *corner = &scene->positions[scene->indices[polygon->first_index]];
        if (polygon->surface == ceiling)
            ceiling_polygon = corner;
        for (size_t k = 0; k < 4; k++) {
            vec3 q = scene->positions[scene->indices[polygon->first_index + k]];
            assert_true(q.x == X[0] || q.x == X[1]);
            assert_true(q.y == Y[0] || q.y == Y[1]);
            assert_true(q.z == (polygon->surface == floor ? 0.0 : H));
        }
    }
    assert_non_null(ceiling_polygon);
    /* Kd exactly, E = pi Ke exactly as computed from the doubles. */
    const rad_material *grey = surface_material(scene, floor), *lamp = surface_material(scene, ceiling);
    assert_true(grey->reflectance[0] == strtod("0.12345678901234567", NULL));
    assert_true(grey->reflectance[2] == strtod("0.66666666666666663", NULL));
    assert_true(lamp->emission[0] == M_PI * strtod("0.33333333333333331", NULL));
    assert_true(lamp->emission[1] == M_PI * strtod("1.4142135623730951", NULL));
    /* Areas, and the factor from (x0, y0, 0) facing up to the ceiling
     * (Howell's catalogue, B-3: a = b / c, the sides over the height). */
    double a = X[1] - X[0], b = Y[1] - Y[0];
    assert_close_relative(rad_scene_surface_area(scene, floor), a * b, 1e-14);
    assert_close_relative(rad_scene_surface_area(scene, ceiling), a * b, 1e-14);
    double A = a / H, B = b / H;
    double exact = (A / sqrt(1 + A * A) * atan(B / sqrt(1 + A * A)) +
                    B / sqrt(1 + B * B) * atan(A / sqrt(1 + B * B))) /
                   (2.0 * M_PI);
    double F = rad_point_polygon_ff(v3(X[0], Y[0], 0.0), v3(0, 0, 1), ceiling_polygon, 4);
    assert_close_relative(F, exact, 1e-14);
    rad_scene_destroy(scene);
}

/* ---- glTF 2.0 ---- */

/* A unit quad (4 float positions, 6 ushort indices, base64) used by two
 * nodes: "lamp" moved up by 2, and "big" scaled by 2 inside "group" moved
 * by 10 in x.  Emissive (1, 0.5, 0.25) at strength 4; a camera node at
 * z = 5 with yfov 0.5 rad. */
static const char quad_gltf[] =
    "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0,\n"
    " \"scenes\": [{\"nodes\": [0, 1, 2]}],\n"
    " \"nodes\": [{\"name\": \"lamp\", \"mesh\": 0, \"translation\": [0, 2, 0]},\n"
    "            {\"name\": \"cam\", \"camera\": 0, \"translation\": [0, 0, 5]},\n"
    "            {\"name\": \"group\", \"translation\": [10, 0, 0], \"children\": [3]},\n"
    "            {\"name\": \"big\", \"mesh\": 0, \"scale\": [2, 2, 2]}],\n"
    " \"cameras\": [{\"type\": \"perspective\",\n"
    "               \"perspective\": {\"yfov\": 0.5, \"aspectRatio\": 1.5, \"znear\": 0.1}}],\n"
    " \"meshes\": [{\"name\": \"quadmesh\",\n"
    "             \"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1,\n"
    "                             \"material\": 0}]}],\n"
    " \"materials\": [{\"name\": \"glow\",\n"
    "                \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.4, 0.3, 1]},\n"
    "                \"emissiveFactor\": [1, 0.5, 0.25],\n"
    "                \"extensions\": {\"KHR_materials_emissive_strength\":\n"
    "                               {\"emissiveStrength\": 4}}}],\n"
    " \"extensionsUsed\": [\"KHR_materials_emissive_strength\"],\n"
    " \"buffers\": [{\"byteLength\": 60, \"uri\": \"data:application/octet-stream;base64,"
    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAgD8AAAAAAAAAAAAAgD8AAAAAAAABAAIAAAACAAMA\"}],\n"
    " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48},\n"
    "                  {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 12}],\n"
    " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4,\n"
    "                \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]},\n"
    "               {\"bufferView\": 1, \"componentType\": 5123, \"count\": 6,\n"
    "                \"type\": \"SCALAR\"}]}\n";

static void check_quad_gltf(const rad_scene *scene)
{
    assert_int_equal(rad_scene_surface_count(scene), 2);
    assert_string_equal(rad_scene_surface_name(scene, 0), "lamp"); /* node, not mesh, name */
    assert_string_equal(rad_scene_surface_name(scene, 1), "big");
    assert_int_equal(rad_scene_polygon_count(scene), 4);
    assert_close(rad_scene_surface_area(scene, 0), 1.0, 1e-12);
    assert_close(rad_scene_surface_area(scene, 1), 4.0, 1e-12); /* scaled by 2 */
    /* lamp at y in [2, 3]; big at x in [10, 12] (parent * child) */
    assert_close(scene->bounds_min.x, 0.0, 0.0);
    assert_close(scene->bounds_max.x, 12.0, 1e-12);
    assert_close(scene->bounds_max.y, 3.0, 1e-12);
    for (size_t p = 0; p < scene->polygon_count; p++)
        if (scene->polygons[p].surface == 0)
            for (uint32_t k = 0; k < scene->polygons[p].vertex_count; k++)
                assert_true(scene->positions[scene->indices[scene->polygons[p].first_index + k]]
                                .y >= 2.0);

    const rad_material *glow = surface_material(scene, 0);
    assert_close(glow->emission[0], M_PI * 4.0 * 1.0, 1e-12);
    assert_close(glow->emission[1], M_PI * 4.0 * 0.5, 1e-12);
    assert_close(glow->emission[2], M_PI * 4.0 * 0.25, 1e-12);
    assert_close(glow->reflectance[0], 0.5, 1e-12);
    assert_close(glow->reflectance[1], 0.4, 1e-12);
    assert_close(glow->reflectance[2], 0.3, 1e-12);

    rad_camera camera;
    assert_true(rad_scene_camera(scene, &camera));
    assert_close(camera.position[2], 5.0, 1e-12); /* the node's translation, counted once */
    assert_close(camera.look_at[2], 4.0, 1e-12);  /* glTF cameras look down -z */
    assert_close(camera.up[1], 1.0, 1e-12);
    assert_close(camera.vfov_degrees, 0.5 * 180.0 / M_PI, 1e-9);
}

static void test_gltf(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_file(ctx, write_temp("quad.gltf", quad_gltf), &scene),
                     RAD_OK);
    check_quad_gltf(scene);
    rad_scene_destroy(scene);
    scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "quad.gltf", quad_gltf, strlen(quad_gltf), NULL,
                                           0, &scene),
                     RAD_OK);
    check_quad_gltf(scene);
    rad_scene_destroy(scene);
}

/* ---- glTF built in memory: hostile and awkward files (test_text) ---- */

/* Replace the first `old` in t by `new_text`; fails the test if absent. */
static void patch(test_text *t, const char *old, const char *new_text)
{
    char *at = strstr(t->data, old);
    if (!at)
        fail_msg("patch: '%s' not in the glTF", old);
    size_t before = (size_t)(at - t->data), old_length = strlen(old);
    test_text patched = {0};
    test_put(&patched, "%.*s%s%s", (int)before, t->data, new_text, at + old_length);
    free(t->data);
    *t = patched;
}

/* One mesh of a glTF made by gltf_text: its single primitive's float
 * positions, its 32-bit indices (NULL: none), its topology and material
 * (0: "white", reflectance 0.5; 1: "lamp", black, emissive 1: E = pi). */
typedef struct gltf_mesh {
    const float *positions;
    size_t vertices;
    const uint32_t *indices;
    size_t index_count;
    int mode;
    int material;
} gltf_mesh;

static void put_base64(test_text *t, const unsigned char *bytes, size_t n)
{
    static const char alphabet[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (size_t i = 0; i < n; i += 3) {
        unsigned v = (unsigned)bytes[i] << 16 | (i + 1 < n ? (unsigned)bytes[i + 1] << 8 : 0) |
                     (i + 2 < n ? bytes[i + 2] : 0);
        test_put(t, "%c%c%c%c", alphabet[v >> 18], alphabet[v >> 12 & 63],
            i + 1 < n ? alphabet[v >> 6 & 63] : '=', i + 2 < n ? alphabet[v & 63] : '=');
    }
}

/* A glTF 2.0 file: `nodes` and the default scene's `roots` as JSON
 * arrays, mesh i made of meshes[i] with accessors 2i (POSITION, VEC3
 * float) and 2i + 1 (indices, SCALAR uint32), all in one base64 buffer;
 * `extra` is more top-level JSON (", \"cameras\": [...]") or "". */
static test_text gltf_text(const char *nodes, const char *roots, const gltf_mesh *meshes, size_t count,
                      const char *extra)
{
    size_t bytes = 0;
    for (size_t m = 0; m < count; m++)
        bytes += 12 * meshes[m].vertices + 4 * meshes[m].index_count;
    unsigned char *buffer = calloc(bytes + 1, 1);
    assert_non_null(buffer);
    test_text t = {0}, views = {0}, accessors = {0};
    test_put(&t, "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": %s}],\n"
            " \"nodes\": %s,\n \"meshes\": [",
        roots, nodes);
    size_t offset = 0;
    for (size_t m = 0; m < count; m++) {
        const gltf_mesh *mesh = &meshes[m];
        test_put(&t, "%s{\"name\": \"m%zu\", \"primitives\": [{\"attributes\": {\"POSITION\": %zu}, "
                "\"mode\": %d, \"material\": %d",
            m ? ",\n  " : "", m, 2 * m, mesh->mode, mesh->material);
        if (mesh->indices)
            test_put(&t, ", \"indices\": %zu", 2 * m + 1);
        test_put(&t, "}]}");
        for (int pass = 0; pass < 2; pass++) {
            size_t length = pass ? 4 * mesh->index_count : 12 * mesh->vertices;
            const void *data = pass ? (const void *)mesh->indices : (const void *)mesh->positions;
            if (length)
                memcpy(buffer + offset, data, length); /* little-endian, as glTF */
            /* no indices: a dummy view of the first 4 bytes, never read */
            test_put(&views, "%s{\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}",
                views.length ? ", " : "", length ? offset : 0, length ? length : 4);
            if (pass == 0)
                test_put(&accessors, "%s{\"bufferView\": %zu, \"componentType\": 5126, \"count\": %zu, "
                                "\"type\": \"VEC3\"}",
                    accessors.length ? ",\n  " : "", 2 * m, mesh->vertices);
            else
                test_put(&accessors, ",\n  {\"bufferView\": %zu, \"componentType\": 5125, "
                                "\"count\": %zu, \"type\": \"SCALAR\"}",
                    2 * m + 1, mesh->index_count ? mesh->index_count : 1);
            offset += length;
        }
    }
    test_put(&t, "],\n \"materials\": [{\"name\": \"white\", \"pbrMetallicRoughness\": "
            "{\"baseColorFactor\": [0.5, 0.5, 0.5, 1]}},\n"
            "  {\"name\": \"lamp\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0, 0, 0, 1]},"
            " \"emissiveFactor\": [1, 1, 1]}],\n"
            " \"buffers\": [{\"byteLength\": %zu, \"uri\": \"data:application/octet-stream;base64,",
        offset ? offset : 4);
    put_base64(&t, buffer, offset ? offset : 4);
    test_put(&t, "\"}],\n \"bufferViews\": [%s],\n \"accessors\": [%s]%s}\n", views.data,
        accessors.data, extra);
    free(buffer);
    free(views.data);
    free(accessors.data);
    return t;
}

/* The unit quad in the z = 0 plane, facing +z (two triangles). */
static const float unit_quad[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
static const uint32_t unit_quad_indices[] = {0, 1, 2, 0, 2, 3};

static rad_result load_gltf(const test_text *t, rad_scene **scene)
{
    *scene = NULL;
    rad_api_enter(ctx);
    return rad_scene_load_memory(ctx, "x.gltf", t->data, t->length, NULL, 0, scene);
}

/* Load `t`; it must fail with `expected` and a one-line message naming
 * x.gltf and holding every part given. */
static void assert_gltf_refused(test_text *t, rad_result expected, const char *part1,
                                const char *part2)
{
    rad_scene sentinel, *scene = &sentinel;
    rad_result r = rad_scene_load_memory(ctx, "x.gltf", t->data, t->length, NULL, 0, &scene);
    if (r != expected)
        fail_msg("got %s (\"%s\"), expected %s", rad_result_string(r), rad_context_error(ctx),
                 rad_result_string(expected));
    assert_null(scene);
    assert_null(strchr(rad_context_error(ctx), '\n'));
    assert_contains(rad_context_error(ctx), "x.gltf: ");
    if (part1)
        assert_contains(rad_context_error(ctx), part1);
    if (part2)
        assert_contains(rad_context_error(ctx), part2);
    free(t->data);
    t->data = NULL;
}

/* A chain of `depth` nested nodes, each moved 1 mm up in y, the last
 * holding the unit quad. */
static test_text nested(size_t depth)
{
    test_text nodes = {0};
    test_put(&nodes, "[");
    for (size_t i = 0; i + 1 < depth; i++)
        test_put(&nodes, "{\"translation\": [0, 0.001, 0], \"children\": [%zu]},", i + 1);
    test_put(&nodes, "{\"translation\": [0, 0.001, 0], \"mesh\": 0}]");
    gltf_mesh quad = {unit_quad, 4, unit_quad_indices, 6, 4, 0};
    test_text t = gltf_text(nodes.data, "[0]", &quad, 1, "");
    free(nodes.data);
    return t;
}

/* 1,000 levels load, every level's transform applied (walked without
 * recursion); 1,001 and 20,000 (which overflowed the stack inside assimp)
 * are refused before assimp reads them, naming the deepest node and the
 * limit. */
static void test_gltf_nesting(void **state)
{
    (void)state;
    test_text t = nested(1000);
    rad_scene *scene = NULL;
    assert_int_equal(load_gltf(&t, &scene), RAD_OK);
    assert_int_equal(rad_scene_polygon_count(scene), 2);
    assert_close(rad_scene_surface_area(scene, 0), 1.0, 1e-12);
    /* 1000 x 0.001 (a float: 0.0010000000475) */
    assert_close(scene->bounds_min.y, 1.0, 1e-6);
    assert_close(scene->bounds_max.y, 2.0, 1e-6);
    rad_scene_destroy(scene);
    free(t.data);

    t = nested(1001);
    assert_gltf_refused(&t, RAD_ERROR_PARSE, "node 1000 is nested 1001 levels deep",
                        "at most 1000 levels");
    t = nested(20000);
    assert_gltf_refused(&t, RAD_ERROR_PARSE, "node 19999 is nested 20000 levels deep", NULL);
}

/* Node graphs that are not disjoint strict trees (glTF 2.0, "Nodes and
 * Hierarchy"), among them the instance bomb: 9 levels of 10 nodes, each
 * listing all 10 of the next level, which assimp expanded to 10^8 copies. */
static void test_gltf_node_graphs(void **state)
{
    (void)state;
    static const struct {
        const char *nodes, *roots, *message[2];
    } cases[] = {
        {"[{\"name\": \"a\", \"children\": [2]}, {\"name\": \"b\", \"children\": [2]}, "
         "{\"name\": \"c\", \"mesh\": 0}]",
         "[0, 1]", {"node 'c' (2) is a child of both node 'a' (0) and node 'b' (1)", NULL}},
        {"[{\"name\": \"a\", \"children\": [1]}, {\"name\": \"b\", \"children\": [0], "
         "\"mesh\": 0}]",
         "[0]", {"is its own ancestor (the nodes form a cycle)", NULL}},
        {"[{\"name\": \"r\", \"mesh\": 0}, {\"children\": [2]}, {\"children\": [3]}, "
         "{\"children\": [1], \"mesh\": 0}]",
         "[0]", {"is its own ancestor", NULL}},
        /* a cycle hung under a root: some node of it has two parents */
        {"[{\"name\": \"r\", \"children\": [1]}, {\"children\": [2]}, {\"children\": [1], "
         "\"mesh\": 0}]",
         "[0]", {"node 1 is a child of both node 'r' (0) and node 2", NULL}},
        {"[{\"name\": \"a\", \"children\": [0], \"mesh\": 0}]", "[0]",
         {"node 'a' (0) is its own child", NULL}},
        {"[{\"name\": \"a\", \"children\": [1, 1]}, {\"mesh\": 0}]", "[0]",
         {"node 'a' (0) lists node 1 twice", NULL}},
        {"[{\"name\": \"a\", \"children\": [1]}, {\"name\": \"b\", \"mesh\": 0}]", "[0, 1]",
         {"scene 0 lists node 'b' (1), a child of node 'a' (0)", NULL}},
        {"[{\"mesh\": 0}]", "[0, 0]", {"scene 0 lists node 0 twice", NULL}},
        {"[{\"children\": [7], \"mesh\": 0}]", "[0]",
         {"node 0: a child is not a node index", NULL}},
        {"[{\"children\": [0.5], \"mesh\": 0}]", "[0]", {"a child is not a node index", NULL}},
        {"[{\"children\": [-1], \"mesh\": 0}]", "[0]", {"a child is not a node index", NULL}},
        {"[{\"mesh\": 3}]", "[0]", {"node 0 refers to no mesh (1 meshes)", NULL}},
        {"[{\"mesh\": 0}]", "[4]", {"scene 0 lists something that is not a node index", NULL}},
        {"[{\"mesh\": 0, \"scale\": [1, 1]}]", "[0]", {"scale must be 3 finite numbers", NULL}},
        {"[{\"mesh\": 0, \"translation\": [0, 1e999, 0]}]", "[0]",
         {"translation must be 3 finite numbers", NULL}},
        {"[{\"mesh\": 0, \"rotation\": [0, 0, 0, 0]}]", "[0]", {"the zero quaternion", NULL}},
        {"[{\"mesh\": 0, \"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0]}]", "[0]",
         {"matrix must be 16 finite numbers", NULL}},
    };
    gltf_mesh quad = {unit_quad, 4, unit_quad_indices, 6, 4, 0};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        test_text t = gltf_text(cases[k].nodes, cases[k].roots, &quad, 1, "");
        rad_api_enter(ctx);
        assert_gltf_refused(&t, RAD_ERROR_PARSE, cases[k].message[0], cases[k].message[1]);
    }

    /* The instance bomb (1.8 KB of nodes in the original). */
    test_text nodes = {0}, roots = {0};
    test_put(&nodes, "[");
    for (int level = 0; level < 9; level++)
        for (int i = 0; i < 10; i++) {
            test_put(&nodes, "%s{\"name\": \"n%d_%d\"", level + i ? ", " : "", level, i);
            if (level == 8)
                test_put(&nodes, ", \"mesh\": 0}");
            else {
                test_put(&nodes, ", \"children\": [");
                for (int k = 0; k < 10; k++)
                    test_put(&nodes, "%s%d", k ? ", " : "", 10 * (level + 1) + k);
                test_put(&nodes, "]}");
            }
        }
    test_put(&nodes, "]");
    test_put(&roots, "[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]");
    test_text t = gltf_text(nodes.data, roots.data, &quad, 1, "");
    rad_api_enter(ctx);
    assert_gltf_refused(&t, RAD_ERROR_PARSE,
                        "node 'n1_0' (10) is a child of both node 'n0_0' (0) and node 'n0_1' (1)",
                        "one parent at most");
    free(nodes.data);
    free(roots.data);
}

/* A zigzag triangle strip of `triangles` triangles of area 1/2 (vertex 2k
 * at (0, k), 2k + 1 at (1, k)), all facing +z. */
static float *zigzag(size_t triangles, size_t *vertices)
{
    *vertices = triangles + 2;
    float *p = calloc(3 * *vertices, sizeof *p);
    assert_non_null(p);
    for (size_t v = 0; v < *vertices; v++) {
        p[3 * v] = (float)(v % 2);
        p[3 * v + 1] = (float)(v / 2);
    }
    return p;
}

/* Instances times triangles against the memory limit: 100 nodes each
 * instancing one strip of 10,000 triangles would hold 10^6 triangles
 * (about 130 MB) and are refused under a 64 MiB limit before assimp reads
 * the file; 10 instances load, every triangle of every instance there.
 * And an external buffer larger than the limit allows. */
static void test_gltf_instances_memory(void **state)
{
    (void)state;
    rad_context_options co = {.threads = 1, .max_memory_bytes = 64.0 * 1048576.0};
    rad_context *limited = NULL;
    assert_int_equal(rad_context_create(&co, &limited), RAD_OK);
    size_t vertices;
    float *strip = zigzag(10000, &vertices);
    gltf_mesh mesh = {strip, vertices, NULL, 0, 5, 0};
    for (int instances = 10; instances <= 100; instances *= 10) {
        test_text nodes = {0}, roots = {0};
        test_put(&nodes, "[");
        test_put(&roots, "[");
        for (int i = 0; i < instances; i++) {
            test_put(&nodes, "%s{\"mesh\": 0, \"translation\": [%d, 0, 0]}", i ? ", " : "", 2 * i);
            test_put(&roots, "%s%d", i ? ", " : "", i);
        }
        test_put(&nodes, "]");
        test_put(&roots, "]");
        test_text t = gltf_text(nodes.data, roots.data, &mesh, 1, "");
        rad_scene *scene = NULL;
        rad_api_enter(limited);
        rad_result r = rad_scene_load_memory(limited, "x.gltf", t.data, t.length, NULL, 0, &scene);
        if (instances == 10) {
            if (r != RAD_OK)
                fail_msg("%s", rad_context_error(limited));
            assert_int_equal(rad_scene_polygon_count(scene), 100000);
            assert_int_equal(rad_scene_surface_count(scene), 10); /* one per node */
            for (size_t i = 0; i < 10; i++)
                assert_close(rad_scene_surface_area(scene, i), 5000.0, 1e-9);
            rad_scene_destroy(scene);
        } else {
            assert_int_equal(r, RAD_ERROR_OUT_OF_MEMORY);
            assert_null(scene);
            assert_contains(rad_context_error(limited), "x.gltf: importing it needs about");
            assert_contains(rad_context_error(limited), "100 instances holding 1e+06 triangles");
            assert_contains(rad_context_error(limited),
                            "above the memory limit of 64.0 MiB "
                            "(rad_context_options.max_memory_bytes)");
        }
        free(t.data);
        free(nodes.data);
        free(roots.data);
    }
    free(strip);

    /* An external buffer of 1 MiB under a 1 MiB limit: assimp would hold it
     * and copy out of it; refused before a byte of it is read. */
    char bin_path[512];
    snprintf(bin_path, sizeof bin_path, "%s/big.bin", temp_dir);
    FILE *bin = fopen(bin_path, "wb");
    assert_non_null(bin);
    assert_int_equal(fseek(bin, 1048575, SEEK_SET), 0);
    assert_int_equal(fputc(0, bin), 0);
    fclose(bin);
    rad_context *small = NULL;
    co.max_memory_bytes = 1048576.0;
    assert_int_equal(rad_context_create(&co, &small), RAD_OK);
    const char *path = write_temp(
        "big.gltf",
        "{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], \"nodes\": "
        "[{\"mesh\": 0}], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}], "
        "\"buffers\": [{\"byteLength\": 1048576, \"uri\": \"big.bin\"}], \"bufferViews\": "
        "[{\"buffer\": 0, \"byteLength\": 36}], \"accessors\": [{\"bufferView\": 0, "
        "\"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}]}");
    rad_scene *scene = NULL;
    rad_api_enter(small);
    assert_int_equal(rad_scene_load_file(small, path, &scene), RAD_ERROR_OUT_OF_MEMORY);
    assert_null(scene);
    assert_contains(rad_context_error(small), "big.gltf: its buffers need about 2.0 MiB to import");
    assert_contains(rad_context_error(small), "above the memory limit of 1.0 MiB");
    remove(bin_path);
    remove(path);
    rad_context_destroy(small);
    rad_context_destroy(limited);
}

/* ---- mirrored nodes: the floor's radiosity under a lamp ---- */

/* Radiosity of the floor ([-1, 1]^2 at z = 0, reflectance 0.5) lit by the
 * lamp of `lamp` (a black emitter of E = pi at z = 1 over [0.25, 0.75]^2
 * when placed right), and the lamp's polygon normals checked to face the
 * floor. */
static double floor_radiosity(const char *lamp_nodes, const float *lamp_positions,
                              const uint32_t *lamp_indices)
{
    gltf_mesh meshes[2] = {{unit_quad, 4, unit_quad_indices, 6, 4, 0},
                           {lamp_positions, 4, lamp_indices, 6, 4, 1}};
    test_text nodes = {0};
    test_put(&nodes, "[{\"name\": \"floor\", \"mesh\": 0, \"translation\": [-1, -1, 0], "
                "\"scale\": [2, 2, 1]}, %s]",
        lamp_nodes);
    test_text t = gltf_text(nodes.data, "[0, 1]", meshes, 2, "");
    rad_scene *scene = NULL;
    if (load_gltf(&t, &scene) != RAD_OK)
        fail_msg("%s", rad_context_error(ctx));
    size_t lamp = surface_index(scene, "lamp"), floor = surface_index(scene, "floor");
    assert_close(rad_scene_surface_area(scene, lamp), 0.25, 1e-12);
    for (size_t p = 0; p < scene->polygon_count; p++)
        if (scene->polygons[p].surface == lamp) {
            assert_close(scene->polygons[p].normal.z, -1.0, 1e-12);
            for (uint32_t k = 0; k < scene->polygons[p].vertex_count; k++) {
                vec3 v = scene->positions[scene->indices[scene->polygons[p].first_index + k]];
                assert_true(v.x >= 0.25 - 1e-12 && v.x <= 0.75 + 1e-12 && fabs(v.z - 1.0) < 1e-12);
            }
        }
    rad_options o = {0};
    o.mesh_size = 0.25;
    o.tolerance = 1e-12;
    rad_solution *solution = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &solution), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, solution), RAD_OK);
    double B[3];
    rad_solution_surface_radiosity(solution, floor, B);
    rad_solution_destroy(solution);
    rad_scene_destroy(scene);
    free(nodes.data);
    free(t.data);
    return B[0];
}

/* A node whose world transform mirrors (negative determinant) flips the
 * winding (glTF 2.0, "Instantiation"): a lamp modelled facing down and
 * mirrored lights the floor exactly as the same lamp placed there without
 * a mirror (it used to face away: the floor got 0).  Neighbours: a mirror
 * given as a matrix, a mirror in z, a mirror on the parent only, two
 * mirrors that cancel (parent and child) and a half turn (-1, -1, 1)
 * (determinant positive: no flip). */
static void test_gltf_mirrored(void **state)
{
    (void)state;
    /* The lamp where it belongs, facing down: the reference. */
    static const float lamp[] = {0.25f, 0.25f, 1,     0.25f, 0.75f, 1,
                                 0.75f, 0.75f, 1,     0.75f, 0.25f, 1};
    static const uint32_t order[] = {0, 1, 2, 0, 2, 3}, reversed[] = {0, 2, 1, 0, 3, 2};
    float mirror_x[12], mirror_z[12], half_turn[12];
    for (int v = 0; v < 4; v++) {
        for (int k = 0; k < 3; k++)
            mirror_x[3 * v + k] = mirror_z[3 * v + k] = half_turn[3 * v + k] = lamp[3 * v + k];
        mirror_x[3 * v] = -lamp[3 * v];
        mirror_z[3 * v + 2] = -lamp[3 * v + 2];
        half_turn[3 * v] = -lamp[3 * v];
        half_turn[3 * v + 1] = -lamp[3 * v + 1];
    }
    double reference = floor_radiosity("{\"name\": \"lamp\", \"mesh\": 1}", lamp, order);
    /* E F rho with F < 0.25 / (pi 1^2): well above 0, below its bound */
    assert_true(reference > 0.02 && reference < 0.5 * M_PI * 0.25 / M_PI);
    static const struct {
        const char *nodes;
        int positions; /* modelled: 0 in place, 1 mirrored in x, 2 in z, 3 turned */
    } cases[] = {
        {"{\"name\": \"lamp\", \"mesh\": 1, \"scale\": [-1, 1, 1]}", 1},
        {"{\"name\": \"lamp\", \"mesh\": 1, \"matrix\": [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, "
         "0, 0, 0, 1]}",
         1},
        {"{\"name\": \"lamp\", \"mesh\": 1, \"scale\": [1, 1, -1]}", 2},
        /* the mirror on the parent, the mesh on an unmirrored child */
        {"{\"scale\": [-1, 1, 1], \"children\": [2]}, {\"name\": \"lamp\", \"mesh\": 1, "
         "\"translation\": [0, 0, 0]}",
         1},
        /* two mirrors that cancel: no flip */
        {"{\"scale\": [-1, 1, 1], \"children\": [2]}, {\"name\": \"lamp\", \"mesh\": 1, "
         "\"scale\": [-1, 1, 1]}",
         0},
        /* a half turn about z: determinant +1, no flip */
        {"{\"name\": \"lamp\", \"mesh\": 1, \"scale\": [-1, -1, 1]}", 3},
    };
    const float *positions[4] = {lamp, mirror_x, mirror_z, half_turn};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        /* Modelled mirrored, a lamp that faces the floor once placed has
         * the reference's vertex order reversed (a mirror turns the
         * orientation of its vertex order; glTF's rule turns it back). */
        bool mirrored = cases[k].positions == 1 || cases[k].positions == 2;
        double B = floor_radiosity(cases[k].nodes, positions[cases[k].positions],
                                   mirrored ? reversed : order);
        if (!(fabs(B - reference) <= 1e-9 * reference))
            fail_msg("case %zu: floor radiosity %.17g, expected %.17g", k, B, reference);
    }
}

/* ---- primitives: indices, accessors, buffers, topologies ---- */

/* The unit quad file with `old` patched to `new_text` (NULL: as it is),
 * topology `mode`, indices `indices` (NULL: the quad's), positions
 * `positions` (NULL: the quad's). */
static test_text quad_patched(const float *positions, const uint32_t *indices, size_t index_count,
                         int mode, const char *old, const char *new_text)
{
    gltf_mesh mesh = {positions ? positions : unit_quad, 4,
                      indices ? indices : unit_quad_indices, indices ? index_count : 6, mode, 0};
    test_text t = gltf_text("[{\"mesh\": 0}]", "[0]", &mesh, 1, "");
    if (old)
        patch(&t, old, new_text);
    return t;
}

/* Every primitive assimp would misread, or drop part of without a word,
 * or crash on, is refused before assimp sees it, naming the file, mesh,
 * primitive and accessor (and, for an index out of range, the index and
 * the vertex count). */
static void test_gltf_bad_primitives(void **state)
{
    (void)state;
    static const uint32_t out_of_range[] = {0, 1, 2, 0, 2, 7}, strip_out[] = {0, 1, 9, 3},
                          four[] = {0, 1, 2, 3}, one[] = {0};
    static const float nan_quad[] = {0, 0, 0, 1, 0, 0, NAN, 1, 0, 0, 1, 0};
    static const float inf_quad[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, -INFINITY};
    const char *sparse_without_view =
        "\"type\": \"VEC3\", \"sparse\": {\"count\": 1, \"indices\": {\"componentType\": 5125}, "
        "\"values\": {\"bufferView\": 0}}}";
    const char *sparse_decreasing =
        "\"type\": \"VEC3\", \"sparse\": {\"count\": 4, \"indices\": {\"bufferView\": 1, "
        "\"componentType\": 5125}, \"values\": {\"bufferView\": 0}}}";
    const struct {
        test_text t;
        rad_result expected;
        const char *message[2];
    } cases[] = {
        /* assimp dropped the triangle silently */
        {quad_patched(NULL, out_of_range, 6, 4, NULL, NULL), RAD_ERROR_PARSE,
         {"x.gltf: mesh 'm0' (0) primitive 0: index 5 refers to vertex 7 of 4", NULL}},
        {quad_patched(NULL, strip_out, 4, 5, NULL, NULL), RAD_ERROR_PARSE,
         {"primitive 0: index 2 refers to vertex 9 of 4", NULL}},
        /* assimp read a float index accessor as integers */
        {quad_patched(NULL, NULL, 0, 4, "\"componentType\": 5125", "\"componentType\": 5126"),
         RAD_ERROR_PARSE, {"indices (accessor 1) must be SCALAR unsigned integers", "5126"}},
        {quad_patched(NULL, NULL, 0, 4, "\"componentType\": 5125", "\"componentType\": 5122"),
         RAD_ERROR_PARSE, {"unsigned integers", "not componentType 5122"}},
        {quad_patched(NULL, NULL, 0, 4, "\"count\": 6, \"type\": \"SCALAR\"",
                      "\"count\": 3, \"type\": \"VEC2\""),
         RAD_ERROR_PARSE, {"indices (accessor 1) must be SCALAR", NULL}},
        /* a view past its buffer, an accessor past its view, no vertices */
        {quad_patched(NULL, NULL, 0, 4, "\"byteLength\": 48", "\"byteLength\": 4800"),
         RAD_ERROR_PARSE, {"bufferView 0 (bytes 0 to 4800) lies outside buffer 0 of 72 bytes",
                           NULL}},
        {quad_patched(NULL, NULL, 0, 4, "\"count\": 6", "\"count\": 60"), RAD_ERROR_PARSE,
         {"accessor 1 needs bytes 0 to 240 of bufferView 1, which has 24", NULL}},
        {quad_patched(NULL, NULL, 0, 4, "\"count\": 4", "\"count\": 0"), RAD_ERROR_PARSE,
         {"primitive 0: accessor 0 has count 0", "at least 1"}},
        {quad_patched(NULL, NULL, 0, 4, "\"byteLength\": 72, \"uri\"",
                      "\"byteLength\": 720, \"uri\""),
         RAD_ERROR_PARSE, {"buffer 0: byteLength is 720, but its data has 72 bytes", NULL}},
        {quad_patched(NULL, NULL, 0, 4, "base64,", "base64,*"), RAD_ERROR_PARSE,
         {"base64", NULL}},
        {quad_patched(NULL, NULL, 0, 4, "\"uri\": \"data:application/octet-stream;base64,",
                      "\"uri\": \"quad.bin\", \"x\": \""),
         RAD_ERROR_IO, {"buffer 0: cannot open 'quad.bin'", NULL}},
        /* positions: finite float triples, as OBJ's */
        {quad_patched(nan_quad, NULL, 0, 4, NULL, NULL), RAD_ERROR_INVALID_SCENE,
         {"x.gltf: mesh 'm0' (0) primitive 0: vertex 2 (nan, 1, 0) is not finite", NULL}},
        {quad_patched(inf_quad, NULL, 0, 4, NULL, NULL), RAD_ERROR_INVALID_SCENE,
         {"vertex 3 (0, 1, -inf) is not finite", NULL}},
        {quad_patched(NULL, NULL, 0, 4, "\"componentType\": 5126", "\"componentType\": 5123"),
         RAD_ERROR_PARSE, {"POSITION (accessor 0) must be VEC3 of float", NULL}},
        {quad_patched(NULL, NULL, 0, 4, "{\"POSITION\": 0}", "{\"NORMAL\": 0}"), RAD_ERROR_PARSE,
         {"primitive 0 has no POSITION attribute", NULL}},
        /* counts for the topology; assimp allocated 2^32 faces for a
         * one-index strip */
        {quad_patched(NULL, four, 4, 4, NULL, NULL), RAD_ERROR_PARSE,
         {"triangles (mode 4) of 4 indices, not a multiple of 3", NULL}},
        {quad_patched(NULL, one, 1, 5, NULL, NULL), RAD_ERROR_PARSE,
         {"a triangle strip (mode 5) of 1 index (3 or more are needed)", NULL}},
        {quad_patched(NULL, one, 1, 6, NULL, NULL), RAD_ERROR_PARSE,
         {"a triangle fan (mode 6) of 1 index", NULL}},
        {quad_patched(NULL, one, 1, 1, NULL, NULL), RAD_ERROR_PARSE,
         {"lines (mode 1) of 1 index (2 or more are needed)", NULL}},
        {quad_patched(NULL, NULL, 0, 4, "\"mode\": 4", "\"mode\": 9"), RAD_ERROR_PARSE,
         {"mode must be 0 to 6", NULL}},
        /* sparse accessors: assimp 5.2 dereferenced the missing view */
        {quad_patched(NULL, NULL, 0, 4, "\"type\": \"VEC3\"}", sparse_without_view),
         RAD_ERROR_PARSE, {"accessor 0: sparse indices and values each need a bufferView", NULL}},
        {quad_patched(NULL, NULL, 0, 4, "\"type\": \"VEC3\"}", sparse_decreasing),
         RAD_ERROR_PARSE, {"accessor 0: sparse index 3 is 0", "must increase"}},
        {quad_patched(NULL, NULL, 0, 4, "\"version\": \"2.0\"", "\"version\": \"1.0\""),
         RAD_ERROR_PARSE, {"glTF version '1.0' is not read (2.0 is)", NULL}},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        test_text t = cases[k].t;
        rad_api_enter(ctx);
        assert_gltf_refused(&t, cases[k].expected, cases[k].message[0], cases[k].message[1]);
    }
}

/* Area and orientation of every polygon of surface 0: all face +z. */
static void check_faces_up(const rad_scene *scene, size_t polygons, double area)
{
    assert_int_equal(rad_scene_polygon_count(scene), polygons);
    for (size_t p = 0; p < scene->polygon_count; p++)
        assert_close(scene->polygons[p].normal.z, 1.0, 1e-12);
    assert_close(rad_scene_surface_area(scene, 0), area, 1e-12);
}

/* Triangle strips and fans (glTF 2.0, "Meshes": strip triangle i is
 * (i, i + 1 + i % 2, i + 2 - i % 2), fan triangle i is (i + 1, i + 2, 0))
 * keep their winding; a triangle whose indices repeat (the stitches that
 * join strips, a repeated fan vertex) has no area and is dropped (it used
 * to fail the whole file).  Points and lines carry no area: ignored. */
static void test_gltf_strips_and_fans(void **state)
{
    (void)state;
    /* Two strips of 2 triangles, x in [0, 1] and [3, 4], joined by the
     * stitches 3 3 4 4 (4 triangles of no area). */
    static const float two_strips[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0,
                                       3, 0, 0, 4, 0, 0, 3, 1, 0, 4, 1, 0};
    static const uint32_t stitched[] = {0, 1, 2, 3, 3, 4, 4, 5, 6, 7};
    gltf_mesh strips = {two_strips, 8, stitched, 10, 5, 0};
    test_text t = gltf_text("[{\"mesh\": 0}]", "[0]", &strips, 1, "");
    rad_scene *scene = NULL;
    assert_int_equal(load_gltf(&t, &scene), RAD_OK);
    check_faces_up(scene, 4, 2.0);
    rad_scene_destroy(scene);
    free(t.data);

    /* A strip without indices: consecutive vertices, nothing repeated. */
    size_t vertices;
    float *zigzag_positions = zigzag(4, &vertices);
    gltf_mesh plain = {zigzag_positions, vertices, NULL, 0, 5, 0};
    t = gltf_text("[{\"mesh\": 0}]", "[0]", &plain, 1, "");
    assert_int_equal(load_gltf(&t, &scene), RAD_OK);
    check_faces_up(scene, 4, 2.0);
    rad_scene_destroy(scene);
    free(t.data);
    free(zigzag_positions);

    /* A fan around (0, 0) over (1, 0), (1, 1), (0, 1), (-1, 1), with its
     * second vertex repeated: 3 triangles of 1/2. */
    static const float fan[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, -1, 1, 0};
    static const uint32_t fan_indices[] = {0, 1, 2, 2, 3, 4};
    gltf_mesh fans = {fan, 5, fan_indices, 6, 6, 0};
    t = gltf_text("[{\"mesh\": 0}]", "[0]", &fans, 1, "");
    assert_int_equal(load_gltf(&t, &scene), RAD_OK);
    check_faces_up(scene, 3, 1.5);
    rad_scene_destroy(scene);
    free(t.data);

    /* A triangle list with one triangle of a repeated index among two. */
    static const uint32_t listed[] = {0, 1, 2, 0, 0, 2, 0, 2, 3};
    gltf_mesh list = {unit_quad, 4, listed, 9, 4, 0};
    t = gltf_text("[{\"mesh\": 0}]", "[0]", &list, 1, "");
    assert_int_equal(load_gltf(&t, &scene), RAD_OK);
    check_faces_up(scene, 2, 1.0);
    rad_scene_destroy(scene);
    free(t.data);

    /* Points, lines, a line loop and a line strip beside one triangle:
     * only the triangle has area. */
    gltf_mesh mixed[5] = {{unit_quad, 4, unit_quad_indices, 3, 4, 0},
                          {unit_quad, 4, unit_quad_indices, 1, 0, 0},
                          {unit_quad, 4, unit_quad_indices, 6, 1, 0},
                          {unit_quad, 4, unit_quad_indices, 4, 2, 0},
                          {unit_quad, 4, NULL, 0, 3, 0}};
    t = gltf_text("[{\"name\": \"t\", \"mesh\": 0}, {\"mesh\": 1}, {\"mesh\": 2}, {\"mesh\": 3}, "
                  "{\"mesh\": 4}]",
                  "[0, 1, 2, 3, 4]", mixed, 5, "");
    assert_int_equal(load_gltf(&t, &scene), RAD_OK);
    assert_int_equal(rad_scene_surface_count(scene), 1);
    assert_string_equal(rad_scene_surface_name(scene, 0), "t");
    check_faces_up(scene, 1, 0.5);
    rad_scene_destroy(scene);
    free(t.data);

    /* Lines alone: nothing has area. */
    t = gltf_text("[{\"mesh\": 0}]", "[0]", &mixed[2], 1, "");
    rad_api_enter(ctx);
    assert_gltf_refused(&t, RAD_ERROR_INVALID_SCENE, "scene is empty (no polygons)", NULL);
}

/* ---- cameras ---- */

typedef struct warnings {
    int count;
    char last[1024];
} warnings;

static void note_warning(void *user, const char *message)
{
    warnings *w = user;
    w->count++;
    snprintf(w->last, sizeof w->last, "%s", message);
}

/* An orthographic camera (which the renderer does not draw) no longer
 * fails the file: the scene's first perspective camera is used, or none
 * (the view is framed automatically), with one warning naming the file
 * and the camera.  The first camera node in depth-first order is the
 * scene's camera. */
static void test_gltf_orthographic_camera(void **state)
{
    (void)state;
    warnings seen = {0};
    rad_context_options co = {.threads = 1, .on_warning = note_warning, .warning_user = &seen};
    rad_context *warned = NULL;
    assert_int_equal(rad_context_create(&co, &warned), RAD_OK);
    const char *cameras = ", \"cameras\": [{\"name\": \"top\", \"type\": \"orthographic\", "
                          "\"orthographic\": {\"xmag\": 2, \"ymag\": 1.5, \"znear\": 0.1, "
                          "\"zfar\": 100}},\n {\"name\": \"eye\", \"type\": \"perspective\", "
                          "\"perspective\": {\"yfov\": 0.8, \"znear\": 0.1}}]";
    gltf_mesh quad = {unit_quad, 4, unit_quad_indices, 6, 4, 0};
    static const struct {
        const char *nodes, *roots;
        bool has_camera;
        double z, vfov;  /* the camera's position z and field of view, degrees */
        const char *warning[2];
    } cases[] = {
        {"[{\"mesh\": 0}, {\"name\": \"above\", \"camera\": 0, \"translation\": [0, 0, 5]}]",
         "[0, 1]", false, 0, 0,
         {"x.gltf: camera 'top' (0) of node 'above' (1) is orthographic",
          "the view is framed automatically"}},
        {"[{\"mesh\": 0, \"children\": [2]}, {\"name\": \"side\", \"camera\": 1, "
         "\"translation\": [0, 0, 7]}, {\"name\": \"above\", \"camera\": 0}]",
         "[0, 1]", true, 7, 0.8 * 180 / M_PI,
         {"camera 'top' (0) of node 'above' (2) is orthographic",
          "using the perspective camera of node 'side' (1)"}},
        {"[{\"mesh\": 0, \"children\": [2]}, {\"name\": \"above\", \"camera\": 0}, "
         "{\"name\": \"near\", \"camera\": 1, \"translation\": [0, 0, 3]}]",
         "[0, 1]", true, 3, 0.8 * 180 / M_PI, {NULL, NULL}},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        seen.count = 0;
        test_text t = gltf_text(cases[k].nodes, cases[k].roots, &quad, 1, cameras);
        rad_scene *scene = NULL;
        rad_api_enter(warned);
        if (rad_scene_load_memory(warned, "x.gltf", t.data, t.length, NULL, 0, &scene) != RAD_OK)
            fail_msg("case %zu: %s", k, rad_context_error(warned));
        rad_camera camera;
        assert_int_equal(rad_scene_camera(scene, &camera), cases[k].has_camera);
        if (cases[k].has_camera) {
            assert_close(camera.position[2], cases[k].z, 1e-12);
            assert_close(camera.look_at[2], cases[k].z - 1.0, 1e-12);
            assert_close(camera.vfov_degrees, cases[k].vfov, 1e-9);
        }
        assert_int_equal(seen.count, cases[k].warning[0] ? 1 : 0);
        for (int i = 0; i < 2 && cases[k].warning[i]; i++)
            assert_contains(seen.last, cases[k].warning[i]);
        assert_null(strchr(seen.last, '\n'));
        rad_scene_destroy(scene);
        free(t.data);
    }
    rad_context_destroy(warned);
}

/* ---- what the materials say that the engine does not use ---- */

/* Every warning of one load, in order. */
typedef struct warning_lines {
    size_t count;
    char lines[16][1024];
} warning_lines;

static void note_warning_line(void *user, const char *message)
{
    warning_lines *w = user;
    if (w->count < sizeof w->lines / sizeof w->lines[0])
        snprintf(w->lines[w->count], sizeof w->lines[0], "%s", message);
    w->count++;
}

/* Load `obj` + `mtl` (or the glTF `obj` when `mtl` is NULL) from memory in a
 * context that collects warnings into `seen`; returns the result. */
static rad_result load_noting(const char *name, const char *obj, const char *mtl,
                              warning_lines *seen)
{
    memset(seen, 0, sizeof *seen);
    rad_context_options co = {.threads = 1, .on_warning = note_warning_line, .warning_user = seen};
    rad_context *noting = NULL;
    assert_int_equal(rad_context_create(&co, &noting), RAD_OK);
    rad_scene *scene = NULL;
    rad_result r = rad_scene_load_memory(noting, name, obj, strlen(obj), mtl,
                                         mtl ? strlen(mtl) : 0, &scene);
    if (r != RAD_OK)
        print_message("%s\n", rad_context_error(noting));
    rad_scene_destroy(scene);
    rad_context_destroy(noting);
    return r;
}

/* An MTL's specular, glossy and textured materials are said once, one line
 * each, naming the surfaces that use them; a plain material with values
 * that say nothing (Ks 0 0 0, d 1, Tr 0, Ni without transparency, illum 2
 * without a highlight) is not; a material no surface uses is not. */
static void test_mtl_unused_properties(void **state)
{
    (void)state;
    const char *obj = "mtllib room.mtl\n"
                      "o mirror_panel\nusemtl mirror\n"
                      "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 4 3 2\n"
                      "o frame\nusemtl mirror\nv 0 1 0\nv 1 1 0\nv 1 1 1\nf 5 6 7\n"
                      "o desk\nusemtl wood\nv 0 0 0\nv 0 1 0\nv 0 1 1\nf 8 9 10\n"
                      "o lamp\nusemtl light\nv 0 0.5 0\nv 0 0.5 1\nv 1 0.5 1\nf 11 12 13\n"
                      "o mirror_panel\nusemtl mirror\nv 2 0 0\nv 3 0 0\nv 3 0 1\nf 14 15 16\n";
    const char *mtl = "newmtl mirror\nKd 0.1 0.1 0.1\nKs 0.9 0.9 0.9\nNs 200\nillum 3\n"
                      "newmtl wood\nKd 0.5 0.4 0.3\nmap_Kd -bm 1 wood.png\n"
                      "newmtl light\nKa 1 1 1\nKd 0.5 0.5 0.5\nKe 10 10 10\nKs 0 0 0\nNs 10\n"
                      "d 1\nTr 0\nNi 1.45\nTf 1 1 1\nillum 2\n"
                      "newmtl unused\nKd 0.5 0.5 0.5\nKs 1 1 1\nmap_Bump b.png\n";
    warning_lines seen;
    assert_int_equal(load_noting("room.obj", obj, mtl, &seen), RAD_OK);
    /* The mirror's Ks, Ns and illum 3 are read now (a glossy reflector:
     * test_twopass.c), so not said. */
    assert_int_equal(seen.count, 1);
    assert_string_equal(seen.lines[0],
                        "room.mtl: material 'wood' (surface 'desk'): map_Kd 'wood.png' is not "
                        "used: its reflectance is Kd (0.5 0.4 0.3)");

    /* Glass, a metal and the texture statements (8 named, then counted),
     * beside Ke from a map.  Not `decal`: assimp 5.2 reads it as `d`
     * followed by "ecal", and fails. */
    const char *one = "mtllib one.mtl\no a\nusemtl m\nv 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n";
    const char *glass = "newmtl m\nKd 0.1 0.1 0.1\nd 0.4\nNi 1.5\nTf 0.9 1 0.9\nillum 7\n"
                        "Pm 1\nPr 0.2\nPc 0 \nPcr 0.1\nmap_Ke glow.png\nbump n.png\nmap_Ks s.png\n"
                        "map_d a.png\nnorm n2.png\ndisp h.png\nrefl -type sphere e.png\n"
                        "map_Bump nb.png\nmap_Ns ns.png\n";
    assert_int_equal(load_noting("one.obj", one, glass, &seen), RAD_OK);
    assert_int_equal(seen.count, 1);
    assert_string_equal(seen.lines[0],
                        "one.mtl: material 'm' (surface 'a'): Tf, Pr, Pm, "
                        "map_Ke 'glow.png', bump 'n.png', map_Ks 's.png', map_d 'a.png', "
                        "norm 'n2.png', disp 'h.png', refl 'e.png', map_Bump 'nb.png' and 1 more are "
                        "not used: its emission is 0 (no Ke)");

    /* Nothing to say: no warning. */
    assert_int_equal(load_noting("one.obj", one, "newmtl m\nKd 0.5 0.5 0.5\nKs 0 0 0\nillum 1\n",
                                 &seen),
                     RAD_OK);
    assert_int_equal(seen.count, 0);

    /* A load that fails after the library's notes says nothing. */
    const char *broken = "mtllib one.mtl\no a\nusemtl m\nv 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n"
                         "usemtl other\n";
    assert_int_equal(load_noting("one.obj", broken, "newmtl m\nKd 0.5 0.5 0.5\nKs 1 1 1\n", &seen),
                     RAD_ERROR_PARSE);
    assert_int_equal(seen.count, 0);
}

/* 15 materials with something unused: 10 lines, then one counting the 5
 * others. */
static void test_mtl_unused_cap(void **state)
{
    (void)state;
    char obj[8192] = "mtllib many.mtl\n", mtl[8192] = "";
    size_t o = strlen(obj), m = 0;
    for (int i = 0; i < 15; i++) {
        o += (size_t)snprintf(obj + o, sizeof obj - o,
                              "o s%d\nusemtl m%d\nv %d 0 0\nv %d 1 0\nv %d 1 1\nf -3 -2 -1\n", i,
                              i, i, i, i);
        m += (size_t)snprintf(mtl + m, sizeof mtl - m, "newmtl m%d\nKd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\n",
                              i);
    }
    warning_lines seen;
    assert_int_equal(load_noting("many.obj", obj, mtl, &seen), RAD_OK);
    assert_int_equal(seen.count, 11);
    for (int i = 0; i < 10; i++) {
        char expected[256];
        snprintf(expected, sizeof expected,
                 "many.mtl: material 'm%d' (surface 's%d'): Ks is not used (the engine reads "
                 "Kd and Ke, and the specular keys with illum 3 to 7)", i, i);
        assert_string_equal(seen.lines[i], expected);
    }
    assert_string_equal(seen.lines[10],
                        "many.obj: ... and 5 more materials with unused properties");

    /* Names past 3 surfaces are counted. */
    char five[1024] = "mtllib five.mtl\nusemtl m\n";
    size_t f = strlen(five);
    for (int i = 0; i < 5; i++)
        f += (size_t)snprintf(five + f, sizeof five - f,
                              "o s%d\nv %d 0 0\nv %d 1 0\nv %d 1 1\nf -3 -2 -1\n", i, i, i, i);
    assert_int_equal(load_noting("five.obj", five, "newmtl m\nKd 0.5 0.5 0.5\nillum 8\n", &seen),
                     RAD_OK);
    assert_int_equal(seen.count, 1);
    assert_string_equal(seen.lines[0],
                        "five.mtl: material 'm' (surfaces 's0', 's1', 's2' and 2 more): illum 8 "
                        "is not used (the engine reads Kd and Ke, and the specular keys with illum 3 to 7)");
}

/* A glTF's texture, metal and transmission are said; an extension of
 * extensionsUsed that nothing reads, once for the file; a plain material
 * (metallicFactor 0) and the emissive strength, which is read, are not. */
static void test_gltf_unused_properties(void **state)
{
    (void)state;
    const char *gltf =
        "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0,\n"
        " \"extensionsUsed\": [\"KHR_materials_transmission\", \"KHR_lights_punctual\", "
        "\"KHR_materials_emissive_strength\"],\n"
        " \"scenes\": [{\"nodes\": [0, 1, 2, 3, 4]}],\n"
        " \"nodes\": [{\"name\": \"desk\", \"mesh\": 0}, {\"name\": \"shelf\", \"mesh\": 0, "
        "\"translation\": [0, 0, 2]},\n"
        "   {\"name\": \"window\", \"mesh\": 1, \"translation\": [0, 0, 4]}, {\"name\": \"floor\", "
        "\"mesh\": 2, \"translation\": [0, 0, 6]},\n"
        "   {\"name\": \"lamp\", \"mesh\": 3, \"translation\": [0, 1, 0]}],\n"
        " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, "
        "\"material\": 0}]},\n"
        "   {\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, \"material\": 1}]},\n"
        "   {\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, \"material\": 2}]},\n"
        "   {\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, \"material\": 3}]}],\n"
        " \"materials\": [{\"name\": \"wood\", \"pbrMetallicRoughness\": {\"baseColorFactor\": "
        "[0.5, 0.4, 0.3, 1], \"baseColorTexture\": {\"index\": 0}, \"metallicFactor\": 1}},\n"
        "   {\"name\": \"glass\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.2, 0.2, 0.2, "
        "1], \"metallicFactor\": 0}, \"extensions\": {\"KHR_materials_transmission\": "
        "{\"transmissionFactor\": 1}}},\n"
        "   {\"name\": \"plain\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, "
        "1], \"metallicFactor\": 0}, \"alphaMode\": \"BLEND\"},\n"
        "   {\"name\": \"lamp\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0, 0, 0, 1], "
        "\"metallicFactor\": 0}, \"emissiveFactor\": [1, 1, 1], \"extensions\": "
        "{\"KHR_materials_emissive_strength\": {\"emissiveStrength\": 2}}}],\n"
        " \"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"wood.png\"}],\n"
        " \"buffers\": [{\"byteLength\": 60, \"uri\": \"data:application/octet-stream;base64,"
        "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAgD8AAAAAAAAAAAAAgD8AAAAAAAABAAIAAAACAAMA\"}],\n"
        " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": "
        "48, \"byteLength\": 12}],\n"
        " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": "
        "\"VEC3\"},\n"
        "   {\"bufferView\": 1, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}\n";
    warning_lines seen;
    assert_int_equal(load_noting("x.gltf", gltf, NULL, &seen), RAD_OK);
    /* The glass's transmission is read now (test_twopass.c): not said. */
    assert_int_equal(seen.count, 2);
    assert_string_equal(seen.lines[0], "x.gltf: extension KHR_lights_punctual is not used");
    assert_string_equal(seen.lines[1],
                        "x.gltf: material 'wood' (surfaces 'desk', 'shelf'): baseColorTexture "
                        "'wood.png' and metallicFactor 1 are not used: its reflectance is "
                        "baseColorFactor (0.5 0.4 0.3)");
}

/* ---- the reader is chosen by content ---- */

/* Write `size` bytes to temp_dir/name; returns the path (static). */
static const char *write_temp_bytes(const char *name, const void *bytes, size_t size)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", temp_dir, name);
    FILE *file = fopen(path, "wb");
    assert_non_null(file);
    assert_int_equal(fwrite(bytes, 1, size, file), size);
    assert_int_equal(fclose(file), 0);
    return path;
}

static void put_le32(unsigned char *p, size_t value)
{
    for (int k = 0; k < 4; k++)
        p[k] = (unsigned char)(value >> (8 * k));
}

/* quad_gltf as a binary glTF: the 12-byte header, the JSON chunk (its
 * buffer's data URI dropped: the BIN chunk is buffer 0) padded with spaces
 * and the BIN chunk with the same 60 bytes (Khronos, glTF 2.0, "Binary
 * glTF Layout").  The caller frees it. */
static unsigned char *quad_glb(size_t *size)
{
    char json[sizeof quad_gltf];
    const char *uri = strstr(quad_gltf, ", \"uri\"");
    assert_non_null(uri);
    const char *after = strchr(strchr(uri + 9, '"') + 1, '"') + 1; /* past the URI's quotes */
    snprintf(json, sizeof json, "%.*s%s", (int)(uri - quad_gltf), quad_gltf, after);
    const float corners[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
    size_t n = strlen(json), padded = (n + 3) & ~(size_t)3, bin = 64;
    *size = 20 + padded + 8 + bin;
    unsigned char *glb = calloc(1, *size);
    assert_non_null(glb);
    memcpy(glb, "glTF", 4);
    put_le32(glb + 4, 2);
    put_le32(glb + 8, *size);
    put_le32(glb + 12, padded);
    memcpy(glb + 16, "JSON", 4);
    memcpy(glb + 20, json, n);
    memset(glb + 20 + n, ' ', padded - n);
    unsigned char *chunk = glb + 20 + padded;
    put_le32(chunk, bin);
    memcpy(chunk + 4, "BIN", 4); /* and a 0 byte */
    memcpy(chunk + 8, corners, sizeof corners); /* little-endian, as the machines this runs on */
    memcpy(chunk + 8 + sizeof corners, indices, sizeof indices);
    return glb;
}

/* The format is the content's, whatever the name says: an OBJ named
 * `scene`, `s.gltf` or `s.txt` used to reach assimp without the pre-scan,
 * which read its NaN; a glTF or GLB named `.obj` is read as what it is. */
static void test_format_by_content(void **state)
{
    (void)state;
    assert_int_equal(import_format_of("glTF\2\0\0\0", 8), IMPORT_GLB);
    assert_int_equal(import_format_of("glT", 3), IMPORT_OBJ);
    assert_int_equal(import_format_of("\xEF\xBB\xBF \r\n\t{\"asset\"", 15), IMPORT_GLTF);
    assert_int_equal(import_format_of(" \n v 0 0 0", 11), IMPORT_OBJ);
    assert_int_equal(import_format_of("", 0), IMPORT_OBJ);
    assert_int_equal(import_format_of("\0{", 2), IMPORT_OBJ);

    static const char nan_obj[] = "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n";
    static const char *const names[] = {"scene", "s.gltf", "s.txt", "s.OBJ", "s.glb", "s.obj.bak"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        rad_scene sentinel, *scene = &sentinel;
        const char *path = write_temp(names[i], nan_obj);
        char expected[600];
        snprintf(expected, sizeof expected, "%s:2: vertex coordinate 'nan' is not a finite number",
                 path);
        assert_int_equal(rad_scene_load_file(ctx, path, &scene), RAD_ERROR_INVALID_SCENE);
        assert_null(scene);
        assert_string_equal(rad_context_error(ctx), expected);
        scene = &sentinel;
        assert_int_equal(rad_scene_load_memory(ctx, names[i], nan_obj, strlen(nan_obj), NULL, 0,
                                               &scene),
                         RAD_ERROR_INVALID_SCENE);
        assert_null(scene);
        snprintf(expected, sizeof expected, "%s:2: vertex coordinate 'nan' is not a finite number",
                 names[i]);
        assert_string_equal(rad_context_error(ctx), expected);
        remove_temp(names[i]);
    }

    /* A good OBJ without an extension, with its library. */
    write_temp("lamp.mtl", lamp_mtl);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_file(ctx, write_temp("room", lamp_obj), &scene), RAD_OK);
    check_lamp(scene);

    /* glTF JSON and binary glTF under OBJ, other and no names. */
    size_t glb_size;
    unsigned char *glb = quad_glb(&glb_size);
    static const char *const gltf_names[] = {"quad.obj", "quad"};
    static const char *const glb_names[] = {"quadb.obj", "quadb.gltf", "quadb"};
    for (size_t i = 0; i < 2; i++) {
        scene = NULL;
        assert_int_equal(rad_scene_load_file(ctx, write_temp(gltf_names[i], quad_gltf), &scene),
                         RAD_OK);
        check_quad_gltf(scene);
        rad_scene_destroy(scene);
        remove_temp(gltf_names[i]);
    }
    for (size_t i = 0; i < 3; i++) {
        scene = NULL;
        const char *path = write_temp_bytes(glb_names[i], glb, glb_size);
        rad_result r = rad_scene_load_file(ctx, path, &scene);
        if (r != RAD_OK)
            print_error("%s\n", rad_context_error(ctx));
        assert_int_equal(r, RAD_OK);
        check_quad_gltf(scene);
        rad_scene_destroy(scene);
        remove_temp(glb_names[i]);
        scene = NULL;
        assert_int_equal(rad_scene_load_memory(ctx, glb_names[i], glb, glb_size, NULL, 0, &scene),
                         RAD_OK);
        check_quad_gltf(scene);
        rad_scene_destroy(scene);
    }
    scene = NULL;
    assert_int_equal(
        rad_scene_load_memory(ctx, "x.obj", quad_gltf, strlen(quad_gltf), NULL, 0, &scene),
        RAD_OK);
    check_quad_gltf(scene);
    rad_scene_destroy(scene);
    free(glb);
    remove_temp("room");
    remove_temp("lamp.mtl");
}

/* ---- several material libraries ---- */

static const char grey_mtl[] = "newmtl grey\nKd 0.5 0.25 0.125\n";
static const char glow_mtl[] = "newmtl glow\nKd 0.1 0.1 0.1\nKe 2 1 0.5\n";
static const char lamp_body[] = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\n"
                                "v 0 0 1\nv 1 0 1\nv 0 1 1\n"
                                "o panel\nusemtl grey\nf 1 2 3 4\n"
                                "o lamp\nusemtl glow\nf -3 -2 -1\n";

/* Load temp_dir/libs.obj made of `head` and lamp_body. */
static rad_result load_libs(const char *head, rad_scene **scene)
{
    char obj[1024];
    snprintf(obj, sizeof obj, "%s%s", head, lamp_body);
    *scene = NULL;
    return rad_scene_load_file(ctx, write_temp("libs.obj", obj), scene);
}

/* `mtllib a.mtl b.mtl` names two libraries, as several `mtllib` lines do:
 * every one is read and pre-scanned, and the materials of all of them are
 * there (before: assimp looked for one file "grey.mtl glow.mtl", found
 * none, and gave every polygon its default grey).  A library named twice
 * is read once; a line whose whole text names a file is that file. */
static void test_material_libraries(void **state)
{
    (void)state;
    write_temp("grey.mtl", grey_mtl);
    write_temp("glow.mtl", glow_mtl);
    char both[256];
    snprintf(both, sizeof both, "%s%s", grey_mtl, glow_mtl);
    write_temp("my lamp.mtl", both);
    char bom[256];
    snprintf(bom, sizeof bom, "\xEF\xBB\xBF%s", glow_mtl);
    write_temp("bom.mtl", bom);
    write_temp("materials.txt", both);
    static const struct {
        const char *head;
        size_t inputs; /* the OBJ and its libraries, each once */
    } good[] = {
        {"mtllib grey.mtl glow.mtl\n", 3},
        {"mtllib grey.mtl\nmtllib glow.mtl\n", 3},
        {"mtllib grey.mtl\tglow.mtl grey.mtl ./grey.mtl\nmtllib glow.mtl\n", 3},
        {"mtllib my lamp.mtl\n", 2},
        {"# libraries\nmtllib    grey.mtl   \n# and\nmtllib glow.mtl\n", 3},
        {"\xEF\xBB\xBFmtllib grey.mtl bom.mtl\n", 3}, /* byte order marks, each skipped */
        {"mtllib materials.txt\n", 2}, /* a library of any name is pre-scanned as MTL */
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        rad_scene *scene;
        rad_result r = load_libs(good[i].head, &scene);
        if (r != RAD_OK)
            print_error("'%s': %s\n", good[i].head, rad_context_error(ctx));
        assert_int_equal(r, RAD_OK);
        assert_int_equal(rad_scene_input_count(scene), good[i].inputs);
        assert_contains(rad_scene_input_path(scene, 1), i == 3   ? "my lamp.mtl"
                                                        : i == 6 ? "materials.txt"
                                                                 : "grey.mtl");
        check_lamp(scene);
    }

    /* From memory the one buffer holds every library's materials. */
    rad_scene *scene = NULL;
    char obj[1024];
    snprintf(obj, sizeof obj, "mtllib grey.mtl\nmtllib glow.mtl\n%s", lamp_body);
    assert_int_equal(rad_scene_load_memory(ctx, "libs.obj", obj, strlen(obj), both, strlen(both),
                                           &scene),
                     RAD_OK);
    check_lamp(scene);

    /* A library named after the faces that use it, its materials in another
     * order than their use: each face keeps its own material, from a file
     * and from memory (assimp made the unknown names materials first and
     * numbered the library's after them: the lamp got the panel's grey). */
    char glow_first[256];
    snprintf(glow_first, sizeof glow_first, "newmtl unused\nKd 0.7 0.7 0.7\n%snewmtl spare\nKd 0.2 0.2 0.2\n%s",
             glow_mtl, grey_mtl);
    write_temp("late.mtl", glow_first);
    static const char *const tails[] = {"mtllib late.mtl\n", "mtllib late.mtl", "mtllib late.mtl\r\n"};
    for (size_t i = 0; i < sizeof tails / sizeof tails[0]; i++) {
        snprintf(obj, sizeof obj, "%s%s", lamp_body, tails[i]);
        scene = NULL;
        rad_result r = rad_scene_load_file(ctx, write_temp("libs.obj", obj), &scene);
        if (r != RAD_OK)
            print_error("'%s': %s\n", tails[i], rad_context_error(ctx));
        assert_int_equal(r, RAD_OK);
        check_lamp(scene);
        scene = NULL;
        assert_int_equal(rad_scene_load_memory(ctx, "libs.obj", obj, strlen(obj), glow_first,
                                               strlen(glow_first), &scene),
                         RAD_OK);
        check_lamp(scene);
    }
    remove_temp("late.mtl");

    /* A missing library is the same error whichever it is. */
    write_temp("bad.mtl", "newmtl glow\nKd 1.5 0 0\n");
    write_temp("grey2.mtl", "newmtl glow\nKd 0.1 0.1 0.1\nKe 1 1 1\nnewmtl grey\nKd 0.3 0.3 0.3\n");
    char outside[600];
    snprintf(outside, sizeof outside, "%s/outside.mtl", temp_dir);
    remove(outside);
    assert_int_equal(symlink("/etc/passwd", outside), 0);
    static const struct {
        const char *head;
        rad_result expected;
        const char *message[2];
    } bad[] = {
        {"mtllib grey.mtl nowhere.mtl\n", RAD_ERROR_IO,
         {"libs.obj:1: material library 'nowhere.mtl': cannot open: No such file or directory",
          NULL}},
        {"mtllib nowhere.mtl grey.mtl\n", RAD_ERROR_IO,
         {"libs.obj:1: material library 'nowhere.mtl': cannot open: No such file or directory",
          NULL}},
        {"mtllib grey.mtl\n\nmtllib nowhere.mtl\n", RAD_ERROR_IO,
         {"libs.obj:3: material library 'nowhere.mtl': cannot open: No such file or directory",
          NULL}},
        {"mtllib grey.mtl bad.mtl\n", RAD_ERROR_INVALID_SCENE,
         {"bad.mtl:2: material 'glow': reflectance (Kd) 1.5 is outside [0, 1)", NULL}},
        {"mtllib grey.mtl grey2.mtl\n", RAD_ERROR_PARSE,
         {"grey2.mtl:4: material 'grey' is defined again (first at ", "grey.mtl:1)"}},
        {"mtllib grey.mtl\n", RAD_ERROR_PARSE,
         {"libs.obj:13: usemtl 'glow': no material of that name in ", "grey.mtl"}},
        {"mtllib grey.mtl outside.mtl\n", RAD_ERROR_IO,
         {"outside the scene's folder", "/etc/passwd"}},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        rad_result r = load_libs(bad[i].head, &scene);
        if (r != bad[i].expected)
            print_error("'%s': %s\n", bad[i].head, rad_context_error(ctx));
        assert_int_equal(r, bad[i].expected);
        assert_null(scene);
        assert_null(strchr(rad_context_error(ctx), '\n'));
        for (int k = 0; k < 2 && bad[i].message[k]; k++)
            assert_contains(rad_context_error(ctx), bad[i].message[k]);
    }
    static const char *const files[] = {"libs.obj", "grey.mtl",  "glow.mtl",   "my lamp.mtl",
                                        "bom.mtl",  "bad.mtl",   "grey2.mtl", "outside.mtl",
                                        "materials.txt"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++)
        remove_temp(files[i]);
}

/* ---- the builder ---- */

static void test_builder_surfaces_and_materials(void **state)
{
    (void)state;
    const double grey[3] = {0.5, 0.5, 0.5}, black[3] = {0.0, 0.0, 0.0};
    const vec3 square[] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 0}};
    rad_scene_builder *b = rad_scene_builder_create(ctx, "built");
    int unused_material = rad_scene_builder_material(b, "unused", grey, black);
    int material = rad_scene_builder_material(b, "grey", grey, black);
    assert_int_equal(unused_material, 0);
    assert_int_equal(material, 1);
    int a = rad_scene_builder_surface(b, "a");
    int empty = rad_scene_builder_surface(b, "empty");
    int c = rad_scene_builder_surface(b, "c");
    assert_int_equal(rad_scene_builder_surface(b, "a"), a); /* same name, same surface */
    assert_int_equal(empty, 1);
    /* The repeated vertex and the closing copy of the first are dropped. */
    assert_int_equal(rad_scene_builder_polygon(b, a, material, square, 6, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_polygon(b, c, material, square, 3, 0), RAD_OK);
    assert_int_equal(rad_scene_builder_polygon(b, a, material, square, 3, 0), RAD_OK);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    assert_int_equal(rad_scene_surface_count(scene), 2); /* "empty" is dropped */
    assert_string_equal(rad_scene_surface_name(scene, 0), "a");
    assert_string_equal(rad_scene_surface_name(scene, 1), "c");
    assert_close(rad_scene_surface_area(scene, 0), 1.5, 1e-15);
    assert_close(rad_scene_surface_area(scene, 1), 0.5, 1e-15);
    assert_int_equal(scene->material_count, 1); /* "unused" is dropped */
    assert_string_equal(scene->materials[0].name, "grey");
    assert_int_equal(scene->polygons[0].vertex_count, 4);
    assert_int_equal(scene->polygons[1].surface, 1);
    assert_int_equal(scene->polygons[2].surface, 0);
    assert_false(rad_scene_has_emitter(scene));
    rad_scene_destroy(scene);
}

/* A quad with one corner lifted is split into two triangles; a planar
 * non-convex pentagon stays one polygon. */
static void test_builder_non_planar(void **state)
{
    (void)state;
    const double grey[3] = {0.5, 0.5, 0.5}, black[3] = {0.0, 0.0, 0.0};
    const vec3 bent[] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.1}, {0, 1, 0}};
    const vec3 arrow[] = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {1, 1, 0}, {0, 2, 0}};
    rad_scene_builder *b = rad_scene_builder_create(ctx, "bent.obj");
    int material = rad_scene_builder_material(b, "grey", grey, black);
    int surface = rad_scene_builder_surface(b, "bent");
    int flat = rad_scene_builder_surface(b, "arrow");
    assert_int_equal(rad_scene_builder_polygon(b, surface, material, bent, 4, 3), RAD_OK);
    assert_int_equal(rad_scene_builder_polygon(b, flat, material, arrow, 5, 4), RAD_OK);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
    assert_int_equal(rad_scene_polygon_count(scene), 3);
    double expected = 0.0;
    for (size_t p = 0; p < 2; p++) {
        const rad_polygon *triangle = &scene->polygons[p];
        assert_int_equal(triangle->vertex_count, 3);
        assert_int_equal(triangle->surface, 0);
        const vec3 *v = &scene->positions[scene->indices[triangle->first_index]];
        vec3 cross = v3_cross(v3_sub(v[1], v[0]), v3_sub(v[2], v[0]));
        expected += 0.5 * v3_length(cross);
        assert_true(v3_dot(cross, triangle->normal) > 0.0); /* winding kept */
        assert_true(triangle->normal.z > 0.9);
    }
    assert_close(rad_scene_surface_area(scene, 0), expected, 1e-15);
    assert_true(expected > 1.0 && expected < 1.01); /* lifting a corner by 0.1 adds < 1 % */
    assert_int_equal(scene->polygons[2].vertex_count, 5);
    assert_close(rad_scene_surface_area(scene, 1), 3.0, 1e-15);
    rad_scene_destroy(scene);
}

/* Emission whose total power would overflow a double on its way through
 * the solver is refused, naming the material; a large but solvable one
 * loads. */
/* Emission beyond RAD_MAX_EXITANCE (1e30 W/m^2) is refused as the material
 * is defined, naming it; 1e30 itself loads.  (5e307 once passed and made the
 * emitted power overflow; within the limits of lengths and exitance no sum
 * of A E can.) */
static void test_emitted_power_overflow(void **state)
{
    (void)state;
    const double grey[3] = {0.5, 0.5, 0.5};
    const vec3 square[] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const double emissions[][3] = {{5e307, 0, 0}, {0, 0, 1.0000001e30}, {1e30, 1e30, 1e30}};
    for (size_t k = 0; k < 3; k++) {
        rad_scene_builder *b = rad_scene_builder_create(ctx, "lamp.obj");
        rad_api_enter(ctx); /* a new call: its first failure is kept */
        int material = rad_scene_builder_material(b, "sun", grey, emissions[k]);
        if (k < 2) {
            assert_int_equal(material, -1);
            assert_contains(rad_context_error(ctx), "lamp.obj: material 'sun': emission");
            assert_contains(rad_context_error(ctx), "W/m^2 is above the 1e+30 W/m^2 the engine works in");
            rad_scene_builder_destroy(b);
            continue;
        }
        int surface = rad_scene_builder_surface(b, "panel");
        assert_int_equal(rad_scene_builder_polygon(b, surface, material, square, 4, 1), RAD_OK);
        assert_int_equal(rad_scene_builder_polygon(b, surface, material, square, 4, 2), RAD_OK);
        rad_scene *scene = NULL;
        assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_OK);
        rad_scene_destroy(scene);
    }
}

static void test_builder_errors(void **state)
{
    (void)state;
    const double grey[3] = {0.5, 0.5, 0.5}, black[3] = {0.0, 0.0, 0.0};
    const double bright[3] = {0.5, 1.2, 0.5}, negative[3] = {0.0, -1.0, 0.0};
    vec3 triangle[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const vec3 bowtie[] = {{0, 0, 0}, {2, 1, 0}, {2, 0, 0}, {0, 2, 0}};
    rad_scene_builder *b = rad_scene_builder_create(ctx, "box.obj");
    rad_api_enter(ctx); /* a new call: its first failure is kept */
    assert_int_equal(rad_scene_builder_material(b, "white", bright, black), -1);
    assert_int_equal(ctx->last_result, RAD_ERROR_INVALID_SCENE);
    assert_string_equal(rad_context_error(ctx),
                        "box.obj: material 'white': reflectance 1.2 is outside [0, 1)");
    rad_api_enter(ctx); /* a new call: its first failure is kept */
    assert_int_equal(rad_scene_builder_material(b, "lamp", grey, negative), -1);
    assert_contains(rad_context_error(ctx), "material 'lamp': emission -1");
    int material = rad_scene_builder_material(b, "grey", grey, black);
    int surface = rad_scene_builder_surface(b, "wall");

    triangle[1].y = NAN;
    rad_api_enter(ctx); /* a new call: its first failure is kept */
    assert_int_equal(rad_scene_builder_polygon(b, surface, material, triangle, 3, 7),
                     RAD_ERROR_INVALID_SCENE);
    assert_string_equal(rad_context_error(ctx),
                        "box.obj:7: polygon in surface 'wall' has a non-finite coordinate");
    rad_api_enter(ctx); /* a new call: its first failure is kept */
    assert_int_equal(rad_scene_builder_polygon(b, surface, material, triangle, 3, 0),
                     RAD_ERROR_INVALID_SCENE);
    assert_string_equal(rad_context_error(ctx),
                        "box.obj: polygon in surface 'wall' has a non-finite coordinate");
    triangle[1] = v3(1e-7, 1e-7, 0.0); /* on the line through the others, nearly */
    triangle[2] = v3(1.0, 1.0 + 1e-13, 0.0);
    rad_api_enter(ctx); /* a new call: its first failure is kept */
    assert_int_equal(rad_scene_builder_polygon(b, surface, material, triangle, 3, 0),
                     RAD_ERROR_INVALID_SCENE);
    assert_contains(rad_context_error(ctx), "has zero area");
    rad_api_enter(ctx); /* a new call: its first failure is kept */
    assert_int_equal(rad_scene_builder_polygon(b, surface, material, triangle, 2, 0),
                     RAD_ERROR_INVALID_SCENE);
    assert_contains(rad_context_error(ctx), "has 2 distinct vertices");
    rad_api_enter(ctx); /* a new call: its first failure is kept */
    assert_int_equal(rad_scene_builder_polygon(b, surface, material, NULL, 0, 0),
                     RAD_ERROR_INVALID_SCENE);
    assert_contains(rad_context_error(ctx), "has 0 distinct vertices");
    rad_api_enter(ctx); /* a new call: its first failure is kept */
    assert_int_equal(rad_scene_builder_polygon(b, surface, material, bowtie, 4, 9),
                     RAD_ERROR_INVALID_SCENE);
    assert_string_equal(rad_context_error(ctx),
                        "box.obj:9: polygon in surface 'wall' intersects itself");
    rad_api_enter(ctx); /* a new call: its first failure is kept */
    assert_int_equal(rad_scene_builder_polygon(b, surface + 5, material, bowtie, 4, 9),
                     RAD_ERROR_INVALID_ARGUMENT);

    rad_scene sentinel, *scene = &sentinel; /* must come back NULL */
    rad_api_enter(ctx); /* a new call: its first failure is kept */
    assert_int_equal(rad_scene_builder_finish(b, &scene), RAD_ERROR_INVALID_SCENE);
    assert_null(scene);
    assert_string_equal(rad_context_error(ctx), "box.obj: scene is empty (no polygons)");
}

/* ---- ear clipping ---- */

static double triangles_area(const vec3 *v, const uint32_t *t, size_t count, vec3 normal)
{
    double area = 0.0;
    for (size_t i = 0; i < count; i++) {
        vec3 cross = v3_cross(v3_sub(v[t[3 * i + 1]], v[t[3 * i]]),
                              v3_sub(v[t[3 * i + 2]], v[t[3 * i]]));
        double signed_area = 0.5 * v3_dot(cross, normal);
        assert_true(fabs(signed_area) > 1e-9); /* no slivers from collinear vertices */
        area += signed_area;
    }
    return area;
}

static void test_triangulate_l_shape(void **state)
{
    (void)state;
    /* An L: the 2 x 2 square without its top-right unit square; area 3. */
    const vec3 l_shape[] = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
    uint32_t t[12];
    _Alignas(double) unsigned char scratch[RAD_TRIANGULATE_SCRATCH(8)];
    assert_int_equal(rad_triangulate_polygon(NULL, l_shape, 6, v3(0, 0, 1), scratch, t), 4);
    assert_close(triangles_area(l_shape, t, 4, v3(0, 0, 1)), 3.0, 1e-15);
    assert_close(0.5 * v3_length(rad_polygon_newell(l_shape, 6)), 3.0, 1e-15);

    /* Seen from the other side (clockwise about the normal) the triangles
     * keep the polygon's own winding. */
    assert_int_equal(rad_triangulate_polygon(NULL, l_shape, 6, v3(0, 0, -1), scratch, t), 4);
    assert_close(triangles_area(l_shape, t, 4, v3(0, 0, 1)), 3.0, 1e-15);

    /* The same L standing in the x = 5 plane, tilted normal. */
    vec3 standing[6];
    for (int i = 0; i < 6; i++)
        standing[i] = v3(5.0, l_shape[i].x, l_shape[i].y);
    assert_int_equal(rad_triangulate_polygon(NULL, standing, 6, v3(1, 0.01, 0), scratch, t), 4);
    assert_close(triangles_area(standing, t, 4, v3(1, 0, 0)), 3.0, 1e-15);
}

static void test_triangulate_collinear(void **state)
{
    (void)state;
    /* The unit square with a vertex in the middle of each side. */
    const vec3 square[] = {{0, 0, 0},   {0.5, 0, 0}, {1, 0, 0},   {1, 0.5, 0},
                           {1, 1, 0},   {0.5, 1, 0}, {0, 1, 0},   {0, 0.5, 0}};
    uint32_t t[18];
    _Alignas(double) unsigned char scratch[RAD_TRIANGULATE_SCRATCH(8)];
    assert_int_equal(rad_triangulate_polygon(NULL, square, 8, v3(0, 0, 1), scratch, t), 6);
    assert_close(triangles_area(square, t, 6, v3(0, 0, 1)), 1.0, 1e-15);
}

static void test_triangulate_rejects(void **state)
{
    (void)state;
    uint32_t t[12];
    _Alignas(double) unsigned char scratch[RAD_TRIANGULATE_SCRATCH(8)];
    /* A symmetric bowtie (area 0) and a lopsided one (area != 0). */
    const vec3 bowtie[] = {{0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 1, 0}};
    const vec3 lopsided[] = {{0, 0, 0}, {2, 1, 0}, {2, 0, 0}, {0, 2, 0}};
    const vec3 line[] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
    const vec3 spike[] = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {2, 3, 0}, {2, 1, 0}, {0, 1, 0}};
    assert_int_equal(rad_triangulate_polygon(NULL, bowtie, 4, v3(0, 0, 1), scratch, t), 0);
    assert_int_equal(rad_triangulate_polygon(NULL, lopsided, 4, v3(0, 0, 1), scratch, t), 0);
    assert_int_equal(rad_triangulate_polygon(NULL, line, 3, v3(0, 0, 1), scratch, t), 0);
    assert_int_equal(rad_triangulate_polygon(NULL, spike, 6, v3(0, 0, 1), scratch, t), 0);
    assert_int_equal(rad_triangulate_polygon(NULL, bowtie, 4, v3(0, 0, 0), scratch, t), 0);
}

/* ---- faces of 10^5 vertices: the sweep and the grid ---- */

#define BIG 100000

/* A deterministic generator for the test shapes (xorshift64*). */
static double random_unit(uint64_t *state)
{
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    return (double)((*state * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

/* Shapes in the z = 0 plane, counter-clockwise; each returns its count. */
static size_t big_circle(vec3 *v)
{
    for (size_t i = 0; i < BIG; i++)
        v[i] = v3(cos(2.0 * M_PI * (double)i / BIG), sin(2.0 * M_PI * (double)i / BIG), 0.0);
    return BIG;
}

/* The square [-1, 1]^2 with 25,000 points per side, all but its corners
 * collinear with their neighbours. */
static size_t big_square(vec3 *v)
{
    const size_t side = BIG / 4;
    for (size_t i = 0; i < side; i++) {
        double t = -1.0 + 2.0 * (double)i / (double)side;
        v[i] = v3(t, -1.0, 0.0);
        v[side + i] = v3(1.0, t, 0.0);
        v[2 * side + i] = v3(-t, 1.0, 0.0);
        v[3 * side + i] = v3(-1.0, -t, 0.0);
    }
    return BIG;
}

/* A comb: a spine [-1, 1] x [-1, -0.9] and 25,000 teeth up to y = 1, half
 * a period wide; area 0.2 + 1.9 = 2.1. */
static size_t big_comb(vec3 *v)
{
    const size_t teeth = BIG / 4;
    const double period = 2.0 / (double)teeth;
    size_t n = 0;
    v[n++] = v3(-1.0, -1.0, 0.0);
    v[n++] = v3(1.0, -1.0, 0.0);
    for (size_t t = 0; t < teeth; t++) {
        double right = 1.0 - (double)t * period;
        if (t > 0)
            v[n++] = v3(right, -0.9, 0.0);
        v[n++] = v3(right, 1.0, 0.0);
        v[n++] = v3(right - 0.5 * period, 1.0, 0.0);
        v[n++] = v3(right - 0.5 * period, -0.9, 0.0);
    }
    v[n++] = v3(-1.0, -0.9, 0.0);
    return n;
}

/* A star: angles in order, radii random in [0.2, 1]. */
static size_t big_star(vec3 *v)
{
    uint64_t state = 0x9e3779b97f4a7c15ull;
    for (size_t i = 0; i < BIG; i++) {
        double angle = 2.0 * M_PI * ((double)i + 0.5 * random_unit(&state)) / BIG;
        double radius = 0.2 + 0.8 * random_unit(&state);
        v[i] = v3(radius * cos(angle), radius * sin(angle), 0.0);
    }
    return BIG;
}

/* A strip 0.02 wide wound 20 times round the origin. */
static size_t big_spiral(vec3 *v)
{
    const size_t half = BIG / 2;
    for (size_t i = 0; i < half; i++) {
        double angle = 20.0 * 2.0 * M_PI * (double)i / (double)(half - 1);
        double radius = 0.05 + angle / (20.0 * 2.0 * M_PI);
        v[i] = v3((radius + 0.01) * cos(angle), (radius + 0.01) * sin(angle), 0.0);
        v[BIG - 1 - i] = v3((radius - 0.01) * cos(angle), (radius - 0.01) * sin(angle), 0.0);
    }
    return BIG;
}

/* Load one face through the builder; returns the scene (or NULL, the
 * result in *result). */
static rad_scene *build_face(const vec3 *v, size_t n, rad_result *result)
{
    rad_scene_builder *b = rad_scene_builder_create(ctx, "big.obj");
    assert_non_null(b);
    const double grey[3] = {0.5, 0.5, 0.5}, black[3] = {0.0, 0.0, 0.0};
    int material = rad_scene_builder_material(b, "grey", grey, black);
    int surface = rad_scene_builder_surface(b, "big");
    rad_scene *scene = NULL;
    rad_api_enter(ctx);
    *result = rad_scene_builder_polygon(b, surface, material, v, n, 3);
    if (*result == RAD_OK)
        *result = rad_scene_builder_finish(b, &scene); /* consumes the builder */
    else
        rad_scene_builder_destroy(b);
    return scene;
}

/* The triangles' total area about `normal`, each one of positive area
 * (the big shapes' slivers are far below triangles_area's 1e-9). */
static double positive_triangles_area(const vec3 *v, const uint32_t *t, size_t count, vec3 normal)
{
    double area = 0.0;
    for (size_t i = 0; i < count; i++) {
        vec3 cross = v3_cross(v3_sub(v[t[3 * i + 1]], v[t[3 * i]]),
                              v3_sub(v[t[3 * i + 2]], v[t[3 * i]]));
        double signed_area = 0.5 * v3_dot(cross, normal);
        assert_true(signed_area > 0.0);
        area += signed_area;
    }
    return area;
}

static void test_triangulate_big_faces(void **state)
{
    (void)state;
    size_t (*const shapes[])(vec3 *) = {big_circle, big_square, big_comb, big_star, big_spiral};
    const char *const names[] = {"circle", "square", "comb", "star", "spiral"};
    vec3 *v = malloc((BIG + 8) * sizeof *v);
    uint32_t *t = malloc(3 * (BIG + 8) * sizeof *t);
    void *scratch = malloc(RAD_TRIANGULATE_SCRATCH(BIG + 8));
    assert_true(v && t && scratch);
    for (size_t s = 0; s < sizeof shapes / sizeof shapes[0]; s++) {
        size_t n = shapes[s](v);
        double area = 0.5 * rad_polygon_newell(v, n).z;
        print_message("%s: %zu vertices, area %.17g\n", names[s], n, area);
        /* The triangles tile the polygon: n - 2 of them, the area to 1e-9. */
        assert_int_equal(rad_triangulate_polygon(NULL, v, n, v3(0, 0, 1), scratch, t), n - 2);
        assert_close_relative(positive_triangles_area(v, t, n - 2, v3(0, 0, 1)), area, 1e-9);
        /* Seen from below, the same. */
        assert_int_equal(rad_triangulate_polygon(NULL, v, n, v3(0, 0, -1), scratch, t), n - 2);
        assert_close_relative(positive_triangles_area(v, t, n - 2, v3(0, 0, 1)), area, 1e-9);
        /* Through the builder: one polygon of that area (the square's
         * collinear points dropped, its corners kept). */
        rad_result r;
        rad_scene *scene = build_face(v, n, &r);
        assert_int_equal(r, RAD_OK);
        assert_int_equal(scene->polygon_count, 1);
        assert_int_equal(scene->polygons[0].vertex_count, s == 1 ? 4 : n);
        assert_close_relative(rad_scene_surface_area(scene, 0), area, 1e-9);
        rad_scene_destroy(scene);
    }
    free(v);
    free(t);
    free(scratch);
}

static void test_triangulate_big_refusals(void **state)
{
    (void)state;
    vec3 *v = malloc((BIG + 8) * sizeof *v);
    uint32_t *t = malloc(3 * (BIG + 8) * sizeof *t);
    void *scratch = malloc(RAD_TRIANGULATE_SCRATCH(BIG + 8));
    assert_true(v && t && scratch);
    /* The circle with two vertices near the end swapped: their chords
     * cross, once. */
    size_t n = big_circle(v);
    vec3 swap = v[n - 3];
    v[n - 3] = v[n - 2];
    v[n - 2] = swap;
    assert_int_equal(rad_triangulate_polygon(NULL, v, n, v3(0, 0, 1), scratch, t), 0);
    rad_result r;
    assert_null(build_face(v, n, &r));
    assert_int_equal(r, RAD_ERROR_INVALID_SCENE);
    assert_string_equal(rad_context_error(ctx), "big.obj:3: polygon in surface 'big' intersects itself");
    /* The comb with the left tip of tooth 12,500 moved onto the right side
     * of the next tooth: the two touch at a vertex, without crossing. */
    n = big_comb(v);
    size_t tip = 5 + 4 * 12499 + 2; /* tooth t > 0: (R, -0.9), (R, 1), tip, ... */
    assert_close(v[tip].y, 1.0, 0.0);
    v[tip] = v3(v[tip + 3].x, 0.5, 0.0); /* tip + 3: (R - period, 1), the next side's top */
    assert_int_equal(rad_triangulate_polygon(NULL, v, n, v3(0, 0, 1), scratch, t), 0);
    v[tip].x += 1e-9; /* just clear of it: simple */
    assert_int_equal(rad_triangulate_polygon(NULL, v, n, v3(0, 0, 1), scratch, t), n - 2);
    free(v);
    free(t);
    free(scratch);
}

/* The pair-by-pair test the sweep replaced: every two non-adjacent edges,
 * through the same predicate (segments_meet in triangulate.c), here
 * written again from its definition. */
static double orient_xy(vec3 a, vec3 b, vec3 c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}
static bool in_box(vec3 a, vec3 b, vec3 p)
{
    return p.x >= fmin(a.x, b.x) && p.x <= fmax(a.x, b.x) && p.y >= fmin(a.y, b.y) &&
           p.y <= fmax(a.y, b.y);
}
static bool brute_force_simple(const vec3 *v, size_t n, double eps)
{
    for (size_t i = 0; i < n; i++) {
        vec3 prev = v[(i + n - 1) % n], p = v[i], next = v[(i + 1) % n];
        if (p.x == next.x && p.y == next.y)
            return false;
        double along = (p.x - prev.x) * (next.x - p.x) + (p.y - prev.y) * (next.y - p.y);
        if (fabs(orient_xy(prev, p, next)) <= eps && along < 0.0)
            return false;
    }
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 2; j < n; j++) {
            if (i == 0 && j == n - 1)
                continue;
            vec3 a = v[i], b = v[i + 1], c = v[j], d = v[(j + 1) % n];
            double d1 = orient_xy(c, d, a), d2 = orient_xy(c, d, b);
            double d3 = orient_xy(a, b, c), d4 = orient_xy(a, b, d);
            if (((d1 > eps && d2 < -eps) || (d1 < -eps && d2 > eps)) &&
                ((d3 > eps && d4 < -eps) || (d3 < -eps && d4 > eps)))
                return false;
            if ((fabs(d1) <= eps && in_box(c, d, a)) || (fabs(d2) <= eps && in_box(c, d, b)) ||
                (fabs(d3) <= eps && in_box(a, b, c)) || (fabs(d4) <= eps && in_box(a, b, d)))
                return false;
        }
    return true;
}

static void test_triangulate_sweep_against_pairs(void **state)
{
    (void)state;
    /* Random polygons of 4 to 12 vertices, half of them on a 4 x 4 grid of
     * integer points (touching, collinear overlapping and coincident
     * vertices, decided exactly) and half anywhere in the unit square;
     * most intersect themselves.  In the (u, v) frame of the normal +z the
     * coordinates are (-y, x) up to the first vertex: exact for these. */
    uint64_t state_bits = 12345;
    _Alignas(double) unsigned char scratch[RAD_TRIANGULATE_SCRATCH(12)];
    uint32_t t[3 * 12];
    size_t simple = 0, refused = 0;
    for (int trial = 0; trial < 4000; trial++) {
        size_t n = 4 + (size_t)(random_unit(&state_bits) * 9.0);
        vec3 v[12];
        for (size_t i = 0; i < n; i++) {
            double x = random_unit(&state_bits), y = random_unit(&state_bits);
            v[i] = trial % 2 ? v3(x, y, 0.0) : v3(floor(4.0 * x), floor(4.0 * y), 0.0);
        }
        double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY, twice_area = 0.0;
        for (size_t i = 0; i < n; i++) {
            x0 = fmin(x0, v[i].x);
            x1 = fmax(x1, v[i].x);
            y0 = fmin(y0, v[i].y);
            y1 = fmax(y1, v[i].y);
            twice_area += orient_xy(v[0], v[i], v[(i + 1) % n]);
        }
        double eps = 64.0 * DBL_EPSILON * ((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0));
        if (fabs(twice_area) <= eps)
            continue; /* refused before either test */
        bool expected = brute_force_simple(v, n, eps);
        size_t count = rad_triangulate_polygon(NULL, v, n, v3(0, 0, 1), scratch, t);
        if (count != (expected ? n - 2 : 0))
            print_error("trial %d: %zu vertices, pairs say %s, got %zu triangles\n", trial, n,
                        expected ? "simple" : "not simple", count);
        assert_int_equal(count, expected ? n - 2 : 0);
        if (expected) {
            assert_close_relative(triangles_area(v, t, n - 2, v3(0, 0, 1)), 0.5 * twice_area, 1e-12);
            simple++;
        } else {
            refused++;
        }
    }
    print_message("%zu simple, %zu refused\n", simple, refused);
    assert_true(simple > 300 && refused > 1000); /* both kinds well represented */
}

static void test_triangulate_cancelled(void **state)
{
    (void)state;
    vec3 *v = malloc(BIG * sizeof *v);
    assert_non_null(v);
    size_t n = big_star(v);
    rad_context_cancel(ctx, true);
    rad_result r;
    assert_null(build_face(v, n, &r));
    assert_int_equal(r, RAD_ERROR_INTERRUPTED);
    assert_string_equal(rad_context_error(ctx), "big.obj:3: interrupted while triangulating a "
                                                "polygon of 100000 vertices in surface 'big'");
    /* And through the OBJ reader, from memory. */
    size_t capacity = 64 * (size_t)BIG, length = 0;
    char *obj = malloc(capacity);
    assert_non_null(obj);
    length += (size_t)snprintf(obj, capacity, "o big\n");
    for (size_t i = 0; i < n; i++)
        length += (size_t)snprintf(obj + length, capacity - length, "v %.9g %.9g 0\n", v[i].x, v[i].y);
    length += (size_t)snprintf(obj + length, capacity - length, "f");
    for (size_t i = 0; i < n; i++)
        length += (size_t)snprintf(obj + length, capacity - length, " %zu", i + 1);
    length += (size_t)snprintf(obj + length, capacity - length, "\n");
    assert_true(length < capacity);
    rad_scene sentinel, *scene = &sentinel;
    rad_api_enter(ctx);
    assert_int_equal(rad_scene_load_memory(ctx, "big.obj", obj, length, NULL, 0, &scene),
                     RAD_ERROR_INTERRUPTED);
    assert_null(scene);
    assert_contains(rad_context_error(ctx), "interrupted");
    rad_context_cancel(ctx, false);
    free(obj);
    free(v);
}

/* ---- bad input: the code, and a message naming the file (and line) ---- */

typedef struct bad_input {
    const char *name;    /* written to temp_dir and loaded */
    const char *text;
    const char *mtl_name; /* written too, when not NULL */
    const char *mtl_text;
    rad_result expected;
    const char *message[3]; /* parts the message must contain */
} bad_input;

static const bad_input bad_inputs[] = {
    {"garbage.obj", "this is not an obj file\n@@@ ### !!!\n", NULL, NULL, RAD_ERROR_PARSE,
     {"garbage.obj:1: ", "unknown statement 'this'", NULL}},
    {"range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 40\n", NULL, NULL, RAD_ERROR_PARSE,
     {"range.obj:5: face references vertex 40 of 3", NULL, NULL}},
    {"relative.obj", "v 0 0 0\nf -1 -2 -3\nv 1 0 0\nv 0 1 0\n", NULL, NULL, RAD_ERROR_PARSE,
     {"relative.obj:2: face references vertex -2 of 1", NULL, NULL}},
    {"nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", NULL, NULL, RAD_ERROR_INVALID_SCENE,
     {"nan.obj:2: vertex coordinate 'nan' is not a finite number", NULL, NULL}},
    {"word.obj", "v 0 zero 0\n", NULL, NULL, RAD_ERROR_PARSE,
     {"word.obj:1: vertex coordinate 'zero' is not a finite number", NULL, NULL}},
    {"indented.obj", "v 0 0 0\nv 1 0 0\n\tv 0 1 0\nv 0 0 1\nf 1 2 3\n", NULL, NULL,
     RAD_ERROR_PARSE, {"indented.obj:3: statement 'v' is indented", NULL, NULL}},
    {"five.obj", "v 0 0 0\nv 1 0 0 1 0\nv 0 1 0\nf 1 2 3\n", NULL, NULL, RAD_ERROR_PARSE,
     {"five.obj:2: vertex has 5 numbers", NULL, NULL}},
    {"point.obj", "v 0 0 0\nv .5 0 0\nv 0 1 0\nf 1 2 3\n", NULL, NULL, RAD_ERROR_PARSE,
     {"point.obj:2: vertex coordinate '.5'", NULL, NULL}},
    {"weight.obj", "v 0 0 0 1\nv 1 0 0 0\nv 0 1 0 1\nf 1 2 3\n", NULL, NULL,
     RAD_ERROR_INVALID_SCENE, {"weight.obj:2: vertex has weight w = 0", NULL, NULL}},
    {"normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n", NULL, NULL,
     RAD_ERROR_PARSE, {"normal.obj:5: face references normal 2 of 1", NULL, NULL}},
    {"line.obj", "v 0 0 0\nv 1 0 0\nl 1 red\n", NULL, NULL, RAD_ERROR_PARSE,
     {"line.obj:3: face has a malformed vertex 'red'", NULL, NULL}},
    {"grey.obj", "mtllib grey.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "grey.mtl",
     "newmtl grey\n\tKd 0.5\n", RAD_ERROR_PARSE, {"grey.mtl:2: material 'grey': Kd needs 3",
                                                 NULL, NULL}},
    {"bright.obj", "mtllib bright.mtl\nusemtl white\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
     "bright.mtl", "# white\nnewmtl white\nKd 1.2 0.5 0.5\n", RAD_ERROR_INVALID_SCENE,
     {"bright.mtl:3: ", "material 'white': reflectance (Kd) 1.2 is outside [0, 1)", NULL}},
    {"dark.obj", "mtllib dark.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "dark.mtl",
     "newmtl black\nKd -0.1 0.5 0.5\n", RAD_ERROR_INVALID_SCENE,
     {"dark.mtl:2: ", "reflectance (Kd) -0.1", NULL}},
    {"ke.obj", "mtllib ke.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "ke.mtl",
     "newmtl lamp\nKe 1 inf 1\n", RAD_ERROR_PARSE, {"ke.mtl:2: ", "'inf' is not a finite", NULL}},
    {"nomtl.obj", "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", NULL, NULL,
     RAD_ERROR_IO, {"nomtl.obj:1: material library 'nowhere.mtl': cannot open", NULL, NULL}},
    {"collinear.obj", "o stick\nv 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", NULL, NULL,
     RAD_ERROR_INVALID_SCENE, {"collinear.obj: polygon in surface 'stick' has zero area", NULL,
                               NULL}},
    {"empty.obj", "# nothing\n# but comments\n", NULL, NULL, RAD_ERROR_INVALID_SCENE,
     {"empty.obj: scene is empty (no polygons)", NULL, NULL}},
    {"lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n", NULL, NULL, RAD_ERROR_INVALID_SCENE,
     {"lines.obj: scene is empty (no polygons)", NULL, NULL}},
    {"bad.gltf", "{\n garbage", NULL, NULL, RAD_ERROR_PARSE, {"bad.gltf:2:", "not JSON", NULL}},
    {"tiny.obj", "v 0 0 0\n", NULL, NULL, RAD_ERROR_INVALID_SCENE,
     {"tiny.obj: scene is empty (no polygons)", NULL, NULL}},
    {"twoverts.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n", NULL, NULL, RAD_ERROR_PARSE,
     {"twoverts.obj:5: face needs 3 or more vertices, has 2 ('l' is for lines)", NULL, NULL}},
    {"onevert.obj", "v 0 0 0\nf 1\n", NULL, NULL, RAD_ERROR_PARSE,
     {"onevert.obj:2: face needs 3 or more vertices, has 1", NULL, NULL}},
    {"noverts.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf\nf 1 2 3\n", NULL, NULL, RAD_ERROR_PARSE,
     {"noverts.obj:4: face needs 3 or more vertices, has 0", NULL, NULL}},
    {"samevert.obj", "v 0 0 0\nv 1 0 0\nf 1 1 1\n", NULL, NULL, RAD_ERROR_INVALID_SCENE,
     {"samevert.obj:3: face needs 3 or more distinct vertices, has 1", NULL, NULL}},
    {"twodistinct.obj", "v 0 0 0\nv 1 0 0\nf 1 2 -1 -2 1\n", NULL, NULL, RAD_ERROR_INVALID_SCENE,
     {"twodistinct.obj:3: face needs 3 or more distinct vertices, has 2", NULL, NULL}},
    {"zeros.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 02 3\n", NULL, NULL, RAD_ERROR_PARSE,
     {"zeros.obj:4: face vertex '02' has an index with a leading zero", NULL, NULL}},
    {"zerosvn.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//01 2//1 3//1\n", NULL, NULL,
     RAD_ERROR_PARSE, {"zerosvn.obj:5: face vertex '1//01' has an index with a leading zero",
                       NULL, NULL}},
    {"plus.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf +1 2 3\n", NULL, NULL, RAD_ERROR_PARSE,
     {"plus.obj:4: face has a malformed vertex '+1'", NULL, NULL}},
    {"continued.obj", "v 0 0 0\nv 1 0 0\n# C:\\scenes\\\nv 0 1 0\nf 1 2 3\n", NULL, NULL,
     RAD_ERROR_PARSE, {"continued.obj:3: line ends in '\\' (a continuation line)", NULL, NULL}},
    {"freeform.obj", "v 0 0 0\ncstype bspline\nv 1 0 0\nend\n", NULL, NULL, RAD_ERROR_PARSE,
     {"freeform.obj:2: 'cstype': free-form geometry is not supported (polygons only)", NULL,
      NULL}},
    {"parm.obj", "v 0 0 0\nparm u 0 1\n", NULL, NULL, RAD_ERROR_PARSE,
     {"parm.obj:2: 'parm': free-form geometry", NULL, NULL}},
    {"lod.obj", "v 0 0 0\nlod 1\n", NULL, NULL, RAD_ERROR_PARSE,
     {"lod.obj:2: 'lod': levels of detail are not supported", NULL, NULL}},
    {"call.obj", "call other.obj\n", NULL, NULL, RAD_ERROR_PARSE,
     {"call.obj:1: 'call': reading another file is not supported", NULL, NULL}},
    {"binary.obj", "\x89PNG\r\n\x1a\n\x1b[2J\x9b\n", NULL, NULL, RAD_ERROR_PARSE,
     {"binary.obj:1: unknown statement '?PNG' (read as OBJ: by its content the file is not glTF "
      "JSON or binary glTF)", NULL, NULL}},
    {"escape.obj", "v 0 0 0\n\x1b[2J\n", NULL, NULL, RAD_ERROR_PARSE,
     {"escape.obj:2: unknown statement '?[2J'", NULL, NULL}},
    {"noname.obj", "mtllib\nv 0 0 0\n", NULL, NULL, RAD_ERROR_PARSE,
     {"noname.obj:1: 'mtllib' names no material library", NULL, NULL}},
    {"unnamed.obj", "mtllib unnamed.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "unnamed.mtl",
     "newmtl a\nKd 0.5 0.5 0.5\nnewmtl \nKd 0.1 0.1 0.1\n", RAD_ERROR_PARSE,
     {"unnamed.mtl:3: 'newmtl' names no material", NULL, NULL}},
    {"usemtl.obj", "mtllib usemtl.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl white\nf 1 2 3\n"
     "usemtl lamp\n", "usemtl.mtl", "newmtl white\nKd 0.5 0.5 0.5\n", RAD_ERROR_PARSE,
     {"usemtl.obj:7: usemtl 'lamp': no material of that name in ", "usemtl.mtl", NULL}},
    {"twice.obj", "mtllib twice.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl white\nf 1 2 3\n",
     "twice.mtl", "newmtl white\nKd 0.5 0.5 0.5\n# again\nnewmtl white\nKd 0.1 0.1 0.1\n",
     RAD_ERROR_PARSE, {"twice.mtl:4: material 'white' is defined again (first at ",
                       "twice.mtl:1)", NULL}},
    {"white.gltf",
     "{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], \"nodes\": "
     "[{\"mesh\": 0}], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, "
     "\"mode\": 4, \"material\": 0}]}], \"materials\": [{\"name\": \"plain\"}], \"buffers\": "
     "[{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,"
     "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}], \"bufferViews\": [{\"buffer\": 0, "
     "\"byteLength\": 36}], \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, "
     "\"count\": 3, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}]}",
     NULL, NULL, RAD_ERROR_INVALID_SCENE,
     {"white.gltf: material 'plain': reflectance 1 is outside [0, 1)", NULL, NULL}},
};

static void check_bad_input(const bad_input *bad, rad_result result, const rad_scene *scene)
{
    if (result != bad->expected)
        print_error("%s: got %s (\"%s\"), expected %s\n", bad->name, rad_result_string(result),
                    rad_context_error(ctx), rad_result_string(bad->expected));
    assert_int_equal(result, bad->expected);
    assert_null(scene);
    assert_null(strchr(rad_context_error(ctx), '\n'));
    for (int i = 0; i < 3 && bad->message[i]; i++)
        assert_contains(rad_context_error(ctx), bad->message[i]);
}

static void test_bad_files(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof bad_inputs / sizeof bad_inputs[0]; i++) {
        const bad_input *bad = &bad_inputs[i];
        if (bad->mtl_name)
            write_temp(bad->mtl_name, bad->mtl_text);
        rad_scene sentinel, *scene = &sentinel;
        rad_result result = rad_scene_load_file(ctx, write_temp(bad->name, bad->text), &scene);
        check_bad_input(bad, result, scene);
    }
}

/* The same inputs from memory, where the MTL travels beside the OBJ. */
static void test_bad_memory(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof bad_inputs / sizeof bad_inputs[0]; i++) {
        const bad_input *bad = &bad_inputs[i];
        if (strcmp(bad->name, "nomtl.obj") == 0)
            continue; /* from memory a missing MTL just means default materials */
        rad_scene sentinel, *scene = &sentinel;
        rad_result result =
            rad_scene_load_memory(ctx, bad->name, bad->text, strlen(bad->text), bad->mtl_text,
                                  bad->mtl_text ? strlen(bad->mtl_text) : 0, &scene);
        check_bad_input(bad, result, scene);
    }
}

static void test_missing_file(void **state)
{
    (void)state;
    char path[512];
    snprintf(path, sizeof path, "%s/missing.obj", temp_dir);
    rad_scene sentinel, *scene = &sentinel;
    assert_int_equal(rad_scene_load_file(ctx, path, &scene), RAD_ERROR_IO);
    assert_null(scene);
    char expected[600];
    snprintf(expected, sizeof expected, "%s: cannot open: No such file or directory", path);
    assert_string_equal(rad_context_error(ctx), expected);
    scene = &sentinel;
    assert_int_equal(rad_scene_load_file(ctx, RAD_TEST_DATA "/missing.gltf", &scene),
                     RAD_ERROR_IO);
    assert_null(scene);
    assert_contains(rad_context_error(ctx), "missing.gltf: cannot open");
}

/* ---- fixtures ---- */

static int setup(void **state)
{
    (void)state;
    if (!mkdtemp(temp_dir))
        return -1;
    return rad_context_create(NULL, &ctx) == RAD_OK ? 0 : -1;
}

static void remove_temp(const char *name)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", temp_dir, name);
    remove(path);
}

static int teardown(void **state)
{
    (void)state;
    remove_temp("quad.gltf");
    for (size_t i = 0; i < sizeof bad_inputs / sizeof bad_inputs[0]; i++) {
        remove_temp(bad_inputs[i].name);
        if (bad_inputs[i].mtl_name)
            remove_temp(bad_inputs[i].mtl_name);
    }
    rad_context_destroy(ctx);
    return rmdir(temp_dir) == 0 ? 0 : -1; /* fails if a file was left behind */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell_box),
        cmocka_unit_test(test_cornell_box_file),
        cmocka_unit_test(test_obj_from_memory),
        cmocka_unit_test(test_obj_groups),
        cmocka_unit_test(test_obj_face_forms),
        cmocka_unit_test(test_obj_exact_digits),
        cmocka_unit_test(test_format_by_content),
        cmocka_unit_test(test_material_libraries),
        cmocka_unit_test(test_gltf),
        cmocka_unit_test(test_gltf_nesting),
        cmocka_unit_test(test_gltf_node_graphs),
        cmocka_unit_test(test_gltf_instances_memory),
        cmocka_unit_test(test_gltf_mirrored),
        cmocka_unit_test(test_gltf_bad_primitives),
        cmocka_unit_test(test_gltf_strips_and_fans),
        cmocka_unit_test(test_gltf_orthographic_camera),
        cmocka_unit_test(test_mtl_unused_properties),
        cmocka_unit_test(test_mtl_unused_cap),
        cmocka_unit_test(test_gltf_unused_properties),
        cmocka_unit_test(test_builder_surfaces_and_materials),
        cmocka_unit_test(test_builder_non_planar),
        cmocka_unit_test(test_builder_errors),
        cmocka_unit_test(test_emitted_power_overflow),
        cmocka_unit_test(test_triangulate_l_shape),
        cmocka_unit_test(test_triangulate_collinear),
        cmocka_unit_test(test_triangulate_rejects),
        cmocka_unit_test(test_triangulate_big_faces),
        cmocka_unit_test(test_triangulate_big_refusals),
        cmocka_unit_test(test_triangulate_sweep_against_pairs),
        cmocka_unit_test(test_triangulate_cancelled),
        cmocka_unit_test(test_bad_files),
        cmocka_unit_test(test_bad_memory),
        cmocka_unit_test(test_missing_file),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
