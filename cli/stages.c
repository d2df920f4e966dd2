/*
 * stages.c -- the stages of the pipeline every command walks (main.c has
 * the map): load the scene, mesh and couple it, solve, then write the
 * run's records and put the outputs in place, or say why not.
 */
#include "cli.h"
#include "options.h"
#include "radiosity.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

rad_result cli_read_scene(rad_context *ctx, const cli_settings *s, rad_scene **scene)
{
    rad_result r = s->scene_path ? rad_scene_load_file(ctx, s->scene_path, scene)
                                 : rad_scene_create_cornell_box(ctx, scene);
    if (r == RAD_OK && s->daylight && (r = rad_scene_daylight_load_file(ctx, *scene, s->daylight)) != RAD_OK) {
        rad_scene_destroy(*scene);
        *scene = NULL;
    }
    return r;
}

/* 1. load: a scene, or for CMD_SOLUTION_INPUT commands a solution file (by
 * its signature), which is solved already */
int cli_load(cli_job *job)
{
    const cli_settings *s = &job->s;
    rad_context *ctx = job->ctx;
    job->t0 = cli_now();
    job->saved = s->scene_path && rad_file_is_solution(s->scene_path);
    if (job->saved && !(job->command->flags & CMD_SOLUTION_INPUT)) {
        fprintf(stderr, "radiosity: %s is a solution file: `radiosity render` draws it and `radiosity "
                        "export` writes its lit mesh; %s needs the scene it was solved for\n",
                s->scene_path, job->command->name);
        return EXIT_USAGE;
    }
    if (job->saved && (s->history || s->progress_dir)) {
        fprintf(stderr, "radiosity: --%s: %s is a solution file, solved already: there is no solve to "
                        "follow\n", s->history ? "history" : "progress-images", s->scene_path);
        return EXIT_USAGE;
    }
    if (job->saved && s->daylight) {
        fprintf(stderr, "radiosity: --daylight: %s is a solution file, solved already with its own light\n",
                s->scene_path);
        return EXIT_USAGE;
    }
    rad_result r = job->saved ? rad_solution_load_file(ctx, s->scene_path, &job->scene, &job->sol)
                              : cli_read_scene(ctx, s, &job->scene);
    if (r != RAD_OK)
        return cli_fail(ctx, r);
    if (s->luminaires && job->saved) {
        fprintf(stderr, "radiosity: --luminaires: %s is a solution file, solved already (give the layout with "
                        "the scene)\n", s->scene_path);
        return EXIT_USAGE;
    }
    if (s->luminaires) {
        /* Luminaires placed by the layout (docs/lighting.md), before any work. */
        r = rad_scene_load_luminaires(ctx, job->scene, s->luminaires);
        if (r == RAD_OK)
            r = rad_output_set_add_input(ctx, job->out.set, s->luminaires);
        if (r != RAD_OK)
            return cli_fail(ctx, r);
    }
    /* Every file the loader read is an input no output may be. */
    for (size_t i = 0; i < rad_scene_input_count(job->scene); i++) {
        r = rad_output_set_add_input(ctx, job->out.set, rad_scene_input_path(job->scene, i));
        if (r != RAD_OK)
            return cli_fail_path(ctx, r);
    }
    return -1;
}

/* 2-3. mesh, visibility, form factors (a loaded solution has them) */
int cli_couple(cli_job *job)
{
    const cli_settings *s = &job->s;
    rad_context *ctx = job->ctx;
    rad_result r = job->saved ? RAD_OK : rad_solution_create(ctx, job->scene, &s->solve, &job->sol);
    cli_progress_end(&job->progress);
    if (r == RAD_ERROR_INTERRUPTED) {
        /* No radiosity yet, so no image: only the stats say what happened. */
        cli_begin_saving(ctx);
        rad_output_set_drop(job->out.set, s->output);
        rad_output_set_drop(job->out.set, s->history);
        int wrote = s->stats &&
                    rad_scene_write_interrupted_stats(ctx, job->scene, "form factors", cli_now() - job->t0,
                                                      job->out.stats) == RAD_OK &&
                    rad_output_set_commit(ctx, job->out.set) == RAD_OK;
        fprintf(stderr, "radiosity: interrupted while computing form factors; %s\n",
                wrote ? "wrote partial stats only" : "nothing written");
        return cli_interrupted_status();
    }
    return r == RAD_OK ? -1 : cli_fail(ctx, r);
}

/* Progressive display keeps one exposure for all frames (the user's, or
 * the first frame's automatic one), so the picture visibly brightens as
 * light is shot; with the ambient term the first frame is already close
 * to the final brightness.  Each frame is its own atomic file, written
 * during the solve (not part of the output set). */
static int on_step(void *user, rad_solution *solution, const rad_solve_step *step)
{
    cli_job *job = user;
    if (step->iteration % (job->s.every ? job->s.every : 1) != 0)
        return 0;
    if (job->frames >= CLI_MAX_PROGRESS_IMAGES) {
        if (job->frames++ == CLI_MAX_PROGRESS_IMAGES && !job->s.quiet)
            fprintf(stderr, "radiosity: --progress-images: %d frames written, the later steps are not drawn "
                            "(--every K draws every K-th)\n", CLI_MAX_PROGRESS_IMAGES);
        return 0;
    }
    rad_image *image = NULL;
    char path[4096];
    snprintf(path, sizeof path, "%s/step_%08d.png", job->s.progress_dir, step->iteration);
    rad_result r = rad_solution_render(job->ctx, solution, &job->s.render, &image);
    if (r == RAD_ERROR_INTERRUPTED) {
        rad_image_destroy(image); /* the interrupted render still hands back its image */
        return 1; /* a signal: the solve stops and its iterate is saved, frame or not */
    }
    if (r == RAD_OK && job->frame_exposure == 0.0)
        job->frame_exposure = rad_image_auto_exposure(image); /* fixed from the first frame on */
    if (r == RAD_OK)
        r = rad_image_write_exposed(job->ctx, image, path, job->frame_exposure);
    if (r == RAD_OK)
        job->frames++;
    rad_image_destroy(image);
    if (r != RAD_OK) {
        job->frame_failed = true;
        return 1; /* stop: the message is in the context */
    }
    return 0;
}

int cli_solve(cli_job *job, const char *verb)
{
    cli_settings *s = &job->s;
    rad_context *ctx = job->ctx;
    if (!s->quiet && !s->scene_path)
        printf("radiosity: no scene given, %s the built-in Cornell box\n", verb);
    if (s->progress_dir) {
        if (mkdir(s->progress_dir, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "radiosity: %s: cannot create directory: %s\n", s->progress_dir, strerror(errno));
            return 1;
        }
        job->frame_exposure = s->render.exposure;
        s->solve.on_step = on_step;
        s->solve.on_step_user = job;
    }
    int status = cli_couple(job);
    if (status >= 0)
        return status;

    /* 4. solve (a loaded solution is solved) */
    rad_result r = job->saved ? RAD_OK : rad_solution_solve(ctx, job->sol);
    cli_progress_end(&job->progress);
    if (job->frame_failed)
        return cli_fail(ctx, RAD_ERROR_IO);
    job->partial = r == RAD_ERROR_INTERRUPTED;
    if (r != RAD_OK && !job->partial)
        return cli_fail(ctx, r);
    if (job->partial)
        fprintf(stderr, "radiosity: interrupted while solving; writing the partial solution\n");
    else if (!s->quiet && !rad_solution_converged(job->sol)) {
        /* Every solver stops at its bound; the line says where and why. */
        char line[1024];
        const char *why = rad_solution_warning(job->sol);
        if (why[0])
            fprintf(stderr, "radiosity: warning: %s\n", cli_rewrite_message(why, line, sizeof line));
        else
            fprintf(stderr, "radiosity: warning: stopped unconverged after %d iterations\n",
                    rad_solution_iterations(job->sol));
    }
    return -1;
}

/* 5. the outputs: each command writes its own into its temporary, then
 * these put the set in place */

rad_result cli_write_records(cli_job *job, rad_result r)
{
    if (r == RAD_OK && job->s.stats)
        r = rad_solution_write_stats(job->ctx, job->sol, job->out.stats, job->partial);
    if (r == RAD_OK && job->s.history)
        r = rad_solution_write_history(job->ctx, job->sol, job->out.history);
    return r;
}

rad_result cli_commit(cli_job *job, rad_result r)
{
    if (r != RAD_OK)
        return r;
    fflush(stdout); /* what we printed comes before an output sent to stdout */
    return rad_output_set_commit(job->ctx, job->out.set);
}

int cli_finish(cli_job *job, rad_result r, const char *detail, ...)
{
    const cli_settings *s = &job->s;
    char what[512];
    va_list ap;
    va_start(ap, detail);
    vsnprintf(what, sizeof what, detail, ap);
    va_end(ap);
    r = cli_commit(job, cli_write_records(job, r));
    if (r != RAD_OK)
        return cli_fail(job->ctx, r);
    if (!s->quiet) {
        /* Matrix-free solvers measure unshot power, not the residual. */
        size_t steps = 0;
        const rad_solve_step *h = rad_solution_history(job->sol, &steps);
        double residual = rad_solution_residual(job->sol);
        char measure[64], full[PATH_MAX];
        if (isnan(residual) && steps > 0)
            snprintf(measure, sizeof measure, "unshot %.2g", h[steps - 1].unshot);
        else
            snprintf(measure, sizeof measure, "residual %.2g", residual);
        /* The solver by name, and the flag that chose it when no --solver
         * did (a uniform mesh's option takes gauss-seidel: cli/options.c),
         * so that the O(n^2) path is never taken unsaid. */
        char solver[96] = "";
        const char *name = s->solve.solver ? s->solve.solver : "hierarchical"; /* the library's default */
        if (!job->saved)
            snprintf(solver, sizeof solver, "%s%s%s, ", name, s->dense_for ? " for " : "",
                     s->dense_for ? s->dense_for : "");
        printf("wrote %s%s%zu elements, %s%s, %.1f s)%s\n", cli_where(s->output, full), what,
               rad_solution_element_count(job->sol), solver, measure, cli_now() - job->t0,
               job->partial ? " [partial]" : "");
        size_t lights = rad_scene_luminaire_count(job->scene);
        if (lights > 0) {
            double lumens = 0.0;
            for (size_t k = 0; k < lights; k++)
                lumens += rad_scene_luminaire_flux(job->scene, k);
            printf("luminaires: %zu, %.6g lm; %.6g lm of direct light lands on the surfaces\n", lights, lumens,
                   rad_solution_direct_lumens(job->sol));
        }
    }
    if (cli_interrupted() && !job->partial)
        fprintf(stderr, "radiosity: interrupted while writing the outputs; they were completed first\n");
    return cli_status(0);
}

