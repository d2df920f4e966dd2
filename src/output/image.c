/*
 * image.c -- the linear-radiance image and its writers.
 *
 *   .png  exposed (a multiplier on radiance, automatic by default), the
 *         sRGB transfer function (IEC 61966-2-1, the exact piecewise curve),
 *         8 bits per channel, via stb_image_write.
 *   .hdr  Radiance RGBE (Ward, "Real pixels", Graphics Gems II, 1991),
 *         linear radiance, via stb_image_write.
 *   .pfm  Portable Float Map: "PF\n<w> <h>\n-1.0\n" (negative scale =
 *         little-endian), then float RGB rows from the bottom up.
 *
 * Every writer goes through rad_atomic_file: the bytes go to a temporary
 * file renamed over the target only when all were written, so a failure
 * never leaves a partial image.
 */
#include "output/output.h"

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
#endif
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC     /* ours alone; libstb's copy stays unused */
/* Not STBI_WRITE_NO_STDIO, though we only write through callbacks into
 * rad_atomic_file: stb 1.16 puts its HDR writer inside that guard. */
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

/* ---- the image ---- */

rad_image *rad_image_create(rad_context *ctx, int width, int height)
{
    if (width < 0 || height < 0) {
        rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "image: bad size %d x %d", width, height);
        return NULL;
    }
    rad_image *image = rad_alloc(ctx, RAD_MEM_RENDER, 1, sizeof *image, "image");
    if (!image)
        return NULL;
    size_t pixels = (size_t)width * (size_t)height;
    image->pixels = rad_alloc(ctx, RAD_MEM_RENDER, pixels, 3 * sizeof(float), "image pixels");
    if (!image->pixels) {
        rad_free(image);
        return NULL;
    }
    image->ctx = ctx;
    image->width = width;
    image->height = height;
    return image;
}

rad_result rad_image_from_pixels(rad_context *ctx, int width, int height, const float *rgb, rad_image **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !rgb || !out)
        return rad_null_argument(ctx, __func__);
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "image: size %d x %d outside [1, 16384]", width,
                        height);
    rad_image *image = rad_image_create(ctx, width, height);
    if (!image)
        return RAD_ERROR_OUT_OF_MEMORY;
    memcpy(image->pixels, rgb, (size_t)width * (size_t)height * 3 * sizeof *rgb);
    *out = image;
    return RAD_OK;
}

void rad_image_destroy(rad_image *image)
{
    if (!image)
        return;
    rad_free(image->pixels);
    rad_free(image);
}

int rad_image_width(const rad_image *image) { return image ? image->width : 0; }
int rad_image_height(const rad_image *image) { return image ? image->height : 0; }
const float *rad_image_pixels(const rad_image *image) { return image ? image->pixels : NULL; }

/* ---- exposure ---- */

static double luminance(const float *rgb)
{
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; /* Rec. 709 Y */
}

/* The k-th smallest of a[0..n) (Wirth's selection, "Algorithms + Data
 * Structures = Programs", 1976); reorders a.  Expected O(n). */
static float select_kth(float *a, size_t n, size_t k)
{
    ptrdiff_t lo = 0, hi = (ptrdiff_t)n - 1, kk = (ptrdiff_t)k;
    while (lo < hi) {
        float pivot = a[kk];
        ptrdiff_t i = lo, j = hi;
        do {
            while (a[i] < pivot)
                i++;
            while (pivot < a[j])
                j--;
            if (i <= j) {
                float swap = a[i];
                a[i] = a[j];
                a[j] = swap;
                i++;
                j--;
            }
        } while (i <= j);
        if (j < kk)
            lo = i;
        if (kk < i)
            hi = j;
    }
    return a[kk];
}

/* Unlit (black) and non-finite values are left out: an image that is mostly
 * background would otherwise be exposed for the background, a lit mesh for
 * its unlit backs. */
rad_result rad_radiance_exposure(rad_context *ctx, const float *rgb, size_t count, double *exposure)
{
    *exposure = 1.0;
    size_t lit = 0;
    float *y = rad_alloc(ctx, RAD_MEM_RENDER, count, sizeof *y, "exposure: luminances");
    if (!y)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < count; i++) {
        double value = luminance(&rgb[3 * i]);
        if (!(value > 0.0) || !isfinite(value))
            continue;
        y[lit++] = (float)value;
    }
    double key = lit ? select_kth(y, lit, (size_t)(0.95 * (double)(lit - 1))) : 0.0;
    rad_free(y);
    *exposure = key > 0.0 ? 0.8 / key : 1.0;
    return RAD_OK;
}

rad_result rad_image_exposure(rad_context *ctx, const rad_image *image, double *exposure)
{
    return rad_radiance_exposure(ctx, image->pixels, (size_t)image->width * (size_t)image->height,
                                 exposure);
}

double rad_image_auto_exposure(const rad_image *image)
{
    double exposure;
    if (!image)
        return 1.0;
    return rad_image_exposure(image->ctx, image, &exposure) == RAD_OK ? exposure : 1.0;
}

/* ---- writers ---- */

double rad_srgb_encode(double linear)
{
    if (!(linear > 0.0))
        return 0.0;
    if (linear >= 1.0)
        return 1.0;
    return linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1.0 / 2.4) - 0.055;
}

/* stb's output callback: append to the atomic file, remember a failure. */
typedef struct stb_sink {
    FILE *file;
    int failed;
} stb_sink;

static void stb_write(void *context, void *data, int size)
{
    stb_sink *sink = context;
    if (size > 0 && fwrite(data, 1, (size_t)size, sink->file) != (size_t)size)
        sink->failed = 1;
}

static rad_result write_png(rad_context *ctx, const rad_image *image, const char *path,
                            double exposure, rad_atomic_file *file)
{
    size_t n = (size_t)image->width * (size_t)image->height;
    unsigned char *bytes = rad_alloc(ctx, RAD_MEM_RENDER, n, 3, "PNG pixels");
    if (!bytes)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < 3 * n; i++)
        bytes[i] = (unsigned char)lround(255.0 * rad_srgb_encode(exposure * image->pixels[i]));
    stb_sink sink = {file->file, 0};
    int ok = stbi_write_png_to_func(stb_write, &sink, image->width, image->height, 3, bytes,
                                    3 * image->width);
    rad_free(bytes);
    if (!ok)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: PNG encoding failed", path);
    if (sink.failed)
        return rad_fail(ctx, RAD_ERROR_IO, "%s: write failed", path);
    return RAD_OK;
}

static rad_result write_hdr(rad_context *ctx, const rad_image *image, const char *path,
                            rad_atomic_file *file)
{
    stb_sink sink = {file->file, 0};
    if (!stbi_write_hdr_to_func(stb_write, &sink, image->width, image->height, 3, image->pixels))
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: HDR encoding failed", path);
    if (sink.failed)
        return rad_fail(ctx, RAD_ERROR_IO, "%s: write failed", path);
    return RAD_OK;
}

static rad_result write_pfm(rad_context *ctx, const rad_image *image, const char *path,
                            rad_atomic_file *file)
{
    size_t row_bytes = (size_t)image->width * 3 * 4;
    unsigned char *row = rad_alloc(ctx, RAD_MEM_RENDER, row_bytes, 1, "PFM row");
    if (!row)
        return RAD_ERROR_OUT_OF_MEMORY;
    int failed = fprintf(file->file, "PF\n%d %d\n-1.0\n", image->width, image->height) < 0;
    for (int y = image->height - 1; y >= 0 && !failed; y--) {
        const float *src = &image->pixels[(size_t)y * (size_t)image->width * 3];
        for (size_t i = 0; i < (size_t)image->width * 3; i++) {
            uint32_t bits;
            memcpy(&bits, &src[i], 4);
            for (int b = 0; b < 4; b++)
                row[4 * i + (size_t)b] = (unsigned char)(bits >> (8 * b)); /* little-endian */
        }
        failed = fwrite(row, 1, row_bytes, file->file) != row_bytes;
    }
    rad_free(row);
    return failed ? rad_fail(ctx, RAD_ERROR_IO, "%s: write failed", path) : RAD_OK;
}

/* `bytes` or `floats` written by stb into an atomic file at `path`. */
static rad_result write_stb(rad_context *ctx, const char *path, int width, int height, int channels,
                            const unsigned char *bytes, const float *floats)
{
    rad_atomic_file file;
    rad_result r = rad_atomic_open(ctx, path, &file);
    if (r != RAD_OK)
        return r;
    stb_sink sink = {file.file, 0};
    int ok = bytes ? stbi_write_png_to_func(stb_write, &sink, width, height, channels, bytes, channels * width)
                   : stbi_write_hdr_to_func(stb_write, &sink, width, height, channels, floats);
    if (!ok)
        r = rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: %s encoding failed", path, bytes ? "PNG" : "HDR");
    else if (sink.failed)
        r = rad_fail(ctx, RAD_ERROR_IO, "%s: write failed", path);
    if (r != RAD_OK) {
        rad_atomic_abort(&file);
        return r;
    }
    return rad_atomic_commit(ctx, &file);
}

rad_result rad_write_png_rgba(rad_context *ctx, const char *path, int width, int height, const unsigned char *rgba)
{
    return write_stb(ctx, path, width, height, 4, rgba, NULL);
}

rad_result rad_write_hdr_rgb(rad_context *ctx, const char *path, int width, int height, const float *rgb)
{
    return write_stb(ctx, path, width, height, 3, NULL, rgb);
}

rad_result rad_image_write_exposed(rad_context *ctx, const rad_image *image, const char *path,
                                   double exposure)
{
    rad_api_enter(ctx);
    if (!ctx || !image || !path)
        return rad_null_argument(ctx, __func__);
    char ext[8];
    rad_path_extension(path, ext, sizeof ext);
    int png = strcmp(ext, "png") == 0, hdr = strcmp(ext, "hdr") == 0,
        pfm = strcmp(ext, "pfm") == 0;
    if (!png && !hdr && !pfm)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: unknown image format (use .png, .hdr or .pfm)", path);
    if (!(exposure >= 0.0) || !isfinite(exposure))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: exposure must be >= 0, got %g",
                        path, exposure);
    if (image->width <= 0 || image->height <= 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: image is empty (%d x %d)", path,
                        image->width, image->height);
    rad_result r = png && exposure == 0.0 ? rad_image_exposure(ctx, image, &exposure) : RAD_OK;
    if (r != RAD_OK)
        return r;

    rad_atomic_file file;
    r = rad_atomic_open(ctx, path, &file);
    if (r != RAD_OK)
        return r;
    if (png)
        r = write_png(ctx, image, path, exposure, &file);
    else if (hdr)
        r = write_hdr(ctx, image, path, &file);
    else
        r = write_pfm(ctx, image, path, &file);
    if (r != RAD_OK) {
        rad_atomic_abort(&file);
        return r;
    }
    return rad_atomic_commit(ctx, &file);
}

rad_result rad_image_write(rad_context *ctx, const rad_image *image, const char *path)
{
    rad_api_enter(ctx);
    return rad_image_write_exposed(ctx, image, path, 0.0);
}
