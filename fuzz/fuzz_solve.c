/*
 * fuzz_solve.c -- hostile geometry all the way through: polygons from the
 * bytes, then meshing, visibility, form factors and a solve by the method
 * the first byte picks, on a budget of 8 to 64 elements so that one input
 * runs in milliseconds.
 *
 * Input: byte 0 picks the method (bits 0-2) and the element budget (bits
 * 3-4); bit 5 reads coordinates as raw little-endian floats (NaN, 1e38,
 * denormals), else as signed bytes on a grid of 1/16 m scaled by 2^(byte 1
 * - 128) (millimetres to kilometres, with the same shapes).  Then polygons:
 * a byte for the corner count (3..6) and material (emitter, white, red,
 * black), and the corners.
 *
 * The contract, beyond "one-line message or a result":
 *  - every element's B is finite and at least its own E (F >= 0 and
 *    rho >= 0: every solver here but CG moves B up from E monotonically, and
 *    the direct solution of (I - rho F) B = E is >= E when the rows of rho F
 *    sum below 1);
 *  - B stays below 4 E_max / (1 - rho_max): B <= E_max / (1 - rho_max) when
 *    the rows of F sum to at most 1; 4x leaves room for the estimators'
 *    own errors, not for a blow-up;
 *  - the emitted power the solution reports is sum_i A_i E_i over its
 *    elements (the hierarchical bookkeeping once reported 0 here);
 *  - an 8 x 8 picture from the automatic camera has finite radiance >= 0
 *    at every scale the grid reaches (2^-128 to 2^127 m).
 */
#include "fuzz.h"

#include "radiosity.h"

#include <math.h>
#include <string.h>

#include "scene/scene.h"

enum { MAX_POLYGONS = 12, MAX_CORNERS = 6 };

typedef struct {
    const char *solver, *form_factors;
    int hemicube_resolution, samples;
    bool monotone; /* B >= E at every iterate */
} method;

static const method METHODS[8] = {
    {"gauss-seidel", "analytic", 0, 0, true},  {"jacobi", "hemicube", 32, 0, true},
    {"shooting", NULL, 0, 64, true},           {"hierarchical", NULL, 0, 0, true},
    {"direct", "contour", 0, 0, true},         {"conjugate-gradient", "hemisphere", 0, 64, false},
    {"southwell", "hybrid", 0, 0, true},       {"gauss-seidel", "montecarlo", 0, 16, true},
};

static const double RHO[4][3] = {{0.3, 0.3, 0.3}, {0.8, 0.8, 0.8}, {0.7, 0.1, 0.1}, {0, 0, 0}};
static const double EMISSION[4][3] = {{10, 10, 10}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};

static double read_coordinate(const uint8_t **p, const uint8_t *end, bool raw, double scale)
{
    if (raw) {
        if (end - *p < 4)
            return 0.0;
        float f;
        memcpy(&f, *p, 4);
        *p += 4;
        return f;
    }
    if (*p >= end)
        return 0.0;
    return (double)(int8_t)*(*p)++ / 16.0 * scale;
}

static rad_scene *build_scene(rad_context *ctx, const uint8_t *data, size_t size)
{
    const uint8_t *p = data + 2, *end = data + size;
    bool raw = (data[0] & 0x20) != 0;
    double scale = ldexp(1.0, (int)data[1] - 128);
    rad_scene_builder *b = rad_scene_builder_create(ctx, "fuzz");
    if (!b)
        return NULL;
    const char *names[4] = {"lamp", "white", "red", "black"};
    int materials[4], surfaces[4];
    for (int m = 0; m < 4; m++) {
        materials[m] = rad_scene_builder_material(b, names[m], RHO[m], EMISSION[m]);
        surfaces[m] = rad_scene_builder_surface(b, names[m]);
        FUZZ_CHECK(materials[m] >= 0 && surfaces[m] >= 0);
    }
    for (int k = 0; k < MAX_POLYGONS && p < end; k++) {
        uint8_t head = *p++;
        size_t corners = 3 + (head & 3u);
        int m = (head >> 2) & 3;
        vec3 v[MAX_CORNERS];
        for (size_t c = 0; c < corners; c++) {
            v[c].x = read_coordinate(&p, end, raw, scale);
            v[c].y = read_coordinate(&p, end, raw, scale);
            v[c].z = read_coordinate(&p, end, raw, scale);
        }
        if (rad_scene_builder_polygon(b, surfaces[m], materials[m], v, corners, k + 1) != RAD_OK) {
            const char *msg = rad_context_error(ctx);
            FUZZ_CHECK(msg[0] != '\0' && strchr(msg, '\n') == NULL);
            rad_scene_builder_destroy(b);
            return NULL;
        }
    }
    rad_scene *scene = NULL;
    if (rad_scene_builder_finish(b, &scene) != RAD_OK) {
        const char *msg = rad_context_error(ctx);
        FUZZ_CHECK(scene == NULL && msg[0] != '\0' && strchr(msg, '\n') == NULL);
        return NULL;
    }
    return scene;
}

static void check_solution(const rad_solution *s, const method *m)
{
    size_t n = rad_solution_element_count(s);
    FUZZ_CHECK(n > 0);
    double emitted_sum = 0.0, e_max = 0.0, rho_max = 0.0;
    for (size_t i = 0; i < n; i++) {
        double rho[3], e[3], b[3];
        FUZZ_CHECK(rad_solution_element_values(s, i, rho, e, b));
        double area = rad_solution_element_area(s, i);
        FUZZ_CHECK(isfinite(area) && area >= 0.0);
        for (int c = 0; c < 3; c++) {
            emitted_sum += area * e[c] / 3.0;
            e_max = fmax(e_max, e[c]);
            rho_max = fmax(rho_max, rho[c]);
        }
    }
    double bound = 4.0 * e_max / (1.0 - rho_max);
    for (size_t i = 0; i < n; i++) {
        double rho[3], e[3], b[3];
        rad_solution_element_values(s, i, rho, e, b);
        for (int c = 0; c < 3; c++) {
            FUZZ_CHECK(isfinite(b[c]));
            if (m->monotone)
                FUZZ_CHECK(b[c] >= e[c] * (1.0 - 1e-9) - 1e-12 * e_max);
            FUZZ_CHECK(b[c] <= bound);
        }
    }
    double emitted = NAN, absorbed = NAN;
    rad_solution_power(s, &emitted, &absorbed);
    FUZZ_CHECK(isfinite(emitted) && isfinite(absorbed) && absorbed >= 0.0);
    FUZZ_CHECK(fabs(emitted - emitted_sum) <= 1e-9 * emitted_sum);
}

/* An 8 x 8 picture from the automatic camera, which frames the scene at
 * whatever scale (a 1e18 m scene once put it where Embree aborts):
 * radiance finite and >= 0 everywhere, or a one-line refusal. */
static void check_render(rad_context *ctx, rad_solution *s)
{
    rad_render_options ro = {.width = 8, .height = 8, .samples = 1};
    rad_image *image = NULL;
    if (rad_solution_render(ctx, s, &ro, &image) != RAD_OK) {
        const char *msg = rad_context_error(ctx);
        FUZZ_CHECK(image == NULL && msg[0] != '\0' && strchr(msg, '\n') == NULL);
        return;
    }
    const float *pixels = rad_image_pixels(image);
    for (int k = 0; k < 3 * 8 * 8; k++)
        FUZZ_CHECK(isfinite(pixels[k]) && pixels[k] >= 0.0f);
    rad_image_destroy(image);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2)
        return 0;
    rad_context_options co = {.threads = 1, .max_memory_bytes = 512.0 * 1048576.0};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    const method *m = &METHODS[data[0] & 7];
    rad_scene *scene = build_scene(ctx, data, size);
    if (scene) {
        rad_options o = {.target_elements = (size_t)8 << ((data[0] >> 3) & 3),
                         .solver = m->solver,
                         .form_factors = m->form_factors,
                         .hemicube_resolution = m->hemicube_resolution,
                         .samples = m->samples,
                         .max_iterations = 200,
                         .epsilon = 1e-3,
                         .seed = 1};
        rad_solution *s = NULL;
        rad_result r = rad_solution_create(ctx, scene, &o, &s);
        if (r == RAD_OK) {
            r = rad_solution_solve(ctx, s);
            if (r == RAD_OK)
                check_solution(s, m);
            if (r == RAD_OK)
                check_render(ctx, s);
        }
        if (r != RAD_OK) {
            const char *msg = rad_context_error(ctx);
            FUZZ_CHECK(msg[0] != '\0' && strchr(msg, '\n') == NULL);
        }
        rad_solution_destroy(s);
        rad_scene_destroy(scene);
    }
    rad_context_destroy(ctx);
    return 0;
}
