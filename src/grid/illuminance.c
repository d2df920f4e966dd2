/*
 * illuminance.c -- the rad_illuminance handle (radiosity.h, "Calculation
 * grids and points"): a grid file parsed against a solved view's scene
 * (grid.c), the illuminance gathered at its points (gather.c), lux and the
 * statistics per grid.  Its writers are output/'s (grid_write.c, the plans
 * in pictures.c); the public calls that take a solution unpack it in api/.
 */
#include "grid/grid.h"
#include "light/light.h"
#include "photometry/photometry.h"

#include <string.h>

/* lux from W/m^2 RGB (docs/units.md "Photometry"). */
static double lux(const double H[3])
{
    return 179.0 * (0.265 * H[0] + 0.670 * H[1] + 0.065 * H[2]);
}

void rad_illuminance_destroy(rad_illuminance *il)
{
    if (!il)
        return;
    rad_grid_set_destroy(il->set);
    rad_free(il->grids);
    rad_free(il->values);
    rad_free(il);
}

static rad_result evaluate(rad_context *ctx, const rad_solution_view *solved, const char *name, const char *text,
                           size_t size, rad_illuminance **out)
{
    if (!solved->solved)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "illuminance: the solution is not solved "
                        "(rad_solution_solve first)");
    rad_illuminance *il = rad_alloc(ctx, RAD_MEM_RENDER, 1, sizeof *il, "illuminance");
    if (!il)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = rad_grid_parse(ctx, solved->scene, name, text, size, &il->set);
    size_t n = il->set ? il->set->point_count : 0;
    double *H = NULL;
    if (r == RAD_OK) {
        il->grids = rad_alloc(ctx, RAD_MEM_RENDER, il->set->grid_count, sizeof *il->grids, "illuminance: grids");
        il->values = rad_alloc(ctx, RAD_MEM_RENDER, n, sizeof *il->values, "illuminance: values");
        H = rad_alloc(ctx, RAD_MEM_RENDER, 6 * n, sizeof *H, "illuminance: irradiance");
        if (!il->grids || !il->values || !H)
            r = RAD_ERROR_OUT_OF_MEMORY;
    }
    rad_grid_gather_stats gs;
    memset(&gs, 0, sizeof gs);
    if (r == RAD_OK) {
        rad_solution_view view = *solved;
        view.threads = rad_context_threads(ctx);
        r = rad_grid_gather(ctx, &view, il->set, RAD_GRID_GATHER_AUTO, H, H + 3 * n, &gs);
    }
    if (r != RAD_OK) {
        rad_free(H);
        rad_illuminance_destroy(il);
        return r;
    }
    double sky[3] = {0, 0, 0};
    il->daylight = solved->scene->daylight != NULL;
    if (il->daylight)
        rad_daylight_sky_horizontal(solved->scene, sky);
    double sky_lux = lux(sky);
    const rad_grid_set *set = il->set;
    for (size_t k = 0; k < n; k++) {
        rad_grid_point_value *p = &il->values[k];
        p->position[0] = set->position[k].x, p->position[1] = set->position[k].y, p->position[2] = set->position[k].z;
        p->normal[0] = set->normal[k].x, p->normal[1] = set->normal[k].y, p->normal[2] = set->normal[k].z;
        p->u = set->u[k];
        p->v = set->v[k];
        p->direct = lux(H + 3 * k);
        p->indirect = lux(H + 3 * (n + k));
        p->illuminance = p->direct + p->indirect;
        p->daylight_factor = il->daylight && sky_lux > 0.0 ? 100.0 * p->illuminance / sky_lux : NAN;
        p->name = set->point_name[k];
    }
    rad_free(H);
    for (size_t g = 0; g < set->grid_count; g++) {
        const rad_grid_def *d = &set->grids[g];
        rad_grid_result *res = &il->grids[g];
        res->name = d->name;
        res->free_points = d->points;
        res->point_count = d->point_count;
        res->points = il->values + d->first_point;
        res->columns = d->columns, res->rows = d->rows;
        res->spacing_u = d->spacing_u, res->spacing_v = d->spacing_v;
        res->width = d->width, res->height = d->height, res->border = d->border;
        res->automatic = d->automatic;
        double sum = 0.0, lo = INFINITY, hi = -INFINITY;
        for (size_t k = 0; k < d->point_count; k++) {
            double E = res->points[k].illuminance;
            sum += E;
            lo = fmin(lo, E);
            hi = fmax(hi, E);
        }
        res->average = d->point_count ? sum / (double)d->point_count : 0.0;
        res->minimum = d->point_count ? lo : 0.0;
        res->maximum = d->point_count ? hi : 0.0;
        res->uniformity = res->average > 0.0 ? res->minimum / res->average : 0.0;
        res->min_over_max = res->maximum > 0.0 ? res->minimum / res->maximum : 0.0;
    }
    il->stats.points = n;
    il->stats.seconds = gs.seconds;
    il->stats.points_per_second = gs.seconds > 0.0 ? (double)n / gs.seconds : 0.0;
    il->stats.shadow_rays = gs.rays;
    il->stats.exact_pairs = gs.exact_pairs;
    il->stats.ray_pairs = gs.ray_pairs;
    il->stats.light_seconds = gs.light_seconds;
    il->stats.thread_seconds = gs.thread_seconds;
    *out = il;
    return RAD_OK;
}

rad_result rad_illuminance_from_view(rad_context *ctx, const rad_solution_view *view, const char *name,
                                     const void *data, size_t size, rad_illuminance **out)
{
    return evaluate(ctx, view, name, data ? data : "", size, out);
}

rad_result rad_illuminance_from_view_file(rad_context *ctx, const rad_solution_view *view, const char *path,
                                          rad_illuminance **out)
{
    unsigned char *data = NULL;
    size_t size = 0;
    rad_result r = rad_read_whole_file(ctx, path, &data, &size);
    if (r == RAD_OK)
        r = evaluate(ctx, view, path, (const char *)data, size, out);
    rad_free(data);
    return r;
}

rad_result rad_illuminance_check_file(rad_context *ctx, const rad_scene *scene, const char *path, size_t *points)
{
    rad_api_enter(ctx);
    if (points)
        *points = 0;
    if (!ctx || !scene || !path)
        return rad_null_argument(ctx, __func__);
    unsigned char *data = NULL;
    size_t size = 0;
    rad_grid_set *set = NULL;
    rad_result r = rad_read_whole_file(ctx, path, &data, &size);
    if (r == RAD_OK)
        r = rad_grid_parse(ctx, scene, path, (const char *)data, size, &set);
    if (r == RAD_OK && points)
        *points = set->point_count;
    rad_grid_set_destroy(set);
    rad_free(data);
    return r;
}

size_t rad_illuminance_grid_count(const rad_illuminance *il)
{
    return il ? il->set->grid_count : 0;
}

const rad_grid_result *rad_illuminance_grid(const rad_illuminance *il, size_t grid)
{
    return il && grid < il->set->grid_count ? &il->grids[grid] : NULL;
}

bool rad_illuminance_has_daylight(const rad_illuminance *il)
{
    return il && il->daylight;
}

void rad_illuminance_get_stats(const rad_illuminance *il, rad_illuminance_stats *out)
{
    if (!out)
        return;
    memset(out, 0, sizeof *out);
    if (il)
        *out = il->stats;
}
