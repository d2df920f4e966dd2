/*
 * test_alloc.c -- the context's allocator (core.c): the memory limit, the
 * accounting by category, and every allocation failing in turn.
 *
 * The sweep is SQLite's way of testing out-of-memory handling: run a small
 * scene through loading and every strategy with all its outputs once,
 * counting the allocations N; then for k = 1..N run it again with the
 * k-th allocation failing.  Every run must end with RAD_ERROR_OUT_OF_MEMORY
 * and the allocator's one-line message (not a later consequence, and not
 * success with something quietly missing), leave no file but those of the
 * writers that had finished, and give all its memory back (the accounting
 * returns to 0; the sanitizer build checks for leaks and bad frees).
 *
 *   test_alloc                        the allocator's cases, no sweep (the quick run)
 *   test_alloc --every N [--offset R] and the k = R+1, R+1+N, R+1+2N, ... of each
 *                                     sweep (the sanitizer build's quick run:
 *                                     --every 97; CTest test_alloc_full_1 and _2,
 *                                     label slow: --every 2 --offset 0 and 1)
 *   test_alloc --full                 and every k (= --every 1)
 */
#include "api/solution.h"

#include <cjson/cJSON.h>
#include <dirent.h>
#include <fcntl.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

static int stride = 1, offset = 0; /* --every N --offset R */

/* ---- the scene: a closed unit box, normals inward, a glowing ceiling ---- */

static const char box_obj[] = "mtllib box.mtl\n"
                              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                              "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                              "usemtl white\n"
                              "o floor\nf 1 5 6 2\n"
                              "o back\nf 1 2 3 4\n"
                              "o front\nf 5 8 7 6\n"
                              "o left\nf 1 4 8 5\n"
                              "o right\nf 2 6 7 3\n"
                              "usemtl lamp\n"
                              "o ceiling\nf 4 3 7 8\n";

static const char box_mtl[] = "newmtl white\nKd 0.5 0.5 0.5\n"
                              "newmtl lamp\nKd 0.3 0.3 0.3\nKe 1 1 1\n";
static const char mirror_mtl[] = "newmtl white\nKd 0.1 0.1 0.1\nKs 0.8 0.8 0.8\nillum 3\n"
                                 "newmtl lamp\nKd 0.3 0.3 0.3\nKe 1 1 1\n";

/* A textured floor (map_Kd, an 8 x 8 checker PNG) under a lamp: the
 * texture's reading, its texels and the coordinates' maps. */
static const char textured_obj[] = "mtllib textured.mtl\n"
                                   "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                   "v 0.3 1 0.3\nv 0.7 1 0.3\nv 0.7 1 0.7\nv 0.3 1 0.7\n"
                                   "o floor\nusemtl floor\nf 1/1 4/4 3/3 2/2\no lamp\nusemtl lamp\nf 5 6 7 8\n";
static const char textured_mtl[] = "newmtl floor\nKd 0.9 0.9 0.9\nmap_Kd checker.png\n"
                                   "newmtl lamp\nKd 0 0 0\nKe 1 1 1\n";
static const unsigned char checker_png[] = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
    0x44, 0x52, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00, 0x00, 0x08, 0x08, 0x02, 0x00, 0x00,
    0x00, 0x4b, 0x6d, 0x29, 0xdc, 0x00, 0x00, 0x00, 0x19, 0x49, 0x44, 0x41, 0x54, 0x78,
    0x9c, 0x63, 0xb0, 0xb1, 0xb1, 0x79, 0xf6, 0xec, 0x19, 0x26, 0xc9, 0x80, 0x55, 0x14,
    0x48, 0x32, 0x0c, 0x4a, 0x1d, 0x00, 0x7e, 0x3e, 0x6c, 0xc1, 0x4e, 0x2c, 0xd7, 0xe5,
    0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82,
};

/* One emissive triangle, positions only (no indices), in a data URI. */
static const char triangle_gltf[] =
    "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],\n"
    " \"nodes\": [{\"name\": \"lamp\", \"mesh\": 0}],\n"
    " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"material\": 0}]}],\n"
    " \"materials\": [{\"emissiveFactor\": [1, 1, 1],\n"
    "                \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1]}}],\n"
    " \"buffers\": [{\"byteLength\": 36,\n"
    "              \"uri\": \"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],\n"
    " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}],\n"
    " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\",\n"
    "                \"min\": [0, 0, 0], \"max\": [1, 1, 0]}]}\n";

/* ---- folders ---- */

static char input_dir[256], output_dir[256];

static void write_text(const char *dir, const char *name, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* Remove every file in the output folder. */
static void clear_outputs(void)
{
    DIR *dir = opendir(output_dir);
    assert_non_null(dir);
    for (struct dirent *e; (e = readdir(dir));) {
        char path[600];
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        snprintf(path, sizeof path, "%s/%s", output_dir, e->d_name);
        remove(path);
    }
    closedir(dir);
}

/* ---- one run: the outputs its writers finished ---- */

#define MAX_OUTPUTS 24

typedef struct outputs {
    const char *written[MAX_OUTPUTS]; /* names in the output folder */
    int count;
} outputs;

static rad_result write_done(rad_result r, outputs *out, const char *name)
{
    if (r == RAD_OK) {
        assert_true(out->count < MAX_OUTPUTS);
        out->written[out->count++] = name;
    }
    return r;
}

static void output_path(const char *name, char *path, size_t size)
{
    snprintf(path, size, "%s/%s", output_dir, name);
}

typedef struct scenario {
    const char *name;
    const char *solver;          /* NULL: loading only */
    const char *form_factors;
    int hemicube_resolution, samples, closure_correction;
    bool view_factors;           /* the strategy keeps F */
    int adaptive_levels;
    bool mirror;                 /* the white walls mirrors (illum 3): both passes of two-pass */
    bool on_step;                /* an on_step that does nothing: the hierarchical leaves
                                    made at every round for display */
    bool luminaires;             /* a luminaire placed by a layout (tests/data/luminaires' IES) */
} scenario;

static int no_op_step(void *user, rad_solution *s, const rad_solve_step *step)
{
    (void)user, (void)s, (void)step;
    return 0;
}

static const scenario scenarios[] = {
    {"loading", NULL, NULL, 0, 0, 0, false, 0, false, false, false},
    {"gauss-seidel (dense, analytic)", "gauss-seidel", "analytic", 0, 0, 0, true, 0, false, false, false},
    {"direct (dense, hemicube, closure)", "direct", "hemicube", 16, 0, 1, true, 0, false, false, false},
    {"conjugate-gradient (dense, montecarlo)", "conjugate-gradient", "montecarlo", 0, 4, 0, true, 0, false, false, false},
    {"southwell (dense, hemisphere)", "southwell", "hemisphere", 0, 64, 0, true, 0, false, false, false},
    {"jacobi (dense, adaptive)", "jacobi", "analytic", 0, 0, 0, true, 2, false, false, false},
    {"shooting (matrix-free)", "shooting", NULL, 0, 32, 0, false, 0, false, false, false},
    {"hierarchical", "hierarchical", NULL, 0, 0, 1, false, 0, false, false, false},
    {"hierarchical (progressive display)", "hierarchical", NULL, 0, 0, 0, false, 0, false, true, false},
    {"galerkin-linear", "galerkin-linear", NULL, 0, 0, 0, false, 0, false, false, false},
    {"collocation", "collocation", NULL, 0, 0, 0, false, 0, false, false, false},
    {"instant-radiosity (virtual point lights)", "instant-radiosity", NULL, 0, 32, 0, false, 0, false, false, false},
    {"gauss-seidel (dense, mirror images, second pass)", "gauss-seidel", "analytic", 0, 0, 0, true, 0, true, false, false},
    {"gauss-seidel (dense, a luminaire)", "gauss-seidel", "analytic", 0, 0, 0, true, 0, false, false, true},
    {"hierarchical (a luminaire: the nodes' direct light)", "hierarchical", NULL, 0, 0, 0, false, 0, false, false, true},
};

/* Loading: the OBJ + MTL from a file and from memory, the glTF from
 * memory, the built-in Cornell box written as OBJ, a generated office. */
static rad_result run_loading(rad_context *ctx, outputs *out)
{
    char path[512];
    rad_scene *scene = NULL;
    snprintf(path, sizeof path, "%s/box.obj", input_dir);
    rad_result r = rad_scene_load_file(ctx, path, &scene);
    rad_scene_destroy(scene);
    if (r == RAD_OK) {
        snprintf(path, sizeof path, "%s/textured.obj", input_dir);
        r = rad_scene_load_file(ctx, path, &scene);
        rad_scene_destroy(scene);
    }
    if (r == RAD_OK) {
        r = rad_scene_load_memory(ctx, "box.obj", box_obj, strlen(box_obj), box_mtl, strlen(box_mtl), &scene);
        rad_scene_destroy(scene);
    }
    if (r == RAD_OK) {
        r = rad_scene_load_memory(ctx, "triangle.gltf", triangle_gltf, strlen(triangle_gltf), NULL, 0, &scene);
        rad_scene_destroy(scene);
    }
    if (r == RAD_OK) {
        r = rad_scene_create_cornell_box(ctx, &scene);
        if (r == RAD_OK) {
            output_path("cornell.obj", path, sizeof path);
            r = rad_scene_write_obj(ctx, scene, path);
            if (r == RAD_OK) {
                write_done(r, out, "cornell.obj");
                write_done(r, out, "cornell.mtl");
            }
        }
        rad_scene_destroy(scene);
    }
    if (r == RAD_OK) {
        rad_office_options oo = {1, 3, 0};
        r = rad_scene_generate_office(ctx, &oo, &scene);
        rad_scene_destroy(scene);
    }
    return r;
}

/* The heat exchange on a dense solution's F (docs/thermal.md): conditions
 * from memory, the solve, every writer. */
static rad_result run_thermal(rad_context *ctx, const rad_scene *scene, const rad_solution *s, outputs *out)
{
    static const char bc[] = "{\"default\": {\"emissivity\": 0.7, \"adiabatic\": true}, \"surfaces\": "
                             "{\"ceiling\": {\"temperature\": 600}, \"floor\": {\"heat_flux\": -100}}}";
    rad_thermal_conditions *c = NULL;
    rad_thermal *t = NULL;
    char path[512];
    rad_result r = rad_thermal_conditions_load_memory(ctx, scene, "bc.json", bc, strlen(bc), &c);
    if (r == RAD_OK)
        r = rad_thermal_solve(ctx, s, c, NULL, &t);
    if (r == RAD_OK) {
        output_path("heat.csv", path, sizeof path);
        r = write_done(rad_thermal_write(ctx, t, path, false), out, "heat.csv");
    }
    if (r == RAD_OK) {
        output_path("heat.json", path, sizeof path);
        r = write_done(rad_thermal_write(ctx, t, path, true), out, "heat.json");
    }
    if (r == RAD_OK) {
        output_path("gebhart.csv", path, sizeof path);
        r = write_done(rad_thermal_write_gebhart(ctx, t, path), out, "gebhart.csv");
    }
    if (r == RAD_OK) {
        output_path("thermal_stats.json", path, sizeof path);
        r = write_done(rad_thermal_write_stats(ctx, t, path), out, "thermal_stats.json");
    }
    rad_thermal_destroy(t);
    rad_thermal_conditions_destroy(c);
    return r;
}

/* Calculation points (docs/lighting.md): a footprint, a rectangle and a
 * free point evaluated on the solution, both writers. */
static rad_result run_illuminance(rad_context *ctx, const rad_solution *s, outputs *out)
{
    static const char grid[] = "{\"grids\": [{\"name\": \"f\", \"surface\": \"floor\", \"height\": 0.3, "
                               "\"spacing\": 0.25, \"border\": 0.1}, {\"name\": \"r\", \"rectangle\": "
                               "{\"origin\": [0.1, 0.1, 0.1], \"u\": [0.5, 0, 0], \"v\": [0, 0.5, 0.2]}, "
                               "\"spacing\": 0.25}], \"points\": [{\"name\": \"p\", \"position\": [0.5, 0.5, 0.5]}]}";
    rad_illuminance *il = NULL;
    char path[512];
    rad_result r = rad_illuminance_evaluate_memory(ctx, s, "grid.json", grid, strlen(grid), &il);
    if (r == RAD_OK) {
        output_path("illuminance.csv", path, sizeof path);
        r = write_done(rad_illuminance_write(ctx, il, path), out, "illuminance.csv");
    }
    if (r == RAD_OK) {
        output_path("illuminance.json", path, sizeof path);
        r = write_done(rad_illuminance_write(ctx, il, path), out, "illuminance.json");
    }
    /* The grids' plans (output/pictures.c), through an output set: all three
     * or none. */
    rad_output_set *set = NULL;
    if (r == RAD_OK)
        r = rad_output_set_create(ctx, &set);
    if (r == RAD_OK) {
        output_path("plan.png", path, sizeof path);
        r = rad_illuminance_write_plots(ctx, il, NULL, set, path);
    }
    if (r == RAD_OK)
        r = rad_output_set_commit(ctx, set);
    if (r == RAD_OK) {
        write_done(r, out, "plan_f.png");
        write_done(r, out, "plan_r.png");
        write_done(r, out, "plan_points.png");
    }
    rad_output_set_destroy(set);
    rad_illuminance_destroy(il);
    return r;
}

/* A strategy: solve, every accessor that allocates, render, every writer. */
static rad_result run_strategy(const scenario *sc, rad_context *ctx, outputs *out)
{
    rad_scene *scene = NULL;
    rad_solution *s = NULL;
    rad_image *image = NULL;
    double *vertex = NULL;
    char path[512];
    const char *mtl = sc->mirror ? mirror_mtl : box_mtl;
    rad_result r = rad_scene_load_memory(ctx, "box.obj", box_obj, strlen(box_obj), mtl, strlen(mtl), &scene);
    if (r == RAD_OK) {
        rad_options o = {0};
        o.target_elements = 48;
        o.solver = sc->solver;
        o.form_factors = sc->form_factors;
        o.hemicube_resolution = sc->hemicube_resolution;
        o.samples = sc->samples;
        o.closure_correction = sc->closure_correction;
        o.adaptive_levels = sc->adaptive_levels;
        o.record_history = 1;
        if (sc->on_step)
            o.on_step = no_op_step;
        o.epsilon = 1e-3;
        o.seed = 1;
        if (sc->luminaires) {
            static const char layout[] = "{\"up\": [0, 1, 0], \"luminaires\": [{\"file\": \"" RAD_TEST_DATA
                                         "/luminaires/downlight.ies\", \"position\": [0.5, 0.9, 0.5]}]}";
            r = rad_scene_load_luminaires_memory(ctx, scene, "layout.json", layout, strlen(layout));
        }
        if (r == RAD_OK)
            r = rad_solution_create(ctx, scene, &o, &s);
    }
    if (r == RAD_OK)
        r = rad_solution_solve(ctx, s);
    if (r == RAD_OK) {
        vertex = malloc(3 * rad_solution_vertex_count(s) * sizeof *vertex + 1);
        assert_non_null(vertex);
        r = rad_solution_vertex_radiosity(ctx, s, vertex);
    }
    if (r == RAD_OK) {
        rad_camera camera = {{0.5, 0.5, 0.95}, {0.5, 0.5, 0.0}, {0.0, 1.0, 0.0}, 60.0};
        rad_render_options ro = {16, 12, 2, &camera, RAD_SHADING_SMOOTH, 0.0, 0, 0, 0, 0};
        r = rad_solution_render(ctx, s, &ro, &image);
    }
    if (r == RAD_OK) {
        output_path("image.png", path, sizeof path);
        r = write_done(rad_image_write(ctx, image, path), out, "image.png");
    }
    if (r == RAD_OK) {
        output_path("image.pfm", path, sizeof path);
        r = write_done(rad_image_write(ctx, image, path), out, "image.pfm");
    }
    /* False colour pictures (output/pictures.c): a render, the coverage, the
     * range, cairo's PNG through an atomic file. */
    for (int q = RAD_FALSE_COLOUR_LUMINANCE; q <= RAD_FALSE_COLOUR_ILLUMINANCE && r == RAD_OK; q++) {
        rad_camera camera = {{0.5, 0.5, 0.95}, {0.5, 0.5, 0.0}, {0.0, 1.0, 0.0}, 60.0};
        rad_render_options ro = {16, 12, 2, &camera, RAD_SHADING_SMOOTH, 0.0, 0, 0, 0, 0};
        rad_false_colour_options fo = {(rad_false_colour_quantity)q, q == RAD_FALSE_COLOUR_ILLUMINANCE, 0, 0, 1};
        const char *name = q == RAD_FALSE_COLOUR_LUMINANCE ? "luminance.png" : "illuminance.png";
        output_path(name, path, sizeof path);
        r = write_done(rad_solution_write_false_colour(ctx, s, &ro, &fo, path), out, name);
    }
    if (r == RAD_OK) {
        output_path("stats.json", path, sizeof path);
        r = write_done(rad_solution_write_stats(ctx, s, path, 0), out, "stats.json");
    }
    if (r == RAD_OK && sc->view_factors) {
        output_path("surfaces.json", path, sizeof path);
        r = write_done(rad_solution_write_view_factors(ctx, s, path, 0), out, "surfaces.json");
        if (r == RAD_OK) {
            output_path("elements.mtx", path, sizeof path);
            r = write_done(rad_solution_write_view_factors(ctx, s, path, 1), out, "elements.mtx");
        }
    }
    if (r == RAD_OK) {
        output_path("history.csv", path, sizeof path);
        r = write_done(rad_solution_write_history(ctx, s, path), out, "history.csv");
    }
    if (r == RAD_OK && sc->view_factors)
        r = run_thermal(ctx, scene, s, out);
    /* Streamed view factors (output/stream.c): element rows in blocks of 5 to
     * Matrix Market (a temporary joined at the end) and CSV, surfaces to JSON. */
    static const char *const streamed[] = {"stream.mtx", "stream.csv", "stream.json"};
    bool streams = sc->view_factors && !sc->closure_correction && !sc->adaptive_levels &&
                   strcmp(sc->form_factors, "analytic") == 0;
    if (r == RAD_OK && streams)
        r = run_illuminance(ctx, s, out);
    for (size_t k = 0; k < 3 && r == RAD_OK && streams; k++) {
        rad_options o = {0};
        o.target_elements = 48;
        o.epsilon = 1e-3;
        o.seed = 1;
        rad_stream_options so = {5, k < 2, 0, NULL, NULL};
        rad_stream_stats st;
        output_path(streamed[k], path, sizeof path);
        r = write_done(rad_scene_stream_view_factors(ctx, scene, &o, &so, path, &st), out, streamed[k]);
    }
    static const char *const meshes[] = {"lit.glb", "lit.gltf", "lit.ply"};
    for (size_t k = 0; k < 3 && r == RAD_OK; k++) {
        output_path(meshes[k], path, sizeof path);
        r = write_done(rad_solution_write_mesh(ctx, s, path, 0.0), out, meshes[k]);
    }
    free(vertex);
    rad_image_destroy(image);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
    return r;
}

/* One run in a fresh context of 2 threads (per-thread scratch included),
 * with allocation `fail_at` failing (0: none).  Checks that everything
 * made was given back; returns the run's result, its context's error in
 * `error` and its allocation count in *allocations. */
static rad_result run_once(const scenario *sc, uint64_t fail_at, outputs *out, char *error, size_t error_size,
                           uint64_t *allocations)
{
    rad_context_options co = {0};
    co.threads = 2;
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(&co, &ctx), RAD_OK);
    rad_context_fail_allocation(ctx, fail_at);
    memset(out, 0, sizeof *out);
    rad_result r = sc->solver ? run_strategy(sc, ctx, out) : run_loading(ctx, out);
    snprintf(error, error_size, "%s", rad_context_error(ctx));
    *allocations = rad_memory_allocations(ctx);
    for (int c = 0; c <= RAD_MEM_CATEGORIES; c++)
        if (rad_memory_in_use(ctx, (rad_memory_category)c) != 0)
            fail_msg("%s, allocation %llu failing: %zu bytes of %s still in use after everything was destroyed",
                     sc->name, (unsigned long long)fail_at, rad_memory_in_use(ctx, (rad_memory_category)c),
                     rad_memory_category_name((rad_memory_category)c));
    rad_context_destroy(ctx);
    return r;
}

/* The output folder holds exactly what the finished writers wrote: no
 * partial file, no temporary name. */
static void check_outputs(const scenario *sc, uint64_t k, const outputs *out)
{
    DIR *dir = opendir(output_dir);
    assert_non_null(dir);
    int found = 0;
    for (struct dirent *e; (e = readdir(dir));) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        bool expected = false;
        for (int i = 0; i < out->count; i++)
            expected |= strcmp(out->written[i], e->d_name) == 0;
        if (!expected)
            fail_msg("%s, allocation %llu failing: '%s' left in the output folder", sc->name,
                     (unsigned long long)k, e->d_name);
        found++;
    }
    closedir(dir);
    assert_int_equal(found, out->count);
}

static void sweep(const scenario *sc)
{
    outputs out;
    char error[1100];
    uint64_t n, again;
    rad_result clean = run_once(sc, 0, &out, error, sizeof error, &n);
    if (clean != RAD_OK)
        fail_msg("%s: %s", sc->name, error);
    check_outputs(sc, 0, &out);
    clear_outputs();
    /* The count is the same every time: allocations happen on the calling
     * thread only, never inside a parallel region. */
    assert_int_equal(run_once(sc, 0, &out, error, sizeof error, &again), RAD_OK);
    assert_int_equal(again, n);
    clear_outputs();
    printf("    %s: %llu allocations\n", sc->name, (unsigned long long)n);
    for (uint64_t k = 1 + (uint64_t)offset; k <= n; k += (uint64_t)stride) {
        uint64_t count;
        rad_result r = run_once(sc, k, &out, error, sizeof error, &count);
        if (r != RAD_ERROR_OUT_OF_MEMORY || !strstr(error, "(test hook: allocation") || strchr(error, '\n'))
            fail_msg("%s, allocation %llu of %llu failing: %s, '%s'", sc->name, (unsigned long long)k,
                     (unsigned long long)n, rad_result_string(r), error);
        check_outputs(sc, k, &out);
        clear_outputs();
    }
}

static void test_fail_each_allocation(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof scenarios / sizeof *scenarios; i++)
        sweep(&scenarios[i]);
}

/* ---- the limit ---- */

static rad_context *limited_context(double bytes)
{
    rad_context_options co = {0};
    co.threads = 1;
    co.max_memory_bytes = bytes;
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(&co, &ctx), RAD_OK);
    return ctx;
}

static void assert_contains(const char *text, const char *part)
{
    if (!strstr(text, part))
        fail_msg("'%s' does not contain '%s'", text, part);
}

/* A request over the limit is refused with one line naming what, the
 * bytes and the limit; the accounting returns to 0 and the context's
 * limit holds for everything (loading too). */
static void test_limit(void **state)
{
    (void)state;
    rad_context *ctx = limited_context(1048576.0);
    assert_int_equal(rad_memory_limit(ctx), 1048576.0);
    rad_api_enter(ctx);
    assert_null(rad_alloc(ctx, RAD_MEM_SOLVER, 2, 1048576, "a big table"));
    assert_contains(rad_context_error(ctx), "a big table: 2.0 MiB more would pass the memory limit of 1.0 MiB");
    assert_contains(rad_context_error(ctx), "max_memory_bytes");
    assert_int_equal(rad_memory_in_use(ctx, RAD_MEM_CATEGORIES), 0);

    /* Blocks are counted in their category until freed, peaks kept. */
    void *a = rad_alloc(ctx, RAD_MEM_MESH, 1000, 1, "a");
    void *b = rad_alloc(ctx, RAD_MEM_RENDER, 500, 2, "b");
    assert_non_null(a);
    assert_non_null(b);
    assert_int_equal(rad_memory_in_use(ctx, RAD_MEM_MESH), 1000);
    assert_int_equal(rad_memory_in_use(ctx, RAD_MEM_RENDER), 1000);
    assert_int_equal(rad_memory_in_use(ctx, RAD_MEM_CATEGORIES), 2000);
    a = rad_realloc(ctx, RAD_MEM_MESH, a, 3000, 1, "a");
    assert_non_null(a);
    assert_int_equal(((unsigned char *)a)[2999], 0); /* grown and zeroed */
    assert_int_equal(rad_memory_in_use(ctx, RAD_MEM_MESH), 3000);
    rad_free(a);
    rad_free(b);
    rad_free(NULL);
    assert_int_equal(rad_memory_in_use(ctx, RAD_MEM_CATEGORIES), 0);
    /* A resize counts both sizes while it copies. */
    assert_int_equal(rad_memory_peak(ctx, RAD_MEM_MESH), 4000);
    assert_int_equal(rad_memory_peak(ctx, RAD_MEM_CATEGORIES), 5000);

    /* The scene loads within 1 MiB; 2000 elements' form factors do not fit
     * and are refused before they are computed, naming the limit. */
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "box.obj", box_obj, strlen(box_obj), box_mtl, strlen(box_mtl), &scene),
                     RAD_OK);
    assert_true(rad_memory_in_use(ctx, RAD_MEM_SCENE) > 0);
    rad_options o = {0};
    o.solver = "gauss-seidel"; /* a dense matrix */
    o.target_elements = 2000;
    rad_solution *s = (rad_solution *)&o;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_ERROR_OUT_OF_MEMORY);
    assert_null(s);
    assert_contains(rad_context_error(ctx), "memory limit of");
    assert_contains(rad_context_error(ctx), "max_memory_bytes");
    /* A solution's own limit is never above the context's. */
    o.target_elements = 48;
    o.max_memory_bytes = 1e12;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    assert_true(s->options.max_memory_bytes <= 1048576.0);
    rad_solution_destroy(s);
    /* ... and lower where asked: 1 byte refuses the first block. */
    o.max_memory_bytes = 1.0;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_ERROR_OUT_OF_MEMORY);
    assert_contains(rad_context_error(ctx), "the memory limit of 1 bytes");
    rad_scene_destroy(scene);
    for (int c = 0; c <= RAD_MEM_CATEGORIES; c++)
        assert_int_equal(rad_memory_in_use(ctx, (rad_memory_category)c), 0);
    rad_context_destroy(ctx);

    rad_context_options bad = {0};
    bad.max_memory_bytes = -1.0;
    assert_int_equal(rad_context_create(&bad, &ctx), RAD_ERROR_INVALID_ARGUMENT);
}

/* A context destroyed before what was made with it lives on until the
 * last of them goes (the sanitizer build checks the order is safe). */
static void test_context_outlived(void **state)
{
    (void)state;
    rad_context *ctx = limited_context(0.0);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    rad_context_destroy(ctx);
    assert_true(rad_scene_surface_count(scene) > 0);
    rad_scene_destroy(scene);
}

/* ---- loading within the limit ---- */

/* Fill the FIFO at `path` with `line` over and over until its reader
 * leaves (the writer then dies of SIGPIPE); returns the writer's pid. */
static pid_t endless_writer(const char *path, const char *line)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        signal(SIGPIPE, SIG_DFL);
        alarm(60); /* should the reader never come */
        char block[65536];
        size_t n = strlen(line), used = 0;
        while (used + n <= sizeof block) {
            memcpy(block + used, line, n);
            used += n;
        }
        int fd = open(path, O_WRONLY);
        while (fd >= 0 && write(fd, block, used) > 0)
            ;
        _exit(0);
    }
    return pid;
}

/* A load that must fail with `expected` and a message holding `part`,
 * in a fresh context of `limit` bytes (0: the default), reading no more
 * than `most_scene_bytes` into scene memory. */
static void load_fails(const char *path, double limit, rad_result expected, const char *part,
                       double most_scene_bytes)
{
    rad_context *ctx = limited_context(limit);
    rad_scene *scene = (rad_scene *)&ctx;
    double t0 = rad_seconds();
    rad_result r = rad_scene_load_file(ctx, path, &scene);
    if (r != expected || !strstr(rad_context_error(ctx), part))
        fail_msg("%s: %s '%s', expected %s '...%s...'", path, rad_result_string(r),
                 rad_context_error(ctx), rad_result_string(expected), part);
    assert_null(scene);
    assert_null(strchr(rad_context_error(ctx), '\n'));
    assert_true(rad_seconds() - t0 < 10.0);
    /* + 4 KiB: the file names and the folder the load keeps */
    if ((double)rad_memory_peak(ctx, RAD_MEM_SCENE) > most_scene_bytes + 4096.0)
        fail_msg("%s: %zu bytes of scene memory at most, expected <= %.0f", path,
                 rad_memory_peak(ctx, RAD_MEM_SCENE), most_scene_bytes + 4096.0);
    assert_int_equal(rad_memory_in_use(ctx, RAD_MEM_CATEGORIES), 0);
    rad_context_destroy(ctx);
}

/* Reading stops where the import could pass the limit: at limit / 20
 * bytes of scene text (assimp takes up to 20x), the file and its
 * libraries together.  A regular file is refused by its size, unread; a
 * stream when it has given that much; text with a NUL byte at once. */
static void test_loading_limit(void **state)
{
    (void)state;
    const double limit = 8.0 * 1048576.0, budget = limit / 20.0; /* 409.6 KiB */
    char path[512];

    /* /dev/zero and /dev/urandom under an OBJ name: a NUL in the first
     * piece read (before: /dev/zero was read up to the limit). */
    snprintf(path, sizeof path, "%s/zero.obj", input_dir);
    remove(path);
    assert_int_equal(symlink("/dev/zero", path), 0);
    load_fails(path, limit, RAD_ERROR_PARSE, "zero.obj:1: NUL byte in the text", 65536.0);
    load_fails(path, 0.0, RAD_ERROR_PARSE, "zero.obj:1: NUL byte in the text", 65536.0);
    remove(path);
    load_fails("/dev/urandom", 0.0, RAD_ERROR_PARSE, "NUL byte in the text", 65536.0);

    /* Endless text from a FIFO: stopped at the budget.  The doubling
     * block and its copy stay under twice the budget. */
    snprintf(path, sizeof path, "%s/endless.obj", input_dir);
    remove(path);
    assert_int_equal(mkfifo(path, 0600), 0);
    pid_t writer = endless_writer(path, "v 0 0 0\n");
    load_fails(path, limit, RAD_ERROR_OUT_OF_MEMORY,
               "endless.obj: a file of more than 409.6 KiB may need more than 8.0 MiB to import "
               "(20x its size), above the memory limit of 8.0 MiB "
               "(rad_context_options.max_memory_bytes)",
               2.0 * budget + 2.0);
    waitpid(writer, NULL, 0);
    remove(path);

    /* A sparse file of 1 GiB: refused by its size, without reading it. */
    snprintf(path, sizeof path, "%s/huge.obj", input_dir);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fclose(f);
    assert_int_equal(truncate(path, (off_t)1 << 30), 0);
    load_fails(path, limit, RAD_ERROR_OUT_OF_MEMORY,
               "huge.obj: a file of 1.00 GiB may need 20.00 GiB to import (20x its size), above "
               "the memory limit of 8.0 MiB", 0.0);
    /* ... and with no limit given, a NUL byte in its first MiB at the latest. */
    assert_int_equal(truncate(path, (off_t)16 << 20), 0);
    load_fails(path, 0.0, RAD_ERROR_PARSE, "huge.obj:1: NUL byte in the text",
               16.0 * 1048576.0 + 1.0);
    remove(path);

    /* An OBJ of 300 KiB fits; with its 200 KiB library it does not. */
    char *text = malloc(300 * 1024 + 1);
    assert_non_null(text);
    snprintf(text, 64, "mtllib big.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    for (size_t i = strlen(text); i < 300 * 1024; i++)
        text[i] = i % 64 == 63 ? '\n' : '#';
    text[300 * 1024] = '\0';
    write_text(input_dir, "big.obj", text);
    text[200 * 1024] = '\0';
    memcpy(text, "newmtl m\n", 9);
    write_text(input_dir, "big.mtl", text);
    snprintf(path, sizeof path, "%s/big.obj", input_dir);
    load_fails(path, limit, RAD_ERROR_OUT_OF_MEMORY,
               "big.obj:1: material library 'big.mtl': with it the scene's files come to 500.0 "
               "KiB, which may need 9.8 MiB to import (20x their size), above the memory limit "
               "of 8.0 MiB", 300.0 * 1024 + 1);
    remove(path);
    snprintf(path, sizeof path, "%s/big.mtl", input_dir);
    remove(path);
    free(text);

    /* 1 MiB of text fits in 8 MiB, but not the 20 MiB assimp may need. */
    rad_context *ctx = limited_context(limit);
    rad_scene *scene = (rad_scene *)&path;
    size_t size = 1048576;
    text = malloc(size);
    assert_non_null(text);
    for (size_t i = 0; i < size; i++)
        text[i] = i % 64 == 63 ? '\n' : '#';
    assert_int_equal(rad_scene_load_memory(ctx, "comments.obj", text, size, NULL, 0, &scene),
                     RAD_ERROR_OUT_OF_MEMORY);
    assert_contains(rad_context_error(ctx), "comments.obj: a file of 1.0 MiB may need 20.0 MiB to import");
    assert_contains(rad_context_error(ctx), "the memory limit of 8.0 MiB");
    free(text);
    assert_int_equal(rad_memory_in_use(ctx, RAD_MEM_CATEGORIES), 0);
    rad_context_destroy(ctx);
}

/* With no limit given, the limit is half the memory the process may use:
 * the physical memory, or less where RLIMIT_AS (ulimit -v) says so (here
 * in a child, not to limit the tests). */
static void test_default_limit(void **state)
{
    (void)state;
    rad_context *ctx = limited_context(0.0);
    double available = (double)rad_available_memory_bytes();
    assert_true(available > 0.0 && available <= (double)rad_physical_memory_bytes());
    assert_true(rad_memory_limit(ctx) == (double)(size_t)(0.5 * available));
    rad_context_destroy(ctx);

#ifdef __SANITIZE_ADDRESS__
    /* AddressSanitizer's shadow memory (terabytes, reserved at start) counts
     * toward RLIMIT_AS: once it is lowered, every new mapping fails, and
     * whether the child needs one depends on what ran before it.  The plain
     * build checks the limit. */
    return;
#endif
    pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0) {
        struct rlimit as = {(rlim_t)3 << 30, (rlim_t)3 << 30};
        rad_context *limited = NULL;
        int ok = setrlimit(RLIMIT_AS, &as) == 0 &&
                 rad_available_memory_bytes() == (size_t)3 << 30 &&
                 rad_context_create(NULL, &limited) == RAD_OK &&
                 rad_memory_limit(limited) == 1.5 * 1073741824.0;
        rad_context_destroy(limited);
        _exit(ok ? 0 : 1);
    }
    int status = -1;
    assert_int_equal(waitpid(child, &status, 0), child);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

/* The stats report the allocator's peaks by category. */
static void test_stats_by_category(void **state)
{
    (void)state;
    rad_context *ctx = limited_context(0.0);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "box.obj", box_obj, strlen(box_obj), box_mtl, strlen(box_mtl), &scene),
                     RAD_OK);
    rad_options o = {0};
    o.solver = "gauss-seidel"; /* every category, form factors included */
    o.target_elements = 48;
    rad_solution *s = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &s), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, s), RAD_OK);
    rad_image *image = NULL;
    rad_render_options ro = {8, 8, 1, NULL, RAD_SHADING_SMOOTH, 0.0, 0, 0, 0, 0};
    assert_int_equal(rad_solution_render(ctx, s, &ro, &image), RAD_OK);
    char path[512];
    output_path("stats.json", path, sizeof path);
    assert_int_equal(rad_solution_write_stats(ctx, s, path, 0), RAD_OK);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char text[16384];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    cJSON *root = cJSON_Parse(text);
    assert_non_null(root);
    const cJSON *mem = cJSON_GetObjectItemCaseSensitive(root, "memory_bytes");
    const cJSON *by = cJSON_GetObjectItemCaseSensitive(mem, "by_category");
    double total = cJSON_GetObjectItemCaseSensitive(mem, "allocator_peak")->valuedouble;
    const char *expected[] = {"scene", "mesh", "visibility", "form_factors", "solver", "render"};
    double largest = 0.0;
    for (size_t i = 0; i < sizeof expected / sizeof *expected; i++) {
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(by, expected[i]);
        assert_non_null(v);
        assert_true(v->valuedouble > 0.0);
        largest = fmax(largest, v->valuedouble);
    }
    assert_non_null(cJSON_GetObjectItemCaseSensitive(by, "hierarchy"));
    assert_non_null(cJSON_GetObjectItemCaseSensitive(by, "output"));
    /* F alone is 48^2 floats or more; the total peak is at least any stage's. */
    assert_true(cJSON_GetObjectItemCaseSensitive(by, "form_factors")->valuedouble >= 4.0 * 48 * 48);
    assert_true(total >= largest);
    cJSON_Delete(root);
    clear_outputs();
    rad_image_destroy(image);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
    assert_int_equal(rad_memory_in_use(ctx, RAD_MEM_CATEGORIES), 0);
    rad_context_destroy(ctx);
}

static int setup(void **state)
{
    (void)state;
    snprintf(input_dir, sizeof input_dir, "/tmp/test_alloc_in.XXXXXX");
    snprintf(output_dir, sizeof output_dir, "/tmp/test_alloc_out.XXXXXX");
    if (!mkdtemp(input_dir) || !mkdtemp(output_dir))
        return -1;
    write_text(input_dir, "box.obj", box_obj);
    write_text(input_dir, "box.mtl", box_mtl);
    write_text(input_dir, "textured.obj", textured_obj);
    write_text(input_dir, "textured.mtl", textured_mtl);
    char png[600];
    snprintf(png, sizeof png, "%s/checker.png", input_dir);
    /* open/write, not stdio: no buffer allocated here (test_default_limit's
     * child under ASan has no address space to spare for new size classes). */
    int fd = open(png, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    bool written = fd >= 0 && write(fd, checker_png, sizeof checker_png) == (ssize_t)sizeof checker_png;
    if (fd >= 0)
        close(fd);
    return written ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    clear_outputs();
    rmdir(output_dir);
    char path[600];
    snprintf(path, sizeof path, "%s/box.obj", input_dir);
    remove(path);
    snprintf(path, sizeof path, "%s/box.mtl", input_dir);
    remove(path);
    static const char *const textured[] = {"textured.obj", "textured.mtl", "checker.png"};
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/%s", input_dir, textured[k]);
        remove(path);
    }
    rmdir(input_dir);
    return 0;
}

/* Every message is one line of text: line breaks and tabs become spaces,
 * other control bytes (an escape sequence in a surface name) '?', UTF-8
 * passes. */
static void test_messages_one_line(void **state)
{
    (void)state;
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    rad_api_enter(ctx);
    assert_int_equal(rad_fail(ctx, RAD_ERROR_PARSE, "surface '%s'", "a\nb\r\x1b[2J\tc\x7f\xc3\xa9"),
                     RAD_ERROR_PARSE);
    assert_string_equal(rad_context_error(ctx), "surface 'a b ?[2J c?\xc3\xa9'");
    rad_context_destroy(ctx);
}

/* A count on the command line: decimal digits, at most 10^6; -1 otherwise. */
static long count_argument(const char *text)
{
    char *end = NULL;
    long value = strtol(text, &end, 10);
    return *text >= '0' && *text <= '9' && !*end && value <= 1000000 ? value : -1;
}

int main(int argc, char **argv)
{
    bool sweep = false;
    if (argc == 2 && strcmp(argv[1], "--full") == 0) {
        sweep = true;
    } else if (strcmp(argc > 1 ? argv[1] : "", "--every") == 0 &&
               (argc == 3 || (argc == 5 && strcmp(argv[3], "--offset") == 0))) {
        long every = count_argument(argv[2]), from = argc == 5 ? count_argument(argv[4]) : 0;
        sweep = every >= 1 && from >= 0 && from < every;
        stride = (int)every;
        offset = (int)from;
    }
    if (argc > 1 && !sweep) {
        fprintf(stderr, "usage: test_alloc [--full | --every N [--offset R]] (0 <= R < N)\n");
        return 2;
    }
    const struct CMUnitTest fast_tests[] = {
        cmocka_unit_test(test_limit),
        cmocka_unit_test(test_context_outlived),
        cmocka_unit_test(test_loading_limit),
        cmocka_unit_test(test_default_limit),
        cmocka_unit_test(test_stats_by_category),
        cmocka_unit_test(test_messages_one_line),
    };
    /* The same, and the sweep: every allocation (--full) or every N-th failing. */
    const struct CMUnitTest sweep_tests[] = {
        cmocka_unit_test(test_limit),
        cmocka_unit_test(test_context_outlived),
        cmocka_unit_test(test_loading_limit),
        cmocka_unit_test(test_default_limit),
        cmocka_unit_test(test_stats_by_category),
        cmocka_unit_test(test_messages_one_line),
        cmocka_unit_test(test_fail_each_allocation),
    };
    return sweep ? cmocka_run_group_tests_name("alloc_sweep", sweep_tests, setup, teardown)
                 : cmocka_run_group_tests_name("alloc", fast_tests, setup, teardown);
}
