/*
 * options.h -- the `radiosity` command's flags and their parser, shared by
 * every command (render, viewfactors, export, generate, solve).
 *
 * One table of flags (options.c): each maps to a field of the library's
 * option structs, whose row in the library's option table (radiosity.h,
 * "Option table") gives its type, range, default and help, or is the
 * program's own (--output, --stats, --camera, ...) with a row of the same
 * kind.  The parser, --help, the man page and the rewriting of the
 * library's messages into flag names all read that table.
 *
 * cli_parse_args() has no side effects: it prints nothing, exits nothing
 * and allocates nothing (the settings point into argv), so a fuzz target
 * can call it on any input (fuzz/fuzz_cli_options.c).  main.c acts on what
 * it returns.
 */
#ifndef RAD_CLI_OPTIONS_H
#define RAD_CLI_OPTIONS_H

#include "radiosity.h"

#include <stddef.h>
#include <stdio.h>

/* The commands, as bits: a flag lists those that take it. */
enum { CLI_RENDER = 1, CLI_VIEWFACTORS = 2, CLI_GENERATE = 4, CLI_EXPORT = 8, CLI_SOLVE = 16, CLI_BAKE = 32,
       CLI_VIEW = 64, CLI_THERMAL = 128, CLI_PHOTOMETRY = 256,
       CLI_ILLUMINANCE = 512 };

/* What the command line asks for. */
typedef enum cli_action {
    CLI_RUN,          /* run s->command */
    CLI_HELP,         /* --help: cli_print_help(stdout, s->command), exit 0 */
    CLI_VERSION,      /* --version */
    CLI_LIST_METHODS, /* --list-methods */
    CLI_MAN,          /* --man: cli_print_man(stdout) */
    CLI_NO_ARGUMENTS, /* nothing given: help on stderr, exit 2 */
    CLI_USAGE_ERROR   /* the message is in err: exit 2 */
} cli_action;

/* The parsed command line; zero-initialised, 0 means the default. */
typedef struct cli_settings {
    int command;              /* CLI_RENDER, CLI_VIEWFACTORS, CLI_EXPORT, CLI_GENERATE, CLI_SOLVE or CLI_BAKE */
    const char *scene_path;   /* render, viewfactors, export, solve: NULL = the built-in Cornell
                                 box; render: a solution file too */
    const char *scene_kind;   /* generate: "office" */
    const char *output;       /* the command's default when not given */
    const char *stats;
    const char *camera;       /* parsed later by rad_camera_from_string */
    const char *history;
    const char *progress_dir;
    int every;
    int element_level;        /* viewfactors, thermal: 0 surfaces, 1 elements */
    int smooth;               /* viewfactors: rad_smoothing (--smooth) */
    double sparse_threshold;  /* viewfactors: .mtx factors below it dropped, 0 = none */
    size_t block_rows;        /* viewfactors: rows per streamed block; 0 = stream only when the
                                 dense matrix does not fit (rad_stream_options) */
    rad_options solve;
    rad_render_options render;
    rad_office_options office;
    int threads;
    int quiet;
    int read_outside;         /* --read-outside-scene-folder */
    int missing_textures;     /* --missing-textures: 0 error, 1 flat */
    double texels_per_metre;  /* bake: 0 = the library's default */
    int atlas_size;           /* bake: 0 = the library's default */
    int lightmap_quantity;    /* bake: rad_lightmap_quantity */
    const char *bc;           /* thermal: the boundary-condition file */
    const char *gebhart;      /* thermal: where the Gebhart factors go, or NULL */
    const char *thermal_solver; /* thermal --solver (also made the solution's); NULL = direct */
    double thermal_tolerance; /* thermal --tolerance; 0 = the library's default */
    int offscreen;            /* view: one frame to --output, no window */
    int no_ambient;           /* view: B without the ambient term while shooting */
    const char *keys;         /* view: keys the window presses itself */
    char *const *photometry_files; /* photometry: the files (into argv, consecutive) */
    size_t photometry_file_count;
    const char *daylight;     /* --daylight: the daylight file (sky, sun, openings), or NULL */
    const char *luminaires;   /* render, export, solve, bake, view, illuminance: a layout file (docs/lighting.md) */
    int false_colour;         /* render: 0 none, else rad_false_colour_quantity (--false-colour) */
    int log_scale;            /* render --scale: 0 linear, 1 log */
    const char *range;        /* render --range MIN:MAX, NULL = automatic */
    int contours;             /* render --contours: isolines at the legend's ticks */
    const char *grid;         /* illuminance: the grid file (--grid) */
    const char *output2;      /* illuminance: a second -o (CSV and JSON both), or NULL */
    const char *dense_for;    /* the flag that made gauss-seidel the solver, no --solver given
                                 (said in a note before the solve), or NULL */
} cli_settings;

/* Where a flag's value goes. */
typedef enum cli_target {
    CLI_TO_SOLVE,    /* a field of rad_options (settings.solve) */
    CLI_TO_RENDER,   /* a field of rad_render_options (settings.render) */
    CLI_TO_OFFICE,   /* a field of rad_office_options (settings.office) */
    CLI_TO_SETTINGS, /* the program's own: `own` describes it, offset in cli_settings */
    CLI_TO_ACTION    /* --help, --version, ...: returns `action` */
} cli_target;

typedef struct cli_flag {
    const char *name;         /* "max-memory" for --max-memory */
    char short_name;          /* 'o' for -o; 0 for none */
    const char *metavar;      /* "SIZE"; NULL: a switch, which takes no value */
    unsigned commands;        /* the commands that take it; 0: any, and none needed */
    cli_target target;
    const char *field;        /* CLI_TO_SOLVE / _RENDER / _OFFICE: the library field */
    const char *word;         /* a switch on an ENUM or FLAG field: the word it sets
                                 (NULL: 1) */
    const char *help;         /* NULL: the field's help */
    rad_option_info own;      /* CLI_TO_SETTINGS: type, offset, range, default, help */
    cli_action action;        /* CLI_TO_ACTION */
} cli_flag;

/* The index-th flag of the table; NULL past the end. */
const cli_flag *cli_flag_get(size_t index);

/* The row that describes a flag's value: the library's row of its field,
 * or the flag's own.  Never NULL for a flag of the table. */
const rad_option_info *cli_flag_info(const cli_flag *flag);

/* Parse argv[1..argc-1] into *s (which the caller zeroes).  Returns what to
 * do; on CLI_USAGE_ERROR, err holds one line without the program name or
 * newline, e.g. "--tolerance: expected a number in (0, 1), got '2'".
 * Strings in *s point into argv.  Cannot fail otherwise. */
cli_action cli_parse_args(int argc, char *const *argv, cli_settings *s, char *err, size_t err_size);

/* --help, from the table: the overall help for command 0, else that
 * command's (CLI_RENDER, ...). */
void cli_print_help(FILE *out, int command);

/* The manual page radiosity(1) as roff, from the same table. */
void cli_print_man(FILE *out);

/* Copy a library message into out (at most `size` bytes, NUL included),
 * with every field the table maps to a flag written as the flag:
 * "rad_options.max_memory_bytes" -> "--max-memory".  Returns out. */
char *cli_rewrite_message(const char *message, char *out, size_t size);

/* The name of a command bit ("render"); "" for anything else. */
const char *cli_command_name(int command);

#endif
