/*
 * fuzz_cli_options.c -- the command line (cli_parse_args in cli/options.c).
 * The input is argv[1..] separated by NUL bytes.  The parser must not
 * print, exit or read past argv; a usage error leaves one line of text;
 * accepted settings are in range.
 */
#include "fuzz.h"
#include "options.h"

#include <math.h>
#include <string.h>

enum { MAX_ARGS = 64, MAX_TEXT = 4096 };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > MAX_TEXT)
        return 0;
    char text[MAX_TEXT + 1];
    memcpy(text, data, size);
    text[size] = '\0';
    static char program[] = "radiosity";
    char *argv[MAX_ARGS + 2];
    int argc = 0;
    argv[argc++] = program;
    for (size_t start = 0; start <= size && argc < MAX_ARGS + 1;) {
        argv[argc++] = text + start;
        start += strlen(text + start) + 1;
    }
    argv[argc] = NULL;

    cli_settings s;
    memset(&s, 0, sizeof s);
    char err[512];
    memset(err, 'x', sizeof err);
    cli_action a = cli_parse_args(argc, argv, &s, err, sizeof err);
    FUZZ_CHECK(memchr(err, '\0', sizeof err) != NULL);
    switch (a) {
    case CLI_USAGE_ERROR: FUZZ_CHECK(err[0] != '\0'); break;
    case CLI_RUN:
        FUZZ_CHECK(s.command == CLI_RENDER || s.command == CLI_VIEWFACTORS);
        FUZZ_CHECK(s.solve.mesh_size == 0.0 || (s.solve.mesh_size >= 1e-9 && s.solve.mesh_size <= 1e9));
        FUZZ_CHECK(s.render.width >= 0 && s.render.width <= 16384);
        FUZZ_CHECK(s.render.height >= 0 && s.render.height <= 16384);
        FUZZ_CHECK(s.threads >= 0 && s.threads <= 1024);
        FUZZ_CHECK(s.solve.max_memory_bytes == 0.0 ||
                   (isfinite(s.solve.max_memory_bytes) && s.solve.max_memory_bytes > 0.0));
        FUZZ_CHECK(s.every == 0 || s.progress_dir != NULL);
        break;
    case CLI_HELP: case CLI_VERSION: case CLI_LIST_METHODS: break;
    case CLI_NO_ARGUMENTS: FUZZ_CHECK(0); break; /* argc >= 2 here */
    }
    return 0;
}
