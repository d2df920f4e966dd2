/*
 * daylight.c -- the public daylight calls (radiosity.h "Daylight"): read
 * the file against the scene (light/daylight_file.c), scale the sky
 * (light/sky.c), move the openings out of the scene.
 */
#include "api/solution.h"
#include "light/sky.h"
#include "photometry/photometry.h"

rad_result rad_scene_daylight_load_memory(rad_context *ctx, rad_scene *scene, const char *name, const void *data,
                                          size_t size)
{
    rad_api_enter(ctx);
    if (!ctx || !scene || !name || (!data && size > 0))
        return rad_null_argument(ctx, __func__);
    rad_daylight *d = NULL;
    rad_result r = rad_daylight_parse(ctx, scene, name, data ? (const char *)data : "", size, &d);
    if (r != RAD_OK)
        return r;
    rad_sky_prepare(d);
    return rad_scene_attach_daylight(ctx, scene, d, NULL);
}

rad_result rad_scene_daylight_load_file(rad_context *ctx, rad_scene *scene, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !scene || !path)
        return rad_null_argument(ctx, __func__);
    unsigned char *data = NULL;
    size_t size = 0;
    rad_result r = rad_read_whole_file(ctx, path, &data, &size);
    rad_daylight *d = NULL;
    if (r == RAD_OK)
        r = rad_daylight_parse(ctx, scene, path, (const char *)data, size, &d);
    rad_free(data);
    if (r != RAD_OK)
        return r;
    rad_sky_prepare(d);
    return rad_scene_attach_daylight(ctx, scene, d, path);
}

double rad_scene_daylight_sky_illuminance(const rad_scene *scene)
{
    return scene && scene->daylight ? RAD_LUMINOUS_EFFICACY * scene->daylight->sky.horizontal : 0.0;
}

size_t rad_scene_daylight_opening_count(const rad_scene *scene)
{
    return scene && scene->daylight ? scene->daylight->opening_name_count : 0;
}
