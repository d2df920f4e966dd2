/*
 * import_input.c -- a scene's bytes, read once and within the memory limit,
 * its format told by its content, and an OBJ's material libraries.
 *
 *    scene file --read (at most limit / 20 bytes)--> bytes --content--> OBJ | glTF | GLB
 *    OBJ: pre-scan; every `mtllib` name read and pre-scanned, in order,
 *         each file once --> the libraries' text, one after the other
 *    OBJ: positions read exactly, `v` lines rewritten as vertex indices
 *         (obj_prescan.c, import_obj_exact_positions)
 *    --> import_input: what assimp is served from memory (assimp_io.c)
 *
 * The format.  assimp 5.2 picks its reader by the file's extension when
 * one reader claims it, and by content otherwise, so the reader chosen
 * for the pre-scan by extension missed an OBJ named `scene`, `s.txt` or
 * `s.gltf`.  Here the content decides, as assimp's own detection would
 * for these three: the binary glTF magic "glTF", else JSON (an object,
 * '{' first), else OBJ, since no other format's text is read, and the
 * OBJ pre-scan names the first statement that is not OBJ.  assimp then
 * gets the bytes under the scene's name with that format's extension
 * added where it differs ("scene" -> "scene.obj"), so it picks the
 * same reader.  A GLB named `.obj` is read as the GLB it is: the content
 * is unambiguous, and a refusal would only make the user rename it.
 *
 * Memory.  assimp's import is not counted by the allocator; it takes up
 * to IMPORT_ASSIMP_PEAK_PER_BYTE = 20 bytes per byte of scene text
 * (measured with assimp 5.2, peak resident set less the engine's own
 * blocks: about 4x for generated offices and grids of quads, 30-40 MB
 * files; 18x for a file of nothing but the shortest face lines, "f 1 2 3",
 * 8 bytes a face, each becoming a face, its indices and a copy of its
 * corners).  So no more than limit / 20 bytes are read, the file and its
 * libraries together: a regular file larger than that is refused by its
 * size, unread, and a stream (a FIFO, /dev/zero) when it has given that
 * much.  An OBJ's exact positions (24 bytes a vertex) and the text
 * assimp reads in its place (each `v` line at most 22 bytes) are the
 * allocator's, and the file's own text is freed once they are made.
 *
 * The libraries.  `mtllib a.mtl b.mtl` names two (the OBJ format separates
 * names by blanks; assimp 5.2 would open "a.mtl b.mtl"); a line whose whole
 * text names an existing file is that one file ("mtllib my room.mtl", as
 * exporters write names with spaces).  Every library is read and checked,
 * a file named twice once; their materials must not repeat a name, and
 * every `usemtl` must name one.  assimp opens only the first `mtllib` it
 * sees, and is served all the libraries' text there: the OBJ it reads has
 * its later `mtllib` statements made comments.
 */
#include "import/import_internal.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>

import_format import_format_of(const char *data, size_t size)
{
    if (size >= 4 && memcmp(data, "glTF", 4) == 0)
        return IMPORT_GLB;
    size_t i = size >= 3 && memcmp(data, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;
    while (i < size && strchr(" \t\r\n", data[i]) && data[i] != '\0')
        i++; /* JSON's whitespace (RFC 8259) */
    return i < size && data[i] == '{' ? IMPORT_GLTF : IMPORT_OBJ;
}

/* Past a UTF-8 byte order mark at the start of OBJ or MTL text: assimp
 * 5.2 takes it for part of the first word, and drops that statement (an
 * OBJ's first vertex: every face then names the wrong ones). */
static void skip_byte_order_mark(const char **text, size_t *size)
{
    if (*size >= 3 && memcmp(*text, "\xEF\xBB\xBF", 3) == 0) {
        *text += 3;
        *size -= 3;
    }
}

const char *import_format_extension(import_format format)
{
    return format == IMPORT_GLB ? "glb" : format == IMPORT_GLTF ? "gltf" : "obj";
}

/* `name` as assimp must see it to pick the reader of `format`: with the
 * format's extension, added when it has another one or none. */
static char *alias_of(rad_context *ctx, const char *name, import_format format)
{
    const char *wanted = import_format_extension(format);
    char extension[16];
    rad_path_extension(name, extension, sizeof extension);
    bool keep = strcmp(extension, wanted) == 0;
    size_t size = strlen(name) + strlen(wanted) + 2;
    char *alias = rad_alloc(ctx, RAD_MEM_SCENE, size, 1, name);
    if (alias)
        snprintf(alias, size, keep ? "%s" : "%s.%s", name, wanted);
    return alias;
}

void import_input_free(import_input *in)
{
    rad_free(in->alias);
    rad_free(in->owned[0]);
    rad_free(in->owned[1]);
    import_obj_positions_free(&in->positions);
    import_material_names_free(&in->materials_exact);
    import_notes_free(&in->notes);
    memset(in, 0, sizeof *in);
}

/* ---- within the memory limit ---- */

/* The most bytes of scene text (a file and its libraries together) whose
 * import stays within the limit. */
static double text_budget(const rad_context *ctx)
{
    return rad_memory_limit(ctx) / IMPORT_ASSIMP_PEAK_PER_BYTE;
}

/* Refuse `what`: with it the scene's text comes to `bytes` (at least that
 * many when `more`), which may need 20x to import, above the memory limit.
 * `alone`: `what` is all of it. */
static rad_result refuse_size(rad_context *ctx, const char *what, double bytes, bool alone,
                              bool more)
{
    double limit = rad_memory_limit(ctx);
    char size_text[32], need[32], limit_text[32];
    rad_format_bytes(bytes, size_text, sizeof size_text);
    rad_format_bytes(IMPORT_ASSIMP_PEAK_PER_BYTE * bytes, need, sizeof need);
    rad_format_bytes(limit, limit_text, sizeof limit_text);
    const char *at_least = more ? "more than " : "";
    return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                    "%s: %s%s%s%s may need %s%s to import (%.0fx %s size), above the memory "
                    "limit of %s (rad_context_options.max_memory_bytes)",
                    what, alone ? "a file of " : "with it the scene's files come to ", at_least,
                    size_text, alone ? "" : ", which", at_least, need, IMPORT_ASSIMP_PEAK_PER_BYTE,
                    alone ? "its" : "their", limit_text);
}

/* Bytes read at a time: 1 MiB. */
enum { READ_PIECE = 1 << 20 };

/* 1 + the newlines in [text, at): the line of `at`. */
static size_t line_of(const char *text, const char *at)
{
    size_t line = 1;
    for (const char *c = text; (c = memchr(c, '\n', (size_t)(at - c))) != NULL; c++)
        line++;
    return line;
}

/* Read the file at `path` whole into a block of the context (rad_free it).
 * `already` bytes of the scene's text were read before it; with them it
 * may come to text_budget() bytes, else RAD_ERROR_OUT_OF_MEMORY naming
 * `what` (a regular file by its size, unread; a stream when it has given
 * that much).  Unless it starts as binary glTF does, it is text, and a NUL
 * byte stops the reading ("PATH:LINE: NUL byte in the text"): a sparse
 * file of zeros fails at once.  RAD_ERROR_IO naming `what` when it cannot
 * be opened or read; RAD_ERROR_INTERRUPTED when the context is cancelled
 * while it waits (a FIFO without a writer). */
static rad_result read_whole(rad_context *ctx, const char *path, const char *what, double already,
                             char **data, size_t *size)
{
    *data = NULL;
    *size = 0;
    double most = text_budget(ctx) - already;
    most = most > 0.0 ? most : 0.0;
    FILE *file = fopen(path, "rb");
    if (!file)
        return errno == EINTR && rad_cancelled(ctx)
                   ? rad_fail(ctx, RAD_ERROR_INTERRUPTED, "%s: interrupted while opening", what)
                   : rad_fail(ctx, RAD_ERROR_IO, "%s: cannot open: %s", what, strerror(errno));
    size_t capacity = 1 << 16;
    struct stat st;
    if (fstat(fileno(file), &st) == 0 && S_ISREG(st.st_mode)) {
        if ((double)st.st_size > most) {
            fclose(file);
            return refuse_size(ctx, what, already + (double)st.st_size, already == 0.0, false);
        }
        capacity = (size_t)st.st_size + 1; /* + 1: the read that finds the end needs no growth */
    }
    if ((double)capacity > most + 1.0)
        capacity = (size_t)most + 1;
    char *buffer = rad_alloc(ctx, RAD_MEM_SCENE, capacity, 1, what);
    size_t length = 0, checked = 0;
    bool decided = false, text = true; /* text: all but binary glTF */
    rad_result r = buffer ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
    while (r == RAD_OK) {
        /* In pieces, so that a NUL byte or a cancellation stops a large
         * file early, and untouched pages of a large block stay unmapped. */
        size_t wanted = capacity - length < READ_PIECE ? capacity - length : READ_PIECE;
        size_t got = fread(buffer + length, 1, wanted, file);
        length += got;
        bool short_read = got < wanted;
        if (!decided && (length >= 4 || (short_read && !ferror(file)))) {
            decided = true;
            text = !(length >= 4 && memcmp(buffer, "glTF", 4) == 0);
        }
        const char *nul = decided && text ? memchr(buffer + checked, '\0', length - checked) : NULL;
        checked = decided ? length : 0;
        if (nul) {
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%zu: NUL byte in the text", path,
                         line_of(buffer, nul));
        } else if (short_read) { /* the end, or an error */
            if (!ferror(file))
                break;
            if (errno != EINTR)
                r = rad_fail(ctx, RAD_ERROR_IO, "%s: cannot read: %s", what, strerror(errno));
            else if (rad_cancelled(ctx))
                r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "%s: interrupted while reading", what);
            clearerr(file); /* a signal that did not cancel: read on */
        } else if (length < capacity) {
            if (rad_cancelled(ctx))
                r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "%s: interrupted while reading", what);
        } else if ((double)length > most) {
            r = refuse_size(ctx, what, already + most, already == 0.0, true);
        } else if (rad_cancelled(ctx)) {
            r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "%s: interrupted while reading", what);
        } else {
            /* Doubling, up to one byte past the budget: that byte is the refusal. */
            size_t grown = (double)capacity * 2.0 > most + 1.0 ? (size_t)most + 1 : 2 * capacity;
            char *bigger = rad_realloc(ctx, RAD_MEM_SCENE, buffer, grown, 1, what);
            if (!bigger)
                r = RAD_ERROR_OUT_OF_MEMORY;
            buffer = bigger ? bigger : buffer;
            capacity = bigger ? grown : capacity;
        }
    }
    fclose(file);
    if (r != RAD_OK) {
        rad_free(buffer);
        return r;
    }
    *data = buffer;
    *size = length;
    return RAD_OK;
}

/* ---- an OBJ's material libraries ---- */

/* The libraries' text, one after the other. */
typedef struct library_text {
    char *text;
    size_t size, capacity;
} library_text;

/* Append `size` bytes and, unless they end one, a newline. */
static rad_result append_library(rad_context *ctx, library_text *all, const char *text,
                                 size_t size, const char *what)
{
    size_t needed = all->size + size + 1;
    if (needed > all->capacity) {
        size_t grown = needed > 2 * all->capacity ? needed : 2 * all->capacity;
        char *bigger = rad_realloc(ctx, RAD_MEM_SCENE, all->text, grown, 1, what);
        if (!bigger)
            return RAD_ERROR_OUT_OF_MEMORY;
        all->text = bigger;
        all->capacity = grown;
    }
    memcpy(all->text + all->size, text, size);
    all->size += size;
    if (size > 0 && text[size - 1] != '\n')
        all->text[all->size++] = '\n';
    return RAD_OK;
}

/* A library file already read, by identity: "a.mtl", "./a.mtl" and a
 * link to it are one file. */
typedef struct library_seen {
    uint64_t device, inode;
} library_seen;

typedef struct libraries {
    rad_context *ctx;
    const char *obj_path;
    size_t folder;          /* bytes of obj_path up to its last '/', included */
    rad_input_log *log;
    double read;            /* bytes of the scene's text read so far */
    library_text all;
    import_material_names names;
    import_notes *notes;    /* what the libraries say that is not used */
    library_seen *seen;
    size_t seen_count, seen_capacity;
} libraries;

/* The library `name` joined to the OBJ's folder (unless absolute), in a
 * block of the context. */
static char *library_path(libraries *l, const char *name, size_t name_length)
{
    size_t folder = name[0] == '/' ? 0 : l->folder;
    char *path = rad_alloc(l->ctx, RAD_MEM_SCENE, folder + name_length + 1, 1, l->obj_path);
    if (path) {
        memcpy(path, l->obj_path, folder);
        memcpy(path + folder, name, name_length);
    }
    return path;
}

/* Read and pre-scan library `name` (named at `line` of the OBJ), once. */
static rad_result read_library(libraries *l, const char *name, size_t name_length, int line)
{
    char *path = library_path(l, name, name_length);
    if (!path)
        return RAD_ERROR_OUT_OF_MEMORY;
    char what[512];
    snprintf(what, sizeof what, "%s:%d: material library '%.*s'", l->obj_path, line,
             (int)(name_length < 256 ? name_length : 256), name);
    uint64_t device, inode;
    if (rad_file_identity(path, &device, &inode)) {
        for (size_t i = 0; i < l->seen_count; i++)
            if (l->seen[i].device == device && l->seen[i].inode == inode) {
                rad_free(path);
                return RAD_OK;
            }
        if (l->seen_count == l->seen_capacity) {
            size_t grown = l->seen_capacity ? 2 * l->seen_capacity : 4;
            library_seen *seen =
                rad_realloc(l->ctx, RAD_MEM_SCENE, l->seen, grown, sizeof *seen, what);
            if (!seen) {
                rad_free(path);
                return RAD_ERROR_OUT_OF_MEMORY;
            }
            l->seen = seen;
            l->seen_capacity = grown;
        }
        l->seen[l->seen_count++] = (library_seen){device, inode};
    }
    if (!rad_input_allowed(l->log, path)) {
        rad_free(path);
        return RAD_ERROR_IO;
    }
    char *text = NULL;
    size_t size = 0;
    rad_result r = read_whole(l->ctx, path, what, l->read, &text, &size);
    const char *start = text;
    if (r == RAD_OK) {
        rad_input_log_add(l->log, path);
        l->read += (double)size;
        skip_byte_order_mark(&start, &size);
        l->names.textures_read = true; /* a file load: its textures are read */
        r = import_mtl_prescan(l->ctx, path, start, size, &l->names, l->notes);
    }
    if (r == RAD_OK)
        r = append_library(l->ctx, &l->all, start, size, what);
    rad_free(text);
    rad_free(path);
    return r;
}

static bool is_blank(char c) { return c == ' ' || c == '\t'; }

/* Every library of every `mtllib` statement, in order. */
static rad_result read_libraries(libraries *l, const import_obj_scan *scan)
{
    for (size_t s = 0; s < scan->mtllib_count; s++) {
        const import_obj_mtllib *m = &scan->mtllibs[s];
        /* The whole line names an existing file: that one (it has blanks). */
        if (strpbrk(m->names, " \t")) {
            char *whole = library_path(l, m->names, strlen(m->names));
            struct stat st;
            bool exists = whole && stat(whole, &st) == 0;
            rad_free(whole);
            if (!whole)
                return RAD_ERROR_OUT_OF_MEMORY;
            if (exists) {
                rad_result r = read_library(l, m->names, strlen(m->names), m->line);
                if (r != RAD_OK)
                    return r;
                continue;
            }
        }
        for (const char *name = m->names; *name;) {
            size_t length = 0;
            while (name[length] && !is_blank(name[length]))
                length++;
            rad_result r = read_library(l, name, length, m->line);
            if (r != RAD_OK)
                return r;
            name += length;
            while (is_blank(*name))
                name++;
        }
    }
    return RAD_OK;
}

/* Make every `mtllib` statement after the first a comment: assimp opens the
 * first, and is served all the libraries there. */
static void comment_later_mtllibs(char *text, const import_obj_scan *scan)
{
    for (size_t s = 1; s < scan->mtllib_count; s++)
        text[scan->mtllibs[s].offset] = '#';
}

/* Check the materials an OBJ's libraries define and the OBJ uses. */
static rad_result check_materials(rad_context *ctx, const char *path, const char *text,
                                  size_t size, import_material_names *names)
{
    rad_result r = import_material_names_check(ctx, names);
    return r == RAD_OK ? import_obj_check_usemtl(ctx, path, text, size, names) : r;
}

/* The OBJ's exact positions and the text assimp reads instead of `in`'s
 * (obj_prescan.c); the text read is freed, it is not needed again. */
static rad_result exact_positions(rad_context *ctx, const char *name, import_input *in)
{
    rad_result r = import_obj_exact_positions(ctx, name, in->data, in->size, &in->positions);
    if (r != RAD_OK)
        return r;
    rad_free(in->owned[0]);
    in->owned[0] = NULL;
    in->data = in->positions.text;
    in->size = in->positions.size;
    return RAD_OK;
}

/* ---- the two ways in ---- */

rad_result import_input_read_file(rad_context *ctx, const char *path, rad_input_log *log,
                                  import_input *in)
{
    memset(in, 0, sizeof *in);
    char *data = NULL;
    size_t size = 0;
    rad_result r = read_whole(ctx, path, path, 0.0, &data, &size);
    if (r != RAD_OK)
        return r;
    in->owned[0] = data;
    in->data = data;
    in->size = size;
    in->format = import_format_of(data, size);
    in->alias = alias_of(ctx, path, in->format);
    if (!in->alias) {
        import_input_free(in);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    if (in->format != IMPORT_OBJ)
        return RAD_OK;

    skip_byte_order_mark(&in->data, &in->size);
    char *text = data + (in->data - data); /* ours to change */
    size = in->size;
    import_obj_scan scan;
    r = import_obj_prescan(ctx, path, text, size, &scan);
    if (r != RAD_OK) {
        import_input_free(in);
        return r;
    }
    const char *slash = strrchr(path, '/');
    libraries l = {.ctx = ctx,
                   .obj_path = path,
                   .folder = slash ? (size_t)(slash - path) + 1 : 0,
                   .log = log,
                   .read = (double)size,
                   .notes = &in->notes};
    r = read_libraries(&l, &scan);
    if (r == RAD_OK && scan.mtllib_count > 0)
        r = check_materials(ctx, path, text, size, &l.names);
    if (r == RAD_OK && l.all.text) {
        comment_later_mtllibs(text, &scan);
        in->owned[1] = l.all.text;
        in->materials = l.all.text;
        in->materials_size = l.all.size;
        l.all.text = NULL;
    }
    rad_free(l.all.text);
    rad_free(l.seen);
    in->materials_exact = l.names;
    import_obj_scan_free(&scan);
    if (r == RAD_OK)
        r = exact_positions(ctx, path, in);
    if (r != RAD_OK)
        import_input_free(in);
    return r;
}

rad_result import_input_from_memory(rad_context *ctx, const char *name, const char *data,
                                    size_t size, const char *mtl, size_t mtl_size,
                                    import_input *in)
{
    memset(in, 0, sizeof *in);
    double total = (double)size + (double)mtl_size;
    if (total > text_budget(ctx))
        return refuse_size(ctx, name, total, true, false);
    in->data = data;
    in->size = size;
    in->format = import_format_of(data, size);
    in->alias = alias_of(ctx, name, in->format);
    if (!in->alias)
        return RAD_ERROR_OUT_OF_MEMORY;
    if (in->format != IMPORT_OBJ)
        return RAD_OK;

    skip_byte_order_mark(&data, &size);
    skip_byte_order_mark(&mtl, &mtl_size);
    in->data = data;
    in->size = size;
    import_obj_scan scan;
    rad_result r = import_obj_prescan(ctx, name, data, size, &scan);
    import_material_names names = {0};
    if (r == RAD_OK && mtl) {
        /* Messages name the library as the OBJ's first `mtllib` does, else
         * as NAME.mtl (NAME without its extension). */
        char mtl_name[256];
        if (scan.mtllib_count > 0) {
            const char *first = scan.mtllibs[0].names;
            snprintf(mtl_name, sizeof mtl_name, "%.*s", (int)strcspn(first, " \t"), first);
        } else {
            const char *dot = strrchr(name, '.'), *slash = strrchr(name, '/');
            int stem = dot && (!slash || dot > slash) ? (int)(dot - name) : (int)strlen(name);
            snprintf(mtl_name, sizeof mtl_name, "%.*s.mtl", stem, name);
        }
        r = import_mtl_prescan(ctx, mtl_name, mtl, mtl_size, &names, &in->notes);
        if (r == RAD_OK)
            r = check_materials(ctx, name, data, size, &names);
        in->materials = mtl;
        in->materials_size = mtl_size;
    }
    if (r == RAD_OK && scan.mtllib_count > 1) {
        /* The caller's text is not ours to change: a copy. */
        char *copy = rad_alloc(ctx, RAD_MEM_SCENE, size, 1, name);
        if (copy) {
            memcpy(copy, data, size);
            comment_later_mtllibs(copy, &scan);
            in->owned[0] = copy;
            in->data = copy;
        } else {
            r = RAD_ERROR_OUT_OF_MEMORY;
        }
    }
    in->materials_exact = names;
    import_obj_scan_free(&scan);
    if (r == RAD_OK)
        r = exact_positions(ctx, name, in);
    if (r != RAD_OK)
        import_input_free(in);
    return r;
}
