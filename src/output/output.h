/*
 * output.h -- turning a solution into files: images (render.c, image.c),
 * automatic camera framing (camera.c), stats and view-factor files (stats.c),
 * lit meshes (mesh_export.c).
 */
#ifndef RAD_OUTPUT_H
#define RAD_OUTPUT_H

#include "interp/interp.h"
#include "render/render.h"
#include "strategy/strategy.h"

struct rad_image {
    rad_context *ctx;       /* the context it was made in (and its auto exposure's scratch) */
    int width, height;
    float *pixels;          /* RGB radiance, W/(m^2 sr), row 0 at the top */
};

rad_image *rad_image_create(rad_context *ctx, int width, int height);

/* What the renderer needs from a solution. */
typedef struct rad_render_input {
    const rad_mesh *mesh;
    const rad_vis *vis;              /* closest-hit queries against the patches */
    const double *element_radiosity; /* 3 per element, W/m^2 */
    const double *vertex_radiosity;  /* 3 per mesh vertex, W/m^2 */
    rad_camera camera;               /* resolved: never "none" */
    /* Per-pixel instant radiosity (rad_render_options.vpl_paths): the VPLs,
     * and the elements' reflectance and emission (3 per element); vpls
     * NULL: off. */
    const struct rad_vpl_set *vpls;
    const double *reflectance, *emission; /* 3 per element; also for textures */
    uint64_t seed;
    /* Textures: the reflectance at the point seen modulates the element's
     * reflected light, B = E + (B_element - E) rho(point) / rho_element
     * (NULL: no textures drawn). */
    const rad_scene *scene;
    const rad_material *materials;   /* per patch->material: the specular parts the second pass
                                        follows; NULL: the first pass alone */
    /* Rays that leave the scene (through its openings, or past an outdoor
     * model) see this daylight's sky and ground (light/sky.h); NULL: black. */
    const struct rad_daylight *daylight;
    /* The final gather (render/render.h): with it, element_radiosity and
     * vertex_radiosity hold the residual B - rho D the picture
     * interpolates, and each shading point adds rho D(x) of its own
     * (reflectance needed); NULL or inactive: the values as they are. */
    const rad_direct_light *direct;
} rad_render_input;

/* Ray-cast the mesh from the camera; each sample takes the radiance B/pi of
 * the element it hits (flat) or the interpolated vertex values (smooth).
 * Stratified anti-aliasing with samples x samples per pixel.  Parallel;
 * deterministic. */
rad_result rad_render_image(rad_context *ctx, const rad_render_input *input,
                            const rad_render_options *options, rad_image **out);

/* A camera that frames the bounding box, looking along -z from +z
 * (a three-quarter view would hide the interior of open boxes). */
rad_camera rad_camera_frame(vec3 bounds_min, vec3 bounds_max, double aspect);

/* Farthest a camera may be from the centre of what it draws, in sizes
 * (diagonals) of it. */
#define RAD_CAMERA_MAX_DISTANCE 1e6

/* RAD_ERROR_INVALID_ARGUMENT, with a message beginning "camera: ", when
 * the camera is farther than RAD_CAMERA_MAX_DISTANCE diagonals from the
 * centre of the box [lo, hi] (camera.c says why). */
rad_result rad_camera_check_distance(rad_context *ctx, const rad_camera *camera, vec3 lo, vec3 hi);

/* Parse "px,py,pz,lx,ly,lz[,ux,uy,uz[,vfov]]" (the CLI's --camera). */
rad_result rad_camera_parse(rad_context *ctx, const char *text, rad_camera *camera);

/* rad_image_write with an explicit exposure for .png (a multiplier on
 * radiance; 0 = rad_image_auto_exposure).  .hdr and .pfm are always
 * written as linear radiance, unexposed. */
rad_result rad_image_write_exposed(rad_context *ctx, const rad_image *image, const char *path,
                                   double exposure);

/* Automatic exposure: the multiplier that maps the 95th percentile of
 * luminance among lit pixels to 0.8, into *exposure.  Fails only for
 * memory (a float per pixel). */
rad_result rad_image_exposure(rad_context *ctx, const rad_image *image, double *exposure);

/* The same rule over any `count` RGB radiances (pixels, a lit mesh's
 * vertices): the values that are black or not finite left out, 1 when
 * none is left.  Fails only for memory (a float per value). */
rad_result rad_radiance_exposure(rad_context *ctx, const float *rgb, size_t count, double *exposure);

/* Raw pixels written atomically, row 0 first: 8-bit RGBA as PNG, float RGB
 * as Radiance HDR (RGBE).  RAD_ERROR_IO, RAD_ERROR_OUT_OF_MEMORY. */
rad_result rad_write_png_rgba(rad_context *ctx, const char *path, int width, int height, const unsigned char *rgba);
rad_result rad_write_hdr_rgb(rad_context *ctx, const char *path, int width, int height, const float *rgb);

/* IEC 61966-2-1 sRGB encoding of a linear value, clamped to [0, 1] (the
 * exact piecewise curve); 255 x it, rounded, is an 8-bit channel. */
double rad_srgb_encode(double linear);

/* ---- results as files (stats.c); every file is written atomically ---- */

/* `text` as valid UTF-8: each byte that does not begin a well-formed
 * sequence (RFC 3629) becomes U+FFFD.  A new string in the context's
 * output memory (rad_free it); NULL when out of memory. */
char *rad_utf8_clean(rad_context *ctx, const char *text);

/* A CSV field: quoted (with doubled quotes) when it holds a comma, quote or
 * line break (RFC 4180), or begins or ends with a blank (which readers
 * that trim would lose).  Cannot fail. */
void rad_csv_field(FILE *f, const char *text);

/* A cJSON tree written atomically as `path` (printed, then one line
 * break); a NULL root or one cJSON cannot print: RAD_ERROR_OUT_OF_MEMORY. */
struct cJSON;
rad_result rad_write_json(rad_context *ctx, struct cJSON *root, const char *path);

/* The stats JSON of a solution (docs/stats.md); `partial` marks an
 * interrupted run. */
rad_result rad_write_stats(rad_context *ctx, const rad_solution_view *view, const char *path, bool partial);

/* The same with `extra` adding its own members to the root object (a
 * cJSON object) before it is written; a failure it returns (out of
 * memory) is the writer's. */
typedef rad_result (*rad_stats_extra_fn)(rad_context *ctx, struct cJSON *root, const void *user);
rad_result rad_write_stats_extra(rad_context *ctx, const rad_solution_view *view, const char *path, bool partial,
                                 rad_stats_extra_fn extra, const void *user);

/* The solution file (strategy/saved.h): the view's scene, mesh and values
 * with the vertex values the renderer uses (3 per mesh vertex), written
 * atomically to `path`.  RAD_ERROR_INVALID_ARGUMENT when it is not solved. */
rad_result rad_write_solution(rad_context *ctx, const rad_solution_view *view, const double *vertex_radiosity,
                              const char *path);

/* View factors by the path's extension (.json, .csv, .mtx; docs/formats.md),
 * surface-level or, with `elements`, element-level.  Fails without F. */
rad_result rad_write_view_factors(rad_context *ctx, const rad_solution_view *view, const char *path,
                                  bool elements);
/* The same with options (rad_solution_write_view_factors_with; view3d.c):
 * .vf as well, smoothing, sparse thresholds.  `options` is not NULL. */
rad_result rad_write_view_factors_with(rad_context *ctx, const rad_solution_view *view, const char *path,
                                       const rad_view_factor_options *options);

/* ---- streamed view factors: rows in blocks, never the n x n matrix
 * (vf_stream.c; the writers' helpers in stats.c) ---- */

/* A JSON string literal (the Matrix Market comments), as the view-factor
 * writers write names (CSV fields: rad_csv_field).  Cannot fail (errors
 * show in the stream). */
void rad_write_json_string(FILE *f, const char *text);

/* The surface-level view factors F (S x S, made by the caller: taken over
 * and freed, also on failure) written as rad_write_view_factors writes
 * them (.json, .csv, .mtx, .vf), with `options` (NULL: none; its
 * `elements` is ignored); the view needs scene, options, n and ff. */
rad_result rad_write_surface_view_factors(rad_context *ctx, const rad_solution_view *view, double *F,
                                          const char *path, const rad_view_factor_options *options);

/* What a row sink is told at the start. */
typedef struct rad_vf_stream_info {
    const rad_solution_view *view; /* scene, options, mesh, n, area, ff (F NULL) */
    const char *path;              /* the output, written atomically */
    const rad_view_factor_options *factors; /* surface level: adjustments, smoothing (NULL: none) */
} rad_vf_stream_info;

/* Where streamed rows go: one entry per output, chosen by the path's
 * extension and the level (rad_vf_sink_find).  begin opens (nothing
 * visible at `path` until end commits); row receives element row i (n
 * doubles, F_ij from element i to every j), rows in order 0 .. n-1,
 * once each; end with commit writes what remains and puts the file in
 * place, without it removes every temporary; both free the state, which
 * is NULL after a failed begin.  Each fails through rad_fail. */
typedef struct rad_vf_sink {
    const char *extension;         /* the path's, lower case */
    bool elements;                 /* element-level rows (else surface level) */
    rad_result (*begin)(rad_context *ctx, const rad_vf_stream_info *info, void **state);
    rad_result (*row)(rad_context *ctx, void *state, size_t i, const double *F_row);
    rad_result (*end)(rad_context *ctx, void *state, bool commit);
    /* Optional: the bytes rows [rows, n) will still need on the output's
     * file system (temporaries and the final copy counted), extrapolated
     * from what rows [0, rows) took; with rows = 0 a lower bound.  Cannot
     * fail. */
    double (*estimate)(const void *state, size_t rows, size_t n);
} rad_vf_sink;

extern const rad_vf_sink *const rad_vf_sinks[]; /* NULL-terminated */

/* The sink for `path`'s extension at the level asked; NULL if none
 * streams it. */
const rad_vf_sink *rad_vf_sink_find(const char *path, bool elements);

/* The lit mesh by the path's extension (.glb, .gltf, .ply; docs/formats.md):
 * vertices with their radiosity B (W/m^2) and display colour, the radiance
 * B/pi times `exposure` (0 = the automatic rule over the vertices). */
rad_result rad_write_mesh(rad_context *ctx, const rad_solution_view *view, const char *path, double exposure);

/* ---- lightmaps (lightmap.c): the solution baked into atlases of texels ---- */

/* How a texel got its value (docs/formats.md, "Lightmap"). */
enum { RAD_TEXEL_EMPTY = 0, RAD_TEXEL_INSIDE, RAD_TEXEL_BORDER, RAD_TEXEL_DILATED };

/* One patch's chart: its frame in the patch plane and its place in an atlas. */
typedef struct rad_chart {
    uint32_t patch;
    uint32_t atlas;
    int x, y;                /* the box's first texel in the atlas (its padding is around it) */
    int width, height;       /* the box, texels (>= 2 each) */
    vec3 origin;             /* m: the point at the box's corner (x, y) */
    vec3 axis_u, axis_v;     /* unit: u along the patch's longest edge, v = normal x u */
    uint32_t corner_count;   /* the patch's corners in the box, texels from (x, y), ccw */
    double corner_u[4], corner_v[4];
} rad_chart;

typedef struct rad_atlas {
    int width, height;       /* texels, powers of two; row 0 is the image's first row */
    float *texels;           /* 3 per texel: the quantity, W/m^2 (0 where no chart is) */
    int32_t *owner;          /* per texel: the chart whose padded box holds it, or -1 */
    unsigned char *state;    /* per texel: RAD_TEXEL_* */
} rad_atlas;

typedef struct rad_lightmap {
    double texels_per_metre;
    int quantity;            /* RAD_LIGHTMAP_RADIOSITY or RAD_LIGHTMAP_IRRADIANCE */
    rad_chart *charts;       /* one per patch, in patch order */
    size_t chart_count;
    rad_atlas *atlases;
    size_t atlas_count;
    double chart_texels;     /* the charts' boxes, texels */
    double atlas_texels;     /* the atlases', texels: chart_texels / this is the fill ratio */
} rad_lightmap;

typedef struct rad_lightmap_options {
    double texels_per_metre; /* 0 = 10 */
    int atlas_size;          /* the largest atlas side, a power of two from 8 to 16384; 0 = 2048 */
    int quantity;            /* RAD_LIGHTMAP_RADIOSITY (0) or RAD_LIGHTMAP_IRRADIANCE */
} rad_lightmap_options;

/* Chart every patch of the view's mesh, pack the charts and fill the
 * atlases (lightmap.c).  Fails with RAD_ERROR_INVALID_ARGUMENT for bad
 * options or a chart larger than an atlas, RAD_ERROR_OUT_OF_MEMORY (with
 * a message naming the limit) when the atlases exceed the solution's
 * memory limit, RAD_ERROR_INTERRUPTED when cancelled; *out is then NULL. */
rad_result rad_lightmap_bake(rad_context *ctx, const rad_solution_view *view, const rad_lightmap_options *options,
                             rad_lightmap **out);
void rad_lightmap_destroy(rad_lightmap *lightmap);

/* Continuous atlas texel coordinates (texel centres at k + 0.5) of point p
 * of chart c's patch, and back.  Cannot fail. */
void rad_chart_texel(const rad_lightmap *lightmap, const rad_chart *c, vec3 p, double *x, double *y);
vec3 rad_chart_point(const rad_lightmap *lightmap, const rad_chart *c, double x, double y);

/* What the lit mesh needs to use lightmaps (rad_write_mesh_baked). */
typedef struct rad_mesh_lightmaps {
    const rad_lightmap *lightmap;
    char **png_uris;         /* atlas_count relative URIs of the RGBM PNGs, percent-encoded */
    char **hdr_names;        /* atlas_count file names of the HDRs, for asset.extras */
    double rgbm_range;       /* M: radiance = rgb x alpha x M (each in [0, 1]) */
} rad_mesh_lightmaps;

/* rad_write_mesh's glTF (.glb, .gltf) with every vertex split per patch,
 * TEXCOORD_1 its chart's atlas coordinates, one material per scene
 * material and atlas, each with MOZ_lightmap on its atlas's PNG. */
rad_result rad_write_mesh_baked(rad_context *ctx, const rad_solution_view *view, const char *path, double exposure,
                                const rad_mesh_lightmaps *maps);

/* Bake and write: the lightmap of `options`, its atlases added to `set`
 * beside `path` (which the set holds) as STEM_lightmapK.hdr / .png and
 * written into their temporaries with the glTF (bake.c); the atlases'
 * figures in *stats (all but seconds). */
rad_result rad_write_bake(rad_context *ctx, const rad_solution_view *view, const rad_bake_options *options,
                          rad_output_set *set, const char *path, rad_bake_stats *stats);

/* The convergence history as CSV: iteration, seconds, residual, unshot. */
rad_result rad_write_history(rad_context *ctx, const rad_solve_step *steps, size_t count, const char *path);

/* The heat exchange's figures (rad_thermal_write) and its Gebhart factors
 * G (S x S; rad_thermal_write_gebhart), by extension .csv or .json
 * (thermal_write.c; docs/thermal.md). */
rad_result rad_write_thermal(rad_context *ctx, const rad_thermal *thermal, const char *path, bool elements);
rad_result rad_write_gebhart(rad_context *ctx, const rad_thermal *thermal, const double *G, const char *path);

/* The solution's stats with a "thermal" object (rad_thermal_write_stats). */
rad_result rad_write_thermal_stats(rad_context *ctx, const rad_solution_view *view, const rad_thermal *thermal,
                                   const char *path);

/* ---- pictures people read (pictures.c, falsecolour.c, plot.c;
 * docs/lighting.md "Pictures"); the colour map, scale and legend:
 * picture.h ---- */

struct rad_colour_scale;

/* rad_solution_write_false_colour's picture of a solved view (pictures.c):
 * `options` already checked (rad_false_colour_check; NULL: luminance,
 * automatic range), `render` the camera and size (NULL: the defaults).
 * Luminance takes `radiance`, the solution's own render with `render`
 * (rad_solution_render: textures, the second pass), and a flat render of
 * the view for its coverage; illuminance (radiance NULL) renders the
 * elements' lux with the coverage in one.  Within the running call's
 * memory limit; RAD_ERROR_IO, RAD_ERROR_OUT_OF_MEMORY,
 * RAD_ERROR_INTERRUPTED. */
rad_result rad_write_false_colour_view(rad_context *ctx, const rad_solution_view *view,
                                       const rad_render_options *render, const rad_false_colour_options *options,
                                       const rad_image *radiance, const char *path);

/* Each element's illuminance in lux (n), 179 Y(H) with H = (B - E) / rho
 * + direct per channel, a black channel gathered from the others
 * (falsecolour.c says how).  Parallel; RAD_ERROR_INTERRUPTED when cancelled. */
rad_result rad_view_illuminance(rad_context *ctx, const rad_solution_view *view, double *lux);

/* The false colour picture of `values` (width x height, row 0 at the top;
 * NaN = background, drawn white) on `scale`, the legend at the right with
 * `unit` (UTF-8), isolines at the ticks with `contours`, as a PNG at
 * `path`, atomically.  RAD_ERROR_IO, RAD_ERROR_OUT_OF_MEMORY. */
rad_result rad_false_colour_write(rad_context *ctx, const float *values, int width, int height,
                                  const struct rad_colour_scale *scale, const char *unit, bool contours,
                                  const char *path);

/* One calculation grid or set of points, as its plan is drawn
 * (rad_plot_grid_write): the caller's arrays, read during the call. */
typedef struct rad_plot_grid {
    const char *name;        /* the title's first word(s) (UTF-8) */
    size_t count;            /* points */
    const double *u, *v;     /* m: each point's in-plane coordinates (v up the page) */
    const double *value;     /* the values, in `unit` */
    const char *unit;        /* "lx" */
    /* A regular grid: nu x nv cells, each point at the centre of its cell
     * (count <= nu x nv: a footprint's cells off it have no point and are
     * not drawn); 0 x 0: free points, drawn as labelled dots. */
    size_t nu, nv;
    double cell_u, cell_v;   /* m: a cell's sides; 0: the points' spread over nu - 1 (nv - 1) */
} rad_plot_grid;

typedef struct rad_plot_options {
    int log_scale;           /* nonzero: logarithmic */
    double range_min, range_max; /* 0 and 0: automatic (as false colour) */
    int width;               /* the picture's width in pixels, legend included; 0 = 900 */
} rad_plot_options;

/* The plan of `grid` as a PNG at `path`, atomically: cells (or dots)
 * coloured by value with the value printed in each (when it fits: a font
 * of at least RAD_PLOT_MIN_FONT px), the outline, the legend, and a title
 * line with the average, minimum, maximum and uniformity U0 = min / avg.
 * RAD_ERROR_INVALID_ARGUMENT for an empty grid, more points than nu x nv
 * cells, a cell side negative or not finite, values
 * or coordinates not finite, bad range; RAD_ERROR_IO,
 * RAD_ERROR_OUT_OF_MEMORY. */
rad_result rad_plot_grid_write(rad_context *ctx, const rad_plot_grid *grid, const rad_plot_options *options,
                               const char *path);
#define RAD_PLOT_MIN_FONT 7.0

/* What rad_plot_grid_write prints: the value labels (label(k) for point
 * k, count of them, each as rad_format_value) and the title line into
 * `title`.  Cannot fail. */
void rad_plot_grid_label(const rad_plot_grid *grid, size_t k, char *text, size_t size);
void rad_plot_grid_title(const rad_plot_grid *grid, char *text, size_t size);

#endif /* RAD_OUTPUT_H */
