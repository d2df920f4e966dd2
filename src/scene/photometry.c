/*
 * photometry.c -- the intensity table of a luminaire: construction,
 * bilinear evaluation over (C, gamma), the flux integral, the tilt factor.
 * The file readers (IES LM-63, EULUMDAT) fill the same table.
 */
#include "scene/photometry.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double DEG = 3.14159265358979323846 / 180.0;

void rad_photometry_free(rad_photometry *p)
{
    if (!p)
        return;
    rad_free(p->source);
    rad_free(p->label);
    rad_free(p->c_angles);
    rad_free(p->gamma_angles);
    rad_free(p->candela);
    rad_free(p->tilt_angles);
    rad_free(p->tilt_factors);
    rad_free(p);
}

/* Index k with a[k] <= x <= a[k + 1] in an increasing array, and the
 * weight of a[k + 1]. */
static size_t bracket(const double *a, size_t n, double x, double *t)
{
    if (n < 2 || x <= a[0]) {
        *t = 0.0;
        return 0;
    }
    if (x >= a[n - 1]) {
        *t = 1.0;
        return n - 2;
    }
    size_t lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (a[mid] <= x)
            lo = mid;
        else
            hi = mid;
    }
    double span = a[lo + 1] - a[lo];
    *t = span > 0.0 ? (x - a[lo]) / span : 0.0;
    return lo;
}

static double column(const rad_photometry *p, size_t ic, double gamma)
{
    const double *col = p->candela + ic * p->gamma_count;
    if (p->gamma_count == 1)
        return col[0];
    double t;
    size_t k = bracket(p->gamma_angles, p->gamma_count, gamma, &t);
    return (1.0 - t) * col[k] + t * col[k + 1];
}

double rad_photometry_intensity(const rad_photometry *p, vec3 d)
{
    double len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    if (!(len > 0.0))
        return 0.0;
    /* gamma from the nadir (-z); C counter-clockwise from +x seen from above */
    double gamma = acos(fmax(-1.0, fmin(1.0, -d.z / len))) / DEG;
    double c = atan2(d.y, d.x) / DEG;
    if (c < 0.0)
        c += 360.0;
    if (p->c_count == 1)
        return column(p, 0, gamma);
    double t;
    size_t k = bracket(p->c_angles, p->c_count, c, &t);
    return (1.0 - t) * column(p, k, gamma) + t * column(p, k + 1, gamma);
}

double rad_photometry_tilt_factor(const rad_photometry *p, double degrees)
{
    if (p->tilt_count == 0)
        return 1.0;
    if (p->tilt_count == 1)
        return p->tilt_factors[0];
    double t;
    size_t k = bracket(p->tilt_angles, p->tilt_count, degrees, &t);
    return (1.0 - t) * p->tilt_factors[k] + t * p->tilt_factors[k + 1];
}

/* The flux of the bilinear table, integrated over the sphere: Gauss-Legendre
 * in cos(gamma) and the trapezoid... per cell, fine enough that the
 * interpolated surface's integral is exact to 1e-9 (the integrand is
 * piecewise smooth between table angles, so each cell is integrated alone). */
static double integrate_flux(const rad_photometry *p)
{
    static const double x[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                0.8611363115940526};
    static const double w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                0.3478548451374538};
    size_t nc = p->c_count == 1 ? 1 : p->c_count - 1;
    double total = 0.0;
    for (size_t ic = 0; ic < nc; ic++) {
        double c0 = p->c_count == 1 ? 0.0 : p->c_angles[ic], c1 = p->c_count == 1 ? 360.0 : p->c_angles[ic + 1];
        for (size_t ig = 0; ig + 1 < p->gamma_count; ig++) {
            double g0 = p->gamma_angles[ig], g1 = p->gamma_angles[ig + 1];
            for (int sub = 0; sub < 8; sub++) { /* 8 slices of the cell in gamma */
                double a = g0 + (g1 - g0) * sub / 8.0, b = g0 + (g1 - g0) * (sub + 1) / 8.0;
                for (int i = 0; i < 4; i++)
                    for (int j = 0; j < 4; j++) {
                        double g = 0.5 * (a + b) + 0.5 * (b - a) * x[i];
                        double c = 0.5 * (c0 + c1) + 0.5 * (c1 - c0) * x[j];
                        vec3 d = {sin(g * DEG) * cos(c * DEG), sin(g * DEG) * sin(c * DEG), -cos(g * DEG)};
                        total += w[i] * w[j] * 0.25 * (b - a) * DEG * (c1 - c0) * DEG * sin(g * DEG) *
                                 rad_photometry_intensity(p, d);
                    }
            }
        }
    }
    return total;
}

rad_photometry *rad_photometry_from_table(rad_context *ctx, const char *source, size_t c_count,
                                          const double *c_angles, size_t gamma_count,
                                          const double *gamma_angles, const double *candela,
                                          rad_result *err)
{
    rad_result dummy;
    if (!err)
        err = &dummy;
    *err = RAD_ERROR_INVALID_ARGUMENT;
    if (c_count < 1 || gamma_count < 2 || !c_angles || !gamma_angles || !candela)
        return NULL;
    for (size_t i = 0; i < gamma_count; i++)
        if (!(gamma_angles[i] >= 0.0 && gamma_angles[i] <= 180.0) || (i > 0 && !(gamma_angles[i] > gamma_angles[i - 1])))
            return NULL;
    for (size_t i = 0; i < c_count; i++)
        if (!(c_angles[i] >= 0.0 && c_angles[i] <= 360.0) || (i > 0 && !(c_angles[i] > c_angles[i - 1])))
            return NULL;
    if (c_count > 1 && (c_angles[0] != 0.0 || c_angles[c_count - 1] != 360.0))
        return NULL;
    for (size_t i = 0; i < c_count * gamma_count; i++)
        if (!(candela[i] >= 0.0 && isfinite(candela[i])))
            return NULL;
    *err = RAD_ERROR_OUT_OF_MEMORY;
    rad_photometry *p = rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *p, "photometry");
    if (!p)
        return NULL;
    memset(p, 0, sizeof *p);
    size_t sl = strlen(source ? source : "") + 1;
    p->source = rad_alloc(ctx, RAD_MEM_SCENE, sl, 1, "photometry: name");
    p->label = rad_alloc(ctx, RAD_MEM_SCENE, 1, 1, "photometry: label");
    p->c_angles = rad_alloc(ctx, RAD_MEM_SCENE, c_count, sizeof *p->c_angles, "photometry: C angles");
    p->gamma_angles = rad_alloc(ctx, RAD_MEM_SCENE, gamma_count, sizeof *p->gamma_angles, "photometry: angles");
    p->candela = rad_alloc(ctx, RAD_MEM_SCENE, c_count * gamma_count, sizeof *p->candela, "photometry: candela");
    if (!p->source || !p->label || !p->c_angles || !p->gamma_angles || !p->candela) {
        rad_photometry_free(p);
        return NULL;
    }
    memcpy(p->source, source ? source : "", sl);
    p->label[0] = '\0';
    p->type = RAD_PHOTOMETRY_C;
    p->c_count = c_count;
    p->gamma_count = gamma_count;
    memcpy(p->c_angles, c_angles, c_count * sizeof *c_angles);
    memcpy(p->gamma_angles, gamma_angles, gamma_count * sizeof *gamma_angles);
    memcpy(p->candela, candela, c_count * gamma_count * sizeof *candela);
    p->flux = integrate_flux(p);
    *err = RAD_OK;
    return p;
}
