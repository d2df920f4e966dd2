/*
 * core.c -- context, errors, progress, clocks, memory figures and the
 * accounting allocator (atomic file output is in file.c).
 */
#include "core/core.h"

#include <ctype.h>
#include <errno.h>
#include <stddef.h>
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
    case RAD_ERROR_NUMERICAL: return "RAD_ERROR_NUMERICAL";
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
    if (!(options->max_memory_bytes >= 0.0)) {
        free(ctx);
        return RAD_ERROR_INVALID_ARGUMENT;
    }
    double limit = options->max_memory_bytes > 0.0 ? options->max_memory_bytes
                                                   : rad_default_memory_limit();
    ctx->memory.limit = limit >= (double)SIZE_MAX ? SIZE_MAX : (size_t)limit;
    atomic_init(&ctx->memory.references, 1);
    ctx->memory.call_limit = ctx->memory.limit;
    ctx->progress = options->progress;
    ctx->progress_user = options->progress_user;
    ctx->on_error = options->on_error;
    ctx->read_outside_scene_folder = options->read_outside_scene_folder;
    ctx->missing_textures_flat = options->missing_textures_flat;
    ctx->error_user = options->error_user;
    ctx->on_warning = options->on_warning;
    ctx->warning_user = options->warning_user;
    atomic_init(&ctx->cancel, 0);
    *out = ctx;
    return RAD_OK;
}

/* Drop one reference: the owner's (rad_context_destroy) or a block's.  The
 * last one frees the context. */
static void context_release(rad_context *ctx)
{
    if (atomic_fetch_sub_explicit(&ctx->memory.references, 1, memory_order_acq_rel) == 1)
        free(ctx);
}

void rad_context_destroy(rad_context *ctx)
{
    if (ctx)
        context_release(ctx);
}

const char *rad_context_error(const rad_context *ctx) { return ctx ? ctx->error : ""; }

int rad_context_threads(const rad_context *ctx) { return ctx ? ctx->threads : 1; }

void rad_context_cancel(rad_context *ctx, bool cancel)
{
    if (ctx)
        atomic_store(&ctx->cancel, cancel ? 1 : 0);
}

bool rad_context_cancelled(const rad_context *ctx) { return rad_cancelled(ctx); }

/* One line of text: a message never carries a line break into the terminal
 * (a glTF name "a\nb" split it), nor an escape sequence (a name holding
 * ESC [2J cleared the screen).  Blanks become spaces, other control bytes
 * '?'; UTF-8 and every printable byte pass. */
static void one_line(char *s)
{
    for (unsigned char *c = (unsigned char *)s; *c; c++)
        if (*c == '\n' || *c == '\r' || *c == '\t')
            *c = ' ';
        else if (*c < 0x20 || *c == 0x7f)
            *c = '?';
}

rad_result rad_fail(rad_context *ctx, rad_result result, const char *fmt, ...)
{
    if (!ctx)
        return result;
    if (ctx->error_latched)
        return ctx->last_result; /* the code that goes with the message kept */
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ctx->error, sizeof ctx->error, fmt, ap);
    va_end(ap);
    one_line(ctx->error);
    ctx->last_result = result;
    ctx->error_latched = true;
    if (ctx->on_error)
        ctx->on_error(ctx->error_user, result, ctx->error);
    return result;
}

void rad_warn(rad_context *ctx, const char *fmt, ...)
{
    if (!ctx || !ctx->on_warning)
        return;
    char message[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    one_line(message);
    ctx->on_warning(ctx->warning_user, message);
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

/* The number in a cgroup file ("max" and anything unreadable: no limit). */
static size_t cgroup_file_bytes(const char *path)
{
    FILE *file = fopen(path, "r");
    if (!file)
        return SIZE_MAX;
    unsigned long long bytes;
    int read = fscanf(file, "%llu", &bytes);
    fclose(file);
    return read == 1 && bytes < SIZE_MAX ? (size_t)bytes : SIZE_MAX;
}

/* The lowest memory limit of this process's cgroups and their ancestors:
 * memory.max (cgroup v2, line "0::/path" of /proc/self/cgroup) or
 * memory.limit_in_bytes (v1, the line listing "memory").  SIZE_MAX when
 * there is none; a container's limit is usually its root's. */
static size_t cgroup_memory_bytes(void)
{
    FILE *file = fopen("/proc/self/cgroup", "r");
    if (!file)
        return SIZE_MAX;
    size_t lowest = SIZE_MAX;
    char line[1024];
    while (fgets(line, sizeof line, file)) {
        char *controllers = strchr(line, ':');
        char *path = controllers ? strchr(controllers + 1, ':') : NULL;
        if (!path || path[1] != '/')
            continue;
        *path++ = '\0';
        controllers++;
        path[strcspn(path, "\n")] = '\0';
        bool v1 = false; /* "memory" among the comma-separated controllers */
        for (const char *word = controllers; *word;) {
            v1 = v1 || (strncmp(word, "memory", 6) == 0 && (word[6] == ',' || word[6] == '\0'));
            word += strcspn(word, ",");
            if (*word == ',')
                word++;
        }
        if (!v1 && controllers[0] != '\0')
            continue;
        for (size_t length = strlen(path);;) {
            char limit_file[1200];
            snprintf(limit_file, sizeof limit_file, "/sys/fs/cgroup%s%.*s/%s", v1 ? "/memory" : "",
                     (int)length, path, v1 ? "memory.limit_in_bytes" : "memory.max");
            size_t bytes = cgroup_file_bytes(limit_file);
            lowest = bytes < lowest ? bytes : lowest;
            if (length <= 1)
                break;
            while (length > 1 && path[length - 1] != '/')
                length--; /* up to the parent: "/a/b" -> "/a/" -> "/a" */
            if (length > 1)
                length--;
        }
    }
    fclose(file);
    return lowest;
}

size_t rad_available_memory_bytes(void)
{
    size_t bytes = rad_physical_memory_bytes(), cgroup = cgroup_memory_bytes();
    bytes = cgroup < bytes ? cgroup : bytes;
    const int resources[] = {RLIMIT_AS, RLIMIT_DATA};
    for (size_t i = 0; i < sizeof resources / sizeof resources[0]; i++) {
        struct rlimit limit;
        if (getrlimit(resources[i], &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
            limit.rlim_cur < bytes)
            bytes = (size_t)limit.rlim_cur;
    }
    return bytes;
}

double rad_default_memory_limit(void)
{
    return RAD_DEFAULT_MEMORY_SHARE * (double)rad_available_memory_bytes();
}

/* ---- the allocator ---- */

/* The header before every block: 16 bytes, so the caller's bytes keep
 * malloc's 16-byte alignment.  Sizes fit in 60 bits on every machine
 * this runs on; the low 4 bits hold the category. */
typedef struct block_header {
    _Alignas(16) rad_context *ctx;
    size_t size_category;       /* bytes << 4 | category */
} block_header;

_Static_assert(sizeof(block_header) == 16, "the header keeps malloc's alignment");
_Static_assert(RAD_MEM_CATEGORIES <= 16, "categories fit in 4 bits");

static const char *const category_names[RAD_MEM_CATEGORIES] = {
    "scene", "mesh", "visibility", "form_factors", "solver", "hierarchy", "render", "output",
};

const char *rad_memory_category_name(rad_memory_category category)
{
    return category < RAD_MEM_CATEGORIES ? category_names[category] : "all";
}

void rad_format_bytes(double bytes, char *text, size_t text_size)
{
    if (bytes < 1024.0)
        snprintf(text, text_size, "%.0f bytes", bytes);
    else if (bytes < 1048576.0)
        snprintf(text, text_size, "%.1f KiB", bytes / 1024.0);
    else if (bytes < 1073741824.0)
        snprintf(text, text_size, "%.1f MiB", bytes / 1048576.0);
    else
        snprintf(text, text_size, "%.2f GiB", bytes / 1073741824.0);
}

static void raise_peak(atomic_size_t *peak, size_t now)
{
    size_t seen = atomic_load_explicit(peak, memory_order_relaxed);
    while (seen < now &&
           !atomic_compare_exchange_weak_explicit(peak, &seen, now, memory_order_relaxed, memory_order_relaxed))
        ;
}

/* Count `bytes` more in use, or fail naming `what` when they would pass the
 * call's limit or the test hook says so.  The check and the count are one
 * atomic add, so threads sharing a context cannot pass the limit together. */
static bool account(rad_context *ctx, rad_memory_category category, size_t bytes, const char *what)
{
    rad_memory *m = &ctx->memory;
    uint64_t k = atomic_fetch_add_explicit(&m->allocations, 1, memory_order_relaxed) + 1;
    if (k == m->fail_at) {
        char amount[32];
        rad_format_bytes((double)bytes, amount, sizeof amount);
        rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory allocating %s (test hook: allocation %llu)",
                 what, amount, (unsigned long long)k);
        return false;
    }
    size_t now = atomic_fetch_add_explicit(&m->in_use, bytes, memory_order_relaxed) + bytes;
    if (now < bytes || now > m->call_limit) {
        atomic_fetch_sub_explicit(&m->in_use, bytes, memory_order_relaxed);
        char amount[32], limit[32], used[32];
        rad_format_bytes((double)bytes, amount, sizeof amount);
        rad_format_bytes((double)m->call_limit, limit, sizeof limit);
        rad_format_bytes((double)(now - bytes), used, sizeof used);
        /* Name the limit in force: a solution's own where it is lower. */
        rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: %s more would pass the memory limit of %s (%s in use; %s)", what,
                 amount, limit, used,
                 m->call_limit < m->limit ? "rad_options.max_memory_bytes" : "rad_context_options.max_memory_bytes");
        return false;
    }
    raise_peak(&m->peak, now);
    size_t in_category = atomic_fetch_add_explicit(&m->in_use_by[category], bytes, memory_order_relaxed) + bytes;
    raise_peak(&m->peak_by[category], in_category);
    return true;
}

static void unaccount(rad_context *ctx, rad_memory_category category, size_t bytes)
{
    atomic_fetch_sub_explicit(&ctx->memory.in_use, bytes, memory_order_relaxed);
    atomic_fetch_sub_explicit(&ctx->memory.in_use_by[category], bytes, memory_order_relaxed);
}

/* count * size, or fail naming `what` when it overflows (or leaves no room
 * for the header). */
static bool block_bytes(rad_context *ctx, size_t count, size_t size, const char *what, size_t *bytes)
{
    if (size != 0 && count > (SIZE_MAX >> 4) / size) {
        rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: %zu x %zu bytes overflows the address space", what,
                 count, size);
        return false;
    }
    *bytes = count * size;
    return true;
}

static void *block_fill(block_header *h, rad_context *ctx, rad_memory_category category, size_t bytes)
{
    if (ctx && ctx != h->ctx)
        atomic_fetch_add_explicit(&ctx->memory.references, 1, memory_order_relaxed);
    h->ctx = ctx;
    h->size_category = bytes << 4 | (size_t)category;
    return h + 1;
}

static void out_of_memory(rad_context *ctx, const char *what, size_t bytes)
{
    char amount[32];
    rad_format_bytes((double)bytes, amount, sizeof amount);
    rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory allocating %s", what, amount);
}

void *rad_alloc(rad_context *ctx, rad_memory_category category, size_t count, size_t size, const char *what)
{
    size_t bytes;
    if (!block_bytes(ctx, count, size, what, &bytes))
        return NULL;
    if (ctx && !account(ctx, category, bytes, what))
        return NULL;
    block_header *h = calloc(1, sizeof *h + bytes); /* h->ctx == NULL: no reference yet */
    if (!h) {
        if (ctx)
            unaccount(ctx, category, bytes);
        out_of_memory(ctx, what, bytes);
        return NULL;
    }
    return block_fill(h, ctx, category, bytes);
}

void *rad_realloc(rad_context *ctx, rad_memory_category category, void *block, size_t count, size_t size,
                  const char *what)
{
    if (!block)
        return rad_alloc(ctx, category, count, size, what);
    size_t bytes;
    if (!block_bytes(ctx, count, size, what, &bytes))
        return NULL;
    block_header *h = (block_header *)block - 1;
    rad_context *old_ctx = h->ctx;
    rad_memory_category old_category = (rad_memory_category)(h->size_category & 15);
    size_t old_bytes = h->size_category >> 4;
    /* Count the new size before letting go of the old: a realloc may need both. */
    if (ctx && !account(ctx, category, bytes, what))
        return NULL;
    block_header *grown = realloc(h, sizeof *h + bytes);
    if (!grown) {
        if (ctx)
            unaccount(ctx, category, bytes);
        out_of_memory(ctx, what, bytes);
        return NULL;
    }
    if (old_ctx)
        unaccount(old_ctx, old_category, old_bytes);
    if (bytes > old_bytes)
        memset((char *)(grown + 1) + old_bytes, 0, bytes - old_bytes);
    void *block_now = block_fill(grown, ctx, category, bytes);
    if (old_ctx && old_ctx != ctx)
        context_release(old_ctx);
    return block_now;
}

void rad_free(void *block)
{
    if (!block)
        return;
    block_header *h = (block_header *)block - 1;
    rad_context *ctx = h->ctx;
    if (ctx)
        unaccount(ctx, (rad_memory_category)(h->size_category & 15), h->size_category >> 4);
    free(h);
    if (ctx)
        context_release(ctx);
}

char *rad_strdup(rad_context *ctx, rad_memory_category category, const char *s, const char *what)
{
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char *d = rad_alloc(ctx, category, n, 1, what);
    if (d)
        memcpy(d, s, n);
    return d;
}

double rad_memory_limit(const rad_context *ctx)
{
    return ctx ? (double)ctx->memory.call_limit : rad_default_memory_limit();
}

void rad_memory_limit_call(rad_context *ctx, double bytes)
{
    if (ctx && bytes > 0.0 && bytes < (double)ctx->memory.call_limit)
        ctx->memory.call_limit = (size_t)bytes;
}

size_t rad_memory_in_use(const rad_context *ctx, rad_memory_category category)
{
    if (!ctx)
        return 0;
    return category < RAD_MEM_CATEGORIES ? atomic_load(&ctx->memory.in_use_by[category])
                                         : atomic_load(&ctx->memory.in_use);
}

size_t rad_memory_peak(const rad_context *ctx, rad_memory_category category)
{
    if (!ctx)
        return 0;
    return category < RAD_MEM_CATEGORIES ? atomic_load(&ctx->memory.peak_by[category])
                                         : atomic_load(&ctx->memory.peak);
}

uint64_t rad_memory_allocations(const rad_context *ctx)
{
    return ctx ? (uint64_t)atomic_load(&ctx->memory.allocations) : 0;
}

void rad_context_fail_allocation(rad_context *ctx, uint64_t k)
{
    if (ctx)
        ctx->memory.fail_at = k ? rad_memory_allocations(ctx) + k : 0;
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
