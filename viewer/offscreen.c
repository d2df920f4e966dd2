/*
 * offscreen.c -- frames without a window: an OpenGL 3.3 core context on
 * EGL's surfaceless platform (EGL_MESA_platform_surfaceless: no X, no
 * Wayland, no GPU needed; Mesa's llvmpipe draws on the CPU), a float
 * framebuffer object to draw into, glReadPixels to read the radiance back.
 *
 *   multisampled FBO (RGBA32F + depth) --glBlitFramebuffer--> resolved FBO
 *   (samples averaged in linear radiance, as the ray caster averages its
 *   rays) --glReadPixels--> rgb, rows flipped to row 0 at the top
 */
#include "viewer.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct rv_offscreen {
    EGLDisplay display;
    EGLContext context;
    char renderer_name[256];
};

rv_offscreen *rv_offscreen_create(char *why, size_t why_size)
{
    snprintf(why, why_size, "no EGL device");
    if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless") ||
        !epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_platform_base")) {
        snprintf(why, why_size, "EGL has no surfaceless platform (EGL_MESA_platform_surfaceless)");
        return NULL;
    }
    EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    EGLint major = 0, minor = 0;
    if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor)) {
        snprintf(why, why_size, "cannot open the EGL surfaceless display (error 0x%x)", (unsigned)eglGetError());
        return NULL;
    }
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                         EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext context = EGL_NO_CONTEXT;
    if (eglBindAPI(EGL_OPENGL_API) && epoxy_has_egl_extension(display, "EGL_KHR_surfaceless_context") &&
        epoxy_has_egl_extension(display, "EGL_KHR_no_config_context"))
        context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, context_attributes);
    if (context == EGL_NO_CONTEXT || !eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
        snprintf(why, why_size, "cannot make an OpenGL 3.3 core context without a surface (EGL error 0x%x)",
                 (unsigned)eglGetError());
        if (context != EGL_NO_CONTEXT)
            eglDestroyContext(display, context);
        eglTerminate(display);
        return NULL;
    }
    rv_offscreen *o = calloc(1, sizeof *o);
    if (!o) {
        snprintf(why, why_size, "out of memory");
        eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display, context);
        eglTerminate(display);
        return NULL;
    }
    o->display = display;
    o->context = context;
    const char *name = (const char *)glGetString(GL_RENDERER);
    snprintf(o->renderer_name, sizeof o->renderer_name, "%s", name ? name : "unknown");
    return o;
}

void rv_offscreen_destroy(rv_offscreen *o)
{
    if (!o)
        return;
    eglMakeCurrent(o->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(o->display, o->context);
    eglReleaseThread();
    /* The display is left initialised: it is the process's one surfaceless
     * display (eglGetPlatformDisplayEXT hands back the same, and
     * eglInitialize of an initialised display does nothing), and
     * terminating it unloads Mesa's driver, which loses 112 bytes at
     * dlclose (LeakSanitizer, Mesa 22.3). */
    free(o);
}

const char *rv_offscreen_renderer_name(const rv_offscreen *o) { return o->renderer_name; }

/* A framebuffer with a float colour and a depth renderbuffer of `samples`
 * samples (0: single); false when incomplete. */
static bool make_framebuffer(int width, int height, int samples, GLuint *fbo, GLuint rb[2])
{
    glGenFramebuffers(1, fbo);
    glGenRenderbuffers(2, rb);
    glBindFramebuffer(GL_FRAMEBUFFER, *fbo);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[0]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA32F, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[1]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb[1]);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    return glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
}

static void free_framebuffer(GLuint *fbo, GLuint rb[2])
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteRenderbuffers(2, rb);
    glDeleteFramebuffers(1, fbo);
}

bool rv_offscreen_draw(rv_offscreen *o, const rv_renderer *r, const rv_draw *d, int samples, float *rgb)
{
    (void)o;
    GLint max_samples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    samples = samples < 0 ? 0 : samples > max_samples ? max_samples : samples;
    if (samples == 1)
        samples = 0;
    GLuint fbo = 0, rb[2] = {0, 0}, resolved = 0, resolved_rb[2] = {0, 0};
    bool ok = make_framebuffer(d->width, d->height, samples, &fbo, rb);
    if (ok && samples > 0)
        ok = make_framebuffer(d->width, d->height, 0, &resolved, resolved_rb);
    float *rgba = ok ? malloc((size_t)d->width * (size_t)d->height * 4 * sizeof *rgba) : NULL;
    if (ok && rgba) {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        rv_renderer_draw(r, d);
        if (samples > 0) {
            glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolved);
            glBlitFramebuffer(0, 0, d->width, d->height, 0, 0, d->width, d->height, GL_COLOR_BUFFER_BIT,
                              GL_NEAREST);
            glBindFramebuffer(GL_FRAMEBUFFER, resolved);
        }
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadPixels(0, 0, d->width, d->height, GL_RGBA, GL_FLOAT, rgba);
        /* GL's row 0 is the bottom one. */
        for (int y = 0; y < d->height; y++) {
            const float *row = rgba + (size_t)(d->height - 1 - y) * (size_t)d->width * 4;
            for (int x = 0; x < d->width; x++)
                for (int c = 0; c < 3; c++)
                    rgb[3 * ((size_t)y * (size_t)d->width + (size_t)x) + (size_t)c] = row[4 * x + c];
        }
    }
    ok = ok && rgba && glGetError() == GL_NO_ERROR;
    free(rgba);
    if (resolved)
        free_framebuffer(&resolved, resolved_rb);
    free_framebuffer(&fbo, rb);
    return ok;
}
