/*
 * daylight.c -- the direct daylight at a point (docs/lighting.md
 * "Daylight"): the sky seen through the scene's openings, the sky seen
 * directly (points outdoors), the sun, and the ground below the horizon.
 *
 * Every direction d from the point that escapes the scene sees the
 * environment's radiance L(d) (light/sky.c: the sky above the horizon, the
 * uniform ground or nothing below).  The escaping directions are split by
 * the first opening they cross, so none is counted twice:
 *
 *   - through opening piece k (k the nearest piece the ray crosses):
 *     adaptive subdivision of the piece (rad_ff_split4), each part
 *     weighted by its exact point-to-polygon factor (Lambert's formula,
 *     formfactor/polygon.c) times L toward its centre, a shadow ray
 *     through the centre; a part is split while its centre and corner rays
 *     disagree about reaching the sky, or while its four children change
 *     its value by more than tolerance x E_h x its factor;
 *
 *   - through no opening (points outdoors, or seeing out past a wall's
 *     edge): the hemisphere about n by Shirley & Chiu's concentric map of
 *     the unit square (area-preserving onto the disk, so each cell of the
 *     square is an equal share of the projected solid angle: E = pi times
 *     the mean of L V over the square), 8 x 8 cells split the same way
 *     down to 1/256 of the side;
 *
 *   - the sun: parallel light, E_n max(0, n . s) where the ray toward s
 *     escapes (openings are holes; a point sun: no penumbra).
 *
 * Shadow rays start rad_vis_epsilon(mesh) off the point along n and run to
 * infinity.  No state is kept: thread-safe and deterministic.
 */
#include "light/light.h"
#include "light/sky.h"
#include "formfactor/formfactor.h"

#include <math.h>
#include <string.h>

enum {
    PIECE_MIN_DEPTH = 2,   /* a piece is always split into 16 parts: no agreement by chance */
    PIECE_MAX_DEPTH = 9,   /* 1/512 of the piece's side: shadow edges to 0.2 % of it */
    CELL_START = 8,        /* 8 x 8 cells of the hemisphere's square */
    CELL_MAX_DEPTH = 5     /* 1/256 of the square's side */
};
#define NO_OPENING SIZE_MAX

typedef struct query {
    const rad_daylight *day;
    const rad_vis *vis;
    vec3 point, normal, origin; /* origin: the point lifted off its surface */
    double scale;          /* W/m^2: tolerance x E_h, the unit of the refinement tests */
} query;

/* Where the ray o + t dir crosses opening piece `o` (convex), or INFINITY. */
static double crossing(const rad_opening *o, vec3 origin, vec3 dir)
{
    double denom = v3_dot(o->normal, dir);
    if (denom == 0.0)
        return INFINITY;
    double t = v3_dot(o->normal, v3_sub(o->corner[0], origin)) / denom;
    if (!(t > 0.0))
        return INFINITY;
    vec3 x = v3_mad(origin, dir, t);
    for (uint32_t k = 0; k < o->corner_count; k++) {
        vec3 a = o->corner[k], b = o->corner[(k + 1) % o->corner_count];
        if (v3_dot(v3_cross(v3_sub(b, a), v3_sub(x, a)), o->normal) < 0.0)
            return INFINITY;
    }
    return t;
}

/* Whether the ray from the point along dir reaches the environment with
 * `through` the first opening piece it crosses (NO_OPENING: crossing
 * none).  `any`: openings do not matter (the sun). */
static bool escapes(const query *q, vec3 dir, size_t through, bool any)
{
    if (!any) {
        const rad_daylight *d = q->day;
        double limit = through == NO_OPENING ? INFINITY : crossing(&d->openings[through], q->origin, dir);
        if (through != NO_OPENING && limit == INFINITY)
            limit = v3_dot(d->openings[through].normal, v3_sub(d->openings[through].corner[0], q->origin)) /
                    v3_dot(d->openings[through].normal, dir); /* on the piece's edge: its plane */
        for (size_t k = 0; k < d->opening_count; k++) {
            if (k == through)
                continue;
            double t = crossing(&d->openings[k], q->origin, dir);
            if (t < limit || (through == NO_OPENING && t < INFINITY))
                return false;
        }
    }
    if (!q->vis)
        return true;
    rad_ray ray = {q->origin, dir, 0.0, INFINITY};
    uint8_t blocked = 0;
    q->vis->backend->occluded(q->vis->state, &ray, 1, &blocked);
    return !blocked;
}

/* ---- through an opening ---- */

/* The part's factor from the point (the part turned to face it) and its
 * contribution F L(centre) V(centre). */
static double part_value(const query *q, const vec3 *region, uint32_t corners, size_t piece, double *factor)
{
    vec3 poly[4] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    vec3 pn = q->day->openings[piece].normal;
    bool flip = v3_dot(pn, v3_sub(q->point, region[0])) < 0.0;
    for (uint32_t k = 0; k < corners; k++)
        poly[k] = region[flip ? corners - 1 - k : k];
    double f = rad_point_polygon_ff_front(q->point, q->normal, poly, corners);
    *factor = f;
    if (!(f > 0.0))
        return 0.0;
    vec3 c = {0, 0, 0};
    for (uint32_t k = 0; k < corners; k++)
        c = v3_add(c, region[k]);
    vec3 dir = v3_normalize(v3_sub(v3_scale(c, 1.0 / corners), q->point));
    double radiance = rad_daylight_radiance(q->day, dir);
    if (radiance == 0.0 || !escapes(q, dir, piece, false))
        return 0.0;
    return M_PI * f * radiance; /* E = pi L F: F is the projected solid angle over pi */
}

/* Whether the rays toward the part's corners (pulled 1e-3 of the way to
 * its centre, inside it) all agree with the one toward its centre. */
static bool part_visibility_uniform(const query *q, const vec3 *region, uint32_t corners, size_t piece)
{
    vec3 c = {0, 0, 0};
    for (uint32_t k = 0; k < corners; k++)
        c = v3_add(c, region[k]);
    c = v3_scale(c, 1.0 / corners);
    bool first = escapes(q, v3_normalize(v3_sub(c, q->point)), piece, false);
    for (uint32_t k = 0; k < corners; k++) {
        vec3 x = v3_lerp(region[k], c, 1e-3);
        vec3 dir = v3_normalize(v3_sub(x, q->point));
        bool lit = escapes(q, dir, piece, false);
        /* Sky above and nothing below: the horizon is an edge too. */
        if (lit != first || (rad_daylight_radiance(q->day, dir) == 0.0) !=
                                (rad_daylight_radiance(q->day, v3_normalize(v3_sub(c, q->point))) == 0.0))
            return false;
    }
    return true;
}

static double integrate_part(const query *q, const vec3 *region, uint32_t corners, size_t piece, int depth,
                             double value, double factor)
{
    if (!(factor > 0.0) || depth >= PIECE_MAX_DEPTH)
        return value;
    vec3 sub[4][4];
    rad_ff_split4(region, corners, sub);
    double child[4], child_factor[4], sum = 0.0;
    for (int k = 0; k < 4; k++) {
        child[k] = part_value(q, sub[k], corners, piece, &child_factor[k]);
        sum += child[k];
    }
    bool settled = depth >= PIECE_MIN_DEPTH && fabs(sum - value) <= q->scale * factor &&
                   part_visibility_uniform(q, region, corners, piece);
    if (settled)
        return sum;
    double total = 0.0;
    for (int k = 0; k < 4; k++)
        total += integrate_part(q, sub[k], corners, piece, depth + 1, child[k], child_factor[k]);
    return total;
}

/* ---- the hemisphere, through no opening ---- */

/* Shirley & Chiu 1997: the unit square onto the unit disk, area-preserving;
 * lifted to the hemisphere about (t, b, n). */
static vec3 concentric(const query *q, vec3 t, vec3 b, double u, double v)
{
    double a = 2.0 * u - 1.0, c = 2.0 * v - 1.0, r, phi;
    if (a == 0.0 && c == 0.0)
        return q->normal;
    if (fabs(a) > fabs(c))
        r = a, phi = 0.25 * M_PI * c / a;
    else
        r = c, phi = 0.5 * M_PI - 0.25 * M_PI * a / c;
    double x = r * cos(phi), y = r * sin(phi), z = sqrt(fmax(0.0, 1.0 - x * x - y * y));
    return v3_normalize(v3_add(v3_add(v3_scale(t, x), v3_scale(b, y)), v3_scale(q->normal, z)));
}

static double cell_radiance(const query *q, vec3 t, vec3 b, double u, double v, bool *lit)
{
    vec3 dir = concentric(q, t, b, u, v);
    double radiance = rad_daylight_radiance(q->day, dir);
    *lit = radiance > 0.0 && escapes(q, dir, NO_OPENING, false);
    return *lit ? radiance : 0.0;
}

/* pi x the integral of L V over the cell [u, u + h] x [v, v + h]. */
static double integrate_cell(const query *q, vec3 t, vec3 b, double u, double v, double h, int depth, double value)
{
    double child[4], sum = 0.0;
    bool lit[4], centre_lit, uniform = true;
    for (int k = 0; k < 4; k++) {
        double cu = u + h * (0.25 + 0.5 * (k & 1)), cv = v + h * (0.25 + 0.5 * (k >> 1));
        child[k] = M_PI * 0.25 * h * h * cell_radiance(q, t, b, cu, cv, &lit[k]);
        sum += child[k];
    }
    cell_radiance(q, t, b, u + 0.5 * h, v + 0.5 * h, &centre_lit);
    for (int k = 0; k < 4; k++)
        uniform &= lit[k] == centre_lit;
    if (depth >= CELL_MAX_DEPTH || (uniform && fabs(sum - value) <= q->scale * h * h))
        return sum;
    double total = 0.0;
    for (int k = 0; k < 4; k++)
        total += integrate_cell(q, t, b, u + 0.5 * h * (k & 1), v + 0.5 * h * (k >> 1), 0.5 * h, depth + 1,
                                child[k]);
    return total;
}

static double through_no_opening(const query *q)
{
    vec3 n = q->normal;
    vec3 t = v3_normalize(v3_cross(fabs(n.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0), n)), b = v3_cross(n, t);
    double h = 1.0 / CELL_START, total = 0.0;
    for (int i = 0; i < CELL_START; i++)
        for (int j = 0; j < CELL_START; j++) {
            bool lit;
            double value = M_PI * h * h * cell_radiance(q, t, b, (i + 0.5) * h, (j + 0.5) * h, &lit);
            total += integrate_cell(q, t, b, i * h, j * h, h, 0, value);
        }
    return total;
}

void rad_daylight_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                             vec3 n, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    const rad_daylight *day = scene ? scene->daylight : NULL;
    if (!day)
        return;
    n = v3_normalize(n);
    double eps = mesh ? rad_vis_epsilon(mesh) : 0.0;
    query q = {day, vis, p, n, v3_mad(p, n, eps), day->tolerance * fmax(day->sky.horizontal, 1e-300)};
    double e = 0.0;
    for (size_t k = 0; k < day->opening_count; k++) {
        const rad_opening *o = &day->openings[k];
        double factor, value = part_value(&q, o->corner, o->corner_count, k, &factor);
        e += integrate_part(&q, o->corner, o->corner_count, k, 0, value, factor);
    }
    e += through_no_opening(&q);
    const rad_sky *sky = &day->sky;
    double cos_sun = v3_dot(n, sky->sun);
    if (day->sun_normal > 0.0 && cos_sun > 0.0 && escapes(&q, sky->sun, NO_OPENING, true))
        e += day->sun_normal * cos_sun;
    out[0] = out[1] = out[2] = e;
}

void rad_daylight_sky_horizontal(const rad_scene *scene, double out[3])
{
    double e = scene && scene->daylight ? scene->daylight->sky.horizontal : 0.0;
    out[0] = out[1] = out[2] = e;
}
