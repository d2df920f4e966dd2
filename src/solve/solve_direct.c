/*
 * solve_direct.c -- the radiosity system solved exactly, by LU
 * factorisation with partial pivoting (LAPACK dgesv), one colour channel
 * at a time (Cohen & Wallace 1993, sec. 5.2; the notes' "Direct Methods"):
 *
 *     K_c B_c = E_c,   K_c = I - diag(rho_c) F       (n x n doubles)
 *
 * O(n^3) time and 8 n^2 bytes, but no tolerance: the answer is exact up to
 * double rounding, so it is the reference the iterative solvers are tested
 * against.  K_c is built from F as it is stored, so the system solved
 * is the engine's own; channels with the same reflectance everywhere (grey
 * scenes) share one factorisation.  K is written column-major, as LAPACK
 * keeps it, so LAPACKE makes no transposed copy of its own.  Above the
 * memory limit (rad_system.max_memory) the solver refuses rather than
 * swap; the iterative solvers need O(n) beside F.
 *
 * The factorisation is our own blocking of LAPACK's (Golub & Van Loan,
 * "Matrix Computations", 4th ed., sec. 3.4.7: right-looking blocked LU
 * with partial pivoting), so that its answer does not depend on the thread
 * count:
 *
 *           k0  k0 + PANEL
 *     [ L\U |  U12  |      ]     for each panel of PANEL columns:
 *     [     |-------+----- ]       1. dgetrf on the panel K[k0:, k0:k0+nb]
 *     [     |  L11  |  A12 ]       2. every other block of PANEL columns, in
 *     [     |  L21  |  A22 ]          parallel: the panel's row swaps, and
 *                                     right of it U12 = L11^-1 A12,
 *                                     A22 -= L21 U12 (dtrsm, dgemm)
 *
 * The blocks are PANEL wide on any number of threads and each is one
 * thread's, with OpenBLAS itself held to one thread: every number comes
 * from the same operations in the same order, so B is bit-identical on 1
 * or 16 threads.  (OpenBLAS's threaded dgesv splits its work by the
 * thread count, and moved the last bits of B, 4e-16, between 1 and 2.)
 * Cancellation is polled between panels.
 */
#include "solve/solve.h"

#include <cblas.h>
#include <dlfcn.h>
#include <lapacke.h>
#include <limits.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

/* ---- LAPACK and BLAS, loaded when first needed ----
 *
 * OpenBLAS starts its own pool of threads when it is loaded, and they spin
 * (sched_yield) for about 0.1 s before they sleep.  Linked into the
 * program, that happened on every run, whatever the solver, and took a
 * core from the rest of a 0.2 s render of the Cornell box.  Only this
 * solver needs the libraries (its own threads do the parallel work, with
 * OpenBLAS held to one), so they are opened here on first use: the
 * headers give the types, dlopen the code.  Debian's sonames. */
#define RAD_OPENBLAS_SONAME "libopenblas.so.0"
#define RAD_LAPACKE_SONAME "liblapacke.so.3"

typedef lapack_int (*getrf_fn)(int, lapack_int, lapack_int, double *, lapack_int, lapack_int *);
typedef lapack_int (*laswp_fn)(int, lapack_int, double *, lapack_int, lapack_int, lapack_int, const lapack_int *,
                               lapack_int);
typedef lapack_int (*getrs_fn)(int, char, lapack_int, lapack_int, const double *, lapack_int, const lapack_int *,
                               double *, lapack_int);
typedef void (*trsm_fn)(enum CBLAS_ORDER, enum CBLAS_SIDE, enum CBLAS_UPLO, enum CBLAS_TRANSPOSE, enum CBLAS_DIAG,
                        blasint, blasint, double, const double *, blasint, double *, blasint);
typedef void (*gemm_fn)(enum CBLAS_ORDER, enum CBLAS_TRANSPOSE, enum CBLAS_TRANSPOSE, blasint, blasint, blasint,
                        double, const double *, blasint, const double *, blasint, double, double *, blasint);
typedef int (*get_threads_fn)(void);
typedef void (*set_threads_fn)(int);

static struct {
    getrf_fn getrf;
    laswp_fn laswp;
    getrs_fn getrs;
    trsm_fn trsm;
    gemm_fn gemm;
    get_threads_fn get_threads;
    set_threads_fn set_threads;
    char error[256];      /* "" when loaded */
} lapack;

static pthread_once_t lapack_once = PTHREAD_ONCE_INIT;

/* dlsym's object pointer as a function pointer (copied: ISO C has no cast
 * between the two). */
static bool find_symbol(void *library, const char *name, void *fn, size_t size)
{
    void *symbol = library ? dlsym(library, name) : NULL;
    if (!symbol) {
        if (!lapack.error[0])
            snprintf(lapack.error, sizeof lapack.error, "%s not found (%s)", name,
                     library ? "missing symbol" : "library not loaded");
        return false;
    }
    memcpy(fn, &symbol, size);
    return true;
}

static void lapack_load(void)
{
    void *blas = dlopen(RAD_OPENBLAS_SONAME, RTLD_NOW | RTLD_LOCAL);
    if (!blas) {
        const char *why = dlerror();
        snprintf(lapack.error, sizeof lapack.error, "%s", why ? why : RAD_OPENBLAS_SONAME " not found");
        return;
    }
    void *lapacke = dlopen(RAD_LAPACKE_SONAME, RTLD_NOW | RTLD_LOCAL);
    if (!lapacke) {
        const char *why = dlerror();
        snprintf(lapack.error, sizeof lapack.error, "%s", why ? why : RAD_LAPACKE_SONAME " not found");
        return;
    }
    find_symbol(lapacke, "LAPACKE_dgetrf_work", &lapack.getrf, sizeof lapack.getrf);
    find_symbol(lapacke, "LAPACKE_dlaswp_work", &lapack.laswp, sizeof lapack.laswp);
    find_symbol(lapacke, "LAPACKE_dgetrs_work", &lapack.getrs, sizeof lapack.getrs);
    find_symbol(blas, "cblas_dtrsm", &lapack.trsm, sizeof lapack.trsm);
    find_symbol(blas, "cblas_dgemm", &lapack.gemm, sizeof lapack.gemm);
    find_symbol(blas, "openblas_get_num_threads", &lapack.get_threads, sizeof lapack.get_threads);
    find_symbol(blas, "openblas_set_num_threads", &lapack.set_threads, sizeof lapack.set_threads);
    /* The libraries stay loaded for the life of the process. */
}

/* 64 x 64 doubles: one tile of K and of F stay in L1/L2 during the transposition. */
enum { TILE = 64 };

/* Columns per panel and per block of the update: wide enough for dgemm to
 * run near its peak (a 128-column update is 2 x 128 flops per element of
 * A22 read), narrow enough for a 2,000-element system to split into 16
 * blocks among the threads. */
enum { PANEL = 128 };

/* K = I - diag(rho) F in column-major order, by tiles (F is row-major). */
static void build_matrix(const rad_system *sys, const double *rho, size_t stride, double *K)
{
    size_t n = sys->n;
    size_t tiles = (n + TILE - 1) / TILE;
#pragma omp parallel for schedule(static) num_threads(rad_pass_threads(sys))
    for (size_t jt = 0; jt < tiles; jt++) {
        size_t j0 = jt * TILE, j1 = j0 + TILE < n ? j0 + TILE : n;
        for (size_t i0 = 0; i0 < n; i0 += TILE) {
            size_t i1 = i0 + TILE < n ? i0 + TILE : n;
            for (size_t i = i0; i < i1; i++) {
                const double *Fi = sys->F + i * n;
                double r = rho[stride * i];
                for (size_t j = j0; j < j1; j++)
                    K[j * n + i] = (i == j ? 1.0 : 0.0) - r * (double)Fi[j];
            }
        }
    }
}

/* LU with partial pivoting of the column-major n x n K in place (above);
 * pivots 1-based, as LAPACK's.  RAD_ERROR_INTERNAL for an exactly zero
 * pivot, RAD_ERROR_INTERRUPTED when cancelled between panels. */
static rad_result factor(rad_context *ctx, const rad_system *sys, double *K, lapack_int *pivots, int channel)
{
    size_t n = sys->n, blocks = (n + PANEL - 1) / PANEL;
    lapack_int ld = (lapack_int)n;
    for (size_t k0 = 0; k0 < n; k0 += PANEL) {
        size_t nb = n - k0 < PANEL ? n - k0 : PANEL;
        double *panel = K + k0 + k0 * n;
        lapack_int info = lapack.getrf(LAPACK_COL_MAJOR, (lapack_int)(n - k0), (lapack_int)nb, panel, ld,
                                              pivots + k0);
        if (info != 0)
            /* rho_i sum_j F_ij < 1 makes K strictly diagonally dominant, so
             * a zero pivot means F is broken (row sums far above 1). */
            return rad_fail(ctx, RAD_ERROR_INTERNAL,
                            "solve: direct: LAPACK dgetrf failed (info %d) on channel %d: the matrix is "
                            "singular; are the form-factor row sums above 1?",
                            (int)(info > 0 ? info + (lapack_int)k0 : info), channel);
        for (size_t i = k0; i < k0 + nb; i++)
            pivots[i] += (lapack_int)k0; /* the panel's rows count from k0 */
#pragma omp parallel for schedule(dynamic, 1) num_threads(rad_pass_threads(sys))
        for (size_t b = 0; b < blocks; b++) {
            size_t j0 = b * PANEL, width = n - j0 < PANEL ? n - j0 : PANEL;
            if (j0 == k0)
                continue;
            double *columns = K + j0 * n;
            lapack.laswp(LAPACK_COL_MAJOR, (lapack_int)width, columns, ld, (lapack_int)k0 + 1,
                                (lapack_int)(k0 + nb), pivots, 1);
            if (j0 < k0)
                continue; /* left of the panel: L, only swapped */
            lapack.trsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasUnit, (blasint)nb,
                        (blasint)width, 1.0, panel, (blasint)n, columns + k0, (blasint)n);
            if (k0 + nb < n)
                lapack.gemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (blasint)(n - k0 - nb), (blasint)width,
                            (blasint)nb, -1.0, panel + nb, (blasint)n, columns + k0, (blasint)n, 1.0,
                            columns + k0 + nb, (blasint)n);
        }
        rad_progress(ctx, "solve", (uint64_t)(k0 + nb), (uint64_t)n);
        if (rad_cancelled(ctx))
            return rad_fail(ctx, RAD_ERROR_INTERRUPTED,
                            "solve: direct: interrupted in the factorisation of channel %d", channel);
    }
    return RAD_OK;
}

static bool same_channel(const rad_system *sys, int a, int b)
{
    for (size_t i = 0; i < sys->n; i++)
        if (sys->reflectance[3 * i + a] != sys->reflectance[3 * i + b])
            return false;
    return true;
}

/* "12.3 MiB" or "4.50 GiB". */
static void format_bytes(double bytes, char *out, size_t size)
{
    if (bytes >= 1073741824.0)
        snprintf(out, size, "%.2f GiB", bytes / 1073741824.0);
    else
        snprintf(out, size, "%.2f MiB", bytes / 1048576.0);
}

static rad_result direct(rad_context *ctx, const rad_system *sys, const rad_solve_params *p,
                         double *B, rad_solve_stats *stats)
{
    size_t n = sys->n;
    double t0 = rad_seconds();
    /* K, the right-hand sides (up to 3 columns) and the pivots, beside F
     * (8 n^2 bytes too), which is held while K is built from it. */
    double needed = 16.0 * (double)n * (double)n + 24.0 * (double)n + 4.0 * (double)n;
    double limit = sys->max_memory > 0.0 ? sys->max_memory : rad_memory_limit(ctx);
    if (needed > limit || n > (size_t)INT_MAX) {
        char need_text[32], limit_text[32];
        format_bytes(needed, need_text, sizeof need_text);
        format_bytes(limit, limit_text, sizeof limit_text);
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                        "solve: the direct solver's LU of the %zu x %zu system needs %s (8 n^2 bytes "
                        "beside F's 8 n^2), "
                        "above the memory limit of %s (rad_options.max_memory_bytes); use an iterative solver "
                        "(rad_options.solver: gauss-seidel, jacobi or conjugate-gradient) or fewer elements",
                        n, n, need_text, limit_text);
    }
    if (n == 0) {
        stats->residual = 0.0;
        stats->converged = true;
        return RAD_OK;
    }
    pthread_once(&lapack_once, lapack_load);
    if (lapack.error[0])
        return rad_fail(ctx, RAD_ERROR_INTERNAL, "solve: direct: cannot load LAPACK: %s (Debian: liblapacke, libopenblas0)",
                        lapack.error);
    double *K = rad_alloc(ctx, RAD_MEM_SOLVER, n * n, sizeof *K, "solve: direct: LU matrix");
    double *rhs = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *rhs, "solve: direct: right-hand sides");
    lapack_int *pivots = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *pivots, "solve: direct: pivots");
    if (!K || !rhs || !pivots) {
        rad_free(K);
        rad_free(rhs);
        rad_free(pivots);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    /* OpenBLAS keeps its thread count in a global: one thread for the
     * factorisation (the parallelism is ours), the caller's back afterwards.
     * Two direct solves at once in one process may restore it while the
     * other runs; OpenBLAS's threaded dgemm and dtrsm then split columns,
     * not sums, so even that changes no bit. */
    int blas_threads = lapack.get_threads();
    lapack.set_threads(1);

    rad_result result = RAD_OK;
    bool solved[3] = {false, false, false};
    for (int c = 0; c < 3 && result == RAD_OK; c++) {
        if (solved[c])
            continue;
        int channels[3], m = 0;
        for (int d = c; d < 3; d++)
            if (!solved[d] && (d == c || same_channel(sys, c, d)))
                channels[m++] = d;
        build_matrix(sys, sys->reflectance + c, 3, K);
        for (int k = 0; k < m; k++)
            for (size_t i = 0; i < n; i++)
                rhs[(size_t)k * n + i] = sys->emission[3 * i + channels[k]];
        result = factor(ctx, sys, K, pivots, c);
        if (result != RAD_OK)
            break;
        lapack_int info = lapack.getrs(LAPACK_COL_MAJOR, 'N', (lapack_int)n, m, K, (lapack_int)n, pivots,
                                              rhs, (lapack_int)n);
        if (info != 0) {
            result = rad_fail(ctx, RAD_ERROR_INTERNAL, "solve: direct: LAPACK dgetrs failed (info %d)", (int)info);
            break;
        }
        for (int k = 0; k < m; k++) {
            for (size_t i = 0; i < n; i++)
                B[3 * i + channels[k]] = rhs[(size_t)k * n + i];
            solved[channels[k]] = true;
        }
        if (rad_cancelled(ctx) && !(solved[0] && solved[1] && solved[2]))
            result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: direct: interrupted after channel %d", c);
    }
    lapack.set_threads(blas_threads > 0 ? blas_threads : 1);
    rad_free(K);
    rad_free(rhs);
    rad_free(pivots);

    stats->iterations = result == RAD_OK ? 1 : 0;
    rad_result measured = rad_residual(ctx, sys, B, &stats->residual);
    if (result == RAD_OK)
        result = measured;
    stats->converged = result == RAD_OK && stats->residual <= p->tolerance;
    stats->iteration_limit = 1.0;
    if (result == RAD_OK && !stats->converged)
        snprintf(stats->warning, sizeof stats->warning,
                 "direct: the residual of the exact solve, %.3g, is above the tolerance %.3g: what the "
                 "rounding of F and of the factorisation leaves",
                 stats->residual, p->tolerance);
    if (result == RAD_OK && p->monitor) {
        rad_solve_step step = {1, rad_seconds() - t0, stats->residual, NAN};
        if (p->monitor(p->monitor_user, &step, B, NULL))
            return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: stopped after the direct solve");
    }
    return result;
}

const rad_solver rad_solver_direct = {
    "direct",
    "LU factorisation (LAPACK dgesv) per colour channel: exact, the reference; O(n^3) time, "
    "8 n^2 bytes beside F (refused above rad_options.max_memory_bytes)",
    direct,
    0,
};
