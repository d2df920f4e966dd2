/*
 * result.c -- the heat exchange once solved (radiosity.h, "Radiative heat
 * exchange"): per-element and per-surface values, the balance, the Gebhart
 * factors on demand; and its release.
 */
#include "thermal/thermal.h"
#include "scene/scene.h"

#include <math.h>

void rad_thermal_destroy(rad_thermal *t)
{
    if (!t)
        return;
    rad_free(t->emissivity);
    rad_free(t->value);
    rad_free(t->known_temperature);
    rad_free(t->surface);
    rad_free(t->surface_names);
    rad_free(t->fields.radiosity);
    rad_free(t->fields.irradiation);
    rad_free(t->fields.heat_flux);
    rad_free(t->fields.temperature);
    rad_free(t->surfaces);
    rad_free(t->element_condition);
    rad_free(t->environment);
    rad_free(t);
}

static void element_values(const rad_thermal *t, size_t i, rad_thermal_values *out)
{
    out->area = t->sys.area[i];
    out->emissivity = t->emissivity[i];
    out->temperature = t->fields.temperature[i];
    out->radiosity = t->fields.radiosity[i];
    out->irradiation = t->fields.irradiation[i];
    out->heat_flux = t->fields.heat_flux[i];
    out->heat = t->sys.area[i] * t->fields.heat_flux[i];
    out->condition = t->element_condition[i];
}

bool rad_thermal_surface_values(const rad_thermal *t, size_t surface, rad_thermal_values *out)
{
    if (!t || !out || surface >= t->scene->surface_count)
        return false;
    *out = t->surfaces[surface];
    return true;
}

bool rad_thermal_element_values(const rad_thermal *t, size_t element, rad_thermal_values *out)
{
    if (!t || !out || element >= t->sys.n)
        return false;
    element_values(t, element, out);
    return true;
}

double rad_thermal_get_balance(const rad_thermal *t, rad_thermal_balance *out)
{
    if (!t) {
        if (out)
            *out = (rad_thermal_balance){NAN, NAN, NAN, NAN, NAN};
        return NAN;
    }
    if (out)
        *out = t->balance;
    return t->stats.residual;
}

rad_result rad_thermal_gebhart(rad_context *ctx, const rad_thermal *t, double *G)
{
    rad_api_enter(ctx);
    if (!ctx || !t || !G)
        return rad_null_argument(ctx, __func__);
    return rad_thermal_gebhart_factors(ctx, &t->sys, t->scene->surface_count, t->solver, &t->params, G);
}
