/*
 * test_solvers.c -- every registered solver against the exact answers and
 * against each other, through the same command users run.
 *
 * The solvers are read from `radiosity --list-methods` (matrix-free ones,
 * which compute their own sampled factors, and the Galerkin ones, which
 * build their own system, are left to their own suites),
 * so a new solver is tested as soon as it is registered.  `direct` (LU) is
 * the reference on scenes without a closed form.  The path of the
 * radiosity binary is argv[1]; scenes are written from tests/data/cases.json.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "cli_support.h"

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

enum { MAX_SOLVERS = 32 };
static char *solvers[MAX_SOLVERS]; /* owned, freed in teardown */
static int solver_count;

/* ---- helpers ---- */

/* Render `scene` ("" = the built-in Cornell box) with `extra` options and
 * return the stats (caller frees); `tag` names the files. */
static cJSON *render_stats(const char *scene, const char *tag, const char *extra)
{
    char stats[600], png[600];
    snprintf(stats, sizeof stats, "%s/%s.stats.json", test_workdir(), tag);
    snprintf(png, sizeof png, "%s/%s.png", test_workdir(), tag);
    int status = cli_run_capture(NULL, "render %s%s%s -o '%s' --stats '%s' --width 8 --height 8 %s",
                                 scene[0] ? "'" : "", scene, scene[0] ? "'" : "", png, stats, extra);
    if (status != 0)
        fail_msg("%s: radiosity render %s exited with %d", tag, extra, status);
    cJSON *j = cli_read_json(stats);
    assert_non_null(j);
    return j;
}

/* Per-surface mean radiosity, surface by surface in the order of the stats. */
static int surface_radiosities(const cJSON *stats, double (*rgb)[3], char (*names)[64], int max)
{
    int count = 0;
    const cJSON *s;
    cJSON_ArrayForEach(s, cJSON_GetObjectItem(stats, "surfaces"))
    {
        assert_true(count < max);
        for (int c = 0; c < 3; c++)
            rgb[count][c] = cJSON_GetArrayItem(cJSON_GetObjectItem(s, "radiosity"), c)->valuedouble;
        snprintf(names[count], 64, "%s", cJSON_GetObjectItem(s, "name")->valuestring);
        count++;
    }
    return count;
}

static void assert_relative(double got, double exact, double tol, const char *what)
{
    double rel = exact == 0.0 ? fabs(got) : fabs(got - exact) / fabs(exact);
    if (!(rel <= tol))
        fail_msg("%s: got %.12g, expected %.12g, relative error %.2e > %.1e", what, got, exact, rel, tol);
}

/* Every surface of `got` against the same surface of `want` (non-zero values). */
static void assert_same_surfaces(const cJSON *got, const cJSON *want, double tol, const char *what)
{
    enum { MAX = 64 };
    double a[MAX][3], b[MAX][3];
    char na[MAX][64], nb[MAX][64];
    int n = surface_radiosities(got, a, na, MAX), m = surface_radiosities(want, b, nb, MAX);
    assert_int_equal(n, m);
    assert_true(n > 0);
    for (int k = 0; k < n; k++) {
        assert_string_equal(na[k], nb[k]);
        for (int c = 0; c < 3; c++) {
            char label[256];
            snprintf(label, sizeof label, "%s: %.63s[%d]", what, na[k], c);
            assert_relative(a[k][c], b[k][c], tol, label);
        }
    }
}

/* ---- scenes ---- */

static const char *cube_faces[6] = {"x0", "x1", "y0", "y1", "z0", "z1"};

/* A cube of the case geometry: faces named prefix + face, rho and E from
 * the case unless `rho` / `emitter` are given (then the face `emitter`
 * emits E and reflects `emitter_rho`, the others reflect `rho`). */
static void write_cube_faces(cli_scene_writer *w, const char *case_id, const char *prefix,
                             const double offset[3], const double *rho, const char *emitter, double E,
                             const double *emitter_rho)
{
    const cJSON *g = cJSON_GetObjectItem(cli_find_case(case_id), "geometry");
    for (int f = 0; f < 6; f++) {
        const cJSON *s = cJSON_GetObjectItem(g, cube_faces[f]);
        const cJSON *rho_case = cJSON_GetObjectItem(s, "rho"), *E_case = cJSON_GetObjectItem(s, "E");
        double r[3], e;
        bool emits = emitter && strcmp(emitter, cube_faces[f]) == 0;
        for (int c = 0; c < 3; c++)
            r[c] = emits ? emitter_rho[c] : rho ? rho[c] : rho_case ? rho_case->valuedouble : 0.5;
        e = emitter ? (emits ? E : 0.0) : E_case ? E_case->valuedouble : 0.0;
        char name[64];
        snprintf(name, sizeof name, "%s%s", prefix, cube_faces[f]);
        cli_scene_material_rgb(w, name, r, e);
        cli_scene_case_surface_moved(w, s, name, name, offset);
    }
}

static void write_case_cube(cli_scene_writer *w, const char *name, const char *case_id)
{
    static const double zero[3] = {0, 0, 0};
    cli_scene_begin(w, name);
    write_cube_faces(w, case_id, "", zero, NULL, NULL, 0.0, NULL);
    cli_scene_end(w);
}

/* Two closed rooms that cannot see each other: room a is the six-patch
 * case (grey, lit from the ceiling), room b three metres along x, lit from
 * a black floor, with walls that reflect no blue (rho = 0: solvers that
 * eliminate such unknowns must still give B = E there). */
static const double room_b_offset[3] = {3.0, 0.0, 0.0};
static const double room_b_rho[3] = {0.7, 0.5, 0.0};
static const double black[3] = {0.0, 0.0, 0.0};

static void write_rooms(cli_scene_writer *w, const char *name, bool room_a, bool room_b)
{
    static const double zero[3] = {0, 0, 0};
    cli_scene_begin(w, name);
    if (room_a)
        write_cube_faces(w, "cube_top_emitter_6patch", "a_", zero, NULL, NULL, 0.0, NULL);
    if (room_b)
        write_cube_faces(w, "cube_top_emitter_6patch", "b_", room_b_offset, room_b_rho, "z0", 2.0, black);
    cli_scene_end(w);
}

/* ---- the solver list ---- */

static void test_registry(void **state)
{
    (void)state;
    /* The registry is read in setup(); the solvers every build has must be there. */
    static const char *required[] = {"gauss-seidel", "southwell", "jacobi", "direct", "conjugate-gradient"};
    for (size_t r = 0; r < sizeof required / sizeof required[0]; r++) {
        bool found = false;
        for (int k = 0; k < solver_count; k++)
            found = found || strcmp(solvers[k], required[r]) == 0;
        if (!found)
            fail_msg("solver %s is not listed by --list-methods", required[r]);
    }
}

/* ---- (a) the Cornell box: every solver agrees with LU ---- */

static void test_cornell_box_against_direct(void **state)
{
    (void)state;
    cJSON *ref = render_stats("", "cornell_direct", "--elements 800 --solver direct");
    assert_true(cli_stats_number(ref, "solver", "residual") < 1e-12);
    for (int k = 0; k < solver_count; k++) {
        char extra[256], tag[128];
        snprintf(extra, sizeof extra, "--elements 800 --solver %s --tolerance 1e-9", solvers[k]);
        snprintf(tag, sizeof tag, "cornell_%s", solvers[k]);
        cJSON *s = render_stats("", tag, extra);
        assert_same_surfaces(s, ref, 1e-5, solvers[k]);
        /* Converged, or near it: shooting bookkeeps F_ji through reciprocity,
         * so its residual stops at the reciprocity error (~6e-9 here). */
        if (!(cli_stats_number(s, "solver", "residual") < 1e-7))
            fail_msg("%s: residual %g", solvers[k], cli_stats_number(s, "solver", "residual"));
        cJSON_Delete(s);
    }
    cJSON_Delete(ref);
}

/* ---- (b) the six-patch cube: exact ---- */

static void test_six_patch_exact(void **state)
{
    (void)state;
    const cJSON *c = cli_find_case("cube_top_emitter_6patch");
    cli_scene_writer w;
    write_case_cube(&w, "six_patch", "cube_top_emitter_6patch");
    for (int k = 0; k < solver_count; k++) {
        char extra[256], tag[128];
        /* --mesh-size 2: one element per face, as the exact solution assumes. */
        snprintf(extra, sizeof extra, "--solver %s --mesh-size 2 --tolerance 1e-9", solvers[k]);
        snprintf(tag, sizeof tag, "six_patch_%s", solvers[k]);
        cJSON *stats = render_stats(w.obj_path, tag, extra);
        assert_int_equal((int)cJSON_GetObjectItem(stats, "elements")->valuedouble, 6);
        for (int f = 0; f < 6; f++) {
            double B[3];
            cli_stats_surface_radiosity(stats, cube_faces[f], B);
            double exact = cJSON_GetObjectItem(cJSON_GetObjectItem(c, "exact"), cube_faces[f])->valuedouble;
            char label[128];
            snprintf(label, sizeof label, "%s: %s", solvers[k], cube_faces[f]);
            for (int ch = 0; ch < 3; ch++)
                assert_relative(B[ch], exact, 1e-6, label);
        }
        cJSON_Delete(stats);
    }
}

/* ---- (c) the furnace: B = E / (1 - rho) = 2 everywhere ---- */

static void test_furnace(void **state)
{
    (void)state;
    double exact = cJSON_GetObjectItem(cli_find_case("furnace_cube_rho0.5"), "exact")->valuedouble;
    cli_scene_writer w;
    write_case_cube(&w, "furnace", "furnace_cube_rho0.5");
    for (int k = 0; k < solver_count; k++) {
        char extra[256], tag[128];
        /* Closure correction: rows of F sum to 1 up to float rounding, so B = 2
         * holds to ~1e-7; without it the row sums (1 +- 2e-5 at 300 elements)
         * alone move B by ~3e-6, whatever the solver. */
        snprintf(extra, sizeof extra, "--solver %s --elements 300 --tolerance 1e-9 --closure-correction",
                 solvers[k]);
        snprintf(tag, sizeof tag, "furnace_%s", solvers[k]);
        cJSON *stats = render_stats(w.obj_path, tag, extra);
        for (int f = 0; f < 6; f++) {
            double B[3];
            cli_stats_surface_radiosity(stats, cube_faces[f], B);
            char label[128];
            snprintf(label, sizeof label, "%s: furnace %s", solvers[k], cube_faces[f]);
            for (int ch = 0; ch < 3; ch++)
                assert_relative(B[ch], exact, 1e-6, label);
        }
        cJSON_Delete(stats);
    }
}

/* ---- (d) two rooms: two components, each solved as if alone ---- */

static void test_separate_rooms(void **state)
{
    (void)state;
    cli_scene_writer both, a, b;
    write_rooms(&both, "rooms", true, true);
    write_rooms(&a, "room_a", true, false);
    write_rooms(&b, "room_b", false, true);
    cJSON *ref = render_stats(both.obj_path, "rooms_reference", "--solver direct --mesh-size 0.25");
    for (int k = 0; k < solver_count; k++) {
        char extra[256], tag[128];
        /* 0.25 m: 16 elements a face, the same grid together or alone. */
        snprintf(extra, sizeof extra, "--solver %s --mesh-size 0.25 --tolerance 1e-9", solvers[k]);
        snprintf(tag, sizeof tag, "rooms_%s", solvers[k]);
        cJSON *sb = render_stats(both.obj_path, tag, extra);
        snprintf(tag, sizeof tag, "room_a_%s", solvers[k]);
        cJSON *sa = render_stats(a.obj_path, tag, extra);
        snprintf(tag, sizeof tag, "room_b_%s", solvers[k]);
        cJSON *sr = render_stats(b.obj_path, tag, extra);
        assert_int_equal((int)cli_stats_number(sb, "solver", "components"), 2);
        assert_int_equal((int)cli_stats_number(sa, "solver", "components"), 0); /* one room: not split */
        assert_true(cli_stats_number(sb, "solver", "residual") < 1e-8);
        assert_same_surfaces(sb, ref, 1e-6, solvers[k]);
        for (int f = 0; f < 6; f++) {
            char name[16], label[160];
            double together[3], alone[3];
            snprintf(name, sizeof name, "a_%s", cube_faces[f]);
            snprintf(label, sizeof label, "%s: %s", solvers[k], name);
            cli_stats_surface_radiosity(sb, name, together);
            cli_stats_surface_radiosity(sa, name, alone);
            for (int c = 0; c < 3; c++)
                assert_relative(together[c], alone[c], 1e-7, label);
            snprintf(name, sizeof name, "b_%s", cube_faces[f]);
            snprintf(label, sizeof label, "%s: %s", solvers[k], name);
            cli_stats_surface_radiosity(sb, name, together);
            cli_stats_surface_radiosity(sr, name, alone);
            for (int c = 0; c < 3; c++)
                assert_relative(together[c], alone[c], 1e-7, label);
        }
        /* Room b: red walls, no blue; its black floor sends out just E. */
        double wall[3], floor[3];
        cli_stats_surface_radiosity(sb, "b_x0", wall);
        cli_stats_surface_radiosity(sb, "b_z0", floor);
        assert_true(wall[0] > 1.5 * wall[1] && wall[2] == 0.0);
        for (int c = 0; c < 3; c++)
            assert_relative(floor[c], 2.0, 1e-14, "black emitter"); /* pi x Ke, Ke read to 17 digits */
        cJSON_Delete(sb);
        cJSON_Delete(sa);
        cJSON_Delete(sr);
    }
    cJSON_Delete(ref);
}

/* ---- (e) over-relaxation: same answer, different path ---- */

static void relaxed(const cJSON *ref, const char *solver, double omega)
{
    char extra[256], tag[128];
    snprintf(extra, sizeof extra, "--elements 800 --solver %s --tolerance 1e-9", solver);
    snprintf(tag, sizeof tag, "plain_%s", solver);
    cJSON *plain = render_stats("", tag, extra);
    snprintf(extra, sizeof extra, "--elements 800 --solver %s --tolerance 1e-9 --relaxation %g", solver,
             omega);
    snprintf(tag, sizeof tag, "relaxed_%s", solver);
    cJSON *over = render_stats("", tag, extra);
    assert_same_surfaces(over, ref, 1e-5, tag);
    assert_true(cli_stats_number(over, "solver", "relaxation") == omega);
    /* omega was used: the iteration count moved. */
    if (cli_stats_number(over, "solver", "iterations") == cli_stats_number(plain, "solver", "iterations"))
        fail_msg("%s: --relaxation %g took as many iterations (%g) as omega = 1", solver, omega,
                 cli_stats_number(plain, "solver", "iterations"));
    cJSON_Delete(plain);
    cJSON_Delete(over);
}

static void test_relaxation(void **state)
{
    (void)state;
    cJSON *ref = render_stats("", "relax_direct", "--elements 800 --solver direct");
    relaxed(ref, "gauss-seidel", 1.2);
    relaxed(ref, "southwell", 1.5);
    relaxed(ref, "jacobi", 0.8); /* weighted Jacobi diverges above 2 / (1 + rho_max) */
    cJSON_Delete(ref);
}

/* ---- (f) the convergence history ---- */

/* Run with --history and check the CSV: its header, iterations strictly
 * increasing, seconds not decreasing, the last row's residual that of the
 * stats and below the tolerance 1e-6.  `split`: the scene has independent
 * rooms, whose steps are numbered over the whole run (the stats keep the
 * most any room took). */
static void check_history(const char *scene, const char *solver, const char *tag, bool split)
{
    char extra[1024], csv[600];
    snprintf(csv, sizeof csv, "%s/%s.csv", test_workdir(), tag);
    snprintf(extra, sizeof extra, "%s --solver %s --tolerance 1e-6 --history '%s'",
             split ? "--mesh-size 0.25" : "--elements 300", solver, csv);
    cJSON *stats = render_stats(scene, tag, extra);
    char *text = test_read_file(csv, NULL);
    assert_non_null(text);
    char *save = NULL, *line = strtok_r(text, "\n", &save);
    assert_non_null(line);
    assert_string_equal(line, "iteration,seconds,residual,unshot");
    long previous = 0, rows = 0;
    double last_residual = NAN, previous_seconds = 0.0;
    while ((line = strtok_r(NULL, "\n", &save)) != NULL) {
        char *end;
        long iteration = strtol(line, &end, 10);
        if (*end != ',' || iteration <= previous)
            fail_msg("%s: history row '%s' after iteration %ld", tag, line, previous);
        double seconds = strtod(end + 1, &end);
        assert_true(*end == ',' && seconds >= previous_seconds);
        char *residual = end + 1;
        last_residual = *residual == ',' ? NAN : strtod(residual, NULL);
        previous = iteration;
        previous_seconds = seconds;
        rows++;
    }
    assert_true(rows >= 1);
    if (!(last_residual < 1e-6))
        fail_msg("%s: last residual in the history %g, not below the tolerance", tag, last_residual);
    if (split)
        assert_true(previous >= (long)cli_stats_number(stats, "solver", "iterations"));
    else
        assert_int_equal(previous, (long)cli_stats_number(stats, "solver", "iterations"));
    assert_relative(last_residual, cli_stats_number(stats, "solver", "residual"), 1e-8, tag);
    free(text);
    cJSON_Delete(stats);
}

static void test_history(void **state)
{
    (void)state;
    for (int k = 0; k < solver_count; k++) {
        char tag[128];
        snprintf(tag, sizeof tag, "history_%s", solvers[k]);
        check_history("", solvers[k], tag, false);
    }
    /* Two rooms solved one after the other: still one history. */
    cli_scene_writer rooms;
    write_rooms(&rooms, "history_rooms", true, true);
    check_history(rooms.obj_path, "gauss-seidel", "history_rooms_gauss-seidel", true);
    check_history(rooms.obj_path, "southwell", "history_rooms_southwell", true);
}

/* ---- conjugate gradients beyond the symmetrised system ---- */

static void test_conjugate_gradient_restarts(void **state)
{
    (void)state;
    /* CG runs on (A_i F_ij + A_j F_ji) / 2; F is float, so reciprocity holds
     * to ~1e-7 and plain CG stalls at a residual of ~8e-10 on this box.  The
     * restarts on the true residual must take it well below that. */
    cJSON *s = render_stats("", "cg_deep", "--elements 800 --solver conjugate-gradient --tolerance 1e-11");
    const cJSON *converged = cJSON_GetObjectItem(cJSON_GetObjectItem(s, "solver"), "converged");
    if (!(cli_stats_number(s, "solver", "residual") < 1e-11) || !cJSON_IsTrue(converged))
        fail_msg("conjugate-gradient: residual %g, not below 1e-11",
                 cli_stats_number(s, "solver", "residual"));
    /* 17 iterations; a non-symmetric operator (say F p in place of F^T A p)
     * still converges through the restarts, but takes over 40. */
    if (!(cli_stats_number(s, "solver", "iterations") < 30))
        fail_msg("conjugate-gradient: %g iterations to 1e-11", cli_stats_number(s, "solver", "iterations"));
    cJSON_Delete(s);
}

/* ---- (g) the direct solver refuses what does not fit ---- */

static void test_direct_memory_limit(void **state)
{
    (void)state;
    cli_scene_writer w;
    write_case_cube(&w, "big_cube", "furnace_cube_rho0.5");
    char errors[600], png[600];
    snprintf(errors, sizeof errors, "%s/direct_memory.err", test_workdir());
    snprintf(png, sizeof png, "%s/direct_memory.png", test_workdir());
    /* 384 elements: F (8 n^2 = 1.1 MiB) fits in 2 MiB, LU beside it (16 n^2 = 2.3 MiB) does not. */
    int status = cli_run_capture(errors,
                                 "render '%s' -o '%s' --width 8 --height 8 --mesh-size 0.125 "
                                 "--solver direct --max-memory 2M",
                                 w.obj_path, png);
    assert_int_equal(status, 1);
    char *text = test_read_file(errors, NULL);
    assert_non_null(text);
    char *newline = strchr(text, '\n');
    assert_non_null(newline);
    assert_true(newline[1] == '\0'); /* one line */
    if (!strstr(text, "2.00 MiB") || !strstr(text, "--max-memory") || !strstr(text, "direct") ||
        !strstr(text, "384"))
        fail_msg("the refusal should name the size, the limit and the way out: %s", text);
    free(text);
    /* The same limit lets an iterative solver through: the refusal was the LU's. */
    status = cli_run_capture(NULL,
                             "render '%s' -o '%s' --width 8 --height 8 --mesh-size 0.125 "
                             "--solver gauss-seidel --max-memory 2M",
                             w.obj_path, png);
    assert_int_equal(status, 0);
}

/* ---- results do not depend on the thread count ---- */

/* Run `radiosity render` (Cornell box, 600 elements) with `env` before it
 * and `extra` after; the image as a PFM (caller frees) and the stats. */
static char *render_image(const char *tag, const char *env, const char *extra, size_t *size, cJSON **stats)
{
    char pfm[600], json[600], cmd[4096];
    snprintf(pfm, sizeof pfm, "%s/%s.pfm", test_workdir(), tag);
    snprintf(json, sizeof json, "%s/%s.json", test_workdir(), tag);
    snprintf(cmd, sizeof cmd, "%s '%s' render -o '%s' --stats '%s' --width 24 --height 24 --elements 600 %s -q",
             env, cli_binary(), pfm, json, extra);
    int status = system(cmd);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        fail_msg("%s: %s exited with %d", tag, cmd, status);
    FILE *f = fopen(pfm, "rb");
    assert_non_null(f);
    char *bytes = malloc(1 << 16);
    assert_non_null(bytes);
    *size = fread(bytes, 1, 1 << 16, f);
    fclose(f);
    *stats = cli_read_json(json);
    assert_non_null(*stats);
    return bytes;
}

/* Every solver, dense and matrix-free: the image, every surface's
 * radiosity, the residual and the iteration count are bit-identical on 1,
 * 2 and 3 threads, set by --threads or by OMP_NUM_THREADS; direct also
 * with OpenBLAS told to use 2 threads (its LU is ours, blocked the same
 * on any thread count: it used to differ in the last bits, 4e-16). */
static void test_thread_count(void **state)
{
    (void)state;
    static const char *runs[][2] = {
        {"", "--threads 1"}, {"", "--threads 2"}, {"", "--threads 3"},
        {"OMP_NUM_THREADS=2", ""}, {"OPENBLAS_NUM_THREADS=2 OMP_NUM_THREADS=2", ""},
    };
    const char *matrix_free[] = {"shooting", "hierarchical"};
    for (int k = 0; k < solver_count + 2; k++) {
        const char *solver = k < solver_count ? solvers[k] : matrix_free[k - solver_count];
        char extra[256], tag[128];
        snprintf(extra, sizeof extra, "--solver %s --tolerance 1e-9%s", solver,
                 k >= solver_count ? " --ff-samples 32 --epsilon 1e-3" : "");
        size_t size0 = 0;
        cJSON *stats0 = NULL;
        snprintf(tag, sizeof tag, "threads0_%s", solver);
        char *image0 = render_image(tag, runs[0][0], extra, &size0, &stats0);
        assert_true(size0 > 24 * 24 * 12);
        for (size_t r = 1; r < sizeof runs / sizeof runs[0]; r++) {
            char more[512];
            snprintf(more, sizeof more, "%s %s", extra, runs[r][1]);
            snprintf(tag, sizeof tag, "threads%zu_%s", r, solver);
            size_t size = 0;
            cJSON *stats = NULL;
            char *image = render_image(tag, runs[r][0], more, &size, &stats);
            char label[128];
            snprintf(label, sizeof label, "%.32s with %.48s%.16s", solver, runs[r][0], runs[r][1]);
            if (size != size0 || memcmp(image, image0, size) != 0)
                fail_msg("%s: the image differs from one thread's", label);
            assert_same_surfaces(stats, stats0, 0.0, label);
            double a = cli_stats_number(stats, "solver", "iterations"), b = cli_stats_number(stats0, "solver", "iterations");
            if (a != b)
                fail_msg("%s: %g iterations, %g on one thread", label, a, b);
            const cJSON *ra = cJSON_GetObjectItem(cJSON_GetObjectItem(stats, "solver"), "residual");
            const cJSON *rb = cJSON_GetObjectItem(cJSON_GetObjectItem(stats0, "solver"), "residual");
            assert_true(cJSON_IsNull(ra) == cJSON_IsNull(rb));
            if (!cJSON_IsNull(ra) && ra->valuedouble != rb->valuedouble)
                fail_msg("%s: residual %.17g, %.17g on one thread", label, ra->valuedouble, rb->valuedouble);
            free(image);
            cJSON_Delete(stats);
        }
        free(image0);
        cJSON_Delete(stats0);
    }
}

/* ---- (h) bright closed boxes: every solver stops ---- */

/* The furnace cube with reflectance rho on every face, each emitting E = 1:
 * B = E / (1 - rho) everywhere (H = B in a closed box).  The matrix the
 * solvers are given has element rows s_i in [s_min, s_max] (stats), and
 * then (maximum principle: B_max = E + rho sum_j F_ij B_j <= E + rho s_max
 * B_max, and the same for the minimum)
 *
 *     E / (1 - rho s_min) <= B_i <= E / (1 - rho s_max),
 *
 * the band the exact answer of that matrix lies in. */
static void write_bright_cube(cli_scene_writer *w, const char *name, double rho)
{
    static const double zero[3] = {0, 0, 0};
    const double r[3] = {rho, rho, rho};
    cli_scene_begin(w, name);
    write_cube_faces(w, "furnace_cube_rho0.5", "", zero, r, NULL, 0.0, NULL);
    cli_scene_end(w);
}

/* Render without --quiet, for the warning; stderr into `errors`. */
static cJSON *render_loud(const char *scene, const char *tag, const char *extra, char *errors, size_t size)
{
    char stats[600], png[600], err[600], cmd[4096];
    snprintf(stats, sizeof stats, "%s/%s.stats.json", test_workdir(), tag);
    snprintf(png, sizeof png, "%s/%s.png", test_workdir(), tag);
    snprintf(err, sizeof err, "%s/%s.err", test_workdir(), tag);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' --stats '%s' --width 8 --height 8 %s >/dev/null 2>'%s'",
             cli_binary(), scene, png, stats, extra, err);
    int status = system(cmd);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        fail_msg("%s: radiosity render %s exited with %d", tag, extra, status);
    char *text = test_read_file(err, NULL);
    assert_non_null(text);
    snprintf(errors, size, "%s", text);
    free(text);
    cJSON *j = cli_read_json(stats);
    assert_non_null(j);
    return j;
}

static bool stats_flag(const cJSON *stats, const char *key)
{
    return cJSON_IsTrue(cJSON_GetObjectItem(cJSON_GetObjectItem(stats, "solver"), key));
}

/* The area-weighted mean radiosity over the six unit faces (channel 0). */
static double cube_mean(const cJSON *stats)
{
    double sum = 0.0;
    for (int f = 0; f < 6; f++) {
        double B[3];
        cli_stats_surface_radiosity(stats, cube_faces[f], B);
        sum += B[0];
    }
    return sum / 6.0;
}

/* An unconverged stop: one warning line naming the solver, the count and
 * why; the stats say the same. */
static void assert_stopped(const cJSON *stats, const char *errors, const char *solver, double limit,
                           const char *units)
{
    char expected[256];
    snprintf(expected, sizeof expected, "radiosity: warning: %s did not converge in %.0f %s (the cap; reflectance x row sum 0.999999",
             solver, limit, units);
    const char *newline = strchr(errors, '\n');
    if (strncmp(errors, expected, strlen(expected)) != 0 || !newline || newline[1] != '\0')
        fail_msg("%s: expected one line '%s...', got '%s'", solver, expected, errors);
    assert_false(stats_flag(stats, "converged"));
    assert_true(cli_stats_number(stats, "solver", "iterations") == limit);
    assert_true(cli_stats_number(stats, "solver", "iteration_limit") == limit);
    const cJSON *warning = cJSON_GetObjectItem(cJSON_GetObjectItem(stats, "solver"), "warning");
    assert_true(cJSON_IsString(warning) && strstr(errors, warning->valuestring));
    /* Bounded time: 10^4 bounces of a 24-element box are seconds. */
    assert_true(cli_stats_number(stats, "solver", "seconds") < 120.0);
}

static void test_bright_boxes_dense(void **state)
{
    (void)state;
    cli_scene_writer w99, w6;
    write_bright_cube(&w99, "bright99", 0.99);
    write_bright_cube(&w6, "bright6", 0.999999);
    for (int k = 0; k < solver_count; k++) {
        char extra[256], tag[128], errors[2048];
        /* 0.99: every solver converges, inside the band of its matrix, and
         * the band is within 0.2% of the closed form E / (1 - rho) = 100. */
        snprintf(extra, sizeof extra, "--solver %s --mesh-size 0.25", solvers[k]);
        snprintf(tag, sizeof tag, "bright99_%s", solvers[k]);
        cJSON *s = render_loud(w99.obj_path, tag, extra, errors, sizeof errors);
        assert_true(stats_flag(s, "converged"));
        assert_string_equal(errors, "");
        double lo = 1.0 / (1.0 - 0.99 * cli_stats_number(s, "form_factors", "row_sum_min"));
        double hi = 1.0 / (1.0 - 0.99 * cli_stats_number(s, "form_factors", "row_sum_max"));
        for (int f = 0; f < 6; f++) {
            double B[3];
            cli_stats_surface_radiosity(s, cube_faces[f], B);
            if (!(B[0] >= lo * (1.0 - 1e-6) && B[0] <= hi * (1.0 + 1e-6)))
                fail_msg("%s: rho 0.99: B(%s) = %.9g outside [%.9g, %.9g]", solvers[k], cube_faces[f], B[0], lo, hi);
            assert_relative(B[0], 100.0, 2e-3, tag);
        }
        cJSON_Delete(s);

        /* 0.999999, closed up (rows 1 to float rounding): conjugate
         * gradients and LU converge, to 10^6 within the band; gathering and
         * Southwell stop at the cap of 10^4 bounces (24 elements: 10^4
         * sweeps, 240,000 shots), with B between E and the band. */
        snprintf(extra, sizeof extra, "--solver %s --mesh-size 0.5 --closure-correction", solvers[k]);
        snprintf(tag, sizeof tag, "bright6_%s", solvers[k]);
        s = render_loud(w6.obj_path, tag, extra, errors, sizeof errors);
        assert_int_equal((int)cJSON_GetObjectItem(s, "elements")->valuedouble, 24);
        lo = 1.0 / (1.0 - 0.999999 * cli_stats_number(s, "form_factors", "row_sum_min"));
        hi = 1.0 / (1.0 - 0.999999 * cli_stats_number(s, "form_factors", "row_sum_max"));
        bool exact = strcmp(solvers[k], "direct") == 0 || strcmp(solvers[k], "conjugate-gradient") == 0;
        if (exact) {
            assert_true(stats_flag(s, "converged"));
            assert_string_equal(errors, "");
            for (int f = 0; f < 6; f++) {
                double B[3];
                cli_stats_surface_radiosity(s, cube_faces[f], B);
                if (!(B[0] >= lo * (1.0 - 1e-6) && B[0] <= hi * (1.0 + 1e-6)))
                    fail_msg("%s: rho 0.999999: B(%s) = %.9g outside [%.9g, %.9g]", solvers[k], cube_faces[f], B[0],
                             lo, hi);
                assert_relative(B[0], 1e6, 0.02, tag);
            }
        } else {
            bool southwell = strcmp(solvers[k], "southwell") == 0;
            assert_stopped(s, errors, solvers[k], southwell ? 240000.0 : 10000.0, southwell ? "shots" : "sweeps");
            double mean = cube_mean(s), residual = cli_stats_number(s, "solver", "residual");
            assert_true(mean > 1.0 && mean < lo);
            /* The residual reported is the iterate's: at least the power not
             * yet accounted for, 1 - (1 - rho) B / E summed over the box. */
            if (!(residual >= 1.0 - 1e-6 * mean - 1e-3 && residual <= 1.0))
                fail_msg("%s: residual %g for a mean B of %g", solvers[k], residual, mean);
        }
        cJSON_Delete(s);
    }
}

/* Shooting and hierarchical on the same boxes.  Shooting's own measure is
 * the unshot power u (of the emitted): with nothing escaping, the power it
 * has deposited is exact bookkeeping, sum A B = (emitted - rho U) / (1 - rho)
 * and absorbed = emitted - U.  Converged, the unshot light's remainder is
 * added as the ambient term of the group light joined (solve_shooting.c),
 * exact in this closed box of one reflectance: sum A B = emitted / (1 - rho),
 * absorbed = emitted; stopped at its bound, it keeps what it deposited. */
static void test_bright_boxes_matrix_free(void **state)
{
    (void)state;
    cli_scene_writer w99, w6;
    write_bright_cube(&w99, "mf_bright99", 0.99);
    write_bright_cube(&w6, "mf_bright6", 0.999999);
    const double rho[2] = {0.99, 0.999999};
    const char *scene[2] = {w99.obj_path, w6.obj_path};
    for (int b = 0; b < 2; b++) {
        char tag[64], errors[2048];
        snprintf(tag, sizeof tag, "shoot_%d", b);
        /* Without the control variate, which leaves a closed box of one
         * reflectance nothing to shoot (docs/methods.md "The control
         * variate"): the shooting's own bookkeeping and cap are tested. */
        cJSON *s = render_loud(scene[b], tag, "--solver shooting --mesh-size 0.5 --ff-samples 64 --no-control-variate",
                               errors, sizeof errors);
        double u = cli_stats_number(s, "solver", "unshot");
        double emitted = cli_stats_number(s, "power_W", "emitted");
        /* E as read (pi x Ke): the emitted power / 6 m^2. */
        double left = b == 0 ? 0.0 : u; /* converged: the remainder added */
        assert_relative(cube_mean(s), emitted / 6.0 * (1.0 - rho[b] * left) / (1.0 - rho[b]), 1e-9,
                        "shooting: deposited power");
        assert_relative(cli_stats_number(s, "power_W", "absorbed"), emitted * (1.0 - left), 1e-9,
                        "shooting: absorbed");
        if (b == 0) {
            assert_true(stats_flag(s, "converged") && u <= 1e-3);
            assert_string_equal(errors, "");
        } else {
            /* 24 elements: one batch a bounce. */
            assert_stopped(s, errors, "shooting", 10000.0, "batches");
            assert_true(u > 0.9);
        }
        cJSON_Delete(s);

        /* Hierarchical: B = E / (1 - rho c), c its links' closure weighted by
         * power (1 here: uniform leaves at this min-area), converged at 0.99;
         * at 0.999999 its first round stops at the cap. */
        snprintf(tag, sizeof tag, "hier_%d", b);
        s = render_loud(scene[b], tag, "--solver hierarchical --epsilon 1e-3 --min-area 0.05", errors, sizeof errors);
        if (b == 0) {
            assert_true(stats_flag(s, "converged"));
            assert_string_equal(errors, "");
            const cJSON *closure = cJSON_GetObjectItem(
                cJSON_GetObjectItem(cJSON_GetObjectItem(s, "solver"), "hierarchical"), "closure");
            double c = cJSON_GetObjectItem(closure, "power_weighted")->valuedouble;
            assert_relative(cube_mean(s), 1.0 / (1.0 - rho[b] * c), 1e-4, "hierarchical: B = E / (1 - rho c)");
            assert_relative(cube_mean(s), 100.0, 1e-3, "hierarchical: closed form");
        } else {
            assert_stopped(s, errors, "hierarchical (refinement round 1)", 10000.0, "sweeps");
        }
        cJSON_Delete(s);
    }
}

/* ---- setup: the work folder, the cases, the solver list ---- */

static int read_solvers(void)
{
    char cmd[600];
    snprintf(cmd, sizeof cmd, "'%s' --list-methods", cli_binary());
    FILE *p = popen(cmd, "r");
    if (!p)
        return -1;
    char line[1024];
    bool in_solvers = false;
    while (fgets(line, sizeof line, p)) {
        if (line[0] != ' ') {
            in_solvers = strncmp(line, "solvers", 7) == 0;
            continue;
        }
        if (!in_solvers || strstr(line, "matrix-free") || solver_count == MAX_SOLVERS)
            continue;
        /* The galerkin strategy's solvers make and solve their own system,
         * (M - rho K) B = M E, not F's: test_galerkin.c is their suite. */
        if (strstr(line, " galerkin-") || strstr(line, " collocation "))
            continue;
        char name[64];
        if (sscanf(line, " %63s", name) == 1)
            solvers[solver_count++] = strdup(name);
    }
    return pclose(p) == 0 && solver_count > 0 ? 0 : -1;
}

static int setup(void **state)
{
    (void)state;
    return cli_setup("solvers") == 0 && read_solvers() == 0 ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    for (int k = 0; k < solver_count; k++)
        free(solvers[k]);
    return cli_teardown();
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_solvers PATH_TO_RADIOSITY\n");
        return 2;
    }
    cli_set_binary(argv[1]);
    /* "--slow" after the program's path: the cases at scale instead of the quick ones. */
    bool slow = argc == 3 && strcmp(argv[2], "--slow") == 0;
    if (argc > 3 || (argc == 3 && !slow)) {
        fprintf(stderr, "usage: test_solvers PATH_TO_RADIOSITY [--slow]\n");
        return 2;
    }
    const struct CMUnitTest fast_tests[] = {
        cmocka_unit_test(test_registry),
        cmocka_unit_test(test_six_patch_exact),
        cmocka_unit_test(test_furnace),
        cmocka_unit_test(test_separate_rooms),
        cmocka_unit_test(test_history),
        cmocka_unit_test(test_conjugate_gradient_restarts),
        cmocka_unit_test(test_direct_memory_limit),
        cmocka_unit_test(test_bright_boxes_dense),
    };
    /* At scale: with --slow alone (CTest: test_solvers_slow, label slow). */
    const struct CMUnitTest slow_tests[] = {
        cmocka_unit_test(test_cornell_box_against_direct),
        cmocka_unit_test(test_relaxation),
        cmocka_unit_test(test_thread_count),
        cmocka_unit_test(test_bright_boxes_matrix_free),
    };
    return slow ? cmocka_run_group_tests_name("solvers_slow", slow_tests, setup, teardown)
                : cmocka_run_group_tests_name("solvers", fast_tests, setup, teardown);
}
