/*
 * test_cli.c -- the `radiosity` command as a user meets it: every bad input
 * gives exactly one line on stderr that names the file (and the line where
 * it is known), a non-zero exit status (1 failure, 2 usage), and leaves no
 * output file behind; good runs print where the result went.  The path of
 * the binary is argv[1].
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "cli_support.h"

#include <dirent.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* No file whose name starts with `prefix` (the output or its temporary). */
static void assert_no_output(const char *prefix)
{
    DIR *d = opendir(test_workdir());
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d)))
        if (strncmp(e->d_name, prefix, strlen(prefix)) == 0)
            fail_msg("unexpected output file %s", e->d_name);
    closedir(d);
}

/* ---- bad input: the scene ---- */

static void bad_scene(const char *obj_name, const char *obj, const char *mtl_name, const char *mtl,
                      const char *needle1, const char *needle2)
{
    test_write_file(obj_name, obj);
    if (mtl_name)
        test_write_file(mtl_name, mtl);
    assert_int_equal(cli_run_here("render %s -o bad_out.png --stats bad_stats.json", obj_name), 1);
    cli_assert_one_line_error(needle1, needle2);
    assert_no_output("bad_out");
    assert_no_output("bad_stats");
}

static void test_missing_file(void **state)
{
    (void)state;
    assert_int_equal(cli_run_here("render no_such_scene.obj -o bad_out.png"), 1);
    cli_assert_one_line_error("no_such_scene.obj", "No such file");
    assert_no_output("bad_out");
}

static void test_malformed_obj(void **state)
{
    (void)state;
    bad_scene("garbage.obj", "this is not\n\x01\x02 an obj file at all {{{\nf 1 2\n", NULL, NULL,
              "garbage.obj", NULL);
}

static void test_face_index_out_of_range(void **state)
{
    (void)state;
    bad_scene("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 40\n", NULL, NULL, "range.obj:4", NULL);
}

static void test_nan_coordinates(void **state)
{
    (void)state;
    bad_scene("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", NULL, NULL, "nan.obj:2", NULL);
}

static void test_infinite_coordinates(void **state)
{
    (void)state;
    bad_scene("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n", NULL, NULL, "inf.obj:3", NULL);
}

/* Coordinates beyond the engine's range (1e30 m) name their line; a scene
 * of 1e18 m, whose rays Embree could not hold unscaled (an assertion
 * aborted the run), renders as the same scene in metres does. */
static void test_huge_coordinates(void **state)
{
    (void)state;
    bad_scene("huge.obj", "v 0 0 0\nv 1 0 0\nv 0 3e31 0\nf 1 2 3\n", NULL, NULL,
              "huge.obj:3: vertex coordinate '3e31' is beyond the 1e+30 m", NULL);
    test_write_file("good.mtl", cli_good_mtl);
    test_write_file("far.obj", "mtllib good.mtl\n"
                          "o floor\nusemtl white\n"
                          "v 0 0 0\nv 1e18 0 0\nv 1e18 0 1e18\nv 0 0 1e18\nf 1 4 3 2\n"
                          "o lamp\nusemtl lamp\n"
                          "v 0 1e18 0\nv 1e18 1e18 0\nv 1e18 1e18 1e18\nv 0 1e18 1e18\nf 5 6 7 8\n");
    test_write_file("near.obj", cli_good_obj);
    assert_int_equal(cli_run_here("render far.obj -q --elements 50 --width 32 --height 32 --exposure 1 -o far.png "
                         "--camera 0.5e18,0.5e18,-2e18,0.5e18,0,0.5e18"), 0);
    assert_int_equal(cli_run_here("render near.obj -q --elements 50 --width 32 --height 32 --exposure 1 -o near.png "
                         "--camera 0.5,0.5,-2,0.5,0,0.5"), 0);
    /* The same picture, byte for byte. */
    unsigned char bytes[2][16384];
    size_t size[2];
    const char *names[2] = {"far.png", "near.png"};
    for (int k = 0; k < 2; k++) {
        char path[600];
        snprintf(path, sizeof path, "%s/%s", test_workdir(), names[k]);
        FILE *f = fopen(path, "rb");
        assert_non_null(f);
        size[k] = fread(bytes[k], 1, sizeof bytes[k], f);
        fclose(f);
    }
    assert_true(size[0] > 100 && size[0] < sizeof bytes[0]);
    assert_int_equal(size[0], size[1]);
    assert_memory_equal(bytes[0], bytes[1], size[0]);
    /* A camera 10^7 scene sizes away is refused before the work: exit 2. */
    assert_int_equal(cli_run_here("render near.obj -o cam.png --stats cam.json --camera 0.5,2e7,0.5,0.5,0,0.5,0,0,1"), 2);
    cli_assert_one_line_error("--camera: the position is", "at most 1e+06 times");
    assert_no_output("cam.");
}

/* Files of any size, whole (PNG holds NUL bytes). */
static size_t read_bytes(const char *name, unsigned char *buf, size_t size)
{
    char p[600];
    snprintf(p, sizeof p, "%s/%s", test_workdir(), name);
    FILE *f = fopen(p, "rb");
    if (!f)
        return 0;
    size_t n = fread(buf, 1, size, f);
    fclose(f);
    return n;
}

/* Solve once, render from the file: the picture of solving and rendering
 * at once, byte for byte; from another camera too.  The file is refused
 * where it cannot serve, and a damaged one is named. */
static void test_solution_file(void **state)
{
    (void)state;
    assert_int_equal(cli_run_here("solve --elements 200 -q -o box.radsol --stats solve.json"), 0);
    assert_true(test_file_exists(test_path("box.radsol")) && test_file_exists(test_path("solve.json")));
    const char *camera = "--camera 0.1,0.3,-0.5,0.3,0.25,0.3";
    assert_int_equal(cli_run_here("render box.radsol -q --width 64 --height 48 %s -o from_file.png", camera), 0);
    assert_int_equal(cli_run_here("render --elements 200 -q --width 64 --height 48 %s -o solved.png", camera), 0);
    static unsigned char a[65536], b[65536];
    size_t na = read_bytes("from_file.png", a, sizeof a), nb = read_bytes("solved.png", b, sizeof b);
    assert_true(na > 100 && na < sizeof a);
    assert_int_equal(na, nb);
    assert_memory_equal(a, b, na);
    /* export draws its lit mesh from the file as from the solve, to the byte. */
    assert_int_equal(cli_run_here("export box.radsol -q -o from_file.glb"), 0);
    assert_int_equal(cli_run_here("export --elements 200 -q -o solved.glb"), 0);
    na = read_bytes("from_file.glb", a, sizeof a);
    nb = read_bytes("solved.glb", b, sizeof b);
    assert_true(na > 1000 && na < sizeof a);
    assert_int_equal(na, nb);
    assert_memory_equal(a, b, na);
    /* Refused before any work: another extension, a solution where a
     * scene is needed, a solve to follow. */
    assert_int_equal(cli_run_here("solve --elements 50 -o box.png"), 2);
    cli_assert_one_line_error("box.png: a solution file is named .radsol", NULL);
    assert_no_output("box.png");
    assert_int_equal(cli_run_here("viewfactors box.radsol -o vf.json"), 2);
    cli_assert_one_line_error("box.radsol is a solution file", "needs the scene");
    assert_int_equal(cli_run_here("render box.radsol --history h.csv -o x.png"), 2);
    cli_assert_one_line_error("--history: box.radsol is a solution file", NULL);
    assert_no_output("h.csv");
    /* Damaged: cut short. */
    size_t n = read_bytes("box.radsol", a, sizeof a);
    assert_true(n > 1000);
    char p[600];
    snprintf(p, sizeof p, "%s/cut.radsol", test_workdir());
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    fwrite(a, 1, n / 2, f);
    fclose(f);
    assert_int_equal(cli_run_here("render cut.radsol -o cut.png"), 1);
    cli_assert_one_line_error("cut.radsol: the payload should hold", "truncated or damaged");
    assert_no_output("cut.png");
}

/* The frames in folder `dir` of the work folder, step_*.png. */
static int count_frames(const char *dir, char *last, size_t last_size)
{
    char p[600];
    snprintf(p, sizeof p, "%s/%s", test_workdir(), dir);
    DIR *d = opendir(p);
    assert_non_null(d);
    int n = 0;
    struct dirent *e;
    last[0] = '\0';
    while ((e = readdir(d)))
        if (strncmp(e->d_name, "step_", 5) == 0) {
            n++;
            if (strcmp(e->d_name, last) > 0)
                snprintf(last, last_size, "%s", e->d_name);
        }
    closedir(d);
    return n;
}

/* --progress-images with hierarchical radiosity: a frame per sweep (the
 * current leaves, refinement rounds included), numbered by the sweep, as
 * many as the stats' iterations; the last is the final picture to the
 * byte (one exposure for all), the first darker (the first sweep has
 * gathered one bounce); --every K keeps every K-th. */
static void test_progress_images_hierarchical(void **state)
{
    (void)state;
    const char *common = "--solver hierarchical --width 24 --height 24 --exposure 1 -q";
    assert_int_equal(cli_run_here("render %s --progress-images hframes --stats h.json -o h.png", common), 0);
    cJSON *stats = cli_read_json(test_path("h.json"));
    assert_non_null(stats);
    int sweeps = (int)cli_stats_number(stats, "solver", "iterations");
    cJSON_Delete(stats);
    char last[256], path[300];
    int frames = count_frames("hframes", last, sizeof last);
    printf("hierarchical: %d sweeps, %d frames, the last %s\n", sweeps, frames, last);
    assert_true(sweeps >= 3);
    assert_int_equal(frames, sweeps);
    char want[64];
    snprintf(want, sizeof want, "step_%08d.png", sweeps);
    assert_string_equal(last, want);
    static unsigned char a[65536], b[65536];
    snprintf(path, sizeof path, "hframes/%s", last);
    size_t na = read_bytes(path, a, sizeof a), nb = read_bytes("h.png", b, sizeof b);
    assert_true(na > 100 && na < sizeof a);
    assert_int_equal(na, nb);
    assert_memory_equal(a, b, na);
    size_t n1 = read_bytes("hframes/step_00000001.png", b, sizeof b);
    assert_true(n1 > 100);
    assert_true(n1 != na || memcmp(a, b, na) != 0);
    /* Every 4th sweep. */
    assert_int_equal(cli_run_here("render %s --progress-images hframes4 --every 4 -o h4.png", common), 0);
    assert_int_equal(count_frames("hframes4", last, sizeof last), sweeps / 4);
}

static void test_zero_area_polygon(void **state)
{
    (void)state;
    bad_scene("flat.obj", "mtllib good.mtl\no sliver\nusemtl lamp\nv 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
              "good.mtl", cli_good_mtl, "flat.obj", "sliver");
}

static void test_reflectance_too_high(void **state)
{
    (void)state;
    bad_scene("bright.obj", "mtllib bright.mtl\no a\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
              "bright.mtl", "newmtl m\nKd 1.2 0.5 0.5\n", "bright.mtl:2", "1.2");
}

static void test_reflectance_negative(void **state)
{
    (void)state;
    bad_scene("neg.obj", "mtllib neg.mtl\no a\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
              "neg.mtl", "newmtl m\nKd 0.5 -0.1 0.5\n", "neg.mtl:2", NULL);
}

static void test_no_emitter(void **state)
{
    (void)state;
    bad_scene("dark.obj", "mtllib good.mtl\no a\nusemtl white\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
              "good.mtl", cli_good_mtl, "dark.obj", "emitter");
}

static void test_empty_scene(void **state)
{
    (void)state;
    bad_scene("empty.obj", "# nothing here\n", NULL, NULL, "empty.obj", "empty");
}

static void test_malformed_gltf(void **state)
{
    (void)state;
    bad_scene("broken.gltf", "{ \"asset\": {\"version\": \"2.0\"}, \"meshes\": [ {", NULL, NULL,
              "broken.gltf", NULL);
}

/* A glTF of the unit quad (4 float positions, 6 ushort indices, base64):
 * a white floor facing +z, a lamp turned over it at z = 1, and `extra`
 * top-level JSON (", \"cameras\": ...") with its `extra_nodes`. */
static void write_gltf(const char *name, const char *extra_nodes, const char *extra)
{
    size_t size = strlen(extra_nodes) + strlen(extra) + 4096;
    char *text = malloc(size);
    assert_non_null(text);
    snprintf(text, size,
             "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0,\n"
             " \"scenes\": [{\"nodes\": [0, 1%s]}],\n"
             " \"nodes\": [{\"name\": \"floor\", \"mesh\": 0},\n"
             "   {\"name\": \"lamp\", \"mesh\": 1, \"translation\": [0, 1, 1], "
             "\"rotation\": [1, 0, 0, 0]}%s],\n"
             " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, "
             "\"material\": 0}]},\n"
             "   {\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, "
             "\"material\": 1}]}],\n"
             " \"materials\": [{\"pbrMetallicRoughness\": "
             "{\"baseColorFactor\": [0.5, 0.5, 0.5, 1]}},\n"
             "   {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1]}, "
             "\"emissiveFactor\": [1, 1, 1]}],\n"
             " \"buffers\": [{\"byteLength\": 60, \"uri\": \"data:application/octet-stream;base64,"
             "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAgD8AAAAAAAAAAAAAgD8"
             "AAAAAAAABAAIAAAACAAMA\"}],\n"
             " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 48}, "
             "{\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 12}],\n"
             " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, "
             "\"type\": \"VEC3\"},\n"
             "   {\"bufferView\": 1, \"componentType\": 5123, \"count\": 6, "
             "\"type\": \"SCALAR\"}]%s}\n",
             extra_nodes[0] ? ", 2" : "", extra_nodes, extra);
    test_write_file(name, text);
    free(text);
}

/* An orthographic glTF camera, which the renderer does not draw, no longer
 * fails the run: one warning line, the view framed automatically, exit 0. */
static void test_gltf_orthographic_camera(void **state)
{
    (void)state;
    write_gltf("ortho.gltf",
               ",\n   {\"name\": \"top\", \"camera\": 0, \"translation\": [0.5, 0.5, 3]}",
               ", \"cameras\": [{\"type\": \"orthographic\", \"orthographic\": "
               "{\"xmag\": 1, \"ymag\": 1, \"znear\": 0.1, \"zfar\": 10}}]");
    assert_int_equal(cli_run_here("render ortho.gltf -o ortho.png --elements 50 --width 32 --height 32"), 0);
    cli_assert_one_line_error("radiosity: warning: ortho.gltf: camera 0 of node 'top' (2) is "
                          "orthographic, which the renderer does not draw",
                          "the view is framed automatically");
    assert_true(test_file_exists(test_path("ortho.png")));
}

/* What a material says that the engine does not use (a highlight, a
 * texture) is said once on stderr, one line a material; the run still
 * exits 0 and writes its image. */
static void test_unused_material_properties(void **state)
{
    (void)state;
    test_write_file("shiny.mtl", "newmtl white\nKd 0.5 0.5 0.5\nKs 0.8 0.8 0.8\nNs 100\nillum 2\n"
                            "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\nKs 0 0 0\nd 1\nillum 1\n");
    test_write_file("shiny.obj", "mtllib shiny.mtl\n"
                            "o floor\nusemtl white\n"
                            "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 4 3 2\n"
                            "o lamp\nusemtl lamp\n"
                            "v 0 1 0\nv 1 1 0\nv 1 1 1\nv 0 1 1\nf 5 6 7 8\n");
    assert_int_equal(cli_run_here("render shiny.obj -o shiny.png --elements 50 --width 32 --height 32"), 0);
    cli_assert_one_line_error("radiosity: warning: shiny.mtl: material 'white' (surface 'floor'): Ks, "
                          "Ns and illum 2 are not used (the engine reads Kd and Ke, and the specular keys with illum 3 to 7)",
                          NULL);
    assert_true(test_file_exists(test_path("shiny.png")));
}

/* glTF files refused before assimp reads them: a tree 2,000 nodes deep
 * (20,000 overflowed the stack inside assimp), an index out of range
 * (assimp dropped the triangle): one line, exit 1, no output. */
static void test_gltf_refused(void **state)
{
    (void)state;
    size_t size = 64 * 2000 + 256, length = 0;
    char *nodes = malloc(size);
    assert_non_null(nodes);
    for (int i = 0; i < 1999; i++)
        length += (size_t)snprintf(nodes + length, size - length, ",\n   {\"children\": [%d]}",
                                   i + 3);
    snprintf(nodes + length, size - length, ",\n   {\"name\": \"bottom\"}");
    write_gltf("deep.gltf", nodes, "");
    free(nodes);
    assert_int_equal(cli_run_here("render deep.gltf -o bad_out.png"), 1);
    cli_assert_one_line_error("deep.gltf: node 'bottom' (2001) is nested 2000 levels deep",
                          "at most 1000 levels are read");
    assert_no_output("bad_out");

    write_gltf("range.gltf", "", "");
    char *text = NULL;
    char path[600];
    snprintf(path, sizeof path, "%s/range.gltf", test_workdir());
    FILE *f = fopen(path, "r+b");
    assert_non_null(f);
    text = calloc(1, 8192);
    assert_non_null(text);
    size_t n = fread(text, 1, 8191, f);
    /* the last index, 3 (its group of bytes 00 03 00 is "AAMA"), becomes 9
     * (00 09 00, "AAkA") */
    char *last = strstr(text, "AAACAAMA");
    assert_non_null(last);
    memcpy(last + 4, "AAkA", 4);
    rewind(f);
    assert_int_equal(fwrite(text, 1, n, f), n);
    fclose(f);
    free(text);
    assert_int_equal(cli_run_here("render range.gltf -o bad_out.png"), 1);
    cli_assert_one_line_error("range.gltf: mesh 0 primitive 0: index 5 refers to vertex 9 of 4", NULL);
    assert_no_output("bad_out");
}

/* The reader is the content's: an OBJ named `noext`, `s.gltf` or `s.txt`
 * is pre-scanned like any OBJ (before: it reached assimp, which read its
 * NaN coordinate), and a good one renders whatever its name. */
static void test_scene_format_by_content(void **state)
{
    (void)state;
    static const char *const names[] = {"noext", "s.gltf", "s.txt"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        char needle[64];
        snprintf(needle, sizeof needle, "%s:2: vertex coordinate 'nan' is not a finite number",
                 names[i]);
        bad_scene(names[i], "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", NULL, NULL, needle, NULL);
    }
    test_write_file("good.mtl", cli_good_mtl);
    test_write_file("room", cli_good_obj);
    assert_int_equal(cli_run_here("render room -o room.png --width 16 --height 16 --elements 50 "
                         "--stats room.json"),
                     0);
    char path[600], text[16384];
    snprintf(path, sizeof path, "%s/room.json", test_workdir());
    test_read_into(path, text, sizeof text);
    assert_non_null(strstr(text, "\"name\":\t\"lamp\""));
    assert_non_null(strstr(text, "\"emission\":\t[3.14159265358979")); /* pi Ke, Ke = 1 */
}

/* A face of fewer than 3 vertices is an error with its line (before: it
 * was dropped silently); a line is `l`, and is ignored. */
static void test_face_vertex_count(void **state)
{
    (void)state;
    bad_scene("twoverts.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", NULL, NULL,
              "twoverts.obj:4: face needs 3 or more vertices, has 2 ('l' is for lines)", NULL);
    bad_scene("samevert.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 2 2 2\n", NULL, NULL,
              "samevert.obj:5: face needs 3 or more distinct vertices, has 1", NULL);
}

/* `mtllib walls.mtl lamps.mtl`: both libraries are read and their
 * materials used (before: "walls.mtl lamps.mtl" was taken for one file
 * name, which did not exist); a missing second one is the error a missing
 * first one is. */
static void test_several_material_libraries(void **state)
{
    (void)state;
    const char *body = cli_good_obj + strlen("mtllib good.mtl\n");
    char obj[1024];
    test_write_file("walls.mtl", "newmtl white\nKd 0.5 0.5 0.5\n");
    test_write_file("lamps.mtl", "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n");
    snprintf(obj, sizeof obj, "mtllib walls.mtl lamps.mtl\n%s", body);
    test_write_file("libs.obj", obj);
    assert_int_equal(cli_run_here("render libs.obj -o libs.png --width 16 --height 16 --elements 50 "
                         "--stats libs.json"),
                     0);
    char path[600], text[16384];
    snprintf(path, sizeof path, "%s/libs.json", test_workdir());
    test_read_into(path, text, sizeof text);
    assert_non_null(strstr(text, "\"emission\":\t[3.14159265358979"));
    snprintf(obj, sizeof obj, "mtllib walls.mtl missing.mtl\n%s", body);
    bad_scene("libs2.obj", obj, NULL, NULL,
              "libs2.obj:1: material library 'missing.mtl': cannot open: No such file or directory",
              NULL);
}

/* ---- bad input: the command line ---- */

/* A method name is checked against the library's registry while parsing:
 * a usage error that lists the known names. */
static void test_unknown_method_names(void **state)
{
    (void)state;
    assert_int_equal(cli_run_here("render -o bad_out.png --solver nosuch"), 2);
    cli_assert_one_line_error("--solver: expected one of", "gauss-seidel");
    assert_int_equal(cli_run_here("render -o bad_out.png --form-factors nosuch"), 2);
    cli_assert_one_line_error("nosuch", "analytic");
    assert_int_equal(cli_run_here("viewfactors -o bad_out.json --visibility nosuch"), 2);
    cli_assert_one_line_error("nosuch", "embree");
    assert_no_output("bad_out");
}

static void test_usage_errors(void **state)
{
    (void)state;
    assert_int_equal(cli_run_here("render --width abc"), 2);
    cli_assert_one_line_error("--width", "abc");
    assert_int_equal(cli_run_here("render --mesh-size -1"), 2);
    cli_assert_one_line_error("--mesh-size", NULL);
    assert_int_equal(cli_run_here("render --tolerance nan"), 2);
    cli_assert_one_line_error("--tolerance", NULL);
    assert_int_equal(cli_run_here("render --bogus"), 2);
    cli_assert_one_line_error("--bogus", NULL);
    assert_int_equal(cli_run_here("frobnicate"), 2);
    cli_assert_one_line_error("frobnicate", NULL);
    assert_int_equal(cli_run_here("render --camera 1,2,3"), 2);
    cli_assert_one_line_error("--camera", NULL);
    assert_int_equal(cli_run_here("render a.obj b.obj"), 2);
    cli_assert_one_line_error("more than one scene", NULL);
    assert_int_equal(cli_run_here("render --solver"), 2);
    cli_assert_one_line_error("--solver", NULL);
    assert_int_equal(cli_run_here("render --oracle nosuch"), 2);
    cli_assert_one_line_error("--oracle", "nosuch");
    assert_int_equal(cli_run_here("render --tolerance 2"), 2);
    cli_assert_one_line_error("--tolerance: expected a number in (0, 1), got '2'", NULL);
    assert_int_equal(cli_run_here("render --rooms 3"), 2);
    cli_assert_one_line_error("--rooms does not apply to render", NULL);
    assert_int_equal(cli_run_here("render -o ''"), 2);
    cli_assert_one_line_error("--output needs a value", NULL);
    /* The library's refusal, its field written as our flag. */
    assert_int_equal(cli_run_here("render --solver shooting --closure-correction -o cc.png"), 1);
    cli_assert_one_line_error("--closure-correction rescales", "shooting");
    assert_no_output("cc.png");
    assert_int_equal(cli_run_here("%s", ""), 2); /* no command at all */
    assert_no_output("radiosity.png");
}

static void test_unwritable_output(void **state)
{
    (void)state;
    test_write_file("good.obj", cli_good_obj);
    test_write_file("good.mtl", cli_good_mtl);
    assert_int_equal(cli_run_here("render good.obj --elements 50 -o no_such_dir/out.png"), 1);
    cli_assert_one_line_error("no_such_dir/out.png", NULL);
    /* An unknown format is refused before any work, as a usage error. */
    assert_int_equal(cli_run_here("render good.obj --elements 50 -o out.xyz"), 2);
    cli_assert_one_line_error("out.xyz", ".png");
    assert_no_output("out.xyz");
}

/* ---- good runs ---- */

static void test_render_reports_output(void **state)
{
    (void)state;
    test_write_file("good.obj", cli_good_obj);
    test_write_file("good.mtl", cli_good_mtl);
    assert_int_equal(cli_run_here("render good.obj --solver gauss-seidel --elements 50 --width 16 --height 16 -o good.png "
                                  "--stats good.json"), 0);
    assert_true(test_file_exists(test_path("good.png")));
    assert_true(test_file_exists(test_path("good.json")));
    assert_non_null(strstr(cli_stdout(), "good.png"));
    assert_string_equal(cli_stderr(), ""); /* no progress bar without a terminal */
    assert_non_null(strstr(cli_stdout(), "50 elements, gauss-seidel, residual"));
    /* --elements without --solver: gauss-seidel, and the line says why. */
    assert_int_equal(cli_run_here("render good.obj --elements 50 --width 16 --height 16 -o good.png"), 0);
    assert_non_null(strstr(cli_stdout(), "50 elements, gauss-seidel for --elements, residual"));
    assert_string_equal(cli_stderr(), "");
    assert_int_equal(cli_run_here("render good.obj --width 16 --height 16 -o good.png"), 0);
    assert_non_null(strstr(cli_stdout(), " elements, hierarchical, residual"));
    assert_int_equal(cli_run_here("render good.obj --elements 50 --width 16 --height 16 -o good.pfm -q"), 0);
    assert_true(test_file_exists(test_path("good.pfm")));
    assert_string_equal(cli_stdout(), "");
}

/* export: an unknown mesh format is a usage error before the load (the
 * scene named does not even exist); a good run writes the mesh and its
 * stats, and says where. */
static void test_export(void **state)
{
    (void)state;
    assert_int_equal(cli_run_here("export no_such_scene.obj -o x.obj --stats x.json"), 2);
    cli_assert_one_line_error("x.obj: unknown mesh format", ".glb, .gltf or .ply");
    assert_no_output("x.");
    test_write_file("good.obj", cli_good_obj);
    test_write_file("good.mtl", cli_good_mtl);
    assert_int_equal(cli_run_here("export good.obj -o x.obj"), 2);
    cli_assert_one_line_error("x.obj: unknown mesh format", NULL);
    assert_no_output("x.");
    /* Flags of render only are refused. */
    assert_int_equal(cli_run_here("export good.obj --width 16 -o lit.glb"), 2);
    cli_assert_one_line_error("--width does not apply to export", NULL);
    assert_no_output("lit.");
    assert_int_equal(cli_run_here("export good.obj --elements 50 --solver southwell --exposure 2 -o lit.glb --stats lit.json"),
                     0);
    assert_true(test_file_exists(test_path("lit.glb")));
    assert_true(test_file_exists(test_path("lit.json")));
    assert_non_null(strstr(cli_stdout(), "lit.glb ("));
    assert_non_null(strstr(cli_stdout(), " vertices, "));
    assert_string_equal(cli_stderr(), "");
    assert_int_equal(cli_run_here("export good.obj --elements 50 -o lit.ply -q"), 0);
    assert_true(test_file_exists(test_path("lit.ply")));
    assert_string_equal(cli_stdout(), "");
    assert_int_equal(cli_run_here("export --help"), 0);
    assert_non_null(strstr(cli_stdout(), "usage: radiosity export"));
    assert_non_null(strstr(cli_stdout(), "--exposure X"));
    assert_non_null(strstr(cli_stdout(), "--solver NAME"));
    assert_null(strstr(cli_stdout(), "--camera"));
}

/* bake: an unknown mesh format or a bad atlas size is a usage error before
 * the load; a good run writes the glTF and the first atlas's HDR and PNG
 * beside it, from a scene or from a solution file. */
static void test_bake(void **state)
{
    (void)state;
    assert_int_equal(cli_run_here("bake no_such_scene.obj -o baked.obj --stats baked.json"), 2);
    cli_assert_one_line_error("baked.obj: unknown lightmapped mesh format", ".glb or .gltf");
    assert_no_output("baked");
    assert_int_equal(cli_run_here("bake no_such_scene.obj -o baked.ply"), 2);
    cli_assert_one_line_error("baked.ply: unknown lightmapped mesh format", NULL);
    assert_int_equal(cli_run_here("bake no_such_scene.obj -o baked.glb --atlas-size 1000"), 2);
    cli_assert_one_line_error("--atlas-size: expected a power of two", NULL);
    assert_no_output("baked");
    test_write_file("good.obj", cli_good_obj);
    test_write_file("good.mtl", cli_good_mtl);
    assert_int_equal(cli_run_here("bake good.obj --solver gauss-seidel --elements 50 --texels-per-metre 20 -o baked.glb "
                                  "--stats baked.json"), 0);
    assert_true(test_file_exists(test_path("baked.glb")));
    assert_true(test_file_exists(test_path("baked_lightmap0.hdr")));
    assert_true(test_file_exists(test_path("baked_lightmap0.png")));
    assert_true(test_file_exists(test_path("baked.json")));
    assert_non_null(strstr(cli_stdout(), "baked.glb and 1 lightmap (fill "));
    assert_string_equal(cli_stderr(), "");
    /* Too many texels for an atlas: one line, nothing written. */
    assert_int_equal(cli_run_here("bake good.obj --elements 50 --texels-per-metre 1e5 -o huge.glb -q"), 1);
    cli_assert_one_line_error("above the atlas limit", NULL);
    assert_no_output("huge.glb");
    assert_no_output("huge_");
    assert_int_equal(cli_run_here("solve good.obj --elements 50 -q -o baked.radsol"), 0);
    assert_int_equal(cli_run_here("bake baked.radsol --lightmap irradiance -q -o again.gltf"), 0);
    assert_true(test_file_exists(test_path("again.gltf")) && test_file_exists(test_path("again_lightmap0.png")) && test_file_exists(test_path("again_lightmap0.hdr")));
    assert_int_equal(cli_run_here("bake --help"), 0);
    assert_non_null(strstr(cli_stdout(), "--texels-per-metre N"));
    assert_non_null(strstr(cli_stdout(), "--lightmap WHICH"));
}

static void test_help_version_methods(void **state)
{
    (void)state;
    assert_int_equal(cli_run_here("--help"), 0);
    assert_non_null(strstr(cli_stdout(), "--mesh-size"));
    assert_non_null(strstr(cli_stdout(), "viewfactors"));
    assert_non_null(strstr(cli_stdout(), "--rooms"));
    /* A command's help has its flags only. */
    assert_int_equal(cli_run_here("render --help"), 0);
    assert_non_null(strstr(cli_stdout(), "usage: radiosity render"));
    assert_non_null(strstr(cli_stdout(), "--samples N"));
    assert_null(strstr(cli_stdout(), "--rooms"));
    assert_int_equal(cli_run_here("generate --help"), 0);
    assert_non_null(strstr(cli_stdout(), "--rooms N"));
    assert_null(strstr(cli_stdout(), "--solver"));
    assert_int_equal(cli_run_here("--man"), 0);
    assert_true(strncmp(cli_stdout(), ".TH RADIOSITY 1", 15) == 0);
    assert_int_equal(cli_run_here("--version"), 0);
    assert_non_null(strstr(cli_stdout(), "radiosity 0."));
    assert_int_equal(cli_run_here("--list-methods"), 0);
    assert_non_null(strstr(cli_stdout(), "analytic"));
    assert_non_null(strstr(cli_stdout(), "southwell"));
    assert_non_null(strstr(cli_stdout(), "brute"));
    /* The registry's descriptions name fields; the listing names flags. */
    assert_non_null(strstr(cli_stdout(), "(--relaxation)"));
    assert_null(strstr(cli_stdout(), "rad_options."));
}

static void test_viewfactors_csv(void **state)
{
    (void)state;
    test_write_file("good.obj", cli_good_obj);
    test_write_file("good.mtl", cli_good_mtl);
    assert_int_equal(cli_run_here("viewfactors good.obj --elements 64 -o vf.csv"), 0);
    char path[600], text[4096];
    snprintf(path, sizeof path, "%s/vf.csv", test_workdir());
    test_read_into(path, text, sizeof text);
    assert_true(strncmp(text, "from,area_m2,floor,lamp\n", 24) == 0);
    /* Two unit squares 1 m apart, facing: F = 0.1998 both ways. */
    double area, f_ff, f_fl;
    assert_int_equal(sscanf(strchr(text, '\n') + 1, "floor,%lf,%lf,%lf", &area, &f_ff, &f_fl), 3);
    assert_true(fabs(area - 1.0) < 1e-12);
    assert_true(f_ff == 0.0);
    assert_true(fabs(f_fl - 0.199824895698) < 2e-4);
}

/* Same scene, options and seed: bit-identical image and radiosities with 1
 * and 2 threads. */
static void test_deterministic_across_threads(void **state)
{
    (void)state;
    char a[600], b[600], ta[8192], tb[8192];
    for (int threads = 1; threads <= 2; threads++)
        assert_int_equal(cli_run_here("render --elements 400 --width 48 --height 48 --threads %d -o det%d.pfm "
                             "--stats det%d.json",
                             threads, threads, threads),
                         0);
    snprintf(a, sizeof a, "%s/det1.pfm", test_workdir());
    snprintf(b, sizeof b, "%s/det2.pfm", test_workdir());
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    assert_non_null(fa);
    assert_non_null(fb);
    size_t na = fread(ta, 1, sizeof ta, fa), nb = fread(tb, 1, sizeof tb, fb);
    fclose(fa);
    fclose(fb);
    assert_true(na > 1000);
    assert_int_equal(na, nb);
    assert_memory_equal(ta, tb, na);
    /* The per-surface radiosities in the stats agree to the last digit. */
    snprintf(a, sizeof a, "%s/det1.json", test_workdir());
    snprintf(b, sizeof b, "%s/det2.json", test_workdir());
    test_read_into(a, ta, sizeof ta);
    test_read_into(b, tb, sizeof tb);
    const char *sa = strstr(ta, "\"surfaces\""), *sb = strstr(tb, "\"surfaces\"");
    assert_non_null(sa);
    assert_non_null(sb);
    /* "surfaces" is followed by the top-level "seconds" (timings differ). */
    const char *ea = strstr(sa, "\"seconds\""), *eb = strstr(sb, "\"seconds\"");
    assert_non_null(ea);
    assert_non_null(eb);
    assert_int_equal(ea - sa, eb - sb);
    assert_memory_equal(sa, sb, (size_t)(ea - sa));
}

/* SIGINT / SIGTERM while solving: the current solution is written, marked
 * partial, and the exit status is 130 / 143.  The matrix-free solver with an
 * unreachable tolerance keeps the run in its solve phase long enough. */
static void interrupt_with(int sig, int expected_status, const char *tag)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && ('%s' render --solver shooting --elements 20000 --unshot-tolerance 1e-12 "
             "--ff-samples 64 --width 32 --height 32 -o int_%s.png --stats int_%s.json "
             ">int_out.txt 2>int_err.txt & pid=$!; sleep 2; kill -%d $pid; wait $pid; echo $? > int_status.txt)",
             test_workdir(), cli_binary(), tag, tag, sig);
    assert_int_equal(system(cmd), 0);
    char path[600], text[8192];
    snprintf(path, sizeof path, "%s/int_status.txt", test_workdir());
    test_read_into(path, text, sizeof text);
    assert_int_equal(atoi(text), expected_status);
    char name[64];
    snprintf(name, sizeof name, "int_%s.png", tag);
    assert_true(test_file_exists(test_path(name)));
    snprintf(path, sizeof path, "%s/int_%s.json", test_workdir(), tag);
    test_read_into(path, text, sizeof text);
    assert_non_null(strstr(text, "\"partial\":\ttrue"));
    assert_non_null(strstr(text, "\"converged\":\tfalse"));
    snprintf(path, sizeof path, "%s/int_err.txt", test_workdir());
    test_read_into(path, text, sizeof text);
    assert_non_null(strstr(text, "interrupted"));
}

static void test_interrupt_writes_partial(void **state)
{
    (void)state;
    interrupt_with(2, 130, "int");   /* SIGINT */
    interrupt_with(15, 143, "term"); /* SIGTERM */
}

/* ---- limits: every large allocation is estimated first, and refused with
 * the option that avoids it (docs/robustness.md) ---- */

static void too_big(const char *args, const char *needle1, const char *needle2)
{
    assert_int_equal(cli_run_here("render %s -o big.png --stats big.json", args), 1);
    cli_assert_one_line_error(needle1, needle2);
    assert_no_output("big");
}

static void test_limits(void **state)
{
    (void)state;
    /* 8e10 elements: past uint32 element indices, refused before any
     * allocation. */
    too_big("--mesh-size 1e-9", "exceed the limit", "--mesh-size");
    /* The dense matrix of the default 2000 elements (32 MB) in 1 MB. */
    too_big("--solver gauss-seidel --max-memory 1M", "(--max-memory)", "'shooting' (--solver");
    /* A matrix-free run whose mesh alone is over the limit. */
    too_big("--solver shooting --elements 300000 --max-memory 20M", "mesh:", "--elements");
    /* Hit records of 10^8 rays a shot. */
    too_big("--solver shooting --elements 200 --ff-samples 100000000 --max-memory 1G", "shooting:",
            "--ff-samples");
    /* A hemicube's buffers: 3 x 8192^2 pixels a thread. */
    too_big("--elements 200 --form-factors hemicube --hemicube-res 8192 --max-memory 1G", "hemicube",
            "--hemicube-res");
    /* A 16384 x 16384 image. */
    too_big("--elements 200 --width 16384 --height 16384 --max-memory 1G", "render:", "--width");
    /* Element-to-element view factors: 3000^2 doubles (69 MiB) beside F's
     * as many do not fit in 100 MB, so they are made in row blocks
     * (docs/formats.md, "Streamed view factors") and written. */
    assert_int_equal(cli_run_here("viewfactors --elements 3000 --level element --max-memory 100M -o big.csv"), 0);
    char big[600];
    snprintf(big, sizeof big, "%s/big.csv", test_workdir());
    assert_int_equal(access(big, F_OK), 0);
    remove(big);
}

/* --max-memory limits loading too: endless input (/dev/zero under an OBJ
 * name) is read only up to the limit, a file larger than the limit is
 * refused by its size without being read, and /dev/zero itself is no
 * scene; each fails at once with one line and exit status 1. */
static void test_loading_limits(void **state)
{
    (void)state;
    char path[600], cmd[4096];
    /* /dev/zero under an OBJ name, with and without a limit: a NUL byte
     * in the first piece read, at once (before: with no --max-memory it
     * grew to 24 GB until the kernel killed it). */
    snprintf(path, sizeof path, "%s/zero.obj", test_workdir());
    remove(path);
    assert_int_equal(symlink("/dev/zero", path), 0);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    assert_int_equal(cli_run_here("render zero.obj -o zout.png --max-memory 64M"), 1);
    cli_assert_one_line_error("zero.obj:1: NUL byte in the text", NULL);
    assert_int_equal(cli_run_here("render zero.obj -o zout.png"), 1);
    cli_assert_one_line_error("zero.obj:1: NUL byte in the text", NULL);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    assert_true((double)(t1.tv_sec - t0.tv_sec) < 20.0);
    assert_no_output("zout");
    remove(path);
    assert_int_equal(cli_run_here("render /dev/zero -o zout.png"), 1);
    cli_assert_one_line_error("/dev/zero:1: NUL byte in the text", NULL);
    assert_int_equal(cli_run_here("render /dev/urandom -o zout.png"), 1);
    cli_assert_one_line_error("/dev/urandom:", "NUL byte in the text");

    /* A FIFO that never ends: read up to what the import could take
     * within the limit (1/20 of it), then refused.  With no --max-memory
     * the limit is half of what the process may use: here ulimit -v 2 GiB
     * (where the program can run so: not under AddressSanitizer, which
     * reserves terabytes of address space). */
    snprintf(path, sizeof path, "%s/endless.obj", test_workdir());
    remove(path);
    assert_int_equal(mkfifo(path, 0600), 0);
    snprintf(cmd, sizeof cmd, "(ulimit -v 2097152; '%s' --version) >/dev/null 2>&1", cli_binary());
    int runs = system(cmd) == 0 ? 2 : 1;
    const char *limits[2] = {"--max-memory 64M", ""};
    const char *ulimits[2] = {"", "ulimit -v 2097152; "};
    const char *expected[2] = {
        "endless.obj: a file of more than 3.2 MiB may need more than 64.0 MiB to import (20x its "
        "size), above the memory limit of 64.0 MiB (--max-memory)",
        "endless.obj: a file of more than 51.2 MiB may need more than 1.00 GiB to import (20x its "
        "size), above the memory limit of 1.00 GiB (--max-memory)"};
    for (int k = 0; k < runs; k++) {
        /* The writer opens the FIFO under `timeout`: it waits for a reader. */
        snprintf(cmd, sizeof cmd,
                 "cd '%s' && (timeout 60 sh -c \"yes 'v 0 0 0' > endless.obj\" >/dev/null 2>&1 &) "
                 "&& (%s'%s' render endless.obj -o zout.png %s >stdout.txt 2>stderr.txt "
                 "</dev/null)",
                 test_workdir(), ulimits[k], cli_binary(), limits[k]);
        int status = system(cmd);
        cli_stderr_from(test_path("stderr.txt"));
        assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 1);
        cli_assert_one_line_error(expected[k], NULL);
        assert_no_output("zout");
    }
    snprintf(path, sizeof path, "%s/endless.obj", test_workdir());
    remove(path);

    /* Sparse files: refused by their size, unread; or, with room for them,
     * stopped by the NUL byte at their start. */
    snprintf(path, sizeof path, "%s/sparse.obj", test_workdir());
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fclose(f);
    assert_int_equal(truncate(path, (off_t)100 << 30), 0); /* 100 GiB, no blocks */
    assert_int_equal(cli_run_here("render sparse.obj -o zout.png --max-memory 64M"), 1);
    cli_assert_one_line_error("sparse.obj: a file of 100.00 GiB may need 2000.00 GiB to import (20x "
                          "its size), above the memory limit of 64.0 MiB (--max-memory)",
                          NULL);
    assert_int_equal(truncate(path, (off_t)2 << 30), 0); /* 2 GiB */
    clock_gettime(CLOCK_MONOTONIC, &t0);
    assert_int_equal(cli_run_here("render sparse.obj -o zout.png"), 1);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    assert_true((double)(t1.tv_sec - t0.tv_sec) < 20.0);
    if (!strstr(cli_stderr(), "sparse.obj:1: NUL byte in the text"))
        cli_assert_one_line_error("sparse.obj: a file of 2.00 GiB may need 40.00 GiB to import", NULL);
    assert_no_output("zout");
    remove(path);
}

/* SIGTERM while the form factors are computed (the dense analytic matrix
 * for 12,000 elements takes far longer than the 2 s we wait): exit 143,
 * the stats say "partial" and name the phase, no image (there is no
 * radiosity yet) and no temporary file is left. */
static void test_interrupt_during_form_factors(void **state)
{
    (void)state;
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && ('%s' render --elements 12000 --width 32 --height 32 -o ffint.png "
             "--stats ffint.json >ffint_out.txt 2>ffint_err.txt & pid=$!; sleep 2; kill -15 $pid; "
             "wait $pid; echo $? > ffint_status.txt)",
             test_workdir(), cli_binary());
    assert_int_equal(system(cmd), 0);
    char path[600], text[8192];
    snprintf(path, sizeof path, "%s/ffint_status.txt", test_workdir());
    test_read_into(path, text, sizeof text);
    assert_int_equal(atoi(text), 143);
    assert_false(test_file_exists(test_path("ffint.png")));
    snprintf(path, sizeof path, "%s/ffint.json", test_workdir());
    test_read_into(path, text, sizeof text);
    assert_non_null(strstr(text, "\"partial\":\ttrue"));
    assert_non_null(strstr(text, "\"interrupted\":\t\"form factors\""));
    assert_non_null(strstr(text, "\"scene\":\t\"cornell-box\""));
    assert_non_null(strstr(text, "\"surfaces\":\t8"));
    assert_no_output("ffint.png");
    assert_no_output("ffint.json.tmp");
    snprintf(path, sizeof path, "%s/ffint_err.txt", test_workdir());
    test_read_into(path, text, sizeof text);
    assert_non_null(strstr(text, "interrupted while computing form factors; wrote partial stats"));
}

/* --seed is one parser in every command: an unsigned 64-bit integer in
 * decimal digits, exact (no double on the way), and the same one-line
 * refusal of anything else, exit 2; the stats carry the seed's exact
 * digits (they went through a double: 9007199254740993 was written as
 * ...992). */
static void test_seed(void **state)
{
    (void)state;
    const char *good[] = {"0", "9007199254740993", "18446744073709551615"};
    for (size_t k = 0; k < 3; k++) {
        assert_int_equal(cli_run_here("render --elements 24 --width 4 --height 4 -o seed.png --stats seed.json --seed %s",
                             good[k]),
                         0);
        char path[600], text[16384], want[64];
        snprintf(path, sizeof path, "%s/seed.json", test_workdir());
        test_read_into(path, text, sizeof text);
        snprintf(want, sizeof want, "\"seed\":\t%s,", good[k]);
        if (!strstr(text, want))
            fail_msg("the stats lack %s", want);
    }
    const char *bad[] = {"-1", "18446744073709551616", "0x10", "1e3", "1.5", "+1", "' 1'", "seven", "''"};
    const char *commands[] = {"render -o seed.png", "viewfactors -o seed.json", "generate office -o seed.obj"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++)
        for (size_t c = 0; c < 3; c++) {
            assert_int_equal(cli_run_here("%s --seed %s", commands[c], bad[k]), 2);
            if (strcmp(bad[k], "''") == 0)
                cli_assert_one_line_error("--seed needs a value", NULL);
            else
                cli_assert_one_line_error("--seed: expected an integer in [0, 18446744073709551615], got '", NULL);
        }
}

static int setup(void **state)
{
    (void)state;
    return test_workdir_make("cli");
}

static int teardown(void **state)
{
    (void)state;
    return test_workdir_remove();
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_cli PATH_TO_RADIOSITY\n");
        return 2;
    }
    cli_set_binary(argv[1]);
    /* "--slow" after the program's path: the cases at scale instead of the quick ones. */
    bool slow = argc == 3 && strcmp(argv[2], "--slow") == 0;
    if (argc > 3 || (argc == 3 && !slow)) {
        fprintf(stderr, "usage: test_cli PATH_TO_RADIOSITY [--slow]\n");
        return 2;
    }
    const struct CMUnitTest fast_tests[] = {
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_malformed_obj),
        cmocka_unit_test(test_face_index_out_of_range),
        cmocka_unit_test(test_nan_coordinates),
        cmocka_unit_test(test_infinite_coordinates),
        cmocka_unit_test(test_huge_coordinates),
        cmocka_unit_test(test_solution_file),
        cmocka_unit_test(test_progress_images_hierarchical),
        cmocka_unit_test(test_zero_area_polygon),
        cmocka_unit_test(test_reflectance_too_high),
        cmocka_unit_test(test_reflectance_negative),
        cmocka_unit_test(test_no_emitter),
        cmocka_unit_test(test_empty_scene),
        cmocka_unit_test(test_malformed_gltf),
        cmocka_unit_test(test_gltf_orthographic_camera),
        cmocka_unit_test(test_unused_material_properties),
        cmocka_unit_test(test_gltf_refused),
        cmocka_unit_test(test_scene_format_by_content),
        cmocka_unit_test(test_face_vertex_count),
        cmocka_unit_test(test_several_material_libraries),
        cmocka_unit_test(test_unknown_method_names),
        cmocka_unit_test(test_usage_errors),
        cmocka_unit_test(test_seed),
        cmocka_unit_test(test_unwritable_output),
        cmocka_unit_test(test_render_reports_output),
        cmocka_unit_test(test_export),
        cmocka_unit_test(test_bake),
        cmocka_unit_test(test_help_version_methods),
        cmocka_unit_test(test_viewfactors_csv),
        cmocka_unit_test(test_deterministic_across_threads),
        cmocka_unit_test(test_interrupt_writes_partial),
        cmocka_unit_test(test_loading_limits),
    };
    /* At scale: with --slow alone (CTest: test_cli_slow, label slow). */
    const struct CMUnitTest slow_tests[] = {
        cmocka_unit_test(test_interrupt_during_form_factors),
        cmocka_unit_test(test_limits),
    };
    return slow ? cmocka_run_group_tests_name("cli_slow", slow_tests, setup, teardown)
                : cmocka_run_group_tests_name("cli", fast_tests, setup, teardown);
}
