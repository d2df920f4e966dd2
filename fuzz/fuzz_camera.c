/*
 * fuzz_camera.c -- the --camera text (rad_camera_from_string): a failure
 * leaves a one-line message; a success is a camera the renderer can use
 * (finite numbers, a view direction and a sideways direction of finite,
 * non-zero length, a field of view in (0, 180) degrees).
 */
#include "fuzz.h"
#include "radiosity.h"

#include <math.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096)
        return 0; /* a command-line argument; longer adds nothing */
    char text[4097];
    memcpy(text, data, size);
    text[size] = '\0';
    rad_context_options co = {.threads = 1};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_camera c;
    memset(&c, 0, sizeof c);
    rad_result r = rad_camera_from_string(ctx, text, &c);
    if (r != RAD_OK) {
        const char *msg = rad_context_error(ctx);
        FUZZ_CHECK(r == RAD_ERROR_INVALID_ARGUMENT);
        FUZZ_CHECK(msg[0] != '\0' && strchr(msg, '\n') == NULL);
    } else {
        double f[3], s[3];
        for (int k = 0; k < 3; k++) {
            FUZZ_CHECK(isfinite(c.position[k]) && isfinite(c.look_at[k]) && isfinite(c.up[k]));
            f[k] = c.look_at[k] - c.position[k];
        }
        s[0] = f[1] * c.up[2] - f[2] * c.up[1];
        s[1] = f[2] * c.up[0] - f[0] * c.up[2];
        s[2] = f[0] * c.up[1] - f[1] * c.up[0];
        double lf = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        double ls = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
        FUZZ_CHECK(isfinite(lf) && lf > 0.0);
        FUZZ_CHECK(isfinite(ls) && ls > 0.0);
        FUZZ_CHECK(c.vfov_degrees > 0.0 && c.vfov_degrees < 180.0);
    }
    rad_context_destroy(ctx);
    return 0;
}
