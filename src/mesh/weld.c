/*
 * weld.c -- welding grid points into shared vertices, and T-vertices.
 *
 * Grid points are merged when they lie within 1e-6 x the scene diagonal of
 * each other (less for slivers: mesh_weld_tolerance), belong to the same
 * surface, and their patches' normals differ by less than the crease
 * angle: shading is then smooth within a surface but keeps the physical
 * discontinuity at corners.
 *
 * A welded vertex lying inside a boundary edge of another element of its
 * surface is a T-vertex (neighbouring patches with different grids):
 *
 *    +-----+-----+
 *    |     |     |
 *    a-----v-----+    v lies inside the edge (a, b) of the element below:
 *    |           |    its value must be lerp(value[a], value[b], t)
 *    b-----------+
 *
 * Both searches hash points into cubic cells by sorting (cell key, item)
 * pairs, with an open-addressing index from key to first entry.
 */
#include "mesh/mesh_internal.h"

#include <stdlib.h>
#include <string.h>

/* ---- spatial hashing by sorting: (cell key, item) pairs ---- */

static uint64_t cell_key(int64_t x, int64_t y, int64_t z)
{
    return rad_mix64((uint64_t)x * 0x9e3779b97f4a7c15ULL ^ rad_mix64((uint64_t)y) ^
                     rad_mix64((uint64_t)z * 0xc2b2ae3d27d4eb4fULL));
}

/* The grid cell of coordinate x for cells 1/inv wide.  Clamped to +-2^62
 * so that a coordinate far from the cell size (a tiny weld tolerance in a
 * scene far from the origin) never overflows the conversion. */
static int64_t cell_of(double x, double inv)
{
    double c = floor(x * inv);
    if (!(c > -4.6e18))
        return c < 0.0 ? -(INT64_C(1) << 62) : 0; /* -inf, or NaN */
    return c < 4.6e18 ? (int64_t)c : (INT64_C(1) << 62);
}

static int cell_entry_cmp(const void *a, const void *b)
{
    const cell_entry *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->item < y->item ? -1 : (x->item > y->item);
}

/* A hash index over sorted entries: key -> first entry with that key, in
 * O(1) instead of a binary search (10^6 boundary vertices and 27 cells per
 * query made the searches the leaf mesh's bottleneck). */
typedef struct cell_index {
    uint64_t *key;
    uint32_t *first;      /* UINT32_MAX: empty slot */
    size_t mask;
} cell_index;

static bool cell_index_build(rad_context *ctx, const cell_entry *e, size_t n, cell_index *ix)
{
    size_t size = 64;
    while (size < 2 * n)
        size *= 2;
    ix->key = rad_alloc(ctx, RAD_MEM_MESH, size, sizeof *ix->key, "mesh: cell index");
    ix->first = ix->key ? rad_alloc(ctx, RAD_MEM_MESH, size, sizeof *ix->first, "mesh: cell index") : NULL;
    ix->mask = size - 1;
    if (!ix->first) {
        rad_free(ix->key);
        ix->key = NULL;
        return false;
    }
    memset(ix->first, 0xff, size * sizeof *ix->first);
    for (size_t i = 0; i < n; i++) {
        if (i > 0 && e[i].key == e[i - 1].key)
            continue;
        size_t h = rad_mix64(e[i].key) & ix->mask;
        while (ix->first[h] != UINT32_MAX)
            h = (h + 1) & ix->mask;
        ix->key[h] = e[i].key;
        ix->first[h] = (uint32_t)i;
    }
    return true;
}

/* First index of `key` in the sorted entries, or n when absent. */
static size_t cell_index_find(const cell_index *ix, size_t n, uint64_t key)
{
    for (size_t h = rad_mix64(key) & ix->mask; ix->first[h] != UINT32_MAX; h = (h + 1) & ix->mask)
        if (ix->key[h] == key)
            return ix->first[h];
    return n;
}

static void cell_index_free(cell_index *ix)
{
    rad_free(ix->key);
    rad_free(ix->first);
}

/* ---- welding ---- */

/* The distance within which grid points are one vertex: 1e-6 x the scene
 * diagonal (far above the round-off of grid points computed from
 * different patches), but below 1e-3 x the narrowest element, so that the
 * corners of a sliver's elements (a 1 km x 1 um strip) never merge into
 * zero-area elements.  The narrowest element is estimated per patch as
 * its width (2 x area / longest edge) or its shortest edge, whichever is
 * less, over its cells along the longest side. */
double mesh_weld_tolerance(const rad_mesh *mesh, double diag)
{
    double narrowest = HUGE_VAL;
    for (size_t i = 0; i < mesh->patch_count; i++) {
        const rad_patch *p = &mesh->patches[i];
        double width = rad_corners_width(p->corner, p->corner_count);
        uint32_t cells = p->nu > p->nv ? p->nu : p->nv;
        if (width > 0.0)
            narrowest = fmin(narrowest, width / (double)cells);
    }
    double tol = 1e-6 * diag;
    if (narrowest > 0.0 && 1e-3 * narrowest < tol)
        tol = 1e-3 * narrowest;
    return tol;
}

/* Weld raw grid points; fills weld[raw] = welded index and the positions. */
rad_result mesh_weld(rad_context *ctx, const rad_mesh *mesh, const raw_vertex *raw, size_t nraw,
                     double tol, double cos_crease, uint32_t *weld_of, vec3 **positions,
                     size_t *count)
{
    cell_entry *cells = rad_alloc(ctx, RAD_MEM_MESH, nraw ? nraw : 1, sizeof *cells, "mesh: weld table");
    vec3 *pos = rad_alloc(ctx, RAD_MEM_MESH, nraw ? nraw : 1, sizeof *pos, "mesh: vertices");
    if (!cells || !pos) {
        rad_free(cells);
        rad_free(pos);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    double inv = 1.0 / tol;
    for (size_t r = 0; r < nraw; r++) {
        vec3 p = raw[r].position;
        cells[r].key = cell_key(cell_of(p.x, inv), cell_of(p.y, inv), cell_of(p.z, inv));
        cells[r].item = (uint32_t)r;
    }
    qsort(cells, nraw, sizeof *cells, cell_entry_cmp);
    cell_index cix;
    if (!cell_index_build(ctx, cells, nraw, &cix)) {
        rad_free(cells);
        rad_free(pos);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    size_t nw = 0;
    for (size_t r = 0; r < nraw; r++) {
        vec3 p = raw[r].position;
        const rad_patch *pr = &mesh->patches[raw[r].patch];
        int64_t cx = cell_of(p.x, inv), cy = cell_of(p.y, inv), cz = cell_of(p.z, inv);
        uint32_t best = UINT32_MAX;
        for (int dz = -1; dz <= 1; dz++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    uint64_t key = cell_key(cx + dx, cy + dy, cz + dz);
                    /* A cell's entries are in raw order (cell_entry_cmp), so
                     * the first match is the earliest and the scan stops
                     * there: N coincident points (the apex of a fan of 10^5
                     * triangles) cost O(N), not O(N^2). */
                    for (size_t k = cell_index_find(&cix, nraw, key); k < nraw && cells[k].key == key; k++) {
                        uint32_t c = cells[k].item;
                        if (c >= r || c >= best)
                            break;
                        const rad_patch *pc = &mesh->patches[raw[c].patch];
                        if (pc->surface != pr->surface || v3_dot(pc->normal, pr->normal) < cos_crease)
                            continue;
                        /* Not across a contact line: the two sides of a
                         * partition's foot are lit and dark. */
                        if (raw[c].patch != raw[r].patch && mesh->contact_count &&
                            (rad_mesh_on_contact(mesh, pr->polygon, p) || rad_mesh_on_contact(mesh, pc->polygon, p)))
                            continue;
                        if (v3_length(v3_sub(raw[c].position, p)) <= tol) {
                            best = c;
                            break;
                        }
                    }
                }
        if (best != UINT32_MAX) {
            weld_of[r] = weld_of[best];
        } else {
            weld_of[r] = (uint32_t)nw;
            pos[nw++] = p;
        }
    }
    rad_free(cells);
    cell_index_free(&cix);
    *positions = pos;
    *count = nw;
    return RAD_OK;
}

/* ---- T-vertices ---- */

/* Find welded vertices lying inside boundary edges of elements of the same
 * surface and plane (T-vertices): a vertex whose elements turn by more than
 * the crease from the edge's element is not constrained by it (the corner
 * of a box, whose faces are one surface, must not pass a face's shading to
 * the next: red blotches on the Cornell tall block's front).  Only vertices on boundary edges can be T-vertices,
 * so both sets are small; they are matched through a grid of cell size h. */
rad_result mesh_find_tvertices(rad_context *ctx, rad_mesh *mesh, double tol, double h, double cos_crease)
{
    typedef struct edge_rec {
        uint32_t a, b, element;
    } edge_rec;
    size_t ne = 0;
    for (size_t i = 0; i < mesh->element_count; i++)
        ne += mesh->elements[i].vertex_count;
    rad_result result = RAD_ERROR_OUT_OF_MEMORY;
    cell_entry *order = NULL, *grid = NULL;
    uint8_t *on_boundary = NULL;
    uint32_t *vsurf = NULL, *vcoarse = NULL, *rank = NULL;
    vec3 *vnormal = NULL;
    cell_entry *by_size = NULL;
    cell_index gix = {NULL, NULL, 0};
    edge_rec *edges = rad_alloc(ctx, RAD_MEM_MESH, ne, sizeof *edges, "mesh: edges");
    if (!edges)
        goto done;
    size_t k = 0;
    for (size_t i = 0; i < mesh->element_count; i++) {
        const rad_element *e = &mesh->elements[i];
        for (uint32_t c = 0; c < e->vertex_count; c++) {
            uint32_t a = e->vertex[c], b = e->vertex[(c + 1) % e->vertex_count];
            edges[k].a = a < b ? a : b;
            edges[k].b = a < b ? b : a;
            edges[k].element = (uint32_t)i;
            k++;
        }
    }
    /* Sort edges by (a, b) to find those used once (boundary edges). */
    order = rad_alloc(ctx, RAD_MEM_MESH, ne, sizeof *order, "mesh: edges");
    if (!order)
        goto done;
    for (size_t i = 0; i < ne; i++) {
        order[i].key = ((uint64_t)edges[i].a << 32) | edges[i].b;
        order[i].item = (uint32_t)i;
    }
    qsort(order, ne, sizeof *order, cell_entry_cmp);
    size_t nb = 0;
    on_boundary = rad_alloc(ctx, RAD_MEM_MESH, mesh->vertex_count, 1, "mesh: boundary flags");
    if (!on_boundary)
        goto done;
    for (size_t i = 0; i < ne;) {
        size_t j = i;
        while (j < ne && order[j].key == order[i].key)
            j++;
        if (j - i == 1) {
            order[nb++] = order[i]; /* compact: boundary edges first */
            on_boundary[edges[order[i].item].a] = on_boundary[edges[order[i].item].b] = 1;
        }
        i = j;
    }
    /* Vertex -> a surface and normal, from any element that uses it. */
    vsurf = rad_alloc(ctx, RAD_MEM_MESH, mesh->vertex_count, sizeof *vsurf, "mesh: vertex surfaces");
    vnormal = vsurf ? rad_alloc(ctx, RAD_MEM_MESH, mesh->vertex_count, sizeof *vnormal, "mesh: vertex normals")
                    : NULL;
    size_t nbv = 0;
    for (size_t v = 0; v < mesh->vertex_count; v++)
        nbv += on_boundary[v];
    grid = vnormal ? rad_alloc(ctx, RAD_MEM_MESH, nbv, sizeof *grid, "mesh: vertex grid") : NULL;
    if (!grid)
        goto done;
    /* Welded vertices join elements within the crease of each other, so
     * any one element's normal stands for the vertex's plane. */
    for (size_t i = 0; i < mesh->element_count; i++)
        for (uint32_t c = 0; c < mesh->elements[i].vertex_count; c++) {
            vsurf[mesh->elements[i].vertex[c]] = mesh->elements[i].surface;
            vnormal[mesh->elements[i].vertex[c]] = mesh->elements[i].normal;
        }
    /* Who constrains whom.  Where two grids meet along a line with their
     * vertices interleaved (pieces of a floor cut along a block's
     * footprint), constraining each side's vertices to the other's edges
     * ties the two into one cyclic system: its only solution is linear
     * along the whole line, and Gauss-Seidel needed 43,000 passes to get
     * there on the default Cornell box.  So a vertex is constrained only by
     * an edge of an element coarser than every element it belongs to
     * (longest edge, then index): the constraints form a hierarchy, solved
     * in one pass from the coarse down (records sorted so), and a quadtree's
     * small leaves still follow their big neighbours exactly. */
    size_t ne_all = mesh->element_count;
    by_size = rad_alloc(ctx, RAD_MEM_MESH, ne_all ? ne_all : 1, sizeof *by_size, "mesh: element sizes");
    rank = by_size ? rad_alloc(ctx, RAD_MEM_MESH, ne_all ? ne_all : 1, sizeof *rank, "mesh: element sizes") : NULL;
    vcoarse = rank ? rad_alloc(ctx, RAD_MEM_MESH, mesh->vertex_count ? mesh->vertex_count : 1, sizeof *vcoarse,
                               "mesh: vertex owners")
                   : NULL;
    if (!vcoarse)
        goto done;
    for (size_t i = 0; i < ne_all; i++) {
        const rad_element *e = &mesh->elements[i];
        double longest = 0.0;
        for (uint32_t c = 0; c < e->vertex_count; c++)
            longest = fmax(longest, v3_length(v3_sub(mesh->vertices[e->vertex[(c + 1) % e->vertex_count]],
                                                     mesh->vertices[e->vertex[c]])));
        uint64_t bits;
        memcpy(&bits, &longest, sizeof bits); /* >= 0: the bits order as the values */
        by_size[i].key = UINT64_MAX - bits;   /* longest first, then by index */
        by_size[i].item = (uint32_t)i;
    }
    qsort(by_size, ne_all, sizeof *by_size, cell_entry_cmp);
    for (size_t q = 0; q < ne_all; q++)
        rank[by_size[q].item] = (uint32_t)q; /* 0 = the coarsest */
    for (size_t v = 0; v < mesh->vertex_count; v++)
        vcoarse[v] = UINT32_MAX;
    for (size_t i = 0; i < ne_all; i++)
        for (uint32_t c = 0; c < mesh->elements[i].vertex_count; c++) {
            uint32_t v = mesh->elements[i].vertex[c];
            vcoarse[v] = rank[i] < vcoarse[v] ? rank[i] : vcoarse[v]; /* the rank of its coarsest element */
        }
    /* Cells of the mesh size h: a boundary edge is walked along its
     * length in pieces of half a cell, so a long edge visits the cells it
     * passes and no others.  (Cells as wide as the longest boundary edge
     * put a face of 10^5 fan triangles, whose edges are as long as the
     * face, into a handful of cells: every edge then scanned every vertex,
     * 94% of a 26 s run.) */
    double cell = h > 0.0 ? h : 1.0;
    /* The walk visits about 2 x (boundary length) / cell pieces: where the
     * mesh size is small against long boundary edges (a 1 km x 1 um
     * sliver cut into 64 elements: 10^6 pieces of 2 mm), cells grow until
     * the pieces are at most 64 per boundary vertex, so the work stays
     * linear in the boundary's size. */
    double boundary_length = 0.0;
    for (size_t bi = 0; bi < nb; bi++) {
        const edge_rec *ed = &edges[order[bi].item];
        boundary_length += v3_length(v3_sub(mesh->vertices[ed->b], mesh->vertices[ed->a]));
    }
    cell = fmax(cell, 2.0 * boundary_length / (64.0 * (double)(nbv + 16)));
    double inv = 1.0 / cell;
    size_t g = 0;
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        if (!on_boundary[v])
            continue;
        vec3 p = mesh->vertices[v];
        grid[g].key = cell_key(cell_of(p.x, inv), cell_of(p.y, inv), cell_of(p.z, inv));
        grid[g].item = (uint32_t)v;
        g++;
    }
    qsort(grid, g, sizeof *grid, cell_entry_cmp);
    if (!cell_index_build(ctx, grid, g, &gix))
        goto done;

    size_t cap = 0;
    result = RAD_OK;
    for (size_t bi = 0; bi < nb && result == RAD_OK; bi++) {
        const edge_rec *ed = &edges[order[bi].item];
        const rad_element *el = &mesh->elements[ed->element];
        vec3 a = mesh->vertices[ed->a], b = mesh->vertices[ed->b];
        vec3 ab = v3_sub(b, a);
        double len2 = v3_dot(ab, ab);
        if (!(len2 > 0.0))
            continue;
        /* Piece k covers t in [k / pieces, (k + 1) / pieces]; a vertex is
         * taken by the piece its projection falls in, so once. */
        double len = sqrt(len2);
        double pieces_d = ceil(len / (0.5 * cell));
        size_t pieces = pieces_d < 1.0 ? 1 : pieces_d > 1e9 ? 1000000000 : (size_t)pieces_d;
        for (size_t piece = 0; piece < pieces && result == RAD_OK; piece++) {
            double t0 = (double)piece / (double)pieces, t1 = (double)(piece + 1) / (double)pieces;
            vec3 p0 = v3_mad(a, ab, t0), p1 = v3_mad(a, ab, t1);
            vec3 lo = v3_min(p0, p1), hi = v3_max(p0, p1);
            int64_t x0 = cell_of(lo.x - tol, inv), x1 = cell_of(hi.x + tol, inv);
            int64_t y0 = cell_of(lo.y - tol, inv), y1 = cell_of(hi.y + tol, inv);
            int64_t z0 = cell_of(lo.z - tol, inv), z1 = cell_of(hi.z + tol, inv);
            for (int64_t z = z0; z <= z1 && result == RAD_OK; z++)
                for (int64_t y = y0; y <= y1 && result == RAD_OK; y++)
                    for (int64_t x = x0; x <= x1 && result == RAD_OK; x++) {
                        uint64_t key = cell_key(x, y, z);
                        for (size_t q = cell_index_find(&gix, g, key); q < g && grid[q].key == key; q++) {
                            uint32_t v = grid[q].item;
                            if (v == ed->a || v == ed->b || vsurf[v] != el->surface ||
                                v3_dot(vnormal[v], el->normal) < cos_crease ||
                                rank[ed->element] >= vcoarse[v])
                                continue;
                            /* A vertex on a contact line: the edge runs along
                             * it (the far side is not this side) or across it. */
                            if (mesh->contact_count &&
                                rad_mesh_on_contact(mesh, mesh->patches[el->patch].polygon, mesh->vertices[v]))
                                continue;
                            vec3 d = v3_sub(mesh->vertices[v], a);
                            double t = v3_dot(d, ab) / len2;
                            if (t <= 1e-9 || t >= 1.0 - 1e-9)
                                continue;
                            if (t < t0 || (piece + 1 < pieces ? t >= t1 : t > t1))
                                continue; /* another piece's */
                            if (v3_length(v3_sub(d, v3_scale(ab, t))) > tol)
                                continue;
                            if (mesh->tvertex_count == cap) {
                                size_t nc = cap ? 2 * cap : 64;
                                rad_tvertex *nt = rad_realloc(ctx, RAD_MEM_MESH, mesh->tvertices, nc,
                                                              sizeof *nt, "mesh: T-vertices");
                                if (!nt) {
                                    result = RAD_ERROR_OUT_OF_MEMORY;
                                    break;
                                }
                                mesh->tvertices = nt;
                                cap = nc;
                            }
                            rad_tvertex tv = {v, ed->a, ed->b, t};
                            mesh->tvertices[mesh->tvertex_count++] = tv;
                        }
                    }
        }
    }
    if (result == RAD_OK && mesh->tvertex_count > 1) {
        /* Coarse owners first: every record's edge ends are then final
         * before it reads them.  by_size is reused as the sort's table. */
        cell_entry *order_tv = mesh->tvertex_count <= ne_all
                                   ? by_size
                                   : rad_alloc(ctx, RAD_MEM_MESH, mesh->tvertex_count, sizeof *order_tv,
                                               "mesh: T-vertex order");
        rad_tvertex *sorted = order_tv ? rad_alloc(ctx, RAD_MEM_MESH, mesh->tvertex_count, sizeof *sorted,
                                                   "mesh: T-vertex order")
                                       : NULL;
        if (!sorted) {
            if (order_tv != by_size)
                rad_free(order_tv);
            result = RAD_ERROR_OUT_OF_MEMORY;
            goto done;
        }
        for (size_t q = 0; q < mesh->tvertex_count; q++) {
            order_tv[q].key = (uint64_t)vcoarse[mesh->tvertices[q].vertex] << 32 | mesh->tvertices[q].vertex;
            order_tv[q].item = (uint32_t)q;
        }
        qsort(order_tv, mesh->tvertex_count, sizeof *order_tv, cell_entry_cmp);
        for (size_t q = 0; q < mesh->tvertex_count; q++)
            sorted[q] = mesh->tvertices[order_tv[q].item];
        memcpy(mesh->tvertices, sorted, mesh->tvertex_count * sizeof *sorted);
        rad_free(sorted);
        if (order_tv != by_size)
            rad_free(order_tv);
    }
done:
    rad_free(by_size);
    rad_free(rank);
    rad_free(vcoarse);
    rad_free(edges);
    rad_free(order);
    rad_free(on_boundary);
    rad_free(vsurf);
    rad_free(vnormal);
    rad_free(grid);
    cell_index_free(&gix);
    return result;
}
