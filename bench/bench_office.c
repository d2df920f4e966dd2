/*
 * bench_office.c -- a whole lighting-design run on an open-plan office:
 * load (the seeded generator, 10 rooms), mesh, visibility and form
 * factors, direct light, solve, and the illuminance on about 2,000
 * calculation points (each room's floor footprint at 0.8 m, the 0.5 m
 * border of EN 12464-1).  Prints each phase's seconds, the grid's points
 * per second, and the shadow rays per second of the gathering against the
 * engine's visibility layer and a bare Embree loop on random segments of
 * the same mesh, in the same run.
 *
 *   build/bench/bench_office [--threads N] [--rooms N] [--points N] [--elements N] [--panels]
 *
 * The light: four luminaires per room (40 in all), placed by a layout file
 * (docs/lighting.md "Luminaires") written here in memory: the Lambertian
 * downlight of tests/data/luminaires at 4,000 lm, 10 cm below the ceiling
 * at the room's quarter points; the generator's ceiling panels stop
 * emitting (a scene lit by luminaires has no emitting surface).  With
 * --panels, the panels light the office instead and no layout is read.
 * Fixed seed (1): figures are comparable across commits on one machine.
 */
#include "api/solution.h"

#include <embree3/rtcore.h>
#include <stdlib.h>
#include <string.h>

static void usage(void)
{
    fprintf(stderr, "usage: bench_office [--threads N] [--rooms N] [--points N] [--elements N] [--panels]\n");
    exit(2);
}

/* Random point pairs on the elements, as the form-factor code casts them
 * (bench_phases.c's rays). */
static void make_rays(const rad_mesh *mesh, size_t count, rad_ray *rays)
{
    rad_rng rng = rad_rng_keyed(0, 1, 2);
    double eps = rad_vis_epsilon(mesh);
    size_t n = mesh->element_count;
    for (size_t k = 0; k < count; k++) {
        const rad_element *a = &mesh->elements[(size_t)(rad_rng_uniform(&rng) * n)];
        const rad_element *b = &mesh->elements[(size_t)(rad_rng_uniform(&rng) * n)];
        double s0 = rad_rng_uniform(&rng), t0 = rad_rng_uniform(&rng);
        double s1 = rad_rng_uniform(&rng), t1 = rad_rng_uniform(&rng);
        vec3 p = v3_mad(rad_element_sample(mesh, a, s0, t0), a->normal, eps);
        vec3 q = v3_mad(rad_element_sample(mesh, b, s1, t1), b->normal, eps);
        rays[k] = (rad_ray){p, v3_sub(q, p), 0.0, 1.0};
    }
}

/* A bare rtcOccluded1 loop over the patches as triangles, one thread. */
static double bare_embree_rays_per_second(const rad_mesh *mesh, const rad_ray *rays, size_t count)
{
    RTCDevice dev = rtcNewDevice("threads=1");
    RTCScene scene = rtcNewScene(dev);
    RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    size_t ntri = 0;
    for (size_t p = 0; p < mesh->patch_count; p++)
        ntri += mesh->patches[p].corner_count == 4 ? 2 : 1;
    float *v = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                       3 * ntri);
    unsigned *idx = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                            ntri);
    size_t t = 0;
    for (size_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *pa = &mesh->patches[p];
        for (int k = 0; k < (pa->corner_count == 4 ? 2 : 1); k++, t++) {
            int c[3] = {0, k + 1, k + 2};
            for (int m = 0; m < 3; m++) {
                v[9 * t + 3 * m] = (float)pa->corner[c[m]].x;
                v[9 * t + 3 * m + 1] = (float)pa->corner[c[m]].y;
                v[9 * t + 3 * m + 2] = (float)pa->corner[c[m]].z;
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
    for (size_t k = 0; k < count; k++) {
        struct RTCRay r = {0};
        r.org_x = (float)rays[k].origin.x, r.org_y = (float)rays[k].origin.y, r.org_z = (float)rays[k].origin.z;
        r.dir_x = (float)rays[k].direction.x, r.dir_y = (float)rays[k].direction.y;
        r.dir_z = (float)rays[k].direction.z;
        r.tnear = 0.0f;
        r.tfar = 1.0f;
        r.mask = 0xFFFFFFFFu;
        rtcOccluded1(scene, &ictx, &r);
    }
    double dt = rad_seconds() - t0;
    rtcReleaseScene(scene);
    rtcReleaseDevice(dev);
    return (double)count / dt;
}

int main(int argc, char **argv)
{
    int threads = 0, rooms = 10, panels = 0;
    size_t points = 2000, elements = 2000;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--rooms") == 0 && i + 1 < argc)
            rooms = atoi(argv[++i]);
        else if (strcmp(argv[i], "--points") == 0 && i + 1 < argc)
            points = (size_t)atol(argv[++i]);
        else if (strcmp(argv[i], "--elements") == 0 && i + 1 < argc)
            elements = (size_t)atol(argv[++i]);
        else if (strcmp(argv[i], "--panels") == 0)
            panels = 1;
        else
            usage();
    }
    rad_context_options co = {0};
    co.threads = threads;
    rad_context *ctx;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 1;
    /* 1. load: the generated office */
    double t0 = rad_seconds();
    rad_office_options oo = {rooms, 1, 0};
    rad_scene *scene;
    if (rad_scene_generate_office(ctx, &oo, &scene) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    /* The layout: 4 downlights per room at its quarter points, from each
     * room's floor (x, z extent) and ceiling (height). */
    size_t luminaires = 0;
    if (!panels) {
        for (size_t m = 0; m < scene->material_count; m++)
            if (strcmp(scene->materials[m].name, "light_panel") == 0)
                memset(scene->materials[m].emission, 0, sizeof scene->materials[m].emission);
        size_t lcap = 512 + 4 * 200 * (size_t)rooms, llen = 0;
        char *layout = malloc(lcap);
        llen += (size_t)snprintf(layout + llen, lcap - llen, "{\"up\": [0, 1, 0], \"luminaires\": [");
        for (int room = 0; room < rooms; room++) {
            char fname[64], cname[64];
            snprintf(fname, sizeof fname, "room%d/floor", room);
            snprintf(cname, sizeof cname, "room%d/ceiling", room);
            double x0 = INFINITY, x1 = -INFINITY, z0 = INFINITY, z1 = -INFINITY, top = -INFINITY;
            for (size_t q = 0; q < scene->polygon_count; q++) {
                const rad_polygon *poly = &scene->polygons[q];
                const char *sname = scene->surfaces[poly->surface].name;
                bool fl = strcmp(sname, fname) == 0, ce = strcmp(sname, cname) == 0;
                for (uint32_t c = 0; (fl || ce) && c < poly->vertex_count; c++) {
                    vec3 x = scene->positions[scene->indices[poly->first_index + c]];
                    if (fl)
                        x0 = fmin(x0, x.x), x1 = fmax(x1, x.x), z0 = fmin(z0, x.z), z1 = fmax(z1, x.z);
                    else
                        top = fmax(top, x.y);
                }
            }
            for (int k = 0; k < 4; k++) {
                double px = x0 + (x1 - x0) * (k % 2 ? 0.75 : 0.25), pz = z0 + (z1 - z0) * (k / 2 ? 0.75 : 0.25);
                llen += (size_t)snprintf(layout + llen, lcap - llen, "%s{\"file\": \"downlight.ies\", \"lumens\": "
                                         "4000, \"position\": [%.4f, %.4f, %.4f], \"name\": \"room%d-%d\"}",
                                         luminaires ? ", " : "", px, top - 0.1, pz, room, k);
                luminaires++;
            }
        }
        snprintf(layout + llen, lcap - llen, "]}");
        if (rad_scene_load_luminaires_memory(ctx, scene, RAD_BENCH_DATA "/luminaires/office_layout.json", layout,
                                             strlen(layout)) != RAD_OK) {
            fprintf(stderr, "%s\n", rad_context_error(ctx));
            return 1;
        }
        free(layout);
    }
    double load = rad_seconds() - t0;
    /* The grid file: each room's floor footprint at 0.8 m, border 0.5 m, one
     * spacing over all rooms for about `points` points in all. */
    double area = 0.0;
    int floors = 0;
    for (size_t s = 0; s < scene->surface_count; s++) {
        const char *name = scene->surfaces[s].name, *slash = strchr(name, '/');
        if (slash && strcmp(slash, "/floor") == 0) {
            area += scene->surfaces[s].area;
            floors++;
        }
    }
    /* The border takes about a third of the floors: 0.66 of the floor area over the points asked. */
    double spacing = sqrt(0.66 * area / (double)points);
    size_t cap = 256 + 160 * (size_t)floors, len = 0;
    char *json = malloc(cap);
    len += (size_t)snprintf(json + len, cap - len, "{\"up\": \"y\", \"grids\": [");
    for (size_t s = 0, k = 0; s < scene->surface_count; s++) {
        const char *name = scene->surfaces[s].name, *slash = strchr(name, '/');
        if (slash && strcmp(slash, "/floor") == 0)
            len += (size_t)snprintf(json + len, cap - len, "%s{\"name\": \"%s\", \"surface\": \"%s\", \"height\": 0.8, "
                                    "\"spacing\": %.6f}", k++ ? ", " : "", name, name, spacing);
    }
    snprintf(json + len, cap - len, "]}");

    /* 2-4. mesh, visibility, form factors (direct light), solve */
    rad_options o = {0};
    o.target_elements = elements;
    o.solver = "gauss-seidel";
    o.seed = 1;
    rad_solution *sol;
    double c0 = rad_seconds();
    if (rad_solution_create(ctx, scene, &o, &sol) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    double create = rad_seconds() - c0;
    if (rad_solution_solve(ctx, sol) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    /* 5. the grid */
    rad_illuminance *il;
    if (rad_illuminance_evaluate_memory(ctx, sol, "office_grid.json", json, strlen(json), &il) != RAD_OK) {
        fprintf(stderr, "%s\n", rad_context_error(ctx));
        return 1;
    }
    double total = rad_seconds() - t0;
    rad_illuminance_stats st;
    rad_illuminance_get_stats(il, &st);
    const rad_solution_view *v = &sol->view;
    size_t emitters = 0;
    for (size_t s = 0; s < scene->surface_count && panels; s++)
        emitters += strstr(scene->surfaces[s].name, "/light") && !strstr(scene->surfaces[s].name, "housing");
    printf("office: %d rooms (seed 1), %zu surfaces, %zu luminaires, %zu emitting panels, %zu elements, %zu patches, "
           "%d threads\n", rooms, scene->surface_count, luminaires, emitters, v->n, v->mesh->patch_count,
           rad_context_threads(ctx));
    printf("grid: %zu floor footprints at 0.8 m, border 0.5 m, spacing %.3f m: %zu points\n", (size_t)floors,
           spacing, st.points);
    /* What creating the solution spent beyond mesh, BVH and form factors:
     * the element arrays and the direct light's element means. */
    double direct = create - v->seconds.mesh - v->seconds.visibility - v->seconds.form_factors;
    printf("%8s %8s %8s %8s %8s %8s %8s %8s\n", "load", "mesh", "bvh", "ff", "direct", "solve", "grid", "total");
    printf("%8.3f %8.3f %8.4f %8.3f %8.3f %8.3f %8.3f %8.3f\n", load, v->seconds.mesh, v->seconds.visibility,
           v->seconds.form_factors, direct, v->seconds.solve, st.seconds, total);
    double eavg = 0.0, u0 = 1.0;
    for (size_t g = 0; g < rad_illuminance_grid_count(il); g++) {
        const rad_grid_result *r = rad_illuminance_grid(il, g);
        eavg += r->average * (double)r->point_count;
        u0 = fmin(u0, r->uniformity);
    }
    printf("illuminance: Eavg %.1f lux over all points, lowest room U0 %.3f\n", eavg / (double)st.points, u0);
    /* Where each room's lowest point is: the floor footprints run through
     * the furniture, and the lowest points of seed 1 lie on a chair back's
     * rear face (z of the face, 0.8 m between its 0.45 and 0.9), half their
     * hemisphere inside the back: a few lux.  That is the grid's placement,
     * not the light. */
    for (size_t g = 0; g < rad_illuminance_grid_count(il); g++) {
        const rad_grid_result *r = rad_illuminance_grid(il, g);
        size_t lo = 0;
        for (size_t k = 1; k < r->point_count; k++)
            lo = r->points[k].illuminance < r->points[lo].illuminance ? k : lo;
        printf("  %s: Emin %.1f at (%.2f, %.2f, %.2f) direct %.1f indirect %.1f\n", r->name, r->points[lo].illuminance,
                   r->points[lo].position[0], r->points[lo].position[1], r->points[lo].position[2], r->points[lo].direct,
                   r->points[lo].indirect);
    }
    /* The gathering's own time: all the points' thread-seconds less the
     * direct light's (luminaires, daylight). */
    double gathering = st.thread_seconds - st.light_seconds;
    printf("grid: %.0f points/s (wall); per point %.3f ms of direct light, %.3f ms of gathering (thread time)\n",
           st.points_per_second, 1e3 * st.light_seconds / (double)st.points, 1e3 * gathering / (double)st.points);
    printf("gathering: %llu shadow rays (%.0f per point), %.2f M rays per thread-second of gathering; %llu "
           "point-element pairs by rays, %llu exact\n",
           st.shadow_rays, (double)st.shadow_rays / (double)st.points, (double)st.shadow_rays / gathering / 1e6,
           st.ray_pairs, st.exact_pairs);
    fflush(stdout);

    /* Ray throughput on the same mesh, one thread: the engine's layer and a
     * bare Embree loop, 1,000,000 random element-to-element segments. */
    size_t nrays = 1000000;
    rad_ray *rays = malloc(nrays * sizeof *rays);
    uint8_t *hit = malloc(nrays);
    make_rays(v->mesh, nrays, rays);
    double r0 = rad_seconds();
    for (size_t k = 0; k < nrays; k += 64)
        v->vis->backend->occluded(v->vis->state, rays + k, nrays - k < 64 ? nrays - k : 64, hit + k);
    double ours = (double)nrays / (rad_seconds() - r0);
    double bare = bare_embree_rays_per_second(v->mesh, rays, nrays);
    double gather_per_thread = (double)st.shadow_rays / gathering;
    printf("rays, 1 thread, random segments: engine layer %.2f M rays/s, bare Embree %.2f M rays/s\n", ours / 1e6,
           bare / 1e6);
    printf("gathering: %.2f M rays per thread-second = %.2f of the engine layer's rate on random segments (the "
           "rest of its time is the exact point-to-polygon factors)\n", gather_per_thread / 1e6,
           gather_per_thread / ours);
    free(rays);
    free(hit);
    free(json);
    rad_illuminance_destroy(il);
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
