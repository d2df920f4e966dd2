/*
 * view3d.c -- surface view factors as thermal solvers take them: the
 * obstruction-only surfaces of a .vs3 left out, enclosure smoothing
 * (formfactor/smooth.c), sparse thresholds rebalanced on the kept pattern,
 * and View3D's view-factor file (.vf).
 *
 * View3D's file (NIST View3D 3.x, SaveVF; docs/formats.md "View3D"):
 *
 *     text (out=0)                          binary (out=1)
 *     "PROGRAM VERSION out encl emit N"     the same 32 bytes (header padded
 *       padded with blanks to 30 + "\n"       to 30, then "\r\n"), then
 *     A_1 ... A_N          (%g)             N float32 areas,
 *     F_11 ... F_1N        (%.6f, N rows)   N x N float32 factors by row,
 *     ...                                   N float32 emissivities
 *     e_1 ... e_N          (%.3f)           (little-endian, as View3D on x86)
 *
 * The header, the rows and the closing line are written by separate calls
 * so a row-streaming writer can emit one row at a time.
 */
#include "output/view3d.h"

#include <string.h>

#include "formfactor/formfactor.h"

rad_result rad_view3d_write_header(rad_context *ctx, FILE *f, int format, int enclosure, int emittances,
                                   size_t n, const double *area)
{
    char header[64];
    int len = snprintf(header, sizeof header, "radiosity %s %d %d %d %zu", RAD_VERSION_STRING, format,
                       enclosure, emittances, n);
    /* View3D's readers take the first line with fgets(35): it must fit. */
    if (len < 0 || len > 30)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "View3D file: %zu surfaces do not fit its header", n);
    memset(header + len, ' ', (size_t)(30 - len));
    if (format == 0) {
        header[30] = '\n';
        fwrite(header, 1, 31, f);
        for (size_t i = 0; i < n; i++)
            fprintf(f, i ? " %g" : "%g", area[i]);
        fputc('\n', f);
    } else {
        header[30] = '\r';
        header[31] = '\n';
        fwrite(header, 1, 32, f);
        for (size_t i = 0; i < n; i++) {
            float v = (float)area[i];
            fwrite(&v, sizeof v, 1, f);
        }
    }
    return RAD_OK;
}

void rad_view3d_write_row(FILE *f, int format, const double *row, size_t n)
{
    for (size_t j = 0; j < n; j++) {
        if (format == 0) {
            fprintf(f, j ? " %.6f" : "%.6f", row[j]);
        } else {
            float v = (float)row[j];
            fwrite(&v, sizeof v, 1, f);
        }
    }
    if (format == 0)
        fputc('\n', f);
}

void rad_view3d_write_end(FILE *f, int format, const double *emissivity, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (format == 0) {
            fprintf(f, i ? " %.3f" : "%.3f", emissivity[i]);
        } else {
            float v = (float)emissivity[i];
            fwrite(&v, sizeof v, 1, f);
        }
    }
    if (format == 0)
        fputc('\n', f);
}

rad_result rad_vf_script_f(rad_context *ctx, size_t n, const double *emissivity, double *F)
{
    /* Radiosity of a grey diffuse enclosure, J = eps E + rho F J, gives the
     * power emitted by i and absorbed by j per unit black-body exitance:
     * A_i SF_ij = A_i eps_i [F (I - rho F)^-1]_ij eps_j (Hottel & Sarofim
     * 1967, total exchange areas).  M = I - rho F is inverted by Gauss-Jordan
     * with partial pivoting; rho < 1 keeps it regular (F rows sum <= 1). */
    double *M = rad_alloc(ctx, RAD_MEM_OUTPUT, n ? n * n : 1, sizeof *M, "script-F: system");
    double *X = M ? rad_alloc(ctx, RAD_MEM_OUTPUT, n ? n * n : 1, sizeof *X, "script-F: inverse") : NULL;
    double *row = X ? rad_alloc(ctx, RAD_MEM_OUTPUT, n ? n : 1, sizeof *row, "script-F: row") : NULL;
    if (!row) {
        rad_free(M);
        rad_free(X);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++) {
            M[i * n + j] = (i == j ? 1.0 : 0.0) - (1.0 - emissivity[i]) * F[i * n + j];
            X[i * n + j] = i == j ? 1.0 : 0.0;
        }
    for (size_t k = 0; k < n; k++) {
        size_t p = k;
        for (size_t i = k + 1; i < n; i++)
            if (fabs(M[i * n + k]) > fabs(M[p * n + k]))
                p = i;
        for (size_t j = 0; j < n && p != k; j++) {
            double t = M[k * n + j];
            M[k * n + j] = M[p * n + j];
            M[p * n + j] = t;
            t = X[k * n + j];
            X[k * n + j] = X[p * n + j];
            X[p * n + j] = t;
        }
        double pivot = M[k * n + k];
        for (size_t j = 0; j < n; j++) {
            M[k * n + j] /= pivot;
            X[k * n + j] /= pivot;
        }
        for (size_t i = 0; i < n; i++) {
            double f = M[i * n + k];
            if (i == k || f == 0.0)
                continue;
            for (size_t j = 0; j < n; j++) {
                M[i * n + j] -= f * M[k * n + j];
                X[i * n + j] -= f * X[k * n + j];
            }
        }
    }
    for (size_t i = 0; i < n; i++) {
        for (size_t j = 0; j < n; j++) {
            double v = 0.0;
            for (size_t k = 0; k < n; k++)
                v += F[i * n + k] * X[k * n + j];
            row[j] = emissivity[i] * v * emissivity[j];
        }
        memcpy(F + i * n, row, n * sizeof *row);
    }
    rad_free(M);
    rad_free(X);
    rad_free(row);
    return RAD_OK;
}

double rad_surface_emissivity(const rad_scene *scene, size_t surface)
{
    for (size_t p = 0; p < scene->polygon_count; p++)
        if (scene->polygons[p].surface == surface)
            return 1.0 - scene->materials[scene->polygons[p].material].reflectance[0];
    return 1.0;
}

rad_result rad_vf_adjust(rad_context *ctx, const rad_scene *scene, char **names, double *area, double *F,
                         size_t *count, size_t *kept, const rad_view_factor_options *o)
{
    size_t S = *count, n = 0;
    /* View3D's masks (its View3D() and post-processing): the mask's row is 1
     * to its base and 0 elsewhere, nothing else sees it; the base is
     * reported with its whole area, its rows those of the part the mask
     * leaves open (the engine's base has a hole there) scaled by that part's
     * share, plus A_mask / A_base to the mask.  Several masks on one base,
     * one after the other. */
    for (size_t m = 0; m < S; m++) {
        if (!scene->surfaces[m].mask)
            continue;
        size_t b = scene->surfaces[m].mask_base;
        double whole = area[b] + area[m], share = area[b] / whole;
        for (size_t j = 0; j < S; j++) {
            F[b * S + j] *= share;
            F[m * S + j] = 0.0;
            F[j * S + m] = 0.0;
        }
        F[b * S + m] = area[m] / whole;
        F[m * S + b] = 1.0;
        area[b] = whole;
    }
    /* Obstruction-only surfaces out; the rows and columns of the others kept. */
    for (size_t i = 0; i < S; i++)
        if (!scene->surfaces[i].obstruction)
            kept[n++] = i;
        else if (names) {
            rad_free(names[i]);
            names[i] = NULL;
        }
    for (size_t a = 0; a < n; a++) {
        if (names)
            names[a] = names[kept[a]];
        area[a] = area[kept[a]];
        for (size_t b = 0; b < n; b++)
            F[a * n + b] = F[kept[a] * S + kept[b]];
    }
    *count = n;
    if (!o || (o->smooth == RAD_SMOOTH_NONE && !(o->sparse_threshold > 0.0)))
        return RAD_OK;
    rad_smooth_report report;
    double dropped = 0.0;
    rad_result r = rad_ff_smooth(ctx, n, area, F, o->smooth == RAD_SMOOTH_ENCLOSURE, o->sparse_threshold, &dropped,
                                 &report);
    if (r != RAD_OK && o->sparse_threshold > 0.0) {
        char why[400];
        snprintf(why, sizeof why, "%s", rad_context_error(ctx));
        return rad_fail(ctx, r, "sparse threshold %g: %s; use a lower threshold", o->sparse_threshold, why);
    }
    if (r != RAD_OK)
        return r;
    if (o->report)
        *o->report = report;
    if (o->dropped)
        *o->dropped = dropped;
    return RAD_OK;
}
