/*
 * options.c -- the option table (include/radiosity.h, "Option table") and
 * rad_options as a solution uses them.
 *
 * One row per field a user sets: its type, range, default and help.  The
 * rows drive rad_options_resolve (defaults filled in, every field checked,
 * method names looked up in the registries), and the `radiosity` command
 * builds its flags, --help and man page from the same rows, so the library
 * and the program cannot disagree on a range or a default.  Messages name
 * the field as the header spells it: "rad_options.tolerance must be in
 * (0, 1), got 2".
 *
 * The checks of rad_render_options and rad_office_options stay where those
 * structs are used (output/render.c, generate/generate.c); their rows here
 * describe those checks, and tests/test_options.c holds the two together.
 */
#include "strategy/options.h"

#include "strategy/strategy.h"

#include <inttypes.h>
#include <limits.h>
#include <string.h>

/* ---- the rows ---- */

static const rad_option_word clustering_words[] = {{"auto", 0}, {"on", 1}, {"off", -1}, {NULL, 0}};
static const rad_option_word oracle_words[] = {{"sources", 0}, {"classic", 1}, {NULL, 0}};
static const rad_option_word shading_words[] = {
    {"smooth", RAD_SHADING_SMOOTH}, {"flat", RAD_SHADING_FLAT}, {NULL, 0}};

#define SOLUTION(field) .name = #field, .offset = offsetof(rad_options, field)
#define RENDER(field) .name = #field, .offset = offsetof(rad_render_options, field)
#define OFFICE(field) .name = #field, .offset = offsetof(rad_office_options, field)
/* A seed takes any uint64_t: 0 to 2^64 - 1 (rounded up here; the range
 * text prints it exactly). */
#define UINT64_RANGE .min = 0.0, .max = 18446744073709551616.0

static const rad_option_info solution_rows[] = {
    {SOLUTION(mesh_size), .type = RAD_OPTION_DOUBLE, .min = 0.0, .min_open = true, .max = INFINITY,
     .default_value = NAN, .default_text = "from the element count",
     .help = "longest element edge, metres"},
    {SOLUTION(target_elements), .type = RAD_OPTION_SIZE, .min = 1.0, .max = 1e8, .default_value = 2000.0,
     .default_text = "2000", .help = "about this many elements in all, unless a mesh size is given"},
    {SOLUTION(crease_angle_degrees), .type = RAD_OPTION_DOUBLE, .min = 0.0, .min_open = true, .max = 180.0,
     .default_value = 30.0, .default_text = "30",
     .help = "vertices of a surface are shared across polygons meeting at less than this angle, degrees"},
    {SOLUTION(form_factors), .type = RAD_OPTION_METHOD, .methods = RAD_METHOD_FORM_FACTOR,
     .default_value = NAN, .default_text = "analytic", .help = "form-factor method"},
    {SOLUTION(shadow_rays), .type = RAD_OPTION_INT, .min = 1.0, .max = 48.0, .default_value = 4.0,
     .default_text = "4", .help = "visibility rays per element pair, 4x more where partial"},
    {SOLUTION(visibility), .type = RAD_OPTION_METHOD, .methods = RAD_METHOD_VISIBILITY,
     .default_value = NAN, .default_text = "embree", .help = "ray backend"},
    {SOLUTION(hemicube_resolution), .type = RAD_OPTION_INT, .min = 2.0, .max = 8192.0,
     .default_value = 256.0, .default_text = "256", .help = "hemicube: pixels along a full face"},
    {SOLUTION(samples), .type = RAD_OPTION_INT, .min = 1.0, .max = INT_MAX, .default_value = NAN,
     .default_text = "the method's",
     .help = "hemisphere: rays per element; montecarlo: point pairs per element pair; "
             "shooting: rays per shot; instant-radiosity: light paths (default 1024)"},
    {SOLUTION(near_field), .type = RAD_OPTION_DOUBLE, .min = 0.0, .min_open = true, .max = INFINITY,
     .default_value = 3.0, .default_text = "3",
     .help = "hybrid: pairs closer than this many element sizes use the exact method"},
    {SOLUTION(closure_correction), .type = RAD_OPTION_FLAG, .default_value = 0.0,
     .help = "rescale F so rows sum to 1 keeping reciprocity; hierarchical: scale each patch's "
             "sending by its link closure (closed scenes only; refused by shooting)"},
    {SOLUTION(no_control_variate), .type = RAD_OPTION_FLAG, .default_value = 0.0,
     .help = "shooting, instant-radiosity: estimate B itself, not B less a constant per lit group whose "
             "transport is known (the control variate that makes the closed furnace exact)"},
    {SOLUTION(raw_form_factors), .type = RAD_OPTION_FLAG, .default_value = 0.0,
     .help = "hemicube, hemisphere, montecarlo: keep F as sampled, without the default step that "
             "makes it reciprocal and holds its rows to their measured closure (energy conservation)"},
    {SOLUTION(solver), .type = RAD_OPTION_METHOD, .methods = RAD_METHOD_SOLVER, .default_value = NAN,
     .default_text = "hierarchical",
     .help = "solver (without one: hierarchical, lit scenes too; gauss-seidel where an element count, a "
             "mesh size, a form-factor method or adaptive subdivision is given, and for view factors and "
             "progress images); "
             "galerkin-linear, galerkin-constant and collocation: basis functions per vertex or element "
             "(docs/methods.md, \"Galerkin elements\")"},
    {SOLUTION(tolerance), .type = RAD_OPTION_DOUBLE, .min = 0.0, .min_open = true, .max = 1.0, .max_open = true,
     .default_value = 1e-6, .default_text = "1e-6",
     .help = "stop when the residual (unaccounted power / emitted power) falls below this"},
    {SOLUTION(unshot_tolerance), .type = RAD_OPTION_DOUBLE, .min = 0.0, .min_open = true, .max = 1.0,
     .max_open = true, .default_value = NAN, .default_text = "not used",
     .help = "shooting: also stop when unshot power / emitted power falls below this"},
    {SOLUTION(max_iterations), .type = RAD_OPTION_INT, .min = 0.0, .max = INT_MAX, .default_value = NAN,
     .default_text = "0 (automatic: 2 ln(tolerance) / ln(rho_max) + 10 bounces of light, at most 10^4)",
     .help = "cap on sweeps (gathering), shots (southwell) or batches of 32 shots (shooting); above what "
             "the reflectances need it is lowered to that"},
    {SOLUTION(relaxation), .type = RAD_OPTION_DOUBLE, .min = 0.0, .min_open = true, .max = 2.0, .max_open = true,
     .default_value = 1.0, .default_text = "1",
     .help = "over-relaxation: SOR for jacobi and gauss-seidel, overshooting for southwell"},
    {SOLUTION(record_history), .type = RAD_OPTION_FLAG, .default_value = 0.0,
     .help = "keep every step's residual in the history (gathering then measures it every sweep)"},
    {SOLUTION(epsilon), .type = RAD_OPTION_DOUBLE, .min = 0.0, .min_open = true, .max = 1e6, .max_open = true,
     .default_value = 1e-4, .default_text = "1e-4",
     .help = "hierarchical: refine a link while its error (power its receiver reflects) exceeds this "
             "times the scene's emitted power (N rooms need about 1/N of one room's value for the "
             "same accuracy per room)"},
    {SOLUTION(min_area), .type = RAD_OPTION_DOUBLE, .min = 0.0, .min_open = true, .max = INFINITY,
     .default_value = NAN, .default_text = "1e-4 x the total area x min(1, 100 / patches)",
     .help = "hierarchical: smallest element area, m^2"},
    {SOLUTION(clustering), .type = RAD_OPTION_ENUM, .words = clustering_words, .default_value = 0.0,
     .default_text = "auto",
     .help = "hierarchical: start from a cluster hierarchy (auto: when there are more than 64 patches)"},
    {SOLUTION(classic_oracle), .type = RAD_OPTION_FLAG, .words = oracle_words, .default_value = 0.0,
     .default_text = "sources",
     .help = "hierarchical: split links on the receiver, visibility and the source's radiosity "
             "(sources), or on the first two only (classic: fewer links, ~3x the per-surface error)"},
    {SOLUTION(adaptive_levels), .type = RAD_OPTION_INT, .min = 0.0, .max = 12.0, .default_value = 0.0,
     .default_text = "0 (off)",
     .help = "dense solvers: after solving, split elements where the radiosity changes or a shadow "
             "edge crosses, up to this many levels (and rounds of coupling and solving) below the "
             "starting mesh"},
    {SOLUTION(adaptive_threshold), .type = RAD_OPTION_DOUBLE, .min = 0.0, .min_open = true, .max = 1e3,
     .default_value = 0.1, .default_text = "0.1",
     .help = "adaptive: split an element whose radiosity differs from a neighbour's, or whose "
             "shadowed emitter would add, more than this times the mean radiosity"},
    {SOLUTION(adaptive_max_elements), .type = RAD_OPTION_SIZE, .min = 1.0, .max = 1e8, .default_value = NAN,
     .default_text = "4 x the starting mesh's",
     .help = "adaptive: stop splitting at this many elements (balancing neighbours may add a few)"},
    {SOLUTION(seed), .type = RAD_OPTION_UINT64, UINT64_RANGE, .default_value = 0.0, .default_text = "0",
     .help = "seed of all sampling; results do not depend on the thread count"},
    {SOLUTION(max_memory_bytes), .type = RAD_OPTION_BYTES, .min = 0.0, .min_open = true, .max = INFINITY,
     .default_value = NAN,
     .default_text = "half the memory available (physical, or a lower cgroup or ulimit limit)",
     .help = "refuse to allocate more memory than this"},
};

static const rad_option_info render_rows[] = {
    {RENDER(width), .type = RAD_OPTION_INT, .min = 1.0, .max = 16384.0, .default_value = 512.0,
     .default_text = "512", .help = "image width, pixels"},
    {RENDER(height), .type = RAD_OPTION_INT, .min = 1.0, .max = 16384.0, .default_value = 512.0,
     .default_text = "512", .help = "image height, pixels"},
    {RENDER(samples), .type = RAD_OPTION_INT, .min = 1.0, .max = 16384.0, .default_value = 4.0,
     .default_text = "4",
     .help = "anti-aliasing: samples per pixel along each axis (their square in all) where a 2 x 2 pilot "
             "sees more than one patch (edges); elsewhere the pilot"},
    {RENDER(shading), .type = RAD_OPTION_ENUM, .words = shading_words, .default_value = 0.0,
     .default_text = "smooth", .help = "smooth (vertex values interpolated) or flat (one colour per element)"},
    {RENDER(exposure), .type = RAD_OPTION_DOUBLE, .min = 0.0, .min_open = true, .max = INFINITY,
     .default_value = NAN, .default_text = "automatic", .help = "multiplier on radiance before sRGB"},
    {RENDER(vpl_paths), .type = RAD_OPTION_INT, .min = 1.0, .max = 1e7, .default_value = NAN,
     .default_text = "off (the solved radiosity)",
     .help = "per-pixel instant radiosity: this many light paths' virtual point lights and the emitters "
             "gathered at each camera ray's point (view-dependent; the 1/r^2 clamp as the "
             "instant-radiosity solver's)"},
    {RENDER(specular_depth), .type = RAD_OPTION_INT, .min = -1.0, .max = 64.0, .default_value = 8.0,
     .default_text = "8",
     .help = "second pass: mirror, glass and glossy bounces followed from the eye where the scene has "
             "specular materials; -1: the first pass alone"},
    {RENDER(glossy_samples), .type = RAD_OPTION_INT, .min = 1.0, .max = 16384.0, .default_value = 16.0,
     .default_text = "16", .help = "second pass: rays a glossy surface seen from the eye sends"},
    {RENDER(direct_gather), .type = RAD_OPTION_INT, .min = -1.0, .max = 1.0, .default_value = 1.0,
     .default_text = "1 (on)",
     .help = "final gather: the emitting surfaces' direct light computed at each pixel's point with exact "
             "visibility, the solved elements for the rest (sharp shadows); -1: the elements alone"},
};

static const rad_option_info office_rows[] = {
    {OFFICE(rooms), .type = RAD_OPTION_INT, .min = 1.0, .max = 100000.0, .default_value = 4.0,
     .default_text = "4", .help = "rooms on the floor"},
    {OFFICE(seed), .type = RAD_OPTION_UINT64, UINT64_RANGE, .default_value = 0.0, .default_text = "0",
     .help = "seed of the layout; the same seed gives the same scene"},
    {OFFICE(closed_doors), .type = RAD_OPTION_FLAG, .default_value = 0.0,
     .help = "close every door: a door leaf on both faces of the wall, each room sealed"},
};

#define COUNT(rows) (sizeof rows / sizeof rows[0])

static const struct {
    const char *name;
    const rad_option_info *rows;
    size_t count;
} sets[] = {
    [RAD_OPTION_SET_SOLUTION] = {"rad_options", solution_rows, COUNT(solution_rows)},
    [RAD_OPTION_SET_RENDER] = {"rad_render_options", render_rows, COUNT(render_rows)},
    [RAD_OPTION_SET_OFFICE] = {"rad_office_options", office_rows, COUNT(office_rows)},
};

const rad_option_info *rad_option_info_get(rad_option_set set, size_t index)
{
    if ((size_t)set >= COUNT(sets) || index >= sets[set].count)
        return NULL;
    return &sets[set].rows[index];
}

const rad_option_info *rad_option_find(rad_option_set set, const char *name)
{
    const rad_option_info *o;
    for (size_t i = 0; name && (o = rad_option_info_get(set, i)); i++)
        if (strcmp(o->name, name) == 0)
            return o;
    return NULL;
}

const char *rad_option_set_name(rad_option_set set)
{
    return (size_t)set < COUNT(sets) ? sets[set].name : "";
}

static int is_number(rad_option_type type)
{
    return type == RAD_OPTION_INT || type == RAD_OPTION_SIZE || type == RAD_OPTION_DOUBLE ||
           type == RAD_OPTION_BYTES;
}

bool rad_option_in_range(const rad_option_info *o, double value)
{
    if (!o)
        return false;
    if (o->type == RAD_OPTION_ENUM) {
        for (const rad_option_word *w = o->words; w->word; w++)
            if (value == w->value)
                return true;
        return false;
    }
    if (!is_number(o->type))
        return true;
    return isfinite(value) && (o->min_open ? value > o->min : value >= o->min) &&
           (o->max_open ? value < o->max : value <= o->max);
}

bool rad_option_lookup_word(const rad_option_info *o, const char *text, int *value)
{
    if (!o || !text)
        return false;
    if (o->type == RAD_OPTION_METHOD) {
        const char *name, *description;
        for (size_t i = 0; rad_method_info(o->methods, i, &name, &description); i++)
            if (strcmp(name, text) == 0)
                return true;
        return false;
    }
    if (o->type != RAD_OPTION_FLAG && o->type != RAD_OPTION_ENUM)
        return false;
    for (const rad_option_word *w = o->words; w && w->word; w++)
        if (strcmp(w->word, text) == 0) {
            if (value)
                *value = w->value;
            return true;
        }
    return false;
}

/* Appends to a bounded buffer; `length` counts what was wanted. */
typedef struct text_out {
    char *text;
    size_t size, length;
} text_out;

static void put(text_out *t, const char *s)
{
    size_t n = strlen(s);
    if (t->length + 1 < t->size) {
        size_t room = t->size - 1 - t->length;
        memcpy(t->text + t->length, s, n < room ? n : room);
        t->text[t->length + (n < room ? n : room)] = '\0';
    }
    t->length += n;
}

/* "a, b or c", the i-th of n items at a time. */
static void put_listed(text_out *t, size_t i, size_t n, const char *item)
{
    if (i > 0)
        put(t, i + 1 == n ? " or " : ", ");
    put(t, item);
}

size_t rad_option_range_text(const rad_option_info *o, char *text, size_t size)
{
    if (!text)
        size = 0;
    text_out t = {text, size, 0};
    if (size)
        text[0] = '\0';
    if (!o)
        return 0;
    char number[64];
    if (is_number(o->type) || o->type == RAD_OPTION_UINT64) {
        put(&t, o->min_open ? "(" : "[");
        if (o->type == RAD_OPTION_UINT64) /* a double cannot hold 2^64 - 1 */
            snprintf(number, sizeof number, "0, %" PRIu64, UINT64_MAX);
        else
            snprintf(number, sizeof number, "%.15g, %.15g", o->min, o->max);
        put(&t, number);
        put(&t, o->max_open || isinf(o->max) ? ")" : "]");
    } else if (o->type == RAD_OPTION_ENUM || (o->type == RAD_OPTION_FLAG && o->words)) {
        size_t n = 0;
        while (o->words[n].word)
            n++;
        for (size_t i = 0; i < n; i++)
            put_listed(&t, i, n, o->words[i].word);
    } else if (o->type == RAD_OPTION_METHOD) {
        const char *name, *description;
        size_t n = 0;
        while (rad_method_info(o->methods, n, &name, &description))
            n++;
        for (size_t i = 0; i < n && rad_method_info(o->methods, i, &name, &description); i++)
            put_listed(&t, i, n, name);
    }
    return t.length;
}

/* ---- rad_options: defaults and checks ---- */

/* Registry names are short; the copy keeps the options independent of the
 * caller's strings. */
static void copy_name(char *dst, size_t size, const char *name)
{
    snprintf(dst, size, "%s", name);
}

/* Fill in the default of one field of `o` when it is 0 (NULL) and check
 * it against its row. */
static rad_result resolve_field(rad_context *ctx, const rad_option_info *row, rad_options *o)
{
    char *field = (char *)o + row->offset;
    char range[512], got[64];
    rad_option_range_text(row, range, sizeof range);
    double value = 0.0;
    switch (row->type) {
    case RAD_OPTION_INT:
    case RAD_OPTION_FLAG:
    case RAD_OPTION_ENUM: {
        int *v = (int *)field;
        if (*v == 0 && isfinite(row->default_value))
            *v = (int)row->default_value;
        value = *v;
        snprintf(got, sizeof got, "%d", *v);
        break;
    }
    case RAD_OPTION_SIZE: {
        size_t *v = (size_t *)field;
        if (*v == 0 && isfinite(row->default_value))
            *v = (size_t)row->default_value;
        value = (double)*v;
        snprintf(got, sizeof got, "%zu", *v);
        break;
    }
    case RAD_OPTION_DOUBLE:
    case RAD_OPTION_BYTES: {
        double *v = (double *)field;
        if (*v == 0.0 && isfinite(row->default_value))
            *v = row->default_value;
        value = *v;
        snprintf(got, sizeof got, "%g", *v);
        break;
    }
    case RAD_OPTION_METHOD: {
        const char **v = (const char **)field;
        if (!*v)
            *v = row->default_text;
        if (!rad_option_lookup_word(row, *v, NULL))
            return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "rad_options.%s must be one of %s, got '%s'",
                            row->name, range, *v);
        return RAD_OK;
    }
    case RAD_OPTION_UINT64:
    case RAD_OPTION_STRING: return RAD_OK;
    }
    if (value == 0.0 || rad_option_in_range(row, value))
        return RAD_OK;
    if (row->type == RAD_OPTION_ENUM) {
        /* The library's callers set numbers: give them with the words. */
        text_out t = {range, sizeof range, 0};
        range[0] = '\0';
        size_t n = 0;
        while (row->words[n].word)
            n++;
        for (size_t i = 0; i < n; i++) {
            char item[64];
            snprintf(item, sizeof item, "%d (%s)", row->words[i].value, row->words[i].word);
            put_listed(&t, i, n, item);
        }
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "rad_options.%s must be %s, got %s", row->name,
                        range, got);
    }
    return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "rad_options.%s must be in %s, got %s", row->name, range,
                    got);
}

const char *rad_options_default_solver(const rad_options *o, unsigned needs)
{
    if (o->mesh_size != 0.0 || o->target_elements != 0)
        needs |= RAD_HAS_UNIFORM_MESH;
    if (o->form_factors)
        needs |= RAD_HAS_FORM_FACTORS;
    if (o->adaptive_levels != 0 || o->adaptive_threshold != 0.0 || o->adaptive_max_elements != 0)
        needs |= RAD_CAN_ADAPTIVE;
    const char *solver = rad_option_find(RAD_OPTION_SET_SOLUTION, "solver")->default_text;
    return (rad_strategy_capabilities(solver) & needs) == needs ? solver : "gauss-seidel";
}

rad_result rad_options_resolve(rad_context *ctx, const rad_options *in, rad_options *out, rad_method_names *names)
{
    rad_options o = in ? *in : (rad_options){0};
    /* No solver named: the table's default, unless an option it would
     * ignore is given. */
    if (!o.solver)
        o.solver = rad_options_default_solver(&o, 0);
    for (size_t i = 0; i < COUNT(solution_rows); i++) {
        rad_result r = resolve_field(ctx, &solution_rows[i], &o);
        if (r != RAD_OK)
            return r;
    }
    /* The one default that is not a constant: the context's memory limit
     * (rad_context_options.max_memory_bytes), which a solution's own only
     * lowers (api.c). */
    if (o.max_memory_bytes == 0.0)
        o.max_memory_bytes = rad_memory_limit(ctx);
    if (!(o.max_memory_bytes > 0.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "rad_options.max_memory_bytes: the physical memory is unknown, give a limit");
    copy_name(names->form_factors, sizeof names->form_factors, o.form_factors);
    copy_name(names->solver, sizeof names->solver, o.solver);
    copy_name(names->visibility, sizeof names->visibility, o.visibility);
    o.form_factors = names->form_factors;
    o.solver = names->solver;
    o.visibility = names->visibility;
    const rad_strategy *strategy = rad_strategy_for_solver(o.solver);
    if (o.adaptive_levels > 0 && strategy && !(rad_strategy_capabilities(o.solver) & RAD_CAN_ADAPTIVE))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "rad_options.adaptive_levels subdivides the mesh of the dense solvers; solver '%s' "
                        "(%s) makes its own",
                        o.solver, strategy->name);
    *out = o;
    return RAD_OK;
}
