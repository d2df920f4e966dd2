/*
 * test_defaults.c -- the default `radiosity render` of the built-in Cornell
 * box against the converged answer.
 *
 * tests/data/cornell_converged.json holds the area-mean radiosity (RGB) of
 * every named surface in the limit of zero element size: a sequence of
 * uniform meshes extrapolated by Richardson's rule (B(h) = B0 + c h^p, p
 * fitted per surface and channel; docs/testing.md gives the command that
 * remakes it, bench/cornell_reference.sh).  The promise tested here is
 * issue 15's: the program's defaults, whatever they are (solver, mesh,
 * oracle, tolerances), give every surface within 1% of that limit in each
 * channel.  The image size does not enter the solution, so the run draws
 * a small one.
 *
 * So that the comparison is known to bite, a deliberately coarse solution
 * (about 60 uniform elements) must miss the same bound.
 *
 * The path of the radiosity binary is argv[1].
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "cli_support.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* The bound of issue 15: each surface, each channel, within 1%. */
#define DEFAULTS_BOUND 0.01

/* The worst relative error, over every surface and channel of the
 * reference, of the solution `radiosity render ARGS` reports in its stats;
 * its name and channel in *where. */
static double worst_error(const char *args, char *where, size_t where_size)
{
    char stats_path[600], png[600], ref_path[600];
    snprintf(stats_path, sizeof stats_path, "%s/stats.json", test_workdir());
    snprintf(png, sizeof png, "%s/box.png", test_workdir());
    snprintf(ref_path, sizeof ref_path, "%s/cornell_converged.json", RAD_TEST_DATA);
    assert_int_equal(cli_run("render -o '%s' --stats '%s' --width 32 --height 32 %s", png, stats_path, args), 0);
    cJSON *stats = cli_read_json(stats_path), *ref = cli_read_json(ref_path);
    assert_non_null(stats);
    assert_non_null(ref);
    const cJSON *surfaces = cJSON_GetObjectItem(ref, "surfaces");
    assert_true(cJSON_GetArraySize(surfaces) == 8); /* the box's 8 named surfaces */
    double worst = 0.0;
    const cJSON *s;
    cJSON_ArrayForEach(s, surfaces)
    {
        const char *name = cJSON_GetObjectItem(s, "name")->valuestring;
        const cJSON *B0 = cJSON_GetObjectItem(s, "radiosity");
        assert_int_equal(cJSON_GetArraySize(B0), 3);
        double got[3];
        cli_stats_surface_radiosity(stats, name, got);
        for (int c = 0; c < 3; c++) {
            double exact = cJSON_GetArrayItem(B0, c)->valuedouble;
            assert_true(exact > 0.0); /* every surface reflects some of each channel */
            double e = fabs(got[c] / exact - 1.0);
            if (!(e <= worst)) {
                worst = e;
                snprintf(where, where_size, "%s channel %d: %.6g against %.6g", name, c, got[c], exact);
            }
        }
    }
    cJSON_Delete(stats);
    cJSON_Delete(ref);
    return worst;
}

static void test_defaults_within_one_percent(void **state)
{
    (void)state;
    char where[256] = "";
    double worst = worst_error("", where, sizeof where);
    printf("defaults: worst per-surface error %.3f%% (%s)\n", 100.0 * worst, where);
    assert_true(worst < DEFAULTS_BOUND);
}

/* The same comparison fails a coarse mesh: the bound means something. */
static void test_coarse_mesh_misses(void **state)
{
    (void)state;
    char where[256] = "";
    double worst = worst_error("--solver gauss-seidel --elements 60", where, sizeof where);
    printf("60 elements: worst per-surface error %.3f%% (%s)\n", 100.0 * worst, where);
    assert_true(worst > DEFAULTS_BOUND);
}

static int setup(void **state)
{
    (void)state;
    return cli_setup("defaults");
}

static int teardown(void **state)
{
    (void)state;
    return cli_teardown();
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_defaults PATH_TO_RADIOSITY\n");
        return 2;
    }
    cli_set_binary(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_within_one_percent),
        cmocka_unit_test(test_coarse_mesh_misses),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
