/*
 * fuzz_glb.c -- a binary glTF 2.0 file (.glb) from memory: the GLB header
 * and JSON chunk as our code reads them (cJSON, for the emissive strength
 * and camera), assimp's GLB reader with the binary chunk, the scene
 * builder and the mesher.
 */
#include "fuzz_scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rad_context_options co = {.threads = 1, .on_warning = fuzz_check_warning};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_scene *scene = NULL;
    rad_result r = rad_scene_load_memory(ctx, "x.glb", data, size, NULL, 0, &scene);
    fuzz_check_load(ctx, r, scene);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
