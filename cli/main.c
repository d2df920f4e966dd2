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
 * the outputs planned) and dispatches.  The stages 1 to 5 are stages.c's,
 * one comment each; what a command adds between them (a camera, a grid
 * file, the thermal conditions) is in its own file.
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

#include <limits.h>
#include <stdio.h>
#include <string.h>
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
