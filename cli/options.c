/*
 * options.c -- the `radiosity` command's flags (see options.h): the table,
 * the parser every command shares, --help and the man page printed from
 * the table, and the library's field names rewritten into flags.
 *
 * A flag that sets a library field takes the field's type, range, default
 * and help from the library's option table (radiosity.h), so the program
 * accepts exactly what the library accepts and documents what the library
 * does.  The parser has no side effects: errors go into the caller's
 * buffer, and --help / --version / --list-methods / --man are returned as
 * actions for main.c to carry out.
 */
#include "options.h"

#include <ctype.h>
#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the commands ---- */

typedef struct command_def {
    int bit;
    const char *name;
    const char *synopsis;  /* after "radiosity " */
    const char *summary;
} command_def;

static const command_def COMMANDS[] = {
    {CLI_RENDER, "render", "render [SCENE|SOLUTION.radsol] [options]",
     "solve the scene (or load the solution) and write an image"},
    {CLI_VIEWFACTORS, "viewfactors", "viewfactors [SCENE] [options]",
     "write the view factors between the scene's named surfaces"},
    {CLI_EXPORT, "export", "export [SCENE|SOLUTION.radsol] [options]",
     "solve the scene (or load the solution) and write the lit mesh: glTF 2.0 (.glb, .gltf) or PLY "
     "(docs/formats.md)"},
    {CLI_GENERATE, "generate", "generate office [options]",
     "write a procedural office floor as OBJ + MTL (docs/scenes.md)"},
    {CLI_SOLVE, "solve", "solve [SCENE] [options]",
     "solve the scene and write the solution file, to render from any camera without solving again"},
    {CLI_BAKE, "bake", "bake [SCENE|SOLUTION.radsol] [options]",
     "solve the scene (or load the solution) and write lightmaps (HDR, RGBM PNG) with the glTF lit mesh "
     "that uses them (docs/formats.md)"},
    {CLI_THERMAL, "thermal", "thermal [SCENE] --bc BC.json [options]",
     "radiative heat exchange between grey diffuse surfaces with given temperatures or heat fluxes: "
     "radiosity, net flux, net power and the unknown temperatures per surface (docs/thermal.md)"},
    {CLI_PHOTOMETRY, "photometry", "photometry FILE...",
     "read luminaire photometric files (IES LM-63 1986-2019, EULUMDAT .ldt) and print each one's summary: "
     "format, type, symmetry, angles, maximum candela and its direction, flux, rated lumens, light output "
     "ratio, luminous opening, tilt (docs/lighting.md)"},
    {CLI_VIEW, "view", "view [SCENE|SOLUTION.radsol] [options]",
     "open a window that shows the solution as the solver refines it (progressive), or with --offscreen "
     "draw one frame with OpenGL without a window (docs/viewer.md; an optional build part)"},
    {CLI_ILLUMINANCE, "illuminance", "illuminance [SCENE] --grid G.json [-o E.csv] [-o E.json] [options]",
     "solve the scene and compute the illuminance in lux at the grid file's calculation points (work planes "
     "spaced by EN 12464-1, a surface's footprint at a height, free points), direct and indirect, with Eavg, "
     "Emin, Emax and U0 per grid (docs/lighting.md)"},
};
#define COMMAND_COUNT (sizeof COMMANDS / sizeof COMMANDS[0])

const char *cli_command_name(int command)
{
    for (size_t k = 0; k < COMMAND_COUNT; k++)
        if (COMMANDS[k].bit == command)
            return COMMANDS[k].name;
    return "";
}

/* ---- the flags ---- */

/* The commands that solve (render, export, solve, bake, view), and those
 * that also mesh and couple (viewfactors, thermal); view writes no stats or
 * history (its rows below take it out). */
#define RS (CLI_RENDER | CLI_EXPORT | CLI_SOLVE | CLI_BAKE | CLI_VIEW | CLI_ILLUMINANCE)
#define RV (CLI_RENDER | CLI_VIEWFACTORS | CLI_EXPORT | CLI_SOLVE | CLI_BAKE | CLI_VIEW | CLI_THERMAL | CLI_ILLUMINANCE)
#define ALL (CLI_RENDER | CLI_VIEWFACTORS | CLI_EXPORT | CLI_GENERATE | CLI_SOLVE | CLI_BAKE | CLI_VIEW | CLI_THERMAL | \
             CLI_ILLUMINANCE)
/* The solver's own flags, for the commands that solve B and for thermal's net-radiation solve. */
#define RST (RS | CLI_THERMAL)
#define SOLVE(field_) .target = CLI_TO_SOLVE, .field = #field_
#define RENDER(field_) .target = CLI_TO_RENDER, .field = #field_
#define OFFICE(field_) .target = CLI_TO_OFFICE, .field = #field_
#define OWN(field_, type_) .target = CLI_TO_SETTINGS, .own.name = #field_, \
    .own.offset = offsetof(cli_settings, field_), .own.type = type_
#define ACTION(action_) .target = CLI_TO_ACTION, .action = action_

static const rad_option_word level_words[] = {{"surface", 0}, {"element", 1}, {NULL, 0}};
static const rad_option_word smooth_words[] = {{"enclosure", RAD_SMOOTH_ENCLOSURE}, {"open", RAD_SMOOTH_OPEN},
                                               {NULL, 0}};
static const rad_option_word lightmap_words[] = {{"radiosity", RAD_LIGHTMAP_RADIOSITY},
                                                 {"irradiance", RAD_LIGHTMAP_IRRADIANCE},
                                                 {NULL, 0}};

static const rad_option_word false_colour_words[] = {{"luminance", RAD_FALSE_COLOUR_LUMINANCE},
                                                     {"illuminance", RAD_FALSE_COLOUR_ILLUMINANCE},
                                                     {NULL, 0}};
static const rad_option_word scale_words[] = {{"linear", 0}, {"log", 1}, {NULL, 0}};

static const rad_option_word missing_texture_words[] = {{"error", 0}, {"flat", 1}, {NULL, 0}};

static const cli_flag FLAGS[] = {
    {"output", 'o', "FILE", CLI_RENDER, OWN(output, RAD_OPTION_STRING),
     .own.help = "output image: .png (exposed, sRGB), .hdr or .pfm (linear)",
     .own.default_text = "radiosity.png"},
    {"output", 'o', "FILE", CLI_VIEWFACTORS, OWN(output, RAD_OPTION_STRING),
     .own.help = "output view factors: .json, .csv, .mtx or .vf (View3D's file) (docs/formats.md)",
     .own.default_text = "viewfactors.json"},
    {"output", 'o', "FILE", CLI_EXPORT, OWN(output, RAD_OPTION_STRING),
     .own.help = "output lit mesh: .glb or .gltf (glTF 2.0) or .ply (docs/formats.md)",
     .own.default_text = "lit.glb"},
    {"output", 'o', "FILE", CLI_GENERATE, OWN(output, RAD_OPTION_STRING),
     .own.help = "output OBJ; the MTL is written beside it", .own.default_text = "office.obj"},
    {"output", 'o', "FILE", CLI_SOLVE, OWN(output, RAD_OPTION_STRING),
     .own.help = "output solution file, .radsol (docs/formats.md); `radiosity render FILE` draws it",
     .own.default_text = "solution.radsol"},
    {"output", 'o', "FILE", CLI_BAKE, OWN(output, RAD_OPTION_STRING),
     .own.help = "output lit mesh: .glb or .gltf; the lightmaps FILE_lightmapK.hdr and .png beside it",
     .own.default_text = "lightmapped.glb"},
    {"output", 'o', "FILE", CLI_THERMAL, OWN(output, RAD_OPTION_STRING),
     .own.help = "output heat exchange per surface (or element, --level): .csv or .json (docs/thermal.md)",
     .own.default_text = "heat.csv"},
    {"bc", 0, "FILE.json", CLI_THERMAL, OWN(bc, RAD_OPTION_STRING),
     .own.help = "boundary conditions: each surface's emissivity and temperature, heat flux or adiabatic, "
                 "and the environment temperature (docs/thermal.md); required"},
    {"daylight", 0, "FILE.json", RV, OWN(daylight, RAD_OPTION_STRING),
     .own.help = "light the scene by daylight: a CIE sky, the sun, the ground, entering through the surfaces "
                 "the file names as openings, which leave the scene (docs/lighting.md \"Daylight\")"},
    {"gebhart", 0, "FILE", CLI_THERMAL, OWN(gebhart, RAD_OPTION_STRING),
     .own.help = "also write the Gebhart factors between surfaces: .csv or .json"},
    {"output", 'o', "FILE", CLI_VIEW, OWN(output, RAD_OPTION_STRING),
     .own.help = "with --offscreen: the frame, .png (exposed, sRGB), .hdr or .pfm (linear)",
     .own.default_text = "view.png"},
    {"output", 'o', "FILE", CLI_ILLUMINANCE, OWN(output, RAD_OPTION_STRING),
     .own.help = "output illuminance: .csv (one row per point), .json (per grid: Eavg, Emin, Emax, U0 and "
                 "the points) or .png (each grid's plan, FILE_GRID.png: cells coloured and labelled in lux, "
                 "--scale, --range); give -o twice for two of them (docs/lighting.md)",
     .own.default_text = "illuminance.csv"},
    {"grid", 0, "G.json", CLI_ILLUMINANCE, OWN(grid, RAD_OPTION_STRING),
     .own.help = "the calculation grids and points: rectangles, surface footprints at a height, free points "
                 "(docs/lighting.md, \"Calculation grids and points\"); required"},
    {"offscreen", 0, NULL, CLI_VIEW, OWN(offscreen, RAD_OPTION_FLAG),
     .own.help = "draw one frame with OpenGL (EGL, no window or display needed) to --output and exit"},
    {"no-ambient", 0, NULL, CLI_VIEW, OWN(no_ambient, RAD_OPTION_FLAG),
     .own.help = "show the radiosity without the ambient term of the unshot light (shooting)"},
    {"keys", 0, "K1,K2,...", CLI_VIEW, OWN(keys, RAD_OPTION_STRING),
     .own.help = "keys the window presses itself, one a frame (SDL key names; \"wait\" holds until the "
                 "solve ends): \"wait,p,c,q\" saves a screenshot, prints the camera and quits"},
    {"texels-per-metre", 0, "N", CLI_BAKE, OWN(texels_per_metre, RAD_OPTION_DOUBLE), .own.min = 0.0,
     .own.max = 1e6, .own.min_open = true, .own.default_text = "10",
     .own.help = "lightmap texels per metre of surface"},
    {"atlas-size", 0, "S", CLI_BAKE, OWN(atlas_size, RAD_OPTION_INT), .own.min = 8.0, .own.max = 16384.0,
     .own.default_text = "2048", .own.help = "largest atlas side in texels, a power of two"},
    {"lightmap", 0, "WHICH", CLI_BAKE, OWN(lightmap_quantity, RAD_OPTION_ENUM), .own.words = lightmap_words,
     .own.default_text = "radiosity",
     .own.help = "what the texels hold: radiosity B, or irradiance H = (B - E)/rho (as B/pi, H/pi, W/(m^2 sr))"},
    {"luminaires", 0, "FILE.json", CLI_RENDER | CLI_EXPORT | CLI_SOLVE | CLI_BAKE | CLI_VIEW | CLI_ILLUMINANCE,
     OWN(luminaires, RAD_OPTION_STRING),
     .own.help = "place luminaires from a layout file (photometric files, positions, aims; docs/lighting.md): "
                 "their direct light reaches every element exactly and its reflection enters the solve"},
    {"rooms", 0, "N", CLI_GENERATE, OFFICE(rooms)},
    {"seed", 0, "S", CLI_GENERATE, OFFICE(seed)},
    {"closed-doors", 0, NULL, CLI_GENERATE, OFFICE(closed_doors)},
    {"mesh-size", 0, "L", RV, SOLVE(mesh_size)},
    {"elements", 0, "N", RV, SOLVE(target_elements)},
    {"form-factors", 0, "NAME", RV, SOLVE(form_factors)},
    {"solver", 0, "NAME", RS, SOLVE(solver)},
    {"solver", 0, "NAME", CLI_THERMAL, OWN(thermal_solver, RAD_OPTION_METHOD), .own.methods = RAD_METHOD_SOLVER,
     .own.default_text = "direct",
     .own.help = "linear solver of the net-radiation equations, on the form-factor matrix (not hierarchical "
                 "or shooting)"},
    {"visibility", 0, "NAME", RV, SOLVE(visibility)},
    {"shadow-rays", 0, "N", RV, SOLVE(shadow_rays)},
    {"hemicube-res", 0, "N", RV, SOLVE(hemicube_resolution)},
    {"ff-samples", 0, "N", RV, SOLVE(samples)},
    {"near-field", 0, "X", RV, SOLVE(near_field)},
    {"closure-correction", 0, NULL, RV, SOLVE(closure_correction)},
    {"raw-form-factors", 0, NULL, RV, SOLVE(raw_form_factors)},
    {"no-control-variate", 0, NULL, RV, SOLVE(no_control_variate)},
    {"adaptive", 0, "LEVELS", RS, SOLVE(adaptive_levels)},
    {"adaptive-threshold", 0, "X", RS, SOLVE(adaptive_threshold)},
    {"adaptive-elements", 0, "N", RS, SOLVE(adaptive_max_elements)},
    {"level", 0, "WHICH", CLI_VIEWFACTORS, OWN(element_level, RAD_OPTION_ENUM), .own.words = level_words,
     .own.default_text = "surface", .own.help = "view factors between surfaces or between elements"},
    {"level", 0, "WHICH", CLI_THERMAL, OWN(element_level, RAD_OPTION_ENUM), .own.words = level_words,
     .own.default_text = "surface", .own.help = "heat exchange per surface or per element"},
    {"smooth", 0, "WHICH", CLI_VIEWFACTORS, OWN(smooth, RAD_OPTION_ENUM), .own.words = smooth_words,
     .own.help = "least-squares enclosure smoothing of the surface factors written: reciprocal, rows summing "
                 "to 1 (enclosure) or to their measured sums (open) (docs/methods.md)"},
    {"sparse-threshold", 0, "X", CLI_VIEWFACTORS, OWN(sparse_threshold, RAD_OPTION_DOUBLE), .own.min = 0.0,
     .own.max = 1.0, .own.min_open = true, .own.max_open = true,
     .own.help = "with -o F.mtx: pairs of factors below X dropped, the rest rebalanced so reciprocity and "
                 "the row sums still hold"},
    {"block-rows", 0, "N", CLI_VIEWFACTORS, OWN(block_rows, RAD_OPTION_SIZE), .own.min = 1.0, .own.max = 1e9,
     .own.default_text = "automatic",
     .own.help = "make the factors N element rows at a time, never the whole matrix (memory O(n) beyond a "
                 "block; each pair across blocks evaluated twice); without it, only when the matrix would "
                 "pass the memory limit (docs/formats.md, streamed view factors)"},
    {"epsilon", 0, "X", RS, SOLVE(epsilon)},
    {"min-area", 0, "A", RS, SOLVE(min_area)},
    {"clustering", 0, "WHEN", RS, SOLVE(clustering)},
    {"oracle", 0, "WHICH", RS, SOLVE(classic_oracle)},
    {"tolerance", 0, "X", RS, SOLVE(tolerance)},
    {"tolerance", 0, "X", CLI_THERMAL, OWN(thermal_tolerance, RAD_OPTION_DOUBLE), .own.min = 0.0, .own.max = 1.0,
     .own.min_open = true, .own.max_open = true, .own.default_text = "1e-10",
     .own.help = "stop the net-radiation solve when its residual (relative to sum A |E|) falls below"},
    {"max-iterations", 0, "N", RST, SOLVE(max_iterations)},
    {"unshot-tolerance", 0, "X", RS, SOLVE(unshot_tolerance)},
    {"relaxation", 0, "W", RS, SOLVE(relaxation)},
    {"history", 0, "FILE.csv", RS & ~CLI_VIEW, OWN(history, RAD_OPTION_STRING),
     .own.help = "write the convergence history: iteration, seconds, residual, unshot power"},
    {"progress-images", 0, "DIR", CLI_RENDER, OWN(progress_dir, RAD_OPTION_STRING),
     .own.help = "write the image every --every iterations while solving (progressive display; hierarchical: "
                 "the current leaves after each sweep, refinement rounds included); at most 1000 frames"},
    {"every", 0, "K", CLI_RENDER, OWN(every, RAD_OPTION_INT), .own.min = 1.0, .own.max = INT_MAX,
     .own.default_text = "1", .own.help = "with --progress-images: every K iterations"},
    {"width", 0, "W", CLI_RENDER | CLI_VIEW, RENDER(width)},
    {"height", 0, "H", CLI_RENDER | CLI_VIEW, RENDER(height)},
    {"samples", 0, "N", CLI_RENDER, RENDER(samples)},
    {"camera", 0, "P,L[,U[,FOV]]", CLI_RENDER | CLI_VIEW, OWN(camera, RAD_OPTION_STRING),
     .own.help = "camera: position px,py,pz, look-at point lx,ly,lz, up ux,uy,uz (0,1,0), "
                 "vertical field of view in degrees (40)",
     .own.default_text = "the scene's camera, else framed automatically"},
    {"exposure", 0, "X", CLI_RENDER | CLI_VIEW, RENDER(exposure)},
    {"exposure", 0, "X", CLI_EXPORT | CLI_BAKE, RENDER(exposure),
     .help = "multiplier on radiance for the display colours (glTF COLOR_0, PLY red/green/blue)"},
    {"flat", 0, NULL, CLI_RENDER | CLI_VIEW, RENDER(shading), .word = "flat",
     .help = "flat shading: one colour per element"},
    {"vpl", 0, "N", CLI_RENDER, RENDER(vpl_paths)},
    {"false-colour", 0, "WHAT", CLI_RENDER, OWN(false_colour, RAD_OPTION_ENUM), .own.words = false_colour_words,
     .own.help = "write a false colour PNG instead of the image: luminance (cd/m^2 of the rendered "
                 "radiance) or illuminance (lux on the surfaces seen), with a legend (docs/lighting.md "
                 "\"Pictures\")"},
    {"scale", 0, "WHICH", CLI_RENDER | CLI_ILLUMINANCE, OWN(log_scale, RAD_OPTION_ENUM), .own.words = scale_words,
     .own.default_text = "linear",
     .own.help = "with --false-colour, or illuminance's .png plans: the colour scale, linear or log"},
    {"range", 0, "MIN:MAX", CLI_RENDER | CLI_ILLUMINANCE, OWN(range, RAD_OPTION_STRING),
     .own.default_text = "automatic: 0 (log: max/1000) to the 99th percentile rounded up to a nice number",
     .own.help = "with --false-colour, or illuminance's .png plans: the values at the two ends of the colour "
                 "scale (cd/m^2 or lx)"},
    {"contours", 0, NULL, CLI_RENDER, OWN(contours, RAD_OPTION_FLAG),
     .own.help = "with --false-colour: black lines where the value crosses a legend tick (isolux, "
                 "isoluminance)"},
    {"specular-depth", 0, "N", CLI_RENDER, RENDER(specular_depth)},
    {"glossy-samples", 0, "N", CLI_RENDER, RENDER(glossy_samples)},
    {"direct-gather", 0, "N", CLI_RENDER, RENDER(direct_gather)},
    {"seed", 0, "S", RV, SOLVE(seed)},
    {"threads", 0, "N", RV, OWN(threads, RAD_OPTION_INT), .own.min = 1.0, .own.max = 1024.0,
     .own.default_text = "all cores", .own.help = "worker threads; results do not depend on them"},
    {"stats", 0, "FILE.json", RV & ~CLI_VIEW, OWN(stats, RAD_OPTION_STRING),
     .own.help = "write run statistics as JSON (docs/stats.md)"},
    {"max-memory", 0, "SIZE", RV, SOLVE(max_memory_bytes)},
    {"missing-textures", 0, "WHAT", RV, OWN(missing_textures, RAD_OPTION_ENUM), .own.words = missing_texture_words,
     .own.default_text = "error",
     .own.help = "a texture (map_Kd, baseColorTexture) that cannot be read: error (fail, naming the "
                 "material, file and line) or flat (warn and use the material's flat colour)"},
    {"read-outside-scene-folder", 0, NULL, RV | CLI_PHOTOMETRY, OWN(read_outside, RAD_OPTION_FLAG),
     .own.help = "let the scene refer to files outside its folder (by default an mtllib, glTF "
                 "buffer or image that resolves outside the scene file's folder is refused)"},
    {"quiet", 'q', NULL, ALL, OWN(quiet, RAD_OPTION_FLAG), .own.help = "print nothing but errors"},
    {"list-methods", 0, NULL, 0, ACTION(CLI_LIST_METHODS),
     .help = "list form-factor methods, solvers and ray backends"},
    {"version", 0, NULL, 0, ACTION(CLI_VERSION), .help = "print the version"},
    {"man", 0, NULL, 0, ACTION(CLI_MAN), .help = "print the manual page as roff (man -l)"},
    {"help", 'h', NULL, 0, ACTION(CLI_HELP), .help = "print this help; after a command, that command's"},
};
#define FLAG_COUNT (sizeof FLAGS / sizeof FLAGS[0])

const cli_flag *cli_flag_get(size_t index)
{
    return index < FLAG_COUNT ? &FLAGS[index] : NULL;
}

/* The library's set of a flag's field; -1 for the program's own flags. */
static int flag_set(const cli_flag *f)
{
    switch (f->target) {
    case CLI_TO_SOLVE: return RAD_OPTION_SET_SOLUTION;
    case CLI_TO_RENDER: return RAD_OPTION_SET_RENDER;
    case CLI_TO_OFFICE: return RAD_OPTION_SET_OFFICE;
    case CLI_TO_SETTINGS:
    case CLI_TO_ACTION: break;
    }
    return -1;
}

const rad_option_info *cli_flag_info(const cli_flag *f)
{
    int set = flag_set(f);
    return set < 0 ? &f->own : rad_option_find((rad_option_set)set, f->field);
}

static const char *flag_help(const cli_flag *f)
{
    return f->help ? f->help : cli_flag_info(f)->help;
}

/* Where a flag's value is stored in the settings. */
static void *flag_field(const cli_flag *f, cli_settings *s)
{
    char *base = f->target == CLI_TO_SOLVE    ? (char *)&s->solve
                 : f->target == CLI_TO_RENDER ? (char *)&s->render
                 : f->target == CLI_TO_OFFICE ? (char *)&s->office
                                              : (char *)s;
    return base + cli_flag_info(f)->offset;
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

/* What a value must look like, for messages: "a number in (0, 1)". */
static void expectation(const rad_option_info *o, char *text, size_t size)
{
    char range[512];
    rad_option_range_text(o, range, sizeof range);
    switch (o->type) {
    case RAD_OPTION_INT:
    case RAD_OPTION_SIZE:
    case RAD_OPTION_UINT64: snprintf(text, size, "an integer in %s", range); break;
    case RAD_OPTION_DOUBLE: snprintf(text, size, "a number in %s", range); break;
    case RAD_OPTION_BYTES: snprintf(text, size, "a size such as 4G or 512M, in %s bytes", range); break;
    case RAD_OPTION_METHOD: snprintf(text, size, "one of %s", range); break;
    case RAD_OPTION_FLAG:
    case RAD_OPTION_ENUM: snprintf(text, size, "%s", range); break;
    case RAD_OPTION_STRING: snprintf(text, size, "a value"); break;
    }
}

/* Parse `text` as the value of a row into `field` (of the row's C type).
 * Returns 0, or 1 with nothing stored. */
static int parse_value(const rad_option_info *o, const char *text, void *field)
{
    char *end = NULL;
    errno = 0;
    switch (o->type) {
    case RAD_OPTION_INT:
    case RAD_OPTION_SIZE: {
        long long v = strtoll(text, &end, 10);
        if (end == text || *end != '\0' || errno == ERANGE || !rad_option_in_range(o, (double)v))
            return 1;
        if (o->type == RAD_OPTION_INT)
            *(int *)field = (int)v; /* the range is within int */
        else
            *(size_t *)field = (size_t)v;
        return 0;
    }
    case RAD_OPTION_UINT64: {
        /* Digits only: strtoull would take "-1" as 2^64 - 1.  No double on
         * the way, so every value is exact. */
        if (text[0] < '0' || text[0] > '9')
            return 1;
        unsigned long long v = strtoull(text, &end, 10);
        if (*end != '\0' || errno == ERANGE)
            return 1;
        *(uint64_t *)field = (uint64_t)v;
        return 0;
    }
    case RAD_OPTION_DOUBLE:
    case RAD_OPTION_BYTES: {
        double v = strtod(text, &end);
        if (end != text && o->type == RAD_OPTION_BYTES) {
            double unit = 1.0;
            switch (*end) {
            case 'K': case 'k': unit = 1024.0; break;
            case 'M': case 'm': unit = 1048576.0; break;
            case 'G': case 'g': unit = 1073741824.0; break;
            }
            if (unit > 1.0)
                v *= unit, end++;
        }
        /* Overflow gives infinity, which no range holds; underflow gives
         * what is nearest, which the range judges. */
        if (end == text || *end != '\0' || !rad_option_in_range(o, v))
            return 1;
        *(double *)field = v;
        return 0;
    }
    case RAD_OPTION_FLAG:
    case RAD_OPTION_ENUM: {
        int v;
        if (!rad_option_lookup_word(o, text, &v))
            return 1;
        *(int *)field = v;
        return 0;
    }
    case RAD_OPTION_METHOD:
        if (!rad_option_lookup_word(o, text, NULL))
            return 1;
        *(const char **)field = text;
        return 0;
    case RAD_OPTION_STRING: *(const char **)field = text; return 0;
    }
    return 1;
}

/* A switch: 1, or the value of its word. */
static void set_switch(const cli_flag *f, cli_settings *s)
{
    int value = 1;
    if (f->word)
        rad_option_lookup_word(cli_flag_info(f), f->word, &value);
    *(int *)flag_field(f, s) = value;
}

/* The flag `arg` names ("--name", "--name=...", "-x") for the command, or
 * NULL; *known tells whether some command has it. */
static const cli_flag *find_flag(const char *arg, int command, int *known, const char **value)
{
    const char *name = NULL;
    size_t len = 0;
    *value = NULL;
    *known = 0;
    if (arg[1] == '-') {
        name = arg + 2;
        const char *eq = strchr(name, '=');
        len = eq ? (size_t)(eq - name) : strlen(name);
        if (eq)
            *value = eq + 1;
    } else if (arg[2] != '\0') {
        return NULL;
    }
    for (size_t k = 0; k < FLAG_COUNT; k++) {
        const cli_flag *f = &FLAGS[k];
        int match = name ? strlen(f->name) == len && strncmp(f->name, name, len) == 0
                         : f->short_name && f->short_name == arg[1];
        if (!match)
            continue;
        *known = 1;
        if (!f->commands || (f->commands & command))
            return f;
    }
    return NULL;
}

/* The default of the command's --output (its row's default). */
static const char *default_output(int command)
{
    for (size_t k = 0; k < FLAG_COUNT; k++)
        if (strcmp(FLAGS[k].name, "output") == 0 && (FLAGS[k].commands & command))
            return FLAGS[k].own.default_text;
    return NULL;
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
    for (size_t k = 0; k < COMMAND_COUNT; k++)
        if (strcmp(argv[1], COMMANDS[k].name) == 0)
            s->command = COMMANDS[k].bit, i = 2;
    for (; i < argc; i++) {
        const char *arg = argv[i];
        if (arg[0] != '-' || arg[1] == '\0') {
            /* A scene: a file for render, viewfactors, solve and export, a kind for generate. */
            if (!s->command) {
                usage_error(e, "unknown command '%s'", arg);
                return CLI_USAGE_ERROR;
            }
            if (s->command == CLI_PHOTOMETRY) {
                /* photometry FILE...: the files, given together */
                if (s->photometry_file_count == 0)
                    s->photometry_files = argv + i;
                else if (argv + i != s->photometry_files + s->photometry_file_count) {
                    usage_error(e, "give the photometric files together ('%s' after an option)", arg);
                    return CLI_USAGE_ERROR;
                }
                s->photometry_file_count++;
                continue;
            }
            const char **scene = s->command == CLI_GENERATE ? &s->scene_kind : &s->scene_path;
            if (*scene) {
                usage_error(e, "more than one scene given ('%s' and '%s')", *scene, arg);
                return CLI_USAGE_ERROR;
            }
            if (s->command == CLI_GENERATE && strcmp(arg, "office") != 0) {
                usage_error(e, "unknown scene kind '%s' (known: office)", arg);
                return CLI_USAGE_ERROR;
            }
            *scene = arg;
            continue;
        }
        int known;
        const char *value;
        const cli_flag *f = find_flag(arg, s->command, &known, &value);
        int bad = 0;
        if (!f && !known)
            bad = usage_error(e, "unknown option '%s'", arg);
        else if (!f && !s->command)
            bad = usage_error(e, "%s needs a command: render, solve, viewfactors, export, bake, thermal, generate "
                                 "or view", arg);
        else if (!f)
            bad = usage_error(e, "%s does not apply to %s", arg, cli_command_name(s->command));
        else if (f->metavar && !value && i + 1 >= argc)
            bad = usage_error(e, "%s needs a value (%s)", arg, f->metavar);
        else if (!f->metavar && value)
            bad = usage_error(e, "%s takes no value", arg);
        if (bad)
            return CLI_USAGE_ERROR;
        if (f->target == CLI_TO_ACTION)
            return f->action;
        if (!f->metavar) {
            set_switch(f, s);
            continue;
        }
        if (!value)
            value = argv[++i];
        /* illuminance takes -o twice: the CSV and the JSON. */
        if (s->command == CLI_ILLUMINANCE && strcmp(f->name, "output") == 0 && s->output && value[0]) {
            if (s->output2) {
                usage_error(e, "--output: illuminance writes at most two files (a .csv and a .json)");
                return CLI_USAGE_ERROR;
            }
            s->output2 = value;
            continue;
        }
        const rad_option_info *o = cli_flag_info(f);
        if (value[0] == '\0') {
            usage_error(e, "--%s needs a value (%s)", f->name, f->metavar);
            return CLI_USAGE_ERROR;
        }
        if (parse_value(o, value, flag_field(f, s)) != 0) {
            char expected[600];
            expectation(o, expected, sizeof expected);
            usage_error(e, "--%s: expected %s, got '%s'", f->name, expected, value);
            return CLI_USAGE_ERROR;
        }
    }
    if (!s->command) {
        usage_error(e, "no command given: use render, solve, viewfactors, export, bake, thermal, illuminance, generate or view");
        return CLI_USAGE_ERROR;
    }
    if (s->command == CLI_PHOTOMETRY && s->photometry_file_count == 0) {
        usage_error(e, "no photometric file given");
        return CLI_USAGE_ERROR;
    }
    if (s->command == CLI_GENERATE && !s->scene_kind) {
        usage_error(e, "no scene kind given (known: office)");
        return CLI_USAGE_ERROR;
    }
    if (s->atlas_size & (s->atlas_size - 1)) {
        usage_error(e, "--atlas-size: expected a power of two, got %d", s->atlas_size);
        return CLI_USAGE_ERROR;
    }
    /* thermal solves on the form-factor matrix: a linear solver of the
     * table, LU by default (exact, and thermal scenes are small). */
    if (s->command == CLI_THERMAL)
        s->solve.solver = s->thermal_solver ? s->thermal_solver : "direct";
    if (s->every && !s->progress_dir) {
        usage_error(e, "--every needs --progress-images DIR");
        return CLI_USAGE_ERROR;
    }
    if (s->progress_dir && s->solve.solver &&
        !(rad_method_capabilities(RAD_METHOD_SOLVER, s->solve.solver) & RAD_CAN_PROGRESS_IMAGES)) {
        usage_error(e, "--progress-images is not available with --solver %s "
                       "(its elements change while it solves; use --history)", s->solve.solver);
        return CLI_USAGE_ERROR;
    }
    /* The default solver is hierarchical, which meshes as it solves, lit
     * or not.  What needs a uniform mesh or a form-factor matrix takes
     * gauss-seidel instead when no --solver is given: the view factors (a
     * matrix's F), progress images (elements that stay put while solving),
     * and the uniform mesh's and the matrix's own options, which
     * hierarchical would ignore (adaptive subdivision among them).  Never
     * silently: a solve that the uniform mesh's options sent to the O(n^2)
     * solver says so in a note naming the flag (docs/hierarchical.md,
     * "Which solver"). */
    /* The window shows progressive refinement: shooting, unless another
     * solver is asked for (an off-screen frame solves as render does). */
    if (!s->solve.solver && s->command == CLI_VIEW && !s->offscreen && s->solve.adaptive_levels == 0)
        s->solve.solver = "shooting";
    if (!s->solve.solver && s->command != CLI_VIEWFACTORS && !s->progress_dir)
        s->dense_for = s->solve.target_elements != 0 ? "--elements"
                       : s->solve.mesh_size != 0.0   ? "--mesh-size"
                       : s->solve.form_factors       ? "--form-factors"
                       : s->solve.adaptive_levels != 0 || s->solve.adaptive_threshold != 0.0 ||
                               s->solve.adaptive_max_elements != 0
                           ? "--adaptive"
                           : NULL;
    if (!s->solve.solver &&
        (s->command == CLI_VIEWFACTORS || s->progress_dir || s->solve.target_elements != 0 ||
         s->solve.mesh_size != 0.0 || s->solve.form_factors || s->solve.adaptive_levels != 0 ||
         s->solve.adaptive_threshold != 0.0 || s->solve.adaptive_max_elements != 0))
        s->solve.solver = "gauss-seidel";
    if (!s->output)
        s->output = default_output(s->command);
    if (s->history)
        s->solve.record_history = 1;
    return CLI_RUN;
}

/* ---- the library's messages, in flags ---- */

/* The length of "rad_options.field" at p when it names the field of flag
 * f, and not a longer identifier; 0 otherwise. */
static size_t names_field(const char *p, const cli_flag *f)
{
    int set = flag_set(f);
    if (set < 0)
        return 0;
    const char *struct_name = rad_option_set_name((rad_option_set)set);
    size_t sl = strlen(struct_name), fl = strlen(f->field);
    if (strncmp(p, struct_name, sl) != 0 || p[sl] != '.' || strncmp(p + sl + 1, f->field, fl) != 0)
        return 0;
    char next = p[sl + 1 + fl];
    return next == '_' || isalnum((unsigned char)next) ? 0 : sl + 1 + fl;
}

char *cli_rewrite_message(const char *message, char *out, size_t size)
{
    /* The context's fields that flags set (main.c), which the option table
     * does not hold: the library names them in its messages too. */
    static const struct {
        const char *field, *flag;
    } context_fields[] = {
        {"rad_context_options.max_memory_bytes", "max-memory"},
        {"rad_context_options.read_outside_scene_folder", "read-outside-scene-folder"},
        {"rad_context_options.missing_textures_flat", "missing-textures"},
        {"rad_context_options.threads", "threads"},
    };
    size_t n = 0;
    if (!size)
        return out;
    for (const char *p = message; *p && n + 1 < size;) {
        size_t skip = 0, k = 0;
        while (k < FLAG_COUNT && !(skip = names_field(p, &FLAGS[k])))
            k++;
        for (size_t c = 0; !skip && c < sizeof context_fields / sizeof context_fields[0]; c++) {
            size_t length = strlen(context_fields[c].field);
            if (strncmp(p, context_fields[c].field, length) != 0 || p[length] == '_' ||
                isalnum((unsigned char)p[length]))
                continue; /* p[length] is read only once the field matched: within the text */
            for (k = 0; k < FLAG_COUNT && strcmp(FLAGS[k].name, context_fields[c].flag) != 0; k++)
                ;
            skip = k < FLAG_COUNT ? length : 0;
        }
        if (skip && k < FLAG_COUNT) {
            size_t wrote = (size_t)snprintf(out + n, size - n, "--%s", FLAGS[k].name);
            n += wrote < size - n ? wrote : size - n - 1;
            p += skip;
        } else {
            out[n++] = *p++;
        }
    }
    out[n] = '\0';
    return out;
}

/* ---- --help and the man page ---- */

/* The flag as the user writes it: "-o, --output FILE". */
static void flag_usage(const cli_flag *f, char *text, size_t size)
{
    char shortcut[8] = "";
    if (f->short_name)
        snprintf(shortcut, sizeof shortcut, "-%c, ", f->short_name);
    snprintf(text, size, "%s--%s%s%s", shortcut, f->name, f->metavar ? " " : "", f->metavar ? f->metavar : "");
}

/* "help; X in (0, 1), default 1e-6": the help with the accepted values and
 * the default, from the flag's row. */
static void flag_description(const cli_flag *f, char *text, size_t size)
{
    const rad_option_info *o = cli_flag_info(f);
    char range[512] = "", values[600] = "", deflt[300] = "";
    if (f->metavar)
        rad_option_range_text(o, range, sizeof range);
    if (range[0] && (o->type == RAD_OPTION_METHOD || o->type == RAD_OPTION_ENUM || o->type == RAD_OPTION_FLAG))
        snprintf(values, sizeof values, "%s: %s", f->metavar, range);
    else if (range[0])
        snprintf(values, sizeof values, "%s in %s%s", f->metavar, range,
                 o->type == RAD_OPTION_BYTES ? " bytes, with K, M or G for 2^10, 2^20, 2^30" : "");
    if (f->metavar && o->default_text)
        snprintf(deflt, sizeof deflt, "%sdefault %s", values[0] ? ", " : "", o->default_text);
    snprintf(text, size, "%s%s%s%s", flag_help(f), values[0] || deflt[0] ? "; " : "", values, deflt);
}

/* " [render, viewfactors]": the commands of a flag that not all take. */
static void flag_commands(const cli_flag *f, char *text, size_t size)
{
    text[0] = '\0';
    if (!f->commands || f->commands == ALL)
        return;
    size_t n = 0;
    for (size_t k = 0; k < COMMAND_COUNT; k++)
        if (f->commands & COMMANDS[k].bit) {
            int wrote = snprintf(text + n, size - n, "%s%s", n ? ", " : " [", COMMANDS[k].name);
            n += wrote > 0 && (size_t)wrote < size - n ? (size_t)wrote : 0;
        }
    snprintf(text + n, size - n, "]");
}

static const char *const DESCRIPTION =
    "SCENE is an OBJ (+MTL) or glTF 2.0 file; without one, the built-in Cornell box.\n"
    "Units: metres; emission and radiosity in W/m^2; OBJ Ke is emitted radiance (E = pi Ke).\n";

static const char *const EXIT_STATUS = "exit status: 0 ok, 1 failure, 2 usage error, 130/143 interrupted\n";

void cli_print_help(FILE *out, int command)
{
    const command_def *c = NULL;
    for (size_t k = 0; k < COMMAND_COUNT; k++)
        if (COMMANDS[k].bit == command)
            c = &COMMANDS[k];
    if (c) {
        fprintf(out, "usage: radiosity %s\n%s.\n\n%s%soptions:\n", c->synopsis, c->summary,
                command == CLI_GENERATE || command == CLI_PHOTOMETRY ? "" : DESCRIPTION,
                command == CLI_GENERATE || command == CLI_PHOTOMETRY ? "" : "\n");
    } else {
        fprintf(out, "radiosity %s -- diffuse global illumination by the radiosity method\n\nusage:\n",
                RAD_VERSION_STRING);
        for (size_t k = 0; k < COMMAND_COUNT; k++)
            if (strlen(COMMANDS[k].synopsis) <= 32)
                fprintf(out, "  radiosity %-32s %s\n", COMMANDS[k].synopsis, COMMANDS[k].summary);
            else /* too long for the column: the summary on a line of its own */
                fprintf(out, "  radiosity %s\n  %-42s %s\n", COMMANDS[k].synopsis, "", COMMANDS[k].summary);
        fprintf(out, "  radiosity %-32s %s\n", "COMMAND --help", "the options of one command");
        fprintf(out, "  radiosity --list-methods | --version | --man | --help\n\n%s\n"
                     "options ([...]: the commands that take it, where not all do):\n",
                DESCRIPTION);
    }
    for (size_t k = 0; k < FLAG_COUNT; k++) {
        const cli_flag *f = &FLAGS[k];
        if (c && !(f->commands & command) && f->target != CLI_TO_ACTION)
            continue;
        if (c && f->target == CLI_TO_ACTION && f->action != CLI_HELP)
            continue;
        char usage[64], description[1200], commands[128] = "";
        flag_usage(f, usage, sizeof usage);
        flag_description(f, description, sizeof description);
        if (!c)
            flag_commands(f, commands, sizeof commands);
        fprintf(out, "  %-28s %s%s\n", usage, description, commands);
    }
    fprintf(out, "\n%s", EXIT_STATUS);
}

/* Text for roff: backslashes and hyphens escaped, no line starting with a
 * control character. */
static void roff(FILE *out, const char *text)
{
    if (text[0] == '.' || text[0] == '\'')
        fputs("\\&", out);
    for (const char *p = text; *p; p++) {
        if (*p == '\\')
            fputs("\\e", out);
        else if (*p == '-')
            fputs("\\-", out);
        else
            fputc(*p, out);
        if (*p == '\n' && (p[1] == '.' || p[1] == '\''))
            fputs("\\&", out);
    }
}

static void man_flag(FILE *out, const cli_flag *f)
{
    fputs(".TP\n", out);
    if (f->short_name)
        fprintf(out, "\\fB\\-%c\\fR, ", f->short_name);
    fputs("\\fB\\-\\-", out);
    roff(out, f->name);
    fputs("\\fR", out);
    if (f->metavar) {
        fputs(" \\fI", out);
        roff(out, f->metavar);
        fputs("\\fR", out);
    }
    char description[1200];
    flag_description(f, description, sizeof description);
    fputc('\n', out);
    roff(out, description);
    fputc('\n', out);
}

void cli_print_man(FILE *out)
{
    /* Left-aligned and unhyphenated: flags and numbers must not break. */
    fprintf(out, ".TH RADIOSITY 1 \"\" \"radiosity %s\" \"User Commands\"\n.nh\n.ad l\n", RAD_VERSION_STRING);
    fputs(".SH NAME\nradiosity \\- diffuse global illumination by the radiosity method\n"
          ".SH SYNOPSIS\n",
          out);
    for (size_t k = 0; k < COMMAND_COUNT; k++) {
        fputs(k ? ".br\n" : "", out);
        fprintf(out, "\\fBradiosity %s\\fR ", COMMANDS[k].name);
        roff(out, strchr(COMMANDS[k].synopsis, ' ') + 1);
        fputc('\n', out);
    }
    fputs(".br\n\\fBradiosity\\fR \\-\\-list\\-methods | \\-\\-version | \\-\\-man | \\-\\-help\n"
          ".SH DESCRIPTION\n"
          "\\fBradiosity\\fR solves the radiosity equation B = E + rho F B for diffuse (Lambertian)\n"
          "scenes: it meshes the surfaces into elements, computes the form factors F between them\n"
          "with one of several methods, solves for the radiosity B of every element and writes an\n"
          "image, the view factors between named surfaces, the lit mesh, or statistics.  The\n"
          "library behind it is declared in radiosity.h; its option structs have the ranges and\n"
          "defaults given here.\n"
          ".PP\n",
          out);
    roff(out, DESCRIPTION);
    fputs(".SH COMMANDS\n", out);
    for (size_t k = 0; k < COMMAND_COUNT; k++) {
        fprintf(out, ".TP\n\\fB%s\\fR\n", COMMANDS[k].name);
        roff(out, COMMANDS[k].summary);
        fputs(".\n", out);
    }
    fputs(".SH OPTIONS\n"
          "Ranges are intervals: a parenthesis excludes its bound, a bracket includes it.\n"
          "A value may follow its flag as the next argument or after '='.\n",
          out);
    for (size_t k = 0; k < COMMAND_COUNT; k++) {
        fprintf(out, ".SS %s\n", COMMANDS[k].name);
        for (size_t i = 0; i < FLAG_COUNT; i++)
            if (FLAGS[i].commands & COMMANDS[k].bit)
                man_flag(out, &FLAGS[i]);
    }
    fputs(".SS \"any command, or none\"\n", out);
    for (size_t i = 0; i < FLAG_COUNT; i++)
        if (!FLAGS[i].commands)
            man_flag(out, &FLAGS[i]);
    fputs(".SH EXIT STATUS\n"
          ".TP\n.B 0\nsuccess\n"
          ".TP\n.B 1\nfailure: a scene that cannot be read or solved, an output that cannot be\n"
          "written, a memory limit; nothing partial is left behind\n"
          ".TP\n.B 2\nusage error: an unknown flag, a value out of range\n"
          ".TP\n.B 130, 143\ninterrupted by SIGINT or SIGTERM; the partial solution is written and marked\n"
          "so in the statistics\n"
          ".SH FILES\n"
          "Scenes are OBJ with MTL (Kd: reflectance, Ke: emitted radiance) or glTF 2.0 (.gltf, .glb).\n"
          "Images are PNG (exposed, sRGB), Radiance HDR or PFM (linear radiance).  View factors are\n"
          "JSON, CSV or Matrix Market; lit meshes glTF 2.0 (.glb, .gltf) or binary PLY, with the\n"
          "radiosity of every vertex in W/m^2 and its display colour; statistics are JSON.  Every output is written to a temporary\n"
          "name and renamed, so it is whole or absent.\n"
          ".SH UNITS\n"
          "Lengths in metres, areas in m^2; radiosity B and emission E in W/m^2 (exitance);\n"
          "radiance L = B / pi in W/(m^2 sr).  OBJ Ke and glTF emission are radiance: E = pi Ke.\n"
          ".SH SEE ALSO\n"
          "In the source tree: docs/units.md, docs/methods.md, docs/hierarchical.md,\n"
          "docs/scenes.md, docs/stats.md, docs/formats.md; the library's header radiosity.h.\n",
          out);
}
