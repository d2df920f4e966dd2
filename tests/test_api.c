/*
 * test_api.c -- the public header as a contract, used as a program outside
 * the library would (it includes radiosity.h and nothing internal): the
 * run-time version agrees with the header's macros, and every public
 * function given a NULL pointer does what radiosity.h says, "NULL":
 * fallible calls return RAD_ERROR_INVALID_ARGUMENT, name themselves in the
 * context's message, set *out to NULL and write no file; accessors return
 * their neutral value; destroying NULL does nothing.  Under the sanitizer
 * build a crash or a leak on any of these paths fails the suite.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "test_support.h"

#include <radiosity.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* A non-NULL pointer the calls must overwrite with NULL on failure. */
static char sentinel;
#define NOT_NULL(type) ((type *)(void *)&sentinel)

/* `result` is RAD_ERROR_INVALID_ARGUMENT and, where there is a context, its
 * message names the function. */
static void check_invalid(rad_result result, const rad_context *ctx, const char *function,
                          const char *file, int line)
{
    if (result != RAD_ERROR_INVALID_ARGUMENT) {
        print_error("%s returned %s, expected RAD_ERROR_INVALID_ARGUMENT\n", function,
                    rad_result_string(result));
        _fail(file, line);
    }
    if (ctx && !strstr(rad_context_error(ctx), function)) {
        print_error("message \"%s\" does not name %s\n", rad_context_error(ctx), function);
        _fail(file, line);
    }
}
#define assert_invalid(result, ctx, function) \
    check_invalid((result), (ctx), (function), __FILE__, __LINE__)

/* One small solved scene the NULL tests need real objects from. */
typedef struct api_fixture {
    rad_context *ctx;
    rad_scene *scene;
    rad_solution *solution;
    rad_image *image;
} api_fixture;

static int fixture_setup(void **state)
{
    api_fixture *f = calloc(1, sizeof *f);
    if (!f || rad_context_create(NULL, &f->ctx) != RAD_OK ||
        rad_scene_create_cornell_box(f->ctx, &f->scene) != RAD_OK)
        return -1;
    rad_options options = {0};
    options.target_elements = 60; /* enough to have every surface meshed; fast */
    rad_render_options render = {0};
    render.width = render.height = 8;
    render.samples = 1;
    if (rad_solution_create(f->ctx, f->scene, &options, &f->solution) != RAD_OK ||
        rad_solution_solve(f->ctx, f->solution) != RAD_OK ||
        rad_solution_render(f->ctx, f->solution, &render, &f->image) != RAD_OK)
        return -1;
    *state = f;
    return 0;
}

static int fixture_teardown(void **state)
{
    api_fixture *f = *state;
    rad_image_destroy(f->image);
    rad_solution_destroy(f->solution);
    rad_scene_destroy(f->scene);
    rad_context_destroy(f->ctx);
    free(f);
    return 0;
}

/* ---- version ---- */

static void test_version(void **unused)
{
    (void)unused;
    assert_string_equal(rad_version(), RAD_VERSION_STRING);
    assert_int_equal(rad_version_number(), RAD_VERSION_NUMBER);
    assert_int_equal(RAD_VERSION_NUMBER,
                     RAD_VERSION_MAJOR * 1000000 + RAD_VERSION_MINOR * 1000 + RAD_VERSION_PATCH);
    char text[32];
    snprintf(text, sizeof text, "%d.%d.%d", RAD_VERSION_MAJOR, RAD_VERSION_MINOR,
             RAD_VERSION_PATCH);
    assert_string_equal(text, RAD_VERSION_STRING);
}

/* ---- context and results ---- */

static void test_null_context(void **unused)
{
    (void)unused;
    assert_int_equal(rad_context_create(NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_context_options negative = {0};
    negative.threads = -1;
    rad_context *ctx = NOT_NULL(rad_context);
    assert_int_equal(rad_context_create(&negative, &ctx), RAD_ERROR_INVALID_ARGUMENT);
    assert_null(ctx);
    rad_context_destroy(NULL);
    assert_string_equal(rad_context_error(NULL), "");
    assert_int_equal(rad_context_threads(NULL), 1);
    rad_context_cancel(NULL, true);
    assert_false(rad_context_cancelled(NULL));

    assert_string_equal(rad_result_string(RAD_ERROR_INVALID_ARGUMENT), "RAD_ERROR_INVALID_ARGUMENT");
    assert_string_equal(rad_result_string(RAD_ERROR_NUMERICAL), "RAD_ERROR_NUMERICAL");
    assert_string_equal(rad_result_string((rad_result)99), "RAD_ERROR_UNKNOWN");
}

/* ---- scenes ---- */

static void test_null_scene(void **state)
{
    api_fixture *f = *state;
    rad_context *ctx = f->ctx;
    const char *obj = test_path("scene.obj");
    const char text[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

    rad_scene *scene = NOT_NULL(rad_scene);
    assert_invalid(rad_scene_load_file(NULL, obj, &scene), NULL, "rad_scene_load_file");
    assert_null(scene);
    assert_invalid(rad_scene_load_file(ctx, NULL, &scene), ctx, "rad_scene_load_file");
    assert_invalid(rad_scene_load_file(ctx, obj, NULL), ctx, "rad_scene_load_file");

    scene = NOT_NULL(rad_scene);
    assert_invalid(rad_scene_load_memory(NULL, "x.obj", text, sizeof text - 1, NULL, 0, &scene),
                   NULL, "rad_scene_load_memory");
    assert_null(scene);
    assert_invalid(rad_scene_load_memory(ctx, NULL, text, sizeof text - 1, NULL, 0, &scene), ctx,
                   "rad_scene_load_memory");
    assert_invalid(rad_scene_load_memory(ctx, "x.obj", NULL, 5, NULL, 0, &scene), ctx,
                   "rad_scene_load_memory");
    assert_invalid(rad_scene_load_memory(ctx, "x.obj", text, sizeof text - 1, NULL, 5, &scene),
                   ctx, "rad_scene_load_memory");
    assert_invalid(rad_scene_load_memory(ctx, "x.obj", text, sizeof text - 1, NULL, 0, NULL), ctx,
                   "rad_scene_load_memory");

    scene = NOT_NULL(rad_scene);
    assert_invalid(rad_scene_create_cornell_box(NULL, &scene), NULL, "rad_scene_create_cornell_box");
    assert_null(scene);
    assert_invalid(rad_scene_create_cornell_box(ctx, NULL), ctx, "rad_scene_create_cornell_box");

    scene = NOT_NULL(rad_scene);
    assert_invalid(rad_scene_generate_office(NULL, NULL, &scene), NULL, "rad_scene_generate_office");
    assert_null(scene);
    assert_invalid(rad_scene_generate_office(ctx, NULL, NULL), ctx, "rad_scene_generate_office");

    assert_invalid(rad_scene_write_obj(NULL, f->scene, obj), NULL, "rad_scene_write_obj");
    assert_invalid(rad_scene_write_obj(ctx, NULL, obj), ctx, "rad_scene_write_obj");
    assert_invalid(rad_scene_write_obj(ctx, f->scene, NULL), ctx, "rad_scene_write_obj");
    assert_invalid(rad_scene_write_obj(ctx, f->scene, ""), ctx, "rad_scene_write_obj");
    assert_false(test_file_exists(obj));

    rad_scene_destroy(NULL);
    assert_int_equal(rad_scene_surface_count(NULL), 0);
    assert_null(rad_scene_surface_name(NULL, 0));
    assert_null(rad_scene_surface_name(f->scene, rad_scene_surface_count(f->scene)));
    assert_true(rad_scene_surface_area(NULL, 0) == 0.0);
    assert_true(rad_scene_surface_area(f->scene, rad_scene_surface_count(f->scene)) == 0.0);
    assert_int_equal(rad_scene_polygon_count(NULL), 0);

    rad_camera camera = {{1, 2, 3}, {4, 5, 6}, {0, 1, 0}, 40};
    assert_false(rad_scene_camera(NULL, &camera));
    assert_true(camera.position[0] == 1.0); /* untouched */
    assert_false(rad_scene_camera(f->scene, NULL));
    assert_invalid(rad_camera_from_string(NULL, "0,0,0,0,0,1", &camera), NULL,
                   "rad_camera_from_string");
    assert_invalid(rad_camera_from_string(ctx, NULL, &camera), ctx, "rad_camera_from_string");
    assert_invalid(rad_camera_from_string(ctx, "0,0,0,0,0,1", NULL), ctx, "rad_camera_from_string");
    assert_true(camera.position[0] == 1.0);
}

/* ---- solutions ---- */

static void test_null_solution(void **state)
{
    api_fixture *f = *state;
    rad_context *ctx = f->ctx;
    const rad_solution *s = f->solution;

    rad_solution *solution = NOT_NULL(rad_solution);
    assert_invalid(rad_solution_create(NULL, f->scene, NULL, &solution), NULL, "rad_solution_create");
    assert_null(solution);
    solution = NOT_NULL(rad_solution);
    assert_invalid(rad_solution_create(ctx, NULL, NULL, &solution), ctx, "rad_solution_create");
    assert_null(solution);
    assert_invalid(rad_solution_create(ctx, f->scene, NULL, NULL), ctx, "rad_solution_create");
    assert_invalid(rad_solution_solve(NULL, f->solution), NULL, "rad_solution_solve");
    assert_invalid(rad_solution_solve(ctx, NULL), ctx, "rad_solution_solve");
    rad_solution_destroy(NULL);

    assert_int_equal(rad_solution_element_count(NULL), 0);
    assert_true(isnan(rad_solution_residual(NULL)));
    assert_int_equal(rad_solution_iterations(NULL), 0);
    assert_false(rad_solution_converged(NULL));
    assert_string_equal(rad_solution_warning(NULL), "");
    size_t count = 7;
    assert_null(rad_solution_history(NULL, &count));
    assert_int_equal(count, 0);
    assert_null(rad_solution_history(s, NULL));
    assert_non_null(rad_solution_history(s, &count));
    assert_true(count > 0);

    double rgb[3] = {7, 7, 7};
    rad_solution_surface_radiosity(NULL, 0, rgb);
    assert_true(rgb[0] == 0.0 && rgb[1] == 0.0 && rgb[2] == 0.0);
    rgb[0] = rgb[1] = rgb[2] = 7;
    rad_solution_surface_radiosity(s, rad_scene_surface_count(f->scene), rgb);
    assert_true(rgb[0] == 0.0 && rgb[1] == 0.0 && rgb[2] == 0.0);
    rad_solution_surface_radiosity(s, 0, NULL);

    double F[1] = {7};
    rad_solution_surface_view_factors(NULL, F);
    assert_true(F[0] == 7.0); /* untouched: the surface count is unknown */
    rad_solution_surface_view_factors(s, NULL);

    double emitted = 7, absorbed = 7;
    rad_solution_power(NULL, &emitted, &absorbed);
    assert_true(isnan(emitted) && isnan(absorbed));
    rad_solution_power(s, NULL, &absorbed);
    assert_true(absorbed > 0.0);
    rad_solution_power(s, &emitted, NULL);
    assert_true(emitted > 0.0);
    rad_solution_power(s, NULL, NULL);

    const char *history = test_path("history.csv");
    assert_invalid(rad_solution_write_history(NULL, s, history), NULL, "rad_solution_write_history");
    assert_invalid(rad_solution_write_history(ctx, NULL, history), ctx, "rad_solution_write_history");
    assert_invalid(rad_solution_write_history(ctx, s, NULL), ctx, "rad_solution_write_history");
    assert_false(test_file_exists(history));

    const char *stats = test_path("stats.json");
    assert_invalid(rad_solution_write_stats(NULL, s, stats, false), NULL, "rad_solution_write_stats");
    assert_invalid(rad_solution_write_stats(ctx, NULL, stats, false), ctx, "rad_solution_write_stats");
    assert_invalid(rad_solution_write_stats(ctx, s, NULL, true), ctx, "rad_solution_write_stats");
    assert_false(test_file_exists(stats));

    const char *vf = test_path("vf.json");
    assert_invalid(rad_solution_write_view_factors(NULL, s, vf, false), NULL,
                   "rad_solution_write_view_factors");
    assert_invalid(rad_solution_write_view_factors(ctx, NULL, vf, false), ctx,
                   "rad_solution_write_view_factors");
    assert_invalid(rad_solution_write_view_factors(ctx, s, NULL, true), ctx,
                   "rad_solution_write_view_factors");
    assert_false(test_file_exists(vf));

    rad_stream_options so = {0};
    rad_stream_stats st;
    const char *fn = "rad_scene_stream_view_factors";
    assert_invalid(rad_scene_stream_view_factors(NULL, f->scene, NULL, &so, vf, &st), NULL, fn);
    assert_invalid(rad_scene_stream_view_factors(ctx, NULL, NULL, &so, vf, &st), ctx, fn);
    assert_invalid(rad_scene_stream_view_factors(ctx, f->scene, NULL, NULL, vf, &st), ctx, fn);
    assert_invalid(rad_scene_stream_view_factors(ctx, f->scene, NULL, &so, NULL, &st), ctx, fn);
    assert_invalid(rad_scene_stream_view_factors(ctx, f->scene, NULL, &so, vf, NULL), ctx, fn);
    assert_false(test_file_exists(vf));

    const char *lit = test_path("lit.glb");
    assert_invalid(rad_solution_write_mesh(NULL, s, lit, 0.0), NULL, "rad_solution_write_mesh");
    assert_invalid(rad_solution_write_mesh(ctx, NULL, lit, 0.0), ctx, "rad_solution_write_mesh");
    assert_invalid(rad_solution_write_mesh(ctx, s, NULL, 1.0), ctx, "rad_solution_write_mesh");
    assert_false(test_file_exists(lit));

    /* Element and vertex accessors: NULL solution or output writes nothing. */
    double xyz[3] = {7, 7, 7}, rgb3[3] = {7, 7, 7};
    size_t corners[4] = {7, 7, 7, 7};
    assert_int_equal(rad_solution_vertex_count(NULL), 0);
    assert_int_equal(rad_solution_link_count(NULL), 0);
    assert_false(rad_solution_vertex_position(NULL, 0, xyz));
    assert_false(rad_solution_vertex_position(s, 0, NULL));
    assert_int_equal(rad_solution_element_vertices(NULL, 0, corners), 0);
    assert_int_equal(rad_solution_element_vertices(s, 0, NULL), 0);
    assert_int_equal(rad_solution_element_surface(NULL, 0), SIZE_MAX);
    assert_true(rad_solution_element_area(NULL, 0) == 0.0);
    assert_false(rad_solution_element_geometry(NULL, 0, xyz, xyz));
    assert_true(rad_solution_element_geometry(s, 0, NULL, NULL));
    assert_false(rad_solution_element_values(NULL, 0, rgb3, rgb3, rgb3));
    assert_true(rad_solution_element_values(s, 0, NULL, NULL, NULL));
    assert_true(xyz[0] == 7.0 && rgb3[0] == 7.0 && corners[0] == 7);
    double *vertex_rgb = calloc(3 * rad_solution_vertex_count(s), sizeof *vertex_rgb);
    assert_invalid(rad_solution_vertex_radiosity(NULL, s, vertex_rgb), NULL, "rad_solution_vertex_radiosity");
    assert_invalid(rad_solution_vertex_radiosity(ctx, NULL, vertex_rgb), ctx, "rad_solution_vertex_radiosity");
    assert_invalid(rad_solution_vertex_radiosity(ctx, s, NULL), ctx, "rad_solution_vertex_radiosity");
    assert_invalid(rad_solution_display_radiosity(NULL, s, true, NULL, vertex_rgb), NULL,
                   "rad_solution_display_radiosity");
    assert_invalid(rad_solution_display_radiosity(ctx, NULL, true, NULL, vertex_rgb), ctx,
                   "rad_solution_display_radiosity");
    assert_invalid(rad_solution_display_radiosity(ctx, s, true, NULL, NULL), ctx, "rad_solution_display_radiosity");
    assert_int_equal(rad_solution_display_radiosity(ctx, s, true, NULL, vertex_rgb), RAD_OK);
    free(vertex_rgb);

    const char *partial = test_path("partial.json");
    assert_invalid(rad_scene_write_interrupted_stats(NULL, f->scene, "mesh", 1.0, partial), NULL,
                   "rad_scene_write_interrupted_stats");
    assert_invalid(rad_scene_write_interrupted_stats(ctx, NULL, "mesh", 1.0, partial), ctx,
                   "rad_scene_write_interrupted_stats");
    assert_invalid(rad_scene_write_interrupted_stats(ctx, f->scene, NULL, 1.0, partial), ctx,
                   "rad_scene_write_interrupted_stats");
    assert_invalid(rad_scene_write_interrupted_stats(ctx, f->scene, "mesh", 1.0, NULL), ctx,
                   "rad_scene_write_interrupted_stats");
    assert_false(test_file_exists(partial));
}

/* ---- images ---- */

static void test_null_image(void **state)
{
    api_fixture *f = *state;
    rad_context *ctx = f->ctx;

    rad_image *image = NOT_NULL(rad_image);
    assert_invalid(rad_solution_render(NULL, f->solution, NULL, &image), NULL, "rad_solution_render");
    assert_null(image);
    image = NOT_NULL(rad_image);
    assert_invalid(rad_solution_render(ctx, NULL, NULL, &image), ctx, "rad_solution_render");
    assert_null(image);
    assert_invalid(rad_solution_render(ctx, f->solution, NULL, NULL), ctx, "rad_solution_render");

    rad_image_destroy(NULL);
    assert_int_equal(rad_image_width(NULL), 0);
    assert_int_equal(rad_image_height(NULL), 0);
    assert_null(rad_image_pixels(NULL));
    assert_true(rad_image_auto_exposure(NULL) == 1.0);
    float pixel[3] = {1.0f, 2.0f, 3.0f};
    rad_image *made = (rad_image *)&made; /* not NULL: the call must set it */
    assert_invalid(rad_image_from_pixels(NULL, 1, 1, pixel, &made), NULL, "rad_image_from_pixels");
    assert_null(made);
    made = (rad_image *)&made;
    assert_invalid(rad_image_from_pixels(ctx, 1, 1, NULL, &made), ctx, "rad_image_from_pixels");
    assert_null(made);
    assert_invalid(rad_image_from_pixels(ctx, 1, 1, pixel, NULL), ctx, "rad_image_from_pixels");
    assert_int_equal(rad_image_from_pixels(ctx, 1, 1, pixel, &made), RAD_OK);
    assert_true(rad_image_pixels(made)[2] == 3.0f);
    rad_image_destroy(made);

    const char *png = test_path("image.png");
    assert_invalid(rad_image_write(NULL, f->image, png), NULL, "rad_image_write");
    assert_invalid(rad_image_write(ctx, NULL, png), ctx, "rad_image_write");
    assert_invalid(rad_image_write(ctx, f->image, NULL), ctx, "rad_image_write");
    assert_invalid(rad_image_write_exposed(NULL, f->image, png, 1.0), NULL, "rad_image_write_exposed");
    assert_invalid(rad_image_write_exposed(ctx, NULL, png, 1.0), ctx, "rad_image_write_exposed");
    assert_invalid(rad_image_write_exposed(ctx, f->image, NULL, 1.0), ctx, "rad_image_write_exposed");
    assert_false(test_file_exists(png));
    /* The real objects work: the NULL checks turn nothing valid away. */
    assert_int_equal(rad_image_write(ctx, f->image, png), RAD_OK);
    assert_true(test_file_exists(png));
    remove(png);
}

/* ---- method registries ---- */

static void test_null_methods(void **unused)
{
    (void)unused;
    const char *name = NULL, *description = NULL;
    assert_true(rad_method_info(RAD_METHOD_SOLVER, 0, NULL, NULL));
    assert_true(rad_method_info(RAD_METHOD_SOLVER, 0, &name, NULL));
    assert_non_null(name);
    assert_true(rad_method_info(RAD_METHOD_FORM_FACTOR, 0, NULL, &description));
    assert_non_null(description);
    name = description = NULL;
    assert_false(rad_method_info(RAD_METHOD_VISIBILITY, 1000, &name, &description));
    assert_false(rad_method_info((rad_method_kind)99, 0, &name, &description));
    assert_null(name);
    assert_null(description);
    assert_int_equal(rad_method_capabilities(RAD_METHOD_SOLVER, NULL), 0);
    assert_int_equal(rad_method_capabilities(RAD_METHOD_SOLVER, "no-such-solver"), 0);
    assert_int_equal(rad_method_capabilities(RAD_METHOD_FORM_FACTOR, "analytic"), 0);
    assert_int_equal(rad_method_capabilities((rad_method_kind)99, "gauss-seidel"), 0);
}

/* ---- capabilities: what each solver's bits say it does, it does ---- */

/* A closed unit cube, faces inward, the ceiling emitting; `wall` the
 * material of the wall at z = 0. */
static rad_scene *closed_box(rad_context *ctx, const char *wall)
{
    char obj[1024];
    snprintf(obj, sizeof obj,
             "mtllib box.mtl\n"
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
             "o floor\nusemtl white\nf 1 5 6 2\no ceiling\nusemtl light\nf 4 3 7 8\n"
             "o back\nusemtl %s\nf 1 2 3 4\no front\nusemtl white\nf 5 8 7 6\n"
             "o left\nusemtl white\nf 1 4 8 5\no right\nusemtl white\nf 2 6 7 3\n",
             wall);
    const char *mtl = "newmtl white\nKd 0.5 0.5 0.5\n"
                      "newmtl light\nKd 0.5 0.5 0.5\nKe 1 1 1\n"
                      "newmtl mirror\nKd 0.1 0.1 0.1\nKs 0.8 0.8 0.8\nillum 3\n";
    rad_scene *scene = NULL;
    if (rad_scene_load_memory(ctx, "box.obj", obj, strlen(obj), mtl, strlen(mtl), &scene) != RAD_OK)
        fail_msg("%s", rad_context_error(ctx));
    return scene;
}

static void keep_warning(void *user, const char *message)
{
    snprintf(user, 512, "%s", message);
}

/* rad_solution_create's result for `solver` with `options` on `scene`;
 * the solution destroyed again. */
static rad_result try_create(rad_context *ctx, const rad_scene *scene, const char *solver, rad_options options)
{
    options.solver = solver;
    options.target_elements = 24;
    rad_solution *s = NULL;
    rad_result r = rad_solution_create(ctx, scene, &options, &s);
    rad_solution_destroy(s);
    return r;
}

static void test_capabilities(void **unused)
{
    (void)unused;
    char warning[512] = "";
    rad_context_options co = {0};
    co.on_warning = keep_warning;
    co.warning_user = warning;
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(&co, &ctx), RAD_OK);
    rad_scene *plain = closed_box(ctx, "white"), *mirror = closed_box(ctx, "mirror");
    rad_scene *lit = closed_box(ctx, "white");
    const char *sky = "{\"sky\": {\"type\": 5, \"diffuse_illuminance\": 10000}}";
    assert_int_equal(rad_scene_daylight_load_memory(ctx, lit, "sky.json", sky, strlen(sky)), RAD_OK);
    const char *name;
    size_t with_f = 0;
    for (size_t i = 0; rad_method_info(RAD_METHOD_SOLVER, i, &name, NULL); i++) {
        unsigned can = rad_method_capabilities(RAD_METHOD_SOLVER, name);
        print_message("%-26s %#x\n", name, can);
        assert_int_not_equal(can, 0);
        assert_false((can & RAD_CAN_MIRRORS) && (can & RAD_REFUSES_MIRRORS));

        /* A stored F: the element-level view factors are written. */
        rad_options o = {0};
        o.solver = name;
        o.target_elements = 24;
        rad_solution *s = NULL;
        assert_int_equal(rad_solution_create(ctx, plain, &o, &s), RAD_OK);
        size_t before = rad_solution_element_count(s);
        assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
        if (can & RAD_HAS_UNIFORM_MESH)
            assert_int_equal(rad_solution_element_count(s), before);
        rad_result r = rad_solution_write_view_factors(ctx, s, test_path("vf.csv"), true);
        assert_int_equal(r == RAD_OK, (can & RAD_HAS_FORM_FACTORS) != 0);
        with_f += r == RAD_OK;
        remove(test_path("vf.csv"));
        rad_solution_destroy(s);

        rad_options adaptive = {0}, closure = {0};
        adaptive.adaptive_levels = 1;
        closure.closure_correction = 1;
        r = try_create(ctx, plain, name, adaptive);
        assert_int_equal(r, (can & RAD_CAN_ADAPTIVE) ? RAD_OK : RAD_ERROR_INVALID_ARGUMENT);
        r = try_create(ctx, plain, name, closure);
        assert_int_equal(r, (can & RAD_CAN_CLOSURE_CORRECTION) ? RAD_OK : RAD_ERROR_INVALID_ARGUMENT);
        r = try_create(ctx, lit, name, (rad_options){0});
        assert_int_equal(r, (can & RAD_CAN_LIGHTS) ? RAD_OK : RAD_ERROR_INVALID_ARGUMENT);

        /* Mirrors: carried, refused, or the diffuse part alone with a warning. */
        warning[0] = '\0';
        r = try_create(ctx, mirror, name, (rad_options){0});
        assert_int_equal(r, (can & RAD_REFUSES_MIRRORS) ? RAD_ERROR_INVALID_ARGUMENT : RAD_OK);
        bool warned = strstr(warning, "does not carry light through mirrors") != NULL;
        assert_int_equal(warned, r == RAD_OK && !(can & RAD_CAN_MIRRORS));
    }
    assert_int_equal(with_f, 5); /* the linear solvers of the dense strategy */
    assert_int_equal(rad_method_capabilities(RAD_METHOD_SOLVER, "southwell") & (RAD_CAN_MIRRORS | RAD_REFUSES_MIRRORS),
                     RAD_REFUSES_MIRRORS);
    rad_scene_destroy(plain);
    rad_scene_destroy(mirror);
    rad_scene_destroy(lit);
    rad_context_destroy(ctx);
}

int main(void)
{
    if (test_workdir_make("api") != 0) {
        perror("mkdtemp");
        return 1;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_version),
        cmocka_unit_test(test_null_context),
        cmocka_unit_test(test_null_scene),
        cmocka_unit_test(test_null_solution),
        cmocka_unit_test(test_null_image),
        cmocka_unit_test(test_null_methods),
        cmocka_unit_test(test_capabilities),
    };
    int failed = cmocka_run_group_tests(tests, fixture_setup, fixture_teardown);
    test_workdir_remove();
    return failed;
}
