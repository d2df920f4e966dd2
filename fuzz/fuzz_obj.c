/*
 * fuzz_obj.c -- an OBJ file from memory (no material library): the
 * pre-scan, assimp's OBJ reader, the scene builder and the mesher.
 */
#include "fuzz_scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rad_context_options co = {.threads = 1};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_scene *scene = NULL;
    rad_result r = rad_scene_load_memory(ctx, "x.obj", data, size, NULL, 0, &scene);
    fuzz_check_load(ctx, r, scene);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
