/*
 * test_options.c -- the option tables.  The library's rows (radiosity.h,
 * "Option table") are sound and rad_options_resolve refuses a value just
 * outside a row's range naming the field; the render and office checks
 * agree with their rows; the command's flags (cli/options.c) accept each
 * bound and refuse just outside it with the same range, naming the flag;
 * seeds are exact; --help and the man page list every flag with its
 * default; generate goes through the shared parser; library messages are
 * rewritten into flags.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "strategy/options.h"
#include "options.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static rad_context *ctx;

static const rad_option_set SETS[] = {RAD_OPTION_SET_SOLUTION, RAD_OPTION_SET_RENDER, RAD_OPTION_SET_OFFICE};
static const size_t SET_SIZES[] = {sizeof(rad_options), sizeof(rad_render_options), sizeof(rad_office_options)};

static int is_number(rad_option_type type)
{
    return type == RAD_OPTION_INT || type == RAD_OPTION_SIZE || type == RAD_OPTION_DOUBLE ||
           type == RAD_OPTION_BYTES;
}

static int is_integer(rad_option_type type)
{
    return type == RAD_OPTION_INT || type == RAD_OPTION_SIZE;
}

/* The nearest value beyond a bound (outward = 1) or inside it (-1):
 * integers step by 1, doubles by one ulp. */
static double step_from(const rad_option_info *o, double bound, double direction)
{
    return is_integer(o->type) ? bound + direction : nextafter(bound, direction * INFINITY);
}

/* Values just inside and just outside each finite bound of a numeric row. */
typedef struct probe {
    double inside[2], outside[2];
    int count;
} probe;

static probe probes(const rad_option_info *o)
{
    probe p = {{0}, {0}, 0};
    p.inside[p.count] = o->min_open ? step_from(o, o->min, 1.0) : o->min;
    p.outside[p.count++] = o->min_open ? o->min : step_from(o, o->min, -1.0);
    if (isfinite(o->max)) {
        p.inside[p.count] = o->max_open ? step_from(o, o->max, -1.0) : o->max;
        p.outside[p.count++] = o->max_open ? o->max : step_from(o, o->max, 1.0);
    }
    return p;
}

/* ---- the library's rows ---- */

static void test_rows_are_sound(void **state)
{
    (void)state;
    for (size_t k = 0; k < 3; k++) {
        size_t i = 0;
        const rad_option_info *o;
        for (; (o = rad_option_info_get(SETS[k], i)); i++) {
            assert_true(o->offset < SET_SIZES[k]);
            assert_ptr_equal(rad_option_find(SETS[k], o->name), o);
            assert_non_null(o->help);
            assert_null(strstr(o->help, "--"));
            if (is_number(o->type)) {
                assert_true(o->min < o->max);
                assert_non_null(o->default_text);
            }
            /* A numeric default is in range and is what its text says. */
            if (is_number(o->type) && isfinite(o->default_value)) {
                assert_true(rad_option_in_range(o, o->default_value));
                assert_true(strtod(o->default_text, NULL) == o->default_value);
            }
            if (o->type == RAD_OPTION_ENUM || (o->type == RAD_OPTION_FLAG && o->words)) {
                assert_non_null(o->words);
                assert_string_equal(o->words[0].word, o->default_text); /* 0, the default, first */
                assert_int_equal(o->words[0].value, 0);
            }
            if (o->type == RAD_OPTION_METHOD) { /* the name resolve fills in */
                rad_options defaults = {0}, out;
                rad_method_names names;
                assert_int_equal(rad_options_resolve(ctx, &defaults, &out, &names), RAD_OK);
                assert_string_equal(*(const char *const *)(const void *)((const char *)&out + o->offset),
                                    o->default_text);
            }
        }
        assert_true(i > 0);
        assert_null(rad_option_find(SETS[k], "no_such_field"));
    }
    assert_null(rad_option_info_get((rad_option_set)3, 0));
    assert_string_equal(rad_option_set_name(RAD_OPTION_SET_RENDER), "rad_render_options");
    /* The defaults the review found wrong in --help: the library's are the truth. */
    assert_true(rad_option_find(RAD_OPTION_SET_RENDER, "samples")->default_value == 4.0);
    assert_true(rad_option_find(RAD_OPTION_SET_SOLUTION, "shadow_rays")->default_value == 4.0);
}

static void test_range_text(void **state)
{
    (void)state;
    static const struct {
        const char *field, *text;
    } cases[] = {{"tolerance", "(0, 1)"},           {"shadow_rays", "[1, 48]"},
                 {"crease_angle_degrees", "(0, 180]"}, {"min_area", "(0, inf)"},
                 {"clustering", "auto, on or off"},  {"classic_oracle", "sources or classic"},
                 {"seed", "[0, 18446744073709551615]"}, {"closure_correction", ""}};
    char text[256];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        rad_option_range_text(rad_option_find(RAD_OPTION_SET_SOLUTION, cases[i].field), text, sizeof text);
        assert_string_equal(text, cases[i].text);
    }
    rad_option_range_text(rad_option_find(RAD_OPTION_SET_SOLUTION, "visibility"), text, sizeof text);
    assert_non_null(strstr(text, "embree"));
    assert_non_null(strstr(text, " or brute"));
    /* Truncated, still terminated; the length wanted is returned. */
    assert_int_equal(rad_option_range_text(rad_option_find(RAD_OPTION_SET_SOLUTION, "tolerance"), text, 3), 6);
    assert_string_equal(text, "(0");
    /* Words and method names, as the command looks them up. */
    int value = 7;
    assert_true(rad_option_lookup_word(rad_option_find(RAD_OPTION_SET_SOLUTION, "clustering"), "off", &value));
    assert_int_equal(value, -1);
    assert_false(rad_option_lookup_word(rad_option_find(RAD_OPTION_SET_SOLUTION, "clustering"), "of", &value));
    assert_true(rad_option_lookup_word(rad_option_find(RAD_OPTION_SET_SOLUTION, "solver"), "jacobi", &value));
    assert_false(rad_option_lookup_word(rad_option_find(RAD_OPTION_SET_SOLUTION, "solver"), "Jacobi", &value));
    assert_false(rad_option_lookup_word(rad_option_find(RAD_OPTION_SET_SOLUTION, "tolerance"), "1", &value));
}

/* Store a number in a field of the row's C type. */
static void store(void *base, const rad_option_info *o, double value)
{
    char *field = (char *)base + o->offset;
    if (o->type == RAD_OPTION_SIZE)
        *(size_t *)(void *)field = (size_t)value;
    else if (is_integer(o->type) || o->type == RAD_OPTION_ENUM || o->type == RAD_OPTION_FLAG)
        *(int *)(void *)field = (int)value;
    else
        *(double *)(void *)field = value;
}

/* rad_options_resolve on one field set to `value`; returns the result. */
static rad_result resolve_with(const rad_option_info *o, double value)
{
    rad_options in = {0}, out;
    rad_method_names names;
    store(&in, o, value);
    rad_api_enter(ctx); /* each probe is a call of its own: its first failure is kept */
    return rad_options_resolve(ctx, &in, &out, &names);
}

static void test_library_refuses_out_of_range(void **state)
{
    (void)state;
    const rad_option_info *o;
    for (size_t i = 0; (o = rad_option_info_get(RAD_OPTION_SET_SOLUTION, i)); i++) {
        if (!is_number(o->type))
            continue;
        probe p = probes(o);
        for (int b = 0; b < p.count; b++) {
            if (resolve_with(o, p.inside[b]) != RAD_OK)
                fail_msg("rad_options.%s = %.17g refused: %s", o->name, p.inside[b], rad_context_error(ctx));
            double out = p.outside[b];
            if (out == 0.0) { /* 0 is the default, never refused */
                assert_int_equal(resolve_with(o, out), RAD_OK);
                continue;
            }
            if (o->type == RAD_OPTION_INT && (out > INT_MAX || out < INT_MIN))
                continue; /* the field cannot hold it */
            if (o->type == RAD_OPTION_SIZE && out < 0)
                continue;
            if (resolve_with(o, out) != RAD_ERROR_INVALID_ARGUMENT)
                fail_msg("rad_options.%s = %.17g accepted", o->name, out);
            char range[256], expected[400];
            rad_option_range_text(o, range, sizeof range);
            snprintf(expected, sizeof expected, "rad_options.%s must be in %s, got ", o->name, range);
            if (strncmp(rad_context_error(ctx), expected, strlen(expected)) != 0)
                fail_msg("expected '%s...', got '%s'", expected, rad_context_error(ctx));
        }
        /* Not finite: refused, whatever the range. */
        if (!is_integer(o->type)) {
            assert_int_equal(resolve_with(o, NAN), RAD_ERROR_INVALID_ARGUMENT);
            assert_int_equal(resolve_with(o, INFINITY), RAD_ERROR_INVALID_ARGUMENT);
        }
    }
    assert_int_equal(resolve_with(rad_option_find(RAD_OPTION_SET_SOLUTION, "tolerance"), 2.0),
                     RAD_ERROR_INVALID_ARGUMENT);
    assert_string_equal(rad_context_error(ctx), "rad_options.tolerance must be in (0, 1), got 2");
    assert_int_equal(resolve_with(rad_option_find(RAD_OPTION_SET_SOLUTION, "clustering"), 2.0),
                     RAD_ERROR_INVALID_ARGUMENT);
    assert_string_equal(rad_context_error(ctx),
                        "rad_options.clustering must be 0 (auto), 1 (on) or -1 (off), got 2");
    rad_options in = {.solver = "nosuch"}, out;
    rad_method_names names;
    rad_api_enter(ctx);
    assert_int_equal(rad_options_resolve(ctx, &in, &out, &names), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "rad_options.solver must be one of gauss-seidel"));
    assert_non_null(strstr(rad_context_error(ctx), "got 'nosuch'"));
}

/* The render and office checks live beside their structs' users; their
 * rows must describe them. */
static void test_render_and_office_checks_match_rows(void **state)
{
    (void)state;
    rad_scene *scene = NULL;
    rad_solution *solution = NULL;
    assert_int_equal(rad_scene_create_cornell_box(ctx, &scene), RAD_OK);
    rad_options options = {.target_elements = 60};
    assert_int_equal(rad_solution_create(ctx, scene, &options, &solution), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, solution), RAD_OK);
    const rad_option_info *o;
    for (size_t i = 0; (o = rad_option_info_get(RAD_OPTION_SET_RENDER, i)); i++) {
        if (o->type != RAD_OPTION_INT)
            continue;
        rad_render_options ro = {.width = 1, .height = 1, .samples = 1};
        rad_image *image = NULL;
        store(&ro, o, o->min);
        assert_int_equal(rad_solution_render(ctx, solution, &ro, &image), RAD_OK);
        rad_image_destroy(image);
        probe p = probes(o);
        for (int b = 0; b < p.count; b++) {
            store(&ro, o, p.outside[b] == 0.0 ? -1.0 : p.outside[b]);
            assert_int_equal(rad_solution_render(ctx, solution, &ro, &image), RAD_ERROR_INVALID_ARGUMENT);
            char range[64], expected[200];
            rad_option_range_text(o, range, sizeof range);
            snprintf(expected, sizeof expected, "rad_render_options.%s must be in %s, got ", o->name, range);
            if (strncmp(rad_context_error(ctx), expected, strlen(expected)) != 0)
                fail_msg("expected '%s...', got '%s'", expected, rad_context_error(ctx));
        }
    }
    rad_solution_destroy(solution);
    rad_scene_destroy(scene);

    o = rad_option_find(RAD_OPTION_SET_OFFICE, "rooms");
    rad_office_options office = {.rooms = (int)o->max + 1};
    assert_int_equal(rad_scene_generate_office(ctx, &office, &scene), RAD_ERROR_INVALID_ARGUMENT);
    assert_string_equal(rad_context_error(ctx), "rad_office_options.rooms must be in [1, 100000], got 100001");
    office.rooms = -1;
    assert_int_equal(rad_scene_generate_office(ctx, &office, &scene), RAD_ERROR_INVALID_ARGUMENT);
    office.rooms = (int)o->min;
    assert_int_equal(rad_scene_generate_office(ctx, &office, &scene), RAD_OK);
    rad_scene_destroy(scene);
}

/* ---- the command's flags ---- */

static cli_settings settings;
static char err[1024];

/* Parse "radiosity ARGS..." (NULL-terminated) into `settings`. */
static cli_action parse(const char *first, ...)
{
    char *argv[32];
    int argc = 0;
    static char program[] = "radiosity";
    argv[argc++] = program;
    va_list ap;
    va_start(ap, first);
    for (const char *a = first; a && argc < 31; a = va_arg(ap, const char *))
        argv[argc++] = (char *)(uintptr_t)a; /* the parser does not write argv */
    va_end(ap);
    argv[argc] = NULL;
    memset(&settings, 0, sizeof settings);
    return cli_parse_args(argc, argv, &settings, err, sizeof err);
}

/* The first command that takes a flag. */
static const char *command_of(const cli_flag *f)
{
    for (int bit = CLI_RENDER; bit <= CLI_THERMAL; bit <<= 1)
        if (f->commands & bit)
            return cli_command_name(bit);
    return NULL;
}

/* Parse one flag with a value for its first command; --every needs
 * --progress-images, generate its scene kind. */
static cli_action parse_flag(const cli_flag *f, const char *value)
{
    char flag[64];
    snprintf(flag, sizeof flag, "--%s", f->name);
    if (strcmp(f->name, "every") == 0)
        return parse("render", flag, value, "--progress-images", "frames", NULL);
    if (f->commands & CLI_GENERATE && !(f->commands & CLI_RENDER))
        return parse("generate", "office", flag, value, NULL);
    return parse(command_of(f), flag, value, NULL);
}

/* The number a flag stored. */
static double stored(const cli_flag *f, const rad_option_info *o)
{
    const char *base = f->target == CLI_TO_SOLVE    ? (const char *)&settings.solve
                       : f->target == CLI_TO_RENDER ? (const char *)&settings.render
                       : f->target == CLI_TO_OFFICE ? (const char *)&settings.office
                                                    : (const char *)&settings;
    const void *field = base + o->offset;
    if (o->type == RAD_OPTION_SIZE)
        return (double)*(const size_t *)field;
    if (o->type == RAD_OPTION_INT || o->type == RAD_OPTION_ENUM || o->type == RAD_OPTION_FLAG)
        return *(const int *)field;
    return *(const double *)field;
}

static void test_flags_map_to_library_rows(void **state)
{
    (void)state;
    size_t k = 0;
    for (const cli_flag *f; (f = cli_flag_get(k)); k++) {
        const rad_option_info *o = cli_flag_info(f);
        if (!o)
            fail_msg("--%s: no row for field '%s'", f->name, f->field);
        if (f->target == CLI_TO_SOLVE)
            assert_ptr_equal(o, rad_option_find(RAD_OPTION_SET_SOLUTION, f->field));
        if (f->target == CLI_TO_ACTION || f->target == CLI_TO_SETTINGS)
            assert_null(f->field);
        /* A switch sets a FLAG or ENUM; a value belongs to every other type. */
        if (!f->metavar && f->target != CLI_TO_ACTION)
            assert_true(o->type == RAD_OPTION_FLAG || o->type == RAD_OPTION_ENUM);
    }
    assert_true(k > 30);
}

static void test_flags_accept_bounds_and_refuse_beyond(void **state)
{
    (void)state;
    for (size_t k = 0; cli_flag_get(k); k++) {
        const cli_flag *f = cli_flag_get(k);
        const rad_option_info *o = cli_flag_info(f);
        if (!f->metavar || !is_number(o->type))
            continue;
        char range[256];
        rad_option_range_text(o, range, sizeof range);
        probe p = probes(o);
        for (int b = 0; b < p.count; b++) {
            char value[64];
            snprintf(value, sizeof value, "%.17g", p.inside[b]);
            if (parse_flag(f, value) != CLI_RUN)
                fail_msg("--%s %s refused: %s", f->name, value, err);
            assert_true(stored(f, o) == p.inside[b]);
            snprintf(value, sizeof value, "%.17g", p.outside[b]);
            if (parse_flag(f, value) != CLI_USAGE_ERROR)
                fail_msg("--%s %s accepted", f->name, value);
            char expected[400];
            snprintf(expected, sizeof expected, "--%s: expected %s", f->name,
                     is_integer(o->type) ? "an integer in " : o->type == RAD_OPTION_DOUBLE ? "a number in " : "a size");
            if (strncmp(err, expected, strlen(expected)) != 0 || !strstr(err, range))
                fail_msg("--%s %s: expected '%s ... %s', got '%s'", f->name, value, expected, range, err);
        }
        const char *bad[] = {"nan", "inf", "x", "1x", "1e999"};
        for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
            if (parse_flag(f, bad[i]) != CLI_USAGE_ERROR)
                fail_msg("--%s %s accepted", f->name, bad[i]);
    }
    assert_int_equal(parse("render", "--tolerance", "2", NULL), CLI_USAGE_ERROR);
    assert_string_equal(err, "--tolerance: expected a number in (0, 1), got '2'");
    assert_int_equal(parse("render", "--max-memory=1.5K", NULL), CLI_RUN);
    assert_true(settings.solve.max_memory_bytes == 1536.0);
    assert_int_equal(parse("render", "--max-memory", "4g", NULL), CLI_RUN);
    assert_true(settings.solve.max_memory_bytes == 4294967296.0);
}

static void test_words_and_methods(void **state)
{
    (void)state;
    for (size_t k = 0; cli_flag_get(k); k++) {
        const cli_flag *f = cli_flag_get(k);
        const rad_option_info *o = cli_flag_info(f);
        if (!f->metavar)
            continue;
        if (o->type == RAD_OPTION_ENUM || o->type == RAD_OPTION_FLAG) {
            for (const rad_option_word *w = o->words; w->word; w++) {
                assert_int_equal(parse_flag(f, w->word), CLI_RUN);
                assert_true(stored(f, o) == w->value);
            }
        } else if (o->type == RAD_OPTION_METHOD) {
            const char *name, *description;
            for (size_t i = 0; rad_method_info(o->methods, i, &name, &description); i++) {
                assert_int_equal(parse_flag(f, name), CLI_RUN);
                const char *base = f->target == CLI_TO_SOLVE ? (const char *)&settings.solve : (const char *)&settings;
                assert_string_equal(*(const char *const *)(const void *)(base + o->offset), name);
            }
        } else {
            continue;
        }
        assert_int_equal(parse_flag(f, "nosuch"), CLI_USAGE_ERROR);
        char range[512];
        rad_option_range_text(o, range, sizeof range);
        assert_non_null(strstr(err, range));
    }
    assert_int_equal(parse("render", "--flat", NULL), CLI_RUN);
    assert_int_equal(settings.render.shading, RAD_SHADING_FLAT);
    assert_int_equal(parse("render", "--closure-correction", NULL), CLI_RUN);
    assert_int_equal(settings.solve.closure_correction, 1);
    assert_int_equal(parse("render", "--flat=1", NULL), CLI_USAGE_ERROR);
}

/* --seed parses alike in every command, and every value it accepts is
 * exact: no double on the way (2^53 + 1 used to become 2^53). */
static void test_seed_is_exact(void **state)
{
    (void)state;
    const char *good[] = {"0", "7", "9007199254740993", "18446744073709551615"};
    const uint64_t want[] = {0, 7, 9007199254740993ull, UINT64_MAX};
    const char *bad[] = {"-1", "+1", " 1", "1.5", "1e3", "0x10", "18446744073709551616", "", "seven"};
    for (size_t i = 0; i < 4; i++) {
        assert_int_equal(parse("render", "--seed", good[i], NULL), CLI_RUN);
        assert_true(settings.solve.seed == want[i]);
        assert_int_equal(parse("viewfactors", "--seed", good[i], NULL), CLI_RUN);
        assert_true(settings.solve.seed == want[i]);
        assert_int_equal(parse("generate", "office", "--seed", good[i], NULL), CLI_RUN);
        assert_true(settings.office.seed == want[i]);
    }
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(parse("render", "--seed", bad[i], NULL), CLI_USAGE_ERROR);
        char generate_err[sizeof err];
        memcpy(generate_err, err, sizeof err);
        assert_int_equal(parse("generate", "office", "--seed", bad[i], NULL), CLI_USAGE_ERROR);
        assert_string_equal(err, generate_err);
    }
}

static void test_generate_takes_the_shared_parser(void **state)
{
    (void)state;
    assert_int_equal(parse("generate", "office", "--rooms", "3", "--seed=11", "-o", "a.obj", "-q", NULL), CLI_RUN);
    assert_int_equal(settings.command, CLI_GENERATE);
    assert_string_equal(settings.scene_kind, "office");
    assert_int_equal(settings.office.rooms, 3);
    assert_true(settings.office.seed == 11);
    assert_string_equal(settings.output, "a.obj");
    assert_int_equal(settings.quiet, 1);
    assert_int_equal(parse("generate", "office", NULL), CLI_RUN);
    assert_string_equal(settings.output, "office.obj");
    assert_int_equal(settings.office.rooms, 0); /* the library's default */
    assert_int_equal(parse("generate", "office", "--rooms", "100001", NULL), CLI_USAGE_ERROR);
    assert_string_equal(err, "--rooms: expected an integer in [1, 100000], got '100001'");
    assert_int_equal(parse("generate", "house", NULL), CLI_USAGE_ERROR);
    assert_string_equal(err, "unknown scene kind 'house' (known: office)");
    assert_int_equal(parse("generate", NULL), CLI_USAGE_ERROR);
    assert_string_equal(err, "no scene kind given (known: office)");
    assert_int_equal(parse("generate", "office", "--width", "4", NULL), CLI_USAGE_ERROR);
    assert_string_equal(err, "--width does not apply to generate");
    assert_int_equal(parse("generate", "office", "-o", "", NULL), CLI_USAGE_ERROR);
    assert_int_equal(parse("generate", "--help", NULL), CLI_HELP);
    assert_int_equal(settings.command, CLI_GENERATE);
    /* The defaults of the other commands' outputs come from the table too. */
    assert_int_equal(parse("render", NULL), CLI_RUN);
    assert_string_equal(settings.output, "radiosity.png");
    assert_int_equal(parse("viewfactors", NULL), CLI_RUN);
    assert_string_equal(settings.output, "viewfactors.json");
    assert_int_equal(parse("--rooms", "3", NULL), CLI_USAGE_ERROR);
    assert_string_equal(err, "--rooms needs a command: render, solve, viewfactors, export, bake, thermal, generate "
                             "or view");
}

/* ---- --help, the man page, the messages ---- */

static char *capture_help(int command)
{
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    assert_non_null(f);
    if (command >= 0)
        cli_print_help(f, command);
    else
        cli_print_man(f);
    fclose(f);
    return text;
}

/* Some line of `text` holds both needles. */
static int line_with(const char *text, const char *a, const char *b)
{
    for (const char *line = text; *line;) {
        const char *end = strchr(line, '\n');
        size_t n = end ? (size_t)(end - line) : strlen(line);
        char buf[2048];
        snprintf(buf, sizeof buf, "%.*s", (int)n, line);
        if (strstr(buf, a) && (!b || strstr(buf, b)))
            return 1;
        line += n + (end ? 1 : 0);
    }
    return 0;
}

static void test_help_lists_every_flag_with_default(void **state)
{
    (void)state;
    const int commands[] = {0, CLI_RENDER, CLI_VIEWFACTORS, CLI_EXPORT, CLI_GENERATE};
    for (size_t c = 0; c < 5; c++) {
        char *help = capture_help(commands[c]);
        for (size_t k = 0; cli_flag_get(k); k++) {
            const cli_flag *f = cli_flag_get(k);
            if (commands[c] && !(f->commands & commands[c]))
                continue;
            if (commands[c] && f->target == CLI_TO_ACTION && f->action != CLI_HELP)
                continue;
            const rad_option_info *o = cli_flag_info(f);
            char flag[64], deflt[300];
            snprintf(flag, sizeof flag, "--%s%s%s", f->name, f->metavar ? " " : "", f->metavar ? f->metavar : "");
            snprintf(deflt, sizeof deflt, "default %s", o->default_text ? o->default_text : "");
            if (!line_with(help, flag, f->metavar && o->default_text ? deflt : NULL))
                fail_msg("help of command %d lacks '%s' with '%s'", commands[c], flag, deflt);
        }
        if (commands[c] == CLI_GENERATE)
            assert_null(strstr(help, "--solver"));
        free(help);
    }
}

/* roff escapes '-' as "\-". */
static void roff_escaped(const char *text, char *out, size_t size)
{
    size_t n = 0;
    for (; *text && n + 3 < size; text++) {
        if (*text == '-')
            out[n++] = '\\';
        out[n++] = *text;
    }
    out[n] = '\0';
}

static void test_man_page_has_every_flag(void **state)
{
    (void)state;
    char *man = capture_help(-1);
    const char *sections[] = {".TH RADIOSITY 1", ".SH NAME", ".SH SYNOPSIS", ".SH DESCRIPTION",
                              ".SH COMMANDS", ".SH OPTIONS", ".SS render", ".SS viewfactors",
                              ".SS generate", ".SH EXIT STATUS", ".SH FILES", ".SH UNITS", ".SH SEE ALSO"};
    for (size_t i = 0; i < sizeof sections / sizeof sections[0]; i++)
        if (!strstr(man, sections[i]))
            fail_msg("man page lacks %s", sections[i]);
    for (size_t k = 0; cli_flag_get(k); k++) {
        const cli_flag *f = cli_flag_get(k);
        const rad_option_info *o = cli_flag_info(f);
        char flag[700], escaped[600], deflt[300];
        roff_escaped(f->name, escaped, sizeof escaped);
        snprintf(flag, sizeof flag, "\\fB\\-\\-%s", escaped);
        snprintf(deflt, sizeof deflt, "default %s", o->default_text ? o->default_text : "");
        roff_escaped(deflt, escaped, sizeof escaped);
        if (!strstr(man, flag))
            fail_msg("man page lacks %s", flag);
        if (f->metavar && o->default_text && !strstr(man, escaped))
            fail_msg("man page lacks '%s'", escaped);
    }
    /* Every line that starts with a dot is a request we meant. */
    const char *requests[] = {".TH ", ".SH ", ".SS ", ".TP", ".PP", ".br", ".B ", ".nh", ".ad l"};
    for (const char *line = man; *line; line = strchr(line, '\n') ? strchr(line, '\n') + 1 : line + strlen(line)) {
        if (*line != '.')
            continue;
        int known = 0;
        for (size_t i = 0; i < sizeof requests / sizeof requests[0]; i++)
            known |= strncmp(line, requests[i], strlen(requests[i])) == 0;
        if (!known)
            fail_msg("unexpected roff request: %.40s", line);
    }
    free(man);
}

static void test_messages_name_flags(void **state)
{
    (void)state;
    char out[512];
    cli_rewrite_message("form factors: above the memory limit of 1 GiB (rad_options.max_memory_bytes); "
                        "use a smaller rad_options.hemicube_resolution or fewer threads",
                        out, sizeof out);
    assert_string_equal(out, "form factors: above the memory limit of 1 GiB (--max-memory); "
                             "use a smaller --hemicube-res or fewer threads");
    cli_rewrite_message("rad_options.samples, rad_render_options.samples, rad_office_options.rooms must",
                        out, sizeof out);
    assert_string_equal(out, "--ff-samples, --samples, --rooms must");
    /* A field without a flag, and a longer name, stay as they are. */
    cli_rewrite_message("rad_options.crease_angle_degrees rad_options.samples_x", out, sizeof out);
    assert_string_equal(out, "rad_options.crease_angle_degrees rad_options.samples_x");
    cli_rewrite_message("use rad_options.max_memory_bytes", out, 10);
    assert_string_equal(out, "use --max");
    /* The library's registries speak of fields, never of flags. */
    for (int kind = 0; kind < 3; kind++) {
        const char *name, *description;
        for (size_t i = 0; rad_method_info((rad_method_kind)kind, i, &name, &description); i++)
            assert_null(strstr(description, "--"));
    }
}

static int setup(void **state)
{
    (void)state;
    return rad_context_create(NULL, &ctx) == RAD_OK ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    rad_context_destroy(ctx);
    return 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rows_are_sound),
        cmocka_unit_test(test_range_text),
        cmocka_unit_test(test_library_refuses_out_of_range),
        cmocka_unit_test(test_render_and_office_checks_match_rows),
        cmocka_unit_test(test_flags_map_to_library_rows),
        cmocka_unit_test(test_flags_accept_bounds_and_refuse_beyond),
        cmocka_unit_test(test_words_and_methods),
        cmocka_unit_test(test_seed_is_exact),
        cmocka_unit_test(test_generate_takes_the_shared_parser),
        cmocka_unit_test(test_help_lists_every_flag_with_default),
        cmocka_unit_test(test_man_page_has_every_flag),
        cmocka_unit_test(test_messages_name_flags),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
