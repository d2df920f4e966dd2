/*
 * render.c -- ray-cast images of a solution: each camera ray takes the
 * radiance L = B / pi of the surface point it hits (surfaces are
 * Lambertian, so radiance is the same in every direction).
 *
 *   pinhole camera: forward f = normalize(look_at - position),
 *                   right r = normalize(f x up), true up u = r x f;
 *                   pixel (x, y), row 0 at the top, maps to
 *                   f + ((2 x / W) - 1) tan(vfov/2) aspect r
 *                     + (1 - (2 y / H)) tan(vfov/2) u
 *   hit -> patch parameters -> element + local coordinates (mesh.h, O(1))
 *       -> flat: B of the element; smooth: interpolated vertex values
 *   back side of a patch (one-sided surfaces) and misses are black.
 *
 * Anti-aliasing: samples x samples strata per pixel, each jittered by a
 * random offset keyed by (pixel, sample), so the image does not depend on
 * the thread count.  Adaptively: each pixel first takes a 2 x 2 pilot;
 * where its four rays see the same patch (the same element, flat), the
 * pixel lies inside one continuous piece of the shading and the pilot's
 * mean is its value; only the others (edges, shadows' silhouettes against
 * the background, misses) take all samples x samples strata.  Most pixels
 * of a view are inside a surface, so an image costs about 4 rays a pixel
 * instead of 16 at the default 4 x 4, with the edges as before.  Rows are
 * shared out to OpenMP threads; each thread sends its row's rays to the
 * visibility backend in batches.
 *
 * Per-pixel instant radiosity (input->vpls, rad_render_options.vpl_paths):
 * each camera ray's point gathers the emitters and the virtual point
 * lights itself (solve/vpl.h) instead of reading the solution, B = E + rho
 * H at that very point: no mesh error, the VPLs' noise and clamp instead;
 * what the clamp removes comes back from rays into the near field, which
 * read the solution underneath (so it, too, should be a converged one).
 * The shadow rays of the direct light are keyed on (pixel, stratum).
 *
 * Second pass (two-pass methods: Wallace, Cohen & Greenberg 1987; Sillion
 * & Puech 1989): where a camera ray meets a specular material the path
 * goes on from the eye, and where it lands on a diffuse surface it reads
 * the first pass's radiosity, so the picture holds what radiosity cannot
 * (the view-dependent mirror image, refraction, glossy reflection):
 *
 *   L(x, w) = B(x) / pi                                   the diffuse part
 *           + rho_s L(x', r)                              mirror, r = reflected
 *           + t [R L(x', r) + (1 - R) L(x'', refracted)]  glass, R Fresnel's
 *           + rho_s mean over Phong-lobe samples of L      glossy
 *
 * Values are carried as pi L (radiosity units) and scaled with the rest.
 * Glass is exact Fresnel for unpolarised light at each interface (Born &
 * Wolf, ch. 1.5), total internal reflection included; both branches are
 * followed, so the multiple reflections inside a pane sum to its
 * (1 - R)^2 / (1 - R^2).  The glossy lobe is the modified Phong BRDF
 * rho_s (n + 2) / (2 pi) cos^n(alpha) (Lafortune & Willems 1994),
 * importance-sampled (pdf (n + 1) / (2 pi) cos^n alpha: each sample
 * weighs rho_s (n + 2) / (n + 1) cos theta), stratified, keyed by (pixel,
 * sample, bounce), so the image is the same on any number of threads.  A
 * path ends after specular_depth bounces or when its weight falls below
 * RENDER_MIN_WEIGHT.
 */
#include "output/output.h"
#include "light/sky.h"
#include "solve/vpl.h"

#include <stdlib.h>

#ifdef _OPENMP
#include <omp.h>
#include <string.h>
#endif

#define RAD_RENDER_MAX_SIZE 16384   /* pixels per side, samples per side */
#define RAD_RENDER_BATCH 4096       /* rays per backend call: amortises the
                                       call, fits a thread's cache */

typedef struct render_view {
    vec3 position, forward, right, up; /* right and up scaled to the image half-extent */
    int width, height, samples;
} render_view;

static int option_or_default(int value, int fallback) { return value == 0 ? fallback : value; }

static rad_result check_size(rad_context *ctx, const char *what, int value)
{
    if (value < 1 || value > RAD_RENDER_MAX_SIZE)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "rad_render_options.%s must be in [1, %d], got %d", what,
                        RAD_RENDER_MAX_SIZE, value);
    return RAD_OK;
}

/* The camera against the patches' bounding box (rad_camera_check_distance). */
static rad_result check_camera_distance(rad_context *ctx, const rad_render_input *input)
{
    const rad_mesh *mesh = input->mesh;
    vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
    for (size_t i = 0; i < mesh->patch_count; i++)
        for (uint32_t c = 0; c < mesh->patches[i].corner_count; c++) {
            lo = v3_min(lo, mesh->patches[i].corner[c]);
            hi = v3_max(hi, mesh->patches[i].corner[c]);
        }
    return rad_camera_check_distance(ctx, &input->camera, lo, hi);
}

static rad_result make_view(rad_context *ctx, const rad_camera *camera, int width, int height,
                            int samples, render_view *view)
{
    vec3 position = v3(camera->position[0], camera->position[1], camera->position[2]);
    vec3 look_at = v3(camera->look_at[0], camera->look_at[1], camera->look_at[2]);
    vec3 up = v3(camera->up[0], camera->up[1], camera->up[2]);
    vec3 forward = v3_sub(look_at, position);
    vec3 right = v3_cross(forward, up);
    if (!v3_finite(position) || !v3_finite(look_at) || !v3_finite(up))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "render: camera is not finite");
    if (v3_length(forward) == 0.0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "render: camera position and look-at point coincide");
    /* Same round-off allowance as rad_camera_parse. */
    if (v3_length(right) <= 1e-9 * v3_length(forward) * v3_length(up))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "render: camera up vector is zero or parallel to the view direction");
    if (!(camera->vfov_degrees > 0.0 && camera->vfov_degrees < 180.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "render: vertical field of view must be in (0, 180) degrees, got %g",
                        camera->vfov_degrees);
    double half_height = tan(0.5 * camera->vfov_degrees * M_PI / 180.0);
    double half_width = half_height * (double)width / (double)height;
    view->position = position;
    view->forward = v3_normalize(forward);
    view->right = v3_normalize(right);
    view->up = v3_scale(v3_cross(view->right, view->forward), half_height);
    view->right = v3_scale(view->right, half_width);
    view->width = width;
    view->height = height;
    view->samples = samples;
    return RAD_OK;
}

/* Per-pixel instant radiosity at the point p of element e seen by a
 * camera ray: B = E + rho (direct + VPLs + near field), the VPLs clamped
 * as the strategy's (solve/vpl.h); the direct light's shadow rays and the
 * near-field rays from the stream keyed on `key` (pixel and stratum). */
static void shade_vpl(const rad_render_input *input, double epsilon, uint32_t e, const rad_patch *patch, vec3 p,
                      uint64_t key, double rgb[3])
{
    enum { BLOCK = 64, DIRECT_RAYS = 4 };
    const rad_mesh *mesh = input->mesh;
    const rad_vpl_set *set = input->vpls;
    vec3 n = patch->normal;
    vec3 x = v3_mad(p, n, epsilon + rad_element_bend(mesh, &mesh->elements[e]));
    rad_rng rng = rad_rng_keyed(input->seed, 0x52454e44u, key); /* "REND" */
    double H[3], h[3], h_raw[3];
    rad_vpl_direct(set, mesh, input->vis, input->emission, x, n, DIRECT_RAYS, &rng, H);
    rad_ray rays[BLOCK];
    uint8_t blocked[BLOCK];
    for (size_t first = 0; first < set->count; first += BLOCK) {
        size_t count = set->count - first < BLOCK ? set->count - first : BLOCK;
        rad_vpl_gather(set, input->vis, x, n, first, count, rays, blocked, h, h_raw);
        for (int c = 0; c < 3; c++)
            H[c] += h[c];
    }
    /* The clamp's loss, recovered from the near field (as the strategy's
     * compensation, strategy/instant.c): rays of length r_c; a ray that
     * meets element j at distance t adds (1 - t^2 / r_c^2) of j's
     * reflected radiosity B_j - E_j, B from the solution underneath. */
    double rc = set->clamp_radius;
    if (rc > 0.0) {
        enum { NEAR_RAYS = 16, SIDE = 4 };
        vec3 tu = v3_normalize(fabs(n.x) > 0.9 ? v3_cross(n, v3(0, 1, 0)) : v3_cross(n, v3(1, 0, 0)));
        vec3 tv = v3_cross(n, tu);
        rad_hit hits[NEAR_RAYS];
        for (int k = 0; k < NEAR_RAYS; k++) {
            double u = ((k % SIDE) + rad_rng_uniform(&rng)) / SIDE, v = ((k / SIDE) + rad_rng_uniform(&rng)) / SIDE;
            double r = sqrt(u), phi = 2.0 * M_PI * v;
            vec3 d = v3_add(v3_add(v3_scale(tu, r * cos(phi)), v3_scale(tv, r * sin(phi))),
                            v3_scale(n, sqrt(fmax(0.0, 1.0 - u))));
            rays[k] = (rad_ray){x, d, 0.0, rc};
        }
        input->vis->backend->intersect(input->vis->state, rays, NEAR_RAYS, hits);
        for (int k = 0; k < NEAR_RAYS; k++) {
            if (!isfinite(hits[k].t))
                continue;
            const rad_patch *q = &mesh->patches[hits[k].patch];
            if (v3_dot(rays[k].direction, q->normal) >= 0.0)
                continue;
            double s0, t0, ls, lt;
            rad_patch_parameters(q, v3_mad(x, rays[k].direction, hits[k].t), &s0, &t0);
            uint32_t j = rad_mesh_locate(mesh, hits[k].patch, s0, t0, &ls, &lt);
            double missing = 1.0 - hits[k].t * hits[k].t / (rc * rc);
            for (int c = 0; c < 3 && missing > 0.0; c++)
                H[c] += missing *
                        fmax(input->element_radiosity[3 * (size_t)j + c] - input->emission[3 * (size_t)j + c], 0.0) /
                        NEAR_RAYS;
        }
    }
    double rho[3];
    if (input->scene && rad_scene_textured(input->scene, patch->polygon))
        rad_scene_reflectance_at(input->scene, patch->polygon, p, rho);
    else
        memcpy(rho, input->reflectance + 3 * (size_t)e, sizeof rho);
    for (int c = 0; c < 3; c++)
        rgb[c] = input->emission[3 * (size_t)e + c] + rho[c] * fmax(H[c], 0.0);
}

/* A camera ray's point whose direct light (the final gather) is left to
 * the pixel: a 2 x 2 pilot that sees one patch takes it once, at the mean
 * of its four points, instead of four times. */
typedef struct render_deferred {
    bool valid;
    vec3 point;           /* m */
    uint32_t element;
} render_deferred;

/* What a trace needs beyond the input: the second pass's settings. */
typedef struct render_pass {
    const rad_render_input *input;
    rad_direct_cache *caches; /* one per thread: the final gather's (NULL: none) */
    render_deferred *defer;   /* non-NULL: the eye's diffuse points' direct light is noted here, not added */
    rad_shading shading;
    int specular_depth;  /* 0: the first pass alone */
    int glossy_samples;
    double epsilon;      /* m: secondary rays start this far off the surface */
} render_pass;

/* A path whose weight (the product of its bounces' weights) is below this
 * contributes under 1e-6 of what it would alone: the inner reflections of
 * a pane (R^2 = 1.6e-3 a round trip) are followed until their sum is exact
 * to ~1e-9, and glass does not split into 2^depth paths. */
#define RENDER_MIN_WEIGHT 1e-6

#define RENDER_MISS UINT32_MAX        /* what a ray saw: nothing */
#define RENDER_BACK (UINT32_MAX - 1u) /* what a ray saw: the back of a patch */
#define RENDER_MIXED (UINT32_MAX - 2u) /* what a pixel's rays saw: not all the same (or specular) */

/* Radiosity (W/m^2) seen along `ray` given its hit; 0 for a miss or the
 * back of a patch.  Returns what was seen: the patch (smooth shading,
 * continuous across it) or the element (flat), RENDER_MISS or RENDER_BACK. */
static uint32_t shade(const render_pass *pass, const rad_ray *ray, const rad_hit *hit, int depth,
                      double carried, uint64_t key, rad_rng *rng, double rgb[3]);

/* rgb += weight x pi L along (origin, direction), when the path's weight
 * (`carried` to here, times this bounce's) counts: one closest-hit query,
 * then shade. */
static void add_traced(const render_pass *pass, vec3 origin, vec3 direction, int depth, double carried,
                       uint64_t key, rad_rng *rng, const double weight[3], double rgb[3])
{
    double path = carried * fmax(fmax(weight[0], weight[1]), weight[2]);
    if (path < RENDER_MIN_WEIGHT)
        return;
    rad_ray ray = {origin, direction, 0.0, INFINITY};
    rad_hit hit;
    pass->input->vis->backend->intersect(pass->input->vis->state, &ray, 1, &hit);
    double seen[3];
    shade(pass, &ray, &hit, depth, path, key, rng, seen);
    for (int c = 0; c < 3; c++)
        rgb[c] += weight[c] * seen[c];
}

/* Fresnel reflectance for unpolarised light from index n1 into n2 at
 * cos_i (> 0); 1 beyond the critical angle, *cos_t the refracted cosine. */
static double fresnel_dielectric(double n1, double n2, double cos_i, double *cos_t)
{
    double eta = n1 / n2, sin_t2 = eta * eta * fmax(0.0, 1.0 - cos_i * cos_i);
    if (sin_t2 >= 1.0) {
        *cos_t = 0.0;
        return 1.0;
    }
    double ct = sqrt(1.0 - sin_t2);
    double rs = (n1 * cos_i - n2 * ct) / (n1 * cos_i + n2 * ct);
    double rp = (n2 * cos_i - n1 * ct) / (n2 * cos_i + n1 * ct);
    *cos_t = ct;
    return 0.5 * (rs * rs + rp * rp);
}

/* A unit vector at cos_alpha from unit `axis`, at azimuth phi. */
static vec3 about_axis(vec3 axis, double cos_alpha, double phi)
{
    vec3 helper = fabs(axis.x) < 0.9 ? v3(1.0, 0.0, 0.0) : v3(0.0, 1.0, 0.0);
    vec3 u = v3_normalize(v3_cross(helper, axis)), w = v3_cross(axis, u);
    double sin_alpha = sqrt(fmax(0.0, 1.0 - cos_alpha * cos_alpha));
    return v3_add(v3_scale(axis, cos_alpha),
                  v3_add(v3_scale(u, sin_alpha * cos(phi)), v3_scale(w, sin_alpha * sin(phi))));
}

/* The specular part at point p of a patch of material m, seen along unit
 * `d`; `facing` is the patch's normal (front hits) or its negation (glass
 * from inside).  Adds pi L to rgb. */
static void specular_part(const render_pass *pass, const rad_material *m, vec3 p, vec3 d, vec3 normal,
                          int depth, double carried, uint64_t key, rad_rng *rng, double rgb[3])
{
    const double eps = pass->epsilon;
    bool front = v3_dot(d, normal) < 0.0;
    vec3 facing = front ? normal : v3_scale(normal, -1.0);
    double cos_i = -v3_dot(d, facing);
    vec3 reflected = v3_mad(d, facing, 2.0 * cos_i);
    vec3 above = v3_mad(p, facing, eps), below = v3_mad(p, facing, -eps);
    double weight[3];
    switch (m->specular_kind) {
    case RAD_SPECULAR_MIRROR:
        add_traced(pass, above, reflected, depth + 1, carried, key, rng, m->specular, rgb);
        break;
    case RAD_SPECULAR_GLASS: {
        double n1 = front ? 1.0 : m->ior, n2 = front ? m->ior : 1.0, cos_t;
        double R = fresnel_dielectric(n1, n2, cos_i, &cos_t);
        for (int c = 0; c < 3; c++)
            weight[c] = m->specular[c] * R;
        add_traced(pass, above, reflected, depth + 1, carried, key, rng, weight, rgb);
        if (R < 1.0) {
            double eta = n1 / n2;
            vec3 refracted = v3_normalize(v3_mad(v3_scale(d, eta), facing, eta * cos_i - cos_t));
            for (int c = 0; c < 3; c++)
                weight[c] = m->specular[c] * (1.0 - R);
            add_traced(pass, below, refracted, depth + 1, carried, key, rng, weight, rgb);
        }
        break;
    }
    case RAD_SPECULAR_GLOSSY: {
        /* From the eye: glossy_samples stratified on a square grid; deeper: one. */
        int grid = 1;
        if (depth == 0)
            while ((grid + 1) * (grid + 1) <= pass->glossy_samples)
                grid++;
        double n = m->shininess, sum[3] = {0.0, 0.0, 0.0};
        for (int k = 0; k < grid * grid; k++) {
            double u1 = ((double)(k % grid) + rad_rng_uniform(rng)) / grid;
            double u2 = ((double)(k / grid) + rad_rng_uniform(rng)) / grid;
            vec3 out = about_axis(reflected, pow(u1, 1.0 / (n + 1.0)), 2.0 * M_PI * u2);
            double cos_out = v3_dot(out, facing);
            if (cos_out <= 0.0) /* below the surface: the lobe's part that is absorbed */
                continue;
            for (int c = 0; c < 3; c++)
                weight[c] = m->specular[c] * (n + 2.0) / (n + 1.0) * cos_out;
            add_traced(pass, above, out, depth + 1, carried, key, rng, weight, sum);
        }
        for (int c = 0; c < 3; c++)
            rgb[c] += sum[c] / (double)(grid * grid);
        break;
    }
    case RAD_SPECULAR_NONE:
        break;
    }
}

static uint32_t shade(const render_pass *pass, const rad_ray *ray, const rad_hit *hit, int depth,
                      double carried, uint64_t key, rad_rng *rng, double rgb[3])
{
    const rad_render_input *input = pass->input;
    rad_shading shading = pass->shading;
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    if (!isfinite(hit->t)) {
        if (input->daylight) /* the sky (or ground) in that direction, white, as pi L like B (divided at the end) */
            rgb[0] = rgb[1] = rgb[2] = M_PI * rad_daylight_radiance(input->daylight, v3_normalize(ray->direction));
        return RENDER_MISS;
    }
    const rad_mesh *mesh = input->mesh;
    const rad_patch *patch = &mesh->patches[hit->patch];
    vec3 p = v3_mad(ray->origin, ray->direction, hit->t);
    const rad_material *m = input->materials && depth < pass->specular_depth
                                ? &input->materials[patch->material] : NULL;
    if (m && m->specular_kind == RAD_SPECULAR_NONE)
        m = NULL;
    bool back = v3_dot(ray->direction, patch->normal) > 0.0;
    if (back && !(m && m->specular_kind == RAD_SPECULAR_GLASS))
        return RENDER_BACK;
    if (m) /* the specular part: the pixel is refined as an edge would be */
        specular_part(pass, m, p, v3_normalize(ray->direction), patch->normal, depth, carried, key, rng, rgb);
    if (back)
        return RENDER_MIXED;
    double s, t, local_s, local_t;
    rad_patch_parameters(patch, p, &s, &t);
    uint32_t e = rad_mesh_locate(mesh, hit->patch, s, t, &local_s, &local_t);
    bool smooth = shading == RAD_SHADING_SMOOTH && input->vertex_radiosity;
    double diffuse[3];
    if (input->vpls) {
        /* Keyed on (pixel, stratum, stream) from the eye; a path's later
         * diffuse ends on a draw of its own stream. */
        uint64_t k = depth == 0 ? key : (uint64_t)(rad_rng_uniform(rng) * 9007199254740992.0);
        shade_vpl(input, pass->epsilon, e, patch, p, k, diffuse);
        for (int c = 0; c < 3; c++)
            rgb[c] += diffuse[c];
        return m ? RENDER_MIXED : hit->patch;
    }
    if (smooth) {
        rad_element_interpolate(mesh, &mesh->elements[e], input->vertex_radiosity, local_s,
                                local_t, diffuse);
    } else {
        for (int c = 0; c < 3; c++)
            diffuse[c] = input->element_radiosity[3 * (size_t)e + (size_t)c];
    }
    /* The final gather: the emitters' light at this very point (or at the
     * pixel's, render_row; not where a texture varies the reflectance). */
    if (pass->caches && pass->defer && depth == 0 && !(input->scene && rad_scene_textured(input->scene, patch->polygon))) {
        pass->defer->valid = true;
        pass->defer->point = p;
        pass->defer->element = e;
    } else if (pass->caches) {
        int thread = 0;
#ifdef _OPENMP
        thread = omp_get_thread_num();
#endif
        double direct[3];
        rad_direct_at(input->direct, &pass->caches[thread], e, p, key, direct);
        for (int c = 0; c < 3; c++)
            diffuse[c] += input->reflectance[3 * (size_t)e + (size_t)c] * direct[c];
    }
    /* A texture modulates the reflected part by the texel's reflectance
     * over the element's mean (which the solution used): a texture of one
     * colour changes nothing. */
    if (input->scene && input->reflectance && input->emission &&
        rad_scene_textured(input->scene, patch->polygon)) {
        double rho[3];
        rad_scene_reflectance_at(input->scene, patch->polygon, p, rho);
        for (int c = 0; c < 3; c++) {
            double mean = input->reflectance[3 * (size_t)e + (size_t)c], E = input->emission[3 * (size_t)e + (size_t)c];
            if (mean > 0.0)
                diffuse[c] = E + (diffuse[c] - E) * (rho[c] / mean);
        }
    }
    for (int c = 0; c < 3; c++)
        rgb[c] += diffuse[c];
    return m ? RENDER_MIXED : smooth ? hit->patch : e;
}

/* The camera ray through stratum `stratum` of `grid` x `grid` of pixel
 * (x, y), jittered by the stream `stream` keyed on (pixel, stratum). */
static void camera_ray(const render_view *view, uint64_t stream, uint64_t x, int y, uint64_t stratum,
                       uint64_t grid, rad_ray *ray)
{
    uint64_t pixel = (uint64_t)y * (uint64_t)view->width + x;
    rad_rng rng = rad_rng_keyed(stream, pixel, stratum);
    double jx = rad_rng_uniform(&rng), jy = rad_rng_uniform(&rng);
    double fx = ((double)x + ((double)(stratum % grid) + jx) / (double)grid) / view->width;
    double fy = ((double)y + ((double)(stratum / grid) + jy) / (double)grid) / view->height;
    ray->origin = view->position;
    ray->direction = v3_mad(v3_mad(view->forward, view->right, 2.0 * fx - 1.0), view->up, 1.0 - 2.0 * fy);
    ray->tnear = 0.0;
    ray->tfar = INFINITY;
}


/* Pixels `pixel[0 .. count)` of row y, `grid` x `grid` strata each, in
 * batches of `batch` rays: their sums into sum[3 x]; seen[x] what all of a
 * pixel's rays saw when they agree, RENDER_MIXED when they do not. */
static void trace_pixels(const render_pass *pass, const render_view *view, int y,
                         const uint32_t *pixel, size_t count, uint64_t grid, uint64_t stream, size_t batch,
                         rad_ray *rays, rad_hit *hits, double *sum, uint32_t *seen, double *deferred_sum,
                         uint32_t *deferred)
{
    /* deferred_sum (3 per pixel: the sum of its deferred points) and
     * deferred (2 per pixel: their count, the first one's element), or
     * NULL: every point's direct light added at once. */
    render_pass local = *pass;
    render_deferred note;
    local.defer = deferred ? &note : NULL;
    pass = &local;
    const uint64_t per_pixel = grid * grid, total = (uint64_t)count * per_pixel;
    for (uint64_t first = 0; first < total; first += batch) {
        size_t n = (size_t)(total - first < batch ? total - first : batch);
        for (size_t k = 0; k < n; k++) {
            uint64_t r = first + k;
            camera_ray(view, stream, pixel[r / per_pixel], y, r % per_pixel, grid, &rays[k]);
        }
        pass->input->vis->backend->intersect(pass->input->vis->state, rays, n, hits);
        for (size_t k = 0; k < n; k++) {
            uint64_t r = first + k, x = pixel[r / per_pixel];
            double rgb[3];
            /* The second pass's stream: keyed like the camera ray's, apart. */
            rad_rng rng = rad_rng_keyed(stream ^ 0x5bd1e9955bd1e995ULL,
                                        (uint64_t)y * (uint64_t)view->width + x, r % per_pixel);
            uint64_t key = ((uint64_t)y * (uint64_t)view->width + x) * per_pixel * 2 + (r % per_pixel) * 2 + stream;
            note.valid = false;
            uint32_t what = shade(pass, &rays[k], &hits[k], 0, 1.0, key, &rng, rgb);
            if (r % per_pixel == 0) {
                sum[3 * x] = sum[3 * x + 1] = sum[3 * x + 2] = 0.0;
                seen[x] = what;
                if (deferred) {
                    deferred_sum[3 * x] = deferred_sum[3 * x + 1] = deferred_sum[3 * x + 2] = 0.0;
                    deferred[2 * x] = 0;
                }
            } else if (seen[x] != what) {
                seen[x] = RENDER_MIXED;
            }
            if (deferred && note.valid) {
                if (deferred[2 * x]++ == 0)
                    deferred[2 * x + 1] = note.element;
                deferred_sum[3 * x] += note.point.x;
                deferred_sum[3 * x + 1] += note.point.y;
                deferred_sum[3 * x + 2] += note.point.z;
            }
            for (int c = 0; c < 3; c++)
                sum[3 * x + (uint64_t)c] += rgb[c];
        }
    }
}

/* One row: every pixel's 2 x 2 pilot, then all strata where the pilot
 * saw more than one thing (file header); writes the row's pixels. */
static void render_row(const render_pass *pass, const render_view *view, int y, size_t batch, rad_ray *rays, rad_hit *hits,
                       double *sum, uint32_t *seen, uint32_t *pixel, double *deferred_sum, uint32_t *deferred,
                       float *pixels)
{
    const uint64_t grid = (uint64_t)view->samples, pilot = grid > 2 ? 2 : grid;
    size_t width = (size_t)view->width;
    for (size_t x = 0; x < width; x++)
        pixel[x] = (uint32_t)x;
    /* The pilot is the final sampling when the grid is no finer (stream 0,
     * as the full strata: the same rays then).  The final gather's direct
     * light is deferred in the pilot when pixels that see more go on to
     * all strata (which take it point by point). */
    bool defer = pass->caches && pilot < grid;
    trace_pixels(pass, view, y, pixel, width, pilot, pilot == grid ? 0 : 1, batch, rays, hits, sum, seen,
                 defer ? deferred_sum : NULL, defer ? deferred : NULL);
    if (defer) {
        const rad_render_input *input = pass->input;
        int thread = 0;
#ifdef _OPENMP
        thread = omp_get_thread_num();
#endif
        for (size_t x = 0; x < width; x++) {
            if (seen[x] == RENDER_MIXED || deferred[2 * x] == 0)
                continue;
            /* The points' mean, on the patch they all lie on. */
            double count = deferred[2 * x];
            vec3 p = v3(deferred_sum[3 * x] / count, deferred_sum[3 * x + 1] / count, deferred_sum[3 * x + 2] / count);
            uint32_t patch = input->mesh->elements[deferred[2 * x + 1]].patch;
            double s, t, ls, lt, direct[3];
            rad_patch_parameters(&input->mesh->patches[patch], p, &s, &t);
            uint32_t e = rad_mesh_locate(input->mesh, patch, s, t, &ls, &lt);
            rad_direct_at(input->direct, &pass->caches[thread], e, p, (uint64_t)y * (uint64_t)width + x, direct);
            for (int c = 0; c < 3; c++)
                sum[3 * x + (size_t)c] += count * input->reflectance[3 * (size_t)e + (size_t)c] * direct[c];
        }
    }
    double scale[2] = {1.0 / (M_PI * (double)(pilot * pilot)), /* mean, and L = B / pi */
                       1.0 / (M_PI * (double)(grid * grid))};
    size_t again = 0;
    if (pilot < grid)
        for (size_t x = 0; x < width; x++)
            if (seen[x] == RENDER_MIXED)
                pixel[again++] = (uint32_t)x;
    for (size_t x = 0; x < width; x++)
        seen[x] = 0; /* pilot scale */
    for (size_t i = 0; i < again; i++)
        seen[pixel[i]] = 1;
    /* Sums of the refined pixels are overwritten with their full strata. */
    uint32_t *unused = pixel + width; /* what the full strata saw: not needed */
    if (again)
        trace_pixels(pass, view, y, pixel, again, grid, 0, batch, rays, hits, sum, unused, NULL, NULL);
    for (size_t x = 0; x < width; x++)
        for (int c = 0; c < 3; c++)
            pixels[3 * x + (size_t)c] = (float)(sum[3 * x + (size_t)c] * scale[seen[x]]);
}

rad_result rad_render_image(rad_context *ctx, const rad_render_input *input,
                            const rad_render_options *options, rad_image **out)
{
    *out = NULL;
    rad_render_options o = options ? *options : (rad_render_options){0};
    int width = option_or_default(o.width, 512);
    int height = option_or_default(o.height, 512);
    int samples = option_or_default(o.samples, 4);
    rad_result r;
    if ((r = check_size(ctx, "width", width)) != RAD_OK ||
        (r = check_size(ctx, "height", height)) != RAD_OK ||
        (r = check_size(ctx, "samples", samples)) != RAD_OK)
        return r;
    render_view view;
    if ((r = make_view(ctx, &input->camera, width, height, samples, &view)) != RAD_OK ||
        (r = check_camera_distance(ctx, input)) != RAD_OK)
        return r;

    if (o.specular_depth < -1 || o.specular_depth > 64)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "rad_render_options.specular_depth must be in [-1, 64], got %d", o.specular_depth);
    if (o.glossy_samples != 0 && (r = check_size(ctx, "glossy_samples", o.glossy_samples)) != RAD_OK)
        return r;
    render_pass pass = {input, NULL, NULL, o.shading, o.specular_depth < 0 ? 0 : option_or_default(o.specular_depth, 8),
                        option_or_default(o.glossy_samples, 16), rad_vis_epsilon(input->mesh)};

    int threads = ctx && ctx->threads > 0 ? ctx->threads : 1;
    if (input->direct && rad_direct_light_active(input->direct) && input->reflectance && !input->vpls) {
        pass.caches = rad_alloc(ctx, RAD_MEM_RENDER, (size_t)threads, sizeof *pass.caches, "render: gather caches");
        int ready = 0;
        r = pass.caches ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;
        for (; r == RAD_OK && ready < threads; ready++)
            if ((r = rad_direct_cache_init(ctx, input->direct, &pass.caches[ready])) != RAD_OK)
                break;
        if (r != RAD_OK) {
            for (int t = 0; t < ready; t++)
                rad_direct_cache_free(&pass.caches[t]);
            rad_free(pass.caches);
            return r;
        }
    }
    /* A row's rays, up to RAD_RENDER_BATCH at a time: small images need no more. */
    uint64_t row_rays = (uint64_t)width * (uint64_t)samples * (uint64_t)samples;
    size_t batch = row_rays < RAD_RENDER_BATCH ? (size_t)row_rays : RAD_RENDER_BATCH;
    rad_image *image = rad_image_create(ctx, width, height);
    rad_ray *rays = image ? rad_alloc(ctx, RAD_MEM_RENDER, (size_t)threads * batch, sizeof *rays, "render rays")
                          : NULL;
    rad_hit *hits = rays ? rad_alloc(ctx, RAD_MEM_RENDER, (size_t)threads * batch, sizeof *hits, "render hits")
                         : NULL;
    double *sums = hits ? rad_alloc(ctx, RAD_MEM_RENDER, (size_t)threads * (size_t)width, 3 * sizeof(double),
                                    "render rows")
                        : NULL;
    /* Per thread and pixel of a row: what it saw, and two pixel lists. */
    uint32_t *marks = sums ? rad_alloc(ctx, RAD_MEM_RENDER, (size_t)threads * (size_t)width, 3 * sizeof(uint32_t),
                                       "render rows")
                           : NULL;
    double *deferred_sums = marks ? rad_alloc(ctx, RAD_MEM_RENDER, (size_t)threads * (size_t)width, 3 * sizeof(double),
                                              "render rows")
                                  : NULL;
    uint32_t *deferred = deferred_sums ? rad_alloc(ctx, RAD_MEM_RENDER, (size_t)threads * (size_t)width,
                                                   2 * sizeof(uint32_t), "render rows")
                                       : NULL;
    if (!deferred) {
        rad_free(marks);
        rad_free(deferred_sums);
        marks = NULL;
    }
    if (!marks) {
        if (pass.caches) {
            for (int t = 0; t < threads; t++)
                rad_direct_cache_free(&pass.caches[t]);
            rad_free(pass.caches);
        }
        rad_image_destroy(image);
        rad_free(rays);
        rad_free(hits);
        rad_free(sums);
        return RAD_ERROR_OUT_OF_MEMORY;
    }

    int rows_done = 0, rows_skipped = 0;
    rad_progress(ctx, "render", 0, (uint64_t)height);
#pragma omp parallel num_threads(threads)
    {
        int thread = 0;
#ifdef _OPENMP
        thread = omp_get_thread_num();
#endif
        rad_ray *my_rays = rays + (size_t)thread * batch;
        rad_hit *my_hits = hits + (size_t)thread * batch;
        double *my_sum = sums + (size_t)thread * (size_t)width * 3;
        uint32_t *my_seen = marks + (size_t)thread * (size_t)width * 3, *my_pixel = my_seen + width;
#pragma omp for schedule(dynamic)
        for (int y = 0; y < height; y++) {
            if (rad_cancelled(ctx)) {
#pragma omp atomic update
                rows_skipped++;
                continue;
            }
            render_row(&pass, &view, y, batch, my_rays, my_hits, my_sum, my_seen, my_pixel,
                       deferred_sums + (size_t)thread * (size_t)width * 3, deferred + (size_t)thread * (size_t)width * 2,
                       &image->pixels[(size_t)y * (size_t)width * 3]);
            int done;
#pragma omp atomic capture
            done = ++rows_done;
            if (thread == 0) /* progress callbacks run on the calling thread only */
                rad_progress(ctx, "render", (uint64_t)done, (uint64_t)height);
        }
    }
    rad_free(rays);
    rad_free(hits);
    rad_free(sums);
    rad_free(marks);
    rad_free(deferred_sums);
    rad_free(deferred);
    if (pass.caches) {
        for (int t = 0; t < threads; t++)
            rad_direct_cache_free(&pass.caches[t]);
        rad_free(pass.caches);
    }
    rad_progress(ctx, "render", (uint64_t)rows_done, (uint64_t)height);
    *out = image;
    if (rows_skipped > 0)
        return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "render: interrupted after %d of %d rows",
                        rows_done, height);
    return RAD_OK;
}
