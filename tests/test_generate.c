/*
 * test_generate.c -- the procedural office floor (src/generate/generate.c) and
 * the OBJ + MTL writer: the same seed gives the same scene bit for bit and
 * another seed another; polygons grow linearly with rooms; every polygon is
 * valid and every name unique; walls, floors, ceilings, windows and lights
 * face into their room, furniture stays inside it and pieces of furniture
 * do not overlap; interior walls are back-to-back pairs with the same
 * openings; the OBJ + MTL written reads back to the same polygons, areas,
 * reflectances and emission (E = pi Ke), atomically; and, physically, a
 * closed room absorbs the power it emits.  With the path of the
 * `radiosity` binary as argv[1], also the `generate` command.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "cli_support.h"
#include "scene/scene.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static rad_context *ctx;

/* ---- helpers ---- */

static rad_scene *office(int rooms, uint64_t seed)
{
    rad_office_options o = {.rooms = rooms, .seed = seed};
    rad_scene *scene = NULL;
    rad_result r = rad_scene_generate_office(ctx, &o, &scene);
    if (r != RAD_OK)
        print_error("rad_scene_generate_office: %s\n", rad_context_error(ctx));
    assert_int_equal(r, RAD_OK);
    assert_non_null(scene);
    return scene;
}

static const char *surface_of(const rad_scene *s, const rad_polygon *p)
{
    return s->surfaces[p->surface].name;
}

/* The room number of "roomN/...", or -1. */
static int room_of(const char *name)
{
    int room = -1, n = 0;
    if (sscanf(name, "room%d/%n", &room, &n) != 1 || n == 0)
        return -1;
    return room;
}

static vec3 centroid(const rad_scene *s, const rad_polygon *p)
{
    vec3 c = v3(0, 0, 0);
    for (uint32_t i = 0; i < p->vertex_count; i++)
        c = v3_add(c, s->positions[s->indices[p->first_index + i]]);
    return v3_scale(c, 1.0 / p->vertex_count);
}

typedef struct box3 {
    vec3 lo, hi;
} box3;

static box3 polygon_bounds(const rad_scene *s, const rad_polygon *p, box3 b)
{
    for (uint32_t i = 0; i < p->vertex_count; i++) {
        vec3 v = s->positions[s->indices[p->first_index + i]];
        b.lo = v3_min(b.lo, v);
        b.hi = v3_max(b.hi, v);
    }
    return b;
}

static box3 empty_box(void)
{
    box3 b = {v3(INFINITY, INFINITY, INFINITY), v3(-INFINITY, -INFINITY, -INFINITY)};
    return b;
}

/* Each room's interior, from its floor polygon; `rooms` entries. */
static box3 *room_boxes(const rad_scene *s, int rooms)
{
    box3 *box = malloc((size_t)rooms * sizeof *box);
    assert_non_null(box);
    for (int i = 0; i < rooms; i++)
        box[i] = empty_box();
    double height = 0.0;
    for (size_t k = 0; k < s->polygon_count; k++) {
        const rad_polygon *p = &s->polygons[k];
        const char *name = surface_of(s, p);
        int room = room_of(name);
        assert_true(room >= 0 && room < rooms);
        if (strcmp(strchr(name, '/'), "/floor") == 0)
            box[room] = polygon_bounds(s, p, box[room]);
        if (strcmp(strchr(name, '/'), "/ceiling") == 0)
            height = centroid(s, p).y;
    }
    assert_true(height > 2.5 && height < 3.5);
    for (int i = 0; i < rooms; i++) {
        assert_true(box[i].hi.x - box[i].lo.x >= 3.8 && box[i].hi.x - box[i].lo.x <= 6.0);
        assert_true(box[i].hi.z - box[i].lo.z >= 3.8 && box[i].hi.z - box[i].lo.z <= 6.0);
        box[i].hi.y = height;
    }
    return box;
}

static bool is_part(const char *name, const char *part) { return strstr(name, part) != NULL; }

static int compare_strings(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* ---- determinism and size ---- */

static void test_same_seed_same_scene(void **state)
{
    (void)state;
    rad_scene *a = office(7, 12345), *b = office(7, 12345);
    assert_int_equal(a->polygon_count, b->polygon_count);
    assert_int_equal(a->position_count, b->position_count);
    assert_int_equal(a->surface_count, b->surface_count);
    assert_int_equal(a->material_count, b->material_count);
    assert_memory_equal(a->positions, b->positions, a->position_count * sizeof *a->positions);
    assert_memory_equal(a->indices, b->indices, a->index_count * sizeof *a->indices);
    for (size_t i = 0; i < a->polygon_count; i++) {
        assert_int_equal(a->polygons[i].surface, b->polygons[i].surface);
        assert_int_equal(a->polygons[i].material, b->polygons[i].material);
    }
    for (size_t i = 0; i < a->surface_count; i++)
        assert_string_equal(a->surfaces[i].name, b->surfaces[i].name);
    for (size_t i = 0; i < a->material_count; i++)
        assert_memory_equal(&a->materials[i].reflectance, &b->materials[i].reflectance,
                            sizeof a->materials[i].reflectance);
    assert_string_equal(a->source, "office:7:12345");
    rad_camera c;
    assert_true(rad_scene_camera(a, &c));
    rad_scene_destroy(a);
    rad_scene_destroy(b);
}

static void test_different_seed_different_scene(void **state)
{
    (void)state;
    rad_scene *a = office(7, 1), *b = office(7, 2);
    bool differ = a->position_count != b->position_count ||
                  memcmp(a->positions, b->positions, a->position_count * sizeof *a->positions) != 0;
    assert_true(differ);
    /* Even the rooms' sizes differ. */
    box3 *ra = room_boxes(a, 7), *rb = room_boxes(b, 7);
    assert_true(ra[0].hi.x != rb[0].hi.x || ra[0].hi.z != rb[0].hi.z);
    free(ra);
    free(rb);
    rad_scene_destroy(a);
    rad_scene_destroy(b);
}

static void test_polygons_grow_linearly(void **state)
{
    (void)state;
    const int rooms[] = {1, 4, 16, 64};
    double per_room[4];
    for (int k = 0; k < 4; k++) {
        double sum = 0.0;
        for (uint64_t seed = 0; seed < 4; seed++) {
            rad_scene *s = office(rooms[k], seed);
            double p = (double)s->polygon_count / rooms[k];
            assert_true(p >= 80.0 && p <= 300.0);
            sum += p;
            rad_scene_destroy(s);
        }
        per_room[k] = sum / 4;
    }
    /* Polygons per room stay within 25% of the 64-room figure: linear. */
    for (int k = 0; k < 3; k++)
        assert_true(fabs(per_room[k] / per_room[3] - 1.0) < 0.25);
}

static void test_options(void **state)
{
    (void)state;
    rad_scene *s = (rad_scene *)1;
    rad_office_options o = {.rooms = -1};
    assert_int_equal(rad_scene_generate_office(ctx, &o, &s), RAD_ERROR_INVALID_ARGUMENT);
    assert_null(s);
    assert_non_null(strstr(rad_context_error(ctx), "rooms"));
    o.rooms = 100001;
    assert_int_equal(rad_scene_generate_office(ctx, &o, &s), RAD_ERROR_INVALID_ARGUMENT);
    assert_null(s);
    assert_int_equal(rad_scene_generate_office(ctx, &o, NULL), RAD_ERROR_INVALID_ARGUMENT);
    /* NULL options and rooms 0 are the default: 4 rooms, seed 0. */
    assert_int_equal(rad_scene_generate_office(ctx, NULL, &s), RAD_OK);
    assert_string_equal(s->source, "office:4:0");
    box3 *box = room_boxes(s, 4);
    free(box);
    rad_scene_destroy(s);
}

/* ---- validity ---- */

static void test_valid_polygons_and_unique_names(void **state)
{
    (void)state;
    for (uint64_t seed = 0; seed < 3; seed++) {
        rad_scene *s = office(10, seed);
        assert_true(rad_scene_has_emitter(s));
        for (size_t k = 0; k < s->polygon_count; k++) {
            const rad_polygon *p = &s->polygons[k];
            assert_int_equal(p->vertex_count, 4);
            assert_true(p->area > 1e-6);
            assert_true(fabs(v3_length(p->normal) - 1.0) < 1e-12);
            /* Axis-aligned, planar. */
            assert_true(fabs(fabs(p->normal.x) + fabs(p->normal.y) + fabs(p->normal.z) - 1.0) <
                        1e-12);
            vec3 c = centroid(s, p);
            for (uint32_t i = 0; i < 4; i++)
                assert_true(fabs(v3_dot(v3_sub(s->positions[s->indices[p->first_index + i]], c),
                                        p->normal)) < 1e-12);
        }
        for (size_t m = 0; m < s->material_count; m++)
            for (int c = 0; c < 3; c++) {
                assert_true(s->materials[m].reflectance[c] >= 0.0 &&
                            s->materials[m].reflectance[c] < 1.0);
                assert_true(s->materials[m].emission[c] >= 0.0 &&
                            s->materials[m].emission[c] < 400.0);
            }
        /* Names unique (the builder would merge repeats silently: count
         * the rooms' own parts instead). */
        const char **names = malloc(s->surface_count * sizeof *names);
        assert_non_null(names);
        for (size_t i = 0; i < s->surface_count; i++)
            names[i] = s->surfaces[i].name;
        qsort(names, s->surface_count, sizeof *names, compare_strings);
        for (size_t i = 1; i < s->surface_count; i++)
            assert_true(strcmp(names[i - 1], names[i]) != 0);
        free(names);
        /* Every room has its floor, ceiling, four walls and a light. */
        for (int room = 0; room < 10; room++) {
            const char *parts[] = {"floor", "ceiling", "wall_north", "wall_south",
                                   "wall_east", "wall_west", "light1", "desk1/top", "shelf1/frame"};
            for (size_t k = 0; k < sizeof parts / sizeof parts[0]; k++) {
                char want[64];
                snprintf(want, sizeof want, "room%d/%s", room, parts[k]);
                bool found = false;
                for (size_t i = 0; i < s->surface_count && !found; i++)
                    found = strcmp(s->surfaces[i].name, want) == 0;
                if (!found)
                    fail_msg("seed %d: no surface %s", (int)seed, want);
            }
        }
        rad_scene_destroy(s);
    }
}

/* Room shells face into their room; furniture stays strictly inside it
 * and below the lights. */
static void test_orientation_and_containment(void **state)
{
    (void)state;
    const int rooms = 10;
    for (uint64_t seed = 0; seed < 3; seed++) {
        rad_scene *s = office(rooms, seed);
        box3 *box = room_boxes(s, rooms);
        int emitters = 0;
        for (size_t k = 0; k < s->polygon_count; k++) {
            const rad_polygon *p = &s->polygons[k];
            const char *name = surface_of(s, p);
            const box3 *b = &box[room_of(name)];
            vec3 centre = v3_scale(v3_add(b->lo, b->hi), 0.5);
            vec3 c = centroid(s, p);
            if (is_part(name, "/door_"))
                continue; /* the reveal, inside the wall */
            if (is_part(name, "/wall_") || is_part(name, "/floor") || is_part(name, "/ceiling") ||
                is_part(name, "/window")) {
                if (!(v3_dot(p->normal, v3_sub(centre, c)) > 0.0))
                    fail_msg("%s faces away from its room", name);
                continue;
            }
            const double *e = s->materials[p->material].emission;
            if (e[0] > 0.0) {
                emitters++;
                assert_true(p->normal.y < -1.0 + 1e-12); /* lights face down */
            }
            box3 own = polygon_bounds(s, p, empty_box());
            if (!(own.lo.x > b->lo.x && own.hi.x < b->hi.x && own.lo.z > b->lo.z &&
                  own.hi.z < b->hi.z && own.lo.y >= 0.0 && own.hi.y < b->hi.y))
                fail_msg("%s is not inside its room", name);
        }
        assert_true(emitters >= rooms);
        free(box);
        rad_scene_destroy(s);
    }
}

/* Pieces of furniture ("roomN/desk1", "roomN/shelf2", "roomN/chair1": a
 * surface name up to its second '/') do not overlap one another. */
static void test_furniture_does_not_overlap(void **state)
{
    (void)state;
    for (uint64_t seed = 0; seed < 4; seed++) {
        rad_scene *s = office(9, seed);
        enum { MAX_PIECES = 512 };
        char piece[MAX_PIECES][48];
        box3 bounds[MAX_PIECES];
        int pieces = 0;
        for (size_t k = 0; k < s->polygon_count; k++) {
            const rad_polygon *p = &s->polygons[k];
            const char *name = surface_of(s, p);
            if (!is_part(name, "/desk") && !is_part(name, "/shelf") && !is_part(name, "/chair"))
                continue;
            char key[48];
            const char *slash = strchr(strchr(name, '/') + 1, '/');
            size_t n = slash ? (size_t)(slash - name) : strlen(name);
            snprintf(key, sizeof key, "%.*s", (int)n, name);
            int i = 0;
            while (i < pieces && strcmp(piece[i], key) != 0)
                i++;
            if (i == pieces) {
                assert_true(pieces < MAX_PIECES);
                snprintf(piece[pieces], sizeof piece[pieces], "%s", key);
                bounds[pieces++] = empty_box();
            }
            bounds[i] = polygon_bounds(s, p, bounds[i]);
        }
        assert_true(pieces >= 9 * 2);
        for (int i = 0; i < pieces; i++)
            for (int j = i + 1; j < pieces; j++) {
                const box3 *a = &bounds[i], *b = &bounds[j];
                bool overlap = a->lo.x < b->hi.x && b->lo.x < a->hi.x && a->lo.y < b->hi.y &&
                               b->lo.y < a->hi.y && a->lo.z < b->hi.z && b->lo.z < a->hi.z;
                if (overlap)
                    fail_msg("seed %d: %s and %s overlap", (int)seed, piece[i], piece[j]);
            }
        rad_scene_destroy(s);
    }
}

/* In a full 3 x 3 grid every wall polygon off the building's outline has a
 * twin in the neighbouring room: the same rectangle 10 cm behind it (the
 * wall's thickness), facing the other way, so both rooms cut the same door. */
static void test_interior_walls_are_back_to_back(void **state)
{
    (void)state;
    rad_scene *s = office(9, 77);
    int interior = 0;
    for (size_t k = 0; k < s->polygon_count; k++) {
        const rad_polygon *p = &s->polygons[k];
        if (!is_part(surface_of(s, p), "/wall_"))
            continue;
        vec3 c = centroid(s, p);
        bool outline = (p->normal.x != 0.0 && (c.x == s->bounds_min.x || c.x == s->bounds_max.x)) ||
                       (p->normal.z != 0.0 && (c.z == s->bounds_min.z || c.z == s->bounds_max.z));
        if (outline)
            continue;
        interior++;
        bool twin = false;
        for (size_t j = 0; j < s->polygon_count && !twin; j++) {
            const rad_polygon *q = &s->polygons[j];
            vec3 d = v3_add(v3_sub(centroid(s, q), c), v3_scale(p->normal, 0.1));
            twin = j != k && fabs(q->area - p->area) < 1e-12 &&
                   v3_dot(q->normal, p->normal) < -1.0 + 1e-12 && v3_dot(d, d) < 1e-18 && room_of(surface_of(s, q)) != room_of(surface_of(s, p));
        }
        if (!twin)
            fail_msg("%s: wall polygon at (%g, %g, %g) has no twin", surface_of(s, p), c.x, c.y,
                     c.z);
    }
    /* 12 walls between 9 rooms, seen from both sides; the 6 in the rows
     * and 2 in column 0 have doors, cut into 3 pieces each. */
    assert_true(interior >= 2 * (4 + 8 * 3));
    rad_scene_destroy(s);
}

/* ---- the OBJ + MTL writer ---- */

static int count_temp_files(void)
{
    DIR *d = opendir(test_workdir());
    assert_non_null(d);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strstr(e->d_name, ".tmp."))
            n++;
    closedir(d);
    return n;
}

static void test_obj_round_trip(void **state)
{
    (void)state;
    rad_scene *s = office(5, 99);
    char path[256], mtl[256];
    snprintf(path, sizeof path, "%s/office.obj", test_workdir());
    snprintf(mtl, sizeof mtl, "%s/office.mtl", test_workdir());
    assert_int_equal(rad_scene_write_obj(ctx, s, path), RAD_OK);
    assert_int_equal(access(mtl, R_OK), 0);
    assert_int_equal(count_temp_files(), 0);

    rad_scene *back = NULL;
    rad_result r = rad_scene_load_file(ctx, path, &back);
    if (r != RAD_OK)
        print_error("%s\n", rad_context_error(ctx));
    assert_int_equal(r, RAD_OK);
    assert_int_equal(back->polygon_count, s->polygon_count);
    assert_int_equal(back->surface_count, s->surface_count);
    double area = 0.0, area_back = 0.0;
    size_t exact = 0;
    for (size_t k = 0; k < s->polygon_count; k++) {
        const rad_polygon *p = &s->polygons[k], *q = &back->polygons[k];
        area += p->area;
        area_back += q->area;
        assert_string_equal(surface_of(s, p), surface_of(back, q));
        assert_int_equal(p->vertex_count, q->vertex_count);
        /* assimp parses OBJ numbers to float as float(integer part) +
         * float(fraction): 1 float ulp off for a few percent of millimetre
         * decimals (3.548 -> 3.5479999), which the importer cannot undo. */
        for (uint32_t i = 0; i < p->vertex_count; i++) {
            vec3 a = s->positions[s->indices[p->first_index + i]];
            vec3 b = back->positions[back->indices[q->first_index + i]];
            double ulp = ldexp(1.0, -23) * fmax(1.0, fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z))));
            if (!(fabs(a.x - b.x) <= ulp && fabs(a.y - b.y) <= ulp && fabs(a.z - b.z) <= ulp))
                fail_msg("%s: (%.17g, %.17g, %.17g) read back as (%.17g, %.17g, %.17g)",
                         surface_of(s, p), a.x, a.y, a.z, b.x, b.y, b.z);
            exact += a.x == b.x && a.y == b.y && a.z == b.z;
        }
        const rad_material *m = &s->materials[p->material], *n = &back->materials[q->material];
        assert_string_equal(m->name, n->name);
        for (int c = 0; c < 3; c++) {
            assert_true(fabs(n->reflectance[c] - m->reflectance[c]) <= 1e-12);
            assert_true(fabs(n->emission[c] - m->emission[c]) <= 1e-12 * m->emission[c]);
        }
    }
    assert_true(exact >= s->position_count * 9 / 10); /* most are exact */
    /* The generator's camera (in room 0) comes back from its comment, exactly. */
    assert_true(s->has_camera && back->has_camera);
    assert_memory_equal(&back->camera, &s->camera, sizeof s->camera);
    /* Those ulps move areas by ~1e-9 relative (measured 0.7e-9 to 2.6e-9). */
    assert_true(fabs(area_back - area) <= 1e-8 * area);
    for (size_t i = 0; i < s->surface_count; i++)
        assert_true(fabs(back->surfaces[i].area - s->surfaces[i].area) <=
                    1e-6 * s->surfaces[i].area);
    rad_scene_destroy(back);
    rad_scene_destroy(s);
    remove(path);
    remove(mtl);

    /* A camera comment that is not whole or not usable stays a comment. */
    static const char *const comments[] = {
        "# radiosity camera: 1 2 3  0 0 0  0 1 0  40\n",      /* kept */
        "# radiosity camera: 1 2 3  0 0 0  0 1 0\n",          /* nine numbers */
        "# radiosity camera: 1 2 3  1 2 3  0 1 0  40\n",      /* looks at itself */
        "# radiosity camera: 1 2 3  0 0 0  0 1 0  180\n",     /* no field of view */
        "# radiosity camera: 1 2 nan  0 0 0  0 1 0  40\n",    /* not finite */
        "# radiosity camera: 1 2 3  0 0 0  0 1 0  40 x\n",    /* more than ten */
    };
    for (size_t k = 0; k < sizeof comments / sizeof comments[0]; k++) {
        char text[512];
        snprintf(text, sizeof text, "%smtllib m.mtl\nusemtl lamp\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", comments[k]);
        static const char lamp[] = "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n";
        rad_scene *c = NULL;
        assert_int_equal(rad_scene_load_memory(ctx, "c.obj", text, strlen(text), lamp, strlen(lamp), &c), RAD_OK);
        assert_int_equal(c->has_camera, k == 0);
        if (k == 0)
            assert_true(c->camera.position[2] == 3.0 && c->camera.vfov_degrees == 40.0);
        rad_scene_destroy(c);
    }
}

static void test_obj_write_failure_leaves_nothing(void **state)
{
    (void)state;
    rad_scene *s = office(1, 5);
    assert_int_equal(rad_scene_write_obj(ctx, s, "/nonexistent-rad-dir/office.obj"),
                     RAD_ERROR_IO);
    assert_non_null(strstr(rad_context_error(ctx), "/nonexistent-rad-dir/office.obj"));

    /* The MTL cannot be renamed into place (a folder is in the way): no OBJ
     * either, and no temporary file. */
    char path[256], blocker[256];
    snprintf(path, sizeof path, "%s/blocked.obj", test_workdir());
    snprintf(blocker, sizeof blocker, "%s/blocked.mtl", test_workdir());
    assert_int_equal(mkdir(blocker, 0700), 0);
    assert_int_equal(rad_scene_write_obj(ctx, s, path), RAD_ERROR_IO);
    assert_int_equal(access(path, F_OK), -1);
    assert_int_equal(count_temp_files(), 0);
    rmdir(blocker);
    assert_int_equal(rad_scene_write_obj(ctx, NULL, path), RAD_ERROR_INVALID_ARGUMENT);
    rad_scene_destroy(s);
}

/* ---- physics ---- */

/* The floor plan is closed (windows are filled by daylight panes, lights
 * are closed boxes): at convergence all emitted power is absorbed. */
static void check_power_balance(int rooms)
{
    rad_scene *s = office(rooms, 3);
    rad_options o = {.solver = "shooting", .target_elements = 1500, .unshot_tolerance = 1e-4};
    rad_solution *sol = NULL;
    rad_result r = rad_solution_create(ctx, s, &o, &sol);
    if (r == RAD_OK)
        r = rad_solution_solve(ctx, sol);
    if (r != RAD_OK)
        print_error("%s\n", rad_context_error(ctx));
    assert_int_equal(r, RAD_OK);
    double emitted = 0.0, absorbed = 0.0;
    rad_solution_power(sol, &emitted, &absorbed);
    print_message("rooms %d: %zu elements, emitted %.3f W, absorbed %.3f W (%.4f)\n", rooms,
                  rad_solution_element_count(sol), emitted, absorbed, absorbed / emitted);
    /* Unshot tolerance 1e-4.  The rest (measured 0.18% for 1 room, 0.33%
     * for 4) is shot from floor under furniture: those rays start inside
     * a closed box and meet its back faces.  A leak through the walls
     * (walls of zero thickness lost 17% of 4 rooms' power) fails this. */
    assert_true(fabs(absorbed / emitted - 1.0) < 1e-2);
    rad_solution_destroy(sol);
    rad_scene_destroy(s);
}

static void test_power_balance_one_room(void **state)
{
    (void)state;
    check_power_balance(1);
}

static void test_power_balance_four_rooms(void **state)
{
    (void)state;
    check_power_balance(4);
}

/* ---- the command ---- */

static int lines(const char *text)
{
    int n = 0;
    for (; *text; text++)
        n += *text == '\n';
    return n;
}

static void test_cli_generate(void **state)
{
    (void)state;
    if (!cli_binary()) /* argv[1], or NULL: skipped */
        skip();
    char path[300];
    assert_int_equal(cli_run_here("generate office --rooms 3 --seed 11 -o cli.obj"), 0);
    snprintf(path, sizeof path, "%s/cli.obj", test_workdir());
    rad_scene *back = NULL;
    assert_int_equal(rad_scene_load_file(ctx, path, &back), RAD_OK);
    rad_scene *s = office(3, 11);
    assert_int_equal(back->polygon_count, s->polygon_count);
    rad_scene_destroy(s);
    rad_scene_destroy(back);

    const char *bad[] = {"generate house -o bad.obj",
                         "generate office --rooms 0 -o bad.obj",
                         "generate office --rooms 100001 -o bad.obj",
                         "generate office --rooms many -o bad.obj",
                         "generate office --seed -3 -o bad.obj",
                         "generate office --colour red -o bad.obj",
                         "generate"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(cli_run_here("%s", bad[i]), 2);
        if (lines(cli_stderr()) != 1)
            fail_msg("'%s': expected one line on stderr, got \"%s\"", bad[i], cli_stderr());
    }
    assert_int_equal(cli_run_here("generate office -o /nonexistent-rad-dir/x.obj"), 1);
    assert_int_equal(lines(cli_stderr()), 1);
    assert_non_null(strstr(cli_stderr(), "/nonexistent-rad-dir/x.obj"));
    snprintf(path, sizeof path, "%s/bad.obj", test_workdir());
    assert_int_equal(access(path, F_OK), -1);
    assert_int_equal(count_temp_files(), 0);
}

/* ---- setup ---- */

static int setup(void **state)
{
    (void)state;
    if (test_workdir_make("generate") != 0)
        return -1;
    rad_context_options o = {0};
    return rad_context_create(&o, &ctx) == RAD_OK ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    rad_context_destroy(ctx);
    return test_workdir_remove();
}

int main(int argc, char **argv)
{
    cli_set_binary(argc > 1 ? argv[1] : NULL);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_seed_same_scene),
        cmocka_unit_test(test_different_seed_different_scene),
        cmocka_unit_test(test_polygons_grow_linearly),
        cmocka_unit_test(test_options),
        cmocka_unit_test(test_valid_polygons_and_unique_names),
        cmocka_unit_test(test_orientation_and_containment),
        cmocka_unit_test(test_furniture_does_not_overlap),
        cmocka_unit_test(test_interior_walls_are_back_to_back),
        cmocka_unit_test(test_obj_round_trip),
        cmocka_unit_test(test_obj_write_failure_leaves_nothing),
        cmocka_unit_test(test_power_balance_one_room),
        cmocka_unit_test(test_power_balance_four_rooms),
        cmocka_unit_test(test_cli_generate),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
