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
 * The same by sectors (vis/reach.c): BANDS x AZIMUTHS boxes, one per
 * sector of the fan's directions, whose union keeps the box's promise and
 * leaves out most of the room behind a door (the strip the door's light
 * falls on stays in).  A query tests the whole box, then the bands', then
 * their sectors'.
 *
 * Cost: FAN rays a luminaire (40 downlights: 0.33 M rays), against
 * points x luminaires shadow rays saved.  Each luminaire alone, in
 * parallel: the boxes do not depend on the thread count.
 */
#include "light/light.h"

#include "photometry/photometry.h"

#include <math.h>

enum {
    FAN = 8192,
    BANDS = 8,                  /* the fan's sectors (vis/reach.c): bands of z ... */
    AZIMUTHS = 16,              /* ... times azimuths */
    SECTORS = BANDS * AZIMUTHS
};

struct rad_light_reach {
    size_t count;
    vec3 *lo, *hi;              /* per luminaire, m; +-inf: everywhere */
    vec3 *band_lo, *band_hi;    /* BANDS per luminaire: the union of the band's sectors */
    vec3 *sector_lo, *sector_hi; /* SECTORS per luminaire */
};

/* One luminaire's boxes (vis/reach.c's fan from its centre, widened by its
 * luminous size), whole, by band and by sector; infinite when a ray left
 * the scene. */
static void luminaire_boxes(const rad_scene *scene, const rad_luminaire *L, const rad_vis *vis, double eps,
                            rad_light_reach *reach, size_t k)
{
    const rad_photometry *ph = scene->luminaires.photometries[L->photometry];
    double size = fmax(fmax(ph->length, ph->width), ph->height);
    vec3 *slo = reach->sector_lo + k * SECTORS, *shi = reach->sector_hi + k * SECTORS;
    rad_vis_reach_sectors(vis, L->position, eps, FAN, (isfinite(size) ? size : 0.0) + 4.0 * eps, BANDS, AZIMUTHS,
                          &reach->lo[k], &reach->hi[k], slo, shi);
    for (int b = 0; b < BANDS; b++) {
        vec3 lo = slo[b * AZIMUTHS], hi = shi[b * AZIMUTHS];
        for (int a = 1; a < AZIMUTHS; a++) {
            lo = v3_min(lo, slo[b * AZIMUTHS + a]);
            hi = v3_max(hi, shi[b * AZIMUTHS + a]);
        }
        reach->band_lo[k * BANDS + b] = lo;
        reach->band_hi[k * BANDS + b] = hi;
    }
}

static void everywhere(rad_light_reach *reach, size_t k)
{
    vec3 lo = v3(-INFINITY, -INFINITY, -INFINITY), hi = v3(INFINITY, INFINITY, INFINITY);
    reach->lo[k] = lo, reach->hi[k] = hi;
    for (size_t b = 0; b < BANDS; b++)
        reach->band_lo[k * BANDS + b] = lo, reach->band_hi[k * BANDS + b] = hi;
    for (size_t s = 0; s < SECTORS; s++)
        reach->sector_lo[k * SECTORS + s] = lo, reach->sector_hi[k * SECTORS + s] = hi;
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
    reach->hi = rad_alloc(ctx, RAD_MEM_SCENE, n + 1, sizeof *reach->hi, "luminaires' reach");
    reach->band_lo = rad_alloc(ctx, RAD_MEM_SCENE, BANDS * n + 1, sizeof(vec3), "luminaires' reach");
    reach->band_hi = rad_alloc(ctx, RAD_MEM_SCENE, BANDS * n + 1, sizeof(vec3), "luminaires' reach");
    reach->sector_lo = rad_alloc(ctx, RAD_MEM_SCENE, SECTORS * n + 1, sizeof(vec3), "luminaires' reach");
    reach->sector_hi = rad_alloc(ctx, RAD_MEM_SCENE, SECTORS * n + 1, sizeof(vec3), "luminaires' reach");
    if (!reach->lo || !reach->hi || !reach->band_lo || !reach->band_hi || !reach->sector_lo || !reach->sector_hi) {
        rad_light_reach_destroy(reach);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    double eps = mesh ? rad_vis_epsilon(mesh) : 0.0;
    volatile int stop = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads > 0 ? threads : 1)
    for (size_t k = 0; k < n; k++) {
        if (stop)
            continue;
        if (vis)
            luminaire_boxes(scene, &scene->luminaires.items[k], vis, eps, reach, k);
        else /* no shadows: everywhere */
            everywhere(reach, k);
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
    rad_free(reach->band_lo);
    rad_free(reach->band_hi);
    rad_free(reach->sector_lo);
    rad_free(reach->sector_hi);
    rad_free(reach);
}

bool rad_light_reach_meets(const rad_light_reach *reach, size_t k, vec3 lo, vec3 hi)
{
    if (!v3_boxes_meet(lo, hi, reach->lo[k], reach->hi[k]))
        return false;
    if (!v3_finite(reach->lo[k]))
        return true;
    const vec3 *blo = reach->band_lo + k * BANDS, *bhi = reach->band_hi + k * BANDS;
    const vec3 *slo = reach->sector_lo + k * SECTORS, *shi = reach->sector_hi + k * SECTORS;
    for (int b = 0; b < BANDS; b++) {
        if (!v3_boxes_meet(lo, hi, blo[b], bhi[b]))
            continue;
        for (int a = b * AZIMUTHS; a < (b + 1) * AZIMUTHS; a++)
            if (v3_boxes_meet(lo, hi, slo[a], shi[a]))
                return true;
    }
    return false;
}

bool rad_light_reach_holds(const rad_light_reach *reach, size_t k, vec3 p)
{
    return rad_light_reach_meets(reach, k, p, p);
}

size_t rad_light_reach_list(const rad_light_reach *reach, vec3 lo, vec3 hi, uint32_t *out)
{
    size_t m = 0;
    for (size_t k = 0; k < reach->count; k++)
        if (rad_light_reach_meets(reach, k, lo, hi))
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
