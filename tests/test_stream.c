/*
 * test_stream.c -- view factors in row blocks (rad_scene_stream_view_factors)
 * against the dense matrix, through include/radiosity.h only:
 *
 *   identity      every streamed format (surface .json/.csv/.mtx, element
 *                 .csv/.mtx) is byte for byte the dense writer's file, for
 *                 blocks of 1, 7 and n rows, with the pair methods
 *                 (analytic, hybrid) and a sampled row method kept raw
 *                 (hemicube); the pair counts are the dense loop's, plus
 *                 the pairs evaluated again (none for one block of n)
 *   diagnostics   row sums, F_ii and reciprocity from the stream equal the
 *                 dense run's, and rows of the closed Cornell box sum to 1
 *   memory        a limit below the dense matrix streams automatically
 *                 (only_if_needed) where the dense route fails; above it
 *                 nothing is streamed, not even refused; what cannot
 *                 stream is refused only where the stream is needed
 *   refusals      the balance step, the closure correction, adaptive
 *                 subdivision and element-level JSON: refused, no file
 *   cancellation  cancelled mid-stream: interrupted, no output, no
 *                 temporary left
 *   ranks         two and three "ranks" (threads exchanging blocks over
 *                 pipes, as the MPI program does with messages) write the
 *                 single process's bytes
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "test_support.h"

#include <dirent.h>
#include <math.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "radiosity.h"

static rad_context *ctx;
static rad_scene *box;
static char folder[64];

static int setup(void **state)
{
    (void)state;
    rad_context_options co = {0};
    co.threads = 2;
    if (rad_context_create(&co, &ctx) != RAD_OK || rad_scene_create_cornell_box(ctx, &box) != RAD_OK)
        return -1;
    snprintf(folder, sizeof folder, "/tmp/test_stream.XXXXXX");
    return mkdtemp(folder) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    DIR *d = opendir(folder);
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (e->d_name[0] != '.' || (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))) {
            char path[512];
            snprintf(path, sizeof path, "%s/%s", folder, e->d_name);
            unlink(path);
        }
    if (d)
        closedir(d);
    rmdir(folder);
    rad_scene_destroy(box);
    rad_context_destroy(ctx);
    return 0;
}

static const char *in_folder(const char *name)
{
    static char path[4][512];
    static int next;
    next = (next + 1) % 4;
    snprintf(path[next], sizeof path[next], "%s/%s", folder, name);
    return path[next];
}

static void assert_same_file(const char *a, const char *b)
{
    size_t na, nb;
    char *ta = test_read_file(a, &na), *tb = test_read_file(b, &nb);
    if (na != nb || memcmp(ta, tb, na) != 0) {
        size_t k = 0;
        while (k < na && k < nb && ta[k] == tb[k])
            k++;
        fail_msg("%s and %s differ at byte %zu (%zu and %zu bytes)", a, b, k, na, nb);
    }
    free(ta);
    free(tb);
}

/* Files in the folder whose names begin with '.' (the writers' temporaries). */
static int temporaries(void)
{
    int count = 0;
    DIR *d = opendir(folder);
    struct dirent *e;
    while (d && (e = readdir(d)))
        count += e->d_name[0] == '.' && strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    if (d)
        closedir(d);
    return count;
}

static rad_options box_options(const char *method, size_t elements)
{
    rad_options o = {0};
    o.form_factors = method;
    o.target_elements = elements;
    o.solver = "gauss-seidel"; /* the dense strategy: it keeps F */
    return o;
}

static const char *const formats[][2] = {
    {"surface", "json"}, {"surface", "csv"}, {"surface", "mtx"}, {"element", "csv"}, {"element", "mtx"},
};

/* Dense files for every format into "dense.<level>.<ext>"; its F stats. */
static rad_solution *write_dense(const rad_options *o, const char *tag)
{
    rad_solution *sol = NULL;
    assert_int_equal(rad_solution_create(ctx, box, o, &sol), RAD_OK);
    for (size_t f = 0; f < sizeof formats / sizeof *formats; f++) {
        char name[64];
        snprintf(name, sizeof name, "dense.%s.%s.%s", tag, formats[f][0], formats[f][1]);
        assert_int_equal(rad_solution_write_view_factors(ctx, sol, in_folder(name), formats[f][0][0] == 'e'),
                         RAD_OK);
    }
    return sol;
}

/* Every format streamed in blocks of `rows`, each the dense file. */
static void stream_all(const rad_options *o, const char *tag, size_t rows, const rad_stream_ranks *ranks,
                       rad_stream_stats *last)
{
    for (size_t f = 0; f < sizeof formats / sizeof *formats; f++) {
        char name[64], dense[64];
        snprintf(name, sizeof name, "stream.%s.%s", formats[f][0], formats[f][1]);
        snprintf(dense, sizeof dense, "dense.%s.%s.%s", tag, formats[f][0], formats[f][1]);
        rad_stream_options so = {rows, formats[f][0][0] == 'e', 0, ranks, NULL};
        rad_stream_stats st;
        rad_result r = rad_scene_stream_view_factors(ctx, box, o, &so, in_folder(name), &st);
        assert_int_equal(r, RAD_OK);
        assert_int_equal(st.streamed, 1);
        assert_same_file(in_folder(name), in_folder(dense));
        *last = st;
    }
    assert_int_equal(temporaries(), 0);
}

/* The dense run's form-factor diagnostics, from its stats file. */
typedef struct dense_ff {
    double row_sum_min, row_sum_max, row_sum_mean, diagonal_max, reciprocity_max, pairs;
} dense_ff;

static dense_ff dense_stats(rad_solution *sol)
{
    assert_int_equal(rad_solution_write_stats(ctx, sol, in_folder("dense.stats.json"), false), RAD_OK);
    size_t size;
    char *text = test_read_file(in_folder("dense.stats.json"), &size);
    cJSON *root = cJSON_Parse(text);
    free(text);
    cJSON *ff = cJSON_GetObjectItem(root, "form_factors");
    assert_non_null(ff);
    dense_ff d = {
        cJSON_GetObjectItem(ff, "row_sum_min")->valuedouble,  cJSON_GetObjectItem(ff, "row_sum_max")->valuedouble,
        cJSON_GetObjectItem(ff, "row_sum_mean")->valuedouble, cJSON_GetObjectItem(ff, "diagonal_max")->valuedouble,
        cJSON_GetObjectItem(ff, "reciprocity_max")->valuedouble, cJSON_GetObjectItem(ff, "pairs")->valuedouble,
    };
    cJSON_Delete(root);
    unlink(in_folder("dense.stats.json"));
    return d;
}

static void check_identity(const char *method, int raw)
{
    rad_options o = box_options(method, 100);
    o.raw_form_factors = raw;
    o.hemicube_resolution = 64; /* hemicube: a coarse one is as good a test, and quick */
    rad_solution *sol = write_dense(&o, method);
    size_t n = rad_solution_element_count(sol);
    assert_true(n > 60);
    dense_ff dense = dense_stats(sol);
    size_t sizes[] = {1, 7, n};
    for (size_t k = 0; k < 3; k++) {
        rad_stream_stats st;
        stream_all(&o, method, sizes[k], NULL, &st);
        assert_int_equal(st.elements, n);
        assert_int_equal(st.block_rows, sizes[k]);
        assert_int_equal(st.blocks, (n + sizes[k] - 1) / sizes[k]);
        /* The diagnostics are the dense matrix's, bit for bit. */
        assert_true(st.row_sum_min == dense.row_sum_min);
        assert_true(st.row_sum_max == dense.row_sum_max);
        assert_true(st.diagonal_max == dense.diagonal_max);
        assert_true(fabs(st.row_sum_mean - dense.row_sum_mean) < 1e-14);
        if (strcmp(method, "hemicube") != 0) {
            /* Pair methods: every pair's reciprocity, as dense measures it. */
            assert_true(st.reciprocity_max == dense.reciprocity_max);
            assert_true((double)st.pairs == dense.pairs);
            /* Blocks of one row: every pair again; of n rows: none. */
            if (sizes[k] == n)
                assert_int_equal(st.pairs_again, 0);
            else if (sizes[k] == 1)
                assert_int_equal(st.pairs_again, st.pairs);
            else
                assert_true(st.pairs_again > st.pairs / 2 && st.pairs_again < st.pairs);
        }
        /* The closed box: a wall's row sees the whole enclosure, 1 (a
         * raw estimate within its sampling error); the blocks' bottoms,
         * on the floor, nothing. */
        double slack = raw ? 0.05 : 0.02;
        assert_true(fabs(st.row_sum_max - 1.0) < slack && st.row_sum_min == 0.0);
    }
    rad_solution_destroy(sol);
}

static void test_identity_analytic(void **state)
{
    (void)state;
    check_identity("analytic", 0);
}

static void test_identity_hybrid(void **state)
{
    (void)state;
    check_identity("hybrid", 0);
}

static void test_identity_hemicube_raw(void **state)
{
    (void)state;
    check_identity("hemicube", 1);
}

/* A limit below the dense matrix: the dense route fails, the stream runs in
 * blocks within the limit and writes the dense file.  Above: not streamed. */
static void test_memory_limit(void **state)
{
    (void)state;
    rad_options o = box_options("analytic", 300);
    rad_solution *sol = write_dense(&o, "limit");
    size_t n = rad_solution_element_count(sol);
    rad_solution_destroy(sol);
    rad_options tight = o;
    tight.max_memory_bytes = 8.0 * (double)n * (double)n * 0.75; /* 3/4 of F: the mesh fits beside blocks */
    assert_int_equal(rad_solution_create(ctx, box, &tight, &sol), RAD_ERROR_OUT_OF_MEMORY);
    rad_stream_options so = {0, 1, 1, NULL, NULL};
    rad_stream_stats st;
    assert_int_equal(rad_scene_stream_view_factors(ctx, box, &tight, &so, in_folder("auto.mtx"), &st), RAD_OK);
    assert_int_equal(st.streamed, 1);
    assert_true(st.block_rows >= 1 && st.block_rows < n);
    assert_true(st.block_bytes <= tight.max_memory_bytes / 8.0 + 64);
    assert_same_file(in_folder("auto.mtx"), in_folder("dense.limit.element.mtx"));
    /* With room for the dense route: nothing written. */
    assert_int_equal(rad_scene_stream_view_factors(ctx, box, &o, &so, in_folder("none.mtx"), &st), RAD_OK);
    assert_int_equal(st.streamed, 0);
    assert_int_equal(access(in_folder("none.mtx"), F_OK), -1);
    /* What cannot stream is the dense route's where that fits, and refused,
     * saying why the stream was taken, where it does not. */
    rad_options sampled = o;
    sampled.form_factors = "hemicube";
    rad_stream_options json = {0, 1, 1, NULL, NULL};
    assert_int_equal(rad_scene_stream_view_factors(ctx, box, &sampled, &json, in_folder("e.json"), &st), RAD_OK);
    assert_int_equal(st.streamed, 0);
    sampled.max_memory_bytes = tight.max_memory_bytes;
    assert_int_equal(rad_scene_stream_view_factors(ctx, box, &sampled, &json, in_folder("e.json"), &st),
                     RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "element-level JSON"));
    assert_non_null(strstr(rad_context_error(ctx), "passes the memory limit"));
    assert_int_equal(access(in_folder("e.json"), F_OK), -1);
}

static void expect_refusal(const rad_options *o, int elements, const char *name, const char *words)
{
    rad_stream_options so = {4, elements, 0, NULL, NULL};
    rad_stream_stats st;
    assert_int_equal(rad_scene_stream_view_factors(ctx, box, o, &so, in_folder(name), &st),
                     RAD_ERROR_INVALID_ARGUMENT);
    if (!strstr(rad_context_error(ctx), words))
        fail_msg("'%s' does not say '%s'", rad_context_error(ctx), words);
    assert_int_equal(access(in_folder(name), F_OK), -1);
    assert_int_equal(temporaries(), 0);
}

static void test_refusals(void **state)
{
    (void)state;
    rad_options o = box_options("hemicube", 100);
    expect_refusal(&o, 0, "r1.json", "balance step");
    o = box_options("montecarlo", 100);
    expect_refusal(&o, 1, "r2.csv", "balance step");
    o = box_options("analytic", 100);
    o.closure_correction = 1;
    expect_refusal(&o, 0, "r3.json", "closure correction");
    o = box_options("analytic", 100);
    o.adaptive_levels = 1;
    expect_refusal(&o, 0, "r4.json", "adaptive");
    o = box_options("analytic", 100);
    expect_refusal(&o, 1, "r5.json", "element-level JSON");
    expect_refusal(&o, 0, "r6.txt", "unknown view-factor format");
}

/* Cancel once half the rows are out. */
static void cancel_halfway(void *user, const char *phase, uint64_t done, uint64_t total)
{
    (void)user;
    if (strcmp(phase, "form factors") == 0 && done > total / 2)
        rad_context_cancel(ctx, true);
}

static void test_cancellation(void **state)
{
    (void)state;
    rad_context_options co = {0};
    co.threads = 2;
    co.progress = cancel_halfway;
    rad_context *main_ctx = ctx;
    assert_int_equal(rad_context_create(&co, &ctx), RAD_OK);
    rad_options o = box_options("analytic", 200);
    const char *names[] = {"c.mtx", "c.csv", "c.json"};
    for (int k = 0; k < 3; k++) {
        rad_stream_options so = {8, k < 2, 0, NULL, NULL};
        rad_stream_stats st;
        rad_context_cancel(ctx, false);
        assert_int_equal(rad_scene_stream_view_factors(ctx, box, &o, &so, in_folder(names[k]), &st),
                         RAD_ERROR_INTERRUPTED);
        assert_true(st.blocks > 0 && st.blocks < (st.elements + 7) / 8);
        assert_int_equal(access(in_folder(names[k]), F_OK), -1);
        assert_int_equal(temporaries(), 0);
    }
    rad_context_destroy(ctx);
    ctx = main_ctx;
}

/* ---- ranks as threads: rank k sends its blocks down pipe[k] ---- */

typedef struct fake_ranks {
    int pipe[4][2];
} fake_ranks;

static int pipe_send(void *user, const double *data, size_t count)
{
    int *fd = user;
    const char *p = (const char *)data;
    size_t left = count * sizeof *data;
    while (left) {
        ssize_t w = write(*fd, p, left);
        if (w <= 0)
            return 1;
        p += w;
        left -= (size_t)w;
    }
    return 0;
}

static int pipe_receive(void *user, int from, double *data, size_t count)
{
    fake_ranks *fr = user;
    char *p = (char *)data;
    size_t left = count * sizeof *data;
    while (left) {
        ssize_t got = read(fr->pipe[from][0], p, left);
        if (got <= 0)
            return 1;
        p += got;
        left -= (size_t)got;
    }
    return 0;
}

typedef struct rank_job {
    rad_stream_ranks ranks;
    rad_options options;
    int elements;
    rad_result result;
} rank_job;

static void *run_rank(void *arg)
{
    rank_job *job = arg;
    rad_context_options co = {0};
    co.threads = 1;
    rad_context *own = NULL;
    job->result = rad_context_create(&co, &own);
    rad_stream_options so = {5, job->elements, 0, &job->ranks, NULL};
    rad_stream_stats st;
    if (job->result == RAD_OK)
        job->result = rad_scene_stream_view_factors(own, box, &job->options, &so, NULL, &st);
    rad_context_destroy(own);
    return NULL;
}

static void check_ranks(int size)
{
    rad_options o = box_options("analytic", 120);
    rad_solution *sol = write_dense(&o, "ranks");
    rad_solution_destroy(sol);
    for (int level = 0; level < 2; level++) {
        fake_ranks fr;
        pthread_t thread[4];
        rank_job job[4];
        for (int k = 1; k < size; k++) {
            assert_int_equal(pipe(fr.pipe[k]), 0);
            job[k].ranks = (rad_stream_ranks){k, size, NULL, pipe_send, &fr.pipe[k][1]};
            job[k].options = o;
            job[k].elements = level;
            assert_int_equal(pthread_create(&thread[k], NULL, run_rank, &job[k]), 0);
        }
        rad_stream_ranks zero = {0, size, pipe_receive, NULL, &fr};
        rad_stream_options so = {5, level, 0, &zero, NULL};
        rad_stream_stats st;
        const char *name = level ? "ranks.mtx" : "ranks.json";
        assert_int_equal(rad_scene_stream_view_factors(ctx, box, &o, &so, in_folder(name), &st), RAD_OK);
        for (int k = 1; k < size; k++) {
            pthread_join(thread[k], NULL);
            assert_int_equal(job[k].result, RAD_OK);
            close(fr.pipe[k][0]);
            close(fr.pipe[k][1]);
        }
        assert_int_equal(st.blocks, (st.elements + 4) / 5);
        assert_same_file(in_folder(name), in_folder(level ? "dense.ranks.element.mtx" : "dense.ranks.surface.json"));
    }
}

static void test_two_ranks(void **state)
{
    (void)state;
    check_ranks(2);
}

static void test_three_ranks(void **state)
{
    (void)state;
    check_ranks(3);
}

/* The surface level's thermal adjustments (smoothing, the sparse threshold)
 * and View3D's file go through the same writer from a stream: the dense
 * bytes (the closed Cornell box, smoothed as an enclosure). */
static void test_adjusted_surface_factors(void **state)
{
    (void)state;
    rad_options o = box_options("analytic", 120);
    rad_solution *sol = NULL;
    assert_int_equal(rad_solution_create(ctx, box, &o, &sol), RAD_OK);
    static const char *const ext[] = {"vf", "mtx", "json"};
    for (size_t k = 0; k < 3; k++) {
        rad_smooth_report dense_report = {0}, stream_report = {0};
        rad_view_factor_options vo = {0};
        vo.smooth = RAD_SMOOTH_ENCLOSURE;
        vo.sparse_threshold = k == 1 ? 1e-3 : 0.0;
        vo.report = &dense_report;
        char dense[64], name[64];
        snprintf(dense, sizeof dense, "dense.adjusted.%s", ext[k]);
        snprintf(name, sizeof name, "stream.adjusted.%s", ext[k]);
        assert_int_equal(rad_solution_write_view_factors_with(ctx, sol, in_folder(dense), &vo), RAD_OK);
        vo.report = &stream_report;
        rad_stream_options so = {7, 0, 0, NULL, &vo};
        rad_stream_stats st;
        assert_int_equal(rad_scene_stream_view_factors(ctx, box, &o, &so, in_folder(name), &st), RAD_OK);
        assert_int_equal(st.streamed, 1);
        assert_same_file(in_folder(name), in_folder(dense));
        /* The smoothing ran on both routes and closed the rows. */
        assert_true(stream_report.row_error_before > 1e-9);
        assert_true(stream_report.row_error_after < 1e-12);
        assert_true(stream_report.row_error_before == dense_report.row_error_before);
    }
    /* Element rows are written as computed: no smoothing there. */
    rad_view_factor_options vo = {0};
    vo.smooth = RAD_SMOOTH_ENCLOSURE;
    rad_stream_options so = {7, 1, 0, NULL, &vo};
    rad_stream_stats st;
    assert_int_equal(rad_scene_stream_view_factors(ctx, box, &o, &so, in_folder("stream.smooth.mtx"), &st),
                     RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(access(in_folder("stream.smooth.mtx"), F_OK), -1);
    rad_solution_destroy(sol);
    assert_int_equal(temporaries(), 0);
}

int main(int argc, char **argv)
{
    /* "--slow": the cases at scale instead of the quick ones. */
    bool slow = argc == 2 && strcmp(argv[1], "--slow") == 0;
    if (argc > 2 || (argc == 2 && !slow)) {
        fprintf(stderr, "usage: test_stream [--slow]\n");
        return 2;
    }
    const struct CMUnitTest fast_tests[] = {
        cmocka_unit_test(test_identity_hybrid),
        cmocka_unit_test(test_memory_limit),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_cancellation),
        cmocka_unit_test(test_two_ranks),
        cmocka_unit_test(test_three_ranks),
        cmocka_unit_test(test_adjusted_surface_factors),
    };
    /* At scale: with --slow alone (CTest: test_stream_slow, label slow). */
    const struct CMUnitTest slow_tests[] = {
        cmocka_unit_test(test_identity_analytic),
        cmocka_unit_test(test_identity_hemicube_raw),
    };
    return slow ? cmocka_run_group_tests_name("stream_slow", slow_tests, setup, teardown)
                : cmocka_run_group_tests_name("stream", fast_tests, setup, teardown);
}
