/*
 * vertex.c -- element radiosities to vertex radiosities (Cohen & Wallace,
 * "Radiosity and Realistic Image Synthesis", 1993, sec. 9.2; the lecture
 * notes' "Computing Vertex Colors").
 *
 *   interior vertex v:  B_v = sum_e A_e B_e / sum_e A_e over the elements
 *                       around v.
 *   boundary vertex v:  (on an edge used by one element only) linear
 *                       extrapolation through the element centre.  For a
 *                       quad e, the centre is the midpoint of the diagonal
 *                       from v to the opposite vertex o, so
 *
 *                           B_v = 2 B_e - B_o        o +-------+
 *                                                      |   e   |
 *                                                      |   *   |
 *                                                    v +-------+
 *
 *                       and for a triangle (v, a, b), whose centroid is
 *                       (v + a + b) / 3, B_v = 3 B_e - B_a - B_b.  These
 *                       estimates, over the elements whose other vertices
 *                       are interior, are averaged by area: exact for a
 *                       field linear over parallelograms and triangles.
 *                       With no such element, the notes' formula
 *                       2 * mean(elements) - mean(interior neighbours);
 *                       with no interior neighbour, the plain mean.
 *                       Clamped to >= 0.
 *   T-vertices:         set to lerp(B_a, B_b, t) by Gauss-Seidel passes
 *                       (a T-vertex may sit on an edge whose end is another
 *                       T-vertex; each constraint is an average, so the
 *                       passes converge).
 *
 * An edge of a neighbour's that a T-vertex splits is used by one element on
 * each side but appears as different vertex pairs; such edges (the long
 * edge (a, b) and its pieces through the T-vertices) are not boundary.
 */
#include "interp/interp.h"
#include "strategy/strategy.h"

#include <stdlib.h>
#include <string.h>

static uint64_t edge_key(uint32_t a, uint32_t b)
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    return (uint64_t)lo << 32 | hi;
}

static int compare_u64(const void *pa, const void *pb)
{
    uint64_t a = *(const uint64_t *)pa, b = *(const uint64_t *)pb;
    return (a > b) - (a < b);
}

/* Number of occurrences of `key` in the sorted array. */
static size_t count_sorted(const uint64_t *keys, size_t n, uint64_t key)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (keys[mid] < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    size_t count = 0;
    while (lo + count < n && keys[lo + count] == key)
        count++;
    return count;
}

/* T-vertex records sorted by vertex, for "which split edges is v on":
 * keys (vertex << 32 | record index), sorted. */
typedef struct tvertex_index {
    const rad_tvertex *records;
    uint64_t *by_vertex;
    size_t count;
} tvertex_index;

/* The range [*first, *first + return) of `by_vertex` with records of v. */
static size_t tvertex_records(const tvertex_index *ti, uint32_t v, size_t *first)
{
    size_t lo = 0, hi = ti->count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if ((ti->by_vertex[mid] >> 32) < v)
            lo = mid + 1;
        else
            hi = mid;
    }
    size_t n = 0;
    while (lo + n < ti->count && (ti->by_vertex[lo + n] >> 32) == v)
        n++;
    *first = lo;
    return n;
}

/* True if vertex z lies on the split edge (a, b) of record r: an end, or a
 * T-vertex of that same edge. */
static bool on_split_edge(const tvertex_index *ti, uint32_t z, const rad_tvertex *r)
{
    if (z == r->a || z == r->b)
        return true;
    size_t first, n = tvertex_records(ti, z, &first);
    uint64_t parent = edge_key(r->a, r->b);
    for (size_t i = 0; i < n; i++) {
        const rad_tvertex *q = &ti->records[(uint32_t)ti->by_vertex[first + i]];
        if (edge_key(q->a, q->b) == parent)
            return true;
    }
    return false;
}

/* True if the edge (x, y) is a split edge or a piece of one. */
static bool edge_is_split(const tvertex_index *ti, const uint64_t *split_keys, uint32_t x,
                          uint32_t y)
{
    if (ti->count == 0)
        return false;
    if (count_sorted(split_keys, ti->count, edge_key(x, y)) > 0)
        return true;
    for (int end = 0; end < 2; end++) {
        size_t first, n = tvertex_records(ti, end ? y : x, &first);
        for (size_t i = 0; i < n; i++) {
            const rad_tvertex *r = &ti->records[(uint32_t)ti->by_vertex[first + i]];
            if (on_split_edge(ti, x, r) && on_split_edge(ti, y, r))
                return true;
        }
    }
    return false;
}

static void clamp_nonnegative(double *rgb)
{
    for (int c = 0; c < 3; c++)
        if (!(rgb[c] >= 0.0))
            rgb[c] = 0.0;
}

rad_result rad_vertex_values(rad_context *ctx, const rad_mesh *mesh,
                             const double *element_value, double *vertex_value)
{
    const size_t nv = mesh->vertex_count, ne = mesh->element_count;
    rad_result result = RAD_ERROR_OUT_OF_MEMORY;
    double *weight = rad_alloc(ctx, RAD_MEM_RENDER, nv, sizeof(double), "vertex weights");
    uint32_t *adjacent_start = rad_alloc(ctx, RAD_MEM_RENDER, nv + 1, sizeof(uint32_t), "vertex adjacency");
    uint32_t *adjacent = rad_alloc(ctx, RAD_MEM_RENDER, 4 * ne, sizeof(uint32_t), "vertex adjacency");
    uint64_t *edges = rad_alloc(ctx, RAD_MEM_RENDER, 4 * ne, sizeof(uint64_t), "element edges");
    uint64_t *split_keys = rad_alloc(ctx, RAD_MEM_RENDER, mesh->tvertex_count, sizeof(uint64_t), "T-edges");
    uint64_t *tvertex_order = rad_alloc(ctx, RAD_MEM_RENDER, mesh->tvertex_count, sizeof(uint64_t),
                                              "T-vertex index");
    bool *boundary = rad_alloc(ctx, RAD_MEM_RENDER, nv, sizeof(bool), "boundary vertices");
    uint32_t *stamp = rad_alloc(ctx, RAD_MEM_RENDER, nv, sizeof(uint32_t), "vertex marks");
    double *interior = rad_alloc(ctx, RAD_MEM_RENDER, 3 * nv, sizeof(double), "interior vertex values");
    if (!weight || !adjacent_start || !adjacent || !edges || !split_keys || !tvertex_order ||
        !boundary || !stamp || !interior)
        goto done;

    /* Area-weighted means, and the vertex -> element adjacency (CSR). */
    memset(vertex_value, 0, 3 * nv * sizeof(double));
    size_t edge_count = 0;
    for (size_t e = 0; e < ne; e++) {
        const rad_element *el = &mesh->elements[e];
        for (uint32_t i = 0; i < el->vertex_count; i++) {
            uint32_t v = el->vertex[i];
            weight[v] += el->area;
            for (int c = 0; c < 3; c++)
                vertex_value[3 * v + c] += el->area * element_value[3 * e + c];
            adjacent_start[v + 1]++;
            edges[edge_count++] = edge_key(v, el->vertex[(i + 1) % el->vertex_count]);
        }
    }
    for (size_t v = 0; v < nv; v++) {
        adjacent_start[v + 1] += adjacent_start[v];
        for (int c = 0; c < 3; c++)
            vertex_value[3 * v + c] = weight[v] > 0.0 ? vertex_value[3 * v + c] / weight[v] : 0.0;
    }
    memcpy(interior, vertex_value, 3 * nv * sizeof(double));
    {
        uint32_t *fill = stamp; /* borrowed as a cursor per vertex */
        for (size_t v = 0; v < nv; v++)
            fill[v] = adjacent_start[v];
        for (size_t e = 0; e < ne; e++)
            for (uint32_t i = 0; i < mesh->elements[e].vertex_count; i++)
                adjacent[fill[mesh->elements[e].vertex[i]]++] = (uint32_t)e;
        for (size_t v = 0; v < nv; v++)
            stamp[v] = UINT32_MAX;
    }

    /* Boundary vertices: ends of an edge used by one element only, unless
     * the edge is split by T-vertices (then its other side is there, as
     * different vertex pairs). */
    qsort(edges, edge_count, sizeof *edges, compare_u64);
    tvertex_index ti = {mesh->tvertices, tvertex_order, mesh->tvertex_count};
    for (size_t k = 0; k < ti.count; k++) {
        tvertex_order[k] = (uint64_t)mesh->tvertices[k].vertex << 32 | k;
        split_keys[k] = edge_key(mesh->tvertices[k].a, mesh->tvertices[k].b);
    }
    qsort(split_keys, ti.count, sizeof *split_keys, compare_u64);
    qsort(tvertex_order, ti.count, sizeof *tvertex_order, compare_u64);
    for (size_t e = 0; e < ne; e++) {
        const rad_element *el = &mesh->elements[e];
        for (uint32_t i = 0; i < el->vertex_count; i++) {
            uint32_t x = el->vertex[i], y = el->vertex[(i + 1) % el->vertex_count];
            if (count_sorted(edges, edge_count, edge_key(x, y)) == 1 &&
                !edge_is_split(&ti, split_keys, x, y))
                boundary[x] = boundary[y] = true;
        }
    }

    /* Extrapolate the boundary vertices from the interior means. */
    for (size_t v = 0; v < nv; v++) {
        if (!boundary[v])
            continue;
        double estimate[3] = {0, 0, 0}, estimate_weight = 0.0;
        double neighbour[3] = {0, 0, 0};
        size_t neighbour_count = 0;
        for (uint32_t k = adjacent_start[v]; k < adjacent_start[v + 1]; k++) {
            uint32_t e = adjacent[k];
            const rad_element *el = &mesh->elements[e];
            uint32_t n = el->vertex_count, at = 0;
            while (at < n && el->vertex[at] != v)
                at++;
            const double *be = &element_value[3 * e];
            if (n == 4) {
                uint32_t o = el->vertex[(at + 2) % 4];
                if (!boundary[o] && weight[o] > 0.0) {
                    for (int c = 0; c < 3; c++)
                        estimate[c] += el->area * (2.0 * be[c] - interior[3 * o + c]);
                    estimate_weight += el->area;
                }
            } else {
                uint32_t a = el->vertex[(at + 1) % 3], b = el->vertex[(at + 2) % 3];
                if (!boundary[a] && !boundary[b] && weight[a] > 0.0 && weight[b] > 0.0) {
                    for (int c = 0; c < 3; c++)
                        estimate[c] += el->area * (3.0 * be[c] - interior[3 * a + c] -
                                                   interior[3 * b + c]);
                    estimate_weight += el->area;
                }
            }
            for (uint32_t i = 0; i < n; i++) {
                uint32_t u = el->vertex[i];
                if (u == v || boundary[u] || weight[u] <= 0.0 || stamp[u] == (uint32_t)v)
                    continue;
                stamp[u] = (uint32_t)v;
                for (int c = 0; c < 3; c++)
                    neighbour[c] += interior[3 * u + c];
                neighbour_count++;
            }
        }
        double *out = &vertex_value[3 * v];
        if (estimate_weight > 0.0) {
            for (int c = 0; c < 3; c++)
                out[c] = estimate[c] / estimate_weight;
        } else if (neighbour_count > 0) {
            for (int c = 0; c < 3; c++)
                out[c] = 2.0 * interior[3 * v + c] - neighbour[c] / (double)neighbour_count;
        }
        clamp_nonnegative(out);
    }

    /* T-vertices: Gauss-Seidel over the constraints until nothing moves by
     * more than 1e-12 of the largest value (round-off level), or 100 passes.
     * The records come coarse first (mesh/weld.c), so one pass sets them
     * all and the second confirms it. */
    double scale = 0.0;
    for (size_t i = 0; i < 3 * nv; i++)
        scale = fmax(scale, fabs(vertex_value[i]));
    for (int pass = 0; pass < 100 && mesh->tvertex_count > 0; pass++) {
        double change = 0.0;
        for (size_t k = 0; k < mesh->tvertex_count; k++) {
            const rad_tvertex *r = &mesh->tvertices[k];
            for (int c = 0; c < 3; c++) {
                double value = (1.0 - r->t) * vertex_value[3 * r->a + c] +
                               r->t * vertex_value[3 * r->b + c];
                change = fmax(change, fabs(value - vertex_value[3 * r->vertex + c]));
                vertex_value[3 * r->vertex + c] = value;
            }
        }
        if (change <= 1e-12 * scale)
            break;
    }
    result = RAD_OK;

done:
    rad_free(weight);
    rad_free(adjacent_start);
    rad_free(adjacent);
    rad_free(edges);
    rad_free(split_keys);
    rad_free(tvertex_order);
    rad_free(boundary);
    rad_free(stamp);
    rad_free(interior);
    return result;
}

void rad_element_interpolate(const rad_mesh *mesh, const rad_element *e,
                             const double *vertex_value, double s, double t, double rgb[3])
{
    (void)mesh;
    /* A point found by a ray or a projection can lie a rounding error
     * outside its element; clamped, the weights stay a convex combination,
     * so values >= 0 give a value >= 0 (-7e-18 W/m^2 reached a picture). */
    s = fmin(fmax(s, 0.0), 1.0);
    t = fmin(fmax(t, 0.0), 1.0);
    if (e->vertex_count != 4 && s + t > 1.0) {
        double sum = s + t;
        s /= sum;
        t /= sum;
    }
    const double *v0 = &vertex_value[3 * e->vertex[0]];
    const double *v1 = &vertex_value[3 * e->vertex[1]];
    const double *v2 = &vertex_value[3 * e->vertex[2]];
    if (e->vertex_count == 4) {
        const double *v3 = &vertex_value[3 * e->vertex[3]];
        double w0 = (1.0 - s) * (1.0 - t), w1 = s * (1.0 - t), w2 = s * t, w3 = (1.0 - s) * t;
        for (int c = 0; c < 3; c++)
            rgb[c] = w0 * v0[c] + w1 * v1[c] + w2 * v2[c] + w3 * v3[c];
    } else {
        double w0 = 1.0 - s - t;
        for (int c = 0; c < 3; c++)
            rgb[c] = w0 * v0[c] + s * v1[c] + t * v2[c];
    }
}

rad_result rad_view_vertex_values(rad_context *ctx, const rad_solution_view *view, const double *element_value,
                                  double *vertex_value)
{
    if (view->vertex_radiosity) {
        memcpy(vertex_value, view->vertex_radiosity, 3 * view->mesh->vertex_count * sizeof *vertex_value);
        return RAD_OK;
    }
    return rad_vertex_values(ctx, view->mesh, element_value, vertex_value);
}
