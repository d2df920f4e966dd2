/*
 * fuzz_layout.c -- the luminaire layout file (photometry/layout.c,
 * rad_layout_parse) against the built-in Cornell box, its photometric
 * files served from tables (names ending ".ies": an I0 cos gamma
 * distribution with a 0.3 x 0.2 m opening; anything else: not found, so no
 * file is read).  A failure is RAD_ERROR_PARSE (or the loader's
 * RAD_ERROR_IO, or out of memory) with a one-line message, and the scene
 * unchanged; a success gives every luminaire a finite position, an
 * orthonormal right-handed frame, a finite multiplier >= 0 and a unique
 * name, and its direct light at a point is finite and >= 0.
 */
#include "fuzz.h"
#include "light/light.h"
#include "radiosity.h"
#include "photometry/layout.h"
#include "photometry/photometry.h"

#include <math.h>
#include <string.h>

static rad_result loader(rad_context *ctx, const char *path, void *user, rad_photometry **out)
{
    (void)user;
    size_t n = strlen(path);
    if (n < 4 || strcmp(path + n - 4, ".ies") != 0)
        return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot open", path);
    double c = 0.0, gamma[3] = {0.0, 90.0, 180.0}, cd[3] = {100.0, 0.0, 0.0};
    rad_photometry *p = rad_photometry_from_table(ctx, path, 1, &c, 3, gamma, cd, NULL);
    if (!p)
        return RAD_ERROR_OUT_OF_MEMORY;
    p->length = 0.3, p->width = 0.2, p->shape = RAD_OPENING_RECTANGLE;
    *out = p;
    return RAD_OK;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 65536)
        return 0; /* a few luminaires' keys; longer adds nothing */
    rad_context_options co = {.threads = 1};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_scene *scene = NULL;
    if (rad_scene_create_cornell_box(ctx, &scene) != RAD_OK) {
        rad_context_destroy(ctx);
        return 0;
    }
    rad_result r = rad_layout_parse(ctx, &scene->luminaires, "layout.json", (const char *)data, size, loader, NULL);
    if (r != RAD_OK) {
        const char *msg = rad_context_error(ctx);
        FUZZ_CHECK(r == RAD_ERROR_PARSE || r == RAD_ERROR_IO || r == RAD_ERROR_OUT_OF_MEMORY);
        FUZZ_CHECK(strncmp(msg, "layout.json", 11) == 0 || r != RAD_ERROR_PARSE);
        FUZZ_CHECK(strchr(msg, '\n') == NULL);
        FUZZ_CHECK(scene->luminaires.count == 0 && scene->luminaires.photometry_count == 0);
    } else {
        for (size_t k = 0; k < scene->luminaires.count; k++) {
            const rad_luminaire *L = &scene->luminaires.items[k];
            FUZZ_CHECK(v3_finite(L->position));
            FUZZ_CHECK(isfinite(L->multiplier) && L->multiplier >= 0.0);
            FUZZ_CHECK(L->photometry < scene->luminaires.photometry_count);
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++)
                    FUZZ_CHECK(fabs(v3_dot(L->axis[a], L->axis[b]) - (a == b)) < 1e-9);
            FUZZ_CHECK(v3_dot(v3_cross(L->axis[0], L->axis[1]), L->axis[2]) > 0.0);
            for (size_t j = 0; j < k && j < 200; j++)
                FUZZ_CHECK(strcmp(L->name, scene->luminaires.items[j].name) != 0);
        }
        if (scene->luminaires.count > 0 && scene->luminaires.count <= 1000) {
            double h[3];
            rad_luminaires_irradiance(scene, NULL, NULL, v3(0.3, 0.0, 0.2), v3(0, 1, 0), h);
            FUZZ_CHECK(isfinite(h[0]) && h[0] >= 0.0 && h[0] == h[1] && h[1] == h[2]);
        }
    }
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
