/*
 * window.c -- the interactive window: SDL2 for the window, input and the
 * OpenGL 3.3 core context (functions through libepoxy), renderer.c to draw,
 * progressive.c to solve while the window shows the picture improve.
 *
 * Each frame: events -> camera / switches; the newest snapshot of the
 * solve, if any, uploaded (two glBufferSubData); draw; the status line
 * (the window's title, and the terminal on request) updated at most 4
 * times a second.  The frame loop never waits for the solver: it only
 * copies a published snapshot under the worker's mutex.  Keys and mouse
 * are listed in docs/viewer.md and printed by H.
 */
#include "viewer.h"
#include "viewer_internal.h"

#include <SDL2/SDL.h>
#include <epoxy/gl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *HELP =
    "radiosity view: keys and mouse\n"
    "  left drag        orbit about the target (fly mode: look around)\n"
    "  middle drag      pan;   right drag, wheel: move nearer / farther\n"
    "  arrows           orbit (fly mode: move forward, back, sideways)\n"
    "  Page Up / Down   fly mode: move up / down\n"
    "  Tab              orbit <-> fly camera\n"
    "  F                frame all\n"
    "  + / -            exposure up / down (half a stop);  0: automatic exposure\n"
    "  G                false colour (log luminance) on / off\n"
    "  W                wireframe of the elements on / off\n"
    "  L                flat / smooth shading\n"
    "  A                ambient term on / off (shooting)\n"
    "  Space            pause / resume the solver;  Backspace: stop it (keeps the iterate)\n"
    "  P                screenshot: view-NNNN.png (the exposure shown)\n"
    "  C                print the --camera of this view\n"
    "  S                save the solution: view.radsol;  E: export the lit mesh: view.glb\n"
    "  H                this help;   Q, Escape: quit\n";

typedef struct window_state {
    rad_context *ctx;
    const rv_args *args;
    const rad_scene *scene;
    rad_solution *solution;
    rv_step_slot *slot;
    SDL_Window *window;
    rv_renderer *renderer;
    rv_progress *progress;        /* NULL once the solve has ended */
    rv_camera camera;
    bool fly, false_colour, wireframe, ambient, paused, stopped, solved;
    bool auto_pending;            /* the automatic exposure waits for lit surfaces */
    rad_shading shading;
    double exposure;              /* 0 until the first automatic one */
    double false_min, false_max;  /* log10 luminance */
    uint64_t generation;
    rv_status status;
    double *element_rgb, *vertex_rgb;
    char message[256];            /* the last action's, shown in the status line */
} window_state;

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void say(window_state *w, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    vsnprintf(w->message, sizeof w->message, format, args);
    va_end(args);
    printf("%s\n", w->message);
    fflush(stdout);
}

static void drawable_size(const window_state *w, int *width, int *height)
{
    SDL_GL_GetDrawableSize(w->window, width, height);
    if (*width < 1)
        *width = 1;
    if (*height < 1)
        *height = 1;
}

/* The linear frame of the current view, `width` x `height`, into rgb. */
static bool linear_frame(window_state *w, int width, int height, rv_output output, float *rgb)
{
    rv_draw d = {.camera = &w->camera, .width = width, .height = height, .shading = w->shading,
                 .output = output, .exposure = w->exposure, .false_min = w->false_min,
                 .false_max = w->false_max, .wireframe = w->wireframe};
    bool ok = rv_offscreen_draw(NULL, w->renderer, &d, 4, rgb);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return ok;
}

/* The renderer's automatic exposure (95th percentile of luminance to 0.8)
 * of a small frame of this view, and the false colour range: two decades
 * below that key to one above. */
static void auto_exposure(window_state *w)
{
    enum { SIZE = 128 };
    float *rgb = malloc(SIZE * SIZE * 3 * sizeof *rgb);
    rad_image *image = NULL;
    if (rgb && linear_frame(w, SIZE, SIZE, RV_OUTPUT_RADIANCE, rgb) &&
        rad_image_from_pixels(w->ctx, SIZE, SIZE, rgb, &image) == RAD_OK) {
        w->exposure = rad_image_auto_exposure(image);
        double key = log10(0.8 / w->exposure);
        w->false_min = key - 2.0;
        w->false_max = key + 1.0;
    }
    rad_image_destroy(image);
    free(rgb);
}

/* sRGB to linear: a display colour stored so the PNG writer's curve gives
 * it back. */
static float srgb_decode(float v)
{
    return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

static void screenshot(window_state *w)
{
    char path[64];
    for (int k = 1; k < 10000; k++) {
        snprintf(path, sizeof path, "view-%04d.png", k);
        if (access(path, F_OK) != 0)
            break;
    }
    int width, height;
    drawable_size(w, &width, &height);
    float *rgb = malloc((size_t)width * (size_t)height * 3 * sizeof *rgb);
    rv_output output = w->false_colour ? RV_OUTPUT_FALSE_COLOUR : RV_OUTPUT_RADIANCE;
    if (!rgb || !linear_frame(w, width, height, output, rgb)) {
        say(w, "screenshot: %s", rgb ? "cannot draw the frame" : "out of memory");
        free(rgb);
        return;
    }
    if (w->false_colour)
        for (size_t i = 0; i < (size_t)width * (size_t)height * 3; i++)
            rgb[i] = srgb_decode(rgb[i]);
    if (rv_write_frame(w->ctx, path, width, height, rgb, w->false_colour ? 1.0 : w->exposure) == RAD_OK)
        say(w, "wrote %s", path);
    else
        say(w, "screenshot: %s", rad_context_error(w->ctx));
    free(rgb);
}

/* New buffers for the solution's mesh (after a solve that changed it). */
static bool rebuild(window_state *w)
{
    double *element_rgb, *vertex_rgb;
    if (!rv_display_values(w->ctx, w->solution, w->ambient, &element_rgb, &vertex_rgb))
        return false;
    rv_renderer *renderer = rv_renderer_create(w->solution, element_rgb, vertex_rgb);
    if (!renderer) {
        free(element_rgb);
        free(vertex_rgb);
        return false;
    }
    rv_renderer_destroy(w->renderer);
    free(w->element_rgb);
    free(w->vertex_rgb);
    w->renderer = renderer;
    w->element_rgb = element_rgb;
    w->vertex_rgb = vertex_rgb;
    return true;
}

/* The solve has ended: join the worker, show the final values. */
static void finish_solve(window_state *w)
{
    char message[512];
    rad_result r = rv_progress_finish(w->progress, message, sizeof message);
    w->progress = NULL;
    w->solved = r == RAD_OK;
    if (r == RAD_OK || r == RAD_ERROR_INTERRUPTED) {
        bool rebuilt = rebuild(w);
        if (rebuilt && w->auto_pending) {
            auto_exposure(w); /* no snapshot came (ended before its first step): on the result */
            w->auto_pending = false;
        }
        if (!rebuilt)
            say(w, "cannot rebuild the buffers: %s", rad_context_error(w->ctx));
        else
            say(w, "%s", r == RAD_ERROR_INTERRUPTED ? "interrupted: the iterate is kept (E exports it)"
                         : rad_solution_converged(w->solution) ? "solved"
                                                                : "stopped: the iterate is the solution (S saves it)");
    } else {
        say(w, "the solve failed: %s", message);
    }
}

static void update_title(window_state *w)
{
    char title[512], links[48] = "";
    const rad_solve_step *s = &w->status.step;
    /* The solution is read only when no solve is running; while one runs,
     * the links come with the snapshots. */
    size_t link_count = w->progress ? w->status.links : rad_solution_link_count(w->solution);
    if (link_count)
        snprintf(links, sizeof links, " | %zu links", link_count);
    const char *state = w->progress ? (w->status.paused ? "paused" : "solving") : w->solved ? "solved" : "stopped";
    snprintf(title, sizeof title,
             "radiosity view | %s | step %d | residual %.3g | unshot %.3g | %zu elements%s | "
             "exposure %.3g%s%s | %s",
             state, s->iteration, s->residual, s->unshot, rv_renderer_elements(w->renderer), links, w->exposure,
             w->false_colour ? " | false colour" : "", w->ambient ? "" : " | no ambient", w->message);
    SDL_SetWindowTitle(w->window, title);
}

static void key(window_state *w, SDL_Keycode k, bool *quit)
{
    double centre[3], radius;
    rv_renderer_bounds(w->renderer, centre, &radius);
    int width, height;
    drawable_size(w, &width, &height);
    char text[512];
    switch (k) {
    case SDLK_q:
    case SDLK_ESCAPE: *quit = true; break;
    case SDLK_h: fputs(HELP, stdout); break;
    case SDLK_TAB:
        w->fly = !w->fly;
        say(w, "%s camera", w->fly ? "fly" : "orbit");
        break;
    case SDLK_f: rv_camera_frame(&w->camera, centre, radius, (double)width / height); break;
    case SDLK_PLUS:
    case SDLK_EQUALS:
    case SDLK_KP_PLUS: w->exposure *= sqrt(2.0); break;
    case SDLK_MINUS:
    case SDLK_KP_MINUS: w->exposure /= sqrt(2.0); break;
    case SDLK_0: auto_exposure(w); break;
    case SDLK_g: w->false_colour = !w->false_colour; break;
    case SDLK_w: w->wireframe = !w->wireframe; break;
    case SDLK_l: w->shading = w->shading == RAD_SHADING_FLAT ? RAD_SHADING_SMOOTH : RAD_SHADING_FLAT; break;
    case SDLK_a:
        w->ambient = !w->ambient;
        say(w, "ambient term %s", w->ambient ? "on" : "off");
        if (w->progress)
            rv_progress_ambient(w->progress, w->ambient); /* from the next snapshot */
        else if (!rebuild(w))
            say(w, "cannot rebuild the buffers: %s", rad_context_error(w->ctx));
        break;
    case SDLK_SPACE:
        if (w->progress) {
            w->paused = !w->paused;
            rv_progress_pause(w->progress, w->paused);
        }
        break;
    case SDLK_BACKSPACE:
        if (w->progress)
            rv_progress_stop(w->progress);
        break;
    case SDLK_p: screenshot(w); break;
    case SDLK_c:
        rv_camera_text(&w->camera, text, sizeof text);
        say(w, "--camera %s", text);
        break;
    case SDLK_s:
        if (w->progress)
            say(w, "%s", "save: the solver is running (Backspace stops it)");
        else if (rad_solution_save(w->ctx, w->solution, "view.radsol") == RAD_OK)
            say(w, "wrote %s", "view.radsol");
        else
            say(w, "save: %s", rad_context_error(w->ctx));
        break;
    case SDLK_e:
        if (w->progress)
            say(w, "%s", "export: the solver is running (Backspace stops it)");
        else if (rad_solution_write_mesh(w->ctx, w->solution, "view.glb", w->exposure) == RAD_OK)
            say(w, "wrote %s", "view.glb");
        else
            say(w, "export: %s", rad_context_error(w->ctx));
        break;
    default: break;
    }
}

/* Held keys (fly: move; orbit: turn), scaled by the frame time. */
static void held_keys(window_state *w, double seconds)
{
    const Uint8 *down = SDL_GetKeyboardState(NULL);
    double centre[3], radius;
    rv_renderer_bounds(w->renderer, centre, &radius);
    double step = 0.5 * radius * seconds, turn = 1.5 * seconds;
    int forward = down[SDL_SCANCODE_UP] - down[SDL_SCANCODE_DOWN];
    int right = down[SDL_SCANCODE_RIGHT] - down[SDL_SCANCODE_LEFT];
    int up = down[SDL_SCANCODE_PAGEUP] - down[SDL_SCANCODE_PAGEDOWN];
    if (w->fly)
        rv_camera_move(&w->camera, forward * step, right * step, up * step);
    else if (forward || right)
        rv_camera_orbit(&w->camera, -right * turn, forward * turn);
}

static void mouse(window_state *w, const SDL_MouseMotionEvent *m)
{
    double centre[3], radius;
    rv_renderer_bounds(w->renderer, centre, &radius);
    double turn = 0.005; /* radians a pixel */
    if (m->state & SDL_BUTTON_LMASK) {
        if (w->fly)
            rv_camera_look(&w->camera, -m->xrel * turn, -m->yrel * turn);
        else
            rv_camera_orbit(&w->camera, -m->xrel * turn, -m->yrel * turn);
    } else if (m->state & SDL_BUTTON_MMASK) {
        double pan = 0.002 * radius;
        rv_camera_move(&w->camera, 0.0, -m->xrel * pan, m->yrel * pan);
    } else if (m->state & SDL_BUTTON_RMASK) {
        rv_camera_dolly(&w->camera, exp(0.005 * m->yrel));
    }
}

/* The next key of a --keys script ("wait,p,c,q": comma-separated keys,
 * named as SDL names them, "wait" holding until the solve ends); returns
 * the rest of the script, NULL once done. */
static const char *scripted_key(window_state *w, const char *script, bool *quit)
{
    if (!script || !*script)
        return NULL;
    const char *end = strchr(script, ',');
    size_t length = end ? (size_t)(end - script) : strlen(script);
    char name[32];
    snprintf(name, sizeof name, "%.*s", (int)(length < sizeof name ? length : sizeof name - 1), script);
    if (strcmp(name, "wait") == 0 && w->progress)
        return script; /* not yet */
    if (strcmp(name, "wait") != 0) {
        SDL_Keycode k = SDL_GetKeyFromName(name);
        if (k == SDLK_UNKNOWN)
            say(w, "--keys: unknown key '%s'", name);
        else
            key(w, k, quit);
    }
    return end ? end + 1 : NULL;
}

int rv_window_run(rad_context *ctx, const rv_args *a, const rad_scene *scene, rad_solution *solution,
                  rv_step_slot *slot, bool saved)
{
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
        fprintf(stderr, "radiosity: view: cannot open a window: %s (--offscreen draws without one)\n",
                SDL_GetError());
        return RV_EXIT_NO_DEVICE;
    }
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 3);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 3);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_PROFILE_MASK, SDL_GL_CONTEXT_PROFILE_CORE);
    SDL_GL_SetAttribute(SDL_GL_DOUBLEBUFFER, 1);
    SDL_GL_SetAttribute(SDL_GL_DEPTH_SIZE, 24);
    SDL_GL_SetAttribute(SDL_GL_MULTISAMPLEBUFFERS, 1);
    SDL_GL_SetAttribute(SDL_GL_MULTISAMPLESAMPLES, 4);
    int width = a->width ? a->width : 1024, height = a->height ? a->height : 768;
    window_state w = {.ctx = ctx, .args = a, .scene = scene, .solution = solution, .slot = slot,
                      .ambient = !a->no_ambient, .shading = a->shading, .solved = saved,
                      .exposure = a->exposure};
    w.window = SDL_CreateWindow("radiosity view", SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, width, height,
                                SDL_WINDOW_OPENGL | SDL_WINDOW_RESIZABLE | SDL_WINDOW_ALLOW_HIGHDPI);
    if (!w.window) {
        /* Without multisampling, if that was what failed. */
        SDL_GL_SetAttribute(SDL_GL_MULTISAMPLEBUFFERS, 0);
        SDL_GL_SetAttribute(SDL_GL_MULTISAMPLESAMPLES, 0);
        w.window = SDL_CreateWindow("radiosity view", SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, width,
                                    height, SDL_WINDOW_OPENGL | SDL_WINDOW_RESIZABLE | SDL_WINDOW_ALLOW_HIGHDPI);
    }
    SDL_GLContext gl = w.window ? SDL_GL_CreateContext(w.window) : NULL;
    if (!gl) {
        fprintf(stderr, "radiosity: view: cannot open an OpenGL 3.3 core window: %s\n", SDL_GetError());
        if (w.window)
            SDL_DestroyWindow(w.window);
        SDL_Quit();
        return RV_EXIT_NO_DEVICE;
    }
    SDL_GL_SetSwapInterval(1);
    int status = 1;
    if (!rebuild(&w)) {
        fprintf(stderr, "radiosity: view: %s\n", rad_context_error(ctx));
        goto done;
    }
    drawable_size(&w, &width, &height);
    w.camera = rv_start_camera(scene, a, w.renderer, (double)width / height);
    if (!saved) {
        w.progress = rv_progress_start(solution, slot, rad_context_threads(ctx), w.ambient, 1.0 / 30.0, false);
        if (!w.progress) {
            fprintf(stderr, "radiosity: view: cannot start the solver's thread\n");
            goto done;
        }
    }
    if (!a->quiet)
        printf("radiosity view: %zu elements, OpenGL %s (%s); H prints the keys\n",
               rv_renderer_elements(w.renderer), (const char *)glGetString(GL_VERSION),
               (const char *)glGetString(GL_RENDERER));
    bool quit = false, vsync = SDL_GL_GetSwapInterval() == 1;
    w.auto_pending = a->exposure == 0.0 && !saved;
    const char *script = a->keys; /* --keys: pressed one a frame */
    GLsync in_flight = NULL;
    Uint64 last = SDL_GetPerformanceCounter(), last_title = 0;
    while (!quit) {
        /* Ctrl-C / SIGTERM reach the program's context (cli/common.c). */
        if (rad_context_cancelled(ctx))
            break;
        script = scripted_key(&w, script, &quit);
        SDL_Event e;
        while (SDL_PollEvent(&e)) {
            if (e.type == SDL_QUIT)
                quit = true;
            else if (e.type == SDL_KEYDOWN)
                key(&w, e.key.keysym.sym, &quit);
            else if (e.type == SDL_MOUSEMOTION)
                mouse(&w, &e.motion);
            else if (e.type == SDL_MOUSEWHEEL)
                rv_camera_dolly(&w.camera, exp(-0.1 * e.wheel.y));
        }
        Uint64 t = SDL_GetPerformanceCounter();
        double seconds = (double)(t - last) / (double)SDL_GetPerformanceFrequency();
        last = t;
        held_keys(&w, fmin(seconds, 0.1));
        if (w.progress) {
            bool fresh = false;
            /* A new mesh (the hierarchical solver refined its leaves): new
             * buffers; else only the colours. */
            rv_mesh mesh = {0};
            if (rv_progress_take_mesh(w.progress, &w.generation, &mesh, &w.element_rgb, &w.vertex_rgb)) {
                rv_renderer *renderer = rv_renderer_create_mesh(&mesh, w.element_rgb, w.vertex_rgb);
                if (renderer) {
                    rv_renderer_destroy(w.renderer);
                    w.renderer = renderer;
                    fresh = true;
                } else {
                    say(&w, "cannot build the buffers of the refined mesh; the old one stays");
                }
                rv_mesh_free(&mesh);
            }
            if (rv_progress_take(w.progress, &w.generation, w.element_rgb, w.vertex_rgb, &w.status))
                fresh = true;
            if (fresh) {
                rv_renderer_update(w.renderer, w.element_rgb, w.vertex_rgb);
                /* The automatic exposure, provisional on B = E (only the
                 * lights lit), is fixed on the first shot's picture, as
                 * render --progress-images fixes it: from then on the
                 * picture visibly brightens as light is shot. */
                if (w.auto_pending) {
                    auto_exposure(&w);
                    w.auto_pending = false;
                }
            }
            if (w.status.done)
                finish_solve(&w);
        }
        if (w.exposure == 0.0)
            auto_exposure(&w);
        drawable_size(&w, &width, &height);
        rv_draw d = {.camera = &w.camera, .width = width, .height = height, .shading = w.shading,
                     .output = w.false_colour ? RV_OUTPUT_FALSE_COLOUR : RV_OUTPUT_DISPLAY,
                     .exposure = w.exposure, .false_min = w.false_min, .false_max = w.false_max,
                     .wireframe = w.wireframe};
        /* At most one frame in flight: without a vertical sync that blocks
         * (SDL's off-screen driver, some X servers) a software renderer
         * queues frames faster than it draws them, and memory grows. */
        if (in_flight) {
            glClientWaitSync(in_flight, GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000u);
            glDeleteSync(in_flight);
        }
        rv_renderer_draw(w.renderer, &d);
        SDL_GL_SwapWindow(w.window);
        in_flight = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
        if (!vsync)
            SDL_Delay(10); /* no vertical sync: about 100 frames a second at most */
        if ((double)(t - last_title) / (double)SDL_GetPerformanceFrequency() > 0.25) {
            update_title(&w);
            last_title = t;
        }
    }
    if (in_flight)
        glDeleteSync(in_flight);
    status = 0;
done:
    if (w.progress) {
        rv_progress_stop(w.progress);
        rv_progress_finish(w.progress, NULL, 0);
    }
    rv_renderer_destroy(w.renderer);
    free(w.element_rgb);
    free(w.vertex_rgb);
    SDL_GL_DeleteContext(gl);
    SDL_DestroyWindow(w.window);
    SDL_Quit();
    return status;
}
