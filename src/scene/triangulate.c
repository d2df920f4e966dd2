/*
 * triangulate.c -- polygon geometry for the scene: Newell's normal, the
 * simplicity test of a polygon, and its triangulation, both fast enough
 * for a face of 10^5 vertices (a second or less, where pair tests took
 * minutes).
 *
 * Newell's method (Sutherland, Sproull, Schumacker 1974) sums the
 * projections of the edges onto the three coordinate planes; for a planar
 * polygon the result is the normal times twice the area, and for a slightly
 * non-planar one it is the normal of a good best-fit plane.
 *
 * Everything else works in 2D: the polygon is projected onto the plane of
 * the given normal with a right-handed frame (u, v, n), so counter-clockwise
 * in (u, v) means "right-hand rule along n".
 *
 * Simplicity: the sweep of Shamos & Hoey (1976, "Geometric intersection
 * problems"; de Berg et al., Computational Geometry, ch. 2).  A vertical
 * line sweeps the vertices in (x, y) order; the edges it cuts are kept
 * sorted bottom to top in a treap.  Two edges that meet are neighbours in
 * that order just before the sweep reaches their leftmost meeting point,
 * so it is enough to test an edge against its neighbours when it is
 * inserted and the two edges that become neighbours when one is deleted:
 * O(n log n), against O(n^2) for every pair.  At a vertex its edges are
 * inserted before any is deleted, so edges that only touch there are both
 * present and get compared.  Every refusal is decided by the same pair test
 * (segments_meet) the pair-by-pair check used, with the same tolerance.
 *
 *         \        status, bottom to top at the sweep line:
 *     ---- \ ---       e2   (inserted at its left end: compared with e1, e3)
 *        e2 \  e3      e1
 *     e1 ----o----     (deleted at its right end: its two neighbours compared)
 *
 * Triangulation: ear clipping (Meisters 1975, "Polygons have ears"), with
 * the ear test of FIST (Held 2001, "FIST: fast industrial-strength
 * triangulation of polygons"): a convex vertex i is an ear when no
 * non-convex vertex lies in the closed triangle (prev, i, next), since in a
 * simple polygon a triangle that holds some vertex holds a reflex one.  The
 * reflex vertices (and those straight within the tolerance) sit in a
 * uniform grid of about one cell per vertex, rebuilt as they dwindle; a test
 * visits only the cells the triangle covers, row by row, instead of walking
 * round the polygon.  Ear clipping was chosen over monotone decomposition
 * (Garey, Johnson, Preparata, Tarjan 1978), which is O(n log n) in the
 * worst case, because this contract keeps collinear vertices and wants
 * every triangle of positive area, which ear clipping gives by
 * construction; on every shape tried (circle, star of random radii, comb,
 * spiral, 10^5 vertices each) it takes 0.1-0.4 s, though an adversary can
 * still make it quadratic.
 *
 * Exactly straight vertices (turn 0, as on a side of a square sampled
 * 25,000 times) are never ears.  They are hidden from the ring of ear
 * candidates as soon as they are straight, and come back as fan triangles
 * when the ear beside them is clipped:
 *
 *        p o---h---h---o i         a clip of i emits (p, h, q), (h, h, q),
 *           \         /            (h, i, q): every triangle of positive
 *            \       /             area, n - 2 of them in all
 *             \     /
 *               o q
 *
 * so a long straight side (the top of a comb whose teeth are gone) costs
 * nothing in the ear tests.  Vertices straight only within the tolerance
 * (float coordinates on a fine circle) stay candidates that are never ears
 * and block ears as the pair-by-pair test did.
 */
#include "scene/scene.h"

#include <float.h>
#include <stdlib.h>

vec3 rad_polygon_newell(const vec3 *vertices, size_t n)
{
    vec3 normal = v3(0.0, 0.0, 0.0);
    for (size_t i = 0; i < n; i++) {
        vec3 a = vertices[i], b = vertices[(i + 1) % n];
        normal.x += (a.y - b.y) * (a.z + b.z);
        normal.y += (a.z - b.z) * (a.x + b.x);
        normal.z += (a.x - b.x) * (a.y + b.y);
    }
    return normal;
}

typedef struct point2 {
    double x, y;
} point2;

#define NONE UINT32_MAX

/* Steps between two polls of the cancel flag: about a millisecond. */
#define POLL_INTERVAL 4096

/* Twice the signed area of (a, b, c): > 0 when counter-clockwise. */
static double orient2(point2 a, point2 b, point2 c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/* p lies in the bounding box of segment ab (used once p is known to be
 * collinear with it). */
static bool within_segment_box(point2 a, point2 b, point2 p)
{
    return p.x >= fmin(a.x, b.x) && p.x <= fmax(a.x, b.x) && p.y >= fmin(a.y, b.y) &&
           p.y <= fmax(a.y, b.y);
}

/* Segments ab and cd cross or touch; `eps` is the orientation tolerance. */
static bool segments_meet(point2 a, point2 b, point2 c, point2 d, double eps)
{
    double d1 = orient2(c, d, a), d2 = orient2(c, d, b);
    double d3 = orient2(a, b, c), d4 = orient2(a, b, d);
    if (((d1 > eps && d2 < -eps) || (d1 < -eps && d2 > eps)) &&
        ((d3 > eps && d4 < -eps) || (d3 < -eps && d4 > eps)))
        return true;
    return (fabs(d1) <= eps && within_segment_box(c, d, a)) ||
           (fabs(d2) <= eps && within_segment_box(c, d, b)) ||
           (fabs(d3) <= eps && within_segment_box(a, b, c)) ||
           (fabs(d4) <= eps && within_segment_box(a, b, d));
}

static bool point_less(point2 a, point2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }

/* ---- simplicity: the Shamos-Hoey sweep ---- */

/* Edge e runs from vertex e to vertex e + 1 (mod n).  The status is a treap
 * (Seidel & Aragon 1996) keyed by the edges' order along the sweep line,
 * with parent links so that an edge is deleted and its neighbours found
 * from its own node, without comparisons. */
typedef struct sweep {
    const point2 *pts;
    uint32_t n;
    double eps;
    uint32_t *below, *above, *parent; /* treap children and parent, per edge */
    uint32_t root;
} sweep;

/* The treap's priority for edge e: a fixed hash (the finaliser of
 * MurmurHash3), so runs repeat exactly and need no random state. */
static uint32_t priority(uint32_t e)
{
    e ^= e >> 16;
    e *= 0x85ebca6bu;
    e ^= e >> 13;
    e *= 0xc2b2ae35u;
    e ^= e >> 16;
    return e;
}

static uint32_t edge_next(const sweep *s, uint32_t e) { return e + 1 == s->n ? 0 : e + 1; }

/* The edge's left and right ends, in the sweep's (x, y) order. */
static uint32_t edge_left(const sweep *s, uint32_t e)
{
    uint32_t f = edge_next(s, e);
    return point_less(s->pts[e], s->pts[f]) ? e : f;
}
static uint32_t edge_right(const sweep *s, uint32_t e)
{
    uint32_t f = edge_next(s, e);
    return point_less(s->pts[e], s->pts[f]) ? f : e;
}

/* Edges sharing a polygon vertex are allowed to touch there. */
static bool edges_adjacent(const sweep *s, uint32_t e, uint32_t f)
{
    return edge_next(s, e) == f || edge_next(s, f) == e;
}

/* The pair test of the pair-by-pair check, with the lower edge first, so
 * that the sweep refuses exactly what that check refused. */
static bool edges_meet(const sweep *s, uint32_t e, uint32_t f)
{
    uint32_t i = e < f ? e : f, j = e < f ? f : e;
    return segments_meet(s->pts[i], s->pts[i + 1], s->pts[j], s->pts[edge_next(s, j)], s->eps);
}

/* Where edge e, being inserted at its left end p, goes relative to edge t
 * in the status: +1 above, -1 below; 0 when they meet (the polygon is not
 * simple).  An edge through p within the tolerance meets e unless the two
 * are adjacent or the pair test says otherwise; then the direction of e
 * decides, and the indices when even that is a tie. */
static int edge_side(const sweep *s, uint32_t e, uint32_t t)
{
    point2 a = s->pts[edge_left(s, t)], b = s->pts[edge_right(s, t)];
    point2 p = s->pts[edge_left(s, e)];
    double o = orient2(a, b, p);
    if (o > s->eps)
        return 1;
    if (o < -s->eps)
        return -1;
    if (!edges_adjacent(s, e, t) && edges_meet(s, e, t))
        return 0;
    double direction = orient2(a, b, s->pts[edge_right(s, e)]);
    if (direction != 0.0)
        return direction > 0.0 ? 1 : -1;
    if (o != 0.0)
        return o > 0.0 ? 1 : -1;
    return e > t ? 1 : -1;
}

/* Lift x above its parent (one rotation), keeping the in-order sequence. */
static void rotate_up(sweep *s, uint32_t x)
{
    uint32_t p = s->parent[x], g = s->parent[p];
    if (s->below[p] == x) {
        s->below[p] = s->above[x];
        if (s->above[x] != NONE)
            s->parent[s->above[x]] = p;
        s->above[x] = p;
    } else {
        s->above[p] = s->below[x];
        if (s->below[x] != NONE)
            s->parent[s->below[x]] = p;
        s->below[x] = p;
    }
    s->parent[p] = x;
    s->parent[x] = g;
    if (g == NONE)
        s->root = x;
    else if (s->below[g] == p)
        s->below[g] = x;
    else
        s->above[g] = x;
}

/* The edge just above (up = true) or just below x in the status, or NONE. */
static uint32_t status_neighbour(const sweep *s, uint32_t x, bool up)
{
    const uint32_t *toward = up ? s->above : s->below, *away = up ? s->below : s->above;
    if (toward[x] != NONE) {
        x = toward[x];
        while (away[x] != NONE)
            x = away[x];
        return x;
    }
    uint32_t p = s->parent[x];
    while (p != NONE && toward[p] == x) {
        x = p;
        p = s->parent[p];
    }
    return p;
}

/* False when e meets the edge it is tested against. */
static bool neighbours_apart(const sweep *s, uint32_t e, uint32_t f)
{
    return e == NONE || f == NONE || edges_adjacent(s, e, f) || !edges_meet(s, e, f);
}

/* Insert edge e at its left end; false when it meets an edge in the status. */
static bool status_insert(sweep *s, uint32_t e)
{
    uint32_t parent = NONE, at = s->root;
    int side = 0;
    while (at != NONE) {
        side = edge_side(s, e, at);
        if (side == 0)
            return false;
        parent = at;
        at = side > 0 ? s->above[at] : s->below[at];
    }
    s->below[e] = s->above[e] = NONE;
    s->parent[e] = parent;
    if (parent == NONE)
        s->root = e;
    else if (side > 0)
        s->above[parent] = e;
    else
        s->below[parent] = e;
    while (s->parent[e] != NONE && priority(e) > priority(s->parent[e]))
        rotate_up(s, e);
    return neighbours_apart(s, e, status_neighbour(s, e, false)) &&
           neighbours_apart(s, e, status_neighbour(s, e, true));
}

/* Delete edge e; false when its two neighbours, now adjacent, meet. */
static bool status_delete(sweep *s, uint32_t e)
{
    uint32_t lower = status_neighbour(s, e, false), upper = status_neighbour(s, e, true);
    while (s->below[e] != NONE || s->above[e] != NONE) {
        uint32_t l = s->below[e], u = s->above[e];
        rotate_up(s, u == NONE || (l != NONE && priority(l) > priority(u)) ? l : u);
    }
    uint32_t p = s->parent[e];
    if (p == NONE)
        s->root = NONE;
    else if (s->below[p] == e)
        s->below[p] = NONE;
    else
        s->above[p] = NONE;
    return neighbours_apart(s, lower, upper);
}

/* Sort order[0..n) by the points' (x, y): heapsort, O(n log n) in the
 * worst case and no memory beyond the array. */
static void sort_vertices(const point2 *pts, uint32_t *order, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++)
        order[i] = i;
    for (uint32_t end = n, start = n / 2;;) {
        uint32_t root;
        if (start > 0) {
            root = --start;
        } else {
            if (--end == 0)
                break;
            uint32_t top = order[0];
            order[0] = order[end];
            order[end] = top;
            root = 0;
        }
        uint32_t item = order[root];
        for (uint32_t child; (child = 2 * root + 1) < end; root = child) {
            if (child + 1 < end && point_less(pts[order[child]], pts[order[child + 1]]))
                child++;
            if (!point_less(pts[item], pts[order[child]]))
                break;
            order[root] = order[child];
        }
        order[root] = item;
    }
}

typedef enum verdict { VERDICT_NO, VERDICT_YES, VERDICT_INTERRUPTED } verdict;

/* Whether the closed polygon pts[0..n) is simple: no zero-length edge, no
 * spike (an edge doubling back on the previous one) and no two
 * non-adjacent edges that cross or touch.  Uses four arrays of n words. */
static verdict polygon_is_simple(const rad_context *ctx, const point2 *pts, uint32_t n,
                                 double eps, uint32_t *words)
{
    for (uint32_t i = 0; i < n; i++) {
        point2 prev = pts[(i + n - 1) % n], p = pts[i], next = pts[(i + 1) % n];
        if (p.x == next.x && p.y == next.y)
            return VERDICT_NO;
        double turn = orient2(prev, p, next);
        double along = (p.x - prev.x) * (next.x - p.x) + (p.y - prev.y) * (next.y - p.y);
        if (fabs(turn) <= eps && along < 0.0)
            return VERDICT_NO;
    }
    uint32_t *order = words;
    sweep s = {pts, n, eps, words + n, words + 2 * (size_t)n, words + 3 * (size_t)n, NONE};
    sort_vertices(pts, order, n);
    /* Two vertices at one point: their edges touch there (adjacent ones
     * would make a zero-length edge, refused above). */
    for (uint32_t k = 1; k < n; k++)
        if (pts[order[k]].x == pts[order[k - 1]].x && pts[order[k]].y == pts[order[k - 1]].y)
            return VERDICT_NO;
    for (uint32_t k = 0; k < n; k++) {
        if (k % POLL_INTERVAL == POLL_INTERVAL - 1 && rad_cancelled(ctx))
            return VERDICT_INTERRUPTED;
        uint32_t v = order[k];
        uint32_t edges[2] = {v == 0 ? n - 1 : v - 1, v};
        for (int j = 0; j < 2; j++)
            if (edge_left(&s, edges[j]) == v && !status_insert(&s, edges[j]))
                return VERDICT_NO;
        for (int j = 0; j < 2; j++)
            if (edge_right(&s, edges[j]) == v && !status_delete(&s, edges[j]))
                return VERDICT_NO;
    }
    return VERDICT_YES;
}

/* ---- triangulation: ear clipping with a grid of reflex vertices ---- */

/* Vertex flags. */
#define VERTEX_HIDDEN 1u  /* straight: out of the ring of candidates */
#define VERTEX_INDEXED 2u /* reflex or straight: in the grid */

/* The polygon being clipped.  Two rings: `ring_prev`/`ring_next` link the
 * candidates (convex and reflex vertices still there), `full_next` every
 * vertex still there, hidden ones included, in polygon order. */
typedef struct clipper {
    const point2 *pts;
    double eps, sign;
    uint32_t *ring_prev, *ring_next, *full_next;
    uint32_t *cell_prev, *cell_next, *flags, *cell_head;
    size_t ring_count;   /* candidates left */
    size_t reflex_count; /* vertices in the grid */
    /* The grid: cells_x by cells_y cells over [x0, x0 + cells_x / scale_x]
     * x [y0, ...]; about one cell per reflex vertex when it was built. */
    double x0, y0, scale_x, scale_y;
    uint32_t cells_x, cells_y;
    size_t built_with;
    uint32_t *triangles;
    size_t count;
    uint32_t capacity; /* triangles the output holds: n - 2 */
    bool failed;
} clipper;

/* Turn at candidate v in the polygon's orientation: > eps convex, < -eps
 * reflex, else straight. */
static double turn_at(const clipper *c, uint32_t v)
{
    return c->sign *
           orient2(c->pts[c->ring_prev[v]], c->pts[v], c->pts[c->ring_next[v]]);
}

static uint32_t cell_coordinate(double t, double origin, double scale, uint32_t cells)
{
    double f = (t - origin) * scale;
    return f <= 0.0 ? 0 : (f >= (double)cells ? cells - 1 : (uint32_t)f);
}

static uint32_t cell_of(const clipper *c, point2 p)
{
    return cell_coordinate(p.y, c->y0, c->scale_y, c->cells_y) * c->cells_x +
           cell_coordinate(p.x, c->x0, c->scale_x, c->cells_x);
}

static void grid_add(clipper *c, uint32_t v)
{
    uint32_t cell = cell_of(c, c->pts[v]);
    c->cell_prev[v] = NONE;
    c->cell_next[v] = c->cell_head[cell];
    if (c->cell_head[cell] != NONE)
        c->cell_prev[c->cell_head[cell]] = v;
    c->cell_head[cell] = v;
    c->flags[v] |= VERTEX_INDEXED;
    c->reflex_count++;
}

static void grid_remove(clipper *c, uint32_t v)
{
    if (c->cell_prev[v] != NONE)
        c->cell_next[c->cell_prev[v]] = c->cell_next[v];
    else
        c->cell_head[cell_of(c, c->pts[v])] = c->cell_next[v];
    if (c->cell_next[v] != NONE)
        c->cell_prev[c->cell_next[v]] = c->cell_prev[v];
    c->flags[v] &= ~VERTEX_INDEXED;
    c->reflex_count--;
}

/* (Re)build the grid over the reflex candidates of the ring through
 * `start`, one cell per reflex vertex or so, in the shape of their box. */
static void grid_build(clipper *c, uint32_t start)
{
    size_t reflex = 0;
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    uint32_t v = start;
    do {
        c->flags[v] &= ~VERTEX_INDEXED;
        if (turn_at(c, v) <= c->eps) {
            reflex++;
            x0 = fmin(x0, c->pts[v].x);
            x1 = fmax(x1, c->pts[v].x);
            y0 = fmin(y0, c->pts[v].y);
            y1 = fmax(y1, c->pts[v].y);
        }
        v = c->ring_next[v];
    } while (v != start);
    c->reflex_count = 0;
    c->built_with = reflex;
    c->cells_x = c->cells_y = 1;
    c->x0 = x0;
    c->y0 = y0;
    if (reflex > 0) {
        double width = x1 - x0, height = y1 - y0, cells = (double)reflex;
        double nx = width > 0.0 && height > 0.0 ? sqrt(cells * width / height)
                                                : (width > 0.0 ? cells : 1.0);
        nx = fmin(fmax(nx, 1.0), cells);
        c->cells_x = (uint32_t)nx;
        c->cells_y = (uint32_t)fmax(1.0, cells / (double)c->cells_x);
    }
    c->scale_x = x1 > x0 ? c->cells_x / (x1 - x0) : 0.0;
    c->scale_y = y1 > y0 ? c->cells_y / (y1 - y0) : 0.0;
    for (size_t k = 0; k < (size_t)c->cells_x * c->cells_y; k++)
        c->cell_head[k] = NONE;
    if (reflex == 0)
        return;
    v = start;
    do {
        if (turn_at(c, v) <= c->eps)
            grid_add(c, v);
        v = c->ring_next[v];
    } while (v != start);
}

/* Take straight candidate v out of the ring; it stays in the full ring,
 * on the edge between its neighbours. */
static void hide(clipper *c, uint32_t v)
{
    if (c->flags[v] & VERTEX_INDEXED)
        grid_remove(c, v);
    c->flags[v] |= VERTEX_HIDDEN;
    c->ring_next[c->ring_prev[v]] = c->ring_next[v];
    c->ring_prev[c->ring_next[v]] = c->ring_prev[v];
    c->ring_count--;
}

/* Candidates a and b = ring_next[a] have new neighbours: hide them while
 * they are straight (which gives their neighbours new neighbours in turn),
 * then file them in the grid or out of it.  Returns the candidate that
 * ends up after a's place. */
static uint32_t refresh_pair(clipper *c, uint32_t a, uint32_t b)
{
    while (c->ring_count > 3) {
        if (turn_at(c, a) == 0.0) {
            uint32_t before = c->ring_prev[a];
            hide(c, a);
            a = before;
        } else if (turn_at(c, b) == 0.0) {
            uint32_t after = c->ring_next[b];
            hide(c, b);
            b = after;
        } else {
            break;
        }
    }
    uint32_t ends[2] = {a, b};
    for (int k = 0; k < 2; k++) {
        bool reflex = turn_at(c, ends[k]) <= c->eps;
        if (reflex && !(c->flags[ends[k]] & VERTEX_INDEXED))
            grid_add(c, ends[k]);
        else if (!reflex && (c->flags[ends[k]] & VERTEX_INDEXED))
            grid_remove(c, ends[k]);
    }
    return b;
}

/* The x extent of triangle (a, b, d) within the band y_low <= y <= y_high:
 * its corners in the band and its edges' crossings of the band's lines;
 * x_low > x_high when it misses the band. */
static void band_extent(point2 a, point2 b, point2 d, double y_low, double y_high, double *x_low,
                        double *x_high)
{
    point2 corner[3] = {a, b, d};
    double lines[2] = {y_low, y_high};
    *x_low = INFINITY;
    *x_high = -INFINITY;
    for (int k = 0; k < 3; k++) {
        point2 u = corner[k], w = corner[(k + 1) % 3];
        if (u.y >= y_low && u.y <= y_high) {
            *x_low = fmin(*x_low, u.x);
            *x_high = fmax(*x_high, u.x);
        }
        for (int l = 0; l < 2; l++)
            if ((u.y < lines[l] && w.y > lines[l]) || (u.y > lines[l] && w.y < lines[l])) {
                double x = u.x + (lines[l] - u.y) * (w.x - u.x) / (w.y - u.y);
                *x_low = fmin(*x_low, x);
                *x_high = fmax(*x_high, x);
            }
    }
}

/* Candidate i, between p and q, is an ear: convex, and the closed triangle
 * (p, i, q) holds no reflex vertex, nor the candidate beyond p or q when it
 * lies on the diagonal pq (a straight run ending there). */
static bool is_ear(const clipper *c, uint32_t p, uint32_t i, uint32_t q)
{
    const point2 *pts = c->pts;
    point2 a = pts[p], b = pts[i], d = pts[q];
    double s = c->sign, eps = c->eps;
    if (s * orient2(a, b, d) <= eps)
        return false; /* reflex or straight */
    uint32_t beyond[2] = {c->ring_next[q], c->ring_prev[p]};
    for (int k = 0; k < 2; k++)
        if (beyond[k] != p && beyond[k] != q && beyond[k] != i &&
            fabs(orient2(a, d, pts[beyond[k]])) <= eps && within_segment_box(a, d, pts[beyond[k]]))
            return false;
    if (c->reflex_count == 0)
        return true;
    /* A point within the tolerance of an edge of length l is off it by up
     * to eps / l: widen the box by that for the shortest edge. */
    double shortest2 = fmin(fmin((b.x - a.x) * (b.x - a.x) + (b.y - a.y) * (b.y - a.y),
                                 (d.x - b.x) * (d.x - b.x) + (d.y - b.y) * (d.y - b.y)),
                            (a.x - d.x) * (a.x - d.x) + (a.y - d.y) * (a.y - d.y));
    double margin = eps / sqrt(shortest2);
    uint32_t cy0 = cell_coordinate(fmin(a.y, fmin(b.y, d.y)) - margin, c->y0, c->scale_y, c->cells_y);
    uint32_t cy1 = cell_coordinate(fmax(a.y, fmax(b.y, d.y)) + margin, c->y0, c->scale_y, c->cells_y);
    /* Row by row, only the cells the triangle covers (a thin triangle
     * covers a small part of its box).  The outer rows reach to infinity:
     * vertices turned reflex since the grid was built may lie beyond it,
     * filed in the border cells. */
    for (uint32_t cy = cy0; cy <= cy1; cy++) {
        double y_low = cy == 0 ? -INFINITY : c->y0 + cy / c->scale_y - margin;
        double y_high = cy + 1 == c->cells_y ? INFINITY : c->y0 + (cy + 1) / c->scale_y + margin;
        double x_low, x_high;
        band_extent(a, b, d, y_low, y_high, &x_low, &x_high);
        if (x_low > x_high)
            continue;
        uint32_t cx0 = cell_coordinate(x_low - margin, c->x0, c->scale_x, c->cells_x);
        uint32_t cx1 = cell_coordinate(x_high + margin, c->x0, c->scale_x, c->cells_x);
        for (uint32_t cx = cx0; cx <= cx1; cx++)
            for (uint32_t r = c->cell_head[cy * c->cells_x + cx]; r != NONE; r = c->cell_next[r]) {
                if (r == p || r == q)
                    continue;
                point2 x = pts[r];
                if (s * orient2(a, b, x) >= -eps && s * orient2(b, d, x) >= -eps &&
                    s * orient2(d, a, x) >= -eps)
                    return false; /* x inside or on the triangle: clipping would touch it */
            }
    }
    return true;
}

static void emit(clipper *c, uint32_t a, uint32_t b, uint32_t d)
{
    /* Fans over hidden vertices are thin but never flat: the opposite
     * corner is off the straight side by more than the tolerance. */
    if (c->count >= c->capacity || !(c->sign * orient2(c->pts[a], c->pts[b], c->pts[d]) > 0.0)) {
        c->failed = true;
        return;
    }
    c->triangles[3 * c->count + 0] = a;
    c->triangles[3 * c->count + 1] = b;
    c->triangles[3 * c->count + 2] = d;
    c->count++;
}

/* Emit the triangle (a, b, d) of candidates with the hidden vertices on its
 * sides a->b, b->d and d->a (the last only for the final triangle: an
 * ear's d->a is the new diagonal), in the polygon's order, all of positive
 * area.  Without hidden vertices on d->a: a fan from d over a..b, whose
 * last triangle is a fan from its first corner over b..d.  With them (k1
 * the first): a fan from b over d..a, whose first triangle is a fan from
 * k1 over b..d and last a fan from the last hidden one over a..b. */
static void emit_triangle(clipper *c, uint32_t a, uint32_t b, uint32_t d, bool closing)
{
    const uint32_t *next = c->full_next;
    if (!closing || next[d] == a) {
        uint32_t x = a, y = b;
        for (uint32_t h = next[a]; h != b; h = next[h]) {
            emit(c, x, h, d);
            x = h;
        }
        for (uint32_t g = next[b]; g != d; g = next[g]) {
            emit(c, x, y, g);
            y = g;
        }
        emit(c, x, y, d);
        return;
    }
    uint32_t first = next[d], y = b, x;
    for (uint32_t g = next[b]; g != d; g = next[g]) {
        emit(c, y, g, first);
        y = g;
    }
    emit(c, y, d, first);
    for (x = first; next[x] != a; x = next[x])
        emit(c, x, next[x], b);
    y = a;
    for (uint32_t h = next[a]; h != b; h = next[h]) {
        emit(c, x, y, h);
        y = h;
    }
    emit(c, x, y, b);
}

/* Clip every ear of the simple polygon; false if it could not (a polygon
 * the tolerance makes look simple but is not), or when cancelled (then
 * *interrupted is set). */
static bool clip_ears(const rad_context *ctx, clipper *c, uint32_t n, bool *interrupted)
{
    for (uint32_t v = 0; v < n; v++) {
        c->ring_prev[v] = v == 0 ? n - 1 : v - 1;
        c->ring_next[v] = v + 1 == n ? 0 : v + 1;
        c->full_next[v] = c->ring_next[v];
        c->flags[v] = 0;
    }
    c->ring_count = n;
    uint32_t start = 0;
    for (uint32_t v = 0; v < n && c->ring_count > 3; v++) {
        if (!(c->flags[v] & VERTEX_HIDDEN) && turn_at(c, v) == 0.0) {
            uint32_t before = c->ring_prev[v];
            hide(c, v);
            start = refresh_pair(c, before, c->ring_next[before]);
        }
    }
    while (c->flags[start] & VERTEX_HIDDEN)
        start = c->full_next[start];
    c->reflex_count = 0;
    grid_build(c, start);

    /* Walk round the ring, clipping where there is an ear and going on at
     * q.  (Going on past q, or first to where the last ear was, were tried:
     * each made one of the test shapes, a spiral or a comb, minutes long.) */
    uint32_t i = start;
    size_t misses = 0, steps = 0;
    while (c->ring_count > 3 && !c->failed) {
        if (++steps % POLL_INTERVAL == 0 && rad_cancelled(ctx)) {
            *interrupted = true;
            return false;
        }
        uint32_t p = c->ring_prev[i], q = c->ring_next[i];
        if (is_ear(c, p, i, q)) {
            emit_triangle(c, p, i, q, false);
            c->full_next[p] = q;
            c->ring_next[p] = q;
            c->ring_prev[q] = p;
            c->ring_count--;
            i = refresh_pair(c, p, q);
            misses = 0;
            /* Keep the grid about as fine as the reflex vertices left. */
            if (c->built_with >= 64 && c->reflex_count < c->built_with / 4)
                grid_build(c, i);
        } else {
            i = q;
            if (++misses > c->ring_count)
                return false; /* a full turn without an ear: not simple after all */
        }
    }
    uint32_t p = c->ring_prev[i], q = c->ring_next[i];
    if (c->failed || c->sign * orient2(c->pts[p], c->pts[i], c->pts[q]) <= c->eps)
        return false;
    emit_triangle(c, p, i, q, true);
    return !c->failed && c->count == c->capacity;
}

size_t rad_triangulate_polygon(const rad_context *ctx, const vec3 *vertices, size_t n,
                               vec3 normal, void *scratch, uint32_t *triangles)
{
    if (n < 3 || n >= UINT32_MAX || !v3_finite(normal) || v3_length(normal) == 0.0)
        return 0;
    vec3 axis_n = v3_normalize(normal);
    /* A right-handed frame (u, v, n): u is perpendicular to n and to the
     * coordinate axis least aligned with n. */
    vec3 helper = fabs(axis_n.x) <= fabs(axis_n.y) && fabs(axis_n.x) <= fabs(axis_n.z)
                      ? v3(1.0, 0.0, 0.0)
                      : (fabs(axis_n.y) <= fabs(axis_n.z) ? v3(0.0, 1.0, 0.0) : v3(0.0, 0.0, 1.0));
    vec3 axis_u = v3_normalize(v3_cross(helper, axis_n));
    vec3 axis_v = v3_cross(axis_n, axis_u);

    /* Scratch: the points, then seven arrays of n words. */
    point2 *pts = scratch;
    uint32_t *words = (uint32_t *)(void *)(pts + n);

    double min_x = INFINITY, min_y = INFINITY, max_x = -INFINITY, max_y = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        vec3 d = v3_sub(vertices[i], vertices[0]);
        pts[i].x = v3_dot(d, axis_u);
        pts[i].y = v3_dot(d, axis_v);
        min_x = fmin(min_x, pts[i].x);
        max_x = fmax(max_x, pts[i].x);
        min_y = fmin(min_y, pts[i].y);
        max_y = fmax(max_y, pts[i].y);
    }
    double extent2 = (max_x - min_x) * (max_x - min_x) + (max_y - min_y) * (max_y - min_y);
    if (!isfinite(extent2))
        return 0;
    /* An orientation test on coordinates of size L carries a rounding error
     * of a few ulp of L^2; 64 ulp leaves a margin and still resolves
     * features a million times smaller than the polygon. */
    double eps = 64.0 * DBL_EPSILON * extent2;

    double twice_area = 0.0;
    for (size_t i = 0; i < n; i++)
        twice_area += orient2(pts[0], pts[i], pts[(i + 1) % n]);
    if (fabs(twice_area) <= eps)
        return 0; /* degenerate, or a figure-eight whose lobes cancel */
    verdict simple = polygon_is_simple(ctx, pts, (uint32_t)n, eps, words);
    if (simple != VERDICT_YES)
        return simple == VERDICT_INTERRUPTED ? RAD_TRIANGULATE_INTERRUPTED : 0;

    clipper c = {
        .pts = pts,
        .eps = eps,
        .sign = twice_area > 0.0 ? 1.0 : -1.0, /* clockwise about `normal`: mirror the tests */
        .ring_prev = words,
        .ring_next = words + n,
        .full_next = words + 2 * n,
        .cell_prev = words + 3 * n,
        .cell_next = words + 4 * n,
        .flags = words + 5 * n,
        .cell_head = words + 6 * n, /* at most n cells: one per reflex vertex */
        .triangles = triangles,
        .capacity = (uint32_t)(n - 2),
    };
    bool interrupted = false;
    if (!clip_ears(ctx, &c, (uint32_t)n, &interrupted))
        return interrupted ? RAD_TRIANGULATE_INTERRUPTED : 0;
    return c.count;
}
