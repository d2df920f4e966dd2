/*
 * bake.c -- `radiosity bake`: the lightmap (lightmap.c) written as files
 * of one output set beside the lit mesh that uses them:
 *
 *     room.glb             the lit mesh (mesh_export.c) with TEXCOORD_1 and
 *                          MOZ_lightmap, naming the PNGs by relative URI
 *     room_lightmap0.hdr   Radiance RGBE, linear: B/pi (or H/pi), W/(m^2 sr)
 *     room_lightmap0.png   the same as RGBM: value = rgb x a x M
 *     room_lightmap1.*     ... one pair per atlas
 *
 * RGBM (shared-exponent-free "RGB times a multiplier", as Unity and
 * three.js's RGBMLoader decode it, without their gamma): M is the
 * smallest power of two at least the largest value (at least 1); a texel
 * of value v stores a = ceil(255 max(v) / M) / 255 (at least 1/255) and
 * rgb = v / (a M), each rounded to 8 bits.
 */
#include "output/output.h"

#include <stdlib.h>
#include <string.h>

/* `text` percent-encoded as a URI path segment (RFC 3986: all but the
 * unreserved characters), into a new string; NULL when out of memory. */
static char *uri_encode(rad_context *ctx, const char *text)
{
    size_t n = strlen(text);
    char *out = rad_alloc(ctx, RAD_MEM_OUTPUT, 3 * n + 1, 1, "bake: file names");
    if (!out)
        return NULL;
    char *q = out;
    for (const unsigned char *p = (const unsigned char *)text; *p; p++) {
        if ((*p >= 'A' && *p <= 'Z') || (*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || *p == '-' ||
            *p == '.' || *p == '_' || *p == '~')
            *q++ = (char)*p;
        else
            q += sprintf(q, "%%%02X", *p);
    }
    *q = '\0';
    return out;
}

size_t rad_bake_image_path(const char *path, size_t atlas, const char *extension, char *out, size_t size)
{
    if (!path || !extension)
        return 0;
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    size_t stem = dot && (!slash || dot > slash) ? (size_t)(dot - path) : strlen(path);
    int n = snprintf(out, out ? size : 0, "%.*s_lightmap%zu.%s", (int)stem, path, atlas, extension);
    return n < 0 ? 0 : (size_t)n;
}

/* rad_bake_image_path into a new string; NULL when out of memory. */
static char *image_path(rad_context *ctx, const char *path, size_t atlas, const char *extension)
{
    size_t size = rad_bake_image_path(path, atlas, extension, NULL, 0) + 1;
    char *out = rad_alloc(ctx, RAD_MEM_OUTPUT, size, 1, "bake: file names");
    if (out)
        rad_bake_image_path(path, atlas, extension, out, size);
    return out;
}

static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

/* The set's temporary for `path`, added now unless planned before. */
static rad_result temp_for(rad_context *ctx, rad_output_set *set, const char *path, const char **temp)
{
    *temp = rad_output_set_temp(set, path);
    return *temp ? RAD_OK : rad_output_set_add(ctx, set, path, RAD_OUTPUT_IMAGE, temp);
}

/* Atlas `a` as RGBM bytes (4 per texel) and radiance floats (3 per texel). */
static void encode(const rad_atlas *atlas, double range, unsigned char *rgbm, float *radiance)
{
    size_t n = (size_t)atlas->width * (size_t)atlas->height;
    for (size_t i = 0; i < n; i++) {
        double v[3], peak = 0.0;
        for (int c = 0; c < 3; c++) {
            v[c] = fmax(0.0, (double)atlas->texels[3 * i + (size_t)c] / M_PI);
            radiance[3 * i + (size_t)c] = (float)v[c];
            peak = fmax(peak, v[c]);
        }
        double a = fmin(255.0, fmax(1.0, ceil(255.0 * peak / range - 1e-9)));
        for (int c = 0; c < 3; c++)
            rgbm[4 * i + (size_t)c] = (unsigned char)fmin(255.0, lround(255.0 * v[c] / (a / 255.0 * range)));
        rgbm[4 * i + 3] = (unsigned char)a;
    }
}

rad_result rad_write_bake(rad_context *ctx, const rad_solution_view *view, const rad_bake_options *options,
                          rad_output_set *set, const char *path, rad_bake_stats *stats)
{
    const char *mesh_temp = rad_output_set_temp(set, path);
    if (!mesh_temp)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: not in the output set (rad_output_set_add it first)",
                        path);
    char ext[8];
    rad_path_extension(path, ext, sizeof ext);
    if (strcmp(ext, "glb") != 0 && strcmp(ext, "gltf") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: unknown lightmapped mesh format (use .glb or .gltf; the lightmaps are written beside it)",
                        path);
    rad_lightmap_options lo = {options->texels_per_metre, options->atlas_size, (int)options->quantity};
    rad_lightmap *lm;
    rad_result r = rad_lightmap_bake(ctx, view, &lo, &lm);
    if (r != RAD_OK)
        return r;
    size_t n = lm->atlas_count;
    rad_mesh_lightmaps maps = {lm, NULL, NULL, 1.0};
    maps.png_uris = rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *maps.png_uris, "bake: file names");
    maps.hdr_names = maps.png_uris ? rad_alloc(ctx, RAD_MEM_OUTPUT, n, sizeof *maps.hdr_names, "bake: file names")
                                   : NULL;
    unsigned char *rgbm = NULL;
    float *radiance = NULL;
    if (!maps.hdr_names) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    size_t largest = 0;
    for (size_t a = 0; a < n; a++) {
        const rad_atlas *atlas = &lm->atlases[a];
        size_t texels = (size_t)atlas->width * (size_t)atlas->height;
        largest = texels > largest ? texels : largest;
        for (size_t i = 0; i < 3 * texels; i++)
            while (isfinite(atlas->texels[i]) && (double)atlas->texels[i] / M_PI > maps.rgbm_range)
                maps.rgbm_range *= 2.0;
    }
    rgbm = rad_alloc(ctx, RAD_MEM_OUTPUT, largest, 4, "bake: PNG texels");
    radiance = rgbm ? rad_alloc(ctx, RAD_MEM_OUTPUT, largest, 3 * sizeof *radiance, "bake: HDR texels") : NULL;
    if (!radiance) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    for (size_t a = 0; a < n && r == RAD_OK; a++) {
        const rad_atlas *atlas = &lm->atlases[a];
        char *png = image_path(ctx, path, a, "png"), *hdr = image_path(ctx, path, a, "hdr");
        maps.png_uris[a] = png ? uri_encode(ctx, base_name(png)) : NULL;
        maps.hdr_names[a] = hdr ? rad_strdup(ctx, RAD_MEM_OUTPUT, base_name(hdr), "bake: file names") : NULL;
        const char *png_temp = NULL, *hdr_temp = NULL;
        if (!maps.png_uris[a] || !maps.hdr_names[a])
            r = RAD_ERROR_OUT_OF_MEMORY;
        if (r == RAD_OK)
            r = temp_for(ctx, set, hdr, &hdr_temp);
        if (r == RAD_OK)
            r = temp_for(ctx, set, png, &png_temp);
        if (r == RAD_OK) {
            encode(atlas, maps.rgbm_range, rgbm, radiance);
            r = rad_write_hdr_rgb(ctx, hdr_temp, atlas->width, atlas->height, radiance);
        }
        if (r == RAD_OK)
            r = rad_write_png_rgba(ctx, png_temp, atlas->width, atlas->height, rgbm);
        rad_free(png);
        rad_free(hdr);
    }
    if (r == RAD_OK)
        r = rad_write_mesh_baked(ctx, view, mesh_temp, options->exposure, &maps);
    if (r == RAD_OK) {
        stats->atlases = n;
        stats->chart_texels = lm->chart_texels;
        stats->atlas_texels = lm->atlas_texels;
    }
done:
    for (size_t a = 0; a < n && maps.hdr_names; a++) {
        rad_free(maps.png_uris[a]);
        rad_free(maps.hdr_names[a]);
    }
    rad_free(maps.png_uris);
    rad_free(maps.hdr_names);
    rad_free(rgbm);
    rad_free(radiance);
    rad_lightmap_destroy(lm);
    return r;
}
