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

/* Whether the ray from the point along dir crosses opening piece
 * `through` first (NO_OPENING: crosses none); `any`: openings do not
 * matter (the sun). */
static bool opening_first(const query *q, vec3 dir, size_t through, bool any)
{
    if (any)
        return true;
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
    return true;
}

enum { BATCH = 16 }; /* the ray backends' packet width */

/* out[k]: whether the ray from the point along dirs[k] reaches the
 * environment, `through` the first opening piece it crosses (as
 * opening_first); rays with ask[k] false are not traced (out false).
 * n <= BATCH: one packet for the ray backend. */
static void escapes(const query *q, const vec3 *dirs, const bool *ask, size_t n, size_t through, bool any,
                    bool *out)
{
    rad_ray rays[BATCH];
    size_t which[BATCH], m = 0;
    for (size_t k = 0; k < n; k++) {
        out[k] = (!ask || ask[k]) && opening_first(q, dirs[k], through, any);
        if (out[k] && q->vis) {
            rays[m] = (rad_ray){q->origin, dirs[k], 0.0, INFINITY};
            which[m++] = k;
        }
    }
    if (m == 0)
        return;
    uint8_t blocked[BATCH];
    q->vis->backend->occluded(q->vis->state, rays, m, blocked);
    for (size_t k = 0; k < m; k++)
        out[which[k]] = !blocked[k];
}

/* ---- through an opening ---- */

/* What a part's shadow rays found: not yet asked, or all of them (centre
 * and corners) agreeing on lit or on dark; parts inside a part whose rays
 * agree are taken to agree too (the subdivision's resolution). */
typedef enum part_sight { SIGHT_UNKNOWN = 0, SIGHT_LIT, SIGHT_DARK } part_sight;

static vec3 part_centre(const vec3 *region, uint32_t corners)
{
    vec3 c = {0, 0, 0};
    for (uint32_t k = 0; k < corners; k++)
        c = v3_add(c, region[k]);
    return v3_scale(c, 1.0 / corners);
}

/* Parts `regions[0..n)` (n <= 4) of opening piece `piece`: each one's
 * factor from the point (the part turned to face it) and contribution
 * pi F L(centre) V(centre) (E = pi L F, F the projected solid angle over
 * pi); V from `sight` where known, else from shadow rays, traced as one
 * batch. */
static void part_values(const query *q, vec3 (*regions)[4], size_t n, uint32_t corners, size_t piece,
                        part_sight sight, double *value, double *factor)
{
    vec3 pn = q->day->openings[piece].normal, dirs[4];
    bool ask[4], lit[4];
    for (size_t j = 0; j < n; j++) {
        const vec3 *region = regions[j];
        vec3 poly[4] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
        bool flip = v3_dot(pn, v3_sub(q->point, region[0])) < 0.0;
        for (uint32_t k = 0; k < corners; k++)
            poly[k] = region[flip ? corners - 1 - k : k];
        factor[j] = rad_point_polygon_ff_front(q->point, q->normal, poly, corners);
        dirs[j] = v3_normalize(v3_sub(part_centre(region, corners), q->point));
        value[j] = factor[j] > 0.0 && sight != SIGHT_DARK ? M_PI * factor[j] * rad_daylight_radiance(q->day, dirs[j])
                                                          : 0.0;
        ask[j] = value[j] > 0.0 && sight == SIGHT_UNKNOWN;
    }
    if (sight != SIGHT_UNKNOWN)
        return;
    escapes(q, dirs, ask, n, piece, false, lit);
    for (size_t j = 0; j < n; j++)
        if (!lit[j])
            value[j] = 0.0;
}

/* Whether the rays toward the part's corners (pulled 1e-3 of the way to
 * its centre, inside it) and its centre agree, on reaching the
 * environment and on seeing something there (the horizon is an edge too
 * where there is no ground). */
static part_sight part_visibility(const query *q, const vec3 *region, uint32_t corners, size_t piece)
{
    vec3 c = part_centre(region, corners), dirs[5];
    bool ask[5], lit[5];
    dirs[0] = v3_normalize(v3_sub(c, q->point));
    for (uint32_t k = 0; k < corners; k++)
        dirs[k + 1] = v3_normalize(v3_sub(v3_lerp(region[k], c, 1e-3), q->point));
    for (uint32_t k = 0; k <= corners; k++)
        ask[k] = rad_daylight_radiance(q->day, dirs[k]) > 0.0;
    escapes(q, dirs, ask, corners + 1, piece, false, lit);
    for (uint32_t k = 1; k <= corners; k++)
        if (lit[k] != lit[0])
            return SIGHT_UNKNOWN;
    return lit[0] ? SIGHT_LIT : SIGHT_DARK;
}

static double integrate_part(const query *q, const vec3 *region, uint32_t corners, size_t piece, int depth,
                             double value, double factor, part_sight sight)
{
    if (!(factor > 0.0) || depth >= PIECE_MAX_DEPTH)
        return value;
    if (sight == SIGHT_UNKNOWN && depth >= PIECE_MIN_DEPTH)
        sight = part_visibility(q, region, corners, piece);
    if (sight == SIGHT_DARK)
        return 0.0;
    vec3 sub[4][4];
    rad_ff_split4(region, corners, sub);
    double child[4], child_factor[4], sum = 0.0;
    part_values(q, sub, 4, corners, piece, sight, child, child_factor);
    for (int k = 0; k < 4; k++)
        sum += child[k];
    if (sight != SIGHT_UNKNOWN && fabs(sum - value) <= q->scale * factor)
        return sum;
    double total = 0.0;
    for (int k = 0; k < 4; k++)
        total += integrate_part(q, sub[k], corners, piece, depth + 1, child[k], child_factor[k], sight);
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

/* L V toward (u[k], v[k]) of the square, n <= BATCH directions; lit[k]:
 * the ray escapes through no opening to a non-zero radiance.  `known`:
 * all are lit as `known_lit` says (no rays), else one batch of rays. */
static void cell_radiance(const query *q, vec3 t, vec3 b, const double *u, const double *v, size_t n, bool known,
                          bool known_lit, double *value, bool *lit)
{
    vec3 dirs[BATCH];
    bool ask[BATCH];
    for (size_t k = 0; k < n; k++) {
        dirs[k] = concentric(q, t, b, u[k], v[k]);
        value[k] = rad_daylight_radiance(q->day, dirs[k]);
        ask[k] = value[k] > 0.0;
        lit[k] = known_lit && ask[k];
    }
    if (!known)
        escapes(q, dirs, ask, n, NO_OPENING, false, lit);
    for (size_t k = 0; k < n; k++)
        if (!lit[k])
            value[k] = 0.0;
}

/* pi x the integral of L V over the cell [u, u + h] x [v, v + h], whose
 * centre gave `value` (pi h^2 L V) and `centre_lit`.  The four children's
 * centres and the cell's corners are traced until their rays and the
 * centre's agree; below such a cell its parts are taken to agree too
 * (`known`), and only the sky's variation splits them further. */
static double integrate_cell(const query *q, vec3 t, vec3 b, double u, double v, double h, int depth, double value,
                             bool centre_lit, bool known)
{
    /* The children's centres, then (while the sight is not known) the
     * cell's corners, 1e-3 of the side inside it. */
    double cu[8], cv[8], child[8], sum = 0.0;
    bool lit[8], uniform = true;
    for (int k = 0; k < 4; k++) {
        cu[k] = u + h * (0.25 + 0.5 * (k & 1)), cv[k] = v + h * (0.25 + 0.5 * (k >> 1));
        cu[k + 4] = u + h * (k & 1 ? 0.999 : 0.001), cv[k + 4] = v + h * (k >> 1 ? 0.999 : 0.001);
    }
    cell_radiance(q, t, b, cu, cv, known ? 4 : 8, known, centre_lit, child, lit);
    for (int k = 0; k < (known ? 4 : 8); k++)
        uniform &= lit[k] == centre_lit;
    for (int k = 0; k < 4; k++) {
        child[k] *= M_PI * 0.25 * h * h;
        sum += child[k];
    }
    if (depth >= CELL_MAX_DEPTH || (uniform && fabs(sum - value) <= q->scale * h * h))
        return sum;
    double total = 0.0;
    for (int k = 0; k < 4; k++)
        total += integrate_cell(q, t, b, u + 0.5 * h * (k & 1), v + 0.5 * h * (k >> 1), 0.5 * h, depth + 1, child[k],
                                lit[k], uniform);
    return total;
}

static double through_no_opening(const query *q)
{
    vec3 n = q->normal;
    vec3 t = v3_normalize(v3_cross(fabs(n.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0), n)), b = v3_cross(n, t);
    double h = 1.0 / CELL_START, total = 0.0;
    for (int i = 0; i < CELL_START; i++) {
        double u[CELL_START], v[CELL_START], value[CELL_START];
        bool lit[CELL_START];
        for (int j = 0; j < CELL_START; j++)
            u[j] = (i + 0.5) * h, v[j] = (j + 0.5) * h;
        cell_radiance(q, t, b, u, v, CELL_START, false, false, value, lit);
        for (int j = 0; j < CELL_START; j++)
            total += integrate_cell(q, t, b, i * h, j * h, h, 0, M_PI * h * h * value[j], lit[j], false);
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
        vec3 whole[1][4] = {{o->corner[0], o->corner[1], o->corner[2], o->corner[3]}};
        double factor, value;
        part_values(&q, whole, 1, o->corner_count, k, SIGHT_UNKNOWN, &value, &factor);
        e += integrate_part(&q, o->corner, o->corner_count, k, 0, value, factor, SIGHT_UNKNOWN);
    }
    e += through_no_opening(&q);
    const rad_sky *sky = &day->sky;
    double cos_sun = v3_dot(n, sky->sun);
    bool sunlit = false;
    if (day->sun_normal > 0.0 && cos_sun > 0.0)
        escapes(&q, &sky->sun, NULL, 1, NO_OPENING, true, &sunlit);
    if (sunlit)
        e += day->sun_normal * cos_sun;
    out[0] = out[1] = out[2] = e;
}

void rad_daylight_sky_horizontal(const rad_scene *scene, double out[3])
{
    double e = scene && scene->daylight ? scene->daylight->sky.horizontal : 0.0;
    out[0] = out[1] = out[2] = e;
}
