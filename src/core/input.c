/*
 * input.c -- reading input files: a whole file within the context's memory
 * limit, and the log of the files a load reads, confined to the folder of
 * the file that names them (a scene's textures and buffers, a layout's
 * photometric files, an IES file's TILT file), so that an untrusted input
 * cannot make the engine read elsewhere (docs/robustness.md).
 */
/* realpath is an X/Open (XSI) addition to POSIX. */
#define _XOPEN_SOURCE 700

#include "core/core.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

rad_result rad_read_file(rad_context *ctx, const char *path, const char *what, size_t most, const char *kind,
                         unsigned char **data, size_t *size)
{
    *data = NULL;
    *size = 0;
    if (!what)
        what = path;
    FILE *f = fopen(path, "rb");
    if (!f)
        return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot open: %s", what, strerror(errno));
    struct stat st;
    bool regular = fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode);
    if (!regular && S_ISDIR(st.st_mode)) {
        fclose(f);
        return kind ? rad_fail(ctx, RAD_ERROR_IO, "%s: is a folder, not a %s", what, kind)
                    : rad_fail(ctx, RAD_ERROR_IO, "%s: cannot read: Is a directory", what);
    }
    /* A regular file by its size (+ 1: the read that finds the end needs
     * no growth), a stream from 64 KiB doubling; never more than one byte
     * past `most`, that byte being the refusal. */
    size_t capacity = regular ? (size_t)st.st_size + 1 : 65536;
    if (most && capacity > most + 1)
        capacity = most + 1;
    const char *label = kind ? what : "input file"; /* for the memory accounting */
    unsigned char *buffer = rad_alloc(ctx, RAD_MEM_SCENE, capacity, 1, label);
    size_t used = 0;
    rad_result r = buffer ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
    while (r == RAD_OK) {
        used += fread(buffer + used, 1, capacity - used, f);
        if (used < capacity) {
            if (ferror(f))
                r = rad_fail(ctx, rad_cancelled(ctx) ? RAD_ERROR_INTERRUPTED : RAD_ERROR_IO, "%s: cannot read: %s",
                             what, strerror(errno));
            break;
        }
        if (most && used > most) {
            r = most % (1u << 20) == 0
                    ? rad_fail(ctx, RAD_ERROR_PARSE, "%s: more than %zu MiB: not a %s", what, most >> 20,
                               kind ? kind : "file this reads")
                    : rad_fail(ctx, RAD_ERROR_PARSE, "%s: more than %zu bytes: not a %s", what, most,
                               kind ? kind : "file this reads");
            break;
        }
        if (rad_cancelled(ctx)) {
            r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "%s: interrupted while reading", what);
            break;
        }
        size_t grown = most && 2 * capacity > most + 1 ? most + 1 : 2 * capacity;
        unsigned char *bigger = rad_realloc(ctx, RAD_MEM_SCENE, buffer, grown, 1, label);
        if (!bigger)
            r = RAD_ERROR_OUT_OF_MEMORY;
        else {
            buffer = bigger;
            capacity = grown;
        }
    }
    fclose(f);
    if (r != RAD_OK) {
        rad_free(buffer);
        return r;
    }
    *data = buffer;
    *size = used;
    return RAD_OK;
}

rad_result rad_read_whole_file(rad_context *ctx, const char *path, unsigned char **data, size_t *size)
{
    return rad_read_file(ctx, path, NULL, 0, NULL, data, size);
}

/* ---- the log of files read, and their confinement ---- */

void rad_input_log_add(rad_input_log *log, const char *path)
{
    for (size_t i = 0; i < log->count; i++)
        if (strcmp(log->paths[i], path) == 0)
            return;
    if (log->count == log->capacity) {
        size_t grown = log->capacity ? 2 * log->capacity : 4;
        char **paths = rad_realloc(NULL, RAD_MEM_SCENE, log->paths, grown, sizeof *paths, "input file names");
        if (!paths) {
            log->failed = true;
            return;
        }
        log->paths = paths;
        log->capacity = grown;
    }
    char *copy = rad_strdup(NULL, RAD_MEM_SCENE, path, "input file name");
    if (!copy) {
        log->failed = true;
        return;
    }
    log->paths[log->count++] = copy;
}

void rad_input_log_free(rad_input_log *log)
{
    for (size_t i = 0; i < log->count; i++)
        rad_free(log->paths[i]);
    rad_free(log->paths);
    rad_free(log->root);
    memset(log, 0, sizeof *log);
}

rad_result rad_input_log_confine(rad_context *ctx, rad_input_log *log, const char *scene_path)
{
    log->ctx = ctx;
    log->scene = scene_path;
    if (ctx && ctx->read_outside_scene_folder)
        return RAD_OK;
    const char *slash = strrchr(scene_path, '/');
    char *folder = slash ? rad_strdup(ctx, RAD_MEM_SCENE, scene_path, scene_path)
                         : rad_strdup(ctx, RAD_MEM_SCENE, ".", scene_path);
    if (!folder)
        return RAD_ERROR_OUT_OF_MEMORY;
    if (slash)
        folder[slash == scene_path ? 1 : slash - scene_path] = '\0';
    char *resolved = realpath(folder, NULL);
    rad_free(folder);
    /* Unresolvable: an empty root, under which nothing lies. */
    log->root = rad_strdup(ctx, RAD_MEM_SCENE, resolved ? resolved : "", scene_path);
    free(resolved); /* realpath's copy is libc's */
    return log->root ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
}

bool rad_input_allowed(rad_input_log *log, const char *path)
{
    if (!log->root)
        return true;
    char *resolved = realpath(path, NULL);
    if (!resolved)
        return true; /* not there: the open fails and says so */
    size_t n = strlen(log->root);
    bool inside = n > 0 && strncmp(resolved, log->root, n) == 0 &&
                  (resolved[n] == '/' || (n == 1 && log->root[0] == '/'));
    if (!inside && !log->refused) {
        log->refused = true;
        rad_fail(log->ctx, RAD_ERROR_IO,
                 "%s: refers to '%s' (%s), outside the scene's folder %s: refused "
                 "(rad_context_options.read_outside_scene_folder allows it)",
                 log->scene, path, resolved, log->root[0] ? log->root : "(unresolvable)");
    }
    free(resolved);
    return inside;
}
