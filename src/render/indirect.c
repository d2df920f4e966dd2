/*
 * indirect.c -- the interreflected light a picture draws smooth, gathered
 * again at each element from the solution's radiosities (render.h):
 *
 *   I(c_i) = sum_j (B_j - E_j) F(c_i -> j) V(c_i, j)      c_i: i's centroid
 *
 * A hierarchical solution's leaves take the irradiance of links made at
 * coarser levels, pushed down unchanged, so a leaf's value can be off by
 * 10-20% where its mean over the surface is right to 1%; as sources, in a
 * sum over all of them, those errors average out, and the gather at each
 * element restores the variation across the receiver (the final gather of
 * Reichert 1992; Lischinski, Tampieri & Greenberg 1993 gather at a
 * receiver's points from the solution's elements).
 *
 * F: Lambert's point-to-polygon factor (Baum, Rushmeier & Winget 1989)
 * within 3 diameters of j, beyond them the point kernel cos cos A / (pi
 * r^2), whose relative error there is below ~1/(4 x 9).  V: per pair of
 * patches, the blockers that may hide anything between them (shaft culling
 * with the blockers' planes, direct.c's may_block): none -> V = 1 exactly;
 * else the segment c_i -> c_j tested against each listed blocker (a point
 * sample of V per source element: sources are small next to the distances
 * that matter for smooth light).  Deterministic: no random numbers.
 */
#include "render/render.h"

#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* Blockers kept per pair of patches; a pair with more is tested by rays. */
enum { PAIR_BLOCKERS = 15 };

typedef struct pair_list {
    uint16_t count;               /* UINT16_MAX: more than PAIR_BLOCKERS (rays) */
    uint16_t blocker[PAIR_BLOCKERS];
} pair_list;

/* Does the segment x -> y cross blocker b (strictly between its ends)? */
static bool segment_hits(const rad_direct_blocker *b, vec3 x, vec3 y, double tol)
{
    double dx = v3_dot(b->normal, x) - b->offset, dy = v3_dot(b->normal, y) - b->offset;
    if (!((dx > tol && dy < -tol) || (dx < -tol && dy > tol)))
        return false;
    vec3 p = v3_lerp(x, y, dx / (dx - dy));
    for (uint32_t e = 0; e < b->corner_count; e++) {
        vec3 a = b->corner[e], c = b->corner[(e + 1) % b->corner_count];
        if (v3_dot(v3_cross(v3_sub(c, a), v3_sub(p, a)), b->normal) < 0.0)
            return false;
    }
    return true;
}

/* What the gather shares. */
typedef struct gather_geometry {
    const rad_direct_light *d;
    const rad_mesh *mesh;
    const pair_list *pairs;       /* P x P */
    size_t P;
    const float *diameter;        /* per element, m */
    const vec3 *point;            /* per element: its centroid lifted off it, m */
} gather_geometry;

/* The factor from element i's point to element j (Lambert's within 3
 * diameters of j, else the point kernel), 0 unless each faces the other. */
static double gather_factor(const gather_geometry *g, size_t i, size_t j)
{
    const rad_mesh *mesh = g->mesh;
    const rad_element *ei = &mesh->elements[i], *ej = &mesh->elements[j];
    double tol = g->d->plane_tol;
    vec3 x = g->point[i], to = v3_sub(ej->centroid, x);
    double cos_i = v3_dot(ei->normal, to), cos_j = -v3_dot(ej->normal, to);
    /* Each in front of the other (within the plane tolerance). */
    if (!(cos_j > tol) || !(v3_dot(ei->normal, v3_sub(ej->centroid, ei->centroid)) > -tol))
        return 0.0;
    double r2 = v3_dot(to, to);
    if (r2 > 9.0 * (double)g->diameter[j] * (double)g->diameter[j])
        return cos_i > 0.0 ? cos_i * cos_j * ej->area / (M_PI * r2 * r2) : 0.0;
    vec3 corner[4];
    for (uint32_t c = 0; c < ej->vertex_count; c++)
        corner[c] = mesh->vertices[ej->vertex[c]];
    return rad_point_polygon_ff(x, ei->normal, corner, ej->vertex_count);
}

/* Does anything hide element j's point from element i's?  (The pair's
 * blockers; rays where there are too many to list.)  Symmetric. */
static bool gather_hidden(const gather_geometry *g, size_t i, size_t j)
{
    const rad_mesh *mesh = g->mesh;
    const pair_list *list = &g->pairs[(size_t)mesh->elements[i].patch * g->P + mesh->elements[j].patch];
    if (list->count == 0)
        return false;
    vec3 x = g->point[i], y = g->point[j];
    if (list->count == UINT16_MAX) {
        rad_ray ray = {x, v3_sub(y, x), 0.0, 1.0};
        uint8_t blocked = 0;
        g->d->vis->backend->occluded(g->d->vis->state, &ray, 1, &blocked);
        return blocked != 0;
    }
    for (int k = 0; k < list->count; k++)
        if (segment_hits(&g->d->blocker[list->blocker[k]], x, y, g->d->plane_tol))
            return true;
    return false;
}

rad_result rad_indirect_residual(rad_context *ctx, const rad_direct_light *d, const double *display,
                                 const double *self, const double *reflectance, const double *direct, int threads,
                                 double *residual, bool *gathered)
{
    *gathered = false;
    const rad_mesh *mesh = d->mesh;
    if (!mesh || !d->blocker || mesh->patch_count > RAD_INDIRECT_MAX_PATCHES ||
        mesh->element_count > RAD_INDIRECT_MAX_ELEMENTS)
        return RAD_OK;
    size_t P = mesh->patch_count, n = mesh->element_count;
    pair_list *pairs = rad_alloc(ctx, RAD_MEM_RENDER, P * P, sizeof *pairs, "render: patch pairs");
    float *diameter = rad_alloc(ctx, RAD_MEM_RENDER, n + 1, sizeof *diameter, "render: element sizes");
    if (!pairs || !diameter) {
        rad_free(pairs);
        rad_free(diameter);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    if (threads < 1)
        threads = 1;
    /* The blockers of each pair of patches (a, b), a <= b, mirrored. */
#pragma omp parallel for num_threads(threads) schedule(dynamic, 4)
    for (size_t a = 0; a < P; a++) {
        const rad_patch *pa = &mesh->patches[a];
        for (size_t b = a; b < P; b++) {
            const rad_patch *pb = &mesh->patches[b];
            vec3 v[8];
            int nv = 0;
            vec3 lo = pa->corner[0], hi = pa->corner[0];
            for (uint32_t c = 0; c < pa->corner_count; c++)
                v[nv++] = pa->corner[c];
            int na = nv;
            for (uint32_t c = 0; c < pb->corner_count; c++)
                v[nv++] = pb->corner[c];
            for (int c = 0; c < nv; c++) {
                lo = v3_min(lo, v[c]);
                hi = v3_max(hi, v[c]);
            }
            pair_list list = {0};
            for (size_t q = 0; q < d->blocker_count; q++) {
                const rad_direct_blocker *bl = &d->blocker[q];
                if (bl->patch == a || bl->patch == b)
                    continue;
                if (!v3_boxes_meet(bl->lo, bl->hi, lo, hi))
                    continue;
                if (!rad_direct_may_block(bl, v, na, nv, d->plane_tol))
                    continue;
                if (list.count == PAIR_BLOCKERS) {
                    list.count = UINT16_MAX;
                    break;
                }
                list.blocker[list.count++] = (uint16_t)q;
            }
            pairs[a * P + b] = pairs[b * P + a] = list;
        }
    }
    vec3 *point = rad_alloc(ctx, RAD_MEM_RENDER, n + 1, sizeof *point, "render: gathering points");
    if (!point) {
        rad_free(pairs);
        rad_free(diameter);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t j = 0; j < n; j++) {
        const rad_element *e = &mesh->elements[j];
        double dm = 0.0;
        for (uint32_t a = 0; a < e->vertex_count; a++)
            for (uint32_t b = a + 1; b < e->vertex_count; b++)
                dm = fmax(dm, v3_length(v3_sub(mesh->vertices[e->vertex[a]], mesh->vertices[e->vertex[b]])));
        diameter[j] = (float)dm;
        point[j] = v3_mad(e->centroid, e->normal, d->eps + rad_element_bend(mesh, e));
    }
    gather_geometry geo = {d, mesh, pairs, P, diameter, point};
    /* With the factors kept (n x n floats within RAD_INDIRECT_DENSE_BYTES),
     * the sources themselves are gathered again first: Jacobi sweeps of
     * B = E + rho (D + direct + F_V (B - E)) from the solution's B, with D
     * the exact mean direct light of each element (direct.c), so that the
     * sources nearest a receiver (the floor in front of a block's face,
     * in the block's penumbra) are no longer the solution's leaves. */
    bool keep = (double)n * (double)n * sizeof(float) <= RAD_INDIRECT_DENSE_BYTES;
    float *FV = keep ? rad_alloc(ctx, RAD_MEM_RENDER, n * n, sizeof *FV, "render: gathering factors") : NULL;
    double *source = rad_alloc(ctx, RAD_MEM_RENDER, 3 * n, sizeof *source, "render: sources");
    double *H = rad_alloc(ctx, RAD_MEM_RENDER, 3 * n, sizeof *H, "render: gathered irradiance");
    double *mean = keep ? rad_alloc(ctx, RAD_MEM_RENDER, 3 * n, sizeof *mean, "render: direct means") : NULL;
    /* Kept factors that cannot be had fail the render: the picture must
     * not depend on the memory at hand. */
    rad_result r = source && H && (!keep || (FV && mean)) ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
    if (r == RAD_OK && FV)
        r = rad_direct_means(ctx, d, threads, mean);
    if (r != RAD_OK)
        goto done;
    for (size_t k = 0; k < 3 * n; k++)
        source[k] = display[k] - self[k];
    if (FV) {
        /* Each pair once (its visibility is one test for both ways); rows
         * written by several threads, each cell by one. */
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16)
        for (size_t i = 0; i < n; i++) {
            FV[i * n + i] = 0.0f;
            for (size_t j = i + 1; j < n; j++) {
                double fij = 0.0, fji = 0.0;
                if (mesh->elements[j].patch != mesh->elements[i].patch) {
                    fij = gather_factor(&geo, i, j);
                    fji = gather_factor(&geo, j, i);
                    if ((fij > 0.0 || fji > 0.0) && gather_hidden(&geo, i, j))
                        fij = fji = 0.0;
                }
                FV[i * n + j] = (float)fmax(fij, 0.0);
                FV[j * n + i] = (float)fmax(fji, 0.0);
            }
        }
    }
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16)
    for (size_t i = 0; i < n; i++) {
        double h[3] = {0.0, 0.0, 0.0};
        const float *row = FV ? FV + i * n : NULL;
        for (size_t j = 0; j < n; j++) {
            double F;
            if (row)
                F = row[j];
            else if (mesh->elements[j].patch == mesh->elements[i].patch ||
                     !((F = gather_factor(&geo, i, j)) > 0.0) || gather_hidden(&geo, i, j))
                continue;
            if (F != 0.0)
                for (int c = 0; c < 3; c++)
                    h[c] += F * source[3 * j + (size_t)c];
        }
        memcpy(&H[3 * i], h, sizeof h);
    }
    for (int sweep = 0; FV && sweep < RAD_INDIRECT_SWEEPS; sweep++) {
        for (size_t j = 0; j < n; j++)
            for (int c = 0; c < 3; c++) {
                size_t at = 3 * j + (size_t)c;
                source[at] = reflectance[at] * (mean[at] + (direct ? direct[at] : 0.0) + H[at]);
            }
#pragma omp parallel for num_threads(threads) schedule(static)
        for (size_t i = 0; i < n; i++) {
            const float *row = FV + i * n;
            double h[3] = {0.0, 0.0, 0.0};
            for (size_t j = 0; j < n; j++)
                if (row[j] != 0.0f)
                    for (int c = 0; c < 3; c++)
                        h[c] += (double)row[j] * source[3 * j + (size_t)c];
            memcpy(&H[3 * i], h, sizeof h);
        }
    }
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            size_t at = 3 * i + (size_t)c;
            residual[at] = self[at] + reflectance[at] * ((direct ? direct[at] : 0.0) + H[at]);
        }
    *gathered = true;
done:
    rad_free(FV);
    rad_free(source);
    rad_free(H);
    rad_free(mean);
    rad_free(pairs);
    rad_free(diameter);
    rad_free(point);
    return r;
}

rad_result rad_render_mesh_create(rad_context *ctx, const rad_scene *scene, const rad_mesh *solved,
                                  double crease_angle_degrees, rad_mesh **out)
{
    *out = NULL;
    if (!solved->tree || solved->patch_count > RAD_INDIRECT_MAX_PATCHES ||
        solved->element_count > RAD_INDIRECT_MAX_ELEMENTS)
        return RAD_OK;
    /* No coarser than the leaves. */
    size_t target = solved->element_count > RAD_RENDER_MESH_ELEMENTS ? solved->element_count : RAD_RENDER_MESH_ELEMENTS;
    rad_mesh_options o = {.target_elements = target, .crease_angle_degrees = crease_angle_degrees};
    rad_mesh *mesh = NULL;
    rad_result r = rad_mesh_build(ctx, scene, &o, &mesh);
    if (r != RAD_OK)
        return r;
    /* The rays meet the solved mesh's patches: the render mesh must have
     * the same ones (it does, both made from the scene's polygons). */
    bool same = mesh->patch_count == solved->patch_count;
    for (size_t p = 0; same && p < mesh->patch_count; p++)
        same = mesh->patches[p].corner_count == solved->patches[p].corner_count &&
               memcmp(mesh->patches[p].corner, solved->patches[p].corner,
                      mesh->patches[p].corner_count * sizeof(vec3)) == 0;
    if (!same) {
        rad_mesh_destroy(mesh);
        return RAD_OK;
    }
    *out = mesh;
    return RAD_OK;
}

void rad_render_mesh_sample(const rad_mesh *solved, const double *vertex_value, const double *per_element[],
                            int arrays, const rad_mesh *mesh, double *value, double *out[])
{
    for (size_t i = 0; i < mesh->element_count; i++) {
        const rad_element *e = &mesh->elements[i];
        const rad_patch *patch = &solved->patches[e->patch];
        double s, t, ls, lt;
        rad_patch_parameters(patch, e->centroid, &s, &t);
        uint32_t j = rad_mesh_locate(solved, e->patch, s, t, &ls, &lt);
        rad_element_interpolate(solved, &solved->elements[j], vertex_value, ls, lt, &value[3 * i]);
        for (int a = 0; a < arrays; a++)
            for (int c = 0; c < 3; c++)
                out[a][3 * i + (size_t)c] = per_element[a] ? per_element[a][3 * (size_t)j + (size_t)c] : 0.0;
    }
}
