/*
 * main.c -- the `radiosity` command.  Each command walks the pipeline:
 *
 *   1. load      the scene file, or the built-in Cornell box
 *   2. mesh      surfaces -> elements            } rad_solution_create
 *   3. couple    visibility + form factors F_ij  }
 *   4. solve     B = E + rho F B                   rad_solution_solve
 *   5. output    image / view factors / stats      rad_solution_render, ..._write_*
 *
 * Options live in one table (OPTIONS below) from which --help is printed,
 * so the two cannot drift.  Exit status: 0 ok, 1 failure, 2 usage error,
 * 130 / 143 when interrupted by SIGINT / SIGTERM (partial outputs are
 * written and marked as such).
 */
#include "radiosity.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

enum { EXIT_USAGE = 2 };

/* ---- the option table ---- */

enum option_id {
    OPT_OUTPUT, OPT_MESH_SIZE, OPT_ELEMENTS, OPT_FORM_FACTORS, OPT_SOLVER, OPT_VISIBILITY,
    OPT_SHADOW_RAYS, OPT_TOLERANCE, OPT_MAX_ITERATIONS, OPT_WIDTH, OPT_HEIGHT, OPT_SAMPLES,
    OPT_CAMERA, OPT_EXPOSURE, OPT_FLAT, OPT_THREADS, OPT_SEED, OPT_STATS, OPT_MAX_MEMORY,
    OPT_QUIET, OPT_HELP, OPT_VERSION, OPT_LIST_METHODS, OPT_HEMICUBE_RES, OPT_SAMPLES_FF,
    OPT_NEAR_FIELD, OPT_CLOSURE, OPT_RELAXATION, OPT_UNSHOT_TOLERANCE, OPT_HISTORY,
    OPT_PROGRESS_IMAGES, OPT_EVERY, OPT_LEVEL, OPT_EPSILON, OPT_MIN_AREA, OPT_CLUSTERING
};

enum { CMD_RENDER = 1, CMD_VIEWFACTORS = 2, CMD_ALL = 3 };

typedef struct option_def {
    enum option_id id;
    char short_name;
    const char *name;
    const char *arg;       /* NULL for flags */
    int commands;          /* which commands take it */
    const char *help;
} option_def;

static const option_def OPTIONS[] = {
    {OPT_OUTPUT, 'o', "output", "FILE", CMD_ALL,
     "output file: image (.png .hdr .pfm; default radiosity.png) or view factors "
     "(.json .csv; default viewfactors.json)"},
    {OPT_MESH_SIZE, 0, "mesh-size", "L", CMD_ALL, "longest element edge, metres"},
    {OPT_ELEMENTS, 0, "elements", "N", CMD_ALL, "about N elements in all (default 2000)"},
    {OPT_FORM_FACTORS, 0, "form-factors", "NAME", CMD_ALL, "form-factor method (default analytic)"},
    {OPT_SOLVER, 0, "solver", "NAME", CMD_RENDER, "solver (default gauss-seidel)"},
    {OPT_VISIBILITY, 0, "visibility", "NAME", CMD_ALL, "ray backend: embree (default) or brute"},
    {OPT_SHADOW_RAYS, 0, "shadow-rays", "N", CMD_ALL,
     "visibility rays per element pair, 4x more where partial (default 4)"},
    {OPT_HEMICUBE_RES, 0, "hemicube-res", "N", CMD_ALL, "hemicube: pixels along a full face (default 256)"},
    {OPT_SAMPLES_FF, 0, "ff-samples", "N", CMD_ALL,
     "hemisphere: rays per element; montecarlo: point pairs per element pair; matrix-free "
     "shooting: rays per shot (default: the method's)"},
    {OPT_NEAR_FIELD, 0, "near-field", "X", CMD_ALL,
     "hybrid: pairs closer than X element sizes use the exact method (default 3)"},
    {OPT_CLOSURE, 0, "closure-correction", NULL, CMD_ALL,
     "rescale F so rows sum to 1 keeping reciprocity (closed scenes only; docs/methods.md)"},
    {OPT_LEVEL, 0, "level", "WHICH", CMD_VIEWFACTORS,
     "view factors between 'surface's (default) or 'element's"},
    {OPT_EPSILON, 0, "epsilon", "X", CMD_RENDER,
     "hierarchical: refine links whose error exceeds X x the mean emitted exitance (default 1e-3)"},
    {OPT_MIN_AREA, 0, "min-area", "A", CMD_RENDER,
     "hierarchical: smallest element area, m^2 (default 1e-4 x the total area)"},
    {OPT_CLUSTERING, 0, "clustering", "WHEN", CMD_RENDER,
     "hierarchical: start from a cluster hierarchy 'on', 'off' or 'auto' (> 64 patches; default)"},
    {OPT_TOLERANCE, 0, "tolerance", "X", CMD_RENDER,
     "stop when the residual (unaccounted power / emitted power) < X (default 1e-6)"},
    {OPT_MAX_ITERATIONS, 0, "max-iterations", "N", CMD_RENDER,
     "cap on sweeps (gathering) or shots (shooting); 0 = automatic"},
    {OPT_UNSHOT_TOLERANCE, 0, "unshot-tolerance", "X", CMD_RENDER,
     "shooting: stop when unshot power / emitted power < X (default: --tolerance)"},
    {OPT_RELAXATION, 0, "relaxation", "W", CMD_RENDER,
     "over-relaxation in (0, 2): SOR for jacobi / gauss-seidel, overshooting for southwell (default 1)"},
    {OPT_HISTORY, 0, "history", "FILE.csv", CMD_RENDER,
     "write the convergence history: iteration, seconds, residual, unshot power"},
    {OPT_PROGRESS_IMAGES, 0, "progress-images", "DIR", CMD_RENDER,
     "write the image every --every iterations while solving (progressive display)"},
    {OPT_EVERY, 0, "every", "K", CMD_RENDER, "with --progress-images: every K iterations (default 1)"},
    {OPT_WIDTH, 0, "width", "W", CMD_RENDER, "image width in pixels (default 512)"},
    {OPT_HEIGHT, 0, "height", "H", CMD_RENDER, "image height in pixels (default 512)"},
    {OPT_SAMPLES, 0, "samples", "N", CMD_RENDER, "N x N anti-aliasing samples per pixel (default 2)"},
    {OPT_CAMERA, 0, "camera", "P,L[,U[,FOV]]", CMD_RENDER,
     "camera: position px,py,pz, look-at lx,ly,lz, up ux,uy,uz, vertical FOV in degrees "
     "(default: the scene's camera, else framed automatically)"},
    {OPT_EXPOSURE, 0, "exposure", "X", CMD_RENDER, "multiply radiance by X before sRGB (default automatic)"},
    {OPT_FLAT, 0, "flat", NULL, CMD_RENDER, "flat shading: one colour per element"},
    {OPT_THREADS, 0, "threads", "N", CMD_ALL, "worker threads (default: all cores)"},
    {OPT_SEED, 0, "seed", "N", CMD_ALL, "seed of all sampling (default 0); results do not depend on --threads"},
    {OPT_STATS, 0, "stats", "FILE.json", CMD_ALL, "write run statistics as JSON (docs/stats.md)"},
    {OPT_MAX_MEMORY, 0, "max-memory", "SIZE", CMD_ALL,
     "refuse to use more memory than SIZE (e.g. 4G, 512M; default 80% of RAM)"},
    {OPT_QUIET, 'q', "quiet", NULL, CMD_ALL, "print nothing but errors"},
    {OPT_LIST_METHODS, 0, "list-methods", NULL, 0, "list form-factor methods, solvers and ray backends"},
    {OPT_VERSION, 0, "version", NULL, 0, "print the version"},
    {OPT_HELP, 'h', "help", NULL, 0, "print this help"},
};
#define OPTION_COUNT (sizeof OPTIONS / sizeof OPTIONS[0])

static void print_help(FILE *out)
{
    fprintf(out,
            "radiosity %s -- diffuse global illumination by the radiosity method\n\n"
            "usage:\n"
            "  radiosity render [SCENE] [options]        solve and write an image\n"
            "  radiosity viewfactors [SCENE] [options]   write view factors between named surfaces\n"
            "  radiosity --list-methods | --version | --help\n\n"
            "SCENE is an OBJ (+MTL) or glTF 2.0 file; without one, the built-in Cornell box.\n"
            "Units: metres; emission and radiosity in W/m^2; OBJ Ke is emitted radiance (E = pi Ke).\n\n"
            "options:\n",
            RAD_VERSION_STRING);
    for (size_t i = 0; i < OPTION_COUNT; i++) {
        const option_def *o = &OPTIONS[i];
        char left[64];
        snprintf(left, sizeof left, "%s%c%s--%s%s%s", o->short_name ? "-" : "",
                 o->short_name ? o->short_name : ' ', o->short_name ? ", " : "  ", o->name,
                 o->arg ? " " : "", o->arg ? o->arg : "");
        const char *which = o->commands == CMD_RENDER ? " [render]" : "";
        fprintf(out, "  %-28s %s%s\n", left, o->help, which);
    }
    fprintf(out, "\nexit status: 0 ok, 1 failure, 2 usage error, 130/143 interrupted\n");
}

/* ---- parsed settings ---- */

typedef struct settings {
    int command;
    const char *scene_path;
    const char *output;
    const char *stats;
    const char *camera;
    const char *history;
    const char *progress_dir;
    long every;
    int element_level;
    rad_options solve;
    rad_render_options render;
    int threads;
    int quiet;
} settings;

static int usage_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* Print "radiosity: <message> (see radiosity --help)"; returns EXIT_USAGE. */
static int usage_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "radiosity: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, " (see radiosity --help)\n");
    va_end(ap);
    return EXIT_USAGE;
}

static int parse_double(const char *opt, const char *text, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || !isfinite(v) || v < lo || v > hi) {
        char range[96];
        snprintf(range, sizeof range, "a number in [%g, %g], got '%s'", lo, hi, text);
        return usage_error("--%s: expected %s", opt, range);
    }
    *out = v;
    return 0;
}

static int parse_int(const char *opt, const char *text, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE || v < lo || v > hi) {
        char range[96];
        snprintf(range, sizeof range, "an integer in [%ld, %ld], got '%s'", lo, hi, text);
        return usage_error("--%s: expected %s", opt, range);
    }
    *out = v;
    return 0;
}

static int parse_size(const char *opt, const char *text, double *bytes)
{
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    double unit = 1.0;
    if (*end == 'K' || *end == 'k')
        unit = 1024.0, end++;
    else if (*end == 'M' || *end == 'm')
        unit = 1048576.0, end++;
    else if (*end == 'G' || *end == 'g')
        unit = 1073741824.0, end++;
    if (end == text || *end != '\0' || !isfinite(v) || v <= 0.0)
        return usage_error("--%s: expected a size such as 4G or 512M, got '%s'", opt, text);
    *bytes = v * unit;
    return 0;
}

static void list_methods(void)
{
    static const char *titles[] = {"form factors (--form-factors)", "solvers (--solver)",
                                   "ray backends (--visibility)"};
    for (int k = 0; k < 3; k++) {
        printf("%s:\n", titles[k]);
        const char *name, *desc;
        for (size_t i = 0; rad_method_info((rad_method_kind)k, i, &name, &desc); i++)
            printf("  %-14s %s\n", name, desc);
    }
}

/* Returns -1 to go on, else an exit status. */
static int parse_args(int argc, char **argv, settings *s)
{
    int i = 1;
    if (argc < 2) {
        print_help(stderr);
        return EXIT_USAGE;
    }
    if (strcmp(argv[1], "render") == 0)
        s->command = CMD_RENDER, i = 2;
    else if (strcmp(argv[1], "viewfactors") == 0)
        s->command = CMD_VIEWFACTORS, i = 2;
    for (; i < argc; i++) {
        const char *arg = argv[i];
        if (arg[0] != '-' || arg[1] == '\0') {
            if (!s->command)
                return usage_error("unknown command '%s'", arg);
            if (s->scene_path)
                return usage_error("more than one scene given ('%s' and '%s')", s->scene_path, arg);
            s->scene_path = arg;
            continue;
        }
        const option_def *o = NULL;
        const char *value = NULL;
        if (arg[1] == '-') {
            const char *name = arg + 2;
            const char *eq = strchr(name, '=');
            size_t len = eq ? (size_t)(eq - name) : strlen(name);
            for (size_t k = 0; k < OPTION_COUNT; k++)
                if (strlen(OPTIONS[k].name) == len && strncmp(OPTIONS[k].name, name, len) == 0)
                    o = &OPTIONS[k];
            if (eq)
                value = eq + 1;
        } else if (arg[2] == '\0') {
            for (size_t k = 0; k < OPTION_COUNT; k++)
                if (OPTIONS[k].short_name == arg[1])
                    o = &OPTIONS[k];
        }
        if (!o)
            return usage_error("unknown option '%s'", arg);
        if (o->arg && !value) {
            if (i + 1 >= argc)
                return usage_error("%s needs a value (%s)", arg, o->arg);
            value = argv[++i];
        } else if (!o->arg && value) {
            return usage_error("%s takes no value", arg);
        }
        if (o->commands && !s->command)
            return usage_error("%s needs a command: render or viewfactors", arg);
        if (o->commands && !(o->commands & s->command))
            return usage_error("%s does not apply to this command", arg);
        long l;
        double d;
        int bad = 0;
        switch (o->id) {
        case OPT_HELP: print_help(stdout); return 0;
        case OPT_VERSION: printf("radiosity %s\n", RAD_VERSION_STRING); return 0;
        case OPT_LIST_METHODS: list_methods(); return 0;
        case OPT_OUTPUT: s->output = value; break;
        case OPT_STATS: s->stats = value; break;
        case OPT_CAMERA: s->camera = value; break;
        case OPT_FORM_FACTORS: s->solve.form_factors = value; break;
        case OPT_SOLVER: s->solve.solver = value; break;
        case OPT_VISIBILITY: s->solve.visibility = value; break;
        case OPT_FLAT: s->render.shading = RAD_SHADING_FLAT; break;
        case OPT_QUIET: s->quiet = 1; break;
        case OPT_MESH_SIZE:
            bad = parse_double(o->name, value, 1e-9, 1e9, &s->solve.mesh_size);
            break;
        case OPT_ELEMENTS:
            bad = parse_int(o->name, value, 1, 100000000, &l);
            s->solve.target_elements = (size_t)l;
            break;
        case OPT_SHADOW_RAYS:
            bad = parse_int(o->name, value, 1, 48, &l);
            s->solve.shadow_rays = (int)l;
            break;
        case OPT_TOLERANCE:
            bad = parse_double(o->name, value, 1e-15, 0.5, &s->solve.tolerance);
            break;
        case OPT_EPSILON:
            bad = parse_double(o->name, value, 1e-12, 1e3, &s->solve.epsilon);
            break;
        case OPT_MIN_AREA:
            bad = parse_double(o->name, value, 1e-18, 1e18, &s->solve.min_area);
            break;
        case OPT_CLUSTERING:
            if (strcmp(value, "on") == 0)
                s->solve.clustering = 1;
            else if (strcmp(value, "off") == 0)
                s->solve.clustering = -1;
            else if (strcmp(value, "auto") == 0)
                s->solve.clustering = 0;
            else
                return usage_error("--clustering takes on, off or auto, got '%s'", value);
            break;
        case OPT_MAX_ITERATIONS:
            bad = parse_int(o->name, value, 0, 2000000000, &l);
            s->solve.max_iterations = (int)l;
            break;
        case OPT_WIDTH:
            bad = parse_int(o->name, value, 1, 16384, &l);
            s->render.width = (int)l;
            break;
        case OPT_HEIGHT:
            bad = parse_int(o->name, value, 1, 16384, &l);
            s->render.height = (int)l;
            break;
        case OPT_SAMPLES:
            bad = parse_int(o->name, value, 1, 16, &l);
            s->render.samples = (int)l;
            break;
        case OPT_EXPOSURE:
            bad = parse_double(o->name, value, 1e-12, 1e12, &s->render.exposure);
            break;
        case OPT_THREADS:
            bad = parse_int(o->name, value, 1, 1024, &l);
            s->threads = (int)l;
            break;
        case OPT_SEED:
            bad = parse_double(o->name, value, 0, 9007199254740992.0, &d);
            if (!bad && d != floor(d))
                bad = usage_error("--%s: expected a non-negative integer, got '%s'", o->name, value);
            s->solve.seed = (uint64_t)d;
            break;
        case OPT_MAX_MEMORY:
            bad = parse_size(o->name, value, &s->solve.max_memory_bytes);
            break;
        case OPT_HEMICUBE_RES:
            bad = parse_int(o->name, value, 2, 8192, &l);
            s->solve.hemicube_resolution = (int)l;
            break;
        case OPT_SAMPLES_FF:
            bad = parse_int(o->name, value, 1, 100000000, &l);
            s->solve.samples = (int)l;
            break;
        case OPT_NEAR_FIELD:
            bad = parse_double(o->name, value, 1e-6, 1e6, &s->solve.near_field);
            break;
        case OPT_CLOSURE: s->solve.closure_correction = 1; break;
        case OPT_RELAXATION:
            bad = parse_double(o->name, value, 1e-3, 1.999, &s->solve.relaxation);
            break;
        case OPT_UNSHOT_TOLERANCE:
            bad = parse_double(o->name, value, 1e-15, 0.5, &s->solve.unshot_tolerance);
            break;
        case OPT_HISTORY:
            s->history = value;
            s->solve.record_history = 1;
            break;
        case OPT_PROGRESS_IMAGES: s->progress_dir = value; break;
        case OPT_EVERY: bad = parse_int(o->name, value, 1, 2000000000, &s->every); break;
        case OPT_LEVEL:
            if (strcmp(value, "surface") == 0)
                s->element_level = 0;
            else if (strcmp(value, "element") == 0)
                s->element_level = 1;
            else
                bad = usage_error("--level: expected 'surface' or 'element', got '%s'", value);
            break;
        }
        if (bad)
            return bad;
    }
    if (!s->command)
        return usage_error("no command given: use render or viewfactors");
    if (s->every && !s->progress_dir)
        return usage_error("--every needs --progress-images DIR");
    return -1;
}

/* ---- progress on stderr, only when it is a terminal ---- */

typedef struct progress_state {
    const char *phase;
    int last_percent;
    double start;
} progress_state;

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void progress_bar(void *user, const char *phase, uint64_t done, uint64_t total)
{
    progress_state *p = user;
    int percent = total ? (int)(100.0 * (double)done / (double)total) : 100;
    if (p->phase != phase) {
        if (p->phase)
            fputc('\n', stderr);
        p->phase = phase;
        p->last_percent = -1;
        p->start = now_seconds();
    }
    if (percent == p->last_percent)
        return;
    p->last_percent = percent;
    char bar[31];
    int filled = percent * 30 / 100;
    for (int k = 0; k < 30; k++)
        bar[k] = k < filled ? '#' : '.';
    bar[30] = '\0';
    fprintf(stderr, "\r%-13s [%s] %3d%%  %6.1f s", phase, bar, percent, now_seconds() - p->start);
    fflush(stderr);
}

static void progress_end(progress_state *p)
{
    if (p->phase)
        fputc('\n', stderr);
    p->phase = NULL;
}

/* ---- interruption ---- */

static volatile int cancel_flag;
static volatile sig_atomic_t cancel_signal;

static void on_signal(int sig)
{
    cancel_flag = 1;
    cancel_signal = sig;
}

/* ---- progressive display: an image every K solver steps ---- */

typedef struct progressive {
    rad_context *ctx;
    const char *dir;
    long every;
    const rad_render_options *render;
    double exposure;
    int failed;
} progressive;

static int on_step(void *user, rad_solution *solution, const rad_solve_step *step)
{
    progressive *p = user;
    if (!p->dir || step->iteration % p->every != 0)
        return 0;
    rad_image *image = NULL;
    char path[4096];
    snprintf(path, sizeof path, "%s/step_%08d.png", p->dir, step->iteration);
    rad_result r = rad_solution_render(p->ctx, solution, p->render, &image);
    if (r == RAD_OK && p->exposure == 0.0)
        p->exposure = rad_image_auto_exposure(image); /* fixed from the first frame on */
    if (r == RAD_OK)
        r = rad_image_write_exposed(p->ctx, image, path, p->exposure);
    rad_image_destroy(image);
    if (r != RAD_OK) {
        p->failed = 1;
        return 1; /* stop: the message is in the context */
    }
    return 0;
}

/* ---- the commands ---- */

static int fail(rad_context *ctx, rad_result r)
{
    const char *msg = rad_context_error(ctx);
    fprintf(stderr, "radiosity: %s\n", msg[0] ? msg : rad_result_string(r));
    return 1;
}

static int interrupted_status(void) { return cancel_signal == SIGTERM ? 143 : 130; }

/* The absolute path of a file just written, for telling the user where it
 * is; falls back to the name as given. */
static const char *where(const char *path, char *buf)
{
    return realpath(path, buf) ? buf : path;
}

int main(int argc, char **argv)
{
    settings s;
    memset(&s, 0, sizeof s);
    int status = parse_args(argc, argv, &s);
    if (status >= 0)
        return status;

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    progress_state progress = {0};
    rad_context_options co = {0};
    co.threads = s.threads;
    co.cancel = &cancel_flag;
    if (!s.quiet && isatty(STDERR_FILENO)) {
        co.progress = progress_bar;
        co.progress_user = &progress;
    }
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK) {
        fprintf(stderr, "radiosity: cannot create a context\n");
        return 1;
    }
    const char *output = s.output ? s.output
                                  : (s.command == CMD_RENDER ? "radiosity.png" : "viewfactors.json");
    rad_camera camera;
    rad_scene *scene = NULL;
    rad_solution *sol = NULL;
    rad_image *image = NULL;
    rad_result r = RAD_OK;
    status = 1;

    /* 1. load */
    double t0 = now_seconds();
    r = s.scene_path ? rad_scene_load_file(ctx, s.scene_path, &scene)
                     : rad_scene_create_cornell_box(ctx, &scene);
    if (r != RAD_OK) {
        status = fail(ctx, r);
        goto done;
    }
    if (s.camera) {
        /* The library owns the camera syntax (docs/cli.md). */
        r = rad_camera_from_string(ctx, s.camera, &camera);
        if (r != RAD_OK) {
            fprintf(stderr, "radiosity: %s (see radiosity --help)\n", rad_context_error(ctx));
            status = EXIT_USAGE;
            goto done;
        }
        s.render.camera = &camera;
    }
    if (s.command == CMD_RENDER && !s.quiet && !s.scene_path)
        printf("radiosity: no scene given, rendering the built-in Cornell box\n");

    /* Progressive display keeps one exposure for all frames (the user's, or
     * the first frame's automatic one), so the picture visibly brightens as
     * light is shot; with the ambient term the first frame is already close
     * to the final brightness. */
    progressive prog = {ctx, s.progress_dir, s.every ? s.every : 1, &s.render, s.render.exposure, 0};
    if (s.progress_dir) {
        if (mkdir(s.progress_dir, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "radiosity: %s: cannot create directory: %s\n", s.progress_dir, strerror(errno));
            goto done;
        }
        s.solve.on_step = on_step;
        s.solve.on_step_user = &prog;
    }

    /* 2-3. mesh, visibility, form factors */
    r = rad_solution_create(ctx, scene, &s.solve, &sol);
    progress_end(&progress);
    if (r == RAD_ERROR_INTERRUPTED) {
        fprintf(stderr, "radiosity: interrupted while computing form factors; nothing written\n");
        status = interrupted_status();
        goto done;
    }
    if (r != RAD_OK) {
        status = fail(ctx, r);
        goto done;
    }

    if (s.command == CMD_VIEWFACTORS) {
        /* 5. view factors */
        r = rad_solution_write_view_factors(ctx, sol, output, s.element_level);
        if (r == RAD_OK && s.stats)
            r = rad_solution_write_stats(ctx, sol, s.stats, 0);
        if (r != RAD_OK) {
            status = fail(ctx, r);
            goto done;
        }
        char full[PATH_MAX];
        if (!s.quiet)
            printf("wrote %s (%zu surfaces, %zu elements, %.2f s)\n", where(output, full),
                   rad_scene_surface_count(scene), rad_solution_element_count(sol),
                   now_seconds() - t0);
        status = 0;
        goto done;
    }

    /* 4. solve */
    r = rad_solution_solve(ctx, sol);
    progress_end(&progress);
    if (prog.failed) {
        status = fail(ctx, RAD_ERROR_IO);
        goto done;
    }
    int partial = r == RAD_ERROR_INTERRUPTED;
    if (r != RAD_OK && !partial) {
        status = fail(ctx, r);
        goto done;
    }
    if (partial)
        fprintf(stderr, "radiosity: interrupted while solving; writing the partial solution\n");
    else if (!s.quiet && rad_solution_residual(sol) > (s.solve.tolerance > 0 ? s.solve.tolerance : 1e-6))
        fprintf(stderr, "radiosity: warning: stopped at residual %.3g after %d iterations\n",
                rad_solution_residual(sol), rad_solution_iterations(sol));

    /* 5. image and stats.  A second signal during output is ignored: the
     * partial results are being saved. */
    cancel_flag = 0;
    r = rad_solution_render(ctx, sol, &s.render, &image);
    progress_end(&progress);
    if (r == RAD_OK)
        r = rad_image_write_exposed(ctx, image, output, s.render.exposure);
    if (r == RAD_OK && s.stats)
        r = rad_solution_write_stats(ctx, sol, s.stats, partial);
    if (r == RAD_OK && s.history)
        r = rad_solution_write_history(ctx, sol, s.history);
    if (r != RAD_OK) {
        status = fail(ctx, r);
        goto done;
    }
    char full[PATH_MAX];
    if (!s.quiet) {
        /* Matrix-free solvers measure unshot power, not the residual. */
        size_t steps = 0;
        const rad_solve_step *h = rad_solution_history(sol, &steps);
        double residual = rad_solution_residual(sol);
        char measure[64];
        if (isnan(residual) && steps > 0)
            snprintf(measure, sizeof measure, "unshot %.2g", h[steps - 1].unshot);
        else
            snprintf(measure, sizeof measure, "residual %.2g", residual);
        printf("wrote %s (%dx%d, %zu elements, %s, %.1f s)%s\n", where(output, full),
               rad_image_width(image), rad_image_height(image), rad_solution_element_count(sol),
               measure, now_seconds() - t0, partial ? " [partial]" : "");
    }
    status = partial ? interrupted_status() : 0;

done:
    rad_image_destroy(image);
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return status;
}
