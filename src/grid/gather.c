/*
 * gather.c -- the illuminance at calculation points, computed at each
 * point from a solved view:
 *
 *   H(x, n) = H_light(x, n)                      luminaires, daylight (light.h)
 *           + sum_j B_j F(x -> j) V(x, j)        every element's radiosity
 *
 * F(x -> j) is the exact unoccluded point-to-polygon factor (Lambert's
 * formula with the polygon clipped to the point's hemisphere, polygon.c:
 * light from behind the point's normal counts zero, so a point in free
 * space is lit from its normal's side only).  F V is the visible part:
 *
 *   - a point on a surface (a ray along -n meets a patch facing n within
 *     a few rad_vis_epsilon) takes that element as its receiver: the
 *     occluder classification of the pair (receiver, j) holds for every
 *     point of the receiver (occluders.c), so clear pairs need no ray,
 *     blocked ones count zero and partial ones with their blockers listed
 *     get the exact factor of the source less the blockers' shadows
 *     (rad_point_polygon_ff_visible).  The surface's own elements in the
 *     point's plane are left out (their factor is zero);
 *   - otherwise (free points, work planes in the air, partial pairs the
 *     classification cannot list) shadow rays to stratified points y_k of
 *     the element estimate the hidden part:  F V = F - (1/N) sum_k
 *     [blocked] k(y_k),  k(y) = cos cos A_j / (pi r^2) (a control variate
 *     as solve/vpl.c's direct light: exact when nothing blocks, unbiased
 *     otherwise); N = 1, 4 or 16 by the element's size over its distance.
 *
 * The sum splits in the emitters' self-emission E_j (their direct light)
 * and the rest, B_j - E_j (the interreflection, luminaires' and daylight's
 * first reflection included).  Parallel over points: each point's sum is
 * made in one thread in element order, and its rays are keyed on (seed,
 * point, element), so the numbers do not depend on the thread count.
 */
#include "grid/grid.h"

#include "formfactor/formfactor.h"
#include "light/light.h"

#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* Rays gathered before one occlusion query (Embree's packets are 16). */
enum { BATCH = 256 };

typedef struct gather_shared {
    const rad_solution_view *view;
    const rad_grid_set *set;
    const rad_ff_occluders *occ;  /* NULL: no classification (rays) */
    const double *self;           /* 3n: self-emission E_j (W/m^2) */
    const float *diameter;        /* n: element diameter, m */
    double eps, plane_tol;
    uint64_t seed;
} gather_shared;

/* Per-thread pending rays, grouped by element: each element's hidden part
 * is taken from its unoccluded factor after the query, and the difference
 * clamped to [0, F] (the estimate of a visible part is never negative nor
 * above the whole; on the generated office unclamped sums left points by
 * desks' edges at -0.6 lux). */
typedef struct ray_batch {
    rad_ray ray[BATCH];
    double weight[BATCH];         /* factor hidden if blocked (kernel / N) */
    uint8_t blocked[BATCH];
    int count;
    uint32_t element[BATCH];      /* pending elements ... */
    double factor[BATCH];         /* ... their unoccluded factor */
    int first[BATCH + 1];         /* ... and their rays: first[e] .. first[e + 1] - 1 */
    int elements;
    uint64_t rays;
} ray_batch;

static void flush(const gather_shared *g, ray_batch *b, double direct[3], double indirect[3])
{
    if (b->elements == 0)
        return;
    const rad_vis *vis = g->view->vis;
    if (b->count > 0)
        vis->backend->occluded(vis->state, b->ray, (size_t)b->count, b->blocked);
    b->first[b->elements] = b->count;
    const double *B = g->view->radiosity;
    for (int e = 0; e < b->elements; e++) {
        double hidden = 0.0;
        for (int k = b->first[e]; k < b->first[e + 1]; k++)
            if (b->blocked[k])
                hidden += b->weight[k];
        double F = b->factor[e], seen = fmin(fmax(F - hidden, 0.0), F);
        size_t j = b->element[e];
        for (int c = 0; c < 3; c++) {
            direct[c] += seen * g->self[3 * j + (size_t)c];
            indirect[c] += seen * (B[3 * j + (size_t)c] - g->self[3 * j + (size_t)c]);
        }
    }
    b->rays += (uint64_t)b->count;
    b->count = 0;
    b->elements = 0;
}

/* The element under point p facing n (the point lies on it), or -1. */
static int64_t receiver_of(const gather_shared *g, vec3 p, vec3 n)
{
    const rad_mesh *mesh = g->view->mesh;
    const rad_vis *vis = g->view->vis;
    if (!vis)
        return -1;
    rad_ray ray = {v3_mad(p, n, 2.0 * g->eps), v3_scale(n, -1.0), 0.0, 4.0 * g->eps};
    rad_hit hit;
    vis->backend->intersect(vis->state, &ray, 1, &hit);
    if (!isfinite(hit.t))
        return -1;
    const rad_patch *patch = &mesh->patches[hit.patch];
    /* Facing the point's way within 1e-6 of a radian squared. */
    if (patch->obstruction || patch->element_count == 0 || v3_dot(patch->normal, n) < 1.0 - 1e-6)
        return -1;
    double s, t, ls, lt;
    rad_patch_parameters(patch, p, &s, &t);
    s = fmin(fmax(s, 0.0), 1.0);
    t = fmin(fmax(t, 0.0), 1.0);
    return (int64_t)rad_mesh_locate(mesh, hit.patch, s, t, &ls, &lt);
}

static void gather_point(const gather_shared *g, size_t index, ray_batch *b, double direct[3],
                         double indirect[3], uint64_t *exact_pairs, uint64_t *ray_pairs, double *light_seconds)
{
    const rad_solution_view *view = g->view;
    const rad_mesh *mesh = view->mesh;
    const double *B = view->radiosity;
    vec3 p = g->set->position[index], n = g->set->normal[index];
    double t0 = rad_seconds();
    rad_light_irradiance(view->scene, mesh, view->vis, p, n, direct);
    *light_seconds += rad_seconds() - t0;
    indirect[0] = indirect[1] = indirect[2] = 0.0;
    int64_t recv = receiver_of(g, p, n);
    const rad_element *re = recv >= 0 ? &mesh->elements[recv] : NULL;
    vec3 origin = v3_mad(p, n, g->eps);
    for (size_t j = 0; j < view->n; j++) {
        const double *Bj = B + 3 * j;
        if (!(Bj[0] > 0.0 || Bj[1] > 0.0 || Bj[2] > 0.0))
            continue;
        const rad_element *e = &mesh->elements[j];
        /* The point must be in front of the element's plane. */
        if (!(v3_dot(e->normal, v3_sub(p, e->centroid)) > g->plane_tol))
            continue;
        if (re && e->surface == re->surface && fabs(v3_dot(e->normal, v3_sub(p, e->centroid))) <= g->plane_tol)
            continue;
        vec3 corner[4];
        for (uint32_t k = 0; k < e->vertex_count; k++)
            corner[k] = mesh->vertices[e->vertex[k]];
        double F = rad_point_polygon_ff(p, n, corner, e->vertex_count);
        if (!(F > 0.0))
            continue;
        double seen = F;
        bool rays = view->vis != NULL;
        if (re && g->occ && rays) {
            rad_ff_blockers blockers;
            blockers.count = 0;
            blockers.complete = false;
            rad_ff_verdict verdict = rad_ff_occluders_classify(g->occ, (uint32_t)recv, (uint32_t)j, &blockers);
            if (verdict == RAD_FF_BLOCKED) {
                ++*exact_pairs;
                continue;
            }
            if (verdict == RAD_FF_CLEAR) {
                rays = false;
            } else if (blockers.complete && blockers.count > 0) {
                rad_ff_blockers_trim(&blockers, corner[0], e->normal, mesh->vertices[re->vertex[0]], re->normal);
                double f = rad_point_polygon_ff_visible(p, n, corner, e->vertex_count, e->normal, &blockers);
                if (f >= 0.0) {
                    seen = fmin(f, F);
                    rays = false;
                }
            }
            if (!rays)
                ++*exact_pairs;
        }
        if (!rays) {
            for (int c = 0; c < 3; c++) {
                direct[c] += seen * g->self[3 * j + (size_t)c];
                indirect[c] += seen * (Bj[c] - g->self[3 * j + (size_t)c]);
            }
            continue;
        }
        ++*ray_pairs;
        /* N = k x k stratified rays: 1 beyond 4 diameters, 4 beyond one,
         * 16 nearer (the hidden part's error falls as the element looks
         * smaller: its kernel varies less over it). */
        double dist = v3_length(v3_sub(e->centroid, p)), diam = g->diameter[j];
        int k = dist > 4.0 * diam ? 1 : dist > diam ? 2 : 4;
        if (b->count + k * k > BATCH || b->elements == BATCH)
            flush(g, b, direct, indirect);
        b->element[b->elements] = (uint32_t)j;
        b->factor[b->elements] = F;
        b->first[b->elements] = b->count;
        b->elements++;
        double lift = g->eps + rad_element_bend(mesh, e);
        rad_rng rng = rad_rng_keyed(g->seed, 0x67726964ULL + index, j);
        double inv = 1.0 / (k * k);
        for (int a = 0; a < k; a++)
            for (int c = 0; c < k; c++) {
                double u = (a + rad_rng_uniform(&rng)) / k, v = (c + rad_rng_uniform(&rng)) / k;
                vec3 y = v3_mad(rad_element_sample(mesh, e, u, v), e->normal, lift);
                vec3 d = v3_sub(y, p);
                double r2 = v3_dot(d, d);
                double kernel = fmax(0.0, v3_dot(n, d)) * fmax(0.0, -v3_dot(e->normal, d)) / (M_PI * r2 * r2) *
                                e->area * rad_element_sample_weight(mesh, e, u, v);
                if (!(kernel > 0.0))
                    continue;
                b->ray[b->count] = (rad_ray){origin, v3_sub(y, origin), 0.0, 1.0};
                b->weight[b->count] = kernel * inv;
                b->count++;
            }
    }
    flush(g, b, direct, indirect);
}

rad_result rad_grid_gather(rad_context *ctx, const rad_solution_view *view, const rad_grid_set *set,
                           double *direct, double *indirect, rad_grid_gather_stats *stats)
{
    memset(stats, 0, sizeof *stats);
    double t0 = rad_seconds();
    size_t n = view->n, points = set->point_count;
    const rad_mesh *mesh = view->mesh;
    int threads = view->threads > 0 ? view->threads : 1;
    double *self = rad_alloc(ctx, RAD_MEM_RENDER, 3 * n + 1, sizeof *self, "illuminance: self-emission");
    float *diameter = rad_alloc(ctx, RAD_MEM_RENDER, n + 1, sizeof *diameter, "illuminance: element sizes");
    ray_batch *batches = rad_alloc(ctx, RAD_MEM_RENDER, (size_t)threads, sizeof *batches, "illuminance: rays");
    void *block = NULL;
    const rad_ff_occluders *occ = NULL;
    rad_result r = self && diameter && batches ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
    if (r == RAD_OK && view->vis)
        r = rad_ff_occluders_build(ctx, mesh, 0, &block, &occ);
    if (r != RAD_OK) {
        rad_free(self);
        rad_free(diameter);
        rad_free(batches);
        rad_free(block);
        return r;
    }
    /* Self-emission: the element's emission less the first reflection of
     * the direct light the strategies added to it (strategy.h). */
    for (size_t j = 0; j < n; j++) {
        for (int c = 0; c < 3; c++) {
            size_t at = 3 * j + (size_t)c;
            self[at] = view->emission[at] - (view->direct ? view->reflectance[at] * view->direct[at] : 0.0);
            if (self[at] < 0.0)
                self[at] = 0.0;
        }
        const rad_element *e = &mesh->elements[j];
        double d = 0.0;
        for (uint32_t a = 0; a < e->vertex_count; a++)
            for (uint32_t b = a + 1; b < e->vertex_count; b++)
                d = fmax(d, v3_length(v3_sub(mesh->vertices[e->vertex[a]], mesh->vertices[e->vertex[b]])));
        diameter[j] = (float)d;
    }
    gather_shared g = {view, set, occ, self, diameter, rad_vis_epsilon(mesh), rad_ff_plane_tolerance(mesh),
                       view->options ? view->options->seed : 0};
    int done = 0, skipped = 0;
    uint64_t exact = 0, by_rays = 0;
    double light = 0.0, busy = 0.0;
    rad_progress(ctx, "illuminance", 0, (uint64_t)points);
#pragma omp parallel num_threads(threads) reduction(+ : exact, by_rays, light, busy)
    {
        int thread = 0;
#ifdef _OPENMP
        thread = omp_get_thread_num();
#endif
        ray_batch *b = &batches[thread];
        double start = rad_seconds();
#pragma omp for schedule(dynamic, 4) nowait
        for (size_t k = 0; k < points; k++) {
            if (rad_cancelled(ctx)) {
#pragma omp atomic update
                skipped++;
                continue;
            }
            gather_point(&g, k, b, direct + 3 * k, indirect + 3 * k, &exact, &by_rays, &light);
            int now;
#pragma omp atomic capture
            now = ++done;
            if (thread == 0)
                rad_progress(ctx, "illuminance", (uint64_t)now, (uint64_t)points);
        }
        busy += rad_seconds() - start;
    }
    rad_progress(ctx, "illuminance", (uint64_t)done, (uint64_t)points);
    for (int t = 0; t < threads; t++)
        stats->rays += batches[t].rays;
    stats->exact_pairs = exact;
    stats->ray_pairs = by_rays;
    stats->seconds = rad_seconds() - t0;
    stats->light_seconds = light;
    stats->thread_seconds = busy;
    rad_free(self);
    rad_free(diameter);
    rad_free(batches);
    rad_free(block);
    if (skipped > 0)
        return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "illuminance: interrupted after %d of %zu points", done, points);
    return RAD_OK;
}
