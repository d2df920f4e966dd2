/*
 * ff_mirror.c -- extended form factors through ideal mirrors, the first
 * pass of two-pass methods (Wallace, Cohen & Greenberg 1987; Sillion &
 * Puech 1989): light that reaches a diffuse element by way of a planar
 * mirror is gathered from the mirror image of its source.
 *
 *              j (source)          j' = j reflected across the mirror's plane
 *               \                 /
 *                \     mirror    /      F_ij^ext = F_ij + rho_s F_i(j')
 *   ------------- m ---------- plane
 *                /
 *               i (receiver)
 *
 * F_i(j') is the point-to-polygon factor (Lambert's contour formula,
 * rad_point_polygon_ff) from i's centroid to j's reflected polygon (its
 * vertex order reversed: a reflection flips the winding, so the image
 * faces where j's reflection faces), times the fraction of the paths from
 * the centroid to j's sample points that pass through the mirror polygon
 * (their crossing of the plane inside it) and are unoccluded on both legs
 * (centroid -> mirror point, mirror point -> j): 2 x 2 points of j, two
 * rays each.  One reflection: images of images (facing mirrors) are left
 * out.  The factors are added on the scalar F, so a mirror's rho_s is the
 * mean of its channels (exact for grey mirrors).  Cost: per mirror patch,
 * every pair of elements in front of its plane (culled by the image's
 * factor) and eight rays where the image is seen: O(M n^2).
 */
#include "formfactor/formfactor.h"

#include <string.h>

#define MIRROR_SIDE 2 /* sample points of the source per side: 4 paths a pair */

/* Reflect p across the plane through q with unit normal m. */
static vec3 reflect_point(vec3 p, vec3 q, vec3 m)
{
    return v3_mad(p, m, -2.0 * v3_dot(v3_sub(p, q), m));
}

/* Whether x, on the plane of the convex patch, lies inside it. */
static bool inside_patch(const rad_patch *patch, vec3 x)
{
    uint32_t n = patch->corner_count;
    for (uint32_t k = 0; k < n; k++) {
        vec3 a = patch->corner[k], b = patch->corner[(k + 1) % n];
        if (v3_dot(v3_cross(v3_sub(b, a), v3_sub(x, a)), patch->normal) < 0.0)
            return false;
    }
    return true;
}

/* The factor from element i's centroid to element j's image in mirror
 * patch `mirror`, visibility included; counts its rays into *rays. */
static double image_factor(const rad_mesh *mesh, const rad_vis *vis, const rad_patch *mirror, uint32_t i,
                           uint32_t j, double eps, uint64_t *rays)
{
    const rad_element *ei = &mesh->elements[i], *ej = &mesh->elements[j];
    vec3 q = mirror->corner[0], m = mirror->normal;
    vec3 image[4];
    uint32_t n = ej->vertex_count;
    for (uint32_t k = 0; k < n; k++) /* reversed: the reflection flips the winding */
        image[k] = reflect_point(mesh->vertices[ej->vertex[n - 1 - k]], q, m);
    vec3 c = v3_mad(ei->centroid, ei->normal, eps);
    double F = rad_point_polygon_ff(ei->centroid, ei->normal, image, n);
    if (!(F > 0.0))
        return 0.0;
    rad_ray ray[2 * MIRROR_SIDE * MIRROR_SIDE];
    uint8_t blocked[2 * MIRROR_SIDE * MIRROR_SIDE];
    size_t count = 0;
    int through = 0;
    for (int a = 0; a < MIRROR_SIDE; a++)
        for (int b = 0; b < MIRROR_SIDE; b++) {
            vec3 p = rad_element_sample(mesh, ej, (a + 0.5) / MIRROR_SIDE, (b + 0.5) / MIRROR_SIDE);
            vec3 p_image = reflect_point(p, q, m);
            vec3 d = v3_sub(p_image, c);
            double along = v3_dot(d, m);
            if (along == 0.0)
                continue;
            double s = v3_dot(v3_sub(q, c), m) / along;
            if (!(s > 0.0 && s < 1.0))
                continue;
            vec3 x = v3_mad(c, d, s); /* where the path meets the mirror's plane */
            if (!inside_patch(mirror, x))
                continue;
            vec3 legs[2][2] = {{c, x}, {x, v3_mad(p, ej->normal, eps)}};
            for (int l = 0; l < 2; l++) {
                vec3 dir = v3_sub(legs[l][1], legs[l][0]);
                double length = v3_length(dir);
                if (!(length > 2.0 * eps)) { /* a leg shorter than the offsets: nothing between */
                    ray[count] = (rad_ray){legs[l][0], dir, 0.0, 0.0};
                } else {
                    ray[count] = (rad_ray){legs[l][0], dir, l == 1 ? eps / length : 0.0,
                                           1.0 - (l == 0 ? eps : 0.0) / length};
                }
                count++;
            }
            through++;
        }
    if (through == 0)
        return 0.0;
    vis->backend->occluded(vis->state, ray, count, blocked);
    *rays += count;
    int open = 0;
    for (size_t k = 0; k < count; k += 2)
        open += !blocked[k] && !blocked[k + 1];
    return F * (double)open / (double)(MIRROR_SIDE * MIRROR_SIDE);
}

bool rad_mesh_has_mirror(const rad_mesh *mesh, const rad_material *materials)
{
    for (size_t p = 0; p < mesh->patch_count; p++)
        if (materials[mesh->patches[p].material].specular_kind == RAD_SPECULAR_MIRROR)
            return true;
    return false;
}

rad_result rad_ff_mirror_images(rad_context *ctx, const rad_mesh *mesh, const rad_vis *vis,
                                const rad_material *materials, const double *F, double **F_ext_out,
                                rad_ff_mirror_stats *stats)
{
    *F_ext_out = NULL;
    memset(stats, 0, sizeof *stats);
    double t0 = rad_seconds();
    size_t n = mesh->element_count;
    double *F_ext = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, n * n, sizeof *F_ext, "extended form factors");
    if (!F_ext)
        return RAD_ERROR_OUT_OF_MEMORY;
    memcpy(F_ext, F, n * n * sizeof *F_ext);
    double eps = rad_vis_epsilon(mesh), tol = rad_ff_plane_tolerance(mesh);
    int threads = ctx && ctx->threads > 0 ? ctx->threads : 1;
    uint64_t rays = 0, pairs = 0;
    bool cancelled = false;
    for (size_t mp = 0; mp < mesh->patch_count && !cancelled; mp++) {
        const rad_patch *mirror = &mesh->patches[mp];
        const rad_material *mat = &materials[mirror->material];
        if (mat->specular_kind != RAD_SPECULAR_MIRROR)
            continue;
        stats->mirror_patches++;
        double rho_s = (mat->specular[0] + mat->specular[1] + mat->specular[2]) / 3.0;
        vec3 q = mirror->corner[0], m = mirror->normal;
#pragma omp parallel for schedule(dynamic) num_threads(threads) reduction(+ : rays, pairs)
        for (size_t i = 0; i < n; i++) {
            if (rad_cancelled(ctx))
                continue;
            const rad_element *ei = &mesh->elements[i];
            if (!(v3_dot(v3_sub(ei->centroid, q), m) > tol) || mesh->patches[ei->patch].obstruction)
                continue;
            for (size_t j = 0; j < n; j++) {
                const rad_element *ej = &mesh->elements[j];
                if (j == i || !(v3_dot(v3_sub(ej->centroid, q), m) > tol) ||
                    mesh->patches[ej->patch].obstruction)
                    continue;
                pairs++;
                double Fi = image_factor(mesh, vis, mirror, (uint32_t)i, (uint32_t)j, eps, &rays);
                F_ext[i * n + j] += rho_s * Fi;
            }
        }
        cancelled = rad_cancelled(ctx);
    }
    stats->rays = rays;
    stats->pairs = pairs;
    stats->seconds = rad_seconds() - t0;
    if (cancelled) {
        rad_free(F_ext);
        return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "extended form factors: interrupted");
    }
    *F_ext_out = F_ext;
    return RAD_OK;
}
