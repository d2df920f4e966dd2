/*
 * direct.c -- the emitters' direct light at the picture's shading points
 * (render.h says why): for a point x on receiver element r,
 *
 *   D(x) = sum_j E_j F(x -> visible part of j)    j: the emitting sources
 *
 * F is Lambert's point-to-polygon factor (Baum, Rushmeier & Winget 1989).
 * A source is an emitting patch whose elements emit alike (one polygon), or
 * else one emitting element.  Visibility is exact: the blockers that may
 * hide part of source j from any point of r are listed once per receiver
 * element (shaft culling with planes, as occluders.c: a blocker whose plane
 * does not separate r from j, or whose polygon misses the plane's section
 * of their hull, hides nothing), trimmed to the part in front of both
 * planes, and rad_point_polygon_ff_visible takes the factor of the source
 * less their shadows projected from x.  The blockers are the patches, a
 * bent quad as its two triangles (the Cornell box's blocks are 2 mm out of
 * plane; occluders.c leaves such pairs to rays).  More than
 * RAD_FF_MAX_BLOCKERS: 4 x 4 stratified shadow rays per emitting element
 * with the unoccluded kernel as a control variate (as grid/gather.c),
 * keyed on the caller's key, so the picture does not depend on the thread
 * count.  A per-thread cache keeps the lists of the last receivers.
 */
#include "render/render.h"

#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static bool emits(const double *self, size_t j)
{
    return self[3 * j] > 0.0 || self[3 * j + 1] > 0.0 || self[3 * j + 2] > 0.0;
}

/* Do all of patch p's elements emit the same, and is it flat (to the
 * plane tolerance)?  Then it is one source. */
static bool uniform_patch(const rad_mesh *mesh, const double *self, const rad_patch *p, double plane_tol)
{
    const double *first = &self[3 * (size_t)p->first_element];
    for (uint32_t k = 1; k < p->element_count; k++)
        if (memcmp(&self[3 * (size_t)(p->first_element + k)], first, 3 * sizeof(double)) != 0)
            return false;
    for (uint32_t c = 0; c < p->corner_count; c++)
        if (fabs(v3_dot(p->normal, v3_sub(p->corner[c], p->corner[0]))) > plane_tol)
            return false;
    (void)mesh;
    return true;
}

rad_result rad_direct_light_create(rad_context *ctx, const rad_mesh *mesh, const rad_vis *vis,
                                   const double *self, uint64_t seed, rad_direct_light *out)
{
    memset(out, 0, sizeof *out);
    size_t count = 0;
    for (size_t j = 0; j < mesh->element_count; j++)
        count += emits(self, j);
    if (count == 0 || count > RAD_DIRECT_MAX_SOURCES || !vis)
        return RAD_OK;
    double plane_tol = rad_ff_plane_tolerance(mesh);
    out->source = rad_alloc(ctx, RAD_MEM_RENDER, count, sizeof *out->source, "render: emitters");
    out->member = rad_alloc(ctx, RAD_MEM_RENDER, count, sizeof *out->member, "render: emitters");
    out->blocker = rad_alloc(ctx, RAD_MEM_RENDER, 2 * mesh->patch_count + 1, sizeof *out->blocker, "render: blockers");
    if (!out->source || !out->member || !out->blocker) {
        rad_direct_light_free(out);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    for (size_t q = 0; q < mesh->patch_count; q++) {
        const rad_patch *p = &mesh->patches[q];
        double spread = 0.0;
        for (uint32_t c = 0; c < p->corner_count; c++)
            spread = fmax(spread, fabs(v3_dot(p->normal, v3_sub(p->corner[c], p->corner[0]))));
        int pieces = spread > plane_tol && p->corner_count == 4 ? 2 : 1;
        for (int k = 0; k < pieces; k++) {
            rad_direct_blocker *b = &out->blocker[out->blocker_count++];
            static const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
            b->corner_count = pieces == 2 ? 3 : p->corner_count;
            for (uint32_t c = 0; c < b->corner_count; c++)
                b->corner[c] = p->corner[pieces == 2 ? tri[k][c] : (int)c];
            b->patch = (uint32_t)q;
            b->normal = v3_normalize(v3_cross(v3_sub(b->corner[1], b->corner[0]), v3_sub(b->corner[2], b->corner[0])));
            b->offset = v3_dot(b->normal, b->corner[0]);
            b->lo = b->hi = b->corner[0];
            for (uint32_t c = 1; c < b->corner_count; c++) {
                b->lo = v3_min(b->lo, b->corner[c]);
                b->hi = v3_max(b->hi, b->corner[c]);
            }
        }
    }
    uint32_t members = 0;
    for (size_t q = 0; q < mesh->patch_count; q++) {
        const rad_patch *p = &mesh->patches[q];
        if (p->element_count == 0 || !emits(self, p->first_element))
            continue;
        bool whole = uniform_patch(mesh, self, p, plane_tol);
        for (uint32_t k = 0; k < p->element_count; k++) {
            uint32_t j = p->first_element + k;
            if (!emits(self, j))
                continue;
            if (!whole || k == 0) { /* a new source: the patch, or this element */
                rad_direct_source *src = &out->source[out->source_count++];
                const rad_element *e = &mesh->elements[j];
                src->corner_count = whole ? p->corner_count : e->vertex_count;
                src->centre = v3(0.0, 0.0, 0.0);
                for (uint32_t c = 0; c < src->corner_count; c++) {
                    src->corner[c] = whole ? p->corner[c] : mesh->vertices[e->vertex[c]];
                    src->centre = v3_add(src->centre, v3_scale(src->corner[c], 1.0 / src->corner_count));
                }
                src->normal = whole ? p->normal : e->normal;
                memcpy(src->self, &self[3 * (size_t)j], sizeof src->self);
                src->first = members;
                src->count = 0;
            }
            out->member[members++] = j;
            out->source[out->source_count - 1].count++;
        }
    }
    out->mesh = mesh;
    out->vis = vis;
    out->eps = rad_vis_epsilon(mesh);
    out->plane_tol = plane_tol;
    out->seed = seed;
    return RAD_OK;
}

void rad_direct_light_free(rad_direct_light *d)
{
    rad_free(d->source);
    rad_free(d->member);
    rad_free(d->blocker);
    memset(d, 0, sizeof *d);
}

rad_result rad_direct_cache_init(rad_context *ctx, const rad_direct_light *d, rad_direct_cache *cache)
{
    size_t n = (d->source_count ? d->source_count : 1) * RAD_DIRECT_CACHE_WAYS;
    for (int w = 0; w < RAD_DIRECT_CACHE_WAYS; w++)
        cache->receiver[w] = UINT32_MAX;
    cache->verdict = rad_alloc(ctx, RAD_MEM_RENDER, n, sizeof *cache->verdict, "render: direct light cache");
    cache->blockers = rad_alloc(ctx, RAD_MEM_RENDER, n, sizeof *cache->blockers, "render: direct light cache");
    if (!cache->verdict || !cache->blockers) {
        rad_direct_cache_free(cache);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    return RAD_OK;
}

void rad_direct_cache_free(rad_direct_cache *cache)
{
    rad_free(cache->verdict);
    rad_free(cache->blockers);
    cache->verdict = NULL;
    cache->blockers = NULL;
}

/* Can blocker b hide any segment between the corners' hulls of r (nr
 * corners) and s (ns)?  Conservative (shaft culling with planes, as
 * occluders.c): the segments cross b's plane only if it separates some
 * corner of r from some of s, and they meet the plane inside S, the hull
 * of the corners on it and of the corner-to-corner crossings; if S lies
 * wholly outside one of b's edges, b hides nothing. */
bool rad_direct_may_block(const rad_direct_blocker *b, const vec3 *v, int nr, int nv, double tol)
{
    double dist[8];
    bool r_front = false, r_back = false, s_front = false, s_back = false;
    for (int k = 0; k < nv; k++) {
        dist[k] = v3_dot(b->normal, v[k]) - b->offset;
        bool f = dist[k] > tol, bk = dist[k] < -tol;
        if (k < nr) {
            r_front |= f;
            r_back |= bk;
        } else {
            s_front |= f;
            s_back |= bk;
        }
    }
    if (!((r_front && s_back) || (r_back && s_front)))
        return false;
    vec3 S[24];
    int n = 0;
    for (int a = 0; a < nv; a++) {
        if (fabs(dist[a]) <= tol)
            S[n++] = v[a];
        else if (dist[a] > tol)
            for (int c = 0; c < nv; c++)
                if (dist[c] < -tol && n < 24)
                    S[n++] = v3_lerp(v[a], v[c], dist[a] / (dist[a] - dist[c]));
    }
    for (uint32_t e = 0; e < b->corner_count; e++) {
        vec3 a = b->corner[e], c = b->corner[(e + 1) % b->corner_count];
        vec3 inward = v3_cross(b->normal, v3_sub(c, a));
        bool all_out = true;
        for (int k = 0; k < n && all_out; k++)
            all_out = v3_dot(inward, v3_sub(S[k], a)) < -tol * v3_length(inward);
        if (all_out)
            return false;
    }
    return true;
}

/* The classification of (receiver, every source): clear (no blocker can
 * hide any of it), or partial with its blockers trimmed to what lies in
 * front of both planes (rad_ff_blockers_trim), complete when at most
 * RAD_FF_MAX_BLOCKERS remain (else rays). */
static void classify_receiver(const rad_direct_light *d, rad_ff_verdict *verdict, rad_ff_blockers *blockers,
                              uint32_t receiver)
{
    const rad_mesh *mesh = d->mesh;
    const rad_element *re = &mesh->elements[receiver];
    vec3 v[8] = {{0.0, 0.0, 0.0}};
    int nr = 0;
    for (uint32_t c = 0; c < re->vertex_count; c++)
        v[nr++] = mesh->vertices[re->vertex[c]];
    vec3 rlo = v[0], rhi = v[0];
    for (int c = 1; c < nr; c++) {
        rlo = v3_min(rlo, v[c]);
        rhi = v3_max(rhi, v[c]);
    }
    for (size_t k = 0; k < d->source_count; k++) {
        const rad_direct_source *src = &d->source[k];
        rad_ff_blockers *b = &blockers[k];
        b->count = 0;
        b->complete = true;
        b->trimmed = true;
        int nv = nr;
        vec3 lo = rlo, hi = rhi;
        for (uint32_t c = 0; c < src->corner_count; c++) {
            v[nv++] = src->corner[c];
            lo = v3_min(lo, src->corner[c]);
            hi = v3_max(hi, src->corner[c]);
        }
        uint32_t src_patch = mesh->elements[d->member[src->first]].patch;
        for (size_t q = 0; q < d->blocker_count && b->complete; q++) {
            const rad_direct_blocker *bl = &d->blocker[q];
            if (bl->patch == re->patch || bl->patch == src_patch)
                continue;
            if (!v3_boxes_meet(bl->lo, bl->hi, lo, hi))
                continue;
            if (!rad_direct_may_block(bl, v, nr, nv, d->plane_tol))
                continue;
            rad_ff_blockers one;
            one.count = 1;
            one.corners[0] = bl->corner_count;
            memcpy(one.corner[0], bl->corner, bl->corner_count * sizeof(vec3));
            rad_ff_blockers_trim(&one, src->corner[0], src->normal, v[0], re->normal);
            if (one.count == 0)
                continue;
            if (b->count == RAD_FF_MAX_BLOCKERS) {
                b->complete = false;
                break;
            }
            b->corners[b->count] = one.corners[0];
            memcpy(b->corner[b->count], one.corner[0], sizeof one.corner[0]);
            b->top[b->count] = one.top[0];
            b->count++;
        }
        verdict[k] = b->count == 0 && b->complete ? RAD_FF_CLEAR : RAD_FF_PARTIAL;
    }
}

/* F x V of element e from p (normal n) by 4 x 4 stratified shadow rays,
 * the kernel-weighted share of clear rays (rad_element_seen). */
static double visible_by_rays(const rad_direct_light *d, const rad_element *e, uint32_t j, vec3 p, vec3 n, double F,
                              uint64_t key)
{
    enum { SIDE = 4, RAYS = SIDE * SIDE };
    const rad_mesh *mesh = d->mesh;
    vec3 origin = v3_mad(p, n, d->eps);
    double lift = d->eps + rad_element_bend(mesh, e), weight[RAYS];
    rad_ray rays[RAYS];
    uint8_t blocked[RAYS];
    rad_rng rng = rad_rng_keyed(d->seed ^ 0x64697265ULL /* "dire" */, key, j);
    int count = rad_element_kernel_rays(mesh, e, p, n, origin, lift, SIDE, &rng, rays, weight);
    if (count == 0)
        return F;
    d->vis->backend->occluded(d->vis->state, rays, (size_t)count, blocked);
    return rad_element_seen(F, weight, blocked, count);
}

/* The source's visible factor from p by rays, member by member. */
static double source_by_rays(const rad_direct_light *d, const rad_direct_source *src, vec3 p, vec3 n, uint64_t key)
{
    const rad_mesh *mesh = d->mesh;
    double sum = 0.0;
    for (uint32_t m = 0; m < src->count; m++) {
        uint32_t j = d->member[src->first + m];
        const rad_element *e = &mesh->elements[j];
        vec3 corner[4];
        for (uint32_t c = 0; c < e->vertex_count; c++)
            corner[c] = mesh->vertices[e->vertex[c]];
        double F = rad_point_polygon_ff(p, n, corner, e->vertex_count);
        if (F > 0.0)
            sum += visible_by_rays(d, e, j, p, n, F, key);
    }
    return sum;
}

void rad_direct_at(const rad_direct_light *d, rad_direct_cache *cache, uint32_t receiver, vec3 p,
                   uint64_t key, double rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    if (!d->source_count)
        return;
    vec3 n = d->mesh->elements[receiver].normal;
    size_t way = receiver % RAD_DIRECT_CACHE_WAYS;
    rad_ff_verdict *verdict = cache->verdict + way * d->source_count;
    rad_ff_blockers *blockers = cache->blockers + way * d->source_count;
    if (cache->receiver[way] != receiver) {
        classify_receiver(d, verdict, blockers, receiver);
        cache->receiver[way] = receiver;
    }
    for (size_t k = 0; k < d->source_count; k++) {
        if (verdict[k] == RAD_FF_BLOCKED)
            continue;
        const rad_direct_source *src = &d->source[k];
        /* In front of the source's plane, beyond its tolerance. */
        if (!(v3_dot(src->normal, v3_sub(p, src->centre)) > d->plane_tol))
            continue;
        /* Clear: the whole factor; partial: the visible pieces' (which
         * clips to the point's hemisphere itself), else rays. */
        const rad_ff_blockers *b = &blockers[k];
        double seen = verdict[k] == RAD_FF_PARTIAL && b->complete
                          ? rad_point_polygon_ff_visible(p, n, src->corner, src->corner_count, src->normal, b)
                          : -1.0;
        if (seen < 0.0) {
            double F = rad_point_polygon_ff(p, n, src->corner, src->corner_count);
            if (!(F > 0.0))
                continue;
            seen = verdict[k] == RAD_FF_CLEAR ? F : fmin(source_by_rays(d, src, p, n, key), F);
        }
        for (int c = 0; c < 3; c++)
            rgb[c] += seen * src->self[c];
    }
}

rad_result rad_direct_means(rad_context *ctx, const rad_direct_light *d, int threads, double *mean)
{
    const rad_mesh *mesh = d->mesh;
    size_t n = mesh ? mesh->element_count : 0;
    if (!rad_direct_light_active(d))
        return RAD_OK;
    if (threads < 1)
        threads = 1;
    rad_direct_cache *caches = rad_alloc(ctx, RAD_MEM_RENDER, (size_t)threads, sizeof *caches, "render: caches");
    if (!caches)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = RAD_OK;
    int ready = 0;
    for (; ready < threads && r == RAD_OK; ready++)
        if ((r = rad_direct_cache_init(ctx, d, &caches[ready])) != RAD_OK)
            break;
    if (r == RAD_OK) {
#pragma omp parallel for num_threads(threads) schedule(dynamic, 64)
        for (size_t i = 0; i < n; i++) {
            int thread = 0;
#ifdef _OPENMP
            thread = omp_get_thread_num();
#endif
            enum { SIDE = 3 }; /* midpoints of 3 x 3 cells: the mean to ~1% across a penumbra's edge */
            const rad_element *e = &mesh->elements[i];
            double sum[3] = {0.0, 0.0, 0.0};
            for (int a = 0; a < SIDE; a++)
                for (int b = 0; b < SIDE; b++) {
                    double rgb[3], u = (a + 0.5) / SIDE, v = (b + 0.5) / SIDE;
                    double w = rad_element_sample_weight(mesh, e, u, v);
                    rad_direct_at(d, &caches[thread], (uint32_t)i, rad_element_sample(mesh, e, u, v),
                                  ((uint64_t)i << 8) | (uint64_t)(a * SIDE + b), rgb);
                    for (int c = 0; c < 3; c++)
                        sum[c] += w * rgb[c] / (SIDE * SIDE);
                }
            memcpy(&mean[3 * i], sum, sizeof sum);
        }
    }
    for (int t = 0; t < ready; t++)
        rad_direct_cache_free(&caches[t]);
    rad_free(caches);
    return r;
}
