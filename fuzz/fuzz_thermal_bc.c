/*
 * fuzz_thermal_bc.c -- the thermal command's boundary-condition file
 * (rad_thermal_conditions_load_memory) against the built-in Cornell box's
 * surfaces: a failure is RAD_ERROR_PARSE with a one-line message naming
 * the file; a success gives every surface a valid condition (emissivity 0
 * or in (0, 1], a finite temperature >= 0 or a finite flux) and a finite
 * environment temperature >= 0.
 */
#include "fuzz.h"
#include "radiosity.h"

#include <math.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 65536)
        return 0; /* a condition per surface; longer adds nothing */
    rad_context_options co = {.threads = 1};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_scene *scene = NULL;
    if (rad_scene_create_cornell_box(ctx, &scene) != RAD_OK) {
        rad_context_destroy(ctx);
        return 0;
    }
    rad_thermal_conditions *c = NULL;
    rad_result r = rad_thermal_conditions_load_memory(ctx, scene, "bc.json", data, size, &c);
    if (r != RAD_OK) {
        const char *msg = rad_context_error(ctx);
        FUZZ_CHECK(r == RAD_ERROR_PARSE || r == RAD_ERROR_OUT_OF_MEMORY);
        FUZZ_CHECK(c == NULL);
        FUZZ_CHECK(strncmp(msg, "bc.json", 7) == 0 || r == RAD_ERROR_OUT_OF_MEMORY);
        FUZZ_CHECK(strchr(msg, '\n') == NULL);
    } else {
        double env = rad_thermal_conditions_environment(c);
        FUZZ_CHECK(isfinite(env) && env >= 0.0);
        for (size_t k = 0; k < rad_scene_surface_count(scene); k++) {
            rad_thermal_surface s;
            FUZZ_CHECK(rad_thermal_conditions_get(c, k, &s));
            FUZZ_CHECK(s.emissivity == 0.0 || (s.emissivity > 0.0 && s.emissivity <= 1.0));
            FUZZ_CHECK(s.condition == RAD_THERMAL_TEMPERATURE || s.condition == RAD_THERMAL_HEAT_FLUX ||
                       s.condition == RAD_THERMAL_ADIABATIC);
            FUZZ_CHECK(isfinite(s.value));
            FUZZ_CHECK(s.condition != RAD_THERMAL_TEMPERATURE || s.value >= 0.0);
        }
    }
    rad_thermal_conditions_destroy(c);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
