/*
 * options.c -- the `radiosity` command's option table, --help printed from
 * it, and the parser (see options.h).  The parser has no side effects:
 * errors go into the caller's buffer, and --help / --version /
 * --list-methods are returned as actions for main.c to carry out.
 */
#include "options.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the option table ---- */

enum option_id {
    OPT_OUTPUT, OPT_MESH_SIZE, OPT_ELEMENTS, OPT_FORM_FACTORS, OPT_SOLVER, OPT_VISIBILITY,
    OPT_SHADOW_RAYS, OPT_TOLERANCE, OPT_MAX_ITERATIONS, OPT_WIDTH, OPT_HEIGHT, OPT_SAMPLES,
    OPT_CAMERA, OPT_EXPOSURE, OPT_FLAT, OPT_THREADS, OPT_SEED, OPT_STATS, OPT_MAX_MEMORY,
    OPT_QUIET, OPT_HELP, OPT_VERSION, OPT_LIST_METHODS, OPT_HEMICUBE_RES, OPT_SAMPLES_FF,
    OPT_NEAR_FIELD, OPT_CLOSURE, OPT_RELAXATION, OPT_UNSHOT_TOLERANCE, OPT_HISTORY,
    OPT_PROGRESS_IMAGES, OPT_EVERY, OPT_LEVEL, OPT_EPSILON, OPT_MIN_AREA, OPT_CLUSTERING, OPT_ORACLE
};

typedef struct option_def {
    enum option_id id;
    char short_name;
    const char *name;
    const char *arg;       /* NULL for flags */
    int commands;          /* which commands take it */
    const char *help;
} option_def;

static const option_def OPTIONS[] = {
    {OPT_OUTPUT, 'o', "output", "FILE", CLI_ALL,
     "output file: image (.png .hdr .pfm; default radiosity.png) or view factors "
     "(.json .csv; default viewfactors.json)"},
    {OPT_MESH_SIZE, 0, "mesh-size", "L", CLI_ALL, "longest element edge, metres"},
    {OPT_ELEMENTS, 0, "elements", "N", CLI_ALL, "about N elements in all (default 2000)"},
    {OPT_FORM_FACTORS, 0, "form-factors", "NAME", CLI_ALL, "form-factor method (default analytic)"},
    {OPT_SOLVER, 0, "solver", "NAME", CLI_RENDER, "solver (default gauss-seidel)"},
    {OPT_VISIBILITY, 0, "visibility", "NAME", CLI_ALL, "ray backend: embree (default) or brute"},
    {OPT_SHADOW_RAYS, 0, "shadow-rays", "N", CLI_ALL,
     "visibility rays per element pair, 4x more where partial (default 4)"},
    {OPT_HEMICUBE_RES, 0, "hemicube-res", "N", CLI_ALL, "hemicube: pixels along a full face (default 256)"},
    {OPT_SAMPLES_FF, 0, "ff-samples", "N", CLI_ALL,
     "hemisphere: rays per element; montecarlo: point pairs per element pair; matrix-free "
     "shooting: rays per shot (default: the method's)"},
    {OPT_NEAR_FIELD, 0, "near-field", "X", CLI_ALL,
     "hybrid: pairs closer than X element sizes use the exact method (default 3)"},
    {OPT_CLOSURE, 0, "closure-correction", NULL, CLI_ALL,
     "rescale F so rows sum to 1 keeping reciprocity; hierarchical: scale each patch's sending by its link closure (closed scenes only; docs/methods.md)"},
    {OPT_LEVEL, 0, "level", "WHICH", CLI_VIEWFACTORS,
     "view factors between 'surface's (default) or 'element's"},
    {OPT_EPSILON, 0, "epsilon", "X", CLI_RENDER,
     "hierarchical: refine a link while its error (power its receiver reflects) exceeds X x the whole scene's emitted power (default 1e-4; a building of N rooms needs about 1/N of a room's X for the same accuracy per room)"},
    {OPT_MIN_AREA, 0, "min-area", "A", CLI_RENDER,
     "hierarchical: smallest element area, m^2 (default 1e-4 x the total area x min(1, 100 / patches))"},
    {OPT_CLUSTERING, 0, "clustering", "WHEN", CLI_RENDER,
     "hierarchical: start from a cluster hierarchy 'on', 'off' or 'auto' (> 64 patches; default)"},
    {OPT_ORACLE, 0, "oracle", "WHICH", CLI_RENDER,
     "hierarchical: split links on the receiver, visibility and the source's radiosity 'sources' (default), "
     "or on the first two only, 'classic' (fewer links, ~3x the per-surface error)"},
    {OPT_TOLERANCE, 0, "tolerance", "X", CLI_RENDER,
     "stop when the residual (unaccounted power / emitted power) < X (default 1e-6)"},
    {OPT_MAX_ITERATIONS, 0, "max-iterations", "N", CLI_RENDER,
     "cap on sweeps (gathering) or shots (shooting); 0 = automatic"},
    {OPT_UNSHOT_TOLERANCE, 0, "unshot-tolerance", "X", CLI_RENDER,
     "shooting: stop when unshot power / emitted power < X (default: --tolerance)"},
    {OPT_RELAXATION, 0, "relaxation", "W", CLI_RENDER,
     "over-relaxation in (0, 2): SOR for jacobi / gauss-seidel, overshooting for southwell (default 1)"},
    {OPT_HISTORY, 0, "history", "FILE.csv", CLI_RENDER,
     "write the convergence history: iteration, seconds, residual, unshot power"},
    {OPT_PROGRESS_IMAGES, 0, "progress-images", "DIR", CLI_RENDER,
     "write the image every --every iterations while solving (progressive display)"},
    {OPT_EVERY, 0, "every", "K", CLI_RENDER, "with --progress-images: every K iterations (default 1)"},
    {OPT_WIDTH, 0, "width", "W", CLI_RENDER, "image width in pixels (default 512)"},
    {OPT_HEIGHT, 0, "height", "H", CLI_RENDER, "image height in pixels (default 512)"},
    {OPT_SAMPLES, 0, "samples", "N", CLI_RENDER, "N x N anti-aliasing samples per pixel (default 2)"},
    {OPT_CAMERA, 0, "camera", "P,L[,U[,FOV]]", CLI_RENDER,
     "camera: position px,py,pz, look-at lx,ly,lz, up ux,uy,uz, vertical FOV in degrees "
     "(default: the scene's camera, else framed automatically)"},
    {OPT_EXPOSURE, 0, "exposure", "X", CLI_RENDER, "multiply radiance by X before sRGB (default automatic)"},
    {OPT_FLAT, 0, "flat", NULL, CLI_RENDER, "flat shading: one colour per element"},
    {OPT_THREADS, 0, "threads", "N", CLI_ALL, "worker threads (default: all cores)"},
    {OPT_SEED, 0, "seed", "N", CLI_ALL, "seed of all sampling (default 0); results do not depend on --threads"},
    {OPT_STATS, 0, "stats", "FILE.json", CLI_ALL, "write run statistics as JSON (docs/stats.md)"},
    {OPT_MAX_MEMORY, 0, "max-memory", "SIZE", CLI_ALL,
     "refuse to use more memory than SIZE (e.g. 4G, 512M; default 80% of RAM)"},
    {OPT_QUIET, 'q', "quiet", NULL, CLI_ALL, "print nothing but errors"},
    {OPT_LIST_METHODS, 0, "list-methods", NULL, 0, "list form-factor methods, solvers and ray backends"},
    {OPT_VERSION, 0, "version", NULL, 0, "print the version"},
    {OPT_HELP, 'h', "help", NULL, 0, "print this help"},
};
#define OPTION_COUNT (sizeof OPTIONS / sizeof OPTIONS[0])

void cli_print_help(FILE *out)
{
    fprintf(out,
            "radiosity %s -- diffuse global illumination by the radiosity method\n\n"
            "usage:\n"
            "  radiosity render [SCENE] [options]        solve and write an image\n"
            "  radiosity generate office [--rooms N] [--seed S] [-o F.obj]   write a procedural scene\n"
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
        const char *which = o->commands == CLI_RENDER ? " [render]" : "";
        fprintf(out, "  %-28s %s%s\n", left, o->help, which);
    }
    fprintf(out, "\nexit status: 0 ok, 1 failure, 2 usage error, 130/143 interrupted\n");
}

/* ---- the parser ---- */

/* Where a usage error goes: the caller's buffer. */
typedef struct error_sink {
    char *text;
    size_t size;
} error_sink;

static int usage_error(error_sink *e, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Write the message into e; returns 1 (the parser's "bad"). */
static int usage_error(error_sink *e, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (e->size)
        vsnprintf(e->text, e->size, fmt, ap);
    va_end(ap);
    return 1;
}

static int parse_double(error_sink *e, const char *opt, const char *text, double lo, double hi,
                        double *out)
{
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || !isfinite(v) || v < lo || v > hi)
        return usage_error(e, "--%s: expected a number in [%g, %g], got '%s'", opt, lo, hi, text);
    *out = v;
    return 0;
}

static int parse_int(error_sink *e, const char *opt, const char *text, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE || v < lo || v > hi)
        return usage_error(e, "--%s: expected an integer in [%ld, %ld], got '%s'", opt, lo, hi, text);
    *out = v;
    return 0;
}

static int parse_size(error_sink *e, const char *opt, const char *text, double *bytes)
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
    if (end == text || *end != '\0' || !isfinite(v) || v <= 0.0 || !isfinite(v * unit))
        return usage_error(e, "--%s: expected a size such as 4G or 512M, got '%s'", opt, text);
    *bytes = v * unit;
    return 0;
}

cli_action cli_parse_args(int argc, char *const *argv, cli_settings *s, char *err, size_t err_size)
{
    error_sink sink = {err, err_size};
    error_sink *e = &sink;
    int i = 1;
    if (err_size)
        err[0] = '\0';
    if (argc < 2)
        return CLI_NO_ARGUMENTS;
    if (strcmp(argv[1], "render") == 0)
        s->command = CLI_RENDER, i = 2;
    else if (strcmp(argv[1], "viewfactors") == 0)
        s->command = CLI_VIEWFACTORS, i = 2;
    for (; i < argc; i++) {
        const char *arg = argv[i];
        if (arg[0] != '-' || arg[1] == '\0') {
            if (!s->command) {
                usage_error(e, "unknown command '%s'", arg);
                return CLI_USAGE_ERROR;
            }
            if (s->scene_path) {
                usage_error(e, "more than one scene given ('%s' and '%s')", s->scene_path, arg);
                return CLI_USAGE_ERROR;
            }
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
        int bad = 0;
        if (!o)
            bad = usage_error(e, "unknown option '%s'", arg);
        else if (o->arg && !value && i + 1 >= argc)
            bad = usage_error(e, "%s needs a value (%s)", arg, o->arg);
        else if (!o->arg && value)
            bad = usage_error(e, "%s takes no value", arg);
        else if (o->commands && !s->command)
            bad = usage_error(e, "%s needs a command: render or viewfactors", arg);
        else if (o->commands && !(o->commands & s->command))
            bad = usage_error(e, "%s does not apply to this command", arg);
        if (bad)
            return CLI_USAGE_ERROR;
        if (o->arg && !value)
            value = argv[++i];
        long l = 0;
        double d = 0.0;
        switch (o->id) {
        case OPT_HELP: return CLI_HELP;
        case OPT_VERSION: return CLI_VERSION;
        case OPT_LIST_METHODS: return CLI_LIST_METHODS;
        case OPT_OUTPUT: s->output = value; break;
        case OPT_STATS: s->stats = value; break;
        case OPT_CAMERA: s->camera = value; break;
        case OPT_FORM_FACTORS: s->solve.form_factors = value; break;
        case OPT_SOLVER: s->solve.solver = value; break;
        case OPT_VISIBILITY: s->solve.visibility = value; break;
        case OPT_FLAT: s->render.shading = RAD_SHADING_FLAT; break;
        case OPT_QUIET: s->quiet = 1; break;
        case OPT_MESH_SIZE:
            bad = parse_double(e, o->name, value, 1e-9, 1e9, &s->solve.mesh_size);
            break;
        case OPT_ELEMENTS:
            bad = parse_int(e, o->name, value, 1, 100000000, &l);
            s->solve.target_elements = (size_t)l;
            break;
        case OPT_SHADOW_RAYS:
            bad = parse_int(e, o->name, value, 1, 48, &l);
            s->solve.shadow_rays = (int)l;
            break;
        case OPT_TOLERANCE:
            bad = parse_double(e, o->name, value, 1e-15, 0.5, &s->solve.tolerance);
            break;
        case OPT_EPSILON:
            bad = parse_double(e, o->name, value, 1e-12, 1e3, &s->solve.epsilon);
            break;
        case OPT_MIN_AREA:
            bad = parse_double(e, o->name, value, 1e-18, 1e18, &s->solve.min_area);
            break;
        case OPT_CLUSTERING:
            if (strcmp(value, "on") == 0)
                s->solve.clustering = 1;
            else if (strcmp(value, "off") == 0)
                s->solve.clustering = -1;
            else if (strcmp(value, "auto") == 0)
                s->solve.clustering = 0;
            else
                bad = usage_error(e, "--clustering takes on, off or auto, got '%s'", value);
            break;
        case OPT_ORACLE:
            if (strcmp(value, "sources") == 0)
                s->solve.classic_oracle = 0;
            else if (strcmp(value, "classic") == 0)
                s->solve.classic_oracle = 1;
            else
                bad = usage_error(e, "--oracle takes sources or classic, got '%s'", value);
            break;
        case OPT_MAX_ITERATIONS:
            bad = parse_int(e, o->name, value, 0, 2000000000, &l);
            s->solve.max_iterations = (int)l;
            break;
        case OPT_WIDTH:
            bad = parse_int(e, o->name, value, 1, 16384, &l);
            s->render.width = (int)l;
            break;
        case OPT_HEIGHT:
            bad = parse_int(e, o->name, value, 1, 16384, &l);
            s->render.height = (int)l;
            break;
        case OPT_SAMPLES:
            bad = parse_int(e, o->name, value, 1, 16, &l);
            s->render.samples = (int)l;
            break;
        case OPT_EXPOSURE:
            bad = parse_double(e, o->name, value, 1e-12, 1e12, &s->render.exposure);
            break;
        case OPT_THREADS:
            bad = parse_int(e, o->name, value, 1, 1024, &l);
            s->threads = (int)l;
            break;
        case OPT_SEED:
            bad = parse_double(e, o->name, value, 0, 9007199254740992.0, &d);
            if (!bad && d != floor(d))
                bad = usage_error(e, "--%s: expected a non-negative integer, got '%s'", o->name, value);
            s->solve.seed = (uint64_t)d;
            break;
        case OPT_MAX_MEMORY:
            bad = parse_size(e, o->name, value, &s->solve.max_memory_bytes);
            break;
        case OPT_HEMICUBE_RES:
            bad = parse_int(e, o->name, value, 2, 8192, &l);
            s->solve.hemicube_resolution = (int)l;
            break;
        case OPT_SAMPLES_FF:
            bad = parse_int(e, o->name, value, 1, 100000000, &l);
            s->solve.samples = (int)l;
            break;
        case OPT_NEAR_FIELD:
            bad = parse_double(e, o->name, value, 1e-6, 1e6, &s->solve.near_field);
            break;
        case OPT_CLOSURE: s->solve.closure_correction = 1; break;
        case OPT_RELAXATION:
            bad = parse_double(e, o->name, value, 1e-3, 1.999, &s->solve.relaxation);
            break;
        case OPT_UNSHOT_TOLERANCE:
            bad = parse_double(e, o->name, value, 1e-15, 0.5, &s->solve.unshot_tolerance);
            break;
        case OPT_HISTORY:
            s->history = value;
            s->solve.record_history = 1;
            break;
        case OPT_PROGRESS_IMAGES: s->progress_dir = value; break;
        case OPT_EVERY: bad = parse_int(e, o->name, value, 1, 2000000000, &s->every); break;
        case OPT_LEVEL:
            if (strcmp(value, "surface") == 0)
                s->element_level = 0;
            else if (strcmp(value, "element") == 0)
                s->element_level = 1;
            else
                bad = usage_error(e, "--level: expected 'surface' or 'element', got '%s'", value);
            break;
        }
        if (bad)
            return CLI_USAGE_ERROR;
    }
    if (!s->command) {
        usage_error(e, "no command given: use render or viewfactors");
        return CLI_USAGE_ERROR;
    }
    if (s->every && !s->progress_dir) {
        usage_error(e, "--every needs --progress-images DIR");
        return CLI_USAGE_ERROR;
    }
    if (s->progress_dir && s->solve.solver && strcmp(s->solve.solver, "hierarchical") == 0) {
        usage_error(e, "--progress-images is not available with --solver hierarchical "
                       "(its elements change while it solves; use --history)");
        return CLI_USAGE_ERROR;
    }
    return CLI_RUN;
}
