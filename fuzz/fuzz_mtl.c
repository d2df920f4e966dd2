/*
 * fuzz_mtl.c -- a material library from memory beside a fixed OBJ that
 * names it in two `mtllib` statements (the buffer holds every library's
 * materials) and uses three of its materials (by the names the seeds
 * use): the MTL pre-scan, the material names (each defined once, each
 * used one defined), assimp's MTL reader and material validation.
 */
#include "fuzz_scene.h"

static const char obj[] = "mtllib x.mtl\nmtllib y.mtl\n"
                          "o floor\nusemtl white\n"
                          "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 4 3 2\n"
                          "o lamp\nusemtl light\n"
                          "v 0 1 0\nv 1 1 0\nv 1 1 1\nv 0 1 1\nf 5 6 7 8\n"
                          "o wall\nusemtl red\n"
                          "v 0 0 0\nv 0 1 0\nv 0 1 1\nf 9 10 11\n";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rad_context_options co = {.threads = 1, .on_warning = fuzz_check_warning};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_scene *scene = NULL;
    rad_result r = rad_scene_load_memory(ctx, "x.obj", obj, sizeof obj - 1, data, size, &scene);
    fuzz_check_load(ctx, r, scene);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
