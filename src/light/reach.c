/*
 * reach.c -- where each luminaire's light can arrive, so that a point asks
 * the luminaires that may light it and not every one of a building's
 * (light.h, docs/lighting.md "Reach").
 *
 * A fan of FAN rays leaves the luminaire's centre in every direction (a
 * Fibonacci sphere: near-uniform, deterministic; vis/reach.c) and stops at
 * the first surface.  The box holds the centre and every hit, each widened
 * by
 *
 *     r = SPREAD x t + size + 4 eps
 *
 * t the hit's distance, SPREAD twice the fan's angular spacing
 * sqrt(4 pi / FAN) (the gap between neighbouring rays at that distance,
 * twice over), size the luminaire's luminous size (its opening emits from
 * off the centre), eps the shadow rays' lift.  The segments from the
 * centre to the hits lie in the box, so a point the light reaches along
 * a clear line lies in it unless that line passes through a gap the fan
 * stepped over (narrower than about SPREAD / 2 x distance: 3 cm at 1 m,
 * 30 cm at 10 m, two rooms away through a door ajar).  A ray that hits
 * nothing leaves the scene: the luminaire's box is then everywhere (an
 * open scene culls nothing).
 *
 *      +-----------+-----------+        room A's downlight: its fan
 *      |     *     |           |        ends on A's walls, and the rays
 *      |    /|\    |           |        through the door on B's far
 *      |   / | \   D ---->     |        wall: A's box is A and the strip
 *      +-----------+-----------+        of B behind the door
 *
 * Cost: FAN rays a luminaire (40 downlights: 0.33 M rays), against
 * points x luminaires shadow rays saved.  Each luminaire alone, in
 * parallel: the boxes do not depend on the thread count.
 */
#include "light/light.h"

#include "photometry/photometry.h"

#include <math.h>

enum { FAN = 8192 };

struct rad_light_reach {
    size_t count;
    vec3 *lo, *hi;      /* per luminaire, m; +-inf: everywhere */
};

/* One luminaire's box (vis/reach.c's fan from its centre, widened by its
 * luminous size); infinite when a ray left the scene. */
static void luminaire_box(const rad_scene *scene, const rad_luminaire *L, const rad_vis *vis, double eps,
                          vec3 *lo, vec3 *hi)
{
    const rad_photometry *ph = scene->luminaires.photometries[L->photometry];
    double size = fmax(fmax(ph->length, ph->width), ph->height);
    rad_vis_reach(vis, L->position, eps, FAN, (isfinite(size) ? size : 0.0) + 4.0 * eps, lo, hi);
}

rad_result rad_light_reach_build(rad_context *ctx, const rad_scene *scene, const rad_mesh *mesh,
                                 const rad_vis *vis, int threads, rad_light_reach **out)
{
    *out = NULL;
    size_t n = scene->luminaires.count;
    rad_light_reach *reach = rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *reach, "luminaires' reach");
    if (!reach)
        return RAD_ERROR_OUT_OF_MEMORY;
    reach->count = n;
    reach->lo = rad_alloc(ctx, RAD_MEM_SCENE, n + 1, sizeof *reach->lo, "luminaires' reach");
    reach->hi = reach->lo ? rad_alloc(ctx, RAD_MEM_SCENE, n + 1, sizeof *reach->hi, "luminaires' reach") : NULL;
    if (!reach->hi) {
        rad_light_reach_destroy(reach);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    double eps = mesh ? rad_vis_epsilon(mesh) : 0.0;
    volatile int stop = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads > 0 ? threads : 1)
    for (size_t k = 0; k < n; k++) {
        if (stop)
            continue;
        if (vis) {
            luminaire_box(scene, &scene->luminaires.items[k], vis, eps, &reach->lo[k], &reach->hi[k]);
        } else { /* no shadows: everywhere */
            reach->lo[k] = v3(-INFINITY, -INFINITY, -INFINITY);
            reach->hi[k] = v3(INFINITY, INFINITY, INFINITY);
        }
        if (rad_cancelled(ctx))
            stop = 1;
    }
    if (stop) {
        rad_light_reach_destroy(reach);
        return RAD_ERROR_INTERRUPTED;
    }
    *out = reach;
    return RAD_OK;
}

void rad_light_reach_destroy(rad_light_reach *reach)
{
    if (!reach)
        return;
    rad_free(reach->lo);
    rad_free(reach->hi);
    rad_free(reach);
}

bool rad_light_reach_holds(const rad_light_reach *reach, size_t k, vec3 p)
{
    return v3_box_holds(reach->lo[k], reach->hi[k], p);
}

size_t rad_light_reach_list(const rad_light_reach *reach, vec3 lo, vec3 hi, uint32_t *out)
{
    size_t m = 0;
    for (size_t k = 0; k < reach->count; k++)
        if (v3_boxes_meet(lo, hi, reach->lo[k], reach->hi[k]))
            out[m++] = (uint32_t)k;
    return m;
}

size_t rad_light_reach_everywhere(const rad_light_reach *reach)
{
    size_t m = 0;
    for (size_t k = 0; reach && k < reach->count; k++)
        m += !v3_finite(reach->lo[k]);
    return m;
}
