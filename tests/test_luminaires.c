/*
 * test_luminaires.c -- luminaires placed in scenes and their direct light
 * (docs/lighting.md "Luminaires"), against closed forms:
 *
 *   point source   E = I(theta) cos(alpha) / d^2 at points of horizontal,
 *                  vertical and inclined planes, isotropic and I0 cos^k,
 *                  to 1e-9; shadows: zero behind a blocker, exact beside it
 *   area source    a Lambertian rectangle (I = I0 cos gamma, L = I0 / (w l))
 *                  seen from near: pi L F with the exact point-to-rectangle
 *                  factor, within 1 %; continuity at the five-times switch
 *   flux           a closed black box: sum A H_d x 179 = the flux x multiplier
 *   solve          a grey box lit by a luminaire: absorbed = emitted; adaptive
 *                  subdivision; the command (--luminaires, stats, errors)
 *   layout         placement (aim, aim_at, spin, arrays) by the peak's
 *                  direction; every error with its message
 *   determinism    the element means whatever the thread count
 *   cie171_*       CIE 171:2006's point- and area-source cases (docs/cie171.md)
 *
 * Distributions come from tables (rad_photometry_from_table) through a
 * loader the layout parser takes, so the tests need no photometric reader.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "cli_support.h"
#include "api/solution.h"
#include "formfactor/formfactor.h"
#include "light/light.h"
#include "photometry/layout.h"
#include "photometry/photometry.h"
#include "strategy/strategy.h"
#include "vis/vis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const double DEG = M_PI / 180.0;
#define K 179.0 /* RAD_LUMINOUS_EFFICACY */

/* ---- distributions by name ---- */

/* I0 cos^k(gamma) below the horizontal, 0 above; every degree. */
static rad_photometry *cos_power(rad_context *ctx, const char *name, double i0, double k)
{
    double gamma[181], cd[181], c = 0.0;
    for (int g = 0; g <= 180; g++) {
        gamma[g] = g;
        cd[g] = g < 90 ? i0 * pow(cos(g * DEG), k) : 0.0;
    }
    return rad_photometry_from_table(ctx, name, 1, &c, 181, gamma, cd, NULL);
}

/* A narrow lobe about (C = 0, gamma = 60): 1000 cd there, cos^40 of the
 * angle from it; C every 5 degrees, gamma every 5. */
static rad_photometry *lobe(rad_context *ctx, const char *name)
{
    enum { NC = 73, NG = 37 };
    double c[NC], g[NG], *cd = malloc(NC * NG * sizeof *cd);
    vec3 peak = v3(sin(60 * DEG), 0, -cos(60 * DEG));
    for (int i = 0; i < NC; i++)
        c[i] = 5.0 * i;
    for (int j = 0; j < NG; j++)
        g[j] = 5.0 * j;
    for (int i = 0; i < NC; i++)
        for (int j = 0; j < NG; j++) {
            vec3 d = v3(sin(g[j] * DEG) * cos(c[i] * DEG), sin(g[j] * DEG) * sin(c[i] * DEG), -cos(g[j] * DEG));
            double x = v3_dot(d, peak);
            cd[i * NG + j] = x > 0.0 ? 1000.0 * pow(x, 40) : 0.0;
        }
    rad_photometry *p = rad_photometry_from_table(ctx, name, NC, c, NG, g, cd, NULL);
    free(cd);
    return p;
}

/* The test loader: the file's last path part names the distribution. */
static rad_result test_loader(rad_context *ctx, const char *path, void *user, rad_photometry **out)
{
    (void)user;
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    rad_photometry *p = NULL;
    if (strcmp(base, "iso.ies") == 0) {
        double c = 0.0, g[2] = {0.0, 180.0}, cd[2] = {1000.0, 1000.0};
        p = rad_photometry_from_table(ctx, path, 1, &c, 2, g, cd, NULL);
    } else if (strcmp(base, "cos3.ies") == 0) {
        p = cos_power(ctx, path, 2000.0, 3.0);
    } else if (strcmp(base, "lambert.ies") == 0) { /* 0.6 m long, 0.3 m wide */
        p = cos_power(ctx, path, 1200.0, 1.0);
        if (p)
            p->length = 0.6, p->width = 0.3, p->shape = RAD_OPENING_RECTANGLE;
    } else if (strcmp(base, "disk.ies") == 0) { /* round, 0.4 m across */
        p = cos_power(ctx, path, 1200.0, 1.0);
        if (p)
            p->length = 0.4, p->width = 0.4, p->shape = RAD_OPENING_ELLIPSE;
    } else if (strcmp(base, "lobe.ies") == 0) {
        p = lobe(ctx, path);
    } else if (strcmp(base, "tilt.ies") == 0) { /* isotropic, TILT: 1 at 0 degrees, 0.5 at 90 */
        double c = 0.0, g[2] = {0.0, 180.0}, cd[2] = {1000.0, 1000.0};
        p = rad_photometry_from_table(ctx, path, 1, &c, 2, g, cd, NULL);
        if (p) {
            p->tilt_angles = rad_alloc(ctx, RAD_MEM_SCENE, 2, sizeof(double), "test: tilt");
            p->tilt_factors = rad_alloc(ctx, RAD_MEM_SCENE, 2, sizeof(double), "test: tilt");
            assert_true(p->tilt_angles && p->tilt_factors);
            p->tilt_angles[0] = 0.0, p->tilt_angles[1] = 90.0;
            p->tilt_factors[0] = 1.0, p->tilt_factors[1] = 0.5;
            p->tilt_count = 2;
        }
    } else if (strcmp(base, "dark.ies") == 0) {
        double c = 0.0, g[2] = {0.0, 180.0}, cd[2] = {0.0, 0.0};
        p = rad_photometry_from_table(ctx, path, 1, &c, 2, g, cd, NULL);
    } else {
        return rad_fail(ctx, RAD_ERROR_IO, "%s: cannot open", path);
    }
    if (!p)
        return RAD_ERROR_OUT_OF_MEMORY;
    *out = p;
    return RAD_OK;
}

static rad_result layout(rad_context *ctx, rad_scene *scene, const char *json)
{
    rad_api_enter(ctx); /* a new call: its first failure is the one kept */
    return rad_layout_parse(ctx, &scene->luminaires, "mem/layout.json", json, strlen(json), test_loader, NULL);
}

/* ---- scenes ---- */

/* A closed box [0, s]^3, faces inward, reflectance rho. */
static rad_scene *box(rad_context *ctx, double s, double rho)
{
    char obj[1024], mtl[128];
    snprintf(obj, sizeof obj,
             "mtllib box.mtl\nusemtl grey\n"
             "v 0 0 0\nv %g 0 0\nv %g %g 0\nv 0 %g 0\nv 0 0 %g\nv %g 0 %g\nv %g %g %g\nv 0 %g %g\n"
             "o floor\nf 1 2 3 4\no ceiling\nf 5 8 7 6\no west\nf 1 4 8 5\no east\nf 2 6 7 3\n"
             "o south\nf 1 5 6 2\no north\nf 4 3 7 8\n",
             s, s, s, s, s, s, s, s, s, s, s, s);
    snprintf(mtl, sizeof mtl, "newmtl grey\nKd %g %g %g\n", rho, rho, rho);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "box.obj", obj, strlen(obj), mtl, strlen(mtl), &scene), RAD_OK);
    return scene;
}

/* A floor [-5, 5]^2 at z = 0 and a 1 x 1 m plate at z = 1 over [0, 1]^2. */
static rad_scene *floor_and_plate(rad_context *ctx)
{
    const char *obj = "mtllib m.mtl\nusemtl grey\n"
                      "v -5 -5 0\nv 5 -5 0\nv 5 5 0\nv -5 5 0\n"
                      "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                      "o floor\nf 1 2 3 4\no plate\nf 5 8 7 6\n";
    const char *mtl = "newmtl grey\nKd 0.5 0.5 0.5\n";
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "floor.obj", obj, strlen(obj), mtl, strlen(mtl), &scene), RAD_OK);
    return scene;
}

/* The irradiance at p (normal n) in lux. */
static double lux_at(const rad_scene *scene, const rad_mesh *mesh, const rad_vis *vis, vec3 p, vec3 n)
{
    double h[3];
    rad_luminaires_irradiance(scene, mesh, vis, p, v3_normalize(n), h);
    assert_true(h[0] == h[1] && h[1] == h[2]); /* white */
    return K * h[0];
}

static void assert_close(double got, double want, double rel, const char *what)
{
    if (!(fabs(got - want) <= rel * fabs(want) + 1e-300)) {
        print_error("%s: got %.12g, expected %.12g (relative error %.3g, allowed %.3g)\n", what, got, want,
                    fabs(got - want) / fabs(want), rel);
        fail();
    }
}

/* ---- point sources ---- */

/* Planes through the luminaire's view: for each gamma (whole degrees, the
 * table's nodes) and C, the point where that direction meets the plane,
 * compared with I(gamma) cos(alpha) / d^2. */
static void check_planes(const char *file, double i0, double k)
{
    rad_context *ctx = test_context(1);
    rad_scene *scene = box(ctx, 1.0, 0.5); /* any scene: the luminaires are what is tested */
    char json[256];
    snprintf(json, sizeof json, "{\"luminaires\": [{\"file\": \"%s\", \"position\": [0.3, -0.2, 3]}]}", file);
    assert_int_equal(layout(ctx, scene, json), RAD_OK);
    vec3 L = v3(0.3, -0.2, 3);
    struct { vec3 point, normal; } planes[] = {
        {v3(0, 0, 0), v3(0, 0, 1)},                 /* the floor */
        {v3(2.5, 0, 0), v3(-1, 0, 0)},              /* a wall, facing the luminaire */
        {v3(0, -4, 0), v3(0, 1, 0)},                /* another */
        {v3(1, 1, 0.5), v3(-0.3, -0.4, 0.866)},     /* inclined */
    };
    int checked = 0;
    for (size_t pl = 0; pl < sizeof planes / sizeof planes[0]; pl++) {
        vec3 n = v3_normalize(planes[pl].normal);
        for (int g = 1; g < 180; g += 7)
            for (int c = 0; c < 360; c += 40) {
                vec3 d = v3(sin(g * DEG) * cos(c * DEG), sin(g * DEG) * sin(c * DEG), -cos(g * DEG));
                double denom = v3_dot(d, n);
                if (!(denom < -1e-3))
                    continue; /* parallel, or the plane's back */
                double t = v3_dot(v3_sub(planes[pl].point, L), n) / denom;
                if (!(t > 0.0) || t > 1e3)
                    continue;
                vec3 p = v3_mad(L, d, t);
                double intensity = g < 90 ? i0 * pow(cos(g * DEG), k) : (k == 0.0 ? i0 : 0.0);
                double want = intensity * (-denom) / (t * t);
                double got = lux_at(scene, NULL, NULL, p, n);
                if (want == 0.0) {
                    assert_true(got == 0.0);
                } else {
                    char what[96];
                    snprintf(what, sizeof what, "%s plane %zu gamma %d C %d", file, pl, g, c);
                    assert_close(got, want, 1e-9, what);
                }
                checked++;
            }
        /* Behind the receiver: nothing. */
        vec3 p = v3_mad(L, n, 1.0);
        assert_true(lux_at(scene, NULL, NULL, p, n) == 0.0);
    }
    assert_true(checked > 40);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

static void point_isotropic_planes(void **state)
{
    (void)state;
    check_planes("iso.ies", 1000.0, 0.0);
}

static void point_cos_power_planes(void **state)
{
    (void)state;
    check_planes("cos3.ies", 2000.0, 3.0);
}

/* A plate between the luminaire and the floor: zero in its shadow, the
 * exact value beside it. */
static void point_shadow(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    rad_scene *scene = floor_and_plate(ctx);
    assert_int_equal(layout(ctx, scene, "{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0.5, 0.5, 3]}]}"),
                     RAD_OK);
    rad_mesh *mesh = NULL;
    rad_vis *vis = NULL;
    rad_mesh_options mo = {0.5, 0, 0};
    assert_int_equal(rad_mesh_build(ctx, scene, &mo, &mesh), RAD_OK);
    assert_int_equal(rad_vis_create(ctx, "embree", mesh, &vis), RAD_OK);
    vec3 up = v3(0, 0, 1), L = v3(0.5, 0.5, 3);
    /* The plate's shadow on the floor: [-0.25, 1.25]^2 (scaled 3/2 about L). */
    vec3 behind[] = {v3(0.5, 0.5, 0), v3(-0.2, -0.2, 0), v3(1.2, 0.1, 0), v3(0.0, 1.2, 0)};
    for (size_t k = 0; k < 4; k++)
        assert_true(lux_at(scene, mesh, vis, behind[k], up) == 0.0);
    vec3 beside[] = {v3(-0.3, 0.5, 0), v3(1.3, 1.3, 0), v3(3, -2, 0), v3(0.5, -0.3, 0)};
    for (size_t k = 0; k < 4; k++) {
        vec3 d = v3_sub(L, beside[k]);
        double r = v3_length(d), want = 1000.0 * (d.z / r) / (r * r);
        assert_close(lux_at(scene, mesh, vis, beside[k], up), want, 1e-12, "beside the shadow");
        /* without shadow rays the shadowed points are lit alike */
        assert_close(lux_at(scene, mesh, NULL, behind[k], up),
                     1000.0 * (L.z / v3_length(v3_sub(L, behind[k]))) / pow(v3_length(v3_sub(L, behind[k])), 2),
                     1e-12, "without vis");
    }
    /* The scene's light (light.h) is the luminaires' here. */
    for (size_t k = 0; k < 4; k++) {
        double a[3], c[3];
        rad_light_irradiance(scene, mesh, vis, beside[k], up, a);
        rad_luminaires_irradiance(scene, mesh, vis, beside[k], up, c);
        assert_memory_equal(a, c, sizeof a);
    }
    /* A subset of the luminaires (light.h, rad_light_among): a list of the
     * one luminaire gives all the light, an empty list none; the reach
     * (light/reach.c) holds the lit point and the shadowed one (the plate
     * is no wall: the fan goes round it) and gives the same light. */
    {
        static const uint32_t one[1] = {0};
        rad_light_among listed = {one, 1, NULL}, nothing = {one, 0, NULL};
        double a[3], c[3];
        rad_light_irradiance(scene, mesh, vis, beside[1], up, a);
        rad_light_irradiance_among(scene, mesh, vis, beside[1], up, &listed, c);
        assert_memory_equal(a, c, sizeof a);
        rad_light_irradiance_among(scene, mesh, vis, beside[1], up, &nothing, c);
        assert_true(c[0] == 0.0 && c[1] == 0.0 && c[2] == 0.0);
        rad_light_reach *reach = NULL;
        assert_int_equal(rad_light_reach_build(ctx, scene, mesh, vis, 1, &reach), RAD_OK);
        /* Open scene: rays leave it, so the reach is everywhere. */
        assert_int_equal(rad_light_reach_everywhere(reach), 1);
        assert_true(rad_light_reach_holds(reach, 0, behind[0]) && rad_light_reach_holds(reach, 0, beside[0]));
        rad_light_among reached = {NULL, 0, reach};
        rad_light_irradiance_among(scene, mesh, vis, beside[1], up, &reached, c);
        assert_memory_equal(a, c, sizeof a);
        rad_light_reach_destroy(reach);
    }
    /* The plate's top is lit (its own shadow rays start off it). */
    vec3 top = v3(0.5, 0.5, 1.0);
    assert_close(lux_at(scene, mesh, vis, top, up), 1000.0 / 4.0, 1e-12, "the plate's top");
    rad_vis_destroy(vis);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* ---- area sources ---- */

/* The factor from a point to a parallel rectangle [x1, x2] x [y1, y2] at
 * height h above it (facing it), by the corner formula (Hottel; Howell's
 * catalogue C-11), odd in x and y, superposed over the four corners. */
static double corner_factor(double a, double b, double h)
{
    double A = a / h, B = b / h;
    return (A / sqrt(1 + A * A) * atan(B / sqrt(1 + A * A)) + B / sqrt(1 + B * B) * atan(A / sqrt(1 + B * B))) /
           (2.0 * M_PI);
}

static double rectangle_factor(double x1, double x2, double y1, double y2, double h)
{
    return corner_factor(x2, y2, h) - corner_factor(x1, y2, h) - corner_factor(x2, y1, h) +
           corner_factor(x1, y1, h);
}

static void area_lambertian_rectangle(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    rad_scene *scene = box(ctx, 1.0, 0.5);
    /* spin 30: the opening's length along (cos 30, sin 30, 0) */
    assert_int_equal(layout(ctx, scene, "{\"luminaires\": [{\"file\": \"lambert.ies\", \"position\": [0, 0, 2], "
                                        "\"spin\": 30}]}"),
                     RAD_OK);
    double l = 0.6, w = 0.3, L = 1200.0 / (l * w); /* cd/m^2 */
    double worst = 0.0;
    for (double h = 0.05; h < 3.0; h *= 1.3)
        for (double x = -0.8; x <= 0.8; x += 0.4)
            for (double y = -0.5; y <= 0.5; y += 0.25) {
                /* the point in the luminaire's own x-y, then turned by the spin */
                vec3 p = v3(x * cos(30 * DEG) - y * sin(30 * DEG), x * sin(30 * DEG) + y * cos(30 * DEG), 2.0 - h);
                double want = M_PI * L * rectangle_factor(-l / 2 - x, l / 2 - x, -w / 2 - y, w / 2 - y, h);
                double got = lux_at(scene, NULL, NULL, p, v3(0, 0, 1));
                if (want < 1e-3 * L)
                    continue; /* beside the opening at grazing distance: next to nothing */
                worst = fmax(worst, fabs(got - want) / want);
                assert_close(got, want, 0.01, "Lambertian rectangle");
            }
    print_message("area source: worst relative error %.3g\n", worst);
    /* Continuity at the switch (5 x 0.6 m = 3 m from the centre). */
    double below = lux_at(scene, NULL, NULL, v3(0, 0, 2.0 - 3.0 * (1 - 1e-9)), v3(0, 0, 1));
    double above = lux_at(scene, NULL, NULL, v3(0, 0, 2.0 - 3.0 * (1 + 1e-9)), v3(0, 0, 1));
    /* The jump is the point source's own error there: below 1 % (the
     * five-times rule), and the area side is the exact value. */
    double exact = M_PI * L * rectangle_factor(-l / 2, l / 2, -w / 2, w / 2, 3.0);
    print_message("at the switch: area %.9g, point %.9g, exact %.9g lux (jump %.3g)\n", below, above, exact,
                  below / above - 1);
    assert_close(below, exact, 1e-3, "the area source at five luminous sizes");
    assert_close(above, exact, 1e-2, "the point source at five luminous sizes");
    assert_close(below, above, 1e-2, "continuity at five luminous sizes");
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* A round Lambertian opening straight above: E = pi L r^2 / (r^2 + h^2). */
static void area_lambertian_disk(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    rad_scene *scene = box(ctx, 1.0, 0.5);
    assert_int_equal(layout(ctx, scene, "{\"luminaires\": [{\"file\": \"disk.ies\", \"position\": [0, 0, 2]}]}"),
                     RAD_OK);
    double r = 0.2, L = 1200.0 / (M_PI * r * r);
    for (double h = 0.02; h < 2.5; h *= 1.25) {
        double want = M_PI * L * r * r / (r * r + h * h);
        assert_close(lux_at(scene, NULL, NULL, v3(0, 0, 2.0 - h), v3(0, 0, 1)), want, 0.01, "Lambertian disk");
    }
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* ---- flux and the solve ---- */

/* The direct light landing in a closed box: all of the luminaire's flux. */
static void flux_closed_black_box(void **state)
{
    (void)state;
    rad_context *ctx = test_context(2);
    rad_scene *scene = box(ctx, 2.0, 0.0);
    assert_int_equal(layout(ctx, scene, "{\"luminaires\": [{\"file\": \"cos3.ies\", \"position\": [1, 1, 1.9], "
                                        "\"multiplier\": 2.5, \"aim\": [0.2, 0.1, -1]},"
                                        "{\"file\": \"iso.ies\", \"position\": [0.7, 1.2, 1], \"llf\": 0.8}]}"),
                     RAD_OK);
    double flux = rad_luminaire_flux(&scene->luminaires, 0) + rad_luminaire_flux(&scene->luminaires, 1);
    /* The tables' own flux: 2 pi I0 / (k + 1) for cos^k, 4 pi I0 isotropic. */
    assert_close(rad_luminaire_flux(&scene->luminaires, 1), 0.8 * 4 * M_PI * 1000.0, 1e-9, "isotropic flux");
    assert_close(rad_luminaire_flux(&scene->luminaires, 0), 2.5 * 2 * M_PI * 2000.0 / 4.0, 2e-3, "cos^3 flux");
    rad_solution *sol = NULL;
    rad_options o = {.solver = "jacobi", .target_elements = 600};
    assert_int_equal(rad_solution_create(ctx, scene, &o, &sol), RAD_OK);
    const rad_solution_view *v = &sol->view;
    assert_non_null(v->direct);
    double landing = 0.0;
    for (size_t i = 0; i < v->n; i++)
        landing += v->area[i] * v->direct[3 * i] * K;
    print_message("closed black box: %.6f lm landed of %.6f lm (%.3g)\n", landing, flux, landing / flux - 1);
    assert_close(landing, flux, 1e-3, "flux landing in a closed box");
    assert_int_equal(rad_solution_solve(ctx, sol), RAD_OK);
    double emitted, absorbed;
    rad_solution_power(sol, &emitted, &absorbed);
    assert_close(emitted * K, landing, 1e-12, "emitted = landed");
    assert_close(absorbed, emitted, 1e-9, "a black box absorbs all");
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* A grey box lit by a luminaire only: what the solve absorbs is what the
 * luminaire sends in. */
static void solve_energy_balance(void **state)
{
    (void)state;
    rad_context *ctx = test_context(2);
    rad_scene *scene = box(ctx, 2.0, 0.6);
    assert_false(rad_scene_has_emitter(scene));
    assert_int_equal(layout(ctx, scene, "{\"luminaires\": [{\"file\": \"cos3.ies\", \"position\": [1, 1, 1.8]}]}"),
                     RAD_OK);
    const char *solvers[] = {"direct", "gauss-seidel", "shooting", "galerkin-constant", "instant-radiosity"};
    for (size_t k = 0; k < sizeof solvers / sizeof solvers[0]; k++) {
        rad_solution *sol = NULL;
        rad_options o = {.solver = solvers[k], .target_elements = 300, .tolerance = 1e-10, .closure_correction = k < 2};
        assert_int_equal(rad_solution_create(ctx, scene, &o, &sol), RAD_OK);
        assert_int_equal(rad_solution_solve(ctx, sol), RAD_OK);
        double emitted, absorbed;
        rad_solution_power(sol, &emitted, &absorbed);
        print_message("%s: emitted %.9g W, absorbed %.9g W (%.3g)\n", solvers[k], emitted, absorbed,
                      absorbed / emitted - 1);
        if (k < 2)
            assert_close(absorbed, emitted, 1e-6, solvers[k]);
        /* the walls are brighter than their direct light's reflection */
        const rad_solution_view *v = &sol->view;
        for (size_t i = 0; i < v->n; i++)
            assert_true(v->radiosity[3 * i] >= v->emission[3 * i] * (1 - 1e-12));
        rad_solution_destroy(sol);
    }
    /* Adaptive subdivision follows the luminaire's light (its lit
     * elements are not emitters), and every new mesh gets its direct light. */
    rad_solution *sol = NULL;
    rad_options ad = {.solver = "gauss-seidel", .target_elements = 200, .adaptive_levels = 2,
                      .adaptive_threshold = 0.02, .tolerance = 1e-10};
    assert_int_equal(rad_solution_create(ctx, scene, &ad, &sol), RAD_OK);
    size_t before = rad_solution_element_count(sol);
    assert_int_equal(rad_solution_solve(ctx, sol), RAD_OK);
    assert_true(rad_solution_element_count(sol) > before);
    assert_non_null(sol->view.direct);
    double em, ab;
    rad_solution_power(sol, &em, &ab);
    print_message("adaptive: %zu -> %zu elements, %.6g lm landed\n", before, rad_solution_element_count(sol),
                  rad_solution_direct_lumens(sol));
    assert_close(rad_solution_direct_lumens(sol), rad_luminaire_flux(&scene->luminaires, 0), 1e-3, "adaptive: flux landed");
    /* The solution file holds the light: read back, the luminaires, the
     * direct light and the radiosity are the same bits. */
    char path[] = "/tmp/rad_test_luminaires_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(rad_solution_save(ctx, sol, path), RAD_OK);
    rad_scene *loaded_scene = NULL;
    rad_solution *loaded = NULL;
    assert_int_equal(rad_solution_load_file(ctx, path, &loaded_scene, &loaded), RAD_OK);
    unlink(path);
    assert_int_equal(rad_scene_luminaire_count(loaded_scene), 1);
    assert_string_equal(rad_scene_luminaire_name(loaded_scene, 0), rad_scene_luminaire_name(scene, 0));
    assert_true(rad_scene_luminaire_flux(loaded_scene, 0) == rad_scene_luminaire_flux(scene, 0));
    assert_int_equal(loaded->view.n, sol->view.n);
    assert_non_null(loaded->view.direct);
    assert_memory_equal(loaded->view.direct, sol->view.direct, 3 * sol->view.n * sizeof(double));
    assert_memory_equal(loaded->view.emission, sol->view.emission, 3 * sol->view.n * sizeof(double));
    assert_memory_equal(loaded->view.radiosity, sol->view.radiosity, 3 * sol->view.n * sizeof(double));
    double h0[3], h1[3];
    rad_luminaires_irradiance(scene, NULL, NULL, v3(1, 1, 0), v3(0, 0, 1), h0);
    rad_luminaires_irradiance(loaded_scene, NULL, NULL, v3(1, 1, 0), v3(0, 0, 1), h1);
    assert_memory_equal(h0, h1, sizeof h0);
    rad_solution_destroy(loaded);
    rad_scene_destroy(loaded_scene);
    rad_solution_destroy(sol);
    /* Without a solver named, the lit scene gets the default, hierarchical
     * (its nodes take the direct light: hier/direct.c); the uniform mesh's
     * own options still ask for gauss-seidel. */
    assert_int_equal(rad_solution_create(ctx, scene, NULL, &sol), RAD_OK);
    assert_string_equal(sol->options.solver, "hierarchical");
    rad_solution_destroy(sol);
    assert_int_equal(rad_solution_create(ctx, scene, &(rad_options){.target_elements = 100}, &sol), RAD_OK);
    assert_string_equal(sol->options.solver, "gauss-seidel");
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* The element means, whatever the thread count: bit for bit. */
static void direct_thread_determinism(void **state)
{
    (void)state;
    double *first = NULL;
    size_t n0 = 0;
    for (int threads = 1; threads <= 3; threads++) {
        rad_context *ctx = test_context(threads);
        rad_scene *scene = floor_and_plate(ctx);
        assert_int_equal(layout(ctx, scene, "{\"luminaires\": [{\"file\": \"lambert.ies\", \"position\": [0.4, 0.6, "
                                            "1.3]}, {\"file\": \"cos3.ies\", \"position\": [-2, 1, 2.5]}]}"),
                         RAD_OK);
        rad_solution *sol = NULL;
        rad_options o = {.solver = "jacobi", .target_elements = 400};
        assert_int_equal(rad_solution_create(ctx, scene, &o, &sol), RAD_OK);
        const rad_solution_view *v = &sol->view;
        if (!first) {
            n0 = v->n;
            first = malloc(3 * n0 * sizeof *first);
            memcpy(first, v->direct, 3 * n0 * sizeof *first);
        } else {
            assert_int_equal(v->n, n0);
            assert_memory_equal(first, v->direct, 3 * n0 * sizeof *first);
        }
        rad_solution_destroy(sol);
        rad_scene_destroy(scene);
        rad_context_destroy(ctx);
    }
    free(first);
}

/* ---- layouts ---- */

/* The irradiance at distance 2 along world direction d, facing back: the
 * lobe's 1000 cd where d is its peak. */
static double lobe_lux(const rad_scene *scene, size_t k, vec3 d)
{
    rad_scene alone = *scene; /* luminaire k only: the others' lobes reach its points too */
    alone.luminaires.items = &scene->luminaires.items[k];
    alone.luminaires.count = 1;
    vec3 p = v3_mad(scene->luminaires.items[k].position, v3_normalize(d), 2.0);
    return lux_at(&alone, NULL, NULL, p, v3_scale(d, -1.0));
}

static void layout_placement(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    rad_scene *scene = box(ctx, 1.0, 0.5);
    assert_int_equal(layout(ctx, scene,
                            "{\"luminaires\": ["
                            "{\"file\": \"lobe.ies\", \"position\": [0, 0, 10], \"name\": \"plain\"},"
                            "{\"file\": \"lobe.ies\", \"position\": [20, 0, 10], \"spin\": 90, \"name\": \"spun\"},"
                            "{\"file\": \"lobe.ies\", \"position\": [40, 0, 10], \"aim\": [1, 0, 0], \"name\": \"aimed\"},"
                            "{\"file\": \"lobe.ies\", \"position\": [60, 0, 10], \"aim_at\": [60, 0, 20], \"name\": \"up\"},"
                            "{\"file\": \"lobe.ies\", \"position\": [80, 0, 10], \"spin\": 90, \"name\": \"row\","
                            " \"array\": {\"count\": [3, 2], \"spacing\": [1, 2]}}]}"),
                     RAD_OK);
    assert_int_equal(scene->luminaires.count, 4 + 6);
    assert_int_equal(scene->luminaires.photometry_count, 1); /* one file, loaded once */
    double s60 = sin(60 * DEG), c60 = 0.5, peak = 1000.0 / 4.0;
    /* plain: C = 0 along +x, the nadir -z */
    assert_close(lobe_lux(scene, 0, v3(s60, 0, -c60)), peak, 1e-9, "plain peak");
    assert_true(lobe_lux(scene, 0, v3(0, s60, -c60)) < 1e-3 * peak);
    /* spin 90: C = 0 along +y */
    assert_close(lobe_lux(scene, 1, v3(0, s60, -c60)), peak, 1e-9, "spun peak");
    assert_true(lobe_lux(scene, 1, v3(s60, 0, -c60)) < 1e-3 * peak);
    /* aimed along +x: the minimal turn from straight down takes C = 0 to +z */
    assert_close(lobe_lux(scene, 2, v3(c60, 0, s60)), peak, 1e-9, "aimed peak");
    /* aimed straight up: half a turn about x, C = 0 stays +x */
    assert_close(lobe_lux(scene, 3, v3(s60, 0, c60)), peak, 1e-9, "upward peak");
    /* the array: along the luminaire's x (= +y after the spin) and y (= -x) */
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 3; i++) {
            const rad_luminaire *L = &scene->luminaires.items[4 + (size_t)(3 * j + i)];
            char name[32];
            snprintf(name, sizeof name, "row[%d,%d]", i, j);
            assert_string_equal(L->name, name);
            assert_true(fabs(L->position.x - (80.0 - 2.0 * j)) < 1e-12 && fabs(L->position.y - i) < 1e-12 &&
                        L->position.z == 10.0);
            assert_close(lobe_lux(scene, 4 + (size_t)(3 * j + i), v3(0, s60, -c60)), peak, 1e-9, "array peak");
        }
    /* a y-up world: the default aim is -y, and the reference x stays */
    rad_scene *other = box(ctx, 1.0, 0.5);
    assert_int_equal(layout(ctx, other, "{\"up\": [0, 1, 0], \"llf\": 0.5, \"luminaires\": [{\"file\": \"lobe.ies\", "
                                        "\"position\": [0, 10, 0]}]}"),
                     RAD_OK);
    assert_close(lobe_lux(other, 0, v3(s60, -c60, 0)), 0.5 * peak, 1e-9, "y-up peak with the layout's llf");
    assert_string_equal(other->luminaires.items[0].name, "luminaire 1");
    rad_scene_destroy(other);
    /* The file's TILT factor at the angle between the aim and straight
     * down (interpolated: 0.75 at 45 degrees, 0.5 at 90, 1 aimed down). */
    rad_scene *tilted = box(ctx, 1.0, 0.5);
    assert_int_equal(layout(ctx, tilted, "{\"luminaires\": [{\"file\": \"tilt.ies\", \"position\": [0, 0, 3]},"
                                         "{\"file\": \"tilt.ies\", \"position\": [0, 0, 3], \"aim\": [1, 0, -1]},"
                                         "{\"file\": \"tilt.ies\", \"position\": [0, 0, 3], \"aim_at\": [0, 5, 3]}]}"),
                     RAD_OK);
    double iso = 4 * M_PI * 1000.0;
    assert_close(rad_luminaire_flux(&tilted->luminaires, 0), iso, 1e-9, "not tilted");
    assert_close(rad_luminaire_flux(&tilted->luminaires, 1), 0.75 * iso, 1e-9, "tilted 45 degrees");
    assert_close(rad_luminaire_flux(&tilted->luminaires, 2), 0.5 * iso, 1e-9, "tilted 90 degrees");
    rad_scene_destroy(tilted);
    /* lumens: scaled to the flux asked for */
    rad_scene *third = box(ctx, 1.0, 0.5);
    assert_int_equal(layout(ctx, third, "{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 3], "
                                        "\"lumens\": 1000, \"multiplier\": 3}]}"),
                     RAD_OK);
    assert_close(rad_luminaire_flux(&third->luminaires, 0), 3000.0, 1e-12, "lumens x multiplier");
    rad_scene_destroy(third);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

static void layout_errors(void **state)
{
    (void)state;
    static const struct { const char *json, *message; } cases[] = {
        {"{\"luminaires\": [", "mem/layout.json:1: not valid JSON"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"aim_at\": [1]}]}",
         "mem/layout.json: luminaires[0].aim_at: must be 3 finite numbers"},
        {"[1]", "mem/layout.json: must be a JSON object with \"luminaires\""},
        {"{\"lights\": []}", "mem/layout.json: lights: unknown key"},
        {"{}", "mem/layout.json: luminaires: missing"},
        {"{\"luminaires\": {}}", "mem/layout.json: luminaires: must be a list"},
        {"{\"luminaires\": [], \"luminaires\": []}", "mem/layout.json: luminaires: given twice"},
        {"{\"up\": [0, 0, 0], \"luminaires\": []}", "mem/layout.json: up: must be 3 finite numbers, not all 0"},
        {"{\"llf\": -1, \"luminaires\": []}", "mem/layout.json: llf: must be a number > 0"},
        {"{\"luminaires\": [3]}", "mem/layout.json: luminaires[0]: must be an object"},
        {"{\"luminaires\": [{\"position\": [0, 0, 1]}]}", "mem/layout.json: luminaires[0].file: missing"},
        {"{\"luminaires\": [{\"file\": 3, \"position\": [0, 0, 1]}]}",
         "mem/layout.json: luminaires[0].file: must be a non-empty string"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\"}]}", "mem/layout.json: luminaires[0].position: missing"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0]}]}",
         "mem/layout.json: luminaires[0].position: must be 3 finite numbers"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"colour\": 1}]}",
         "mem/layout.json: luminaires[0].colour: unknown key"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"aim\": [0, 0, 0]}]}",
         "mem/layout.json: luminaires[0].aim: must be 3 finite numbers, not all 0"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"aim\": [0, 0, -1], "
         "\"aim_at\": [0, 0, 0]}]}",
         "mem/layout.json: luminaires[0]: both aim and aim_at given"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"aim_at\": [0, 0, 1]}]}",
         "mem/layout.json: luminaires[0].aim_at: the point is the luminaire's position"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"spin\": \"90\"}]}",
         "mem/layout.json: luminaires[0].spin: must be a finite number"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"llf\": 0}]}",
         "mem/layout.json: luminaires[0].llf: must be a number > 0"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"lumens\": -5}]}",
         "mem/layout.json: luminaires[0].lumens: must be a number > 0"},
        {"{\"luminaires\": [{\"file\": \"dark.ies\", \"position\": [0, 0, 1], \"lumens\": 500}]}",
         "mem/layout.json: luminaires[0].lumens: the distribution of 'dark.ies' sends no flux"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"multiplier\": -1}]}",
         "mem/layout.json: luminaires[0].multiplier: must be a finite number >= 0"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"name\": \"\"}]}",
         "mem/layout.json: luminaires[0].name: must be a non-empty string"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"name\": \"a\"},"
         "{\"file\": \"iso.ies\", \"position\": [0, 0, 2], \"name\": \"a\"}]}",
         "mem/layout.json: two luminaires are named 'a'"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"array\": {\"count\": [0, 2], "
         "\"spacing\": [1, 1]}}]}",
         "mem/layout.json: luminaires[0].array.count: must be two whole numbers >= 1"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"array\": {\"count\": [2000, 2000], "
         "\"spacing\": [1, 1]}}]}",
         "mem/layout.json: luminaires[0].array.count: must be two whole numbers >= 1, [along x, along y], at most"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"array\": {\"count\": [2, 2]}}]}",
         "mem/layout.json: luminaires[0].array.spacing: must be two finite numbers"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"array\": {\"count\": [2, 2], "
         "\"spacing\": [1, 1], \"pitch\": 2}}]}",
         "mem/layout.json: luminaires[0].array.pitch: unknown key"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1]}, {\"file\": \"nope.ies\", "
         "\"position\": [0, 0, 1]}]}",
         "mem/nope.ies: cannot open"},
        {"{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], \"file\": \"iso.ies\"}]}",
         "mem/layout.json: luminaires[0].file: given twice"},
    };
    rad_context *ctx = test_context(1);
    rad_scene *scene = box(ctx, 1.0, 0.5);
    assert_int_equal(layout(ctx, scene, "{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 0.5], "
                                        "\"name\": \"kept\"}]}"),
                     RAD_OK);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        rad_result r = layout(ctx, scene, cases[k].json);
        const char *msg = rad_context_error(ctx);
        if (r == RAD_OK || strncmp(msg, cases[k].message, strlen(cases[k].message)) != 0 || strchr(msg, '\n')) {
            print_error("case %zu: %s\n  got %s: \"%s\"\n  expected \"%s...\"\n", k, cases[k].json,
                        rad_result_string(r), msg, cases[k].message);
            fail();
        }
        assert_int_equal(r, strstr(cases[k].message, "cannot open") ? RAD_ERROR_IO : RAD_ERROR_PARSE);
        /* all or nothing: the scene keeps what it had */
        assert_int_equal(scene->luminaires.count, 1);
        assert_int_equal(scene->luminaires.photometry_count, 1);
    }
    /* A second layout may not reuse a name the scene has. */
    assert_int_equal(layout(ctx, scene, "{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [0, 0, 1], "
                                        "\"name\": \"kept\"}]}"),
                     RAD_ERROR_PARSE);
    assert_non_null(strstr(rad_context_error(ctx), "two luminaires are named 'kept'"));
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* The files of tests/data/luminaires through the public calls: an IES
 * file read once, placed by a layout and by a glTF node. */
static void layout_and_gltf_files(void **state)
{
    (void)state;
    rad_context *ctx = test_context(2);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_file(ctx, RAD_TEST_DATA "/luminaires/room.obj", &scene), RAD_OK);
    assert_int_equal(rad_scene_load_luminaires(ctx, scene, RAD_TEST_DATA "/luminaires/layout.json"), RAD_OK);
    assert_int_equal(rad_scene_luminaire_count(scene), 5);
    assert_int_equal(scene->luminaires.photometry_count, 1);
    assert_string_equal(rad_scene_luminaire_name(scene, 3), "grid[1,1]");
    assert_string_equal(rad_scene_luminaire_name(scene, 4), "wallwash");
    assert_null(rad_scene_luminaire_name(scene, 5));
    /* The file's 1000 lm (I = 1000 / pi cos gamma, tabulated every 10
     * degrees: the bilinear table's flux is 0.25 % below). */
    double flux = scene->luminaires.photometries[0]->flux;
    assert_close(flux, 1000.0, 3e-3, "the downlight's flux");
    assert_close(rad_scene_luminaire_flux(scene, 0), 0.8 * flux, 1e-12, "the layout's llf");
    assert_close(rad_scene_luminaire_flux(scene, 4), flux, 1e-12, "the entry's llf");
    double position[3], axes[9];
    assert_true(rad_scene_luminaire_placement(scene, 3, position, axes));
    assert_true(position[0] == 3.0 && position[1] == 3.0 && position[2] == 2.99);
    assert_true(rad_scene_luminaire_placement(scene, 4, NULL, axes));
    /* aim_at [4, 2, 1] from [2, 2, 2.5]: the nadir -z along (0.8, 0, -0.6) */
    assert_true(fabs(axes[6] + 0.8) < 1e-12 && fabs(axes[7]) < 1e-12 && fabs(axes[8] - 0.6) < 1e-12);
    assert_false(rad_scene_luminaire_placement(scene, 5, position, axes));
    /* The near-field pieces are made for each receiver: what lands in the
     * closed room is the flux within their accuracy. */
    rad_solution *sol = NULL;
    rad_options o = {.solver = "jacobi", .target_elements = 800};
    assert_int_equal(rad_solution_create(ctx, scene, &o, &sol), RAD_OK);
    double total = 4 * 0.8 * flux + flux, landing = rad_solution_direct_lumens(sol);
    print_message("room: %.6g lm of %.6g lm landed (%.3g)\n", landing, total, landing / total - 1);
    assert_close(landing, total, 1e-3, "the room's direct light");
    rad_solution_destroy(sol);
    /* A file that is not there: the reader's message, the scene as it was. */
    const char *missing = "{\"luminaires\": [{\"file\": \"none.ies\", \"position\": [1, 1, 1]}]}";
    assert_int_equal(rad_scene_load_luminaires_memory(ctx, scene, RAD_TEST_DATA "/luminaires/x.json", missing,
                                                      strlen(missing)),
                     RAD_ERROR_IO);
    assert_non_null(strstr(rad_context_error(ctx), "none.ies"));
    assert_int_equal(rad_scene_luminaire_count(scene), 5);
    rad_scene_destroy(scene);

    /* The glTF node: 2.5 m above the floor's centre, turned to look down
     * (y up), llf 0.9 from its extras, named after the node. */
    assert_int_equal(rad_scene_load_file(ctx, RAD_TEST_DATA "/luminaires/lamp.gltf", &scene), RAD_OK);
    assert_int_equal(rad_scene_luminaire_count(scene), 1);
    assert_string_equal(rad_scene_luminaire_name(scene, 0), "lamp");
    assert_true(rad_scene_luminaire_placement(scene, 0, position, axes));
    assert_true(fabs(position[0] - 2) < 1e-12 && fabs(position[1] - 2.5) < 1e-12 && fabs(position[2] - 2) < 1e-12);
    assert_true(fabs(axes[7] - 1.0) < 1e-12); /* its z is world +y: the nadir down */
    assert_close(rad_scene_luminaire_flux(scene, 0), 0.9 * scene->luminaires.photometries[0]->flux, 1e-12, "extras' llf");
    /* The floor's centre, 2.5 m below the nadir: 1000 / pi cd x 0.9 / 2.5^2. */
    double h[3];
    rad_luminaires_irradiance(scene, NULL, NULL, v3(2, 0, 2), v3(0, 1, 0), h);
    assert_close(K * h[0], 0.9 * 318.3099 / 6.25, 1e-6, "under the glTF lamp");
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* The public calls' NULL behaviour (radiosity.h, "NULL"). */
static void public_null_arguments(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    rad_scene *scene = box(ctx, 1.0, 0.5);
    assert_int_equal(rad_scene_load_luminaires(ctx, NULL, "x.json"), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "rad_scene_load_luminaires"));
    assert_int_equal(rad_scene_load_luminaires(ctx, scene, NULL), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_scene_load_luminaires(NULL, scene, "x.json"), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_scene_load_luminaires_memory(ctx, scene, "x.json", NULL, 0), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "rad_scene_load_luminaires_memory"));
    assert_int_equal(rad_scene_load_luminaires_memory(ctx, scene, NULL, "{}", 2), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_scene_load_luminaires(ctx, scene, "/nonexistent/layout.json"), RAD_ERROR_IO);
    assert_int_equal(rad_scene_luminaire_count(NULL), 0);
    assert_null(rad_scene_luminaire_name(NULL, 0));
    assert_true(rad_scene_luminaire_flux(NULL, 0) == 0.0);
    assert_true(rad_scene_luminaire_flux(scene, 0) == 0.0);
    double p[3] = {7, 7, 7};
    assert_false(rad_scene_luminaire_placement(NULL, 0, p, NULL));
    assert_true(p[0] == 7.0);
    assert_true(rad_solution_direct_lumens(NULL) == 0.0);
    assert_int_equal(rad_scene_luminaire_count(scene), 0);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* ---- CIE 171:2006 (docs/cie171.md) ---- */

/* Test case 5.1 (point source): an isotropic point source in a black
 * room, the illuminance at grid points of the floor and the walls by the
 * inverse square and cosine laws.  The room as reconstructed (the report's
 * tables were not available: docs/cie171.md): 4 x 4 x 3 m, the source
 * 10,000 cd at the ceiling's centre; references from the closed form. */
static void cie171_point_source(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    const char *obj = "mtllib m.mtl\nusemtl black\n"
                      "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\nv 0 0 3\nv 4 0 3\nv 4 4 3\nv 0 4 3\n"
                      "o floor\nf 1 2 3 4\no ceiling\nf 5 8 7 6\no west\nf 1 4 8 5\no east\nf 2 6 7 3\n"
                      "o south\nf 1 5 6 2\no north\nf 4 3 7 8\n";
    const char *mtl = "newmtl black\nKd 0 0 0\n";
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "cie171-5.1.obj", obj, strlen(obj), mtl, strlen(mtl), &scene), RAD_OK);
    assert_int_equal(layout(ctx, scene, "{\"luminaires\": [{\"file\": \"iso.ies\", \"position\": [2, 2, 3], "
                                        "\"multiplier\": 10}]}"),
                     RAD_OK);
    rad_mesh *mesh = NULL;
    rad_vis *vis = NULL;
    rad_mesh_options mo = {0.5, 0, 0};
    assert_int_equal(rad_mesh_build(ctx, scene, &mo, &mesh), RAD_OK);
    assert_int_equal(rad_vis_create(ctx, "embree", mesh, &vis), RAD_OK);
    vec3 S = v3(2, 2, 3);
    double worst = 0.0;
    for (double a = 0.25; a < 4.0; a += 0.5)
        for (double b = 0.25; b < 4.0; b += 0.5) {
            vec3 pts[3] = {v3(a, b, 0), v3(0, a, b * 0.75), v3(a, 4, b * 0.75)};
            vec3 nrm[3] = {v3(0, 0, 1), v3(1, 0, 0), v3(0, -1, 0)};
            for (int k = 0; k < 3; k++) {
                vec3 d = v3_sub(S, pts[k]);
                double r = v3_length(d), want = 10000.0 * v3_dot(d, nrm[k]) / (r * r * r);
                double got = lux_at(scene, mesh, vis, pts[k], nrm[k]);
                worst = fmax(worst, fabs(got - want) / want);
            }
        }
    print_message("CIE 171 5.1: worst relative error %.3g over 192 points\n", worst);
    assert_true(worst < 1e-9);
    rad_vis_destroy(vis);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* Test case 5.2 (area source): a Lambertian rectangular source above a
 * parallel plane, the illuminance at points below and beside it against
 * pi L F (the corner formula).  Reconstructed as a 0.6 x 0.3 m opening of
 * 1,200 cd at nadir, points from 0.05 to 3 m below (the five-times switch
 * inside the range); the report's tables were not available. */
static void cie171_area_source(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    rad_scene *scene = box(ctx, 1.0, 0.5);
    assert_int_equal(layout(ctx, scene, "{\"luminaires\": [{\"file\": \"lambert.ies\", \"position\": [0, 0, 4]}]}"),
                     RAD_OK);
    double l = 0.6, w = 0.3, L = 1200.0 / (l * w), worst = 0.0;
    for (double h = 0.05; h <= 3.5; h += 0.15)
        for (double x = 0.0; x <= 1.0; x += 0.25) {
            double want = M_PI * L * rectangle_factor(-l / 2 - x, l / 2 - x, -w / 2, w / 2, h);
            double got = lux_at(scene, NULL, NULL, v3(x, 0, 4 - h), v3(0, 0, 1));
            worst = fmax(worst, fabs(got - want) / want);
        }
    print_message("CIE 171 5.2: worst relative error %.3g\n", worst);
    assert_true(worst < 0.01);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* ---- the command ---- */

static void command_luminaires(void **state)
{
    (void)state;
    assert_int_equal(cli_setup("luminaires"), 0);
    char png[600], stats[600], errors[600], bad[600];
    snprintf(png, sizeof png, "%s/room.png", test_workdir());
    snprintf(stats, sizeof stats, "%s/room.json", test_workdir());
    snprintf(errors, sizeof errors, "%s/errors.txt", test_workdir());
    snprintf(bad, sizeof bad, "%s/bad.json", test_workdir());
    /* The room lit by its layout only: the stats count the luminaires and
     * the light they land; emitted = absorbed in the closed room. */
    assert_int_equal(cli_run("render %s/luminaires/room.obj --luminaires %s/luminaires/layout.json --elements 300 "
                             "--tolerance 1e-9 -o %s --stats %s --threads 2",
                             RAD_TEST_DATA, RAD_TEST_DATA, png, stats),
                     0);
    cJSON *json = cli_read_json(stats);
    assert_non_null(json);
    assert_true(cli_stats_number(json, "luminaires", "count") == 5.0);
    double lumens = cli_stats_number(json, "luminaires", "lumens");
    cli_assert_relative(cli_stats_number(json, "luminaires", "direct_lumens"), lumens, 1e-3, "direct lumens");
    /* (1e-5: the analytic factors' rows sum to 1 within a few 1e-6 here;
     * with closure correction the library test above reaches 1e-11) */
    cli_assert_relative(cli_stats_number(json, "power_W", "absorbed"), cli_stats_number(json, "power_W", "emitted"),
                        1e-5, "the room's balance");
    cJSON_Delete(json);
    /* A bad layout: one line naming it and the key, exit 1, no image. */
    unlink(png);
    FILE *f = fopen(bad, "w");
    assert_non_null(f);
    fputs("{\"luminaires\": [{\"file\": \"downlight.ies\", \"position\": [1, 1]}]}\n", f);
    fclose(f);
    assert_int_equal(cli_run_capture(errors, "render %s/luminaires/room.obj --luminaires %s -o %s", RAD_TEST_DATA,
                                     bad, png),
                     1);
    char *text = test_read_file(errors, NULL);
    assert_non_null(text);
    assert_non_null(strstr(text, "bad.json: luminaires[0].position: must be 3 finite numbers"));
    free(text);
    assert_int_equal(access(png, F_OK), -1);
    /* solve keeps the luminaires in the solution file; render draws it
     * with them; --luminaires again with the file is a usage error. */
    assert_int_equal(cli_run("solve %s/luminaires/room.obj --luminaires %s/luminaires/layout.json --elements 300 "
                             "-o %s/room.radsol",
                             RAD_TEST_DATA, RAD_TEST_DATA, test_workdir()),
                     0);
    assert_int_equal(cli_run("render %s/room.radsol -o %s --stats %s", test_workdir(), png, stats), 0);
    json = cli_read_json(stats);
    assert_non_null(json);
    assert_true(cli_stats_number(json, "luminaires", "count") == 5.0);
    cli_assert_relative(cli_stats_number(json, "luminaires", "direct_lumens"), lumens, 1e-3, "loaded direct lumens");
    cJSON_Delete(json);
    assert_int_equal(cli_run_capture(errors, "render %s/room.radsol --luminaires %s/luminaires/layout.json -o %s",
                                     test_workdir(), RAD_TEST_DATA, png),
                     2);
    assert_int_equal(cli_run("solve %s/luminaires/lamp.gltf --elements 100 -o %s/lamp.radsol", RAD_TEST_DATA,
                             test_workdir()),
                     0);
    assert_int_equal(cli_teardown(), 0);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_luminaires PATH/TO/radiosity\n");
        return 2;
    }
    cli_set_binary(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(point_isotropic_planes),
        cmocka_unit_test(point_cos_power_planes),
        cmocka_unit_test(point_shadow),
        cmocka_unit_test(area_lambertian_rectangle),
        cmocka_unit_test(area_lambertian_disk),
        cmocka_unit_test(flux_closed_black_box),
        cmocka_unit_test(solve_energy_balance),
        cmocka_unit_test(direct_thread_determinism),
        cmocka_unit_test(layout_placement),
        cmocka_unit_test(layout_errors),
        cmocka_unit_test(layout_and_gltf_files),
        cmocka_unit_test(public_null_arguments),
        cmocka_unit_test(cie171_point_source),
        cmocka_unit_test(cie171_area_source),
        cmocka_unit_test(command_luminaires),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
