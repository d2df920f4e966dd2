/*
 * import_internal.h -- what the files of the assimp importer share, and
 * nothing outside scene/ uses:
 *
 *    obj_prescan.c   OBJ/MTL text checked, with line numbers, before assimp
 *    gltf_fixes.c    GLB framing checked before assimp; glTF JSON read after
 *    gltf_check.c    a glTF's nodes, meshes, buffers and memory checked before
 *                    assimp; its camera
 *    assimp_io.c     a memory file system for assimp
 *    import_assimp.c aiScene -> rad_scene_builder, and the two entry points
 */
#ifndef RAD_SCENE_IMPORT_INTERNAL_H
#define RAD_SCENE_IMPORT_INTERNAL_H

#include "scene/scene.h"

struct aiFileIO;
struct cJSON;

/* ---- obj_prescan.c ---- */

/* Check the OBJ text [text, text + size) (`path` names it in messages);
 * writes the first `mtllib` name (or "", cut to mtllib_size - 1
 * characters) and its line.  Fails with a line-numbered RAD_ERROR_PARSE
 * or RAD_ERROR_INVALID_SCENE. */
rad_result import_obj_prescan(rad_context *ctx, const char *path, const char *text, size_t size,
                              char *mtllib, size_t mtllib_size, int *mtllib_line);

/* Check the MTL text [text, text + size), as import_obj_prescan. */
rad_result import_mtl_prescan(rad_context *ctx, const char *path, const char *text, size_t size);

/* ---- gltf_fixes.c ---- */

/* The parsed JSON of a .gltf (binary false) or a .glb (its JSON chunk),
 * owned by the caller (cJSON_Delete); NULL if there is none, with
 * *error_offset the byte of the file where the JSON stops parsing (0 when
 * a .glb has no JSON chunk). */
struct cJSON *import_gltf_json(const char *data, size_t size, bool binary, size_t *error_offset);

/* Check that a GLB's header and chunks lie within its `size` bytes, its
 * JSON chunk 4-byte aligned; RAD_ERROR_PARSE naming `name` if not. */
rad_result import_glb_check_framing(rad_context *ctx, const char *name, const char *data,
                                    size_t size);

/* The emissive strength (1 when absent) of assimp material `index` named
 * `name`, from the glTF "materials" array. */
double import_gltf_emissive_strength(const struct cJSON *materials, unsigned index,
                                     const char *name);

/* ---- gltf_check.c ---- */

/* What the check learnt for the import. */
typedef struct import_gltf_facts {
    bool has_camera;   /* the scene's first perspective camera, placed */
    rad_camera camera;
} import_gltf_facts;

/* Check the glTF `json` (of the file `name`, `size` bytes at `data`; a .glb
 * when `binary`) before assimp reads it: version 2.x; nodes in disjoint
 * strict trees at most 1,000 deep; primitives with valid modes and counts,
 * unsigned indices below their vertex count, finite float positions,
 * accessors inside their buffers (read through `io`, which opens the
 * external ones); what the import will take against the memory limit.
 * Fills `facts` (the camera; an orthographic one is replaced, with a
 * warning).  Fails with a one-line message naming the file and the node,
 * mesh, primitive or accessor: RAD_ERROR_PARSE, RAD_ERROR_INVALID_SCENE
 * (non-finite positions, a degenerate camera), RAD_ERROR_IO (a buffer that
 * cannot be read), RAD_ERROR_OUT_OF_MEMORY. */
rad_result import_gltf_check(rad_context *ctx, const char *name, const char *data, size_t size,
                             bool binary, const struct cJSON *json, struct aiFileIO *io,
                             import_gltf_facts *facts);

/* ---- assimp_io.c ---- */

/* The files a memory import serves; the buffers are the caller's. */
typedef struct import_memory_fs {
    rad_context *ctx; /* the open files' handles are allocated in it */
    const char *name; /* the main buffer's file name */
    const char *data;
    size_t size;
    const char *mtl; /* served under any *.mtl name; NULL if none */
    size_t mtl_size;
    bool out_of_memory; /* an open failed for memory: assimp may carry on without the file */
} import_memory_fs;

/* Fill `io` so that assimp reads `fs` (which must outlive the import).
 * Cannot fail. */
void import_memory_io(struct aiFileIO *io, import_memory_fs *fs);

/* The files a file import opened: assimp reads through the file system as
 * its default would, and every file it opens for reading is named here (the
 * MTL of an OBJ, a glTF's buffers), so the scene can list its inputs. */
typedef struct import_file_log {
    char **paths;     /* rad_alloc'd, each rad_alloc'd; no repeats */
    size_t count, capacity;
    bool failed;      /* a name could not be kept (out of memory) */
    /* Confinement: when root is set, files outside it are refused. */
    rad_context *ctx; /* where a refusal is reported */
    const char *scene;/* the scene file, for the message */
    char *root;       /* realpath of the scene's folder (rad_alloc'd), or NULL */
    bool refused;     /* a file was refused (the context has the message) */
} import_file_log;

/* Confine `log` to the folder of `scene_path` unless the context allows
 * reading outside it.  Fails only for memory; a folder that cannot be
 * resolved confines to nothing looser: every reference is then refused. */
rad_result import_file_log_confine(rad_context *ctx, import_file_log *log, const char *scene_path);
/* Whether `path` may be read (inside the root, or no root); a refusal is
 * reported once to the context ("scene.gltf: refers to '../x.bin' outside
 * its folder ...") and sets log->refused. */
bool import_file_allowed(import_file_log *log, const char *path);

/* Fill `io` so that assimp reads files and logs them into `log` (which must
 * outlive the import).  Cannot fail. */
void import_file_io(struct aiFileIO *io, import_file_log *log);
/* Note a file read outside assimp (the pre-scans); sets log->failed when
 * out of memory. */
void import_file_log_add(import_file_log *log, const char *path);
/* Free the names.  Cannot fail. */
void import_file_log_free(import_file_log *log);

#endif /* RAD_SCENE_IMPORT_INTERNAL_H */
