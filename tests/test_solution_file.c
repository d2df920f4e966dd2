/*
 * test_solution_file.c -- the solution file (strategy/saved.h): a solution
 * saved and loaded again is the same solution, and a damaged file is
 * refused with one line naming it, never read as something else.
 *
 *   every strategy        the loaded solution renders the same picture, to
 *                         the bit, from the scene's camera and another; the
 *                         same element, vertex and surface values and power
 *   the scene             rebuilt, with its checksum, names and camera
 *   damage                each truncation, a flipped byte, another version,
 *                         a forged count, and structural damage behind a
 *                         recomputed checksum: refused, one line, nothing out
 *   not solved, NULL      refused as documented
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "api/solution.h"
#include "strategy/saved.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static rad_context *ctx;
static char path[256];

static int setup(void **state)
{
    (void)state;
    rad_context_options co = {.threads = 2};
    snprintf(path, sizeof path, "/tmp/test_solution_file_%d.radsol", (int)getpid());
    return rad_context_create(&co, &ctx) == RAD_OK ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    unlink(path);
    rad_context_destroy(ctx);
    return 0;
}

static rad_solution *solved_cornell(rad_scene **scene, const char *solver)
{
    assert_int_equal(rad_scene_create_cornell_box(ctx, scene), RAD_OK);
    rad_options o = {0};
    o.target_elements = 300;
    o.solver = solver;
    o.epsilon = 1e-3;
    rad_solution *s = NULL;
    if (rad_solution_create(ctx, *scene, &o, &s) != RAD_OK || rad_solution_solve(ctx, s) != RAD_OK)
        fail_msg("%s: %s", solver, rad_context_error(ctx));
    return s;
}

static rad_image *render(rad_solution *s, const rad_camera *camera)
{
    rad_render_options ro = {0};
    ro.width = 48;
    ro.height = 40;
    ro.samples = 2;
    ro.camera = camera;
    rad_image *image = NULL;
    if (rad_solution_render(ctx, s, &ro, &image) != RAD_OK)
        fail_msg("render: %s", rad_context_error(ctx));
    return image;
}

static void assert_same_image(const rad_image *a, const rad_image *b)
{
    assert_int_equal(rad_image_width(a), rad_image_width(b));
    assert_int_equal(rad_image_height(a), rad_image_height(b));
    size_t n = 3 * (size_t)rad_image_width(a) * (size_t)rad_image_height(a);
    assert_memory_equal(rad_image_pixels(a), rad_image_pixels(b), n * sizeof(float));
}

/* Save, load, and compare everything a program can ask of the two. */
static void test_round_trip(void **state)
{
    (void)state;
    static const char *const solvers[4] = {"gauss-seidel", "shooting", "hierarchical", "direct"};
    const rad_camera side = {{0.05, 0.3, -0.4}, {0.3, 0.2, 0.3}, {0, 1, 0}, 55.0};
    for (int k = 0; k < 4; k++) {
        rad_scene *scene = NULL, *scene2 = NULL;
        rad_solution *s = solved_cornell(&scene, solvers[k]), *s2 = NULL;
        if (rad_solution_save(ctx, s, path) != RAD_OK)
            fail_msg("save: %s", rad_context_error(ctx));
        assert_true(rad_file_is_solution(path));
        if (rad_solution_load_file(ctx, path, &scene2, &s2) != RAD_OK)
            fail_msg("%s: load: %s", solvers[k], rad_context_error(ctx));
        /* The scene: names, areas, camera, and the file as its one input. */
        assert_int_equal(rad_scene_surface_count(scene2), rad_scene_surface_count(scene));
        for (size_t i = 0; i < rad_scene_surface_count(scene); i++) {
            assert_string_equal(rad_scene_surface_name(scene2, i), rad_scene_surface_name(scene, i));
            assert_true(rad_scene_surface_area(scene2, i) == rad_scene_surface_area(scene, i));
        }
        rad_camera c1, c2;
        assert_true(rad_scene_camera(scene, &c1) && rad_scene_camera(scene2, &c2));
        assert_memory_equal(&c1, &c2, sizeof c1);
        assert_int_equal(rad_scene_input_count(scene2), 1);
        assert_string_equal(rad_scene_input_path(scene2, 0), path);
        /* The values, to the bit. */
        size_t n = rad_solution_element_count(s);
        assert_int_equal(rad_solution_element_count(s2), n);
        for (size_t i = 0; i < n; i++) {
            double r1[3], e1[3], b1[3], r2[3], e2[3], b2[3];
            assert_true(rad_solution_element_values(s, i, r1, e1, b1));
            assert_true(rad_solution_element_values(s2, i, r2, e2, b2));
            assert_memory_equal(b1, b2, sizeof b1);
            assert_memory_equal(r1, r2, sizeof r1);
            assert_memory_equal(e1, e2, sizeof e1);
            assert_true(rad_solution_element_area(s, i) == rad_solution_element_area(s2, i));
            assert_int_equal(rad_solution_element_surface(s, i), rad_solution_element_surface(s2, i));
        }
        size_t V = rad_solution_vertex_count(s);
        assert_int_equal(rad_solution_vertex_count(s2), V);
        double *v1 = malloc(3 * V * sizeof *v1), *v2 = malloc(3 * V * sizeof *v2);
        assert_int_equal(rad_solution_vertex_radiosity(ctx, s, v1), RAD_OK);
        assert_int_equal(rad_solution_vertex_radiosity(ctx, s2, v2), RAD_OK);
        assert_memory_equal(v1, v2, 3 * V * sizeof *v1);
        free(v1);
        free(v2);
        double em1, ab1, em2, ab2;
        rad_solution_power(s, &em1, &ab1);
        rad_solution_power(s2, &em2, &ab2);
        assert_true(em1 == em2);
        assert_true(fabs(ab1 - ab2) <= 1e-12 * ab1); /* through the header's JSON */
        assert_true(rad_solution_converged(s2));
        assert_int_equal(rad_solution_iterations(s2), rad_solution_iterations(s));
        /* The same pictures, from the scene's camera and from another. */
        rad_image *a = render(s, NULL), *b = render(s2, NULL);
        assert_same_image(a, b);
        rad_image_destroy(a);
        rad_image_destroy(b);
        a = render(s, &side);
        b = render(s2, &side);
        assert_same_image(a, b);
        rad_image_destroy(a);
        rad_image_destroy(b);
        /* Solved already: a solve changes nothing. */
        assert_int_equal(rad_solution_solve(ctx, s2), RAD_OK);
        double B[3], B2[3];
        rad_solution_surface_radiosity(s, 2, B);
        rad_solution_surface_radiosity(s2, 2, B2);
        assert_memory_equal(B, B2, sizeof B);
        rad_solution_destroy(s2);
        rad_scene_destroy(scene2);
        rad_solution_destroy(s);
        rad_scene_destroy(scene);
    }
}

/* The bytes of a saved Cornell box. */
static unsigned char *saved_bytes(size_t *size, const char *solver)
{
    rad_scene *scene = NULL;
    rad_solution *s = solved_cornell(&scene, solver);
    assert_int_equal(rad_solution_save(ctx, s, path), RAD_OK);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    *size = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *data = malloc(*size);
    assert_true(fread(data, 1, *size, f) == *size);
    fclose(f);
    return data;
}

/* Loading `data` fails with `code`, one line naming the file, and `needle`. */
static void assert_refused(const unsigned char *data, size_t size, rad_result code, const char *needle)
{
    rad_scene *scene = (rad_scene *)1;
    rad_solution *s = (rad_solution *)1;
    rad_result r = rad_solution_load_memory(ctx, "damaged.radsol", data, size, &scene, &s);
    if (r != code)
        fail_msg("expected %s, got %s: %s", rad_result_string(code), rad_result_string(r),
                 rad_context_error(ctx));
    assert_null(scene);
    assert_null(s);
    const char *msg = rad_context_error(ctx);
    assert_true(strncmp(msg, "damaged.radsol", 14) == 0);
    assert_null(strchr(msg, '\n'));
    if (needle && !strstr(msg, needle))
        fail_msg("'%s' lacks '%s'", msg, needle);
}

/* Where the payload starts, and the header's text. */
static size_t payload_start(const unsigned char *data)
{
    uint32_t h = (uint32_t)data[8] | (uint32_t)data[9] << 8 | (uint32_t)data[10] << 16 | (uint32_t)data[11] << 24;
    return (12 + h + 7) / 8 * 8;
}

/* Write the payload's checksum into the header again (after damage to the
 * payload that the structural checks, not the checksum, must catch). */
static void rechecksum(unsigned char *data, size_t size)
{
    size_t at = payload_start(data);
    char hex[17];
    snprintf(hex, sizeof hex, "%016" PRIx64, rad_fnv1a(RAD_FNV_OFFSET, data + at, size - at));
    char *key = strstr((char *)data + 12, "\"fnv1a64\":");
    assert_non_null(key);
    char *quote = strchr(key + 10, '"');
    memcpy(quote + 1, hex, 16);
}

static void test_damage(void **state)
{
    (void)state;
    size_t size;
    unsigned char *good = saved_bytes(&size, "hierarchical");
    unsigned char *data = malloc(size);
    rad_scene *scene = NULL;
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_load_memory(ctx, "good.radsol", good, size, &scene, &s), RAD_OK);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);

    /* Every truncation (in steps, and the last bytes one by one). */
    for (size_t cut = 0; cut < size; cut += cut + 40 < size ? 97 : 1)
        assert_refused(good, cut, RAD_ERROR_PARSE, NULL);
    /* Not a solution file; another version; a header longer than the file. */
    memcpy(data, good, size);
    data[1] = 'X';
    assert_refused(data, size, RAD_ERROR_PARSE, "not a radiosity solution file");
    memcpy(data, good, size);
    char *version = strstr((char *)data + 12, "\"version\":\t1");
    assert_non_null(version);
    version[11] = '2';
    assert_refused(data, size, RAD_ERROR_PARSE, "format version 2 is not read");
    memcpy(data, good, size);
    data[11] = 0x7f;
    assert_refused(data, size, RAD_ERROR_PARSE, "the header claims");
    /* A forged count: the payload no longer matches. */
    memcpy(data, good, size);
    char *elements = strstr((char *)data + 12, "\"elements\":\t");
    assert_non_null(elements);
    elements[12] = elements[12] == '9' ? '8' : (char)(elements[12] + 1);
    assert_refused(data, size, RAD_ERROR_PARSE, "the payload should hold");
    /* A flipped byte anywhere in the payload: the checksum. */
    size_t at = payload_start(good);
    for (size_t k = at; k < size; k += (size - at) / 37 + 1) {
        memcpy(data, good, size);
        data[k] ^= 0x10;
        assert_refused(data, size, RAD_ERROR_PARSE, "checksum");
    }
    /* Behind a recomputed checksum, the structure is checked itself:
     * a flipped byte in each place of the payload never crashes, never
     * loads an element out of range, and is refused unless harmless (the
     * low bits of a coordinate or value, which load as what they say).
     * Counted: most are refused. */
    int refused = 0, tried = 0;
    for (size_t k = at; k < size; k += (size - at) / 400 | 1, tried++) {
        memcpy(data, good, size);
        data[k] ^= 0x80;
        rechecksum(data, size);
        rad_result r = rad_solution_load_memory(ctx, "damaged.radsol", data, size, &scene, &s);
        if (r == RAD_OK) {
            rad_image *image = render(s, NULL); /* loads: it must render finite values */
            const float *px = rad_image_pixels(image);
            for (int p = 0; p < 3 * 48 * 40; p++)
                assert_true(isfinite(px[p]) && px[p] >= 0.0f);
            rad_image_destroy(image);
            rad_solution_destroy(s);
            rad_scene_destroy(scene);
        } else {
            assert_null(strchr(rad_context_error(ctx), '\n'));
            refused++;
        }
    }
    printf("structural damage: %d of %d refused\n", refused, tried);
    assert_true(refused > tried / 4);
    free(data);
    free(good);
}

static void test_refusals(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    rad_options o = {0};
    o.target_elements = 50;
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    unlink(path);
    assert_int_equal(rad_solution_save(ctx, s, path), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "not solved"));
    assert_false(rad_file_is_solution(path)); /* nothing written */
    assert_int_equal(rad_solution_save(NULL, s, path), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_save(ctx, NULL, path), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_save(ctx, s, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_solution *s2 = (rad_solution *)1;
    rad_scene *scene2 = (rad_scene *)1;
    assert_int_equal(rad_solution_load_file(ctx, "/nonexistent/x.radsol", &scene2, &s2), RAD_ERROR_IO);
    assert_null(s2);
    assert_null(scene2);
    assert_int_equal(rad_solution_load_file(NULL, path, &scene2, &s2), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_load_file(ctx, NULL, &scene2, &s2), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_load_file(ctx, path, NULL, &s2), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_load_file(ctx, path, &scene2, NULL), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_load_memory(ctx, NULL, "x", 1, &scene2, &s2), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_load_memory(ctx, "x", NULL, 1, &scene2, &s2), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_load_memory(ctx, "x", "", 0, &scene2, &s2), RAD_ERROR_PARSE);
    assert_false(rad_file_is_solution(NULL));
    assert_false(rad_file_is_solution("/tmp"));
    assert_false(rad_file_is_solution("/nonexistent"));
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_damage),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
