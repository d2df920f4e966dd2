/*
 * test_textures.c -- reflectance textures (MTL map_Kd): per-element means,
 * energy, render modulation, missing files.
 *
 * Each test writes a small scene into a temporary folder: a 1 m x 1 m
 * floor (y = 0, texture coordinates (x, z)) under a square lamp, the floor
 * textured by a PNG the test writes (stb_image_write), whose texels' linear
 * values the test knows: an 8-bit sRGB value s decodes to
 * ((s / 255 + 0.055) / 1.055)^2.4 (IEC 61966-2-1).
 *
 *   means       a 2 x 2 checker on 4 x 4 elements: each element the value of
 *               the cell it lies in, Kd x lin(s); the floor's mean their mean
 *   energy      a fine checker's floor reflects the power of a flat floor of
 *               its mean colour (within 0.5%)
 *   flat        a one-colour texture renders exactly as the untextured
 *               material of that colour
 *   modulation  one element under a 2 x 2 checker: pixels in the two kinds of
 *               cell differ by the texels' ratio (flat shading)
 *   missing     a missing image fails the load naming the MTL file, line and
 *               image; with missing_textures_flat it loads with Kd
 *   glTF        baseColorTexture with TEXCOORD_0, (0, 0) at the image's top left
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "radiosity.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wcast-qual"
#pragma GCC diagnostic ignored "-Wmissing-prototypes"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wconversion"
#endif
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#pragma GCC diagnostic ignored "-Wunused-function"
#endif

#define KD 0.9

static char folder[256];
static rad_context *ctx;

static double linear(int s)
{
    double c = s / 255.0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

/* A w x h PNG in the folder: cell (x, y) of a `cells` x `cells` checker
 * gets value `a` where x + y is even, else `b` (grey). */
static void write_checker(const char *name, int w, int h, int cells, int a, int b)
{
    unsigned char *px = malloc((size_t)w * (size_t)h * 3);
    assert_non_null(px);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int cell = (x * cells / w + y * cells / h) % 2;
            for (int c = 0; c < 3; c++)
                px[3 * (y * w + x) + c] = (unsigned char)(cell ? b : a);
        }
    char path[512];
    snprintf(path, sizeof path, "%s/%s", folder, name);
    assert_true(stbi_write_png(path, w, h, 3, px, w * 3) != 0);
    free(px);
}

/* s.obj + s.mtl: the floor with material `floor` (its MTL lines given),
 * the lamp above. */
static void write_scene(const char *floor_material)
{
    char path[512];
    snprintf(path, sizeof path, "%s/s.mtl", folder);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "newmtl floor\n%s\nnewmtl lamp\nKd 0 0 0\nKe 1 1 1\n", floor_material);
    fclose(f);
    snprintf(path, sizeof path, "%s/s.obj", folder);
    f = fopen(path, "w");
    assert_non_null(f);
    fputs("mtllib s.mtl\n"
          "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n"
          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
          "v 0.3 1 0.3\nv 0.7 1 0.3\nv 0.7 1 0.7\nv 0.3 1 0.7\n"
          "o floor\nusemtl floor\nf 1/1 4/4 3/3 2/2\n"
          "o lamp\nusemtl lamp\nf 5 6 7 8\n",
          f);
    fclose(f);
}

static rad_scene *load(void)
{
    char path[512];
    snprintf(path, sizeof path, "%s/s.obj", folder);
    rad_scene *scene = NULL;
    rad_result r = rad_scene_load_file(ctx, path, &scene);
    if (r != RAD_OK)
        fail_msg("%s", rad_context_error(ctx));
    return scene;
}

/* The floor flat in the mean colour of a 220 / 30 checker, loaded. */
static rad_scene *flat_mean_scene(void)
{
    char flat[128];
    double mean = KD * 0.5 * (linear(220) + linear(30));
    snprintf(flat, sizeof flat, "Kd %.17g %.17g %.17g", mean, mean, mean);
    write_scene(flat);
    return load();
}

static rad_solution *solve(rad_scene *scene, double mesh_size)
{
    rad_options o = {.solver = "gauss-seidel", .mesh_size = mesh_size};
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
    return s;
}

static void test_element_means(void **state)
{
    (void)state;
    write_checker("checker.png", 8, 8, 2, 200, 40);
    write_scene("Kd 0.9 0.9 0.9\nmap_Kd checker.png");
    rad_scene *scene = load();
    rad_solution *s = solve(scene, 0.25);
    double bright = KD * linear(200), dark = KD * linear(40);
    int count[2] = {0, 0};
    for (size_t e = 0; e < rad_solution_element_count(s); e++) {
        if (rad_solution_element_surface(s, e) != 0)
            continue;
        double rho[3];
        rad_solution_element_values(s, e, rho, NULL, NULL);
        bool is_bright = fabs(rho[0] - bright) < 1e-6;
        assert_true(is_bright || fabs(rho[0] - dark) < 1e-6);
        assert_true(rho[1] == rho[0] && rho[2] == rho[0]);
        count[is_bright]++;
    }
    assert_int_equal(count[0], 8);
    assert_int_equal(count[1], 8);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
}

/* The floor's reflected power, sum A (B - E), and its mean radiosity. */
static double floor_power(rad_solution *s)
{
    double power = 0.0;
    for (size_t e = 0; e < rad_solution_element_count(s); e++) {
        if (rad_solution_element_surface(s, e) != 0)
            continue;
        double B[3], E[3];
        rad_solution_element_values(s, e, NULL, E, B);
        power += rad_solution_element_area(s, e) * (B[0] - E[0]);
    }
    return power;
}

static void test_energy(void **state)
{
    (void)state;
    write_checker("fine.png", 64, 64, 16, 220, 30);
    write_scene("Kd 0.9 0.9 0.9\nmap_Kd fine.png");
    rad_scene *scene = load();
    rad_solution *s = solve(scene, 1.0 / 32.0);
    double textured = floor_power(s);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
    scene = flat_mean_scene();
    s = solve(scene, 1.0 / 32.0);
    double plain = floor_power(s);
    printf("floor reflects %.6g W checkered, %.6g W flat\n", textured, plain);
    assert_true(fabs(textured / plain - 1.0) < 5e-3);
    /* and a floor of the bright colour would reflect far more: the test bites */
    assert_true(linear(220) / (0.5 * (linear(220) + linear(30))) > 1.5);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
}

static rad_image *render(rad_solution *s, rad_shading shading)
{
    rad_camera camera = {{0.5, 0.9, 0.5}, {0.5, 0.0, 0.5}, {0.0, 0.0, -1.0}, 90.0}; /* under the lamp */
    rad_render_options o = {.width = 32, .height = 32, .samples = 1, .camera = &camera, .shading = shading};
    rad_image *image = NULL;
    assert_int_equal(rad_solution_render(ctx, s, &o, &image), RAD_OK);
    return image;
}

static void test_flat_texture_renders_as_its_colour(void **state)
{
    (void)state;
    write_checker("one.png", 4, 4, 1, 150, 150);
    write_scene("Kd 0.9 0.9 0.9\nmap_Kd one.png");
    rad_scene *scene = load();
    rad_solution *s = solve(scene, 0.1);
    rad_image *a = render(s, RAD_SHADING_SMOOTH);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
    /* The texel is a float: the same value as the flat Kd. */
    double kd = KD * (double)(float)linear(150);
    char flat[128];
    snprintf(flat, sizeof flat, "Kd %.17g %.17g %.17g", kd, kd, kd);
    write_scene(flat);
    scene = load();
    s = solve(scene, 0.1);
    rad_image *b = render(s, RAD_SHADING_SMOOTH);
    int w = rad_image_width(a), h = rad_image_height(a);
    const float *pa = rad_image_pixels(a), *pb = rad_image_pixels(b);
    double worst = 0.0;
    for (int k = 0; k < 3 * w * h; k++)
        worst = fmax(worst, fabs(pa[k] - pb[k]) / fmax(pb[k], 1e-12));
    printf("one-colour texture against its colour: worst pixel difference %.3g\n", worst);
    assert_true(worst < 1e-6);
    rad_image_destroy(a);
    rad_image_destroy(b);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
}

static void test_modulation(void **state)
{
    (void)state;
    write_checker("coarse.png", 2, 2, 2, 200, 40);
    write_scene("Kd 0.9 0.9 0.9\nmap_Kd coarse.png");
    rad_scene *scene = load();
    rad_solution *s = solve(scene, 2.0); /* one element on the floor */
    rad_image *image = render(s, RAD_SHADING_FLAT);
    int w = rad_image_width(image);
    const float *px = rad_image_pixels(image);
    /* Pixels a quarter in from opposite corners of the floor lie in
     * cells of the two kinds; the element is one, so only the texel differs. */
    float p = px[3 * (8 * w + 8)], q = px[3 * (8 * w + 24)];
    double ratio = p > q ? p / q : q / p;
    printf("checker pixels %.6g and %.6g: ratio %.6f, texels %.6f\n", p, q, ratio, linear(200) / linear(40));
    assert_true(fabs(ratio / (linear(200) / linear(40)) - 1.0) < 1e-5);
    rad_image_destroy(image);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
}

static void test_missing_file(void **state)
{
    (void)state;
    write_scene("Kd 0.5 0.4 0.3\nmap_Kd nowhere.png");
    char path[512];
    snprintf(path, sizeof path, "%s/s.obj", folder);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_file(ctx, path, &scene), RAD_ERROR_IO);
    assert_null(scene);
    const char *message = rad_context_error(ctx);
    assert_non_null(strstr(message, "s.mtl:3"));
    assert_non_null(strstr(message, "nowhere.png"));
    assert_non_null(strstr(message, "'floor'"));
    /* With the option: a warning, and Kd. */
    rad_context_options co = {.threads = 1, .missing_textures_flat = true};
    rad_context *flat = NULL;
    assert_int_equal(rad_context_create(&co, &flat), RAD_OK);
    assert_int_equal(rad_scene_load_file(flat, path, &scene), RAD_OK);
    rad_options o = {.solver = "gauss-seidel", .mesh_size = 0.5};
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(flat, scene, &o, &s), RAD_OK);
    double rho[3];
    rad_solution_element_values(s, 0, rho, NULL, NULL);
    assert_true(rho[0] == 0.5 && rho[1] == 0.4 && rho[2] == 0.3);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
    rad_context_destroy(flat);
    /* Not an image: an error too, naming it. */
    snprintf(path, sizeof path, "%s/nowhere.png", folder);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("not a PNG\n", f);
    fclose(f);
    snprintf(path, sizeof path, "%s/s.obj", folder);
    assert_int_equal(rad_scene_load_file(ctx, path, &scene), RAD_ERROR_PARSE);
    assert_non_null(strstr(rad_context_error(ctx), "nowhere.png"));
}

/* glTF: baseColorTexture beside the file, TEXCOORD_0 on the floor's two
 * triangles (the same floor and lamp; glTF puts (u, v) = (0, 0) at the
 * image's top left, OBJ at its bottom left): elements of a 2 x 2 checker
 * cell each get its value, the corner at (0, 0, 0) the image's top-left. */
static void test_gltf_base_color_texture(void **state)
{
    (void)state;
    write_checker("checker.png", 8, 8, 8, 40, 200); /* cell (0, 0), top left: 40 */
    static const char gltf[] =
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],\"nodes\":[{\"name\":\"floor\",\""
        "mesh\":0},{\"name\":\"lamp\",\"mesh\":1}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"T"
        "EXCOORD_0\":1},\"indices\":2,\"material\":0}]},{\"primitives\":[{\"attributes\":{\"POSITION\":3},\"ind"
        "ices\":4,\"material\":1}]}],\"materials\":[{\"name\":\"floor\",\"pbrMetallicRoughness\":{\"baseColorFa"
        "ctor\":[0.9,0.9,0.9,1],\"baseColorTexture\":{\"index\":0},\"metallicFactor\":0}},{\"name\":\"lamp\",\""
        "pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0},\"emissiveFactor\":[1"
        ",1,1]}],\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"checker.png\"}],\"buffers\":[{\"byteLength"
        "\":152,\"uri\":\"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAA"
        "AAAAAIA/AAAAAAAAAAAAAIA/mpmZPgAAgD+amZk+MzMzPwAAgD+amZk+MzMzPwAAgD8zMzM/mpmZPgAAgD8zMzM/AA"
        "AAAAAAAAAAAIA/AAAAAAAAgD8AAIA/AAAAAAAAgD8AAAMAAgAAAAIAAQAAAAEAAgAAAAIAAwA=\"}],\"bufferViews"
        "\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":32"
        "},{\"buffer\":0,\"byteOffset\":128,\"byteLength\":12},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":4"
        "8},{\"buffer\":0,\"byteOffset\":140,\"byteLength\":12}],\"accessors\":[{\"bufferView\":0,\"componentT"
        "ype\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,0,1]},{\"bufferView\":1,\"componentT"
        "ype\":5126,\"count\":4,\"type\":\"VEC2\"},{\"bufferView\":2,\"componentType\":5123,\"count\":6,\"type\":\""
        "SCALAR\"},{\"bufferView\":3,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[0.3,1,0.3],\"m"
        "ax\":[0.7,1,0.7]},{\"bufferView\":4,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}";
    char path[512];
    snprintf(path, sizeof path, "%s/t.gltf", folder);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(gltf, f);
    fclose(f);
    rad_scene *scene = NULL;
    if (rad_scene_load_file(ctx, path, &scene) != RAD_OK)
        fail_msg("%s", rad_context_error(ctx));
    rad_solution *s = solve(scene, 0.125);
    int count[2] = {0, 0};
    bool corner_seen = false;
    for (size_t e = 0; e < rad_solution_element_count(s); e++) {
        if (rad_solution_element_surface(s, e) != 0)
            continue;
        double rho[3], centre[3];
        rad_solution_element_values(s, e, rho, NULL, NULL);
        rad_solution_element_geometry(s, e, NULL, centre);
        bool is_bright = fabs(rho[0] - KD * linear(200)) < 1e-6;
        assert_true(is_bright || fabs(rho[0] - KD * linear(40)) < 1e-6);
        count[is_bright]++;
        if (centre[0] < 0.125 && centre[2] < 0.125) {
            assert_false(is_bright); /* (u, v) = (0, 0): the top-left texel */
            corner_seen = true;
        }
    }
    assert_true(corner_seen);
    assert_int_equal(count[0], count[1]);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
}

/* The area-weighted mean radiosity (red) of the floor's elements whose
 * centre lies left (side 0) or right (side 1) of x = 0.5. */
static double half_mean(rad_solution *s, int side)
{
    double sum = 0.0, area = 0.0;
    for (size_t e = 0; e < rad_solution_element_count(s); e++) {
        double centre[3], B[3];
        if (rad_solution_element_surface(s, e) != 0)
            continue;
        rad_solution_element_geometry(s, e, NULL, centre);
        rad_solution_element_values(s, e, NULL, NULL, B);
        if ((centre[0] > 0.5) != (side == 1))
            continue;
        double a = rad_solution_element_area(s, e);
        sum += a * B[0];
        area += a;
    }
    return sum / area;
}

/* Hierarchical radiosity takes each node's reflectance as its texture's
 * mean over the node (hier/tree.c, rad_texture_mean, the dense elements'
 * rule): a floor whose left half is bright (sRGB 220) and right half dark
 * (30) under a centred lamp, at the solver's defaults, against
 * gauss-seidel on 32 x 32 floor elements: the two halves' mean radiosity
 * within 0.1% (measured 2e-8 and 1e-8: both meshes split at x = 0.5, and
 * the floor's light is the lamp's alone, exact per element and per leaf).
 * With the material's reflectance (Kd x the whole texture's mean), as the
 * hierarchy took it before, both halves read that mean: the bright half
 * 2x darker, as the flat material of that colour shows. */
static void test_hierarchical_textured_nodes(void **state)
{
    (void)state;
    write_checker("halves.png", 2, 1, 2, 220, 30);
    write_scene("Kd 0.9 0.9 0.9\nmap_Kd halves.png");
    rad_scene *scene = load();
    rad_solution *dense = solve(scene, 1.0 / 32.0), *hier = NULL;
    rad_options o = {.solver = "hierarchical"};
    assert_int_equal(rad_solution_create(ctx, scene, &o, &hier), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, hier), RAD_OK);
    double worst = 0.0;
    for (int side = 0; side < 2; side++) {
        double h = half_mean(hier, side), d = half_mean(dense, side);
        printf("textured floor, %s half: hierarchical %.6f, dense %.6f (%+.2e)\n", side ? "dark" : "bright", h, d,
               h / d - 1.0);
        worst = fmax(worst, fabs(h / d - 1.0));
    }
    assert_true(worst < 1e-3);
    double bright = half_mean(hier, 0);
    rad_solution_destroy(hier);
    rad_solution_destroy(dense);
    rad_scene_destroy(scene);
    /* The material's mean as a flat colour: the bright half far darker. */
    scene = flat_mean_scene();
    assert_int_equal(rad_solution_create(ctx, scene, &o, &hier), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, hier), RAD_OK);
    printf("the same floor flat: %.6f on the left half\n", half_mean(hier, 0));
    assert_true(bright > 1.5 * half_mean(hier, 0));
    rad_solution_destroy(hier);
    rad_scene_destroy(scene);
}

static int setup(void **state)
{
    (void)state;
    snprintf(folder, sizeof folder, "/tmp/radiosity-textures-XXXXXX");
    if (!mkdtemp(folder))
        return -1;
    rad_context_options co = {.threads = 1};
    return rad_context_create(&co, &ctx) == RAD_OK ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    rad_context_destroy(ctx);
    char command[600];
    snprintf(command, sizeof command, "rm -rf '%s'", folder);
    return system(command) == 0 ? 0 : -1;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_element_means),
        cmocka_unit_test(test_energy),
        cmocka_unit_test(test_flat_texture_renders_as_its_colour),
        cmocka_unit_test(test_modulation),
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_gltf_base_color_texture),
        cmocka_unit_test(test_hierarchical_textured_nodes),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
