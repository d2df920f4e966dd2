/*
 * pathtrace.c -- a converged reference for the Cornell box, made by a method
 * that shares nothing with the engine: a standalone Monte Carlo path tracer
 * (Kajiya 1986, "The rendering equation") over the scene's OBJ/MTL, with its
 * own reader, its own ray-triangle test (Moller & Trumbore 1997) and no
 * element, form factor or solver of the library.
 *
 *   L(x) = Le(x) + rho(x)/pi  integral over the hemisphere of L_in cos
 *        = Le(x) + [direct: a point y on an emitter, area sampled,
 *                   rho/pi Le(y) cos_x cos_y / r^2 A_emitters, one shadow ray]
 *                + [indirect: a cosine-distributed direction, weight rho,
 *                   the path continued; the emission it meets not counted
 *                   again (next-event estimation already did)]
 *   paths ended by Russian roulette after two bounces (survival max rho).
 *
 * Surfaces are one-sided as in the engine: the back of a polygon emits and
 * reflects nothing (black), and every polygon blocks rays from both sides.
 * Nothing here is biased but the float -> double of the file's numbers.
 *
 *   pathtrace surfaces OBJ [--samples N] [--seed S]
 *       each surface's (OBJ object's) area-mean radiosity B = pi L, RGB,
 *       W/m^2: N points uniform over its area, one path each; prints
 *       JSON with the mean and the standard error of each channel.
 *   pathtrace image OBJ -o OUT.pfm [--ids IDS.pfm] [--noise NOISE.pfm]
 *                       [--width W] [--height H] [--spp N] [--seed S]
 *                       [--camera px,py,pz,lx,ly,lz] [--vfov DEG]
 *       radiance L (W/(m^2 sr)) per pixel, the mean over the pixel's area
 *       (box filter, stratified), as the engine's `radiosity render` writes
 *       its .pfm.  IDS: channel 0 the polygon seen at the pixel's centre
 *       (-1: nothing or a back side), channel 1 1 where all 4 x 4 strata
 *       of the pixel see the same polygon's front; NOISE: channel 0 the
 *       standard error of the pixel's luminance over its mean.  The camera
 *       defaults to the published one of the Cornell box (docs/scenes.md).
 *
 * Deterministic: each pixel's (or surface sample's) random numbers come
 * from a stream keyed on the seed and its index.  One thread.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct { double x, y, z; } vec;
static vec vadd(vec a, vec b) { return (vec){a.x + b.x, a.y + b.y, a.z + b.z}; }
static vec vsub(vec a, vec b) { return (vec){a.x - b.x, a.y - b.y, a.z - b.z}; }
static vec vmul(vec a, double s) { return (vec){a.x * s, a.y * s, a.z * s}; }
static double vdot(vec a, vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static vec vcross(vec a, vec b) { return (vec){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
static vec vnorm(vec a) { return vmul(a, 1.0 / sqrt(vdot(a, a))); }

typedef struct { char name[64]; double rho[3], Le[3]; } material;
typedef struct {
    vec p0, e1, e2, normal; /* unit normal by the right-hand rule (the lit side) */
    double area;            /* m^2 */
    int material, surface, polygon;
} triangle;

enum { MAX_TRI = 4096, MAX_MAT = 64, MAX_SURF = 64, MAX_VERT = 16384 };
static triangle tris[MAX_TRI];
static int tri_count;
static material mats[MAX_MAT];
static int mat_count;
static char surf_name[MAX_SURF][64];
typedef struct { vec lo, hi; int first, count; } object_box; /* a run of triangles and its bounds */
static object_box boxes[MAX_SURF];
static int box_count;
static int surf_count, polygon_count;
static int emitters[MAX_TRI], emitter_count;
static double emitter_cdf[MAX_TRI], emitter_area; /* m^2 */
static vec bound_lo, bound_hi;

static void die(const char *what)
{
    fprintf(stderr, "pathtrace: %s\n", what);
    exit(1);
}

/* ---- the scene: an OBJ subset (v, f, o, usemtl, mtllib) and MTL Kd, Ke ---- */

static int find_material(const char *name)
{
    for (int i = 0; i < mat_count; i++)
        if (strcmp(mats[i].name, name) == 0)
            return i;
    return -1;
}

static void trim(char *s)
{
    size_t n = strlen(s);
    while (n && (s[n - 1] == '\n' || s[n - 1] == '\r' || s[n - 1] == ' ' || s[n - 1] == '\t'))
        s[--n] = 0;
}

static void read_mtl(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        die("cannot open the material library");
    char line[512];
    material *m = NULL;
    while (fgets(line, sizeof line, f)) {
        trim(line);
        if (strncmp(line, "newmtl ", 7) == 0) {
            if (mat_count == MAX_MAT)
                die("too many materials");
            m = &mats[mat_count++];
            memset(m, 0, sizeof *m);
            snprintf(m->name, sizeof m->name, "%.63s", line + 7);
        } else if (m && strncmp(line, "Kd ", 3) == 0) {
            sscanf(line + 3, "%lf %lf %lf", &m->rho[0], &m->rho[1], &m->rho[2]);
        } else if (m && strncmp(line, "Ke ", 3) == 0) { /* Ke is radiance (docs/units.md) */
            sscanf(line + 3, "%lf %lf %lf", &m->Le[0], &m->Le[1], &m->Le[2]);
        }
    }
    fclose(f);
}

static void read_obj(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        die("cannot open the OBJ");
    static vec verts[MAX_VERT];
    int vert_count = 0, material_now = -1, surface_now = -1;
    char line[1024];
    while (fgets(line, sizeof line, f)) {
        trim(line);
        if (strncmp(line, "mtllib ", 7) == 0) {
            char dir[1024];
            snprintf(dir, sizeof dir, "%s", path);
            char *slash = strrchr(dir, '/');
            char lib[2048];
            if (slash) {
                slash[1] = 0;
                snprintf(lib, sizeof lib, "%s%s", dir, line + 7);
            } else {
                snprintf(lib, sizeof lib, "%s", line + 7);
            }
            read_mtl(lib);
        } else if (strncmp(line, "o ", 2) == 0) {
            if (surf_count == MAX_SURF)
                die("too many objects");
            surface_now = surf_count++;
            snprintf(surf_name[surface_now], sizeof surf_name[0], "%.63s", line + 2);
        } else if (strncmp(line, "usemtl ", 7) == 0) {
            if ((material_now = find_material(line + 7)) < 0)
                die("usemtl names an unknown material");
        } else if (strncmp(line, "v ", 2) == 0) {
            if (vert_count == MAX_VERT)
                die("too many vertices");
            vec *v = &verts[vert_count++];
            if (sscanf(line + 2, "%lf %lf %lf", &v->x, &v->y, &v->z) != 3)
                die("bad vertex");
        } else if (strncmp(line, "f ", 2) == 0) {
            int idx[64], n = 0;
            char *s = line + 2, *end;
            while (n < 64) {
                long k = strtol(s, &end, 10);
                if (end == s)
                    break;
                idx[n++] = (int)(k < 0 ? vert_count + k : k - 1);
                s = end;
                while (*s && *s != ' ')
                    s++; /* skip /vt/vn */
            }
            if (n < 3 || material_now < 0 || surface_now < 0)
                die("bad face (or one before its object and material)");
            for (int i = 1; i + 1 < n; i++) { /* a fan: the faces are convex */
                if (tri_count == MAX_TRI)
                    die("too many triangles");
                triangle *t = &tris[tri_count++];
                t->p0 = verts[idx[0]];
                t->e1 = vsub(verts[idx[i]], t->p0);
                t->e2 = vsub(verts[idx[i + 1]], t->p0);
                vec c = vcross(t->e1, t->e2);
                t->area = 0.5 * sqrt(vdot(c, c));
                t->normal = vnorm(c);
                t->material = material_now;
                t->surface = surface_now;
                t->polygon = polygon_count;
            }
            polygon_count++;
        }
    }
    fclose(f);
    bound_lo = (vec){INFINITY, INFINITY, INFINITY};
    bound_hi = vmul(bound_lo, -1.0);
    for (int i = 0; i < tri_count; i++) {
        const triangle *t = &tris[i];
        vec c[3] = {t->p0, vadd(t->p0, t->e1), vadd(t->p0, t->e2)};
        for (int k = 0; k < 3; k++) {
            bound_lo = (vec){fmin(bound_lo.x, c[k].x), fmin(bound_lo.y, c[k].y), fmin(bound_lo.z, c[k].z)};
            bound_hi = (vec){fmax(bound_hi.x, c[k].x), fmax(bound_hi.y, c[k].y), fmax(bound_hi.z, c[k].z)};
        }
        const double *Le = mats[t->material].Le;
        if (Le[0] > 0.0 || Le[1] > 0.0 || Le[2] > 0.0) {
            emitters[emitter_count] = i;
            emitter_area += t->area;
            emitter_cdf[emitter_count++] = emitter_area;
        }
    }
    if (!emitter_count)
        die("nothing emits");
    /* Runs of consecutive triangles of one object, each with its box (the
     * slab test skips most of the blocks' triangles). */
    for (int i = 0; i < tri_count; i++) {
        if (i == 0 || tris[i].surface != tris[i - 1].surface) {
            if (box_count == MAX_SURF)
                die("too many runs of objects");
            boxes[box_count++] = (object_box){{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}, i, 0};
        }
        object_box *b = &boxes[box_count - 1];
        b->count++;
        const triangle *t = &tris[i];
        vec c[3] = {t->p0, vadd(t->p0, t->e1), vadd(t->p0, t->e2)};
        for (int k = 0; k < 3; k++) {
            b->lo = (vec){fmin(b->lo.x, c[k].x), fmin(b->lo.y, c[k].y), fmin(b->lo.z, c[k].z)};
            b->hi = (vec){fmax(b->hi.x, c[k].x), fmax(b->hi.y, c[k].y), fmax(b->hi.z, c[k].z)};
        }
    }
}

/* ---- random numbers: splitmix64 (Steele, Lea & Flood 2014) keyed streams ---- */

typedef struct { uint64_t state; } rng;
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}
static rng rng_keyed(uint64_t seed, uint64_t a, uint64_t b)
{
    return (rng){mix64(mix64(seed ^ 0x9e3779b97f4a7c15ULL) ^ mix64(a + 0x632be59bd9b4e019ULL) ^ (b * 0x85ebca6bULL))};
}
static double uniform(rng *r)
{
    r->state += 0x9e3779b97f4a7c15ULL;
    return (double)(mix64(r->state) >> 11) * (1.0 / 9007199254740992.0);
}

/* ---- rays ---- */

/* 1e-7 of the scene's size: well above double round-off at the hit point,
 * far below any feature of the box (the blocks stand 1e-3 m from nothing). */
static double ray_epsilon;

/* The closest triangle along o + t d, t in (0, tmax); -1 if none. */
static int intersect(vec o, vec d, double tmax, double *t_hit)
{
    int best = -1;
    double best_t = tmax;
    vec inv_d = {1.0 / d.x, 1.0 / d.y, 1.0 / d.z};
    for (int b = 0; b < box_count; b++) {
        const object_box *box = &boxes[b];
        /* Slab test, widened by the epsilon (flat boxes of walls). */
        double e = ray_epsilon, t0 = 0.0, t1 = best_t;
        double lo[3] = {box->lo.x - e, box->lo.y - e, box->lo.z - e};
        double hi[3] = {box->hi.x + e, box->hi.y + e, box->hi.z + e};
        double oo[3] = {o.x, o.y, o.z}, id[3] = {inv_d.x, inv_d.y, inv_d.z};
        for (int k = 0; k < 3 && t0 <= t1; k++) {
            double ta = (lo[k] - oo[k]) * id[k], tb = (hi[k] - oo[k]) * id[k];
            if (ta > tb) {
                double tmp = ta;
                ta = tb;
                tb = tmp;
            }
            if (!(ta <= t1 && tb >= t0)) {
                /* Outside this slab: the box is missed.  A NaN (a direction
                 * parallel to the slab, 0 x inf, from its face) rejects
                 * nothing: the triangles decide. */
                if (ta == ta && tb == tb) {
                    t0 = 1.0;
                    t1 = 0.0;
                }
                continue;
            }
            t0 = fmax(t0, ta);
            t1 = fmin(t1, tb);
        }
        if (t0 > t1)
            continue;
        for (int i = box->first; i < box->first + box->count; i++) {
            const triangle *tr = &tris[i];
            vec p = vcross(d, tr->e2);
            double det = vdot(tr->e1, p);
            if (fabs(det) < 1e-300)
                continue;
            double inv = 1.0 / det;
            vec s = vsub(o, tr->p0);
            double u = vdot(s, p) * inv;
            if (u < 0.0 || u > 1.0)
                continue;
            vec q = vcross(s, tr->e1);
            double v = vdot(d, q) * inv;
            if (v < 0.0 || u + v > 1.0)
                continue;
            double t = vdot(tr->e2, q) * inv;
            if (t > ray_epsilon && t < best_t) {
                best_t = t;
                best = i;
            }
        }
    }
    *t_hit = best_t;
    return best;
}

/* A point uniform over the emitters' area from (u, v) in [0, 1)^2: u picks
 * the triangle by area and, rescaled, with v the point (the square-root
 * warp), so strata of (u, v) stay strata of the area. */
static vec sample_emitter(double u, double v, int *which)
{
    double at = u * emitter_area, below = 0.0;
    int k = 0;
    while (k + 1 < emitter_count && emitter_cdf[k] < at)
        k++;
    if (k > 0)
        below = emitter_cdf[k - 1];
    const triangle *t = &tris[emitters[k]];
    double a = sqrt(fmin(1.0, fmax(0.0, (at - below) / t->area))), b = v;
    *which = emitters[k];
    return vadd(t->p0, vadd(vmul(t->e1, a * (1.0 - b)), vmul(t->e2, a * b)));
}

/* Radiance leaving front-side point x of triangle `tri` (not counting its
 * emission), following one path: next-event estimation plus the cosine-
 * sampled continuation.  `first` (or NULL: drawn from r) holds the first
 * bounce's four numbers, the emitter point's two and the direction's two,
 * so a caller can stratify them. */
static void reflected(vec x, int tri, rng *r, const double first[4], double L[3])
{
    double weight[3] = {1.0, 1.0, 1.0};
    L[0] = L[1] = L[2] = 0.0;
    for (int bounce = 0;; bounce++) {
        const triangle *t = &tris[tri];
        const double *rho = mats[t->material].rho;
        vec n = t->normal;
        /* Direct: one point on the emitters. */
        int light;
        double lu = first && bounce == 0 ? first[0] : uniform(r), lv = first && bounce == 0 ? first[1] : uniform(r);
        vec y = sample_emitter(lu, lv, &light);
        vec to = vsub(y, x);
        double d2 = vdot(to, to), dist = sqrt(d2);
        vec w = vmul(to, 1.0 / dist);
        double cos_x = vdot(n, w), cos_y = -vdot(tris[light].normal, w);
        if (cos_x > 0.0 && cos_y > 0.0) {
            double th;
            if (intersect(x, w, dist * (1.0 - 1e-9) - ray_epsilon, &th) < 0) {
                double g = cos_x * cos_y / d2 * emitter_area / M_PI;
                const double *Le = mats[tris[light].material].Le;
                for (int c = 0; c < 3; c++)
                    L[c] += weight[c] * rho[c] * Le[c] * g;
            }
        }
        /* Indirect: a cosine-distributed direction; weight rho. */
        for (int c = 0; c < 3; c++)
            weight[c] *= rho[c];
        if (bounce >= 2) {
            double survive = fmax(weight[0], fmax(weight[1], weight[2]));
            if (survive < 1.0) {
                if (uniform(r) >= survive)
                    return;
                for (int c = 0; c < 3; c++)
                    weight[c] /= survive;
            }
        }
        double u1 = first && bounce == 0 ? first[2] : uniform(r), u2 = first && bounce == 0 ? first[3] : uniform(r);
        double rad = sqrt(u1), phi = 2.0 * M_PI * u2;
        vec a = fabs(n.x) > 0.9 ? (vec){0, 1, 0} : (vec){1, 0, 0};
        vec tu = vnorm(vcross(a, n)), tv = vcross(n, tu);
        vec d = vadd(vadd(vmul(tu, rad * cos(phi)), vmul(tv, rad * sin(phi))), vmul(n, sqrt(fmax(0.0, 1.0 - u1))));
        double th;
        int hit = intersect(x, d, INFINITY, &th);
        if (hit < 0 || vdot(d, tris[hit].normal) >= 0.0)
            return; /* out of the scene, or the back of a polygon: black */
        x = vadd(x, vmul(d, th));
        tri = hit;
    }
}

/* ---- the modes ---- */

static int surfaces(uint64_t seed, long samples)
{
    printf("{\n \"how\": \"bench/pathtrace surfaces: %ld points uniform over each surface's area, one path each "
           "(next-event estimation, Russian roulette after 2 bounces), seed %llu; se: standard error of the mean\",\n"
           " \"surfaces\": [\n",
           samples, (unsigned long long)seed);
    for (int s = 0; s < surf_count; s++) {
        double area = 0.0, cdf[MAX_TRI];
        int list[MAX_TRI], count = 0;
        for (int i = 0; i < tri_count; i++)
            if (tris[i].surface == s) {
                area += tris[i].area;
                cdf[count] = area;
                list[count++] = i;
            }
        double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
        for (long k = 0; k < samples; k++) {
            rng r = rng_keyed(seed, (uint64_t)s, (uint64_t)k);
            double u = uniform(&r) * area;
            int j = 0;
            while (j + 1 < count && cdf[j] < u)
                j++;
            const triangle *t = &tris[list[j]];
            double a = uniform(&r), b = uniform(&r);
            if (a + b > 1.0) {
                a = 1.0 - a;
                b = 1.0 - b;
            }
            vec x = vadd(t->p0, vadd(vmul(t->e1, a), vmul(t->e2, b)));
            double L[3];
            reflected(x, list[j], &r, NULL, L);
            for (int c = 0; c < 3; c++) {
                double B = M_PI * (mats[t->material].Le[c] + L[c]);
                sum[c] += B;
                sum2[c] += B * B;
            }
        }
        double mean[3], se[3];
        for (int c = 0; c < 3; c++) {
            mean[c] = sum[c] / (double)samples;
            se[c] = sqrt(fmax(0.0, sum2[c] / (double)samples - mean[c] * mean[c]) / (double)(samples - 1));
        }
        printf("  {\"name\": \"%s\", \"radiosity\": [%.9g, %.9g, %.9g], \"se\": [%.4g, %.4g, %.4g]}%s\n",
               surf_name[s], mean[0], mean[1], mean[2], se[0], se[1], se[2], s + 1 < surf_count ? "," : "");
        fflush(stdout);
    }
    printf(" ]\n}\n");
    return 0;
}

static int write_pfm(const char *path, int w, int h, const float *rgb)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return 1;
    fprintf(f, "PF\n%d %d\n-1.0\n", w, h);
    for (int y = h - 1; y >= 0; y--) /* bottom row first; floats little-endian (x86) */
        fwrite(&rgb[(size_t)y * (size_t)w * 3], sizeof(float), (size_t)w * 3, f);
    return fclose(f) != 0;
}

typedef struct { vec position, forward, right, up; int width, height; } camera;

static vec camera_ray(const camera *cam, double fx, double fy)
{
    return vnorm(vadd(cam->forward, vadd(vmul(cam->right, 2.0 * fx - 1.0), vmul(cam->up, 1.0 - 2.0 * fy))));
}

/* Radiance along the camera ray d; *seen the polygon (or -1). */
static void trace_eye(const camera *cam, vec d, rng *r, const double first[4], double L[3], int *seen)
{
    double th;
    int hit = intersect(cam->position, d, INFINITY, &th);
    L[0] = L[1] = L[2] = 0.0;
    *seen = -1;
    if (hit < 0 || vdot(d, tris[hit].normal) >= 0.0)
        return;
    *seen = tris[hit].polygon;
    reflected(vadd(cam->position, vmul(d, th)), hit, r, first, L);
    for (int c = 0; c < 3; c++)
        L[c] += mats[tris[hit].material].Le[c];
}

static int image(uint64_t seed, const camera *cam, long spp, const char *out, const char *ids_path,
                 const char *noise_path)
{
    int w = cam->width, h = cam->height;
    float *rgb = calloc((size_t)w * h * 3, sizeof *rgb), *ids = calloc((size_t)w * h * 3, sizeof *ids),
          *noise = calloc((size_t)w * h * 3, sizeof *noise);
    if (!rgb || !ids || !noise)
        die("out of memory");
    int grid = (int)floor(sqrt((double)spp));
    if (grid < 1)
        grid = 1;
    long *perm_light = malloc((size_t)grid * grid * sizeof *perm_light), *perm_dir = malloc((size_t)grid * grid * sizeof *perm_dir);
    if (!perm_light || !perm_dir)
        die("out of memory");
    double rel2_sum = 0.0;
    long rel_count = 0;
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++) {
            size_t pixel = (size_t)y * w + x;
            rng r = rng_keyed(seed, pixel, 0);
            /* What the pixel sees: its 4 x 4 strata's centres. */
            int centre = -2, uniform_front = 1, first_seen = -2;
            for (int k = 0; k < 16; k++) {
                double th;
                vec d = camera_ray(cam, (x + (k % 4 + 0.5) / 4.0) / w, (y + (k / 4 + 0.5) / 4.0) / h);
                int hit = intersect(cam->position, d, INFINITY, &th);
                int what = hit < 0 || vdot(d, tris[hit].normal) >= 0.0 ? -1 : tris[hit].polygon;
                if (k == 0)
                    first_seen = what;
                if (what != first_seen || what < 0)
                    uniform_front = 0;
            }
            {
                double th;
                vec d = camera_ray(cam, (x + 0.5) / w, (y + 0.5) / h);
                int hit = intersect(cam->position, d, INFINITY, &th);
                centre = hit < 0 || vdot(d, tris[hit].normal) >= 0.0 ? -1 : tris[hit].polygon;
            }
            /* Padded stratification: the pixel position, the emitter point
             * and the first direction each on a grid x grid of strata,
             * paired by random permutations (a path tracer's first bounce
             * carries most of the variance; Shirley 1990). */
            long strata = (long)grid * grid;
            for (long k = 0; k < strata; k++)
                perm_light[k] = perm_dir[k] = k;
            for (long k = strata - 1; k > 0; k--) {
                long i = (long)(uniform(&r) * (double)(k + 1)), j = (long)(uniform(&r) * (double)(k + 1)), t;
                t = perm_light[k], perm_light[k] = perm_light[i], perm_light[i] = t;
                t = perm_dir[k], perm_dir[k] = perm_dir[j], perm_dir[j] = t;
            }
            double sum[3] = {0, 0, 0}, y_sum = 0.0, y_sum2 = 0.0;
            for (long k = 0; k < spp; k++) {
                long s = k % strata, sl = perm_light[s], sd = perm_dir[s];
                double fx = (x + (s % grid + uniform(&r)) / grid) / w, fy = (y + (s / grid + uniform(&r)) / grid) / h;
                double first[4] = {(sl % grid + uniform(&r)) / grid, (sl / grid + uniform(&r)) / grid,
                                   (sd % grid + uniform(&r)) / grid, (sd / grid + uniform(&r)) / grid};
                double L[3];
                int seen;
                trace_eye(cam, camera_ray(cam, fx, fy), &r, first, L, &seen);
                for (int c = 0; c < 3; c++)
                    sum[c] += L[c];
                double Y = 0.2126 * L[0] + 0.7152 * L[1] + 0.0722 * L[2];
                y_sum += Y;
                y_sum2 += Y * Y;
            }
            double Y = y_sum / spp, se = sqrt(fmax(0.0, y_sum2 / spp - Y * Y) / (double)(spp > 1 ? spp - 1 : 1));
            for (int c = 0; c < 3; c++)
                rgb[3 * pixel + c] = (float)(sum[c] / spp);
            ids[3 * pixel] = (float)centre;
            ids[3 * pixel + 1] = (float)uniform_front;
            noise[3 * pixel] = Y > 0.0 ? (float)(se / Y) : 0.0f;
            if (uniform_front && Y > 0.0) {
                rel2_sum += (se / Y) * (se / Y);
                rel_count++;
            }
        }
        if ((y + 1) % 16 == 0)
            fprintf(stderr, "pathtrace: row %d of %d\n", y + 1, h);
    }
    int failed = write_pfm(out, w, h, rgb);
    if (ids_path)
        failed |= write_pfm(ids_path, w, h, ids);
    if (noise_path)
        failed |= write_pfm(noise_path, w, h, noise);
    printf("pathtrace image: %dx%d, %ld paths a pixel, seed %llu; RMS relative standard error of luminance "
           "over pixels that see one polygon: %.3f%%\n",
           w, h, spp, (unsigned long long)seed, rel_count ? 100.0 * sqrt(rel2_sum / rel_count) : 0.0);
    free(rgb);
    free(ids);
    free(noise);
    free(perm_light);
    free(perm_dir);
    return failed;
}

int main(int argc, char **argv)
{
    if (argc < 3 || (strcmp(argv[1], "surfaces") != 0 && strcmp(argv[1], "image") != 0)) {
        fprintf(stderr, "usage: pathtrace surfaces|image OBJ [options] (see the file's header)\n");
        return 2;
    }
    read_obj(argv[2]);
    vec size = vsub(bound_hi, bound_lo);
    ray_epsilon = 1e-7 * sqrt(vdot(size, size));
    uint64_t seed = 0;
    long samples = 0;
    int width = 128, height = 128;
    const char *out = NULL, *ids = NULL, *noise = NULL;
    /* The published camera (tests/data/cornell_box.obj's header): 35 mm lens, 25 mm film. */
    double cam[6] = {0.278, 0.273, -0.8, 0.278, 0.273, 0.0};
    double vfov = 2.0 * atan(0.5 * 0.025 / 0.035) * 180.0 / M_PI;
    for (int i = 3; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            die("an option without its value");
        if (strcmp(a, "--samples") == 0 || strcmp(a, "--spp") == 0)
            samples = atol(v);
        else if (strcmp(a, "--seed") == 0)
            seed = strtoull(v, NULL, 10);
        else if (strcmp(a, "--width") == 0)
            width = atoi(v);
        else if (strcmp(a, "--height") == 0)
            height = atoi(v);
        else if (strcmp(a, "-o") == 0)
            out = v;
        else if (strcmp(a, "--ids") == 0)
            ids = v;
        else if (strcmp(a, "--noise") == 0)
            noise = v;
        else if (strcmp(a, "--vfov") == 0)
            vfov = atof(v);
        else if (strcmp(a, "--camera") == 0) {
            if (sscanf(v, "%lf,%lf,%lf,%lf,%lf,%lf", &cam[0], &cam[1], &cam[2], &cam[3], &cam[4], &cam[5]) != 6)
                die("--camera takes px,py,pz,lx,ly,lz");
        } else
            die("unknown option");
        i++;
    }
    if (strcmp(argv[1], "surfaces") == 0)
        return surfaces(seed, samples > 1 ? samples : 1000000);
    if (!out || width < 1 || height < 1)
        die("image needs -o OUT.pfm and a positive size");
    /* The engine's pinhole (src/output/render.c): right = forward x up, up = right x forward. */
    camera c = {.position = {cam[0], cam[1], cam[2]}, .width = width, .height = height};
    c.forward = vnorm(vsub((vec){cam[3], cam[4], cam[5]}, c.position));
    vec right = vnorm(vcross(c.forward, (vec){0, 1, 0}));
    double hh = tan(0.5 * vfov * M_PI / 180.0);
    c.up = vmul(vcross(right, c.forward), hh);
    c.right = vmul(right, hh * width / height);
    return image(seed, &c, samples > 0 ? samples : 1024, out, ids, noise);
}
