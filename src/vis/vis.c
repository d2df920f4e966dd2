/*
 * vis.c -- the visibility registry and the handle around a backend.
 *
 * Each backend (vis_embree.c, vis_brute.c) is one rad_vis_backend table of
 * function pointers; this file lists them, finds one by name, times its
 * build and owns the handle.  Callers query through vis->backend.
 */
#include "vis/vis.h"

#include <stdlib.h>
#include <string.h>

extern const rad_vis_backend rad_vis_embree;
extern const rad_vis_backend rad_vis_brute;

const rad_vis_backend *const rad_vis_backends[] = {&rad_vis_embree, &rad_vis_brute, NULL};

const rad_vis_backend *rad_vis_find(const char *name)
{
    if (!name)
        return NULL;
    for (size_t i = 0; rad_vis_backends[i]; i++)
        if (strcmp(rad_vis_backends[i]->name, name) == 0)
            return rad_vis_backends[i];
    return NULL;
}

rad_result rad_vis_create(rad_context *ctx, const char *name, const rad_mesh *mesh, rad_vis **out)
{
    *out = NULL;
    const rad_vis_backend *backend = rad_vis_find(name);
    if (!backend)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "unknown visibility backend '%s' (known: embree, brute)",
                        name ? name : "(null)");
    rad_vis *vis = rad_alloc(ctx, RAD_MEM_VISIBILITY, 1, sizeof *vis, "visibility");
    if (!vis)
        return RAD_ERROR_OUT_OF_MEMORY;
    double start = rad_seconds();
    rad_result r = backend->create(ctx, mesh, &vis->state);
    if (r != RAD_OK) {
        rad_free(vis);
        return r;
    }
    vis->backend = backend;
    vis->build_seconds = rad_seconds() - start;
    *out = vis;
    return RAD_OK;
}

void rad_vis_destroy(rad_vis *vis)
{
    if (!vis)
        return;
    vis->backend->destroy(vis->state);
    rad_free(vis);
}
