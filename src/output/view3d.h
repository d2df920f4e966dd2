/*
 * view3d.h -- surface factors for thermal solvers (view3d.c): obstruction
 * surfaces left out, smoothing and sparse thresholds, View3D's .vf file
 * written a header, one row at a time, and a closing line.
 */
#ifndef RAD_OUTPUT_VIEW3D_H
#define RAD_OUTPUT_VIEW3D_H

#include "scene/scene.h"

/* View3D's header line (format 0 text, 1 binary; docs/formats.md) and
 * the areas (m^2).  Fails (RAD_ERROR_INVALID_ARGUMENT) only when n does
 * not fit the 30-character header. */
rad_result rad_view3d_write_header(rad_context *ctx, FILE *f, int format, int enclosure, int emittances,
                                   size_t n, const double *area);
/* Hottel's script-F factors (View3D's emit=1) from view factors F (n x n,
 * in place) and emissivities in (0, 1]: rows then sum to eps_i in an
 * enclosure.  Fails only for memory (F unchanged). */
rad_result rad_vf_script_f(rad_context *ctx, size_t n, const double *emissivity, double *F);
/* One row of factors, F[i][0..n-1].  Cannot fail (errors show at commit). */
void rad_view3d_write_row(FILE *f, int format, const double *row, size_t n);
/* The closing line: the emissivities.  Cannot fail. */
void rad_view3d_write_end(FILE *f, int format, const double *emissivity, size_t n);

/* A surface's emissivity, 1 - rho (red) of its first polygon.  Cannot fail. */
double rad_surface_emissivity(const rad_scene *scene, size_t surface);

/* The surface-level table (names may be NULL; *count surfaces, F row-major
 * count x count) made what the outputs write, in place: obstruction-only
 * surfaces removed (their names freed; kept[a] = the scene surface of row
 * a, *count updated), then with `o` (may be NULL) the sparse threshold and
 * the smoothing.  Fails with RAD_ERROR_INVALID_ARGUMENT when the smoothing
 * cannot meet the sums, RAD_ERROR_OUT_OF_MEMORY. */
rad_result rad_vf_adjust(rad_context *ctx, const rad_scene *scene, char **names, double *area, double *F,
                         size_t *count, size_t *kept, const rad_view_factor_options *o);

#endif /* RAD_OUTPUT_VIEW3D_H */
