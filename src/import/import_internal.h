/*
 * import_internal.h -- what the files of the assimp importer share, and
 * nothing outside scene/ uses:
 *
 *    import_input.c  a scene's bytes read once, within the memory limit;
 *                    its format by content; an OBJ's material libraries
 *    obj_prescan.c   OBJ/MTL text checked, with line numbers, before assimp
 *    gltf_fixes.c    GLB framing checked before assimp; glTF JSON read after
 *    gltf_check.c    a glTF's nodes, meshes, buffers and memory checked before
 *                    assimp; its camera
 *    unused.c        what a file's materials say that the engine does not use,
 *                    noted before assimp, said as warnings after the load
 *    assimp_io.c     the file system assimp reads through: the input from
 *                    memory, a glTF's other files logged and confined
 *    import_assimp.c aiScene -> rad_scene_builder, and the two entry points
 */
#ifndef RAD_SCENE_IMPORT_INTERNAL_H
#define RAD_SCENE_IMPORT_INTERNAL_H

#include "import/import.h"

struct aiFileIO;
struct cJSON;

/* ---- unused.c ---- */

/* One note of what a file says that the engine does not use: a material's
 * properties (listed with the surfaces that use it once the scene is
 * built), or something of the whole file. */
typedef struct import_note {
    char *subject;   /* "scene.mtl: material 'mirror'", "x.gltf" (rad_alloc'd) */
    char *what;      /* "Ks and illum 3 are not used (...)" (rad_alloc'd) */
    char *material;  /* OBJ: the material's name, as assimp names it (rad_alloc'd); else NULL */
    size_t index;    /* glTF: the material's index; IMPORT_NOTE_FILE: the whole file;
                        SIZE_MAX with `material` */
    char *surfaces;  /* "surfaces 'a', 'b'" once known (rad_alloc'd); NULL: no surface uses
                        the material, and nothing is said */
} import_note;

#define IMPORT_NOTE_FILE (SIZE_MAX - 1)

typedef struct import_notes {
    import_note *items; /* in the order said (rad_alloc'd) */
    size_t count, capacity;
} import_notes;

/* Most lines of notes one load says; then one line counts the rest. */
#define IMPORT_NOTES_MAX_LINES 10

/* Add a note (the strings are copied); RAD_ERROR_OUT_OF_MEMORY else. */
rad_result import_notes_add(rad_context *ctx, import_notes *notes, const char *subject,
                            const char *material, size_t index, const char *what);
/* Join `count` items as "a", "a and b", "a, b and c". */
void import_join_items(char *text, size_t size, const char *const *items, size_t count);
/* Note what the glTF `root` (of file `name`) says that is not used: per
 * material, textures, metallicFactor > 0, alphaMode BLEND / MASK where it
 * shows, material extensions other than KHR_materials_emissive_strength,
 * vertex colours of its primitives; the extensions of extensionsUsed that
 * nothing else names.  RAD_ERROR_OUT_OF_MEMORY or RAD_OK. */
rad_result import_gltf_note_unused(rad_context *ctx, const char *name, const struct cJSON *root,
                                   import_notes *notes, bool textures_read);
/* Set `note`'s surfaces: `shown` names (at most 3) of `total` distinct
 * surfaces.  RAD_ERROR_OUT_OF_MEMORY or RAD_OK. */
rad_result import_note_set_surfaces(rad_context *ctx, import_note *note,
                                    const char *const *names, size_t shown, size_t total);
/* Say the notes through rad_warn, the whole file's first, then each
 * material's that some surface uses: at most IMPORT_NOTES_MAX_LINES lines,
 * then "NAME: ... and N more materials with unused properties" (`name`: the
 * scene's).  Cannot fail. */
void import_notes_warn(rad_context *ctx, const char *name, const import_notes *notes);
void import_notes_free(import_notes *notes);

/* ---- obj_prescan.c ---- */

/* An `mtllib` statement of an OBJ: the rest of its line, which names one
 * or more material libraries (the loader splits it). */
typedef struct import_obj_mtllib {
    char *names;   /* blanks trimmed (rad_alloc'd) */
    int line;
    size_t offset; /* of the statement in the text */
} import_obj_mtllib;

typedef struct import_obj_scan {
    import_obj_mtllib *mtllibs; /* every `mtllib` statement, in order (rad_alloc'd) */
    size_t mtllib_count, mtllib_capacity;
} import_obj_scan;

/* Check the OBJ text [text, text + size) (`path` names it in messages) and
 * list its `mtllib` statements in `scan` (import_obj_scan_free it).
 * Fails with a line-numbered RAD_ERROR_PARSE or RAD_ERROR_INVALID_SCENE,
 * or RAD_ERROR_OUT_OF_MEMORY; `scan` is then empty. */
rad_result import_obj_prescan(rad_context *ctx, const char *path, const char *text, size_t size,
                              import_obj_scan *scan);
void import_obj_scan_free(import_obj_scan *scan);

/* The OBJ's vertex positions as the file writes them, for assimp keeps
 * them as float (Debian's assimp is built with float ai_real), and the
 * text assimp is served instead, whose every `v` statement is rewritten as
 * "v LOW HIGH 0": its 0-based index k = LOW + HIGH x 2^24, each part an
 * integer below 2^24, so exact in float.  assimp copies a position to
 * every face corner that names it, so each corner of its meshes gives the
 * index of the exact position back (import_assimp.c).  OBJ only. */
typedef struct import_obj_positions {
    double *xyz;  /* 3 per `v` statement, in file order; x/w etc. for "v x y z w" (rad_alloc'd) */
    size_t count;
    char *text;   /* the OBJ text with its `v` statements rewritten (rad_alloc'd) */
    size_t size;
    bool has_camera;    /* a RAD_OBJ_CAMERA_COMMENT line, well formed */
    rad_camera camera;
} import_obj_positions;

#define IMPORT_OBJ_INDEX_BITS 24

/* Read the positions of the pre-scanned OBJ text [text, text + size) with
 * strtod and make the text assimp reads.  RAD_ERROR_OUT_OF_MEMORY (`out`
 * then empty) or RAD_OK. */
rad_result import_obj_exact_positions(rad_context *ctx, const char *path, const char *text,
                                      size_t size, import_obj_positions *out);
void import_obj_positions_free(import_obj_positions *positions);

/* The materials the libraries of one OBJ define: where each name is. */
typedef struct import_material_name {
    char *name;     /* as `newmtl` gives it, the rest of its line (rad_alloc'd) */
    size_t library; /* index into import_material_names.libraries */
    int line;
    size_t order;   /* definition order */
    bool has_kd, has_ke; /* Kd / Ke given (the last of each counts, as in assimp) */
    double kd[3], ke[3]; /* as strtod reads them: assimp keeps only floats */
    int map_kd_line;     /* the line of its (last) map_Kd; 0: none */
    /* The specular statements (the last of each counts; NAN when absent or
     * not numbers): Ks (one value is grey), Ns, Ni, d, Tr, illum. */
    double ks[3], ns, ni, d, tr, illum;
    int ks_line, ni_line; /* the line of the last Ks (Ni), or of newmtl */
} import_material_name;

typedef struct import_material_names {
    import_material_name *entries; /* rad_alloc'd */
    size_t count, capacity;
    char **libraries;              /* the libraries' names for messages (rad_alloc'd) */
    size_t library_count, library_capacity;
    bool sorted;                   /* by name (import_material_names_check) */
    bool textures_read;            /* a file load: map_Kd is read (texture.c), so not noted unused */
} import_material_names;

/* Check the MTL text [text, text + size), as import_obj_prescan, and add
 * its materials to `names`; note in `notes` (NULL: none) what each
 * material says beyond Kd and Ke that would change its look. */
rad_result import_mtl_prescan(rad_context *ctx, const char *path, const char *text, size_t size,
                              import_material_names *names, import_notes *notes);
/* After the last library: a name defined twice (in one library or two)
 * fails, naming both places (assimp would merge the two silently). */
rad_result import_material_names_check(rad_context *ctx, import_material_names *names);
/* Every `usemtl` of the OBJ text names a material of `names` (checked):
 * RAD_ERROR_PARSE with the line otherwise (assimp would use its grey
 * default material silently). */
rad_result import_obj_check_usemtl(rad_context *ctx, const char *path, const char *text,
                                   size_t size, const import_material_names *names);
void import_material_names_free(import_material_names *names);
/* The material called `name` (names sorted by import_material_names_check),
 * or NULL.  Cannot fail. */
const import_material_name *import_material_find(const import_material_names *names,
                                                 const char *name);

/* ---- import_input.c ---- */

/* What a scene's bytes are.  Chosen by content, never by the file's name:
 * assimp 5.2 picks its reader by the extension when one reader claims
 * it, and by content otherwise (an OBJ named `scene` or `s.txt` reached
 * assimp without the pre-scan). */
typedef enum import_format {
    IMPORT_OBJ,  /* anything else: read as OBJ, so pre-scanned as OBJ */
    IMPORT_GLTF, /* JSON: '{' first, after an optional UTF-8 byte order mark and blanks */
    IMPORT_GLB   /* binary glTF: the magic "glTF" first */
} import_format;

import_format import_format_of(const char *data, size_t size);
/* "obj", "gltf", "glb". */
const char *import_format_extension(import_format format);

/* Bytes of scene text (the file and its libraries) assimp may take per
 * byte while importing; see import_input.c. */
#define IMPORT_ASSIMP_PEAK_PER_BYTE 20.0

/* A scene's input, read and checked: what assimp is then served, from
 * memory, under a name that makes it pick the reader of `format`. */
typedef struct import_input {
    import_format format;
    char *alias;           /* the scene's name with the format's extension, unless it has it */
    const char *data;      /* the scene's bytes; an OBJ's `mtllib` statements after the
                              first are made comments (the first serves every library) */
    size_t size;
    const char *materials; /* OBJ: every library's text, one after the other; NULL: none */
    size_t materials_size;
    import_notes notes;    /* what the pre-scans found unused, said after a load (unused.c) */
    char *owned[2];        /* the blocks above that are ours (rad_free) */
    import_obj_positions positions; /* OBJ: the exact positions; `data` is then its text */
    import_material_names materials_exact; /* OBJ: every library's materials, Kd and Ke exact */
} import_input;

/* Read the scene file `path` once (within the memory limit: a file or
 * stream whose import could pass it is refused before assimp sees it),
 * find its format, pre-scan an OBJ and read and pre-scan every material
 * library it names (each file passing `log`'s confinement and noted in
 * it).  Fails with RAD_ERROR_IO, RAD_ERROR_PARSE, RAD_ERROR_INVALID_SCENE,
 * RAD_ERROR_OUT_OF_MEMORY, RAD_ERROR_INTERRUPTED; `in` is then empty. */
rad_result import_input_read_file(rad_context *ctx, const char *path, rad_input_log *log,
                                  import_input *in);
/* The same from memory: `mtl` (NULL: none) holds every library an OBJ
 * names.  The buffers are borrowed, or copied where an OBJ's text is
 * changed. */
rad_result import_input_from_memory(rad_context *ctx, const char *name, const char *data,
                                    size_t size, const char *mtl, size_t mtl_size,
                                    import_input *in);
/* Free what `in` owns, its notes included.  Cannot fail. */
void import_input_free(import_input *in);

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

/* The glTF material (from the "materials" array) that assimp imported as
 * material `index` named `name`: assimp keeps the glTF order (and appends
 * a default material), so matched by index, by name when the names
 * differ; NULL if none.  Cannot fail. */
const struct cJSON *import_gltf_material(const struct cJSON *materials, unsigned index, const char *name);

/* glTF metals rougher than this stay diffuse (said unread): their lobe
 * (Ns = 2 / r^4 - 2 < 30) is wider than the second pass shows well. */
#define IMPORT_GLTF_MAX_ROUGHNESS 0.5

/* A glTF material's specular part (docs/units.md "Specular materials"). */
typedef struct import_specular {
    rad_specular_kind kind;
    double reflectance[3], specular[3]; /* rho_d and rho_s (glass: t) */
    double shininess, ior;
} import_specular;

/* The specular part of glTF `material` with base colour `base`, into
 * *out: KHR_materials_transmission's factor t > 0 is glass of
 * KHR_materials_ior's index (1.5), rho_d = (1 - t) base; else a written
 * metallicFactor m > 0 with roughnessFactor r (1) at most
 * IMPORT_GLTF_MAX_ROUGHNESS is a mirror (r = 0) or a Phong lobe, rho_s =
 * m base, rho_d = (1 - m) base.  False (out untouched) when the material
 * is diffuse.  Cannot fail. */
bool import_gltf_specular(const struct cJSON *material, const double base[3], import_specular *out);

/* The emissive strength (1 when absent) of assimp material `index` named
 * `name`, from the glTF "materials" array. */
double import_gltf_emissive_strength(const struct cJSON *materials, unsigned index,
                                     const char *name);

/* ---- gltf_check.c ---- */

/* What the check learnt for the import. */
struct rad_gltf_luminaire; /* photometry/layout.h */
typedef struct import_gltf_facts {
    bool has_camera;   /* the scene's first perspective camera, placed */
    rad_camera camera;
    /* The nodes whose extras place a luminaire, in the walk's order
     * (rad_alloc'd; the extras point into the checked JSON). */
    struct rad_gltf_luminaire *luminaires;
    size_t luminaire_count;
} import_gltf_facts;

/* Check the glTF `json` (of the file `name`, `size` bytes at `data`; a .glb
 * when `binary`) before assimp reads it: version 2.x; nodes in disjoint
 * strict trees at most 1,000 deep; primitives with valid modes and counts,
 * unsigned indices below their vertex count, finite float positions,
 * accessors inside their buffers (read through `io`, which opens the
 * external ones); what the import will take against the memory limit.
 * Fills `facts` (the camera; an orthographic one is replaced, with a
 * warning; the nodes whose extras place luminaires, which the caller
 * rad_frees).  Fails with a one-line message naming the file and the node,
 * mesh, primitive or accessor: RAD_ERROR_PARSE, RAD_ERROR_INVALID_SCENE
 * (non-finite positions, a degenerate camera), RAD_ERROR_IO (a buffer that
 * cannot be read), RAD_ERROR_OUT_OF_MEMORY. */
rad_result import_gltf_check(rad_context *ctx, const char *name, const char *data, size_t size,
                             bool binary, const struct cJSON *json, struct aiFileIO *io,
                             import_gltf_facts *facts);

/* ---- assimp_io.c ---- */

/* What assimp reads through import_io: the input from memory under its
 * alias; for an OBJ, the libraries' text under any other name (assimp
 * opens only the `mtllib` it sees, the first); for glTF, other files from
 * the disk through `log` (NULL: none, as for a memory load). */
typedef struct import_files {
    rad_context *ctx;        /* the open files' handles are allocated in it */
    const import_input *in;
    rad_input_log *log;
    bool out_of_memory;      /* an open failed for memory: assimp may carry on without the file */
} import_files;

/* Fill `io` so that assimp reads `files` (which must outlive the import).
 * Cannot fail. */
void import_io(struct aiFileIO *io, import_files *files);

/* Read the image at `path` (PNG, JPEG, BMP, TGA...: stb_image) as a
 * reflectance texture: width x height x 3 linear floats (rad_alloc'd, row
 * 0 the image's top) into *rgb.  On failure *rgb is NULL, `why` says why
 * in a few words, and the result is RAD_ERROR_IO (cannot open),
 * RAD_ERROR_PARSE (not an image) or RAD_ERROR_OUT_OF_MEMORY (above the
 * memory limit, checked from the header before decoding); nothing is
 * reported to the context: the caller names the material. */
rad_result import_texture_read(rad_context *ctx, const char *path, float **rgb, int *width, int *height,
                               char *why, size_t why_size);

#endif /* RAD_SCENE_IMPORT_INTERNAL_H */
