/*
 * fuzz_cli_options.c -- the command line (cli_parse_args in cli/options.c).
 * The input is argv[1..] separated by NUL bytes.  The parser must not
 * print, exit or read past argv; a usage error leaves one line of text;
 * accepted settings are within the ranges of the option table, and a seed
 * other than 0 is exactly the decimal digits of some --seed value given.
 */
#include "fuzz.h"
#include "options.h"

#include <string.h>

enum { MAX_ARGS = 64, MAX_TEXT = 4096 };

/* `text` as decimal digits that fit a uint64_t exactly, into *value. */
static bool exact_digits(const char *text, uint64_t *value)
{
    uint64_t v = 0;
    if (!*text)
        return false;
    for (const char *c = text; *c; c++) {
        if (*c < '0' || *c > '9' || v > (UINT64_MAX - (uint64_t)(*c - '0')) / 10)
            return false;
        v = 10 * v + (uint64_t)(*c - '0');
    }
    *value = v;
    return true;
}

/* Some "--seed V" or "--seed=V" in argv has V exactly `seed`. */
static bool seed_given(int argc, char **argv, uint64_t seed)
{
    for (int k = 1; k < argc; k++) {
        const char *value = strncmp(argv[k], "--seed=", 7) == 0                ? argv[k] + 7
                            : strcmp(argv[k], "--seed") == 0 && k + 1 < argc ? argv[k + 1]
                                                                               : NULL;
        uint64_t v;
        if (value && exact_digits(value, &v) && v == seed)
            return true;
    }
    return false;
}

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
        FUZZ_CHECK(cli_command_name(s.command)[0] != '\0'); /* one of the commands, whichever */
        FUZZ_CHECK(s.output != NULL || s.command == CLI_PHOTOMETRY); /* photometry only prints */
        FUZZ_CHECK(s.command != CLI_PHOTOMETRY ||
                   (s.photometry_file_count > 0 && s.photometry_files >= argv + 2 &&
                    s.photometry_files + s.photometry_file_count <= argv + argc));
        FUZZ_CHECK(s.command != CLI_GENERATE || (s.scene_kind && strcmp(s.scene_kind, "office") == 0));
        /* Every number set is 0 (the default) or within its field's range
         * in the library's option table. */
        for (size_t k = 0; cli_flag_get(k); k++) {
            const cli_flag *f = cli_flag_get(k);
            const rad_option_info *o = cli_flag_info(f);
            const char *base = f->target == CLI_TO_SOLVE    ? (const char *)&s.solve
                               : f->target == CLI_TO_RENDER ? (const char *)&s.render
                               : f->target == CLI_TO_OFFICE ? (const char *)&s.office
                                                            : (const char *)&s;
            double v;
            if (f->target == CLI_TO_ACTION || !f->metavar)
                continue;
            if (o->type == RAD_OPTION_INT || o->type == RAD_OPTION_ENUM)
                v = *(const int *)(const void *)(base + o->offset);
            else if (o->type == RAD_OPTION_SIZE)
                v = (double)*(const size_t *)(const void *)(base + o->offset);
            else if (o->type == RAD_OPTION_DOUBLE || o->type == RAD_OPTION_BYTES)
                v = *(const double *)(const void *)(base + o->offset);
            else
                continue;
            FUZZ_CHECK(v == 0.0 || rad_option_in_range(o, v));
        }
        FUZZ_CHECK(s.every == 0 || s.progress_dir != NULL);
        FUZZ_CHECK(s.solve.seed == 0 || seed_given(argc, argv, s.solve.seed));
        FUZZ_CHECK(s.office.seed == 0 || seed_given(argc, argv, s.office.seed));
        break;
    case CLI_HELP: case CLI_VERSION: case CLI_LIST_METHODS: case CLI_MAN: break;
    case CLI_NO_ARGUMENTS: FUZZ_CHECK(0); break; /* argc >= 2 here */
    }
    return 0;
}
