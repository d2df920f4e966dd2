/*
 * fuzz_vs3.c -- a View3D .vs3 file from memory (import/import_vs3.c): the
 * records, the control line, the surface relations and the holes cut for
 * sub-surfaces and null surfaces, then scene validation.  A failure must
 * leave a one-line message; a scene must be usable (fuzz_check_load).
 */
#include "fuzz_scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rad_context_options co = {.threads = 1, .on_warning = fuzz_check_warning};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_scene *scene = NULL;
    rad_result r = rad_scene_load_memory(ctx, "x.vs3", data, size, NULL, 0, &scene);
    fuzz_check_load(ctx, r, scene);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
