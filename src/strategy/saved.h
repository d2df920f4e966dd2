/*
 * saved.h -- the solution file: a solved solution kept on disk, to render
 * again from any camera without solving again (docs/formats.md).
 *
 * Layout (every number little-endian):
 *
 *   0   8 bytes  magic "\x89RADSOL\n" (the high bit catches 7-bit transfers,
 *                the newline text-mode ones, as PNG's signature does)
 *   8   u32      H, the header's length in bytes
 *   12  H bytes  header: JSON text (cJSON) with the format version, the
 *                counts, the payload's size and FNV-1a 64 checksum, the
 *                scene's source, surfaces, materials, camera and checksum,
 *                the options (every field of the option table) and the
 *                solve's figures
 *   then, from the next multiple of 8: the payload, arrays in this order
 *     scene      positions 3 x f64, indices u32, polygons 4 x u32
 *                (first index, vertex count, surface, material)
 *     mesh       patches, elements, welded vertices 3 x f64, T-vertices,
 *                quadtree (4 x u32 per internal node)
 *     values     element radiosity 3 x f64 (W/m^2), vertex radiosity
 *                3 x f64 (W/m^2, as the renderer interpolates them)
 *     light      only with luminaires (the header's "light": each
 *                distribution's source, shape and angle counts, each
 *                luminaire's name and distribution): per distribution width,
 *                length, height, C angles, gamma angles, candela (f64); per
 *                luminaire position, 3 axes, multiplier (13 f64); each
 *                element's direct irradiance 3 x f64 (W/m^2)
 *     daylight   only with daylight (the header's "daylight": its file's
 *                name, sky model and type, ground, opening count and the
 *                openings' surface names, whether the direct irradiance
 *                follows): the sky's a, b, c, d, e, sun zenith and azimuth,
 *                norm, zenith radiance, horizontal irradiance, its up, north,
 *                east and sun directions (22 f64); the sun's normal
 *                irradiance, the ground's reflectance and radiance, the
 *                zenith luminance, diffuse illuminance and tolerance (6 f64);
 *                per opening its corner count and surface (2 u32), 4
 *                corners, normal, area (16 f64); then, without luminaires,
 *                each element's direct irradiance 3 x f64 (W/m^2)
 *
 * Loading trusts nothing: the scene is rebuilt through the scene builder
 * (which validates every polygon) and must hash to the stored checksum;
 * every index of the mesh is bounded, every patch's elements are its
 * grid or its quadtree exactly once, every value finite and physical.
 */
#ifndef RAD_SAVED_H
#define RAD_SAVED_H

#include "strategy/strategy.h"

#define RAD_SAVED_MAGIC "\x89RADSOL\n"
#define RAD_SAVED_MAGIC_SIZE 8
#define RAD_SAVED_VERSION 1

/* FNV-1a, 64 bits (Fowler, Noll, Vo), continued from `hash` (start with
 * RAD_FNV_OFFSET).  A checksum against corruption, not an adversary. */
#define RAD_FNV_OFFSET 0xcbf29ce484222325ull
uint64_t rad_fnv1a(uint64_t hash, const void *data, size_t size);

/* The scene's checksum: FNV-1a over its positions, polygons, surface names
 * and materials, in a fixed little-endian encoding. */
uint64_t rad_saved_scene_checksum(const rad_scene *scene);

/* A growing little-endian byte buffer (the writer's and the tests'). */
typedef struct rad_bytes {
    unsigned char *data;
    size_t size, capacity;
    bool failed;             /* an allocation failed: everything after is dropped */
    rad_context *ctx;
} rad_bytes;

void rad_bytes_u32(rad_bytes *b, uint32_t v);
void rad_bytes_f64(rad_bytes *b, double v);
void rad_bytes_raw(rad_bytes *b, const void *data, size_t size);
void rad_bytes_free(rad_bytes *b);

struct cJSON;
/* The light part of the payload (luminaires and the elements' direct
 * irradiance `direct`, 3n, NULL: zeros) and its header object; NULL when
 * out of memory. */
struct cJSON *rad_saved_put_light(rad_bytes *b, const rad_scene *scene, const double *direct, size_t n);
/* The daylight part of the payload (the sky as prepared, the sun, the
 * ground, the openings; then the elements' direct irradiance `direct`, 3n,
 * unless NULL: the light part holds it when there are luminaires too) and
 * its header object; NULL when out of memory. */
struct rad_daylight;
struct cJSON *rad_saved_put_daylight(rad_bytes *b, const struct rad_daylight *daylight, const double *direct,
                                     size_t n);

/* The scene and mesh part of the payload, and the counts that go with it
 * into the header (a cJSON object, `counts`). */
struct cJSON;
void rad_saved_put_scene_and_mesh(rad_bytes *b, const rad_scene *scene, const rad_mesh *mesh,
                                  struct cJSON *counts);

/* Read a solution file's bytes (`name` for messages): the scene it was
 * solved for, and the strategy state of the saved solution (its mesh, ray
 * structure, values and figures).  *options receives the options it was
 * solved with (method names copied into *names).  On failure nothing is
 * returned, and the message names the file and what is wrong with it:
 * RAD_ERROR_PARSE for a file that is not a solution file or is damaged,
 * RAD_ERROR_INVALID_SCENE where its scene does not validate. */
struct rad_method_names;
rad_result rad_saved_read(rad_context *ctx, const char *name, const unsigned char *data, size_t size,
                          rad_scene **scene, rad_options *options, struct rad_method_names *names,
                          void **state);

/* The strategy of a loaded solution: solved already, so its solve only
 * says so; it answers to no solver name. */
extern const rad_strategy rad_strategy_saved;

#endif /* RAD_SAVED_H */
