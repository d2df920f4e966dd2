/*
 * generate.h -- `radiosity generate KIND [options]`: write a procedural
 * scene as OBJ + MTL (cli/generate.c).
 */
#ifndef RAD_CLI_GENERATE_H
#define RAD_CLI_GENERATE_H

#include "options.h"

/* Run the generate command on parsed settings (cli_parse_args: the scene
 * kind, s->office, s->output, s->quiet).  Prints one line on stderr on
 * failure.  Returns the exit status: 0 ok, 1 failure (the scene could not
 * be built or written; no file is left), 2 when the library refuses an
 * option. */
int cli_generate(const cli_settings *s);

#endif
