/*
 * mesh.c -- the mesh as a whole: scene polygons -> patches (patch.c) ->
 * structured grids of elements (grid.c) -> vertices welded across patches
 * of one surface, T-vertices recorded (weld.c); the memory estimate made
 * before anything large is allocated; the mesh of a hierarchical
 * solution's leaves; element geometry and sampling.
 */
#include "mesh/mesh_internal.h"

#include <stdlib.h>
#include <string.h>

vec3 rad_corners_sample(const vec3 *corner, uint32_t count, double u, double v)
{
    if (count == 3) {
        if (u + v > 1.0) {
            u = 1.0 - u;
            v = 1.0 - v;
        }
        vec3 a = corner[0];
        return v3_add(a, v3_add(v3_scale(v3_sub(corner[1], a), u), v3_scale(v3_sub(corner[2], a), v)));
    }
    return v3_lerp(v3_lerp(corner[0], corner[1], u), v3_lerp(corner[3], corner[2], u), v);
}

double rad_corners_sample_weight(const vec3 *corner, uint32_t count, double area, double u, double v)
{
    if (count != 4 || !(area > 0.0))
        return 1.0;
    vec3 p0 = corner[0], p1 = corner[1], p2 = corner[2], p3 = corner[3];
    /* x(u, v) = lerp(lerp(p0, p1, u), lerp(p3, p2, u), v), as rad_corners_sample. */
    vec3 du = v3_add(v3_scale(v3_sub(p1, p0), 1.0 - v), v3_scale(v3_sub(p2, p3), v));
    vec3 dv = v3_sub(v3_lerp(p3, p2, u), v3_lerp(p0, p1, u));
    return v3_length(v3_cross(du, dv)) / area;
}

/* The element's corners as its welded vertices. */
static uint32_t element_corners(const rad_mesh *mesh, const rad_element *e, vec3 corner[4])
{
    for (uint32_t k = 0; k < e->vertex_count && k < 4; k++)
        corner[k] = mesh->vertices[e->vertex[k]];
    return e->vertex_count;
}

vec3 rad_element_sample(const rad_mesh *mesh, const rad_element *e, double u, double v)
{
    vec3 corner[4];
    return rad_corners_sample(corner, element_corners(mesh, e, corner), u, v);
}

double rad_element_sample_weight(const rad_mesh *mesh, const rad_element *e, double u, double v)
{
    vec3 corner[4];
    return rad_corners_sample_weight(corner, element_corners(mesh, e, corner), e->area, u, v);
}

void rad_texture_mean(const rad_scene *scene, uint32_t polygon, const vec3 *corner, uint32_t count, double area,
                      double rgb[3])
{
    if (!rad_scene_textured(scene, polygon))
        return;
    const rad_texture *t = &scene->textures[scene->materials[scene->polygons[polygon].material].texture - 1];
    double lo_u = INFINITY, hi_u = -INFINITY, lo_v = INFINITY, hi_v = -INFINITY;
    for (uint32_t k = 0; k < count; k++) {
        double u, v;
        if (!rad_scene_uv(scene, polygon, corner[k], &u, &v))
            return;
        lo_u = fmin(lo_u, u), hi_u = fmax(hi_u, u), lo_v = fmin(lo_v, v), hi_v = fmax(hi_v, v);
    }
    double span = fmax((hi_u - lo_u) * t->width, (hi_v - lo_v) * t->height);
    int side = (int)fmin(64.0, fmax(4.0, ceil(2.0 * span)));
    double sum[3] = {0, 0, 0}, weights = 0.0;
    for (int a = 0; a < side; a++)
        for (int b = 0; b < side; b++) {
            double u = (a + 0.5) / side, v = (b + 0.5) / side;
            double w = rad_corners_sample_weight(corner, count, area, u, v);
            double texel[3];
            rad_scene_reflectance_at(scene, polygon, rad_corners_sample(corner, count, u, v), texel);
            for (int c = 0; c < 3; c++)
                sum[c] += w * texel[c];
            weights += w;
        }
    for (int c = 0; c < 3; c++)
        rgb[c] = weights > 0.0 ? sum[c] / weights : rgb[c];
}

/* Area, normal and centroid of an element from its own corners: the grid
 * points of its patch before welding, so that the elements of a polygon
 * tile it exactly whatever welding moved (a vertex welded 1e-5 m away, in
 * a scene whose weld distance was 4e-5 m, left a wall's elements with
 * 9e-6 more area than the wall: fuzz_obj). */
static void element_geometry(rad_element *e, const vec3 corner[4])
{
    vec3 a = corner[0], b = corner[1], c = corner[2];
    if (e->vertex_count == 3) {
        vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
        e->area = 0.5 * v3_length(n);
        e->normal = v3_normalize(n);
        e->centroid = v3_scale(v3_add(a, v3_add(b, c)), 1.0 / 3.0);
        return;
    }
    vec3 d = corner[3];
    vec3 n1 = v3_cross(v3_sub(b, a), v3_sub(c, a)), n2 = v3_cross(v3_sub(c, a), v3_sub(d, a));
    double a1 = 0.5 * v3_length(n1), a2 = 0.5 * v3_length(n2);
    e->area = a1 + a2;
    e->normal = v3_normalize(v3_add(n1, n2));
    vec3 c1 = v3_scale(v3_add(a, v3_add(b, c)), 1.0 / 3.0);
    vec3 c2 = v3_scale(v3_add(a, v3_add(c, d)), 1.0 / 3.0);
    e->centroid = e->area > 0.0 ? v3_scale(v3_add(v3_scale(c1, a1), v3_scale(c2, a2)), 1.0 / e->area)
                                : c1;
}

/* Each element's corners from the grid points or leaf corners it was made
 * of (raw), its vertex indices then made the welded ones; returns the
 * elements' total area, m^2.  Cannot fail. */
static double weld_elements(rad_mesh *mesh, const raw_vertex *raw, const uint32_t *weld_of)
{
    double area = 0.0;
    for (size_t i = 0; i < mesh->element_count; i++) {
        rad_element *e = &mesh->elements[i];
        vec3 corner[4] = {{0}}; /* 3 or 4 set: the vertex counts are 3 or 4 */
        for (uint32_t c = 0; c < e->vertex_count; c++) {
            corner[c] = raw[e->vertex[c]].position;
            e->vertex[c] = weld_of[e->vertex[c]];
        }
        element_geometry(e, corner);
        area += e->area;
    }
    return area;
}

/* The end of a build that got as far as welding: the scratch freed, and
 * the mesh measured (rad_mesh_measure) into *out, or destroyed when r is a
 * failure. */
static rad_result build_done(rad_result r, rad_mesh *mesh, raw_vertex *raw, uint32_t *weld_of, rad_mesh **out)
{
    rad_free(raw);
    rad_free(weld_of);
    if (r != RAD_OK) {
        rad_mesh_destroy(mesh);
        return r;
    }
    rad_mesh_measure(mesh);
    *out = mesh;
    return RAD_OK;
}

rad_result rad_mesh_build(rad_context *ctx, const rad_scene *scene, const rad_mesh_options *opt,
                          rad_mesh **out)
{
    return rad_mesh_build_within(ctx, scene, opt, 0.0, out);
}

rad_result rad_mesh_build_within(rad_context *ctx, const rad_scene *scene,
                                 const rad_mesh_options *opt, double max_memory_bytes,
                                 rad_mesh **out)
{
    *out = NULL;
    rad_mesh_options o = opt ? *opt : (rad_mesh_options){0};
    if (!(o.mesh_size >= 0.0) || !isfinite(o.mesh_size))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "rad_options.mesh_size must be a positive length in metres");
    if (o.target_elements == 0)
        o.target_elements = 2000;
    if (o.crease_angle_degrees == 0.0)
        o.crease_angle_degrees = 30.0;
    if (!(o.crease_angle_degrees > 0.0 && o.crease_angle_degrees <= 180.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "crease angle must be in (0, 180] degrees");

    rad_mesh *mesh = rad_alloc(ctx, RAD_MEM_MESH, 1, sizeof *mesh, "mesh");
    if (!mesh)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = mesh_patches_from_polygons(ctx, scene, mesh);
    if (r != RAD_OK) {
        rad_free(mesh);
        return r;
    }

    /* An obstruction-only surface (View3D 'O') or mask ('M') blocks rays
     * through its patches; its factors are not wanted (a mask's are set:
     * output/view3d.c), so each patch is one element. */
    for (size_t i = 0; i < mesh->patch_count; i++) {
        const rad_surface *surface = &scene->surfaces[mesh->patches[i].surface];
        mesh->patches[i].obstruction = surface->obstruction || surface->mask;
    }
    double total_area = 0.0;
    for (size_t i = 0; i < scene->polygon_count; i++) {
        const rad_surface *surface = &scene->surfaces[scene->polygons[i].surface];
        if (!surface->obstruction && !surface->mask)
            total_area += scene->polygons[i].area;
    }
    double h = o.mesh_size > 0.0 ? o.mesh_size
                                 : mesh_size_for_target(mesh->patches, mesh->patch_count,
                                                        total_area, (double)o.target_elements);
    double nelem = mesh_count_elements(mesh->patches, mesh->patch_count, h);
    if (nelem > (double)UINT32_MAX / 4) {
        rad_mesh_destroy(mesh);
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "mesh: %.3g elements exceed the limit of %u; use a larger rad_options.mesh_size",
                        nelem, UINT32_MAX / 4);
    }
    mesh->mesh_size = h;

    /* Elements and raw grid points, patch by patch.  The estimate counts
     * the elements, the raw grid points with their weld tables, and the
     * edge tables of the T-vertex search (4 edges of 2 x 16 bytes per
     * element), which all exist at once. */
    size_t nraw = 0;
    for (size_t i = 0; i < mesh->patch_count; i++)
        nraw += mesh_patch_point_count(&mesh->patches[i]);
    double bytes = nelem * ((double)sizeof(rad_element) + 4.0 * 32.0) +
                   (double)nraw * (double)(sizeof(raw_vertex) + sizeof(uint32_t) +
                                           sizeof(cell_entry) + sizeof(vec3));
    if (max_memory_bytes > 0.0 && bytes > max_memory_bytes) {
        rad_mesh_destroy(mesh);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                        "mesh: %.0f elements need about %.2f GiB, above the memory limit of "
                        "%.2f GiB (rad_options.max_memory_bytes); use a larger rad_options.mesh_size or fewer "
                        "rad_options.target_elements",
                        nelem, bytes / 1073741824.0, max_memory_bytes / 1073741824.0);
    }
    mesh->element_count = (size_t)nelem;
    mesh->elements = rad_alloc(ctx, RAD_MEM_MESH, mesh->element_count, sizeof *mesh->elements, "mesh: elements");
    raw_vertex *raw = rad_alloc(ctx, RAD_MEM_MESH, nraw, sizeof *raw, "mesh: grid points");
    uint32_t *weld_of = rad_alloc(ctx, RAD_MEM_MESH, nraw, sizeof *weld_of, "mesh: grid points");
    if (!mesh->elements || !raw || !weld_of) {
        rad_free(raw);
        rad_free(weld_of);
        rad_mesh_destroy(mesh);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    mesh_grid_fill(mesh, raw);

    double diag = rad_scene_diagonal(scene);
    double tol = mesh_weld_tolerance(mesh, diag > 0.0 ? diag : 1.0);
    r = mesh_weld(ctx, mesh, raw, nraw, tol, cos(o.crease_angle_degrees * M_PI / 180.0), weld_of,
                  &mesh->vertices, &mesh->vertex_count);
    if (r == RAD_OK) {
        weld_elements(mesh, raw, weld_of);
        /* The search grid: the edge length, or the typical element size
         * where that is smaller (a hierarchical base mesh asks for one
         * element per patch with an infinite edge length; one cell would
         * make the search quadratic). */
        double typical = mesh->element_count ? sqrt(total_area / (double)mesh->element_count) : h;
        double hg = fmax(fmin(h, typical), 10.0 * tol);
        r = mesh_find_tvertices(ctx, mesh, tol, hg, cos(o.crease_angle_degrees * M_PI / 180.0));
    }
    return build_done(r, mesh, raw, weld_of, out);
}

rad_result rad_mesh_from_leaves(rad_context *ctx, const rad_scene *scene, const rad_mesh *base,
                                const rad_mesh_leaf *leaves, size_t leaf_count, const uint32_t *tree,
                                size_t tree_count, const uint32_t *patch_root, double crease,
                                rad_mesh **out)
{
    *out = NULL;
    if (crease == 0.0)
        crease = 30.0;
    if (leaf_count >= RAD_TREE_LEAF || tree_count >= RAD_TREE_LEAF)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "mesh: %zu leaves exceed the limit of %u",
                        leaf_count, RAD_TREE_LEAF - 1);
    rad_mesh *mesh = rad_alloc(ctx, RAD_MEM_MESH, 1, sizeof *mesh, "mesh");
    if (!mesh)
        return RAD_ERROR_OUT_OF_MEMORY;
    size_t nraw = 0;
    for (size_t i = 0; i < leaf_count; i++)
        nraw += leaves[i].corner_count;
    mesh->patch_count = base->patch_count;
    mesh->patches = rad_alloc(ctx, RAD_MEM_MESH, base->patch_count, sizeof *mesh->patches, "mesh: patches");
    mesh->elements = rad_alloc(ctx, RAD_MEM_MESH, leaf_count ? leaf_count : 1, sizeof *mesh->elements,
                                     "mesh: elements");
    mesh->tree = rad_alloc(ctx, RAD_MEM_MESH, 4 * tree_count + 1, sizeof *mesh->tree, "mesh: quadtree");
    raw_vertex *raw = rad_alloc(ctx, RAD_MEM_MESH, nraw ? nraw : 1, sizeof *raw, "mesh: leaf corners");
    uint32_t *weld_of = rad_alloc(ctx, RAD_MEM_MESH, nraw ? nraw : 1, sizeof *weld_of, "mesh: leaf corners");
    if (!mesh->patches || !mesh->elements || !mesh->tree || !raw || !weld_of) {
        rad_free(raw);
        rad_free(weld_of);
        rad_mesh_destroy(mesh);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memcpy(mesh->patches, base->patches, base->patch_count * sizeof *mesh->patches);
    if (base->contact_count) {
        mesh->contacts = rad_alloc(ctx, RAD_MEM_MESH, base->contact_count, sizeof *mesh->contacts, "mesh: contact lines");
        if (!mesh->contacts) {
            rad_free(raw);
            rad_free(weld_of);
            rad_mesh_destroy(mesh);
            return RAD_ERROR_OUT_OF_MEMORY;
        }
        memcpy(mesh->contacts, base->contacts, base->contact_count * sizeof *mesh->contacts);
        mesh->contact_count = base->contact_count;
    }
    mesh->contact_tol = base->contact_tol;
    memcpy(mesh->tree, tree, 4 * tree_count * sizeof *mesh->tree);
    mesh->tree_count = tree_count;
    mesh->element_count = leaf_count;
    for (size_t p = 0; p < mesh->patch_count; p++) {
        mesh->patches[p].tree_root = patch_root[p];
        mesh->patches[p].element_count = 0;
        mesh->patches[p].first_element = 0;
    }
    size_t k = 0;
    for (size_t i = 0; i < leaf_count; i++) {
        const rad_mesh_leaf *l = &leaves[i];
        rad_patch *p = &mesh->patches[l->patch];
        if (p->element_count++ == 0)
            p->first_element = (uint32_t)i;
        rad_element *e = &mesh->elements[i];
        e->patch = l->patch;
        e->surface = p->surface;
        e->material = p->material;
        e->vertex_count = l->corner_count;
        for (uint32_t c = 0; c < l->corner_count; c++) {
            raw[k].position = l->corner[c];
            raw[k].patch = l->patch;
            e->vertex[c] = (uint32_t)k++;
        }
    }
    /* The rule of mesh_weld_tolerance, on the leaves themselves: 1e-6 of
     * the scene, but under 1e-3 of the narrowest leaf, so a 1 mm lamp
     * over a 2 km floor keeps its corners apart (they were welded into
     * one point at 1e-6 x 2.8 km: the lamp had no area and emitted 0). */
    double diag = rad_scene_diagonal(scene);
    double tol = 1e-6 * (diag > 0.0 ? diag : 1.0);
    for (size_t i = 0; i < leaf_count; i++) {
        const rad_mesh_leaf *l = &leaves[i];
        double width = rad_corners_width(l->corner, l->corner_count);
        if (width > 0.0 && 1e-3 * width < tol)
            tol = 1e-3 * width;
    }
    rad_result r = mesh_weld(ctx, mesh, raw, nraw, tol, cos(crease * M_PI / 180.0), weld_of,
                             &mesh->vertices, &mesh->vertex_count);
    if (r == RAD_OK) {
        double area = weld_elements(mesh, raw, weld_of);
        /* The T-vertex search grid: about the typical leaf size. */
        double h = leaf_count ? sqrt(area / (double)leaf_count) : 1.0;
        mesh->mesh_size = h;
        r = mesh_find_tvertices(ctx, mesh, tol, h > tol ? h : tol, cos(crease * M_PI / 180.0));
    }
    return build_done(r, mesh, raw, weld_of, out);
}

void rad_mesh_measure(rad_mesh *mesh)
{
    vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
    for (size_t i = 0; i < mesh->vertex_count; i++) {
        lo = v3_min(lo, mesh->vertices[i]);
        hi = v3_max(hi, mesh->vertices[i]);
    }
    for (size_t i = 0; i < mesh->patch_count; i++)
        for (uint32_t c = 0; c < mesh->patches[i].corner_count; c++) {
            lo = v3_min(lo, mesh->patches[i].corner[c]);
            hi = v3_max(hi, mesh->patches[i].corner[c]);
        }
    double diagonal = v3_length(v3_sub(hi, lo));
    mesh->diagonal = diagonal > 0.0 && isfinite(diagonal) ? diagonal : 0.0; /* empty: -inf..inf */
}

void rad_mesh_destroy(rad_mesh *mesh)
{
    if (!mesh)
        return;
    rad_free(mesh->patches);
    rad_free(mesh->elements);
    rad_free(mesh->vertices);
    rad_free(mesh->tvertices);
    rad_free(mesh->tree);
    rad_free(mesh->contacts);
    rad_free(mesh);
}

