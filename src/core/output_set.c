/*
 * output_set.c -- several output files written as one transaction: every
 * path is checked before the work (folder, format, aliasing), every file
 * is written to its own temporary, and the files replace the old ones only
 * when all were written (rad_output_set_commit); a failure or an abandoned
 * set leaves the old files and no temporary.
 *
 *   add("out.png")    -> .out.png.k3x9qz.png   (an empty placeholder, O_EXCL)
 *   the writers       -> write the placeholder (atomically, as any path)
 *   commit            -> streams (/dev/stdout, FIFOs) copied in place first,
 *                        then old files linked to backups, renames, backups
 *                        dropped; a failed rename puts the backups back
 *
 * Aliasing is decided by identity (rad_output_target_same): an output that
 * is an input, or another output, is refused whatever names lead to it.
 */
#include "core/core.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct output_entry {
    char *path;               /* as given, for messages */
    char *temp;               /* the placeholder the writers fill; NULL once dropped */
    char *backup;             /* the old file, linked aside during commit; NULL if none */
    rad_output_target target;
} output_entry;

typedef struct input_entry {
    char *path;
    uint64_t device, inode;
} input_entry;

struct rad_output_set {
    output_entry *outputs;
    size_t output_count, output_capacity;
    input_entry *inputs;
    size_t input_count, input_capacity;
};

/* Grow an array of `size`-byte items to hold one more; false when out of memory. */
static bool reserve(void **items, size_t *capacity, size_t count, size_t size)
{
    if (count < *capacity)
        return true;
    size_t grown = *capacity ? 2 * *capacity : 4;
    void *p = rad_realloc(NULL, RAD_MEM_OUTPUT, *items, grown, size, "output set");
    if (!p)
        return false;
    *items = p;
    *capacity = grown;
    return true;
}

rad_result rad_output_set_create(rad_context *ctx, rad_output_set **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !out)
        return rad_null_argument(ctx, __func__);
    *out = rad_alloc(ctx, RAD_MEM_OUTPUT, 1, sizeof **out, "output set");
    return *out ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
}

static void entry_clear(output_entry *e)
{
    if (e->temp)
        unlink(e->temp);
    if (e->backup)
        unlink(e->backup);
    rad_free(e->temp);
    rad_free(e->backup);
    rad_free(e->path);
    rad_output_target_free(&e->target);
}

void rad_output_set_destroy(rad_output_set *set)
{
    if (!set)
        return;
    for (size_t i = 0; i < set->output_count; i++)
        entry_clear(&set->outputs[i]);
    for (size_t i = 0; i < set->input_count; i++)
        rad_free(set->inputs[i].path);
    rad_free(set->outputs);
    rad_free(set->inputs);
    rad_free(set);
}

rad_result rad_output_set_add_input(rad_context *ctx, rad_output_set *set, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !set || !path)
        return rad_null_argument(ctx, __func__);
    input_entry in = {0};
    if (!rad_file_identity(path, &in.device, &in.inode))
        return RAD_OK; /* not there: no output can be it */
    for (size_t i = 0; i < set->output_count; i++) {
        const rad_output_target *t = &set->outputs[i].target;
        if (t->exists && t->device == in.device && t->inode == in.inode)
            return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                            "%s: is the same file as the input %s (refused: it would be overwritten)",
                            set->outputs[i].path, path);
    }
    in.path = rad_strdup(ctx, RAD_MEM_OUTPUT, path, "file name");
    if (!in.path || !reserve((void **)&set->inputs, &set->input_capacity, set->input_count,
                             sizeof *set->inputs)) {
        rad_free(in.path);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    set->inputs[set->input_count++] = in;
    return RAD_OK;
}

/* The writers' formats, checked before any work with the writers' words. */
static rad_result check_format(rad_context *ctx, const char *path, rad_output_kind kind)
{
    char ext[16];
    rad_path_extension(path, ext, sizeof ext);
    if (kind == RAD_OUTPUT_IMAGE && strcmp(ext, "png") != 0 && strcmp(ext, "hdr") != 0 &&
        strcmp(ext, "pfm") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: unknown image format (use .png, .hdr or .pfm)", path);
    if (kind == RAD_OUTPUT_VIEW_FACTORS && strcmp(ext, "json") != 0 && strcmp(ext, "csv") != 0 &&
        strcmp(ext, "mtx") != 0 && strcmp(ext, "vf") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: unknown view-factor format (use .json, .csv, .mtx or .vf)", path);
    if (kind == RAD_OUTPUT_SOLUTION && strcmp(ext, "radsol") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: a solution file is named .radsol (docs/formats.md)", path);
    if (kind == RAD_OUTPUT_MESH && strcmp(ext, "glb") != 0 && strcmp(ext, "gltf") != 0 &&
        strcmp(ext, "ply") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: unknown mesh format (use .glb, .gltf or .ply)", path);
    if (kind == RAD_OUTPUT_BAKE && strcmp(ext, "glb") != 0 && strcmp(ext, "gltf") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: unknown lightmapped mesh format (use .glb or .gltf; the lightmaps are written "
                        "beside it)", path);
    if (kind == RAD_OUTPUT_THERMAL && strcmp(ext, "json") != 0 && strcmp(ext, "csv") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: unknown heat-exchange format (use .csv or .json)",
                        path);
    if (kind == RAD_OUTPUT_ILLUMINANCE && strcmp(ext, "json") != 0 && strcmp(ext, "csv") != 0 &&
        strcmp(ext, "png") != 0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "%s: unknown illuminance format (use .csv, .json, or .png for the grids' plans)", path);
    if (kind != RAD_OUTPUT_FILE && kind != RAD_OUTPUT_IMAGE && kind != RAD_OUTPUT_VIEW_FACTORS &&
        kind != RAD_OUTPUT_SOLUTION && kind != RAD_OUTPUT_MESH && kind != RAD_OUTPUT_BAKE &&
        kind != RAD_OUTPUT_THERMAL && kind != RAD_OUTPUT_ILLUMINANCE)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: unknown output kind %d", path,
                        (int)kind);
    return RAD_OK;
}

rad_result rad_output_set_add(rad_context *ctx, rad_output_set *set, const char *path,
                              rad_output_kind kind, const char **temp_path)
{
    rad_api_enter(ctx);
    if (temp_path)
        *temp_path = NULL;
    if (!ctx || !set || !path || !temp_path)
        return rad_null_argument(ctx, __func__);
    rad_result r = check_format(ctx, path, kind);
    if (r != RAD_OK)
        return r;
    output_entry e = {0};
    r = rad_output_target_resolve(ctx, path, &e.target);
    if (r != RAD_OK)
        return r;
    for (size_t i = 0; i < set->input_count && r == RAD_OK; i++) {
        const input_entry *in = &set->inputs[i];
        if (e.target.exists && e.target.device == in->device && e.target.inode == in->inode)
            r = rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                         "%s: is the same file as the input %s (refused: it would be overwritten)",
                         path, in->path);
    }
    for (size_t i = 0; i < set->output_count && r == RAD_OK; i++)
        if (rad_output_target_same(&e.target, &set->outputs[i].target))
            r = rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                         "%s: is the same file as the output %s (refused: one would overwrite the "
                         "other)", path, set->outputs[i].path);
    /* The placeholder keeps the extension, which tells the writers the
     * format; a stream's lives in the temporary folder. */
    char suffix[18] = "";
    char ext[16];
    rad_path_extension(path, ext, sizeof ext);
    if (ext[0])
        snprintf(suffix, sizeof suffix, ".%s", ext);
    const char *tmpdir = getenv("TMPDIR");
    char *folder = NULL;
    if (r == RAD_OK) {
        folder = e.target.stream
                     ? rad_strdup(ctx, RAD_MEM_OUTPUT, tmpdir && *tmpdir ? tmpdir : "/tmp", "file name")
                     : rad_path_folder(e.target.path);
        e.path = rad_strdup(ctx, RAD_MEM_OUTPUT, path, "file name");
        if (!folder || !e.path ||
            !reserve((void **)&set->outputs, &set->output_capacity, set->output_count,
                     sizeof *set->outputs))
            r = rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    int fd = -1;
    if (r == RAD_OK)
        r = rad_temp_create(ctx, folder, e.target.name, suffix, path, &e.temp, &fd);
    rad_free(folder);
    if (fd >= 0)
        close(fd);
    if (r != RAD_OK) {
        entry_clear(&e);
        return r;
    }
    set->outputs[set->output_count++] = e;
    *temp_path = e.temp;
    return RAD_OK;
}

void rad_output_set_drop(rad_output_set *set, const char *path)
{
    if (!set || !path)
        return;
    for (size_t i = 0; i < set->output_count; i++) {
        output_entry *e = &set->outputs[i];
        if (e->temp && strcmp(e->path, path) == 0) {
            unlink(e->temp);
            rad_free(e->temp);
            e->temp = NULL;
        }
    }
}

/* Link the file a regular output replaces to a new name beside it, so a
 * failed commit can put it back.  Where links are impossible (a file
 * system without them) there is no backup, and no way back for it. */
static void link_backup(output_entry *e)
{
    char *folder = rad_path_folder(e->target.path);
    if (!folder)
        return;
    for (int attempt = 0; attempt < 100 && !e->backup; attempt++) {
        char *name;
        int fd;
        /* A fresh unpredictable name (the placeholder it creates is
         * removed, then the link takes the name; link() fails on any clash). */
        if (rad_temp_create(NULL, folder, e->target.name, ".old", e->path, &name, &fd) != RAD_OK)
            break;
        close(fd);
        unlink(name);
        if (link(e->target.path, name) == 0)
            e->backup = name;
        else {
            rad_free(name);
            if (errno != EEXIST)
                break;
        }
    }
    rad_free(folder);
}

const char *rad_output_set_temp(const rad_output_set *set, const char *path)
{
    for (size_t i = 0; set && path && i < set->output_count; i++)
        if (set->outputs[i].temp && strcmp(set->outputs[i].path, path) == 0)
            return set->outputs[i].temp;
    return NULL;
}

rad_result rad_output_set_commit(rad_context *ctx, rad_output_set *set)
{
    rad_api_enter(ctx);
    if (!ctx || !set)
        return rad_null_argument(ctx, __func__);
    /* Streams first: once written they cannot be taken back, and a
     * failure here (a FIFO's reader gone, /dev/full) leaves every file. */
    for (size_t i = 0; i < set->output_count; i++) {
        output_entry *e = &set->outputs[i];
        if (!e->temp || !e->target.stream)
            continue;
        FILE *from = fopen(e->temp, "rb");
        rad_result r = from ? rad_stream_copy(ctx, &e->target, from, e->path)
                            : rad_fail(ctx, RAD_ERROR_IO, "%s: cannot read its temporary: %s",
                                       e->path, strerror(errno));
        if (from)
            fclose(from);
        if (r != RAD_OK)
            return r;
        unlink(e->temp);
        rad_free(e->temp);
        e->temp = NULL;
    }
    for (size_t i = 0; i < set->output_count; i++)
        if (set->outputs[i].temp && set->outputs[i].target.exists)
            link_backup(&set->outputs[i]);
    size_t renamed = 0;
    rad_result r = RAD_OK;
    for (; renamed < set->output_count; renamed++) {
        output_entry *e = &set->outputs[renamed];
        if (e->temp && rename(e->temp, e->target.path) != 0) {
            r = rad_fail(ctx, RAD_ERROR_IO, "%s: write failed: %s", e->path, strerror(errno));
            break;
        }
    }
    for (size_t i = 0; i < renamed && r != RAD_OK; i++) {
        output_entry *e = &set->outputs[i];
        if (!e->temp)
            continue;
        if (e->backup && rename(e->backup, e->target.path) == 0) {
            rad_free(e->backup);
            e->backup = NULL;
        } else if (!e->target.exists) {
            unlink(e->target.path);
        }
        rad_free(e->temp); /* renamed away: nothing left to remove */
        e->temp = NULL;
    }
    for (size_t i = 0; i < set->output_count && r == RAD_OK; i++) {
        output_entry *e = &set->outputs[i];
        if (e->backup)
            unlink(e->backup);
        rad_free(e->backup);
        rad_free(e->temp);
        e->backup = e->temp = NULL;
    }
    return r; /* after a failure, the set's destroy removes what is left */
}
