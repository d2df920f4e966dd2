/*
 * viewer.h -- `radiosity view`: the interactive window (SDL2 + OpenGL 3.3
 * core) and its off-screen twin (EGL surfaceless + a framebuffer object),
 * which share one renderer, so a test of the off-screen frame tests the
 * window's drawing code.  docs/viewer.md has the keys and the figures.
 *
 *   cli/cmd_view.c --view--> rv_main (view.c)
 *       window.c      SDL2 window, keys and mouse, status line
 *       offscreen.c   EGL surfaceless context + FBO, read back as radiance
 *       renderer.c    the GL renderer: mesh buffers, colour updates, draw
 *       orbit.c       orbit / fly camera, view and projection matrices
 *       progressive.c the solver on a worker thread, snapshots under a mutex
 *
 * Only this folder includes GL, EGL or SDL headers: the library and the
 * rest of the program build without them (CMake option RADIOSITY_VIEWER).
 */
#ifndef RAD_VIEWER_H
#define RAD_VIEWER_H

#include "radiosity.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* ---- what the command line asks of the viewer (cli/cmd_view.c fills it) ---- */

typedef struct rv_args {
    const char *input;            /* scene or solution file; NULL = the Cornell box */
    const char *luminaires;       /* a layout file placed in the scene (docs/lighting.md), or NULL */
    rad_options solve;            /* as for `radiosity render` */
    int width, height;            /* window or frame; 0 = 1024 x 768 (window), 512 x 512 (frame) */
    int samples;                  /* off-screen multisampling per pixel; 0 = 4 */
    const rad_camera *camera;     /* NULL = the scene's, else framed automatically */
    rad_shading shading;
    double exposure;              /* 0 = automatic (the renderer's rule, docs/units.md) */
    const char *output;           /* off-screen: the frame (.png exposed, .hdr, .pfm) */
    bool offscreen;               /* draw one frame without a window, to `output` */
    bool no_ambient;              /* progressive: show B without the ambient term */
    const char *keys;             /* window: keys pressed one a frame ("wait,p,c,q"), for scripts */
    bool quiet;
} rv_args;

/* Run the viewer on an existing context.  Returns the exit status (0 ok,
 * 1 failure, with a one-line message on stderr; 77 = no display / EGL
 * device could be opened, the CTest skip code). */
int rv_main(rad_context *ctx, const rv_args *args);

#define RV_EXIT_NO_DEVICE 77

/* ---- cameras: orbit and fly (orbit.c; no GL, testable) ---- */

typedef struct rv_camera {
    double position[3], target[3], up[3]; /* m; target: what orbiting turns about */
    double vfov_degrees;
} rv_camera;

rv_camera rv_camera_from(const rad_camera *camera);
rad_camera rv_camera_to(const rv_camera *camera);
/* Turn about the target by yaw (about up) and pitch (about the right axis), radians. */
void rv_camera_orbit(rv_camera *c, double yaw, double pitch);
/* Turn the view direction about the eye (fly mode), radians. */
void rv_camera_look(rv_camera *c, double yaw, double pitch);
/* Move eye and target by forward, right and up distances, m. */
void rv_camera_move(rv_camera *c, double forward, double right, double up);
/* Move the eye toward the target by a factor of the distance (0.9: nearer). */
void rv_camera_dolly(rv_camera *c, double factor);
/* Look at the centre of the bounding sphere (centre, radius) from the
 * current direction, from where the sphere fills the view. */
void rv_camera_frame(rv_camera *c, const double centre[3], double radius, double aspect);
/* The `--camera` text that reproduces the view (17 digits). */
void rv_camera_text(const rv_camera *c, char *text, size_t size);
/* Column-major view-projection matrix, relative to `origin` (the scene's
 * centre, so float positions keep their precision); near and far planes
 * from the bounding sphere (origin, radius). */
void rv_camera_matrix(const rv_camera *c, const double origin[3], double radius, double aspect, float m[16]);

/* ---- the GL renderer (renderer.c): needs a current GL 3.3 core context ---- */

typedef struct rv_renderer rv_renderer;

typedef enum rv_output {
    RV_OUTPUT_RADIANCE = 0,       /* linear L = B / pi, W/(m^2 sr): for read-back */
    RV_OUTPUT_DISPLAY = 1,        /* exposure, sRGB curve (the PNG writer's rule) */
    RV_OUTPUT_FALSE_COLOUR = 2    /* log10 luminance on a blue-green-red ramp */
} rv_output;

typedef struct rv_draw {
    const rv_camera *camera;
    int width, height;
    rad_shading shading;
    rv_output output;
    double exposure;              /* RV_OUTPUT_DISPLAY */
    double false_min, false_max;  /* RV_OUTPUT_FALSE_COLOUR: log10 luminance range, cd/m^2 */
    bool wireframe;               /* element edges over the surfaces */
} rv_draw;

/* A copy of a solution's mesh as the renderer draws it (no GL): what the
 * progressive worker hands the window when the mesh changes during a
 * solve (the hierarchical solver's leaves). */
typedef struct rv_mesh {
    size_t vertices, elements;
    double *position;             /* 3 per vertex, m */
    uint32_t *corner;             /* 4 per element: its vertices, counter-clockwise */
    uint8_t *corners;             /* per element: 3 or 4 */
} rv_mesh;

/* Copy the solution's mesh (from rad_options.on_step on the solver's
 * thread, or when no solve runs); false when out of memory (*out then
 * empty).  rv_mesh_free frees the arrays and empties it. */
bool rv_mesh_from_solution(const rad_solution *solution, rv_mesh *out);
void rv_mesh_free(rv_mesh *mesh);

/* Build the buffers for the solution's mesh (positions, vertex and element
 * colours, triangles, edges), colours from `element_rgb` / `vertex_rgb`
 * (W/m^2, 3 per element / vertex).  Reads the solution's mesh only: not
 * while it is being solved.  NULL when out of memory or when the driver
 * refuses the shaders (its log printed on stderr). */
rv_renderer *rv_renderer_create(const rad_solution *solution, const double *element_rgb, const double *vertex_rgb);
/* The same from a copied mesh. */
rv_renderer *rv_renderer_create_mesh(const rv_mesh *mesh, const double *element_rgb, const double *vertex_rgb);
void rv_renderer_destroy(rv_renderer *r);
/* New colours for the same mesh (glBufferSubData of both colour buffers). */
void rv_renderer_update(rv_renderer *r, const double *element_rgb, const double *vertex_rgb);
/* Draw into the bound framebuffer (cleared first). */
void rv_renderer_draw(const rv_renderer *r, const rv_draw *d);
/* Bounding sphere of the mesh, m. */
void rv_renderer_bounds(const rv_renderer *r, double centre[3], double *radius);
size_t rv_renderer_elements(const rv_renderer *r);
size_t rv_renderer_vertices(const rv_renderer *r);

/* ---- off-screen (offscreen.c) ---- */

typedef struct rv_offscreen rv_offscreen;

/* An EGL surfaceless OpenGL 3.3 core context made current on this thread.
 * RAD_ERROR_UNSUPPORTED-like failure: returns NULL with a message in
 * `why` when no EGL device can be opened (then tests skip). */
rv_offscreen *rv_offscreen_create(char *why, size_t why_size);
void rv_offscreen_destroy(rv_offscreen *o);
/* Draw `d` into a float framebuffer with `samples` samples a pixel
 * in the current GL context (o's, or a window's: o may be NULL)
 * (resolved by averaging radiance) and read it back: `rgb` holds
 * width x height RGB, row 0 at the top.  false when the framebuffer
 * cannot be made (size beyond the implementation's). */
bool rv_offscreen_draw(rv_offscreen *o, const rv_renderer *r, const rv_draw *d, int samples, float *rgb);
/* GL_RENDERER of the context ("llvmpipe (LLVM 15.0.6, 256 bits)"). */
const char *rv_offscreen_renderer_name(const rv_offscreen *o);

/* ---- progressive display (progressive.c) ---- */

typedef struct rv_progress rv_progress;

/* A snapshot of the solve, copied out under the mutex. */
typedef struct rv_status {
    uint64_t generation;          /* snapshots published so far */
    rad_solve_step step;          /* the last step seen */
    bool paused, done;
    rad_result result;            /* the solve's, once done */
    size_t elements;              /* the elements of the latest snapshot's mesh */
    size_t links;                 /* hierarchical: the links at the last step, else 0 */
    uint64_t mesh_generation;     /* meshes published: 0 while the solve's first mesh */
} rv_status;

/* The step hook a solution is made with (rad_options.on_step keeps its
 * user pointer, not a copy): the solution calls rv_step_forward with the
 * slot, which calls slot->fn when set.  The slot must outlive the
 * solution; rv_progress_start / _finish set and clear it. */
typedef struct rv_step_slot {
    int (*fn)(void *user, rad_solution *solution, const rad_solve_step *step);
    void *user;
} rv_step_slot;

int rv_step_forward(void *slot, rad_solution *solution, const rad_solve_step *step);

/* Start solving `solution` (made with on_step = rv_step_forward and
 * on_step_user = slot) on a worker thread with its own context
 * (`threads` worker threads).  A snapshot of the display values
 * (rad_solution_display_radiosity, `ambient` as given) is published after
 * a step when `interval` seconds have passed since the last, or 9 times
 * the last snapshot's cost where that is longer (0: every step), and when
 * the solve ends.  `paused`: held at its first step
 * until rv_progress_pause(p, false).  The caller must not touch the solution
 * until rv_progress_finish.  NULL on failure (out of memory, no thread). */
rv_progress *rv_progress_start(rad_solution *solution, rv_step_slot *slot, int threads, bool ambient,
                               double interval, bool paused);
/* Copy the latest snapshot out when it is newer than *generation (then
 * *generation is updated and true returned); never waits for a step.  The
 * arrays hold 3 per element / vertex of the mesh last taken with
 * rv_progress_take_mesh (at first the mesh the solve started on); either
 * may be NULL.  While the snapshot is of a newer mesh nothing is copied
 * (false): take the mesh first.  *status, when not NULL, is filled in any
 * case. */
bool rv_progress_take(rv_progress *p, uint64_t *generation, double *element_rgb, double *vertex_rgb,
                      rv_status *status);
/* When the snapshot's mesh is newer than the last taken (the mesh changed
 * during the solve: the hierarchical solver's leaves after a refinement
 * round, adaptive subdivision), copy it and its values out: *mesh replaced
 * (the old arrays freed), *element_rgb and *vertex_rgb reallocated to its
 * counts and filled, *generation updated; true then (the caller rebuilds
 * its buffers).  False with nothing changed when the mesh is the one taken,
 * or when out of memory (tried again at the next call).  One caller (the
 * frame loop) takes meshes. */
bool rv_progress_take_mesh(rv_progress *p, uint64_t *generation, rv_mesh *mesh, double **element_rgb,
                           double **vertex_rgb);
void rv_progress_pause(rv_progress *p, bool pause);
/* The ambient term on or off from the next snapshot on. */
void rv_progress_ambient(rv_progress *p, bool ambient);
/* Ask the solve to stop after its current step; it keeps the iterate. */
void rv_progress_stop(rv_progress *p);
/* Wait for the worker to end; returns the solve's result and hands the
 * solution back to the caller.  Frees p. */
rad_result rv_progress_finish(rv_progress *p, char *message, size_t message_size);

#endif /* RAD_VIEWER_H */
