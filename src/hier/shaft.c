/*
 * shaft.c -- shaft culling (Haines & Wallace, "Shaft culling for efficient
 * ray-traced radiosity", Eurographics Workshop on Rendering 1991).
 *
 * The shaft of two boxes A and B is the convex region that holds every
 * segment from A to B: their union box, cut by a plane wherever one face
 * of the union box belongs to A alone and an adjacent one to B alone.  In
 * the plane of those two faces' axes (i, j), the cut joins A's corner to
 * B's corner:
 *
 *        j ^      +------+ B          union box face j=max: B's
 *          |    / |      |            union box face i=min: A's
 *          |   /  +------+            so the corner region above the
 *          |  / <- cut                line A(min i, max j) -> B(min i,
 *        +-----+                      max j) is outside the shaft.
 *        |  A  |
 *        +-----+ ---> i
 *
 * A patch whose box lies wholly outside one of these planes (touching
 * counts as outside, within `tol`) cannot block any segment from A to B.
 * If no patch other than the ends' own is left, the pair is fully visible
 * and so is every pair of their descendants: no shadow ray is needed.
 */
#include "hier/hier.h"

typedef struct shaft_plane {
    int i, j;            /* axes of the plane's normal */
    double ni, nj;       /* normal, outward */
    double pi, pj;       /* a point of the plane */
} shaft_plane;

typedef struct shaft {
    double lo[3], hi[3]; /* union box */
    shaft_plane plane[12];
    int planes;
} shaft;

static double axis_of(vec3 v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }

static void shaft_make(shaft *s, vec3 alo, vec3 ahi, vec3 blo, vec3 bhi)
{
    double al[3] = {alo.x, alo.y, alo.z}, ah[3] = {ahi.x, ahi.y, ahi.z};
    double bl[3] = {blo.x, blo.y, blo.z}, bh[3] = {bhi.x, bhi.y, bhi.z};
    /* owner[a][side]: 1 = A alone, 2 = B alone, 0 = both */
    int owner[3][2];
    for (int a = 0; a < 3; a++) {
        s->lo[a] = fmin(al[a], bl[a]);
        s->hi[a] = fmax(ah[a], bh[a]);
        owner[a][0] = al[a] < bl[a] ? 1 : (bl[a] < al[a] ? 2 : 0);
        owner[a][1] = ah[a] > bh[a] ? 1 : (bh[a] > ah[a] ? 2 : 0);
    }
    s->planes = 0;
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            for (int si = 0; si < 2; si++)
                for (int sj = 0; sj < 2; sj++) {
                    int oi = owner[i][si], oj = owner[j][sj];
                    if (!(oi && oj && oi != oj))
                        continue;
                    double ai = si ? ah[i] : al[i], aj = sj ? ah[j] : al[j];
                    double bi = si ? bh[i] : bl[i], bj = sj ? bh[j] : bl[j];
                    double di = bi - ai, dj = bj - aj;
                    double ni = dj, nj = -di;
                    /* Outward: toward the union box's corner on these sides. */
                    double ci = si ? s->hi[i] : s->lo[i], cj = sj ? s->hi[j] : s->lo[j];
                    if (ni * (ci - ai) + nj * (cj - aj) < 0.0) {
                        ni = -ni;
                        nj = -nj;
                    }
                    double len = sqrt(ni * ni + nj * nj);
                    if (!(len > 0.0))
                        continue;
                    shaft_plane *p = &s->plane[s->planes++];
                    p->i = i;
                    p->j = j;
                    p->ni = ni / len;
                    p->nj = nj / len;
                    p->pi = ai;
                    p->pj = aj;
                }
}

/* May the box [lo, hi] reach inside the shaft? */
static bool shaft_overlaps(const shaft *s, vec3 lo, vec3 hi, double tol)
{
    for (int a = 0; a < 3; a++)
        if (!(axis_of(lo, a) < s->hi[a] - tol && axis_of(hi, a) > s->lo[a] + tol))
            return false;
    for (int k = 0; k < s->planes; k++) {
        const shaft_plane *p = &s->plane[k];
        /* The box corner deepest inside (most negative signed distance). */
        double xi = p->ni > 0.0 ? axis_of(lo, p->i) : axis_of(hi, p->i);
        double xj = p->nj > 0.0 ? axis_of(lo, p->j) : axis_of(hi, p->j);
        if (p->ni * (xi - p->pi) + p->nj * (xj - p->pj) >= -tol)
            return false;
    }
    return true;
}

bool hr_shaft_clear(const hr_tree *t, uint32_t a, uint32_t b, double tol)
{
    const hr_node *na = &t->nodes[a], *nb = &t->nodes[b];
    if (na->kind != HR_SURFACE || nb->kind != HR_SURFACE)
        return false; /* a cluster's own members may block */
    shaft s;
    shaft_make(&s, na->lo, na->hi, nb->lo, nb->hi);
    uint32_t pa = na->patch, pb = nb->patch;
    size_t P = t->base->patch_count;
    if (t->clusters == 0) {
        for (size_t p = 0; p < P; p++) {
            if (p == pa || p == pb)
                continue;
            const hr_node *n = &t->nodes[t->root_of_patch[p]];
            if (shaft_overlaps(&s, n->lo, n->hi, tol))
                return false;
        }
        return true;
    }
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        uint32_t k = stack[--top];
        const hr_node *n = &t->nodes[k];
        if (n->kind == HR_SURFACE) {
            if (n->patch != pa && n->patch != pb && shaft_overlaps(&s, n->lo, n->hi, tol))
                return false;
            continue;
        }
        if (!shaft_overlaps(&s, n->lo, n->hi, tol))
            continue;
        if (top + 2 > (int)(sizeof stack / sizeof stack[0]))
            return false; /* deeper than any balanced hierarchy: give up, cast rays */
        stack[top++] = n->child[0];
        stack[top++] = n->child[1];
    }
    return true;
}
