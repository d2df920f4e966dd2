/*
 * fuzz_scene.h -- the checks every scene fuzz target makes on one load:
 * a failure leaves a one-line message and no scene; a success gives named
 * surfaces of finite positive area, and meshes (at a coarse, fixed element
 * budget, so an input runs in milliseconds) into elements of finite
 * area that add up to each surface's area.
 */
#ifndef RAD_FUZZ_SCENE_H
#define RAD_FUZZ_SCENE_H

#include "fuzz.h"
#include "mesh/mesh.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* A warning (an orthographic camera replaced, material properties the
 * engine does not use) is one non-empty line of bounded length; it never
 * stops the load. */
static void fuzz_check_warning(void *user, const char *message)
{
    (void)user;
    FUZZ_CHECK(message[0] != '\0' && strchr(message, '\n') == NULL && strlen(message) < 1024);
}

static void fuzz_check_load(rad_context *ctx, rad_result r, rad_scene *scene)
{
    if (r != RAD_OK) {
        const char *msg = rad_context_error(ctx);
        FUZZ_CHECK(scene == NULL);
        FUZZ_CHECK(msg[0] != '\0' && strchr(msg, '\n') == NULL);
        return;
    }
    FUZZ_CHECK(scene != NULL);
    size_t surfaces = rad_scene_surface_count(scene);
    FUZZ_CHECK(surfaces > 0 && rad_scene_polygon_count(scene) > 0);
    for (size_t i = 0; i < surfaces; i++) {
        double area = rad_scene_surface_area(scene, i);
        FUZZ_CHECK(rad_scene_surface_name(scene, i) != NULL);
        FUZZ_CHECK(isfinite(area) && area > 0.0);
    }
    rad_camera camera;
    if (rad_scene_camera(scene, &camera))
        FUZZ_CHECK(isfinite(camera.vfov_degrees) && camera.vfov_degrees > 0.0 &&
                   camera.vfov_degrees < 180.0);

    /* 64 elements: enough to exercise patching, welding and T-vertices;
     * 256 MiB: a mesh above it fails cleanly, within libFuzzer's limit. */
    rad_mesh_options mo = {0.0, 64, 0.0};
    rad_mesh *mesh = NULL;
    rad_result m = rad_mesh_build_within(ctx, scene, &mo, 256.0 * 1048576.0, &mesh);
    if (m == RAD_OK) {
        /* Elements tile their surface: per surface, their areas sum to the
         * polygons' to 1e-8 (round-off), or to 2e-3 where the mesher merged
         * a triangle pair into one quad patch (merge_triangle_pairs allows
         * 2 degrees between the halves, and the merged quad's area differs
         * from theirs by up to 1 - cos 2 degrees = 6e-4). */
        size_t S = scene->surface_count;
        double *polygons = calloc(S, sizeof *polygons), *elements = calloc(S, sizeof *elements);
        char *merged = calloc(S, 1);
        FUZZ_CHECK(polygons && elements && merged);
        for (size_t p = 0; p < scene->polygon_count; p++)
            polygons[scene->polygons[p].surface] += scene->polygons[p].area;
        for (size_t q = 0; q < mesh->patch_count; q++)
            if (mesh->patches[q].corner_count == 4 &&
                scene->polygons[mesh->patches[q].polygon].vertex_count == 3)
                merged[mesh->patches[q].surface] = 1;
        /* Besides, each area is a cross product of edges, exact to a few
         * ulp of the product of their lengths: a sliver 10^9 times longer
         * than wide (40 m x 4e-8 m, not axis-aligned) has elements whose
         * areas are good to 1e-7 only, whatever the code.  That round-off
         * is allowed for, per element, on top of the relative tolerance. */
        double *roundoff = calloc(S, sizeof *roundoff);
        FUZZ_CHECK(roundoff != NULL);
        FUZZ_CHECK(mesh->element_count > 0);
        for (size_t i = 0; i < mesh->element_count; i++) {
            const rad_element *e = &mesh->elements[i];
            FUZZ_CHECK(isfinite(e->area) && e->area >= 0.0);
            elements[e->surface] += e->area;
            double longest = 0.0;
            for (uint32_t c = 0; c < e->vertex_count; c++)
                longest = fmax(longest, v3_length(v3_sub(mesh->vertices[e->vertex[(c + 1) % e->vertex_count]],
                                                         mesh->vertices[e->vertex[c]])));
            roundoff[e->surface] += 64.0 * DBL_EPSILON * longest * longest;
        }
        for (size_t k = 0; k < S; k++)
            FUZZ_CHECK(fabs(elements[k] - polygons[k]) <= (merged[k] ? 2e-3 : 1e-8) * polygons[k] + roundoff[k]);
        free(roundoff);
        free(polygons);
        free(elements);
        free(merged);
    } else {
        FUZZ_CHECK(mesh == NULL && rad_context_error(ctx)[0] != '\0');
    }
    rad_mesh_destroy(mesh);
}

#endif
