/*
 * grid.h -- calculation grids and points (docs/lighting.md, "Calculation
 * grids and points"): the grid file, the points it places, and the
 * illuminance at each point computed at the point.
 *
 *   grid file (JSON)  ->  rad_grid_set: named grids of points (position,
 *                         unit normal, in-plane u, v) and free points
 *   solved view       ->  E at each point = direct (luminaires, daylight:
 *                         light.h) + what the elements' radiosities B_j
 *                         send it (exact point-to-polygon factors and
 *                         visibility): the emitters' direct light and the
 *                         interreflection
 *
 * EN 12464-1:2011 (4.4 and its grid rule, after ISO/CIE 8995): a grid's
 * spacing is p = 0.2 x 5^log10(d) m (d the longer side of the calculation
 * area, p <= 10 m), the points at the centres of cells of at most p on a
 * side, and a border band of 0.5 m from the walls left out of room areas.
 *
 * Folder order: ... strategy -> thermal -> grid -> interp -> output -> api.
 */
#ifndef RAD_GRID_H
#define RAD_GRID_H

#include "strategy/strategy.h"

/* One grid of the file, or the free points (one group, `points` true). */
typedef struct rad_grid_def {
    char *name;                 /* as the file gives it ("points" for the free points) */
    size_t first_point;         /* into rad_grid_set's point arrays */
    size_t point_count;
    uint32_t columns, rows;     /* along u and v; 0 for free points */
    double spacing_u, spacing_v;/* m, the cells' sides (0 for free points) */
    double width, height;       /* m, the calculation area's sides after the border */
    double border;              /* m */
    bool automatic;             /* spacing by EN 12464-1 */
    bool points;                /* the free points */
} rad_grid_def;

typedef struct rad_grid_set {
    char *source;               /* the file's name, for messages */
    rad_grid_def *grids;
    size_t grid_count;
    vec3 *position;             /* per point, m */
    vec3 *normal;               /* per point, unit: light from behind counts zero */
    double *u, *v;              /* per point, m: in-plane coordinates from the grid's origin
                                   (the rectangle's origin; the footprint's lower corner) */
    char **point_name;          /* per point: the free point's name, NULL for grid points */
    size_t point_count;
    int up_axis;                /* 0, 1, 2: x, y, z (default y, the generator's and glTF's) */
} rad_grid_set;

/* EN 12464-1's largest spacing for a calculation area whose longer side is
 * d m: 0.2 x 5^log10(d), at most 10 m.  d > 0. */
double rad_grid_en12464_spacing(double d);
/* The number of points along a side of `length` m at spacing at most p:
 * the smallest n >= 1 with length / n <= p. */
uint32_t rad_grid_point_count(double length, double p);

/* Parse a grid file (`name` for messages) against the scene: the set of
 * points.  Errors are RAD_ERROR_PARSE naming the file and the entry and
 * key ("g.json: grids[1].spacing: ..."); RAD_ERROR_OUT_OF_MEMORY.  *out
 * is NULL on failure and nothing leaks. */
rad_result rad_grid_parse(rad_context *ctx, const rad_scene *scene, const char *name, const char *text,
                          size_t size, rad_grid_set **out);
void rad_grid_set_destroy(rad_grid_set *set);

/* ---- the gathering's hierarchy over the elements (cluster.c) ---- */

enum { RAD_GATHER_REPS = 8 };                 /* representatives per node */
#define RAD_GATHER_LEAF UINT32_MAX            /* child[1] of a leaf; the root of an empty tree */

typedef struct rad_gather_node {
    vec3 lo, hi;                /* m: the box of its elements' corners */
    vec3 centre;                /* m: the centre of power (centroids weighted by A_j Y(B_j)) */
    vec3 axis;                  /* unit: the axis of the cone of its elements' normals */
    double spread;              /* rad: the cone's half-angle */
    double weight;              /* W: sum A_j Y(B_j) (luminance weights 0.265, 0.670, 0.065) */
    double moment[6];           /* W m^2: the weight's second moment about `centre`,
                                   xx yy zz xy xz yz (the elements' own spread included) */
    vec3 power_self[3];         /* W per channel: sum A_j E_j n_j (self-emission) */
    vec3 power_rest[3];         /* W per channel: sum A_j (B_j - E_j) n_j */
    uint32_t child[2];          /* nodes; a leaf: child[0] its element, child[1] RAD_GATHER_LEAF */
    uint32_t rep[RAD_GATHER_REPS]; /* elements whose centroids visibility rays aim at */
    int reps;
    bool emits;                 /* some element has self-emission (the direct part: never one source) */
} rad_gather_node;

typedef struct rad_gather_tree {
    rad_gather_node *nodes;
    size_t node_count;
    uint32_t root;              /* RAD_GATHER_LEAF: no element sends light */
    size_t elements;            /* leaves: the elements with some radiosity */
} rad_gather_tree;

/* The tree over the elements of `view` whose radiosity is not zero, `self`
 * (3n, W/m^2) their self-emission.  RAD_ERROR_OUT_OF_MEMORY (then *out is
 * NULL).  Deterministic: the same view gives the same tree. */
rad_result rad_gather_tree_build(rad_context *ctx, const rad_solution_view *view, const double *self,
                                 rad_gather_tree **out);
void rad_gather_tree_destroy(rad_gather_tree *tree);

/* The tree's opening criterion: a node counts as one source where its
 * bounding sphere's diameter is below THETA x its distance (bench_gather:
 * at 0.3 its error stays within the exact gathering's own spread over
 * seeds on the generated office). */
#define RAD_GRID_GATHER_THETA 0.3

/* From how many elements the default gathering walks the tree: on the
 * generated office (bench_gather, 2 threads) it is as fast as the exact
 * sum at 20,000 elements and 1.7 times faster at 40,000, and nearer the
 * many-ray reference at both (the exact path's single ray per far element
 * lets a little blocked light through); small scenes, whose tests hold the
 * exact values, keep the exact sum. */
#define RAD_GRID_GATHER_TREE_MIN 10000

/* The rays of the fan that bounds what a point sees, for the tree's walk
 * (vis.h, rad_vis_reach): their spacing, 0.16 rad, widens the box by 0.31
 * x the distance, and a line of sight through a gap narrower than about
 * 0.16 x its length can be missed (15 cm at 1 m through a door ajar: the
 * light of a slit).  1,000 rooms: the gathering from 472 s to XX s. */
#define RAD_GRID_REACH_FAN 512

/* How the elements' radiosity is gathered at a point. */
typedef enum rad_grid_gather_method {
    RAD_GRID_GATHER_AUTO = 0,   /* the default: the tree from RAD_GRID_GATHER_TREE_MIN elements,
                                   exact below (bench_gather, docs/performance.md) */
    RAD_GRID_GATHER_EXACT,      /* every element, exactly (the reference) */
    RAD_GRID_GATHER_TREE        /* far clusters as one source, near elements exactly */
} rad_grid_gather_method;

/* What the gathering counted. */
typedef struct rad_grid_gather_stats {
    uint64_t rays;              /* shadow rays cast */
    uint64_t exact_pairs;       /* point-element pairs whose visibility was exact (occluders.c) */
    uint64_t ray_pairs;         /* ... estimated by shadow rays */
    double seconds;             /* wall clock of the gathering */
    double light_seconds;       /* thread-seconds in the direct light of luminaires and daylight
                                   (rad_light_irradiance), summed over threads */
    double thread_seconds;      /* thread-seconds of all the points' work, summed over threads */
    uint64_t cluster_pairs;     /* point-cluster pairs taken as one source (the tree) */
    uint64_t cluster_rays;      /* ... the visibility rays to clusters' representatives (in `rays`) */
    bool tree;                  /* the tree gathered */
} rad_grid_gather_stats;

/* Irradiance (W/m^2 RGB, 3 per point) at every point of `set` from a
 * solved view: `direct` the luminaires' and daylight's (light.h) plus the
 * emitters' self-emission gathered; `indirect` the rest of the elements'
 * radiosity gathered.  Parallel over points (view->threads), the same
 * numbers whatever the thread count (shadow rays keyed on the seed, the
 * point and the element); progress "illuminance"; RAD_ERROR_INTERRUPTED
 * when cancelled (outputs then incomplete).  RAD_ERROR_OUT_OF_MEMORY. */
rad_result rad_grid_gather(rad_context *ctx, const rad_solution_view *view, const rad_grid_set *set,
                           rad_grid_gather_method method, double *direct, double *indirect,
                           rad_grid_gather_stats *stats);
/* The same with the tree's opening criterion `theta` (diameter over
 * distance; 0: RAD_GRID_GATHER_THETA) and, with `strata` > 0, strata x
 * strata shadow rays for every element that needs rays (0: 1, 2 or 4 by
 * its size over its distance): the references of the tests and
 * bench_gather. */
rad_result rad_grid_gather_tuned(rad_context *ctx, const rad_solution_view *view, const rad_grid_set *set,
                                 rad_grid_gather_method method, double theta, int strata, double *direct,
                                 double *indirect, rad_grid_gather_stats *stats);

/* ---- the rad_illuminance handle (illuminance.c; radiosity.h) ---- */

struct rad_illuminance {
    rad_grid_set *set;
    rad_grid_result *grids;        /* set->grid_count */
    rad_grid_point_value *values;  /* set->point_count */
    bool daylight;                 /* the scene has daylight: daylight factors are numbers */
    rad_illuminance_stats stats;
};

/* The grid file's text (`name` for messages; NULL data with size 0: an
 * empty text) parsed against view->scene and gathered from the solved view
 * with the context's threads: lux per point, each grid's statistics, the
 * daylight factors.  RAD_ERROR_INVALID_ARGUMENT when the view is not
 * solved, else as rad_grid_parse and rad_grid_gather fail; *out is NULL on
 * failure and nothing leaks.  The arguments are not NULL (the public calls
 * check them). */
rad_result rad_illuminance_from_view(rad_context *ctx, const rad_solution_view *view, const char *name,
                                     const void *data, size_t size, rad_illuminance **out);
/* The same for the file at `path`, read whole first (rad_read_whole_file). */
rad_result rad_illuminance_from_view_file(rad_context *ctx, const rad_solution_view *view, const char *path,
                                          rad_illuminance **out);

#endif /* RAD_GRID_H */
