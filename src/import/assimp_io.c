/*
 * assimp_io.c -- the read-only file system assimp imports through.  The
 * scene's bytes were read and checked before (import_input.c); assimp
 * gets those very bytes from memory, under a name whose extension makes
 * it pick the reader the content calls for:
 *
 *    aiImportFileEx(alias, io)
 *       open(alias)        -> the input, from memory
 *       open(other), OBJ   -> every material library's text, from memory
 *       open(other), glTF  -> the file on disk, confined and logged (file
 *                             loads); not found (memory loads)
 *
 * Reads, seeks and sizes behave like assimp's own MemoryIOStream.  So a
 * FIFO is read once, a file changed on disk after the pre-scan changes
 * nothing, and an OBJ's libraries are the ones the pre-scan read.
 *
 * The log notes every file a load read, so that a scene can say which
 * files it came from (rad_scene_input_path).  Nothing is read outside the
 * scene file's folder (symbolic links resolved) unless the context allows
 * it: a glTF buffer "../../etc/passwd" is refused, named.
 */
/* realpath is an X/Open (XSI) addition to POSIX. */
#define _XOPEN_SOURCE 700

#include "import/import_internal.h"

#include <errno.h>

#include <assimp/cfileio.h>

#include <stdlib.h>
#include <string.h>

typedef struct memory_file {
    struct aiFile file;
    const char *data;
    size_t size, position;
} memory_file;

static memory_file *memory_file_of(struct aiFile *file)
{
    return (memory_file *)(void *)file->UserData;
}

static size_t memory_read(struct aiFile *file, char *buffer, size_t size, size_t count)
{
    memory_file *m = memory_file_of(file);
    if (size == 0 || m->position >= m->size)
        return 0;
    size_t whole = (m->size - m->position) / size;
    if (count > whole)
        count = whole;
    memcpy(buffer, m->data + m->position, count * size);
    m->position += count * size;
    return count;
}

static size_t memory_write(struct aiFile *file, const char *buffer, size_t size, size_t count)
{
    (void)file;
    (void)buffer;
    (void)size;
    (void)count;
    return 0; /* read-only */
}

static size_t memory_tell(struct aiFile *file) { return memory_file_of(file)->position; }

static size_t memory_size(struct aiFile *file) { return memory_file_of(file)->size; }

/* Offsets wrap like assimp's own MemoryIOStream: aiOrigin_END counts back
 * from the end, and a "negative" aiOrigin_CUR offset arrives as a huge
 * size_t that wraps around. */
static enum aiReturn memory_seek(struct aiFile *file, size_t offset, enum aiOrigin origin)
{
    memory_file *m = memory_file_of(file);
    size_t target = origin == aiOrigin_END   ? m->size - offset
                    : origin == aiOrigin_CUR ? m->position + offset
                                             : offset;
    if ((origin == aiOrigin_END && offset > m->size) || target > m->size)
        return aiReturn_FAILURE;
    m->position = target;
    return aiReturn_SUCCESS;
}

static void memory_flush(struct aiFile *file) { (void)file; }

static struct aiFile *memory_file_open(import_files *files, const char *path, const char *data,
                                       size_t size)
{
    memory_file *m = rad_alloc(files->ctx, RAD_MEM_SCENE, 1, sizeof *m, path);
    if (!m) {
        /* assimp may take it for a missing file: the import fails anyway */
        files->out_of_memory = true;
        return NULL;
    }
    m->data = data;
    m->size = size;
    m->file.ReadProc = memory_read;
    m->file.WriteProc = memory_write;
    m->file.TellProc = memory_tell;
    m->file.FileSizeProc = memory_size;
    m->file.SeekProc = memory_seek;
    m->file.FlushProc = memory_flush;
    m->file.UserData = (aiUserData)(void *)m;
    return &m->file;
}

static struct aiFile *disk_open(rad_input_log *log, const char *path);

static struct aiFile *import_open(struct aiFileIO *io, const char *path, const char *mode)
{
    import_files *files = (import_files *)(void *)io->UserData;
    if (!path || !mode || strpbrk(mode, "wa+"))
        return NULL; /* an import only reads */
    const import_input *in = files->in;
    if (strcmp(path, in->alias) == 0)
        return memory_file_open(files, path, in->data, in->size);
    if (in->format == IMPORT_OBJ)
        return in->materials ? memory_file_open(files, path, in->materials, in->materials_size)
                             : NULL;
    return files->log ? disk_open(files->log, path) : NULL;
}

static void import_close(struct aiFileIO *io, struct aiFile *file)
{
    (void)io;
    if (!file)
        return;
    if (file->ReadProc == memory_read) {
        rad_free(memory_file_of(file));
        return;
    }
    fclose((FILE *)(void *)file->UserData);
    rad_free(file);
}

void import_io(struct aiFileIO *io, import_files *files)
{
    io->OpenProc = import_open;
    io->CloseProc = import_close;
    io->UserData = (aiUserData)(void *)files;
}

static FILE *stdio_of(struct aiFile *file) { return (FILE *)(void *)file->UserData; }

static size_t stdio_read(struct aiFile *file, char *buffer, size_t size, size_t count)
{
    return fread(buffer, size, count, stdio_of(file));
}

static size_t stdio_tell(struct aiFile *file)
{
    long at = ftell(stdio_of(file));
    return at < 0 ? 0 : (size_t)at;
}

static size_t stdio_size(struct aiFile *file)
{
    FILE *f = stdio_of(file);
    long at = ftell(f);
    if (at < 0 || fseek(f, 0, SEEK_END) != 0)
        return 0;
    long end = ftell(f);
    fseek(f, at, SEEK_SET);
    return end < 0 ? 0 : (size_t)end;
}

static enum aiReturn stdio_seek(struct aiFile *file, size_t offset, enum aiOrigin origin)
{
    int whence = origin == aiOrigin_END ? SEEK_END : origin == aiOrigin_CUR ? SEEK_CUR : SEEK_SET;
    /* aiOrigin_CUR and _END offsets are two's-complement in a size_t. */
    return fseek(stdio_of(file), (long)offset, whence) == 0 ? aiReturn_SUCCESS : aiReturn_FAILURE;
}

static void stdio_flush(struct aiFile *file) { fflush(stdio_of(file)); }

/* A file a glTF refers to, from the disk: confined, and logged. */
static struct aiFile *disk_open(rad_input_log *log, const char *path)
{
    if (!rad_input_allowed(log, path))
        return NULL;
    struct aiFile *file = rad_alloc(NULL, RAD_MEM_SCENE, 1, sizeof *file, "input file");
    FILE *f = file ? fopen(path, "rb") : NULL;
    if (!f) {
        rad_free(file);
        return NULL;
    }
    rad_input_log_add(log, path);
    file->ReadProc = stdio_read;
    file->WriteProc = memory_write;
    file->TellProc = stdio_tell;
    file->FileSizeProc = stdio_size;
    file->SeekProc = stdio_seek;
    file->FlushProc = stdio_flush;
    file->UserData = (aiUserData)(void *)f;
    return file;
}
