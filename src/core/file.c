/*
 * file.c -- writing output files safely: where a path really leads, which
 * file it is (its identity), temporaries created so that nothing planted in
 * the folder can redirect them, and atomic replacement.
 *
 * A temporary is created with O_CREAT | O_EXCL under an unpredictable name
 * (".out.png.k3x9qz"): a symbolic link or file planted at that name makes
 * the creation fail (and another name is tried); it never redirects the
 * write.  The name is short (the target's name is cut to 40 bytes), so a
 * target whose own name is as long as the file system allows still gets
 * one.  Only regular files are renamed over; a device, a FIFO or the
 * program's own stdout/stderr is written in place (docs/robustness.md).
 */
/* realpath and S_ISVTX are X/Open (XSI) additions to POSIX. */
#define _XOPEN_SOURCE 700

#include "core/core.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Bytes of the target's name kept in a temporary's name: with the dot, a
 * dot, six random letters and a suffix of up to 16 bytes, well below any
 * file system's NAME_MAX (255 on Linux). */
enum { TEMP_PREFIX_BYTES = 40, TEMP_RANDOM = 6, TEMP_ATTEMPTS = 1000 };

char *rad_path_folder(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        return rad_strdup(NULL, RAD_MEM_OUTPUT, ".", "file name");
    if (slash == path)
        return rad_strdup(NULL, RAD_MEM_OUTPUT, "/", "file name");
    size_t n = (size_t)(slash - path);
    char *folder = rad_alloc(NULL, RAD_MEM_OUTPUT, n + 1, 1, "file name");
    if (folder) {
        memcpy(folder, path, n);
        folder[n] = '\0';
    }
    return folder;
}

static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

bool rad_file_identity(const char *path, uint64_t *device, uint64_t *inode)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return false;
    *device = (uint64_t)st.st_dev;
    *inode = (uint64_t)st.st_ino;
    return true;
}

/* The program's stdout (1) or stderr (2) when `st` is the same file as it,
 * else -1: such an output is written through that descriptor, after what
 * the program printed, instead of replacing or truncating the file. */
static int standard_stream_of(const struct stat *st)
{
    for (int fd = 1; fd <= 2; fd++) {
        struct stat s;
        if (fstat(fd, &s) == 0 && s.st_dev == st->st_dev && s.st_ino == st->st_ino)
            return fd;
    }
    return -1;
}

/* The kernel's fs.protected_symlinks rule, for the links we follow
 * ourselves (realpath): a link in a sticky, world-writable folder (/tmp)
 * is followed only when it belongs to us or to the folder's owner, so a
 * link planted there by another user cannot aim our output at our files. */
static bool link_is_trusted(const char *path, const struct stat *link)
{
    char *folder = rad_path_folder(path);
    struct stat dir;
    bool ok = folder && stat(folder, &dir) == 0;
    rad_free(folder);
    if (!ok)
        return false;
    if (!(dir.st_mode & S_ISVTX) || !(dir.st_mode & S_IWOTH))
        return true;
    return link->st_uid == geteuid() || link->st_uid == dir.st_uid;
}

rad_result rad_output_target_resolve(rad_context *ctx, const char *path, rad_output_target *out)
{
    memset(out, 0, sizeof *out);
    out->stream_fd = -1;
    if (!*path)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "the output path is empty");
    struct stat st;
    char *resolved = NULL;
    if (lstat(path, &st) == 0) {
        if (S_ISLNK(st.st_mode)) {
            struct stat link = st;
            if (stat(path, &st) != 0)
                return rad_fail(ctx, RAD_ERROR_IO,
                                "%s: is a dangling symbolic link (refused: writing would create a "
                                "file where it points)", path);
            if (!link_is_trusted(path, &link))
                return rad_fail(ctx, RAD_ERROR_IO,
                                "%s: is a symbolic link owned by another user in a shared folder "
                                "(refused)", path);
            if (S_ISREG(st.st_mode) && !(resolved = realpath(path, NULL)))
                return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot resolve the link: %s", path,
                                strerror(errno));
        }
        if (S_ISDIR(st.st_mode)) {
            free(resolved);
            return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write: is a directory", path);
        }
        out->stream_fd = standard_stream_of(&st);
        if (out->stream_fd < 0 && !S_ISREG(st.st_mode) && !S_ISCHR(st.st_mode) &&
            !S_ISFIFO(st.st_mode)) {
            free(resolved);
            return rad_fail(ctx, RAD_ERROR_IO,
                            "%s: cannot write: not a regular file, character device or FIFO", path);
        }
        out->stream = out->stream_fd >= 0 || !S_ISREG(st.st_mode);
        if (out->stream && out->stream_fd < 0 && access(path, W_OK) != 0) {
            free(resolved);
            return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write: %s", path, strerror(errno));
        }
        out->exists = true;
        out->device = (uint64_t)st.st_dev;
        out->inode = (uint64_t)st.st_ino;
    } else if (errno != ENOENT) {
        return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write: %s", path, strerror(errno));
    }
    /* realpath's copy is libc's; the target keeps an allocator copy. */
    out->path = rad_strdup(ctx, RAD_MEM_OUTPUT, resolved ? resolved : path, "output file name");
    free(resolved);
    char *folder = out->path ? rad_path_folder(out->path) : NULL;
    if (!folder) {
        rad_output_target_free(out);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    out->name = base_name(out->path);
    rad_result r = RAD_OK;
    if (!out->stream) {
        /* The temporary and the rename both need a writable folder. */
        struct stat dir;
        if (stat(folder, &dir) != 0)
            r = rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write: %s", path, strerror(errno));
        else if (!S_ISDIR(dir.st_mode))
            r = rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write: %s is not a directory", path, folder);
        else if (access(folder, W_OK | X_OK) != 0)
            r = rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write into %s: %s", path, folder,
                         strerror(errno));
        else if (!*out->name)
            r = rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write: is a directory", path);
        else if (!out->exists) {
            out->device = (uint64_t)dir.st_dev;
            out->inode = (uint64_t)dir.st_ino;
        }
    }
    rad_free(folder);
    if (r != RAD_OK)
        rad_output_target_free(out);
    return r;
}

void rad_output_target_free(rad_output_target *target)
{
    rad_free(target->path);
    memset(target, 0, sizeof *target);
    target->stream_fd = -1;
}

bool rad_output_target_same(const rad_output_target *a, const rad_output_target *b)
{
    if (a->exists != b->exists || a->device != b->device || a->inode != b->inode)
        return false;
    if (!a->exists)
        return strcmp(a->name, b->name) == 0;
    struct stat st;
    return !(stat(a->path, &st) == 0 && S_ISCHR(st.st_mode));
}

rad_result rad_temp_create(rad_context *ctx, const char *folder, const char *name, const char *suffix,
                           const char *what, char **path, int *fd)
{
    *path = NULL;
    *fd = -1;
    size_t prefix = strlen(name);
    if (prefix > TEMP_PREFIX_BYTES) {
        prefix = TEMP_PREFIX_BYTES;
        while (prefix > 0 && ((unsigned char)name[prefix] & 0xC0) == 0x80)
            prefix--; /* not in the middle of a UTF-8 character */
    }
    size_t size = strlen(folder) + prefix + strlen(suffix) + TEMP_RANDOM + 4;
    char *temp = rad_alloc(ctx, RAD_MEM_OUTPUT, size, 1, "file name");
    if (!temp)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", what);
    /* The key mixes the clock, the process and the buffer's address; a
     * clash (or a planted name) costs one more attempt. */
    static const char letters[] = "abcdefghijklmnopqrstuvwxyz0123456789";
    uint64_t key = rad_mix64((uint64_t)(rad_seconds() * 1e9) ^ ((uint64_t)getpid() << 32) ^
                             (uint64_t)(uintptr_t)temp);
    int err = EEXIST;
    for (int attempt = 0; attempt < TEMP_ATTEMPTS && err == EEXIST; attempt++) {
        char random[TEMP_RANDOM + 1];
        uint64_t bits = rad_mix64(key + (uint64_t)attempt);
        for (int k = 0; k < TEMP_RANDOM; k++, bits /= 36)
            random[k] = letters[bits % 36];
        random[TEMP_RANDOM] = '\0';
        snprintf(temp, size, "%s/.%.*s.%s%s", folder, (int)prefix, name, random, suffix);
        *fd = open(temp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0666);
        err = *fd < 0 ? errno : 0;
    }
    if (*fd < 0) {
        rad_free(temp);
        return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot create a temporary file: %s", what,
                        strerror(err));
    }
    *path = temp;
    return RAD_OK;
}

rad_result rad_stream_copy(rad_context *ctx, const rad_output_target *target, FILE *from,
                           const char *what)
{
    int fd = target->stream_fd >= 0 ? dup(target->stream_fd)
                                    : open(target->path, O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (fd < 0)
        return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write: %s", what, strerror(errno));
    rewind(from);
    char buffer[65536];
    size_t n;
    int err = 0;
    while (!err && (n = fread(buffer, 1, sizeof buffer, from)) > 0) {
        for (size_t done = 0; done < n;) {
            ssize_t w = write(fd, buffer + done, n - done);
            if (w < 0 && errno == EINTR)
                continue;
            if (w <= 0) {
                err = w < 0 ? errno : EIO;
                break;
            }
            done += (size_t)w;
        }
    }
    if (!err && ferror(from))
        err = EIO;
    if (close(fd) != 0 && !err && errno != EINTR)
        err = errno;
    return err ? rad_fail(ctx, RAD_ERROR_IO, "%s: write failed: %s", what, strerror(err)) : RAD_OK;
}

rad_result rad_atomic_open(rad_context *ctx, const char *path, rad_atomic_file *out)
{
    memset(out, 0, sizeof *out);
    rad_result r = rad_output_target_resolve(ctx, path, &out->target);
    if (r != RAD_OK)
        return r;
    out->final_path = rad_strdup(ctx, RAD_MEM_OUTPUT, path, "file name");
    if (!out->final_path) {
        rad_atomic_abort(out);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    if (out->target.stream) {
        /* Written in place at commit, only once complete. */
        out->file = tmpfile();
        if (!out->file) {
            int err = errno;
            rad_atomic_abort(out);
            return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot create a temporary file: %s", path,
                            strerror(err));
        }
        return RAD_OK;
    }
    char *folder = rad_path_folder(out->target.path);
    int fd = -1;
    r = folder ? rad_temp_create(ctx, folder, out->target.name, "", path, &out->temp_path, &fd)
               : rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    rad_free(folder);
    if (r == RAD_OK && !(out->file = fdopen(fd, "wb"))) {
        close(fd);
        r = rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write: %s", path, strerror(errno));
    }
    if (r != RAD_OK)
        rad_atomic_abort(out);
    return r;
}

rad_result rad_atomic_commit(rad_context *ctx, rad_atomic_file *f)
{
    rad_result r = RAD_OK;
    if (fflush(f->file) != 0 || ferror(f->file))
        r = rad_fail(ctx, RAD_ERROR_IO, "%s: write failed: %s", f->final_path, strerror(errno));
    if (r == RAD_OK && f->target.stream)
        r = rad_stream_copy(ctx, &f->target, f->file, f->final_path);
    int closed = fclose(f->file);
    f->file = NULL;
    if (r == RAD_OK && closed != 0)
        r = rad_fail(ctx, RAD_ERROR_IO, "%s: write failed: %s", f->final_path, strerror(errno));
    if (r == RAD_OK && f->temp_path && rename(f->temp_path, f->target.path) != 0)
        r = rad_fail(ctx, RAD_ERROR_IO, "%s: write failed: %s", f->final_path, strerror(errno));
    if (r == RAD_OK) {
        rad_free(f->temp_path);
        f->temp_path = NULL;
    }
    rad_atomic_abort(f);
    return r;
}

void rad_atomic_abort(rad_atomic_file *f)
{
    if (f->file)
        fclose(f->file);
    if (f->temp_path)
        unlink(f->temp_path);
    rad_free(f->final_path);
    rad_free(f->temp_path);
    rad_output_target_free(&f->target);
    memset(f, 0, sizeof *f);
}
