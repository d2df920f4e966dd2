/*
 * fuzz_grid.c -- the illuminance command's grid file (src/grid/grid.c)
 * against the built-in Cornell box's surfaces, parsed without solving,
 * within a 64 MiB memory limit: a failure is RAD_ERROR_PARSE with a
 * one-line message naming the file (or out of memory); a success places
 * finite points with unit normals, each grid's points contiguous and in
 * range, a rectangle's count its columns x rows.
 */
#include "fuzz.h"
#include "grid/grid.h"
#include "radiosity.h"

#include <math.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 65536)
        return 0; /* a few grids; longer adds nothing */
    rad_context_options co = {.threads = 1, .max_memory_bytes = 64.0 * 1024 * 1024};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_scene *scene = NULL;
    if (rad_scene_create_cornell_box(ctx, &scene) != RAD_OK) {
        rad_context_destroy(ctx);
        return 0;
    }
    rad_grid_set *set = NULL;
    rad_result r = rad_grid_parse(ctx, scene, "g.json", (const char *)data, size, &set);
    if (r != RAD_OK) {
        const char *msg = rad_context_error(ctx);
        FUZZ_CHECK(r == RAD_ERROR_PARSE || r == RAD_ERROR_OUT_OF_MEMORY);
        FUZZ_CHECK(set == NULL);
        FUZZ_CHECK(strncmp(msg, "g.json", 6) == 0 || r == RAD_ERROR_OUT_OF_MEMORY);
        FUZZ_CHECK(strchr(msg, '\n') == NULL);
    } else {
        size_t next = 0;
        for (size_t g = 0; g < set->grid_count; g++) {
            const rad_grid_def *d = &set->grids[g];
            FUZZ_CHECK(d->first_point == next);
            FUZZ_CHECK(d->point_count > 0);
            next += d->point_count;
            FUZZ_CHECK(d->points || d->point_count <= (size_t)d->columns * d->rows);
            FUZZ_CHECK(d->points || (d->spacing_u > 0.0 && d->spacing_v > 0.0));
        }
        FUZZ_CHECK(next == set->point_count);
        for (size_t k = 0; k < set->point_count; k++) {
            FUZZ_CHECK(v3_finite(set->position[k]) && isfinite(set->u[k]) && isfinite(set->v[k]));
            FUZZ_CHECK(fabs(v3_length(set->normal[k]) - 1.0) < 1e-9);
        }
    }
    rad_grid_set_destroy(set);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
    return 0;
}
