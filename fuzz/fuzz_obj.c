/*
 * fuzz_obj.c -- a scene file from memory (no material library): the
 * content detection, the pre-scan, assimp's OBJ reader (or its glTF
 * reader, for input that is JSON or binary glTF by its content), the scene
 * builder and the mesher.  The input is loaded under two names, "x.obj"
 * and "scene": the reader is chosen by content, so both loads must end
 * alike (the same result, the same surfaces and areas).
 */
#include "fuzz_scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rad_context_options co = {.threads = 1, .on_warning = fuzz_check_warning};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_scene *scene = NULL, *unnamed = NULL;
    rad_result r = rad_scene_load_memory(ctx, "x.obj", data, size, NULL, 0, &scene);
    fuzz_check_load(ctx, r, scene);
    rad_result r_unnamed = rad_scene_load_memory(ctx, "scene", data, size, NULL, 0, &unnamed);
    FUZZ_CHECK(r_unnamed == r);
    if (r == RAD_OK) {
        size_t surfaces = rad_scene_surface_count(scene);
        FUZZ_CHECK(rad_scene_surface_count(unnamed) == surfaces);
        FUZZ_CHECK(rad_scene_polygon_count(unnamed) == rad_scene_polygon_count(scene));
        for (size_t i = 0; i < surfaces; i++)
            FUZZ_CHECK(rad_scene_surface_area(unnamed, i) == rad_scene_surface_area(scene, i));
    }
    rad_scene_destroy(unnamed);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
