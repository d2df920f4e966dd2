/*
 * core.h -- what every module shares: 3-vectors, the context (threads,
 * progress, cancellation, first error, the allocator and its memory
 * limit), timers, seeded random numbers and atomic file output.  Upstream
 * of everything; includes nothing of ours but the public header.
 */
#ifndef RAD_CORE_H
#define RAD_CORE_H

#include "radiosity.h"

#include <math.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---- 3-vectors (double: geometry is done in double, rays in float) ---- */

typedef struct vec3 {
    double x, y, z;
} vec3;

static inline vec3 v3(double x, double y, double z) { vec3 r = {x, y, z}; return r; }
static inline vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 v3_scale(vec3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline vec3 v3_mad(vec3 a, vec3 b, double s) { return v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline double v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 v3_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double v3_length(vec3 a) { return sqrt(v3_dot(a, a)); }
static inline vec3 v3_normalize(vec3 a)
{
    double l = v3_length(a);
    return l > 0.0 ? v3_scale(a, 1.0 / l) : a;
}
static inline vec3 v3_lerp(vec3 a, vec3 b, double t) { return v3_mad(a, v3_sub(b, a), t); }
static inline vec3 v3_min(vec3 a, vec3 b) { return v3(fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z)); }
static inline vec3 v3_max(vec3 a, vec3 b) { return v3(fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z)); }
static inline bool v3_finite(vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
/* Axis-aligned boxes [lo, hi] (closed): whether two meet, whether one holds p. */
static inline bool v3_boxes_meet(vec3 alo, vec3 ahi, vec3 blo, vec3 bhi)
{
    return alo.x <= bhi.x && blo.x <= ahi.x && alo.y <= bhi.y && blo.y <= ahi.y && alo.z <= bhi.z && blo.z <= ahi.z;
}
static inline bool v3_box_holds(vec3 lo, vec3 hi, vec3 p)
{
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
}

/* ---- memory accounting (the allocator is below the context) ---- */

/* What a block is for, by pipeline stage: the stats report the peak of each
 * (docs/stats.md). */
typedef enum rad_memory_category {
    RAD_MEM_SCENE = 0,      /* scenes, their builders, files read while loading */
    RAD_MEM_MESH,           /* patches, elements, welded vertices, weld tables */
    RAD_MEM_VISIBILITY,     /* our side of the ray structure (Embree's BVH is Embree's) */
    RAD_MEM_FORM_FACTORS,   /* F, its variances, the methods' tables and scratch */
    RAD_MEM_SOLVER,         /* element arrays, solver vectors, LU, groups, history */
    RAD_MEM_HIERARCHY,      /* nodes, links, the leaves' mesh of hierarchical radiosity */
    RAD_MEM_RENDER,         /* vertex values, ray batches, images */
    RAD_MEM_OUTPUT,         /* the writers' tables and temporary names */
    RAD_MEM_CATEGORIES      /* count; as an argument: all categories together */
} rad_memory_category;

/* A context's accounting.  The counters are atomic so that they stay exact
 * whichever thread frees a block (an object may be destroyed on another
 * thread than the one that made it); the engine itself allocates on the
 * calling thread only, never inside a parallel region. */
typedef struct rad_memory {
    atomic_size_t references;                   /* live blocks, + 1 until rad_context_destroy */
    size_t limit;                               /* bytes: rad_context_options.max_memory_bytes */
    size_t call_limit;                          /* bytes: the limit of the running call (<= limit) */
    atomic_size_t in_use;                       /* bytes in live blocks */
    atomic_size_t peak;                         /* most bytes in use at once */
    atomic_size_t in_use_by[RAD_MEM_CATEGORIES];
    atomic_size_t peak_by[RAD_MEM_CATEGORIES];
    atomic_uint_fast64_t allocations;           /* rad_alloc / rad_realloc calls so far */
    uint64_t fail_at;                           /* test hook: this allocation fails; 0 = none */
} rad_memory;

/* ---- context ---- */

struct rad_context {
    int threads;                /* OpenMP and Embree threads */
    rad_progress_fn progress;
    void *progress_user;
    rad_error_fn on_error;
    void *error_user;
    rad_warning_fn on_warning;
    void *warning_user;
    bool read_outside_scene_folder; /* see rad_context_options */
    bool missing_textures_flat;     /* see rad_context_options */
    atomic_int cancel;          /* raised by rad_context_cancel, even from a signal handler */
    rad_result last_result;
    bool error_latched;         /* this call already recorded its first failure */
    char error[1024];           /* first line of the first failure of the most recent failed call */
    rad_memory memory;
};

/* Record a failure and return `result`, so callers can write
 * `return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot open", path);`.
 * Only the first failure of a public call is kept (and reported to the
 * error callback): it names the cause, where later ones would name its
 * consequences; a later one returns the first one's result, so the code a
 * call returns matches the message ("out of memory" stays
 * RAD_ERROR_OUT_OF_MEMORY when assimp then fails to parse).  ctx may be
 * NULL (then the message is dropped). */
rad_result rad_fail(rad_context *ctx, rad_result result, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* A JSON input file's text parsed strictly (core/json.c): *out the root
 * (cJSON_Delete it), or NULL and RAD_ERROR_PARSE naming `name` and the
 * line ("bc.json:3: not valid JSON", "...: text after the JSON object"). */
struct cJSON;
rad_result rad_json_parse(rad_context *ctx, const char *name, const char *text, size_t size, struct cJSON **out);

/* Tell the warning callback, if there is one, of input read differently
 * from the file (one line, as rad_fail's).  Not a failure: nothing is
 * latched.  ctx may be NULL. */
void rad_warn(rad_context *ctx, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* The public functions' answer to a NULL context, object, path or out
 * pointer (radiosity.h, "NULL"): "FUNCTION: NULL argument" in the context
 * when there is one, and RAD_ERROR_INVALID_ARGUMENT. */
static inline rad_result rad_null_argument(rad_context *ctx, const char *function)
{
    return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: NULL argument", function);
}

/* Every public function that takes a context calls this first: its first
 * failure will be the one kept.  NULL is a no-op. */
static inline void rad_api_enter(rad_context *ctx)
{
    if (ctx) {
        ctx->error_latched = false;
        ctx->memory.call_limit = ctx->memory.limit;
    }
}

/* True once the user asked to stop (rad_context_cancel).  Any thread. */
static inline bool rad_cancelled(const rad_context *ctx)
{
    return ctx && atomic_load_explicit(&ctx->cancel, memory_order_relaxed) != 0;
}

/* Report progress (calling thread only); cheap when no callback is set. */
void rad_progress(rad_context *ctx, const char *phase, uint64_t done, uint64_t total);

/* ---- time and memory ---- */

double rad_seconds(void);              /* monotonic wall clock, seconds */
size_t rad_peak_memory_bytes(void);    /* peak resident set of the process */
size_t rad_physical_memory_bytes(void);
/* The memory this process may use: the physical memory, or less where its
 * cgroup (a container's limit) or RLIMIT_AS / RLIMIT_DATA (ulimit -v, -d)
 * allows less. */
size_t rad_available_memory_bytes(void);

/* The default memory limit (rad_context_options.max_memory_bytes = 0) is
 * this share of rad_available_memory_bytes().  Half: the limit counts only
 * the engine's own blocks, and assimp while importing, Embree's BVH, LAPACK
 * and the other processes of the machine need the rest (at 80% of the
 * physical memory, the engine's blocks alone could take the machine). */
#define RAD_DEFAULT_MEMORY_SHARE 0.5
/* RAD_DEFAULT_MEMORY_SHARE x rad_available_memory_bytes(), bytes. */
double rad_default_memory_limit(void);

/* ---- the allocator: every block the engine owns comes from here ----
 *
 * Each block carries a 16-byte header (the alignment malloc gives) with its
 * owning context and its size and category, so rad_free needs no context:
 *
 *     malloc'd:  | ctx | bytes << 4 | category |  the caller's bytes ...  |
 *                ^ header (16 bytes)            ^ what rad_alloc returns
 *
 * Every block holds a reference to its context, so a context destroyed
 * before the scenes, solutions and images made with it lives on (unusable,
 * as SQLite's closed-but-busy connection does) until the last of them is
 * destroyed.  Allocation is not for hot loops or
 * parallel regions: per-thread scratch is allocated once, before the
 * region, one slice per thread. */

/* count * size bytes, zeroed, accounted to `category` of ctx.  Fails
 * (NULL; the context error, one line, names `what`, the bytes and the
 * limit) on overflow, when the context's bytes in use would pass its limit,
 * when malloc fails, or when the test hook says so (RAD_ERROR_OUT_OF_MEMORY
 * is the caller's to return).  ctx may be NULL: unaccounted, unlimited. */
void *rad_alloc(rad_context *ctx, rad_memory_category category, size_t count, size_t size,
                const char *what);
/* Resize `block` (NULL: allocate) to count * size bytes, the part beyond its
 * old size zeroed, accounted to `category` of ctx.  On failure NULL, as
 * rad_alloc, and `block` is untouched (still the caller's to free). */
void *rad_realloc(rad_context *ctx, rad_memory_category category, void *block, size_t count,
                  size_t size, const char *what);
/* Free a block of rad_alloc / rad_realloc / rad_strdup.  NULL is a no-op. */
void rad_free(void *block);
/* A copy of s in a block of `category` (NULL for NULL, or as rad_alloc). */
char *rad_strdup(rad_context *ctx, rad_memory_category category, const char *s, const char *what);

/* The limit of the running call, bytes: the context's, or lower where a
 * solution has its own (rad_options.max_memory_bytes).  Every estimate that
 * refuses work before doing it compares against this. */
double rad_memory_limit(const rad_context *ctx);
/* Lower the limit for the rest of this call to `bytes` (> 0), as a
 * solution's calls do with its own limit; rad_api_enter restores it. */
void rad_memory_limit_call(rad_context *ctx, double bytes);
/* Bytes in use now and at most, in one category or all of them
 * (RAD_MEM_CATEGORIES).  0 for NULL. */
size_t rad_memory_in_use(const rad_context *ctx, rad_memory_category category);
size_t rad_memory_peak(const rad_context *ctx, rad_memory_category category);
/* "scene", "mesh", ... "output" (the stats' keys). */
const char *rad_memory_category_name(rad_memory_category category);
/* Allocations (rad_alloc, rad_realloc, rad_strdup) so far in this context. */
uint64_t rad_memory_allocations(const rad_context *ctx);
/* Test hook (SQLite's way): make the k-th allocation from now fail, as if
 * malloc had; k = 0 turns it off.  Not API: tests/test_alloc.c uses it. */
void rad_context_fail_allocation(rad_context *ctx, uint64_t k);

/* Bytes as people read them: "512 bytes", "1.5 KiB", "12.0 MiB", "1.20 GiB". */
void rad_format_bytes(double bytes, char *text, size_t text_size);

/* ---- random numbers: counter-based, so a sample depends only on its key ---- */

/* SplitMix64 finaliser: a good 64-bit mix (Steele, Lea, Flood 2014). */
static inline uint64_t rad_mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

typedef struct rad_rng {
    uint64_t state;
} rad_rng;

/* A stream keyed by (seed, a, b): the same key gives the same numbers
 * whatever thread draws them. */
static inline rad_rng rad_rng_keyed(uint64_t seed, uint64_t a, uint64_t b)
{
    rad_rng r = {rad_mix64(seed ^ rad_mix64(a ^ rad_mix64(b + 0x632be59bd9b4e019ULL)))};
    return r;
}

/* Uniform in [0, 1). */
static inline double rad_rng_uniform(rad_rng *r)
{
    r->state += 0x9e3779b97f4a7c15ULL;
    uint64_t z = r->state;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* perm[0 .. n-1] <- a random permutation of 0 .. n-1 (Fisher-Yates), n - 1
 * draws from r: the strata of one end of a sample paired with those of the
 * other.  Cannot fail. */
static inline void rad_rng_shuffle(rad_rng *r, int *perm, int n)
{
    for (int k = 0; k < n; k++)
        perm[k] = k;
    for (int k = n - 1; k > 0; k--) {
        int m = (int)(rad_rng_uniform(r) * (k + 1)), t = perm[k];
        perm[k] = perm[m];
        perm[m] = t;
    }
}

/* ---- the engine's limits ---- */

/* The lengths the engine works in, m.  Radiosity is scale-free, so any
 * unit would do, but lengths are squared (areas), raised to the fourth
 * power (the kernel's r^4 with cosines unnormalised) and summed over 10^8
 * elements: within [1e-30, 1e30] m every such product stays inside
 * double's range (1e-308 to 1e308) with a wide margin, whatever the scale.
 * A coordinate beyond RAD_MAX_COORDINATE or a polygon smaller across than
 * RAD_MIN_LENGTH is refused, naming it (the limits are 40 and 60 orders of
 * magnitude from anything physical: a unit mix-up, or hostile input).
 * Rays are traced in a frame scaled to the scene (vis_embree.c), so single
 * precision does not narrow this range. */
#define RAD_MAX_COORDINATE 1e30
#define RAD_MIN_LENGTH 1e-30

/* The largest exitance a material may have, W/m^2 (the Sun's is 6.3e7).
 * Radiosity reaches 10^6 E at a reflectance of 0.999999, and pictures hold
 * radiance in float (3.4e38 at most): within 1e30 W/m^2 every value an
 * image can show stays finite.  With the lengths above, the emitted power
 * sum A E stays below 1e90 W a polygon, so no sum of it can overflow the
 * solvers' doubles (which once had to be checked apart: a glTF
 * emissiveStrength of 5e307). */
#define RAD_MAX_EXITANCE 1e30

/* ---- reading input files (input.c) ---- */

/* The whole file at `path` in a block of the context (rad_free it), within
 * its memory limit: a regular file by its size, a stream as it comes.
 * Fails with RAD_ERROR_IO naming the path, RAD_ERROR_OUT_OF_MEMORY,
 * RAD_ERROR_INTERRUPTED. */
rad_result rad_read_whole_file(rad_context *ctx, const char *path, unsigned char **data, size_t *size);

/* The same, for a reader that knows what it reads: at most `most` bytes
 * (0: as many as the memory limit allows) of a `kind` of file ("photometric
 * file"; NULL: any), named `what` in messages (NULL: the path; e.g.
 * "lamp.ies:2: TILT=t.dat").  A folder is "WHAT: is a folder, not a KIND"
 * (RAD_ERROR_IO), a longer file "WHAT: more than 64 MiB: not a KIND"
 * (RAD_ERROR_PARSE); cancellation is polled between pieces of a stream. */
rad_result rad_read_file(rad_context *ctx, const char *path, const char *what, size_t most, const char *kind,
                         unsigned char **data, size_t *size);

/* The files a load opened: the scene file, an OBJ's libraries, every file
 * assimp opens for reading (a glTF's buffers), a layout's photometric
 * files, so the scene can list its inputs; and the folder they must lie in. */
typedef struct rad_input_log {
    char **paths;     /* rad_alloc'd, each rad_alloc'd; no repeats */
    size_t count, capacity;
    bool failed;      /* a name could not be kept (out of memory) */
    /* Confinement: when root is set, files outside it are refused. */
    rad_context *ctx; /* where a refusal is reported */
    const char *scene;/* the file that names the others, for the message */
    char *root;       /* realpath of that file's folder (rad_alloc'd), or NULL */
    bool refused;     /* a file was refused (the context has the message) */
} rad_input_log;

/* Confine `log` to the folder of `scene_path` unless the context allows
 * reading outside it.  Fails only for memory; a folder that cannot be
 * resolved confines to nothing looser: every reference is then refused. */
rad_result rad_input_log_confine(rad_context *ctx, rad_input_log *log, const char *scene_path);
/* Whether `path` may be read (inside the root, or no root); a refusal is
 * reported once to the context ("scene.gltf: refers to '../x.bin' outside
 * its folder ...") and sets log->refused. */
bool rad_input_allowed(rad_input_log *log, const char *path);
/* Note a file read outside assimp (the scene, an OBJ's libraries); sets
 * log->failed when out of memory. */
void rad_input_log_add(rad_input_log *log, const char *path);
/* Free the names.  Cannot fail. */
void rad_input_log_free(rad_input_log *log);

/* ---- file output (file.c): where an output really goes, its identity,
 * temporaries that cannot be hijacked, and atomic replacement ----
 *
 *   out.png (regular, or not there yet)  -> .out.png.k3x9qz in its folder,
 *                                            renamed over out.png at commit
 *   link.png -> data/real.png (regular)  -> the temporary beside real.png,
 *                                            renamed over real.png (the link stays)
 *   /dev/null, a FIFO, /dev/stdout        -> written in place at commit, from
 *                                            an anonymous temporary; never renamed over
 *   a folder, a socket, a block device,
 *   a dangling link                       -> refused
 */

/* An output path, resolved.  Two outputs, or an output and an input, are
 * the same file when their identities match: (device, inode) of a file
 * that exists, else (device, inode) of its folder and its base name; so
 * "./a.png", "a.png", "d/../a.png" and a hard link all match. */
typedef struct rad_output_target {
    char *path;            /* the file replaced: the path as given, or a symlink's target */
    const char *name;      /* its base name, within `path` */
    bool stream;           /* written in place (character device, FIFO, our stdout/stderr) */
    int stream_fd;         /* 1 or 2 when the target is the program's stdout/stderr, else -1 */
    bool exists;
    uint64_t device, inode; /* of the file when it exists, else of its folder */
} rad_output_target;

/* Resolve `path` for writing and check, before any work, that it can be
 * written: its folder exists and is writable (regular files), or the
 * device or FIFO is writable (streams).  Fails with RAD_ERROR_IO naming the
 * path ("out/x.png: cannot write: No such file or directory", "d: is a
 * directory", "l.png: is a dangling symbolic link"), RAD_ERROR_OUT_OF_MEMORY;
 * *out is then empty.  Free with rad_output_target_free. */
rad_result rad_output_target_resolve(rad_context *ctx, const char *path, rad_output_target *out);
void rad_output_target_free(rad_output_target *target);
/* Whether two targets are the same file.  Character devices never alias
 * (writing /dev/null twice is harmless). */
bool rad_output_target_same(const rad_output_target *a, const rad_output_target *b);
/* The identity of an existing file (following links); false if it cannot
 * be had. */
bool rad_file_identity(const char *path, uint64_t *device, uint64_t *inode);

/* Create a new, empty file named ".PREFIX.XXXXXX" + suffix (PREFIX: the
 * start of `name`, cut so that the whole name stays short) in `folder`,
 * with O_CREAT | O_EXCL and mode 0666 & ~umask: it cannot be a file or a
 * link that was there before.  *path (malloc'd) and *fd (O_WRONLY) are the
 * caller's.  Fails with RAD_ERROR_IO naming `what`. */
rad_result rad_temp_create(rad_context *ctx, const char *folder, const char *name, const char *suffix,
                           const char *what, char **path, int *fd);
/* The folder part of a path ("." when none), malloc'd; NULL when out of memory. */
char *rad_path_folder(const char *path);

/* Copy the bytes of `from` (read from its start) into a stream target,
 * opened now without O_CREAT or O_TRUNC (a FIFO waits for its reader).
 * RAD_ERROR_IO naming `what` on failure. */
rad_result rad_stream_copy(rad_context *ctx, const rad_output_target *target, FILE *from,
                           const char *what);

/* ---- atomic output: a temporary beside the target, renamed over it ---- */

typedef struct rad_atomic_file {
    FILE *file;                /* where the caller writes */
    char *final_path;          /* the path as given, for messages */
    char *temp_path;           /* the temporary; NULL for a stream (anonymous temporary) */
    rad_output_target target;
} rad_atomic_file;

/* Resolve `path` (rad_output_target_resolve) and open a temporary for it. */
rad_result rad_atomic_open(rad_context *ctx, const char *path, rad_atomic_file *out);
/* Flush, close and rename over the target (or copy into a stream); on any
 * error removes the temporary file. */
rad_result rad_atomic_commit(rad_context *ctx, rad_atomic_file *file);
/* Remove the temporary file (after a failed write).  Cannot fail. */
void rad_atomic_abort(rad_atomic_file *file);

/* The temporary an output set holds for `path` (as added), or NULL. */
const char *rad_output_set_temp(const rad_output_set *set, const char *path);

/* Lower-case extension of a path without the dot ("" if none), in `ext`. */
void rad_path_extension(const char *path, char *ext, size_t ext_size);

#endif /* RAD_CORE_H */
