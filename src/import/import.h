/*
 * import.h -- the readers that make a scene from a file: OBJ (+MTL) and
 * glTF 2.0 through assimp, NIST View3D's .vs3 by its own reader; and the
 * public loaders (load.c), which tell them apart by name and content.
 *
 *     file --detect--> assimp (OBJ, glTF, GLB) | View3D (.vs3) --> builder --> rad_scene
 */
#ifndef RAD_IMPORT_H
#define RAD_IMPORT_H

#include "scene/scene.h"

/* assimp: OBJ(+MTL) and glTF 2.0, from a file or memory (import/import_assimp.c). */
rad_result rad_import_assimp_file(rad_context *ctx, const char *path, rad_scene **out);
rad_result rad_import_assimp_memory(rad_context *ctx, const char *name, const void *data,
                                    size_t size, const void *mtl, size_t mtl_size,
                                    rad_scene **out);

/* View3D's .vs3 vertex/surface format (import/import_vs3.c). */
rad_result rad_import_vs3_memory(rad_context *ctx, const char *name, const char *text, size_t size,
                                 rad_scene **out);
rad_result rad_import_vs3_file(rad_context *ctx, const char *path, rad_scene **out);
/* True when a file's name ends in .vs3 (any case) or its text begins, after
 * blank and comment lines, with a View3D title or control line ("T ", "C "). */
bool rad_vs3_detect(const char *name, const char *text, size_t size);

#endif /* RAD_IMPORT_H */
