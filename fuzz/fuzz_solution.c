/*
 * fuzz_solution.c -- the solution file reader (rad_solution_load_memory).
 *
 * A mutated file nearly always fails its payload checksum, which would
 * keep the fuzzer at the door; so each input is read twice: as it is, and
 * with the checksum in its header written again for its payload, which
 * lets the mutations reach the structural checks behind it.
 *
 * The contract: a failure leaves a one-line message naming the file and
 * nothing else; a success is a solution that answers its accessors with
 * finite values and renders an 8 x 8 picture of finite radiance >= 0.
 */
#include "fuzz.h"

#include "radiosity.h"
#include "strategy/saved.h"

#include <inttypes.h>
#include <math.h>
#include <string.h>

/* The first `needle` in bytes [p, p + size), or NULL. */
static char *find(uint8_t *p, size_t size, const char *needle)
{
    size_t n = strlen(needle);
    for (size_t i = 0; i + n <= size; i++)
        if (memcmp(p + i, needle, n) == 0)
            return (char *)p + i;
    return NULL;
}

static void load(rad_context *ctx, const uint8_t *data, size_t size)
{
    rad_scene *scene = NULL;
    rad_solution *s = NULL;
    rad_result r = rad_solution_load_memory(ctx, "fuzz.radsol", data, size, &scene, &s);
    if (r != RAD_OK) {
        const char *msg = rad_context_error(ctx);
        FUZZ_CHECK(scene == NULL && s == NULL);
        FUZZ_CHECK(strncmp(msg, "fuzz.radsol", 11) == 0 || r == RAD_ERROR_OUT_OF_MEMORY);
        FUZZ_CHECK(strchr(msg, '\n') == NULL);
        return;
    }
    size_t n = rad_solution_element_count(s);
    FUZZ_CHECK(n > 0);
    for (size_t i = 0; i < n; i++) {
        double rho[3], e[3], b[3];
        FUZZ_CHECK(rad_solution_element_values(s, i, rho, e, b));
        FUZZ_CHECK(rad_solution_element_surface(s, i) < rad_scene_surface_count(scene));
        for (int c = 0; c < 3; c++)
            FUZZ_CHECK(isfinite(b[c]) && b[c] >= 0.0 && rho[c] >= 0.0 && rho[c] < 1.0);
    }
    rad_render_options ro = {.width = 8, .height = 8, .samples = 1};
    rad_image *image = NULL;
    if (rad_solution_render(ctx, s, &ro, &image) == RAD_OK) {
        const float *px = rad_image_pixels(image);
        for (int k = 0; k < 3 * 64; k++)
            FUZZ_CHECK(isfinite(px[k]) && px[k] >= 0.0f);
    } else {
        FUZZ_CHECK(strchr(rad_context_error(ctx), '\n') == NULL);
    }
    rad_image_destroy(image);
    rad_solution_destroy(s);
    rad_scene_destroy(scene);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rad_context_options co = {.threads = 1, .max_memory_bytes = 256.0 * 1048576.0};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    load(ctx, data, size);
    /* Again with the payload's checksum written into the header. */
    if (size > RAD_SAVED_MAGIC_SIZE + 4) {
        uint32_t h = (uint32_t)data[8] | (uint32_t)data[9] << 8 | (uint32_t)data[10] << 16 |
                     (uint32_t)data[11] << 24;
        size_t at = ((size_t)h + 12 + 7) / 8 * 8;
        uint8_t *copy = malloc(size);
        if (copy && at <= size) {
            memcpy(copy, data, size);
            char *key = find(copy + 12, h < size - 12 ? h : size - 12, "\"fnv1a64\":");
            char *quote = key ? memchr(key + 10, '"', (size_t)((char *)copy + size - (key + 10))) : NULL;
            if (quote && (size_t)((char *)copy + size - quote) > 17) {
                char hex[17];
                snprintf(hex, sizeof hex, "%016" PRIx64, rad_fnv1a(RAD_FNV_OFFSET, copy + at, size - at));
                memcpy(quote + 1, hex, 16);
                load(ctx, copy, size);
            }
        }
        free(copy);
    }
    rad_context_destroy(ctx);
    return 0;
}
