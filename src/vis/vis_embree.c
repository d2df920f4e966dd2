/*
 * vis_embree.c -- the production visibility backend on Embree 3 (Wald et
 * al., "Embree: a kernel framework for efficient CPU ray tracing", 2014).
 *
 * One device and one scene per handle.  The scene holds two geometries
 * built from the primitive list (vis.h: flat patches whole, bent ones as
 * their elements): triangles (RTC_GEOMETRY_TYPE_TRIANGLE) and quads
 * (RTC_GEOMETRY_TYPE_QUAD); an array per geometry maps Embree's primID back
 * to the primitive, and so to its patch.
 *
 * Embree works in float and asserts that ray origins and directions stay
 * below 1.8e18 (its FLT_LARGE).  So the geometry is handed over in a frame
 * of its own: translated to the centre of its bounding box and scaled by
 * the power of two that brings its half-diagonal to [1, 2).  Rays are mapped
 * the same way in double, with a unit direction and their parameters in
 * that frame.  Float rounding is then relative to the scene's size, not to
 * its distance from the origin nor to its unit, and a scene of 1e-20 m or
 * of 1e25 m is traced exactly as the same scene in metres (a power of two
 * scales every float exactly).  A ray that starts far outside (a camera a
 * thousand scene sizes away) is first advanced, in double, to just before
 * the scene's bounding sphere.  Closest hits are refined in double against
 * the hit patch's plane.
 *
 * Embree runs its own TBB thread pool for the build; the device is created
 * with "threads=N" for the context's N so it does not oversubscribe the
 * OpenMP threads.  Queries are thread-safe once the scene is committed.
 * Occlusion goes in packets of 16 (rtcOccluded16): 1.2-1.7x the rays/s of
 * rtcOccluded1 on incoherent shadow rays in a 54-patch scene (test_vis);
 * closest hits (the renderer's, a small share of the work) go one by one.
 */
#include "vis/vis.h"

#include <embree3/rtcore.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

typedef struct embree_state {
    RTCDevice device;
    RTCScene scene;
    const rad_mesh *mesh;
    vec3 shift;                  /* m: subtracted from geometry and ray origins */
    double scale;                /* 1/m, a power of two: then multiplies them */
    unsigned triangle_geometry;  /* geomID, or RTC_INVALID_GEOMETRY_ID */
    unsigned quad_geometry;
    rad_vis_prim *prims;         /* the primitives (vis.h) */
    size_t prim_count;
    uint32_t *triangle_prim;     /* primID -> index into prims */
    uint32_t *quad_prim;
    atomic_int error_recorded;   /* the first error claims `error` */
    char error[512];
} embree_state;

/* Embree's error callback: keep the first message, for rad_fail. */
static void embree_error(void *user, enum RTCError code, const char *message)
{
    embree_state *s = user;
    if (atomic_exchange(&s->error_recorded, 1) != 0)
        return;
    snprintf(s->error, sizeof s->error, "%s (code %d)", message ? message : "unknown error",
             (int)code);
}

static void embree_destroy(void *state)
{
    embree_state *s = state;
    if (!s)
        return;
    if (s->scene)
        rtcReleaseScene(s->scene);
    if (s->device)
        rtcReleaseDevice(s->device);
    rad_free(s->prims);
    rad_free(s->triangle_prim);
    rad_free(s->quad_prim);
    rad_free(s);
}

/* Add the primitives with `corners` corners as one geometry; returns its
 * geomID, or RTC_INVALID_GEOMETRY_ID if there are none or Embree failed
 * (the error callback has the reason). */
static unsigned embree_add_prims(embree_state *s, uint32_t corners, size_t count,
                                 uint32_t *prim_of_primitive)
{
    if (count == 0)
        return RTC_INVALID_GEOMETRY_ID;
    RTCGeometry geometry = rtcNewGeometry(
        s->device, corners == 3 ? RTC_GEOMETRY_TYPE_TRIANGLE : RTC_GEOMETRY_TYPE_QUAD);
    if (!geometry)
        return RTC_INVALID_GEOMETRY_ID;
    float *position = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                              RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                              corners * count);
    unsigned *index = rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_INDEX, 0, corners == 3 ? RTC_FORMAT_UINT3 : RTC_FORMAT_UINT4,
        corners * sizeof(unsigned), count);
    if (!position || !index) {
        rtcReleaseGeometry(geometry);
        return RTC_INVALID_GEOMETRY_ID;
    }
    size_t primitive = 0;
    for (size_t i = 0; i < s->prim_count; i++) {
        const rad_vis_prim *p = &s->prims[i];
        if (p->corner_count != corners)
            continue;
        for (uint32_t c = 0; c < corners; c++) {
            size_t v = primitive * corners + c;
            vec3 q = v3_scale(v3_sub(p->corner[c], s->shift), s->scale);
            position[3 * v + 0] = (float)q.x;
            position[3 * v + 1] = (float)q.y;
            position[3 * v + 2] = (float)q.z;
            index[v] = (unsigned)v;
        }
        prim_of_primitive[primitive++] = (uint32_t)i;
    }
    rtcCommitGeometry(geometry);
    unsigned id = rtcAttachGeometry(s->scene, geometry);
    rtcReleaseGeometry(geometry);
    return id;
}

static rad_result embree_create(rad_context *ctx, const rad_mesh *mesh, void **state)
{
    *state = NULL;
    embree_state *s = rad_alloc(ctx, RAD_MEM_VISIBILITY, 1, sizeof *s, "Embree visibility");
    if (!s)
        return RAD_ERROR_OUT_OF_MEMORY;
    s->mesh = mesh;
    s->triangle_geometry = s->quad_geometry = RTC_INVALID_GEOMETRY_ID;
    atomic_init(&s->error_recorded, 0);

    rad_result pr = rad_vis_primitives(ctx, mesh, &s->prims, &s->prim_count);
    if (pr != RAD_OK) {
        embree_destroy(s);
        return pr;
    }
    size_t triangles = 0, quads = 0;
    vec3 lo = v3(0, 0, 0), hi = v3(0, 0, 0);
    for (size_t i = 0; i < s->prim_count; i++) {
        const rad_vis_prim *p = &s->prims[i];
        if (p->corner_count == 3)
            triangles++;
        else if (p->corner_count == 4)
            quads++;
        else {
            embree_destroy(s);
            return rad_fail(ctx, RAD_ERROR_INTERNAL, "Embree: primitive %zu has %u corners", i,
                            (unsigned)p->corner_count);
        }
        for (uint32_t c = 0; c < p->corner_count; c++) {
            lo = i == 0 && c == 0 ? p->corner[0] : v3_min(lo, p->corner[c]);
            hi = i == 0 && c == 0 ? p->corner[0] : v3_max(hi, p->corner[c]);
        }
    }
    s->shift = v3_scale(v3_add(lo, hi), 0.5);
    /* 2^-e with half-diagonal = m 2^e, m in [0.5, 1): exact, and the
     * scene then spans [-2, 2] at most.  A point scene keeps scale 1. */
    double half = 0.5 * v3_length(v3_sub(hi, lo));
    int e = 0;
    if (half > 0.0 && isfinite(half))
        frexp(half, &e);
    s->scale = ldexp(1.0, 1 - e);
    s->triangle_prim = rad_alloc(ctx, RAD_MEM_VISIBILITY, triangles, sizeof(uint32_t), "Embree triangle map");
    s->quad_prim = rad_alloc(ctx, RAD_MEM_VISIBILITY, quads, sizeof(uint32_t), "Embree quad map");
    if (!s->triangle_prim || !s->quad_prim) {
        embree_destroy(s);
        return RAD_ERROR_OUT_OF_MEMORY;
    }

    char config[64];
    snprintf(config, sizeof config, "threads=%d", ctx && ctx->threads > 0 ? ctx->threads : 0);
    s->device = rtcNewDevice(config);
    if (!s->device) {
        int code = (int)rtcGetDeviceError(NULL);
        embree_destroy(s);
        return rad_fail(ctx, RAD_ERROR_INTERNAL, "Embree: cannot create a device (error %d)",
                        code);
    }
    rtcSetDeviceErrorFunction(s->device, embree_error, s);
    s->scene = rtcNewScene(s->device);
    if (s->scene) {
        /* Robust traversal: no rays slip through shared patch edges, at a
         * few per cent of speed. */
        rtcSetSceneFlags(s->scene, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(s->scene, RTC_BUILD_QUALITY_HIGH);
        s->triangle_geometry = embree_add_prims(s, 3, triangles, s->triangle_prim);
        s->quad_geometry = embree_add_prims(s, 4, quads, s->quad_prim);
        rtcCommitScene(s->scene);
    }
    if (!s->scene || rtcGetDeviceError(s->device) != RTC_ERROR_NONE ||
        atomic_load(&s->error_recorded)) {
        rad_result r = rad_fail(ctx, RAD_ERROR_INTERNAL, "Embree: scene build failed: %s",
                                s->error[0] ? s->error : "no message");
        embree_destroy(s);
        return r;
    }
    *state = s;
    return RAD_OK;
}

/* Beyond this distance from the centre (in the scaled frame, where the
 * scene lies within radius 2), a ray's origin is advanced along the ray
 * before it is rounded to float. */
#define EMBREE_FAR 64.0

/* Our ray in Embree's float frame; returns 0 for an empty segment, else
 * sets *t_offset and *t_scale so that our t = offset + scale * Embree's t.
 * Embree needs tnear >= 0, so a negative tnear is taken as 0 (both
 * backends). */
static int embree_ray(const embree_state *s, const rad_ray *ray, struct RTCRay *out,
                      double *t_offset, double *t_scale)
{
    double tnear = ray->tnear > 0.0 ? ray->tnear : 0.0, tfar = ray->tfar;
    vec3 o = v3_scale(v3_sub(ray->origin, s->shift), s->scale);
    vec3 d = v3_scale(ray->direction, s->scale);
    double length = v3_length(d);
    if (!(tfar > tnear) || !(length > 0.0) || !isfinite(length) || !v3_finite(o))
        return 0;
    /* A far origin: start at the entry into the sphere of radius
     * EMBREE_FAR instead (nothing lies before it), or give up on a ray
     * that passes the sphere by. */
    double offset = 0.0;
    if (v3_length(o) > EMBREE_FAR) {
        vec3 u = v3_scale(d, 1.0 / length);
        double along = -v3_dot(o, u);                      /* to the point nearest the centre */
        double miss2 = v3_dot(o, o) - along * along;       /* squared distance of that point */
        if (!(along > 0.0) || miss2 >= EMBREE_FAR * EMBREE_FAR)
            return 0;
        double enter = (along - sqrt(EMBREE_FAR * EMBREE_FAR - miss2)) / length;
        if (enter > tnear) {
            offset = enter;
            o = v3_mad(o, d, enter);
        }
    }
    double near = (tnear - offset) * length, far = (tfar - offset) * length;
    if (!(far > (near > 0.0 ? near : 0.0)))
        return 0;
    *t_offset = offset;
    *t_scale = 1.0 / length;
    out->org_x = (float)o.x;
    out->org_y = (float)o.y;
    out->org_z = (float)o.z;
    out->tnear = near > 0.0 ? (float)near : 0.0f;
    out->dir_x = (float)(d.x / length);
    out->dir_y = (float)(d.y / length);
    out->dir_z = (float)(d.z / length);
    out->time = 0.0f;
    out->tfar = far < 1e30 ? (float)far : INFINITY;
    out->mask = 0xFFFFFFFFu;
    out->id = 0;
    out->flags = 0;
    return 1;
}

static void embree_occluded(void *state, const rad_ray *rays, size_t count, uint8_t *occluded)
{
    embree_state *s = state;
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (size_t first = 0; first < count; first += 16) {
        size_t n = count - first < 16 ? count - first : 16;
        struct RTCRay16 packet;  /* RTC_ALIGN(64) in Embree's header */
        _Alignas(64) int valid[16]; /* -1 = active lane; Embree wants 64-byte alignment */
        for (size_t k = 0; k < 16; k++) {
            /* Inactive lanes get an empty segment too, so nothing Embree
             * may load is uninitialised. */
            struct RTCRay ray = {0, 0, 0, 0.0f, 0, 0, 1.0f, 0.0f, -1.0f, 0, 0, 0};
            double offset, scale;
            valid[k] = k < n && embree_ray(s, &rays[first + k], &ray, &offset, &scale) ? -1 : 0;
            packet.org_x[k] = ray.org_x;
            packet.org_y[k] = ray.org_y;
            packet.org_z[k] = ray.org_z;
            packet.tnear[k] = ray.tnear;
            packet.dir_x[k] = ray.dir_x;
            packet.dir_y[k] = ray.dir_y;
            packet.dir_z[k] = ray.dir_z;
            packet.time[k] = 0.0f;
            packet.tfar[k] = ray.tfar;
            packet.mask[k] = 0xFFFFFFFFu;
            packet.id[k] = 0;
            packet.flags[k] = 0;
        }
        rtcOccluded16(valid, s->scene, &context, &packet);
        for (size_t k = 0; k < n; k++)
            occluded[first + k] = valid[k] && packet.tfar[k] < 0.0f;
    }
}

static void embree_intersect(void *state, const rad_ray *rays, size_t count, rad_hit *hits)
{
    embree_state *s = state;
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (size_t k = 0; k < count; k++) {
        hits[k].t = INFINITY;
        hits[k].patch = 0;
        struct RTCRayHit rayhit;
        double offset, scale;
        if (!embree_ray(s, &rays[k], &rayhit.ray, &offset, &scale))
            continue;
        rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rayhit.hit.primID = RTC_INVALID_GEOMETRY_ID;
        rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(s->scene, &context, &rayhit);
        unsigned geometry = rayhit.hit.geomID;
        if (geometry == RTC_INVALID_GEOMETRY_ID)
            continue;
        const rad_vis_prim *p = &s->prims[geometry == s->triangle_geometry
                                              ? s->triangle_prim[rayhit.hit.primID]
                                              : s->quad_prim[rayhit.hit.primID]];
        /* Refine t in double against the primitive's plane: float t is good
         * to ~1e-7 of the scene size, the plane solve to ~1e-16.  Keep the
         * float t when the ray grazes the plane or the refined t leaves
         * the segment. */
        double t = offset + scale * (double)rayhit.ray.tfar;
        vec3 normal = v3_normalize(
            v3_cross(v3_sub(p->corner[1], p->corner[0]), v3_sub(p->corner[2], p->corner[0])));
        double along = v3_dot(normal, rays[k].direction);
        if (along != 0.0) {
            double refined = v3_dot(normal, v3_sub(p->corner[0], rays[k].origin)) / along;
            if (fabs(refined - t) <= 1e-3 * fabs(t) && refined > rays[k].tnear &&
                refined < rays[k].tfar)
                t = refined;
        }
        hits[k].t = t;
        hits[k].patch = p->patch;
    }
}

const rad_vis_backend rad_vis_embree = {
    "embree",
    "Embree 3 BVH, float rays, robust traversal (default)",
    embree_create,
    embree_destroy,
    embree_occluded,
    embree_intersect,
};
