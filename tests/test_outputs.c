/*
 * test_outputs.c -- where output files go, and what is left when a run
 * fails or is interrupted (docs/robustness.md, "Output files").
 *
 *   temporaries   unpredictable names made with O_EXCL: a link planted at
 *                 the old predictable name is never followed; names short
 *                 enough for a 255-byte output name
 *   targets       devices, FIFOs and stdout written in place, never renamed
 *                 over; a link to a regular file replaces its target; a
 *                 dangling link, a folder, a missing folder are refused
 *   aliasing      an output that is an input (the scene, its MTL, a glTF's
 *                 buffer) or another output, by any name: exit 2
 *   all or none   the output set: a failure leaves every old file
 *   signals       at each stage: exit 130 / 143, what exists saved and
 *                 marked, no temporary left; a second signal loses nothing
 *
 * The library's output set is tested directly; the rest drives the
 * `radiosity` program (argv[1]).  Runs that must be caught at a stage are
 * watched, never timed: the program's progress on a pseudo-terminal names
 * the phase it is in, a progress frame appearing marks the solve, and
 * /proc shows when `generate` has its signal handlers.
 */
/* posix_openpt, grantpt, unlockpt and ptsname are X/Open. */
#define _XOPEN_SOURCE 700

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "cli_support.h"
#include "core/core.h"

#include <cjson/cJSON.h>

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* The longest any watched run may take before the test gives up on it. */
enum { WATCH_SECONDS = 300 };

/* A short pause inside a polling loop (never a wait for a stage). */
static void pause_ms(long ms)
{
    struct timespec t = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&t, NULL);
}

/* ---- files in the work folder ---- */

/* The whole of a work file (static buffer), "" when missing. */
static const char *text_of(const char *name)
{
    static char text[65536];
    test_read_into(test_path(name), text, sizeof text);
    return text;
}

/* No temporary of ours in a folder: no hidden file, no "*.tmp.*". */
static void assert_no_temporaries(const char *folder)
{
    DIR *d = opendir(folder);
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d)))
        if ((e->d_name[0] == '.' && strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) ||
            strstr(e->d_name, ".tmp."))
            fail_msg("temporary left in %s: %s", folder, e->d_name);
    closedir(d);
}

/* A quad lamp over a quad floor as glTF whose geometry is the external
 * buffer quad.bin (the loader reads it). */
/* A glTF `name` (in the work folder) whose buffer is at `uri`; the buffer
 * itself is always written as work/quad.bin. */
static void write_gltf_referring(const char *name, const char *uri)
{
    float positions[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1},
                             {0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}};
    uint16_t indices[12] = {0, 3, 2, 0, 2, 1, 4, 7, 6, 4, 6, 5};
    FILE *f = fopen(test_path("quad.bin"), "wb");
    assert_non_null(f);
    fwrite(positions, sizeof positions, 1, f);
    fwrite(indices, sizeof indices, 1, f);
    fclose(f);
    char text[4096];
    snprintf(text, sizeof text,
               "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0, 1]}],"
               "\"nodes\": [{\"name\": \"floor\", \"mesh\": 0}, {\"name\": \"lamp\", \"mesh\": 1}],"
               "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, "
               "\"material\": 0}]}, {\"primitives\": [{\"attributes\": {\"POSITION\": 0}, "
               "\"indices\": 2, \"material\": 1}]}],"
               "\"materials\": [{\"name\": \"white\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1]}}, "
               "{\"name\": \"lamp\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1]}, "
               "\"emissiveFactor\": [1, 1, 1]}],"
               "\"buffers\": [{\"byteLength\": 120, \"uri\": \"%s\"}],"
               "\"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 96}, "
               "{\"buffer\": 0, \"byteOffset\": 96, \"byteLength\": 24}],"
               "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 8, "
               "\"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 1]}, "
               "{\"bufferView\": 1, \"byteOffset\": 0, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}, "
               "{\"bufferView\": 1, \"byteOffset\": 12, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}",
             uri);
    test_write_file(name, text);
}

static void write_gltf_with_buffer(void) { write_gltf_referring("quad.gltf", "quad.bin"); }

/* ======================================================================
 * The library: targets, temporaries, the output set, a scene's inputs
 * ==================================================================== */

static void test_temporary_names(void **state)
{
    (void)state;
    /* Unpredictable, new (O_EXCL), hidden, short, mode 0666 & ~umask. */
    char name[256];
    memset(name, 'n', 250);
    strcpy(name + 250, ".png");
    mode_t mask = umask(022);
    umask(mask);
    char *a, *b;
    int fa, fb;
    assert_int_equal(rad_temp_create(NULL, test_workdir(), name, ".png", "t", &a, &fa), RAD_OK);
    assert_int_equal(rad_temp_create(NULL, test_workdir(), name, ".png", "t", &b, &fb), RAD_OK);
    assert_string_not_equal(a, b);
    struct stat st;
    assert_int_equal(lstat(a, &st), 0);
    assert_true(S_ISREG(st.st_mode));
    assert_int_equal(st.st_mode & 0777, 0666 & ~mask);
    const char *base = strrchr(a, '/') + 1;
    assert_true(base[0] == '.' && strlen(base) < 64);
    assert_non_null(strstr(base, ".png"));
    close(fa);
    close(fb);
    unlink(a);
    unlink(b);
    rad_free(a);
    rad_free(b);
}

static void test_output_targets(void **state)
{
    (void)state;
    rad_output_target t;
    /* A link to a regular file resolves to the file. */
    test_write_file("real.json", "old");
    assert_int_equal(symlink("real.json", test_path("link.json")), 0);
    assert_int_equal(rad_output_target_resolve(NULL, test_path("link.json"), &t), RAD_OK);
    assert_false(t.stream);
    assert_string_equal(t.name, "real.json");
    rad_output_target_free(&t);
    /* Devices are streams. */
    assert_int_equal(rad_output_target_resolve(NULL, "/dev/null", &t), RAD_OK);
    assert_true(t.stream);
    rad_output_target_free(&t);
    /* Refused: a dangling link, a folder, a missing folder. */
    assert_int_equal(symlink("nowhere.json", test_path("dangling.json")), 0);
    assert_int_equal(rad_output_target_resolve(NULL, test_path("dangling.json"), &t), RAD_ERROR_IO);
    assert_int_equal(rad_output_target_resolve(NULL, test_workdir(), &t), RAD_ERROR_IO);
    assert_int_equal(rad_output_target_resolve(NULL, test_path("no/such.json"), &t), RAD_ERROR_IO);
    assert_null(t.path);
    unlink(test_path("link.json"));
    unlink(test_path("dangling.json"));
    unlink(test_path("real.json"));
}

/* Write `text` to an output set's temporary as a writer would. */
static void fill(const char *temp, const char *text)
{
    FILE *f = fopen(temp, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void test_output_set_all_or_none(void **state)
{
    (void)state;
    rad_context *ctx;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    test_write_file("a.json", "old a");
    test_write_file("b.json", "old b");

    /* Committed: both replaced, nothing else left. */
    rad_output_set *set;
    const char *ta, *tb;
    assert_int_equal(rad_output_set_create(ctx, &set), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("a.json"), RAD_OUTPUT_FILE, &ta), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("b.json"), RAD_OUTPUT_FILE, &tb), RAD_OK);
    fill(ta, "new a");
    fill(tb, "new b");
    assert_string_equal(text_of("a.json"), "old a"); /* nothing visible before the commit */
    assert_int_equal(rad_output_set_commit(ctx, set), RAD_OK);
    rad_output_set_destroy(set);
    assert_string_equal(text_of("a.json"), "new a");
    assert_string_equal(text_of("b.json"), "new b");
    assert_no_temporaries(test_workdir());

    /* Abandoned (a failure before the commit): the old files, no temporary. */
    assert_int_equal(rad_output_set_create(ctx, &set), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("a.json"), RAD_OUTPUT_FILE, &ta), RAD_OK);
    fill(ta, "lost");
    rad_output_set_destroy(set);
    assert_string_equal(text_of("a.json"), "new a");
    assert_no_temporaries(test_workdir());

    /* Dropped: that file stays, the others are replaced. */
    assert_int_equal(rad_output_set_create(ctx, &set), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("a.json"), RAD_OUTPUT_FILE, &ta), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("b.json"), RAD_OUTPUT_FILE, &tb), RAD_OK);
    fill(tb, "b3");
    rad_output_set_drop(set, test_path("a.json"));
    assert_int_equal(rad_output_set_commit(ctx, set), RAD_OK);
    rad_output_set_destroy(set);
    assert_string_equal(text_of("a.json"), "new a");
    assert_string_equal(text_of("b.json"), "b3");
    assert_no_temporaries(test_workdir());

    /* A stream that fails at the commit (/dev/full) changes no file. */
    assert_int_equal(rad_output_set_create(ctx, &set), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("a.json"), RAD_OUTPUT_FILE, &ta), RAD_OK);
    const char *tf;
    assert_int_equal(rad_output_set_add(ctx, set, "/dev/full", RAD_OUTPUT_FILE, &tf), RAD_OK);
    fill(ta, "a4");
    fill(tf, "into a full device");
    assert_int_equal(rad_output_set_commit(ctx, set), RAD_ERROR_IO);
    assert_non_null(strstr(rad_context_error(ctx), "/dev/full"));
    rad_output_set_destroy(set);
    assert_string_equal(text_of("a.json"), "new a");
    assert_no_temporaries(test_workdir());

    /* A rename that fails half-way (its target became a folder) puts back
     * the file already replaced. */
    assert_int_equal(rad_output_set_create(ctx, &set), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("a.json"), RAD_OUTPUT_FILE, &ta), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("c.json"), RAD_OUTPUT_FILE, &tb), RAD_OK);
    fill(ta, "a5");
    fill(tb, "c5");
    assert_int_equal(mkdir(test_path("c.json"), 0777), 0);
    assert_int_equal(rad_output_set_commit(ctx, set), RAD_ERROR_IO);
    rad_output_set_destroy(set);
    assert_string_equal(text_of("a.json"), "new a");
    assert_int_equal(rmdir(test_path("c.json")), 0);
    assert_no_temporaries(test_workdir());

    unlink(test_path("a.json"));
    unlink(test_path("b.json"));
    rad_context_destroy(ctx);
}

static void test_output_set_aliasing(void **state)
{
    (void)state;
    rad_context *ctx;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    test_write_file("in.obj", "o x\n");
    assert_int_equal(link(test_path("in.obj"), test_path("hard.json")), 0);
    char dotted[1024];
    snprintf(dotted, sizeof dotted, "%s/./new.png", test_workdir());

    rad_output_set *set;
    const char *t;
    assert_int_equal(rad_output_set_create(ctx, &set), RAD_OK);
    assert_int_equal(rad_output_set_add_input(ctx, set, test_path("in.obj")), RAD_OK);
    /* The input by a hard link. */
    assert_int_equal(rad_output_set_add(ctx, set, test_path("hard.json"), RAD_OUTPUT_FILE, &t),
                     RAD_ERROR_INVALID_ARGUMENT);
    assert_null(t);
    assert_non_null(strstr(rad_context_error(ctx), "hard.json"));
    assert_non_null(strstr(rad_context_error(ctx), "in.obj"));
    /* A file not there yet, by two spellings. */
    assert_int_equal(rad_output_set_add(ctx, set, test_path("new.png"), RAD_OUTPUT_IMAGE, &t), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, dotted, RAD_OUTPUT_FILE, &t),
                     RAD_ERROR_INVALID_ARGUMENT);
    /* An input named after the output: refused as well. */
    test_write_file("late.mtl", "");
    assert_int_equal(rad_output_set_add(ctx, set, test_path("late.mtl"), RAD_OUTPUT_FILE, &t), RAD_OK);
    assert_int_equal(rad_output_set_add_input(ctx, set, test_path("late.mtl")),
                     RAD_ERROR_INVALID_ARGUMENT);
    /* /dev/null twice is harmless; formats are checked. */
    assert_int_equal(rad_output_set_add(ctx, set, "/dev/null", RAD_OUTPUT_FILE, &t), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, "/dev/null", RAD_OUTPUT_FILE, &t), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("x.xyz"), RAD_OUTPUT_IMAGE, &t),
                     RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("x.png"), RAD_OUTPUT_VIEW_FACTORS, &t),
                     RAD_ERROR_INVALID_ARGUMENT);
    rad_output_set_destroy(set);
    assert_no_temporaries(test_workdir());
    assert_string_equal(text_of("late.mtl"), "");
    unlink(test_path("in.obj"));
    unlink(test_path("hard.json"));
    unlink(test_path("late.mtl"));
    rad_context_destroy(ctx);
}

static void test_scene_inputs(void **state)
{
    (void)state;
    rad_context *ctx;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    test_write_file("good.obj", cli_good_obj);
    test_write_file("good.mtl", cli_good_mtl);
    rad_scene *scene;
    assert_int_equal(rad_scene_load_file(ctx, test_path("good.obj"), &scene), RAD_OK);
    assert_int_equal(rad_scene_input_count(scene), 2);
    assert_string_equal(rad_scene_input_path(scene, 0), test_path("good.obj"));
    assert_non_null(strstr(rad_scene_input_path(scene, 1), "good.mtl"));
    assert_null(rad_scene_input_path(scene, 2));
    rad_scene_destroy(scene);

    write_gltf_with_buffer();
    assert_int_equal(rad_scene_load_file(ctx, test_path("quad.gltf"), &scene), RAD_OK);
    bool buffer = false;
    for (size_t i = 0; i < rad_scene_input_count(scene); i++)
        buffer |= strstr(rad_scene_input_path(scene, i), "quad.bin") != NULL;
    assert_true(buffer);
    rad_scene_destroy(scene);

    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    assert_int_equal(rad_scene_input_count(scene), 0);
    rad_scene_destroy(scene);
    assert_int_equal(rad_scene_input_count(NULL), 0);
    assert_null(rad_scene_input_path(NULL, 0));
    rad_context_destroy(ctx);
}

/* A scene reads nothing outside its folder (links resolved) unless the
 * context allows it: a buffer or material library that climbs out, is
 * absolute, or is a link pointing out is refused, named, and nothing
 * loads. */
static void test_scene_references_confined(void **state)
{
    (void)state;
    rad_context *ctx;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    assert_int_equal(mkdir(test_path("scene"), 0777), 0);
    write_gltf_with_buffer(); /* work/quad.bin, outside work/scene */
    char absolute[600], uri_line[700];
    snprintf(absolute, sizeof absolute, "%s", test_path("quad.bin"));
    assert_int_equal(symlink("../quad.bin", test_path("scene/link.bin")), 0);
    const char *uris[] = {"../quad.bin", absolute, "link.bin", "./../scene/../quad.bin"};
    for (size_t k = 0; k < sizeof uris / sizeof uris[0]; k++) {
        write_gltf_referring("scene/out.gltf", uris[k]);
        rad_scene *scene = (rad_scene *)(void *)ctx; /* must come back NULL */
        rad_result r = rad_scene_load_file(ctx, test_path("scene/out.gltf"), &scene);
        assert_null(scene);
        if (uris[k] == absolute) {
            /* assimp 5.2 joins even an absolute URI to the folder: nothing
             * there, nothing read; the load fails naming the URI. */
            assert_int_not_equal(r, RAD_OK);
            assert_non_null(strstr(rad_context_error(ctx), absolute));
            continue;
        }
        snprintf(uri_line, sizeof uri_line, "%s'", uris[k]); /* as opened: folder + uri */
        if (r != RAD_ERROR_IO || !strstr(rad_context_error(ctx), uri_line) ||
            !strstr(rad_context_error(ctx), "outside the scene's folder"))
            fail_msg("uri %s: %s: '%s'", uris[k], rad_result_string(r), rad_context_error(ctx));
    }
    /* Inside, also through a link that stays inside: loads. */
    assert_int_equal(symlink("../quad.bin", test_path("scene/ignored")), 0);
    test_write_file("scene/copy.bin", "");
    {
        FILE *from = fopen(test_path("quad.bin"), "rb"), *to = fopen(test_path("scene/copy.bin"), "wb");
        char bytes[256];
        size_t n = fread(bytes, 1, sizeof bytes, from);
        fwrite(bytes, 1, n, to);
        fclose(from);
        fclose(to);
    }
    assert_int_equal(symlink("copy.bin", test_path("scene/inner.bin")), 0);
    write_gltf_referring("scene/in.gltf", "inner.bin");
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_file(ctx, test_path("scene/in.gltf"), &scene), RAD_OK);
    rad_scene_destroy(scene);

    /* An OBJ's material library: relative and absolute, refused. */
    test_write_file("good.mtl", cli_good_mtl);
    char obj[8192];
    snprintf(obj, sizeof obj, "mtllib ../good.mtl\n%s", strstr(cli_good_obj, "\n") + 1);
    test_write_file("scene/up.obj", obj);
    assert_int_equal(rad_scene_load_file(ctx, test_path("scene/up.obj"), &scene), RAD_ERROR_IO);
    assert_non_null(strstr(rad_context_error(ctx), "/../good.mtl'"));
    snprintf(obj, sizeof obj, "mtllib %s\n%s", test_path("good.mtl"), strstr(cli_good_obj, "\n") + 1);
    test_write_file("scene/abs.obj", obj);
    assert_int_equal(rad_scene_load_file(ctx, test_path("scene/abs.obj"), &scene), RAD_ERROR_IO);
    assert_non_null(strstr(rad_context_error(ctx), "outside the scene's folder"));
    rad_context_destroy(ctx);

    /* The explicit option lifts it. */
    rad_context_options co = {0};
    co.read_outside_scene_folder = true;
    assert_int_equal(rad_context_create(&co, &ctx), RAD_OK);
    write_gltf_referring("scene/out.gltf", "../quad.bin");
    assert_int_equal(rad_scene_load_file(ctx, test_path("scene/out.gltf"), &scene), RAD_OK);
    rad_scene_destroy(scene);
    assert_int_equal(rad_scene_load_file(ctx, test_path("scene/up.obj"), &scene), RAD_OK);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);

    /* The program: one line naming the reference, exit 1, no output;
     * --read-outside-scene-folder lets it through. */
    int status = cli_run_here("render scene/out.gltf --elements 50 --width 16 --height 16 --quiet -o out.png");
    if (status != 1)
        fail_msg("status %d: %s", status, text_of("stderr.txt"));
    cli_assert_one_line_error("/../quad.bin'", "outside the scene's folder");
    /* The message names the flag, not the library's field. */
    assert_non_null(strstr(cli_stderr(), "(--read-outside-scene-folder allows it)"));
    assert_false(test_file_exists(test_path("out.png")));
    assert_int_equal(cli_run_here("render scene/out.gltf --read-outside-scene-folder --elements 50 --width 16 "
                         "--height 16 --quiet -o out.png"),
                     0);
    assert_true(test_file_exists(test_path("out.png")));
}

/* ======================================================================
 * The program: targets
 * ==================================================================== */

#define QUICK "--elements 50 --width 16 --height 16 --quiet"

/* The old scheme's temporary was "PATH.tmp.<pid>": a link planted there
 * (the pid is known between fork and exec) must not be followed. */
static void test_link_at_old_temporary_name(void **state)
{
    (void)state;
    test_write_file("victim.txt", "precious");
    int go[2];
    assert_int_equal(pipe(go), 0);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        char byte;
        close(go[1]);
        if (read(go[0], &byte, 1) != 1 || chdir(test_workdir()) != 0)
            _exit(127);
        int null = open("/dev/null", O_WRONLY);
        dup2(null, 1);
        dup2(null, 2);
        execl(cli_binary(), cli_binary(), "render", "--elements", "50", "--width", "16",
              "--height", "16", "--quiet", "-o", "planted.png", "--stats", "planted.json",
              (char *)NULL);
        _exit(127);
    }
    close(go[0]);
    char link_name[64];
    snprintf(link_name, sizeof link_name, "planted.png.tmp.%ld", (long)pid);
    assert_int_equal(symlink(test_path("victim.txt"), test_path(link_name)), 0);
    snprintf(link_name, sizeof link_name, "planted.json.tmp.%ld", (long)pid);
    assert_int_equal(symlink(test_path("victim.txt"), test_path(link_name)), 0);
    assert_int_equal(write(go[1], "x", 1), 1);
    close(go[1]);
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    assert_string_equal(text_of("victim.txt"), "precious");
    assert_non_null(strstr(text_of("planted.json"), "\"version\""));
}

static void test_links_and_folders(void **state)
{
    (void)state;
    /* A link to a regular file: the file is replaced, the link stays. */
    test_write_file("target.json", "old");
    assert_int_equal(symlink("target.json", test_path("via_link.json")), 0);
    assert_int_equal(cli_run_here("render " QUICK " -o l.png --stats via_link.json"), 0);
    struct stat st;
    assert_int_equal(lstat(test_path("via_link.json"), &st), 0);
    assert_true(S_ISLNK(st.st_mode));
    assert_non_null(strstr(text_of("target.json"), "\"version\""));
    /* A dangling link: refused before any work, nothing created. */
    assert_int_equal(symlink("ghost.json", test_path("dangling.json")), 0);
    assert_int_equal(cli_run_here("render " QUICK " -o l.png --stats dangling.json"), 1);
    cli_assert_one_line_error("dangling.json", "dangling symbolic link");
    assert_false(test_file_exists(test_path("ghost.json")));
    /* A folder as the output, a missing folder. */
    assert_int_equal(mkdir(test_path("folder.png"), 0777), 0);
    assert_int_equal(cli_run_here("render " QUICK " -o folder.png"), 1);
    cli_assert_one_line_error("folder.png", "is a directory");
    assert_int_equal(cli_run_here("render " QUICK " -o l.png --history missing/h.csv"), 1);
    cli_assert_one_line_error("missing/h.csv", "No such file or directory");
    assert_no_temporaries(test_workdir());
}

static void test_read_only_folder(void **state)
{
    (void)state;
    if (geteuid() == 0)
        skip(); /* root writes anywhere */
    assert_int_equal(mkdir(test_path("ro"), 0555), 0);
    assert_int_equal(cli_run_here("render " QUICK " -o ro/out.png"), 1);
    cli_assert_one_line_error("ro/out.png", "Permission denied");
    chmod(test_path("ro"), 0755);
    rmdir(test_path("ro"));
}

static void test_long_names(void **state)
{
    (void)state;
    /* 250 and 255 bytes (NAME_MAX): legal, so written; 256: the system's error. */
    char name[300], args[600];
    for (size_t length = 250; length <= 256; length += length == 250 ? 5 : 1) {
        memset(name, 'x', length - 4);
        strcpy(name + length - 4, ".png");
        snprintf(args, sizeof args, "render " QUICK " -o %s", name);
        int status = cli_run_here("%s", args);
        if (length <= 255) {
            assert_int_equal(status, 0);
            assert_true(test_file_exists(test_path(name)));
            unlink(test_path(name));
        } else {
            assert_int_equal(status, 1);
            cli_assert_one_line_error("File name too long", NULL);
        }
    }
    assert_no_temporaries(test_workdir());
}

static void test_devices_fifos_stdout(void **state)
{
    (void)state;
    /* /dev/null stays the device. */
    assert_int_equal(cli_run_here("render " QUICK " -o d.png --stats /dev/null --history /dev/null"), 0);
    struct stat st;
    assert_int_equal(stat("/dev/null", &st), 0);
    assert_true(S_ISCHR(st.st_mode));
    /* /dev/stdout, a regular file here: written through stdout, after it. */
    assert_int_equal(cli_run_here("render --elements 50 --width 16 --height 16 -o d.png --stats /dev/stdout"),
                     0);
    assert_non_null(strstr(cli_stdout(), "\"version\""));
    assert_non_null(strstr(cli_stdout(), "wrote "));
    /* A full device fails at the commit: the old image stays. */
    test_write_file("keep.png", "old image");
    assert_int_equal(cli_run_here("render " QUICK " -o keep.png --stats /dev/full"), 1);
    cli_assert_one_line_error("/dev/full", NULL);
    assert_string_equal(text_of("keep.png"), "old image");
    /* A FIFO with a reader: the stats go through it, it stays a FIFO. */
    assert_int_equal(mkfifo(test_path("pipe.json"), 0666), 0);
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "cd '%s' && (cat pipe.json > from_pipe.json &) && '%s' render " QUICK
             " -o f.png --stats pipe.json; echo $? > fifo_status.txt; wait",
             test_workdir(), cli_binary());
    assert_int_equal(system(cmd), 0);
    assert_int_equal(atoi(text_of("fifo_status.txt")), 0);
    /* The reader may still be finishing: wait for its file to be whole. */
    for (int i = 0; i < 100 * WATCH_SECONDS && !strstr(text_of("from_pipe.json"), "}\n"); i++)
        pause_ms(10);
    assert_non_null(strstr(text_of("from_pipe.json"), "\"version\""));
    assert_int_equal(lstat(test_path("pipe.json"), &st), 0);
    assert_true(S_ISFIFO(st.st_mode));
    assert_no_temporaries(test_workdir());
}

/* ======================================================================
 * The program: aliasing and all-or-none
 * ==================================================================== */

static void test_outputs_aliasing_inputs(void **state)
{
    (void)state;
    test_write_file("good.obj", cli_good_obj);
    test_write_file("good.mtl", cli_good_mtl);
    assert_int_equal(cli_run_here("render good.obj " QUICK " -o a.png --stats good.obj"), 2);
    cli_assert_one_line_error("good.obj: is the same file as the input good.obj", NULL);
    assert_int_equal(cli_run_here("render good.obj " QUICK " -o a.png --history good.mtl"), 2);
    cli_assert_one_line_error("good.mtl", "input");
    assert_int_equal(cli_run_here("render good.obj " QUICK " -o a.png --history ./good.mtl"), 2);
    assert_int_equal(link(test_path("good.mtl"), test_path("mtl_link.csv")), 0);
    assert_int_equal(cli_run_here("render good.obj " QUICK " -o a.png --history mtl_link.csv"), 2);
    assert_string_equal(text_of("good.obj"), cli_good_obj);
    assert_string_equal(text_of("good.mtl"), cli_good_mtl);
    /* A glTF's buffer, by a hard link with a view-factor name. */
    write_gltf_with_buffer();
    assert_int_equal(link(test_path("quad.bin"), test_path("buffer.json")), 0);
    assert_int_equal(cli_run_here("viewfactors quad.gltf --elements 20 --quiet -o buffer.json"), 2);
    cli_assert_one_line_error("buffer.json", "quad.bin");
    assert_int_equal(cli_run_here("viewfactors quad.gltf --elements 20 --quiet -o vf.json"), 0);
    assert_false(test_file_exists(test_path("a.png")));
    assert_no_temporaries(test_workdir());
}

static void test_outputs_aliasing_each_other(void **state)
{
    (void)state;
    assert_int_equal(cli_run_here("render " QUICK " -o same.png --stats same.png"), 2);
    cli_assert_one_line_error("same.png: is the same file as the output same.png", NULL);
    assert_int_equal(cli_run_here("render " QUICK " -o same.png --stats ./same.png"), 2);
    assert_int_equal(cli_run_here("viewfactors --elements 50 --quiet -o vf.json --stats vf.json"), 2);
    test_write_file("one.csv", "old");
    assert_int_equal(link(test_path("one.csv"), test_path("two.json")), 0);
    assert_int_equal(cli_run_here("render " QUICK " -o o.png --history one.csv --stats two.json"), 2);
    assert_string_equal(text_of("one.csv"), "old");
    assert_false(test_file_exists(test_path("same.png")) || test_file_exists(test_path("o.png")));
    assert_no_temporaries(test_workdir());
}

static void test_all_or_none(void **state)
{
    (void)state;
    test_write_file("old.png", "old image");
    test_write_file("old.json", "old stats");
    /* Stats into a missing folder: refused before any work; nothing replaced. */
    assert_int_equal(cli_run_here("render " QUICK " -o old.png --stats nowhere/s.json"), 1);
    cli_assert_one_line_error("nowhere/s.json", NULL);
    assert_string_equal(text_of("old.png"), "old image");
    /* A view-factor run with a bad stats path, likewise. */
    test_write_file("old_vf.json", "old vf");
    assert_int_equal(cli_run_here("viewfactors --elements 50 --quiet -o old_vf.json --stats nowhere/s.json"), 1);
    assert_string_equal(text_of("old_vf.json"), "old vf");
    /* A failure after the work (the solve refuses the scene): nothing replaced. */
    test_write_file("dark.obj", "o floor\nv 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 3 2\n");
    assert_int_equal(cli_run_here("render dark.obj " QUICK " -o old.png --stats old.json"), 1);
    assert_string_equal(text_of("old.png"), "old image");
    assert_string_equal(text_of("old.json"), "old stats");
    assert_no_temporaries(test_workdir());
}

/* ======================================================================
 * Names in the outputs: any byte but NUL can reach a surface's name
 * ==================================================================== */

/* Four unit quads (floor, lamp above, two walls) in a data URI, one glTF
 * node each, named as a hostile file would. */
static const char quads_base64[] =
    "AAAAAAAAAAAAAAAAAAAAAAAAAAAAAIA/AACAPwAAAAAAAIA/AACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAACAPwAAgD8AAAAAAACAPwAAgD8AAIA/"
    "AAAAAAAAgD8AAIA/AAAAAAAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAgD8AAIA/AAAAAAAAAAAAAIA/AACAPwAAAAAAAAAAAACAPwAAAAAAAIA/"
    "AACAPwAAgD8AAIA/AACAPwAAgD8AAAAAAAABAAIAAAACAAMABAAFAAYABAAGAAcACAAJAAoACAAKAAsADAANAA4ADAAOAA8A";

#define FFFD "\xef\xbf\xbd"
/* The name in the glTF (JSON text; raw bytes as they are), and the name
 * every output must carry: valid UTF-8, U+FFFD for each byte that does not
 * begin a well-formed sequence (0xff, 0xfe; 0xc3 before '('; a surrogate
 * 0xed 0xa0 0x80; 0xf4 0x90 0x80 0x80 past U+10FFFF; overlong 0xc0 0xaf),
 * and cut at NUL (a C string cannot hold one; assimp stops there). */
static const char *const odd_names[4][2] = {
    {"floor \xff\xfe \xc3\x28 \xed\xa0\x80 \xf4\x90\x80\x80 \xc0\xaf \xc3\xa9",
     "floor " FFFD FFFD " " FFFD "( " FFFD FFFD FFFD " " FFFD FFFD FFFD FFFD " " FFFD FFFD " \xc3\xa9"},
    {"lamp\\n3 3 9\\r\\\"x\\\",%\\t", "lamp\n3 3 9\r\"x\",%\t"},
    {" wall, \\\"a\\\"\\\\ ", " wall, \"a\"\\ "},
    {"nul\\u0000hidden", "nul"},
};
#define ODD_SCENE "sc\xe9ne\n%.gltf"
#define ODD_SCENE_CLEAN "sc" FFFD "ne\n%.gltf"

static void write_odd_scene(void)
{
    char text[8192];
    snprintf(text, sizeof text,
             "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0, 1, 2, 3]}],"
             "\"nodes\": [{\"name\": \"%s\", \"mesh\": 0}, {\"name\": \"%s\", \"mesh\": 1}, "
             "{\"name\": \"%s\", \"mesh\": 2}, {\"name\": \"%s\", \"mesh\": 3}],"
             "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, \"material\": 0}]},"
             "{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 2, \"material\": 1}]},"
             "{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 3, \"material\": 0}]},"
             "{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 4, \"material\": 0}]}],"
             "\"materials\": [{\"name\": \"white\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1]}}, "
             "{\"name\": \"lamp\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1]}, "
             "\"emissiveFactor\": [1, 1, 1]}],"
             "\"buffers\": [{\"byteLength\": 240, \"uri\": \"data:application/octet-stream;base64,%s\"}],"
             "\"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 192}, "
             "{\"buffer\": 0, \"byteOffset\": 192, \"byteLength\": 48}],"
             "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 16, \"type\": \"VEC3\", "
             "\"min\": [0, 0, 0], \"max\": [1, 1, 1]}, "
             "{\"bufferView\": 1, \"byteOffset\": 0, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}, "
             "{\"bufferView\": 1, \"byteOffset\": 12, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}, "
             "{\"bufferView\": 1, \"byteOffset\": 24, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}, "
             "{\"bufferView\": 1, \"byteOffset\": 36, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}",
             odd_names[0][0], odd_names[1][0], odd_names[2][0], odd_names[3][0], quads_base64);
    test_write_file(ODD_SCENE, text);
}

/* Well-formed UTF-8 (RFC 3629), decoded by code point. */
static bool valid_utf8(const char *text, size_t size)
{
    const unsigned char *p = (const unsigned char *)text, *end = p + size;
    while (p < end) {
        unsigned cp, len;
        if (*p < 0x80) {
            p++;
            continue;
        } else if ((*p & 0xe0) == 0xc0) {
            cp = *p & 0x1f, len = 2;
        } else if ((*p & 0xf0) == 0xe0) {
            cp = *p & 0x0f, len = 3;
        } else if ((*p & 0xf8) == 0xf0) {
            cp = *p & 0x07, len = 4;
        } else {
            return false;
        }
        if ((size_t)(end - p) < len)
            return false;
        for (unsigned k = 1; k < len; k++) {
            if ((p[k] & 0xc0) != 0x80)
                return false;
            cp = cp << 6 | (p[k] & 0x3f);
        }
        unsigned least = len == 2 ? 0x80 : len == 3 ? 0x800 : 0x10000;
        if (cp < least || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
            return false;
        p += len;
    }
    return true;
}

/* A whole work file (caller frees), its size in *size. */
static char *read_work(const char *name, size_t *size)
{
    FILE *f = fopen(test_path(name), "rb");
    assert_non_null(f);
    char *text = malloc(1 << 20);
    assert_non_null(text);
    *size = fread(text, 1, (1 << 20) - 1, f);
    text[*size] = '\0';
    fclose(f);
    return text;
}

/* The name the outputs give element k of surface `surface`. */
static void element_name(char *out, size_t size, int surface, int k)
{
    snprintf(out, size, "%s#%d", odd_names[surface][1], k);
}

/* One RFC 4180 field from *p (quoted or not) into out; *p moves past it
 * and its comma; returns the character that ended it (',', '\n' or 0). */
static char csv_next(const char **p, char *out, size_t size)
{
    size_t n = 0;
    const char *c = *p;
    if (*c == '"') {
        for (c++;; c++) {
            assert_true(*c != '\0');
            if (*c == '"' && c[1] == '"')
                c++;
            else if (*c == '"')
                break;
            if (n + 1 < size)
                out[n++] = *c;
        }
        c++;
    } else {
        for (; *c && *c != ',' && *c != '\n'; c++) {
            assert_true(*c != '"' && *c != '\r');
            if (n + 1 < size)
                out[n++] = *c;
        }
    }
    out[n] = '\0';
    char end = *c;
    assert_true(end == ',' || end == '\n' || end == '\0');
    *p = end ? c + 1 : c;
    return end;
}

/* Every output that carries names: the view factors as JSON, CSV and
 * Matrix Market at surface and element level, and the stats.  Each file is
 * valid UTF-8; the JSON parses (cJSON) and gives back every name; the CSV
 * parses (RFC 4180) into N + 1 records of N + 2 fields with the names in
 * its header; in the Matrix Market file every line before the size line is
 * a comment, one per row, whose JSON string is the name (before, a name
 * holding "\n3 3 9" forged a size line, and bytes 0x80-0xff made the stats
 * invalid JSON). */
static void test_names_in_every_output(void **state)
{
    (void)state;
    write_odd_scene();
    for (int level = 0; level < 2; level++) {
        const char *flag = level ? "--level element --mesh-size 0.5" : "";
        int per_surface = level ? 4 : 1, N = 4 * per_surface;
        char expected[16][256];
        for (int s = 0; s < 4; s++)
            for (int k = 0; k < per_surface; k++) {
                if (level)
                    element_name(expected[s * per_surface + k], sizeof expected[0], s, k);
                else
                    snprintf(expected[s], sizeof expected[0], "%s", odd_names[s][1]);
            }
        const char *formats[3] = {"json", "csv", "mtx"};
        for (int f = 0; f < 3; f++) {
            char out[64];
            snprintf(out, sizeof out, "vf%d.%s", level, formats[f]);
            assert_int_equal(cli_run_here("viewfactors '%s' %s -o %s --stats vf%d_stats.json", ODD_SCENE, flag, out, level), 0);
            size_t size;
            char *text = read_work(out, &size);
            if (!valid_utf8(text, size))
                fail_msg("%s is not valid UTF-8", out);
            if (f == 0) {
                cJSON *vf = cJSON_Parse(text);
                assert_non_null(vf);
                assert_string_equal(cJSON_GetObjectItem(vf, "scene")->valuestring, ODD_SCENE_CLEAN);
                const cJSON *list = cJSON_GetObjectItem(vf, level ? "elements_list" : "surfaces");
                assert_int_equal(cJSON_GetArraySize(list), N);
                for (int r = 0; r < N; r++) {
                    const cJSON *row = cJSON_GetArrayItem(list, r);
                    assert_string_equal(cJSON_GetObjectItem(row, "name")->valuestring, expected[r]);
                    if (level)
                        assert_string_equal(cJSON_GetObjectItem(row, "surface")->valuestring,
                                            odd_names[r / per_surface][1]);
                }
                cJSON_Delete(vf);
            } else if (f == 1) {
                const char *p = text;
                char field[512];
                assert_true(csv_next(&p, field, sizeof field) == ',' && strcmp(field, "from") == 0);
                assert_true(csv_next(&p, field, sizeof field) == ',' && strcmp(field, "area_m2") == 0);
                for (int c = 0; c < N; c++) {
                    char end = csv_next(&p, field, sizeof field);
                    assert_string_equal(field, expected[c]);
                    assert_true(end == (c + 1 < N ? ',' : '\n'));
                }
                for (int r = 0; r < N; r++) {
                    assert_true(csv_next(&p, field, sizeof field) == ',');
                    assert_string_equal(field, expected[r]);
                    for (int c = 0; c <= N; c++) {
                        char end = csv_next(&p, field, sizeof field);
                        assert_true(end == (c < N ? ',' : '\n'));
                        char *stop;
                        strtod(field, &stop);
                        assert_true(stop != field && *stop == '\0'); /* a number */
                    }
                }
                assert_true(*p == '\0');
            } else {
                char *save = NULL, *line = strtok_r(text, "\n", &save);
                assert_string_equal(line, "%%MatrixMarket matrix coordinate real general");
                line = strtok_r(NULL, "\n", &save);
                assert_true(line[0] == '%' && !strstr(line, "\"")); /* the description */
                for (int r = 0; r < N; r++) {
                    line = strtok_r(NULL, "\n", &save);
                    char prefix[16];
                    snprintf(prefix, sizeof prefix, "%% %d \"", r + 1);
                    assert_true(strncmp(line, prefix, strlen(prefix)) == 0);
                    char *tail = strstr(line, "\" area_m2 ");
                    assert_non_null(tail);
                    tail[1] = '\0';
                    cJSON *name = cJSON_Parse(line + strlen(prefix) - 1);
                    assert_true(cJSON_IsString(name));
                    assert_string_equal(name->valuestring, expected[r]);
                    cJSON_Delete(name);
                }
                line = strtok_r(NULL, "\n", &save);
                int rows = 0, cols = 0, nnz = 0;
                char rest;
                assert_int_equal(sscanf(line, "%d %d %d%c", &rows, &cols, &nnz, &rest), 3);
                assert_true(rows == N && cols == N && nnz > 0);
            }
            free(text);
        }
        char stats_name[64];
        snprintf(stats_name, sizeof stats_name, "vf%d_stats.json", level);
        size_t size;
        char *text = read_work(stats_name, &size);
        assert_true(valid_utf8(text, size));
        cJSON *stats = cJSON_Parse(text);
        assert_non_null(stats);
        assert_string_equal(cJSON_GetObjectItem(stats, "scene")->valuestring, ODD_SCENE_CLEAN);
        const cJSON *surfaces = cJSON_GetObjectItem(stats, "surfaces");
        assert_int_equal(cJSON_GetArraySize(surfaces), 4);
        for (int k = 0; k < 4; k++)
            assert_string_equal(cJSON_GetObjectItem(cJSON_GetArrayItem(surfaces, k), "name")->valuestring,
                                odd_names[k][1]);
        cJSON_Delete(stats);
        free(text);
    }

    /* The OBJ writer: names are made statements' words (blanks and controls
     * to '_'), and the scene's path in its comments cannot end them (a scene
     * read from a path holding "\nv 9 9 9" added a vertex to every OBJ
     * written from it).  An output whose MTL name mtllib cannot hold (a
     * blank, a line break, '#') is refused, nothing written.  Read back:
     * the same scene. */
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(NULL, &ctx), RAD_OK);
    rad_scene *scene = NULL, *back = NULL;
    test_write_file("odd\nv 9 9 9\nf 1 2 3.gltf", text_of(ODD_SCENE));
    assert_int_equal(rad_scene_load_file(ctx, test_path("odd\nv 9 9 9\nf 1 2 3.gltf"), &scene), RAD_OK);
    const char *refused[] = {"odd\nv 9 9 9.obj", "two words.obj", "hash#.obj", "tab\t.obj"};
    for (size_t k = 0; k < sizeof refused / sizeof refused[0]; k++) {
        char path[600];
        snprintf(path, sizeof path, "%s", test_path(refused[k]));
        assert_int_equal(rad_scene_write_obj(ctx, scene, path), RAD_ERROR_INVALID_ARGUMENT);
        assert_non_null(strstr(rad_context_error(ctx), "an OBJ cannot name its MTL"));
        assert_false(test_file_exists(test_path(refused[k])));
    }
    char obj[600];
    snprintf(obj, sizeof obj, "%s", test_path("odd_written.obj"));
    if (rad_scene_write_obj(ctx, scene, obj) != RAD_OK)
        fail_msg("%s", rad_context_error(ctx));
    const char *written = text_of("odd_written.obj");
    assert_null(strstr(written, "\nv 9 9 9"));
    assert_non_null(strstr(written, "odd?v 9 9 9?f 1 2 3.gltf: 4 surfaces"));
    assert_non_null(strstr(text_of("odd_written.mtl"), "odd?v 9 9 9?f 1 2 3.gltf: materials"));
    assert_int_equal(rad_scene_load_file(ctx, obj, &back), RAD_OK);
    assert_int_equal(rad_scene_surface_count(back), 4);
    assert_int_equal(rad_scene_polygon_count(back), rad_scene_polygon_count(scene));
    rad_scene_destroy(back);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* ======================================================================
 * The program: signals at each stage
 * ==================================================================== */

typedef struct watched {
    pid_t pid;
    int terminal;        /* the master side of the child's stderr */
    char seen[1 << 16];  /* what it printed there, the last 64 KiB */
    size_t length;
} watched;

/* Start `radiosity ARGS` (split at blanks) in the work folder with stderr on
 * a pseudo-terminal, so that it draws its progress (phase names). */
static void watch_start(watched *w, const char *args)
{
    memset(w, 0, sizeof *w);
    w->terminal = posix_openpt(O_RDWR | O_NOCTTY);
    assert_true(w->terminal >= 0);
    assert_int_equal(grantpt(w->terminal), 0);
    assert_int_equal(unlockpt(w->terminal), 0);
    const char *slave = ptsname(w->terminal);
    assert_non_null(slave);
    static char copy[2048], program[1024];
    snprintf(copy, sizeof copy, "%s", args);
    snprintf(program, sizeof program, "%s", cli_binary());
    char *argv[64] = {program};
    int argc = 1;
    for (char *t = strtok(copy, " "); t && argc < 63; t = strtok(NULL, " "))
        argv[argc++] = t;
    argv[argc] = NULL;
    w->pid = fork();
    assert_true(w->pid >= 0);
    if (w->pid == 0) {
        int err = open(slave, O_RDWR | O_NOCTTY);
        int out = open(test_path("watched_out.txt"), O_WRONLY | O_CREAT | O_TRUNC, 0666);
        int in = open("/dev/null", O_RDONLY);
        if (err < 0 || out < 0 || in < 0 || chdir(test_workdir()) != 0)
            _exit(127);
        dup2(in, 0);
        dup2(out, 1);
        dup2(err, 2);
        execv(cli_binary(), argv);
        _exit(127);
    }
}

/* Read what the child printed for up to `ms` milliseconds; false at its end. */
static bool watch_read(watched *w, int ms)
{
    struct pollfd p = {w->terminal, POLLIN, 0};
    if (poll(&p, 1, ms) <= 0)
        return true;
    char buffer[4096];
    ssize_t n = read(w->terminal, buffer, sizeof buffer);
    if (n <= 0)
        return false; /* EIO: every writer closed, the child is gone */
    if (w->length + (size_t)n >= sizeof w->seen) {
        size_t keep = sizeof w->seen / 2;
        memmove(w->seen, w->seen + w->length - keep, keep);
        w->length = keep;
    }
    memcpy(w->seen + w->length, buffer, (size_t)n);
    w->length += (size_t)n;
    w->seen[w->length] = '\0';
    return true;
}

/* Wait until the child has printed `text` (a phase name) after `from`. */
static void watch_for_text(watched *w, const char *text)
{
    size_t from = w->length;
    time_t end = time(NULL) + WATCH_SECONDS;
    while (!strstr(w->seen + (from < w->length ? from : w->length), text))
        if (!watch_read(w, 100) || time(NULL) > end)
            fail_msg("the run never reached '%s'; it printed: %s", text, w->seen);
}

/* Wait until a work file exists. */
static void watch_for_file(watched *w, const char *name)
{
    time_t end = time(NULL) + WATCH_SECONDS;
    while (!test_file_exists(test_path(name)))
        if (!watch_read(w, 10) || time(NULL) > end)
            fail_msg("the run never wrote %s; it printed: %s", name, w->seen);
}

/* Read to the child's end; its exit status (-1 when a signal killed it). */
static int watch_end(watched *w)
{
    while (watch_read(w, 100)) {
        int status;
        if (waitpid(w->pid, &status, WNOHANG) == w->pid) {
            close(w->terminal);
            return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        }
    }
    int status;
    assert_int_equal(waitpid(w->pid, &status, 0), w->pid);
    close(w->terminal);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* A run in the solve for as long as we like: shooting never reaches 1e-12. */
#define LONG_SOLVE "--solver shooting --elements 4000 --unshot-tolerance 1e-12 --ff-samples 64"

static void test_signal_during_form_factors(void **state)
{
    (void)state;
    watched w;
    watch_start(&w, "render --elements 12000 --width 16 --height 16 -o ff.png --stats ff.json "
                    "--history ff.csv");
    watch_for_text(&w, "form factors");
    kill(w.pid, SIGTERM);
    assert_int_equal(watch_end(&w), 143);
    assert_false(test_file_exists(test_path("ff.png")) || test_file_exists(test_path("ff.csv")));
    const char *stats = text_of("ff.json");
    assert_non_null(strstr(stats, "\"partial\":\ttrue"));
    assert_non_null(strstr(stats, "\"interrupted\":\t\"form factors\""));
    assert_non_null(strstr(w.seen, "interrupted while computing form factors; wrote partial stats"));
    assert_no_temporaries(test_workdir());
}

static void test_signal_during_solve_with_progress_images(void **state)
{
    (void)state;
    watched w;
    watch_start(&w, "render " LONG_SOLVE " --width 16 --height 16 --progress-images frames "
                    "--every 1 -o solve.png --stats solve.json");
    watch_for_file(&w, "frames/step_00000002.png");
    kill(w.pid, SIGINT);
    assert_int_equal(watch_end(&w), 130);
    assert_true(test_file_exists(test_path("solve.png")));
    const char *stats = text_of("solve.json");
    assert_non_null(strstr(stats, "\"partial\":\ttrue"));
    assert_non_null(strstr(stats, "\"converged\":\tfalse"));
    assert_no_temporaries(test_workdir());
    assert_no_temporaries(test_path("frames"));
}

/* The first signal stops the solve; a second one, while the partial
 * solution is rendered and saved, loses nothing. */
static void test_second_signal_while_saving(void **state)
{
    (void)state;
    watched w;
    watch_start(&w, "render " LONG_SOLVE " --width 400 --height 400 -o twice.png --stats twice.json");
    watch_for_text(&w, "solve");
    kill(w.pid, SIGINT);
    watch_for_text(&w, "render");
    kill(w.pid, SIGINT);
    assert_int_equal(watch_end(&w), 130);
    assert_true(test_file_exists(test_path("twice.png")));
    assert_non_null(strstr(text_of("twice.json"), "\"partial\":\ttrue"));
    assert_no_temporaries(test_workdir());
}

/* Signals during the final render of a converged solution: the render and
 * the outputs are completed (not marked partial: the solution is whole),
 * then the run exits 143, the status of the first signal.  The second is
 * sent 0.2 s later: two signals pending at once are delivered in the
 * order of their numbers (SIGINT first), whatever order they were sent
 * in, so back to back the test would race. */
static void test_signal_during_final_render(void **state)
{
    (void)state;
    watched w;
    watch_start(&w, "render --elements 60 --width 700 --height 700 --samples 8 -o final.png "
                    "--stats final.json --history final.csv");
    watch_for_text(&w, "render");
    kill(w.pid, SIGTERM);
    nanosleep(&(struct timespec){0, 200000000}, NULL);
    kill(w.pid, SIGINT);
    assert_int_equal(watch_end(&w), 143);
    assert_true(test_file_exists(test_path("final.png")) && test_file_exists(test_path("final.csv")));
    assert_non_null(strstr(text_of("final.json"), "\"partial\":\tfalse"));
    assert_non_null(strstr(w.seen, "interrupted while writing the outputs"));
    assert_no_temporaries(test_workdir());
}

/* A closed box of reflectance 0.999999 lit from its floor: no solver
 * reaches 1e-15 on it (the iterative ones run to their bound of 10^4
 * bounces), so each is in its solve when the signal comes. */
static void write_bright_box(void)
{
    test_write_file("bright.mtl", "newmtl wall\nKd 0.999999 0.999999 0.999999\n"
                             "newmtl lamp\nKd 0.999999 0.999999 0.999999\nKe 1 1 1\n");
    test_write_file("bright.obj", "mtllib bright.mtl\n"
                             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                             "usemtl lamp\no floor\nf 1 2 3 4\nusemtl wall\no ceiling\nf 5 8 7 6\n"
                             "o front\nf 1 5 6 2\no back\nf 4 3 7 8\no left\nf 1 4 8 5\no right\nf 2 6 7 3\n");
}

/* SIGTERM while each solver solves: exit 143, the partial solution
 * written and marked.  Those that show their steps are caught after their
 * second frame; hierarchical (whose steps are not displayable) and direct
 * (one step: its LU, polled between panels) when the progress names their
 * phase. */
static void test_signal_during_each_solver(void **state)
{
    (void)state;
    write_bright_box();
    static const char *framed[] = {"gauss-seidel", "jacobi", "conjugate-gradient", "southwell", "shooting"};
    for (size_t k = 0; k < sizeof framed / sizeof framed[0] + 2; k++) {
        const char *solver = k < 5 ? framed[k] : k == 5 ? "hierarchical" : "direct";
        char args[1024], frame[128], stats_name[128], png[128];
        snprintf(png, sizeof png, "sig_%s.png", solver);
        snprintf(stats_name, sizeof stats_name, "sig_%s.json", solver);
        if (k < 5)
            snprintf(args, sizeof args,
                     "render bright.obj --solver %s --elements 600 --tolerance 1e-15 --ff-samples 64 --width 16 "
                     "--height 16 --progress-images frames_%s --every 1 -o %s --stats %s",
                     solver, solver, png, stats_name);
        else if (k == 5)
            snprintf(args, sizeof args, "render bright.obj --solver hierarchical --tolerance 1e-15 --width 16 "
                                        "--height 16 -o %s --stats %s", png, stats_name);
        else /* an LU of 2904 unknowns: seconds, in 23 panels */
            snprintf(args, sizeof args,
                     "render bright.obj --solver direct --elements 3000 --form-factors hemicube --hemicube-res 16 "
                     "--width 16 --height 16 -o %s --stats %s",
                     png, stats_name);
        watched w;
        watch_start(&w, args);
        if (k < 5) {
            snprintf(frame, sizeof frame, "frames_%s/step_00000002.png", solver);
            watch_for_file(&w, frame);
        } else {
            watch_for_text(&w, k == 5 ? "hierarchical" : "solve");
        }
        kill(w.pid, SIGTERM);
        int status = watch_end(&w);
        if (status != 143)
            fail_msg("%s: exit %d after SIGTERM while solving; it printed: %s", solver, status, w.seen);
        assert_true(test_file_exists(test_path(png)));
        const char *stats = text_of(stats_name);
        if (!strstr(stats, "\"partial\":\ttrue") || !strstr(stats, "\"converged\":\tfalse"))
            fail_msg("%s: the stats are not marked partial: %s", solver, stats);
        assert_non_null(strstr(w.seen, "interrupted while solving; writing the partial solution"));
        assert_no_temporaries(test_workdir());
    }
}

/* Whether the process has a handler for SIGINT (Linux /proc). */
static bool catches_sigint(pid_t pid)
{
    char path[64], line[256];
    snprintf(path, sizeof path, "/proc/%ld/status", (long)pid);
    FILE *f = fopen(path, "r");
    bool caught = false;
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "SigCgt:", 7) == 0)
            caught = (strtoull(line + 7, NULL, 16) & (1ull << (SIGINT - 1))) != 0;
    if (f)
        fclose(f);
    return caught;
}

/* generate: exit 130, both files or neither, no temporary. */
static void test_signal_during_generate(void **state)
{
    (void)state;
    watched w;
    watch_start(&w, "generate office --rooms 3000 -o gen.obj");
    time_t end = time(NULL) + WATCH_SECONDS;
    while (!catches_sigint(w.pid)) {
        if (time(NULL) > end)
            fail_msg("generate never set up its signal handlers");
        pause_ms(1);
    }
    kill(w.pid, SIGINT);
    assert_int_equal(watch_end(&w), 130);
    assert_int_equal(test_file_exists(test_path("gen.obj")), test_file_exists(test_path("gen.mtl")));
    if (test_file_exists(test_path("gen.obj")))
        assert_non_null(strstr(text_of("gen.mtl"), "newmtl"));
    assert_no_temporaries(test_workdir());
    unlink(test_path("gen.obj"));
    unlink(test_path("gen.mtl"));
}

/* A scene that never comes (a FIFO nobody writes): the load blocks in
 * open(), and SIGTERM breaks it off.  That is an interruption like any
 * other, 143, not a failure (before: exit 1). */
static void test_signal_during_load(void **state)
{
    (void)state;
    assert_int_equal(mkfifo(test_path("never.obj"), 0600), 0);
    watched w;
    watch_start(&w, "render never.obj -o never.png");
    time_t end = time(NULL) + WATCH_SECONDS;
    while (!catches_sigint(w.pid)) {
        if (time(NULL) > end)
            fail_msg("render never set up its signal handlers");
        pause_ms(1);
    }
    pause_ms(100);
    kill(w.pid, SIGTERM);
    assert_int_equal(watch_end(&w), 143);
    assert_false(test_file_exists(test_path("never.png")));
    assert_no_temporaries(test_workdir());
    unlink(test_path("never.obj"));
}

/* ---- the work folder ---- */

static int setup(void **state)
{
    (void)state;
    return test_workdir_make("outputs");
}

static int teardown(void **state)
{
    (void)state;
    return test_workdir_remove();
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s PATH-TO-radiosity\n", argv[0]);
        return 2;
    }
    cli_set_binary(argv[1]);
    /* "--slow" after the program's path: the cases at scale instead of the quick ones. */
    bool slow = argc == 3 && strcmp(argv[2], "--slow") == 0;
    if (argc > 3 || (argc == 3 && !slow)) {
        fprintf(stderr, "usage: test_outputs PATH_TO_RADIOSITY [--slow]\n");
        return 2;
    }
    const struct CMUnitTest fast_tests[] = {
        cmocka_unit_test_setup_teardown(test_temporary_names, setup, teardown),
        cmocka_unit_test_setup_teardown(test_output_targets, setup, teardown),
        cmocka_unit_test_setup_teardown(test_output_set_all_or_none, setup, teardown),
        cmocka_unit_test_setup_teardown(test_output_set_aliasing, setup, teardown),
        cmocka_unit_test_setup_teardown(test_scene_inputs, setup, teardown),
        cmocka_unit_test_setup_teardown(test_scene_references_confined, setup, teardown),
        cmocka_unit_test_setup_teardown(test_link_at_old_temporary_name, setup, teardown),
        cmocka_unit_test_setup_teardown(test_links_and_folders, setup, teardown),
        cmocka_unit_test_setup_teardown(test_read_only_folder, setup, teardown),
        cmocka_unit_test_setup_teardown(test_long_names, setup, teardown),
        cmocka_unit_test_setup_teardown(test_devices_fifos_stdout, setup, teardown),
        cmocka_unit_test_setup_teardown(test_outputs_aliasing_inputs, setup, teardown),
        cmocka_unit_test_setup_teardown(test_outputs_aliasing_each_other, setup, teardown),
        cmocka_unit_test_setup_teardown(test_all_or_none, setup, teardown),
        cmocka_unit_test_setup_teardown(test_names_in_every_output, setup, teardown),
        cmocka_unit_test_setup_teardown(test_signal_during_solve_with_progress_images, setup, teardown),
        cmocka_unit_test_setup_teardown(test_second_signal_while_saving, setup, teardown),
        cmocka_unit_test_setup_teardown(test_signal_during_final_render, setup, teardown),
        cmocka_unit_test_setup_teardown(test_signal_during_generate, setup, teardown),
        cmocka_unit_test_setup_teardown(test_signal_during_load, setup, teardown),
    };
    /* At scale: with --slow alone (CTest: test_outputs_slow, label slow). */
    const struct CMUnitTest slow_tests[] = {
        cmocka_unit_test_setup_teardown(test_signal_during_form_factors, setup, teardown),
        cmocka_unit_test_setup_teardown(test_signal_during_each_solver, setup, teardown),
    };
    return slow ? cmocka_run_group_tests_name("outputs_slow", slow_tests, NULL, NULL)
                : cmocka_run_group_tests_name("outputs", fast_tests, NULL, NULL);
}
