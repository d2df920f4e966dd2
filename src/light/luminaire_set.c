/*
 * luminaire_set.c -- the public calls of the luminaires placed in a scene
 * (radiosity.h, "Luminaires"): layout files read into the scene's set
 * through the layout parser (photometry/layout.c) with the photometric
 * readers, and what a program reads back.  The direct lumens landing on a
 * solution's elements are its view's (strategy.c).
 */
#include "scene/scene.h"
#include "photometry/photometry.h"

rad_result rad_scene_load_luminaires_memory(rad_context *ctx, rad_scene *scene, const char *name, const void *data,
                                            size_t size)
{
    rad_api_enter(ctx);
    if (!ctx || !scene || !name || !data)
        return rad_null_argument(ctx, __func__);
    return rad_layout_parse(ctx, &scene->luminaires, name, data, size, rad_layout_load_photometry, NULL);
}

rad_result rad_scene_load_luminaires(rad_context *ctx, rad_scene *scene, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !scene || !path)
        return rad_null_argument(ctx, __func__);
    unsigned char *data = NULL;
    size_t size = 0;
    rad_result r = rad_read_whole_file(ctx, path, &data, &size);
    if (r == RAD_OK)
        r = rad_layout_parse(ctx, &scene->luminaires, path, (const char *)data, size, rad_layout_load_photometry, NULL);
    rad_free(data);
    return r;
}

size_t rad_scene_luminaire_count(const rad_scene *scene) { return scene ? scene->luminaires.count : 0; }

const char *rad_scene_luminaire_name(const rad_scene *scene, size_t index)
{
    return scene && index < scene->luminaires.count ? scene->luminaires.items[index].name : NULL;
}

double rad_scene_luminaire_flux(const rad_scene *scene, size_t index)
{
    return scene && index < scene->luminaires.count ? rad_luminaire_flux(&scene->luminaires, index) : 0.0;
}

bool rad_scene_luminaire_placement(const rad_scene *scene, size_t index, double position[3], double axes[9])
{
    if (!scene || index >= scene->luminaires.count)
        return false;
    const rad_luminaire *L = &scene->luminaires.items[index];
    if (position) {
        position[0] = L->position.x, position[1] = L->position.y, position[2] = L->position.z;
    }
    for (int k = 0; axes && k < 3; k++) {
        axes[3 * k] = L->axis[k].x, axes[3 * k + 1] = L->axis[k].y, axes[3 * k + 2] = L->axis[k].z;
    }
    return true;
}
