/*
 * test_twopass.c -- two-pass rendering (docs/methods.md "Two-pass
 * rendering"): the specular part of MTL materials as the importer reads
 * it, and the renderer's second pass against closed forms (a mirror's
 * rho_s, a glass pane's Fresnel transmittance with its inner reflections,
 * a glossy Phong lobe's albedo under a uniform sky).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "test_support.h"

#include "radiosity.h"
#include "api/solution.h"
#include "hier/hier.h"
#include "output/output.h"
#include "scene/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void keep_warning(void *user, const char *message)
{
    snprintf(user, 512, "%s", message);
}

static rad_scene *load(rad_context *ctx, const char *obj, const char *mtl)
{
    rad_scene *scene = NULL;
    rad_result r = rad_scene_load_memory(ctx, "two.obj", obj, strlen(obj), mtl, strlen(mtl), &scene);
    if (r != RAD_OK)
        print_message("%s\n", rad_context_error(ctx));
    assert_int_equal(r, RAD_OK);
    return scene;
}

static const rad_material *material_named(const rad_scene *scene, const char *name)
{
    for (size_t i = 0; i < scene->material_count; i++)
        if (strcmp(scene->materials[i].name, name) == 0)
            return &scene->materials[i];
    fail_msg("no material '%s'", name);
    return NULL;
}

/* Four triangles' worth of OBJ: one quad per material, so each is used. */
static const char *four_quads = "mtllib two.mtl\n"
                                "o a\nusemtl mirror\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
                                "o b\nusemtl glossy\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 5 6 7 8\n"
                                "o c\nusemtl glass\nv 0 0 2\nv 1 0 2\nv 1 1 2\nv 0 1 2\nf 9 10 11 12\n"
                                "o d\nusemtl plain\nv 0 0 3\nv 1 0 3\nv 1 1 3\nv 0 1 3\nf 13 14 15 16\n";

/* illum 3 with Ks: a mirror without Ns (or Ns >= 1000), a Phong lobe of
 * exponent Ns below; illum 7: glass of index Ni transmitting 1 - d;
 * illum 2 (highlights) stays diffuse. */
static void test_mtl_specular_read(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    const char *mtl = "newmtl mirror\nKd 0.1 0.1 0.1\nKs 0.8 0.7 0.6\nillum 3\n"
                      "newmtl glossy\nKd 0.2 0.2 0.2\nKs 0.5\nNs 40\nillum 5\n"
                      "newmtl glass\nKd 0 0 0\nNi 1.45\nd 0.25\nillum 7\n"
                      "newmtl plain\nKd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs 10\nillum 2\n";
    rad_scene *scene = load(ctx, four_quads, mtl);
    const rad_material *m = material_named(scene, "mirror");
    assert_int_equal(m->specular_kind, RAD_SPECULAR_MIRROR);
    assert_true(m->specular[0] == 0.8 && m->specular[1] == 0.7 && m->specular[2] == 0.6);
    assert_true(m->reflectance[0] == 0.1);
    m = material_named(scene, "glossy");
    assert_int_equal(m->specular_kind, RAD_SPECULAR_GLOSSY);
    assert_true(m->specular[2] == 0.5 && m->shininess == 40.0);
    m = material_named(scene, "glass");
    assert_int_equal(m->specular_kind, RAD_SPECULAR_GLASS);
    assert_true(m->ior == 1.45 && m->specular[1] == 0.75);
    m = material_named(scene, "plain");
    assert_int_equal(m->specular_kind, RAD_SPECULAR_NONE);
    assert_true(rad_scene_has_specular(scene));
    rad_scene_destroy(scene);

    /* Ns 1000 and up: the ideal mirror. */
    mtl = "newmtl mirror\nKd 0 0 0\nKs 0.9 0.9 0.9\nNs 1000\nillum 3\n"
          "newmtl glossy\nKd 0.2 0.2 0.2\nillum 3\n" /* no Ks: nothing to reflect */
          "newmtl glass\nKd 0.3 0.2 0.1\nillum 4\n"  /* no d: what Kd leaves, 1.5 without Ni */
          "newmtl plain\nKd 0.5 0.5 0.5\n";
    scene = load(ctx, four_quads, mtl);
    assert_int_equal(material_named(scene, "mirror")->specular_kind, RAD_SPECULAR_MIRROR);
    assert_int_equal(material_named(scene, "glossy")->specular_kind, RAD_SPECULAR_NONE);
    m = material_named(scene, "glass");
    assert_int_equal(m->specular_kind, RAD_SPECULAR_GLASS);
    assert_true(m->ior == 1.5 && fabs(m->specular[0] - 0.7) < 1e-15);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* rho_d + rho_s above 1 reflects more than it receives: refused, naming
 * the library's line of Ks; a glass index of 1 or less, naming it too. */
static void test_mtl_specular_energy(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    const char *mtl = "newmtl mirror\nKd 0.1 0.1 0.1\nKs 0.8 0.8 0.8\nillum 3\n"
                      "newmtl glossy\nKd 0.5 0.5 0.5\nillum 3\nKs 0.4 0.6 0.4\n"
                      "newmtl glass\nKd 0 0 0\nillum 7\n"
                      "newmtl plain\nKd 0.5 0.5 0.5\n";
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "two.obj", four_quads, strlen(four_quads), mtl, strlen(mtl),
                                           &scene),
                     RAD_ERROR_INVALID_SCENE);
    assert_null(scene);
    assert_string_equal(rad_context_error(ctx),
                        "two.mtl:8: material 'glossy': diffuse 0.5 + specular 0.6 reflectance is above 1 "
                        "(the surface would reflect more than it receives)");
    mtl = "newmtl mirror\nKd 0.1 0.1 0.1\nKs 0.8 0.8 0.8\nillum 3\n"
          "newmtl glossy\nKd 0.5 0.5 0.5\n"
          "newmtl glass\nKd 0 0 0\nNi 0.9\nillum 7\n"
          "newmtl plain\nKd 0.5 0.5 0.5\n";
    assert_int_equal(rad_scene_load_memory(ctx, "two.obj", four_quads, strlen(four_quads), mtl, strlen(mtl),
                                           &scene),
                     RAD_ERROR_INVALID_SCENE);
    assert_non_null(strstr(rad_context_error(ctx), "two.mtl:9: material 'glass': glass needs an index of "
                                                   "refraction (Ni) in (1, 10], got 0.9"));
    rad_context_destroy(ctx);
}

/* glTF: a written metallicFactor with a smooth roughnessFactor is a
 * mirror (r = 0) or a Phong lobe of Ns = 2 / r^4 - 2 (r = 0.3: 303.8),
 * rho_s = m x base, rho_d = (1 - m) x base; KHR_materials_transmission is
 * glass of KHR_materials_ior's index, rho_d = (1 - t) x base; a rough metal
 * (roughness 1 by default) stays diffuse. */
static void test_gltf_specular_read(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
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
        "[0.9, 0.9, 0.9, 1], \"metallicFactor\": 1, \"roughnessFactor\": 0}},\n"
        "   {\"name\": \"glass\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, "
        "1], \"metallicFactor\": 0}, \"extensions\": {\"KHR_materials_transmission\": "
        "{\"transmissionFactor\": 0.8}, \"KHR_materials_ior\": {\"ior\": 1.4}}},\n"
        "   {\"name\": \"plain\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.8, 0.8, 0.8, "
        "1], \"metallicFactor\": 0.5, \"roughnessFactor\": 0.3}},\n"
        "   {\"name\": \"lamp\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1], "
        "\"metallicFactor\": 1}, \"emissiveFactor\": [1, 1, 1]}],\n"
        " \"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"wood.png\"}],\n"
        " \"buffers\": [{\"byteLength\": 60, \"uri\": \"data:application/octet-stream;base64,"
        "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAgD8AAAAAAAAAAAAAgD8AAAAAAAABAAIAAAACAAMA\"}],\n"
        " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": "
        "48, \"byteLength\": 12}],\n"
        " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": "
        "\"VEC3\"},\n"
        "   {\"bufferView\": 1, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}\n";
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "x.gltf", gltf, strlen(gltf), NULL, 0, &scene), RAD_OK);
    const rad_material *m = material_named(scene, "wood");
    assert_int_equal(m->specular_kind, RAD_SPECULAR_MIRROR);
    assert_true(fabs(m->specular[0] - 0.9) < 1e-7 && m->reflectance[0] == 0.0);
    m = material_named(scene, "glass");
    assert_int_equal(m->specular_kind, RAD_SPECULAR_GLASS);
    assert_true(fabs(m->ior - 1.4) < 1e-12 && fabs(m->specular[0] - 0.8) < 1e-12);
    assert_true(fabs(m->reflectance[1] - 0.1) < 1e-7);
    m = material_named(scene, "plain");
    assert_int_equal(m->specular_kind, RAD_SPECULAR_GLOSSY);
    assert_true(fabs(m->shininess - (2.0 / (0.09 * 0.09) - 2.0)) < 1e-9);
    assert_true(fabs(m->specular[2] - 0.4) < 1e-7 && fabs(m->reflectance[2] - 0.4) < 1e-7);
    m = material_named(scene, "lamp");
    assert_int_equal(m->specular_kind, RAD_SPECULAR_NONE);
    assert_true(fabs(m->reflectance[0] - 0.5) < 1e-7);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* ---- the first pass: extended form factors ---- */

/* The factor from a point to a rectangle in a parallel plane at height h,
 * the rectangle [a1, a2] x [b1, b2] in coordinates centred under the point
 * (Howell's catalogue, C-11, by superposition of corner rectangles). */
static double corner_factor(double x, double y, double h)
{
    double X = sqrt(x * x + h * h), Y = sqrt(y * y + h * h);
    return (x / X * atan(y / X) + y / Y * atan(x / Y)) / (2.0 * M_PI);
}

static double parallel_rectangle(double a1, double a2, double b1, double b2, double h)
{
    return corner_factor(a2, b2, h) - corner_factor(a1, b2, h) - corner_factor(a2, b1, h) +
           corner_factor(a1, b1, h);
}

/* A floor beside a vertical mirror at x = 0 (its face toward -x), a small
 * lamp above the floor. */
static const char *beside_mirror_obj =
    "mtllib two.mtl\n"
    "o floor\nusemtl floor\nv -2 0 -1\nv -2 0 1\nv 0 0 1\nv 0 0 -1\nf 1 2 3 4\n"
    "o mirror\nusemtl mirror\nv 0 0 -2\nv 0 0 2\nv 0 2 2\nv 0 2 -2\nf 5 6 7 8\n"
    "o lamp\nusemtl lamp\nv -0.6 1 -0.1\nv -0.4 1 -0.1\nv -0.4 1 0.1\nv -0.6 1 0.1\nf 9 10 11 12\n";
static const char *beside_mirror_mtl = "newmtl floor\nKd 0.5 0.5 0.5\n"
                                       "newmtl mirror\nKd 0 0 0\nKs 0.8 0.8 0.8\nillum 3\n"
                                       "newmtl lamp\nKd 0 0 0\nKe 1 1 1\n";

/* A floor (rho_d 0.5) under a small lamp (radiance 1, E = pi) beside a
 * vertical mirror (rho_s 0.8, no diffuse part) at x = 0: each floor
 * element receives, beyond what it receives with a black wall there,
 * exactly rho_s x the factor from its centroid to the lamp's mirror image
 * (the lamp reflected to x in [0.4, 0.6]), so its B grows by rho_d E
 * rho_s F(image): against Howell's closed form to 1e-9 (the floor sees
 * itself in the mirror edge-on: nothing more comes back).  The same with
 * the mirror turned away (its back to the floor): nothing added. */
static void test_mirror_image_irradiance(void **state)
{
    (void)state;
    rad_context *ctx = test_context(2);
    const char *obj = beside_mirror_obj;
    const char *mtl_mirror = beside_mirror_mtl;
    const char *mtl_black = "newmtl floor\nKd 0.5 0.5 0.5\n"
                            "newmtl mirror\nKd 0 0 0\n"
                            "newmtl lamp\nKd 0 0 0\nKe 1 1 1\n";
    rad_scene *with = load(ctx, obj, mtl_mirror), *without = load(ctx, obj, mtl_black);
    rad_options o = {.target_elements = 300};
    rad_solution *a = NULL, *b = NULL;
    assert_int_equal(rad_solution_create(ctx, with, &o, &a), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, a), RAD_OK);
    assert_int_equal(rad_solution_create(ctx, without, &o, &b), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, b), RAD_OK);
    size_t n = rad_solution_element_count(a), floor_elements = 0;
    assert_int_equal(n, rad_solution_element_count(b));
    double worst = 0.0, largest = 0.0;
    for (size_t e = 0; e < n; e++) {
        if (rad_solution_element_surface(a, e) != 0)
            continue;
        double c[3], Ba[3], Bb[3];
        assert_true(rad_solution_element_geometry(a, e, NULL, c));
        assert_true(rad_solution_element_values(a, e, NULL, NULL, Ba));
        assert_true(rad_solution_element_values(b, e, NULL, NULL, Bb));
        double image = parallel_rectangle(0.4 - c[0], 0.6 - c[0], -0.1 - c[2], 0.1 - c[2], 1.0);
        double expected = 0.5 * M_PI * 0.8 * image;
        double error = fabs((Ba[0] - Bb[0]) - expected) / expected;
        worst = fmax(worst, error);
        largest = fmax(largest, expected);
        floor_elements++;
    }
    print_message("mirror image: %zu floor elements, largest extra B %.6f W/m^2, worst relative error %.2e\n",
                  floor_elements, largest, worst);
    assert_true(floor_elements > 50);
    assert_true(worst < 1e-9);
    rad_solution_destroy(a);
    rad_solution_destroy(b);
    rad_scene_destroy(with);
    rad_scene_destroy(without);

    /* Nothing added: the mirror's back to the floor (no light through a
     * mirror seen from behind), and a mirror hung above the lamp's height,
     * where every path from the floor to the lamp's image (which meets
     * the wall below y = 1) misses it. */
    const char *nothing[] = {
        "mtllib two.mtl\n"
        "o floor\nusemtl floor\nv -2 0 -1\nv -2 0 1\nv 0 0 1\nv 0 0 -1\nf 1 2 3 4\n"
        "o mirror\nusemtl mirror\nv 0 0 -2\nv 0 2 -2\nv 0 2 2\nv 0 0 2\nf 5 6 7 8\n"
        "o lamp\nusemtl lamp\nv -0.6 1 -0.1\nv -0.4 1 -0.1\nv -0.4 1 0.1\nv -0.6 1 0.1\n"
        "f 9 10 11 12\n",
        "mtllib two.mtl\n"
        "o floor\nusemtl floor\nv -2 0 -1\nv -2 0 1\nv 0 0 1\nv 0 0 -1\nf 1 2 3 4\n"
        "o mirror\nusemtl mirror\nv 0 1.01 -2\nv 0 1.01 2\nv 0 2 2\nv 0 2 -2\nf 5 6 7 8\n"
        "o lamp\nusemtl lamp\nv -0.6 1 -0.1\nv -0.4 1 -0.1\nv -0.4 1 0.1\nv -0.6 1 0.1\n"
        "f 9 10 11 12\n"};
    for (int k = 0; k < 2; k++) {
        with = load(ctx, nothing[k], mtl_mirror);
        without = load(ctx, nothing[k], mtl_black);
        assert_int_equal(rad_solution_create(ctx, with, &o, &a), RAD_OK);
        assert_int_equal(rad_solution_solve(ctx, a), RAD_OK);
        assert_int_equal(rad_solution_create(ctx, without, &o, &b), RAD_OK);
        assert_int_equal(rad_solution_solve(ctx, b), RAD_OK);
        for (size_t e = 0; e < rad_solution_element_count(a); e++) {
            double Ba[3], Bb[3];
            assert_true(rad_solution_element_values(a, e, NULL, NULL, Ba));
            assert_true(rad_solution_element_values(b, e, NULL, NULL, Bb));
            assert_true(Ba[0] == Bb[0]);
        }
        rad_solution_destroy(a);
        rad_solution_destroy(b);
        rad_scene_destroy(with);
        rad_scene_destroy(without);
    }
    rad_context_destroy(ctx);
}

/* Southwell's shooting reads F_ji through reciprocity, which light
 * through mirrors does not keep: refused, naming the way out; the
 * hierarchical solver carries mirrors (hier/mirror.c): no warning. */
static void test_mirror_solvers(void **state)
{
    (void)state;
    char said[512] = "";
    rad_context *ctx = NULL;
    rad_context_options co = {.threads = 1, .on_warning = keep_warning, .warning_user = said};
    assert_int_equal(rad_context_create(&co, &ctx), RAD_OK);
    const char *obj = beside_mirror_obj;
    const char *mtl = beside_mirror_mtl;
    rad_scene *scene = load(ctx, obj, mtl);
    rad_options o = {.target_elements = 50, .solver = "southwell"};
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_ERROR_INVALID_ARGUMENT);
    assert_null(s);
    assert_string_equal(rad_context_error(ctx),
                        "two.obj: solver 'southwell' reads F_ji through reciprocity, which light through "
                        "mirrors does not keep; use gauss-seidel, jacobi, direct or conjugate-gradient");
    o.solver = "hierarchical";
    said[0] = '\0';
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    assert_string_equal(said, "");
    o.solver = "instant-radiosity";
    rad_solution_destroy(s);
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    assert_non_null(strstr(said, "solver 'instant-radiosity' does not carry light through mirrors"));
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* Energy: a closed box with a mirror floor (rho_d 0.1, rho_s 0.8) absorbs
 * what it emits, the light through the mirror counted where it lands and
 * the mirror absorbing 1 - rho_d - rho_s.  The mirror images' centroid
 * rule leaves 1.6e-3 at 300 elements, 3.9e-4 at 1,200 (second order);
 * counting the mirror's specular part as absorbed too reads 30 % more
 * absorbed than emitted. */
static void test_mirror_power_balance(void **state)
{
    (void)state;
    rad_context *ctx = test_context(2);
    const char *obj = "mtllib two.mtl\n"
                      "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                      "o floor\nusemtl mirror\nf 1 5 6 2\n"
                      "o top\nusemtl lamp\nf 4 3 7 8\n"
                      "o left\nusemtl wall\nf 1 4 8 5\n"
                      "o right\nusemtl wall\nf 2 6 7 3\n"
                      "o back\nusemtl wall\nf 1 2 3 4\n"
                      "o front\nusemtl wall\nf 5 8 7 6\n";
    const char *mtl = "newmtl mirror\nKd 0.1 0.1 0.1\nKs 0.8 0.8 0.8\nillum 3\n"
                      "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n"
                      "newmtl wall\nKd 0.5 0.5 0.5\n";
    rad_scene *scene = load(ctx, obj, mtl);
    rad_options o = {.target_elements = 300, .solver = "gauss-seidel"};
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
    double emitted, absorbed;
    rad_solution_power(s, &emitted, &absorbed);
    print_message("closed box, mirror floor: emitted %.6f W, absorbed %.6f W (%.2e)\n", emitted, absorbed,
                  (emitted - absorbed) / emitted);
    assert_true(fabs(emitted - absorbed) < 2e-3 * emitted);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* ---- the first pass in the hierarchy (hier/mirror.c) ---- */

/* A closed 2 m box, a mirror floor (rho_d 0.1, rho_s 0.8), an emitting
 * ceiling, one coloured wall: every wall sees the ceiling's image. */
static const char *mirror_box_obj = "mtllib two.mtl\n"
                                    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                                    "o floor\nusemtl mirror\nf 1 5 6 2\n"
                                    "o top\nusemtl lamp\nf 4 3 7 8\n"
                                    "o left\nusemtl wall\nf 1 4 8 5\n"
                                    "o right\nusemtl red\nf 2 6 7 3\n"
                                    "o back\nusemtl wall\nf 1 2 3 4\n"
                                    "o front\nusemtl wall\nf 5 8 7 6\n";
static const char *mirror_box_mtl = "newmtl mirror\nKd 0.1 0.1 0.1\nKs 0.8 0.8 0.8\nillum 3\n"
                                    "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n"
                                    "newmtl wall\nKd 0.5 0.5 0.5\n"
                                    "newmtl red\nKd 0.7 0.2 0.2\n";
/* The same box, the floor a plain diffuse one (the answer without the
 * mirror's light). */
static const char *plain_box_mtl = "newmtl mirror\nKd 0.1 0.1 0.1\n"
                                   "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n"
                                   "newmtl wall\nKd 0.5 0.5 0.5\n"
                                   "newmtl red\nKd 0.7 0.2 0.2\n";

/* The largest per-surface difference of a from b, any channel, relative
 * to b's radiosity; surfaces with B = 0 in b are skipped. */
static double worst_surface_difference(const rad_scene *scene, const rad_solution *a, const rad_solution *b,
                                       const char *what)
{
    double worst = 0.0;
    for (size_t k = 0; k < rad_scene_surface_count(scene); k++) {
        double A[3], B[3];
        rad_solution_surface_radiosity(a, k, A);
        rad_solution_surface_radiosity(b, k, B);
        for (int c = 0; c < 3; c++)
            if (B[c] > 0.0)
                worst = fmax(worst, fabs(A[c] - B[c]) / B[c]);
        print_message("%s: surface %zu: %.6f %.6f %.6f against %.6f %.6f %.6f\n", what, k, A[0], A[1], A[2], B[0],
                      B[1], B[2]);
    }
    print_message("%s: worst surface difference %.2e\n", what, worst);
    return worst;
}

static rad_solution *solved(rad_context *ctx, const rad_scene *scene, const rad_options *o)
{
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, o, &s), RAD_OK);
    if (rad_solution_solve(ctx, s) != RAD_OK)
        fail_msg("%s", rad_context_error(ctx));
    return s;
}

/* Hierarchical radiosity at its defaults carries the mirror as the dense
 * path does, per surface against gauss-seidel on 1,200 elements:
 *
 *   closed box, mirror floor   worst 0.92% (the mirror's own diffuse B,
 *                              0.13 W/m^2: +0.61%; the walls 0.06-0.28%;
 *                              dense at 4,800 elements moves them by under
 *                              0.1%).  Hierarchical's own error on this
 *                              box with a plain floor is +1.8% on the dark
 *                              floor (rho 0.1: the oracle's epsilon is
 *                              power, W), so 2% is the tolerance.
 *   floor beside a mirror      +0.07% on the floor (0.06% without the
 *                              mirror), 0.5% the tolerance
 *
 * And the mirror's light matters: without it (the same box, the floor
 * diffuse) the walls are 25% darker, so the test bites. */
static void test_hier_mirror_agrees(void **state)
{
    (void)state;
    rad_context *ctx = test_context(2);
    rad_scene *scene = load(ctx, mirror_box_obj, mirror_box_mtl);
    rad_scene *plain = load(ctx, mirror_box_obj, plain_box_mtl);
    rad_options dense = {.target_elements = 1200, .solver = "gauss-seidel"}, hier = {0};
    rad_solution *d = solved(ctx, scene, &dense), *h = solved(ctx, scene, &hier), *p = solved(ctx, plain, &hier);
    assert_true(worst_surface_difference(scene, h, d, "mirror box") < 2e-2);
    assert_true(h->view.hier->mirror_links > 100);
    double without[3], with[3];
    rad_solution_surface_radiosity(p, 2, without);
    rad_solution_surface_radiosity(h, 2, with);
    assert_true(with[0] > 1.2 * without[0]);
    rad_solution_destroy(d);
    rad_solution_destroy(h);
    rad_solution_destroy(p);
    rad_scene_destroy(scene);
    rad_scene_destroy(plain);

    /* Open: a floor beside a vertical mirror under a small lamp (above). */
    const char *obj = beside_mirror_obj;
    const char *mtl = beside_mirror_mtl;
    scene = load(ctx, obj, mtl);
    d = solved(ctx, scene, &dense);
    h = solved(ctx, scene, &hier);
    double floor_d[3], floor_h[3];
    rad_solution_surface_radiosity(d, 0, floor_d);
    rad_solution_surface_radiosity(h, 0, floor_h);
    print_message("floor beside a mirror: hierarchical %.6f, dense %.6f (%+.2e)\n", floor_h[0], floor_d[0],
                  floor_h[0] / floor_d[0] - 1.0);
    assert_true(fabs(floor_h[0] / floor_d[0] - 1.0) < 5e-3);
    rad_solution_destroy(d);
    rad_solution_destroy(h);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* Power: the closed mirror box absorbs what it emits, the mirror
 * absorbing 1 - rho_d - rho_s of what it receives.  The mirror links'
 * balance (hier.c, balance_mirrors) makes it exact to the balance's
 * float scales: 8e-7 measured (without it: 5.6e-3, the links' geometry
 * 0.45% short for the walls beside the mirror and the sources' means).
 * Also at 1 and 2 threads bit for bit. */
static void test_hier_mirror_power_and_threads(void **state)
{
    (void)state;
    rad_context *one = test_context(1), *two = test_context(2);
    rad_scene *scene = load(one, mirror_box_obj, mirror_box_mtl);
    rad_options hier = {0};
    rad_solution *a = solved(one, scene, &hier), *b = solved(two, scene, &hier);
    double emitted, absorbed;
    rad_solution_power(a, &emitted, &absorbed);
    print_message("mirror box, hierarchical: emitted %.6f W, absorbed %.6f W (%.2e)\n", emitted, absorbed,
                  (emitted - absorbed) / emitted);
    assert_true(fabs(emitted - absorbed) < 1e-5 * emitted);
    size_t n = rad_solution_element_count(a);
    assert_int_equal(n, rad_solution_element_count(b));
    for (size_t e = 0; e < n; e++) {
        double Ba[3], Bb[3];
        assert_true(rad_solution_element_values(a, e, NULL, NULL, Ba));
        assert_true(rad_solution_element_values(b, e, NULL, NULL, Bb));
        assert_memory_equal(Ba, Bb, sizeof Ba);
    }
    rad_solution_destroy(a);
    rad_solution_destroy(b);
    rad_scene_destroy(scene);
    rad_context_destroy(one);
    rad_context_destroy(two);
}

/* ---- the second pass ---- */

/* Solve `scene` (dense, a few hundred elements) and render a w x w image
 * from camera (position, look-at, up, vfov); returns the mean radiance
 * of the image's red channel. */
static double render_mean(rad_context *ctx, const rad_scene *scene, const char *camera_text, int w,
                          int specular_depth, int glossy_samples, float **pixels_out)
{
    rad_options o = {.target_elements = 200};
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
    rad_camera camera;
    assert_int_equal(rad_camera_parse(ctx, camera_text, &camera), RAD_OK);
    rad_render_options ro = {.width = w, .height = w, .samples = 1, .camera = &camera,
                             .shading = RAD_SHADING_FLAT, .specular_depth = specular_depth,
                             .glossy_samples = glossy_samples};
    rad_image *image = NULL;
    assert_int_equal(rad_solution_render(ctx, s, &ro, &image), RAD_OK);
    const float *p = rad_image_pixels(image);
    double sum = 0.0;
    for (int i = 0; i < w * w; i++)
        sum += p[3 * i];
    if (pixels_out) {
        *pixels_out = malloc((size_t)w * (size_t)w * 3 * sizeof(float));
        memcpy(*pixels_out, p, (size_t)w * (size_t)w * 3 * sizeof(float));
    }
    rad_image_destroy(image);
    rad_solution_destroy(s);
    return sum / (w * w);
}

/* A mirror (rho_s 0.8, no diffuse part) under a lamp of radiance 1 seen
 * from the eye: radiance 0.8 exactly; the first pass alone shows the
 * mirror's B / pi = 0. */
static void test_render_mirror(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    const char *obj = "mtllib two.mtl\n"
                      "o mirror\nusemtl mirror\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n"
                      "o lamp\nusemtl lamp\nv -50 -50 5\nv -50 50 5\nv 50 50 5\nv 50 -50 5\nf 5 6 7 8\n";
    const char *mtl = "newmtl mirror\nKd 0 0 0\nKs 0.8 0.8 0.8\nillum 3\n"
                      "newmtl lamp\nKd 0 0 0\nKe 1 1 1\n";
    rad_scene *scene = load(ctx, obj, mtl);
    const char *camera = "0,0,3,0,0,0,0,1,0,10";
    double seen = render_mean(ctx, scene, camera, 8, 0, 0, NULL);
    assert_true(fabs(seen - 0.8) < 1e-6);
    assert_true(render_mean(ctx, scene, camera, 8, -1, 0, NULL) == 0.0);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* A glass pane (n = 1.5, two faces) at normal incidence before a lamp of
 * radiance 1: the pane transmits (1 - R)^2 / (1 - R^2), R = ((n - 1) /
 * (n + 1))^2, its inner reflections included (Born & Wolf 1.5); to 1e-6
 * (the image's floats; the view is 0.2 degrees wide, R's change across it
 * below 1e-8).  A single interface's 1 - R would be off by 4 %, and
 * stopping after one pass through, (1 - R)^2, by 0.16 %. */
static void test_render_glass_pane(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    const char *obj = "mtllib two.mtl\n"
                      "o front\nusemtl glass\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n"
                      "o back\nusemtl glass\nv -1 -1 -0.1\nv -1 1 -0.1\nv 1 1 -0.1\nv 1 -1 -0.1\nf 5 6 7 8\n"
                      "o lamp\nusemtl lamp\nv -5 -5 -2\nv 5 -5 -2\nv 5 5 -2\nv -5 5 -2\nf 9 10 11 12\n";
    const char *mtl = "newmtl glass\nKd 0 0 0\nNi 1.5\nillum 7\n"
                      "newmtl lamp\nKd 0 0 0\nKe 1 1 1\n";
    rad_scene *scene = load(ctx, obj, mtl);
    double R = (0.5 / 2.5) * (0.5 / 2.5);
    double expected = (1.0 - R) * (1.0 - R) / (1.0 - R * R);
    double seen = render_mean(ctx, scene, "0,0,3,0,0,0,0,1,0,0.2", 4, 0, 0, NULL);
    print_message("glass pane: transmitted %.9f, closed form %.9f\n", seen, expected);
    assert_true(fabs(seen - expected) < 1e-6 * expected);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* A glossy floor (rho_s 0.7, Ns 50, no diffuse part) at the bottom of a
 * box whose other walls all have radiance 1, seen straight down: the
 * modified Phong lobe's albedo at normal incidence is rho_s exactly
 * (Lafortune & Willems 1994), so the image is 0.7 up to the sampling
 * (4096 stratified lobe samples; their spread 2e-2 each: 3e-4 at most
 * in the mean).  Without the lobe's (n + 2) / (n + 1) or its cosine the
 * mean is 2 % off.  The same image on 1 and 3 threads. */
static void test_render_glossy(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    const char *obj = "mtllib two.mtl\n"
                      "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                      "o floor\nusemtl glossy\nf 1 5 6 2\n"
                      "o top\nusemtl lamp\nf 4 3 7 8\n"
                      "o left\nusemtl lamp\nf 1 4 8 5\n"
                      "o right\nusemtl lamp\nf 2 6 7 3\n"
                      "o back\nusemtl lamp\nf 1 2 3 4\n"
                      "o front\nusemtl lamp\nf 5 8 7 6\n";
    const char *mtl = "newmtl glossy\nKd 0 0 0\nKs 0.7 0.7 0.7\nNs 50\nillum 3\n"
                      "newmtl lamp\nKd 0 0 0\nKe 1 1 1\n";
    rad_scene *scene = load(ctx, obj, mtl);
    const char *camera = "0,0.5,0,0,-1,0,0,0,1,1";
    float *one = NULL, *three = NULL;
    double seen = render_mean(ctx, scene, camera, 8, 0, 64, &one);
    print_message("glossy floor: %.6f, closed form 0.7\n", seen);
    assert_true(fabs(seen - 0.7) < 2e-3 * 0.7);
    rad_context *ctx3 = test_context(3);
    render_mean(ctx3, scene, camera, 8, 0, 64, &three);
    assert_memory_equal(one, three, 8 * 8 * 3 * sizeof(float));
    free(one);
    free(three);
    rad_context_destroy(ctx3);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mtl_specular_read),
        cmocka_unit_test(test_mtl_specular_energy),
        cmocka_unit_test(test_gltf_specular_read),
        cmocka_unit_test(test_mirror_image_irradiance),
        cmocka_unit_test(test_mirror_solvers),
        cmocka_unit_test(test_mirror_power_balance),
        cmocka_unit_test(test_hier_mirror_agrees),
        cmocka_unit_test(test_hier_mirror_power_and_threads),
        cmocka_unit_test(test_render_mirror),
        cmocka_unit_test(test_render_glass_pane),
        cmocka_unit_test(test_render_glossy),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
