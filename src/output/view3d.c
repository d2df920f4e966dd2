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

rad_result rad_view3d_write_header(rad_context *ctx, FILE *f, int format, int enclosure, size_t n,
                                   const double *area)
{
    char header[64];
    int len = snprintf(header, sizeof header, "radiosity %s %d %d 0 %zu", RAD_VERSION_STRING, format,
                       enclosure, n);
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
    double *targets = rad_alloc(ctx, RAD_MEM_OUTPUT, n ? n : 1, sizeof *targets, "view factors: targets");
    if (!targets)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < n; i++) {
        double sum = 0.0;
        for (size_t j = 0; j < n; j++)
            sum += F[i * n + j];
        targets[i] = o->smooth == RAD_SMOOTH_ENCLOSURE ? 1.0 : fmax(0.0, fmin(sum, 1.0));
    }
    double dropped = 0.0;
    if (o->sparse_threshold > 0.0) {
        /* A pair goes when both of its factors are below the threshold, so
         * the pattern stays symmetric and reciprocity can hold on it. */
        for (size_t i = 0; i < n; i++) {
            double row = 0.0;
            for (size_t j = 0; j < n; j++)
                if (F[i * n + j] < o->sparse_threshold && F[j * n + i] < o->sparse_threshold)
                    row += F[i * n + j];
            dropped = fmax(dropped, row);
        }
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < n; j++)
                if (F[i * n + j] < o->sparse_threshold && F[j * n + i] < o->sparse_threshold)
                    F[i * n + j] = F[j * n + i] = 0.0;
    }
    rad_smooth_report report;
    rad_result r = rad_ff_smooth(ctx, n, area, F, targets, &report);
    rad_free(targets);
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
