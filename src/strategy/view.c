/*
 * view.c -- the questions every solution answers from its read-only view:
 * the power balance, per-surface radiosity, surface-to-surface view
 * factors, the direct lumens landing.
 */
#include "strategy/strategy.h"

#include "photometry/photometry.h"

#ifdef _OPENMP
#include <omp.h>
#endif
#include <stdlib.h>
#include <string.h>

void rad_view_surface_radiosity(const rad_solution_view *v, size_t surface, double rgb[3])
{
    double sum[3] = {0, 0, 0}, area = 0.0;
    for (size_t i = 0; i < v->n; i++) {
        if (v->mesh->elements[i].surface != surface)
            continue;
        area += v->area[i];
        for (int c = 0; c < 3; c++)
            sum[c] += v->area[i] * v->radiosity[3 * i + c];
    }
    for (int c = 0; c < 3; c++)
        rgb[c] = area > 0.0 ? sum[c] / area : 0.0;
}

rad_result rad_view_surface_view_factors(rad_context *ctx, const rad_solution_view *v, double *F)
{
    size_t S = v->scene->surface_count, n = v->n;
    memset(F, 0, S * S * sizeof *F);
    if (!v->F) /* no factors were computed */
        return RAD_OK;
    double *area = rad_alloc(ctx, RAD_MEM_OUTPUT, S, sizeof *area, "view factors: surface areas");
    if (!area) {
        for (size_t k = 0; k < S * S; k++)
            F[k] = NAN;
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < n; i++) {
        uint32_t si = v->mesh->elements[i].surface;
        area[si] += v->area[i];
        const double *Fi = v->F + i * n;
        double *row = F + (size_t)si * S;
        for (size_t j = 0; j < n; j++)
            row[v->mesh->elements[j].surface] += v->area[i] * Fi[j];
    }
    for (size_t a = 0; a < S; a++)
        for (size_t b = 0; b < S; b++)
            F[a * S + b] = area[a] > 0.0 ? F[a * S + b] / area[a] : 0.0;
    rad_free(area);
    return RAD_OK;
}

/* The direct light of luminaires and daylight landing on the elements,
 * sum A H_d, and the part of it absorbed at once, sum A (1 - rho) H_d (W,
 * means over RGB): the solve sees only the reflected part rho H_d, as
 * emission. */
static void direct_power(const rad_solution_view *v, double *landing, double *absorbed)
{
    double land = 0.0, ab = 0.0;
    for (size_t i = 0; v->direct && i < v->n; i++)
        for (int c = 0; c < 3; c++) {
            double p = v->area[i] * v->direct[3 * i + c];
            land += p;
            ab += (1.0 - v->reflectance[3 * i + c]) * p;
        }
    *landing = land / 3.0;
    *absorbed = ab / 3.0;
}

rad_result rad_view_power(rad_context *ctx, const rad_solution_view *v, double *emitted, double *absorbed)
{
    size_t n = v->n;
    double em = 0.0, landing, direct_absorbed;
    /* With luminaires or daylight, the power entering is the surfaces' own
     * emission and the direct light landing; what the solve calls emission
     * holds only its reflected part, so the absorbed part is added to both
     * sides. */
    direct_power(v, &landing, &direct_absorbed);
    if (!v->F) { /* the strategy counted what it deposited */
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++)
                em += v->area[i] * v->emission[3 * i + c];
        *emitted = em / 3.0 + direct_absorbed;
        *absorbed = v->solve->absorbed + direct_absorbed;
        return RAD_OK;
    }
    /* Per-element absorption in parallel, summed in order (thread-independent). */
    double *absorbed_by = rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *absorbed_by, "power balance"), ab = 0.0;
    if (!absorbed_by) {
        *emitted = *absorbed = NAN;
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    /* With mirrors: irradiance through the coupling the solve used (the
     * mirror images' light included), and a mirror absorbs what it
     * reflects neither diffusely nor specularly. */
    const double *F = v->F_coupling ? v->F_coupling : v->F;
#pragma omp parallel for schedule(static) num_threads(v->threads)
    for (size_t i = 0; i < n; i++) {
        double h[3];
        rad_gather(F + i * n, v->radiosity, n, h);
        const rad_material *m = &v->scene->materials[v->mesh->elements[i].material];
        bool mirror = v->F_coupling && m->specular_kind == RAD_SPECULAR_MIRROR;
        double a = 0.0;
        for (int c = 0; c < 3; c++) {
            double rho_s = mirror ? (m->specular[0] + m->specular[1] + m->specular[2]) / 3.0 : 0.0;
            a += v->area[i] * (1.0 - v->reflectance[3 * i + c] - rho_s) * h[c];
        }
        absorbed_by[i] = a;
    }
    for (size_t i = 0; i < n; i++) {
        ab += absorbed_by[i];
        for (int c = 0; c < 3; c++)
            em += v->area[i] * v->emission[3 * i + c];
    }
    rad_free(absorbed_by);
    *emitted = em / 3.0 + direct_absorbed;
    *absorbed = ab / 3.0 + direct_absorbed;
    return RAD_OK;
}

double rad_view_direct_lumens(const rad_solution_view *v)
{
    if (!v->direct)
        return 0.0;
    double landing = 0.0;
    for (size_t i = 0; i < v->n; i++) {
        const double *h = v->direct + 3 * i;
        landing += v->area[i] * (RAD_Y_R * h[0] + RAD_Y_G * h[1] + RAD_Y_B * h[2]);
    }
    return RAD_LUMINOUS_EFFICACY * landing;
}
