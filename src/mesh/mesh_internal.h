/*
 * mesh_internal.h -- what the files of the mesh module share, and nothing
 * outside it uses:
 *
 *    scene polygons --patch.c--> patches --grid.c--> elements + raw grid points
 *                   --weld.c--> welded vertices, T-vertices   (mesh.c drives)
 */
#ifndef RAD_MESH_INTERNAL_H
#define RAD_MESH_INTERNAL_H

#include "mesh/mesh.h"

/* A grid point (or leaf corner) before welding. */
typedef struct raw_vertex {
    vec3 position;           /* m */
    uint32_t patch;
} raw_vertex;

/* An entry of the weld and T-vertex tables: items hashed by cell, sorted
 * by key (weld.c).  Here for the memory estimate (mesh.c). */
typedef struct cell_entry {
    uint64_t key;
    uint32_t item;
} cell_entry;

/* ---- patch.c ---- */

/* The scene's polygons as patches: convex quads and triangles, triangle
 * pairs merged into quads, cut along contact lines (conform.c), which go
 * to mesh->contacts.  Fills mesh->patches (NULL when there are none),
 * patch_count, contacts, contact_count and contact_tol.  Fails for memory,
 * or for a polygon that cannot be triangulated (message names it); then
 * those fields are left empty. */
rad_result mesh_patches_from_polygons(rad_context *ctx, const rad_scene *scene, rad_mesh *mesh);

/* ---- conform.c ---- */

/* Split the patches along their contact lines: where another patch
 * crosses or touches a patch's plane (within tol, m) inside it.  Replaces
 * *patches (each patch by its pieces, in order) and sets *cut_patches to
 * the number of patches split; *contacts (malloc'd, the caller's; NULL
 * when none) gets the lines, sorted by polygon.  Fails for memory or cancellation (then
 * *patches is unchanged). */
rad_result mesh_conform_patches(rad_context *ctx, double tol, rad_patch **patches, size_t *count,
                                size_t *cut_patches, rad_contact **contacts, size_t *contact_count);

/* ---- grid.c ---- */

/* Size every patch's grid (nu, nv, element_count) for edge length h (m);
 * returns the total element count.  Cannot fail. */
double mesh_count_elements(rad_patch *patches, size_t count, double h);

/* The edge length h (m) whose grids come closest to `target` elements over
 * patches of total_area (m^2).  Leaves the patches sized for some trial
 * h: call mesh_count_elements with the result.  Cannot fail. */
double mesh_size_for_target(rad_patch *patches, size_t count, double total_area, double target);

/* Number of grid points of a sized patch. */
uint32_t mesh_patch_point_count(const rad_patch *p);

/* Fill mesh->elements (vertex indices into `raw`, patch, surface,
 * material; not the geometry) and `raw` (the patches' grid points, patch
 * by patch), and each patch's first_element.  The patches must be sized and
 * the arrays hold element_count elements and sum mesh_patch_point_count
 * points.  Cannot fail. */
void mesh_grid_fill(rad_mesh *mesh, raw_vertex *raw);

/* ---- weld.c ---- */

/* The weld distance (m) for the sized patches of `mesh` in a scene of
 * diagonal `diag` (m).  Cannot fail. */
double mesh_weld_tolerance(const rad_mesh *mesh, double diag);

/* Weld the nraw raw points: points within `tol` of each other, on one
 * surface, whose patch normals are within the crease (cos_crease) become
 * one vertex.  Writes weld_of[raw] = vertex index, and *positions (malloc'd,
 * the caller's) with *count vertices.  Fails only for memory. */
rad_result mesh_weld(rad_context *ctx, const rad_mesh *mesh, const raw_vertex *raw, size_t nraw,
                     double tol, double cos_crease, uint32_t *weld_of, vec3 **positions,
                     size_t *count);

/* Record in mesh->tvertices the welded vertices lying (within `tol`) inside
 * a boundary edge of an element of their surface whose normal is within
 * the crease (cos_crease) of theirs; `h` (m) is the search grid's cell
 * size.  Fails only for memory. */
rad_result mesh_find_tvertices(rad_context *ctx, rad_mesh *mesh, double tol, double h, double cos_crease);

#endif /* RAD_MESH_INTERNAL_H */
