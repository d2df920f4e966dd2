/*
 * luminaire.c -- the direct light of placed luminaires at a point
 * (docs/lighting.md "Luminaires").
 *
 * Far from its opening a luminaire is a goniometric point source at its
 * photometric centre (IES LM-63's and CIE 121's far-field assumption):
 *
 *     E = I(theta) cos(alpha) / d^2        I in cd x multiplier, / 179 -> W/m^2
 *
 * theta the direction from the luminaire to the point in the luminaire's
 * frame, alpha the angle of incidence at the receiver, d the distance, and
 * one shadow ray from the point to the centre.  The point-source law holds
 * within 1 % beyond five times the luminous size (the "five-times rule",
 * IESNA Lighting Handbook 10th ed., ch. 9; Ashdown, "Near-field photometry",
 * 1993).  Nearer, the opening becomes an area source: split into sub-sources,
 * each carrying the distribution scaled by its share of the opening and
 * placed at its own centroid, recursively until every sub-source is beyond
 * five times its own size, each then four point sources at its Gauss points
 * (below), each with its own shadow ray:
 *
 *        luminaire frame, seen from below         round opening: annular
 *        y (C = 90)                               sectors split in r and phi
 *        ^  +---------+---------+
 *        |  |    |    |         |  w (width, along y)
 *        |  |----+----|  *   *  |
 *        |  |    |  * |  *   *  |  * = Gauss points of the pieces
 *        |  +---------+---------+
 *        +------------------------> x (C = 0)      l (length, along x)
 *
 * The opening lies in the luminaire's x-y plane through the photometric
 * centre (a rectangle l x w, or an ellipse for the round shapes of
 * photometry.h; a box or cylinder by its horizontal section), except the
 * vertical discs, which stand in the y-z or x-z plane; the height of the
 * other shapes only enters the luminous size that decides point or area
 * (the largest of width, length and height).  An opening without area (a
 * point, a line) stays a point at every distance.
 */
#include "light/light.h"

#include "photometry/photometry.h"

#include <math.h>
#include <string.h>

enum {
    BATCH = 64,       /* shadow rays handed to the backend at once */
    MAX_DEPTH = 24    /* halvings of the opening: 2^-24 of it, far below any shadow ray's epsilon */
};

/* The distance, in luminous sizes, beyond which a source is a point. */
#define FAR_FACTOR 5.0

typedef struct pending {
    rad_ray rays[BATCH];
    double weight[BATCH]; /* W/m^2 each ray carries when clear */
    size_t count;
    const rad_vis *vis;
    double sum;
} pending;

static void flush(pending *q)
{
    if (q->count == 0)
        return;
    uint8_t blocked[BATCH];
    if (q->vis)
        q->vis->backend->occluded(q->vis->state, q->rays, q->count, blocked);
    else
        memset(blocked, 0, sizeof blocked);
    for (size_t k = 0; k < q->count; k++)
        if (!blocked[k])
            q->sum += q->weight[k];
    q->count = 0;
}

/* A point source of `share` of luminaire L's distribution at `centre`
 * (world), seen from p with normal n: its unshadowed irradiance queued
 * with the shadow ray from p (lifted eps along n) to the centre. */
static void point_source(pending *q, const rad_luminaire *L, const rad_photometry *ph, double share,
                         vec3 centre, vec3 p, vec3 n, double eps)
{
    vec3 to = v3_sub(centre, p);
    double d2 = v3_dot(to, to);
    if (!(d2 > 0.0))
        return;
    double d = sqrt(d2), cos_alpha = v3_dot(n, to) / d;
    if (!(cos_alpha > 0.0))
        return; /* behind the receiver */
    vec3 out = v3_scale(to, -1.0); /* luminaire -> point */
    vec3 local = v3(v3_dot(out, L->axis[0]), v3_dot(out, L->axis[1]), v3_dot(out, L->axis[2]));
    double candela = rad_photometry_intensity(ph, local) * L->multiplier * share;
    if (!(candela > 0.0))
        return;
    double e = candela * cos_alpha / (d2 * RAD_LUMINOUS_EFFICACY);
    vec3 origin = v3_mad(p, n, eps);
    vec3 dir = v3_sub(centre, origin);
    double len = v3_length(dir);
    if (!(len > eps)) {
        /* The centre lies within the shadow rays' tolerance of p: nothing
         * can stand between them. */
        q->sum += e;
        return;
    }
    q->rays[q->count] = (rad_ray){origin, dir, 0.0, 1.0 - eps / len};
    q->weight[q->count] = e;
    if (++q->count == BATCH)
        flush(q);
}

/* A rectangle of the opening, [x0, x1] x [y0, y1] in the luminaire's
 * frame, or an annular sector of the round opening, (r0, r1) x (phi0,
 * phi1) of the unit disk scaled by the half-length and half-width. */
typedef struct piece {
    double a0, a1, b0, b1;
    int depth;
} piece;

static void piece_geometry(bool round, double half_l, double half_w, const piece *s, double *x, double *y,
                           double *area, double *size)
{
    if (!round) {
        *x = 0.5 * (s->a0 + s->a1), *y = 0.5 * (s->b0 + s->b1);
        *area = (s->a1 - s->a0) * (s->b1 - s->b0);
        *size = fmax(s->a1 - s->a0, s->b1 - s->b0);
        return;
    }
    /* Sector of the unit disk: centroid radius 2/3 (r1^3 - r0^3) / (r1^2 -
     * r0^2) x sin(dphi / 2) / (dphi / 2), on the bisector; the ellipse is
     * the disk's affine image, which keeps area shares and centroids. */
    double r0 = s->a0, r1 = s->a1, dphi = s->b1 - s->b0, mid = 0.5 * (s->b0 + s->b1);
    double rc = 2.0 / 3.0 * (r1 * r1 * r1 - r0 * r0 * r0) / (r1 * r1 - r0 * r0);
    rc *= dphi < 1e-12 ? 1.0 : sin(0.5 * dphi) / (0.5 * dphi);
    *x = half_l * rc * cos(mid), *y = half_w * rc * sin(mid);
    *area = 0.5 * (r1 * r1 - r0 * r0) * dphi * half_l * half_w;
    double scale = fmax(half_l, half_w);
    *size = scale * fmax(r1 - r0, fmin(2.0 * r1, r1 * dphi));
}

/* A piece beyond five times its size: four point sources at the 2 x 2
 * Gauss-Legendre points of its parameters (rectangles: x and y; sectors:
 * r^2 and phi, in which the area is uniform), a quarter of its share
 * each.  The midpoint alone errs by O((size / d)^2), up to 2 % at grazing
 * incidence beside the opening; the Gauss points by O((size / d)^4). */
static void leaf(pending *q, const rad_luminaire *L, const rad_photometry *ph, vec3 au, vec3 av, bool round,
                 double half_l, double half_w, const piece *s, double share, vec3 p, vec3 n, double eps)
{
    static const double at[2] = {0.21132486540518711775, 0.78867513459481288225}; /* (1 -+ 1/sqrt 3) / 2 */
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            double x, y;
            if (!round) {
                x = s->a0 + at[i] * (s->a1 - s->a0);
                y = s->b0 + at[j] * (s->b1 - s->b0);
            } else {
                double r2 = s->a0 * s->a0 + at[i] * (s->a1 * s->a1 - s->a0 * s->a0), r = sqrt(r2);
                double phi = s->b0 + at[j] * (s->b1 - s->b0);
                x = half_l * r * cos(phi), y = half_w * r * sin(phi);
            }
            vec3 centre = v3_add(L->position, v3_add(v3_scale(au, x), v3_scale(av, y)));
            point_source(q, L, ph, 0.25 * share, centre, p, n, eps);
        }
}

/* The plane of a luminaire's opening: two of its axes, the extents along
 * them (m) and whether the opening is round (photometry.h's shapes): the
 * horizontal opening, or the bounding box's bottom, for all but the
 * vertical discs, which stand in the y-z or x-z plane. */
typedef struct opening {
    int u, v;             /* indices into rad_luminaire.axis */
    double extent_u, extent_v;
    bool round;
} opening;

static opening opening_of(const rad_photometry *ph)
{
    opening o = {0, 1, ph->length, ph->width, false};
    switch (ph->shape) {
    case RAD_OPENING_ELLIPSE:
    case RAD_OPENING_VERTICAL_CYLINDER:
    case RAD_OPENING_ELLIPSOID: o.round = true; break;
    case RAD_OPENING_VERTICAL_ELLIPSE_X: o = (opening){1, 2, ph->width, ph->height, true}; break;
    case RAD_OPENING_VERTICAL_ELLIPSE_Y: o = (opening){0, 2, ph->length, ph->height, true}; break;
    default: break;
    }
    return o;
}

/* One luminaire's irradiance at p into q. */
static void one_luminaire(pending *q, const rad_scene *scene, const rad_luminaire *L, vec3 p, vec3 n, double eps)
{
    const rad_photometry *ph = scene->luminaires.photometries[L->photometry];
    opening o = opening_of(ph);
    double size = fmax(fmax(ph->length, ph->width), ph->height);
    double d = v3_length(v3_sub(L->position, p));
    if (!(size > 0.0) || d > FAR_FACTOR * size || !(o.extent_u > 0.0) || !(o.extent_v > 0.0)) {
        point_source(q, L, ph, 1.0, L->position, p, n, eps);
        return;
    }
    bool round = o.round;
    double half_l = 0.5 * o.extent_u, half_w = 0.5 * o.extent_v;
    double total = round ? M_PI * half_l * half_w : o.extent_u * o.extent_v;
    vec3 au = L->axis[o.u], av = L->axis[o.v];
    piece stack[4 * MAX_DEPTH + 8];
    size_t top = 0;
    stack[top++] = round ? (piece){0.0, 1.0, 0.0, 2.0 * M_PI, 0} : (piece){-half_l, half_l, -half_w, half_w, 0};
    while (top > 0) {
        piece s = stack[--top];
        double x, y, area, sub;
        piece_geometry(round, half_l, half_w, &s, &x, &y, &area, &sub);
        vec3 centre = v3_add(L->position, v3_add(v3_scale(au, x), v3_scale(av, y)));
        /* The root piece always splits once: the luminous size (with the
         * height) already said it is near. */
        bool near = s.depth == 0 || v3_length(v3_sub(centre, p)) <= FAR_FACTOR * sub;
        if (!near || s.depth >= MAX_DEPTH) {
            leaf(q, L, ph, au, av, round, half_l, half_w, &s, area / total, p, n, eps);
            continue;
        }
        /* Split in two along the longer side (rectangles), or in r and phi
         * (sectors: the first split of the disk cuts it into four quadrants). */
        piece a = s, b = s;
        a.depth = b.depth = s.depth + 1;
        if (!round) {
            if (s.a1 - s.a0 >= s.b1 - s.b0)
                a.a1 = b.a0 = 0.5 * (s.a0 + s.a1);
            else
                a.b1 = b.b0 = 0.5 * (s.b0 + s.b1);
        } else {
            double radial = s.a1 - s.a0, arc = s.a1 * (s.b1 - s.b0);
            if (radial >= arc)
                a.a1 = b.a0 = 0.5 * (s.a0 + s.a1);
            else
                a.b1 = b.b0 = 0.5 * (s.b0 + s.b1);
        }
        stack[top++] = b;
        stack[top++] = a;
    }
}

void rad_luminaires_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                               vec3 n, double out[3])
{
    rad_luminaires_irradiance_among(scene, mesh, vis, p, n, NULL, out);
}

void rad_luminaires_irradiance_among(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                                     vec3 n, const rad_light_among *set, double out[3])
{
    double lift = mesh ? rad_vis_epsilon(mesh) : 0.0;
    pending q;
    q.count = 0;
    q.vis = vis;
    q.sum = 0.0;
    const rad_luminaire *items = scene->luminaires.items;
    if (set && set->list) {
        for (size_t i = 0; i < set->count; i++)
            one_luminaire(&q, scene, &items[set->list[i]], p, n, lift);
    } else {
        const rad_light_reach *reach = set ? set->reach : NULL;
        for (size_t k = 0; k < scene->luminaires.count; k++)
            if (!reach || rad_light_reach_holds(reach, k, p))
                one_luminaire(&q, scene, &items[k], p, n, lift);
    }
    flush(&q);
    out[0] = out[1] = out[2] = q.sum;
}
