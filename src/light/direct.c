/*
 * direct.c -- the scene's direct light (light.h): the sum over its kinds of
 * source at a point, and the mean over an element by adaptive cubature.
 *
 * The mean over a polygon (an element's corners, or a hierarchical node's:
 * triangle or planar quad): the region is integrated with a fixed rule (quads: 2 x 2 Gauss-Legendre on
 * the bilinear map with its Jacobian; triangles: Strang and Fix's 3-point
 * rule of degree 2), then as its four children (rad_ff_split4); where the
 * two disagree by more than REL_TOL of the element's whole estimate the
 * children are integrated alike, down to MAX_DEPTH levels (4^MAX_DEPTH
 * regions at most, each of 3 or 4 points: bounded; shadow edges, where the
 * integrand jumps, are what reach the bottom).  The same order of regions
 * and points whatever the thread: deterministic.  The points' own values
 * also tell how much the light varies over the polygon (their largest
 * difference from the mean), which the hierarchical solver's oracle reads
 * to split nodes along shadows (hier/direct.c).
 */
#include "light/light.h"

#include "formfactor/formfactor.h"

#include <math.h>
#include <string.h>

enum { MAX_DEPTH = 4 };
/* Agreement between a region's estimate and its children's, relative to
 * the element's first estimate: 1e-3 keeps the mean's error near 1e-4 on
 * smooth light (the children's estimate is kept, an order better). */
#define REL_TOL 1e-3

bool rad_light_present(const rad_scene *scene)
{
    return scene && (scene->luminaires.count > 0 || scene->daylight != NULL);
}

void rad_light_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                          vec3 n, double out[3])
{
    rad_light_irradiance_among(scene, mesh, vis, p, n, NULL, out);
}

void rad_light_irradiance_among(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p,
                                vec3 n, const rad_light_among *set, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    if (!rad_light_present(scene))
        return;
    double part[3];
    if (scene->luminaires.count > 0) {
        rad_luminaires_irradiance_among(scene, mesh, vis, p, n, set, part);
        for (int c = 0; c < 3; c++)
            out[c] += part[c];
    }
    if (scene->daylight) {
        rad_daylight_irradiance(scene, mesh, vis, p, n, part);
        for (int c = 0; c < 3; c++)
            out[c] += part[c];
    }
}

typedef struct cubature {
    const rad_scene *scene;
    const rad_mesh *mesh;
    const rad_vis *vis;
    vec3 normal;
    const rad_light_among *set; /* the luminaires let in (NULL: all) */
    double lo[3], hi[3]; /* W/m^2: the range of the values at the points evaluated */
} cubature;

static void light_at(cubature *c, vec3 x, double out[3])
{
    rad_light_irradiance_among(c->scene, c->mesh, c->vis, x, c->normal, c->set, out);
    for (int ch = 0; ch < 3; ch++) {
        c->lo[ch] = fmin(c->lo[ch], out[ch]);
        c->hi[ch] = fmax(c->hi[ch], out[ch]);
    }
}

/* The integral (W per channel) of the irradiance over one region. */
static void region_integral(cubature *c, const vec3 *q, uint32_t corners, double out[3])
{
    double h[3];
    out[0] = out[1] = out[2] = 0.0;
    if (corners == 3) {
        static const double bary[3][2] = {{1.0 / 6.0, 1.0 / 6.0}, {2.0 / 3.0, 1.0 / 6.0}, {1.0 / 6.0, 2.0 / 3.0}};
        double area = 0.5 * v3_length(v3_cross(v3_sub(q[1], q[0]), v3_sub(q[2], q[0])));
        for (int k = 0; k < 3; k++) {
            vec3 x = v3_add(q[0], v3_add(v3_scale(v3_sub(q[1], q[0]), bary[k][0]),
                                         v3_scale(v3_sub(q[2], q[0]), bary[k][1])));
            light_at(c, x, h);
            for (int ch = 0; ch < 3; ch++)
                out[ch] += area / 3.0 * h[ch];
        }
        return;
    }
    static const double at[2] = {0.21132486540518711775, 0.78867513459481288225};
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++) {
            double u = at[a], v = at[b];
            vec3 x = v3_lerp(v3_lerp(q[0], q[1], u), v3_lerp(q[3], q[2], u), v);
            vec3 du = v3_add(v3_scale(v3_sub(q[1], q[0]), 1.0 - v), v3_scale(v3_sub(q[2], q[3]), v));
            vec3 dv = v3_sub(v3_lerp(q[3], q[2], u), v3_lerp(q[0], q[1], u));
            double jacobian = v3_length(v3_cross(du, dv));
            light_at(c, x, h);
            for (int ch = 0; ch < 3; ch++)
                out[ch] += 0.25 * jacobian * h[ch];
        }
}

/* The region's four children by the fixed rule, and their sum. */
static void children_integral(cubature *c, const vec3 *q, uint32_t corners, vec3 sub[4][4], double part[4][3],
                              double fine[3])
{
    rad_ff_split4(q, corners, sub);
    fine[0] = fine[1] = fine[2] = 0.0;
    for (int k = 0; k < 4; k++) {
        region_integral(c, sub[k], corners, part[k]);
        for (int ch = 0; ch < 3; ch++)
            fine[ch] += part[k][ch];
    }
}

/* The integral over a region whose own estimate is `coarse` and whose
 * children's are part[] (sum `fine`): the children's where the two agree
 * within `tol` W, else each child refined alike, to MAX_DEPTH levels. */
static void refine(cubature *c, vec3 sub[4][4], uint32_t corners, const double coarse[3],
                   double part[4][3], const double fine[3], int depth, double tol, double out[3])
{
    double diff = 0.0;
    for (int ch = 0; ch < 3; ch++)
        diff = fmax(diff, fabs(fine[ch] - coarse[ch]));
    if (diff <= tol || depth + 1 >= MAX_DEPTH) {
        memcpy(out, fine, 3 * sizeof *out);
        return;
    }
    out[0] = out[1] = out[2] = 0.0;
    for (int k = 0; k < 4; k++) {
        vec3 grand[4][4];
        double gpart[4][3], gfine[3], r[3];
        children_integral(c, sub[k], corners, grand, gpart, gfine);
        /* A quarter of the region: a quarter of its tolerance. */
        refine(c, grand, corners, part[k], gpart, gfine, depth + 1, 0.25 * tol, r);
        for (int ch = 0; ch < 3; ch++)
            out[ch] += r[ch];
    }
}

static double polygon_area(const vec3 *q, uint32_t corners)
{
    if (corners == 3)
        return 0.5 * v3_length(v3_cross(v3_sub(q[1], q[0]), v3_sub(q[2], q[0])));
    return 0.5 * v3_length(v3_cross(v3_sub(q[2], q[0]), v3_sub(q[3], q[1])));
}

/* mean = total / area; deviation = the points' largest difference from it. */
static void conclude(const rad_light_cubature *cub, const double total[3], double mean[3], double *deviation)
{
    double spread = 0.0;
    for (int ch = 0; ch < 3; ch++) {
        mean[ch] = total[ch] / cub->area;
        spread = fmax(spread, fmax(cub->hi[ch] - mean[ch], mean[ch] - cub->lo[ch]));
    }
    if (deviation)
        *deviation = spread;
}

void rad_light_polygon_start(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis,
                             const vec3 *corner, uint32_t corners, vec3 normal, const rad_light_among *set,
                             rad_light_cubature *cub, double mean[3], double *deviation)
{
    memset(cub, 0, sizeof *cub);
    mean[0] = mean[1] = mean[2] = 0.0;
    if (deviation)
        *deviation = 0.0;
    if (!rad_light_present(scene) || (corners != 3 && corners != 4))
        return;
    /* The region rules integrate over the corners' own area; the mean is
     * over it. */
    double area = polygon_area(corner, corners);
    if (!(area > 0.0))
        return;
    cubature c = {scene, mesh, vis, normal, set, {INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    vec3 sub[4][4];
    double fine[3];
    region_integral(&c, corner, corners, cub->whole);
    children_integral(&c, corner, corners, sub, cub->part, fine);
    cub->area = area;
    memcpy(cub->lo, c.lo, sizeof c.lo);
    memcpy(cub->hi, c.hi, sizeof c.hi);
    conclude(cub, fine, mean, deviation);
}

void rad_light_polygon_finish(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis,
                              const vec3 *corner, uint32_t corners, vec3 normal, const rad_light_among *set,
                              double tolerance, rad_light_cubature *cub, double mean[3], double *deviation)
{
    mean[0] = mean[1] = mean[2] = 0.0;
    if (deviation)
        *deviation = 0.0;
    if (!(cub->area > 0.0))
        return;
    cubature c = {scene, mesh, vis, normal, set, {0}, {0}};
    memcpy(c.lo, cub->lo, sizeof c.lo);
    memcpy(c.hi, cub->hi, sizeof c.hi);
    vec3 sub[4][4];
    rad_ff_split4(corner, corners, sub);
    double fine[3] = {0, 0, 0}, total[3];
    for (int k = 0; k < 4; k++)
        for (int ch = 0; ch < 3; ch++)
            fine[ch] += cub->part[k][ch];
    double scale = fmax(fmax(cub->whole[0], cub->whole[1]), cub->whole[2]);
    refine(&c, sub, corners, cub->whole, cub->part, fine, 0, fmax(REL_TOL * scale, tolerance), total);
    memcpy(cub->lo, c.lo, sizeof c.lo);
    memcpy(cub->hi, c.hi, sizeof c.hi);
    conclude(cub, total, mean, deviation);
}

void rad_light_polygon_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis,
                                  const vec3 *corner, uint32_t corners, vec3 normal,
                                  const rad_light_among *set, double out[3], double *deviation)
{
    rad_light_cubature cub;
    rad_light_polygon_start(scene, mesh, vis, corner, corners, normal, set, &cub, out, deviation);
    rad_light_polygon_finish(scene, mesh, vis, corner, corners, normal, set, 0.0, &cub, out, deviation);
}

void rad_light_element_irradiance(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis,
                                  size_t element, double out[3])
{
    const rad_element *e = &mesh->elements[element];
    out[0] = out[1] = out[2] = 0.0;
    if (!rad_light_present(scene) || !(e->area > 0.0))
        return;
    vec3 q[4];
    for (uint32_t k = 0; k < e->vertex_count && k < 4; k++)
        q[k] = mesh->vertices[e->vertex[k]];
    rad_light_polygon_irradiance(scene, mesh, vis, q, e->vertex_count, e->normal, NULL, out, NULL);
}
