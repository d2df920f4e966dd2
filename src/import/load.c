/*
 * load.c -- rad_scene_load_file and rad_scene_load_memory: the format told
 * by name and content (View3D's .vs3 by its extension or first record,
 * everything else through assimp), the importer run, its time kept.
 */
#include "import/import.h"

#include <stdio.h>
#include <sys/stat.h>

rad_result rad_scene_load_file(rad_context *ctx, const char *path, rad_scene **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !path || !out)
        return rad_null_argument(ctx, __func__);
    double start = rad_seconds();
    /* View3D's .vs3, by its extension or its first record. */
    char head[512];
    size_t head_size = 0;
    struct stat st;
    FILE *peek = stat(path, &st) == 0 && S_ISREG(st.st_mode) ? fopen(path, "rb") : NULL;
    if (peek) { /* regular files only: a FIFO's bytes are read once */
        head_size = fread(head, 1, sizeof head, peek);
        fclose(peek);
    }
    rad_result r = rad_vs3_detect(path, head, head_size) ? rad_import_vs3_file(ctx, path, out)
                                                          : rad_import_assimp_file(ctx, path, out);
    if (r == RAD_OK)
        (*out)->load_seconds = rad_seconds() - start;
    return r;
}

rad_result rad_scene_load_memory(rad_context *ctx, const char *name, const void *data,
                                 size_t size, const void *mtl, size_t mtl_size,
                                 rad_scene **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !name || !out || (!data && size > 0) || (!mtl && mtl_size > 0))
        return rad_null_argument(ctx, __func__);
    double start = rad_seconds();
    rad_result r = rad_vs3_detect(name, data, size)
                       ? rad_import_vs3_memory(ctx, name, data, size, out)
                       : rad_import_assimp_memory(ctx, name, data, size, mtl, mtl_size, out);
    if (r == RAD_OK)
        (*out)->load_seconds = rad_seconds() - start;
    return r;
}
