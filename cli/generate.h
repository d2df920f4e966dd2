/*
 * generate.h -- `radiosity generate KIND [options]`: write a procedural
 * scene as OBJ + MTL (cli/generate.c).
 */
#ifndef RAD_CLI_GENERATE_H
#define RAD_CLI_GENERATE_H

/* Run the generate command.  argv[0] is "generate", argv[1] the scene kind
 * ("office"), then its options.  Prints one line on stderr on failure.
 * Returns the exit status: 0 ok, 1 failure (the scene could not be built
 * or written; no file is left), 2 usage error. */
int rad_cli_generate(int argc, char **argv);

#endif
