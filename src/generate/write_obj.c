/*
 * write_obj.c -- any scene saved as OBJ + MTL (PATH.obj beside PATH.mtl),
 * so that a generated scene can be looked at, edited and loaded again.
 *
 * What is written reads back as the same scene: one `o` per surface with
 * its polygons in scene order, coordinates and reflectances as the
 * shortest decimal that reads back as the same double, emission as the
 * MTL's radiance Ke = E / pi, and names made safe for the format.  Both
 * files are written in full before either replaces what was there
 * (an output set), so a failure leaves neither behind.
 */
#include "scene/scene.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

/* The shortest of 15 or 17 significant digits that reads back as the same
 * double, so 4.237 is written "4.237" and nothing is lost either way. */
static void format_double(char *text, size_t size, double value)
{
    /* Fast path, 5x quicker than printf: a value that is the double nearest
     * to k / 10^6 for |k| < 2^53 is written as that decimal, which reads
     * back (correctly rounded) as the same double. */
    double scaled = value * 1e6;
    if (fabs(scaled) < 9007199254740992.0) {
        long long k = llround(scaled);
        if ((double)k / 1e6 == value) {
            unsigned long long magnitude = (unsigned long long)(k < 0 ? -k : k);
            unsigned long long whole = magnitude / 1000000, fraction = magnitude % 1000000;
            int n = snprintf(text, size, "%s%llu", k < 0 ? "-" : "", whole);
            if (fraction && n > 0 && (size_t)n + 8 <= size) {
                char *p = text + n;
                *p++ = '.';
                for (unsigned long long unit = 100000; unit && fraction; unit /= 10) {
                    *p++ = (char)('0' + fraction / unit);
                    fraction %= unit;
                }
                *p = '\0';
            }
            return;
        }
    }
    snprintf(text, size, "%.15g", value);
    if (strtod(text, NULL) != value)
        snprintf(text, size, "%.17g", value);
}

/* An OBJ/MTL name: blanks, control characters and '#' would end or
 * comment out the statement, so they become '_'; empty becomes `fallback`. */
static void write_name(FILE *file, const char *name, const char *fallback, size_t index)
{
    if (!name || !*name) {
        fprintf(file, "%s_%zu", fallback, index);
        return;
    }
    for (const char *c = name; *c; c++)
        fputc((unsigned char)*c <= ' ' || *c == '#' || *c == 0x7f ? '_' : *c, file);
}

/* The scene's path in a comment line: a control character (a newline in
 * a file name) would end the comment and start a statement, so it becomes
 * '?'. */
static void write_comment_text(FILE *file, const char *text)
{
    for (const char *c = text ? text : "scene"; *c; c++)
        fputc((unsigned char)*c < ' ' || *c == 0x7f ? '?' : *c, file);
}

/* Material i's name in the MTL, made unique by its index when an earlier
 * material has the same name (the builder does not require unique names).
 * O(materials^2), once per material: scenes have few materials. */
static void write_material_name(FILE *file, const rad_scene *scene, size_t i)
{
    write_name(file, scene->materials[i].name, "material", i);
    for (size_t j = 0; j < i; j++)
        if (scene->materials[i].name && scene->materials[j].name &&
            strcmp(scene->materials[i].name, scene->materials[j].name) == 0) {
            fprintf(file, "_%zu", i);
            return;
        }
}

static rad_result write_mtl(const rad_scene *scene, FILE *mtl)
{
    fputs("# ", mtl);
    write_comment_text(mtl, scene->source);
    fputs(": materials (Kd = reflectance, Ke = emitted radiance = exitance / pi)\n", mtl);
    for (size_t i = 0; i < scene->material_count; i++) {
        const rad_material *m = &scene->materials[i];
        char v[3][32];
        fputs("\nnewmtl ", mtl);
        write_material_name(mtl, scene, i);
        for (int c = 0; c < 3; c++)
            format_double(v[c], sizeof v[c], m->reflectance[c]);
        fprintf(mtl, "\nKd %s %s %s\n", v[0], v[1], v[2]);
        /* 15 digits: E / pi is not exact anyway, and no reader keeps more. */
        fprintf(mtl, "Ke %.15g %.15g %.15g\nillum 1\n", m->emission[0] / M_PI,
                m->emission[1] / M_PI, m->emission[2] / M_PI);
    }
    return RAD_OK;
}

/* Polygons grouped by surface (one `o` per surface), in scene order within
 * each: a counting sort, O(polygons + surfaces). */
static rad_result write_obj_body(rad_context *ctx, const rad_scene *scene, FILE *obj,
                                 const char *mtl_name)
{
    size_t surfaces = scene->surface_count, polygons = scene->polygon_count;
    size_t *start = rad_alloc(ctx, RAD_MEM_OUTPUT, surfaces + 1, sizeof *start, "OBJ: surface offsets");
    uint32_t *order = start ? rad_alloc(ctx, RAD_MEM_OUTPUT, polygons, sizeof *order, "OBJ: polygon order")
                            : NULL;
    if (!start || !order) {
        rad_free(start);
        rad_free(order);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memset(start, 0, (surfaces + 1) * sizeof *start);
    for (size_t p = 0; p < polygons; p++)
        start[scene->polygons[p].surface + 1]++;
    for (size_t s = 0; s < surfaces; s++)
        start[s + 1] += start[s];
    for (size_t p = 0; p < polygons; p++)
        order[start[scene->polygons[p].surface]++] = (uint32_t)p;
    /* start[s] now ends surface s: shift back to beginnings. */
    for (size_t s = surfaces; s > 0; s--)
        start[s] = start[s - 1];
    start[0] = 0;

    fputs("# ", obj);
    write_comment_text(obj, scene->source);
    fprintf(obj, ": %zu surfaces, %zu polygons; metres, y up\n", surfaces, polygons);
    if (scene->has_camera) {
        /* OBJ has no camera: a comment the loader reads back
         * (obj_prescan.c, import_obj_exact_positions), other readers skip. */
        const rad_camera *c = &scene->camera;
        fprintf(obj, "%s %.17g %.17g %.17g  %.17g %.17g %.17g  %.17g %.17g %.17g  %.17g\n", RAD_OBJ_CAMERA_COMMENT,
                c->position[0], c->position[1], c->position[2], c->look_at[0], c->look_at[1], c->look_at[2],
                c->up[0], c->up[1], c->up[2], c->vfov_degrees);
    }
    fprintf(obj, "mtllib %s\n", mtl_name);
    size_t written = 0; /* vertices so far: OBJ indices are 1 + this */
    for (size_t s = 0; s < surfaces; s++) {
        fputs("\no ", obj);
        write_name(obj, scene->surfaces[s].name, "surface", s);
        fputc('\n', obj);
        uint32_t material = UINT32_MAX;
        for (size_t k = start[s]; k < start[s + 1]; k++) {
            const rad_polygon *p = &scene->polygons[order[k]];
            if (p->material != material) {
                material = p->material;
                fputs("usemtl ", obj);
                write_material_name(obj, scene, material);
                fputc('\n', obj);
            }
            for (uint32_t i = 0; i < p->vertex_count; i++) {
                vec3 v = scene->positions[scene->indices[p->first_index + i]];
                char x[32], y[32], z[32];
                format_double(x, sizeof x, v.x);
                format_double(y, sizeof y, v.y);
                format_double(z, sizeof z, v.z);
                fprintf(obj, "v %s %s %s\n", x, y, z);
            }
            fputc('f', obj);
            for (uint32_t i = 0; i < p->vertex_count; i++)
                fprintf(obj, " %zu", written + 1 + i);
            fputc('\n', obj);
            written += p->vertex_count;
        }
    }
    rad_free(start);
    rad_free(order);
    return RAD_OK;
}

rad_result rad_scene_write_obj(rad_context *ctx, const rad_scene *scene, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !scene || !path)
        return rad_null_argument(ctx, __func__);
    if (!*path)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "rad_scene_write_obj: the path is empty");
    /* PATH.obj -> PATH.mtl; any other name gets ".mtl" appended. */
    size_t length = strlen(path);
    char extension[8];
    rad_path_extension(path, extension, sizeof extension);
    size_t stem = strcmp(extension, "obj") == 0 ? length - 4 : length;
    char *mtl_path = rad_alloc(ctx, RAD_MEM_OUTPUT, stem + 5, 1, path);
    if (!mtl_path)
        return RAD_ERROR_OUT_OF_MEMORY;
    memcpy(mtl_path, path, stem);
    memcpy(mtl_path + stem, ".mtl", 5);
    const char *slash = strrchr(mtl_path, '/');
    const char *mtl_name = slash ? slash + 1 : mtl_path;
    /* The OBJ names its MTL in an `mtllib` statement, where a blank
     * separates file names and a line break or '#' ends the statement (a
     * name holding "\nv 9 9 9" would add a vertex): such a name cannot be
     * written, and is refused before anything is. */
    for (const char *c = mtl_name; *c; c++)
        if ((unsigned char)*c <= ' ' || *c == '#' || *c == 0x7f) {
            rad_result bad = rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                                      "%s: an OBJ cannot name its MTL when the file name holds a blank, a "
                                      "control character or '#' (mtllib separates names by blanks): choose "
                                      "another name",
                                      path);
            rad_free(mtl_path);
            return bad;
        }

    /* Both written in full before either is put in place; a write error
     * (full disk) or an interruption leaves neither. */
    rad_output_set *set = NULL;
    const char *obj_temp = NULL, *mtl_temp = NULL;
    rad_atomic_file obj = {0}, mtl = {0};
    rad_result r = rad_output_set_create(ctx, &set);
    if (r == RAD_OK)
        r = rad_output_set_add(ctx, set, path, RAD_OUTPUT_FILE, &obj_temp);
    if (r == RAD_OK)
        r = rad_output_set_add(ctx, set, mtl_path, RAD_OUTPUT_FILE, &mtl_temp);
    if (r == RAD_OK)
        r = rad_atomic_open(ctx, obj_temp, &obj);
    if (r == RAD_OK)
        r = rad_atomic_open(ctx, mtl_temp, &mtl);
    if (r == RAD_OK)
        r = write_mtl(scene, mtl.file);
    if (r == RAD_OK)
        r = write_obj_body(ctx, scene, obj.file, mtl_name);
    if (r == RAD_OK)
        r = rad_atomic_commit(ctx, &mtl);
    if (r == RAD_OK)
        r = rad_atomic_commit(ctx, &obj);
    if (r == RAD_OK && rad_cancelled(ctx))
        r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "%s: interrupted; nothing written", path);
    if (r == RAD_OK)
        r = rad_output_set_commit(ctx, set);
    rad_atomic_abort(&obj);
    rad_atomic_abort(&mtl);
    rad_output_set_destroy(set);
    rad_free(mtl_path);
    return r;
}
