/*
 * test_bake.c -- lightmaps of the Cornell box (output/lightmap.c,
 * rad_solution_bake): the packing (every chart and its padding inside its
 * atlas, no two overlapping), bilinear lookups anywhere in a chart reading
 * only its own filled texels, seams between patches of one surface within
 * the solution's own variation there, texel centres equal to
 * rad_solution_point_radiosity, irradiance H = (B - E)/rho; the files
 * (glTF with TEXCOORD_1 and MOZ_lightmap, HDR, RGBM PNG) read back, and the
 * Khronos validator where it is installed.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "test_support.h"

#include "api/solution.h"
#include "gltf_support.h"

#include <cjson/cJSON.h>
#include <stdio.h>

/* The Debian package's stb_image, to read the lightmaps back. */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wcast-qual"
#pragma GCC diagnostic ignored "-Wmissing-prototypes"
#pragma GCC diagnostic ignored "-Wundef"
#pragma GCC diagnostic ignored "-Wvla"
#pragma GCC diagnostic ignored "-Wunused-function"
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#define PADDING 2 /* lightmap.c's */

static rad_context *ctx;
static rad_scene *scene;
static rad_solution *solution;
static rad_lightmap *lightmap;   /* radiosity at 100 texels per metre (about 55 across a wall) */
static double *vertex_B;         /* 3 per vertex, W/m^2 */

static rad_lightmap *bake(double texels_per_metre, int atlas_size, int quantity)
{
    rad_lightmap_options o = {texels_per_metre, atlas_size, quantity};
    rad_lightmap *lm = NULL;
    rad_result r = rad_lightmap_bake(ctx, &solution->view, &o, &lm);
    if (r != RAD_OK)
        fail_msg("bake: %s", rad_context_error(ctx));
    return lm;
}

static int setup(void **state)
{
    (void)state;
    if (test_workdir_make("bake") != 0)
        return -1;
    if (rad_context_create(NULL, &ctx) != RAD_OK || rad_scene_create_cornell_box(ctx, &scene) != RAD_OK)
        return -1;
    rad_options options = {0};
    options.target_elements = 300;
    if (rad_solution_create(ctx, scene, &options, &solution) != RAD_OK || rad_solution_solve(ctx, solution) != RAD_OK)
        return -1;
    vertex_B = malloc(3 * rad_solution_vertex_count(solution) * sizeof *vertex_B);
    if (!vertex_B || rad_solution_vertex_radiosity(ctx, solution, vertex_B) != RAD_OK)
        return -1;
    rad_lightmap_options o = {100.0, 0, RAD_LIGHTMAP_RADIOSITY};
    return rad_lightmap_bake(ctx, &solution->view, &o, &lightmap) == RAD_OK ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    rad_lightmap_destroy(lightmap);
    free(vertex_B);
    rad_solution_destroy(solution);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return test_workdir_remove();
}

/* ---- packing ---- */

static bool power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

/* Every padded box inside its atlas, none overlapping another of its atlas,
 * every chart corner inside its box, every texel of a padded box owned by
 * its chart and filled; no texel outside the boxes owned. */
static void assert_packing(const rad_lightmap *lm, int atlas_size)
{
    assert_true(lm->atlas_count >= 1);
    double owned = 0.0, padded = 0.0;
    for (size_t a = 0; a < lm->atlas_count; a++) {
        const rad_atlas *atlas = &lm->atlases[a];
        assert_true(power_of_two(atlas->width) && power_of_two(atlas->height));
        assert_true(atlas->width <= atlas_size && atlas->height <= atlas_size);
        for (size_t t = 0; t < (size_t)atlas->width * (size_t)atlas->height; t++)
            if (atlas->owner[t] >= 0) {
                owned++;
                assert_int_not_equal(atlas->state[t], RAD_TEXEL_EMPTY);
            }
    }
    for (size_t i = 0; i < lm->chart_count; i++) {
        const rad_chart *c = &lm->charts[i];
        assert_int_equal(c->patch, i);
        assert_true(c->atlas < lm->atlas_count);
        const rad_atlas *atlas = &lm->atlases[c->atlas];
        assert_true(c->width >= 2 && c->height >= 2);
        assert_true(c->x - PADDING >= 0 && c->y - PADDING >= 0);
        assert_true(c->x + c->width + PADDING <= atlas->width && c->y + c->height + PADDING <= atlas->height);
        for (uint32_t k = 0; k < c->corner_count; k++) {
            assert_true(c->corner_u[k] >= -1e-9 && c->corner_u[k] <= c->width + 1e-9);
            assert_true(c->corner_v[k] >= -1e-9 && c->corner_v[k] <= c->height + 1e-9);
        }
        padded += (double)(c->width + 2 * PADDING) * (c->height + 2 * PADDING);
        for (int y = c->y - PADDING; y < c->y + c->height + PADDING; y++)
            for (int x = c->x - PADDING; x < c->x + c->width + PADDING; x++)
                assert_int_equal(atlas->owner[(size_t)y * (size_t)atlas->width + (size_t)x], (int32_t)i);
        for (size_t j = 0; j < i; j++) {
            const rad_chart *d = &lm->charts[j];
            if (d->atlas != c->atlas)
                continue;
            bool apart = c->x + c->width + PADDING <= d->x - PADDING || d->x + d->width + PADDING <= c->x - PADDING ||
                         c->y + c->height + PADDING <= d->y - PADDING || d->y + d->height + PADDING <= c->y - PADDING;
            if (!apart)
                fail_msg("charts %zu and %zu overlap with their padding", i, j);
        }
    }
    /* No texel owned twice, none outside the boxes. */
    assert_true(owned == padded);
    assert_true(lm->chart_texels <= lm->atlas_texels);
}

static void test_packing(void **state)
{
    (void)state;
    assert_int_equal(lightmap->chart_count, solution->view.mesh->patch_count);
    assert_int_equal(lightmap->atlas_count, 1);
    assert_packing(lightmap, 2048);
    /* Small atlases: several of them, each packed as well. */
    rad_lightmap *lm = bake(100.0, 128, RAD_LIGHTMAP_RADIOSITY);
    assert_true(lm->atlas_count > 1);
    assert_packing(lm, 128);
    rad_lightmap_destroy(lm);
    /* A tiny density: every chart still 2 x 2. */
    lm = bake(1e-3, 8, RAD_LIGHTMAP_RADIOSITY);
    assert_packing(lm, 8);
    rad_lightmap_destroy(lm);
}

static void test_refused(void **state)
{
    (void)state;
    rad_api_enter(ctx);
    rad_lightmap *lm = (rad_lightmap *)1;
    rad_lightmap_options o = {1e5, 2048, RAD_LIGHTMAP_RADIOSITY}; /* a wall of 55,000 texels */
    assert_int_equal(rad_lightmap_bake(ctx, &solution->view, &o, &lm), RAD_ERROR_INVALID_ARGUMENT);
    assert_null(lm);
    assert_non_null(strstr(rad_context_error(ctx), "atlas limit"));
    rad_api_enter(ctx); /* a new first error */
    o = (rad_lightmap_options){100.0, 1000, RAD_LIGHTMAP_RADIOSITY}; /* not a power of two */
    assert_int_equal(rad_lightmap_bake(ctx, &solution->view, &o, &lm), RAD_ERROR_INVALID_ARGUMENT);
    o = (rad_lightmap_options){INFINITY, 0, RAD_LIGHTMAP_RADIOSITY};
    assert_int_equal(rad_lightmap_bake(ctx, &solution->view, &o, &lm), RAD_ERROR_INVALID_ARGUMENT);
    /* Above the memory limit: the message names it. */
    rad_options limited = *solution->view.options;
    limited.max_memory_bytes = 1e5;
    rad_solution_view view = solution->view;
    view.options = &limited;
    o = (rad_lightmap_options){2000.0, 16384, RAD_LIGHTMAP_RADIOSITY};
    rad_api_enter(ctx);
    assert_int_equal(rad_lightmap_bake(ctx, &view, &o, &lm), RAD_ERROR_OUT_OF_MEMORY);
    assert_non_null(strstr(rad_context_error(ctx), "memory limit"));
    /* The public call: NULLs, a path the set does not hold, a format without
     * images. */
    rad_output_set *set;
    const char *temp;
    assert_int_equal(rad_output_set_create(ctx, &set), RAD_OK);
    assert_int_equal(rad_solution_bake(ctx, NULL, NULL, set, "a.glb", NULL), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_bake(ctx, solution, NULL, NULL, "a.glb", NULL), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_bake(ctx, solution, NULL, set, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_solution_bake(ctx, solution, NULL, set, test_path("a.glb"), NULL),
                     RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "not in the output set"));
    assert_int_equal(rad_output_set_add(ctx, set, test_path("a.ply"), RAD_OUTPUT_BAKE, &temp),
                     RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_output_set_add(ctx, set, test_path("a.ply"), RAD_OUTPUT_MESH, &temp), RAD_OK);
    assert_int_equal(rad_solution_bake(ctx, solution, NULL, set, test_path("a.ply"), NULL),
                     RAD_ERROR_INVALID_ARGUMENT);
    rad_output_set_destroy(set);
    assert_false(test_file_exists(test_path("a.ply")));
    char name[64];
    assert_int_equal(rad_bake_image_path("out/room.v2.glb", 3, "png", name, sizeof name), 25);
    assert_string_equal(name, "out/room.v2_lightmap3.png");
    assert_int_equal(rad_bake_image_path("dir.d/room", 0, "hdr", name, sizeof name), 24);
    assert_string_equal(name, "dir.d/room_lightmap0.hdr");
    assert_int_equal(rad_bake_image_path(NULL, 0, "hdr", name, sizeof name), 0);
}

/* ---- lookups ---- */

static double uniform(uint64_t *state)
{
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*state >> 11) / 9007199254740992.0;
}

static bool in_chart(const rad_chart *c, double u, double v)
{
    for (uint32_t k = 0; k < c->corner_count; k++) {
        uint32_t j = (k + 1) % c->corner_count;
        double ex = c->corner_u[j] - c->corner_u[k], ey = c->corner_v[j] - c->corner_v[k];
        if (ex * (v - c->corner_v[k]) - ey * (u - c->corner_u[k]) < -1e-9)
            return false;
    }
    return true;
}

/* A bilinear lookup at atlas texel coordinates (x, y): its four texels must
 * be in the atlas, of chart `chart`, filled; the filtered value in rgb. */
static void bilinear(const rad_lightmap *lm, uint32_t chart, double x, double y, double rgb[3])
{
    const rad_atlas *atlas = &lm->atlases[lm->charts[chart].atlas];
    int x0 = (int)floor(x - 0.5), y0 = (int)floor(y - 0.5);
    double fx = x - 0.5 - x0, fy = y - 0.5 - y0;
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    for (int dy = 0; dy < 2; dy++)
        for (int dx = 0; dx < 2; dx++) {
            int tx = x0 + dx, ty = y0 + dy;
            if (tx < 0 || ty < 0 || tx >= atlas->width || ty >= atlas->height)
                fail_msg("chart %u: lookup at (%g, %g) reads texel (%d, %d) outside the atlas", chart, x, y, tx, ty);
            size_t at = (size_t)ty * (size_t)atlas->width + (size_t)tx;
            if (atlas->owner[at] != (int32_t)chart || atlas->state[at] == RAD_TEXEL_EMPTY)
                fail_msg("chart %u: lookup at (%g, %g) reads texel (%d, %d) of chart %d, state %d", chart, x, y, tx,
                         ty, atlas->owner[at], atlas->state[at]);
            double w = (dx ? fx : 1.0 - fx) * (dy ? fy : 1.0 - fy);
            for (int c = 0; c < 3; c++)
                rgb[c] += w * atlas->texels[3 * at + (size_t)c];
        }
}

static void assert_lookups(const rad_lightmap *lm, int samples_per_atlas)
{
    uint64_t rng = 12345;
    for (size_t a = 0; a < lm->atlas_count; a++) {
        uint32_t charts[4096];
        size_t count = 0;
        for (size_t i = 0; i < lm->chart_count && count < 4096; i++)
            if (lm->charts[i].atlas == a)
                charts[count++] = (uint32_t)i;
        assert_true(count > 0);
        for (int s = 0; s < samples_per_atlas; s++) {
            const rad_chart *c = &lm->charts[charts[(size_t)(uniform(&rng) * (double)count)]];
            double u, v;
            do {
                u = uniform(&rng) * c->width, v = uniform(&rng) * c->height;
            } while (!in_chart(c, u, v));
            /* Every fourth sample on the chart's edge, where bilinear reads
             * the border and padding. */
            if (s % 4 == 0) {
                uint32_t k = (uint32_t)(uniform(&rng) * c->corner_count), j = (k + 1) % c->corner_count;
                double t = uniform(&rng);
                u = c->corner_u[k] + t * (c->corner_u[j] - c->corner_u[k]);
                v = c->corner_v[k] + t * (c->corner_v[j] - c->corner_v[k]);
            }
            double rgb[3];
            bilinear(lm, c->patch, c->x + u, c->y + v, rgb);
        }
    }
}

static void test_bilinear(void **state)
{
    (void)state;
    assert_lookups(lightmap, 4000);
    rad_lightmap *lm = bake(100.0, 128, RAD_LIGHTMAP_RADIOSITY);
    assert_lookups(lm, 2000);
    rad_lightmap_destroy(lm);
    lm = bake(7.0, 64, RAD_LIGHTMAP_RADIOSITY); /* coarse: 2-4 texels a chart */
    assert_lookups(lm, 2000);
    rad_lightmap_destroy(lm);
}

/* Every texel whose centre is in its chart holds rad_solution_point_radiosity
 * there, to float precision. */
static void test_texel_centres(void **state)
{
    (void)state;
    const rad_mesh *mesh = solution->view.mesh;
    size_t checked = 0;
    for (size_t i = 0; i < lightmap->chart_count; i++) {
        const rad_chart *c = &lightmap->charts[i];
        const rad_atlas *atlas = &lightmap->atlases[c->atlas];
        for (int y = c->y; y < c->y + c->height; y++)
            for (int x = c->x; x < c->x + c->width; x++) {
                size_t at = (size_t)y * (size_t)atlas->width + (size_t)x;
                if (atlas->state[at] != RAD_TEXEL_INSIDE)
                    continue;
                /* The patch's own point there (the measured box's quads are
                 * not quite planar: the chart is their plane). */
                double ps, pt;
                rad_patch_parameters(&mesh->patches[i], rad_chart_point(lightmap, c, x + 0.5, y + 0.5), &ps, &pt);
                /* On the patch's edge (the measured quads' non-planarity puts a
                 * few centres there) the nearest patch is ambiguous: a block's
                 * two faces meet at a crease. */
                if (!(ps > 1e-9 && pt > 1e-9 && ps < 1.0 - 1e-9 && pt < 1.0 - 1e-9))
                    continue;
                vec3 p = rad_patch_point(&mesh->patches[i], ps, pt);
                double xyz[3] = {p.x, p.y, p.z}, B[3];
                if (rad_solution_point_radiosity(ctx, solution, mesh->patches[i].surface, xyz, B) != RAD_OK)
                    fail_msg("%s", rad_context_error(ctx));
                for (int k = 0; k < 3; k++)
                    if (fabs(atlas->texels[3 * at + (size_t)k] - B[k]) > 1e-6 * B[k] + 1e-9)
                        fail_msg("chart %zu texel (%d, %d): %.9g, point radiosity %.9g", i, x, y,
                                 atlas->texels[3 * at + (size_t)k], B[k]);
                checked++;
            }
    }
    assert_true(checked > 1000);
}

/* ---- seams ---- */

/* A unit box whose floor is four quads of one surface (split at x = 0.4,
 * z = 0.6) and whose back wall is two triangles: the Cornell box's
 * surfaces are one patch each. */
static const char split_obj[] = "mtllib box.mtl\n"
                                "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                                "v 0 0 0\nv 0.4 0 0\nv 1 0 0\nv 0 0 0.6\nv 0.4 0 0.6\nv 1 0 0.6\n"
                                "v 0 0 1\nv 0.4 0 1\nv 1 0 1\n"
                                "usemtl white\n"
                                "o floor\nf 9 12 13 10\nf 10 13 14 11\nf 12 15 16 13\nf 13 16 17 14\n"
                                "o back\nf 1 2 3\nf 1 3 4\n"
                                "o front\nf 5 8 7 6\n"
                                "o left\nf 1 4 8 5\n"
                                "o right\nf 2 6 7 3\n"
                                "usemtl lamp\n"
                                "o ceiling\nf 4 3 7 8\n";
static const char split_mtl[] = "newmtl white\nKd 0.5 0.5 0.5\n"
                                "newmtl lamp\nKd 0.3 0.3 0.3\nKe 1 1 1\n";

/* For each element edge shared (by welded vertex pair) by elements of two
 * patches of one surface: bilinear lookups just inside both charts at the
 * same points along the edge agree within the solution's own variation
 * there, the spread of the two elements' vertex values. */
static void test_seams(void **state)
{
    (void)state;
    rad_scene *split;
    rad_solution *sol;
    if (rad_scene_load_memory(ctx, "split.obj", split_obj, strlen(split_obj), split_mtl, strlen(split_mtl),
                              &split) != RAD_OK)
        fail_msg("%s", rad_context_error(ctx));
    rad_options options = {0};
    options.target_elements = 400;
    assert_int_equal(rad_solution_create(ctx, split, &options, &sol), RAD_OK);
    assert_int_equal(rad_solution_solve(ctx, sol), RAD_OK);
    double *split_B = malloc(3 * rad_solution_vertex_count(sol) * sizeof *split_B);
    assert_non_null(split_B);
    assert_int_equal(rad_solution_vertex_radiosity(ctx, sol, split_B), RAD_OK);
    rad_lightmap_options o = {40.0, 0, RAD_LIGHTMAP_RADIOSITY};
    rad_lightmap *lm;
    assert_int_equal(rad_lightmap_bake(ctx, &sol->view, &o, &lm), RAD_OK);
    assert_lookups(lm, 3000);
    const rad_mesh *mesh = sol->view.mesh;
    size_t seams = 0;
    for (size_t a = 0; a < mesh->element_count; a++)
        for (size_t b = a + 1; b < mesh->element_count; b++) {
            const rad_element *ea = &mesh->elements[a], *eb = &mesh->elements[b];
            if (ea->patch == eb->patch || ea->surface != eb->surface)
                continue;
            for (uint32_t k = 0; k < ea->vertex_count; k++) {
                uint32_t v0 = ea->vertex[k], v1 = ea->vertex[(k + 1) % ea->vertex_count];
                bool shared = false;
                for (uint32_t j = 0; j < eb->vertex_count; j++)
                    if (eb->vertex[j] == v1 && eb->vertex[(j + 1) % eb->vertex_count] == v0)
                        shared = true;
                if (!shared)
                    continue;
                double spread = 0.0;
                for (int c = 0; c < 3; c++) {
                    double lo = INFINITY, hi = -INFINITY;
                    for (uint32_t j = 0; j < ea->vertex_count; j++)
                        lo = fmin(lo, split_B[3 * ea->vertex[j] + (size_t)c]),
                        hi = fmax(hi, split_B[3 * ea->vertex[j] + (size_t)c]);
                    for (uint32_t j = 0; j < eb->vertex_count; j++)
                        lo = fmin(lo, split_B[3 * eb->vertex[j] + (size_t)c]),
                        hi = fmax(hi, split_B[3 * eb->vertex[j] + (size_t)c]);
                    spread = fmax(spread, hi - lo);
                }
                const rad_chart *ca = &lm->charts[ea->patch], *cb = &lm->charts[eb->patch];
                for (int s = 1; s < 10; s++) {
                    vec3 p = v3_lerp(mesh->vertices[v0], mesh->vertices[v1], s / 10.0);
                    /* Just inside each side: a hundredth of a texel toward its element's centre. */
                    vec3 pa = v3_lerp(p, ea->centroid, 1e-2 / (lm->texels_per_metre *
                                                                v3_length(v3_sub(ea->centroid, p))));
                    vec3 pb = v3_lerp(p, eb->centroid, 1e-2 / (lm->texels_per_metre *
                                                                v3_length(v3_sub(eb->centroid, p))));
                    double xa, ya, xb, yb, A[3], B[3];
                    rad_chart_texel(lm, ca, pa, &xa, &ya);
                    rad_chart_texel(lm, cb, pb, &xb, &yb);
                    bilinear(lm, ca->patch, xa, ya, A);
                    bilinear(lm, cb->patch, xb, yb, B);
                    for (int c = 0; c < 3; c++)
                        if (fabs(A[c] - B[c]) > spread + 1e-6 * fabs(A[c]))
                            fail_msg("seam of patches %u and %u at (%g, %g, %g): %g against %g, the elements "
                                     "vary by %g", ea->patch, eb->patch, p.x, p.y, p.z, A[c], B[c], spread);
                }
                seams++;
            }
        }
    printf("# %zu element edges on seams\n", seams);
    assert_true(seams > 10);
    rad_lightmap_destroy(lm);
    free(split_B);
    rad_solution_destroy(sol);
    rad_scene_destroy(split);
}

/* ---- irradiance ---- */

static void test_irradiance(void **state)
{
    (void)state;
    rad_lightmap *lm = bake(100.0, 0, RAD_LIGHTMAP_IRRADIANCE);
    const rad_solution_view *view = &solution->view;
    size_t checked = 0, emitters = 0;
    for (size_t i = 0; i < lm->chart_count; i++) {
        const rad_chart *c = &lm->charts[i], *d = &lightmap->charts[i];
        assert_true(c->atlas == d->atlas && c->x == d->x && c->y == d->y); /* the same packing */
        const rad_atlas *H = &lm->atlases[c->atlas], *B = &lightmap->atlases[c->atlas];
        size_t e = view->mesh->patches[i].first_element; /* one material a patch */
        for (int y = c->y - PADDING; y < c->y + c->height + PADDING; y++)
            for (int x = c->x - PADDING; x < c->x + c->width + PADDING; x++) {
                size_t at = (size_t)y * (size_t)H->width + (size_t)x;
                assert_int_equal(H->state[at], B->state[at]);
                for (int k = 0; k < 3; k++) {
                    double rho = view->reflectance[3 * e + (size_t)k], E = view->emission[3 * e + (size_t)k];
                    double want = rho > 0.0 ? fmax(0.0, (B->texels[3 * at + (size_t)k] - E) / rho) : 0.0;
                    if (fabs(H->texels[3 * at + (size_t)k] - want) > 1e-5 * want + 1e-6)
                        fail_msg("chart %zu texel (%d, %d): H %.9g, (B - E)/rho %.9g", i, x, y,
                                 H->texels[3 * at + (size_t)k], want);
                    emitters += E > 0.0;
                }
                checked++;
            }
    }
    assert_true(checked > 1000 && emitters > 0);
    rad_lightmap_destroy(lm);
}

/* ---- the files ---- */




static int json_int(const cJSON *object, const char *key)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(object, key);
    assert_true(cJSON_IsNumber(item));
    return item->valueint;
}

/* Bake at 100 texels per metre into 128-texel atlases (several), through
 * an output set as the program does. */
static void bake_files(const char *glb, size_t *atlases)
{
    rad_output_set *set;
    const char *temp;
    rad_bake_options o = {100.0, 128, RAD_LIGHTMAP_RADIOSITY, 0.0};
    rad_bake_stats stats;
    assert_int_equal(rad_output_set_create(ctx, &set), RAD_OK);
    assert_int_equal(rad_output_set_add(ctx, set, glb, RAD_OUTPUT_BAKE, &temp), RAD_OK);
    assert_int_equal(rad_solution_bake(ctx, solution, &o, set, glb, &stats), RAD_OK);
    assert_false(test_file_exists(glb)); /* not before the commit */
    assert_int_equal(rad_output_set_commit(ctx, set), RAD_OK);
    rad_output_set_destroy(set);
    assert_true(stats.atlases > 1 && stats.chart_texels > 0.0 && stats.chart_texels < stats.atlas_texels);
    *atlases = stats.atlases;
}

/* The glTF: every triangle's TEXCOORD_1 in one chart of its material's
 * atlas, at the chart coordinates of its vertices' positions; the HDR and
 * the RGBM PNG of each atlas hold the lightmap's texels / pi. */
static void test_files(void **state)
{
    (void)state;
    char glb[512];
    snprintf(glb, sizeof glb, "%s", test_path("room.glb"));
    size_t atlases;
    bake_files(glb, &atlases);
    rad_lightmap *lm = bake(100.0, 128, RAD_LIGHTMAP_RADIOSITY);
    assert_int_equal(lm->atlas_count, atlases);

    size_t size;
    unsigned char *bytes = (unsigned char *)test_read_file(glb, &size);
    uint32_t json_length = support_le_u32(bytes + 12);
    cJSON *json = cJSON_ParseWithLength((const char *)bytes + 20, json_length);
    assert_non_null(json);
    const unsigned char *bin = bytes + 20 + json_length + 8;
    const cJSON *used = cJSON_GetObjectItemCaseSensitive(json, "extensionsUsed");
    bool moz = false;
    for (int k = 0; k < cJSON_GetArraySize(used); k++)
        moz = moz || strcmp(cJSON_GetArrayItem(used, k)->valuestring, "MOZ_lightmap") == 0;
    assert_true(moz);
    assert_null(cJSON_GetObjectItemCaseSensitive(json, "extensionsRequired"));
    const cJSON *images = cJSON_GetObjectItemCaseSensitive(json, "images");
    assert_int_equal(cJSON_GetArraySize(images), (int)atlases);
    for (size_t a = 0; a < atlases; a++) {
        char want[64];
        snprintf(want, sizeof want, "room_lightmap%zu.png", a);
        assert_string_equal(cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(images, (int)a), "uri")->valuestring,
                            want);
    }
    const cJSON *accessors = cJSON_GetObjectItemCaseSensitive(json, "accessors");
    const cJSON *views = cJSON_GetObjectItemCaseSensitive(json, "bufferViews");
    const cJSON *materials = cJSON_GetObjectItemCaseSensitive(json, "materials");
    const cJSON *mesh;
    size_t triangles = 0;
    cJSON_ArrayForEach(mesh, cJSON_GetObjectItemCaseSensitive(json, "meshes"))
    {
        const cJSON *prim;
        cJSON_ArrayForEach(prim, cJSON_GetObjectItemCaseSensitive(mesh, "primitives"))
        {
            const cJSON *attributes = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
            const cJSON *material = cJSON_GetArrayItem(materials, json_int(prim, "material"));
            const cJSON *moz_lightmap = cJSON_GetObjectItemCaseSensitive(
                cJSON_GetObjectItemCaseSensitive(material, "extensions"), "MOZ_lightmap");
            assert_non_null(moz_lightmap);
            assert_int_equal(json_int(moz_lightmap, "intensity"), 1);
            const cJSON *texture = cJSON_GetObjectItemCaseSensitive(moz_lightmap, "texture");
            assert_int_equal(json_int(texture, "texCoord"), 1);
            int atlas = json_int(texture, "index");
            const unsigned char *data[3];
            static const char *const names[3] = {"POSITION", "TEXCOORD_1", NULL};
            for (int k = 0; k < 3; k++) {
                const cJSON *accessor = cJSON_GetArrayItem(
                    accessors, k < 2 ? json_int(attributes, names[k]) : json_int(prim, "indices"));
                const cJSON *view = cJSON_GetArrayItem(views, json_int(accessor, "bufferView"));
                data[k] = bin + json_int(view, "byteOffset") + json_int(accessor, "byteOffset");
            }
            int count = json_int(cJSON_GetArrayItem(accessors, json_int(prim, "indices")), "count");
            for (int t = 0; t < count; t += 3) {
                double x[3], y[3];
                vec3 p[3];
                for (int k = 0; k < 3; k++) {
                    uint32_t v = support_le_u32(data[2] + 4 * (t + k));
                    p[k] = v3(support_le_f32(data[0] + 12 * v), support_le_f32(data[0] + 12 * v + 4), support_le_f32(data[0] + 12 * v + 8));
                    x[k] = support_le_f32(data[1] + 8 * v) * lm->atlases[atlas].width;
                    y[k] = support_le_f32(data[1] + 8 * v + 4) * lm->atlases[atlas].height;
                }
                /* The chart whose box holds the triangle's centre. */
                double cx = (x[0] + x[1] + x[2]) / 3, cy = (y[0] + y[1] + y[2]) / 3;
                const rad_chart *chart = NULL;
                for (size_t i = 0; i < lm->chart_count && !chart; i++) {
                    const rad_chart *c = &lm->charts[i];
                    if ((int)c->atlas == atlas && cx >= c->x && cx <= c->x + c->width && cy >= c->y &&
                        cy <= c->y + c->height)
                        chart = c;
                }
                if (!chart)
                    fail_msg("a triangle's texture coordinates (%g, %g) are in no chart of atlas %d", cx, cy, atlas);
                for (int k = 0; k < 3; k++) {
                    double wx, wy;
                    rad_chart_texel(lm, chart, p[k], &wx, &wy);
                    if (fabs(wx - x[k]) > 1e-3 || fabs(wy - y[k]) > 1e-3)
                        fail_msg("vertex (%g, %g, %g): TEXCOORD_1 at texel (%g, %g), its chart puts it at (%g, %g)",
                                 p[k].x, p[k].y, p[k].z, x[k], y[k], wx, wy);
                }
                triangles++;
            }
        }
    }
    assert_true(triangles >= rad_solution_element_count(solution));
    const cJSON *extras = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(json, "asset"), "extras"), "radiosity");
    const cJSON *info = cJSON_GetObjectItemCaseSensitive(extras, "lightmap");
    double range = cJSON_GetObjectItemCaseSensitive(info, "rgbm_range")->valuedouble;
    assert_true(range >= 1.0);
    assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(info, "hdr")), (int)atlases);

    /* The images, texel by texel. */
    for (size_t a = 0; a < atlases; a++) {
        const rad_atlas *atlas = &lm->atlases[a];
        char name[64];
        int w = 0, h = 0, n = 0;
        snprintf(name, sizeof name, "room_lightmap%zu.hdr", a);
        float *hdr = stbi_loadf(test_path(name), &w, &h, &n, 3);
        assert_non_null(hdr);
        assert_true(w == atlas->width && h == atlas->height);
        snprintf(name, sizeof name, "room_lightmap%zu.png", a);
        unsigned char *png = stbi_load(test_path(name), &w, &h, &n, 4);
        assert_non_null(png);
        assert_true(w == atlas->width && h == atlas->height && n == 4);
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
            double peak = 0.0;
            for (int c = 0; c < 3; c++)
                peak = fmax(peak, atlas->texels[3 * i + (size_t)c] / M_PI);
            for (int c = 0; c < 3; c++) {
                double L = atlas->texels[3 * i + (size_t)c] / M_PI;
                /* RGBE: 8 bits of mantissa under the largest channel. */
                if (fabs(hdr[3 * i + (size_t)c] - L) > peak / 128.0 + 1e-30)
                    fail_msg("atlas %zu texel %zu: HDR %g, lightmap %g", a, i, hdr[3 * i + (size_t)c], L);
                /* RGBM: value = rgb x a x M, rgb rounded to 1/255 of a x M. */
                double m = png[4 * i + 3] / 255.0 * range;
                double decoded = png[4 * i + (size_t)c] / 255.0 * m;
                if (fabs(decoded - L) > 0.5 / 255.0 * m + 1e-9)
                    fail_msg("atlas %zu texel %zu: RGBM %g, lightmap %g", a, i, decoded, L);
            }
        }
        stbi_image_free(hdr);
        stbi_image_free(png);
    }
    cJSON_Delete(json);
    free(bytes);
    rad_lightmap_destroy(lm);
}

/* ---- the Khronos validator, where it is installed (as test_export) ---- */

static void test_validator(void **state)
{
    (void)state;
    char glb[512], gltf[512];
    snprintf(glb, sizeof glb, "%s", test_path("valid.glb"));
    snprintf(gltf, sizeof gltf, "%s", test_path("valid room.gltf"));
    size_t atlases;
    bake_files(glb, &atlases);
    bake_files(gltf, &atlases);
    /* Its one warning: unlit and MOZ_lightmap on one material, as meant. */
    const char *paths[2] = {glb, gltf};
    support_validate_gltf(RAD_TEST_SOURCE, RAD_NPM_MODULES, paths, 2, "MULTIPLE_EXTENSIONS ",
                          test_path("report.txt"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_packing),
        cmocka_unit_test(test_refused),
        cmocka_unit_test(test_bilinear),
        cmocka_unit_test(test_texel_centres),
        cmocka_unit_test(test_seams),
        cmocka_unit_test(test_irradiance),
        cmocka_unit_test(test_files),
        cmocka_unit_test(test_validator),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
