/*
 * cmd_viewfactors.c -- `radiosity viewfactors [SCENE]`: the view factors
 * between the scene's named surfaces (or its elements, --level element)
 * as JSON, CSV, Matrix Market or View3D's .vf (docs/formats.md); no solve.
 *
 * The dense matrix is made when it fits the memory limit.  Otherwise, or
 * when asked (--block-rows, mpirun), the rows are streamed in blocks
 * (rad_scene_stream_view_factors): each rank above 0 makes its blocks and
 * sends them to rank 0, which alone writes.
 */
#include "cli.h"

#include <limits.h>
#include <stdio.h>
#include <string.h>

/* What the flags ask of the file (--level, --smooth, --sparse-threshold),
 * and what it took. */
typedef struct factor_report {
    rad_smooth_report smoothing; /* row_error_before stays negative when no smoothing ran */
    size_t nonzeros;
    double dropped;
} factor_report;

static rad_view_factor_options factor_options(const cli_settings *s, factor_report *rep)
{
    memset(rep, 0, sizeof *rep);
    rep->smoothing.row_error_before = -1.0;
    rad_view_factor_options vo = {0};
    vo.elements = s->element_level != 0;
    vo.smooth = (rad_smoothing)s->smooth;
    vo.sparse_threshold = s->sparse_threshold;
    vo.report = &rep->smoothing;
    vo.nonzeros = &rep->nonzeros;
    vo.dropped = &rep->dropped;
    return vo;
}

static void print_factor_report(const cli_settings *s, const factor_report *rep)
{
    const rad_smooth_report *m = &rep->smoothing;
    if (s->quiet)
        return;
    if (m->row_error_before >= 0.0)
        printf("smoothing: max |row sum - target| %.3g -> %.3g, max reciprocity error %.3g -> %.3g, "
               "change max %.3g rms %.3g (relative)%s\n",
               m->row_error_before, m->row_error_after, m->reciprocity_before, m->reciprocity_after,
               m->max_relative_change, m->rms_relative_change, m->clamped ? ", some factors held at 0" : "");
    if (s->sparse_threshold > 0.0)
        printf("sparse: %zu non-zeros, at most %.3g of a row's factors dropped and rebalanced\n", rep->nonzeros,
               rep->dropped);
}

/* Ranks above 0: load the scene, make their blocks, send them to rank 0. */
static int stream_rank(cli_job *job)
{
    const cli_settings *s = &job->s;
    rad_scene *scene = NULL;
    rad_result r = cli_read_scene(job->ctx, s, &scene);
    rad_stream_options so = {s->block_rows, s->element_level, 0, job->ranks, NULL};
    rad_stream_stats st;
    if (r == RAD_OK)
        r = rad_scene_stream_view_factors(job->ctx, scene, &s->solve, &so, NULL, &st);
    rad_scene_destroy(scene);
    if (r == RAD_ERROR_INTERRUPTED)
        return cli_interrupted_status();
    return r == RAD_OK ? 0 : cli_fail(job->ctx, r);
}

/* 2-3'. rank 0 (or the only process): stream when asked (--block-rows,
 * several ranks) or when the dense matrix would pass the memory limit.
 * Returns -1 when the dense route is to be taken, else the exit status. */
static int stream_view_factors(cli_job *job)
{
    const cli_settings *s = &job->s;
    const rad_stream_ranks *ranks = job->ranks;
    bool forced = s->block_rows > 0 || ranks->size > 1;
    if (!forced && s->stats)
        return -1; /* the stats file describes a solution: the dense route */
    if (forced && s->stats) {
        fprintf(stderr, "radiosity: --stats: view factors in row blocks (--block-rows, mpirun) write no stats "
                        "file; their diagnostics are printed\n");
        return EXIT_USAGE;
    }
    factor_report rep;
    rad_view_factor_options vo = factor_options(s, &rep);
    rad_stream_options so = {s->block_rows, s->element_level, !forced, ranks->size > 1 ? ranks : NULL, &vo};
    rad_stream_stats st;
    rad_result r = rad_scene_stream_view_factors(job->ctx, job->scene, &s->solve, &so, job->out.main, &st);
    cli_progress_end(&job->progress);
    if (r == RAD_OK && !st.streamed)
        return -1;
    if (r == RAD_ERROR_INTERRUPTED) {
        fprintf(stderr, "radiosity: interrupted while computing form factors; nothing written\n");
        return cli_interrupted_status();
    }
    cli_begin_saving(job->ctx);
    if (r == RAD_OK)
        r = rad_output_set_commit(job->ctx, job->out.set);
    if (r != RAD_OK)
        return cli_fail(job->ctx, r);
    print_factor_report(s, &rep);
    char full[PATH_MAX];
    if (!s->quiet)
        printf("wrote %s (%zu surfaces, %zu elements in %zu block%s of %zu rows on %d process%s; row sums "
               "%.6g to %.6g, reciprocity %.2g; %.1f s)\n",
               cli_where(s->output, full), rad_scene_surface_count(job->scene), st.elements, st.blocks,
               st.blocks == 1 ? "" : "s", st.block_rows, ranks->size, ranks->size == 1 ? "" : "es",
               st.row_sum_min, st.row_sum_max, st.reciprocity_max, cli_now() - job->t0);
    return cli_status(0);
}

int cmd_viewfactors(cli_job *job)
{
    const cli_settings *s = &job->s;
    if (job->ranks->rank > 0)
        return stream_rank(job);
    /* Adjustments that cannot apply are refused before the work. */
    const char *dot = strrchr(s->output, '.');
    bool vf = dot && strcmp(dot, ".vf") == 0, mtx = dot && strcmp(dot, ".mtx") == 0;
    if (s->element_level && (s->smooth || s->sparse_threshold > 0.0 || vf)) {
        fprintf(stderr, "radiosity: --level element: element factors are written as computed; --smooth, "
                        "--sparse-threshold and .vf files are for surface-level factors\n");
        return EXIT_USAGE;
    }
    if (s->sparse_threshold > 0.0 && !mtx) {
        fprintf(stderr, "radiosity: --sparse-threshold: the output must be Matrix Market (-o F.mtx)\n");
        return EXIT_USAGE;
    }
    int status = cli_load(job);
    if (status < 0)
        status = stream_view_factors(job);
    if (status < 0)
        status = cli_couple(job);
    if (status >= 0)
        return status;

    /* 5. the dense matrix's factors */
    cli_begin_saving(job->ctx);
    factor_report rep;
    rad_view_factor_options vo = factor_options(s, &rep);
    rad_result r = rad_solution_write_view_factors_with(job->ctx, job->sol, job->out.main, &vo);
    if (r == RAD_OK)
        print_factor_report(s, &rep);
    r = cli_write_records(job, r);
    if (r == RAD_OK)
        r = rad_output_set_commit(job->ctx, job->out.set);
    if (r != RAD_OK)
        return cli_fail(job->ctx, r);
    char full[PATH_MAX];
    if (!s->quiet)
        printf("wrote %s (%zu surfaces, %zu elements, %.2f s)\n", cli_where(s->output, full),
               rad_scene_surface_count(job->scene), rad_solution_element_count(job->sol), cli_now() - job->t0);
    return cli_status(0);
}
