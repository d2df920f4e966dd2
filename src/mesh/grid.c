/*
 * grid.c -- patches -> structured grids of elements, and point location.
 *
 * A quad patch with edges of length up to L_u (c0->c1 and c3->c2) and L_v
 * is cut into ceil(L_u/h) x ceil(L_v/h) cells at uniform parameter steps; a
 * triangle with longest edge L into k^2 cells, k = ceil(L/h).  Every
 * element edge is then at most h long.  When only a target element count
 * is given, h is found by bisection on the exact count.
 *
 * Because the grid is regular in the patch parameters, the element holding
 * a point is found in O(1) from its (s, t) (mesh.h sketches the cell
 * order); leaf meshes of hierarchical radiosity descend the patch's
 * quadtree instead.
 */
#include "mesh/mesh_internal.h"

/* ---- grid sizes ---- */

static uint32_t cells_for(double length, double h)
{
    double c = ceil(length / h - 1e-9);
    if (c < 1.0)
        c = 1.0;
    if (c > 65535.0)
        c = 65535.0;
    return (uint32_t)c;
}

static void size_patch(rad_patch *p, double h)
{
    if (p->obstruction) {
        p->nu = p->nv = 1;
        p->element_count = 1;
    } else if (p->corner_count == 4) {
        double lu = fmax(v3_length(v3_sub(p->corner[1], p->corner[0])),
                         v3_length(v3_sub(p->corner[2], p->corner[3])));
        double lv = fmax(v3_length(v3_sub(p->corner[3], p->corner[0])),
                         v3_length(v3_sub(p->corner[2], p->corner[1])));
        p->nu = cells_for(lu, h);
        p->nv = cells_for(lv, h);
        p->element_count = p->nu * p->nv;
    } else {
        double l = fmax(v3_length(v3_sub(p->corner[1], p->corner[0])),
                        fmax(v3_length(v3_sub(p->corner[2], p->corner[1])),
                             v3_length(v3_sub(p->corner[0], p->corner[2]))));
        p->nu = p->nv = cells_for(l, h);
        p->element_count = p->nu * p->nu;
    }
}

double mesh_count_elements(rad_patch *patches, size_t count, double h)
{
    double total = 0.0;
    for (size_t i = 0; i < count; i++) {
        size_patch(&patches[i], h);
        total += (double)patches[i].element_count;
    }
    return total;
}

/* The element edge length h giving about `target` elements: the count
 * falls monotonically with h, so bisect on log h. */
double mesh_size_for_target(rad_patch *patches, size_t count, double total_area, double target)
{
    double lo = sqrt(total_area / target) * 0.05, hi = sqrt(total_area / target) * 20.0;
    /* Long thin patches need h up to their length: one element each (the
     * fewest there can be) is reached at the longest patch edge. */
    for (size_t i = 0; i < count; i++)
        for (uint32_t k = 0; k < patches[i].corner_count; k++)
            hi = fmax(hi, 1.01 * v3_length(v3_sub(patches[i].corner[(k + 1) % patches[i].corner_count],
                                                  patches[i].corner[k])));
    for (int it = 0; it < 60; it++) {
        double mid = sqrt(lo * hi);
        if (mesh_count_elements(patches, count, mid) > target)
            lo = mid;
        else
            hi = mid;
    }
    /* Of the two brackets, take the count closer to the target. */
    double nlo = mesh_count_elements(patches, count, lo);
    double nhi = mesh_count_elements(patches, count, hi);
    return fabs(nlo - target) < fabs(nhi - target) ? lo : hi;
}

/* ---- grid points and elements ---- */

/* Raw (unwelded) grid-point index of the patch's local grid point. */
static uint32_t quad_point(const rad_patch *p, uint32_t base, uint32_t i, uint32_t j)
{
    return base + j * (p->nu + 1) + i;
}

static uint32_t tri_point(uint32_t k, uint32_t base, uint32_t a, uint32_t b)
{
    /* rows b = 0..k hold k+1-b points */
    return base + b * (k + 1) - b * (b - 1) / 2 + a;
}

uint32_t mesh_patch_point_count(const rad_patch *p)
{
    return p->corner_count == 4 ? (p->nu + 1) * (p->nv + 1) : (p->nu + 1) * (p->nu + 2) / 2;
}

void mesh_grid_fill(rad_mesh *mesh, raw_vertex *raw)
{
    uint32_t base = 0, first = 0;
    for (size_t pi = 0; pi < mesh->patch_count; pi++) {
        rad_patch *p = &mesh->patches[pi];
        p->first_element = first;
        if (p->corner_count == 4) {
            for (uint32_t j = 0; j <= p->nv; j++)
                for (uint32_t i = 0; i <= p->nu; i++) {
                    raw_vertex *rv = &raw[quad_point(p, base, i, j)];
                    rv->position = rad_patch_point(p, (double)i / p->nu, (double)j / p->nv);
                    rv->patch = (uint32_t)pi;
                }
            for (uint32_t j = 0; j < p->nv; j++)
                for (uint32_t i = 0; i < p->nu; i++) {
                    rad_element *e = &mesh->elements[first + j * p->nu + i];
                    e->vertex_count = 4;
                    e->vertex[0] = quad_point(p, base, i, j);
                    e->vertex[1] = quad_point(p, base, i + 1, j);
                    e->vertex[2] = quad_point(p, base, i + 1, j + 1);
                    e->vertex[3] = quad_point(p, base, i, j + 1);
                }
        } else {
            uint32_t kk = p->nu;
            for (uint32_t b = 0; b <= kk; b++)
                for (uint32_t a = 0; a + b <= kk; a++) {
                    raw_vertex *rv = &raw[tri_point(kk, base, a, b)];
                    rv->position = rad_patch_point(p, (double)a / kk, (double)b / kk);
                    rv->patch = (uint32_t)pi;
                }
            for (uint32_t b = 0; b < kk; b++) {
                uint32_t row = first + b * (2 * kk - b);
                for (uint32_t a = 0; a + b < kk; a++) {
                    rad_element *e = &mesh->elements[row + a];
                    e->vertex_count = 3;
                    e->vertex[0] = tri_point(kk, base, a, b);
                    e->vertex[1] = tri_point(kk, base, a + 1, b);
                    e->vertex[2] = tri_point(kk, base, a, b + 1);
                }
                for (uint32_t a = 0; a + b + 1 < kk; a++) {
                    rad_element *e = &mesh->elements[row + (kk - b) + a];
                    e->vertex_count = 3;
                    e->vertex[0] = tri_point(kk, base, a + 1, b);
                    e->vertex[1] = tri_point(kk, base, a + 1, b + 1);
                    e->vertex[2] = tri_point(kk, base, a, b + 1);
                }
            }
        }
        for (uint32_t k = 0; k < p->element_count; k++) {
            rad_element *e = &mesh->elements[first + k];
            e->patch = (uint32_t)pi;
            e->surface = p->surface;
            e->material = p->material;
        }
        base += mesh_patch_point_count(p);
        first += p->element_count;
    }
}

/* ---- point location ---- */

static uint32_t clamp_index(double x, uint32_t n)
{
    if (!(x > 0.0))
        return 0;
    if (x >= (double)n)
        return n - 1;
    return (uint32_t)x;
}

uint32_t rad_patch_locate(const rad_patch *p, double s, double t, double *ls, double *lt)
{
    if (p->corner_count == 4) {
        double x = s * p->nu, y = t * p->nv;
        uint32_t i = clamp_index(x, p->nu), j = clamp_index(y, p->nv);
        *ls = fmin(fmax(x - i, 0.0), 1.0);
        *lt = fmin(fmax(y - j, 0.0), 1.0);
        return p->first_element + j * p->nu + i;
    }
    uint32_t k = p->nu;
    double x = s * k, y = t * k;
    uint32_t row = clamp_index(y, k);
    double fy = fmin(fmax(y - row, 0.0), 1.0);
    uint32_t col = clamp_index(x, k - row);
    double fx = fmin(fmax(x - col, 0.0), 1.0);
    uint32_t row_start = row * (2 * k - row);
    if (fx + fy <= 1.0 || col + 1 >= k - row) {
        if (fx + fy > 1.0) { /* outside the last upward cell: project back */
            double excess = 0.5 * (fx + fy - 1.0);
            fx -= excess;
            fy -= excess;
        }
        *ls = fmax(fx, 0.0);
        *lt = fmax(fy, 0.0);
        return p->first_element + row_start + col;
    }
    /* Downward cell: v0 = (col+1, row), v1 = (col+1, row+1), v2 = (col, row+1),
     * so x = col + 1 - t and y = row + s + t. */
    *ls = fx + fy - 1.0;
    *lt = 1.0 - fx;
    return p->first_element + row_start + (k - row) + col;
}

uint32_t rad_mesh_locate(const rad_mesh *mesh, uint32_t patch, double s, double t, double *ls,
                         double *lt)
{
    const rad_patch *p = &mesh->patches[patch];
    if (!mesh->tree)
        return rad_patch_locate(p, s, t, ls, lt);
    /* Descend the quadtree with the point's coordinates relative to the
     * current node (hier/tree.c gives the children's layout). */
    double x = s, y = t;
    uint32_t entry = p->tree_root;
    for (int depth = 0; !(entry & RAD_TREE_LEAF) && depth < 64; depth++) {
        const uint32_t *child = &mesh->tree[4 * (size_t)entry];
        int c;
        if (p->corner_count == 4) {
            int i = x >= 0.5, j = y >= 0.5;
            c = j ? (i ? 2 : 3) : (i ? 1 : 0);
            x = 2.0 * x - i;
            y = 2.0 * y - j;
        } else if (x + y < 0.5) {
            c = 0, x = 2.0 * x, y = 2.0 * y;
        } else if (x >= 0.5) {
            c = 1, x = 2.0 * x - 1.0, y = 2.0 * y;
        } else if (y >= 0.5) {
            c = 2, x = 2.0 * x, y = 2.0 * y - 1.0;
        } else { /* the medial child (m01, m12, m20) */
            double lx = 2.0 * x + 2.0 * y - 1.0, ly = 1.0 - 2.0 * x;
            c = 3, x = lx, y = ly;
        }
        entry = child[c];
    }
    *ls = fmin(fmax(x, 0.0), 1.0);
    *lt = fmin(fmax(y, 0.0), 1.0);
    return entry & ~RAD_TREE_LEAF;
}
