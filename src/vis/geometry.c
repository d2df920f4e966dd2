/*
 * geometry.c -- what the ray backends are built from and how far rays
 * start from a surface: the lift (a fixed fraction of the mesh's
 * diagonal), the patches too narrow for it, and the primitives (a patch,
 * or the elements of a patch bent beyond a tenth of the lift).
 */
#include "vis/vis.h"

#include <math.h>
#include <string.h>

double rad_vis_epsilon(const rad_mesh *mesh)
{
    /* An empty or single-point mesh has no scale: take 1 m. */
    return 1e-5 * (mesh->diagonal > 0.0 ? mesh->diagonal : 1.0);
}

uint32_t rad_vis_front_element(const rad_mesh *mesh, const rad_ray *ray, const rad_hit *hit)
{
    if (!isfinite(hit->t))
        return UINT32_MAX;
    const rad_patch *p = &mesh->patches[hit->patch];
    if (v3_dot(ray->direction, p->normal) >= 0.0)
        return UINT32_MAX;
    double s, t, ls, lt;
    rad_patch_parameters(p, v3_mad(ray->origin, ray->direction, hit->t), &s, &t);
    return rad_mesh_locate(mesh, hit->patch, s, t, &ls, &lt);
}

size_t rad_vis_unresolved(const rad_mesh *mesh, double *narrowest, uint32_t *which)
{
    double eps = rad_vis_epsilon(mesh);
    size_t count = 0;
    *narrowest = INFINITY;
    *which = 0;
    for (size_t i = 0; i < mesh->patch_count; i++) {
        double width = rad_corners_width(mesh->patches[i].corner, mesh->patches[i].corner_count);
        if (width < eps) {
            count++;
            if (width < *narrowest) {
                *narrowest = width;
                *which = (uint32_t)i;
            }
        }
    }
    return count;
}

/* Largest distance of a quad's corners from the plane of its first three. */
static double patch_bend(const rad_patch *p)
{
    if (p->corner_count != 4)
        return 0.0;
    return fabs(v3_dot(p->normal, v3_sub(p->corner[3], p->corner[0]))) +
           fabs(v3_dot(p->normal, v3_sub(p->corner[1], p->corner[0]))) +
           fabs(v3_dot(p->normal, v3_sub(p->corner[2], p->corner[0])));
}

rad_result rad_vis_primitives(rad_context *ctx, const rad_mesh *mesh, rad_vis_prim **out,
                              size_t *count)
{
    /* Bent beyond a tenth of the ray offset: use the elements. */
    double limit = 0.1 * rad_vis_epsilon(mesh);
    size_t n = 0;
    for (size_t i = 0; i < mesh->patch_count; i++)
        n += patch_bend(&mesh->patches[i]) > limit ? mesh->patches[i].element_count : 1;
    rad_vis_prim *prims = rad_alloc(ctx, RAD_MEM_VISIBILITY, n ? n : 1, sizeof *prims, "visibility primitives");
    if (!prims)
        return RAD_ERROR_OUT_OF_MEMORY;
    size_t k = 0;
    for (size_t i = 0; i < mesh->patch_count; i++) {
        const rad_patch *p = &mesh->patches[i];
        if (patch_bend(p) > limit) {
            for (uint32_t e = 0; e < p->element_count; e++) {
                const rad_element *el = &mesh->elements[p->first_element + e];
                prims[k].corner_count = el->vertex_count;
                for (uint32_t c = 0; c < el->vertex_count; c++)
                    prims[k].corner[c] = mesh->vertices[el->vertex[c]];
                prims[k++].patch = (uint32_t)i;
            }
        } else {
            prims[k].corner_count = p->corner_count;
            memcpy(prims[k].corner, p->corner, sizeof p->corner);
            prims[k++].patch = (uint32_t)i;
        }
    }
    *out = prims;
    *count = k;
    return RAD_OK;
}
