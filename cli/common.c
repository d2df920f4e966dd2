/*
 * common.c -- what several commands use (cli.h): the clock, the library's
 * messages and warnings with its field names written as our flags, the
 * progress bar, the signals, and the false colour flags of render and
 * illuminance.
 *
 * The signal state is the process's, not a context's: a handler can reach
 * nothing else.  It is set once, before the handler can see anything but
 * its zero values.
 */
#include "cli.h"

#include <ctype.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

double cli_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

const char *cli_where(const char *path, char *buf)
{
    return realpath(path, buf) ? buf : path;
}

/* ---- messages ---- */

int cli_fail(rad_context *ctx, rad_result r)
{
    char msg[1024];
    cli_rewrite_message(rad_context_error(ctx), msg, sizeof msg);
    fprintf(stderr, "radiosity: %s\n", msg[0] ? msg : rad_result_string(r));
    /* A stage that fails once a signal has come (a load whose read or open
     * the signal broke off) was interrupted: 130 / 143, like the rest. */
    return cli_status(1);
}

int cli_fail_path(rad_context *ctx, rad_result r)
{
    cli_fail(ctx, r);
    return r == RAD_ERROR_INVALID_ARGUMENT ? EXIT_USAGE : 1;
}

void cli_print_warning(void *user, const char *message)
{
    (void)user;
    char text[1024];
    cli_rewrite_message(message, text, sizeof text);
    fprintf(stderr, "radiosity: warning: %s\n", text);
}

/* ---- progress on stderr ---- */

void cli_progress_bar(void *user, const char *phase, uint64_t done, uint64_t total)
{
    cli_progress *p = user;
    int percent = total ? (int)(100.0 * (double)done / (double)total) : 100;
    if (p->phase != phase) {
        if (p->phase)
            fputc('\n', stderr);
        p->phase = phase;
        p->last_percent = -1;
        p->start = cli_now();
    }
    if (percent == p->last_percent)
        return;
    p->last_percent = percent;
    char bar[31];
    int filled = percent * 30 / 100;
    for (int k = 0; k < 30; k++)
        bar[k] = k < filled ? '#' : '.';
    bar[30] = '\0';
    fprintf(stderr, "\r%-13s [%s] %3d%%  %6.1f s", phase, bar, percent, cli_now() - p->start);
    fflush(stderr);
}

void cli_progress_end(cli_progress *p)
{
    if (p->phase)
        fputc('\n', stderr);
    p->phase = NULL;
}

/* ---- interruption (cli.h tells the rules) ---- */

/* The context whose work a signal cancels; rad_context_cancel is an atomic
 * store. */
static rad_context *volatile cancel_context;
static volatile sig_atomic_t cancel_signal;
static volatile sig_atomic_t saving;

static void on_signal(int sig)
{
    if (!cancel_signal)
        cancel_signal = sig;
    if (!saving)
        rad_context_cancel(cancel_context, true);
}

void cli_signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    /* A FIFO whose reader left is a write error, not a silent death. */
    sa.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &sa, NULL);
}

void cli_signals_watch(rad_context *ctx) { cancel_context = ctx; }

void cli_begin_saving(rad_context *ctx)
{
    saving = 1;
    rad_context_cancel(ctx, false);
}

bool cli_interrupted(void) { return cancel_signal != 0; }

int cli_interrupted_status(void) { return cancel_signal == SIGTERM ? 143 : 130; }

int cli_status(int status) { return cancel_signal ? cli_interrupted_status() : status; }

/* ---- false colour ---- */

int cli_false_colour_options(const cli_job *job, rad_false_colour_options *fo)
{
    const cli_settings *s = &job->s;
    memset(fo, 0, sizeof *fo);
    if (s->command == CLI_ILLUMINANCE) {
        /* The grids' plans: an output ending in .png. */
        bool png = false;
        for (int k = 0; k < 2; k++) {
            const char *o = k ? s->output2 : s->output, *dot = o ? strrchr(o, '.') : NULL;
            png = png || (dot && strcasecmp(dot, ".png") == 0);
        }
        if ((s->log_scale || s->range) && !png) {
            fprintf(stderr, "radiosity: --%s: only for the grids' plans, an output ending in .png (see radiosity "
                            "illuminance --help)\n", s->range ? "range" : "scale");
            return EXIT_USAGE;
        }
    } else if (!s->false_colour) {
        if (s->log_scale || s->range || s->contours) {
            fprintf(stderr, "radiosity: --%s: only with --false-colour luminance|illuminance (see radiosity "
                            "render --help)\n", s->range ? "range" : s->contours ? "contours" : "scale");
            return EXIT_USAGE;
        }
        return -1;
    }
    fo->quantity = s->command == CLI_ILLUMINANCE ? RAD_FALSE_COLOUR_ILLUMINANCE
                                                 : (rad_false_colour_quantity)s->false_colour;
    fo->log_scale = s->log_scale;
    fo->contours = s->contours;
    if (s->range) {
        char *end = NULL;
        fo->range_min = strtod(s->range, &end);
        bool good = end != s->range && *end == ':';
        if (good) {
            const char *max = end + 1;
            fo->range_max = strtod(max, &end);
            good = end != max && *end == '\0';
        }
        if (!good) {
            fprintf(stderr, "radiosity: --range: expected MIN:MAX (two numbers), got '%s'\n", s->range);
            return EXIT_USAGE;
        }
        if (fo->range_min == 0.0 && fo->range_max == 0.0) {
            fprintf(stderr, "radiosity: --range: 0:0 is empty; leave --range out for the automatic range\n");
            return EXIT_USAGE;
        }
    }
    char ext[8];
    const char *dot = strrchr(s->output, '.');
    snprintf(ext, sizeof ext, "%s", dot ? dot + 1 : "");
    for (char *c = ext; *c; c++)
        *c = (char)tolower((unsigned char)*c);
    if (s->command != CLI_ILLUMINANCE && strcmp(ext, "png") != 0) {
        fprintf(stderr, "radiosity: --false-colour writes PNG: the output must end in .png, got %s\n", s->output);
        return EXIT_USAGE;
    }
    if (rad_false_colour_check(job->ctx, fo) != RAD_OK) {
        fprintf(stderr, "radiosity: --%s\n", rad_context_error(job->ctx));
        return EXIT_USAGE;
    }
    return -1;
}
