/*
 * main.c -- the `radiosity` command.  Each command walks the pipeline:
 *
 *   0. outputs   every path checked, one output set           plan_outputs
 *   1. load      the scene file, or the built-in Cornell box   cli_load
 *   2. mesh      surfaces -> elements            }             cli_couple: rad_solution_create
 *   3. couple    visibility + form factors F_ij  }
 *   4. solve     B = E + rho F B                               cli_solve: rad_solution_solve
 *   5. output    image / view factors / lit mesh / stats       the command's own (cmd_*.c),
 *                                                              put in place by cli_commit
 *
 * As in Redis's command table, a row per command gives its name, its
 * function and flags that say what the shared code does for it; run()
 * does only what every command shares (the context, signals, progress,
 * the outputs planned) and dispatches.  The stages are here, one comment
 * each; what a command adds between them (a camera, a grid file, the
 * thermal conditions) is in its own file.
 *
 * Flags live in one table (options.c), shared by every command, which
 * takes each flag's range, default and help from the library's option
 * table; --help and the man page are printed from it, so none can drift.  Exit
 * status: 0 ok, 1 failure, 2 usage error, 130 / 143 when interrupted by
 * SIGINT / SIGTERM (partial outputs are written and marked as such).
 */
#include "cli.h"
#include "options.h"
#include "radiosity.h"
#ifdef RADIOSITY_MPI
#include "mpi_ranks.h"
#endif

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The commands, by the name the parser recognised (options.c); every
 * command there has its row here. */
static const cli_command cli_commands[] = {
    {"render", CMD_OUTPUT_SET | CMD_SOLUTION_INPUT, RAD_OUTPUT_IMAGE, NULL, cmd_render},
    {"solve", CMD_OUTPUT_SET, RAD_OUTPUT_SOLUTION, NULL, cmd_solve},
    {"export", CMD_OUTPUT_SET | CMD_SOLUTION_INPUT, RAD_OUTPUT_MESH, NULL, cmd_export},
    {"bake", CMD_OUTPUT_SET | CMD_SOLUTION_INPUT, RAD_OUTPUT_BAKE, NULL, cmd_bake},
    {"illuminance", CMD_OUTPUT_SET | CMD_SOLUTION_INPUT, RAD_OUTPUT_ILLUMINANCE, cmd_illuminance_check,
     cmd_illuminance},
    {"viewfactors", CMD_OUTPUT_SET | CMD_MPI, RAD_OUTPUT_VIEW_FACTORS, NULL, cmd_viewfactors},
    {"thermal", CMD_OUTPUT_SET, RAD_OUTPUT_THERMAL, cmd_thermal_check, cmd_thermal},
    {"view", 0, RAD_OUTPUT_FILE, NULL, cmd_view},
    {"photometry", 0, RAD_OUTPUT_FILE, NULL, cmd_photometry},
    {"generate", CMD_SERIAL, RAD_OUTPUT_FILE, NULL, cmd_generate},
};

static const cli_command *find_command(const char *name)
{
    for (size_t k = 0; k < sizeof cli_commands / sizeof cli_commands[0]; k++)
        if (strcmp(cli_commands[k].name, name) == 0)
            return &cli_commands[k];
    return NULL;
}

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

/* Parse the command line (options.c), find the command's row and carry
 * out --help, --version, --list-methods, --man and usage errors, the
 * row's own check among them.  Returns -1 to go on, else an exit status. */
static int parse_args(int argc, char **argv, cli_settings *s, const cli_command **command)
{
    char err[1024];
    cli_action action = cli_parse_args(argc, argv, s, err, sizeof err);
    if (action == CLI_RUN) {
        *command = find_command(cli_command_name(s->command));
        if (!*command)
            snprintf(err, sizeof err, "%s has no row in the command table", cli_command_name(s->command));
        if (!*command || ((*command)->check && (*command)->check(s, err, sizeof err)))
            action = CLI_USAGE_ERROR;
    }
    switch (action) {
    case CLI_RUN: return -1;
    case CLI_HELP: cli_print_help(stdout, s->command); return 0;
    case CLI_VERSION: printf("radiosity %s\n", RAD_VERSION_STRING); return 0;
    case CLI_LIST_METHODS: list_methods(); return 0;
    case CLI_MAN: cli_print_man(stdout); return 0;
    case CLI_NO_ARGUMENTS: cli_print_help(stderr, 0); return EXIT_USAGE;
    case CLI_USAGE_ERROR: break;
    }
    const char *name = cli_command_name(s->command);
    fprintf(stderr, "radiosity: %s (see radiosity %s%s--help)\n", err, name, name[0] ? " " : "");
    return EXIT_USAGE;
}

/* Plan the outputs (job->out) and name the scene file as an input.
 * Returns -1 to go on, else an exit status: 2 when a path is refused as
 * an argument (an alias, an unknown format), 1 when it cannot be
 * written. */
static int plan_outputs(cli_job *job)
{
    const cli_settings *s = &job->s;
    rad_context *ctx = job->ctx;
    cli_outputs *o = &job->out;
    rad_result r = rad_output_set_create(ctx, &o->set);
    if (r == RAD_OK && s->scene_path)
        r = rad_output_set_add_input(ctx, o->set, s->scene_path);
    if (r == RAD_OK && s->bc)
        r = rad_output_set_add_input(ctx, o->set, s->bc);
    if (r == RAD_OK)
        r = rad_output_set_add(ctx, o->set, s->output, job->command->output, &o->main);
    if (r == RAD_OK && s->gebhart)
        r = rad_output_set_add(ctx, o->set, s->gebhart, RAD_OUTPUT_THERMAL, &o->gebhart);
    if (r == RAD_OK && s->grid)
        r = rad_output_set_add_input(ctx, o->set, s->grid);
    if (r == RAD_OK && s->output2)
        r = rad_output_set_add(ctx, o->set, s->output2, RAD_OUTPUT_ILLUMINANCE, &o->second);
    /* bake: the first atlas's lightmaps (there is always one); others are
     * added when the packing knows them. */
    static const char *const lightmap_ext[2] = {"hdr", "png"};
    for (int k = 0; k < 2 && r == RAD_OK && job->command->output == RAD_OUTPUT_BAKE; k++) {
        char name[PATH_MAX];
        const char *temp;
        if (rad_bake_image_path(s->output, 0, lightmap_ext[k], name, sizeof name) >= sizeof name)
            r = RAD_ERROR_INVALID_ARGUMENT;
        else
            r = rad_output_set_add(ctx, o->set, name, RAD_OUTPUT_IMAGE, &temp);
    }
    if (r == RAD_OK && s->stats)
        r = rad_output_set_add(ctx, o->set, s->stats, RAD_OUTPUT_FILE, &o->stats);
    if (r == RAD_OK && s->history)
        r = rad_output_set_add(ctx, o->set, s->history, RAD_OUTPUT_FILE, &o->history);
    return r == RAD_OK ? -1 : cli_fail_path(ctx, r);
}

rad_result cli_read_scene(rad_context *ctx, const cli_settings *s, rad_scene **scene)
{
    rad_result r = s->scene_path ? rad_scene_load_file(ctx, s->scene_path, scene)
                                 : rad_scene_create_cornell_box(ctx, scene);
    if (r == RAD_OK && s->daylight && (r = rad_scene_daylight_load_file(ctx, *scene, s->daylight)) != RAD_OK) {
        rad_scene_destroy(*scene);
        *scene = NULL;
    }
    return r;
}

/* 1. load: a scene, or for CMD_SOLUTION_INPUT commands a solution file (by
 * its signature), which is solved already */
int cli_load(cli_job *job)
{
    const cli_settings *s = &job->s;
    rad_context *ctx = job->ctx;
    job->t0 = cli_now();
    job->saved = s->scene_path && rad_file_is_solution(s->scene_path);
    if (job->saved && !(job->command->flags & CMD_SOLUTION_INPUT)) {
        fprintf(stderr, "radiosity: %s is a solution file: `radiosity render` draws it and `radiosity "
                        "export` writes its lit mesh; %s needs the scene it was solved for\n",
                s->scene_path, job->command->name);
        return EXIT_USAGE;
    }
    if (job->saved && (s->history || s->progress_dir)) {
        fprintf(stderr, "radiosity: --%s: %s is a solution file, solved already: there is no solve to "
                        "follow\n", s->history ? "history" : "progress-images", s->scene_path);
        return EXIT_USAGE;
    }
    if (job->saved && s->daylight) {
        fprintf(stderr, "radiosity: --daylight: %s is a solution file, solved already with its own light\n",
                s->scene_path);
        return EXIT_USAGE;
    }
    rad_result r = job->saved ? rad_solution_load_file(ctx, s->scene_path, &job->scene, &job->sol)
                              : cli_read_scene(ctx, s, &job->scene);
    if (r != RAD_OK)
        return cli_fail(ctx, r);
    if (s->luminaires && job->saved) {
        fprintf(stderr, "radiosity: --luminaires: %s is a solution file, solved already (give the layout with "
                        "the scene)\n", s->scene_path);
        return EXIT_USAGE;
    }
    if (s->luminaires) {
        /* Luminaires placed by the layout (docs/lighting.md), before any work. */
        r = rad_scene_load_luminaires(ctx, job->scene, s->luminaires);
        if (r == RAD_OK)
            r = rad_output_set_add_input(ctx, job->out.set, s->luminaires);
        if (r != RAD_OK)
            return cli_fail(ctx, r);
    }
    /* Every file the loader read is an input no output may be. */
    for (size_t i = 0; i < rad_scene_input_count(job->scene); i++) {
        r = rad_output_set_add_input(ctx, job->out.set, rad_scene_input_path(job->scene, i));
        if (r != RAD_OK)
            return cli_fail_path(ctx, r);
    }
    return -1;
}

/* 2-3. mesh, visibility, form factors (a loaded solution has them) */
int cli_couple(cli_job *job)
{
    const cli_settings *s = &job->s;
    rad_context *ctx = job->ctx;
    rad_result r = job->saved ? RAD_OK : rad_solution_create(ctx, job->scene, &s->solve, &job->sol);
    cli_progress_end(&job->progress);
    if (r == RAD_ERROR_INTERRUPTED) {
        /* No radiosity yet, so no image: only the stats say what happened. */
        cli_begin_saving(ctx);
        rad_output_set_drop(job->out.set, s->output);
        rad_output_set_drop(job->out.set, s->history);
        int wrote = s->stats &&
                    rad_scene_write_interrupted_stats(ctx, job->scene, "form factors", cli_now() - job->t0,
                                                      job->out.stats) == RAD_OK &&
                    rad_output_set_commit(ctx, job->out.set) == RAD_OK;
        fprintf(stderr, "radiosity: interrupted while computing form factors; %s\n",
                wrote ? "wrote partial stats only" : "nothing written");
        return cli_interrupted_status();
    }
    return r == RAD_OK ? -1 : cli_fail(ctx, r);
}

/* Progressive display keeps one exposure for all frames (the user's, or
 * the first frame's automatic one), so the picture visibly brightens as
 * light is shot; with the ambient term the first frame is already close
 * to the final brightness.  Each frame is its own atomic file, written
 * during the solve (not part of the output set). */
static int on_step(void *user, rad_solution *solution, const rad_solve_step *step)
{
    cli_job *job = user;
    if (step->iteration % (job->s.every ? job->s.every : 1) != 0)
        return 0;
    rad_image *image = NULL;
    char path[4096];
    snprintf(path, sizeof path, "%s/step_%08d.png", job->s.progress_dir, step->iteration);
    rad_result r = rad_solution_render(job->ctx, solution, &job->s.render, &image);
    if (r == RAD_ERROR_INTERRUPTED) {
        rad_image_destroy(image); /* the interrupted render still hands back its image */
        return 1; /* a signal: the solve stops and its iterate is saved, frame or not */
    }
    if (r == RAD_OK && job->frame_exposure == 0.0)
        job->frame_exposure = rad_image_auto_exposure(image); /* fixed from the first frame on */
    if (r == RAD_OK)
        r = rad_image_write_exposed(job->ctx, image, path, job->frame_exposure);
    rad_image_destroy(image);
    if (r != RAD_OK) {
        job->frame_failed = true;
        return 1; /* stop: the message is in the context */
    }
    return 0;
}

int cli_solve(cli_job *job, const char *verb)
{
    cli_settings *s = &job->s;
    rad_context *ctx = job->ctx;
    if (!s->quiet && !s->scene_path)
        printf("radiosity: no scene given, %s the built-in Cornell box\n", verb);
    if (s->progress_dir) {
        if (mkdir(s->progress_dir, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "radiosity: %s: cannot create directory: %s\n", s->progress_dir, strerror(errno));
            return 1;
        }
        job->frame_exposure = s->render.exposure;
        s->solve.on_step = on_step;
        s->solve.on_step_user = job;
    }
    int status = cli_couple(job);
    if (status >= 0)
        return status;

    /* 4. solve (a loaded solution is solved) */
    rad_result r = job->saved ? RAD_OK : rad_solution_solve(ctx, job->sol);
    cli_progress_end(&job->progress);
    if (job->frame_failed)
        return cli_fail(ctx, RAD_ERROR_IO);
    job->partial = r == RAD_ERROR_INTERRUPTED;
    if (r != RAD_OK && !job->partial)
        return cli_fail(ctx, r);
    if (job->partial)
        fprintf(stderr, "radiosity: interrupted while solving; writing the partial solution\n");
    else if (!s->quiet && !rad_solution_converged(job->sol)) {
        /* Every solver stops at its bound; the line says where and why. */
        char line[1024];
        const char *why = rad_solution_warning(job->sol);
        if (why[0])
            fprintf(stderr, "radiosity: warning: %s\n", cli_rewrite_message(why, line, sizeof line));
        else
            fprintf(stderr, "radiosity: warning: stopped unconverged after %d iterations\n",
                    rad_solution_iterations(job->sol));
    }
    return -1;
}

/* 5. the outputs: each command writes its own into its temporary, then
 * these put the set in place */

rad_result cli_write_records(cli_job *job, rad_result r)
{
    if (r == RAD_OK && job->s.stats)
        r = rad_solution_write_stats(job->ctx, job->sol, job->out.stats, job->partial);
    if (r == RAD_OK && job->s.history)
        r = rad_solution_write_history(job->ctx, job->sol, job->out.history);
    return r;
}

rad_result cli_commit(cli_job *job, rad_result r)
{
    if (r != RAD_OK)
        return r;
    fflush(stdout); /* what we printed comes before an output sent to stdout */
    return rad_output_set_commit(job->ctx, job->out.set);
}

int cli_finish(cli_job *job, rad_result r, const char *detail, ...)
{
    const cli_settings *s = &job->s;
    char what[512];
    va_list ap;
    va_start(ap, detail);
    vsnprintf(what, sizeof what, detail, ap);
    va_end(ap);
    r = cli_commit(job, cli_write_records(job, r));
    if (r != RAD_OK)
        return cli_fail(job->ctx, r);
    if (!s->quiet) {
        /* Matrix-free solvers measure unshot power, not the residual. */
        size_t steps = 0;
        const rad_solve_step *h = rad_solution_history(job->sol, &steps);
        double residual = rad_solution_residual(job->sol);
        char measure[64], full[PATH_MAX];
        if (isnan(residual) && steps > 0)
            snprintf(measure, sizeof measure, "unshot %.2g", h[steps - 1].unshot);
        else
            snprintf(measure, sizeof measure, "residual %.2g", residual);
        printf("wrote %s%s%zu elements, %s, %.1f s)%s\n", cli_where(s->output, full), what,
               rad_solution_element_count(job->sol), measure, cli_now() - job->t0,
               job->partial ? " [partial]" : "");
        size_t lights = rad_scene_luminaire_count(job->scene);
        if (lights > 0) {
            double lumens = 0.0;
            for (size_t k = 0; k < lights; k++)
                lumens += rad_scene_luminaire_flux(job->scene, k);
            printf("luminaires: %zu, %.6g lm; %.6g lm of direct light lands on the surfaces\n", lights, lumens,
                   rad_solution_direct_lumens(job->sol));
        }
    }
    if (cli_interrupted() && !job->partial)
        fprintf(stderr, "radiosity: interrupted while writing the outputs; they were completed first\n");
    return cli_status(0);
}

static int run(int argc, char **argv, const rad_stream_ranks *ranks)
{
    cli_job job;
    memset(&job, 0, sizeof job);
    const cli_command *command = NULL;
    int status = parse_args(argc, argv, &job.s, &command);
    if (status >= 0)
        return status;
    if (ranks->size > 1 && !(command->flags & CMD_MPI)) {
        if (ranks->rank == 0)
            fprintf(stderr, "radiosity: under mpirun only `radiosity viewfactors` spreads its work over the "
                            "ranks (docs/performance.md); run %s as one process\n", command->name);
        return EXIT_USAGE;
    }
    if (ranks->rank > 0)
        job.s.quiet = 1; /* rank 0 speaks for the job */
    cli_signals_install();

    rad_context_options co = {0};
    co.threads = command->flags & CMD_SERIAL ? 1 : job.s.threads;
    /* --max-memory limits everything the engine allocates, loading included. */
    co.max_memory_bytes = job.s.solve.max_memory_bytes;
    co.read_outside_scene_folder = job.s.read_outside != 0;
    co.missing_textures_flat = job.s.missing_textures != 0;
    co.on_warning = cli_print_warning;
    if (!job.s.quiet && isatty(STDERR_FILENO) && !(command->flags & CMD_SERIAL)) {
        co.progress = cli_progress_bar;
        co.progress_user = &job.progress;
    }
    if (rad_context_create(&co, &job.ctx) != RAD_OK) {
        fprintf(stderr, "radiosity: cannot create a context\n");
        return 1;
    }
    cli_signals_watch(job.ctx);
    job.command = command;
    job.ranks = ranks;

    /* 0. every output path checked before any work; under mpirun, rank 0
     * writes for the job */
    if ((command->flags & CMD_OUTPUT_SET) && ranks->rank == 0)
        status = plan_outputs(&job);
    /* 1-5. the command, through the stages above */
    if (status < 0)
        status = command->fn(&job);

    rad_output_set_destroy(job.out.set);
    rad_solution_destroy(job.sol);
    rad_scene_destroy(job.scene);
    cli_signals_watch(NULL);
    rad_context_destroy(job.ctx);
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
