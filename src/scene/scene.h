/*
 * scene.h -- the scene as the rest of the pipeline sees it: named surfaces
 * made of planar polygons (any vertex count, validated) with Lambertian
 * materials.  Importers (assimp for OBJ/MTL and glTF; the built-in Cornell
 * box) fill a rad_scene_builder; rad_scene_builder_finish validates and
 * produces the immutable scene.
 *
 *     importer --polygons, materials, names--> builder --validate--> rad_scene
 */
#ifndef RAD_SCENE_H
#define RAD_SCENE_H

#include "core/core.h"
#include "photometry/layout.h"

/* The specular part of a material (docs/units.md "Specular materials"):
 * what the first pass folds into extended form factors (mirrors) and the
 * renderer's second pass follows from the eye (all three). */
typedef enum rad_specular_kind {
    RAD_SPECULAR_NONE = 0, /* Lambertian only */
    RAD_SPECULAR_MIRROR,   /* ideal mirror: rho_s of the light leaves along the reflected ray */
    RAD_SPECULAR_GLOSSY,   /* Phong lobe of exponent `shininess` about the reflected ray */
    RAD_SPECULAR_GLASS     /* clear dielectric of index `ior`: Fresnel reflection and refraction */
} rad_specular_kind;

/* Ns at or above which an MTL reflection (illum 3, 5) is an ideal mirror:
 * a Phong lobe cos^1000 has half its energy within 2 degrees, finer than
 * the elements the mirror shows. */
#define RAD_MIRROR_SHININESS 1000.0

typedef struct rad_material {
    char *name;
    double reflectance[3]; /* rho (rho_d), RGB, in [0, 1): with a texture, Kd x the texture's mean */
    double emission[3];    /* E, self-emitted exitance, W/m^2 (= pi * radiance) */
    uint32_t texture;      /* 1 + index into rad_scene.textures (map_Kd, baseColorTexture); 0: none */
    double texture_scale[3]; /* with a texture: Kd, by which its texels are multiplied */
    rad_specular_kind specular_kind;
    double specular[3];    /* rho_s: mirror/glossy reflectance, glass transmittance factor;
                              rho_d + rho_s <= 1 per channel */
    double shininess;      /* Phong exponent (glossy), >= 0 */
    double ior;            /* glass: index of refraction against the air, > 1 */
} rad_material;

/* A reflectance texture (MTL map_Kd, glTF baseColorTexture): texels
 * decoded from sRGB to linear, a piecewise-constant function of (u, v) in
 * [0, 1)^2 repeated (wrapped) outside; row 0 is v = 1 (the image's top). */
typedef struct rad_texture {
    char *path;            /* the file, as the material names it */
    int width, height;     /* texels */
    float *rgb;            /* width x height x 3, linear, in [0, 1] */
    double mean[3];        /* over all texels */
} rad_texture;

typedef struct rad_surface {
    char *name;            /* OBJ o/g name, glTF node name; unique in the scene */
    double area;           /* m^2, sum of its polygons */
    bool obstruction;      /* View3D 'O' surface: blocks rays, not in the view-factor output */
    bool mask;             /* View3D 'M' surface: covers part of surface mask_base (facing it) */
    uint32_t mask_base;    /* the masked surface, when mask */
} rad_surface;

/* What a View3D .vs3 file's control line asks of the view-factor output
 * (import/import_vs3.c, docs/formats.md "View3D"); present is false for
 * every other format. */
typedef struct rad_view3d_control {
    bool present;
    int enclosure;            /* encl: 1 = the surfaces form an enclosure */
    int out_format;           /* out: 0 = text, 1 = binary */
    int emittances;           /* emit: 1 = the .vf holds Hottel's script-F factors */
} rad_view3d_control;

typedef struct rad_polygon {
    uint32_t first_index;  /* into rad_scene.indices */
    uint32_t vertex_count; /* >= 3 */
    uint32_t surface;
    uint32_t material;
    vec3 normal;           /* unit, right-hand rule over the vertex order */
    double area;           /* m^2 */
    uint32_t uv_map;       /* 1 + index into rad_scene.uv_maps; 0: no texture coordinates */
} rad_polygon;

/* Texture coordinates of a planar polygon as an affine map of position:
 * u = m[0] x + m[1] y + m[2] z + m[3], v = m[4] x + ... + m[7] (fitted to
 * three of its vertices; exact for triangles and for the parallelogram
 * maps modellers give quads). */
typedef struct rad_uv_map {
    double m[8];
} rad_uv_map;

/* (u, v) of point p of polygon `polygon`; false without coordinates. */
bool rad_scene_uv(const rad_scene *scene, uint32_t polygon, vec3 p, double *u, double *v);
/* The reflectance (RGB) at point p of polygon `polygon`: its material's
 * Kd x the texel under p where the material has a texture and the polygon
 * coordinates, else the material's reflectance.  Cannot fail. */
void rad_scene_reflectance_at(const rad_scene *scene, uint32_t polygon, vec3 p, double rgb[3]);
/* Whether polygon `polygon` is textured (a texture and coordinates). */
bool rad_scene_textured(const rad_scene *scene, uint32_t polygon);


struct rad_daylight; /* scene/daylight.h: the sky, the sun, the openings */

struct rad_scene {
    char *source;             /* file name, or "cornell-box" */
    vec3 *positions;          /* m */
    size_t position_count;
    uint32_t *indices;        /* polygon vertex lists */
    size_t index_count;
    rad_polygon *polygons;
    size_t polygon_count;
    rad_surface *surfaces;
    size_t surface_count;
    rad_material *materials;
    size_t material_count;
    rad_texture *textures;
    size_t texture_count;
    rad_uv_map *uv_maps;
    size_t uv_map_count;
    vec3 bounds_min, bounds_max; /* m */
    double load_seconds;      /* time the importer took */
    bool has_camera;
    rad_camera camera;
    char **inputs;            /* the files read to make it (rad_scene_input_path) */
    size_t input_count;
    rad_view3d_control view3d; /* a .vs3 file's control line */
    /* Light that is not emitted by surfaces (docs/lighting.md): luminaires
     * (photometric files placed by a layout or by glTF nodes) and daylight;
     * none by default. */
    rad_luminaire_set luminaires;
    struct rad_daylight *daylight;        /* NULL: no daylight */
};

/* Take over a list of malloc'd paths as the scene's inputs (freeing any it
 * had).  Cannot fail. */
void rad_scene_set_inputs(rad_scene *scene, char **paths, size_t count);

/* ---- building a scene ---- */

typedef struct rad_scene_builder rad_scene_builder;

rad_scene_builder *rad_scene_builder_create(rad_context *ctx, const char *source);
void rad_scene_builder_destroy(rad_scene_builder *b);

/* Returns the index of the material, or -1 on failure (error set).
 * `emission` is exitance in W/m^2. */
int rad_scene_builder_material(rad_scene_builder *b, const char *name,
                               const double reflectance[3], const double emission[3]);
/* Give material `material` the reflectance texture `rgb` (width x height x
 * 3 linear floats, rad_alloc'd: taken over, freed on failure too) read
 * from `path`: its reflectance becomes Kd x the texture's mean, Kd kept as
 * the texels' scale.  Fails for memory or a bad material index. */
rad_result rad_scene_builder_texture(rad_scene_builder *b, int material, const char *path, float *rgb,
                                     int width, int height);
/* Texture coordinates for the polygons added next (NULL: none), kept until
 * changed.  Fails only for memory. */
rad_result rad_scene_builder_uv_map(rad_scene_builder *b, const rad_uv_map *map);
/* Give material `material` (an index rad_scene_builder_material gave) a
 * specular part.  Refuses (RAD_ERROR_INVALID_SCENE, naming `where`, e.g.
 * "scene.mtl:12", or the source when NULL) rho_s outside [0, 1], rho_d +
 * rho_s > 1 in a channel (energy), a negative or non-finite shininess and
 * glass with an index of refraction not in (1, 10]. */
rad_result rad_scene_builder_material_specular(rad_scene_builder *b, int material, const char *where,
                                               rad_specular_kind kind, const double specular[3],
                                               double shininess, double ior);
/* True if some material has a specular part. */
bool rad_scene_has_specular(const rad_scene *scene);
/* Returns the index of the surface with that name, creating it if new;
 * -1 on failure. */
int rad_scene_builder_surface(rad_scene_builder *b, const char *name);
/* The name of surface `surface` (an index rad_scene_builder_surface gave),
 * valid while the builder lives.  Cannot fail. */
const char *rad_scene_builder_surface_name(const rad_scene_builder *b, int surface);
/* Add a polygon; `line` (0 if unknown) is used in error messages.  Returns
 * RAD_OK or an error (with message) for bad input. */
rad_result rad_scene_builder_polygon(rad_scene_builder *b, int surface, int material,
                                     const vec3 *vertices, size_t vertex_count, int line);
void rad_scene_builder_camera(rad_scene_builder *b, const rad_camera *camera);
/* Mark surface `surface` obstruction-only (View3D 'O'): it is meshed and
 * blocks rays like any surface, and the view-factor outputs leave it out.
 * Cannot fail. */
void rad_scene_builder_surface_obstruction(rad_scene_builder *b, int surface);
/* Mark surface `surface` a View3D mask of surface `base` (both indices
 * rad_scene_builder_surface gave): its polygons fill a hole cut in the
 * base, block rays like an obstruction, and the surface-level outputs give
 * it View3D's factors (F(mask, base) = 1; output/view3d.c).  Cannot fail. */
void rad_scene_builder_surface_mask(rad_scene_builder *b, int surface, int base);

/* An OBJ's camera, as a comment (OBJ has none): the prefix, then position,
 * look-at point, up vector and vertical field of view in degrees, ten
 * numbers.  Written by rad_scene_write_obj, read back by the OBJ loader. */
#define RAD_OBJ_CAMERA_COMMENT "# radiosity camera:"


/* Validate and produce the scene; the builder is consumed (destroyed) either
 * way.  Fails on an empty scene. */
rad_result rad_scene_builder_finish(rad_scene_builder *b, rad_scene **out);

/* ---- queries used downstream ---- */

/* True if some material emits. */
bool rad_scene_has_emitter(const rad_scene *scene);
double rad_scene_diagonal(const rad_scene *scene); /* m */

/* Bytes of working space rad_triangulate_polygon needs for n vertices: the
 * projected points and seven words per vertex (a multiple of 4, so what
 * follows it stays aligned for uint32_t). */
#define RAD_TRIANGULATE_SCRATCH(n) ((size_t)(n) * (2 * sizeof(double) + 7 * sizeof(uint32_t)))

/* rad_triangulate_polygon's answer when the context was cancelled. */
#define RAD_TRIANGULATE_INTERRUPTED SIZE_MAX

/* Triangulate a simple planar polygon (convex or not) by ear clipping in
 * the plane of `normal`, in `scratch` (RAD_TRIANGULATE_SCRATCH(n) bytes,
 * aligned as malloc aligns).  Writes (n - 2) * 3 local vertex indices into
 * `triangles`, every triangle of positive area and in the polygon's
 * winding; collinear vertices are kept as corners.  Returns the number of
 * triangles, or 0 if the polygon is not simple (edges that cross or touch)
 * or degenerate, or RAD_TRIANGULATE_INTERRUPTED once rad_cancelled(ctx)
 * (polled every few thousand steps; ctx may be NULL).  O(n log n) for the
 * simplicity test; the clipping is as fast on every shape tried, quadratic
 * only for inputs built against it.  Allocates nothing. */
size_t rad_triangulate_polygon(const rad_context *ctx, const vec3 *vertices, size_t n,
                               vec3 normal, void *scratch, uint32_t *triangles);

/* Newell's normal (unnormalised; its length is twice the area). */
vec3 rad_polygon_newell(const vec3 *vertices, size_t n);

#endif /* RAD_SCENE_H */
