/*
 * fuzz_daylight.c -- the daylight file (rad_scene_daylight_load_memory)
 * against the built-in Cornell box: a failure is RAD_ERROR_PARSE or
 * RAD_ERROR_INVALID_SCENE with a one-line message naming the file, the
 * scene unchanged; a success leaves a scene with polygons, a finite sky,
 * and (at the file's tolerance, where it is not finer than 1e-4, to bound
 * the work) a finite, non-negative direct daylight at a point of the floor.
 */
#include "fuzz.h"
#include "radiosity.h"
#include "light/light.h"
#include "scene/daylight.h"

#include <math.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 65536)
        return 0; /* a few keys and names; longer adds nothing */
    rad_context_options co = {.threads = 1};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_scene *scene = NULL;
    if (rad_scene_create_cornell_box(ctx, &scene) != RAD_OK) {
        rad_context_destroy(ctx);
        return 0;
    }
    size_t polygons = rad_scene_polygon_count(scene);
    rad_result r = rad_scene_daylight_load_memory(ctx, scene, "sky.json", data, size);
    if (r != RAD_OK) {
        const char *msg = rad_context_error(ctx);
        FUZZ_CHECK(r == RAD_ERROR_PARSE || r == RAD_ERROR_INVALID_SCENE || r == RAD_ERROR_OUT_OF_MEMORY);
        FUZZ_CHECK(strncmp(msg, "sky.json", 8) == 0 || r == RAD_ERROR_OUT_OF_MEMORY);
        FUZZ_CHECK(strchr(msg, '\n') == NULL);
        FUZZ_CHECK(scene->daylight == NULL && rad_scene_polygon_count(scene) == polygons);
    } else {
        FUZZ_CHECK(rad_scene_polygon_count(scene) > 0);
        double eh = rad_scene_daylight_sky_illuminance(scene);
        FUZZ_CHECK(isfinite(eh) && eh > 0.0);
        if (scene->daylight->tolerance >= 1e-4) {
            double e[3];
            rad_daylight_irradiance(scene, NULL, NULL, v3(0.3, 0.01, 0.3), v3(0, 1, 0), e);
            FUZZ_CHECK(isfinite(e[0]) && e[0] >= 0.0 && e[0] == e[1] && e[1] == e[2]);
        }
    }
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
