/*
 * fuzz_texture.c -- a reflectance texture's file (import/texture.c,
 * import_texture_read: stb_image behind a header check against the memory
 * limit): a failure says why in a few words and is one of the three
 * results it promises; a success is a width x height image of linear
 * values in [0, 1].  The bytes go through a temporary file, as a scene's
 * map_Kd does.
 */
#include "fuzz.h"
#include "import/import_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[] = "/tmp/radiosity-fuzz-texture-XXXXXX";
    int fd = mkstemp(path);
    if (fd < 0)
        return 0;
    bool written = write(fd, data, size) == (ssize_t)size;
    close(fd);
    /* 64 MiB: a header asking for more is refused before decoding. */
    rad_context_options co = {.threads = 1, .max_memory_bytes = 64.0 * 1048576.0};
    rad_context *ctx = NULL;
    if (written && rad_context_create(&co, &ctx) == RAD_OK) {
        float *rgb = NULL;
        int w = 0, h = 0;
        char why[256] = "";
        rad_result r = import_texture_read(ctx, path, &rgb, &w, &h, why, sizeof why);
        if (r != RAD_OK) {
            FUZZ_CHECK(r == RAD_ERROR_IO || r == RAD_ERROR_PARSE || r == RAD_ERROR_OUT_OF_MEMORY);
            FUZZ_CHECK(rgb == NULL && why[0] != '\0' && strchr(why, '\n') == NULL);
        } else {
            FUZZ_CHECK(rgb != NULL && w >= 1 && h >= 1);
            for (size_t k = 0; k < (size_t)w * (size_t)h * 3; k++)
                FUZZ_CHECK(rgb[k] >= 0.0f && rgb[k] <= 1.0f);
        }
        rad_free(rgb);
        rad_context_destroy(ctx);
    }
    unlink(path);
    return 0;
}
