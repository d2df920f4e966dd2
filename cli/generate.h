/*
 * generate.h -- `radiosity generate KIND [options]`: write a procedural
 * scene as OBJ + MTL (cli/generate.c).
 */
#ifndef RAD_CLI_GENERATE_H
#define RAD_CLI_GENERATE_H

#include "options.h"

/* Run the generate command on parsed settings (cli_parse_args: the scene
 * kind, s->office, s->output, s->quiet) in `ctx`, whose cancellation (a
 * signal) stops it with nothing written.  Prints one line on stderr on
 * failure.  Returns the exit status: 0 ok, 1 failure or interruption (the
 * scene could not be built or written; no file and no temporary is left;
 * main() turns an interruption into 130 / 143), 2 when the library
 * refuses an option. */
int cli_generate(const cli_settings *s, rad_context *ctx);

#endif
