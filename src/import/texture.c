/*
 * texture.c -- reading a reflectance texture (MTL map_Kd, glTF
 * baseColorTexture) with stb_image: 8-bit sRGB texels decoded to linear
 * reflectance factors (IEC 61966-2-1's transfer function, the encoding of
 * both formats' colour textures; glTF 2.0 spec 3.9.2 says so outright).
 *
 * The image is a new input of arbitrary size: its header is read first
 * and the texels' floats (12 bytes a texel, plus stb's 3 bytes) must fit
 * the memory limit before anything is decoded.
 */
#include "import/import_internal.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wcast-qual"
#pragma GCC diagnostic ignored "-Wmissing-prototypes"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wconversion"
#endif
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC      /* ours alone */
#define STBI_NO_HDR           /* reflectances are 8-bit colour images */
#define STBI_NO_LINEAR
#define STBI_FAILURE_USERMSG
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
/* stb declares functions it defines only under options we leave off; GCC
 * says so at the end of the file, past the pop. */
#pragma GCC diagnostic ignored "-Wunused-function"
#endif

/* sRGB-encoded 8-bit value -> linear, in [0, 1]. */
static double srgb_to_linear(int value)
{
    double c = value / 255.0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

rad_result import_texture_read(rad_context *ctx, const char *path, float **rgb, int *width, int *height,
                               char *why, size_t why_size)
{
    *rgb = NULL;
    *width = *height = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(why, why_size, "%s", strerror(errno));
        return RAD_ERROR_IO;
    }
    int w, h, channels;
    if (!stbi_info_from_file(f, &w, &h, &channels)) {
        snprintf(why, why_size, "not an image stb_image reads (%s)", stbi_failure_reason());
        fclose(f);
        return RAD_ERROR_PARSE;
    }
    double bytes = 15.0 * (double)w * (double)h, limit = rad_memory_limit(ctx);
    if (w < 1 || h < 1 || bytes > limit) {
        snprintf(why, why_size, "%d x %d texels need %.2f GiB, above the memory limit of %.2f GiB", w, h,
                 bytes / 1073741824.0, limit / 1073741824.0);
        fclose(f);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    unsigned char *pixels = stbi_load_from_file(f, &w, &h, &channels, 3);
    fclose(f);
    if (!pixels) {
        snprintf(why, why_size, "cannot decode it (%s)", stbi_failure_reason());
        return RAD_ERROR_PARSE;
    }
    float *out = rad_alloc(ctx, RAD_MEM_SCENE, (size_t)w * (size_t)h * 3, sizeof *out, path);
    if (!out) {
        stbi_image_free(pixels);
        snprintf(why, why_size, "out of memory");
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    float table[256];
    for (int k = 0; k < 256; k++)
        table[k] = (float)srgb_to_linear(k);
    for (size_t k = 0; k < (size_t)w * (size_t)h * 3; k++)
        out[k] = table[pixels[k]];
    stbi_image_free(pixels);
    *rgb = out;
    *width = w;
    *height = h;
    return RAD_OK;
}
