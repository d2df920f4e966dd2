/*
 * radiosity.h -- the public contract of the radiosity engine.
 *
 * The engine solves the radiosity equation for diffuse (Lambertian) scenes,
 *
 *     B_i = E_i + rho_i * sum_j F_ij B_j            (constant elements)
 *
 * and turns the answer into images, per-surface figures and view factors.
 * Everything a program may use is declared here; nothing else is API.
 *
 * Pipeline, as the API exposes it:
 *
 *     rad_context_create          threads, progress, cancellation, error text
 *       rad_scene_load_file       OBJ+MTL, glTF 2.0 (assimp) or the built-in
 *       rad_scene_create_cornell_box     Cornell box
 *         rad_solution_create     mesh -> visibility -> form factors
 *           rad_solution_solve    B per element, residual
 *             rad_solution_render image of radiance L = B / pi
 *             rad_solution_write_stats / rad_solution_write_view_factors
 *
 * Conventions (docs/units.md): lengths in metres, radiosity B and emission E
 * in W/m^2 (exitance), radiance L = B / pi in W/(m^2 sr).  OBJ/MTL `Ke` and
 * glTF emissive colour are read as emitted RADIANCE, so E = pi * Ke.
 *
 * Error handling: every fallible call returns a rad_result; on failure the
 * out pointer is set to NULL, nothing leaks, and rad_context_error() returns
 * one human-readable line (e.g. "box.obj:12: face has 2 vertices").
 * Destroying NULL is a no-op.  Option structs are zero-initialisable: a zero
 * field means "the documented default".
 */
#ifndef RADIOSITY_H
#define RADIOSITY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define RAD_VERSION_MAJOR 0
#define RAD_VERSION_MINOR 1
#define RAD_VERSION_PATCH 0
#define RAD_VERSION_STRING "0.1.0"

typedef enum rad_result {
    RAD_OK = 0,
    RAD_ERROR_IO,               /* a file could not be read or written */
    RAD_ERROR_PARSE,            /* a file is malformed */
    RAD_ERROR_INVALID_SCENE,    /* NaN coordinates, reflectance >= 1, no emitter, ... */
    RAD_ERROR_INVALID_ARGUMENT, /* an option out of range, an unknown method name */
    RAD_ERROR_OUT_OF_MEMORY,    /* an allocation failed or would exceed the memory limit */
    RAD_ERROR_INTERRUPTED,      /* the cancel flag was raised; results are partial */
    RAD_ERROR_INTERNAL          /* a library (Embree, LAPACK) failed unexpectedly */
} rad_result;

/* A short name for a result code ("RAD_ERROR_IO"); never NULL. */
const char *rad_result_string(rad_result result);

/* ------------------------------------------------------------------------
 * Context: threads, progress, cancellation and the last error message.
 * ---------------------------------------------------------------------- */

typedef struct rad_context rad_context;

/* Progress of a long phase: `phase` is a short name ("form factors"),
 * `done` of `total` units finished.  Called from the calling thread only. */
typedef void (*rad_progress_fn)(void *user, const char *phase, uint64_t done, uint64_t total);

/* Called once per failed call, with its result and the message that
 * rad_context_error() will return, from the thread that made the call. */
typedef void (*rad_error_fn)(void *user, rad_result result, const char *message);

typedef struct rad_context_options {
    int threads;                 /* worker threads; 0 = all cores */
    rad_progress_fn progress;    /* optional progress callback */
    void *progress_user;         /* passed to `progress` */
    rad_error_fn on_error;       /* optional: told of every failure */
    void *error_user;            /* passed to `on_error` */
    double max_memory_bytes;     /* the memory limit: everything the engine allocates in
                                    this context (scenes while loading included) stays
                                    below it, else RAD_ERROR_OUT_OF_MEMORY with the limit
                                    named; 0 = 80% of physical memory.  Memory that
                                    assimp, Embree, LAPACK and cJSON allocate themselves
                                    is not counted (loading refuses files that assimp
                                    would need more than the limit for: docs/robustness.md) */
} rad_context_options;

/* Fails with RAD_ERROR_INVALID_ARGUMENT for negative threads or memory. */
rad_result rad_context_create(const rad_context_options *options, rad_context **out);
/* Destroy the context.  The scenes, solutions and images made with it
 * keep their memory accounted to it: destroyed before them, it lives on
 * (for no further calls) until the last of them is destroyed.  NULL is a
 * no-op. */
void rad_context_destroy(rad_context *ctx);
/* The message of the most recent failed call in this context ("" if none):
 * its FIRST failure, which names the cause ("box.obj:12: ..."), not what
 * followed from it.  Owned by the context; valid until its next failure. */
const char *rad_context_error(const rad_context *ctx);

/* Ask the running and following calls to stop (cancel = true) or let them
 * run again (false).  Long phases poll the flag and return
 * RAD_ERROR_INTERRUPTED, keeping partial results.  An atomic store: safe
 * from a signal handler and from any thread.  NULL is a no-op. */
void rad_context_cancel(rad_context *ctx, bool cancel);
/* Whether cancellation was asked for (false for NULL). */
bool rad_context_cancelled(const rad_context *ctx);
int rad_context_threads(const rad_context *ctx);

/* ------------------------------------------------------------------------
 * Scene: named surfaces made of planar polygons with Lambertian materials.
 * ---------------------------------------------------------------------- */

typedef struct rad_scene rad_scene;

/* Load OBJ(+MTL) or glTF 2.0 (.gltf/.glb) through assimp.  The scene is
 * validated: finite coordinates, polygons of non-zero area, reflectance in
 * [0, 1).  A scene without an emitter loads; solving it is an error. */
rad_result rad_scene_load_file(rad_context *ctx, const char *path, rad_scene **out);

/* Load from memory.  `name` is used in messages and to guess the format
 * from its extension (".obj", ".gltf", ".glb").  `mtl`, if not NULL, is the
 * text of the material library an OBJ names in `mtllib`. */
rad_result rad_scene_load_memory(rad_context *ctx, const char *name, const void *data,
                                 size_t size, const void *mtl, size_t mtl_size,
                                 rad_scene **out);

/* The measured Cornell box (Cornell University Program of Computer
 * Graphics), in metres, with its published camera. */
rad_result rad_scene_create_cornell_box(rad_context *ctx, rad_scene **out);

/* A procedural office floor (docs/scenes.md): `rooms` rooms of about
 * 4-6 x 4-6 x 3 m on a grid, with doors between neighbours, daylight
 * windows on the outside, ceiling lights, desks, chairs and shelves; about
 * 110-220 polygons per room, surfaces named "room3/desk1/top".  The same
 * seed gives the same scene bit for bit. */
typedef struct rad_office_options {
    int rooms;                   /* 1 to 100000; 0 = 4 */
    uint64_t seed;               /* any value (0 included) */
} rad_office_options;

/* `options` may be NULL (the defaults).  Fails with
 * RAD_ERROR_INVALID_ARGUMENT when rooms is out of range. */
rad_result rad_scene_generate_office(rad_context *ctx, const rad_office_options *options,
                                     rad_scene **out);

/* Write a scene as OBJ + MTL: PATH (PATH.obj -> PATH.mtl beside it, named
 * in `mtllib`), one `o` per surface (its name, blanks replaced by '_'),
 * Kd = reflectance, Ke = emitted radiance = E / pi.  Coordinates are written
 * in the shortest decimal that parses back to the same double (the loader
 * reads them through assimp's float); the camera is not written.  Both
 * files go to temporary names first and are renamed only when both are
 * complete, so a failure leaves neither. */
rad_result rad_scene_write_obj(rad_context *ctx, const rad_scene *scene, const char *path);

void rad_scene_destroy(rad_scene *scene);

size_t rad_scene_surface_count(const rad_scene *scene);
const char *rad_scene_surface_name(const rad_scene *scene, size_t surface);
double rad_scene_surface_area(const rad_scene *scene, size_t surface); /* m^2 */
size_t rad_scene_polygon_count(const rad_scene *scene);

/* A pinhole camera.  vfov_degrees is the full vertical field of view. */
typedef struct rad_camera {
    double position[3];
    double look_at[3];
    double up[3];
    double vfov_degrees;
} rad_camera;

/* Parse "px,py,pz,lx,ly,lz[,ux,uy,uz[,vfov]]": position, look-at point,
 * up vector (default 0,1,0) and vertical field of view (default 40). */
rad_result rad_camera_from_string(rad_context *ctx, const char *text, rad_camera *camera);

/* The scene's own camera (from the file, or the Cornell box's published
 * one).  Returns 0 and leaves *camera untouched when there is none. */
int rad_scene_camera(const rad_scene *scene, rad_camera *camera);

/* ------------------------------------------------------------------------
 * Solution: mesh, form factors and radiosity for one scene.
 * ---------------------------------------------------------------------- */

typedef struct rad_solution rad_solution;

/* One solver iteration, as reported to rad_options.on_step and kept in the
 * convergence history. */
typedef struct rad_solve_step {
    int iteration;                /* 1, 2, ...: sweeps or shots */
    double seconds;               /* since the solve began */
    double residual;              /* the residual (see rad_solution_residual); NAN where a
                                     solver does not measure it at this step */
    double unshot;                /* unshot power / emitted power (shooting); NAN otherwise */
} rad_solve_step;

typedef struct rad_options {
    /* Meshing: elements no longer than mesh_size metres on a side; or, when
     * mesh_size is 0, about target_elements elements in all (default 2000). */
    double mesh_size;
    size_t target_elements;
    double crease_angle_degrees;  /* vertices of one surface are shared across
                                     polygons meeting at less than this; 0 = 30 */

    const char *form_factors;     /* method name; NULL = "analytic" */
    int shadow_rays;              /* visibility rays per element pair; 0 = 4 (16 where partial) */
    const char *visibility;       /* "embree" (default) or "brute" */
    int hemicube_resolution;      /* hemicube: pixels along a full face; 0 = 256 */
    int samples;                  /* hemisphere: rays per element; montecarlo: point pairs
                                     per element pair; 0 = the method's default */
    double near_field;            /* hybrid: pairs closer than this many element sizes use
                                     the exact method; 0 = 3 */
    int closure_correction;       /* nonzero: rescale F symmetrically so rows of a closed
                                     scene sum to 1 while A_i F_ij = A_j F_ji (thermal use);
                                     hierarchical: each patch sends B / its link closure;
                                     refused by shooting */

    const char *solver;           /* NULL = "gauss-seidel" */
    double tolerance;             /* stop when the residual falls below; 0 = 1e-6 */
    double unshot_tolerance;      /* also stop when the unshot power / emitted power falls
                                     below (shooting); 0 = not used */
    int max_iterations;           /* sweeps (gathering) or shots (shooting); 0 = automatic */
    double relaxation;            /* over-relaxation factor omega in (0, 2): SOR for jacobi
                                     and gauss-seidel, overshooting for southwell; 0 = 1 */
    /* Called after every solver iteration (sweep or shot) with the solution in its
     * current state (rad_solution_render works on it: progressive display).  Return
     * nonzero to stop the solve early (it then returns RAD_ERROR_INTERRUPTED). */
    int (*on_step)(void *user, rad_solution *solution, const struct rad_solve_step *step);
    void *on_step_user;
    int record_history;           /* nonzero: keep every step's residual in the history
                                     (gathering then measures the residual every sweep) */

    /* Hierarchical radiosity (solver "hierarchical"): a link is refined while its
     * estimated error, as power reflected by the receiver, exceeds epsilon times
     * the power the scene emits; elements are not split below min_area.  Its
     * progress reaches the history, not on_step (the mesh changes as it runs). */
    double epsilon;               /* 0 = 1e-4 */
    double min_area;              /* m^2; 0 = 1e-4 x the scene's total area, divided by
                                     patches / 100 when there are more than 100 */
    int clustering;               /* 0 = automatic (when the scene has more than 64
                                     patches), 1 = always, -1 = never */
    int classic_oracle;           /* nonzero: refine on the receiver's irradiance variation
                                     and visibility only (Hanrahan et al. 1991), not also on
                                     the source's radiosity variation: fewer links per
                                     element, per-surface means ~3x less accurate */

    uint64_t seed;                /* all sampling is seeded per element pair: results do
                                     not depend on the thread count */
    double max_memory_bytes;      /* 0 = the context's limit (rad_context_options); else a
                                     lower limit for this solution's calls (create, solve,
                                     render, the writers); never above the context's */
} rad_options;

/* Mesh the scene, build visibility and compute form factors.  The returned
 * solution holds B = E (not yet solved). */
rad_result rad_solution_create(rad_context *ctx, const rad_scene *scene,
                               const rad_options *options, rad_solution **out);

/* Solve for B with the solver named in the options.  The scene must have
 * an emitter.  Returns RAD_ERROR_INTERRUPTED with the current iterate kept
 * (marked partial in the stats) if the cancel flag was raised. */
rad_result rad_solution_solve(rad_context *ctx, rad_solution *solution);

void rad_solution_destroy(rad_solution *solution);

size_t rad_solution_element_count(const rad_solution *solution);
/* Residual measure after solving: sum_i A_i |r_i| / sum_i A_i E_i summed over
 * the channels, with r = B - E - rho F B (the notes' residual). */
double rad_solution_residual(const rad_solution *solution);
int rad_solution_iterations(const rad_solution *solution);

/* The convergence history of the last solve: *count steps, owned by the
 * solution. */
const rad_solve_step *rad_solution_history(const rad_solution *solution, size_t *count);
/* Write it as CSV (iteration,seconds,residual,unshot), atomically. */
rad_result rad_solution_write_history(rad_context *ctx, const rad_solution *solution,
                                      const char *path);

/* Area-weighted mean radiosity of a surface, RGB, W/m^2. */
void rad_solution_surface_radiosity(const rad_solution *solution, size_t surface,
                                    double rgb[3]);

/* Surface-to-surface view factors: F[i * S + j] for S surfaces, the
 * area-weighted sum over their elements.  `F` holds S*S doubles. */
void rad_solution_surface_view_factors(const rad_solution *solution, double *F);

/* Power in watts (summed over RGB / 3): emitted, absorbed by surfaces. */
void rad_solution_power(const rad_solution *solution, double *emitted, double *absorbed);

/* ---- The solution element by element and vertex by vertex ----
 *
 * Elements are numbered 0 .. rad_solution_element_count() - 1 and welded
 * vertices 0 .. rad_solution_vertex_count() - 1, so a program can read the
 * whole solution (lit meshes, lightmaps, its own analysis).  Elements are
 * planar triangles or quads.  The hierarchical solver's elements are the
 * leaves of its hierarchy: its patches until solved, then the leaves of the
 * last solve; indices and counts hold until the next rad_solution_solve.
 * An index out of range returns false (or 0) and writes nothing.  These
 * calls only read: any number of threads may call them at once on a
 * solution that is not being solved. */

size_t rad_solution_vertex_count(const rad_solution *solution);
/* Welded vertex position, m. */
bool rad_solution_vertex_position(const rad_solution *solution, size_t vertex, double xyz[3]);
/* Radiosity at every vertex (rgb: 3 per vertex, W/m^2): the values smooth
 * shading interpolates (area-weighted means of the elements around a
 * vertex, extrapolated at boundaries, continuous across T-vertices). */
rad_result rad_solution_vertex_radiosity(rad_context *ctx, const rad_solution *solution, double *rgb);

/* The element's corners (3 or 4 vertex indices, counter-clockwise about
 * its normal); returns their count, 0 when out of range. */
int rad_solution_element_vertices(const rad_solution *solution, size_t element, size_t vertex[4]);
/* Index of the scene surface it belongs to (SIZE_MAX when out of range). */
size_t rad_solution_element_surface(const rad_solution *solution, size_t element);
/* Area, m^2 (0 when out of range). */
double rad_solution_element_area(const rad_solution *solution, size_t element);
/* Unit normal, and centroid in m. */
bool rad_solution_element_geometry(const rad_solution *solution, size_t element, double normal[3],
                                   double centroid[3]);
/* Reflectance rho (RGB), emission E and radiosity B (RGB, W/m^2); any of
 * the three may be NULL. */
bool rad_solution_element_values(const rad_solution *solution, size_t element, double reflectance[3],
                                 double emission[3], double radiosity[3]);

/* ------------------------------------------------------------------------
 * Output
 * ---------------------------------------------------------------------- */

typedef enum rad_shading { RAD_SHADING_SMOOTH = 0, RAD_SHADING_FLAT = 1 } rad_shading;

typedef struct rad_render_options {
    int width, height;            /* pixels; 0 = 512 x 512 */
    int samples;                  /* anti-aliasing samples per pixel (square); 0 = 4 */
    const rad_camera *camera;     /* NULL = the scene's, else framed automatically */
    rad_shading shading;
    double exposure;              /* multiplier on radiance; 0 = automatic */
} rad_render_options;

/* A linear-radiance RGB image, W/(m^2 sr). */
typedef struct rad_image rad_image;

rad_result rad_solution_render(rad_context *ctx, rad_solution *solution,
                               const rad_render_options *options, rad_image **out);
void rad_image_destroy(rad_image *image);
int rad_image_width(const rad_image *image);
int rad_image_height(const rad_image *image);
const float *rad_image_pixels(const rad_image *image); /* RGB, row 0 at the top */

/* Write by extension: .png (exposed, sRGB, 8 bit), .hdr (Radiance RGBE) or
 * .pfm (32-bit float).  The file is written to a temporary name and renamed,
 * so a failure never leaves a partial file. */
rad_result rad_image_write(rad_context *ctx, const rad_image *image, const char *path);
/* The automatic exposure of an image: the multiplier that maps the 95th
 * percentile of its luminance to 0.8 (1 if it is black, or when its
 * context has no memory for a float per pixel). */
double rad_image_auto_exposure(const rad_image *image);

/* As rad_image_write, with the PNG exposure given (0 = automatic; ignored
 * by the linear formats). */
rad_result rad_image_write_exposed(rad_context *ctx, const rad_image *image, const char *path,
                                   double exposure);

/* Stats as JSON (schema in docs/stats.md).  `partial` marks an interrupted run. */
rad_result rad_solution_write_stats(rad_context *ctx, const rad_solution *solution,
                                    const char *path, int partial);

/* The stats of a run interrupted before it had a solution (while meshing or
 * computing form factors): version, "partial": true, "interrupted": phase,
 * "converged": false, the scene, its surface count and seconds.total
 * (docs/stats.md).  Atomic like the other writers. */
rad_result rad_scene_write_interrupted_stats(rad_context *ctx, const rad_scene *scene, const char *phase,
                                            double seconds, const char *path);

/* View factors, by extension: .json (surfaces with name, area, row_sum; F),
 * .csv (dense) or .mtx (Matrix Market coordinate, sparse).  `elements`
 * nonzero writes element-to-element factors instead of surface-level ones.
 * Atomic like the image writer.  Formats: docs/formats.md. */
rad_result rad_solution_write_view_factors(rad_context *ctx, const rad_solution *solution,
                                           const char *path, int elements);

/* ------------------------------------------------------------------------
 * Method registries
 * ---------------------------------------------------------------------- */

typedef enum rad_method_kind {
    RAD_METHOD_FORM_FACTOR = 0,
    RAD_METHOD_SOLVER = 1,
    RAD_METHOD_VISIBILITY = 2
} rad_method_kind;

/* Enumerate methods: returns 0 past the end.  *name and *description are
 * static strings. */
int rad_method_info(rad_method_kind kind, size_t index, const char **name,
                    const char **description);

#ifdef __cplusplus
}
#endif

#endif /* RADIOSITY_H */
