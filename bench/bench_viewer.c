/*
 * bench_viewer.c -- the viewer's frame time and the cost of a colour
 * update at 10^4, 10^5 and 10^6 elements (the Cornell box meshed finer),
 * drawn off-screen (EGL surfaceless: Mesa's llvmpipe here, a GPU's driver
 * where there is one) into a 1024 x 768 framebuffer with 4 samples a
 * pixel, as the window draws.
 *
 *   build     rv_renderer_create: positions, triangles, edges uploaded
 *   frame     one draw + glFinish, smooth / flat / with the wireframe
 *             (median of 7 after one warm-up)
 *   display   rad_solution_display_radiosity: element and vertex values
 *             (CPU, the library; what the worker does per snapshot)
 *   upload    rv_renderer_update + glFinish: float conversion and two
 *             glBufferSubData (what the frame loop does per snapshot)
 *
 * Times are CPU time of the process (all its threads), in ms.
 * Usage: bench_viewer [MAX_ELEMENTS]   (default 1000000)
 * One thread (llvmpipe rasterising on the calling thread):
 *   LP_NUM_THREADS=0 OMP_NUM_THREADS=1 build/bench/bench_viewer
 */
#include "viewer.h"

#include <epoxy/gl.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

/* CPU seconds of the whole process (llvmpipe's threads included): the
 * machine is shared, so wall time would count the others' work too. */
static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#define RUNS 7

static double median_frame(const rv_renderer *r, rv_draw *d)
{
    double t[RUNS];
    rv_renderer_draw(r, d);
    glFinish();
    for (int k = 0; k < RUNS; k++) {
        double t0 = now();
        rv_renderer_draw(r, d);
        glFinish();
        t[k] = now() - t0;
    }
    qsort(t, RUNS, sizeof *t, by_value);
    return t[RUNS / 2];
}

int main(int argc, char **argv)
{
    size_t max_elements = argc > 1 ? (size_t)strtoull(argv[1], NULL, 10) : 1000000;
    char why[256];
    rv_offscreen *o = rv_offscreen_create(why, sizeof why);
    if (!o) {
        fprintf(stderr, "bench_viewer: %s\n", why);
        return 1;
    }
    const int width = 1024, height = 768, samples = 4;
    GLuint fbo, rb[2];
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(2, rb);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[0]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[1]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb[1]);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        fprintf(stderr, "bench_viewer: no %d x %d framebuffer with %d samples\n", width, height, samples);
        return 1;
    }
    printf("# OpenGL: %s; %d x %d, %d samples a pixel; CPU ms\n", rv_offscreen_renderer_name(o), width,
           height, samples);
    printf("%9s %9s %9s %9s %9s %9s %9s %9s\n", "elements", "vertices", "build", "smooth", "flat", "wire",
           "display", "upload");
    rad_context_options co = {0};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    for (size_t target = 10000; target <= max_elements; target *= 10) {
        rad_scene *scene = NULL;
        rad_solution *solution = NULL;
        /* Shooting builds no matrix: only the mesh and the rays' structure. */
        rad_options options = {.solver = "shooting", .target_elements = target};
        if (rad_scene_create_cornell_box(ctx, &scene) != RAD_OK ||
            rad_solution_create(ctx, scene, &options, &solution) != RAD_OK) {
            fprintf(stderr, "bench_viewer: %s\n", rad_context_error(ctx));
            return 1;
        }
        size_t ne = rad_solution_element_count(solution), nv = rad_solution_vertex_count(solution);
        double *element_rgb = malloc(3 * ne * sizeof *element_rgb), *vertex_rgb = malloc(3 * nv * sizeof *vertex_rgb);
        double t0 = now();
        if (!element_rgb || !vertex_rgb ||
            rad_solution_display_radiosity(ctx, solution, true, element_rgb, vertex_rgb) != RAD_OK)
            return 1;
        double display = now() - t0;
        t0 = now();
        rv_renderer *r = rv_renderer_create(solution, element_rgb, vertex_rgb);
        glFinish();
        double build = now() - t0;
        if (!r)
            return 1;
        rad_camera camera;
        rad_scene_camera(scene, &camera);
        rv_camera view = rv_camera_from(&camera);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        rv_draw d = {.camera = &view, .width = width, .height = height, .output = RV_OUTPUT_DISPLAY, .exposure = 1.0};
        double smooth = median_frame(r, &d);
        d.shading = RAD_SHADING_FLAT;
        double flat = median_frame(r, &d);
        d.shading = RAD_SHADING_SMOOTH;
        d.wireframe = true;
        double wire = median_frame(r, &d);
        double u[RUNS];
        for (int k = 0; k < RUNS; k++) {
            t0 = now();
            rv_renderer_update(r, element_rgb, vertex_rgb);
            glFinish();
            u[k] = now() - t0;
        }
        qsort(u, RUNS, sizeof *u, by_value);
        printf("%9zu %9zu %9.1f %9.1f %9.1f %9.1f %9.1f %9.2f\n", ne, nv, 1e3 * build, 1e3 * smooth, 1e3 * flat,
               1e3 * wire, 1e3 * display, 1e3 * u[RUNS / 2]);
        fflush(stdout);
        rv_renderer_destroy(r);
        free(element_rgb);
        free(vertex_rgb);
        rad_solution_destroy(solution);
        rad_scene_destroy(scene);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteRenderbuffers(2, rb);
    glDeleteFramebuffers(1, &fbo);
    rad_context_destroy(ctx);
    rv_offscreen_destroy(o);
    return 0;
}
