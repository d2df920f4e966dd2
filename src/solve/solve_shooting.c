/*
 * solve_shooting.c -- progressive refinement without a stored matrix:
 * each shot's form-factor column is sampled on the fly by rays from the
 * shooter, so memory is O(n) and scenes of 10^5 to 10^6 elements fit.
 *
 * A shot from element i casts N rays from stratified points of i in
 * cosine-distributed directions (Malley's method); each carries 1/N of the
 * unshot power A_i dB_i.  The element j a ray reaches first (front side)
 * gains dB_j += rho_j (A_i dB_i / N) / A_j, and (1 - rho_j) of that power is
 * absorbed.  Counting hits estimates F_ij without bias (the notes'
 * "Form Factor - Hemisphere" from the shooter; Shirley 1990 for stochastic
 * shooting), so the expected answer is progressive refinement's.
 *
 *     unshot heap --top K--> shooters --rays (parallel)--> hits
 *          ^                                                 |
 *          +------ deposits, applied in shooter order <------+
 *
 * Determinism: the K largest unshot powers are shot as one batch; each
 * shooter's rays are keyed on (seed, batch, shooter), cast in parallel and
 * their deposits applied in a fixed order, so results do not depend on the
 * thread count.  An indexed max-heap picks shooters in O(log n); unshot
 * power and the ambient term are kept as running sums, so a step costs
 * O(K N log n), not O(n).
 *
 * Stopping: on unshot power / emitted power below the unshot tolerance
 * (default 1e-3: the answer is a Monte Carlo estimate whose noise, ~1/sqrt
 * of the rays an element receives, is far above what further shooting
 * would change), or at the bound of solve.h: a bounce of light is one
 * batch per BATCH elements, and every bounce leaves at most rho_max of the
 * unshot power (each ray carries its share to one element, which reflects
 * rho of it).  The residual needs F, so it is not measured (NAN): the
 * unshot power is shooting's own measure, and bounds it (r = rho F dB, so
 * residual <= rho_max x unshot).
 *
 * The remainder: on reaching the tolerance, the light still unshot is
 * not dropped (a closed furnace read B 8e-4 low at 1e-3 unshot) but added
 * as the expected rest of its bounces, the notes' ambient term (Cohen,
 * Chen, Wallace & Greenberg 1988), confined to where light can go: the
 * groups of elements that light joined, a shooter with every element its
 * rays reached (union-find over the hits).  A group G, its unshot power
 * U_G, area A_G, mean reflectance rho_G and kept_G = 1 - escaped / sent
 * of the power its members shot, each bounce spreads what stays over G by
 * area, so each member gains
 *
 *     B_i += rho_i U_G kept_G / (A_G (1 - rho_G kept_G))
 *
 * exact in a closed group of one reflectance (the furnace: 2.5000000),
 * elsewhere off by a fraction of the unshot power the tolerance allows.
 * A room no ray reached is a group of its own with nothing unshot, so it
 * stays exactly dark (test_hostile's sealed partition: a uniform ambient
 * over the whole scene lit it); a group that never shot, say an emitter
 * too faint to be reached by the tolerance, keeps its light unshot, as
 * where it would go is unknown.
 *
 * The control variate (control_variate.c; Bekaert 1999): B = beta + B',
 * beta a constant per closed group of elements light joins, its transport
 * T known (beta, checked by rays without bias), and only B' shot, from
 * the residual source E' = E + rho T - beta.  E'
 * and so the unshot light can be negative: the heap orders by |unshot|,
 * the tolerance counts |unshot|, a ray carries signed power and the
 * remainder is signed (all linear).  The closed furnace has E' = 0: no
 * shot at all, B = E / (1 - rho) on every face to rounding, where shooting
 * E gave faces 2.5e-4 rms apart.  Where beta = 0 (a room lit by lamps, an
 * open group: control_variate.c) the shots are those without it.
 */
#include "solve/solve.h"
#include "solve/control_variate.h"
#include "mesh/mesh.h"
#include "vis/vis.h"
#include "formfactor/formfactor.h"

#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

enum { BATCH = 32, RAY_BLOCK = 64 };

/* ---- an indexed max-heap of unshot power; ties broken by index ---- */

typedef struct heap {
    uint32_t *item;   /* heap order -> element */
    uint32_t *slot;   /* element -> heap position */
    double *key;      /* element -> unshot power (W, |R| + |G| + |B|) */
    size_t count;
} heap;

static bool heap_above(const heap *h, uint32_t a, uint32_t b)
{
    return h->key[a] > h->key[b] || (h->key[a] == h->key[b] && a < b);
}

static void heap_swap(heap *h, size_t x, size_t y)
{
    uint32_t a = h->item[x], b = h->item[y];
    h->item[x] = b;
    h->item[y] = a;
    h->slot[a] = (uint32_t)y;
    h->slot[b] = (uint32_t)x;
}

static void heap_fix(heap *h, uint32_t element)
{
    size_t k = h->slot[element];
    while (k > 0 && heap_above(h, h->item[k], h->item[(k - 1) / 2])) {
        heap_swap(h, k, (k - 1) / 2);
        k = (k - 1) / 2;
    }
    for (;;) {
        size_t l = 2 * k + 1, r = l + 1, best = k;
        if (l < h->count && heap_above(h, h->item[l], h->item[best]))
            best = l;
        if (r < h->count && heap_above(h, h->item[r], h->item[best]))
            best = r;
        if (best == k)
            break;
        heap_swap(h, k, best);
        k = best;
    }
}

/* ---- the groups light joined, for the remainder ---- */

typedef struct light_group {
    double area;              /* m^2 */
    double rho_area[3];       /* m^2: reflectance x area */
    double unshot[3];         /* W */
    double sent, lost;        /* W, |R| + |G| + |B|: power shot, and escaped or onto back sides */
} light_group;

/* Add each group's expected remainder (file header) to B, and the power it
 * absorbs to *absorbed (W, summed over RGB).  group[i] holds what element
 * i shot (sent, lost); parent is the union-find over the hits; both are
 * used up.  Cannot fail. */
static void add_remainder(const rad_system *sys, const double *dB, size_t *parent, light_group *group, double *B,
                          double *absorbed)
{
    size_t n = sys->n;
    for (size_t i = 0; i < n; i++) {
        light_group *g = &group[i];
        g->area = sys->area[i];
        for (int c = 0; c < 3; c++) {
            g->rho_area[c] = sys->area[i] * sys->reflectance[3 * i + c];
            g->unshot[c] = sys->area[i] * dB[3 * i + c];
        }
    }
    /* Into the roots, in element order (deterministic); a member is only
     * read, a root only written. */
    for (size_t i = 0; i < n; i++) {
        size_t r = rad_union_find_root(parent, i);
        if (r == i)
            continue;
        light_group *g = &group[r];
        const light_group *m = &group[i];
        g->area += m->area;
        g->sent += m->sent;
        g->lost += m->lost;
        for (int c = 0; c < 3; c++) {
            g->rho_area[c] += m->rho_area[c];
            g->unshot[c] += m->unshot[c];
        }
    }
    for (size_t i = 0; i < n; i++) {
        size_t r = rad_union_find_root(parent, i);
        const light_group *g = &group[r];
        if (!(g->sent > 0.0))
            continue; /* never shot: where its light goes is unknown */
        double kept = fmax(0.0, 1.0 - g->lost / g->sent);
        for (int c = 0; c < 3; c++) {
            /* Signed: the control variate's residual light can be
             * negative, and its remainder is too (linear). */
            double U = g->unshot[c], rho = g->rho_area[c] / g->area;
            if (U == 0.0 || !(rho * kept < 1.0))
                continue;
            B[3 * i + c] += sys->reflectance[3 * i + c] * U * kept / (g->area * (1.0 - rho * kept));
            if (r == i)
                *absorbed += U * kept * (1.0 - rho) / (1.0 - rho * kept);
        }
    }
}

/* ---- one shot's rays ---- */

typedef struct hit_record {
    uint32_t element; /* UINT32_MAX: escaped or hit a back side */
} hit_record;

/* Cast N rays from element i; record the element each reaches. */
static void shoot_rays(const rad_context *ctx, const rad_system *sys, uint32_t i, uint64_t key, int N, double eps,
                       hit_record *out, rad_ray *rays, rad_hit *hits)
{
    const rad_mesh *mesh = sys->mesh;
    const rad_element *e = &mesh->elements[i];
    /* Lift by the element's own bend too (a bent quad's bilinear points can
     * lie behind the flat pieces the ray backend holds). */
    double lift = eps;
    if (e->vertex_count == 4)
        for (int k = 1; k < 4; k++)
            lift += fabs(v3_dot(e->normal, v3_sub(mesh->vertices[e->vertex[k]], mesh->vertices[e->vertex[0]])));
    rad_rng rng = rad_rng_keyed(sys->seed, key, i);
    int side = (int)sqrt((double)N);
    if (side < 1)
        side = 1;
    for (int first = 0; first < N; first += RAY_BLOCK) {
        if (rad_cancelled(ctx))
            return; /* the caller discards the batch */
        int count = N - first < RAY_BLOCK ? N - first : RAY_BLOCK;
        /* Origins independent of the directions: tying the two strata by a
         * fixed rule would bias the estimate. */
        rad_element_cosine_rays(mesh, e, lift, side, first, count, &rng, rays);
        sys->vis->backend->intersect(sys->vis->state, rays, (size_t)count, hits);
        for (int k = 0; k < count; k++) {
            /* Escaped, or a back side: absorbed by nothing we track. */
            out[first + k].element = rad_vis_front_element(mesh, &rays[k], &hits[k]);
        }
    }
}

/* Element i's unshot power, W: |R| + |G| + |B| (the control variate's
 * residual light is signed). */
static double unshot_key(const rad_system *sys, const double *dB, size_t i)
{
    return sys->area[i] * (fabs(dB[3 * i]) + fabs(dB[3 * i + 1]) + fabs(dB[3 * i + 2]));
}

/* Unshot over emitted power, the stopping measure: the running sum of
 * |unshot| with the control variate; without it, every unshot value is
 * positive and the channels' sums give the same up to rounding (kept so
 * that a scene where beta = 0 solves as it did before). */
static double unshot_fraction(const rad_control_variate *cv, const double *unshot_c, double unshot_abs,
                              double emitted)
{
    if (!(emitted > 0.0))
        return 0.0;
    return (cv->active ? fmax(unshot_abs, 0.0) : unshot_c[0] + unshot_c[1] + unshot_c[2]) / emitted;
}

static rad_result shooting(rad_context *ctx, const rad_system *sys, const rad_solve_params *p,
                           double *B, rad_solve_stats *stats)
{
    size_t n = sys->n;
    if (!sys->mesh || !sys->vis)
        return rad_fail(ctx, RAD_ERROR_INTERNAL, "shooting: needs the mesh and a ray backend");
    int N = sys->samples > 0 ? sys->samples : 256;
    double goal = p->unshot_tolerance > 0.0 ? p->unshot_tolerance : 1e-3;
    int threads = sys->threads > 0 ? sys->threads : 1;
    /* O(n) vectors and the hit records of BATCH shots in flight: check the
     * estimate first, so that a huge --ff-samples is refused with a way out. */
    double limit = sys->max_memory > 0.0 ? sys->max_memory : rad_memory_limit(ctx);
    /* The control variate: 9 doubles an element, and its groups' 4 words
     * and weighted value while it is made. */
    double bytes = (double)BATCH * (double)N * (double)sizeof(hit_record) +
                   (64.0 + 2.0 * sizeof(size_t) + sizeof(light_group) + 9.0 * sizeof(double) +
                    4.0 * sizeof(size_t) + 2.0 * sizeof(double)) * (double)n;
    if (bytes > limit)
        return rad_fail(ctx, RAD_ERROR_OUT_OF_MEMORY,
                        "shooting: %d rays per shot for %zu elements need %.2f GiB, above the "
                        "memory limit of %.2f GiB (rad_options.max_memory_bytes); use fewer rad_options.samples",
                        N, n, bytes / 1073741824.0, limit / 1073741824.0);
    double *dB = rad_alloc(ctx, RAD_MEM_SOLVER, 3 * n, sizeof *dB, "shooting: unshot radiosity");
    heap h = {0};
    h.item = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *h.item, "shooting: heap");
    h.slot = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *h.slot, "shooting: heap");
    h.key = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *h.key, "shooting: heap");
    hit_record *hits = rad_alloc(ctx, RAD_MEM_SOLVER, (size_t)BATCH * (size_t)N, sizeof *hits, "shooting: hits");
    rad_ray *rays = rad_alloc(ctx, RAD_MEM_SOLVER, (size_t)threads * RAY_BLOCK, sizeof *rays, "shooting: rays");
    rad_hit *rhits = rad_alloc(ctx, RAD_MEM_SOLVER, (size_t)threads * RAY_BLOCK, sizeof *rhits, "shooting: rays");
    size_t *parent = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *parent, "shooting: groups");
    size_t *size = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *size, "shooting: groups");
    light_group *group = rad_alloc(ctx, RAD_MEM_SOLVER, n, sizeof *group, "shooting: groups");
    rad_control_variate cv = {0};
    rad_result result = RAD_OK;
    if (!dB || !h.item || !h.slot || !h.key || !hits || !rays || !rhits || !parent || !size || !group) {
        result = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    /* B = beta + B' (file header): B starts at beta + E', and only the
     * residual light E' is shot. */
    if (sys->control_variate)
        result = rad_control_variate_make(ctx, sys->mesh, sys->vis, sys->area, sys->reflectance, sys->emission,
                                          sys->seed, N, threads, &cv);
    if (result != RAD_OK)
        goto done;
    if (cv.active)
        for (size_t k = 0; k < 3 * n; k++)
            B[k] = cv.beta[k] + cv.source[k];

    /* Running sums: emitted and unshot power per channel, area, rho-area. */
    double emitted = 0.0, unshot_c[3] = {0, 0, 0}, area = 0.0, rho_area[3] = {0, 0, 0}, unshot_abs = 0.0;
    double absorbed = 0.0;
    for (size_t i = 0; i < n; i++) {
        area += sys->area[i];
        for (int c = 0; c < 3; c++) {
            dB[3 * i + c] = cv.active ? cv.source[3 * i + c] : B[3 * i + c];
            unshot_c[c] += sys->area[i] * dB[3 * i + c];
            rho_area[c] += sys->area[i] * sys->reflectance[3 * i + c];
            emitted += sys->area[i] * sys->emission[3 * i + c];
            /* What beta's transport leaves absorbed, known without shooting. */
            if (cv.active)
                absorbed += sys->area[i] * (1.0 - sys->reflectance[3 * i + c]) * cv.transport[3 * i + c];
        }
        h.item[i] = h.slot[i] = (uint32_t)i;
        parent[i] = i;
        size[i] = 1;
        group[i] = (light_group){0};
        h.key[i] = unshot_key(sys, dB, i);
        unshot_abs += h.key[i];
    }
    h.count = n;
    for (size_t k = n / 2; k-- > 0;) /* heapify */
        heap_fix(&h, h.item[k]);
    double t0 = rad_seconds();
    double eps = rad_vis_epsilon(sys->mesh);
    rad_solve_bound bound = rad_solve_bound_make(p->max_iterations, rad_system_contraction(sys), 1.0, goal,
                                                 ceil((double)n / BATCH));
    long long max_batches = (long long)bound.limit;
    stats->iteration_limit = bound.limit;
    uint64_t rays_cast = 0;
    long long batch = 0;
    double unshot = unshot_fraction(&cv, unshot_c, unshot_abs, emitted);
    uint32_t shooter[BATCH];
    double power[BATCH][3];

    for (; batch < max_batches && unshot > goal; batch++) {
        /* The K largest unshot powers, removed from the books as they shoot. */
        int K = 0;
        while (K < BATCH && h.count > 0 && h.key[h.item[0]] > 0.0) {
            uint32_t i = h.item[0];
            shooter[K] = i;
            unshot_abs -= h.key[i];
            for (int c = 0; c < 3; c++) {
                power[K][c] = sys->area[i] * dB[3 * i + c];
                unshot_c[c] -= power[K][c];
                dB[3 * i + c] = 0.0;
            }
            h.key[i] = -1.0; /* sink, then restore to 0 after the batch */
            heap_fix(&h, i);
            K++;
        }
        if (K == 0)
            break;
        /* Small batches on one thread: a team costs more than a few
         * thousand rays (the rays are keyed, so the answer is the same). */
        int team = (double)K * N >= 4096.0 ? threads : 1;
#pragma omp parallel for schedule(dynamic, 1) num_threads(team)
        for (int k = 0; k < K; k++) {
            int tid = 0;
#ifdef _OPENMP
            tid = omp_get_thread_num();
#endif
            shoot_rays(ctx, sys, shooter[k], (uint64_t)batch, N, eps, hits + (size_t)k * N,
                       rays + (size_t)tid * RAY_BLOCK, rhits + (size_t)tid * RAY_BLOCK);
        }
        if (rad_cancelled(ctx)) {
            /* Interrupted inside the batch (a shot of 10^8 rays takes
             * seconds): its hits are incomplete, so the shooters get their
             * unshot power back and B stays the last whole batch's. */
            for (int k = 0; k < K; k++) {
                uint32_t i = shooter[k];
                for (int c = 0; c < 3; c++) {
                    dB[3 * i + c] = power[k][c] / sys->area[i];
                    unshot_c[c] += power[k][c];
                }
                h.key[i] = unshot_key(sys, dB, i);
                unshot_abs += h.key[i];
                heap_fix(&h, i);
            }
            result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: interrupted after %lld batches", batch);
            break;
        }
        rays_cast += (uint64_t)K * (uint64_t)N;
        /* Deposits, in shooter order (deterministic). */
        for (int k = 0; k < K; k++) {
            h.key[shooter[k]] = 0.0;
            heap_fix(&h, shooter[k]);
        }
        for (int k = 0; k < K; k++) {
            const hit_record *hk = hits + (size_t)k * N;
            light_group *g = &group[shooter[k]];
            double shot = fabs(power[k][0]) + fabs(power[k][1]) + fabs(power[k][2]);
            g->sent += shot;
            for (int r = 0; r < N; r++) {
                uint32_t j = hk[r].element;
                if (j == UINT32_MAX) {
                    g->lost += shot / N;
                    continue; /* escaped: an open scene loses it */
                }
                rad_union_find_join(parent, size, shooter[k], j);
                double aj = sys->area[j];
                for (int c = 0; c < 3; c++) {
                    double arriving = power[k][c] / N; /* W */
                    double rho = sys->reflectance[3 * j + c];
                    double d = rho * arriving / aj;
                    dB[3 * j + c] += d;
                    B[3 * j + c] += d;
                    unshot_c[c] += rho * arriving;
                    absorbed += (1.0 - rho) * arriving;
                }
                double key = unshot_key(sys, dB, j);
                unshot_abs += key - h.key[j];
                h.key[j] = key;
                heap_fix(&h, j);
            }
        }
        unshot = unshot_fraction(&cv, unshot_c, unshot_abs, emitted);
        if (p->monitor) {
            for (int c = 0; c < 3; c++) {
                double rho_avg = rho_area[c] / area;
                stats->ambient[c] = fmax(unshot_c[c], 0.0) / area / (1.0 - rho_avg);
            }
            rad_solve_step step = {(int)(batch + 1 < 2147483647LL ? batch + 1 : 2147483647LL),
                                   rad_seconds() - t0, NAN, unshot};
            if (p->monitor(p->monitor_user, &step, B, stats->ambient)) {
                batch++;
                result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: stopped after %lld batches", batch);
                break;
            }
        }
        if ((batch & 63) == 0) {
            /* Progress on a log scale of the unshot power: 1 -> goal. */
            double done = log(fmax(unshot, goal)) / log(goal);
            rad_progress(ctx, "solve", (uint64_t)(1000.0 * fmax(done, 0.0)), 1000);
            if (rad_cancelled(ctx)) {
                batch++;
                result = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: interrupted after %lld batches", batch);
                break;
            }
        }
    }
    for (int c = 0; c < 3; c++) {
        double rho_avg = rho_area[c] / area;
        /* The unshot power is a running sum: round-off can leave it at
         * -1e-18 where all is shot, which no ambient light should become. */
        stats->ambient[c] = fmax(unshot_c[c], 0.0) / area / (1.0 - rho_avg);
    }
    /* Only on reaching the tolerance: a solve stopped at its bound or by
     * its caller keeps what it deposited, and its ambient term for display;
     * converged, the remainder is in B and nothing is left to display. */
    if (result == RAD_OK && unshot <= goal) {
        add_remainder(sys, dB, parent, group, B, &absorbed);
        memset(stats->ambient, 0, sizeof stats->ambient);
    }
    stats->iterations = batch > 2147483647LL ? 2147483647 : (int)batch;
    stats->unshot = unshot;
    stats->absorbed = absorbed / 3.0;
    stats->residual = NAN;
    stats->rays = rays_cast + cv.rays;
    stats->cv_groups = cv.groups;
    stats->cv_groups_varied = cv.groups_varied;
    stats->cv_rays = cv.rays;
    memcpy(stats->cv_beta, cv.beta_mean, sizeof stats->cv_beta);
    stats->converged = result == RAD_OK && unshot <= goal;
    if (result == RAD_OK && !stats->converged)
        rad_solve_warn(stats, "shooting", &bound, (double)batch, "batches", "unshot power", unshot,
                       goal, "");
done:
    rad_free(dB);
    rad_free(h.item);
    rad_free(h.slot);
    rad_free(h.key);
    rad_free(hits);
    rad_free(rays);
    rad_free(rhits);
    rad_free(parent);
    rad_free(size);
    rad_free(group);
    rad_control_variate_free(&cv);
    return result;
}

const rad_solver rad_solver_shooting = {
    "shooting",
    "matrix-free progressive refinement: form-factor columns sampled by rays from the "
    "shooter (rad_options.samples per shot); O(n) memory, for 10^5-10^6 elements",
    shooting,
    0,
};
