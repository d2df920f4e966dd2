/*
 * generate.c -- seeded procedural scenes: an office floor of N rooms, for
 * benchmarks and tests that need scenes larger than a Cornell box (saved
 * as OBJ + MTL by write_obj.c).
 *
 * The floor is a grid of ceil(sqrt(N)) columns; column widths and row
 * depths are drawn between 4 and 6 m, and every wall is 10 cm thick,
 * centred on a grid line, so a wall between two rooms is two rectangles
 * back to back, 10 cm apart, each facing into its own room (see HALF_WALL
 * for why not 0 cm).  y is up; the floor is y = 0.  Seen from above (x to
 * the right, z down), 5 rooms:
 *
 *      x0        x1          x2        x3
 *   z0 +---------+-----------+---------+      ==  window (daylight pane)
 *      | room0   D  room1    D  room2  |      D   door opening
 *      |         |           |         |
 *   z1 +----D----+-----D-----+====+====+      the last row is partial:
 *      | room3   D  room4    |             room 5 would be at (2, 1)
 *   z2 +====+====+=====+=====+
 *
 * Doors: every pair of neighbours in a row; between rows, always in column
 * 0 (so every room is reachable) and elsewhere with probability 1/2.
 * Walls are cut into rectangles around their openings, so light passes
 * through doors, whose reveals (jambs, head, threshold) close the wall's
 * cavity; a window opening is filled by a weakly emitting
 * 'daylight' pane facing into the room, so the floor stays closed: no ray
 * leaves it, and emitted power = absorbed power at convergence.
 *
 * Each room holds one or two ceiling light panels (the emitting underside
 * of a closed 3 cm box hung 2 cm below the ceiling, facing down), one or two desks (a thin closed box on four box
 * legs), maybe a chair block in front of each, and one or two shelves (a
 * box frame with boards).  Furniture stands against a wall, 5 cm off it,
 * and is placed by rejection against what is already there and against
 * the swing area in front of each door, so nothing interpenetrates.
 *
 * Every random number comes from a stream keyed by (seed, what, which)
 * (rad_rng_keyed), and every coordinate is rounded to the millimetre, so a
 * seed gives the same scene bit for bit on any machine, and the OBJ writer
 * reproduces it exactly (a millimetre decimal survives the importer's
 * float).  Emitters are chosen by radiance, E = pi * Ke, for the same
 * reason.
 */
#include "scene/scene.h"

#include <stdarg.h>
#include <stdlib.h>

/* ---- parameters ---- */

enum { OFFICE_DEFAULT_ROOMS = 4, OFFICE_MAX_ROOMS = 100000 };

/* What a random stream is for: the `a` of rad_rng_keyed; `b` says which. */
enum {
    STREAM_BUILDING = 1,
    STREAM_COLUMN,
    STREAM_ROW,
    STREAM_BOUNDARY_X, /* walls x = const, between columns */
    STREAM_BOUNDARY_Z, /* walls z = const, between rows */
    STREAM_ROOM
};

/* Walls have a thickness: two faces of one wall on the same plane would tie
 * for every ray that meets them, and half the rays of a room would find the
 * back of its neighbour's face (17% of the power of 4 rooms was lost so with
 * the shooting solver).  10 cm is also far above the shadow-ray lift
 * (1e-5 x the scene diagonal, vis.c: about 2 mm at 1000 rooms). */
#define HALF_WALL 0.05     /* m, half a wall's thickness */
#define MARGIN 0.05        /* m, furniture to wall: a gap, so nothing touches a wall */
#define GAP 0.10           /* m, between pieces of furniture */
#define DOOR_CLEARANCE 1.0 /* m kept free in front of a door, into the room */
#define LIGHT_DROP 0.02    /* m, light housing below the ceiling */
#define LIGHT_DEPTH 0.03   /* m, light housing height */

/* Round to the millimetre: keeps the scene exactly representable as a
 * short decimal (see the file comment). */
static double mm(double x) { return round(x * 1000.0) / 1000.0; }
/* Round to the centimetre, for drawn sizes. */
static double cm(double x) { return round(x * 100.0) / 100.0; }

static double uniform(rad_rng *r, double lo, double hi) { return lo + (hi - lo) * rad_rng_uniform(r); }

/* ---- materials ---- */

enum {
    MAT_WALL,
    MAT_CEILING,
    MAT_FLOOR0, /* three floor coverings */
    MAT_DESK0 = MAT_FLOOR0 + 3, /* three desk tops */
    MAT_METAL = MAT_DESK0 + 3,  /* desk legs */
    MAT_SHELF,
    MAT_CHAIR0, /* three upholsteries */
    MAT_LIGHT = MAT_CHAIR0 + 3,
    MAT_HOUSING,
    MAT_THRESHOLD,
    MAT_DAYLIGHT,
    MAT_COUNT
};

/* Reflectance rho and emitted radiance Ke, W/(m^2 sr) (the builder gets
 * E = pi Ke).  A room of about 25 m^2 with one or two 0.72 m^2 panels at
 * E ~ 75 W/m^2 gets ~ 2-4 W/m^2 on its surfaces, and the daylight panes
 * (E ~ 10 W/m^2) add a tenth of that: dim, but evenly lit. */
static const struct {
    const char *name;
    double reflectance[3];
    double radiance[3];
} office_materials[MAT_COUNT] = {
    [MAT_WALL] = {"wall", {0.72, 0.70, 0.66}, {0, 0, 0}},
    [MAT_CEILING] = {"ceiling", {0.80, 0.80, 0.78}, {0, 0, 0}},
    [MAT_FLOOR0] = {"floor_grey", {0.30, 0.30, 0.30}, {0, 0, 0}},
    [MAT_FLOOR0 + 1] = {"floor_oak", {0.38, 0.28, 0.18}, {0, 0, 0}},
    [MAT_FLOOR0 + 2] = {"floor_blue", {0.20, 0.24, 0.32}, {0, 0, 0}},
    [MAT_DESK0] = {"desk_beech", {0.58, 0.45, 0.32}, {0, 0, 0}},
    [MAT_DESK0 + 1] = {"desk_white", {0.62, 0.62, 0.60}, {0, 0, 0}},
    [MAT_DESK0 + 2] = {"desk_slate", {0.40, 0.45, 0.50}, {0, 0, 0}},
    [MAT_METAL] = {"metal", {0.30, 0.30, 0.32}, {0, 0, 0}},
    [MAT_SHELF] = {"shelf", {0.50, 0.40, 0.30}, {0, 0, 0}},
    [MAT_CHAIR0] = {"chair_blue", {0.12, 0.18, 0.40}, {0, 0, 0}},
    [MAT_CHAIR0 + 1] = {"chair_red", {0.42, 0.12, 0.10}, {0, 0, 0}},
    [MAT_CHAIR0 + 2] = {"chair_black", {0.06, 0.06, 0.07}, {0, 0, 0}},
    [MAT_LIGHT] = {"light_panel", {0.80, 0.80, 0.80}, {25.0, 24.0, 21.0}},
    [MAT_HOUSING] = {"light_housing", {0.70, 0.70, 0.70}, {0, 0, 0}},
    [MAT_THRESHOLD] = {"threshold", {0.25, 0.25, 0.25}, {0, 0, 0}},
    [MAT_DAYLIGHT] = {"daylight", {0.08, 0.08, 0.08}, {3.0, 3.3, 3.8}},
};

/* ---- the generator's state ---- */

typedef struct rect {
    double x0, x1, z0, z1; /* m, a footprint on the floor */
} rect;

/* An opening in a wall, along the wall's axis (x or z) and in height. */
typedef struct opening {
    double a0, a1; /* m, along the wall */
    double y0, y1; /* m */
} opening;

enum { MAX_OPENINGS = 2 };

typedef struct boundary {
    bool door;           /* between two rooms: openings[0] is the door */
    bool exterior;       /* on the outside: the openings are windows */
    int opening_count;
    opening openings[MAX_OPENINGS];
} boundary;

typedef struct office {
    rad_context *ctx;
    rad_scene_builder *builder;
    uint64_t seed;
    int rooms, columns, rows;
    bool closed_doors;   /* a door leaf fills each door opening on both faces */
    double *x; /* columns + 1 wall lines, m */
    double *z; /* rows + 1 wall lines, m */
    double height; /* m, floor to ceiling */
    int material[MAT_COUNT];
    char name[96];
} office;

/* A room's frame: its index, floor rectangle, and what is in it so far. */
enum { MAX_OCCUPIED = 16 };

typedef struct room {
    int index, row, column;
    rect floor;
    rect occupied[MAX_OCCUPIED]; /* furniture and door clearances */
    int occupied_count;
    int lights, windows, desks, chairs, shelves;
} room;

/* ---- polygons ---- */

/* The code of the failure the builder just recorded (it keeps the message
 * in the context; without a context, out of memory is the likely cause). */
static rad_result last_error(const office *g)
{
    return g->ctx && g->ctx->last_result != RAD_OK ? g->ctx->last_result
                                                   : RAD_ERROR_OUT_OF_MEMORY;
}

/* A surface named "roomN/<what>" (printf-style); -1 on failure. */
static int surface(office *g, const room *rm, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static int surface(office *g, const room *rm, const char *fmt, ...)
{
    int n = snprintf(g->name, sizeof g->name, "room%d/", rm->index);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(g->name + n, sizeof g->name - (size_t)n, fmt, ap);
    va_end(ap);
    return rad_scene_builder_surface(g->builder, g->name);
}

/* A quadrilateral, its vertex order chosen so the normal is along `facing`. */
static rad_result quad(office *g, int surf, int mat, vec3 a, vec3 b, vec3 c, vec3 d, vec3 facing)
{
    vec3 v[4] = {a, b, c, d};
    if (v3_dot(v3_cross(v3_sub(b, a), v3_sub(c, a)), facing) < 0.0) {
        v[1] = d;
        v[3] = b;
    }
    return rad_scene_builder_polygon(g->builder, surf, mat, v, 4, 0);
}

/* A horizontal rectangle at height y facing up (+1) or down (-1). */
static rad_result horizontal(office *g, int surf, int mat, rect r, double y, double facing)
{
    return quad(g, surf, mat, v3(r.x0, y, r.z0), v3(r.x1, y, r.z0), v3(r.x1, y, r.z1),
                v3(r.x0, y, r.z1), v3(0.0, facing, 0.0));
}

/* A vertical rectangle in the plane x = c (axis 0) or z = c (axis 1),
 * spanning [a0, a1] along the other horizontal axis and [y0, y1] in
 * height, facing + or - along its axis. */
static rad_result vertical(office *g, int surf, int mat, int axis, double c, double a0,
                           double a1, double y0, double y1, double facing)
{
    if (axis == 0)
        return quad(g, surf, mat, v3(c, y0, a0), v3(c, y0, a1), v3(c, y1, a1), v3(c, y1, a0),
                    v3(facing, 0.0, 0.0));
    return quad(g, surf, mat, v3(a0, y0, c), v3(a1, y0, c), v3(a1, y1, c), v3(a0, y1, c),
                v3(0.0, 0.0, facing));
}

/* A closed axis-aligned box: six faces, normals outward. */
static rad_result box(office *g, int surf, int mat, rect r, double y0, double y1)
{
    rad_result res;
    if ((res = horizontal(g, surf, mat, r, y1, 1.0)) != RAD_OK ||
        (res = horizontal(g, surf, mat, r, y0, -1.0)) != RAD_OK ||
        (res = vertical(g, surf, mat, 0, r.x0, r.z0, r.z1, y0, y1, -1.0)) != RAD_OK ||
        (res = vertical(g, surf, mat, 0, r.x1, r.z0, r.z1, y0, y1, 1.0)) != RAD_OK ||
        (res = vertical(g, surf, mat, 1, r.z0, r.x0, r.x1, y0, y1, -1.0)) != RAD_OK)
        return res;
    return vertical(g, surf, mat, 1, r.z1, r.x0, r.x1, y0, y1, 1.0);
}

/* ---- the floor plan ---- */

static bool room_exists(const office *g, int row, int column)
{
    return row >= 0 && column >= 0 && column < g->columns &&
           (int64_t)row * g->columns + column < g->rooms;
}

/* The wall line x = x[column] in `row` (axis 0) or z = z[row] in `column`
 * (axis 1), between the rooms on either side: its door or its windows.
 * Drawn from the line's own stream, so both rooms see the same openings. */
static boundary describe_boundary(const office *g, int axis, int row, int column)
{
    boundary bd = {0};
    bool before = axis == 0 ? room_exists(g, row, column - 1) : room_exists(g, row - 1, column);
    bool after = room_exists(g, row, column);
    double a0 = axis == 0 ? g->z[row] : g->x[column];
    double a1 = axis == 0 ? g->z[row + 1] : g->x[column + 1];
    rad_rng rng = rad_rng_keyed(g->seed, axis == 0 ? STREAM_BOUNDARY_X : STREAM_BOUNDARY_Z,
                                ((uint64_t)(uint32_t)row << 32) | (uint32_t)column);
    double length = a1 - a0;
    if (before && after) {
        /* Between rows: a door in column 0 (connectivity) or by chance. */
        double chance = rad_rng_uniform(&rng);
        if (axis == 1 && column > 0 && chance < 0.5)
            return bd;
        double width = cm(uniform(&rng, 0.90, 1.00));
        /* 0.3 m of wall at least on either side of the frame. */
        double start = cm(uniform(&rng, a0 + 0.3, a1 - 0.3 - width));
        bd.door = true;
        bd.opening_count = 1;
        bd.openings[0] = (opening){mm(start), mm(start + width), 0.0, mm(fmin(2.10, g->height - 0.4))};
    } else if (before != after) {
        bd.exterior = true;
        bd.opening_count = length >= 4.8 && rad_rng_uniform(&rng) < 0.6 ? 2 : 1;
        double slot = length / bd.opening_count;
        double sill = 0.90, top = fmin(2.20, g->height - 0.4);
        for (int i = 0; i < bd.opening_count; i++) {
            /* Centred in its slot, +-0.2 m; 1.0-1.6 m wide in a slot of
             * 2.4 m or more leaves >= 0.2 m of wall on each side. */
            double width = cm(uniform(&rng, 1.0, 1.6));
            double centre = a0 + slot * (i + 0.5) + cm(uniform(&rng, -0.2, 0.2));
            bd.openings[i] = (opening){mm(centre - 0.5 * width), mm(centre + 0.5 * width),
                                       sill, mm(top)};
        }
    }
    return bd;
}

/* One side of a wall line, facing into `rm`: the wall cut into rectangles
 * around its openings (full-height strips between them, pieces above and
 * below each), plus a daylight pane in each window, and a clearance in
 * front of each door. */
static rad_result build_wall(office *g, room *rm, const char *side, int axis, int row,
                             int column, double facing)
{
    boundary bd = describe_boundary(g, axis, row, column);
    double line = axis == 0 ? g->x[column] : g->z[row];
    double c = mm(line + facing * HALF_WALL); /* this side's face of the wall */
    double a0 = axis == 0 ? rm->floor.z0 : rm->floor.x0;
    double a1 = axis == 0 ? rm->floor.z1 : rm->floor.x1;
    double h = g->height;
    int surf = surface(g, rm, "wall_%s", side);
    if (surf < 0)
        return last_error(g);
    int wall = g->material[MAT_WALL];
    rad_result r;
    double from = a0;
    for (int i = 0; i < bd.opening_count; i++) {
        const opening *o = &bd.openings[i];
        if ((r = vertical(g, surf, wall, axis, c, from, o->a0, 0.0, h, facing)) != RAD_OK)
            return r;
        if (o->y0 > 0.0 && (r = vertical(g, surf, wall, axis, c, o->a0, o->a1, 0.0, o->y0,
                                         facing)) != RAD_OK)
            return r;
        if ((r = vertical(g, surf, wall, axis, c, o->a0, o->a1, o->y1, h, facing)) != RAD_OK)
            return r;
        from = o->a1;
    }
    if ((r = vertical(g, surf, wall, axis, c, from, a1, 0.0, h, facing)) != RAD_OK)
        return r;

    for (int i = 0; i < bd.opening_count; i++) {
        const opening *o = &bd.openings[i];
        if (bd.exterior) {
            int pane = surface(g, rm, "window%d", ++rm->windows);
            if (pane < 0)
                return last_error(g);
            if ((r = vertical(g, pane, g->material[MAT_DAYLIGHT], axis, c, o->a0, o->a1, o->y0,
                              o->y1, facing)) != RAD_OK)
                return r;
            continue;
        }
        if (g->closed_doors) {
            /* A closed door: a leaf in the opening, flush with this face
             * of the wall (the far face gets its own). */
            int leaf = surface(g, rm, "door_leaf_%s", side);
            if (leaf < 0)
                return last_error(g);
            if ((r = vertical(g, leaf, wall, axis, c, o->a0, o->a1, 0.0, o->y1, facing)) != RAD_OK)
                return r;
        }
        /* The door's reveal, built once, by the room on the far side of
         * the line (facing -1 is the east or south wall of the room
         * before it): jambs, head and threshold close the wall's cavity. */
        if (facing > 0.0) {
            int reveal = surface(g, rm, "door_%s", side);
            if (reveal < 0)
                return last_error(g);
            double n0 = mm(line - HALF_WALL), n1 = c;
            rect across = axis == 0 ? (rect){n0, n1, o->a0, o->a1} : (rect){o->a0, o->a1, n0, n1};
            if ((r = vertical(g, reveal, wall, 1 - axis, o->a0, n0, n1, 0.0, o->y1, 1.0)) !=
                    RAD_OK ||
                (r = vertical(g, reveal, wall, 1 - axis, o->a1, n0, n1, 0.0, o->y1, -1.0)) !=
                    RAD_OK ||
                (r = horizontal(g, reveal, wall, across, o->y1, -1.0)) != RAD_OK ||
                (r = horizontal(g, reveal, g->material[MAT_THRESHOLD], across, 0.0, 1.0)) !=
                    RAD_OK)
                return r;
        }
        if (rm->occupied_count < MAX_OCCUPIED) {
            /* The door's swing: 0.2 m beside the frame, DOOR_CLEARANCE deep. */
            double d0 = o->a0 - 0.2, d1 = o->a1 + 0.2;
            double w0 = c, w1 = c + facing * DOOR_CLEARANCE;
            rect clear = axis == 0 ? (rect){fmin(w0, w1), fmax(w0, w1), d0, d1}
                                   : (rect){d0, d1, fmin(w0, w1), fmax(w0, w1)};
            rm->occupied[rm->occupied_count++] = clear;
        }
    }
    return RAD_OK;
}

/* ---- furniture ---- */

/* Local coordinates against one wall of a room: u along the wall from its
 * low end, w out from the wall into the room.  Sides: 0 north (z = z0),
 * 1 south (z = z1), 2 west (x = x0), 3 east (x = x1). */
static rect local_rect(const room *rm, int side, double u0, double u1, double w0, double w1)
{
    const rect *f = &rm->floor;
    rect r;
    switch (side) {
    case 0: r = (rect){f->x0 + u0, f->x0 + u1, f->z0 + w0, f->z0 + w1}; break;
    case 1: r = (rect){f->x0 + u0, f->x0 + u1, f->z1 - w1, f->z1 - w0}; break;
    case 2: r = (rect){f->x0 + w0, f->x0 + w1, f->z0 + u0, f->z0 + u1}; break;
    default: r = (rect){f->x1 - w1, f->x1 - w0, f->z0 + u0, f->z0 + u1}; break;
    }
    r.x0 = mm(r.x0);
    r.x1 = mm(r.x1);
    r.z0 = mm(r.z0);
    r.z1 = mm(r.z1);
    return r;
}

static double wall_length(const room *rm, int side)
{
    return side < 2 ? rm->floor.x1 - rm->floor.x0 : rm->floor.z1 - rm->floor.z0;
}

static bool overlaps(rect a, rect b, double gap)
{
    return a.x0 < b.x1 + gap && b.x0 < a.x1 + gap && a.z0 < b.z1 + gap && b.z0 < a.z1 + gap;
}

/* Find a place against a wall for something `length` along the wall and
 * `depth` deep (including any space kept free in front of it); 40 tries.
 * On success the whole footprint is marked occupied. */
static bool place(room *rm, rad_rng *rng, double length, double depth, int *side, double *u)
{
    if (rm->occupied_count >= MAX_OCCUPIED)
        return false;
    for (int attempt = 0; attempt < 40; attempt++) {
        int s = (int)(4.0 * rad_rng_uniform(rng));
        double span = wall_length(rm, s) - 2.0 * MARGIN - length;
        if (span <= 0.0)
            continue;
        double at = cm(MARGIN + span * rad_rng_uniform(rng));
        rect r = local_rect(rm, s, at, at + length, MARGIN, MARGIN + depth);
        bool free_here = true;
        for (int i = 0; i < rm->occupied_count && free_here; i++)
            free_here = !overlaps(r, rm->occupied[i], GAP);
        if (free_here) {
            rm->occupied[rm->occupied_count++] = r;
            *side = s;
            *u = at;
            return true;
        }
    }
    return false;
}

/* A desk: a 3 cm top on four 5 cm legs; a chair block in front of it
 * (seat 0.45 m cube, back 0.05 m thick up to 0.9 m) with probability 0.8. */
static rad_result build_desk(office *g, room *rm, rad_rng *rng)
{
    double length = cm(uniform(rng, 1.2, 1.6)), depth = cm(uniform(rng, 0.7, 0.8));
    double top = 0.75, thickness = 0.03, leg = 0.05, inset = 0.03;
    int side;
    double u;
    if (!place(rm, rng, length, depth + 0.75, &side, &u))
        return RAD_OK;
    int n = ++rm->desks;
    int top_surface = surface(g, rm, "desk%d/top", n);
    int legs_surface = top_surface < 0 ? -1 : surface(g, rm, "desk%d/legs", n);
    if (legs_surface < 0)
        return last_error(g);
    int desk = g->material[MAT_DESK0 + (int)(3.0 * rad_rng_uniform(rng))];
    rect r = local_rect(rm, side, u, u + length, MARGIN, MARGIN + depth);
    rad_result res = box(g, top_surface, desk, r, mm(top - thickness), top);
    for (int i = 0; i < 4 && res == RAD_OK; i++) {
        double x = i & 1 ? r.x1 - inset - leg : r.x0 + inset;
        double z = i & 2 ? r.z1 - inset - leg : r.z0 + inset;
        rect l = {mm(x), mm(x + leg), mm(z), mm(z + leg)};
        res = box(g, legs_surface, g->material[MAT_METAL], l, 0.0, mm(top - thickness));
    }
    if (res != RAD_OK || rad_rng_uniform(rng) >= 0.8)
        return res;

    int chair = surface(g, rm, "chair%d", ++rm->chairs);
    if (chair < 0)
        return last_error(g);
    int cloth = g->material[MAT_CHAIR0 + (int)(3.0 * rad_rng_uniform(rng))];
    double seat = 0.45, c0 = u + 0.5 * (length - seat), w0 = MARGIN + depth + 0.15;
    rect s = local_rect(rm, side, c0, c0 + seat, w0, w0 + seat);
    rect back = local_rect(rm, side, c0, c0 + seat, w0 + seat - 0.05, w0 + seat);
    if ((res = box(g, chair, cloth, s, 0.0, seat)) != RAD_OK)
        return res;
    return box(g, chair, cloth, back, seat, 0.90);
}

/* A shelf: two 2 cm side panels, top and bottom boards between them, a
 * 1 cm back panel, and 2-4 boards in between, all touching, none
 * overlapping.  0.3 m in front of it are kept free. */
static rad_result build_shelf(office *g, room *rm, rad_rng *rng)
{
    double length = cm(uniform(rng, 0.8, 1.2)), depth = cm(uniform(rng, 0.30, 0.40));
    double height = cm(uniform(rng, 1.8, 2.0)), panel = 0.02, back = 0.01;
    int boards = 2 + (int)(3.0 * rad_rng_uniform(rng));
    int side;
    double u;
    if (!place(rm, rng, length, depth + 0.3, &side, &u))
        return RAD_OK;
    int n = ++rm->shelves;
    int frame = surface(g, rm, "shelf%d/frame", n);
    int board_surface = frame < 0 ? -1 : surface(g, rm, "shelf%d/boards", n);
    if (board_surface < 0)
        return last_error(g);
    int wood = g->material[MAT_SHELF];
    double w0 = MARGIN, w1 = MARGIN + depth, u0 = u, u1 = u + length;
    double bottom = panel, ceiling = mm(height - panel);
    rad_result r;
    if ((r = box(g, frame, wood, local_rect(rm, side, u0, u0 + panel, w0, w1), 0.0, height)) !=
            RAD_OK ||
        (r = box(g, frame, wood, local_rect(rm, side, u1 - panel, u1, w0, w1), 0.0, height)) !=
            RAD_OK ||
        (r = box(g, frame, wood, local_rect(rm, side, u0 + panel, u1 - panel, w0, w1), 0.0,
                 bottom)) != RAD_OK ||
        (r = box(g, frame, wood, local_rect(rm, side, u0 + panel, u1 - panel, w0, w1), ceiling,
                 height)) != RAD_OK ||
        (r = box(g, frame, wood, local_rect(rm, side, u0 + panel, u1 - panel, w0, w0 + back),
                 bottom, ceiling)) != RAD_OK)
        return r;
    double pitch = (ceiling - bottom) / (boards + 1);
    for (int i = 1; i <= boards; i++) {
        double y = mm(bottom + pitch * i);
        r = box(g, board_surface, wood, local_rect(rm, side, u0 + panel, u1 - panel, w0 + back, w1),
                y, mm(y + panel));
        if (r != RAD_OK)
            return r;
    }
    return RAD_OK;
}

/* ---- one room ---- */

static rad_result build_room(office *g, int index)
{
    room rm = {.index = index, .row = index / g->columns, .column = index % g->columns};
    rm.floor = (rect){mm(g->x[rm.column] + HALF_WALL), mm(g->x[rm.column + 1] - HALF_WALL),
                      mm(g->z[rm.row] + HALF_WALL), mm(g->z[rm.row + 1] - HALF_WALL)};
    rad_rng rng = rad_rng_keyed(g->seed, STREAM_ROOM, (uint64_t)index);
    double h = g->height;
    rad_result r;

    int floor = surface(g, &rm, "floor");
    int ceiling = floor < 0 ? -1 : surface(g, &rm, "ceiling");
    if (ceiling < 0)
        return last_error(g);
    int covering = g->material[MAT_FLOOR0 + (int)(3.0 * rad_rng_uniform(&rng))];
    if ((r = horizontal(g, floor, covering, rm.floor, 0.0, 1.0)) != RAD_OK ||
        (r = horizontal(g, ceiling, g->material[MAT_CEILING], rm.floor, h, -1.0)) != RAD_OK)
        return r;

    /* Walls face into the room: north (z0) +z, south (z1) -z, west (x0)
     * +x, east (x1) -x. */
    if ((r = build_wall(g, &rm, "north", 1, rm.row, rm.column, 1.0)) != RAD_OK ||
        (r = build_wall(g, &rm, "south", 1, rm.row + 1, rm.column, -1.0)) != RAD_OK ||
        (r = build_wall(g, &rm, "west", 0, rm.row, rm.column, 1.0)) != RAD_OK ||
        (r = build_wall(g, &rm, "east", 0, rm.row, rm.column + 1, -1.0)) != RAD_OK)
        return r;

    /* Lights: 1.2 x 0.6 m panels along the room's longer axis, one in the
     * middle, or two at a third and two thirds. */
    double width = rm.floor.x1 - rm.floor.x0, depth = rm.floor.z1 - rm.floor.z0;
    int lights = width * depth > 24.0 || rad_rng_uniform(&rng) < 0.3 ? 2 : 1;
    bool along_x = width >= depth;
    for (int i = 0; i < lights; i++) {
        double t = lights == 1 ? 0.5 : (i + 1) / 3.0;
        double cx = rm.floor.x0 + (along_x ? t : 0.5) * width;
        double cz = rm.floor.z0 + (along_x ? 0.5 : t) * depth;
        double hx = along_x ? 0.6 : 0.3, hz = along_x ? 0.3 : 0.6;
        rect panel = {mm(cx - hx), mm(cx + hx), mm(cz - hz), mm(cz + hz)};
        int light = surface(g, &rm, "light%d", ++rm.lights);
        int housing = light < 0 ? -1 : surface(g, &rm, "light%d/housing", rm.lights);
        if (housing < 0)
            return last_error(g);
        /* A closed box: the emitting face below, a reflecting housing
         * around and above it, so no ray meets the back of an emitter. */
        double y0 = mm(h - LIGHT_DROP - LIGHT_DEPTH), y1 = mm(h - LIGHT_DROP);
        int metal = g->material[MAT_HOUSING];
        if ((r = horizontal(g, light, g->material[MAT_LIGHT], panel, y0, -1.0)) != RAD_OK ||
            (r = horizontal(g, housing, metal, panel, y1, 1.0)) != RAD_OK ||
            (r = vertical(g, housing, metal, 0, panel.x0, panel.z0, panel.z1, y0, y1, -1.0)) !=
                RAD_OK ||
            (r = vertical(g, housing, metal, 0, panel.x1, panel.z0, panel.z1, y0, y1, 1.0)) !=
                RAD_OK ||
            (r = vertical(g, housing, metal, 1, panel.z0, panel.x0, panel.x1, y0, y1, -1.0)) !=
                RAD_OK ||
            (r = vertical(g, housing, metal, 1, panel.z1, panel.x0, panel.x1, y0, y1, 1.0)) !=
                RAD_OK)
            return r;
    }

    /* Room 0 keeps the corner the camera stands in free. */
    if (index == 0)
        rm.occupied[rm.occupied_count++] =
            (rect){rm.floor.x0, rm.floor.x0 + 1.0, rm.floor.z0, rm.floor.z0 + 1.0};
    int desks = width * depth > 20.0 && rad_rng_uniform(&rng) < 0.6 ? 2 : 1;
    int shelves = rad_rng_uniform(&rng) < 0.3 ? 2 : 1;
    for (int i = 0; i < desks; i++)
        if ((r = build_desk(g, &rm, &rng)) != RAD_OK)
            return r;
    for (int i = 0; i < shelves; i++)
        if ((r = build_shelf(g, &rm, &rng)) != RAD_OK)
            return r;
    return RAD_OK;
}

/* ---- the public generator ---- */

rad_result rad_scene_generate_office(rad_context *ctx, const rad_office_options *options,
                                     rad_scene **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !out)
        return rad_null_argument(ctx, __func__);
    rad_office_options o = options ? *options : (rad_office_options){0};
    if (o.rooms == 0)
        o.rooms = OFFICE_DEFAULT_ROOMS;
    if (o.rooms < 1 || o.rooms > OFFICE_MAX_ROOMS)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "rad_office_options.rooms must be in [1, %d], got %d", OFFICE_MAX_ROOMS, o.rooms);
    double start = rad_seconds();

    office g = {.ctx = ctx, .seed = o.seed, .rooms = o.rooms, .closed_doors = o.closed_doors != 0};
    g.columns = (int)ceil(sqrt((double)o.rooms));
    while (g.columns * g.columns < o.rooms) /* sqrt rounding at exact squares */
        g.columns++;
    while (g.columns > 1 && (g.columns - 1) * (g.columns - 1) >= o.rooms)
        g.columns--;
    g.rows = (o.rooms + g.columns - 1) / g.columns;

    char source[64];
    snprintf(source, sizeof source, "office:%d:%llu", o.rooms, (unsigned long long)o.seed);
    g.x = rad_alloc(ctx, RAD_MEM_SCENE, (size_t)g.columns + 1, sizeof *g.x, "office columns");
    g.z = g.x ? rad_alloc(ctx, RAD_MEM_SCENE, (size_t)g.rows + 1, sizeof *g.z, "office rows") : NULL;
    g.builder = g.z ? rad_scene_builder_create(ctx, source) : NULL;
    rad_result r = g.builder ? RAD_OK : RAD_ERROR_OUT_OF_MEMORY;

    if (r == RAD_OK) {
        rad_rng building = rad_rng_keyed(o.seed, STREAM_BUILDING, 0);
        g.height = cm(uniform(&building, 2.8, 3.2));
        g.x[0] = g.z[0] = 0.0;
        for (int c = 0; c < g.columns; c++) {
            rad_rng rng = rad_rng_keyed(o.seed, STREAM_COLUMN, (uint64_t)c);
            g.x[c + 1] = mm(g.x[c] + cm(uniform(&rng, 4.0, 6.0)));
        }
        for (int row = 0; row < g.rows; row++) {
            rad_rng rng = rad_rng_keyed(o.seed, STREAM_ROW, (uint64_t)row);
            g.z[row + 1] = mm(g.z[row] + cm(uniform(&rng, 4.0, 6.0)));
        }
        for (int m = 0; m < MAT_COUNT && r == RAD_OK; m++) {
            double emission[3];
            for (int c = 0; c < 3; c++)
                emission[c] = M_PI * office_materials[m].radiance[c];
            g.material[m] = rad_scene_builder_material(g.builder, office_materials[m].name,
                                                       office_materials[m].reflectance, emission);
            if (g.material[m] < 0)
                r = last_error(&g);
        }
    }
    for (int i = 0; i < o.rooms && r == RAD_OK; i++) {
        if (rad_cancelled(ctx))
            r = rad_fail(ctx, RAD_ERROR_INTERRUPTED, "office: interrupted after %d of %d rooms", i,
                         o.rooms);
        else
            r = build_room(&g, i);
    }

    if (r == RAD_OK) {
        /* From the free corner of room 0 at eye height, across the room. */
        rad_camera camera = {
            .position = {g.x[0] + 0.5, 1.6, g.z[0] + 0.5},
            .look_at = {g.x[1] - 0.5, 1.0, g.z[1] - 0.5},
            .up = {0.0, 1.0, 0.0},
            .vfov_degrees = 60.0,
        };
        rad_scene_builder_camera(g.builder, &camera);
        r = rad_scene_builder_finish(g.builder, out);
        g.builder = NULL;
    }
    rad_scene_builder_destroy(g.builder);
    rad_free(g.x);
    rad_free(g.z);
    if (r == RAD_OK)
        (*out)->load_seconds = rad_seconds() - start;
    return r;
}
