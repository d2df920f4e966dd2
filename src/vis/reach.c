/*
 * reach.c -- the box a point's view can reach (vis.h): a fan of rays from
 * the point to what they first hit.
 *
 * The fan is a Fibonacci sphere of `rays` directions (near-uniform,
 * deterministic).  The box holds the origin and every hit, each widened by
 *
 *     r = spread x t + pad,     spread = 2 sqrt(4 pi / rays)
 *
 * t the hit's distance: twice the fan's angular spacing times the
 * distance, so the segments from the origin to the hits and the gaps
 * between neighbouring rays lie in the box.  A line of sight from the
 * origin leaves the box only through a gap the fan stepped over (narrower
 * than about spread / 2 x distance).  A ray that hits nothing leaves the
 * scene: the reach is then everywhere.
 *
 * Its users (light/reach.c, grid/gather.c) skip what lies outside: light
 * the shadow rays would have found blocked.
 *
 * By sectors: the same boxes for the rays of each sector of directions
 * (bands of z, down the sphere as the fan's index goes, each cut in
 * azimuths), every one holding the origin.  A line of sight lies in the box
 * of the sector of its nearest ray (the segment from the origin to that
 * ray's hit, widened as above, is in it), so the union of the sectors'
 * boxes keeps the whole box's promise and is far tighter: the light that
 * leaves a room by its door reaches the next room's strip behind the door,
 * not the box around both rooms.
 */
#include "vis/vis.h"

#include <math.h>

enum { BATCH = 256 };

static vec3 fan_direction(size_t i, size_t rays)
{
    const double golden = M_PI * (3.0 - sqrt(5.0));
    double z = 1.0 - (2.0 * (double)i + 1.0) / (double)rays, r = sqrt(fmax(0.0, 1.0 - z * z));
    double phi = golden * (double)i;
    return v3(r * cos(phi), r * sin(phi), z);
}

static void widen(vec3 *lo, vec3 *hi, vec3 p, double r)
{
    *lo = v3_min(*lo, v3(p.x - r, p.y - r, p.z - r));
    *hi = v3_max(*hi, v3(p.x + r, p.y + r, p.z + r));
}

bool rad_vis_reach_sectors(const rad_vis *vis, vec3 origin, double tnear, size_t rays, double pad, int bands,
                           int azimuths, vec3 *lo, vec3 *hi, vec3 *sector_lo, vec3 *sector_hi)
{
    const double golden = M_PI * (3.0 - sqrt(5.0));
    double spread = 2.0 * sqrt(4.0 * M_PI / (double)(rays > 0 ? rays : 1));
    size_t sectors = (size_t)bands * (size_t)azimuths;
    *lo = *hi = origin;
    widen(lo, hi, origin, pad);
    for (size_t s = 0; s < sectors; s++)
        sector_lo[s] = *lo, sector_hi[s] = *hi;
    rad_ray ray[BATCH];
    rad_hit hit[BATCH];
    for (size_t start = 0; start < rays; start += BATCH) {
        size_t m = rays - start < BATCH ? rays - start : BATCH;
        for (size_t k = 0; k < m; k++)
            ray[k] = (rad_ray){origin, fan_direction(start + k, rays), tnear, INFINITY};
        vis->backend->intersect(vis->state, ray, m, hit);
        for (size_t k = 0; k < m; k++) {
            if (!isfinite(hit[k].t)) {
                *lo = v3(-INFINITY, -INFINITY, -INFINITY);
                *hi = v3(INFINITY, INFINITY, INFINITY);
                for (size_t s = 0; s < sectors; s++)
                    sector_lo[s] = *lo, sector_hi[s] = *hi;
                return false;
            }
            /* Ray i's sector: its band of z (the directions go down the
             * sphere with i), then its azimuth. */
            size_t i = start + k;
            size_t band = i * (size_t)bands / rays;
            double turns = golden * (double)i / (2.0 * M_PI);
            size_t az = (size_t)((turns - floor(turns)) * azimuths);
            size_t s = band * (size_t)azimuths + (az < (size_t)azimuths ? az : (size_t)azimuths - 1);
            vec3 at = v3_mad(origin, ray[k].direction, hit[k].t);
            double r = spread * hit[k].t + pad;
            widen(lo, hi, at, r);
            widen(&sector_lo[s], &sector_hi[s], at, r);
        }
    }
    return true;
}

bool rad_vis_reach(const rad_vis *vis, vec3 origin, double tnear, size_t rays, double pad, vec3 *lo, vec3 *hi)
{
    vec3 slo, shi;
    return rad_vis_reach_sectors(vis, origin, tnear, rays, pad, 1, 1, lo, hi, &slo, &shi);
}
