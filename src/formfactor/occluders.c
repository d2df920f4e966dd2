/*
 * occluders.c -- which element pairs need shadow rays at all: a pair is
 * clear (V = 1 exactly), blocked (V = 0 exactly) or partial (rays), decided
 * from the ray backend's own primitives (rad_vis_primitives) without a ray.
 *
 * Two facts make it exact (the idea of shaft culling, Haines & Wallace
 * 1991, with planes instead of boxes):
 *
 *  1. A segment x -> y can meet a flat primitive only if it crosses the
 *     primitive's plane: x and y strictly on opposite sides.  The
 *     primitives are grouped by plane; per element a bitset says on which
 *     sides of each plane its corners lie (front / back, beyond the plane
 *     tolerance), so the planes that separate some point of element i from
 *     some point of j are (front_i & back_j) | (back_i & front_j): one AND
 *     per 64 planes.  In a convex room no wall's plane separates anything:
 *     no candidate, no ray.
 *
 *  2. Every segment from element i to element j lies in the convex hull of
 *     their corners, so it meets a separating plane inside
 *     S = plane  ∩  conv(corners of i and j), the convex hull of the
 *     corners on the plane and of the crossing points of corner-to-corner
 *     segments:
 *
 *            j  +------+                S (dashed) on the plane of a
 *                \    /                 primitive k: k outside one of
 *         ........\--/.......  plane    its edges -> k blocks nothing;
 *                  \/   k               S inside k and i, j strictly on
 *            i  +------+                opposite sides -> k blocks all.
 *
 *     A primitive whose edge line has all of S outside (touching counts:
 *     the segments that meet an edge line are a set of measure zero)
 *     blocks nothing; one that holds all of S blocks every segment when i
 *     and j lie strictly on opposite sides of its plane.
 *
 * A pair none of whose candidate primitives meets S is clear; one that a
 * single primitive covers is blocked; the rest are partial (rays).  The
 * test is conservative: S may meet a primitive only near its corner, or
 * several primitives may cover S together, and the pair is then partial,
 * which costs rays, never accuracy.  A primitive not flat to the plane
 * tolerance (the Cornell box's blocks are bent by up to 2 mm) gets a plane
 * of its own with a slab as thick as its bend: pairs that straddle or touch
 * the slab and whose box meets the primitive's go to rays.  Scenes with
 * more than RAD_FF_OCCLUDER_PLANES distinct planes are not classified
 * (every pair partial, as before).
 */
#include "formfactor/formfactor.h"

#include <string.h>

/* A plane's primitives are tested one by one up to this many; a plane with
 * more (a wall of many polygons between two rooms) that S's box meets makes
 * the pair partial. */
enum { PLANE_PRIMS_TESTED = 64 };

typedef struct occ_prim {
    vec3 corner[4];
    vec3 edge_in[4];      /* in-plane inward normal of edge k (corner k -> k+1), unit */
    uint32_t corners;
    vec3 lo, hi;          /* box, m */
} occ_prim;

typedef struct occ_plane {
    vec3 normal;          /* unit */
    double offset;        /* normal . x on the plane, m */
    vec3 lo, hi;          /* box of its primitives, m */
    uint32_t first, count;/* its primitives in prim[] */
    double slab;          /* m: its primitives lie within this of the plane (the
                             plane tolerance, or a bent primitive's spread) */
} occ_plane;

struct rad_ff_occluders {
    const rad_mesh *mesh;
    double tol;           /* m: the plane tolerance */
    size_t words;         /* 64-bit words per element and side */
    size_t planes;
    occ_plane *plane;
    occ_prim *prim;
    uint64_t *front, *back; /* element e's words at e * words */
    vec3 *box;            /* element e's box: box[2e] lo, box[2e + 1] hi, m */
};

static vec3 poly_normal(const vec3 *c, uint32_t n)
{
    vec3 nrm = v3_cross(v3_sub(c[1], c[0]), v3_sub(c[2], c[0]));
    if (n == 4)
        nrm = v3_add(nrm, v3_cross(v3_sub(c[2], c[0]), v3_sub(c[3], c[0])));
    return v3_normalize(nrm);
}

/* Component-wise min / max without fmin's NaN rules (a library call). */
static vec3 vmin(vec3 a, vec3 b)
{
    return v3(a.x < b.x ? a.x : b.x, a.y < b.y ? a.y : b.y, a.z < b.z ? a.z : b.z);
}
static vec3 vmax(vec3 a, vec3 b)
{
    return v3(a.x > b.x ? a.x : b.x, a.y > b.y ? a.y : b.y, a.z > b.z ? a.z : b.z);
}

static size_t align16(size_t bytes) { return (bytes + 15) / 16 * 16; }

rad_result rad_ff_occluders_build(rad_context *ctx, const rad_mesh *mesh, size_t header, void **block,
                                  const rad_ff_occluders **occ_out)
{
    *block = NULL;
    *occ_out = NULL;
    rad_vis_prim *prims = NULL;
    size_t count = 0;
    rad_result r = rad_vis_primitives(ctx, mesh, &prims, &count);
    if (r != RAD_OK)
        return r;
    double tol = rad_ff_plane_tolerance(mesh);
    /* Group the primitives by plane: plane_of[k], and each plane's normal
     * and offset from its first primitive.  A primitive not flat to tol,
     * or a plane beyond the limit, turns the classification off. */
    uint32_t *plane_of = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, count ? count : 1, sizeof *plane_of,
                                   "form factors: occluder planes");
    occ_plane *planes = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, RAD_FF_OCCLUDER_PLANES, sizeof *planes,
                                  "form factors: occluder planes");
    if (!plane_of || !planes) {
        rad_free(prims);
        rad_free(plane_of);
        rad_free(planes);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    size_t nplanes = 0;
    bool classify = true;
    for (size_t k = 0; k < count && classify; k++) {
        const rad_vis_prim *p = &prims[k];
        vec3 nrm = poly_normal(p->corner, p->corner_count);
        double off = 0.0;
        for (uint32_t c = 0; c < p->corner_count; c++)
            off += v3_dot(nrm, p->corner[c]) / p->corner_count;
        double slab = 0.0; /* a bent primitive: its corners' spread about the mean plane */
        for (uint32_t c = 0; c < p->corner_count; c++)
            slab = fmax(slab, fabs(v3_dot(nrm, p->corner[c]) - off));
        bool bent = slab > tol;
        size_t m = bent ? nplanes : 0; /* a bent primitive has a plane of its own */
        for (; m < nplanes; m++) {
            if (planes[m].slab > tol)
                continue;
            /* Same plane, either orientation: all corners within tol. */
            bool on = true;
            for (uint32_t c = 0; c < p->corner_count && on; c++)
                on = fabs(v3_dot(planes[m].normal, p->corner[c]) - planes[m].offset) <= tol;
            if (on && fabs(fabs(v3_dot(planes[m].normal, nrm)) - 1.0) < 1e-9)
                break;
        }
        if (m == nplanes) {
            if (nplanes == RAD_FF_OCCLUDER_PLANES) {
                classify = false;
                break;
            }
            planes[m] = (occ_plane){nrm, off, p->corner[0], p->corner[0], 0, 0, bent ? slab + tol : tol};
            nplanes++;
        }
        plane_of[k] = (uint32_t)m;
        planes[m].count++;
    }
    size_t n = mesh->element_count;
    size_t words = (nplanes + 63) / 64;
    size_t bytes = align16(header) + align16(sizeof(rad_ff_occluders)) + align16(nplanes * sizeof(occ_plane)) +
                   align16(count * sizeof(occ_prim)) + 2 * align16(n * words * sizeof(uint64_t)) +
                   align16(2 * n * sizeof(vec3));
    if (!classify)
        bytes = header;
    unsigned char *mem = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, 1, bytes ? bytes : 1, "form factors: occluder table");
    if (!mem) {
        rad_free(prims);
        rad_free(plane_of);
        rad_free(planes);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    memset(mem, 0, bytes);
    *block = mem;
    if (!classify) {
        rad_free(prims);
        rad_free(plane_of);
        rad_free(planes);
        return RAD_OK;
    }
    unsigned char *at = mem + align16(header);
    rad_ff_occluders *occ = (rad_ff_occluders *)at;
    at += align16(sizeof *occ);
    occ->plane = (occ_plane *)at;
    at += align16(nplanes * sizeof(occ_plane));
    occ->prim = (occ_prim *)at;
    at += align16(count * sizeof(occ_prim));
    occ->front = (uint64_t *)at;
    at += align16(n * words * sizeof(uint64_t));
    occ->back = (uint64_t *)at;
    at += align16(n * words * sizeof(uint64_t));
    occ->box = (vec3 *)at;
    occ->mesh = mesh;
    occ->tol = tol;
    occ->words = words;
    occ->planes = nplanes;
    /* Primitives sorted by plane (a counting sort), with boxes and edges. */
    uint32_t first = 0;
    for (size_t m = 0; m < nplanes; m++) {
        occ->plane[m] = planes[m];
        occ->plane[m].first = first;
        first += planes[m].count;
        occ->plane[m].count = 0;
    }
    for (size_t k = 0; k < count; k++) {
        occ_plane *pl = &occ->plane[plane_of[k]];
        occ_prim *q = &occ->prim[pl->first + pl->count++];
        const rad_vis_prim *p = &prims[k];
        vec3 nrm = poly_normal(p->corner, p->corner_count);
        q->corners = p->corner_count;
        q->lo = q->hi = p->corner[0];
        for (uint32_t c = 0; c < p->corner_count; c++) {
            q->corner[c] = p->corner[c];
            q->lo = vmin(q->lo, p->corner[c]);
            q->hi = vmax(q->hi, p->corner[c]);
            vec3 edge = v3_sub(p->corner[(c + 1) % p->corner_count], p->corner[c]);
            q->edge_in[c] = v3_normalize(v3_cross(nrm, edge)); /* counter-clockwise: inward */
        }
        pl->lo = vmin(pl->lo, q->lo);
        pl->hi = vmax(pl->hi, q->hi);
    }
    /* Each element's sides of each plane. */
    for (size_t e = 0; e < n; e++) {
        const rad_element *el = &mesh->elements[e];
        occ->box[2 * e] = occ->box[2 * e + 1] = mesh->vertices[el->vertex[0]];
        for (uint32_t c = 1; c < el->vertex_count; c++) {
            occ->box[2 * e] = vmin(occ->box[2 * e], mesh->vertices[el->vertex[c]]);
            occ->box[2 * e + 1] = vmax(occ->box[2 * e + 1], mesh->vertices[el->vertex[c]]);
        }
        for (size_t m = 0; m < nplanes; m++) {
            /* Beside a bent primitive's plane (within its slab, beyond the
             * plane tolerance) an element counts as on both sides: such
             * pairs go to rays. */
            double slab = occ->plane[m].slab;
            bool front = false, back = false;
            for (uint32_t c = 0; c < el->vertex_count; c++) {
                double s = v3_dot(occ->plane[m].normal, mesh->vertices[el->vertex[c]]) - occ->plane[m].offset;
                front |= s > slab || (slab > tol && fabs(s) <= slab);
                back |= s < -slab || (slab > tol && fabs(s) <= slab);
            }
            if (front)
                occ->front[e * words + m / 64] |= 1ull << (m % 64);
            if (back)
                occ->back[e * words + m / 64] |= 1ull << (m % 64);
        }
    }
    rad_free(prims);
    rad_free(plane_of);
    rad_free(planes);
    *occ_out = occ;
    return RAD_OK;
}

static void note_blocker(rad_ff_blockers *b, const occ_prim *q);

static bool boxes_meet(vec3 alo, vec3 ahi, vec3 blo, vec3 bhi, double tol)
{
    return alo.x <= bhi.x + tol && blo.x <= ahi.x + tol && alo.y <= bhi.y + tol && blo.y <= ahi.y + tol &&
           alo.z <= bhi.z + tol && blo.z <= ahi.z + tol;
}

/* S against primitive q: 0 disjoint (all of S outside, or on, one edge
 * line), 2 inside (all of S inside or on every edge line), else 1. */
static int s_against(const occ_prim *q, const vec3 *s, int ns, double tol)
{
    bool inside = true;
    for (uint32_t k = 0; k < q->corners; k++) {
        bool all_out = true;
        for (int m = 0; m < ns; m++) {
            double d = v3_dot(q->edge_in[k], v3_sub(s[m], q->corner[k]));
            all_out &= d <= tol;
            inside &= d >= -tol;
        }
        if (all_out)
            return 0;
    }
    return inside ? 2 : 1;
}

rad_ff_verdict rad_ff_occluders_classify(const rad_ff_occluders *occ, uint32_t i, uint32_t j,
                                         rad_ff_blockers *blockers)
{
    if (blockers) {
        blockers->count = 0;
        blockers->complete = true;
        blockers->trimmed = false;
    }
    const rad_mesh *mesh = occ->mesh;
    const rad_element *ei = &mesh->elements[i], *ej = &mesh->elements[j];
    vec3 v[8];
    int nv = 0;
    for (uint32_t c = 0; c < ei->vertex_count; c++)
        v[nv++] = mesh->vertices[ei->vertex[c]];
    int ni = nv;
    for (uint32_t c = 0; c < ej->vertex_count; c++)
        v[nv++] = mesh->vertices[ej->vertex[c]];
    const uint64_t *fi = occ->front + i * occ->words, *bi = occ->back + i * occ->words;
    const uint64_t *fj = occ->front + j * occ->words, *bj = occ->back + j * occ->words;
    double tol = occ->tol;
    bool partial = false;
    /* The pair's box holds every segment between them. */
    vec3 plo = vmin(occ->box[2 * i], occ->box[2 * j]), phi = vmax(occ->box[2 * i + 1], occ->box[2 * j + 1]);
    for (size_t w = 0; w < occ->words; w++) {
        uint64_t cand = (fi[w] & bj[w]) | (bi[w] & fj[w]);
        while (cand) {
            int bit = __builtin_ctzll(cand);
            cand &= cand - 1;
            const occ_plane *pl = &occ->plane[w * 64 + (size_t)bit];
            if (!boxes_meet(plo, phi, pl->lo, pl->hi, pl->slab))
                continue;
            if (pl->slab > tol) {
                /* A bent primitive: the plane test is not exact, rays decide. */
                partial = true;
                if (blockers)
                    blockers->complete = false;
                continue;
            }
            /* S: corners on the plane and crossings of corner pairs. */
            double d[8];
            bool i_front = true, i_back = true, j_front = true, j_back = true;
            for (int k = 0; k < nv; k++) {
                d[k] = v3_dot(pl->normal, v[k]) - pl->offset;
                bool f = d[k] > tol, b = d[k] < -tol;
                if (k < ni) {
                    i_front &= f;
                    i_back &= b;
                } else {
                    j_front &= f;
                    j_back &= b;
                }
            }
            vec3 s[24]; /* on-plane corners + front x back crossings: at most 16 */
            int ns = 0;
            vec3 slo = v3(INFINITY, INFINITY, INFINITY), shi = v3(-INFINITY, -INFINITY, -INFINITY);
            for (int a = 0; a < nv; a++) {
                if (fabs(d[a]) <= tol)
                    s[ns++] = v[a];
                else if (d[a] > tol)
                    for (int b = 0; b < nv; b++)
                        if (d[b] < -tol && ns < (int)(sizeof s / sizeof s[0]))
                            s[ns++] = v3_lerp(v[a], v[b], d[a] / (d[a] - d[b]));
            }
            for (int m = 0; m < ns; m++) {
                slo = vmin(slo, s[m]);
                shi = vmax(shi, s[m]);
            }
            if (ns == 0 || !boxes_meet(slo, shi, pl->lo, pl->hi, tol))
                continue;
            bool strict = (i_front && j_back) || (i_back && j_front);
            if (pl->count > PLANE_PRIMS_TESTED) {
                partial = true;
                if (blockers)
                    blockers->complete = false;
                continue;
            }
            for (uint32_t k = pl->first; k < pl->first + pl->count; k++) {
                const occ_prim *q = &occ->prim[k];
                if (!boxes_meet(slo, shi, q->lo, q->hi, tol))
                    continue;
                int verdict = s_against(q, s, ns, tol);
                if (verdict == 2 && strict)
                    return RAD_FF_BLOCKED;
                if (verdict != 0)
                    note_blocker(blockers, q);
                partial |= verdict != 0;
            }
        }
    }
    return partial ? RAD_FF_PARTIAL : RAD_FF_CLEAR;
}

/* Note a primitive that may block part of the pair; past the room, the
 * list is marked incomplete. */
static void note_blocker(rad_ff_blockers *b, const occ_prim *q)
{
    if (!b)
        return;
    if (b->count < RAD_FF_MAX_BLOCKERS) {
        b->corners[b->count] = q->corners;
        memcpy(b->corner[b->count], q->corner, sizeof q->corner);
        b->top[b->count] = INFINITY;
        b->count++;
    } else
        b->complete = false;
}

/* ---- exact visibility from a point: the source minus the blockers'
 * shadows ---- */

enum { PIECE_CORNERS = 8, PIECES = 32 };

typedef struct piece {
    vec3 c[PIECE_CORNERS];
    int n;
} piece;

/* The part of polygon c[0..n) where sign * m.(p - o) >= 0 (Sutherland-
 * Hodgman) into out (room for `room` corners).  Returns its corner count,
 * 0 when less than a polygon remains, -1 when it does not fit. */
static int clip_half(const vec3 *c, int n, vec3 o, vec3 m, double sign, vec3 *out, int room)
{
    int k = 0;
    for (int a = 0; a < n; a++) {
        vec3 p = c[a], q = c[(a + 1) % n];
        double dp = sign * v3_dot(m, v3_sub(p, o)), dq = sign * v3_dot(m, v3_sub(q, o));
        if (dp >= 0.0) {
            if (k == room)
                return -1;
            out[k++] = p;
        }
        if ((dp >= 0.0) != (dq >= 0.0)) {
            if (k == room)
                return -1;
            out[k++] = v3_lerp(p, q, dp / (dp - dq));
        }
    }
    return k >= 3 ? k : 0;
}

void rad_ff_blockers_trim(rad_ff_blockers *b, vec3 src0, vec3 src_normal, vec3 recv0, vec3 recv_normal)
{
    int kept = 0;
    for (int k = 0; k < b->count; k++) {
        vec3 part[PIECE_CORNERS], tmp[PIECE_CORNERS];
        int m = clip_half(b->corner[k], (int)b->corners[k], src0, src_normal, 1.0, tmp, PIECE_CORNERS);
        if (m > 0)
            m = clip_half(tmp, m, recv0, recv_normal, 1.0, part, PIECE_CORNERS);
        if (m <= 0)
            continue; /* a quad cut twice has at most 6 corners: m < 0 cannot happen */
        double top = 0.0;
        for (int c = 0; c < m; c++)
            top = fmax(top, v3_dot(src_normal, v3_sub(part[c], src0)));
        memcpy(b->corner[kept], part, (size_t)m * sizeof *part);
        b->corners[kept] = (uint32_t)m;
        b->top[kept++] = top;
    }
    b->count = kept;
    b->trimmed = true;
}

/* Split convex `in` by the line through o with in-plane normal m: the part
 * with m.(p - o) <= 0 into *out_piece (n 0 if none), the rest back into
 * *in (n 0 if none).  Returns false when a part outgrows PIECE_CORNERS. */
static bool split_piece(piece *in, vec3 o, vec3 m, piece *out_piece)
{
    double d[PIECE_CORNERS];
    bool any_in = false, any_out = false;
    for (int k = 0; k < in->n; k++) {
        d[k] = v3_dot(m, v3_sub(in->c[k], o));
        any_in |= d[k] > 0.0;
        any_out |= d[k] < 0.0;
    }
    if (!any_out) {
        out_piece->n = 0;
        return true;
    }
    if (!any_in) {
        *out_piece = *in;
        in->n = 0;
        return true;
    }
    piece keep;
    keep.n = 0;
    out_piece->n = 0;
    for (int k = 0; k < in->n; k++) {
        int k1 = k + 1 == in->n ? 0 : k + 1;
        if (d[k] >= 0.0) {
            if (keep.n == PIECE_CORNERS)
                return false;
            keep.c[keep.n++] = in->c[k];
        }
        if (d[k] <= 0.0) {
            if (out_piece->n == PIECE_CORNERS)
                return false;
            out_piece->c[out_piece->n++] = in->c[k];
        }
        if ((d[k] > 0.0 && d[k1] < 0.0) || (d[k] < 0.0 && d[k1] > 0.0)) {
            vec3 x = v3_lerp(in->c[k], in->c[k1], d[k] / (d[k] - d[k1]));
            if (keep.n == PIECE_CORNERS || out_piece->n == PIECE_CORNERS)
                return false;
            keep.c[keep.n++] = x;
            out_piece->c[out_piece->n++] = x;
        }
    }
    if (out_piece->n < 3)
        out_piece->n = 0;
    *in = keep;
    if (in->n < 3)
        in->n = 0;
    return true;
}

/* The area of a flat polygon, m^2. */
static double piece_area(const vec3 *c, int n)
{
    vec3 sum = v3(0, 0, 0);
    for (int k = 1; k + 1 < n; k++)
        sum = v3_add(sum, v3_cross(v3_sub(c[k], c[0]), v3_sub(c[k + 1], c[0])));
    return 0.5 * v3_length(sum);
}

/* Visible pieces smaller than this fraction of the source are dropped: far
 * above the rounding of shadows cut edge to edge (1e-16 of their size),
 * far below anything a factor needs (1e-9 of one pair's factor). */
#define VISIBLE_SLIVER 1e-6

double rad_point_polygon_ff_visible(vec3 x, vec3 normal, const vec3 *src, size_t n, vec3 src_normal,
                                    const rad_ff_blockers *blockers)
{
    double height = v3_dot(src_normal, v3_sub(x, src[0])); /* x above the source's plane, m */
    if (!(height > 0.0))
        return 0.0;
    piece pieces[2][PIECES];
    int count = 1, cur = 0;
    pieces[0][0].n = (int)n;
    memcpy(pieces[0][0].c, src, n * sizeof *src);
    double level = height * (1.0 - 1e-9);
    for (int b = 0; b < blockers->count && count > 0; b++) {
        /* The blocker's part in front of x's tangent plane and strictly
         * between the source's plane and x's height above it (what lies
         * within 1e-9 of x's height projects past any precision: it could
         * only hide rays leaving x almost parallel to the source). */
        vec3 part[PIECE_CORNERS], tmp[PIECE_CORNERS];
        const vec3 *use = blockers->corner[b];
        int m = (int)blockers->corners[b];
        if (!blockers->trimmed) {
            m = clip_half(use, m, src[0], src_normal, 1.0, part, PIECE_CORNERS);
            if (m > 0)
                m = clip_half(part, m, x, normal, 1.0, tmp, PIECE_CORNERS);
            use = tmp;
        }
        if (m > 0 && !(blockers->trimmed && blockers->top[b] < level)) {
            m = clip_half(use, m, v3_mad(src[0], src_normal, level), src_normal, -1.0, part, PIECE_CORNERS);
            use = part;
        }
        if (m < 0)
            return -1.0;
        if (m == 0)
            continue;
        /* Its shadow on the source's plane, counter-clockwise about src_normal. */
        vec3 shadow[PIECE_CORNERS];
        for (int k = 0; k < m; k++) {
            double h = v3_dot(src_normal, v3_sub(use[k], src[0]));
            shadow[k] = v3_add(x, v3_scale(v3_sub(use[k], x), height / (height - h)));
        }
        vec3 area = v3(0, 0, 0);
        for (int k = 1; k + 1 < m; k++)
            area = v3_add(area, v3_cross(v3_sub(shadow[k], shadow[0]), v3_sub(shadow[k + 1], shadow[0])));
        double orient = v3_dot(area, src_normal);
        if (orient == 0.0)
            continue; /* seen edge-on: hides a set of measure zero */
        /* Every piece minus the shadow: the parts outside each shadow edge
         * in turn; what is inside all of them is hidden. */
        int next = 0;
        for (int p = 0; p < count; p++) {
            piece rest = pieces[cur][p];
            for (int k = 0; k < m && rest.n > 0; k++) {
                vec3 a = shadow[k], c = shadow[k + 1 == m ? 0 : k + 1];
                vec3 inward = v3_scale(v3_cross(src_normal, v3_sub(c, a)), orient > 0.0 ? 1.0 : -1.0);
                if (next == PIECES)
                    return -1.0;
                if (!split_piece(&rest, a, inward, &pieces[1 - cur][next]))
                    return -1.0;
                next += pieces[1 - cur][next].n > 0;
            }
        }
        count = next;
        cur = 1 - cur;
    }
    /* Pieces below VISIBLE_SLIVER of the source's area are the rounding of
     * shadows that meet edge to edge (a wall of several polygons, a closed
     * door in it): left in, they let sealed rooms see each other
     * (test_hostile's ten closed offices became one lit group). */
    double src_area = piece_area(src, (int)n);
    double f = 0.0;
    for (int p = 0; p < count; p++)
        if (piece_area(pieces[cur][p].c, pieces[cur][p].n) > VISIBLE_SLIVER * src_area)
            f += rad_point_polygon_ff_front(x, normal, pieces[cur][p].c, (size_t)pieces[cur][p].n);
    return f;
}
