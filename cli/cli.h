/*
 * cli.h -- what the `radiosity` program's files share: the command table
 * (one row and one file per command, cmd_*.c), the job a command works
 * on, the pipeline's stages the commands walk (main.c) and the helpers
 * several of them use (common.c).
 *
 * main.c parses the command line (options.c), looks the command's row up
 * by name, creates the context, installs the signal handlers and, for a
 * command that writes an output set, plans every output before any work.
 * The command then walks the stages it needs, adding its own steps
 * between them; render, for one:
 *
 *   cli_load -> its camera -> cli_solve (cli_couple, the solve) -> the image -> cli_finish
 *
 * What a stage makes hangs off the job, and main.c destroys it whatever
 * the command returns.
 */
#ifndef RAD_CLI_H
#define RAD_CLI_H

#include "options.h"
#include "radiosity.h"

#include <stdbool.h>
#include <stdint.h>

enum { EXIT_USAGE = 2 };

/* What main.c and the stages do for a command (cli_command.flags). */
enum {
    CMD_OUTPUT_SET = 1,     /* its outputs are one output set, planned before any work (job->out) */
    CMD_SOLUTION_INPUT = 2, /* cli_load takes a solution file (.radsol) too: solved already */
    CMD_MPI = 4,            /* spreads its work over mpirun's ranks; rank 0 writes for them all */
    CMD_SERIAL = 8          /* one thread, no progress bar: it is over in a moment */
};

/* Progress on stderr, only when it is a terminal. */
typedef struct cli_progress {
    const char *phase;
    int last_percent;
    double start; /* s, cli_now() */
} cli_progress;

/* The outputs of a run, checked before any work and written as one output
 * set: every file appears at the end, or none (docs/robustness.md).  Each
 * name is the temporary to write into. */
typedef struct cli_outputs {
    rad_output_set *set;
    const char *main;    /* the image, view-factor or mesh file */
    const char *stats, *history;
    const char *gebhart; /* thermal --gebhart */
    const char *second;  /* illuminance's second -o */
} cli_outputs;

typedef struct cli_command cli_command;

/* One run of a command.  main.c fills in the first five fields; the stages
 * the rest. */
/* --progress-images writes at most this many frames in a run (a solve of
 * thousands of steps, shooting's or hierarchical's sweeps at a tight
 * tolerance, would fill a disk); later steps are not drawn, said once. */
#define CLI_MAX_PROGRESS_IMAGES 1000

typedef struct cli_job {
    cli_settings s;                /* the command line; render sets s.render.camera, cli_solve s.solve.on_step */
    const cli_command *command;    /* its row */
    const rad_stream_ranks *ranks; /* mpirun's; {0, 1} without it */
    rad_context *ctx;
    cli_progress progress;
    cli_outputs out;               /* CMD_OUTPUT_SET; on ranks above 0, none */
    rad_scene *scene;              /* cli_load */
    rad_solution *sol;             /* cli_load (a solution file) or cli_couple */
    bool saved;                    /* the input was a solution file: solved already */
    bool partial;                  /* cli_solve was interrupted: its iterate is the result */
    double t0;                     /* s, cli_now() when cli_load began */
    double frame_exposure;         /* --progress-images: the user's, else the first frame's automatic one */
    bool frame_failed;             /* a progress image could not be written: the message is in ctx */
    int frames;                    /* progress images written (at most CLI_MAX_PROGRESS_IMAGES) */
} cli_job;

/* A row of the command table (main.c), looked up by the name the parser
 * recognised. */
struct cli_command {
    const char *name;       /* as typed: `radiosity render` */
    unsigned flags;         /* CMD_OUTPUT_SET, ... */
    rad_output_kind output; /* CMD_OUTPUT_SET: what -o writes */
    /* Usage errors the flag table cannot say (a flag the command needs):
     * nonzero with one line in err, told as the parser's are, before
     * anything starts.  NULL: none. */
    int (*check)(const cli_settings *s, char *err, size_t err_size);
    int (*fn)(cli_job *job); /* the command; returns the exit status */
};

/* ---- the commands (cmd_*.c): each returns the exit status, 130 / 143
 * when a signal interrupted it ---- */

int cmd_render(cli_job *job);
int cmd_solve(cli_job *job);
int cmd_export(cli_job *job);
int cmd_bake(cli_job *job);
int cmd_illuminance(cli_job *job);
int cmd_illuminance_check(const cli_settings *s, char *err, size_t err_size);
int cmd_viewfactors(cli_job *job);
int cmd_thermal(cli_job *job);
int cmd_thermal_check(const cli_settings *s, char *err, size_t err_size);
int cmd_view(cli_job *job);
int cmd_photometry(cli_job *job);
int cmd_generate(cli_job *job);

/* ---- the stages (main.c) ----
 *
 * Each returns -1 to go on, else the exit status with its message
 * printed; what it made stays on the job either way. */

/* The scene file, or the built-in Cornell box, with --daylight's light.
 * On failure *scene is NULL, the message in ctx. */
rad_result cli_read_scene(rad_context *ctx, const cli_settings *s, rad_scene **scene);

/* 1. load: the scene (cli_read_scene) and the luminaires' layout, or a
 * solution file where the command takes one; every file read becomes an
 * input no output may be. */
int cli_load(cli_job *job);

/* 2-3. mesh, visibility, form factors into job->sol (a loaded solution has
 * them); interrupted, the stats alone say so. */
int cli_couple(cli_job *job);

/* 2-4. what is solved said (`verb`: "rendering" the built-in Cornell box),
 * the progress images prepared, cli_couple, then B solved (a loaded
 * solution is solved).  Interrupted, job->partial is set and it goes on:
 * the iterate is saved. */
int cli_solve(cli_job *job, const char *verb);

/* The solution's stats (partial when job->partial) and history into their
 * temporaries, when asked for.  A failure `r` is passed on untouched. */
rad_result cli_write_records(cli_job *job, rad_result r);

/* Every output put in place together, after what was printed (an output
 * may be stdout).  A failure `r` is passed on untouched. */
rad_result cli_commit(cli_job *job, rad_result r);

/* 5's end for render, export and bake, whose output `r` tells how its
 * writing went: cli_write_records, cli_commit, then unless --quiet
 * "wrote FILE" + detail (printf-style: " (%zu vertices, ") + "N elements,
 * residual R, T s)" and the luminaires' light.  Returns the exit status. */
int cli_finish(cli_job *job, rad_result r, const char *detail, ...) __attribute__((format(printf, 3, 4)));

/* ---- helpers (common.c) ---- */

double cli_now(void); /* s, monotonic */

/* The absolute path of a file just written, for telling the user where it
 * is; the name as given when it cannot be resolved.  buf: PATH_MAX bytes. */
const char *cli_where(const char *path, char *buf);

/* The library's message on stderr, its field names written as our flags
 * ("rad_options.max_memory_bytes" -> "--max-memory").  Returns 1, or
 * 130 / 143 once a signal has come. */
int cli_fail(rad_context *ctx, rad_result r);

/* cli_fail for a path refused in the output set: 2 when the path is a bad
 * argument (an alias of an input, an unknown format), else 1. */
int cli_fail_path(rad_context *ctx, rad_result r);

/* The library's warning (an orthographic glTF camera replaced) on stderr,
 * its field names written as our flags; a rad_context_options.on_warning. */
void cli_print_warning(void *user, const char *message);

/* A rad_context_options.progress: a bar on stderr per phase. */
void cli_progress_bar(void *user, const char *phase, uint64_t done, uint64_t total);

/* The bar's line ended, when one is drawn. */
void cli_progress_end(cli_progress *p);

/* Signals.  The first SIGINT or SIGTERM decides the exit status (130 /
 * 143).  While the pipeline works, it cancels the context: the running
 * phase stops and what exists is saved (a partial solution, or the stats
 * of an interrupted run).  Once the outputs are being made
 * (cli_begin_saving), signals only note themselves: a second Ctrl-C cannot
 * lose the results being saved, and the output set removes every
 * temporary whatever happens. */
void cli_signals_install(void);
void cli_signals_watch(rad_context *ctx); /* the context a signal cancels; NULL: none */
void cli_begin_saving(rad_context *ctx);
bool cli_interrupted(void);        /* a signal has come */
int cli_interrupted_status(void);  /* 130, or 143 for SIGTERM */
int cli_status(int status);        /* status, or 130 / 143 once a signal has come */

/* The false colour options of render's flags (--false-colour, --scale,
 * --range, --contours) or of illuminance's plans, checked by the library
 * before any work.  Returns -1 when good, else the exit status (the
 * message printed). */
int cli_false_colour_options(const cli_job *job, rad_false_colour_options *fo);

#endif
