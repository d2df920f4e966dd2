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
 *             rad_solution_write_mesh   the lit mesh (glTF 2.0, PLY)
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
 *
 * NULL: a fallible call given a NULL context, object, path or out pointer
 * returns RAD_ERROR_INVALID_ARGUMENT (the message goes to the context when
 * there is one; *out is set to NULL when `out` is not NULL) and does nothing
 * else.  An options pointer may be NULL: all defaults.  Accessors given a
 * NULL object return the neutral value stated at each (0, NULL, NaN, "").
 *
 * Ownership and lifetime: whoever creates an object owns it and destroys it
 * with the matching rad_*_destroy.  Objects do not keep the context they
 * were made with: a context need only outlive each call it is passed to,
 * and any context may be passed with any object.  A solution borrows its
 * scene, which must outlive it.  Strings and arrays returned by accessors
 * are owned by the object they came from and stay valid until it is
 * destroyed (or until the event stated at the accessor); never free them.
 *
 * Threads: the library has no mutable global state, so calls on different
 * objects may run at the same time on different threads.  A context is used
 * by one thread at a time (it holds the error text and calls the progress
 * callback): give each thread its own.  A scene is immutable once made: any
 * number of threads may read it and create solutions from it at once.  A
 * solution or image may be read (calls taking it `const`) from several
 * threads at once, but not while a call that modifies it (solve, render)
 * runs.  Long calls use the context's worker threads (OpenMP) internally.
 *
 * Linking: pkg-config --cflags --libs radiosity, or in CMake
 * find_package(radiosity) and radiosity::radiosity (shared) or
 * radiosity::radiosity_static.  The shared library exports exactly the
 * functions declared here (RAD_API).
 */
#ifndef RADIOSITY_H
#define RADIOSITY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* What the shared library exports: every function below, nothing else (the
 * library is compiled with -fvisibility=hidden). */
#if defined(__GNUC__) || defined(__clang__)
#define RAD_API __attribute__((visibility("default")))
#else
#define RAD_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* The version of this header; CMakeLists.txt checks it against the project's. */
#define RAD_VERSION_MAJOR 0
#define RAD_VERSION_MINOR 1
#define RAD_VERSION_PATCH 0
#define RAD_VERSION_STRING "0.1.0"
/* MAJOR * 1000000 + MINOR * 1000 + PATCH, for comparisons in #if */
#define RAD_VERSION_NUMBER 1000

/* The version of the library linked at run time, which may differ from the
 * header's when the shared library was replaced: rad_version() is its
 * RAD_VERSION_STRING (a static string), rad_version_number() its
 * RAD_VERSION_NUMBER.  Cannot fail; any thread. */
RAD_API const char *rad_version(void);
RAD_API int rad_version_number(void);

typedef enum rad_result {
    RAD_OK = 0,
    RAD_ERROR_IO,               /* a file could not be read or written */
    RAD_ERROR_PARSE,            /* a file is malformed */
    RAD_ERROR_INVALID_SCENE,    /* NaN coordinates, reflectance >= 1, no emitter, ... */
    RAD_ERROR_INVALID_ARGUMENT, /* an option out of range, an unknown method name */
    RAD_ERROR_OUT_OF_MEMORY,    /* an allocation failed or would exceed the memory limit */
    RAD_ERROR_INTERRUPTED,      /* the cancel flag was raised; results are partial */
    RAD_ERROR_INTERNAL,         /* a library (Embree, LAPACK) failed unexpectedly */
    RAD_ERROR_NUMERICAL         /* the numbers cannot be trusted: a solve diverged (form
                                   factors that make up power), a system is singular */
} rad_result;

/* A short name for a result code ("RAD_ERROR_IO"), a static string;
 * "RAD_ERROR_UNKNOWN" for a value outside the enum.  Never NULL; any thread. */
RAD_API const char *rad_result_string(rad_result result);

/* ------------------------------------------------------------------------
 * Context: threads, progress, cancellation and the last error message.
 * ---------------------------------------------------------------------- */

typedef struct rad_context rad_context;

/* Progress of a long phase: `phase` is a short name ("form factors"), valid
 * during the callback only; `done` of `total` units finished.  Called from
 * the thread that made the library call, never from a worker thread. */
typedef void (*rad_progress_fn)(void *user, const char *phase, uint64_t done, uint64_t total);

/* Called once per failed call, with its result and the message that
 * rad_context_error() will return, from the thread that made the call. */
typedef void (*rad_error_fn)(void *user, rad_result result, const char *message);

/* Called when a call succeeds but reads its input differently from what the
 * file asks (a glTF orthographic camera, which the renderer does not draw,
 * replaced; a material's highlight, texture or transparency, which the
 * diffuse engine does not use: one line a material, after the load), or
 * meets geometry finer than its rays resolve (a polygon narrower than the
 * shadow rays' tolerance, 1e-5 of the scene's size):
 * one line naming the file, valid during the callback only; from the
 * thread that made the call. */
typedef void (*rad_warning_fn)(void *user, const char *message);

typedef struct rad_context_options {
    int threads;                 /* worker threads; 0 = all cores */
    rad_progress_fn progress;    /* optional progress callback */
    void *progress_user;         /* passed to `progress` */
    rad_error_fn on_error;       /* optional: told of every failure */
    void *error_user;            /* passed to `on_error` */
    /* Files a scene refers to (an OBJ's mtllib, a glTF's buffers and images)
     * are read only from the scene file's folder and below, after symbolic
     * links are resolved: a file that asks for "../../etc/passwd" or
     * "/etc/shadow" fails to load, naming the reference.  true lifts this. */
    bool read_outside_scene_folder;
    double max_memory_bytes;     /* the memory limit: everything the engine allocates in
                                    this context (scenes while loading included) stays
                                    below it, else RAD_ERROR_OUT_OF_MEMORY with the limit
                                    named; 0 = half the memory the process may use (the
                                    physical memory, or its cgroup's or RLIMIT_AS /
                                    RLIMIT_DATA's limit where lower).  Memory that
                                    assimp, Embree, LAPACK and cJSON allocate themselves
                                    is not counted (loading refuses files that assimp
                                    would need more than the limit for: docs/robustness.md) */
    rad_warning_fn on_warning;   /* optional: told of input read differently from the file,
                                    and of geometry finer than the rays resolve */
    void *warning_user;          /* passed to `on_warning` */
    /* A reflectance texture (MTL map_Kd, glTF baseColorTexture) that cannot
     * be read fails the load, naming the material, the MTL file and line
     * and the image; true makes it a warning and the material keeps its
     * flat Kd / base colour instead. */
    bool missing_textures_flat;
} rad_context_options;

/* Create a context.  `options` may be NULL (all defaults); it is copied, but
 * the pointers in it (progress_user, error_user, warning_user) are kept and must stay
 * valid until the context is destroyed.  Fails with
 * RAD_ERROR_INVALID_ARGUMENT when `out` is NULL, threads < 0 or
 * max_memory_bytes < 0, RAD_ERROR_OUT_OF_MEMORY when the allocation fails
 * (no context then holds a message). */
RAD_API rad_result rad_context_create(const rad_context_options *options, rad_context **out);
/* Destroy the context.  NULL: no-op.  Objects made with it are not
 * affected: their memory stays accounted to it, and a context destroyed
 * before them lives on (for no further calls) until the last of them is
 * destroyed. */
RAD_API void rad_context_destroy(rad_context *ctx);
/* The message of the most recent failed call in this context ("" if none):
 * its FIRST failure, which names the cause ("box.obj:12: ..."), not what
 * followed from it.  Owned by the context: valid until its next failing
 * call or its destroy.  NULL context: "". */
RAD_API const char *rad_context_error(const rad_context *ctx);

/* Ask the running and following calls to stop (cancel = true) or let them
 * run again (false).  Long phases poll the flag and return
 * RAD_ERROR_INTERRUPTED, keeping partial results.  An atomic store: safe
 * from a signal handler and from any thread.  NULL: no-op. */
RAD_API void rad_context_cancel(rad_context *ctx, bool cancel);
/* Whether cancellation was asked for (false for NULL).  Any thread. */
RAD_API bool rad_context_cancelled(const rad_context *ctx);
/* The worker threads this context's calls use (threads option; 0 there =
 * the number of cores).  NULL context: 1. */
RAD_API int rad_context_threads(const rad_context *ctx);

/* ------------------------------------------------------------------------
 * Scene: named surfaces made of planar polygons with Lambertian materials.
 * ---------------------------------------------------------------------- */

typedef struct rad_scene rad_scene;

/* Load OBJ(+MTL) or glTF 2.0 (.gltf/.glb) through assimp, coordinates in
 * metres.  The format is told by the content, not the name: binary glTF by
 * its magic, glTF by its JSON, anything else is read as OBJ.  The file and
 * its material libraries are read once, within the memory limit (an
 * import may take 20x their size).  The scene is validated: finite
 * coordinates, polygons of non-zero area, reflectance in [0, 1).  A scene
 * without an emitter loads; solving it is an error.  On success *out is a new scene the caller destroys with
 * rad_scene_destroy; it does not refer to `path` or the file afterwards.
 * Fails with RAD_ERROR_IO (unreadable), RAD_ERROR_PARSE (malformed, with
 * file:line), RAD_ERROR_INVALID_SCENE, RAD_ERROR_OUT_OF_MEMORY; NULL ctx,
 * path or out: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_scene_load_file(rad_context *ctx, const char *path, rad_scene **out);

/* Load from memory, as rad_scene_load_file.  `name` is used in messages
 * (the format is the content's).  `mtl`, if not NULL, is the text of the
 * material libraries an OBJ names in its `mtllib` statements, all of them
 * in one buffer.  The buffers are read during the call only (the scene copies
 * what it needs).  NULL ctx, name or out, or NULL data (mtl) with a
 * non-zero size: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_scene_load_memory(rad_context *ctx, const char *name, const void *data,
                                         size_t size, const void *mtl, size_t mtl_size,
                                         rad_scene **out);

/* The measured Cornell box (Cornell University Program of Computer
 * Graphics), in metres, with its published camera; "cornell-box" in
 * messages.  NULL ctx or out: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_scene_create_cornell_box(rad_context *ctx, rad_scene **out);

/* A procedural office floor (docs/scenes.md): `rooms` rooms of about
 * 4-6 x 4-6 x 3 m on a grid, with doors between neighbours, daylight
 * windows on the outside, ceiling lights, desks, chairs and shelves; about
 * 110-220 polygons per room, surfaces named "room3/desk1/top".  The same
 * seed gives the same scene bit for bit. */
typedef struct rad_office_options {
    int rooms;                   /* 1 to 100000; 0 = 4 */
    uint64_t seed;               /* any value (0 included) */
    int closed_doors;            /* nonzero: every door opening holds a closed door leaf on
                                    both faces of its wall, so each room is sealed */
} rad_office_options;

/* `options` may be NULL (the defaults).  Fails with
 * RAD_ERROR_INVALID_ARGUMENT when rooms is out of range or ctx or out is
 * NULL, RAD_ERROR_OUT_OF_MEMORY when the scene does not fit,
 * RAD_ERROR_INTERRUPTED (no scene) when the context was cancelled. */
RAD_API rad_result rad_scene_generate_office(rad_context *ctx, const rad_office_options *options,
                                             rad_scene **out);

/* Write a scene as OBJ + MTL: PATH (PATH.obj -> PATH.mtl beside it, named
 * in `mtllib`), one `o` per surface (its name, blanks replaced by '_'),
 * Kd = reflectance, Ke = emitted radiance = E / pi.  Coordinates are written
 * in the shortest decimal that parses back to the same double (the loader
 * reads them exactly); the camera, which OBJ cannot hold, is written as a
 * comment ("# radiosity camera: ...") that the OBJ loader reads back.  Both
 * files go to temporary names first and are renamed only when both are
 * complete, so a failure leaves neither (they are an output set, below:
 * a path that is a symbolic link, a device or /dev/stdout is treated as
 * there).  A context cancelled before the files are put in place leaves
 * neither and returns RAD_ERROR_INTERRUPTED.  Fails with RAD_ERROR_IO; NULL
 * ctx, scene or path, or an empty path: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_scene_write_obj(rad_context *ctx, const rad_scene *scene, const char *path);

/* The files a scene was read from, so that a program can keep its outputs
 * off them (rad_output_set_add_input): the scene file first, then every
 * file the loader opened (an OBJ's material libraries, a glTF's buffers
 * and images where the loader reads them), each once, as the loader named
 * it (relative to the working folder when the scene's path was).  A scene
 * from memory, the Cornell box or a generated one has none.  NULL scene:
 * 0 / NULL; an index out of range: NULL.  Strings owned by the scene. */
RAD_API size_t rad_scene_input_count(const rad_scene *scene);
RAD_API const char *rad_scene_input_path(const rad_scene *scene, size_t index);

/* Free the scene.  Every solution made from it must be destroyed first.
 * NULL: no-op. */
RAD_API void rad_scene_destroy(rad_scene *scene);

/* Surfaces are numbered 0 .. rad_scene_surface_count() - 1, in the order the
 * file names them; the same numbers index solutions' per-surface results.
 * NULL scene: 0. */
RAD_API size_t rad_scene_surface_count(const rad_scene *scene);
/* A surface's name (OBJ `o`/`g`, glTF node), owned by the scene: valid
 * until rad_scene_destroy.  NULL scene or surface out of range: NULL. */
RAD_API const char *rad_scene_surface_name(const rad_scene *scene, size_t surface);
/* A surface's area, m^2.  NULL scene or surface out of range: 0. */
RAD_API double rad_scene_surface_area(const rad_scene *scene, size_t surface);
/* Planar polygons in the scene (a non-planar face of the file counts as
 * its triangles).  NULL scene: 0. */
RAD_API size_t rad_scene_polygon_count(const rad_scene *scene);

/* A pinhole camera.  vfov_degrees is the full vertical field of view. */
typedef struct rad_camera {
    double position[3];           /* m */
    double look_at[3];            /* m */
    double up[3];
    double vfov_degrees;
} rad_camera;

/* Parse "px,py,pz,lx,ly,lz[,ux,uy,uz[,vfov]]": position, look-at point,
 * up vector (default 0,1,0) and vertical field of view (default 40).
 * *camera is written on success only.  Fails with
 * RAD_ERROR_INVALID_ARGUMENT on malformed text or a NULL ctx, text or
 * camera. */
RAD_API rad_result rad_camera_from_string(rad_context *ctx, const char *text, rad_camera *camera);

/* The scene's own camera (from the file, or the Cornell box's published
 * one).  Returns false and leaves *camera untouched when there is none or
 * scene or camera is NULL. */
RAD_API bool rad_scene_camera(const rad_scene *scene, rad_camera *camera);

/* Check, before any work, that `camera` can draw `scene`: its position
 * within 10^6 scene sizes (bounding-box diagonals) of the scene's centre.
 * Farther, double rounding of the pixel directions would misplace the
 * rays by more than the ray queries resolve, so rendering refuses such a
 * camera too; this call lets a program say so before it solves.
 * RAD_ERROR_INVALID_ARGUMENT with a message beginning "camera: " when it
 * is too far, or when ctx, scene or camera is NULL. */
RAD_API rad_result rad_scene_check_camera(rad_context *ctx, const rad_scene *scene,
                                          const rad_camera *camera);

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

/* rad_options.on_step's return value that ends the solve with its iterate kept
 * as the solution (an interactive "stop here"), where any other nonzero value
 * interrupts it. */
#define RAD_STEP_FINISH 2

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
    int no_control_variate;       /* nonzero: shooting and instant radiosity estimate B itself
                                     instead of B - beta, beta a constant per lit group whose
                                     transport is known (docs/methods.md); for comparison */
    int raw_form_factors;         /* nonzero: keep a sampled method's F (hemicube, hemisphere,
                                     montecarlo) as estimated; by default the two estimates
                                     of each pair are combined (reciprocity) and rows held
                                     to their measured closure, so energy is conserved */

    const char *solver;           /* NULL = "hierarchical" (lit scenes too), or "gauss-seidel"
                                     when mesh_size, target_elements, form_factors or an
                                     adaptive_* field is set (options of the uniform mesh and
                                     the matrix) */
    double tolerance;             /* stop when the residual falls below; 0 = 1e-6 */
    double unshot_tolerance;      /* also stop when the unshot power / emitted power falls
                                     below (shooting); 0 = not used */
    int max_iterations;           /* sweeps (gathering), shots (southwell) or batches of 32
                                     shots (shooting); 0 = automatic: 2 ln(tolerance) /
                                     ln(rho_max) + 10 bounces, at most 10^4; a cap above
                                     that is lowered to it (rad_solution_warning) */
    double relaxation;            /* over-relaxation factor omega in (0, 2): SOR for jacobi
                                     and gauss-seidel, overshooting for southwell; 0 = 1 */
    /* Called after every solver iteration (sweep or shot) with the solution in its
     * current state (rad_solution_render works on it: progressive display).  Return
     * nonzero to stop the solve early (it then returns RAD_ERROR_INTERRUPTED), or
     * RAD_STEP_FINISH to end it here with the iterate as its result: the solve
     * returns RAD_OK, the solution is solved but not converged (rad_solution_warning
     * says where it stopped) and saves, renders and exports as any other.
     * Hierarchical: after every Jacobi sweep, the solution's elements are then the
     * current leaves (their count grows after each refinement round, never shrinks)
     * with their current radiosity, and rad_solution_link_count the current links;
     * keeping them so costs a leaf mesh per round and a copy of the leaves' values
     * per sweep, paid only when on_step is set (docs/hierarchical.md). */
    int (*on_step)(void *user, rad_solution *solution, const struct rad_solve_step *step);
    void *on_step_user;
    int record_history;           /* nonzero: keep every step's residual in the history
                                     (gathering then measures the residual every sweep) */

    /* Hierarchical radiosity (solver "hierarchical"): a link is refined while its
     * estimated error, as power reflected by the receiver, exceeds epsilon times
     * the power the scene emits; elements are not split below min_area.  Its
     * sweeps reach the history and on_step (with the leaves as the mesh, above). */
    double epsilon;               /* 0 = 1e-4 */
    double min_area;              /* m^2; 0 = 1e-4 x the scene's total area, divided by
                                     patches / 100 when there are more than 100 */
    int clustering;               /* 0 = automatic (when the scene has more than 64
                                     patches), 1 = always, -1 = never */
    int classic_oracle;           /* nonzero: refine on the receiver's irradiance variation
                                     and visibility only (Hanrahan et al. 1991), not also on
                                     the source's radiosity variation: fewer links per
                                     element, per-surface means ~3x less accurate */

    /* Adaptive subdivision (the dense solvers): after the solve, elements
     * whose radiosity differs from a neighbour's by more than
     * adaptive_threshold times the scene's mean radiosity, or across which
     * the shadow rays to an emitter disagree, are split into four, the
     * neighbours kept within one level, and the system coupled and solved
     * again; up to adaptive_levels rounds (docs/methods.md). */
    int adaptive_levels;          /* splits below the starting mesh; 0 = off */
    double adaptive_threshold;    /* 0 = 0.1 */
    size_t adaptive_max_elements; /* element budget; 0 = 4 x the starting mesh's */

    uint64_t seed;                /* all sampling is seeded per element pair: results do
                                     not depend on the thread count */
    double max_memory_bytes;      /* 0 = the context's limit (rad_context_options); else a
                                     lower limit for this solution's calls (create, solve,
                                     render, the writers); never above the context's */
} rad_options;

/* Mesh the scene, build visibility and compute form factors, on the
 * context's threads.  The returned solution holds B = E (not yet solved);
 * the caller destroys it with rad_solution_destroy.  It borrows `scene`,
 * which must outlive it; `options` (NULL = all defaults) is copied, method
 * names included, so it need not outlive the call, except on_step_user,
 * which is kept.  The thread count is the context's at this call.  Fails
 * with RAD_ERROR_INVALID_ARGUMENT (an option out of range, an unknown
 * method, NULL ctx, scene or out), RAD_ERROR_OUT_OF_MEMORY (above
 * max_memory_bytes: the message names the option that shrinks it),
 * RAD_ERROR_INTERRUPTED, RAD_ERROR_INTERNAL. */
RAD_API rad_result rad_solution_create(rad_context *ctx, const rad_scene *scene,
                                       const rad_options *options, rad_solution **out);

/* Solve for B with the solver named in the options; solving again starts
 * over from B = E.  The scene must have an emitter (else
 * RAD_ERROR_INVALID_SCENE).  Returns RAD_ERROR_INTERRUPTED with the current
 * iterate kept (marked partial in the stats) if the cancel flag was raised
 * or on_step asked to stop.  NULL ctx or solution:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_solution_solve(rad_context *ctx, rad_solution *solution);

/* Free the solution and everything it owns (history included); the scene
 * and images rendered from it are not affected.  NULL: no-op. */
RAD_API void rad_solution_destroy(rad_solution *solution);

/* Elements of the mesh (the hierarchical solver's leaves once it has
 * solved, or inside on_step).  NULL solution: 0. */
RAD_API size_t rad_solution_element_count(const rad_solution *solution);
/* Residual measure after solving: sum_i A_i |r_i| / sum_i A_i E_i summed over
 * the channels, with r = B - E - rho F B (the notes' residual); 0 before
 * the first solve.  NULL solution: NaN. */
RAD_API double rad_solution_residual(const rad_solution *solution);
/* Iterations (sweeps or shots) the last solve took; 0 before the first.
 * NULL solution: 0. */
RAD_API int rad_solution_iterations(const rad_solution *solution);
/* Whether the last solve reached its tolerance: the residual below
 * rad_options.tolerance, or for shooting (whose measure is the unshot power)
 * the unshot power below rad_options.unshot_tolerance (0 = 1e-3).  Every
 * iterative solver stops at a bound however the scene converges (about
 * 2 ln(tolerance) / ln(rho_max) bounces of light, at most 10^4 unless
 * max_iterations asks for more), so a solve can end unconverged: then
 * rad_solution_warning says why.  False before the first solve, after an
 * interruption, and for a NULL solution. */
RAD_API bool rad_solution_converged(const rad_solution *solution);
/* One line on why the last solve stopped short of its tolerance ("gauss-seidel
 * did not converge in 10000 sweeps (the cap; ...): residual 0.83, tolerance
 * 1e-06"), owned by the solution until its next solve; "" when it converged,
 * was interrupted or has not run.  NULL solution: "". */
RAD_API const char *rad_solution_warning(const rad_solution *solution);

/* The convergence history of the last solve: *count steps, owned by the
 * solution and valid until its next solve or destroy.  NULL solution or
 * count: NULL (and *count = 0 when count is not NULL). */
RAD_API const rad_solve_step *rad_solution_history(const rad_solution *solution, size_t *count);
/* Write it as CSV (iteration,seconds,residual,unshot), atomically.  Fails
 * with RAD_ERROR_IO; NULL ctx, solution or path: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_solution_write_history(rad_context *ctx, const rad_solution *solution,
                                              const char *path);

/* Area-weighted mean radiosity of a surface, RGB, W/m^2, written to rgb.
 * A surface out of range, or a NULL solution: 0, 0, 0.  NULL rgb: nothing
 * is written. */
RAD_API void rad_solution_surface_radiosity(const rad_solution *solution, size_t surface,
                                            double rgb[3]);

/* Surface-to-surface view factors: F[i * S + j] for S surfaces, the
 * area-weighted sum over their elements.  `F` holds S*S doubles
 * (S = rad_scene_surface_count).  Matrix-free solvers compute no factors:
 * all 0.  NULL solution or F: nothing is written. */
RAD_API void rad_solution_surface_view_factors(const rad_solution *solution, double *F);

/* Power in watts (summed over RGB / 3): emitted, absorbed by surfaces.
 * NaN where it cannot be had (NULL solution, out of memory).  A NULL
 * emitted or absorbed is not written. */
RAD_API void rad_solution_power(const rad_solution *solution, double *emitted, double *absorbed);

/* ---- The solution element by element and vertex by vertex ----
 *
 * Elements are numbered 0 .. rad_solution_element_count() - 1 and welded
 * vertices 0 .. rad_solution_vertex_count() - 1, so a program can read the
 * whole solution (lit meshes, lightmaps, its own analysis).  Elements are
 * planar triangles or quads.  The hierarchical solver's elements are the
 * leaves of its hierarchy: its patches until solved, then the leaves of the
 * last solve; indices and counts hold until the next rad_solution_solve.
 * An index out of range, a NULL solution or a NULL output array returns
 * false (or 0, SIZE_MAX as said) and writes nothing.  These calls only
 * read: any number of threads may call them at once on a solution that is
 * not being solved. */

RAD_API size_t rad_solution_vertex_count(const rad_solution *solution);
/* Welded vertex position, m. */
RAD_API bool rad_solution_vertex_position(const rad_solution *solution, size_t vertex, double xyz[3]);
/* Radiosity at every vertex (rgb: 3 per vertex, W/m^2, written in full):
 * the values smooth shading interpolates (area-weighted means of the
 * elements around a vertex, extrapolated at boundaries, continuous across
 * T-vertices).  Fails with RAD_ERROR_OUT_OF_MEMORY; NULL ctx, solution or
 * rgb: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_solution_vertex_radiosity(rad_context *ctx, const rad_solution *solution,
                                                 double *rgb);

/* The element's corners (3 or 4 vertex indices, counter-clockwise about
 * its normal); returns their count, 0 when out of range. */
RAD_API int rad_solution_element_vertices(const rad_solution *solution, size_t element,
                                          size_t vertex[4]);
/* Index of the scene surface it belongs to (SIZE_MAX when out of range). */
RAD_API size_t rad_solution_element_surface(const rad_solution *solution, size_t element);
/* Area, m^2 (0 when out of range). */
RAD_API double rad_solution_element_area(const rad_solution *solution, size_t element);
/* Unit normal, and centroid in m; either may be NULL. */
RAD_API bool rad_solution_element_geometry(const rad_solution *solution, size_t element,
                                          double normal[3], double centroid[3]);
/* Reflectance rho (RGB), emission E and radiosity B (RGB, W/m^2); any of
 * the three may be NULL. */
RAD_API bool rad_solution_element_values(const rad_solution *solution, size_t element,
                                        double reflectance[3], double emission[3], double radiosity[3]);

/* ------------------------------------------------------------------------
 * Output
 * ---------------------------------------------------------------------- */

typedef enum rad_shading { RAD_SHADING_SMOOTH = 0, RAD_SHADING_FLAT = 1 } rad_shading;

typedef struct rad_render_options {
    int width, height;            /* pixels; 0 = 512 x 512 */
    int samples;                  /* anti-aliasing samples per pixel (square) where a 2 x 2 pilot
                                     sees more than one patch; 0 = 4 */
    const rad_camera *camera;     /* NULL = the scene's, else framed automatically */
    rad_shading shading;
    double exposure;              /* multiplier on radiance; 0 = automatic */
    /* Per-pixel instant radiosity (Keller 1997, docs/methods.md): light
     * paths from the emitters; each camera ray's point gathers their
     * virtual point lights and the emitters with shadow rays, instead of
     * reading the solved elements (which then give only reflectance and
     * emission).  View-dependent, no mesh error; rad_options.seed keys it.
     * 0 = off (the solved radiosity). */
    int vpl_paths;
    /* The second pass (on wherever the scene has specular materials: MTL
     * illum 3 to 7): mirror, glass and glossy bounces followed from the
     * eye, the first pass's B / pi read where a path lands on a diffuse
     * surface (docs/methods.md "Two-pass rendering"). */
    int specular_depth;           /* specular bounces a path follows; 0 = 8; -1 = none (B / pi at
                                     the first hit, the first pass alone) */
    int glossy_samples;           /* rays a glossy surface seen from the eye sends (stratified);
                                     0 = 16; deeper glossy bounces send 1 */
    /* The final gather of the emitters' direct light (docs/methods.md "The
     * final gather"): at each shading point the emitting surfaces' light
     * with exact visibility, the elements' values for the rest, so shadows
     * are as sharp as the pixels.  0 or 1 = on (smooth shading, no
     * vpl_paths, at most 256 emitting elements), -1 = off (the elements'
     * values alone). */
    int direct_gather;
} rad_render_options;

/* A linear-radiance RGB image, W/(m^2 sr). */
typedef struct rad_image rad_image;

/* Ray-cast an image of the solution's radiance L = B / pi (solved or not:
 * progressive display from on_step works), on the context's threads.
 * `options` may be NULL (512 x 512, the scene's camera); its camera is read
 * during the call only.  The image is the caller's, independent of the
 * solution (it may outlive it); destroy it with rad_image_destroy.  The
 * solution is modified (it caches vertex values).  Fails with
 * RAD_ERROR_OUT_OF_MEMORY, RAD_ERROR_INTERRUPTED; NULL ctx, solution or
 * out: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_solution_render(rad_context *ctx, rad_solution *solution,
                                       const rad_render_options *options, rad_image **out);
/* Free the image.  NULL: no-op. */
RAD_API void rad_image_destroy(rad_image *image);
/* Pixels across and down.  NULL image: 0. */
RAD_API int rad_image_width(const rad_image *image);
RAD_API int rad_image_height(const rad_image *image);
/* width * height RGB triples, row 0 at the top, W/(m^2 sr); owned by the
 * image, valid until rad_image_destroy.  NULL image: NULL. */
RAD_API const float *rad_image_pixels(const rad_image *image);

/* Write by extension: .png (exposed, sRGB, 8 bit), .hdr (Radiance RGBE) or
 * .pfm (32-bit float).  The file is written to a temporary name (created
 * with O_EXCL beside it) and renamed, so a failure never leaves a partial
 * file; a symbolic link's target is replaced, a device, a FIFO or the
 * program's own stdout is written in place once the bytes are complete, a
 * dangling link or a folder is refused (docs/robustness.md).  Several
 * files as one: rad_output_set below.  Fails with RAD_ERROR_IO;
 * an unknown extension, an empty image or a NULL ctx, image or path:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_image_write(rad_context *ctx, const rad_image *image, const char *path);
/* The automatic exposure of an image: the multiplier that maps the 95th
 * percentile of its luminance to 0.8 (1 if it is black, or NULL, or when
 * its context has no memory for a float per pixel). */
RAD_API double rad_image_auto_exposure(const rad_image *image);

/* As rad_image_write, with the PNG exposure given (0 = automatic; ignored
 * by the linear formats; negative or not finite:
 * RAD_ERROR_INVALID_ARGUMENT). */
RAD_API rad_result rad_image_write_exposed(rad_context *ctx, const rad_image *image,
                                           const char *path, double exposure);

/* Radiosity at a point of surface `surface`, W/m^2 RGB, interpolated from
 * the vertex values (rad_solution_vertex_radiosity) as smooth shading
 * interpolates them: the point is taken to the nearest
 * point of the surface's polygons, which must be within 1e-3 of the
 * scene's size, else RAD_ERROR_INVALID_ARGUMENT naming the distance (and
 * for a surface index out of range, a point not finite, or NULL ctx,
 * solution, point or rgb; rgb is then NaN).  O(polygons of the surface);
 * the first call after a solve computes the vertex values (O(elements)):
 * not at the same time as other calls on the same solution. */
RAD_API rad_result rad_solution_point_radiosity(rad_context *ctx, rad_solution *solution, size_t surface,
                                                const double point[3], double rgb[3]);

/* ---- the solution file: solve once, render from any camera ---- */

/* Write the solved solution to `path` (docs/formats.md, "Solution file"):
 * its scene (polygons, surfaces, materials, camera, with a checksum), its
 * mesh (patches, elements, welded vertices, T-vertices, quadtrees), each
 * element's and vertex's radiosity in W/m^2 as doubles, the options and the
 * solve's figures; atomically (a temporary, renamed).  The vertex values
 * are the renderer's, so they are computed here if no render did.  The
 * scene's light goes with it: luminaires (distributions, placements),
 * daylight (the sky as prepared, sun, ground, openings) and each element's
 * direct light.  Fails with RAD_ERROR_INVALID_ARGUMENT for a solution not
 * solved, or NULL ctx, solution or path; RAD_ERROR_IO,
 * RAD_ERROR_OUT_OF_MEMORY.  Not at the same time as other calls on the
 * same solution. */
RAD_API rad_result rad_solution_save(rad_context *ctx, rad_solution *solution, const char *path);

/* Read a solution file: *scene is the scene it was solved for (rebuilt and
 * checked against its checksum) and *solution the solved solution, which
 * borrows *scene: destroy the solution, then the scene.  Everything in the
 * file is validated (signature, version, counts, checksum, every index,
 * every value); a file that is not a solution file or is damaged fails with
 * RAD_ERROR_PARSE and one line naming the file and what is wrong; a scene
 * that does not validate with RAD_ERROR_INVALID_SCENE; RAD_ERROR_IO,
 * RAD_ERROR_OUT_OF_MEMORY (the file and what it holds count against the
 * memory limit).  The loaded solution renders, answers every accessor and
 * writes its stats; it is solved (rad_solution_solve does nothing) and
 * holds no form factors (view factors are zero).  On failure both are NULL.
 * NULL ctx, path, scene or solution: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_solution_load_file(rad_context *ctx, const char *path, rad_scene **scene,
                                          rad_solution **solution);
/* The same from `size` bytes at `data`; `name` stands for the file in
 * messages. */
RAD_API rad_result rad_solution_load_memory(rad_context *ctx, const char *name, const void *data,
                                            size_t size, rad_scene **scene, rad_solution **solution);
/* True if `path` is a regular file that begins with the solution file's
 * signature (the command line reads such a file as a solution, anything
 * else as a scene).  Any thread; NULL: false. */
RAD_API bool rad_file_is_solution(const char *path);

/* Stats as JSON (schema in docs/stats.md), atomically.  `partial` marks an
 * interrupted run.  Fails with RAD_ERROR_IO, RAD_ERROR_OUT_OF_MEMORY; NULL
 * ctx, solution or path: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_solution_write_stats(rad_context *ctx, const rad_solution *solution,
                                            const char *path, bool partial);

/* The stats of a run interrupted before it had a solution (while meshing or
 * computing form factors): version, "partial": true, "interrupted": phase,
 * "converged": false, the scene, its surface count and seconds.total
 * (docs/stats.md).  Atomic like the other writers.  Fails with
 * RAD_ERROR_IO, RAD_ERROR_OUT_OF_MEMORY; NULL ctx, scene, phase or path:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_scene_write_interrupted_stats(rad_context *ctx, const rad_scene *scene,
                                                     const char *phase, double seconds, const char *path);

/* View factors, by extension: .json (surfaces with name, area, row_sum; F),
 * .csv (dense) or .mtx (Matrix Market coordinate, sparse).  `elements`
 * true writes element-to-element factors instead of surface-level ones.
 * Atomic like the image writer.  Formats: docs/formats.md.  Fails with
 * RAD_ERROR_IO, RAD_ERROR_OUT_OF_MEMORY; an unknown extension, a
 * matrix-free solver (no factors) or a NULL ctx, solution or path:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_solution_write_view_factors(rad_context *ctx, const rad_solution *solution,
                                                   const char *path, bool elements);

/* The lit mesh, by extension (docs/formats.md): .glb (binary glTF 2.0),
 * .gltf (glTF 2.0 with its buffer inside as a base64 data URI: one file) or
 * .ply (binary little-endian PLY).  The mesh is the solution's: its welded
 * vertices (rad_solution_vertex_position) and elements, quads split into
 * two triangles in glTF.  Each vertex holds its radiosity B as
 * rad_solution_vertex_radiosity gives it (W/m^2, as float: glTF attribute
 * _RADIOSITY, PLY radiosity_r/g/b) and a display colour, the radiance
 * B / pi times `exposure` clamped to [0, 1] (glTF COLOR_0, linear, with
 * unlit materials of base colour 1; PLY red/green/blue, sRGB-encoded 8 bits
 * as in PNG images).  `exposure` is a multiplier on radiance in
 * W/(m^2 sr); 0 = automatic: the rule of rad_image_auto_exposure applied to
 * the vertices' radiances.  The exposure used is in the file (glTF
 * asset.extras.radiosity.exposure, a PLY comment).  glTF has one node and
 * mesh per surface, named after it, and one primitive per material of the
 * surface.  Atomic like the image writer; the solution is only read (a
 * solution being solved must not be written).  Fails with RAD_ERROR_IO,
 * RAD_ERROR_OUT_OF_MEMORY; an unknown extension, a negative or non-finite
 * exposure, a .glb above 4 GiB or a NULL ctx, solution or path:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_solution_write_mesh(rad_context *ctx, const rad_solution *solution,
                                           const char *path, double exposure);

/* ------------------------------------------------------------------------
 * View factors in row blocks: scenes whose n x n matrix (8 n^2 bytes:
 * 80 GB at 10^5 elements) does not fit in memory.
 *
 *     rad_stream_options so = {0};             // blocks sized automatically
 *     rad_stream_stats st;
 *     rad_scene_stream_view_factors(ctx, scene, &options, &so, "vf.json", &st);
 *
 * Rows of F are made a block at a time ([r0, r1), block_rows x n doubles)
 * and handed to the output, then the block is reused: memory is O(n)
 * beyond one block.  The output is byte for byte what
 * rad_solution_write_view_factors writes from the dense matrix: a pair
 * method evaluates each pair as the dense loop does, (i < j) with that
 * pair's own random numbers, so reciprocity stays exact across blocks; the
 * pairs between a block and the rows before it are evaluated once more
 * (about twice the dense loop's pair evaluations for small blocks, none
 * extra for one block of n rows).  What streams (docs/formats.md,
 * "Streamed view factors"): surface level as .json, .csv, .mtx (an S x S
 * sum, written at the end); element level as .csv and .mtx.  Refused
 * (RAD_ERROR_INVALID_ARGUMENT): element-level .json (each row's sum comes
 * before all the rows), a sampled method's balance step (hemicube,
 * hemisphere, montecarlo without rad_options.raw_form_factors), the
 * closure correction and adaptive subdivision: each needs the whole
 * matrix.  Standard errors of sampled methods are not written.  An
 * element-level output that would not fit on its file system (estimated
 * before the first row and again after the first block) is refused
 * (RAD_ERROR_IO) and nothing is left.
 * ---------------------------------------------------------------------- */

/* Processes sharing the blocks (an MPI job: `mpirun -np N radiosity
 * viewfactors`; the program supplies the messages, the library needs no
 * MPI).  Block b is made by rank b % size; rank 0 receives the others'
 * blocks in order and writes the one output, so the file does not depend
 * on the number of ranks.  Each rank loads and meshes the scene itself
 * (the mesh is deterministic).  A message is a block's rows followed by
 * RAD_STREAM_TALLY doubles (its counts and reciprocity).  The callbacks
 * are called on the calling thread; nonzero from either fails the call
 * with RAD_ERROR_IO (the program should then end the job: the other ranks
 * wait for rank 0). */
enum { RAD_STREAM_TALLY = 5 };
typedef struct rad_stream_ranks {
    int rank;                 /* this process, 0 .. size - 1; rank 0 writes the output */
    int size;                 /* processes; 0 or 1: this one alone */
    /* Rank 0: fill data with `count` doubles sent by rank `from`. */
    int (*receive)(void *user, int from, double *data, size_t count);
    /* Ranks above 0: send `count` doubles to rank 0. */
    int (*send)(void *user, const double *data, size_t count);
    void *user;
} rad_stream_ranks;

/* Zero-initialisable: 0 means the default. */
typedef struct rad_stream_options {
    size_t block_rows;        /* element rows per block; 0 = as many as fit in 1/8 of the memory
                                 limit (at least 1, at most n) */
    int elements;             /* nonzero: element-to-element factors (.csv, .mtx), else surface level */
    int only_if_needed;       /* nonzero: when the dense matrix (and the element table the dense
                                 writer copies it into) fits under the memory limit, write nothing
                                 and return RAD_OK with stats->streamed = 0, for the caller to take
                                 the dense route; ignored with more than one rank */
    const rad_stream_ranks *ranks; /* NULL: this process alone */
    /* Surface level: obstruction surfaces left out, smoothing, sparse
     * threshold, as rad_solution_write_view_factors_with (NULL: none; its
     * `elements` is ignored).  Element rows are written as computed. */
    const struct rad_view_factor_options *factors;
} rad_stream_options;

/* What a streamed run did (rank 0 sees every block; other ranks their own). */
typedef struct rad_stream_stats {
    int streamed;             /* 0: only_if_needed found that the dense route fits */
    size_t elements;          /* n */
    size_t block_rows;        /* rows per block */
    size_t blocks;            /* blocks made or received */
    uint64_t pairs;           /* element pairs evaluated, as the dense loop counts them */
    uint64_t pairs_again;     /* pairs evaluated a second time (the price of the blocks) */
    uint64_t rays;            /* shadow / visibility rays */
    double row_sum_min, row_sum_max, row_sum_mean; /* over the element rows */
    double diagonal_max;      /* largest F_ii */
    double reciprocity_max;   /* max |A_i F_ij - A_j F_ji| / max(...) over the pairs evaluated
                                 (row methods: pairs within one block) */
    double block_bytes;       /* the block's memory, bytes */
    double mesh_seconds;      /* mesh and ray structure */
    double seconds;           /* form factors and writing */
} rad_stream_stats;

/* Mesh `scene` under `options` (NULL: defaults; the solver is not used)
 * and write its view factors to `path` (by extension, as
 * rad_solution_write_view_factors; ignored, and may be NULL, on ranks
 * above 0) in row blocks.  Atomic: the file appears complete or not at
 * all.  Threads: the context's, within each block.  Polls cancellation
 * (RAD_ERROR_INTERRUPTED, nothing written) and reports progress as
 * "form factors".  *stats is filled (zeroed first).  Fails with
 * RAD_ERROR_IO, RAD_ERROR_OUT_OF_MEMORY; the refusals above, an unknown
 * extension or a NULL ctx, scene, stream or stats (or path on rank 0):
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_scene_stream_view_factors(rad_context *ctx, const rad_scene *scene,
                                                 const rad_options *options, const rad_stream_options *stream,
                                                 const char *path, rad_stream_stats *stats);

/* ------------------------------------------------------------------------
 * Output sets: the files of one run, written all together or not at all.
 *
 *     rad_output_set *set;
 *     rad_output_set_create(ctx, &set);
 *     rad_output_set_add_input(ctx, set, "scene.obj");   // never an output
 *     const char *png, *stats;                           // checked here,
 *     rad_output_set_add(ctx, set, "out.png", RAD_OUTPUT_IMAGE, &png);   // before
 *     rad_output_set_add(ctx, set, "run.json", RAD_OUTPUT_FILE, &stats); // any work
 *     ... load, solve, render ...
 *     rad_image_write(ctx, image, png);                  // into the temporaries
 *     rad_solution_write_stats(ctx, solution, stats, false);
 *     rad_output_set_commit(ctx, set);                   // all appear, or none
 *     rad_output_set_destroy(set);                       // removes what is left
 *
 * Every writer above is atomic on its own; a set makes several of them one
 * transaction, so a run that fails after writing its image (a stats file
 * in a missing folder, an interrupted render) leaves the old image.  Paths
 * are compared by the file they lead to (device and inode; for a file not
 * there yet, its folder and name), so "a.png", "./a.png" and a hard link
 * to it are one file.  What each kind of path does (regular files,
 * symbolic links, devices, FIFOs, /dev/stdout): docs/robustness.md.
 * A set is used by one thread at a time.
 * ---------------------------------------------------------------------- */

typedef struct rad_output_set rad_output_set;

/* What an output holds, for the check of its extension at rad_output_set_add. */
typedef enum rad_output_kind {
    RAD_OUTPUT_FILE = 0,        /* any name: stats, history, OBJ */
    RAD_OUTPUT_IMAGE = 1,       /* .png, .hdr, .pfm (rad_image_write) */
    RAD_OUTPUT_VIEW_FACTORS = 2, /* .json, .csv, .mtx (rad_solution_write_view_factors) */
    RAD_OUTPUT_MESH = 3,         /* .glb, .gltf, .ply (rad_solution_write_mesh) */
    RAD_OUTPUT_BAKE = 4,         /* .glb, .gltf (rad_solution_bake) */
    RAD_OUTPUT_THERMAL = 8,      /* .csv, .json (rad_thermal_write, rad_thermal_write_gebhart) */
    RAD_OUTPUT_SOLUTION = 16,    /* .radsol (rad_solution_save) */
    RAD_OUTPUT_ILLUMINANCE = 32  /* .csv, .json (rad_illuminance_write) */
} rad_output_kind;

/* An empty set.  Fails with RAD_ERROR_OUT_OF_MEMORY; NULL ctx or out:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_output_set_create(rad_context *ctx, rad_output_set **out);

/* Name a file the run reads (rad_scene_input_path gives a loaded scene's):
 * no output of the set may be it, before or after this call.  A path that
 * does not exist is ignored.  Fails with RAD_ERROR_INVALID_ARGUMENT
 * ("out.json: is the same file as the input scene.obj ...") when an output
 * already added is that file, RAD_ERROR_OUT_OF_MEMORY; NULL ctx, set or
 * path: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_output_set_add_input(rad_context *ctx, rad_output_set *set, const char *path);

/* Plan the output `path` and check it now: its format (by `kind`), that it
 * is not an input or another output of the set (RAD_ERROR_INVALID_ARGUMENT,
 * naming both paths), that it can be written (RAD_ERROR_IO: missing or
 * read-only folder, a directory, a dangling symbolic link).  On success
 * *temp_path is a new empty file (in the output's folder, or the temporary
 * folder for a device or FIFO) with the same extension: write the output
 * there with any of this header's writers.  The string is owned by the set
 * (valid until commit, drop or destroy).  On failure *temp_path is NULL and
 * the set is unchanged.  NULL ctx, set, path or temp_path:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_output_set_add(rad_context *ctx, rad_output_set *set, const char *path,
                                      rad_output_kind kind, const char **temp_path);

/* Leave the output added as `path` out of the commit (the run could not
 * make it: no image when interrupted before a solution); the old file
 * stays and its temporary is removed.  An unknown path or a NULL set or
 * path: no-op.  Cannot fail. */
RAD_API void rad_output_set_drop(rad_output_set *set, const char *path);

/* Put every output not dropped in place: devices, FIFOs and the program's
 * own stdout/stderr are written in place first (a failure there changes no
 * file), then the files are renamed over the old ones (a failed rename
 * puts back those already replaced).  Commit once, after every output was
 * written to its temporary.  Fails with RAD_ERROR_IO naming the output;
 * NULL ctx or set: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_output_set_commit(rad_context *ctx, rad_output_set *set);

/* Free the set, removing every temporary not committed (the old files
 * stay).  NULL: no-op. */
RAD_API void rad_output_set_destroy(rad_output_set *set);

/* ------------------------------------------------------------------------
 * Lightmaps: the solution baked into textures (docs/formats.md, "Lightmap").
 */

typedef enum rad_lightmap_quantity {
    RAD_LIGHTMAP_RADIOSITY = 0,  /* B, written as radiance B/pi, W/(m^2 sr) */
    RAD_LIGHTMAP_IRRADIANCE = 1  /* H = (B - E)/rho (0 where rho = 0), written as H/pi */
} rad_lightmap_quantity;

typedef struct rad_bake_options {
    double texels_per_metre;     /* 0 = 10 */
    int atlas_size;              /* the largest atlas side, a power of two from 8 to 16384; 0 = 2048 */
    rad_lightmap_quantity quantity;
    double exposure;             /* the glTF's COLOR_0, as rad_solution_write_mesh; 0 = automatic */
} rad_bake_options;

typedef struct rad_bake_stats {
    size_t atlases;
    double chart_texels;         /* the charts' boxes */
    double atlas_texels;         /* the atlases': chart_texels / atlas_texels is the fill ratio */
    double seconds;              /* charting, packing, filling and writing */
} rad_bake_stats;

/* Bake the solution into lightmaps and write the lit mesh that uses them.
 * `path` (.glb or .gltf) must be in `set` already (rad_output_set_add with
 * RAD_OUTPUT_BAKE or RAD_OUTPUT_MESH); the atlases are added to the set
 * beside it as STEM_lightmapK.hdr (linear radiance, Radiance RGBE) and
 * STEM_lightmapK.png (RGBM), K from 0, and every file is written into its
 * temporary: rad_output_set_commit puts them all in place.  Each patch is a
 * chart in its own plane at options->texels_per_metre, packed with 2 texels
 * of dilated padding into power-of-two atlases.  The glTF is
 * rad_solution_write_mesh's with each vertex split per patch, TEXCOORD_1
 * (atlas coordinates) and MOZ_lightmap on every material.  Fails with
 * RAD_ERROR_INVALID_ARGUMENT (bad options, a chart larger than an atlas, a
 * path not in the set), RAD_ERROR_OUT_OF_MEMORY (the atlases above the
 * memory limit: the message says so), RAD_ERROR_IO.  `stats`, if not
 * NULL, gets the atlases' figures. */
RAD_API rad_result rad_solution_bake(rad_context *ctx, const rad_solution *solution,
                                     const rad_bake_options *options, rad_output_set *set, const char *path,
                                     rad_bake_stats *stats);

/* The name of atlas `atlas`'s lightmap beside the baked mesh `path`:
 * `path` without its extension, "_lightmap", the atlas number, ".",
 * `extension` ("room.glb", 0, "png": "room_lightmap0.png"), into `out`
 * (snprintf's rules: `size` bytes at most, NUL included).  Returns the
 * name's length, 0 for a NULL path or extension.  For planning outputs:
 * the first atlas always exists. */
RAD_API size_t rad_bake_image_path(const char *path, size_t atlas, const char *extension, char *out, size_t size);

/* ------------------------------------------------------------------------
 * Radiative heat exchange (docs/thermal.md): the same equation in a thermal
 * engineer's terms.  Each surface is grey and diffuse with an emissivity
 * eps in (0, 1], and has a known temperature T, a known net heat flux q
 * or none (adiabatic, q = 0); what escapes an open scene meets an
 * environment at T_env.  The net-radiation equations
 *
 *     known T:  J_i = eps_i sigma T_i^4 + (1 - eps_i) G_i
 *     known q:  J_i = q_i + G_i
 *     G_i = sum_j F_ij J_j + (1 - sum_j F_ij) sigma T_env^4
 *
 * are solved on a solution's elements and form factors with a linear
 * solver of the table, giving per element and per surface the radiosity J,
 * irradiation G, net flux q = J - G (W/m^2, leaving the surface), net power
 * Q = A q (W) and the temperatures not given.  sigma = RAD_SIGMA.
 *
 *     rad_solution_create(ctx, scene, &(rad_options){.solver = "direct"}, &sol);
 *     rad_thermal_conditions_load_file(ctx, scene, "bc.json", &bc);
 *     rad_thermal_solve(ctx, sol, bc, NULL, &heat);
 *     rad_thermal_write(ctx, heat, "heat.csv", false);
 *
 * Temperatures in kelvin, fluxes in W/m^2, powers in W (docs/units.md).
 * ---------------------------------------------------------------------- */

/* Stefan-Boltzmann constant, W m^-2 K^-4 (CODATA 2018; exact in SI since 2019). */
#define RAD_SIGMA 5.670374419e-8

typedef enum rad_thermal_condition {
    RAD_THERMAL_UNSET = 0,         /* no condition given (refused by rad_thermal_solve) */
    RAD_THERMAL_TEMPERATURE = 1,   /* value: T, K, finite, >= 0 */
    RAD_THERMAL_HEAT_FLUX = 2,     /* value: net flux leaving the surface, W/m^2, finite */
    RAD_THERMAL_ADIABATIC = 3,     /* q = 0: a re-radiating surface (value unused) */
    /* A View3D obstruction-only surface (or mask): it blocks radiation and
     * takes no part in the exchange; what it intercepts reaches the
     * environment (a black surface at the environment temperature, its power
     * counted as the environment's).  Set for those surfaces when the
     * conditions are made; cannot be set or given otherwise. */
    RAD_THERMAL_OBSTRUCTION = 4
} rad_thermal_condition;

typedef struct rad_thermal_surface {
    rad_thermal_condition condition;
    double value;                  /* K or W/m^2, as the condition says */
    double emissivity;             /* (0, 1]; 0 = from the scene: 1 - the mean over RGB of
                                      each element's reflectance (a View3D file's
                                      emissivities arrive so) */
} rad_thermal_surface;

/* The conditions of every surface of one scene, and T_env.  Made empty
 * (every surface RAD_THERMAL_UNSET, T_env = 0 K) or from a file. */
typedef struct rad_thermal_conditions rad_thermal_conditions;

/* Empty conditions for `scene`, which must outlive them.  Fails with
 * RAD_ERROR_OUT_OF_MEMORY; NULL ctx, scene or out: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_thermal_conditions_create(rad_context *ctx, const rad_scene *scene,
                                                 rad_thermal_conditions **out);

/* Read a boundary-condition file (JSON, docs/thermal.md) for `scene`:
 *
 *     {"environment_temperature": 3,
 *      "default": {"emissivity": 0.9, "adiabatic": true},
 *      "surfaces": {"floor": {"emissivity": 0.8, "temperature": 1200},
 *                   "lid": {"heat_flux": -5000}}}
 *
 * Every surface of the scene needs a condition, from "surfaces" or
 * "default".  Fails with RAD_ERROR_PARSE and one line naming the file and
 * the key ("bc.json: surfaces.floor.emissivity: must be in (0, 1], got
 * 1.5"): not JSON, an unknown key or surface name, a name given twice, a
 * value of the wrong type or out of range (emissivity outside (0, 1], a
 * negative or non-finite temperature), both a temperature and a heat flux,
 * a surface without a condition; RAD_ERROR_IO, RAD_ERROR_OUT_OF_MEMORY.
 * The file is read within the memory limit.  On failure *out is NULL.
 * NULL ctx, scene, path or out: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_thermal_conditions_load_file(rad_context *ctx, const rad_scene *scene, const char *path,
                                                    rad_thermal_conditions **out);
/* The same from `size` bytes at `data`; `name` stands for the file in
 * messages. */
RAD_API rad_result rad_thermal_conditions_load_memory(rad_context *ctx, const rad_scene *scene, const char *name,
                                                      const void *data, size_t size,
                                                      rad_thermal_conditions **out);

/* Set one surface's condition (a copy).  Fails with
 * RAD_ERROR_INVALID_ARGUMENT for a surface out of range, an unknown
 * condition, a value or emissivity out of range (as the file's), or a NULL
 * ctx, conditions or surface_condition. */
RAD_API rad_result rad_thermal_conditions_set(rad_context *ctx, rad_thermal_conditions *conditions,
                                              size_t surface, const rad_thermal_surface *surface_condition);
/* Set T_env in K (finite, >= 0; else RAD_ERROR_INVALID_ARGUMENT, as for a
 * NULL ctx or conditions). */
RAD_API rad_result rad_thermal_conditions_set_environment(rad_context *ctx, rad_thermal_conditions *conditions,
                                                          double kelvin);
/* A surface's condition into *out; false (nothing written) for a surface
 * out of range or a NULL argument. */
RAD_API bool rad_thermal_conditions_get(const rad_thermal_conditions *conditions, size_t surface,
                                        rad_thermal_surface *out);
/* T_env, K.  NULL: NaN. */
RAD_API double rad_thermal_conditions_environment(const rad_thermal_conditions *conditions);
/* NULL: no-op. */
RAD_API void rad_thermal_conditions_destroy(rad_thermal_conditions *conditions);

typedef struct rad_thermal_options {
    const char *solver;            /* a linear solver of the table (rad_method_info); NULL =
                                      "direct" (LU: exact, the reference) */
    double tolerance;              /* the solver's residual, relative to sum A |E|; 0 = 1e-10 */
    int max_iterations;            /* iterative solvers; 0 = automatic (rad_options') */
} rad_thermal_options;

/* The heat exchange solved for one solution's elements. */
typedef struct rad_thermal rad_thermal;

/* Solve the net-radiation equations on `solution`'s elements and form
 * factors (a solution made with a dense solver: "direct", "gauss-seidel",
 * ...; it need not be solved, and its scene needs no emitter) for
 * `conditions` (of the solution's scene).  The result borrows the solution,
 * which must outlive it and not be solved again meanwhile.  A group of
 * surfaces that exchange radiation with heat fluxes only and nothing
 * escaping (under 1e-3 of their radiation) has no unique temperatures:
 * refused.  Fails with RAD_ERROR_INVALID_ARGUMENT (a surface without a
 * condition, such a closed group, a flux no temperature gives, options out
 * of range, a solution without form factors: hierarchical or matrix-free),
 * RAD_ERROR_OUT_OF_MEMORY, RAD_ERROR_INTERRUPTED, or as the solver.  NULL
 * ctx, solution, conditions or out: RAD_ERROR_INVALID_ARGUMENT.  `options`
 * may be NULL (defaults). */
RAD_API rad_result rad_thermal_solve(rad_context *ctx, const rad_solution *solution,
                                     const rad_thermal_conditions *conditions, const rad_thermal_options *options,
                                     rad_thermal **out);
/* NULL: no-op. */
RAD_API void rad_thermal_destroy(rad_thermal *thermal);

/* One surface's or element's figures. */
typedef struct rad_thermal_values {
    double area;                   /* m^2 */
    double emissivity;             /* surface: area-weighted mean */
    double temperature;            /* K; surface: (area-weighted mean of T^4)^(1/4) */
    double radiosity;              /* J, W/m^2; surface: area-weighted mean */
    double irradiation;            /* G, W/m^2; surface: area-weighted mean */
    double heat_flux;              /* q, W/m^2, leaving; surface: Q / area */
    double heat;                   /* Q = A q, W, leaving; surface: sum over its elements */
    rad_thermal_condition condition;
} rad_thermal_values;

/* The figures of surface `surface` (numbered as the scene's) or element
 * `element` (as the solution's) into *out; false (nothing written) when
 * out of range or for a NULL argument. */
RAD_API bool rad_thermal_surface_values(const rad_thermal *thermal, size_t surface, rad_thermal_values *out);
RAD_API bool rad_thermal_element_values(const rad_thermal *thermal, size_t element, rad_thermal_values *out);

/* The energy balance.  With reciprocal factors the surfaces' net power is
 * what leaves for the environment: net_power = environment_power (both 0 in
 * a closed enclosure); `imbalance` is their difference, the form factors'
 * reciprocity error plus the solve's. */
typedef struct rad_thermal_balance {
    double net_power;              /* sum_i Q_i, W */
    double environment_power;      /* sum_i A_i (1 - sum_j F_ij)(J_i - sigma T_env^4), W */
    double imbalance;              /* net_power - environment_power, W */
    double power_scale;            /* sum_i |Q_i|, W */
    double relative_imbalance;     /* imbalance / power_scale; 0 when that is 0 */
} rad_thermal_balance;

/* The balance into *out, and the solver's residual as the return value.
 * NULL thermal: NaN (out, if not NULL, all NaN). */
RAD_API double rad_thermal_get_balance(const rad_thermal *thermal, rad_thermal_balance *out);

/* Gebhart factors between the scene's S surfaces (Gebhart 1961): G[s * S + t]
 * is the fraction of surface s's emission absorbed by t after any number
 * of diffuse reflections (rows sum to 1 in a closed enclosure; eps_s A_s
 * G_st = eps_t A_t G_ts), from the result's emissivities, by its solver, S / 3
 * solves.  `G` holds S * S doubles.  Fails with RAD_ERROR_OUT_OF_MEMORY,
 * RAD_ERROR_INTERRUPTED, or as the solver; NULL ctx, thermal or G:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_thermal_gebhart(rad_context *ctx, const rad_thermal *thermal, double *G);

/* Write the figures, by extension (docs/thermal.md): .csv, one row per
 * surface (or per element when `elements`), or .json (surfaces, and
 * elements when asked, with T_env and the balance).  Atomic like the other
 * writers.  Fails with RAD_ERROR_IO, RAD_ERROR_OUT_OF_MEMORY; an unknown
 * extension or a NULL ctx, thermal or path: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_thermal_write(rad_context *ctx, const rad_thermal *thermal, const char *path,
                                     bool elements);
/* The solution's stats (rad_solution_write_stats) with a "thermal" object:
 * solver, residual, T_env and the balance (docs/stats.md).  Fails as that
 * does; NULL ctx, thermal or path: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_thermal_write_stats(rad_context *ctx, const rad_thermal *thermal, const char *path);

/* Write the Gebhart factors: .csv (a header row of surface names, then one
 * row per emitting surface) or .json ({"surfaces": [...], "G": [[...]]}).
 * Fails as rad_thermal_gebhart and rad_thermal_write. */
RAD_API rad_result rad_thermal_write_gebhart(rad_context *ctx, const rad_thermal *thermal, const char *path);

/* ------------------------------------------------------------------------
 * Calculation grids and points: illuminance (docs/lighting.md,
 * "Calculation grids and points")
 *
 * A grid file (JSON) names work planes (rectangles, or a surface's
 * footprint at a height, spaced by EN 12464-1 or as given) and free points.
 * rad_illuminance_evaluate computes at every point, on a solved solution,
 * the illuminance in lux (docs/units.md: lux = 179 Y(H)): the direct light
 * of luminaires, daylight and emitting surfaces, plus the interreflection
 * gathered from the elements' radiosities with exact point-to-polygon
 * factors and visibility.
 * ---------------------------------------------------------------------- */

typedef struct rad_illuminance rad_illuminance;

/* One point's values. */
typedef struct rad_grid_point_value {
    double position[3];            /* m */
    double normal[3];              /* unit: light from behind counts zero */
    double u, v;                   /* m, in the grid's plane from its origin (the rectangle's
                                      origin, the footprint's lower corner); 0 for free points */
    double illuminance;            /* lux: direct + indirect */
    double direct;                 /* lux: luminaires, daylight, emitting surfaces */
    double indirect;               /* lux: light reflected by the scene's surfaces */
    double daylight_factor;        /* %: illuminance / the unobstructed sky's horizontal
                                      illuminance; NAN without daylight */
    const char *name;              /* a free point's name; NULL for grid points */
} rad_grid_point_value;

/* One grid's points and statistics (the free points form one, "points"). */
typedef struct rad_grid_result {
    const char *name;
    bool free_points;              /* the file's "points" */
    size_t point_count;
    const rad_grid_point_value *points; /* rows of v, u fastest (a footprint skips cells off it) */
    unsigned columns, rows;        /* cells along u and v; 0 for free points */
    double spacing_u, spacing_v;   /* m, the cells' sides; 0 for free points */
    double width, height;          /* m, the calculation area's sides after the border */
    double border;                 /* m */
    bool automatic;                /* spacing by EN 12464-1: p = 0.2 x 5^log10(d) m, <= 10 m */
    double average, minimum, maximum; /* lux: Eavg, Emin, Emax */
    double uniformity;             /* U0 = Emin / Eavg (0 when Eavg is 0) */
    double min_over_max;           /* Emin / Emax (0 when Emax is 0) */
} rad_grid_result;

/* What the evaluation cost. */
typedef struct rad_illuminance_stats {
    size_t points;
    double seconds;                /* the gathering, wall clock */
    double points_per_second;
    unsigned long long shadow_rays; /* cast by the gathering */
    unsigned long long exact_pairs; /* point-element pairs with exact visibility (no ray) */
    unsigned long long ray_pairs;   /* ... with visibility from shadow rays */
    double light_seconds;          /* thread-seconds spent in the direct light of luminaires and
                                      daylight at the points, summed over threads */
    double thread_seconds;         /* thread-seconds of all the points' work, summed over threads */
} rad_illuminance_stats;

/* Evaluate the grid file at `grid_path` (or `size` bytes at `data`, named
 * `name` in messages) on a solved solution; *out holds every point's
 * values.  Threads: the context's; the numbers are the same whatever
 * their count (rays keyed on rad_options.seed).  Progress phase
 * "illuminance"; cancellable.  The solution and its scene must outlive
 * *out.  Fails with RAD_ERROR_PARSE (a bad file: the message names the
 * file and the entry and key), RAD_ERROR_IO, RAD_ERROR_OUT_OF_MEMORY,
 * RAD_ERROR_INTERRUPTED; an unsolved solution or a NULL argument:
 * RAD_ERROR_INVALID_ARGUMENT.  *out is NULL on failure. */
RAD_API rad_result rad_illuminance_evaluate_file(rad_context *ctx, const rad_solution *solution,
                                                 const char *grid_path, rad_illuminance **out);
RAD_API rad_result rad_illuminance_evaluate_memory(rad_context *ctx, const rad_solution *solution,
                                                   const char *name, const void *data, size_t size,
                                                   rad_illuminance **out);
/* Read and check the grid file at `path` against `scene` without solving
 * (a command checks its input before the work); *points (may be NULL) the
 * points it places.  Fails as rad_illuminance_evaluate_file. */
RAD_API rad_result rad_illuminance_check_file(rad_context *ctx, const rad_scene *scene, const char *path,
                                              size_t *points);
/* NULL: no-op. */
RAD_API void rad_illuminance_destroy(rad_illuminance *illuminance);

/* The grids, in the file's order, the free points last; 0 for NULL. */
RAD_API size_t rad_illuminance_grid_count(const rad_illuminance *illuminance);
/* Grid `grid`, owned by *illuminance and valid for its life; NULL out of
 * range or for NULL. */
RAD_API const rad_grid_result *rad_illuminance_grid(const rad_illuminance *illuminance, size_t grid);
/* Whether the scene has daylight (the daylight factors are numbers). */
RAD_API bool rad_illuminance_has_daylight(const rad_illuminance *illuminance);
/* The cost into *out (zeros for NULL illuminance); NULL out: no-op. */
RAD_API void rad_illuminance_get_stats(const rad_illuminance *illuminance, rad_illuminance_stats *out);

/* Write the values by extension (docs/lighting.md): .csv, one row per point
 * (grid, index, name, x, y, z, normal, u, v, E, E_direct, E_indirect in
 * lux, and the daylight factor in % with daylight), or .json (per grid:
 * Eavg, Emin, Emax, U0, Emin/Emax, points, spacing, and every point).
 * Atomic like the other writers (a path an output set gave is written in
 * place by the set's commit).  Fails with RAD_ERROR_IO,
 * RAD_ERROR_OUT_OF_MEMORY; an unknown extension or a NULL argument:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_illuminance_write(rad_context *ctx, const rad_illuminance *illuminance, const char *path);

/* ------------------------------------------------------------------------
 * Method registries
 * ---------------------------------------------------------------------- */

typedef enum rad_method_kind {
    RAD_METHOD_FORM_FACTOR = 0,
    RAD_METHOD_SOLVER = 1,
    RAD_METHOD_VISIBILITY = 2
} rad_method_kind;

/* Enumerate methods: index 0, 1, ... of `kind`; returns false past the end
 * (or for an unknown kind) and writes nothing.  *name and *description are
 * static strings; a NULL name or description is not written.  Any thread. */
RAD_API bool rad_method_info(rad_method_kind kind, size_t index, const char **name,
                             const char **description);

/* What a method can do, as bits (rad_method_capabilities), so that a
 * program asks rather than knowing names.  For solvers, what the solver of
 * that name (rad_options.solver) does with a solution: */
typedef enum rad_capability {
    /* keeps the n x n form-factor matrix F: the view factors of a solution
     * (rad_solution_write_view_factors), thermal (rad_thermal_solve) */
    RAD_HAS_FORM_FACTORS = 1 << 0,
    /* meshes before it solves, to rad_options.mesh_size or target_elements
     * (hierarchical meshes as it solves) */
    RAD_HAS_UNIFORM_MESH = 1 << 1,
    /* adaptive subdivision of its mesh (rad_options.adaptive_levels) */
    RAD_CAN_ADAPTIVE = 1 << 2,
    /* carries light through ideal mirrors in its first pass; without it the
     * solve is the diffuse part alone, with a warning (the render's second
     * pass shows mirrors with any solver) */
    RAD_CAN_MIRRORS = 1 << 3,
    /* refuses scenes with mirrors: it reads F_ji through reciprocity, which
     * the mirror images' factors do not keep */
    RAD_REFUSES_MIRRORS = 1 << 4,
    /* takes luminaires and daylight (direct light that no element emits);
     * without it a lit scene is refused */
    RAD_CAN_LIGHTS = 1 << 5,
    /* takes rad_options.closure_correction (closed scenes); without it the
     * option is refused */
    RAD_CAN_CLOSURE_CORRECTION = 1 << 6,
    /* the iterate can be drawn after every step (rad_options.on_step;
     * `radiosity --progress-images`): its elements stay put while it
     * solves, or (hierarchical) the view shows the current leaves, the
     * mesh renewed after each refinement round */
    RAD_CAN_PROGRESS_IMAGES = 1 << 7
} rad_capability;

/* The rad_capability bits of method `name` of `kind`: for
 * RAD_METHOD_SOLVER, of the solver of that name; 0 for an unknown name, a
 * NULL name, or a kind that defines none (form factors, visibility).
 * Reads static tables: any thread, any time. */
RAD_API unsigned rad_method_capabilities(rad_method_kind kind, const char *name);

/* ------------------------------------------------------------------------
 * Option table: every field of rad_options, rad_render_options and
 * rad_office_options that a user sets, with its type, range, default and
 * one line of help.  The library checks the fields against these rows and
 * names the field when it refuses one ("rad_options.tolerance must be in
 * (0, 1), got 2"); a program builds its flags, help and manual from them.
 * ---------------------------------------------------------------------- */

typedef enum rad_option_set {
    RAD_OPTION_SET_SOLUTION = 0, /* rad_options */
    RAD_OPTION_SET_RENDER = 1,   /* rad_render_options */
    RAD_OPTION_SET_OFFICE = 2    /* rad_office_options */
} rad_option_set;

typedef enum rad_option_type {
    RAD_OPTION_INT = 0, /* int */
    RAD_OPTION_SIZE,    /* size_t */
    RAD_OPTION_UINT64,  /* uint64_t, any value */
    RAD_OPTION_DOUBLE,  /* double, finite */
    RAD_OPTION_BYTES,   /* double, finite: a byte count */
    RAD_OPTION_FLAG,    /* int: 0 or nonzero; `words` may name the two */
    RAD_OPTION_ENUM,    /* int: one of the values in `words` */
    RAD_OPTION_METHOD,  /* const char *: a name from the registry `methods` */
    RAD_OPTION_STRING   /* const char *, any text (no library field has it; for
                           programs that describe their own options alike) */
} rad_option_type;

/* A named value of a FLAG or ENUM field ("on" = 1). */
typedef struct rad_option_word {
    const char *word;
    int value;
} rad_option_word;

typedef struct rad_option_info {
    const char *name;              /* the field as in its struct: "tolerance" */
    rad_option_type type;
    size_t offset;                 /* offsetof(struct, field) */
    /* Accepted values of INT, SIZE, DOUBLE and BYTES fields, besides 0 (the
     * default): min to max, each bound excluded when its _open is nonzero;
     * max may be INFINITY. */
    double min, max;
    bool min_open, max_open;
    double default_value;          /* what 0 stands for; NAN where that is not a constant */
    const char *default_text;      /* the default in words: "1e-06", "auto" */
    const rad_option_word *words;  /* FLAG (optional) and ENUM; ends with {NULL, 0} */
    rad_method_kind methods;       /* METHOD: the registry of its names */
    const char *help;              /* one line, lower case, no final full stop */
} rad_option_info;

/* These functions only read static tables: any thread, any time. */

/* The index-th row of a set, in header order; NULL past the end or for an
 * unknown set.  Rows are static and never change. */
RAD_API const rad_option_info *rad_option_info_get(rad_option_set set, size_t index);
/* The row of field `name` in a set; NULL when there is none (or name is NULL). */
RAD_API const rad_option_info *rad_option_find(rad_option_set set, const char *name);
/* The struct a set describes: "rad_options", "rad_render_options", ...;
 * "" for an unknown set.  A static string. */
RAD_API const char *rad_option_set_name(rad_option_set set);

/* Whether `value` is within the row's range (INT, SIZE, DOUBLE, BYTES:
 * finite and between the bounds; ENUM: one of the words' values); always
 * true for the other types, false for a NULL row.  0, the default, is not
 * special here. */
RAD_API bool rad_option_in_range(const rad_option_info *option, double value);

/* Whether `text` is one of the row's words (FLAG, ENUM: *value, if not
 * NULL, is set to the word's value) or a name in its registry (METHOD);
 * false otherwise, for the other types and for a NULL row or text. */
RAD_API bool rad_option_lookup_word(const rad_option_info *option, const char *text, int *value);

/* The accepted values in words, as the library's messages give them:
 * "(0, 1)", "[1, 48]", "(0, inf)", "auto, on or off", "analytic, contour,
 * ... or montecarlo"; "" for a FLAG without words and a STRING.  Writes at
 * most `size` bytes, NUL included (nothing when text is NULL); returns the
 * length it wanted (0 for a NULL row). */
RAD_API size_t rad_option_range_text(const rad_option_info *option, char *text, size_t size);

/* ------------------------------------------------------------------------
 * Factors for thermal solvers: enclosure smoothing, sparse and View3D
 * outputs (docs/formats.md "View3D", docs/methods.md "Enclosure smoothing").
 * ---------------------------------------------------------------------- */

/* What a smoothing did: the worst row error (|sum_j F_ij - target|, the
 * target 1 in an enclosure) and reciprocity error (|A_i F_ij - A_j F_ji|
 * over the larger of the two) before and after, and the relative change of
 * the non-zero factors (max and RMS).  `clamped`: factors held at 0. */
typedef struct rad_smooth_report {
    double row_error_before, row_error_after;
    double reciprocity_before, reciprocity_after;
    double max_relative_change, rms_relative_change;
    size_t clamped;
} rad_smooth_report;

/* Enclosure smoothing of an n x n surface view-factor matrix F (row-major,
 * F[i * n + j] from i to j) with areas `area` (m^2), in place: the weighted
 * least-squares change (weights 1 / (A_i F_ij)) that makes A_i F_ij =
 * A_j F_ji and each row sum 1 (`enclosure` true) or its measured sum
 * (false, at most 1), every factor kept >= 0; zero factors (F_ii of a
 * planar surface) stay 0.  O(n^3) time, 2 n^2 doubles.  `report` (may be
 * NULL) is filled.  Fails with RAD_ERROR_INVALID_ARGUMENT when a factor is
 * not in [0, 1], an area not positive, or the sums cannot be met on the
 * non-zero pattern (F unchanged); RAD_ERROR_OUT_OF_MEMORY.  NULL ctx, area
 * or F (n > 0): RAD_ERROR_INVALID_ARGUMENT.  Thread-safe for distinct F. */
RAD_API rad_result rad_view_factors_smooth(rad_context *ctx, size_t n, const double *area, double *F,
                                           bool enclosure, rad_smooth_report *report);

typedef enum rad_smoothing {
    RAD_SMOOTH_NONE = 0,
    RAD_SMOOTH_ENCLOSURE = 1, /* rows sum to 1 */
    RAD_SMOOTH_OPEN = 2       /* rows keep their measured sums */
} rad_smoothing;

/* How rad_solution_write_view_factors_with adjusts the surface-level
 * factors it writes (0 everywhere: as rad_solution_write_view_factors). */
typedef struct rad_view_factor_options {
    bool elements;            /* element-to-element factors (no adjustment allowed) */
    rad_smoothing smooth;     /* enclosure smoothing of the written matrix */
    /* .mtx: factors below it (both F_ij and F_ji) dropped and the rest
     * smoothed on the kept pattern to the rows' sums before the drop (to 1
     * with RAD_SMOOTH_ENCLOSURE); 0 = keep all. */
    double sparse_threshold;
    rad_smooth_report *report;/* filled when a smoothing ran (may be NULL) */
    size_t *nonzeros;         /* the factors written as non-zero (may be NULL) */
    double *dropped;          /* sparse: the largest row's factor mass dropped (may be NULL) */
} rad_view_factor_options;

/* As rad_solution_write_view_factors, with `options` (NULL: all 0), and one
 * more format: .vf, View3D's view-factor file (text, or binary when the
 * scene is a .vs3 whose control line says out=1), surfaces only.  Surfaces
 * marked obstruction-only by a .vs3 are left out of every surface-level
 * output.  A .vs3 with encl=1 is smoothed as an enclosure in .vf, as
 * View3D normalises it, unless `smooth` says otherwise.  Fails as
 * rad_solution_write_view_factors, and with RAD_ERROR_INVALID_ARGUMENT for
 * a smoothing that cannot be met (nothing written) or options with
 * element-level factors. */
RAD_API rad_result rad_solution_write_view_factors_with(rad_context *ctx, const rad_solution *solution,
                                                        const char *path,
                                                        const rad_view_factor_options *options);

/* ------------------------------------------------------------------------
 * Display values and images from pixels (interactive viewers)
 * ---------------------------------------------------------------------- */

/* What rad_solution_render draws, for a program that draws the mesh itself
 * (the `radiosity view` window): per element (3 per element, W/m^2 RGB)
 * and per vertex (3 per vertex), either array may be NULL.  With `ambient`
 * true they are the renderer's: each element's radiosity plus, for a
 * partial shooting solution, its reflectance times the ambient term of the
 * unshot light (Cohen, Chen, Wallace, Greenberg 1988), never below 0, and
 * the vertex values interpolated from those as rad_solution_vertex_radiosity
 * interpolates; with `ambient` false the radiosity itself (0 added).  Reads
 * only: callable from rad_options.on_step on the solver's thread (the
 * iterate of that step), or at any time on a solution not being solved;
 * never at the same time as a solve on another thread.  Fails with
 * RAD_ERROR_OUT_OF_MEMORY; NULL ctx or solution, or both arrays NULL:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_solution_display_radiosity(rad_context *ctx, const rad_solution *solution,
                                                  bool ambient, double *element_rgb, double *vertex_rgb);

/* The hierarchical solver's links after its last solve (the interactions
 * it kept between nodes of its hierarchy: the status line's figure, as
 * element_count is), or, inside rad_options.on_step, the links of the
 * current refinement round; 0 for the other solvers, before the first
 * solve and for a NULL solution. */
RAD_API size_t rad_solution_link_count(const rad_solution *solution);

/* An image made from `width` x `height` RGB radiance triples (W/(m^2 sr),
 * row 0 at the top), copied: a program's own pictures (an OpenGL frame
 * read back) then go through rad_image_write_exposed like a rendered one,
 * the same exposure, sRGB curve and atomic writing.  Destroy it with
 * rad_image_destroy.  Fails with RAD_ERROR_OUT_OF_MEMORY; a size outside
 * [1, 16384] or a NULL ctx, rgb or out: RAD_ERROR_INVALID_ARGUMENT (*out
 * NULL). */
RAD_API rad_result rad_image_from_pixels(rad_context *ctx, int width, int height, const float *rgb,
                                         rad_image **out);

/* ------------------------------------------------------------------------
 * Photometric files: a luminaire's summary (IES LM-63, EULUMDAT)
 * ---------------------------------------------------------------------- */

/* What a luminaire's photometric file holds, summarised (docs/lighting.md,
 * "Photometric files"): a plain struct of values, nothing to free. */
typedef struct rad_photometry_info {
    char format[16];          /* "IES" or "EULUMDAT" */
    char version[24];         /* "LM-63-1986" .. "LM-63-2019", "EULUMDAT" */
    char label[128];          /* the luminaire's name in the file (cut to fit), may be "" */
    int type;                 /* the file's photometric type: 1 C, 2 B, 3 A */
    char symmetry[64];        /* "quadrant (C 0-90)", "C0-C180 plane (Isym 2)", ... */
    size_t horizontal_count;  /* the file's horizontal angles (EULUMDAT: C planes listed) */
    size_t vertical_count;    /* the file's vertical angles (EULUMDAT: gamma angles) */
    double horizontal_min, horizontal_max; /* degrees, as the file gives them */
    double vertical_min, vertical_max;     /* degrees, as the file gives them */
    double max_candela;       /* cd, multipliers applied */
    double max_c, max_gamma;  /* degrees: its direction in the luminaire's C-gamma frame */
    double flux;              /* lm: the interpolated distribution integrated over the sphere */
    double rated_lumens;      /* lm: the lamps' rated flux; 0 for absolute photometry */
    double lor;               /* 1: flux / rated_lumens; 0 without rated lumens */
    double stated_lor;        /* 1: the file's own light output ratio (EULUMDAT LORL); -1 none */
    double width, length, height; /* m: the luminous opening's extents along y, x, z */
    char shape[32];           /* "point", "rectangle", "ellipse", ... (docs/lighting.md) */
    char tilt[64];            /* "none", "include" or the tilt file's name */
    size_t tilt_count;        /* tilt angles given; 0 without tilt data */
    double input_watts;       /* W: the file's input power; 0 if not given */
} rad_photometry_info;

/* Read the photometric file at `path`, an IES LM-63 (1986 to 2019) or
 * EULUMDAT file told by its content, and summarise it in *out.  Fails with
 * RAD_ERROR_IO (unreadable; a TILT file outside the file's folder unless
 * the context allows reading outside it), RAD_ERROR_PARSE (malformed: the
 * message names the file and line, "lamp.ies:12: expected 37 vertical
 * angles, found 12 (the file ends)"), RAD_ERROR_OUT_OF_MEMORY; *out is
 * zeroed on failure.  A file whose integrated flux disagrees with its
 * stated light output ratio by more than 2 % is read, with a warning
 * (rad_context_options.on_warning).  NULL ctx, path or out:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_photometry_info_read(rad_context *ctx, const char *path, rad_photometry_info *out);

/* ------------------------------------------------------------------------
 * Daylight: a CIE sky, the sun and the ground, entering through openings
 * (docs/lighting.md "Daylight").
 *
 *     rad_scene_load_file(ctx, "room.obj", &scene);
 *     rad_scene_daylight_load_file(ctx, scene, "sky.json");
 *     rad_solution_create(ctx, scene, NULL, &sol);      lit by daylight only
 *
 * Luminance in cd/m^2 and illuminance in lux enter as L / 179 W/(m^2 sr)
 * and E / 179 W/m^2 on each channel (docs/units.md "Photometry").
 * ---------------------------------------------------------------------- */

/* Give `scene` the daylight of a daylight file (JSON: the sky type 1-15 of
 * CIE S 011 or "cie-overcast", its zenith luminance or diffuse horizontal
 * illuminance, the sun, up and north, the ground, the openings).  The
 * surfaces the file names as openings, and the polygons of a material named
 * "opening", leave the scene: they are holes the daylight enters through,
 * not elements, and block no ray; a surface left without polygons is
 * removed and the surfaces after it are renumbered.  The file is added to
 * the scene's inputs.  A second call replaces the sky, sun and ground;
 * the openings of the first stay openings (their surfaces are gone, so
 * the second file cannot name them).  Call it before any solution is made from
 * the scene, from one thread: it changes the scene.  Fails with
 * RAD_ERROR_IO (unreadable), RAD_ERROR_PARSE (a one-line message naming the
 * file and the key: "sky.json: sun.altitude: must be a number"),
 * RAD_ERROR_INVALID_SCENE (every polygon an opening),
 * RAD_ERROR_OUT_OF_MEMORY; on failure the scene is unchanged.  NULL ctx,
 * scene or path: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_scene_daylight_load_file(rad_context *ctx, rad_scene *scene, const char *path);
/* The same from `size` bytes at `data` (read during the call only);
 * `name` stands for the file in messages and is not added to the inputs.
 * NULL ctx, scene or name, or NULL data with a non-zero size:
 * RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_scene_daylight_load_memory(rad_context *ctx, rad_scene *scene, const char *name,
                                                  const void *data, size_t size);
/* The horizontal illuminance (lux) of the scene's sky unobstructed, the
 * sun excluded: the daylight factor's denominator (DF = E / this).  0 for
 * a NULL scene or one without daylight. */
RAD_API double rad_scene_daylight_sky_illuminance(const rad_scene *scene);
/* How many surfaces became openings.  0 for a NULL scene or one without
 * daylight. */
RAD_API size_t rad_scene_daylight_opening_count(const rad_scene *scene);

/* ------------------------------------------------------------------------
 * Luminaires (docs/lighting.md "Luminaires"): photometric files (IES LM-63,
 * EULUMDAT) placed in a scene by a layout file, or by glTF nodes whose
 * extras name one ({"luminaire": "a.ies", "llf": 0.8}, read when the glTF
 * loads: at the node's origin, nadir along its local -z, C = 0 along its
 * local x).  A luminaire is a light source, not geometry.  Its direct light
 * reaches every element exactly (a goniometric point source beyond five
 * times its luminous size, its opening split into sub-sources nearer, a
 * shadow ray each) and its first reflection enters the solve as emission;
 * candela count as cd / 179 W/sr on each channel (docs/units.md
 * "Photometry").  A scene lit only by luminaires needs no emitting surface.
 * Every solver takes them: hierarchical radiosity (the default) gives each
 * node of its hierarchy the direct irradiance where it makes it, and splits
 * leaves where that light varies; a solution file holds them.
 *
 *     rad_scene_load_file(ctx, "office.obj", &scene);
 *     rad_scene_load_luminaires(ctx, scene, "layout.json");
 *     rad_solution_create(ctx, scene, NULL, &sol);      (hierarchical)
 *     rad_solution_solve(ctx, sol);
 * ---------------------------------------------------------------------- */

/* Read a layout file (JSON) and add its luminaires to `scene`:
 *
 *     {"up": [0, 0, 1], "llf": 0.8,
 *      "luminaires": [{"file": "downlight.ies", "position": [2, 3, 2.7],
 *                      "aim": [0, 0, -1], "spin": 0, "name": "A",
 *                      "array": {"count": [4, 2], "spacing": [1.5, 2]}}]}
 *
 * (all keys: docs/lighting.md).  Each photometric file, named relative to
 * the layout's folder, is read once per scene.  All or nothing: on failure
 * the scene is unchanged.  Call it before making solutions of the scene
 * (they borrow it as it is); it may be called more than once (luminaire
 * names stay unique).  Fails with RAD_ERROR_PARSE and one line naming the
 * file, the entry and the key ("layout.json: luminaires[2].aim: must be 3
 * finite numbers, not all 0"), the photometric reader's errors (naming its
 * file and line), RAD_ERROR_IO, RAD_ERROR_OUT_OF_MEMORY; NULL ctx, scene or
 * path: RAD_ERROR_INVALID_ARGUMENT.  The file is read within the memory
 * limit. */
RAD_API rad_result rad_scene_load_luminaires(rad_context *ctx, rad_scene *scene, const char *path);
/* The same from `size` bytes at `data`; `name` stands for the file in
 * messages and its folder resolves the photometric files' names.  NULL
 * ctx, scene, name or data: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_scene_load_luminaires_memory(rad_context *ctx, rad_scene *scene, const char *name,
                                                    const void *data, size_t size);

/* Luminaires in the scene (layouts and glTF nodes).  NULL scene: 0. */
RAD_API size_t rad_scene_luminaire_count(const rad_scene *scene);
/* Luminaire `index`'s name (the layout's "name", with "[i,j]" in an array,
 * "luminaire N" without one, or the glTF node's), owned by the scene.
 * NULL scene or index out of range: NULL. */
RAD_API const char *rad_scene_luminaire_name(const rad_scene *scene, size_t index);
/* Luminaire `index`'s flux in lumens: its distribution's, times its light
 * loss factor, multiplier, lumens scaling and tilt factor.  NULL scene or
 * index out of range: 0. */
RAD_API double rad_scene_luminaire_flux(const rad_scene *scene, size_t index);
/* Luminaire `index`'s photometric centre (m) and frame: its x (C = 0), y
 * (C = 90) and z (the nadir being -z) as unit world vectors, 9 numbers;
 * either array may be NULL.  False (nothing written) for a NULL scene or
 * an index out of range. */
RAD_API bool rad_scene_luminaire_placement(const rad_scene *scene, size_t index, double position[3],
                                           double axes[9]);
/* The direct light of the scene's luminaires and daylight landing on the
 * solution's elements, lm (179 x Y of sum A H_direct): in a closed scene
 * the luminaires' whole flux.  0 for a scene without them or a NULL
 * solution. */
RAD_API double rad_solution_direct_lumens(const rad_solution *solution);

/* ------------------------------------------------------------------------
 * Pictures people read (issue #16; docs/lighting.md "Pictures"): false
 * colour images of luminance or illuminance with a legend.
 * ---------------------------------------------------------------------- */

typedef enum rad_false_colour_quantity {
    RAD_FALSE_COLOUR_LUMINANCE = 1,   /* cd/m^2 = 179 Y(L) of the rendered radiance */
    RAD_FALSE_COLOUR_ILLUMINANCE = 2  /* lux = 179 Y(H) on the surfaces seen */
} rad_false_colour_quantity;

typedef struct rad_false_colour_options {
    rad_false_colour_quantity quantity; /* 0 = luminance */
    int log_scale;                /* nonzero: logarithmic, else linear */
    /* The range, in the quantity's unit; both 0 = automatic (the 99th
     * percentile of the pixels' values rounded up to a nice number; linear
     * from 0, log over three decades).  Else min < max, and min > 0 on a
     * log scale.  Values outside take the end colours. */
    double range_min, range_max;
    int contours;                 /* nonzero: lines where the value crosses a legend tick */
} rad_false_colour_options;

/* Refuse bad options before any work: RAD_ERROR_INVALID_ARGUMENT with a
 * message naming the field ("false colour: range min 5 must be below max
 * 2").  NULL options: RAD_OK (the defaults). */
RAD_API rad_result rad_false_colour_check(rad_context *ctx, const rad_false_colour_options *options);

/* Render the solution with `render` (as rad_solution_render; the camera,
 * size and shading) and write its false colour picture as a PNG at `path`
 * (atomically, as rad_image_write): the image coloured by the quantity,
 * the background (what no ray hits) white, and a legend bar at the right
 * with tick values and the unit.  Illuminance is each element's
 * irradiance, (B - E) / rho plus the direct light (gathered from the
 * others where rho is 0), interpolated to the vertices as smooth shading
 * does.  The solution is modified as by rad_solution_render.  Fails as
 * rad_solution_render and rad_image_write, and with
 * RAD_ERROR_INVALID_ARGUMENT for bad options (rad_false_colour_check) or
 * a NULL ctx, solution or path. */
RAD_API rad_result rad_solution_write_false_colour(rad_context *ctx, rad_solution *solution,
                                                   const rad_render_options *render,
                                                   const rad_false_colour_options *options, const char *path);

/* Plans of the calculation grids of `illuminance` (docs/lighting.md "Grid
 * plots"): one PNG per grid that has points, at rad_illuminance_plot_path,
 * each cell (a free point: a dot) coloured by its lux on the false colour
 * map with the value printed, the grid's outline, the legend and a title
 * with Eavg, Emin, Emax and U0.  `options` gives the scale and the range
 * (its quantity and contours are not used; NULL: linear, automatic).  With
 * `set` the pictures are added to it (rad_output_set_add, RAD_OUTPUT_IMAGE)
 * and written into their temporaries, to appear at its commit; without,
 * each is written atomically as it is drawn (those drawn before a failure
 * stay).  Fails with RAD_ERROR_IO,
 * RAD_ERROR_OUT_OF_MEMORY; bad options (rad_false_colour_check), a path not
 * ending in .png, an output the set refuses, or a NULL ctx, illuminance or
 * path: RAD_ERROR_INVALID_ARGUMENT. */
RAD_API rad_result rad_illuminance_write_plots(rad_context *ctx, const rad_illuminance *illuminance,
                                               const rad_false_colour_options *options, rad_output_set *set,
                                               const char *path);
/* Where grid `grid`'s plan goes for `path`: STEM_NAME.png, STEM the path
 * without its extension, NAME the grid's name with every character but
 * letters, digits, '-', '.' and '_' made '_' (the free points: "points"),
 * and _K (the grid's index, from 0) after it when an earlier grid gives the
 * same NAME.  Written into `out` (`size` bytes, NUL-terminated, truncated
 * when short); returns the length it needs (as snprintf), 0 for a grid out
 * of range or a NULL illuminance or path.  Cannot fail otherwise. */
RAD_API size_t rad_illuminance_plot_path(const rad_illuminance *illuminance, const char *path, size_t grid,
                                         char *out, size_t size);

#ifdef __cplusplus
}
#endif

#endif /* RADIOSITY_H */
