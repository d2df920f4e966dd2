/*
 * layout.h -- luminaires placed in a scene (docs/lighting.md "Luminaires"):
 * from a layout file (JSON) or from glTF nodes whose extras name a
 * photometric file.  Both end in the scene's photometries (each file once)
 * and luminaires (rad_luminaire: position, frame, multiplier).
 */
#ifndef RAD_LAYOUT_H
#define RAD_LAYOUT_H

#include "core/core.h"

struct rad_photometry;

/* A luminaire placed in the scene (docs/lighting.md "Luminaires"): a
 * photometric distribution at a position, turned by its frame.  It is a
 * light source, not geometry: it has no elements and blocks no rays. */
typedef struct rad_luminaire {
    char *name;               /* unique: the layout's name (with its index in an array) or the glTF node's */
    uint32_t photometry;      /* index into the set's photometries */
    vec3 position;            /* m: the photometric centre */
    vec3 axis[3];             /* unit, world: the luminaire's x (C = 0), y (C = 90), z (up; nadir = -z) */
    double multiplier;        /* on the file's candela: light loss factor x lumens override ratio x
                                 the tilt factor for this orientation */
} rad_luminaire;

/* The luminaires of a scene: each photometric file once, and the
 * placements that use them (rad_scene.luminaires). */
typedef struct rad_luminaire_set {
    struct rad_photometry **photometries; /* each file once */
    size_t photometry_count;
    rad_luminaire *items;
    size_t count;
} rad_luminaire_set;

/* Free what the set holds and empty it.  Cannot fail. */
void rad_luminaire_set_free(rad_luminaire_set *set);
struct cJSON;

/* How a photometric file named by a layout is read: `path` as resolved
 * (relative to the layout's folder); *out a new distribution on success,
 * its source set to `path`.  The error message is the loader's. */
typedef rad_result (*rad_photometry_loader)(rad_context *ctx, const char *path, void *user,
                                            struct rad_photometry **out);

/* The loader of files: rad_photometry_load (IES LM-63, EULUMDAT; user
 * unused). */
rad_result rad_layout_load_photometry(rad_context *ctx, const char *path, void *user,
                                      struct rad_photometry **out);

/* The luminaire's frame (axis[0] = x, C = 0; axis[1] = y, C = 90;
 * axis[2] = z, the nadir being -z) for a nadir along `aim` (any length but
 * zero) in a world whose up is `up` (unit), turned by `spin_degrees` about
 * the luminaire's z (positive turns C = 0 from x towards y: counter-
 * clockwise seen from above the luminaire).  Spin 0: the minimal rotation
 * that takes straight down (-up) to the aim carries the world's reference
 * axis (the one of x, y, z least along up, x first) into C = 0; straight up
 * turns about that axis.  Cannot fail. */
void rad_layout_frame(vec3 aim, vec3 up, double spin_degrees, vec3 axis[3]);

/* The angle in degrees between the nadir (-axis[2]) and straight down. */
double rad_layout_tilt_degrees(const vec3 axis[3], vec3 up);

/* Read the layout [text, text + size) named `name` (its folder resolves
 * the relative file names) and add its luminaires to `set` (a scene's), loading each
 * photometric file once with `load` (files the set already holds are
 * shared).  All or nothing: on failure the set is as it was.  Fails with
 * RAD_ERROR_PARSE and one line naming the file, the entry and the key
 * ("room.json: luminaires[2].aim: must be 3 finite numbers, not all 0"),
 * the loader's error, RAD_ERROR_OUT_OF_MEMORY. */
rad_result rad_layout_parse(rad_context *ctx, rad_luminaire_set *set, const char *name, const char *text, size_t size,
                            rad_photometry_loader load, void *user);

/* A glTF node that places a luminaire: its label for messages ("node 3
 * 'lamp'"), its world transform (rows of [R | t], glTF's column vectors)
 * and its extras object (owned by the glTF's JSON). */
typedef struct rad_gltf_luminaire {
    char label[160];
    char name[128];           /* the node's name, or "node 3" */
    double world[3][4];
    const struct cJSON *extras;
} rad_gltf_luminaire;

/* True when a node's extras place a luminaire (they hold "luminaire"). */
bool rad_gltf_extras_place_luminaire(const struct cJSON *extras);

/* Add the luminaires of glTF nodes to `set` (the glTF `name`'s folder
 * resolves the files): at the node's origin, nadir along its local -z,
 * C = 0 along its local x, the tilt measured from the glTF's down (-y).
 * Extras keys: "luminaire" (file), "llf", "lumens", "multiplier", "name"
 * (default: the node's name); other keys are the modeller's and ignored.  All or nothing, errors as rad_layout_parse's
 * naming the node. */
rad_result rad_layout_place_gltf(rad_context *ctx, rad_luminaire_set *set, const char *name,
                                 const rad_gltf_luminaire *nodes, size_t count, rad_photometry_loader load,
                                 void *user);

/* The luminous flux (lm) luminaire k sends out: its distribution's flux x
 * its multiplier. */
double rad_luminaire_flux(const rad_luminaire_set *set, size_t k);

#endif
