/*
 * fuzz_gltf.c -- a glTF 2.0 JSON file (.gltf) from memory: cJSON for the
 * emissive strength and camera, assimp's glTF reader, the scene builder
 * and the mesher.  Buffers must be embedded (data: URIs): nothing else
 * can be opened from memory.
 */
#include "fuzz_scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rad_context_options co = {.threads = 1, .on_warning = fuzz_check_warning};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_scene *scene = NULL;
    rad_result r = rad_scene_load_memory(ctx, "x.gltf", data, size, NULL, 0, &scene);
    fuzz_check_load(ctx, r, scene);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
