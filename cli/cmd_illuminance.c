/*
 * cmd_illuminance.c -- `radiosity illuminance [SCENE|SOLUTION.radsol]
 * --grid G.json`: solve the scene (or load the solution), then the
 * illuminance in lux at the grid file's calculation points, direct and
 * indirect, with Eavg, Emin, Emax and U0 per grid (docs/lighting.md).
 *
 * -o takes a .csv (a row per point), a .json (per grid), or a .png, which
 * stands for one plan per grid (FILE_GRID.png, coloured and labelled in
 * lux); given twice, both.  The grid file is read once before the solve,
 * so a bad one costs nothing, and again against the solution.
 */
#include "cli.h"

#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

int cmd_illuminance_check(const cli_settings *s, char *err, size_t err_size)
{
    if (s->grid)
        return 0;
    snprintf(err, err_size, "illuminance needs --grid FILE.json: the calculation grids and points");
    return 1;
}

static bool is_plan(const char *given)
{
    const char *dot = given ? strrchr(given, '.') : NULL;
    return dot && strcasecmp(dot, ".png") == 0;
}

/* One of the outputs: the values (.csv, .json), or the grids' plans
 * (.png: the path given leaves the set, each grid's picture joins it). */
static rad_result write_output(cli_job *job, const rad_illuminance *il, const char *given, const char *temp,
                               const rad_false_colour_options *plots)
{
    if (!is_plan(given))
        return rad_illuminance_write(job->ctx, il, temp);
    rad_output_set_drop(job->out.set, given);
    return rad_illuminance_write_plots(job->ctx, il, plots, job->out.set, given);
}

/* 5'. the points evaluated, a summary line per grid, the values (and
 * stats, history) put in place together. */
static int write_illuminance(cli_job *job, const rad_false_colour_options *plots)
{
    const cli_settings *s = &job->s;
    rad_context *ctx = job->ctx;
    rad_illuminance *il = NULL;
    rad_result r = rad_illuminance_evaluate_file(ctx, job->sol, s->grid, &il);
    cli_progress_end(&job->progress);
    if (r == RAD_ERROR_INTERRUPTED) {
        fprintf(stderr, "radiosity: interrupted while computing the illuminance; nothing written\n");
        return cli_interrupted_status();
    }
    if (r != RAD_OK)
        return cli_fail(ctx, r);
    cli_begin_saving(ctx);
    r = write_output(job, il, s->output, job->out.main, plots);
    if (r == RAD_OK && job->out.second)
        r = write_output(job, il, s->output2, job->out.second, plots);
    r = cli_write_records(job, r);
    if (r == RAD_OK && !s->quiet) {
        printf("%-24s %8s %12s %12s %12s %7s\n", "grid", "points", "Eavg lux", "Emin lux", "Emax lux", "U0");
        for (size_t g = 0; g < rad_illuminance_grid_count(il); g++) {
            const rad_grid_result *res = rad_illuminance_grid(il, g);
            printf("%-24.24s %8zu %12.1f %12.1f %12.1f %7.3f\n", res->name, res->point_count, res->average,
                   res->minimum, res->maximum, res->uniformity);
        }
    }
    r = cli_commit(job, r);
    if (r != RAD_OK) {
        rad_illuminance_destroy(il);
        return cli_fail(ctx, r);
    }
    rad_illuminance_stats st;
    rad_illuminance_get_stats(il, &st);
    for (int k = 0; k < 2 && !s->quiet; k++) { /* the plans, by name */
        const char *given = k ? s->output2 : s->output;
        for (size_t g = 0; is_plan(given) && g < rad_illuminance_grid_count(il); g++) {
            char name[PATH_MAX];
            if (rad_illuminance_grid(il, g)->point_count &&
                rad_illuminance_plot_path(il, given, g, name, sizeof name) < sizeof name)
                printf("wrote %s\n", name);
        }
    }
    rad_illuminance_destroy(il);
    char full[PATH_MAX];
    /* The value files by name (the plans were named above). */
    const char *files[2] = {NULL, NULL};
    int nfiles = 0;
    for (int k = 0; k < 2; k++) {
        const char *given = k ? s->output2 : s->output;
        if (given && !is_plan(given))
            files[nfiles++] = k ? given : cli_where(given, full);
    }
    if (!s->quiet)
        printf("wrote %s%s%s (%zu points in %.2f s, %.0f points/s; %zu elements, %.1f s)\n",
               nfiles ? files[0] : "the plans", nfiles > 1 ? " and " : "", nfiles > 1 ? files[1] : "", st.points,
               st.seconds, st.points_per_second, rad_solution_element_count(job->sol), cli_now() - job->t0);
    return cli_status(0);
}

int cmd_illuminance(cli_job *job)
{
    rad_false_colour_options plots;
    int status = cli_false_colour_options(job, &plots);
    if (status < 0)
        status = cli_load(job);
    if (status >= 0)
        return status;
    /* A bad grid file: before any work. */
    if (rad_illuminance_check_file(job->ctx, job->scene, job->s.grid, NULL) != RAD_OK)
        return cli_fail(job->ctx, RAD_ERROR_PARSE);
    status = cli_solve(job, "lighting");
    if (status >= 0)
        return status;
    if (job->partial) {
        fprintf(stderr, "radiosity: interrupted while solving; no illuminance written\n");
        return cli_interrupted_status();
    }
    return write_illuminance(job, &plots);
}
