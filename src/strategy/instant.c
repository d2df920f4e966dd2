/*
 * instant.c -- instant radiosity per element (Keller 1997): the light
 * that has bounced at least once comes from virtual point lights placed
 * along quasi-random light paths (solve/vpl.c), the emitters' light is
 * gathered exactly, and each element's radiosity is
 *
 *     B_i = E_i + rho_i (H_direct,i + H_vpl,i [+ H_comp,i])
 *
 * with no linear system and no stored coupling: memory is O(n + VPLs),
 * time O(n x VPLs) shadow rays.  View-independent, so the result is a
 * per-element solution like the other strategies'; the renderer's
 * per-pixel gather (rad_render_options.vpl_paths) is the view-dependent form.
 *
 *   element i:  4 stratified points      -> H_direct (exact factors x visible fraction)
 *               VPL k at its own point x_k, uniform over i -> H_vpl (unbiased for the
 *                                                              element's mean, but clamped)
 *
 * Clamping (vpl.h): r^2 is held at r_c^2 = total area / (pi VPLs) at
 * least, so a VPL never gives more than Phi / (pi r_c^2); this removes the
 * light a VPL nearer than r_c would give beyond that, and the expected
 * removal goes to 0 as the VPLs grow (r_c ~ 1 / sqrt(VPLs)).  The loss is
 * measured twice: by the near-field pass below (stats' clamp_loss: what
 * it would add back / the VPL irradiance with it; low noise), and by the
 * same gather without the clamp, an unbiased but heavy-tailed estimate
 * (clamp_loss_unclamped: (unclamped - clamped) / unclamped; 0.3% to 2%
 * over four seeds where the near-field pass says 1.6%).
 *
 * Compensation (solver instant-radiosity; instant-radiosity-clamped does
 * without): what the clamp removed at x is the reflected radiance of the
 * surfaces within r_c weighted by 1 - r^2 / r_c^2 (Kollig & Keller 2004
 * recover it by path tracing the near field).  Here one step of that
 * path tracing, with the solution itself for the radiance at the far end:
 * 16 cosine-distributed rays per element of length r_c; a ray reaching
 * element j at distance r adds (1 - r^2 / r_c^2) (B_j - E_j) / 16 to H.
 * B_j is the clamped solution's, so the compensation misses the
 * clamped light's own near-field share (second order: the loss times
 * itself).
 *
 * Accuracy: unbiased in the closed furnace (1 x 2 x 3 m, rho 0.8, 1024
 * paths: B +3e-4 on average over seeds 0-6, standard error 6e-4) but
 * 1.6e-3 rms from seed to seed, and still 1e-3 at 16384 paths: what
 * remains is the gathers' noise (each VPL at one random point of each
 * element, the clamped light's realised loss against the near-field
 * estimate of its mean), so 1e-4 is out of reach at a reasonable cost
 * for the light paths alone.  Hence the control variate
 * (solve/control_variate.h): the paths and the direct gather carry the
 * residual source E' = E + rho T - beta of B' = B - beta, signed, and
 * B = beta + B'.  The furnace's E' is 0: no path, B = 2.5 to 3e-14; a box
 * of mixed reflectances halves the per-surface error (docs/methods.md).
 *
 * Determinism: every element's numbers come from streams keyed on (seed,
 * element), VPLs from the seeded Halton sequence; elements are
 * independent, so the thread count does not change the answer.
 */
#include "strategy/strategy.h"
#include "solve/vpl.h"
#include "solve/control_variate.h"
#include "formfactor/formfactor.h"

#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

enum {
    DEFAULT_PATHS = 1024,  /* light paths when rad_options.samples is 0 */
    DIRECT_POINTS = 2,     /* direct light at DIRECT_POINTS^2 stratified points of each element */
    DIRECT_RAYS = 4,       /* shadow rays per emitter patch and point */
    COMPENSATION_RAYS = 16,
    BLOCK = 64,            /* shadow rays per backend call */
    CV_RAYS = 256,         /* rays per element for the control variate's transport, where beta != 0 */
    /* The residual source's patches are gathered directly, as emitters are;
     * past this many (and more than the emitters' own) the control variate
     * is not used: its gather would cost more than the VPLs' (n x 16 rays
     * a patch against n x ~5 VPLs a path). */
    CV_MAX_PATCHES = 256
};

typedef struct instant_state {
    rad_meshed base;
    bool compensate;
} instant_state;

static bool instant_solver_info(size_t index, const char **name, const char **description)
{
    static const char *const names[2] = {"instant-radiosity", "instant-radiosity-clamped"};
    static const char *const descriptions[2] = {
        "matrix-free instant radiosity (Keller 1997): virtual point lights on quasi-random light "
        "paths (rad_options.samples paths, default 1024) gathered per element with shadow rays; "
        "the 1/r^2 clamp's loss compensated from the near field",
        "matrix-free instant radiosity with the clamp's loss measured but not compensated"};
    if (index >= 2)
        return false;
    *name = names[index];
    *description = descriptions[index];
    return true;
}

static void instant_destroy(void *state)
{
    instant_state *s = state;
    if (!s)
        return;
    rad_meshed_free(&s->base);
    rad_free(s);
}

static rad_result instant_create(rad_context *ctx, const rad_scene *scene, const rad_options *o, void **out)
{
    *out = NULL;
    if (o->closure_correction)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "rad_options.closure_correction rescales form factors, and solver '%s' has none: use "
                        "a gathering solver or hierarchical",
                        o->solver);
    instant_state *s = rad_alloc(ctx, RAD_MEM_SOLVER, 1, sizeof *s, "solution: instant radiosity state");
    if (!s)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = rad_meshed_init(ctx, scene, o, &s->base);
    if (r != RAD_OK) {
        rad_free(s);
        return r;
    }
    s->compensate = strcmp(o->solver, "instant-radiosity") == 0;
    s->base.ff_stats.method = "none (instant radiosity: virtual point lights)";
    *out = s;
    return RAD_OK;
}

/* Element i's direct and VPL irradiance (clamped and not), H[9]:
 * direct RGB, VPL RGB, unclamped VPL RGB. */
static void gather_element(const rad_meshed *m, const rad_vpl_set *set, const double *source, bool signed_source,
                           uint32_t i, double eps, rad_ray *rays, uint8_t *blocked, double *weight, double H[9])
{
    const rad_mesh *mesh = m->mesh;
    const rad_element *e = &mesh->elements[i];
    double lift = eps + rad_element_bend(mesh, e);
    rad_rng rng = rad_rng_keyed(m->options->seed, 0x49525f44u, i); /* "IR_D" */
    memset(H, 0, 9 * sizeof *H);
    for (int a = 0; a < DIRECT_POINTS; a++)
        for (int b = 0; b < DIRECT_POINTS; b++) {
            double u = (a + rad_rng_uniform(&rng)) / DIRECT_POINTS, v = (b + rad_rng_uniform(&rng)) / DIRECT_POINTS;
            double w = rad_element_sample_weight(mesh, e, u, v);
            vec3 x = v3_mad(rad_element_sample(mesh, e, u, v), e->normal, lift);
            double h[3];
            rad_vpl_direct(set, mesh, m->vis, source, x, e->normal, DIRECT_RAYS, &rng, h);
            for (int c = 0; c < 3; c++)
                H[c] += w * h[c] / (DIRECT_POINTS * DIRECT_POINTS);
        }
    /* The control variate of rad_vpl_direct can leave an element in deep
     * shadow a little below 0; the element's irradiance cannot be.  A
     * signed source's can (light of B' = B - beta), so it is not held. */
    if (!signed_source)
        for (int c = 0; c < 3; c++)
            H[c] = fmax(H[c], 0.0);
    /* Each VPL at its own point of the element. */
    rad_rng prng = rad_rng_keyed(m->options->seed, 0x49525f56u, i); /* "IR_V" */
    for (size_t first = 0; first < set->count; first += BLOCK) {
        size_t count = set->count - first < BLOCK ? set->count - first : BLOCK, cast = 0;
        size_t index[BLOCK];
        double g[BLOCK], g_raw[BLOCK];
        for (size_t k = 0; k < count; k++) {
            double u = rad_rng_uniform(&prng), v = rad_rng_uniform(&prng);
            vec3 x = v3_mad(rad_element_sample(mesh, e, u, v), e->normal, lift);
            if (rad_vpl_ray(set, &set->lights[first + k], x, e->normal, &rays[cast], &g[cast], &g_raw[cast])) {
                weight[cast] = rad_element_sample_weight(mesh, e, u, v);
                index[cast++] = first + k;
            }
        }
        if (cast == 0)
            continue;
        m->vis->backend->occluded(m->vis->state, rays, cast, blocked);
        for (size_t r = 0; r < cast; r++) {
            if (blocked[r])
                continue;
            const double *phi = set->lights[index[r]].power;
            for (int c = 0; c < 3; c++) {
                H[3 + c] += weight[r] * phi[c] * g[r];
                H[6 + c] += weight[r] * phi[c] * g_raw[r];
            }
        }
    }
}

/* The near-field light the clamp removed at element i (file header), from
 * the clamped solution B. */
static void compensate_element(const rad_meshed *m, double radius, uint32_t i, double eps, const double *B,
                               const double *source, rad_ray *rays, rad_hit *hits, double H[3])
{
    const rad_mesh *mesh = m->mesh;
    const rad_element *e = &mesh->elements[i];
    double lift = eps + rad_element_bend(mesh, e);
    rad_rng rng = rad_rng_keyed(m->options->seed, 0x49525f43u, i); /* "IR_C" */
    enum { SIDE = 4 }; /* SIDE^2 = COMPENSATION_RAYS strata of the disk */
    rad_element_cosine_rays(mesh, e, lift, SIDE, 0, COMPENSATION_RAYS, &rng, rays);
    for (int k = 0; k < COMPENSATION_RAYS; k++)
        rays[k].tfar = radius;
    m->vis->backend->intersect(m->vis->state, rays, COMPENSATION_RAYS, hits);
    H[0] = H[1] = H[2] = 0.0;
    for (int k = 0; k < COMPENSATION_RAYS; k++) {
        uint32_t j = rad_vis_front_element(mesh, &rays[k], &hits[k]);
        if (j == UINT32_MAX)
            continue;
        double missing = 1.0 - (hits[k].t * hits[k].t) / (radius * radius);
        if (missing <= 0.0)
            continue;
        for (int c = 0; c < 3; c++)
            H[c] += missing * (B[3 * (size_t)j + c] - source[3 * (size_t)j + c]) / COMPENSATION_RAYS;
    }
}

/* Patches the residual source E' is not 0 on (the direct gather's emitters). */
static size_t source_patches(const rad_mesh *mesh, const double *source)
{
    size_t count = 0;
    for (size_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        for (uint32_t k = 0; k < patch->element_count; k++) {
            const double *E = source + 3 * (size_t)(patch->first_element + k);
            if (E[0] != 0.0 || E[1] != 0.0 || E[2] != 0.0) {
                count++;
                break;
            }
        }
    }
    return count;
}

static rad_result instant_solve(rad_context *ctx, void *state, const rad_step_hook *hook)
{
    instant_state *s = state;
    rad_meshed *m = &s->base;
    rad_system sys;
    rad_solve_params p;
    const char *name = s->compensate ? "instant-radiosity" : "instant-radiosity-clamped";
    rad_meshed_begin(m, name, hook, &sys, &p);
    double t0 = rad_seconds();
    size_t n = m->mesh->element_count;
    int threads = m->threads > 0 ? m->threads : 1;
    size_t paths = m->options->samples > 0 ? (size_t)m->options->samples : DEFAULT_PATHS;
    /* B = beta + B' (control_variate.h): the VPLs and the direct gather
     * carry the residual source E' = E + rho T - beta, signed; in the closed
     * furnace E' = 0, no path is traced and B = beta exactly.  Its patches
     * are gathered directly like emitters', so a residual on many patches
     * (CV_MAX_PATCHES) leaves the control variate out. */
    rad_control_variate cv = {0};
    rad_result r = RAD_OK;
    if (!m->options->no_control_variate)
        r = rad_control_variate_make(ctx, m->mesh, m->vis, m->elements.area, m->elements.reflectance,
                                     m->elements.emission, m->options->seed, CV_RAYS, threads, &cv);
    if (r != RAD_OK) {
        rad_meshed_end(m, r, t0);
        return r;
    }
    if (cv.active) {
        size_t own = source_patches(m->mesh, m->elements.emission), residual = source_patches(m->mesh, cv.source);
        if (residual > CV_MAX_PATCHES && residual > own) {
            memset(cv.beta_mean, 0, sizeof cv.beta_mean);
            cv.active = false;
            cv.groups_varied = 0;
        }
    }
    const double *source = cv.active ? cv.source : m->elements.emission;
    rad_vpl_set set;
    r = rad_vpl_create(ctx, m->mesh, m->vis, m->elements.reflectance, source, paths, m->options->seed, &set);
    if (r != RAD_OK) {
        rad_control_variate_free(&cv);
        rad_meshed_end(m, r, t0);
        return r;
    }
    double *H = rad_alloc(ctx, RAD_MEM_SOLVER, n, 9 * sizeof *H, "instant radiosity: irradiance");
    double *comp = rad_alloc(ctx, RAD_MEM_SOLVER, n, 3 * sizeof *comp, "instant radiosity: compensation");
    rad_ray *rays = rad_alloc(ctx, RAD_MEM_SOLVER, (size_t)threads * BLOCK, sizeof *rays, "instant radiosity: rays");
    rad_hit *hits = rad_alloc(ctx, RAD_MEM_SOLVER, (size_t)threads * BLOCK, sizeof *hits, "instant radiosity: rays");
    uint8_t *blocked = rad_alloc(ctx, RAD_MEM_SOLVER, (size_t)threads * BLOCK, 1, "instant radiosity: rays");
    double *weight = rad_alloc(ctx, RAD_MEM_SOLVER, (size_t)threads * BLOCK, sizeof *weight, "instant radiosity: rays");
    if (!H || !comp || !rays || !hits || !blocked || !weight) {
        r = RAD_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    double eps = rad_vis_epsilon(m->mesh);
    int done_count = 0;
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads)
    for (size_t i = 0; i < n; i++) {
        int tid = 0;
#ifdef _OPENMP
        tid = omp_get_thread_num();
#endif
        if (rad_cancelled(ctx))
            continue;
        gather_element(m, &set, source, cv.active, (uint32_t)i, eps, rays + (size_t)tid * BLOCK,
                       blocked + (size_t)tid * BLOCK, weight + (size_t)tid * BLOCK, H + 9 * i);
        int done;
#pragma omp atomic capture
        done = ++done_count;
        if (tid == 0 && (done & 255) == 0)
            rad_progress(ctx, "solve", (uint64_t)done, (uint64_t)n);
    }
    if (rad_cancelled(ctx)) {
        r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: interrupted gathering the virtual point lights");
        goto done;
    }
    /* B' first: the compensation reads the reflected part B' - E'. */
    double *B = m->elements.radiosity;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            B[3 * i + c] = source[3 * i + c] + m->elements.reflectance[3 * i + c] * (H[9 * i + c] + H[9 * i + 3 + c]);
    memset(comp, 0, n * 3 * sizeof *comp);
    /* The near-field pass measures the clamp's loss for both solvers; only
     * instant-radiosity adds it back. */
    if (set.clamp_radius > 0.0) {
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads)
        for (size_t i = 0; i < n; i++) {
            int tid = 0;
#ifdef _OPENMP
            tid = omp_get_thread_num();
#endif
            compensate_element(m, set.clamp_radius, (uint32_t)i, eps, B, source, rays + (size_t)tid * BLOCK,
                               hits + (size_t)tid * BLOCK, comp + 3 * i);
        }
        if (s->compensate)
            for (size_t i = 0; i < n; i++)
                for (int c = 0; c < 3; c++)
                    B[3 * i + c] += m->elements.reflectance[3 * i + c] * comp[3 * i + c];
    }
    if (cv.active)
        for (size_t k = 0; k < 3 * n; k++)
            B[k] += cv.beta[k];
    /* Books: power absorbed (beta's share from its transport T), the
     * clamp's loss and the compensation (of B''s light). */
    double absorbed = 0.0, clamped = 0.0, raw = 0.0, added = 0.0;
    for (size_t i = 0; i < n; i++) {
        double a = m->elements.area[i];
        for (int c = 0; c < 3; c++) {
            double h = H[9 * i + c] + H[9 * i + 3 + c] + (s->compensate ? comp[3 * i + c] : 0.0) +
                       (cv.active ? cv.transport[3 * i + c] : 0.0);
            absorbed += a * (1.0 - m->elements.reflectance[3 * i + c]) * h;
            clamped += a * H[9 * i + 3 + c];
            raw += a * H[9 * i + 6 + c];
            added += a * comp[3 * i + c];
        }
    }
    rad_solve_stats *st = &m->solve_stats;
    st->iterations = 1;
    st->residual = NAN;
    st->converged = true;
    st->absorbed = absorbed / 3.0;
    st->rays = set.rays + (uint64_t)n * ((uint64_t)set.count + DIRECT_POINTS * DIRECT_POINTS * DIRECT_RAYS *
                                                                   (uint64_t)set.emitter_count) +
               (uint64_t)n * COMPENSATION_RAYS + cv.rays;
    st->vpl_paths = set.paths;
    st->vpl_lights = set.count;
    st->vpl_clamp_radius = set.clamp_radius;
    /* Signed light can cancel in these sums: its magnitudes' ratio would
     * need the sums of |.|, and the loss is what matters where light is
     * positive. */
    st->vpl_clamp_loss = clamped + added != 0.0 ? added / (clamped + added) : 0.0;
    st->vpl_clamp_loss_unclamped = raw != 0.0 ? (raw - clamped) / raw : 0.0;
    st->vpl_compensated = s->compensate;
    st->cv_groups = cv.groups;
    st->cv_groups_varied = cv.groups_varied;
    st->cv_rays = cv.rays;
    memcpy(st->cv_beta, cv.beta_mean, sizeof st->cv_beta);
    if (hook->fn) {
        rad_solve_step step = {1, rad_seconds() - t0, NAN, NAN};
        if (hook->fn(hook->user, &step, true))
            r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "solve: stopped after its one gather");
    }
done:
    rad_free(H);
    rad_free(comp);
    rad_free(rays);
    rad_free(hits);
    rad_free(blocked);
    rad_free(weight);
    rad_vpl_free(&set);
    rad_control_variate_free(&cv);
    rad_meshed_end(m, r, t0);
    return r;
}

static void instant_view(const void *state, rad_solution_view *v)
{
    const instant_state *s = state;
    rad_meshed_view(&s->base, v);
}

const rad_strategy rad_strategy_instant = {
    "instant-radiosity",
    "virtual point lights from quasi-random light paths, gathered per element by shadow rays; no matrix",
    RAD_HAS_UNIFORM_MESH | RAD_CAN_LIGHTS | RAD_CAN_PROGRESS_IMAGES,
    instant_solver_info,
    instant_create,
    instant_solve,
    instant_view,
    instant_destroy,
};
