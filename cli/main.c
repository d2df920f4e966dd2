/*
 * main.c -- the `radiosity` command.  Each command walks the pipeline:
 *
 *   1. load      the scene file, or the built-in Cornell box
 *   2. mesh      surfaces -> elements            } rad_solution_create
 *   3. couple    visibility + form factors F_ij  }
 *   4. solve     B = E + rho F B                   rad_solution_solve
 *   5. output    image / view factors / lit mesh   rad_solution_render, ..._write_*
 *                / stats
 *
 * Flags live in one table (options.c), shared by every command, which
 * takes each flag's range, default and help from the library's option
 * table; --help and the man page are printed from it, so none can drift.  Exit
 * status: 0 ok, 1 failure, 2 usage error, 130 / 143 when interrupted by
 * SIGINT / SIGTERM (partial outputs are written and marked as such).
 */
#include "generate.h"
#include "options.h"
#include "radiosity.h"
#ifdef RADIOSITY_MPI
#include "mpi_ranks.h"
#endif
#ifdef RADIOSITY_HAVE_VIEWER
#include "viewer.h"
#endif

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

enum { EXIT_USAGE = 2 };

typedef cli_settings settings;

static void list_methods(void)
{
    static const char *titles[] = {"form factors (--form-factors)", "solvers (--solver)",
                                   "ray backends (--visibility)"};
    for (int k = 0; k < 3; k++) {
        printf("%s:\n", titles[k]);
        const char *name, *desc;
        char text[1024];
        for (size_t i = 0; rad_method_info((rad_method_kind)k, i, &name, &desc); i++)
            printf("  %-14s %s\n", name, cli_rewrite_message(desc, text, sizeof text));
    }
}

/* Parse the command line (options.c) and carry out --help, --version,
 * --list-methods, --man and usage errors.  Returns -1 to go on, else an
 * exit status. */
static int parse_args(int argc, char **argv, settings *s)
{
    char err[1024];
    switch (cli_parse_args(argc, argv, s, err, sizeof err)) {
    case CLI_RUN: return -1;
    case CLI_HELP: cli_print_help(stdout, s->command); return 0;
    case CLI_VERSION: printf("radiosity %s\n", RAD_VERSION_STRING); return 0;
    case CLI_LIST_METHODS: list_methods(); return 0;
    case CLI_MAN: cli_print_man(stdout); return 0;
    case CLI_NO_ARGUMENTS: cli_print_help(stderr, 0); return EXIT_USAGE;
    case CLI_USAGE_ERROR: break;
    }
    const char *command = cli_command_name(s->command);
    fprintf(stderr, "radiosity: %s (see radiosity %s%s--help)\n", err, command, command[0] ? " " : "");
    return EXIT_USAGE;
}

/* ---- progress on stderr, only when it is a terminal ---- */

typedef struct progress_state {
    const char *phase;
    int last_percent;
    double start;
} progress_state;

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void progress_bar(void *user, const char *phase, uint64_t done, uint64_t total)
{
    progress_state *p = user;
    int percent = total ? (int)(100.0 * (double)done / (double)total) : 100;
    if (p->phase != phase) {
        if (p->phase)
            fputc('\n', stderr);
        p->phase = phase;
        p->last_percent = -1;
        p->start = now_seconds();
    }
    if (percent == p->last_percent)
        return;
    p->last_percent = percent;
    char bar[31];
    int filled = percent * 30 / 100;
    for (int k = 0; k < 30; k++)
        bar[k] = k < filled ? '#' : '.';
    bar[30] = '\0';
    fprintf(stderr, "\r%-13s [%s] %3d%%  %6.1f s", phase, bar, percent, now_seconds() - p->start);
    fflush(stderr);
}

static void progress_end(progress_state *p)
{
    if (p->phase)
        fputc('\n', stderr);
    p->phase = NULL;
}

/* ---- interruption ----
 *
 * The first SIGINT or SIGTERM decides the exit status (130 / 143).  While
 * the pipeline works, it cancels the context: the running phase stops and
 * what exists is saved (a partial solution, or the stats of an interrupted
 * run).  Once the outputs are being made (`saving`), signals only note
 * themselves: a second Ctrl-C cannot lose the results being saved, and the
 * output set removes every temporary whatever happens. */

/* The context whose work a signal cancels (set once, before the handler
 * can see anything but NULL); rad_context_cancel is an atomic store. */
static rad_context *volatile cancel_context;
static volatile sig_atomic_t cancel_signal;
static volatile sig_atomic_t saving;

static void on_signal(int sig)
{
    if (!cancel_signal)
        cancel_signal = sig;
    if (!saving)
        rad_context_cancel(cancel_context, true);
}

static void install_signal_handlers(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    /* A FIFO whose reader left is a write error, not a silent death. */
    sa.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &sa, NULL);
}

/* From here on signals are noted, not acted upon (see above). */
static void begin_saving(rad_context *ctx)
{
    saving = 1;
    rad_context_cancel(ctx, false);
}

static int interrupted_status(void) { return cancel_signal == SIGTERM ? 143 : 130; }

/* ---- progressive display: an image every K solver steps ---- */

typedef struct progressive {
    rad_context *ctx;
    const char *dir;
    int every;
    const rad_render_options *render;
    double exposure;
    int failed;
} progressive;

static int on_step(void *user, rad_solution *solution, const rad_solve_step *step)
{
    progressive *p = user;
    if (!p->dir || step->iteration % p->every != 0)
        return 0;
    rad_image *image = NULL;
    char path[4096];
    snprintf(path, sizeof path, "%s/step_%08d.png", p->dir, step->iteration);
    rad_result r = rad_solution_render(p->ctx, solution, p->render, &image);
    if (r == RAD_ERROR_INTERRUPTED) {
        rad_image_destroy(image); /* the interrupted render still hands back its image */
        return 1; /* a signal: the solve stops and its iterate is saved, frame or not */
    }
    if (r == RAD_OK && p->exposure == 0.0)
        p->exposure = rad_image_auto_exposure(image); /* fixed from the first frame on */
    if (r == RAD_OK)
        r = rad_image_write_exposed(p->ctx, image, path, p->exposure);
    rad_image_destroy(image);
    if (r != RAD_OK) {
        p->failed = 1;
        return 1; /* stop: the message is in the context */
    }
    return 0;
}

/* ---- the commands ---- */

/* `radiosity view`: the window or an off-screen frame (viewer/), when this
 * program was built with the viewer (CMake RADIOSITY_VIEWER). */
static int run_view(rad_context *ctx, const settings *s)
{
#ifdef RADIOSITY_HAVE_VIEWER
    rad_camera camera;
    if (s->camera && rad_camera_from_string(ctx, s->camera, &camera) != RAD_OK) {
        fprintf(stderr, "radiosity: --%s (see radiosity view --help)\n", rad_context_error(ctx));
        return EXIT_USAGE;
    }
    if (s->luminaires && s->scene_path && rad_file_is_solution(s->scene_path)) {
        fprintf(stderr, "radiosity: --luminaires: %s is a solution file, solved already (give the layout with "
                        "the scene)\n", s->scene_path);
        return EXIT_USAGE;
    }
    rv_args a = {.input = s->scene_path, .luminaires = s->luminaires, .solve = s->solve, .width = s->render.width,
                 .height = s->render.height, .camera = s->camera ? &camera : NULL,
                 .shading = s->render.shading, .exposure = s->render.exposure, .output = s->output,
                 .offscreen = s->offscreen != 0, .no_ambient = s->no_ambient != 0, .keys = s->keys,
                 .quiet = s->quiet != 0};
    return rv_main(ctx, &a);
#else
    (void)ctx, (void)s;
    fprintf(stderr, "radiosity: view: this program was built without the viewer (it needs libsdl2-dev and "
                    "libepoxy-dev: scripts/setup.sh installs them, then rebuild; docs/viewer.md)\n");
    return 1;
#endif
}

/* The library's message, with its field names written as our flags
 * ("rad_options.max_memory_bytes" -> "--max-memory"). */
static int fail(rad_context *ctx, rad_result r)
{
    char msg[1024];
    cli_rewrite_message(rad_context_error(ctx), msg, sizeof msg);
    fprintf(stderr, "radiosity: %s\n", msg[0] ? msg : rad_result_string(r));
    /* A stage that fails once a signal has come (a load whose read or open
     * the signal broke off) was interrupted: 130 / 143, like the rest. */
    return cancel_signal ? interrupted_status() : 1;
}

/* The library's warnings (an orthographic glTF camera replaced): one line
 * each, its field names written as our flags, as its errors are. */
static void print_warning(void *user, const char *message)
{
    (void)user;
    char text[1024];
    cli_rewrite_message(message, text, sizeof text);
    fprintf(stderr, "radiosity: warning: %s\n", text);
}

/* The absolute path of a file just written, for telling the user where it
 * is; falls back to the name as given. */
static const char *where(const char *path, char *buf)
{
    return realpath(path, buf) ? buf : path;
}

/* The outputs of a run, checked before any work and written as one output
 * set: every file appears at the end, or none (docs/robustness.md). */
typedef struct run_outputs {
    rad_output_set *set;
    const char *main;      /* the image, view-factor or mesh file: its temporary */
    const char *stats, *history;
    const char *gebhart;   /* thermal --gebhart: its temporary */
    const char *second;    /* illuminance's second -o: its temporary */
} run_outputs;

/* Plan the outputs and name the scene file as an input.  Returns -1 to go
 * on, else an exit status: 2 when a path is refused as an argument (an
 * alias, an unknown format), 1 when it cannot be written. */
static int plan_outputs(rad_context *ctx, const settings *s, run_outputs *o)
{
    rad_output_kind kind = s->command == CLI_THERMAL       ? RAD_OUTPUT_THERMAL
                           : s->command == CLI_ILLUMINANCE ? RAD_OUTPUT_ILLUMINANCE
                           : s->command == CLI_VIEWFACTORS ? RAD_OUTPUT_VIEW_FACTORS
                           : s->command == CLI_SOLVE     ? RAD_OUTPUT_SOLUTION
                           : s->command == CLI_EXPORT    ? RAD_OUTPUT_MESH
                           : s->command == CLI_BAKE      ? RAD_OUTPUT_BAKE
                                                         : RAD_OUTPUT_IMAGE;
    rad_result r = rad_output_set_create(ctx, &o->set);
    if (r == RAD_OK && s->scene_path)
        r = rad_output_set_add_input(ctx, o->set, s->scene_path);
    if (r == RAD_OK && s->bc)
        r = rad_output_set_add_input(ctx, o->set, s->bc);
    if (r == RAD_OK)
        r = rad_output_set_add(ctx, o->set, s->output, kind, &o->main);
    if (r == RAD_OK && s->gebhart)
        r = rad_output_set_add(ctx, o->set, s->gebhart, RAD_OUTPUT_THERMAL, &o->gebhart);
    if (r == RAD_OK && s->grid)
        r = rad_output_set_add_input(ctx, o->set, s->grid);
    if (r == RAD_OK && s->output2)
        r = rad_output_set_add(ctx, o->set, s->output2, RAD_OUTPUT_ILLUMINANCE, &o->second);
    /* bake: the first atlas's lightmaps (there is always one); others are
     * added when the packing knows them. */
    static const char *const lightmap_ext[2] = {"hdr", "png"};
    for (int k = 0; k < 2 && r == RAD_OK && s->command == CLI_BAKE; k++) {
        char name[PATH_MAX];
        const char *temp;
        if (rad_bake_image_path(s->output, 0, lightmap_ext[k], name, sizeof name) >= sizeof name)
            r = RAD_ERROR_INVALID_ARGUMENT;
        else
            r = rad_output_set_add(ctx, o->set, name, RAD_OUTPUT_IMAGE, &temp);
    }
    if (r == RAD_OK && s->stats)
        r = rad_output_set_add(ctx, o->set, s->stats, RAD_OUTPUT_FILE, &o->stats);
    if (r == RAD_OK && s->history && s->command != CLI_VIEWFACTORS && s->command != CLI_THERMAL)
        r = rad_output_set_add(ctx, o->set, s->history, RAD_OUTPUT_FILE, &o->history);
    if (r == RAD_OK)
        return -1;
    fail(ctx, r);
    return r == RAD_ERROR_INVALID_ARGUMENT ? EXIT_USAGE : 1;
}

/* Every file the loader read is an input no output may be. */
static int check_scene_inputs(rad_context *ctx, const rad_scene *scene, run_outputs *o)
{
    for (size_t i = 0; i < rad_scene_input_count(scene); i++) {
        rad_result r = rad_output_set_add_input(ctx, o->set, rad_scene_input_path(scene, i));
        if (r != RAD_OK) {
            fail(ctx, r);
            return r == RAD_ERROR_INVALID_ARGUMENT ? EXIT_USAGE : 1;
        }
    }
    return -1;
}

/* The solve command's outputs: the solution file with the stats and the
 * history, put in place together; an interrupted solve is not a solution,
 * so it leaves the partial stats only.  Returns the exit status. */
static int write_solution(rad_context *ctx, const settings *s, rad_solution *sol, run_outputs *out,
                          int partial, double t0)
{
    begin_saving(ctx);
    if (partial)
        rad_output_set_drop(out->set, s->output);
    rad_result r = partial ? RAD_OK : rad_solution_save(ctx, sol, out->main);
    if (r == RAD_OK && s->stats)
        r = rad_solution_write_stats(ctx, sol, out->stats, partial);
    if (r == RAD_OK && s->history)
        r = rad_solution_write_history(ctx, sol, out->history);
    if (r == RAD_OK) {
        fflush(stdout);
        r = rad_output_set_commit(ctx, out->set);
    }
    if (r != RAD_OK)
        return fail(ctx, r);
    if (partial) {
        fprintf(stderr, "radiosity: interrupted while solving; no solution file written%s\n",
                s->stats ? ", the partial stats only" : "");
        return interrupted_status();
    }
    char full[PATH_MAX];
    if (!s->quiet)
        printf("wrote %s (%zu elements, residual %.2g, %.1f s)\n", where(s->output, full),
               rad_solution_element_count(sol), rad_solution_residual(sol), now_seconds() - t0);
    return cancel_signal ? interrupted_status() : 0;
}

/* The thermal command after the form factors: solve the net-radiation
 * equations for the conditions, write the figures (and the Gebhart
 * factors, the stats) as one output set, print the balance.  Returns the
 * exit status. */
static int run_thermal(rad_context *ctx, const settings *s, const rad_scene *scene, const rad_solution *sol,
                       const rad_thermal_conditions *bc, run_outputs *out, progress_state *progress, double t0)
{
    rad_thermal_options to = {s->solve.solver, s->thermal_tolerance, s->solve.max_iterations};
    rad_thermal *heat = NULL;
    rad_result r = rad_thermal_solve(ctx, sol, bc, &to, &heat);
    progress_end(progress);
    if (r == RAD_OK) {
        begin_saving(ctx);
        r = rad_thermal_write(ctx, heat, out->main, s->element_level);
    }
    if (r == RAD_OK && s->gebhart)
        r = rad_thermal_write_gebhart(ctx, heat, out->gebhart);
    if (r == RAD_OK && s->stats)
        r = rad_thermal_write_stats(ctx, heat, out->stats);
    if (r == RAD_OK) {
        fflush(stdout);
        r = rad_output_set_commit(ctx, out->set);
    }
    if (r != RAD_OK) {
        rad_thermal_destroy(heat);
        return fail(ctx, r);
    }
    if (!s->quiet) {
        rad_thermal_balance b;
        double residual = rad_thermal_get_balance(heat, &b);
        char full[PATH_MAX];
        printf("wrote %s (%zu surfaces, %zu elements, residual %.2g, %.1f s)\n", where(s->output, full),
               rad_scene_surface_count(scene), rad_solution_element_count(sol), residual, now_seconds() - t0);
        printf("balance: sum Q = %.6g W, to the environment %.6g W, imbalance %.3g W (%.2g of sum |Q| = %.6g W)\n",
               b.net_power, b.environment_power, b.imbalance, b.relative_imbalance, b.power_scale);
    }
    rad_thermal_destroy(heat);
    return cancel_signal ? interrupted_status() : 0;
}

/* The illuminance command after the solve: the grid file's points
 * evaluated, a summary line per grid, the CSV / JSON (and stats, history)
 * put in place together.  Returns the exit status. */
/* One of illuminance's outputs: the values (.csv, .json), or the grids'
 * plans (.png: the path given leaves the set, each grid's picture joins
 * it). */
static rad_result write_illuminance_output(rad_context *ctx, const rad_illuminance *il, run_outputs *out,
                                           const char *given, const char *temp,
                                           const rad_false_colour_options *plots)
{
    const char *dot = strrchr(given, '.');
    if (!dot || strcasecmp(dot, ".png") != 0)
        return rad_illuminance_write(ctx, il, temp);
    rad_output_set_drop(out->set, given);
    return rad_illuminance_write_plots(ctx, il, plots, out->set, given);
}

static int run_illuminance(rad_context *ctx, const settings *s, rad_solution *sol, run_outputs *out,
                           progress_state *progress, double t0, const rad_false_colour_options *plots)
{
    rad_illuminance *il = NULL;
    rad_result r = rad_illuminance_evaluate_file(ctx, sol, s->grid, &il);
    progress_end(progress);
    if (r == RAD_ERROR_INTERRUPTED) {
        fprintf(stderr, "radiosity: interrupted while computing the illuminance; nothing written\n");
        return interrupted_status();
    }
    if (r != RAD_OK)
        return fail(ctx, r);
    begin_saving(ctx);
    r = write_illuminance_output(ctx, il, out, s->output, out->main, plots);
    if (r == RAD_OK && out->second)
        r = write_illuminance_output(ctx, il, out, s->output2, out->second, plots);
    if (r == RAD_OK && s->stats)
        r = rad_solution_write_stats(ctx, sol, out->stats, 0);
    if (r == RAD_OK && s->history)
        r = rad_solution_write_history(ctx, sol, out->history);
    if (r == RAD_OK && !s->quiet) {
        printf("%-24s %8s %12s %12s %12s %7s\n", "grid", "points", "Eavg lux", "Emin lux", "Emax lux", "U0");
        for (size_t g = 0; g < rad_illuminance_grid_count(il); g++) {
            const rad_grid_result *res = rad_illuminance_grid(il, g);
            printf("%-24.24s %8zu %12.1f %12.1f %12.1f %7.3f\n", res->name, res->point_count, res->average,
                   res->minimum, res->maximum, res->uniformity);
        }
        fflush(stdout);
    }
    if (r == RAD_OK)
        r = rad_output_set_commit(ctx, out->set);
    if (r != RAD_OK) {
        rad_illuminance_destroy(il);
        return fail(ctx, r);
    }
    rad_illuminance_stats st;
    rad_illuminance_get_stats(il, &st);
    for (int k = 0; k < 2 && !s->quiet; k++) { /* the plans, by name */
        const char *given = k ? s->output2 : s->output, *dot = given ? strrchr(given, '.') : NULL;
        for (size_t g = 0; dot && strcasecmp(dot, ".png") == 0 && g < rad_illuminance_grid_count(il); g++) {
            char name[PATH_MAX];
            if (rad_illuminance_grid(il, g)->point_count &&
                rad_illuminance_plot_path(il, given, g, name, sizeof name) < sizeof name)
                printf("wrote %s\n", name);
        }
    }
    rad_illuminance_destroy(il);
    char full[PATH_MAX];
    /* The value files by name (the plans were named above). */
    const char *files[2] = {NULL, NULL};
    int nfiles = 0;
    for (int k = 0; k < 2; k++) {
        const char *given = k ? s->output2 : s->output, *dot = given ? strrchr(given, '.') : NULL;
        if (given && !(dot && strcasecmp(dot, ".png") == 0))
            files[nfiles++] = k ? given : where(given, full);
    }
    if (!s->quiet)
        printf("wrote %s%s%s (%zu points in %.2f s, %.0f points/s; %zu elements, %.1f s)\n",
               nfiles ? files[0] : "the plans", nfiles > 1 ? " and " : "", nfiles > 1 ? files[1] : "", st.points,
               st.seconds, st.points_per_second, rad_solution_element_count(sol), now_seconds() - t0);
    return cancel_signal ? interrupted_status() : 0;
}

/* ---- view factors: what the thermal flags ask of the file, and what it took ---- */

typedef struct factor_report {
    rad_smooth_report smoothing; /* row_error_before stays negative when no smoothing ran */
    size_t nonzeros;
    double dropped;
} factor_report;

static rad_view_factor_options factor_options(const settings *s, factor_report *rep)
{
    memset(rep, 0, sizeof *rep);
    rep->smoothing.row_error_before = -1.0;
    rad_view_factor_options vo = {0};
    vo.elements = s->element_level != 0;
    vo.smooth = (rad_smoothing)s->smooth;
    vo.sparse_threshold = s->sparse_threshold;
    vo.report = &rep->smoothing;
    vo.nonzeros = &rep->nonzeros;
    vo.dropped = &rep->dropped;
    return vo;
}

static void print_factor_report(const settings *s, const factor_report *rep)
{
    const rad_smooth_report *m = &rep->smoothing;
    if (s->quiet)
        return;
    if (m->row_error_before >= 0.0)
        printf("smoothing: max |row sum - target| %.3g -> %.3g, max reciprocity error %.3g -> %.3g, "
               "change max %.3g rms %.3g (relative)%s\n",
               m->row_error_before, m->row_error_after, m->reciprocity_before, m->reciprocity_after,
               m->max_relative_change, m->rms_relative_change, m->clamped ? ", some factors held at 0" : "");
    if (s->sparse_threshold > 0.0)
        printf("sparse: %zu non-zeros, at most %.3g of a row's factors dropped and rebalanced\n", rep->nonzeros,
               rep->dropped);
}

/* ---- view factors in row blocks (rad_scene_stream_view_factors) ---- */

/* Rank 0 (or the only process): stream when asked (--block-rows, several
 * ranks) or when the dense matrix would pass the memory limit.  Returns
 * -1 when the dense route is to be taken, else the exit status. */
static int stream_view_factors(rad_context *ctx, const settings *s, const rad_scene *scene, run_outputs *out,
                               progress_state *progress, const rad_stream_ranks *ranks, double t0)
{
    bool forced = s->block_rows > 0 || ranks->size > 1;
    if (!forced && s->stats)
        return -1; /* the stats file describes a solution: the dense route */
    if (forced && s->stats) {
        fprintf(stderr, "radiosity: --stats: view factors in row blocks (--block-rows, mpirun) write no stats "
                        "file; their diagnostics are printed\n");
        return EXIT_USAGE;
    }
    factor_report rep;
    rad_view_factor_options vo = factor_options(s, &rep);
    rad_stream_options so = {s->block_rows, s->element_level, !forced, ranks->size > 1 ? ranks : NULL, &vo};
    rad_stream_stats st;
    rad_result r = rad_scene_stream_view_factors(ctx, scene, &s->solve, &so, out->main, &st);
    progress_end(progress);
    if (r == RAD_OK && !st.streamed)
        return -1;
    if (r == RAD_ERROR_INTERRUPTED) {
        fprintf(stderr, "radiosity: interrupted while computing form factors; nothing written\n");
        return interrupted_status();
    }
    begin_saving(ctx);
    if (r == RAD_OK)
        r = rad_output_set_commit(ctx, out->set);
    if (r != RAD_OK)
        return fail(ctx, r);
    print_factor_report(s, &rep);
    char full[PATH_MAX];
    if (!s->quiet)
        printf("wrote %s (%zu surfaces, %zu elements in %zu block%s of %zu rows on %d process%s; row sums "
               "%.6g to %.6g, reciprocity %.2g; %.1f s)\n",
               where(s->output, full), rad_scene_surface_count(scene), st.elements, st.blocks, st.blocks == 1 ? "" : "s", st.block_rows,
               ranks->size, ranks->size == 1 ? "" : "es", st.row_sum_min, st.row_sum_max, st.reciprocity_max,
               now_seconds() - t0);
    return cancel_signal ? interrupted_status() : 0;
}

/* The scene file, or the built-in Cornell box, with what the flags add to
 * it (--daylight).  On failure *scene is NULL, the message in ctx. */
static rad_result load_scene(rad_context *ctx, const settings *s, rad_scene **scene)
{
    rad_result r = s->scene_path ? rad_scene_load_file(ctx, s->scene_path, scene)
                                 : rad_scene_create_cornell_box(ctx, scene);
    if (r == RAD_OK && s->daylight && (r = rad_scene_daylight_load_file(ctx, *scene, s->daylight)) != RAD_OK) {
        rad_scene_destroy(*scene);
        *scene = NULL;
    }
    return r;
}

/* Ranks above 0: load the scene, make their blocks, send them to rank 0. */
static int stream_rank(rad_context *ctx, const settings *s, const rad_stream_ranks *ranks)
{
    rad_scene *scene = NULL;
    rad_result r = load_scene(ctx, s, &scene);
    rad_stream_options so = {s->block_rows, s->element_level, 0, ranks, NULL};
    rad_stream_stats st;
    if (r == RAD_OK)
        r = rad_scene_stream_view_factors(ctx, scene, &s->solve, &so, NULL, &st);
    rad_scene_destroy(scene);
    if (r == RAD_ERROR_INTERRUPTED)
        return interrupted_status();
    return r == RAD_OK ? 0 : fail(ctx, r);
}

/* photometry FILE...: each file's summary (radiosity.h, "Photometric
 * files"); a file that cannot be read is named on stderr and the rest are
 * still read; the status is 1 if any failed. */
static int run_photometry(rad_context *ctx, const settings *s)
{
    int status = 0;
    for (size_t k = 0; k < s->photometry_file_count; k++) {
        const char *path = s->photometry_files[k];
        rad_photometry_info in;
        rad_result r = rad_photometry_info_read(ctx, path, &in);
        if (r != RAD_OK) {
            status = fail(ctx, r);
            continue;
        }
        static const char *const types[] = {"?", "C", "B", "A"};
        printf("%s: %s%s%s, type %s%s%s%s\n", path, in.format, strcmp(in.format, in.version) ? " " : "",
               strcmp(in.format, in.version) ? in.version : "", types[in.type >= 1 && in.type <= 3 ? in.type : 0],
               in.label[0] ? ", \"" : "", in.label, in.label[0] ? "\"" : "");
        printf("  symmetry      %s\n", in.symmetry);
        printf("  angles        %zu %s from %g to %g, %zu %s from %g to %g (degrees)\n", in.vertical_count,
               in.format[0] == 'E' ? "gamma" : "vertical", in.vertical_min, in.vertical_max, in.horizontal_count,
               in.format[0] == 'E' ? "C" : "horizontal", in.horizontal_min, in.horizontal_max);
        printf("  maximum       %.6g cd at C %g, gamma %g\n", in.max_candela, in.max_c, in.max_gamma);
        printf("  flux          %.6g lm\n", in.flux);
        if (in.rated_lumens > 0.0)
            printf("  rated lumens  %.6g lm, light output ratio %.4f\n", in.rated_lumens, in.lor);
        else
            printf("  rated lumens  none (absolute photometry)\n");
        if (in.stated_lor >= 0.0)
            printf("  stated LOR    %.4f\n", in.stated_lor);
        printf("  opening       %s, %g x %g x %g m (length x width x height)\n", in.shape, in.length, in.width,
               in.height);
        if (in.tilt_count)
            printf("  tilt          %s, %zu angles\n", in.tilt, in.tilt_count);
        else
            printf("  tilt          none\n");
        if (in.input_watts > 0.0)
            printf("  input         %.6g W\n", in.input_watts);
    }
    return status;
}

/* The false colour options of render's flags (--false-colour, --scale,
 * --range, --contours), checked by the library before any work; returns
 * -1 when good, else the exit status (the message printed). */
static int false_colour_options(rad_context *ctx, const settings *s, rad_false_colour_options *fo)
{
    memset(fo, 0, sizeof *fo);
    if (s->command == CLI_ILLUMINANCE) {
        /* The grids' plans: an output ending in .png. */
        bool png = false;
        for (int k = 0; k < 2; k++) {
            const char *o = k ? s->output2 : s->output, *dot = o ? strrchr(o, '.') : NULL;
            png = png || (dot && strcasecmp(dot, ".png") == 0);
        }
        if ((s->log_scale || s->range) && !png) {
            fprintf(stderr, "radiosity: --%s: only for the grids' plans, an output ending in .png (see radiosity "
                            "illuminance --help)\n", s->range ? "range" : "scale");
            return EXIT_USAGE;
        }
    } else if (!s->false_colour) {
        if (s->log_scale || s->range || s->contours) {
            fprintf(stderr, "radiosity: --%s: only with --false-colour luminance|illuminance (see radiosity "
                            "render --help)\n", s->range ? "range" : s->contours ? "contours" : "scale");
            return EXIT_USAGE;
        }
        return -1;
    }
    fo->quantity = s->command == CLI_ILLUMINANCE ? RAD_FALSE_COLOUR_ILLUMINANCE
                                                 : (rad_false_colour_quantity)s->false_colour;
    fo->log_scale = s->log_scale;
    fo->contours = s->contours;
    if (s->range) {
        char *end = NULL;
        fo->range_min = strtod(s->range, &end);
        bool good = end != s->range && *end == ':';
        if (good) {
            const char *max = end + 1;
            fo->range_max = strtod(max, &end);
            good = end != max && *end == '\0';
        }
        if (!good) {
            fprintf(stderr, "radiosity: --range: expected MIN:MAX (two numbers), got '%s'\n", s->range);
            return EXIT_USAGE;
        }
        if (fo->range_min == 0.0 && fo->range_max == 0.0) {
            fprintf(stderr, "radiosity: --range: 0:0 is empty; leave --range out for the automatic range\n");
            return EXIT_USAGE;
        }
    }
    char ext[8];
    const char *dot = strrchr(s->output, '.');
    snprintf(ext, sizeof ext, "%s", dot ? dot + 1 : "");
    for (char *c = ext; *c; c++)
        *c = (char)tolower((unsigned char)*c);
    if (s->command != CLI_ILLUMINANCE && strcmp(ext, "png") != 0) {
        fprintf(stderr, "radiosity: --false-colour writes PNG: the output must end in .png, got %s\n", s->output);
        return EXIT_USAGE;
    }
    if (rad_false_colour_check(ctx, fo) != RAD_OK) {
        fprintf(stderr, "radiosity: --%s\n", rad_context_error(ctx));
        return EXIT_USAGE;
    }
    return -1;
}

static int run(int argc, char **argv, const rad_stream_ranks *ranks)
{
    /* Every command's flags come from the one table in options.c;
     * generate runs in generate.c, render, solve, viewfactors and export below. */
    settings s;
    memset(&s, 0, sizeof s);
    int status = parse_args(argc, argv, &s);
    if (status >= 0)
        return status;
    if (s.command == CLI_THERMAL && !s.bc) {
        fprintf(stderr, "radiosity: thermal needs --bc FILE.json: the surfaces' emissivities and temperatures or "
                        "heat fluxes (see radiosity thermal --help)\n");
        return EXIT_USAGE;
    }
    if (s.command == CLI_ILLUMINANCE && !s.grid) {
        fprintf(stderr, "radiosity: illuminance needs --grid FILE.json: the calculation grids and points (see "
                        "radiosity illuminance --help)\n");
        return EXIT_USAGE;
    }
    if (s.command == CLI_THERMAL &&
        !(rad_method_capabilities(RAD_METHOD_SOLVER, s.solve.solver) & RAD_HAS_FORM_FACTORS)) {
        fprintf(stderr, "radiosity: --solver %s keeps no form-factor matrix: thermal takes direct, gauss-seidel, "
                        "jacobi, southwell or conjugate-gradient (see radiosity thermal --help)\n", s.solve.solver);
        return EXIT_USAGE;
    }
    if (ranks->size > 1 && s.command != CLI_VIEWFACTORS) {
        if (ranks->rank == 0)
            fprintf(stderr, "radiosity: under mpirun only `radiosity viewfactors` spreads its work over the "
                            "ranks (docs/performance.md); run %s as one process\n", cli_command_name(s.command));
        return EXIT_USAGE;
    }
    if (ranks->rank > 0)
        s.quiet = 1; /* rank 0 speaks for the job */
    install_signal_handlers();

    progress_state progress = {0};
    rad_context_options co = {0};
    co.threads = s.command == CLI_GENERATE ? 1 : s.threads;
    /* --max-memory limits everything the engine allocates, loading included. */
    co.max_memory_bytes = s.solve.max_memory_bytes;
    co.read_outside_scene_folder = s.read_outside != 0;
    co.missing_textures_flat = s.missing_textures != 0;
    co.on_warning = print_warning;
    if (!s.quiet && isatty(STDERR_FILENO) && s.command != CLI_GENERATE) {
        co.progress = progress_bar;
        co.progress_user = &progress;
    }
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK) {
        fprintf(stderr, "radiosity: cannot create a context\n");
        return 1;
    }
    cancel_context = ctx;
    if (ranks->rank > 0) {
        status = stream_rank(ctx, &s, ranks);
        cancel_context = NULL;
        rad_context_destroy(ctx);
        return status;
    }
    if (s.command == CLI_GENERATE) {
        status = cli_generate(&s, ctx);
        cancel_context = NULL;
        rad_context_destroy(ctx);
        return cancel_signal ? interrupted_status() : status;
    }

    if (s.command == CLI_PHOTOMETRY) {
        status = run_photometry(ctx, &s);
        cancel_context = NULL;
        rad_context_destroy(ctx);
        return cancel_signal ? interrupted_status() : status;
    }

    if (s.command == CLI_VIEW) {
        status = run_view(ctx, &s);
        cancel_context = NULL;
        rad_context_destroy(ctx);
        return cancel_signal ? interrupted_status() : status;
    }

    const char *output = s.output; /* the parser gives the command's default */
    rad_camera camera;
    rad_scene *scene = NULL;
    rad_solution *sol = NULL;
    rad_image *image = NULL;
    rad_thermal_conditions *bc = NULL;
    run_outputs out = {0};
    rad_result r = RAD_OK;

    /* 0. every output path checked before any work */
    status = plan_outputs(ctx, &s, &out);
    if (status >= 0)
        goto done;
    rad_false_colour_options false_colour;
    status = false_colour_options(ctx, &s, &false_colour);
    if (status >= 0)
        goto done;
    status = 1;

    /* View-factor adjustments that cannot apply are refused before the work. */
    if (s.command == CLI_VIEWFACTORS) {
        const char *dot = strrchr(output, '.');
        bool vf = dot && strcmp(dot, ".vf") == 0, mtx = dot && strcmp(dot, ".mtx") == 0;
        if (s.element_level && (s.smooth || s.sparse_threshold > 0.0 || vf)) {
            fprintf(stderr, "radiosity: --level element: element factors are written as computed; --smooth, "
                            "--sparse-threshold and .vf files are for surface-level factors\n");
            status = EXIT_USAGE;
            goto done;
        }
        if (s.sparse_threshold > 0.0 && !mtx) {
            fprintf(stderr, "radiosity: --sparse-threshold: the output must be Matrix Market (-o F.mtx)\n");
            status = EXIT_USAGE;
            goto done;
        }
    }

    /* 1. load: a scene, or for render and export a solution file (by its
     * signature), which is solved already */
    double t0 = now_seconds();
    bool saved = s.scene_path && rad_file_is_solution(s.scene_path);
    if (saved && s.command != CLI_RENDER && s.command != CLI_EXPORT && s.command != CLI_BAKE &&
        s.command != CLI_ILLUMINANCE) {
        fprintf(stderr, "radiosity: %s is a solution file: `radiosity render` draws it and `radiosity "
                        "export` writes its lit mesh; %s needs the scene it was solved for\n",
                s.scene_path, cli_command_name(s.command));
        status = EXIT_USAGE;
        goto done;
    }
    if (saved && (s.history || s.progress_dir)) {
        fprintf(stderr, "radiosity: --%s: %s is a solution file, solved already: there is no solve to "
                        "follow\n", s.history ? "history" : "progress-images", s.scene_path);
        status = EXIT_USAGE;
        goto done;
    }
    if (saved && s.daylight) {
        fprintf(stderr, "radiosity: --daylight: %s is a solution file, solved already with its own light\n",
                s.scene_path);
        status = EXIT_USAGE;
        goto done;
    }
    if (saved)
        r = rad_solution_load_file(ctx, s.scene_path, &scene, &sol);
    else
        r = load_scene(ctx, &s, &scene);
    if (r != RAD_OK) {
        status = fail(ctx, r);
        goto done;
    }
    if (s.luminaires && saved) {
        fprintf(stderr, "radiosity: --luminaires: %s is a solution file, solved already (give the layout with "
                        "the scene)\n", s.scene_path);
        status = EXIT_USAGE;
        goto done;
    }
    if (s.luminaires) {
        /* Luminaires placed by the layout (docs/lighting.md), before any work. */
        r = rad_scene_load_luminaires(ctx, scene, s.luminaires);
        if (r == RAD_OK)
            r = rad_output_set_add_input(ctx, out.set, s.luminaires);
        if (r != RAD_OK) {
            status = fail(ctx, r);
            goto done;
        }
    }
    status = check_scene_inputs(ctx, scene, &out);
    if (status >= 0)
        goto done;
    status = 1;
    if (s.command == CLI_ILLUMINANCE && rad_illuminance_check_file(ctx, scene, s.grid, NULL) != RAD_OK) {
        status = fail(ctx, RAD_ERROR_PARSE); /* a bad grid file: before any work */
        goto done;
    }
    if (s.command == CLI_THERMAL && rad_thermal_conditions_load_file(ctx, scene, s.bc, &bc) != RAD_OK) {
        status = fail(ctx, RAD_ERROR_PARSE); /* a bad file: before any work */
        goto done;
    }
    if (s.camera) {
        /* The library owns the camera syntax (docs/cli.md).  Its messages
         * begin "camera: "; with "--" before them they name our flag. */
        r = rad_camera_from_string(ctx, s.camera, &camera);
        if (r != RAD_OK) {
            fprintf(stderr, "radiosity: --%s (see radiosity render --help)\n", rad_context_error(ctx));
            status = EXIT_USAGE;
            goto done;
        }
        s.render.camera = &camera;
    }
    /* A camera too far from the scene to draw it is refused now, not after
     * the solve (the automatic one frames the scene). */
    rad_camera chosen;
    if (s.command == CLI_RENDER && (s.camera ? (chosen = camera, true) : rad_scene_camera(scene, &chosen)) &&
        rad_scene_check_camera(ctx, scene, &chosen) != RAD_OK) {
        fprintf(stderr, "radiosity: %s%s\n", s.camera ? "--" : "", rad_context_error(ctx));
        status = s.camera ? EXIT_USAGE : 1;
        goto done;
    }
    if (s.command != CLI_VIEWFACTORS && s.command != CLI_THERMAL && !s.quiet && !s.scene_path)
        printf("radiosity: no scene given, %s the built-in Cornell box\n",
               s.command == CLI_EXPORT        ? "exporting"
               : s.command == CLI_BAKE        ? "baking"
               : s.command == CLI_ILLUMINANCE ? "lighting"
                                              : "rendering");

    /* Progressive display keeps one exposure for all frames (the user's, or
     * the first frame's automatic one), so the picture visibly brightens as
     * light is shot; with the ambient term the first frame is already close
     * to the final brightness.  Each frame is its own atomic file, written
     * during the solve (not part of the output set). */
    progressive prog = {ctx, s.progress_dir, s.every ? s.every : 1, &s.render, s.render.exposure, 0};
    if (s.progress_dir) {
        if (mkdir(s.progress_dir, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "radiosity: %s: cannot create directory: %s\n", s.progress_dir, strerror(errno));
            goto done;
        }
        s.solve.on_step = on_step;
        s.solve.on_step_user = &prog;
    }

    /* 2-3'. view factors too large for the dense matrix, or asked in row
     * blocks: mesh and stream them (no solution) */
    if (s.command == CLI_VIEWFACTORS) {
        status = stream_view_factors(ctx, &s, scene, &out, &progress, ranks, t0);
        if (status >= 0)
            goto done;
        status = 1;
    }

    /* 2-3. mesh, visibility, form factors (a loaded solution has them) */
    r = saved ? RAD_OK : rad_solution_create(ctx, scene, &s.solve, &sol);
    progress_end(&progress);
    if (r == RAD_ERROR_INTERRUPTED) {
        /* No radiosity yet, so no image: only the stats say what happened. */
        begin_saving(ctx);
        rad_output_set_drop(out.set, output);
        rad_output_set_drop(out.set, s.history);
        int wrote = s.stats &&
                    rad_scene_write_interrupted_stats(ctx, scene, "form factors", now_seconds() - t0,
                                                      out.stats) == RAD_OK &&
                    rad_output_set_commit(ctx, out.set) == RAD_OK;
        fprintf(stderr, "radiosity: interrupted while computing form factors; %s\n",
                wrote ? "wrote partial stats only" : "nothing written");
        status = interrupted_status();
        goto done;
    }
    if (r != RAD_OK) {
        status = fail(ctx, r);
        goto done;
    }

    if (s.command == CLI_THERMAL) {
        /* 4-5. the net-radiation solve on F, its figures */
        status = run_thermal(ctx, &s, scene, sol, bc, &out, &progress, t0);
        goto done;
    }

    if (s.command == CLI_VIEWFACTORS) {
        /* 5. view factors */
        begin_saving(ctx);
        factor_report rep;
        rad_view_factor_options vo = factor_options(&s, &rep);
        r = rad_solution_write_view_factors_with(ctx, sol, out.main, &vo);
        if (r == RAD_OK)
            print_factor_report(&s, &rep);
        if (r == RAD_OK && s.stats)
            r = rad_solution_write_stats(ctx, sol, out.stats, 0);
        if (r == RAD_OK)
            r = rad_output_set_commit(ctx, out.set);
        if (r != RAD_OK) {
            status = fail(ctx, r);
            goto done;
        }
        char full[PATH_MAX];
        if (!s.quiet)
            printf("wrote %s (%zu surfaces, %zu elements, %.2f s)\n", where(output, full),
                   rad_scene_surface_count(scene), rad_solution_element_count(sol),
                   now_seconds() - t0);
        status = cancel_signal ? interrupted_status() : 0;
        goto done;
    }

    /* 4. solve (a loaded solution is solved) */
    r = saved ? RAD_OK : rad_solution_solve(ctx, sol);
    progress_end(&progress);
    if (prog.failed) {
        status = fail(ctx, RAD_ERROR_IO);
        goto done;
    }
    int partial = r == RAD_ERROR_INTERRUPTED;
    if (r != RAD_OK && !partial) {
        status = fail(ctx, r);
        goto done;
    }
    if (partial)
        fprintf(stderr, "radiosity: interrupted while solving; writing the partial solution\n");
    else if (!s.quiet && !rad_solution_converged(sol)) {
        /* Every solver stops at its bound; the line says where and why. */
        char line[1024];
        const char *why = rad_solution_warning(sol);
        if (why[0])
            fprintf(stderr, "radiosity: warning: %s\n", cli_rewrite_message(why, line, sizeof line));
        else
            fprintf(stderr, "radiosity: warning: stopped unconverged after %d iterations\n",
                    rad_solution_iterations(sol));
    }

    if (s.command == CLI_SOLVE) {
        status = write_solution(ctx, &s, sol, &out, partial, t0);
        goto done;
    }

    if (s.command == CLI_ILLUMINANCE) {
        /* 5'. illuminance at the calculation points */
        if (partial) {
            fprintf(stderr, "radiosity: interrupted while solving; no illuminance written\n");
            status = interrupted_status();
        } else {
            status = run_illuminance(ctx, &s, sol, &out, &progress, t0, &false_colour);
        }
        goto done;
    }

    /* 5. image or lit mesh, stats and history, into their temporaries,
     * then all put in place together.  Signals from here on are noted, not
     * acted upon. */
    begin_saving(ctx);
    rad_bake_stats baked = {0};
    if (s.command == CLI_EXPORT) {
        r = rad_solution_write_mesh(ctx, sol, out.main, s.render.exposure);
    } else if (s.command == CLI_BAKE) {
        rad_bake_options bo = {s.texels_per_metre, s.atlas_size, (rad_lightmap_quantity)s.lightmap_quantity,
                               s.render.exposure};
        r = rad_solution_bake(ctx, sol, &bo, out.set, output, &baked);
    } else if (s.false_colour) {
        r = rad_solution_write_false_colour(ctx, sol, &s.render, &false_colour, out.main);
        progress_end(&progress);
    } else {
        r = rad_solution_render(ctx, sol, &s.render, &image);
        progress_end(&progress);
        if (r == RAD_OK)
            r = rad_image_write_exposed(ctx, image, out.main, s.render.exposure);
    }
    if (r == RAD_OK && s.stats)
        r = rad_solution_write_stats(ctx, sol, out.stats, partial);
    if (r == RAD_OK && s.history)
        r = rad_solution_write_history(ctx, sol, out.history);
    if (r == RAD_OK) {
        fflush(stdout); /* what we printed comes before an output sent to stdout */
        r = rad_output_set_commit(ctx, out.set);
    }
    if (r != RAD_OK) {
        status = fail(ctx, r);
        goto done;
    }
    char full[PATH_MAX];
    if (!s.quiet) {
        /* Matrix-free solvers measure unshot power, not the residual. */
        size_t steps = 0;
        const rad_solve_step *h = rad_solution_history(sol, &steps);
        double residual = rad_solution_residual(sol);
        char measure[64];
        if (isnan(residual) && steps > 0)
            snprintf(measure, sizeof measure, "unshot %.2g", h[steps - 1].unshot);
        else
            snprintf(measure, sizeof measure, "residual %.2g", residual);
        if (s.command == CLI_BAKE)
            printf("wrote %s and %zu lightmap%s (fill %.1f%%, baked in %.2f s; %zu elements, %s, %.1f s)%s\n",
                   where(output, full), baked.atlases, baked.atlases == 1 ? "" : "s",
                   100.0 * baked.chart_texels / baked.atlas_texels, baked.seconds, rad_solution_element_count(sol),
                   measure, now_seconds() - t0, partial ? " [partial]" : "");
        else if (s.command == CLI_EXPORT)
            printf("wrote %s (%zu vertices, %zu elements, %s, %.1f s)%s\n", where(output, full),
                   rad_solution_vertex_count(sol), rad_solution_element_count(sol), measure,
                   now_seconds() - t0, partial ? " [partial]" : "");
        else
            printf("wrote %s (%dx%d, %zu elements, %s, %.1f s)%s\n", where(output, full),
                   image ? rad_image_width(image) : s.render.width ? s.render.width : 512,
                   image ? rad_image_height(image) : s.render.height ? s.render.height : 512,
                   rad_solution_element_count(sol),
                   measure, now_seconds() - t0, partial ? " [partial]" : "");
        size_t lights = rad_scene_luminaire_count(scene);
        if (lights > 0) {
            double lumens = 0.0;
            for (size_t k = 0; k < lights; k++)
                lumens += rad_scene_luminaire_flux(scene, k);
            printf("luminaires: %zu, %.6g lm; %.6g lm of direct light lands on the surfaces\n", lights, lumens,
                   rad_solution_direct_lumens(sol));
        }
    }
    if (cancel_signal && !partial)
        fprintf(stderr, "radiosity: interrupted while writing the outputs; they were completed first\n");
    status = cancel_signal ? interrupted_status() : 0;

done:
    rad_thermal_conditions_destroy(bc);
    rad_output_set_destroy(out.set);
    rad_image_destroy(image);
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    cancel_context = NULL;
    rad_context_destroy(ctx);
    return status;
}

int main(int argc, char **argv)
{
    rad_stream_ranks ranks = {0, 1, NULL, NULL, NULL};
#ifdef RADIOSITY_MPI
    if (cli_mpi_start(&argc, &argv, &ranks) < 0) {
        fprintf(stderr, "radiosity: MPI did not start\n");
        return 1;
    }
#endif
    int status = run(argc, argv, &ranks);
#ifdef RADIOSITY_MPI
    cli_mpi_stop(status);
#endif
    return status;
}
