/*
 * mesh.h -- surfaces split into elements.
 *
 * Each scene polygon becomes one or more PATCHES (a planar convex quad or a
 * triangle; other polygons are triangulated).  Each patch is meshed as a
 * structured grid, so an element is found from a point's patch parameters
 * in O(1) (this is how the renderer maps a ray hit to an element):
 *
 *    quad patch, nu x nv cells           triangle patch, k^2 cells (k = 3)
 *    c3 +----+----+----+ c2              c2
 *       |  3 |  4 |  5 |  t                |\
 *       +----+----+----+  ^                |8\
 *       |  0 |  1 |  2 |  |                |--\
 *    c0 +----+----+----+ c1 -> s           |\5|\  (row-major from c0; in row
 *                                          |3\|7\  y the upward cells come
 *                                       c0 +--+--+ c1    first, then downward)
 *
 * Vertices are shared ("welded") between elements of one surface whose
 * normals differ by less than the crease angle, across patch boundaries too.
 * A welded vertex lying inside another element's edge (a T-vertex, where
 * neighbouring patches have different grids) is recorded so that vertex
 * values can be made continuous there (interp/).
 */
#ifndef RAD_MESH_H
#define RAD_MESH_H

#include "scene/scene.h"

typedef struct rad_patch {
    uint32_t polygon;        /* scene polygon it came from */
    uint32_t surface;
    uint32_t material;
    uint32_t corner_count;   /* 3 or 4 */
    vec3 corner[4];          /* m, counter-clockwise about normal */
    vec3 normal;             /* unit */
    uint32_t nu, nv;         /* quad: grid cells along c0->c1 and c0->c3; triangle: nu = nv = k */
    uint32_t first_element;  /* elements of this patch are contiguous */
    uint32_t element_count;
    uint32_t tree_root;      /* leaf meshes (rad_mesh.tree != NULL): the patch's quadtree */
    bool obstruction;        /* of an obstruction-only or mask surface: one element, it only blocks rays */
} rad_patch;

typedef struct rad_element {
    uint32_t patch;
    uint32_t surface;
    uint32_t material;
    uint32_t vertex_count;   /* 3 or 4 */
    uint32_t vertex[4];      /* welded vertex indices, counter-clockwise */
    vec3 centroid;           /* m */
    vec3 normal;             /* unit */
    double area;             /* m^2 */
} rad_element;

/* A vertex that lies on the open edge (a, b) of a neighbouring element:
 * its value must be lerp(value[a], value[b], t) for the shading to be
 * continuous. */
typedef struct rad_tvertex {
    uint32_t vertex, a, b;
    double t;
} rad_tvertex;

/* A contact line: where another surface touches or crosses scene polygon
 * `polygon` inside it (mesh/conform.c).  The radiosity is discontinuous
 * there, so vertices on it are not shared across it. */
typedef struct rad_contact {
    uint32_t polygon;
    vec3 a, b;               /* m */
} rad_contact;

typedef struct rad_mesh {
    rad_patch *patches;
    size_t patch_count;
    rad_element *elements;
    size_t element_count;
    vec3 *vertices;          /* welded positions, m */
    size_t vertex_count;
    rad_tvertex *tvertices;
    size_t tvertex_count;
    double mesh_size;        /* the edge length actually used, m */
    /* Leaf meshes of hierarchical radiosity: instead of a grid, each patch's
     * elements are the leaves of a quadtree (quads split at the parameter
     * midpoints, triangles into their corner and medial triangles; hier/tree.c).
     * Internal node k has children tree[4k .. 4k+3]; an entry (or a patch's
     * tree_root) with RAD_TREE_LEAF set is the element (entry & ~RAD_TREE_LEAF).
     * NULL for grid meshes. */
    uint32_t *tree;
    size_t tree_count;       /* internal nodes */
    rad_contact *contacts;   /* sorted by polygon; NULL when none */
    size_t contact_count;
    double contact_tol;      /* m: a point this near a contact line is on it */
    double diagonal;         /* m: of the box around the vertices and the patch corners, 0
                                when empty (rad_mesh_measure): the scale rad_vis_epsilon takes */
} rad_mesh;

#define RAD_TREE_LEAF 0x80000000u

typedef struct rad_mesh_options {
    double mesh_size;        /* m; 0 = derive from target_elements */
    size_t target_elements;  /* used when mesh_size is 0; 0 = 2000 */
    double crease_angle_degrees; /* 0 = 30 */
} rad_mesh_options;

rad_result rad_mesh_build(rad_context *ctx, const rad_scene *scene,
                          const rad_mesh_options *options, rad_mesh **out);
/* As rad_mesh_build, but first estimates the mesh's memory and fails with
 * RAD_ERROR_OUT_OF_MEMORY (naming --max-memory, --mesh-size, --elements)
 * when it exceeds max_memory_bytes (0 = no limit). */
rad_result rad_mesh_build_within(rad_context *ctx, const rad_scene *scene,
                                 const rad_mesh_options *options, double max_memory_bytes,
                                 rad_mesh **out);
void rad_mesh_destroy(rad_mesh *mesh);

/* Set mesh->diagonal from its vertices and patch corners (the corners
 * cover a mesh whose vertices are not welded or not filled in).  Every
 * builder calls it once the geometry is final, as must whatever builds or
 * moves a mesh by hand (tests).  Cannot fail. */
void rad_mesh_measure(rad_mesh *mesh);

/* The element of `patch` containing the point with patch parameters (s, t)
 * (quad: bilinear coordinates in [0,1]^2; triangle: barycentrics of c1 and
 * c2), and the point's coordinates inside that element (same convention,
 * relative to the element's own vertex order).  Cannot fail: parameters are
 * clamped. */
uint32_t rad_patch_locate(const rad_patch *patch, double s, double t,
                          double *local_s, double *local_t);

/* As rad_patch_locate, for patch `patch` of any mesh: grid meshes locate in
 * O(1), leaf meshes descend the patch's quadtree.  Cannot fail. */
uint32_t rad_mesh_locate(const rad_mesh *mesh, uint32_t patch, double s, double t,
                         double *local_s, double *local_t);

/* A leaf of a hierarchical solution, as rad_mesh_from_leaves takes it. */
typedef struct rad_mesh_leaf {
    uint32_t patch;
    uint32_t corner_count;   /* 3 or 4, as its patch */
    vec3 corner[4];          /* counter-clockwise, in the patch's parameter orientation */
} rad_mesh_leaf;

/* The mesh of a hierarchical solution: `base`'s patches, with `leaves` as
 * elements (grouped by patch, in patch order) located through `tree`
 * (tree_count internal nodes, 4 entries each, encoded as in rad_mesh) from
 * patch_root[p].  Vertices are welded and T-vertices found as in
 * rad_mesh_build.  The arrays are copied.  Fails only for memory. */
rad_result rad_mesh_from_leaves(rad_context *ctx, const rad_scene *scene, const rad_mesh *base,
                                const rad_mesh_leaf *leaves, size_t leaf_count, const uint32_t *tree,
                                size_t tree_count, const uint32_t *patch_root,
                                double crease_angle_degrees, rad_mesh **out);

/* Does point p lie (within mesh->contact_tol) on a contact line of scene
 * polygon `polygon`?  Cannot fail. */
bool rad_mesh_on_contact(const rad_mesh *mesh, uint32_t polygon, vec3 p);

/* A triangle's or quad's width, m: its shortest edge or 2 x area / its
 * longest edge, whichever is less; 0 when it has no extent. */
double rad_corners_width(const vec3 *corner, uint32_t count);

/* Patch parameters (s, t) of a point on (or near) the patch plane. */
void rad_patch_parameters(const rad_patch *patch, vec3 p, double *s, double *t);

/* The point of the patch at parameters (s, t). */
vec3 rad_patch_point(const rad_patch *patch, double s, double t);

/* A point of a triangle or quad (count 3 or 4 corners) at unit-square
 * parameters (u, v) in [0,1)^2: bilinear on quads, the folded square on
 * triangles (uniform in area there).  For sampling.  Cannot fail. */
vec3 rad_corners_sample(const vec3 *corner, uint32_t count, double u, double v);
/* The density correction of that map at (u, v): the Jacobian of the
 * bilinear map over the polygon's area, so that the mean of f(x(u,v)) *
 * weight over uniform (u, v) is the mean of f over the polygon (exactly 1
 * for triangles and parallelograms; its mean is 1 for any flat quad).
 * Cannot fail. */
double rad_corners_sample_weight(const vec3 *corner, uint32_t count, double area, double u, double v);
/* The same for element e's (welded) corners, e->area its area. */
vec3 rad_element_sample(const rad_mesh *mesh, const rad_element *e, double u, double v);
double rad_element_sample_weight(const rad_mesh *mesh, const rad_element *e, double u, double v);

/* A textured polygon piece's reflectance: the texture (times Kd) of scene
 * polygon `polygon` averaged over the triangle or quad `corner` (on that
 * polygon; area m^2), so that the power it reflects is the texels' (docs/
 * methods.md, "Textures"): k x k stratum centres weighted by the map's
 * density, k from the texels the piece spans (two samples a texel, 4 to 64
 * a side).  rgb is left as it is (the material's value) where the polygon
 * is not textured.  Used for the dense strategies' elements and the
 * hierarchy's nodes alike.  Cannot fail. */
void rad_texture_mean(const rad_scene *scene, uint32_t polygon, const vec3 *corner, uint32_t count, double area,
                      double rgb[3]);

#endif /* RAD_MESH_H */
