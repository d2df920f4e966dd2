/*
 * scene.c -- the scene builder, its validation, and the public scene
 * accessors (the loaders are import/load.c's).
 *
 * Importers hand the builder materials, named surfaces and polygons one at
 * a time, and each is checked as it arrives, so that an error can name the
 * file, the line where the importer knows it, and the surface:
 *
 *   rad_scene_builder_polygon:
 *     finite coordinates -> drop repeated vertices -> at least 3 left
 *       -> non-zero area -> drop vertices in line with their neighbours
 *       -> simple (no self-intersection)
 *       -> planar (and not twisted)?  yes: kept as one polygon
 *                                     no: split into triangles
 *   rad_scene_builder_finish:
 *     not empty -> drop surfaces without polygons and unused materials
 *       -> surface areas, bounds -> the immutable rad_scene
 *
 * Every vertex of every polygon gets its own slot in `positions`; welding
 * shared vertices is the mesher's job, which knows the crease angle.
 */
#include "scene/scene.h"
#include "scene/daylight.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

struct rad_scene_builder {
    rad_context *ctx;
    char *source; /* file name, the prefix of every message */
    vec3 *positions;
    size_t position_count, position_capacity;
    uint32_t *indices;
    size_t index_count, index_capacity;
    rad_polygon *polygons;
    size_t polygon_count, polygon_capacity;
    rad_surface *surfaces;
    size_t surface_count, surface_capacity;
    uint32_t *surface_hash;  /* open addressing: surface index + 1, 0 = empty */
    size_t surface_hash_size; /* a power of two, > 2 x surface_count */
    rad_material *materials;
    size_t material_count, material_capacity;
    vec3 *polygon_scratch; /* the polygon being added, repeats dropped */
    size_t polygon_scratch_capacity;
    uint32_t *triangle_scratch; /* its ear-clipped triangles */
    size_t triangle_scratch_capacity;
    unsigned char *triangulate_scratch; /* rad_triangulate_polygon's working space */
    size_t triangulate_scratch_capacity;
    bool has_camera;
    rad_camera camera;
    rad_texture *textures;
    size_t texture_count, texture_capacity;
    rad_uv_map *uv_maps;
    size_t uv_map_count, uv_map_capacity;
    bool uv_current;       /* the polygons added next take uv_maps[uv_map_count - 1] */
};

/* Return `array` grown (by doubling) to hold at least `needed` elements of
 * `size` bytes; NULL with the error set on failure, `array` then intact. */
static void *reserve(rad_scene_builder *b, void *array, size_t *capacity, size_t needed,
                     size_t size, const char *what)
{
    if (needed <= *capacity)
        return array;
    size_t grown = *capacity ? *capacity : 16;
    while (grown < needed)
        grown = grown > SIZE_MAX / 2 ? needed : grown * 2;
    if (grown > SIZE_MAX / size) {
        rad_fail(b->ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: too many %s", b->source, what);
        return NULL;
    }
    char named[320];
    snprintf(named, sizeof named, "%s: %zu %s", b->source, needed, what);
    void *grown_array = rad_realloc(b->ctx, RAD_MEM_SCENE, array, grown, size, named);
    if (!grown_array)
        return NULL;
    *capacity = grown;
    return grown_array;
}

rad_scene_builder *rad_scene_builder_create(rad_context *ctx, const char *source)
{
    source = source ? source : "scene";
    rad_scene_builder *b = rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *b, source);
    if (b)
        b->source = rad_strdup(ctx, RAD_MEM_SCENE, source, source);
    if (!b || !b->source) {
        rad_free(b);
        return NULL;
    }
    b->ctx = ctx;
    return b;
}

void rad_scene_builder_destroy(rad_scene_builder *b)
{
    if (!b)
        return;
    for (size_t i = 0; i < b->surface_count; i++)
        rad_free(b->surfaces[i].name);
    for (size_t i = 0; i < b->material_count; i++)
        rad_free(b->materials[i].name);
    rad_free(b->source);
    rad_free(b->positions);
    rad_free(b->indices);
    rad_free(b->polygons);
    rad_free(b->surfaces);
    rad_free(b->surface_hash);
    rad_free(b->materials);
    rad_free(b->polygon_scratch);
    rad_free(b->triangle_scratch);
    rad_free(b->triangulate_scratch);
    for (size_t i = 0; i < b->texture_count; i++) {
        rad_free(b->textures[i].path);
        rad_free(b->textures[i].rgb);
    }
    rad_free(b->textures);
    rad_free(b->uv_maps);
    rad_free(b);
}

rad_result rad_scene_builder_texture(rad_scene_builder *b, int material, const char *path, float *rgb,
                                     int width, int height)
{
    if (!b || material < 0 || (size_t)material >= b->material_count || !rgb || width < 1 || height < 1) {
        rad_free(rgb);
        return b ? rad_fail(b->ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: texture for material %d of %zu", b->source,
                            material, b->material_count)
                 : RAD_ERROR_INVALID_ARGUMENT;
    }
    rad_texture *textures = reserve(b, b->textures, &b->texture_capacity, b->texture_count + 1,
                                    sizeof *textures, "textures");
    char *name = textures ? rad_strdup(b->ctx, RAD_MEM_SCENE, path, b->source) : NULL;
    if (!name) {
        if (textures)
            b->textures = textures;
        rad_free(rgb);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    b->textures = textures;
    rad_texture *t = &textures[b->texture_count++];
    *t = (rad_texture){name, width, height, rgb, {0, 0, 0}};
    size_t texels = (size_t)width * (size_t)height;
    for (size_t k = 0; k < texels; k++)
        for (int c = 0; c < 3; c++)
            t->mean[c] += rgb[3 * k + (size_t)c];
    rad_material *m = &b->materials[material];
    m->texture = (uint32_t)b->texture_count;
    for (int c = 0; c < 3; c++) {
        t->mean[c] /= (double)texels;
        m->texture_scale[c] = m->reflectance[c];
        m->reflectance[c] *= t->mean[c];
    }
    return RAD_OK;
}

rad_result rad_scene_builder_uv_map(rad_scene_builder *b, const rad_uv_map *map)
{
    if (!b)
        return RAD_ERROR_INVALID_ARGUMENT;
    b->uv_current = false;
    if (!map)
        return RAD_OK;
    rad_uv_map *maps = reserve(b, b->uv_maps, &b->uv_map_capacity, b->uv_map_count + 1, sizeof *maps,
                               "texture coordinates");
    if (!maps)
        return RAD_ERROR_OUT_OF_MEMORY;
    b->uv_maps = maps;
    maps[b->uv_map_count++] = *map;
    b->uv_current = true;
    return RAD_OK;
}

int rad_scene_builder_material(rad_scene_builder *b, const char *name,
                               const double reflectance[3], const double emission[3])
{
    if (!b)
        return -1;
    char fallback[32];
    if (!name || !*name) {
        snprintf(fallback, sizeof fallback, "material_%zu", b->material_count);
        name = fallback;
    }
    for (int c = 0; c < 3; c++) {
        /* rho = 1 would make the radiosity system singular in a closed room. */
        if (!(reflectance[c] >= 0.0 && reflectance[c] < 1.0)) {
            rad_fail(b->ctx, RAD_ERROR_INVALID_SCENE,
                     "%s: material '%s': reflectance %g is outside [0, 1)", b->source, name,
                     reflectance[c]);
            return -1;
        }
        if (!(emission[c] >= 0.0 && isfinite(emission[c]))) {
            rad_fail(b->ctx, RAD_ERROR_INVALID_SCENE,
                     "%s: material '%s': emission %g is not a finite non-negative exitance",
                     b->source, name, emission[c]);
            return -1;
        }
        if (emission[c] > RAD_MAX_EXITANCE) {
            rad_fail(b->ctx, RAD_ERROR_INVALID_SCENE,
                     "%s: material '%s': emission %g W/m^2 is above the %g W/m^2 the engine works in "
                     "(are the units right?)",
                     b->source, name, emission[c], RAD_MAX_EXITANCE);
            return -1;
        }
    }
    if (b->material_count >= INT_MAX) {
        rad_fail(b->ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: too many materials", b->source);
        return -1;
    }
    rad_material *materials = reserve(b, b->materials, &b->material_capacity,
                                      b->material_count + 1, sizeof *materials, "materials");
    if (!materials)
        return -1;
    b->materials = materials;
    rad_material *m = &materials[b->material_count];
    m->name = rad_strdup(b->ctx, RAD_MEM_SCENE, name, b->source);
    if (!m->name)
        return -1;
    memcpy(m->reflectance, reflectance, sizeof m->reflectance);
    memcpy(m->emission, emission, sizeof m->emission);
    m->specular_kind = RAD_SPECULAR_NONE;
    m->specular[0] = m->specular[1] = m->specular[2] = 0.0;
    m->shininess = 0.0;
    m->ior = 1.0;
    return (int)b->material_count++;
}

rad_result rad_scene_builder_material_specular(rad_scene_builder *b, int material, const char *where,
                                               rad_specular_kind kind, const double specular[3],
                                               double shininess, double ior)
{
    rad_material *m = &b->materials[material];
    const char *at = where ? where : b->source;
    for (int c = 0; c < 3; c++) {
        if (!(specular[c] >= 0.0 && specular[c] <= 1.0))
            return rad_fail(b->ctx, RAD_ERROR_INVALID_SCENE,
                            "%s: material '%s': specular reflectance %g is outside [0, 1]", at, m->name,
                            specular[c]);
        /* Energy: what a surface reflects, diffusely and specularly, is at
         * most what it receives (rounding of the decimal inputs allowed). */
        if (m->reflectance[c] + specular[c] > 1.0 + 1e-12)
            return rad_fail(b->ctx, RAD_ERROR_INVALID_SCENE,
                            "%s: material '%s': diffuse %g + specular %g reflectance is above 1 "
                            "(the surface would reflect more than it receives)",
                            at, m->name, m->reflectance[c], specular[c]);
    }
    if (!(shininess >= 0.0 && isfinite(shininess)))
        return rad_fail(b->ctx, RAD_ERROR_INVALID_SCENE,
                        "%s: material '%s': shininess (Ns) %g is not a finite non-negative exponent", at,
                        m->name, shininess);
    if (kind == RAD_SPECULAR_GLASS && !(ior > 1.0 && ior <= 10.0))
        return rad_fail(b->ctx, RAD_ERROR_INVALID_SCENE,
                        "%s: material '%s': glass needs an index of refraction (Ni) in (1, 10], got %g", at,
                        m->name, ior);
    m->specular_kind = kind;
    memcpy(m->specular, specular, sizeof m->specular);
    m->shininess = shininess;
    m->ior = kind == RAD_SPECULAR_GLASS ? ior : 1.0;
    return RAD_OK;
}

bool rad_scene_has_specular(const rad_scene *scene)
{
    for (size_t i = 0; i < scene->material_count; i++)
        if (scene->materials[i].specular_kind != RAD_SPECULAR_NONE)
            return true;
    return false;
}

/* FNV-1a. */
static uint64_t name_hash(const char *name)
{
    uint64_t h = 1469598103934665603ULL;
    for (const unsigned char *c = (const unsigned char *)name; *c; c++)
        h = (h ^ *c) * 1099511628211ULL;
    return h;
}

const char *rad_scene_builder_surface_name(const rad_scene_builder *b, int surface)
{
    return b->surfaces[surface].name;
}

int rad_scene_builder_surface(rad_scene_builder *b, const char *name)
{
    if (!b)
        return -1;
    char fallback[32];
    if (!name || !*name) {
        snprintf(fallback, sizeof fallback, "surface_%zu", b->surface_count);
        name = fallback;
    }
    /* Names are hashed (FNV-1a, open addressing): generated scenes have
     * 10^5 surfaces, where a linear search per polygon takes minutes. */
    uint64_t h = name_hash(name);
    if (b->surface_hash_size) {
        for (size_t k = h & (b->surface_hash_size - 1);; k = (k + 1) & (b->surface_hash_size - 1)) {
            uint32_t e = b->surface_hash[k];
            if (!e)
                break;
            if (strcmp(b->surfaces[e - 1].name, name) == 0)
                return (int)(e - 1);
        }
    }
    if (b->surface_count >= INT_MAX) {
        rad_fail(b->ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: too many surfaces", b->source);
        return -1;
    }
    rad_surface *surfaces = reserve(b, b->surfaces, &b->surface_capacity, b->surface_count + 1,
                                    sizeof *surfaces, "surfaces");
    if (!surfaces)
        return -1;
    b->surfaces = surfaces;
    rad_surface *s = &surfaces[b->surface_count];
    s->name = rad_strdup(b->ctx, RAD_MEM_SCENE, name, b->source);
    s->area = 0.0;
    s->obstruction = false;
    s->mask = false;
    s->mask_base = 0;
    if (!s->name)
        return -1;
    /* Grow the table to keep it under half full, then insert. */
    if (2 * (b->surface_count + 1) >= b->surface_hash_size) {
        size_t size = b->surface_hash_size ? 2 * b->surface_hash_size : 64;
        uint32_t *table = rad_alloc(b->ctx, RAD_MEM_SCENE, size, sizeof *table, b->source);
        if (!table) {
            rad_free(s->name);
            return -1;
        }
        for (size_t i = 0; i < b->surface_count; i++) {
            size_t k = name_hash(b->surfaces[i].name) & (size - 1);
            while (table[k])
                k = (k + 1) & (size - 1);
            table[k] = (uint32_t)(i + 1);
        }
        rad_free(b->surface_hash);
        b->surface_hash = table;
        b->surface_hash_size = size;
    }
    size_t k = h & (b->surface_hash_size - 1);
    while (b->surface_hash[k])
        k = (k + 1) & (b->surface_hash_size - 1);
    b->surface_hash[k] = (uint32_t)(b->surface_count + 1);
    return (int)b->surface_count++;
}

/* "FILE:LINE: polygon in surface 'NAME' <problem>", without ":LINE" when
 * the line is unknown (0). */
static rad_result polygon_error(const rad_scene_builder *b, int surface, int line,
                                rad_result code, const char *problem)
{
    char at[24] = "";
    if (line > 0)
        snprintf(at, sizeof at, ":%d", line);
    return rad_fail(b->ctx, code, "%s%s: polygon in surface '%s' %s", b->source, at,
                    b->surfaces[surface].name, problem);
}


/* Append one checked planar polygon; its vertices get fresh positions. */
static rad_result append_polygon(rad_scene_builder *b, int surface, int material,
                                 const vec3 *vertices, size_t n, vec3 normal, double area)
{
    if (b->position_count + n > UINT32_MAX || b->polygon_count >= UINT32_MAX)
        return rad_fail(b->ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: more than 2^32 vertices",
                        b->source);
    vec3 *positions = reserve(b, b->positions, &b->position_capacity, b->position_count + n,
                              sizeof *positions, "vertices");
    if (!positions)
        return RAD_ERROR_OUT_OF_MEMORY;
    b->positions = positions;
    uint32_t *indices = reserve(b, b->indices, &b->index_capacity, b->index_count + n,
                                sizeof *indices, "vertex indices");
    if (!indices)
        return RAD_ERROR_OUT_OF_MEMORY;
    b->indices = indices;
    rad_polygon *polygons = reserve(b, b->polygons, &b->polygon_capacity,
                                    b->polygon_count + 1, sizeof *polygons, "polygons");
    if (!polygons)
        return RAD_ERROR_OUT_OF_MEMORY;
    b->polygons = polygons;

    rad_polygon *p = &polygons[b->polygon_count++];
    p->first_index = (uint32_t)b->index_count;
    p->vertex_count = (uint32_t)n;
    p->surface = (uint32_t)surface;
    p->material = (uint32_t)material;
    p->normal = normal;
    p->area = area;
    p->uv_map = b->uv_current ? (uint32_t)b->uv_map_count : 0;
    for (size_t i = 0; i < n; i++) {
        indices[b->index_count++] = (uint32_t)b->position_count;
        positions[b->position_count++] = vertices[i];
    }
    return RAD_OK;
}

static bool v3_equal(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

rad_result rad_scene_builder_polygon(rad_scene_builder *b, int surface, int material,
                                     const vec3 *vertices, size_t vertex_count, int line)
{
    if (!b)
        return RAD_ERROR_INVALID_ARGUMENT;
    if (surface < 0 || (size_t)surface >= b->surface_count || material < 0 ||
        (size_t)material >= b->material_count || (vertex_count > 0 && !vertices))
        return rad_fail(b->ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: polygon refers to surface %d and material %d, of %zu and %zu",
                        b->source, surface, material, b->surface_count, b->material_count);
    for (size_t i = 0; i < vertex_count; i++) {
        if (!v3_finite(vertices[i]))
            return polygon_error(b, surface, line, RAD_ERROR_INVALID_SCENE,
                                 "has a non-finite coordinate");
        double largest = fmax(fabs(vertices[i].x), fmax(fabs(vertices[i].y), fabs(vertices[i].z)));
        if (largest > RAD_MAX_COORDINATE) {
            char problem[128];
            snprintf(problem, sizeof problem,
                     "has a coordinate of %.3g m, beyond the %g m the engine works in "
                     "(are the units right?)", largest, RAD_MAX_COORDINATE);
            return polygon_error(b, surface, line, RAD_ERROR_INVALID_SCENE, problem);
        }
    }

    vec3 *polygon = reserve(b, b->polygon_scratch, &b->polygon_scratch_capacity,
                            vertex_count + 1, sizeof *polygon, "polygon vertices");
    if (!polygon)
        return RAD_ERROR_OUT_OF_MEMORY;
    b->polygon_scratch = polygon;
    size_t n = 0;
    for (size_t i = 0; i < vertex_count; i++)
        if (n == 0 || !v3_equal(vertices[i], polygon[n - 1]))
            polygon[n++] = vertices[i];
    while (n > 1 && v3_equal(polygon[n - 1], polygon[0]))
        n--;
    if (n < 3) {
        char problem[64];
        snprintf(problem, sizeof problem, "has %zu distinct vertices (3 or more needed)", n);
        return polygon_error(b, surface, line, RAD_ERROR_INVALID_SCENE, problem);
    }

    vec3 lo = polygon[0], hi = polygon[0], centroid = v3(0.0, 0.0, 0.0);
    for (size_t i = 0; i < n; i++) {
        lo = v3_min(lo, polygon[i]);
        hi = v3_max(hi, polygon[i]);
        centroid = v3_add(centroid, polygon[i]);
    }
    centroid = v3_scale(centroid, 1.0 / (double)n);
    /* The bounding-box diagonal stands in for the polygon's diameter: it is
     * at most sqrt(3) times larger and costs O(n), not O(n^2). */
    double diameter = v3_length(v3_sub(hi, lo));
    vec3 newell = rad_polygon_newell(polygon, n);
    double area = 0.5 * v3_length(newell);
    /* 1e-12 x diameter^2: a polygon a million-millionth as wide as it is
     * long is a line, and its normal is rounding noise.  The test is
     * relative, so it holds at every scale; below RAD_MIN_LENGTH across,
     * a polygon is refused as too small for the engine's arithmetic. */
    if (!(diameter >= RAD_MIN_LENGTH)) {
        char problem[128];
        snprintf(problem, sizeof problem,
                 "is %.3g m across, below the %g m the engine works in (are the units right?)",
                 diameter, RAD_MIN_LENGTH);
        return polygon_error(b, surface, line, RAD_ERROR_INVALID_SCENE, problem);
    }
    if (!(area >= 1e-12 * diameter * diameter))
        return polygon_error(b, surface, line, RAD_ERROR_INVALID_SCENE, "has zero area");
    vec3 normal = v3_scale(newell, 0.5 / area);

    /* Drop vertices in line with their neighbours (a vertex in the middle of
     * an edge, or the tip of a zero-width spike): they add no area, and
     * would turn a quad into a pentagon the mesher must fan.  1e-12
     * relative: the sine of the angle at the vertex, far below any corner a
     * modeller draws and far above round-off in the cross product. */
    /* One pass with a stack, O(n): polygon[0, kept) holds the vertices
     * kept so far, polygon[next, end) those still to look at, and the
     * polygon is the two joined.  A drop steps back to re-check the last
     * kept vertex, whose neighbour it was.  (A memmove per drop took 2.6 s
     * on a square of 25,000 points per side.) */
    size_t kept = 0, next_index = 0, end = n;
    while (n > 3 && kept < n) {
        vec3 vertex = polygon[next_index];
        vec3 prev = kept > 0 ? polygon[kept - 1] : polygon[end - 1];
        vec3 next = next_index + 1 < end ? polygon[next_index + 1] : polygon[0];
        vec3 in = v3_sub(vertex, prev), out = v3_sub(next, vertex);
        if (v3_length(v3_cross(in, out)) <= 1e-12 * v3_length(in) * v3_length(out)) {
            next_index++;
            n--;
            if (kept > 0) /* the previous vertex may now be in line */
                polygon[--next_index] = polygon[--kept];
        } else {
            polygon[kept++] = polygon[next_index++];
        }
    }
    if (kept < next_index)
        memmove(&polygon[kept], &polygon[next_index], (end - next_index) * sizeof *polygon);

    size_t triangle_count = 0;
    if (n > 3) {
        uint32_t *triangles = reserve(b, b->triangle_scratch, &b->triangle_scratch_capacity,
                                      3 * (n - 2), sizeof *triangles, "triangles");
        if (!triangles)
            return RAD_ERROR_OUT_OF_MEMORY;
        b->triangle_scratch = triangles;
        unsigned char *scratch = reserve(b, b->triangulate_scratch, &b->triangulate_scratch_capacity,
                                         RAD_TRIANGULATE_SCRATCH(n), 1, "polygon vertices");
        if (!scratch)
            return RAD_ERROR_OUT_OF_MEMORY;
        b->triangulate_scratch = scratch;
        triangle_count = rad_triangulate_polygon(b->ctx, polygon, n, normal, scratch, triangles);
        if (triangle_count == RAD_TRIANGULATE_INTERRUPTED) {
            char at[24] = "";
            if (line > 0)
                snprintf(at, sizeof at, ":%d", line);
            return rad_fail(b->ctx, RAD_ERROR_INTERRUPTED,
                            "%s%s: interrupted while triangulating a polygon of %zu vertices in "
                            "surface '%s'",
                            b->source, at, n, b->surfaces[surface].name);
        }
        if (triangle_count == 0)
            return polygon_error(b, surface, line, RAD_ERROR_INVALID_SCENE,
                                 "intersects itself");
    }

    /* Newell's normal through the centroid is the best-fit plane.  1e-4 x
     * diameter (0.1 mm on a 1 m wall) is far above float round-off in the
     * files and far below anything a viewer would call curved. */
    double max_distance = 0.0;
    for (size_t i = 0; i < n; i++)
        max_distance = fmax(max_distance, fabs(v3_dot(v3_sub(polygon[i], centroid), normal)));
    /* A thin polygon can pass the distance test yet be twisted (a 1 km x
     * 0.1 mm strip whose ends lie in different planes): its triangles then
     * have more area than its projection (Newell's), and the mesher's
     * elements would not add up to the area recorded here.  1e-9 relative
     * is far above double round-off (1e-15) and the float coordinates of
     * glTF files (twist 1e-7, area excess 1e-14). */
    double triangles_area = 0.0;
    for (size_t t = 0; t < triangle_count; t++) {
        const uint32_t *k = &b->triangle_scratch[3 * t];
        vec3 triangle[3] = {polygon[k[0]], polygon[k[1]], polygon[k[2]]};
        triangles_area += 0.5 * v3_length(rad_polygon_newell(triangle, 3));
    }
    /* A quad is meshed as a bilinear grid, whose area lies between those
     * of its two diagonal splits, whichever diagonal ear clipping chose:
     * the larger split decides (with one diagonal a twisted 90 m x 0.1 m
     * quad passed, and its grid of elements came to 3.6e-6 more area than
     * the surface: fuzz_obj). */
    if (n == 4) {
        vec3 a[3] = {polygon[0], polygon[1], polygon[2]}, c[3] = {polygon[0], polygon[2], polygon[3]};
        vec3 b2[3] = {polygon[1], polygon[2], polygon[3]}, d[3] = {polygon[1], polygon[3], polygon[0]};
        double split02 = 0.5 * (v3_length(rad_polygon_newell(a, 3)) + v3_length(rad_polygon_newell(c, 3)));
        double split13 = 0.5 * (v3_length(rad_polygon_newell(b2, 3)) + v3_length(rad_polygon_newell(d, 3)));
        triangles_area = fmax(triangles_area, fmax(split02, split13));
    }
    bool twisted = triangles_area > area * (1.0 + 1e-9);
    if ((max_distance <= 1e-4 * diameter && !twisted) || n == 3)
        return append_polygon(b, surface, material, polygon, n, normal, area);

    for (size_t t = 0; t < triangle_count; t++) {
        vec3 triangle[3] = {polygon[b->triangle_scratch[3 * t]],
                            polygon[b->triangle_scratch[3 * t + 1]],
                            polygon[b->triangle_scratch[3 * t + 2]]};
        vec3 triangle_newell = rad_polygon_newell(triangle, 3);
        double triangle_area = 0.5 * v3_length(triangle_newell);
        if (!(triangle_area > 1e-15 * area))
            continue; /* round-off: nothing to radiate or receive; ear clipping avoids these anyway */
        rad_result r = append_polygon(b, surface, material, triangle, 3,
                                      v3_scale(triangle_newell, 0.5 / triangle_area),
                                      triangle_area);
        if (r != RAD_OK)
            return r;
    }
    return RAD_OK;
}

void rad_scene_builder_surface_obstruction(rad_scene_builder *b, int surface)
{
    if (b && surface >= 0 && (size_t)surface < b->surface_count)
        b->surfaces[surface].obstruction = true;
}

void rad_scene_builder_surface_mask(rad_scene_builder *b, int surface, int base)
{
    if (b && surface >= 0 && (size_t)surface < b->surface_count && base >= 0 && (size_t)base < b->surface_count) {
        b->surfaces[surface].mask = true;
        b->surfaces[surface].mask_base = (uint32_t)base;
    }
}

void rad_scene_builder_camera(rad_scene_builder *b, const rad_camera *camera)
{
    if (!b)
        return;
    b->has_camera = camera != NULL;
    if (camera)
        b->camera = *camera;
}

static bool camera_is_valid(const rad_camera *c)
{
    vec3 position = v3(c->position[0], c->position[1], c->position[2]);
    vec3 look_at = v3(c->look_at[0], c->look_at[1], c->look_at[2]);
    vec3 up = v3(c->up[0], c->up[1], c->up[2]);
    return v3_finite(position) && v3_finite(look_at) && v3_finite(up) &&
           !v3_equal(position, look_at) && v3_length(up) > 0.0 && c->vfov_degrees > 0.0 &&
           c->vfov_degrees < 180.0;
}

rad_result rad_scene_builder_finish(rad_scene_builder *b, rad_scene **out)
{
    if (!out) {
        rad_scene_builder_destroy(b);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    *out = NULL;
    if (!b)
        return RAD_ERROR_INVALID_ARGUMENT;
    rad_result r = RAD_OK;
    uint32_t *surface_map = NULL, *material_map = NULL;
    rad_scene *scene = NULL;
    if (b->polygon_count == 0) {
        r = rad_fail(b->ctx, RAD_ERROR_INVALID_SCENE, "%s: scene is empty (no polygons)",
                     b->source);
        goto done;
    }
    if (b->has_camera && !camera_is_valid(&b->camera)) {
        r = rad_fail(b->ctx, RAD_ERROR_INVALID_SCENE,
                     "%s: camera has a non-finite or degenerate position, direction or "
                     "field of view",
                     b->source);
        goto done;
    }
    surface_map = rad_alloc(b->ctx, RAD_MEM_SCENE, b->surface_count, sizeof *surface_map, b->source);
    material_map = surface_map ? rad_alloc(b->ctx, RAD_MEM_SCENE, b->material_count, sizeof *material_map,
                                           b->source)
                               : NULL;
    scene = material_map ? rad_alloc(b->ctx, RAD_MEM_SCENE, 1, sizeof *scene, b->source) : NULL;
    if (!scene) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }

    /* From here on nothing can fail.  Keep used surfaces and materials in
     * their order; a map entry of UINT32_MAX marks one that no polygon uses. */
    for (size_t i = 0; i < b->surface_count; i++)
        surface_map[i] = UINT32_MAX;
    for (size_t i = 0; i < b->material_count; i++)
        material_map[i] = UINT32_MAX;
    for (size_t p = 0; p < b->polygon_count; p++) {
        surface_map[b->polygons[p].surface] = 0;
        material_map[b->polygons[p].material] = 0;
    }
    size_t kept = 0;
    for (size_t i = 0; i < b->surface_count; i++) {
        if (surface_map[i] == UINT32_MAX) {
            rad_free(b->surfaces[i].name);
            continue;
        }
        b->surfaces[kept] = b->surfaces[i];
        b->surfaces[kept].area = 0.0;
        surface_map[i] = (uint32_t)kept++;
    }
    for (size_t i = 0; i < kept; i++) /* a mask's base, renumbered */
        if (b->surfaces[i].mask) {
            b->surfaces[i].mask_base = surface_map[b->surfaces[i].mask_base];
            b->surfaces[i].mask = b->surfaces[i].mask_base != UINT32_MAX;
        }
    b->surface_count = kept;
    kept = 0;
    for (size_t i = 0; i < b->material_count; i++) {
        if (material_map[i] == UINT32_MAX) {
            rad_free(b->materials[i].name);
            continue;
        }
        b->materials[kept] = b->materials[i];
        material_map[i] = (uint32_t)kept++;
    }
    b->material_count = kept;
    for (size_t p = 0; p < b->polygon_count; p++) {
        rad_polygon *polygon = &b->polygons[p];
        polygon->surface = surface_map[polygon->surface];
        polygon->material = material_map[polygon->material];
        b->surfaces[polygon->surface].area += polygon->area;
    }
    scene->bounds_min = scene->bounds_max = b->positions[0];
    for (size_t i = 1; i < b->position_count; i++) {
        scene->bounds_min = v3_min(scene->bounds_min, b->positions[i]);
        scene->bounds_max = v3_max(scene->bounds_max, b->positions[i]);
    }

    scene->source = b->source;
    scene->positions = b->positions;
    scene->position_count = b->position_count;
    scene->indices = b->indices;
    scene->index_count = b->index_count;
    scene->polygons = b->polygons;
    scene->polygon_count = b->polygon_count;
    scene->surfaces = b->surfaces;
    scene->surface_count = b->surface_count;
    scene->materials = b->materials;
    scene->material_count = b->material_count;
    scene->has_camera = b->has_camera;
    scene->camera = b->camera;
    scene->textures = b->textures; /* kept whole: materials refer to them by index */
    scene->texture_count = b->texture_count;
    scene->uv_maps = b->uv_maps;
    scene->uv_map_count = b->uv_map_count;
    rad_free(b->polygon_scratch);
    rad_free(b->triangle_scratch);
    rad_free(b->triangulate_scratch);
    rad_free(b->surface_hash);
    memset(b, 0, sizeof *b); /* all moved or freed: the destroy below frees the shell */
    *out = scene;
    scene = NULL;

done:
    rad_free(surface_map);
    rad_free(material_map);
    rad_free(scene);
    rad_scene_builder_destroy(b);
    return r;
}

/* ---- the public scene ---- */

void rad_scene_destroy(rad_scene *scene)
{
    if (!scene)
        return;
    for (size_t i = 0; i < scene->surface_count; i++)
        rad_free(scene->surfaces[i].name);
    for (size_t i = 0; i < scene->material_count; i++)
        rad_free(scene->materials[i].name);
    rad_scene_set_inputs(scene, NULL, 0);
    rad_free(scene->source);
    rad_free(scene->positions);
    rad_free(scene->indices);
    rad_free(scene->polygons);
    rad_free(scene->surfaces);
    rad_free(scene->materials);
    for (size_t i = 0; i < scene->texture_count; i++) {
        rad_free(scene->textures[i].path);
        rad_free(scene->textures[i].rgb);
    }
    rad_free(scene->textures);
    rad_free(scene->uv_maps);
    rad_luminaire_set_free(&scene->luminaires);
    rad_daylight_free(scene->daylight);
    rad_free(scene);
}

/* ---- textures ---- */

bool rad_scene_uv(const rad_scene *scene, uint32_t polygon, vec3 p, double *u, double *v)
{
    uint32_t k = scene->polygons[polygon].uv_map;
    if (k == 0 || k > scene->uv_map_count)
        return false;
    const double *m = scene->uv_maps[k - 1].m;
    *u = m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3];
    *v = m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7];
    return isfinite(*u) && isfinite(*v);
}

bool rad_scene_textured(const rad_scene *scene, uint32_t polygon)
{
    const rad_polygon *poly = &scene->polygons[polygon];
    uint32_t t = scene->materials[poly->material].texture;
    return t > 0 && t <= scene->texture_count && poly->uv_map > 0;
}

void rad_scene_reflectance_at(const rad_scene *scene, uint32_t polygon, vec3 p, double rgb[3])
{
    const rad_material *m = &scene->materials[scene->polygons[polygon].material];
    double u, v;
    if (!rad_scene_textured(scene, polygon) || !rad_scene_uv(scene, polygon, p, &u, &v)) {
        memcpy(rgb, m->reflectance, 3 * sizeof *rgb);
        return;
    }
    const rad_texture *t = &scene->textures[m->texture - 1];
    /* Wrapped (repeat, the MTL and glTF default); the texel containing (u, v). */
    u -= floor(u);
    v -= floor(v);
    long x = (long)(u * t->width), y = (long)((1.0 - v) * t->height);
    x = x < 0 ? 0 : x >= t->width ? t->width - 1 : x;
    y = y < 0 ? 0 : y >= t->height ? t->height - 1 : y;
    const float *texel = t->rgb + 3 * ((size_t)y * (size_t)t->width + (size_t)x);
    for (int c = 0; c < 3; c++)
        rgb[c] = m->texture_scale[c] * texel[c]; /* Kd < 1, texels <= 1 */
}

void rad_scene_set_inputs(rad_scene *scene, char **paths, size_t count)
{
    for (size_t i = 0; i < scene->input_count; i++)
        rad_free(scene->inputs[i]);
    rad_free(scene->inputs);
    scene->inputs = paths;
    scene->input_count = count;
}

size_t rad_scene_input_count(const rad_scene *scene) { return scene ? scene->input_count : 0; }

const char *rad_scene_input_path(const rad_scene *scene, size_t index)
{
    return scene && index < scene->input_count ? scene->inputs[index] : NULL;
}

size_t rad_scene_surface_count(const rad_scene *scene) { return scene ? scene->surface_count : 0; }

const char *rad_scene_surface_name(const rad_scene *scene, size_t surface)
{
    return scene && surface < scene->surface_count ? scene->surfaces[surface].name : NULL;
}

double rad_scene_surface_area(const rad_scene *scene, size_t surface)
{
    return scene && surface < scene->surface_count ? scene->surfaces[surface].area : 0.0;
}

size_t rad_scene_polygon_count(const rad_scene *scene) { return scene ? scene->polygon_count : 0; }

bool rad_scene_camera(const rad_scene *scene, rad_camera *camera)
{
    if (!scene || !scene->has_camera || !camera)
        return false;
    *camera = scene->camera;
    return true;
}

bool rad_scene_has_emitter(const rad_scene *scene)
{
    if (!scene)
        return false;
    for (size_t p = 0; p < scene->polygon_count; p++) {
        const double *emission = scene->materials[scene->polygons[p].material].emission;
        if (emission[0] > 0.0 || emission[1] > 0.0 || emission[2] > 0.0)
            return true;
    }
    return false;
}

double rad_scene_diagonal(const rad_scene *scene)
{
    if (!scene || scene->polygon_count == 0)
        return 0.0;
    return v3_length(v3_sub(scene->bounds_max, scene->bounds_min));
}
