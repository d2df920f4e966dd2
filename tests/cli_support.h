/*
 * cli_support.h -- helpers shared by the suites that drive the `radiosity`
 * program itself (test_accuracy, test_cli, test_outputs, test_ff_*, ...;
 * the rad_test_support library, with test_support.h).
 *
 * A suite points these at the binary (argv[1]), makes a work folder and
 * loads tests/data/cases.json in its group setup, writes scenes there as
 * OBJ+MTL, runs the program on them and reads back the view-factor or
 * stats JSON it wrote; or runs it in the work folder as a user would and
 * reads what it printed.  Failures go through cmocka (fail_msg and the
 * assert_* macros), so these are for use inside a running test only.
 */
#ifndef RAD_TESTS_CLI_SUPPORT_H
#define RAD_TESTS_CLI_SUPPORT_H

#include <cjson/cJSON.h>
#include <stdio.h>

#include "test_support.h"

#if defined(__GNUC__)
#define CLI_PRINTF(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define CLI_PRINTF(fmt, args)
#endif

/* ---- the binary, the work folder and the exact cases ---- */

/* Sets the path of the radiosity binary that cli_run runs (not copied). */
void cli_set_binary(const char *path);
/* The path given to cli_set_binary. */
const char *cli_binary(void);
/* Makes the work folder /tmp/radiosity-TAG-XXXXXX (test_workdir) and
 * loads cases.json; 0, or -1 on failure. */
int cli_setup(const char *tag);
/* Frees the cases and removes the work folder; 0, or -1 on failure. */
int cli_teardown(void);
/* The case with this id in cases.json; fails the test when missing. */
const cJSON *cli_find_case(const char *id);
/* The "exact" value of a case. */
double cli_exact_value(const cJSON *c);

/* ---- files ---- */

/* A file parsed as JSON (caller frees with cJSON_Delete), or NULL when it
 * is not JSON; fails the test when it cannot be read. */
cJSON *cli_read_json(const char *path);

/* ---- writing scenes as OBJ+MTL in the work folder ---- */

/* A scene being written: OBJ text and MTL text. */
typedef struct cli_scene_writer {
    FILE *obj, *mtl;
    int vertices;       /* written so far: OBJ indices are 1 + this */
    char obj_path[512];
} cli_scene_writer;

/* Opens NAME.obj and NAME.mtl in the work folder; fails the test if it cannot. */
void cli_scene_begin(cli_scene_writer *w, const char *name);
/* Grey material: reflectance rho, exitance E (W/m^2) written as Ke = E / pi. */
void cli_scene_material(cli_scene_writer *w, const char *name, double rho, double E);
/* RGB material: reflectance rho[3], exitance E (W/m^2) written as Ke = E / pi. */
void cli_scene_material_rgb(cli_scene_writer *w, const char *name, const double rho[3], double E);
/* One polygon of n vertices as object `surface` with `material`. */
void cli_scene_polygon(cli_scene_writer *w, const char *surface, const char *material,
                       const double (*v)[3], int n);
/* The vertices of a case surface from cases.json (at most 16); returns their count. */
int cli_case_vertices(const cJSON *surface, double v[16][3]);
/* A case surface from cases.json as one polygon. */
void cli_scene_case_surface(cli_scene_writer *w, const cJSON *surface, const char *name,
                            const char *material);
/* A case surface from cases.json as one polygon, moved by `offset`. */
void cli_scene_case_surface_moved(cli_scene_writer *w, const cJSON *surface, const char *name,
                                  const char *material, const double offset[3]);
/* Closes both files. */
void cli_scene_end(cli_scene_writer *w);
/* Case `id` of cases.json as the scene `name` (NULL: id), begun and
 * ended: its geometry's A1, A2 and blocker (when it has one), grey
 * (rho 0.5), dark. */
void cli_scene_two_surfaces(cli_scene_writer *w, const char *id, const char *name);

/* ---- running the binary ---- */

/* Runs `radiosity ARGS --quiet`; returns its exit status (-1 if it did not exit). */
int cli_run(const char *fmt, ...) CLI_PRINTF(1, 2);
/* As cli_run, with stderr written to the file `errors` when not NULL. */
int cli_run_capture(const char *errors, const char *fmt, ...) CLI_PRINTF(2, 3);
/* `radiosity viewfactors` on a written scene into OBJ.F.json; the parsed JSON (caller frees). */
cJSON *cli_view_factors(const cli_scene_writer *w, const char *extra);

/* ---- running the binary in the work folder, as a user does ---- */

/* Runs `radiosity ARGS` in the work folder (no --quiet, stdin /dev/null)
 * and keeps what it printed for cli_stdout and cli_stderr (their first
 * 64 KiB and 8 KiB).  Returns its exit status (-1 if it did not exit). */
int cli_run_here(const char *fmt, ...) CLI_PRINTF(1, 2);
/* What the last cli_run_here printed on stdout, on stderr. */
const char *cli_stdout(void);
const char *cli_stderr(void);
/* Takes the file at `path` as cli_stderr: a run started by hand. */
void cli_stderr_from(const char *path);
/* Fails the test unless cli_stderr is exactly one line and holds needle1
 * and needle2 (either may be NULL). */
void cli_assert_one_line_error(const char *needle1, const char *needle2);

/* A scene every command takes: a floor and a lamp above it, as OBJ text
 * that names the material library good.mtl, and that library. */
extern const char cli_good_obj[];
extern const char cli_good_mtl[];

/* ---- reading the output ---- */

/* Index of a named surface in view-factor JSON; fails the test when absent. */
int cli_surface_index(const cJSON *vf, const char *name);
/* Entry [from][to] of matrix `key` ("F", "F_std_error", ...); fails when absent. */
double cli_vf_matrix(const cJSON *vf, const char *key, const char *from, const char *to);
/* The view factor F[from][to]. */
double cli_vf_get(const cJSON *vf, const char *from, const char *to);
/* The area of a surface (m^2) as reported in view-factor JSON. */
double cli_vf_area(const cJSON *vf, const char *name);
/* stats.OBJECT.KEY as a number; fails the test when missing. */
double cli_stats_number(const cJSON *stats, const char *object, const char *key);
/* The mean RGB radiosity of a named surface in stats JSON; fails when absent. */
void cli_stats_surface_radiosity(const cJSON *stats, const char *name, double rgb[3]);

/* Fails the test unless |got - exact| <= tol |exact| (so never when exact is 0). */
void cli_assert_relative(double got, double exact, double tol, const char *what);

#endif
