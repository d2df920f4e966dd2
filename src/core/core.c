/*
 * core.c -- context, errors, progress, clocks, memory figures, checked
 * allocation (atomic file output is in file.c).
 */
#include "core/core.h"

#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#ifdef _OPENMP
#include <omp.h>
#endif

const char *rad_version(void) { return RAD_VERSION_STRING; }

int rad_version_number(void) { return RAD_VERSION_NUMBER; }

const char *rad_result_string(rad_result result)
{
    switch (result) {
    case RAD_OK: return "RAD_OK";
    case RAD_ERROR_IO: return "RAD_ERROR_IO";
    case RAD_ERROR_PARSE: return "RAD_ERROR_PARSE";
    case RAD_ERROR_INVALID_SCENE: return "RAD_ERROR_INVALID_SCENE";
    case RAD_ERROR_INVALID_ARGUMENT: return "RAD_ERROR_INVALID_ARGUMENT";
    case RAD_ERROR_OUT_OF_MEMORY: return "RAD_ERROR_OUT_OF_MEMORY";
    case RAD_ERROR_INTERRUPTED: return "RAD_ERROR_INTERRUPTED";
    case RAD_ERROR_INTERNAL: return "RAD_ERROR_INTERNAL";
    }
    return "RAD_ERROR_UNKNOWN";
}

rad_result rad_context_create(const rad_context_options *options, rad_context **out)
{
    if (!out)
        return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    rad_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_context_options defaults = {0};
    if (!options)
        options = &defaults;
    if (options->threads < 0) {
        free(ctx);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    ctx->threads = options->threads;
    if (ctx->threads == 0) {
#ifdef _OPENMP
        ctx->threads = omp_get_num_procs();
#else
        ctx->threads = 1;
#endif
    }
    ctx->progress = options->progress;
    ctx->progress_user = options->progress_user;
    ctx->on_error = options->on_error;
    ctx->error_user = options->error_user;
    atomic_init(&ctx->cancel, 0);
    *out = ctx;
    return RAD_OK;
}

void rad_context_destroy(rad_context *ctx) { free(ctx); }

const char *rad_context_error(const rad_context *ctx) { return ctx ? ctx->error : ""; }

int rad_context_threads(const rad_context *ctx) { return ctx ? ctx->threads : 1; }

void rad_context_cancel(rad_context *ctx, bool cancel)
{
    if (ctx)
        atomic_store(&ctx->cancel, cancel ? 1 : 0);
}

bool rad_context_cancelled(const rad_context *ctx) { return rad_cancelled(ctx); }

rad_result rad_fail(rad_context *ctx, rad_result result, const char *fmt, ...)
{
    if (!ctx || ctx->error_latched)
        return result;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ctx->error, sizeof ctx->error, fmt, ap);
    va_end(ap);
    /* One line: a message never carries a newline into the terminal. */
    for (char *c = ctx->error; *c; c++)
        if (*c == '\n' || *c == '\r')
            *c = ' ';
    ctx->last_result = result;
    ctx->error_latched = true;
    if (ctx->on_error)
        ctx->on_error(ctx->error_user, result, ctx->error);
    return result;
}

void rad_progress(rad_context *ctx, const char *phase, uint64_t done, uint64_t total)
{
    if (ctx && ctx->progress)
        ctx->progress(ctx->progress_user, phase, done, total);
}

double rad_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

size_t rad_peak_memory_bytes(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0)
        return 0;
    return (size_t)ru.ru_maxrss * 1024u; /* Linux reports kilobytes */
}

size_t rad_physical_memory_bytes(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0)
        return (size_t)1 << 32;
    return (size_t)pages * (size_t)page;
}

void *rad_alloc_array(rad_context *ctx, size_t count, size_t size, const char *what)
{
    if (size != 0 && count > SIZE_MAX / size) {
        rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: %zu x %zu bytes overflows the address space",
                 what, count, size);
        return NULL;
    }
    size_t bytes = count * size;
    void *p = calloc(1, bytes ? bytes : 1);
    if (!p)
        rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory allocating %.1f MiB", what,
                 (double)bytes / 1048576.0);
    return p;
}

char *rad_strdup(const char *s)
{
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

void rad_path_extension(const char *path, char *ext, size_t ext_size)
{
    if (ext_size == 0)
        return;
    ext[0] = '\0';
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash))
        return;
    size_t i = 0;
    for (dot++; *dot && i + 1 < ext_size; dot++)
        ext[i++] = (char)tolower((unsigned char)*dot);
    ext[i] = '\0';
}
