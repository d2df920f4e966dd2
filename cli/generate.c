/*
 * generate.c -- `radiosity generate office [--rooms N] [--seed S]
 * [-o office.obj] [--quiet]`: build a procedural scene with the library
 * (rad_scene_generate_office) and write it as OBJ + MTL
 * (rad_scene_write_obj, atomic: both files or neither).  The kinds of
 * scene and their options are in docs/scenes.md.
 */
#include "generate.h"

#include "radiosity.h"

#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { EXIT_FAILED = 1, EXIT_USAGE = 2 };

static void print_usage(FILE *out)
{
    fprintf(out,
            "usage: radiosity generate office [--rooms N] [--seed S] [-o FILE.obj] [--quiet]\n"
            "  --rooms N     rooms on the floor, 1 to 100000 (default 4)\n"
            "  --seed S      unsigned 64-bit seed (default 0); the same seed gives the same scene\n"
            "  -o FILE.obj   output (default office.obj); the MTL is written beside it\n"
            "  -q, --quiet   print nothing on success\n");
}

/* One line on stderr; returns the usage exit status. */
static int usage_error(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

static int usage_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("radiosity: generate: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputs(" (see radiosity generate --help)\n", stderr);
    va_end(ap);
    return EXIT_USAGE;
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The value of option argv[*i] ("--name VALUE" or "--name=VALUE"); NULL
 * if missing. */
static const char *option_value(int argc, char **argv, int *i, size_t name_length)
{
    const char *arg = argv[*i];
    if (arg[name_length] == '=')
        return arg + name_length + 1;
    if (*i + 1 >= argc)
        return NULL;
    return argv[++*i];
}

static bool is_option(const char *arg, const char *name)
{
    size_t n = strlen(name);
    return strncmp(arg, name, n) == 0 && (arg[n] == '\0' || arg[n] == '=');
}

int rad_cli_generate(int argc, char **argv)
{
    if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        print_usage(stdout);
        return 0;
    }
    if (argc < 2)
        return usage_error("no scene kind given (known: office)");
    if (strcmp(argv[1], "office") != 0)
        return usage_error("unknown scene kind '%s' (known: office)", argv[1]);

    rad_office_options options = {.rooms = 4};
    const char *output = "office.obj";
    bool quiet = false;
    for (int i = 2; i < argc; i++) {
        const char *arg = argv[i];
        if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0) {
            print_usage(stdout);
            return 0;
        } else if (strcmp(arg, "--quiet") == 0 || strcmp(arg, "-q") == 0) {
            quiet = true;
        } else if (is_option(arg, "--rooms")) {
            const char *value = option_value(argc, argv, &i, strlen("--rooms"));
            if (!value)
                return usage_error("--rooms needs a value (N)");
            char *end;
            errno = 0;
            long rooms = strtol(value, &end, 10);
            if (errno || end == value || *end || rooms < 1 || rooms > 100000)
                return usage_error("--rooms: expected an integer in [1, 100000], got '%s'",
                                   value);
            options.rooms = (int)rooms;
        } else if (is_option(arg, "--seed")) {
            const char *value = option_value(argc, argv, &i, strlen("--seed"));
            if (!value)
                return usage_error("--seed needs a value (S)");
            char *end;
            errno = 0;
            unsigned long long seed = strtoull(value, &end, 10);
            if (errno || end == value || *end || value[0] == '-' || value[0] == '+')
                return usage_error("--seed: expected an unsigned 64-bit integer, got '%s'",
                                   value);
            options.seed = (uint64_t)seed;
        } else if (strcmp(arg, "-o") == 0 || is_option(arg, "--output")) {
            const char *value =
                option_value(argc, argv, &i, strcmp(arg, "-o") == 0 ? 2 : strlen("--output"));
            if (!value || !*value)
                return usage_error("%s needs a file name", arg);
            output = value;
        } else {
            return usage_error("unknown option '%s'", arg);
        }
    }

    rad_context *ctx = NULL;
    rad_context_options co = {.threads = 1};
    if (rad_context_create(&co, &ctx) != RAD_OK) {
        fprintf(stderr, "radiosity: cannot create a context\n");
        return EXIT_FAILED;
    }
    double start = now_seconds();
    rad_scene *scene = NULL;
    rad_result r = rad_scene_generate_office(ctx, &options, &scene);
    double generated = now_seconds();
    if (r == RAD_OK)
        r = rad_scene_write_obj(ctx, scene, output);
    int status = 0;
    if (r != RAD_OK) {
        fprintf(stderr, "radiosity: %s\n", rad_context_error(ctx));
        status = r == RAD_ERROR_INVALID_ARGUMENT ? EXIT_USAGE : EXIT_FAILED;
    } else if (!quiet) {
        printf("wrote %s (office, %d rooms, seed %" PRIu64 ": %zu surfaces, %zu polygons; "
               "generated in %.3f s, written in %.3f s)\n",
               output, options.rooms, options.seed, rad_scene_surface_count(scene),
               rad_scene_polygon_count(scene), generated - start, now_seconds() - generated);
    }
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return status;
}
