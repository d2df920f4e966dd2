/*
 * stats.c -- machine-readable results: the stats JSON (schema in
 * docs/stats.md) and view factors (JSON, CSV or Matrix Market;
 * docs/formats.md).  All are written atomically (temporary file, then
 * rename).
 *
 * Names (surfaces, the scene's path) come from the user's files and may
 * hold any byte but NUL.  Every writer carries them as valid UTF-8, each
 * byte that does not begin a well-formed sequence (RFC 3629: no overlong
 * forms, no surrogates, nothing above U+10FFFF) replaced by U+FFFD, and
 * then in its own syntax: JSON strings escaped by cJSON (quotes,
 * backslashes, control characters), CSV fields quoted per RFC 4180, Matrix
 * Market comments holding the name as a JSON string, so that no name can
 * end a line or forge one.
 */
#include "output/output.h"
#include "output/view3d.h"
#include "photometry/layout.h"
#include "photometry/photometry.h"

#include <cjson/cJSON.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

/* Length of the well-formed UTF-8 sequence at p (1-4), or 0 (RFC 3629,
 * table 3-7 of the Unicode standard). */
static int utf8_sequence(const unsigned char *p)
{
    unsigned char c = p[0];
    if (c < 0x80)
        return 1;
    int len = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
    if (len == 0)
        return 0;
    /* The second byte's range depends on the first (overlongs, surrogates, > U+10FFFF). */
    unsigned char lo = c == 0xe0 ? 0xa0 : c == 0xf0 ? 0x90 : 0x80;
    unsigned char hi = c == 0xed ? 0x9f : c == 0xf4 ? 0x8f : 0xbf;
    if (p[1] < lo || p[1] > hi)
        return 0;
    for (int k = 2; k < len; k++)
        if (p[k] < 0x80 || p[k] > 0xbf)
            return 0;
    return len;
}

/* As output.h says: the rule above; NULL when out of memory (the
 * allocator's message is set). */
char *rad_utf8_clean(rad_context *ctx, const char *text)
{
    size_t len = strlen(text);
    char *out = rad_alloc(ctx, RAD_MEM_OUTPUT, 3 * len + 1, 1, "outputs: names");
    if (!out)
        return NULL;
    const unsigned char *p = (const unsigned char *)text;
    char *q = out;
    while (*p) {
        int k = utf8_sequence(p);
        if (k > 0) {
            memcpy(q, p, (size_t)k);
            q += k;
            p += k;
        } else {
            memcpy(q, "\xef\xbf\xbd", 3); /* U+FFFD for the one byte */
            q += 3;
            p++;
        }
    }
    *q = '\0';
    return out;
}

/* Add `text` to a JSON object as valid UTF-8.  Fails only for memory. */
static rad_result add_text(rad_context *ctx, cJSON *object, const char *key, const char *text)
{
    char *clean = rad_utf8_clean(ctx, text ? text : "");
    if (!clean)
        return RAD_ERROR_OUT_OF_MEMORY;
    cJSON_AddStringToObject(object, key, clean);
    rad_free(clean);
    return RAD_OK;
}

static cJSON *rgb_array(const double v[3])
{
    return cJSON_CreateDoubleArray(v, 3);
}

rad_result rad_write_json(rad_context *ctx, cJSON *root, const char *path)
{
    char *text = root ? cJSON_Print(root) : NULL;
    if (!text)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory building JSON", path);
    rad_atomic_file f;
    rad_result r = rad_atomic_open(ctx, path, &f);
    if (r == RAD_OK) {
        fputs(text, f.file);
        fputc('\n', f.file);
        r = rad_atomic_commit(ctx, &f);
    }
    cJSON_free(text);
    return r;
}

/* Area-weighted means per surface of reflectance, emission and radiosity,
 * in one pass over the elements (9 doubles per surface: rho, E, B), so
 * that scenes of 10^5 surfaces and 10^6 elements are not S x n.  NULL when
 * out of memory. */
static double *surface_means(rad_context *ctx, const rad_solution_view *s)
{
    size_t S = s->scene->surface_count;
    double *m = rad_alloc(ctx, RAD_MEM_OUTPUT, 9 * S, sizeof *m, "stats: surface means");
    double *area = m ? rad_alloc(ctx, RAD_MEM_OUTPUT, S, sizeof *area, "stats: surface means") : NULL;
    if (!area) {
        rad_free(m);
        return NULL;
    }
    for (size_t i = 0; i < s->n; i++) {
        size_t k = s->mesh->elements[i].surface;
        double a = s->area[i];
        area[k] += a;
        for (int c = 0; c < 3; c++) {
            m[9 * k + (size_t)c] += a * s->reflectance[3 * i + (size_t)c];
            m[9 * k + 3 + (size_t)c] += a * s->emission[3 * i + (size_t)c];
            m[9 * k + 6 + (size_t)c] += a * s->radiosity[3 * i + (size_t)c];
        }
    }
    for (size_t k = 0; k < S; k++)
        for (int q = 0; q < 9; q++)
            m[9 * k + (size_t)q] = area[k] > 0.0 ? m[9 * k + (size_t)q] / area[k] : 0.0;
    rad_free(area);
    return m;
}

rad_result rad_scene_write_interrupted_stats(rad_context *ctx, const rad_scene *scene, const char *phase,
                                            double seconds, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !scene || !phase || !path)
        return rad_null_argument(ctx, __func__);
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    cJSON_AddStringToObject(root, "version", RAD_VERSION_STRING);
    cJSON_AddBoolToObject(root, "partial", 1);
    cJSON_AddStringToObject(root, "interrupted", phase);
    cJSON_AddBoolToObject(root, "converged", 0);
    rad_result r = add_text(ctx, root, "scene", scene->source);
    cJSON_AddNumberToObject(root, "surfaces", (double)scene->surface_count);
    cJSON *sec = cJSON_AddObjectToObject(root, "seconds");
    cJSON_AddNumberToObject(sec, "total", seconds);
    if (r == RAD_OK)
        r = rad_write_json(ctx, root, path);
    cJSON_Delete(root);
    return r;
}

rad_result rad_write_stats(rad_context *ctx, const rad_solution_view *s, const char *path, bool partial)
{
    return rad_write_stats_extra(ctx, s, path, partial, NULL, NULL);
}

rad_result rad_write_stats_extra(rad_context *ctx, const rad_solution_view *s, const char *path, bool partial,
                                 rad_stats_extra_fn extra, const void *user)
{
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    size_t n = s->n;
    cJSON_AddStringToObject(root, "version", RAD_VERSION_STRING);
    cJSON_AddBoolToObject(root, "partial", partial);
    rad_result r = add_text(ctx, root, "scene", s->scene->source);
    cJSON_AddNumberToObject(root, "threads", rad_context_threads(ctx));
    /* The seed as its exact digits: a JSON number is text, and a double
     * rounds seeds above 2^53 (9007199254740993 was written ...992). */
    char seed[24];
    snprintf(seed, sizeof seed, "%" PRIu64, s->options->seed);
    cJSON_AddRawToObject(root, "seed", seed);

    cJSON *mesh = cJSON_AddObjectToObject(root, "mesh");
    cJSON_AddNumberToObject(mesh, "elements", (double)n);
    cJSON_AddNumberToObject(mesh, "patches", (double)s->mesh->patch_count);
    cJSON_AddNumberToObject(mesh, "vertices", (double)s->mesh->vertex_count);
    cJSON_AddNumberToObject(mesh, "t_vertices", (double)s->mesh->tvertex_count);
    cJSON_AddNumberToObject(mesh, "mesh_size_m", s->mesh->mesh_size);
    if (s->adaptive) {
        cJSON *ad = cJSON_AddObjectToObject(mesh, "adaptive");
        cJSON_AddNumberToObject(ad, "levels", s->options->adaptive_levels);
        cJSON_AddNumberToObject(ad, "threshold", s->options->adaptive_threshold);
        cJSON_AddNumberToObject(ad, "initial_elements", (double)s->adaptive->initial_elements);
        cJSON_AddNumberToObject(ad, "rounds", s->adaptive->rounds);
        cJSON_AddNumberToObject(ad, "split", (double)s->adaptive->split);
        cJSON_AddNumberToObject(ad, "balanced", (double)s->adaptive->balanced);
    }
    cJSON_AddNumberToObject(root, "elements", (double)n);

    cJSON *ff = cJSON_AddObjectToObject(root, "form_factors");
    cJSON_AddStringToObject(ff, "method", s->ff->method ? s->ff->method : "");
    cJSON_AddStringToObject(ff, "visibility", s->options->visibility);
    cJSON_AddNumberToObject(ff, "shadow_rays", s->options->shadow_rays);
    cJSON_AddNumberToObject(ff, "rays", (double)s->ff->rays);
    cJSON_AddNumberToObject(ff, "pairs", (double)s->ff->pairs);
    cJSON_AddNumberToObject(ff, "row_sum_min", s->ff->row_sum_min);
    cJSON_AddNumberToObject(ff, "row_sum_max", s->ff->row_sum_max);
    cJSON_AddNumberToObject(ff, "row_sum_mean", s->ff->row_sum_mean);
    cJSON_AddNumberToObject(ff, "reciprocity_max", s->ff->reciprocity_max);
    cJSON_AddNumberToObject(ff, "diagonal_max", s->ff->diagonal_max);
    cJSON_AddBoolToObject(ff, "closure_corrected", s->ff->closure_corrected);
    cJSON_AddBoolToObject(ff, "reciprocity_enforced", s->ff->balanced);
    if (s->ff->balanced) { /* what the method estimated, and how far rows were scaled */
        cJSON_AddNumberToObject(ff, "raw_reciprocity_max", s->ff->raw_reciprocity_max);
        cJSON_AddNumberToObject(ff, "raw_row_sum_max", s->ff->raw_row_sum_max);
        cJSON_AddNumberToObject(ff, "closure_scale_min", s->ff->closure_scale_min);
        cJSON_AddNumberToObject(ff, "closure_scale_max", s->ff->closure_scale_max);
    }
    if (s->options->closure_correction) /* the openness measured before correcting */
        cJSON_AddNumberToObject(ff, "escaped", s->ff->escaped);
    if (s->F_variance)
        cJSON_AddNumberToObject(ff, "std_error_max", s->ff->std_error_max);
    if (s->ff->near_pairs)
        cJSON_AddNumberToObject(ff, "near_pairs", (double)s->ff->near_pairs);
    cJSON_AddNumberToObject(ff, "seconds", s->ff->seconds);

    cJSON *so = cJSON_AddObjectToObject(root, "solver");
    cJSON_AddStringToObject(so, "method", s->options->solver);
    cJSON_AddBoolToObject(so, "solved", s->solved);
    cJSON_AddBoolToObject(so, "converged", s->solve->converged && !s->ended_early);
    cJSON_AddNumberToObject(so, "iterations", s->solve->iterations);
    cJSON_AddNumberToObject(so, "iteration_limit", s->solve->iteration_limit);
    cJSON_AddNumberToObject(so, "residual", s->solve->residual);
    cJSON_AddNumberToObject(so, "tolerance", s->options->tolerance);
    cJSON_AddNumberToObject(so, "relaxation", s->options->relaxation);
    if (!isnan(s->solve->unshot))
        cJSON_AddNumberToObject(so, "unshot", s->solve->unshot);
    if (s->ended_early)
        cJSON_AddStringToObject(so, "warning", s->ended_early);
    else if (s->solved && !s->solve->converged && s->solve->warning[0])
        cJSON_AddStringToObject(so, "warning", s->solve->warning);
    cJSON_AddNumberToObject(so, "components", (double)s->solve->components);
    cJSON_AddNumberToObject(so, "components_lit", (double)s->solve->components_lit);
    cJSON_AddItemToObject(so, "ambient", rgb_array(s->solve->ambient));
    cJSON_AddNumberToObject(so, "seconds", s->solve->seconds);
    if (s->solve->vpl_lights > 0) { /* instant radiosity: the VPLs and the clamp's bias */
        cJSON *ir = cJSON_AddObjectToObject(so, "instant_radiosity");
        cJSON_AddNumberToObject(ir, "paths", (double)s->solve->vpl_paths);
        cJSON_AddNumberToObject(ir, "lights", (double)s->solve->vpl_lights);
        cJSON_AddNumberToObject(ir, "clamp_radius_m", s->solve->vpl_clamp_radius);
        cJSON_AddNumberToObject(ir, "clamp_loss", s->solve->vpl_clamp_loss);
        cJSON_AddNumberToObject(ir, "clamp_loss_unclamped", s->solve->vpl_clamp_loss_unclamped);
        cJSON_AddBoolToObject(ir, "compensated", s->solve->vpl_compensated);
    }
    if (s->solve->cv_groups > 0) { /* shooting, instant radiosity: B = beta + B' */
        cJSON *cv = cJSON_AddObjectToObject(so, "control_variate");
        cJSON_AddNumberToObject(cv, "groups", (double)s->solve->cv_groups);
        cJSON_AddNumberToObject(cv, "groups_varied", (double)s->solve->cv_groups_varied);
        cJSON_AddItemToObject(cv, "beta", rgb_array(s->solve->cv_beta));
        cJSON_AddNumberToObject(cv, "rays", (double)s->solve->cv_rays);
    }
    if (s->hier) {
        const rad_hier_stats *h = s->hier;
        cJSON *hi = cJSON_AddObjectToObject(so, "hierarchical");
        cJSON_AddNumberToObject(hi, "epsilon", s->options->epsilon > 0.0 ? s->options->epsilon : 1e-4);
        cJSON_AddNumberToObject(hi, "epsilon_W", h->epsilon_abs);
        cJSON_AddNumberToObject(hi, "min_area_m2", h->min_area);
        cJSON_AddBoolToObject(hi, "clustered", h->clustered);
        cJSON_AddStringToObject(hi, "oracle", h->classic_oracle ? "classic" : "sources");
        cJSON_AddNumberToObject(hi, "closure_corrected_leaves", (double)h->closure_corrected);
        cJSON_AddNumberToObject(hi, "patches", (double)s->hier->patches);
        cJSON_AddNumberToObject(hi, "clusters", (double)h->clusters);
        cJSON_AddNumberToObject(hi, "nodes", (double)h->nodes);
        cJSON_AddNumberToObject(hi, "leaves", (double)h->leaves);
        cJSON_AddNumberToObject(hi, "links", (double)h->links);
        cJSON_AddNumberToObject(hi, "initial_links", (double)h->initial_links);
        cJSON_AddNumberToObject(hi, "mirror_links", (double)h->mirror_links);
        cJSON *kinds = cJSON_AddObjectToObject(hi, "links_by_kind");
        cJSON_AddNumberToObject(kinds, "surface_from_surface", (double)h->links_by_kind[0]);
        cJSON_AddNumberToObject(kinds, "surface_from_cluster", (double)h->links_by_kind[1]);
        cJSON_AddNumberToObject(kinds, "cluster_from_surface", (double)h->links_by_kind[2]);
        cJSON_AddNumberToObject(kinds, "cluster_from_cluster", (double)h->links_by_kind[3]);
        cJSON_AddNumberToObject(hi, "links_per_leaf", h->leaves ? (double)h->links / (double)h->leaves : 0.0);
        cJSON_AddNumberToObject(hi, "bytes_per_link", h->link_bytes);
        cJSON_AddNumberToObject(hi, "memory_bytes", h->bytes);
        cJSON *closure = cJSON_AddObjectToObject(hi, "closure");
        cJSON_AddNumberToObject(closure, "mean", h->closure_mean);
        cJSON_AddNumberToObject(closure, "power_weighted", h->closure_power);
        cJSON_AddNumberToObject(closure, "min", h->closure_min);
        cJSON_AddNumberToObject(closure, "max", h->closure_max);
        cJSON *balance = cJSON_AddObjectToObject(hi, "balance");
        cJSON_AddNumberToObject(balance, "leaves", (double)h->balanced_leaves);
        cJSON_AddNumberToObject(balance, "iterations", h->balance_iterations);
        cJSON_AddNumberToObject(balance, "residual", h->balance_residual);
        cJSON_AddNumberToObject(balance, "scale_min", h->balance_scale_min);
        cJSON_AddNumberToObject(balance, "scale_max", h->balance_scale_max);
        cJSON_AddNumberToObject(hi, "refine_rounds", h->refine_rounds);
        cJSON_AddNumberToObject(hi, "refine_passes", h->refine_passes);
        cJSON_AddNumberToObject(hi, "rays", (double)h->rays);
        cJSON_AddNumberToObject(hi, "shafts", (double)h->shafts);
        cJSON_AddNumberToObject(hi, "shafts_clear", (double)h->shafts_clear);
        cJSON_AddNumberToObject(hi, "seconds_refine", h->seconds_refine);
        cJSON_AddNumberToObject(hi, "seconds_direct", h->seconds_direct);
        cJSON_AddNumberToObject(hi, "seconds_open", h->seconds_open);
        cJSON_AddNumberToObject(hi, "seconds_solve", h->seconds_solve);
        cJSON_AddNumberToObject(hi, "seconds_mesh", h->seconds_mesh);
    }

    double emitted, absorbed;
    if (rad_view_power(ctx, s, &emitted, &absorbed) != RAD_OK) {
        cJSON_Delete(root);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    cJSON *power = cJSON_AddObjectToObject(root, "power_W");
    cJSON_AddNumberToObject(power, "emitted", emitted);
    cJSON_AddNumberToObject(power, "absorbed", absorbed);
    cJSON_AddNumberToObject(power, "escaped", emitted - absorbed);
    if (s->scene->luminaires.count > 0) {
        /* The luminaires (docs/lighting.md): their flux, and the direct
         * light landing on the elements, lm = 179 Y(A H_d). */
        double lumens = 0.0, landing = 0.0;
        for (size_t k = 0; k < s->scene->luminaires.count; k++)
            lumens += rad_luminaire_flux(&s->scene->luminaires, k);
        for (size_t i = 0; s->direct && i < s->n; i++) {
            const double *h = s->direct + 3 * i;
            landing += s->area[i] * (RAD_Y_R * h[0] + RAD_Y_G * h[1] + RAD_Y_B * h[2]);
        }
        cJSON *lum = cJSON_AddObjectToObject(root, "luminaires");
        cJSON_AddNumberToObject(lum, "count", (double)s->scene->luminaires.count);
        cJSON_AddNumberToObject(lum, "lumens", lumens);
        cJSON_AddNumberToObject(lum, "direct_lumens", RAD_LUMINOUS_EFFICACY * landing);
    }

    cJSON *surfaces = cJSON_AddArrayToObject(root, "surfaces");
    double *means = surface_means(ctx, s);
    if (!means) {
        cJSON_Delete(root);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t k = 0; k < s->scene->surface_count && r == RAD_OK; k++) {
        cJSON *o = cJSON_CreateObject();
        r = add_text(ctx, o, "name", s->scene->surfaces[k].name);
        cJSON_AddNumberToObject(o, "area", s->scene->surfaces[k].area);
        cJSON_AddItemToObject(o, "reflectance", rgb_array(&means[9 * k]));
        cJSON_AddItemToObject(o, "emission", rgb_array(&means[9 * k + 3]));
        cJSON_AddItemToObject(o, "radiosity", rgb_array(&means[9 * k + 6]));
        cJSON_AddItemToArray(surfaces, o);
    }
    rad_free(means);

    cJSON *sec = cJSON_AddObjectToObject(root, "seconds");
    cJSON_AddNumberToObject(sec, "load", s->seconds.load);
    cJSON_AddNumberToObject(sec, "mesh", s->seconds.mesh);
    cJSON_AddNumberToObject(sec, "visibility_build", s->seconds.visibility);
    cJSON_AddNumberToObject(sec, "form_factors", s->seconds.form_factors);
    cJSON_AddNumberToObject(sec, "solve", s->seconds.solve);
    cJSON_AddNumberToObject(sec, "render", s->seconds.render);

    cJSON *rays = cJSON_AddObjectToObject(root, "rays");
    cJSON_AddNumberToObject(rays, "form_factors", (double)s->ff->rays);
    cJSON_AddNumberToObject(rays, "solve", (double)s->solve->rays);
    cJSON_AddNumberToObject(rays, "render", (double)s->render_rays);

    cJSON *mem = cJSON_AddObjectToObject(root, "memory_bytes");
    cJSON_AddNumberToObject(mem, "peak_resident", (double)rad_peak_memory_bytes());
    cJSON_AddNumberToObject(mem, "form_factor_matrix", s->F ? (double)n * (double)n * sizeof(double) : 0.0);
    cJSON_AddNumberToObject(mem, "limit", s->options->max_memory_bytes);
    /* The allocator's figures: everything the engine itself holds in this
     * context, at its peak, and each stage's peak (docs/stats.md). */
    cJSON_AddNumberToObject(mem, "allocator_peak", (double)rad_memory_peak(ctx, RAD_MEM_CATEGORIES));
    cJSON *by_category = cJSON_AddObjectToObject(mem, "by_category");
    for (int c = 0; c < RAD_MEM_CATEGORIES; c++)
        cJSON_AddNumberToObject(by_category, rad_memory_category_name((rad_memory_category)c),
                                (double)rad_memory_peak(ctx, (rad_memory_category)c));

    if (r == RAD_OK && extra)
        r = extra(ctx, root, user);
    if (r == RAD_OK)
        r = rad_write_json(ctx, root, path);
    cJSON_Delete(root);
    return r;
}

/* Surface-level standard errors from element variances (independent
 * estimates): var F_IJ = sum_{i in I} (A_i / A_I)^2 sum_{j in J} var F_ij.
 * Fails only for memory. */
static rad_result surface_std_errors(rad_context *ctx, const rad_solution_view *s, double *err)
{
    size_t S = s->scene->surface_count, n = s->n;
    double *area = rad_alloc(ctx, RAD_MEM_OUTPUT, S, sizeof *area, "view factors: surface areas");
    if (!area)
        return RAD_ERROR_OUT_OF_MEMORY;
    memset(err, 0, S * S * sizeof *err);
    for (size_t i = 0; i < n; i++)
        area[s->mesh->elements[i].surface] += s->area[i];
    for (size_t i = 0; i < n; i++) {
        uint32_t si = s->mesh->elements[i].surface;
        double w = s->area[i] / area[si];
        for (size_t j = 0; j < n; j++)
            err[(size_t)si * S + s->mesh->elements[j].surface] += w * w * s->F_variance[i * n + j];
    }
    for (size_t k = 0; k < S * S; k++)
        err[k] = sqrt(err[k]);
    rad_free(area);
    return RAD_OK;
}

/* As output.h says. */
void rad_csv_field(FILE *f, const char *text)
{
    size_t len = strlen(text);
    bool blank_edge = len > 0 && (strchr(" \t", text[0]) || strchr(" \t", text[len - 1]));
    if (!strpbrk(text, ",\"\r\n") && !blank_edge) {
        fputs(text, f);
        return;
    }
    fputc('"', f);
    for (const char *c = text; *c; c++) {
        if (*c == '"')
            fputc('"', f);
        fputc(*c, f);
    }
    fputc('"', f);
}

/* A JSON string literal, for the Matrix Market comments: quotes,
 * backslashes and control characters escaped (RFC 8259, sec. 7); `text`
 * is valid UTF-8, written as is otherwise. */
static void json_string(FILE *f, const char *text)
{
    fputc('"', f);
    for (const unsigned char *c = (const unsigned char *)text; *c; c++) {
        switch (*c) {
        case '"': fputs("\\\"", f); break;
        case '\\': fputs("\\\\", f); break;
        case '\n': fputs("\\n", f); break;
        case '\r': fputs("\\r", f); break;
        case '\t': fputs("\\t", f); break;
        default:
            if (*c < 0x20 || *c == 0x7f)
                fprintf(f, "\\u%04x", *c);
            else
                fputc(*c, f);
        }
    }
    fputc('"', f);
}

/* Names (valid UTF-8, rad_utf8_clean) and areas of the rows of the matrix being
 * written: surfaces, or elements ("surface#k", k counting the surface's
 * elements). */
typedef struct vf_rows {
    size_t count;
    char **names;
    double *area;
    double *F;      /* count x count */
    double *err;    /* count x count standard errors, or NULL */
    size_t *kept;   /* surface level: the scene surface of each row (view3d.c) */
} vf_rows;

static void vf_rows_free(vf_rows *r)
{
    for (size_t k = 0; r->names && k < r->count; k++)
        rad_free(r->names[k]);
    rad_free(r->names);
    rad_free(r->area);
    rad_free(r->F);
    rad_free(r->err);
    rad_free(r->kept);
    memset(r, 0, sizeof *r);
}

/* A JSON array of doubles that read back as the same doubles: each in the
 * fewest of 15, 16 or 17 significant digits that strtod returns exactly
 * (cJSON's own numbers stop at 15 digits when they are within 2 ulp).
 * NULL when memory runs out. */
static cJSON *exact_array(const double *v, size_t count)
{
    cJSON *array = cJSON_CreateArray();
    for (size_t k = 0; array && k < count; k++) {
        char text[32];
        for (int digits = 15; digits <= 17; digits++) {
            snprintf(text, sizeof text, "%.*g", digits, v[k]);
            if (strtod(text, NULL) == v[k])
                break;
        }
        cJSON *item = cJSON_CreateRaw(text);
        if (!item) {
            cJSON_Delete(array);
            return NULL;
        }
        cJSON_AddItemToArray(array, item);
    }
    return array;
}

/* The surface level's rows once F (and err) hold the S x S table: names,
 * areas, then the thermal outputs' adjustments (obstruction surfaces out,
 * smoothing, sparsity: view3d.c), which may drop rows.  r->count = S. */
static rad_result surface_rows_finish(rad_context *ctx, const rad_solution_view *s, const rad_view_factor_options *o,
                                      vf_rows *r)
{
    size_t S = s->scene->surface_count;
    r->names = rad_alloc(ctx, RAD_MEM_OUTPUT, S ? S : 1, sizeof *r->names, "view factors: names");
    r->area = r->names ? rad_alloc(ctx, RAD_MEM_OUTPUT, S ? S : 1, sizeof *r->area, "view factors: areas") : NULL;
    r->kept = r->area ? rad_alloc(ctx, RAD_MEM_OUTPUT, S ? S : 1, sizeof *r->kept, "view factors") : NULL;
    if (!r->kept)
        return RAD_ERROR_OUT_OF_MEMORY;
    for (size_t k = 0; k < S; k++) {
        r->names[k] = rad_utf8_clean(ctx, s->scene->surfaces[k].name);
        r->area[k] = s->scene->surfaces[k].area;
        if (!r->names[k])
            return RAD_ERROR_OUT_OF_MEMORY;
    }
    rad_result result = rad_vf_adjust(ctx, s->scene, r->names, r->area, r->F, &r->count, r->kept, o);
    if (result == RAD_OK && r->err) {
        size_t N = r->count;
        for (size_t a = 0; a < N; a++)
            for (size_t b = 0; b < N; b++)
                r->err[a * N + b] = r->err[r->kept[a] * S + r->kept[b]];
    }
    return result;
}

static rad_result vf_rows_build(rad_context *ctx, const rad_solution_view *s, bool elements,
                                const rad_view_factor_options *o, vf_rows *r)
{
    memset(r, 0, sizeof *r);
    size_t n = s->n, S = s->scene->surface_count;
    r->count = elements ? n : S;
    bool with_err = s->F_variance != NULL;
    double bytes = (double)r->count * (double)r->count * sizeof *r->F * (with_err ? 2.0 : 1.0);
    double held = (double)n * (double)n * sizeof *s->F; /* F itself, beside the table */
    if (bytes + held > s->options->max_memory_bytes)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                        "view factors: the %zu x %zu table needs %.2f GiB beside the %.2f GiB form-factor "
                        "matrix, above the memory limit of %.2f GiB (rad_options.max_memory_bytes); use "
                        "surface-level view factors or fewer rad_options.target_elements",
                        r->count, r->count, bytes / 1073741824.0, held / 1073741824.0,
                        s->options->max_memory_bytes / 1073741824.0);
    if (elements) { /* the surface level names its rows in surface_rows_finish */
        r->names = rad_alloc(ctx, RAD_MEM_OUTPUT, r->count, sizeof *r->names, "view factors: names");
        r->area = r->names ? rad_alloc(ctx, RAD_MEM_OUTPUT, r->count, sizeof *r->area, "view factors: areas")
                           : NULL;
    }
    r->F = !elements || r->area
               ? rad_alloc(ctx, RAD_MEM_OUTPUT, r->count * r->count, sizeof *r->F, "view factors: table")
               : NULL;
    if (r->F && with_err)
        r->err = rad_alloc(ctx, RAD_MEM_OUTPUT, r->count * r->count, sizeof *r->err, "view factors: errors");
    if (!r->F || (with_err && !r->err)) {
        vf_rows_free(r);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    rad_result result = RAD_OK;
    if (!elements) {
        result = rad_view_surface_view_factors(ctx, s, r->F);
        if (result == RAD_OK && with_err)
            result = surface_std_errors(ctx, s, r->err);
        if (result == RAD_OK)
            result = surface_rows_finish(ctx, s, o, r);
    } else {
        size_t *seen = rad_alloc(ctx, RAD_MEM_OUTPUT, S, sizeof *seen, "view factors: names");
        if (!seen)
            result = RAD_ERROR_OUT_OF_MEMORY;
        for (size_t i = 0; i < n && result == RAD_OK; i++) {
            uint32_t si = s->mesh->elements[i].surface;
            char *surface = rad_utf8_clean(ctx, s->scene->surfaces[si].name);
            size_t size = surface ? strlen(surface) + 24 : 0;
            r->names[i] = surface ? rad_alloc(ctx, RAD_MEM_OUTPUT, size, 1, "view factors: names") : NULL;
            if (r->names[i])
                snprintf(r->names[i], size, "%s#%zu", surface, seen[si]++);
            else
                result = RAD_ERROR_OUT_OF_MEMORY;
            rad_free(surface);
            r->area[i] = s->area[i];
            for (size_t j = 0; j < n; j++) {
                r->F[i * n + j] = s->F[i * n + j];
                if (with_err)
                    r->err[i * n + j] = sqrt(s->F_variance[i * n + j]);
            }
        }
        rad_free(seen);
    }
    if (result != RAD_OK)
        vf_rows_free(r);
    return result;
}

/* Surface-level or element-level view factors, from `given` (a surface
 * level S x S table made elsewhere, in its F only: taken over and freed
 * here) or, when NULL, from the view's F. */
static rad_result write_view_factors(rad_context *ctx, const rad_solution_view *s, const char *path,
                                     const rad_view_factor_options *options, vf_rows *given);

rad_result rad_write_view_factors(rad_context *ctx, const rad_solution_view *s, const char *path,
                                  bool elements)
{
    rad_view_factor_options o = {0};
    o.elements = elements;
    return write_view_factors(ctx, s, path, &o, NULL);
}

rad_result rad_write_view_factors_with(rad_context *ctx, const rad_solution_view *s, const char *path,
                                       const rad_view_factor_options *options)
{
    return write_view_factors(ctx, s, path, options, NULL);
}

static rad_result write_view_factors(rad_context *ctx, const rad_solution_view *s, const char *path,
                                     const rad_view_factor_options *options, vf_rows *given)
{
    char ext[16];
    rad_path_extension(path, ext, sizeof ext);
    bool elements = options->elements;
    const char *refusal = NULL;
    if (strcmp(ext, "json") != 0 && strcmp(ext, "csv") != 0 && strcmp(ext, "mtx") != 0 && strcmp(ext, "vf") != 0)
        refusal = "unknown view-factor format (use .json, .csv, .mtx or .vf)";
    else if (elements && (options->smooth || options->sparse_threshold > 0.0 || strcmp(ext, "vf") == 0))
        refusal = "element-level factors are written as computed: smoothing, sparse thresholds and View3D "
                  "files (.vf) are for surface-level factors";
    else if (options->sparse_threshold > 0.0 && strcmp(ext, "mtx") != 0)
        refusal = "a sparse threshold is for Matrix Market output (.mtx)";
    if (refusal || (!s->F && !given)) {
        if (given)
            vf_rows_free(given);
        if (refusal)
            return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: %s", path, refusal);
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: no view factors: solver '%s' computes no "
                        "form-factor matrix", path, s->options->solver);
    }
    rad_view_factor_options vo = *options;
    /* View3D normalises an enclosure (encl=1) before writing its file. */
    bool view3d = strcmp(ext, "vf") == 0;
    if (view3d && vo.smooth == RAD_SMOOTH_NONE && s->scene->view3d.present && s->scene->view3d.enclosure)
        vo.smooth = RAD_SMOOTH_ENCLOSURE;
    vf_rows rows;
    rad_result r;
    if (given) {
        rows = *given;
        r = surface_rows_finish(ctx, s, &vo, &rows);
        if (r != RAD_OK)
            vf_rows_free(&rows);
    } else {
        r = vf_rows_build(ctx, s, elements, &vo, &rows);
    }
    if (r != RAD_OK)
        return r;
    size_t N = rows.count;
    if (vo.nonzeros) {
        *vo.nonzeros = 0;
        for (size_t k = 0; k < N * N; k++)
            *vo.nonzeros += rows.F[k] != 0.0;
    }
    if (view3d) {
        int format = s->scene->view3d.present ? s->scene->view3d.out_format : 0;
        double *emissivity = rad_alloc(ctx, RAD_MEM_OUTPUT, N ? N : 1, sizeof *emissivity, "view factors");
        rad_atomic_file f;
        r = emissivity ? rad_atomic_open(ctx, path, &f) : RAD_ERROR_OUT_OF_MEMORY;
        if (r == RAD_OK) {
            for (size_t a = 0; a < N; a++)
                emissivity[a] = rad_surface_emissivity(s->scene, rows.kept[a]);
            int emit = s->scene->view3d.present && s->scene->view3d.emittances;
            if (emit) /* after the smoothing, as View3D normalises before IntFac */
                r = rad_vf_script_f(ctx, N, emissivity, rows.F);
            if (r == RAD_OK)
                r = rad_view3d_write_header(ctx, f.file, format,
                                            s->scene->view3d.present ? s->scene->view3d.enclosure : 0, emit, N,
                                            rows.area);
            for (size_t a = 0; a < N && r == RAD_OK; a++)
                rad_view3d_write_row(f.file, format, rows.F + a * N, N);
            if (r == RAD_OK) {
                rad_view3d_write_end(f.file, format, emissivity, N);
                r = rad_atomic_commit(ctx, &f);
            } else {
                rad_atomic_abort(&f);
            }
        }
        rad_free(emissivity);
        vf_rows_free(&rows);
        return r;
    }
    if (strcmp(ext, "json") == 0) {
        cJSON *root = cJSON_CreateObject();
        r = add_text(ctx, root, "scene", s->scene->source);
        cJSON_AddStringToObject(root, "method", s->options->form_factors);
        cJSON_AddStringToObject(root, "level", elements ? "element" : "surface");
        cJSON_AddNumberToObject(root, "elements", (double)s->n);
        cJSON_AddBoolToObject(root, "closure_corrected", s->ff->closure_corrected);
        cJSON *list = cJSON_AddArrayToObject(root, elements ? "elements_list" : "surfaces");
        cJSON *F = cJSON_AddArrayToObject(root, "F");
        cJSON *E = rows.err ? cJSON_AddArrayToObject(root, "F_std_error") : NULL;
        for (size_t a = 0; a < N && r == RAD_OK; a++) {
            double sum = 0.0;
            for (size_t b = 0; b < N; b++)
                sum += rows.F[a * N + b];
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "name", rows.names[a]);
            if (elements)
                r = add_text(ctx, o, "surface", s->scene->surfaces[s->mesh->elements[a].surface].name);
            cJSON_AddNumberToObject(o, "area", rows.area[a]);
            cJSON_AddNumberToObject(o, "row_sum", sum);
            cJSON_AddItemToArray(list, o);
            cJSON_AddItemToArray(F, exact_array(rows.F + a * N, N));
            if (E)
                cJSON_AddItemToArray(E, cJSON_CreateDoubleArray(rows.err + a * N, (int)N));
        }
        if (r == RAD_OK)
            r = rad_write_json(ctx, root, path);
        cJSON_Delete(root);
    } else {
        rad_atomic_file f;
        r = rad_atomic_open(ctx, path, &f);
        if (r == RAD_OK && strcmp(ext, "csv") == 0) {
            /* Header: from,area_m2,<to names...>; one row per emitting surface/element. */
            fputs("from,area_m2", f.file);
            for (size_t b = 0; b < N; b++) {
                fputc(',', f.file);
                rad_csv_field(f.file, rows.names[b]);
            }
            fputc('\n', f.file);
            for (size_t a = 0; a < N; a++) {
                rad_csv_field(f.file, rows.names[a]);
                fprintf(f.file, ",%.17g", rows.area[a]);
                for (size_t b = 0; b < N; b++)
                    fprintf(f.file, ",%.17g", rows.F[a * N + b]);
                fputc('\n', f.file);
            }
        } else if (r == RAD_OK) {
            /* Matrix Market coordinate format, 1-based, nonzeros only; the
             * comments carry the row names and areas (docs/formats.md). */
            size_t nnz = 0;
            for (size_t k = 0; k < N * N; k++)
                nnz += rows.F[k] != 0.0;
            fprintf(f.file, "%%%%MatrixMarket matrix coordinate real general\n");
            fprintf(f.file, "%% view factors F[i][j] from row i to column j (radiosity %s, %s level)\n",
                    RAD_VERSION_STRING, elements ? "element" : "surface");
            for (size_t a = 0; a < N; a++) {
                fprintf(f.file, "%% %zu ", a + 1);
                json_string(f.file, rows.names[a]);
                fprintf(f.file, " area_m2 %.17g\n", rows.area[a]);
            }
            fprintf(f.file, "%zu %zu %zu\n", N, N, nnz);
            for (size_t a = 0; a < N; a++)
                for (size_t b = 0; b < N; b++)
                    if (rows.F[a * N + b] != 0.0)
                        fprintf(f.file, "%zu %zu %.17g\n", a + 1, b + 1, rows.F[a * N + b]);
        }
        if (r == RAD_OK)
            r = rad_atomic_commit(ctx, &f);
    }
    vf_rows_free(&rows);
    return r;
}

/* ---- for the streamed view factors (vf_stream.c) ---- */

void rad_write_json_string(FILE *f, const char *text)
{
    json_string(f, text);
}

rad_result rad_write_surface_view_factors(rad_context *ctx, const rad_solution_view *view, double *F,
                                          const char *path, const rad_view_factor_options *options)
{
    vf_rows rows = {.count = view->scene->surface_count, .F = F};
    rad_view_factor_options o = options ? *options : (rad_view_factor_options){0};
    o.elements = false;
    return write_view_factors(ctx, view, path, &o, &rows);
}

rad_result rad_write_history(rad_context *ctx, const rad_solve_step *steps, size_t count, const char *path)
{
    rad_atomic_file f;
    rad_result r = rad_atomic_open(ctx, path, &f);
    if (r != RAD_OK)
        return r;
    fputs("iteration,seconds,residual,unshot\n", f.file);
    for (size_t k = 0; k < count; k++) {
        const rad_solve_step *h = &steps[k];
        fprintf(f.file, "%d,%.9g,", h->iteration, h->seconds);
        if (!isnan(h->residual))
            fprintf(f.file, "%.9g", h->residual);
        fputc(',', f.file);
        if (!isnan(h->unshot))
            fprintf(f.file, "%.9g", h->unshot);
        fputc('\n', f.file);
    }
    return rad_atomic_commit(ctx, &f);
}
