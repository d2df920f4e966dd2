/*
 * saved.c -- a solution read back from its file (saved.h has the layout):
 * the bytes are checked, the scene rebuilt and checked against its
 * checksum, the mesh checked index by index, and the result is a strategy
 * whose state is the solved mesh with its values.
 *
 *   bytes -> magic, header (JSON), payload checksum
 *         -> scene: builder (validates each polygon) -> checksum
 *         -> mesh: counts, indices, grids and quadtrees, geometry
 *         -> values: finite, >= 0 -> ray structure -> strategy state
 *
 * The encoding is saved_encode.c's, shared with the writer
 * (output/solution_file.c) downstream.
 */
#include "strategy/saved.h"

#include "strategy/options.h"
#include "photometry/photometry.h"
#include "scene/daylight.h"

#include <cjson/cJSON.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

/* ---- decoding ---- */

/* A reader over the payload.  Its size was checked against the counts
 * before any read (rad_saved_read), so the reads need no bounds. */
typedef struct cursor {
    const unsigned char *p, *end;
} cursor;

static uint32_t get_u32(cursor *c)
{
    const unsigned char *p = c->p;
    c->p += 4;
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static double get_f64(cursor *c)
{
    uint64_t u = 0;
    for (int k = 0; k < 8; k++)
        u |= (uint64_t)c->p[k] << (8 * k);
    c->p += 8;
    double v;
    memcpy(&v, &u, 8);
    return v;
}

static vec3 get_vec3(cursor *c)
{
    double x = get_f64(c), y = get_f64(c);
    return v3(x, y, get_f64(c));
}

typedef struct saved_state {
    rad_mesh *mesh;
    rad_mesh *patches;       /* hierarchical: the patches meshed whole, which the rays see */
    rad_vis *vis;
    rad_elements elements;
    rad_ff_stats ff_stats;
    rad_solve_stats solve_stats;
    rad_phase_seconds seconds;
    char ff_method[32], solve_method[32];
} saved_state;

static void saved_destroy(void *state)
{
    saved_state *st = state;
    if (!st)
        return;
    rad_vis_destroy(st->vis);
    rad_mesh_destroy(st->mesh);
    rad_mesh_destroy(st->patches);
    rad_elements_free(&st->elements);
    rad_free(st);
}

static bool saved_solver_info(size_t index, const char **name, const char **description)
{
    (void)index, (void)name, (void)description;
    return false; /* made from a file, never chosen by a solver's name */
}

static rad_result saved_create(rad_context *ctx, const rad_scene *scene, const rad_options *options,
                               void **state)
{
    (void)scene, (void)options;
    *state = NULL;
    return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                    "a saved solution is made by rad_solution_load_file, not by a solver's name");
}

static rad_result saved_solve(rad_context *ctx, void *state, const rad_step_hook *hook)
{
    (void)ctx, (void)state, (void)hook;
    return RAD_OK; /* solved when it was saved */
}

static void saved_view(const void *state, rad_solution_view *v)
{
    const saved_state *st = state;
    rad_view_elements(v, st->mesh, &st->elements);
    v->vis = st->vis;
    v->F = NULL;
    v->F_variance = NULL;
    v->vertex_radiosity = NULL; /* made again from the elements (the file's are the renderer's) */
    v->ff = &st->ff_stats;
    v->solve = &st->solve_stats;
    v->hier = NULL;
    v->solved = true;
    v->seconds = st->seconds;
}

const rad_strategy rad_strategy_saved = {
    "saved",
    "a solution read from its file: solved, rendered from any camera",
    0, /* answers to no solver name */
    saved_solver_info,
    saved_create,
    saved_solve,
    saved_view,
    saved_destroy,
};

/* Every reader error names the file; RAD_ERROR_PARSE unless said. */
#define BAD(...) (rad_fail(ctx, RAD_ERROR_PARSE, __VA_ARGS__))

static double number_in(const cJSON *object, const char *key)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(object, key);
    return cJSON_IsNumber(item) ? item->valuedouble : NAN;
}

/* A count from the header: an integer in [0, most]. */
static bool count_in(const cJSON *counts, const char *key, size_t most, size_t *out)
{
    double v = number_in(counts, key);
    if (!(v >= 0.0 && v <= (double)most && v == floor(v)))
        return false;
    *out = (size_t)v;
    return true;
}

/* The options as saved: each row of the option table by its type. */
static rad_result read_options(rad_context *ctx, const char *name, const cJSON *json, rad_options *out,
                               rad_method_names *names)
{
    rad_options o = {0};
    char methods[3][32] = {"", "", ""};
    int method_slot = 0;
    for (size_t i = 0;; i++) {
        const rad_option_info *row = rad_option_info_get(RAD_OPTION_SET_SOLUTION, i);
        if (!row)
            break;
        const cJSON *item = cJSON_GetObjectItemCaseSensitive(json, row->name);
        if (!item)
            continue; /* 0: the default */
        char *field = (char *)&o + row->offset;
        switch (row->type) {
        case RAD_OPTION_INT:
        case RAD_OPTION_FLAG:
        case RAD_OPTION_ENUM: {
            if (!cJSON_IsNumber(item) || !(fabs(item->valuedouble) < 2147483647.0))
                return BAD("%s: option '%s' is not an integer", name, row->name);
            int v = (int)item->valuedouble;
            memcpy(field, &v, sizeof v);
            break;
        }
        case RAD_OPTION_SIZE: {
            if (!cJSON_IsNumber(item) || !(item->valuedouble >= 0.0 && item->valuedouble < 9.0e15))
                return BAD("%s: option '%s' is not a count", name, row->name);
            size_t v = (size_t)item->valuedouble;
            memcpy(field, &v, sizeof v);
            break;
        }
        case RAD_OPTION_UINT64: {
            /* Decimal digits, exactly (a double would round past 2^53). */
            const char *text = cJSON_GetStringValue(item);
            uint64_t v = 0;
            bool ok = text && *text && strlen(text) <= 20;
            for (const char *p = text; ok && *p; p++) {
                ok = *p >= '0' && *p <= '9' && v <= (UINT64_MAX - (uint64_t)(*p - '0')) / 10;
                v = ok ? 10 * v + (uint64_t)(*p - '0') : v;
            }
            if (!ok)
                return BAD("%s: option '%s' is not an unsigned 64-bit integer", name, row->name);
            memcpy(field, &v, sizeof v);
            break;
        }
        case RAD_OPTION_DOUBLE:
        case RAD_OPTION_BYTES: {
            if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble))
                return BAD("%s: option '%s' is not a finite number", name, row->name);
            double v = item->valuedouble;
            memcpy(field, &v, sizeof v);
            break;
        }
        case RAD_OPTION_METHOD: {
            const char *text = cJSON_GetStringValue(item);
            if (!text || strlen(text) >= sizeof methods[0] || method_slot == 3)
                return BAD("%s: option '%s' is not a method name", name, row->name);
            snprintf(methods[method_slot], sizeof methods[0], "%s", text);
            const char *v = methods[method_slot++];
            memcpy(field, &v, sizeof v);
            break;
        }
        case RAD_OPTION_STRING:
            break;
        }
    }
    o.max_memory_bytes = 0.0; /* the reader's machine, not the writer's */
    /* Checked in a context of its own, so that the message that reaches the
     * caller is one line naming the file (a context keeps a call's first
     * failure, which would be the option's alone). */
    rad_context *check = NULL;
    rad_context_options co = {.threads = 1};
    if (rad_context_create(&co, &check) != RAD_OK)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory checking the options", name);
    rad_result r = rad_options_resolve(check, &o, out, names);
    if (r != RAD_OK)
        r = rad_fail(ctx, RAD_ERROR_PARSE, "%s: saved options: %s", name, rad_context_error(check));
    rad_context_destroy(check);
    return r;
}

/* Rebuild the scene through the builder, which validates every polygon:
 * surfaces and material names from the header; corners, polygons,
 * material values and camera from the payload at *c. */
static rad_result read_scene(rad_context *ctx, const char *name, const cJSON *header, cursor *c,
                             size_t corners, size_t polygons, size_t material_count, rad_scene **out)
{
    const cJSON *scene = cJSON_GetObjectItemCaseSensitive(header, "scene");
    const cJSON *surfaces = cJSON_GetObjectItemCaseSensitive(scene, "surfaces");
    const cJSON *materials = cJSON_GetObjectItemCaseSensitive(scene, "materials");
    const char *source = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(scene, "source"));
    const char *checksum = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(scene, "checksum"));
    if (!cJSON_IsArray(surfaces) || !cJSON_IsArray(materials) || !source || !checksum ||
        cJSON_GetArraySize(materials) != (int)material_count)
        return BAD("%s: the header has no scene (source, checksum, surfaces, %zu materials)", name,
                   material_count);
    cursor at = *c, table = {c->p + 24 * corners, c->end};
    cursor values = {table.p + 16 * polygons, c->end};
    cursor camera_at = {values.p + 48 * material_count, c->end};
    c->p = camera_at.p + 88;
    /* The builder's messages name the file being read; the scene keeps the
     * name of the one it was solved for (below). */
    rad_scene_builder *b = rad_scene_builder_create(ctx, name);
    if (!b)
        return RAD_ERROR_OUT_OF_MEMORY;
    int surface_count = cJSON_GetArraySize(surfaces);
    rad_result r = RAD_OK;
    for (int i = 0; r == RAD_OK && i < surface_count; i++) {
        const char *s = cJSON_GetStringValue(cJSON_GetArrayItem(surfaces, i));
        if (!s)
            r = BAD("%s: surface %d has no name", name, i);
        else if (rad_scene_builder_surface(b, s) != i)
            r = rad_context_error(ctx)[0] ? RAD_ERROR_OUT_OF_MEMORY
                                          : BAD("%s: surface '%s' is named twice", name, s);
    }
    for (size_t i = 0; r == RAD_OK && i < material_count; i++) {
        const cJSON *m = cJSON_GetArrayItem(materials, (int)i);
        const char *mname = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(m, "name"));
        double reflectance[3], emission[3];
        bool ok = mname != NULL;
        for (int k = 0; k < 3; k++) {
            reflectance[k] = get_f64(&values);
            emission[k] = get_f64(&values);
            ok = ok && reflectance[k] >= 0.0 && reflectance[k] < 1.0 && emission[k] >= 0.0 &&
                 isfinite(emission[k]);
        }
        if (!ok)
            r = BAD("%s: material %zu: a name, 3 reflectances in [0, 1) and 3 finite emissions >= 0 "
                    "are needed",
                    name, i);
        else if (rad_scene_builder_material(b, mname, reflectance, emission) != (int)i)
            r = rad_context_error(ctx)[0] ? RAD_ERROR_OUT_OF_MEMORY
                                          : BAD("%s: material '%s' is defined twice", name, mname);
    }
    vec3 *v = NULL;
    size_t v_capacity = 0, used = 0;
    for (size_t i = 0; r == RAD_OK && i < polygons; i++) {
        uint32_t count = get_u32(&table), surface = get_u32(&table), material = get_u32(&table);
        (void)get_u32(&table);
        if (count < 3 || count > corners - used || surface >= (uint32_t)surface_count ||
            material >= (uint32_t)material_count) {
            r = BAD("%s: polygon %zu: %" PRIu32 " corners, surface %" PRIu32 ", material %" PRIu32
                    " are out of range",
                    name, i, count, surface, material);
            break;
        }
        if (count > v_capacity) {
            vec3 *grown = rad_realloc(ctx, RAD_MEM_SCENE, v, count, sizeof *v, "solution file: polygon");
            if (!grown) {
                r = RAD_ERROR_OUT_OF_MEMORY;
                break;
            }
            v = grown;
            v_capacity = count;
        }
        for (uint32_t k = 0; k < count; k++)
            v[k] = get_vec3(&at);
        used += count;
        r = rad_scene_builder_polygon(b, (int)surface, (int)material, v, count, 0);
    }
    rad_free(v);
    if (r == RAD_OK && used != corners)
        r = BAD("%s: the polygons use %zu of %zu corners", name, used, corners);
    if (r == RAD_OK) {
        uint32_t has_camera = get_u32(&camera_at);
        (void)get_u32(&camera_at);
        rad_camera cam;
        double *dest[3] = {cam.position, cam.look_at, cam.up};
        for (int k = 0; k < 3; k++)
            for (int j = 0; j < 3; j++)
                dest[k][j] = get_f64(&camera_at);
        cam.vfov_degrees = get_f64(&camera_at);
        if (has_camera > 1)
            r = BAD("%s: the camera flag is %" PRIu32 ", not 0 or 1", name, has_camera);
        else if (has_camera)
            rad_scene_builder_camera(b, &cam); /* the builder checks it */
    }
    rad_scene *built = NULL;
    if (r == RAD_OK)
        r = rad_scene_builder_finish(b, &built);
    else
        rad_scene_builder_destroy(b);
    if (r != RAD_OK)
        return r;
    char hex[17];
    snprintf(hex, sizeof hex, "%016" PRIx64, rad_saved_scene_checksum(built));
    if (strcmp(hex, checksum) != 0 || built->surface_count != (size_t)surface_count ||
        built->material_count != material_count) {
        rad_scene_destroy(built);
        return BAD("%s: the scene rebuilt from the file has checksum %s, not the %s it was saved with",
                   name, hex, checksum);
    }
    char *original = rad_strdup(ctx, RAD_MEM_SCENE, source, "solution file: scene name");
    if (!original) {
        rad_scene_destroy(built);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    rad_free(built->source);
    built->source = original;
    *out = built;
    return RAD_OK;
}

/* The quadtree below `entry` of patch p: every leaf an element of p, seen
 * once (seen[]), children deeper than their parent (no cycle). */
static bool check_tree(const rad_mesh *m, uint32_t entry, uint32_t parent, uint32_t p, unsigned char *seen)
{
    if (entry & RAD_TREE_LEAF) {
        uint32_t e = entry & ~RAD_TREE_LEAF;
        if (e >= m->element_count || m->elements[e].patch != p || seen[e])
            return false;
        seen[e] = 1;
        return true;
    }
    if (entry >= m->tree_count || (parent != UINT32_MAX && entry <= parent))
        return false;
    for (int k = 0; k < 4; k++)
        if (!check_tree(m, m->tree[4 * (size_t)entry + (size_t)k], entry, p, seen))
            return false;
    return true;
}

static bool unit(vec3 n) { return v3_finite(n) && fabs(v3_length(n) - 1.0) < 1e-6; }

/* The mesh: read, then every index bounded and every structure whole. */
static rad_result read_mesh(rad_context *ctx, const char *name, const rad_scene *scene, cursor *c,
                            size_t patches, size_t elements, size_t vertices, size_t tvertices,
                            size_t tree_nodes, rad_mesh **out)
{
    rad_mesh *m = rad_alloc(ctx, RAD_MEM_MESH, 1, sizeof *m, "solution file: mesh");
    if (!m)
        return RAD_ERROR_OUT_OF_MEMORY;
    m->patches = rad_alloc(ctx, RAD_MEM_MESH, patches ? patches : 1, sizeof *m->patches, "solution file: patches");
    m->elements = rad_alloc(ctx, RAD_MEM_MESH, elements ? elements : 1, sizeof *m->elements, "solution file: elements");
    m->vertices = rad_alloc(ctx, RAD_MEM_MESH, vertices ? vertices : 1, sizeof *m->vertices, "solution file: vertices");
    m->tvertices = rad_alloc(ctx, RAD_MEM_MESH, tvertices ? tvertices : 1, sizeof *m->tvertices, "solution file: T-vertices");
    m->tree = tree_nodes ? rad_alloc(ctx, RAD_MEM_MESH, 4 * tree_nodes, sizeof *m->tree, "solution file: quadtree")
                         : NULL;
    unsigned char *seen = rad_alloc(ctx, RAD_MEM_MESH, elements ? elements : 1, 1, "solution file: elements");
    if (!m->patches || !m->elements || !m->vertices || !m->tvertices || (tree_nodes && !m->tree) || !seen) {
        rad_free(seen);
        rad_mesh_destroy(m);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    m->patch_count = patches;
    m->element_count = elements;
    m->vertex_count = vertices;
    m->tvertex_count = tvertices;
    m->tree_count = tree_nodes;
    for (size_t i = 0; i < patches; i++) {
        rad_patch *p = &m->patches[i];
        p->polygon = get_u32(c);
        p->surface = get_u32(c);
        p->material = get_u32(c);
        p->corner_count = get_u32(c);
        p->nu = get_u32(c);
        p->nv = get_u32(c);
        p->first_element = get_u32(c);
        p->element_count = get_u32(c);
        p->tree_root = get_u32(c);
        (void)get_u32(c);
        for (int k = 0; k < 4; k++)
            p->corner[k] = get_vec3(c);
        p->normal = get_vec3(c);
    }
    for (size_t i = 0; i < elements; i++) {
        rad_element *e = &m->elements[i];
        e->patch = get_u32(c);
        e->surface = get_u32(c);
        e->material = get_u32(c);
        e->vertex_count = get_u32(c);
        for (int k = 0; k < 4; k++)
            e->vertex[k] = get_u32(c);
        if (e->vertex_count == 3)
            e->vertex[3] = 0; /* unused: never an index out of range */
        e->centroid = get_vec3(c);
        e->normal = get_vec3(c);
        e->area = get_f64(c);
    }
    for (size_t i = 0; i < vertices; i++)
        m->vertices[i] = get_vec3(c);
    for (size_t i = 0; i < tvertices; i++) {
        rad_tvertex *t = &m->tvertices[i];
        t->vertex = get_u32(c);
        t->a = get_u32(c);
        t->b = get_u32(c);
        (void)get_u32(c);
        t->t = get_f64(c);
    }
    for (size_t i = 0; i < 4 * tree_nodes; i++)
        m->tree[i] = get_u32(c);

    rad_result r = RAD_OK;
    double area_sum = 0.0, scene_area = 0.0;
    for (size_t s = 0; s < scene->surface_count; s++)
        scene_area += scene->surfaces[s].area;
    for (size_t i = 0; r == RAD_OK && i < elements; i++) {
        const rad_element *e = &m->elements[i];
        bool ok = e->patch < patches && (e->vertex_count == 3 || e->vertex_count == 4) &&
                  unit(e->normal) && v3_finite(e->centroid) && isfinite(e->area) && e->area >= 0.0;
        for (uint32_t k = 0; ok && k < e->vertex_count; k++)
            ok = e->vertex[k] < vertices;
        if (ok) /* its patch's surface and material, and its patch's shape: grid cells and leaves are */
            ok = e->surface == m->patches[e->patch].surface && e->material == m->patches[e->patch].material &&
                 e->vertex_count == m->patches[e->patch].corner_count;
        if (!ok)
            r = BAD("%s: element %zu is malformed (patch, corners, vertex indices, normal or area)", name, i);
        else
            area_sum += e->area;
    }
    for (size_t i = 0; r == RAD_OK && i < patches; i++) {
        const rad_patch *p = &m->patches[i];
        bool ok = p->polygon < scene->polygon_count && (p->corner_count == 3 || p->corner_count == 4) &&
                  p->surface == scene->polygons[p->polygon].surface &&
                  p->material == scene->polygons[p->polygon].material && unit(p->normal) && p->nu >= 1 &&
                  p->nv >= 1 && p->element_count >= 1 && p->first_element <= elements &&
                  p->element_count <= elements - p->first_element;
        for (uint32_t k = 0; ok && k < p->corner_count; k++)
            ok = v3_finite(p->corner[k]);
        if (ok && !m->tree) {
            /* A grid: nu x nv cells of a quad, k^2 of a triangle, contiguous. */
            uint64_t cells = p->corner_count == 4 ? (uint64_t)p->nu * p->nv : (uint64_t)p->nu * p->nu;
            ok = (p->corner_count == 4 || p->nu == p->nv) && cells == p->element_count;
            for (uint32_t k = 0; ok && k < p->element_count; k++) {
                uint32_t e = p->first_element + k;
                ok = m->elements[e].patch == i && !seen[e];
                seen[e] = 1;
            }
        } else if (ok) {
            ok = check_tree(m, p->tree_root, UINT32_MAX, (uint32_t)i, seen);
        }
        if (!ok)
            r = BAD("%s: patch %zu is malformed (its polygon, corners, grid or quadtree)", name, i);
    }
    for (size_t i = 0; r == RAD_OK && i < elements; i++)
        if (!seen[i])
            r = BAD("%s: element %zu belongs to no patch's grid or quadtree", name, i);
    for (size_t i = 0; r == RAD_OK && i < vertices; i++)
        if (!v3_finite(m->vertices[i]))
            r = BAD("%s: vertex %zu is not finite", name, i);
    for (size_t i = 0; r == RAD_OK && i < tvertices; i++) {
        const rad_tvertex *t = &m->tvertices[i];
        if (!(t->vertex < vertices && t->a < vertices && t->b < vertices && t->t >= 0.0 && t->t <= 1.0))
            r = BAD("%s: T-vertex %zu is malformed", name, i);
    }
    /* The elements cover the scene: their areas add up to its surfaces'. */
    if (r == RAD_OK && !(fabs(area_sum - scene_area) <= 1e-3 * scene_area))
        r = BAD("%s: the elements' areas add up to %.9g m^2, the scene's surfaces to %.9g m^2", name,
                area_sum, scene_area);
    rad_free(seen);
    if (r != RAD_OK) {
        rad_mesh_destroy(m);
        return r;
    }
    rad_mesh_measure(m);
    *out = m;
    return RAD_OK;
}

static int compare_names(const void *x, const void *y)
{
    return strcmp(*(const char *const *)x, *(const char *const *)y);
}

/* The light part (saved.h): distributions rebuilt through
 * rad_photometry_from_table (which validates the tables), luminaires with
 * finite positions, orthonormal frames, multipliers >= 0 and unique names,
 * attached to `scene`; *direct the elements' direct irradiance, finite and
 * >= 0 (the caller's to free). */
static rad_result read_light(rad_context *ctx, const char *name, rad_scene *scene, const cJSON *ph, const cJSON *lu,
                             cursor *c, size_t elements, double **direct)
{
    size_t P = (size_t)cJSON_GetArraySize(ph), L = (size_t)cJSON_GetArraySize(lu);
    scene->luminaires.photometries = rad_alloc(ctx, RAD_MEM_SCENE, P + 1, sizeof *scene->luminaires.photometries, "solution file: light");
    scene->luminaires.items = rad_alloc(ctx, RAD_MEM_SCENE, L + 1, sizeof *scene->luminaires.items, "solution file: light");
    if (!scene->luminaires.photometries || !scene->luminaires.items)
        return RAD_ERROR_OUT_OF_MEMORY;
    size_t k = 0;
    for (const cJSON *o = ph->child; o; o = o->next, k++) {
        size_t nc = (size_t)number_in(o, "c_count"), ng = (size_t)number_in(o, "gamma_count");
        double dims[3], shape = number_in(o, "shape");
        for (int d = 0; d < 3; d++)
            dims[d] = get_f64(c);
        double *values = rad_alloc(ctx, RAD_MEM_SCENE, nc + ng + nc * ng, sizeof *values, "solution file: light");
        if (!values)
            return RAD_ERROR_OUT_OF_MEMORY;
        for (size_t i = 0; i < nc + ng + nc * ng; i++)
            values[i] = get_f64(c);
        rad_result err = RAD_OK;
        rad_photometry *p = rad_photometry_from_table(ctx, cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(o, "source")),
                                                      nc, values, ng, values + nc, values + nc + ng, &err);
        rad_free(values);
        if (!p)
            return err == RAD_ERROR_OUT_OF_MEMORY ? RAD_ERROR_OUT_OF_MEMORY
                                                  : BAD("%s: light: distribution %zu is not a valid table", name, k);
        scene->luminaires.photometries[scene->luminaires.photometry_count++] = p;
        for (int d = 0; d < 3; d++)
            if (!(isfinite(dims[d]) && dims[d] >= 0.0))
                return BAD("%s: light: distribution %zu has an opening of %g m", name, k, dims[d]);
        if (!(shape >= 0.0 && shape <= RAD_OPENING_VERTICAL_ELLIPSE_Y && shape == floor(shape)))
            return BAD("%s: light: distribution %zu has no shape %g", name, k, shape);
        p->width = dims[0], p->length = dims[1], p->height = dims[2];
        p->shape = (rad_luminous_shape)shape;
    }
    k = 0;
    for (const cJSON *o = lu->child; o; o = o->next, k++) {
        rad_luminaire *l = &scene->luminaires.items[k];
        memset(l, 0, sizeof *l);
        l->name = rad_strdup(ctx, RAD_MEM_SCENE, cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(o, "name")),
                             "solution file: light");
        if (!l->name)
            return RAD_ERROR_OUT_OF_MEMORY;
        scene->luminaires.count = k + 1;
        l->photometry = (uint32_t)number_in(o, "photometry");
        l->position = get_vec3(c);
        for (int a = 0; a < 3; a++)
            l->axis[a] = get_vec3(c);
        l->multiplier = get_f64(c);
        bool ok = v3_finite(l->position) && isfinite(l->multiplier) && l->multiplier >= 0.0;
        for (int a = 0; a < 3 && ok; a++)
            for (int b2 = 0; b2 < 3 && ok; b2++)
                ok = fabs(v3_dot(l->axis[a], l->axis[b2]) - (a == b2 ? 1.0 : 0.0)) < 1e-9;
        if (!ok)
            return BAD("%s: light: luminaire %zu has a position, frame or multiplier out of range", name, k);
    }
    const char **names = rad_alloc(ctx, RAD_MEM_SCENE, L + 1, sizeof *names, "solution file: light");
    if (!names)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < L; i++)
        names[i] = scene->luminaires.items[i].name;
    qsort(names, L, sizeof *names, compare_names);
    bool unique = true;
    for (size_t i = 1; i < L; i++)
        unique = unique && strcmp(names[i - 1], names[i]) != 0;
    rad_free(names);
    if (!unique)
        return BAD("%s: light: two luminaires have one name", name);
    double *d = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * elements + 1, sizeof *d, "solution: direct light");
    if (!d)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < 3 * elements; i++) {
        d[i] = get_f64(c);
        if (!(isfinite(d[i]) && d[i] >= 0.0)) {
            rad_free(d);
            return BAD("%s: light: element %zu has direct irradiance %g W/m^2", name, i / 3, d[i]);
        }
    }
    *direct = d;
    return RAD_OK;
}

static bool unit_vector(vec3 v) { return v3_finite(v) && fabs(v3_length(v) - 1.0) < 1e-9; }

/* The daylight part (saved.h): the sky as prepared, the sun, the ground and
 * the openings, each number finite and in its range, the directions unit
 * vectors, attached to `scene`; *direct (when the header says it follows)
 * the elements' direct irradiance, finite and >= 0 (the caller's to free). */
static rad_result read_daylight(rad_context *ctx, const char *name, rad_scene *scene, const cJSON *day,
                                cursor *c, size_t elements, double **direct)
{
    rad_daylight *d = rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *d, "solution file: daylight");
    if (!d)
        return RAD_ERROR_OUT_OF_MEMORY;
    memset(d, 0, sizeof *d);
    scene->daylight = d; /* the scene frees it from here on */
    const cJSON *names = cJSON_GetObjectItemCaseSensitive(day, "opening_names");
    size_t N = (size_t)cJSON_GetArraySize(names), O = (size_t)number_in(day, "openings");
    d->source = rad_strdup(ctx, RAD_MEM_SCENE, cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(day, "source")),
                           "solution file: daylight");
    d->opening_names = rad_alloc(ctx, RAD_MEM_SCENE, N + 1, sizeof *d->opening_names, "solution file: daylight");
    d->openings = rad_alloc(ctx, RAD_MEM_SCENE, O + 1, sizeof *d->openings, "solution file: daylight");
    if (!d->source || !d->opening_names || !d->openings)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (const cJSON *o = names->child; o; o = o->next) {
        d->opening_names[d->opening_name_count] = rad_strdup(ctx, RAD_MEM_SCENE, o->valuestring, "solution file: daylight");
        if (!d->opening_names[d->opening_name_count])
            return RAD_ERROR_OUT_OF_MEMORY;
        d->opening_name_count++;
    }
    double model = number_in(day, "model"), type = number_in(day, "type");
    rad_sky *k = &d->sky;
    double *sky[10] = {&k->a, &k->b, &k->c, &k->d, &k->e, &k->sun_zenith, &k->sun_azimuth, &k->norm,
                       &k->zenith_radiance, &k->horizontal};
    bool ok = true;
    for (int i = 0; i < 10; i++) {
        *sky[i] = get_f64(c);
        ok = ok && isfinite(*sky[i]);
    }
    k->up = get_vec3(c);
    k->north = get_vec3(c);
    k->east = get_vec3(c);
    k->sun = get_vec3(c);
    double *rest[6] = {&d->sun_normal, &d->ground_reflectance, &d->ground_radiance, &d->zenith_luminance,
                       &d->diffuse_illuminance, &d->tolerance};
    for (int i = 0; i < 6; i++) {
        *rest[i] = get_f64(c);
        ok = ok && isfinite(*rest[i]) && *rest[i] >= 0.0;
    }
    ok = ok && (model == RAD_SKY_CIE_GENERAL ? type >= 1 && type <= 15 && type == floor(type)
                                             : model == RAD_SKY_CIE_OVERCAST && type == 0);
    ok = ok && unit_vector(k->up) && unit_vector(k->north) && unit_vector(k->east) && unit_vector(k->sun) &&
         k->sun_zenith >= 0.0 && k->sun_zenith < 0.5 * M_PI && k->norm >= 0.0 && k->zenith_radiance >= 0.0 &&
         k->horizontal >= 0.0 && d->ground_reflectance <= 1.0 && d->tolerance > 0.0 && d->tolerance <= 0.1;
    if (!ok)
        return BAD("%s: daylight: the sky, sun or ground is out of range", name);
    k->model = (rad_sky_model)model;
    k->type = (int)type;
    d->ground = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(day, "ground"));
    for (size_t i = 0; i < O; i++) {
        rad_opening *o = &d->openings[i];
        o->corner_count = get_u32(c);
        o->surface = get_u32(c);
        for (int q = 0; q < 4; q++)
            o->corner[q] = get_vec3(c);
        o->normal = get_vec3(c);
        o->area = get_f64(c);
        ok = (o->corner_count == 3 || o->corner_count == 4) && o->surface < N && unit_vector(o->normal) &&
             isfinite(o->area) && o->area > 0.0;
        for (int q = 0; q < 4 && ok; q++)
            ok = v3_finite(o->corner[q]);
        if (!ok)
            return BAD("%s: daylight: opening %zu is malformed", name, i);
        d->opening_count = i + 1;
    }
    if (!direct || !cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(day, "direct")))
        return RAD_OK;
    double *h = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * elements + 1, sizeof *h, "solution: direct light");
    if (!h)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < 3 * elements; i++) {
        h[i] = get_f64(c);
        if (!(isfinite(h[i]) && h[i] >= 0.0)) {
            rad_free(h);
            return BAD("%s: daylight: element %zu has direct irradiance %g W/m^2", name, i / 3, h[i]);
        }
    }
    *direct = h;
    return RAD_OK;
}

rad_result rad_saved_read(rad_context *ctx, const char *name, const unsigned char *data, size_t size,
                          rad_scene **scene_out, rad_options *options, rad_method_names *names,
                          void **state)
{
    *scene_out = NULL;
    *state = NULL;
    if (size < RAD_SAVED_MAGIC_SIZE + 4 || memcmp(data, RAD_SAVED_MAGIC, RAD_SAVED_MAGIC_SIZE) != 0)
        return BAD("%s: not a radiosity solution file (it does not begin with the solution "
                   "file's signature)",
                   name);
    cursor c = {data + RAD_SAVED_MAGIC_SIZE, data + size};
    size_t header_size = get_u32(&c);
    if (header_size > size - RAD_SAVED_MAGIC_SIZE - 4)
        return BAD("%s: the header claims %zu bytes, %zu are left in the file", name, header_size,
                   size - RAD_SAVED_MAGIC_SIZE - 4);
    cJSON *header = cJSON_ParseWithLength((const char *)c.p, header_size);
    if (!header)
        return BAD("%s: the header is not JSON", name);
    size_t payload_at = (RAD_SAVED_MAGIC_SIZE + 4 + header_size + 7) / 8 * 8;
    rad_result r = RAD_OK;
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    saved_state *st = NULL;
    const cJSON *counts = cJSON_GetObjectItemCaseSensitive(header, "counts");
    const cJSON *payload = cJSON_GetObjectItemCaseSensitive(header, "payload");
    const cJSON *solution = cJSON_GetObjectItemCaseSensitive(header, "solution");
    double version = number_in(header, "version");
    size_t corners = 0, polygons = 0, material_count = 0, patches = 0, elements = 0, vertices = 0, tvertices = 0, tree_nodes = 0;
    /* Counts are bounded by the bytes they need, so the sizes below cannot overflow. */
    size_t most = size / 16;
    if (version != RAD_SAVED_VERSION) {
        r = BAD("%s: format version %g is not read (this is version %d)", name, version, RAD_SAVED_VERSION);
        goto done;
    }
    if (!count_in(counts, "corners", most, &corners) || !count_in(counts, "polygons", most, &polygons) ||
        !count_in(counts, "materials", most, &material_count) ||
        !count_in(counts, "patches", most, &patches) || !count_in(counts, "elements", most, &elements) ||
        !count_in(counts, "vertices", most, &vertices) || !count_in(counts, "tvertices", most, &tvertices) ||
        !count_in(counts, "tree_nodes", most, &tree_nodes) || !cJSON_IsObject(solution)) {
        r = BAD("%s: the header's counts or solution are missing or out of range", name);
        goto done;
    }
    if (polygons > UINT32_MAX || patches > UINT32_MAX || elements >= RAD_TREE_LEAF ||
        vertices > UINT32_MAX || tree_nodes >= RAD_TREE_LEAF) {
        r = BAD("%s: the counts pass what the mesh can index", name);
        goto done;
    }
    size_t expected = 24 * corners + 16 * polygons + 48 * material_count + 88 + 160 * patches + 88 * elements + 24 * vertices +
                      24 * tvertices + 16 * tree_nodes + 24 * elements + 24 * vertices;
    /* The light, when the header names it: its bytes follow the values. */
    const cJSON *light = cJSON_GetObjectItemCaseSensitive(header, "light");
    const cJSON *light_ph = cJSON_GetObjectItemCaseSensitive(light, "photometries");
    const cJSON *light_lu = cJSON_GetObjectItemCaseSensitive(light, "luminaires");
    size_t light_at = expected;
    if (light) {
        bool ok = cJSON_IsArray(light_ph) && cJSON_IsArray(light_lu) && cJSON_GetArraySize(light_lu) > 0;
        for (const cJSON *o = ok ? light_ph->child : NULL; o && ok; o = o->next) {
            size_t nc = 0, ng = 0;
            ok = count_in(o, "c_count", most, &nc) && count_in(o, "gamma_count", most, &ng) && nc >= 1 && ng >= 2 &&
                 (double)nc * (double)ng <= (double)most && cJSON_IsString(cJSON_GetObjectItemCaseSensitive(o, "source"));
            expected += ok ? 24 + 8 * (nc + ng + nc * ng) : 0;
        }
        for (const cJSON *o = ok ? light_lu->child : NULL; o && ok; o = o->next) {
            const char *lname = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(o, "name"));
            size_t index = 0;
            ok = lname && lname[0] && count_in(o, "photometry", (size_t)cJSON_GetArraySize(light_ph) - 1, &index) &&
                 cJSON_GetArraySize(light_ph) > 0;
            expected += 104;
        }
        expected += 24 * elements;
        if (!ok || expected > size) {
            r = BAD("%s: the header's light (photometries, luminaires) is malformed", name);
            goto done;
        }
    }
    /* The daylight, when the header names it: its bytes follow the light's. */
    const cJSON *day = cJSON_GetObjectItemCaseSensitive(header, "daylight");
    size_t day_at = expected;
    if (day) {
        const cJSON *day_names = cJSON_GetObjectItemCaseSensitive(day, "opening_names");
        size_t openings = 0;
        bool ok = cJSON_IsObject(day) && cJSON_IsArray(day_names) &&
                  cJSON_IsString(cJSON_GetObjectItemCaseSensitive(day, "source")) &&
                  count_in(day, "openings", most, &openings) && cJSON_IsBool(cJSON_GetObjectItemCaseSensitive(day, "ground")) &&
                  cJSON_IsBool(cJSON_GetObjectItemCaseSensitive(day, "direct")) &&
                  cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(day, "direct")) == !light;
        for (const cJSON *o = ok ? day_names->child : NULL; o && ok; o = o->next)
            ok = cJSON_IsString(o) && o->valuestring[0];
        expected += 8 * 28 + 136 * openings + (light ? 0 : 24 * elements);
        if (!ok || expected > size) {
            r = BAD("%s: the header's daylight is malformed", name);
            goto done;
        }
    }
    double payload_bytes = number_in(payload, "bytes");
    const char *checksum = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(payload, "fnv1a64"));
    if (payload_at > size || payload_bytes != (double)expected || expected != size - payload_at || !checksum) {
        r = BAD("%s: the payload should hold %zu bytes for its counts, the file has %zu (truncated or "
                "damaged)",
                name, expected, payload_at <= size ? size - payload_at : 0);
        goto done;
    }
    char hex[17];
    snprintf(hex, sizeof hex, "%016" PRIx64, rad_fnv1a(RAD_FNV_OFFSET, data + payload_at, expected));
    if (strcmp(hex, checksum) != 0) {
        r = BAD("%s: the payload's checksum is %s, not the %s written (the file is damaged)", name, hex,
                checksum);
        goto done;
    }
    r = read_options(ctx, name, cJSON_GetObjectItemCaseSensitive(header, "options"), options, names);
    if (r != RAD_OK)
        goto done;
    c.p = data + payload_at;
    r = read_scene(ctx, name, header, &c, corners, polygons, material_count, &scene);
    if (r == RAD_OK)
        r = read_mesh(ctx, name, scene, &c, patches, elements, vertices, tvertices, tree_nodes, &mesh);
    if (r != RAD_OK)
        goto done;
    double *direct = NULL;
    if (light) {
        cursor lc = {data + payload_at + light_at, data + size};
        r = read_light(ctx, name, scene, light_ph, light_lu, &lc, elements, &direct);
        if (r != RAD_OK)
            goto done;
    }
    if (day) {
        cursor dc = {data + payload_at + day_at, data + size};
        r = read_daylight(ctx, name, scene, day, &dc, elements, light ? NULL : &direct);
        if (r != RAD_OK) {
            rad_free(direct);
            goto done;
        }
    }
    st = rad_alloc(ctx, RAD_MEM_SOLVER, 1, sizeof *st, "solution file: state");
    if (!st || rad_elements_create(ctx, scene, mesh, &st->elements) != RAD_OK) {
        rad_free(direct);
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    if (direct) {
        /* As rad_elements_add_light left them: E + rho H_d. */
        for (size_t k = 0; k < 3 * elements; k++)
            st->elements.emission[k] += st->elements.reflectance[k] * direct[k];
        st->elements.direct = direct;
    }
    st->mesh = mesh;
    mesh = NULL;
    /* The values: B at least E (light only adds) and within what
     * conservation allows, 4 E_max / (1 - rho_max), as every solve is held
     * to (api.c); the vertex values are the renderer's and are made again
     * from them. */
    double e_max = 0.0, rho_max = 0.0;
    for (size_t i = 0; i < 3 * elements; i++) {
        e_max = fmax(e_max, st->elements.emission[i]);
        rho_max = fmax(rho_max, st->elements.reflectance[i]);
    }
    double bound = 4.0 * e_max / (1.0 - rho_max);
    for (size_t i = 0; r == RAD_OK && i < 3 * elements; i++) {
        double b = get_f64(&c);
        if (!(isfinite(b) && b >= st->elements.emission[i] * (1.0 - 1e-9) && b <= bound))
            r = BAD("%s: element %zu has radiosity %g W/m^2, outside [its emission %g, %g] (what "
                    "conservation allows)",
                    name, i / 3, b, st->elements.emission[i], bound);
        st->elements.radiosity[i] = b;
    }
    for (size_t i = 0; r == RAD_OK && i < 3 * vertices; i++) {
        double b = get_f64(&c);
        if (!(isfinite(b) && b >= 0.0))
            r = BAD("%s: vertex %zu has radiosity %g W/m^2", name, i / 3, b);
    }
    if (r != RAD_OK)
        goto done;
    /* The figures of the solve, for the stats and the display. */
    rad_solve_stats *ss = &st->solve_stats;
    rad_ff_stats *ff = &st->ff_stats;
    const char *method = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(solution, "method"));
    const char *ff_method = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(solution, "form_factors"));
    snprintf(st->solve_method, sizeof st->solve_method, "%s", method ? method : "unknown");
    snprintf(st->ff_method, sizeof st->ff_method, "%s", ff_method ? ff_method : "unknown");
    ss->method = st->solve_method;
    ff->method = st->ff_method;
    double iterations = number_in(solution, "iterations");
    ss->iterations = iterations >= 0.0 && iterations < 2147483647.0 ? (int)iterations : 0;
    ss->residual = number_in(solution, "residual");
    ss->converged = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(solution, "converged"));
    ss->unshot = number_in(solution, "unshot");
    ss->absorbed = number_in(solution, "absorbed_W");
    ss->iteration_limit = number_in(solution, "iteration_limit");
    const cJSON *ambient = cJSON_GetObjectItemCaseSensitive(solution, "ambient");
    for (int k = 0; k < 3; k++) {
        const cJSON *a = cJSON_GetArrayItem(ambient, k);
        ss->ambient[k] = cJSON_IsNumber(a) && isfinite(a->valuedouble) && a->valuedouble >= 0.0 ? a->valuedouble : 0.0;
    }
    const char *warning = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(solution, "warning"));
    snprintf(ss->warning, sizeof ss->warning, "%s", warning ? warning : "");
    ff->row_sum_min = ff->row_sum_max = ff->row_sum_mean = NAN;
    ff->reciprocity_max = ff->diagonal_max = ff->std_error_max = NAN;
    if (!(isfinite(ss->absorbed) && ss->absorbed >= 0.0)) {
        r = BAD("%s: the absorbed power is missing or not a finite number >= 0", name);
        goto done;
    }
    /* The ray structure as the solve had it: a hierarchical solution
     * traces against its patches meshed whole (hierarchical.c), whose bent
     * patches are single primitives, not their leaves; so it is built over
     * that mesh again, and the picture is the same to the last bit. */
    double t = rad_seconds();
    if (st->mesh->tree) {
        rad_mesh_options mo = {1e30, 0, options->crease_angle_degrees};
        r = rad_mesh_build(ctx, scene, &mo, &st->patches);
        /* Ray hits name patches of that mesh and are located in the saved
         * one: they must be the same patches (a file from a version that
         * cut the scene's polygons differently is not). */
        bool same = r == RAD_OK && st->patches->patch_count == st->mesh->patch_count;
        for (size_t i = 0; same && i < st->mesh->patch_count; i++) {
            const rad_patch *a = &st->patches->patches[i], *b = &st->mesh->patches[i];
            same = a->corner_count == b->corner_count && a->surface == b->surface;
            for (uint32_t k = 0; same && k < a->corner_count; k++)
                same = v3_length(v3_sub(a->corner[k], b->corner[k])) <=
                       1e-9 * (1.0 + v3_length(a->corner[k]));
        }
        if (r == RAD_OK && !same)
            r = BAD("%s: its patches are not those this version cuts the scene into "
                    "(%zu saved, %zu here); solve the scene again",
                    name, st->mesh->patch_count, st->patches->patch_count);
    }
    if (r == RAD_OK)
        r = rad_vis_create(ctx, options->visibility, st->patches ? st->patches : st->mesh, &st->vis);
    st->seconds.visibility = rad_seconds() - t;

done:
    cJSON_Delete(header);
    rad_mesh_destroy(mesh);
    if (r != RAD_OK) {
        saved_destroy(st);
        rad_scene_destroy(scene);
        return r;
    }
    *scene_out = scene;
    *state = st;
    return RAD_OK;
}
