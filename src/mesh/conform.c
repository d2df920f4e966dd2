/*
 * conform.c -- patches split along contact lines, so that no element
 * straddles a wall, a partition or a box standing on the floor.
 *
 * Where another surface touches or cuts a patch, the radiosity is
 * discontinuous in value (a D0 discontinuity: Heckbert 1992, "Discontinuity
 * meshing for radiosity"; Baum, Mann, Smith & Winget 1991): the floor on
 * one side of a sealed partition is lit, on the other side dark.  An element
 * that straddles the line averages both sides, and its sample points on the
 * dark side carry the lit side's light through the wall (a leak).  So,
 * before meshing, each patch is cut along the lines where other patches
 * meet its plane inside it:
 *
 *      floor patch, seen from above, with a box standing on it:
 *
 *      +-----------+---+-------+          the box's side faces meet the
 *      |           |   |       |          floor along its footprint; each
 *      |           +---+ - - - |  <-      footprint edge cuts the pieces it
 *      |           |box|       |          passes through (only those), by
 *      |           +---+-------+          its whole line: pieces stay
 *      |           |   |       |          convex, and no element of the
 *      +-----------+---+-------+          floor crosses the footprint
 *
 * The segment where a patch Q meets the plane of P: Q's corners within the
 * contact tolerance of the plane, and the points where Q's edges cross it
 * (Q touching the plane along an edge, or passing through it).  Coplanar
 * patches cut nothing (neighbouring pieces of one floor).  A segment cuts a
 * piece of P only where it runs through the piece's interior, farther than
 * the tolerance from its boundary, so neighbouring triangles of a curved
 * mesh, which meet along shared edges, cut nothing.
 *
 * New corners are interpolated along the piece's own 3D edges, so the
 * pieces tile the patch exactly and the two pieces of a cut share their
 * new corners bit for bit.  A bent quad (corners off one plane by more
 * than 1e-6 of its size) is left whole: its pieces could not tile its
 * bilinear surface.  Pairs are found through a uniform grid of cells
 * (the cell size chosen so that the patches make a bounded number of cell
 * entries; a patch that would fill too many cells is tested against every
 * patch instead), and each pair is tested once, in the cell of the larger
 * of the two boxes' lower corners.
 */
#include "mesh/mesh_internal.h"

#include <stdlib.h>
#include <string.h>

enum {
    MAX_PIECE_CORNERS = 32,   /* a convex piece cut from a quad: 4 + one per cut at most */
    MAX_PIECES = 4096,        /* per patch; cutting stops there, with a warning */
    MAX_CELLS_PER_PATCH = 4096
};

/* A cut of patch `patch` along the segment a-b (in or near its plane),
 * made by patch `by`. */
typedef struct cut {
    uint32_t patch, by;
    vec3 a, b;
} cut;

typedef struct cut_list {
    rad_context *ctx;
    cut *items;
    size_t count, capacity;
} cut_list;

static bool cut_push(cut_list *l, uint32_t patch, uint32_t by, vec3 a, vec3 b)
{
    if (l->count == l->capacity) {
        size_t cap = l->capacity ? 2 * l->capacity : 64;
        cut *n = rad_realloc(l->ctx, RAD_MEM_MESH, l->items, cap, sizeof *n, "mesh: contact lines");
        if (!n)
            return false;
        l->items = n;
        l->capacity = cap;
    }
    l->items[l->count++] = (cut){patch, by, a, b};
    return true;
}

/* ---- where patch q meets the plane of patch p ---- */

/* The segment where q meets p's plane: true with its ends in *a, *b when q
 * crosses the plane or touches it along a line; false when q is coplanar,
 * off the plane, or touches it at a point. */
static bool contact_segment(const rad_patch *p, const rad_patch *q, double tol, vec3 *a, vec3 *b)
{
    double d[4];
    bool all_in = true;
    for (uint32_t k = 0; k < q->corner_count; k++) {
        d[k] = v3_dot(p->normal, v3_sub(q->corner[k], p->corner[0]));
        all_in &= fabs(d[k]) <= tol;
    }
    if (all_in)
        return false; /* coplanar */
    vec3 pts[8];
    int n = 0;
    for (uint32_t k = 0; k < q->corner_count; k++) {
        uint32_t k1 = (k + 1) % q->corner_count;
        if (fabs(d[k]) <= tol)
            pts[n++] = v3_mad(q->corner[k], p->normal, -d[k]); /* onto the plane */
        if ((d[k] > tol && d[k1] < -tol) || (d[k] < -tol && d[k1] > tol)) {
            double t = d[k] / (d[k] - d[k1]);
            pts[n++] = v3_lerp(q->corner[k], q->corner[k1], t);
        }
    }
    if (n < 2)
        return false;
    /* The points lie on one line (q is convex and planar): its ends are the
     * pair farthest apart. */
    double best = -1.0;
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n; j++) {
            double l = v3_length(v3_sub(pts[j], pts[i]));
            if (l > best) {
                best = l;
                *a = pts[i];
                *b = pts[j];
            }
        }
    return best > tol;
}

/* ---- cutting convex pieces ---- */

typedef struct piece {
    int n;
    vec3 c[MAX_PIECE_CORNERS]; /* counter-clockwise about the patch normal */
} piece;

/* 2D coordinates in the patch's plane frame (origin o, axes u, w). */
typedef struct frame {
    vec3 o, u, w;
} frame;

static void to2(const frame *f, vec3 q, double *x, double *y)
{
    vec3 d = v3_sub(q, f->o);
    *x = v3_dot(d, f->u);
    *y = v3_dot(d, f->w);
}

/* Does the segment s0-s1 (2D) run through the interior of convex piece
 * `pc` farther than tol from its boundary?  Clips the segment to the piece
 * shrunk by tol (Cyrus-Beck) and asks for a length above tol. */
static bool segment_inside(const frame *f, const piece *pc, double s0x, double s0y, double s1x,
                           double s1y, double tol)
{
    double t0 = 0.0, t1 = 1.0, dx = s1x - s0x, dy = s1y - s0y;
    for (int k = 0; k < pc->n; k++) {
        double ax, ay, bx, by;
        to2(f, pc->c[k], &ax, &ay);
        to2(f, pc->c[(k + 1) % pc->n], &bx, &by);
        double ex = bx - ax, ey = by - ay, len = sqrt(ex * ex + ey * ey);
        if (!(len > 0.0))
            continue;
        /* inside: left of the edge by more than tol */
        double nx = -ey / len, ny = ex / len;
        double num = (s0x - ax) * nx + (s0y - ay) * ny - tol; /* >= 0 inside */
        double den = dx * nx + dy * ny;
        if (den == 0.0) {
            if (num < 0.0)
                return false;
            continue;
        }
        double t = -num / den;
        if (den > 0.0)
            t0 = fmax(t0, t);
        else
            t1 = fmin(t1, t);
        if (t0 >= t1)
            return false;
    }
    return (t1 - t0) * sqrt(dx * dx + dy * dy) > tol;
}

/* Split `pc` by the line through (lx, ly) with unit normal (nx, ny) into
 * *left (positive side) and *right.  Corners within tol of the line go to
 * both; crossings are interpolated along the 3D edge.  False (nothing
 * written) when a side would be empty or thinner than tol. */
static bool split_piece(const frame *f, const piece *pc, double lx, double ly, double nx, double ny,
                        double tol, piece *left, piece *right)
{
    double d[MAX_PIECE_CORNERS], dmin = 0.0, dmax = 0.0;
    for (int k = 0; k < pc->n; k++) {
        double x, y;
        to2(f, pc->c[k], &x, &y);
        d[k] = (x - lx) * nx + (y - ly) * ny;
        dmin = fmin(dmin, d[k]);
        dmax = fmax(dmax, d[k]);
    }
    if (!(dmax > tol && dmin < -tol) || pc->n + 2 > MAX_PIECE_CORNERS)
        return false;
    left->n = right->n = 0;
    for (int k = 0; k < pc->n; k++) {
        int k1 = (k + 1) % pc->n;
        vec3 c = pc->c[k];
        if (d[k] >= -tol)
            left->c[left->n++] = c;
        if (d[k] <= tol)
            right->c[right->n++] = c;
        if ((d[k] > tol && d[k1] < -tol) || (d[k] < -tol && d[k1] > tol)) {
            vec3 x = v3_lerp(c, pc->c[k1], d[k] / (d[k] - d[k1]));
            left->c[left->n++] = x;
            right->c[right->n++] = x;
        }
    }
    return left->n >= 3 && right->n >= 3;
}

/* ---- candidate pairs: a uniform grid of cells ---- */

typedef struct box {
    vec3 lo, hi;
} box;

static int64_t cell_coord(double x, double inv) { return (int64_t)floor(x * inv); }

/* Cells a box covers along each axis, for cells 1/inv wide (capped). */
static double box_cells(const box *b, double inv)
{
    double n = 1.0;
    n *= (double)(cell_coord(b->hi.x, inv) - cell_coord(b->lo.x, inv) + 1);
    n *= (double)(cell_coord(b->hi.y, inv) - cell_coord(b->lo.y, inv) + 1);
    n *= (double)(cell_coord(b->hi.z, inv) - cell_coord(b->lo.z, inv) + 1);
    return n;
}

static bool boxes_overlap(const box *a, const box *b)
{
    return v3_boxes_meet(a->lo, a->hi, b->lo, b->hi);
}

typedef struct cell_item {
    uint64_t key;
    uint32_t patch;
} cell_item;

static int cell_item_cmp(const void *x, const void *y)
{
    const cell_item *a = x, *b = y;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    return a->patch < b->patch ? -1 : (a->patch > b->patch);
}

static uint64_t key_of(int64_t x, int64_t y, int64_t z)
{
    return rad_mix64((uint64_t)x * 0x9e3779b97f4a7c15ULL ^ rad_mix64((uint64_t)y) ^
                     rad_mix64((uint64_t)z * 0xc2b2ae3d27d4eb4fULL));
}

/* Test the pair (i, j) both ways and record the cuts. */
static bool test_pair(cut_list *cuts, const rad_patch *patches, uint32_t i, uint32_t j, double tol)
{
    vec3 a, b;
    if (contact_segment(&patches[i], &patches[j], tol, &a, &b) && !cut_push(cuts, i, j, a, b))
        return false;
    if (contact_segment(&patches[j], &patches[i], tol, &a, &b) && !cut_push(cuts, j, i, a, b))
        return false;
    return true;
}

static int cut_cmp(const void *x, const void *y)
{
    const cut *a = x, *b = y;
    if (a->patch != b->patch)
        return a->patch < b->patch ? -1 : 1;
    return a->by < b->by ? -1 : (a->by > b->by);
}

/* Every cut of every patch: pairs of patches whose boxes (grown by tol)
 * overlap, tested both ways. */
static rad_result find_cuts(rad_context *ctx, const rad_patch *patches, size_t n, double tol,
                            cut_list *cuts)
{
    box *bx = rad_alloc(ctx, RAD_MEM_MESH, n, sizeof *bx, "mesh: patch boxes");
    if (!bx)
        return RAD_ERROR_OUT_OF_MEMORY;
    double extent = 0.0;
    for (size_t i = 0; i < n; i++) {
        box b = {patches[i].corner[0], patches[i].corner[0]};
        for (uint32_t k = 1; k < patches[i].corner_count; k++) {
            b.lo = v3_min(b.lo, patches[i].corner[k]);
            b.hi = v3_max(b.hi, patches[i].corner[k]);
        }
        b.lo = v3_sub(b.lo, v3(tol, tol, tol));
        b.hi = v3_add(b.hi, v3(tol, tol, tol));
        bx[i] = b;
        vec3 e = v3_sub(b.hi, b.lo);
        extent = fmax(extent, fmax(e.x, fmax(e.y, e.z)));
    }
    /* The cell size: from the largest patch down, halved while the
     * entries (patches that fill more than MAX_CELLS_PER_PATCH cells are
     * not entered) stay within 8 per patch. */
    double cell = extent > 0.0 ? extent : 1.0;
    for (int it = 0; it < 64; it++) {
        double inv = 2.0 / cell, entries = 0.0;
        for (size_t i = 0; i < n; i++) {
            double c = box_cells(&bx[i], inv);
            entries += c <= MAX_CELLS_PER_PATCH ? c : 0.0;
        }
        if (entries > 8.0 * (double)n + 64.0)
            break;
        cell *= 0.5;
    }
    double inv = 1.0 / cell;
    size_t entries = 0, big = 0;
    for (size_t i = 0; i < n; i++) {
        double c = box_cells(&bx[i], inv);
        if (c <= MAX_CELLS_PER_PATCH)
            entries += (size_t)c;
        else
            big++;
    }
    cell_item *items = rad_alloc(ctx, RAD_MEM_MESH, entries ? entries : 1, sizeof *items, "mesh: patch cells");
    uint32_t *bigs = rad_alloc(ctx, RAD_MEM_MESH, big ? big : 1, sizeof *bigs, "mesh: patch cells");
    rad_result r = RAD_ERROR_OUT_OF_MEMORY;
    if (!items || !bigs)
        goto done;
    size_t m = 0, nb = 0;
    for (size_t i = 0; i < n; i++) {
        const box *b = &bx[i];
        if (box_cells(b, inv) > MAX_CELLS_PER_PATCH) {
            bigs[nb++] = (uint32_t)i;
            continue;
        }
        for (int64_t z = cell_coord(b->lo.z, inv); z <= cell_coord(b->hi.z, inv); z++)
            for (int64_t y = cell_coord(b->lo.y, inv); y <= cell_coord(b->hi.y, inv); y++)
                for (int64_t x = cell_coord(b->lo.x, inv); x <= cell_coord(b->hi.x, inv); x++)
                    items[m++] = (cell_item){key_of(x, y, z), (uint32_t)i};
    }
    qsort(items, m, sizeof *items, cell_item_cmp);
    r = RAD_OK;
    /* Pairs sharing a cell, each tested in one cell only: the cell of the
     * larger of the two boxes' lower corners. */
    for (size_t s = 0; s < m && r == RAD_OK; ) {
        size_t e = s;
        while (e < m && items[e].key == items[s].key)
            e++;
        for (size_t x = s; x < e && r == RAD_OK; x++) {
            if (rad_cancelled(ctx))
                r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "mesh: interrupted while finding contact lines");
            for (size_t y = x + 1; y < e && r == RAD_OK; y++) {
                uint32_t i = items[x].patch, j = items[y].patch;
                if (!boxes_overlap(&bx[i], &bx[j]))
                    continue;
                vec3 corner = v3_max(bx[i].lo, bx[j].lo);
                if (key_of(cell_coord(corner.x, inv), cell_coord(corner.y, inv), cell_coord(corner.z, inv)) !=
                    items[s].key)
                    continue;
                if (!test_pair(cuts, patches, i, j, tol))
                    r = RAD_ERROR_OUT_OF_MEMORY;
            }
        }
        s = e;
    }
    /* Patches too large for the cells: against every patch (each pair of
     * two large ones once). */
    for (size_t k = 0; k < nb && r == RAD_OK; k++) {
        uint32_t i = bigs[k];
        for (size_t j = 0; j < n && r == RAD_OK; j++) {
            if (j == i || !boxes_overlap(&bx[i], &bx[j]))
                continue;
            if (box_cells(&bx[j], inv) > MAX_CELLS_PER_PATCH && j < i)
                continue; /* the pair was tested from j */
            if (!test_pair(cuts, patches, i, (uint32_t)j, tol))
                r = RAD_ERROR_OUT_OF_MEMORY;
        }
        if (r == RAD_OK && rad_cancelled(ctx))
            r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "mesh: interrupted while finding contact lines");
    }
done:
    rad_free(bx);
    rad_free(items);
    rad_free(bigs);
    return r;
}

/* ---- pieces -> patches ---- */

static bool list_push(rad_context *ctx, rad_patch **items, size_t *count, size_t *cap, const rad_patch *p)
{
    if (*count == *cap) {
        size_t nc = *cap ? 2 * *cap : 64;
        rad_patch *np = rad_realloc(ctx, RAD_MEM_MESH, *items, nc, sizeof *np, "mesh: patches");
        if (!np)
            return false;
        *items = np;
        *cap = nc;
    }
    (*items)[(*count)++] = *p;
    return true;
}

/* A convex piece of patch `from` as patches: a triangle or quad as itself,
 * more corners as a fan about the centroid (as patch.c does for convex
 * polygons). */
static bool emit_piece(rad_context *ctx, const rad_patch *from, const piece *pc, rad_patch **items,
                       size_t *count, size_t *cap)
{
    rad_patch p = *from;
    if (pc->n <= 4) {
        p.corner_count = (uint32_t)pc->n;
        memcpy(p.corner, pc->c, (size_t)pc->n * sizeof *pc->c);
        return list_push(ctx, items, count, cap, &p);
    }
    vec3 c = v3(0, 0, 0);
    for (int k = 0; k < pc->n; k++)
        c = v3_add(c, pc->c[k]);
    c = v3_scale(c, 1.0 / pc->n);
    p.corner_count = 3;
    for (int k = 0; k < pc->n; k++) {
        p.corner[0] = c;
        p.corner[1] = pc->c[k];
        p.corner[2] = pc->c[(k + 1) % pc->n];
        if (!list_push(ctx, items, count, cap, &p))
            return false;
    }
    return true;
}

static int contact_cmp(const void *x, const void *y)
{
    const rad_contact *a = x, *b = y;
    return a->polygon < b->polygon ? -1 : (a->polygon > b->polygon);
}

rad_result mesh_conform_patches(rad_context *ctx, double tol, rad_patch **patches, size_t *count,
                                size_t *cut_patches, rad_contact **contacts, size_t *contact_count)
{
    size_t n = *count;
    *cut_patches = 0;
    *contacts = NULL;
    *contact_count = 0;
    cut_list cuts = {ctx, NULL, 0, 0};
    rad_result r = find_cuts(ctx, *patches, n, tol, &cuts);
    if (r != RAD_OK || cuts.count == 0) {
        rad_free(cuts.items);
        return r;
    }
    qsort(cuts.items, cuts.count, sizeof *cuts.items, cut_cmp);

    rad_patch *out = NULL;
    size_t nout = 0, cap = 0, ncontact = 0;
    /* The contact lines that run through a patch's interior: where the
     * radiosity is discontinuous (a line along a patch's rim is where two
     * faces of a curved mesh meet, which is not). */
    rad_contact *lines = rad_alloc(ctx, RAD_MEM_MESH, cuts.count, sizeof *lines, "mesh: contact lines");
    if (!lines) {
        rad_free(cuts.items);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    int piece_cap = 16;
    piece *pieces = rad_alloc(ctx, RAD_MEM_MESH, (size_t)piece_cap, sizeof *pieces, "mesh: patch pieces");
    if (!pieces) {
        rad_free(lines);
        rad_free(cuts.items);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    bool warned = false;
    size_t c = 0;
    for (size_t i = 0; i < n && r == RAD_OK; i++) {
        const rad_patch *p = &(*patches)[i];
        size_t c0 = c;
        while (c < cuts.count && cuts.items[c].patch == i)
            c++;
        /* A bent quad (corners off one plane by more than 1e-6 of its
         * longest edge, float round-off's scale: the Cornell box's walls,
         * 3 mm in 0.55 m, or two triangles merged within 2 degrees) is not
         * cut: pieces with corners on its edges would not tile its
         * bilinear surface (their areas missed it by 6e-7). */
        vec3 centre = v3(0, 0, 0);
        double longest = 0.0;
        for (uint32_t k = 0; k < p->corner_count; k++) {
            centre = v3_add(centre, p->corner[k]);
            longest = fmax(longest, v3_length(v3_sub(p->corner[(k + 1) % p->corner_count], p->corner[k])));
        }
        centre = v3_scale(centre, 1.0 / p->corner_count);
        double bend = 0.0;
        for (uint32_t k = 0; k < p->corner_count; k++)
            bend = fmax(bend, fabs(v3_dot(p->normal, v3_sub(p->corner[k], centre))));
        if (c == c0 || bend > 1e-6 * longest) {
            if (!list_push(ctx, &out, &nout, &cap, p))
                r = RAD_ERROR_OUT_OF_MEMORY;
            continue;
        }
        frame f;
        f.o = p->corner[0];
        f.u = v3_normalize(v3_sub(p->corner[1], p->corner[0]));
        f.w = v3_cross(p->normal, f.u);
        int np = 1;
        pieces[0].n = (int)p->corner_count;
        memcpy(pieces[0].c, p->corner, p->corner_count * sizeof *p->corner);
        for (size_t k = c0; k < c && r == RAD_OK; k++) {
            double ax, ay, bx, by;
            to2(&f, cuts.items[k].a, &ax, &ay);
            to2(&f, cuts.items[k].b, &bx, &by);
            double dx = bx - ax, dy = by - ay, len = sqrt(dx * dx + dy * dy);
            if (!(len > tol))
                continue;
            double nx = -dy / len, ny = dx / len;
            piece whole;
            whole.n = (int)p->corner_count;
            memcpy(whole.c, p->corner, p->corner_count * sizeof *p->corner);
            if (segment_inside(&f, &whole, ax, ay, bx, by, tol))
                lines[ncontact++] = (rad_contact){p->polygon, cuts.items[k].a, cuts.items[k].b};
            int count_now = np;
            for (int q = 0; q < count_now; q++) {
                if (!segment_inside(&f, &pieces[q], ax, ay, bx, by, tol))
                    continue;
                if (np == MAX_PIECES) {
                    if (!warned)
                        rad_warn(ctx, "mesh: a patch of surface %u meets more than %d contact lines; "
                                      "the rest are not meshed along",
                                 p->surface, MAX_PIECES);
                    warned = true;
                    break;
                }
                piece left, right;
                if (!split_piece(&f, &pieces[q], ax, ay, nx, ny, tol, &left, &right))
                    continue;
                if (np == piece_cap) {
                    piece *grown = rad_realloc(ctx, RAD_MEM_MESH, pieces, 2 * (size_t)piece_cap, sizeof *pieces,
                                               "mesh: patch pieces");
                    if (!grown) {
                        r = RAD_ERROR_OUT_OF_MEMORY;
                        break;
                    }
                    pieces = grown;
                    piece_cap *= 2;
                }
                pieces[q] = left;
                pieces[np++] = right;
            }
        }
        if (r != RAD_OK)
            break;
        if (np > 1)
            (*cut_patches)++;
        for (int q = 0; q < np && r == RAD_OK; q++)
            if (!emit_piece(ctx, p, &pieces[q], &out, &nout, &cap))
                r = RAD_ERROR_OUT_OF_MEMORY;
    }
    rad_free(pieces);
    rad_free(cuts.items);
    if (r != RAD_OK || ncontact == 0) {
        rad_free(lines);
        lines = NULL;
    }
    if (r != RAD_OK) {
        rad_free(out);
        return r;
    }
    if (ncontact > 1)
        qsort(lines, ncontact, sizeof *lines, contact_cmp);
    rad_free(*patches);
    *patches = out;
    *count = nout;
    *contacts = lines;
    *contact_count = ncontact;
    return RAD_OK;
}

bool rad_mesh_on_contact(const rad_mesh *mesh, uint32_t polygon, vec3 p)
{
    /* The polygon's lines: a binary search for the first. */
    size_t lo = 0, hi = mesh->contact_count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (mesh->contacts[mid].polygon < polygon)
            lo = mid + 1;
        else
            hi = mid;
    }
    double tol = mesh->contact_tol;
    for (size_t k = lo; k < mesh->contact_count && mesh->contacts[k].polygon == polygon; k++) {
        vec3 a = mesh->contacts[k].a, ab = v3_sub(mesh->contacts[k].b, a);
        double len2 = v3_dot(ab, ab);
        double t = len2 > 0.0 ? v3_dot(v3_sub(p, a), ab) / len2 : 0.0;
        t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
        if (v3_length(v3_sub(p, v3_mad(a, ab, t))) <= tol)
            return true;
    }
    return false;
}
