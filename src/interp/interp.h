/*
 * interp.h -- element radiosities to vertex radiosities, for smooth
 * (Gouraud / bilinear) shading.
 *
 * Interior vertex: area-weighted mean of the elements around it.
 * Boundary vertex (on an edge used by one element only): linear
 * extrapolation through the element centre, B_v = 2 * mean(elements) -
 * mean(interior neighbour vertices), the construction of the lecture notes
 * ("Computing Vertex Colors", after Cohen & Wallace 1993, sec. 9.2), clamped
 * to >= 0.  T-vertices (mesh.h) are then set to the interpolation of their
 * edge, so shading is continuous across patches with different grids.
 */
#ifndef RAD_INTERP_H
#define RAD_INTERP_H

#include "mesh/mesh.h"

/* element_value: 3 doubles per element; vertex_value: 3 doubles per mesh
 * vertex (written).  Returns RAD_ERROR_OUT_OF_MEMORY on allocation failure. */
rad_result rad_vertex_values(rad_context *ctx, const rad_mesh *mesh,
                             const double *element_value, double *vertex_value);

/* The smooth value at local element coordinates (s, t) (as returned by
 * rad_patch_locate): bilinear on quads, barycentric on triangles. */
void rad_element_interpolate(const rad_mesh *mesh, const rad_element *e,
                             const double *vertex_value, double s, double t, double rgb[3]);

struct rad_solution_view; /* strategy/strategy.h */

/* Vertex values of a view: the strategy's own (view->vertex_radiosity,
 * copied as they are: Galerkin's linear elements), else rad_vertex_values
 * of element_value (3 per element; the view's radiosity or a display of
 * it).  vertex_value: 3 per mesh vertex.  Fails only for memory. */
rad_result rad_view_vertex_values(rad_context *ctx, const struct rad_solution_view *view, const double *element_value,
                                  double *vertex_value);

#endif /* RAD_INTERP_H */
