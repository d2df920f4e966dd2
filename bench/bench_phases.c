/*
 * bench_phases.c -- seconds per pipeline phase on the built-in Cornell box
 * at fixed element counts, and shadow-ray throughput of the engine's
 * visibility layer against a bare Embree occlusion loop on the same scene.
 *
 *   build/bench/bench_phases [--threads N] [--elements N1,N2,...] [--rays N]
 *
 * Fixed seed (0), fixed scene, fixed element targets (default 1000, 4000,
 * 16000): figures are comparable across commits on the same machine.
 * See docs/performance.md for the figures and how they were taken.
 */
#include "api/solution.h"

#include <embree3/rtcore.h>
#include <stdlib.h>
#include <string.h>

static void usage(void)
{
    fprintf(stderr, "usage: bench_phases [--threads N] [--elements N1,N2,...] [--rays N]\n");
    exit(2);
}

/* Random point pairs on the elements, as the form-factor code casts them. */
static void make_rays(const rad_mesh *mesh, size_t count, rad_ray *rays)
{
    rad_rng rng = rad_rng_keyed(0, 1, 2);
    double eps = rad_vis_epsilon(mesh);
    size_t n = mesh->element_count;
    for (size_t k = 0; k < count; k++) {
        const rad_element *a = &mesh->elements[(size_t)(rad_rng_uniform(&rng) * n)];
        const rad_element *b = &mesh->elements[(size_t)(rad_rng_uniform(&rng) * n)];
        /* One draw per declarator: a call's arguments are unsequenced. */
        double s0 = rad_rng_uniform(&rng), t0 = rad_rng_uniform(&rng);
        double s1 = rad_rng_uniform(&rng), t1 = rad_rng_uniform(&rng);
        vec3 p = v3_mad(rad_element_sample(mesh, a, s0, t0), a->normal, eps);
        vec3 q = v3_mad(rad_element_sample(mesh, b, s1, t1), b->normal, eps);
        rays[k].origin = p;
        rays[k].direction = v3_sub(q, p);
        rays[k].tnear = 0.0;
        rays[k].tfar = 1.0;
    }
}

/* The bare loop: one Embree triangle scene over the patches, rtcOccluded1. */
static double bare_embree_rays_per_second(const rad_mesh *mesh, const rad_ray *rays, size_t count,
                                          size_t *blocked)
{
    RTCDevice dev = rtcNewDevice("threads=1");
    RTCScene scene = rtcNewScene(dev);
    RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    size_t ntri = 0;
    for (size_t p = 0; p < mesh->patch_count; p++)
        ntri += mesh->patches[p].corner_count == 4 ? 2 : 1;
    float *v = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                       3 * sizeof(float), 3 * ntri);
    unsigned *idx = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                            3 * sizeof(unsigned), ntri);
    size_t t = 0;
    for (size_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *pa = &mesh->patches[p];
        int tris = pa->corner_count == 4 ? 2 : 1;
        for (int k = 0; k < tris; k++, t++) {
            int c[3] = {0, k + 1, k + 2};
            for (int m = 0; m < 3; m++) {
                vec3 q = pa->corner[c[m]];
                v[9 * t + 3 * m] = (float)q.x;
                v[9 * t + 3 * m + 1] = (float)q.y;
                v[9 * t + 3 * m + 2] = (float)q.z;
                idx[3 * t + m] = (unsigned)(3 * t + m);
            }
        }
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    struct RTCIntersectContext ictx;
    rtcInitIntersectContext(&ictx);
    double t0 = rad_seconds();
    size_t hits = 0;
    for (size_t k = 0; k < count; k++) {
        struct RTCRay r;
        r.org_x = (float)rays[k].origin.x;
        r.org_y = (float)rays[k].origin.y;
        r.org_z = (float)rays[k].origin.z;
        r.dir_x = (float)rays[k].direction.x;
        r.dir_y = (float)rays[k].direction.y;
        r.dir_z = (float)rays[k].direction.z;
        r.tnear = 0.0f;
        r.tfar = 1.0f;
        r.mask = 0xFFFFFFFFu;
        r.time = 0.0f;
        r.flags = 0;
        rtcOccluded1(scene, &ictx, &r);
        hits += r.tfar < 0.0f;
    }
    double dt = rad_seconds() - t0;
    rtcReleaseScene(scene);
    rtcReleaseDevice(dev);
    *blocked = hits;
    return (double)count / dt;
}

int main(int argc, char **argv)
{
    int threads = 0;
    size_t targets[8] = {1000, 4000, 16000};
    size_t ntargets = 3, nrays = 2000000;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--rays") == 0 && i + 1 < argc)
            nrays = (size_t)atol(argv[++i]);
        else if (strcmp(argv[i], "--elements") == 0 && i + 1 < argc) {
            ntargets = 0;
            for (char *tok = strtok(argv[++i], ","); tok && ntargets < 8; tok = strtok(NULL, ","))
                targets[ntargets++] = (size_t)atol(tok);
        } else
            usage();
    }
    rad_context_options co = {0};
    co.threads = threads;
    rad_context *ctx;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    rad_scene *scene;
    if (rad_scene_create_cornell_box(ctx, &scene) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    printf("Cornell box, seed 0, %d threads, analytic form factors, gauss-seidel, 512x512 x 4 spp\n",
           rad_context_threads(ctx));
    printf("%9s %7s %7s %9s %12s %8s %8s %9s %12s %9s\n", "elements", "mesh", "bvh", "ff", "ff_rays",
           "solve", "render", "total", "ff_pairs/s", "peak_MiB");
    for (size_t k = 0; k < ntargets; k++) {
        rad_options o = {0};
        o.target_elements = targets[k];
        rad_solution *sol;
        double t0 = rad_seconds();
        if (rad_solution_create(ctx, scene, &o, &sol) != RAD_OK ||
            rad_solution_solve(ctx, sol) != RAD_OK) {
            fprintf(stderr, "%s\n", rad_context_error(ctx));
            return 1;
        }
        rad_image *img;
        if (rad_solution_render(ctx, sol, NULL, &img) != RAD_OK) {
            fprintf(stderr, "%s\n", rad_context_error(ctx));
            return 1;
        }
        double total = rad_seconds() - t0;
        printf("%9zu %7.3f %7.4f %9.3f %12llu %8.3f %8.3f %9.3f %12.3g %9.0f\n",
               sol->view.mesh->element_count, sol->view.seconds.mesh, sol->view.seconds.visibility,
               sol->view.seconds.form_factors, (unsigned long long)sol->view.ff->rays, sol->view.seconds.solve,
               sol->view.seconds.render, total, (double)sol->view.ff->pairs / sol->view.seconds.form_factors,
               (double)rad_peak_memory_bytes() / 1048576.0);
        fflush(stdout);
        rad_image_destroy(img);
        rad_solution_destroy(sol);
    }

    /* Shadow-ray throughput, one thread, same rays for both. */
    rad_context_options c1 = {0};
    c1.threads = 1;
    rad_context *ctx1;
    rad_context_create(&c1, &ctx1);
    rad_mesh_options mo = {0, 4000, 0};
    rad_mesh *mesh;
    rad_mesh_build(ctx1, scene, &mo, &mesh);
    rad_ray *rays = malloc(nrays * sizeof *rays);
    uint8_t *hit = malloc(nrays);
    make_rays(mesh, nrays, rays);
    rad_vis *vis;
    rad_vis_create(ctx1, "embree", mesh, &vis);
    double t0 = rad_seconds();
    const size_t batch = 64;
    for (size_t k = 0; k < nrays; k += batch)
        vis->backend->occluded(vis->state, rays + k, nrays - k < batch ? nrays - k : batch, hit + k);
    double ours = (double)nrays / (rad_seconds() - t0);
    size_t ours_blocked = 0, bare_blocked = 0;
    for (size_t k = 0; k < nrays; k++)
        ours_blocked += hit[k];
    double bare = bare_embree_rays_per_second(mesh, rays, nrays, &bare_blocked);
    printf("\nshadow rays, 1 thread, %zu random element-to-element rays (%zu patches):\n", nrays,
           mesh->patch_count);
    printf("  engine visibility layer: %6.2f M rays/s (%zu blocked)\n", ours / 1e6, ours_blocked);
    printf("  bare Embree rtcOccluded1: %6.2f M rays/s (%zu blocked)\n", bare / 1e6, bare_blocked);
    printf("  ratio: %.2f\n", ours / bare);
    free(rays);
    free(hit);
    rad_vis_destroy(vis);
    rad_mesh_destroy(mesh);
    rad_context_destroy(ctx1);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
