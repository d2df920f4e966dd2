/*
 * vf_stream.c -- the row sinks of streamed view factors: where element
 * rows go, in order, one at a time, when the n x n matrix is never held
 * (stream.c drives them; docs/formats.md, "Streamed view factors").
 *
 *     sink                    memory          disk
 *     element .csv            O(n) names      the file (dense: n^2 numbers)
 *     element .mtx            O(n) names      the entries twice until the end
 *     surface .json/.csv/.mtx O(S^2)          S^2 numbers, at the end
 *
 * Each writes the bytes rad_write_view_factors writes from the dense
 * matrix (tests/test_stream.c compares them).  Matrix Market's size line
 * (its count of nonzeros) precedes the entries and is known only at the
 * end: the entries go to a temporary beside the output, and the end joins
 * header and entries into the atomic file, then removes the temporary.
 * Element-level JSON holds each row's sum before all the rows: not
 * streamed.  A new format is one more entry in rad_vf_sinks[].
 */
#include "output/output.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* "surface#k" for every element, k counting the surface's elements: the
 * names of rad_write_view_factors' element rows.  NULL when out of memory
 * (nothing left allocated). */
static char **element_names(rad_context *ctx, const rad_solution_view *v)
{
    size_t n = v->n, S = v->scene->surface_count;
    char **names = rad_alloc(ctx, RAD_MEM_OUTPUT, n ? n : 1, sizeof *names, "view factors: names");
    size_t *seen = names ? rad_alloc(ctx, RAD_MEM_OUTPUT, S ? S : 1, sizeof *seen, "view factors: names") : NULL;
    bool ok = seen != NULL;
    for (size_t i = 0; i < n && ok; i++) {
        uint32_t si = v->mesh->elements[i].surface;
        char *surface = rad_utf8_clean(ctx, v->scene->surfaces[si].name);
        size_t size = surface ? strlen(surface) + 24 : 0;
        names[i] = surface ? rad_alloc(ctx, RAD_MEM_OUTPUT, size, 1, "view factors: names") : NULL;
        if (names[i])
            snprintf(names[i], size, "%s#%zu", surface, seen[si]++);
        else
            ok = false;
        rad_free(surface);
    }
    rad_free(seen);
    if (!ok && names) {
        for (size_t i = 0; i < n; i++)
            rad_free(names[i]);
        rad_free(names);
        names = NULL;
    }
    return names;
}

/* ---- element rows: CSV and Matrix Market ---- */

typedef struct element_sink {
    const rad_solution_view *view;
    char **names;              /* n */
    rad_atomic_file out;
    FILE *body;                /* Matrix Market: the entries, until the end joins them */
    char *body_path;           /* its name (rad_alloc'd) */
    size_t nnz;                /* Matrix Market entries so far */
    double body_bytes;         /* bytes in body */
    double start;              /* bytes of the header (CSV) */
    bool mtx;
} element_sink;

static void element_free(element_sink *s, bool remove_files)
{
    if (s->body) {
        fclose(s->body);
        s->body = NULL;
    }
    if (s->body_path) {
        unlink(s->body_path);
        rad_free(s->body_path);
    }
    if (remove_files && s->out.file)
        rad_atomic_abort(&s->out);
    for (size_t i = 0; s->names && i < s->view->n; i++)
        rad_free(s->names[i]);
    rad_free(s->names);
    rad_free(s);
}

static rad_result element_begin(rad_context *ctx, const rad_vf_stream_info *info, bool mtx, void **state)
{
    *state = NULL;
    const rad_solution_view *v = info->view;
    element_sink *s = rad_alloc(ctx, RAD_MEM_OUTPUT, 1, sizeof *s, "view factors: stream");
    if (!s)
        return RAD_ERROR_OUT_OF_MEMORY;
    s->view = v;
    s->mtx = mtx;
    s->names = element_names(ctx, v);
    rad_result r = s->names ? rad_atomic_open(ctx, info->path, &s->out) : RAD_ERROR_OUT_OF_MEMORY;
    if (r == RAD_OK && mtx) {
        /* The entries' temporary, beside the output (same file system). */
        char *folder = rad_path_folder(s->out.target.path);
        int fd = -1;
        r = folder ? rad_temp_create(ctx, folder, "entries", ".mtx", info->path, &s->body_path, &fd)
                   : rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", info->path);
        rad_free(folder);
        if (r == RAD_OK && !(s->body = fdopen(fd, "wb"))) {
            close(fd);
            r = rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write: %s", s->body_path, strerror(errno));
        }
    }
    if (r != RAD_OK) {
        element_free(s, true);
        return r;
    }
    FILE *f = s->out.file;
    if (mtx) {
        fprintf(f, "%%%%MatrixMarket matrix coordinate real general\n");
        fprintf(f, "%% view factors F[i][j] from row i to column j (radiosity %s, element level)\n",
                RAD_VERSION_STRING);
        for (size_t a = 0; a < v->n; a++) {
            fprintf(f, "%% %zu ", a + 1);
            rad_write_json_string(f, s->names[a]);
            fprintf(f, " area_m2 %.17g\n", v->area[a]);
        }
    } else {
        fputs("from,area_m2", f);
        for (size_t b = 0; b < v->n; b++) {
            fputc(',', f);
            rad_csv_field(f, s->names[b]);
        }
        fputc('\n', f);
    }
    s->start = (double)ftell(f);
    *state = s;
    return RAD_OK;
}

static rad_result csv_begin(rad_context *ctx, const rad_vf_stream_info *info, void **state)
{
    return element_begin(ctx, info, false, state);
}

static rad_result mtx_begin(rad_context *ctx, const rad_vf_stream_info *info, void **state)
{
    return element_begin(ctx, info, true, state);
}

static rad_result element_row(rad_context *ctx, void *state, size_t a, const double *F_row)
{
    element_sink *s = state;
    size_t n = s->view->n;
    FILE *f = s->mtx ? s->body : s->out.file;
    if (s->mtx) {
        long before = ftell(f);
        for (size_t b = 0; b < n; b++)
            if (F_row[b] != 0.0) {
                fprintf(f, "%zu %zu %.17g\n", a + 1, b + 1, F_row[b]);
                s->nnz++;
            }
        s->body_bytes += (double)(ftell(f) - before);
    } else {
        rad_csv_field(f, s->names[a]);
        fprintf(f, ",%.17g", s->view->area[a]);
        for (size_t b = 0; b < n; b++)
            fprintf(f, ",%.17g", F_row[b]);
        fputc('\n', f);
    }
    if (ferror(f))
        return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write: %s", s->out.final_path, strerror(errno));
    return RAD_OK;
}

/* Matrix Market: the size line, then the entries copied after it. */
static rad_result mtx_join(rad_context *ctx, element_sink *s)
{
    fprintf(s->out.file, "%zu %zu %zu\n", s->view->n, s->view->n, s->nnz);
    bool ok = fclose(s->body) == 0;
    s->body = NULL;
    FILE *in = ok ? fopen(s->body_path, "rb") : NULL;
    if (!in)
        return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot read back the entries: %s", s->body_path, strerror(errno));
    char buffer[1 << 16];
    size_t got;
    while ((got = fread(buffer, 1, sizeof buffer, in)) > 0)
        if (fwrite(buffer, 1, got, s->out.file) != got)
            break;
    ok = !ferror(in) && !ferror(s->out.file);
    fclose(in);
    if (!ok)
        return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot write: %s", s->out.final_path, strerror(errno));
    return RAD_OK;
}

static rad_result element_end(rad_context *ctx, void *state, bool commit)
{
    element_sink *s = state;
    if (!s)
        return RAD_OK;
    rad_result r = RAD_OK;
    if (commit) {
        if (s->mtx)
            r = mtx_join(ctx, s);
        /* The commit closes the file, and removes it when it fails. */
        if (r == RAD_OK)
            r = rad_atomic_commit(ctx, &s->out);
        else
            rad_atomic_abort(&s->out);
        s->out.file = NULL;
    }
    element_free(s, true);
    return r;
}

static double element_estimate(const void *state, size_t rows, size_t n)
{
    const element_sink *s = state;
    if (rows == 0) /* CSV: at least ",0" per factor; Matrix Market: no entries */
        return s->mtx ? 0.0 : 2.0 * (double)n * (double)n;
    if (s->mtx) /* the rest of the entries, and all of them copied once more */
        return s->body_bytes / (double)rows * (double)(2 * n - rows);
    double done = (double)ftell(s->out.file) - s->start;
    return done / (double)rows * (double)(n - rows);
}

/* ---- surface level: sums over element rows, written at the end ---- */

typedef struct surface_sink {
    const rad_solution_view *view;
    const char *path;
    const rad_view_factor_options *factors;
    double *F;                 /* S x S: sum of A_i F_ij, then divided by the row's area */
    double *area;              /* S, m^2: the surfaces' element areas summed */
} surface_sink;

static rad_result surface_begin(rad_context *ctx, const rad_vf_stream_info *info, void **state)
{
    *state = NULL;
    size_t S = info->view->scene->surface_count;
    surface_sink *s = rad_alloc(ctx, RAD_MEM_OUTPUT, 1, sizeof *s, "view factors: stream");
    if (s) {
        s->F = rad_alloc(ctx, RAD_MEM_OUTPUT, S > 0 ? S * S : 1, sizeof *s->F, "view factors: table");
        s->area = s->F ? rad_alloc(ctx, RAD_MEM_OUTPUT, S ? S : 1, sizeof *s->area, "view factors: surface areas")
                       : NULL;
    }
    if (!s || !s->area) {
        if (s)
            rad_free(s->F);
        rad_free(s);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    s->view = info->view;
    s->path = info->path;
    s->factors = info->factors;
    *state = s;
    return RAD_OK;
}

/* The sums of rad_view_surface_view_factors, in its order (rows in turn,
 * columns in turn), so the table is the dense one bit for bit. */
static rad_result surface_row(rad_context *ctx, void *state, size_t i, const double *F_row)
{
    (void)ctx;
    surface_sink *s = state;
    const rad_solution_view *v = s->view;
    size_t S = v->scene->surface_count;
    uint32_t si = v->mesh->elements[i].surface;
    s->area[si] += v->area[i];
    double *row = s->F + (size_t)si * S;
    for (size_t j = 0; j < v->n; j++)
        row[v->mesh->elements[j].surface] += v->area[i] * F_row[j];
    return RAD_OK;
}

static rad_result surface_end(rad_context *ctx, void *state, bool commit)
{
    surface_sink *s = state;
    if (!s)
        return RAD_OK;
    rad_result r = RAD_OK;
    size_t S = s->view->scene->surface_count;
    if (commit) {
        for (size_t a = 0; a < S; a++)
            for (size_t b = 0; b < S; b++)
                s->F[a * S + b] = s->area[a] > 0.0 ? s->F[a * S + b] / s->area[a] : 0.0;
        r = rad_write_surface_view_factors(ctx, s->view, s->F, s->path, s->factors); /* takes F */
    } else {
        rad_free(s->F);
    }
    rad_free(s->area);
    rad_free(s);
    return r;
}

static const rad_vf_sink csv_sink = {"csv", true, csv_begin, element_row, element_end, element_estimate};
static const rad_vf_sink mtx_sink = {"mtx", true, mtx_begin, element_row, element_end, element_estimate};
static const rad_vf_sink surface_json = {"json", false, surface_begin, surface_row, surface_end, NULL};
static const rad_vf_sink surface_csv = {"csv", false, surface_begin, surface_row, surface_end, NULL};
static const rad_vf_sink surface_mtx = {"mtx", false, surface_begin, surface_row, surface_end, NULL};
static const rad_vf_sink surface_vf = {"vf", false, surface_begin, surface_row, surface_end, NULL};

const rad_vf_sink *const rad_vf_sinks[] = {&csv_sink,    &mtx_sink,    &surface_json, &surface_csv,
                                           &surface_mtx, &surface_vf, NULL};

const rad_vf_sink *rad_vf_sink_find(const char *path, bool elements)
{
    char ext[16];
    rad_path_extension(path, ext, sizeof ext);
    for (size_t k = 0; rad_vf_sinks[k]; k++)
        if (rad_vf_sinks[k]->elements == elements && strcmp(rad_vf_sinks[k]->extension, ext) == 0)
            return rad_vf_sinks[k];
    return NULL;
}
