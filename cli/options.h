/*
 * options.h -- the `radiosity` command's option table and its parser.
 *
 * cli_parse_args() turns argv into a cli_settings without side effects: it
 * prints nothing, exits nothing and allocates nothing (the settings point
 * into argv), so a fuzz target can call it on any input
 * (fuzz/fuzz_cli_options.c).  main.c acts on what it returns.
 */
#ifndef RAD_CLI_OPTIONS_H
#define RAD_CLI_OPTIONS_H

#include "radiosity.h"

#include <stddef.h>
#include <stdio.h>

enum { CLI_RENDER = 1, CLI_VIEWFACTORS = 2, CLI_ALL = 3 };

/* What the command line asks for. */
typedef enum cli_action {
    CLI_RUN,          /* run s->command (CLI_RENDER or CLI_VIEWFACTORS) */
    CLI_HELP,         /* --help: print cli_print_help(stdout), exit 0 */
    CLI_VERSION,      /* --version */
    CLI_LIST_METHODS, /* --list-methods */
    CLI_NO_ARGUMENTS, /* nothing given: help on stderr, exit 2 */
    CLI_USAGE_ERROR   /* the message is in err: exit 2 */
} cli_action;

/* The parsed command line; zero-initialised, 0 means the default. */
typedef struct cli_settings {
    int command;              /* CLI_RENDER or CLI_VIEWFACTORS */
    const char *scene_path;   /* NULL: the built-in Cornell box */
    const char *output;
    const char *stats;
    const char *camera;       /* parsed later by rad_camera_from_string */
    const char *history;
    const char *progress_dir;
    long every;
    int element_level;
    rad_options solve;
    rad_render_options render;
    int threads;
    int quiet;
} cli_settings;

/* Parse argv[1..argc-1] into *s (which the caller zeroes).  Returns what to
 * do; on CLI_USAGE_ERROR, err holds one line without the program name or
 * newline, e.g. "--width: expected an integer in [1, 16384], got 'x'".
 * Strings in *s point into argv.  Cannot fail otherwise. */
cli_action cli_parse_args(int argc, char *const *argv, cli_settings *s, char *err, size_t err_size);

/* Print --help (generated from the option table) to out. */
void cli_print_help(FILE *out);

#endif
