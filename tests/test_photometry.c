/*
 * test_photometry.c -- luminaire photometric files (src/photometry/photometry.c,
 * ies.c, eulumdat.c; docs/lighting.md, "Photometric files").
 *
 *   - flux: an isotropic I gives 4 pi I exactly; I0 cos(gamma) over the
 *     lower hemisphere gives pi I0 to 1e-4 on a 0.5-degree table, and on a
 *     10-degree table falls short by less than the bilinear bound h^2/4
 *     (relative); the closed-form flux of an asymmetric table agrees with
 *     a brute-force quadrature of rad_photometry_intensity;
 *   - symmetry: one quadrant-symmetric distribution written as IES
 *     quadrant, bilateral 0-180, bilateral 90-270, full 0-360 with and
 *     without the 360 plane, and EULUMDAT Isym 0, 2, 3, 4 gives the same
 *     candela at 500 directions (1e-12) and the same flux; one rotational
 *     distribution likewise (IES one plane, quadrant, full; EULUMDAT Isym 1,
 *     4); a missing hemisphere is 0 cd;
 *   - types B and A describing the same axially symmetric beam as type C
 *     agree within the interpolation error; their frames put the beam
 *     where docs/lighting.md says;
 *   - tilt (INCLUDE and a file), multipliers and ballast factors by
 *     version, feet, LM-63-2019 shapes, absolute photometry, every version's
 *     first line, keyword lines, numbers split by commas over lines;
 *   - lumens: files built to have exact lumens integrate to them (0.1 %);
 *     an EULUMDAT LORL that disagrees is a warning;
 *   - 30 malformed files, each refused with RAD_ERROR_PARSE (or IO) and
 *     its message naming file and line.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "test_support.h"

#include "radiosity.h"
#include "photometry/photometry.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <errno.h>
#include <sys/stat.h>

#define DATA RAD_TEST_DATA "/photometry"
static const double DEG = M_PI / 180.0;

static char g_dir[256];
static char g_warning[1024];
static int g_warnings;

static void on_warning(void *user, const char *message)
{
    (void)user;
    snprintf(g_warning, sizeof g_warning, "%s", message);
    g_warnings++;
}

static rad_context *context(void)
{
    rad_context_options co = {.threads = 1, .on_warning = on_warning};
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(&co, &ctx), RAD_OK);
    return ctx;
}

/* ---- writing files (test_text) ---- */

static const char *path_of(const char *name)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    return path;
}

static const char *save(const char *name, test_text *t)
{
    const char *path = path_of(name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fwrite(t->data, 1, t->length, f);
    fclose(f);
    free(t->data);
    memset(t, 0, sizeof *t);
    return path;
}

typedef double (*distribution)(double c, double gamma);

/* An IES file: `first` its first line (NULL: LM-63-1986), line 10 and 11
 * as given, candela f(h, v) at the angles. */
typedef struct ies_spec {
    const char *first, *tilt;
    double lamps, lumens, multiplier;
    int type, units;
    double width, length, height, ballast, second, watts;
    size_t nv, nh;
    const double *v, *h;
    distribution f;
} ies_spec;

static const char *write_ies(const char *name, const ies_spec *s)
{
    test_text t = {0};
    if (s->first)
        test_put(&t, "%s\n[TEST] test_photometry\n[LUMINAIRE] %s\n", s->first, name);
    else
        test_put(&t, "test_photometry 1986 %s\n", name);
    test_put(&t, "TILT=%s\n", s->tilt ? s->tilt : "NONE");
    test_put(&t, "%g %.17g %.17g %zu %zu %d %d %.17g %.17g %.17g\n", s->lamps, s->lumens, s->multiplier, s->nv, s->nh,
        s->type, s->units, s->width, s->length, s->height);
    test_put(&t, "%.17g %.17g %.17g\n", s->ballast, s->second, s->watts);
    for (size_t i = 0; i < s->nv; i++)
        test_put(&t, "%.17g%s", s->v[i], i % 10 == 9 || i + 1 == s->nv ? "\n" : " ");
    for (size_t i = 0; i < s->nh; i++)
        test_put(&t, "%.17g%s", s->h[i], i % 10 == 9 || i + 1 == s->nh ? "\n" : ", ");
    for (size_t j = 0; j < s->nh; j++)
        for (size_t i = 0; i < s->nv; i++)
            test_put(&t, "%.17g%s", s->f(s->h[j], s->v[i]), i % 7 == 6 || i + 1 == s->nv ? "\n" : " ");
    return save(name, &t);
}

static ies_spec ies_default(size_t nv, const double *v, size_t nh, const double *h, distribution f)
{
    ies_spec s = {"IESNA:LM-63-2002", NULL, 1, 1000, 1, 1, 2, 0, 0, 0, 1, 1, 10, nv, nh, v, h, f};
    return s;
}

/* An EULUMDAT file of Mc planes c[] (all listed), the stored ones by
 * Isym, cd/klm f(c, gamma) / (lumens / 1000). */
static const char *write_ldt(const char *name, int isym, size_t mc, const double *c, size_t ng, const double *g,
                             distribution f, double lumens, double lorl, int lamps)
{
    test_text t = {0};
    test_put(&t, "radiosity tests\n1\n%d\n%zu\n%g\n%zu\n%g\nreport\n%s\n1\nx.ldt\n2026\n", isym, mc, mc > 1 ? c[1] : 0.0,
        ng, g[1] - g[0], name);
    test_put(&t, "600\n600\n80\n500\n400\n0\n0\n0\n0\n100\n%g\n1\n0\n1\n%d\nLED\n%.17g\n3000K\n80\n20\n", lorl, lamps,
        lumens);
    for (int i = 0; i < 10; i++)
        test_put(&t, "0.5\n");
    for (size_t i = 0; i < mc; i++)
        test_put(&t, "%.17g\n", c[i]);
    for (size_t i = 0; i < ng; i++)
        test_put(&t, "%.17g\n", g[i]);
    size_t first = 0, planes = mc;
    switch (isym) {
    case 1: planes = 1; break;
    case 2: planes = mc / 2 + 1; break;
    case 3: first = 3 * mc / 4, planes = mc / 2 + 1; break;
    case 4: planes = mc / 4 + 1; break;
    default: break;
    }
    for (size_t j = 0; j < planes; j++)
        for (size_t i = 0; i < ng; i++)
            test_put(&t, "%.17g\n", f(c[(first + j) % mc], g[i]) * 1000.0 / fabs(lumens));
    return save(name, &t);
}

static rad_photometry *load(rad_context *ctx, const char *path)
{
    rad_photometry *p = NULL;
    rad_result r = rad_photometry_load(ctx, path, &p);
    if (r != RAD_OK)
        fprintf(stderr, "%s: %s\n", path, rad_context_error(ctx));
    assert_int_equal(r, RAD_OK);
    assert_non_null(p);
    return p;
}

static vec3 direction(double c, double gamma)
{
    return v3(sin(gamma * DEG) * cos(c * DEG), sin(gamma * DEG) * sin(c * DEG), -cos(gamma * DEG));
}

/* 500 directions from a fixed sequence (golden-ratio spiral, jittered
 * off the table's nodes). */
static vec3 probe(int k)
{
    double z = 1.0 - 2.0 * (k + 0.37) / 500.0;
    double phi = k * 2.399963229728653 + 0.123;
    double r = sqrt(fmax(0.0, 1.0 - z * z));
    return v3(r * cos(phi), r * sin(phi), z);
}

static void assert_same(const rad_photometry *a, const rad_photometry *b, double tolerance)
{
    double peak = rad_photometry_max(a, NULL, NULL);
    for (int k = 0; k < 500; k++) {
        double ia = rad_photometry_intensity(a, probe(k)), ib = rad_photometry_intensity(b, probe(k));
        if (fabs(ia - ib) > tolerance * peak)
            fail_msg("%s vs %s: direction %d: %.17g vs %.17g", a->source, b->source, k, ia, ib);
    }
    if (fabs(a->flux - b->flux) > tolerance * a->flux)
        fail_msg("%s vs %s: flux %.17g vs %.17g", a->source, b->source, a->flux, b->flux);
}

/* ---- flux ---- */

static void test_flux_closed_forms(void **state)
{
    (void)state;
    rad_context *ctx = context();
    /* isotropic: two gamma nodes, one plane; and a 4-plane table */
    double g2[2] = {0, 180}, c1[1] = {0}, iso[2] = {250, 250};
    rad_photometry *p = rad_photometry_from_table(ctx, "iso", 1, c1, 2, g2, iso, NULL);
    assert_non_null(p);
    assert_true(fabs(p->flux - 4.0 * M_PI * 250.0) < 1e-12 * p->flux);
    rad_photometry_free(p);
    double c5[5] = {0, 90, 180, 270, 360}, iso5[10];
    for (int i = 0; i < 10; i++)
        iso5[i] = 250;
    p = rad_photometry_from_table(ctx, "iso", 5, c5, 2, g2, iso5, NULL);
    assert_true(fabs(p->flux - 4.0 * M_PI * 250.0) < 1e-12 * p->flux);
    rad_photometry_free(p);

    /* a table that stops short of the poles holds its end values: 0..90
     * at 250 cd is isotropic */
    double g90[2] = {0, 90};
    p = rad_photometry_from_table(ctx, "half", 1, c1, 2, g90, iso, NULL);
    assert_non_null(p);
    assert_true(fabs(p->flux - 4.0 * M_PI * 250.0) < 1e-12 * p->flux);
    assert_true(rad_photometry_intensity(p, v3(0, 0, 1)) == 250.0);
    rad_photometry_free(p);
    /* not a table: gamma beyond 180, decreasing, three equal; C not closing at 360 */
    double bad_g[3] = {0, 90, 190}, dec_g[3] = {0, 90, 45}, three[4] = {0, 90, 90, 90}, cd4[8] = {0};
    double open_c[2] = {0, 180};
    rad_result err = RAD_OK;
    assert_null(rad_photometry_from_table(ctx, "bad", 1, c1, 3, bad_g, cd4, &err));
    assert_int_equal(err, RAD_ERROR_INVALID_ARGUMENT);
    assert_null(rad_photometry_from_table(ctx, "bad", 1, c1, 3, dec_g, cd4, NULL));
    assert_null(rad_photometry_from_table(ctx, "bad", 1, c1, 4, three, cd4, NULL));
    assert_null(rad_photometry_from_table(ctx, "bad", 2, open_c, 2, g2, cd4, NULL));

    /* I0 cos(gamma), lower hemisphere: pi I0.  Linear interpolation of
     * cos on a step h errs by at most h^2/8 I0 (|cos''| <= 1), so the flux
     * by at most 2 pi (h^2/8) I0 int sin = pi I0 h^2/4: relative h^2/4,
     * 1.9e-5 at 0.5 degrees, 7.6e-3 at 10; cos is concave there, so the
     * table falls short. */
    const double I0 = 1000.0;
    for (int fine = 0; fine < 2; fine++) {
        double step = fine ? 0.5 : 10.0;
        size_t n = (size_t)(90.0 / step) + 2;
        double *g = malloc(n * sizeof *g), *cd = malloc(n * sizeof *cd);
        for (size_t i = 0; i + 1 < n; i++)
            g[i] = i * step, cd[i] = I0 * cos(g[i] * DEG);
        cd[n - 2] = 0.0; /* cos 90 rounds to 6e-14 */
        g[n - 1] = 180.0, cd[n - 1] = 0.0;
        p = rad_photometry_from_table(ctx, "cos", 1, c1, n, g, cd, NULL);
        assert_non_null(p);
        double shortfall = (M_PI * I0 - p->flux) / (M_PI * I0), h = step * DEG;
        if (fine)
            assert_true(fabs(shortfall) < 1e-4);
        assert_true(shortfall > 0.0 && shortfall <= h * h / 4.0);
        /* and not much below it: the bound is tight to a factor 3 (the
         * error's mean over a cell is h^2/12 of the curvature) */
        assert_true(shortfall > h * h / 4.0 / 4.0);
        rad_photometry_free(p);
        free(g);
        free(cd);
    }
    rad_context_destroy(ctx);
}

static double lumpy(double c, double gamma)
{
    return 100.0 + 60.0 * cos(c * DEG) * sin(gamma * DEG) + 30.0 * sin(2.0 * c * DEG) + 20.0 * cos(gamma * DEG);
}

/* The closed form against a brute-force integral of the evaluation:
 * midpoint rule in C and Gauss-Legendre (4 points) in gamma on a grid
 * 8 times finer than the table's: the bilinear surface is smooth inside
 * each cell, so the quadrature is good to ~1e-7. */
static void test_flux_against_quadrature(void **state)
{
    (void)state;
    rad_context *ctx = context();
    double c[13], g[10], cd[13 * 10];
    for (int i = 0; i < 13; i++)
        c[i] = 30.0 * i;
    double gs[10] = {0, 10, 25, 40, 60, 90, 90, 120, 150, 180}; /* a step at 90 */
    memcpy(g, gs, sizeof g);
    for (int i = 0; i < 13; i++)
        for (int j = 0; j < 10; j++)
            cd[i * 10 + j] = j == 6 ? 5.0 : lumpy(c[i], g[j]);
    rad_photometry *p = rad_photometry_from_table(ctx, "lumpy", 13, c, 10, g, cd, NULL);
    assert_non_null(p);
    static const double x[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
    static const double w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
    double total = 0.0;
    for (int ic = 0; ic < 12 * 8; ic++) {
        double cc = (ic + 0.5) * 30.0 / 8.0;
        for (int ig = 0; ig < 9; ig++) {
            if (g[ig + 1] == g[ig])
                continue;
            for (int s = 0; s < 8; s++) {
                double a = g[ig] + (g[ig + 1] - g[ig]) * s / 8.0, b = g[ig] + (g[ig + 1] - g[ig]) * (s + 1) / 8.0;
                for (int k = 0; k < 4; k++) {
                    double gg = 0.5 * (a + b) + 0.5 * (b - a) * x[k];
                    total += w[k] * 0.5 * (b - a) * DEG * (30.0 / 8.0) * DEG * sin(gg * DEG) *
                             rad_photometry_intensity(p, direction(cc, gg));
                }
            }
        }
    }
    assert_true(fabs(total - p->flux) < 1e-6 * p->flux);
    /* the step: at gamma 90 exactly the value on the lower side; above, the upper plane's */
    assert_true(fabs(rad_photometry_intensity(p, direction(0, 90)) - lumpy(0, 90)) < 1e-9);
    assert_true(fabs(rad_photometry_intensity(p, direction(0, 90.0001)) - 5.0) < 1e-3);
    rad_photometry_free(p);
    rad_context_destroy(ctx);
}

/* ---- symmetry ---- */

static double quad(double c, double gamma) { return (200.0 + 80.0 * cos(2.0 * c * DEG)) * (1.0 + cos(gamma * DEG)) + 10.0; }
static double rot(double c, double gamma)
{
    (void)c;
    return 300.0 * cos(0.5 * gamma * DEG) * cos(0.5 * gamma * DEG) + 5.0;
}

static void test_every_symmetry_same_distribution(void **state)
{
    (void)state;
    rad_context *ctx = context();
    double v[37], h[25];
    for (int i = 0; i < 37; i++)
        v[i] = 5.0 * i;
    for (int i = 0; i < 25; i++)
        h[i] = 15.0 * i; /* 0 .. 360 */
    /* IES: full with 360, full without, bilateral 0-180, bilateral 90-270, quadrant */
    ies_spec s = ies_default(37, v, 25, h, quad);
    rad_photometry *ref = load(ctx, write_ies("full360.ies", &s));
    assert_string_equal(ref->symmetry, "none (C 0-360)");
    struct {
        const char *name;
        size_t first, count;
        const char *symmetry;
    } ies[] = {{"full345.ies", 0, 24, "none (C 0 to below 360)"},
               {"bilateral0.ies", 0, 13, "bilateral (C 0-180)"},
               {"bilateral90.ies", 6, 13, "bilateral (C 90-270)"},
               {"quadrant.ies", 0, 7, "quadrant (C 0-90)"}};
    for (size_t k = 0; k < sizeof ies / sizeof ies[0]; k++) {
        s = ies_default(37, v, ies[k].count, h + ies[k].first, quad);
        rad_photometry *p = load(ctx, write_ies(ies[k].name, &s));
        assert_string_equal(p->symmetry, ies[k].symmetry);
        assert_same(ref, p, 1e-12);
        rad_photometry_free(p);
    }
    /* EULUMDAT: Mc 24 planes of 15 degrees, Isym 0, 2, 3, 4 */
    for (int isym = 0; isym <= 4; isym++) {
        if (isym == 1)
            continue;
        char name[32];
        snprintf(name, sizeof name, "isym%d.ldt", isym);
        rad_photometry *p = load(ctx, write_ldt(name, isym, 24, h, 37, v, quad, 1000.0, 100.0, 1));
        assert_int_equal(p->format, RAD_PHOTOMETRY_LDT);
        assert_same(ref, p, 1e-12);
        rad_photometry_free(p);
    }
    /* the table really has the distribution: at nodes, exactly */
    assert_true(fabs(rad_photometry_intensity(ref, direction(30, 45)) - quad(30, 45)) < 1e-12 * quad(30, 45));
    assert_true(fabs(rad_photometry_intensity(ref, direction(210, 45)) - quad(210, 45)) < 1e-12 * quad(30, 45));
    rad_photometry_free(ref);

    /* rotational: one plane, quadrant, full; Isym 1 and 4 */
    s = ies_default(37, v, 1, h, rot);
    ref = load(ctx, write_ies("rot1.ies", &s));
    assert_int_equal(ref->c_count, 1);
    s = ies_default(37, v, 7, h, rot);
    rad_photometry *p = load(ctx, write_ies("rotq.ies", &s));
    assert_same(ref, p, 1e-12);
    rad_photometry_free(p);
    s = ies_default(37, v, 25, h, rot);
    p = load(ctx, write_ies("rotf.ies", &s));
    assert_same(ref, p, 1e-12);
    rad_photometry_free(p);
    double c1[1] = {0};
    p = load(ctx, write_ldt("rot.ldt", 1, 1, c1, 37, v, rot, 1000.0, 100.0, 1));
    assert_same(ref, p, 1e-12);
    rad_photometry_free(p);
    p = load(ctx, write_ldt("rot4.ldt", 4, 24, h, 37, v, rot, 1000.0, 100.0, 1));
    assert_same(ref, p, 1e-12);
    rad_photometry_free(p);
    rad_photometry_free(ref);
    rad_context_destroy(ctx);
}

/* An asymmetric distribution in the four IES/LDT full layouts, and the
 * direction convention: C = 90 is +y. */
static double skew(double c, double gamma) { return 100.0 + 50.0 * sin(c * DEG) * sin(gamma * DEG); }
static double lean(double c, double gamma) { return 100.0 + 50.0 * cos(c * DEG) * sin(gamma * DEG); }

static void test_c_frame(void **state)
{
    (void)state;
    rad_context *ctx = context();
    double v[19], h[25];
    for (int i = 0; i < 19; i++)
        v[i] = 10.0 * i;
    for (int i = 0; i < 25; i++)
        h[i] = 15.0 * i;
    ies_spec s = ies_default(19, v, 25, h, skew);
    rad_photometry *p = load(ctx, write_ies("skew.ies", &s));
    rad_photometry *q = load(ctx, write_ldt("skew.ldt", 0, 24, h, 19, v, skew, 1000.0, 100.0, 1));
    assert_same(p, q, 1e-12);
    double c, g;
    double peak = rad_photometry_max(p, &c, &g);
    assert_true(fabs(peak - 150.0) < 1e-12 && c == 90.0 && g == 90.0);
    assert_true(fabs(rad_photometry_intensity(p, v3(0, 1, 0)) - 150.0) < 1e-12);  /* +y: C 90 */
    assert_true(fabs(rad_photometry_intensity(p, v3(0, -1, 0)) - 50.0) < 1e-12);  /* -y: C 270 */
    assert_true(fabs(rad_photometry_intensity(p, v3(0, 0, -1)) - 100.0) < 1e-12); /* nadir */
    /* skew is symmetric in the C90-C270 plane only: IES 90-270 and
     * EULUMDAT Isym 3 (C 270..360/0..90 stored) give the full file's
     * candela; lean is symmetric in the C0-C180 plane only: IES 0-180 and
     * Isym 2 */
    rad_photometry_free(q);
    s = ies_default(19, v, 13, h + 6, skew);
    q = load(ctx, write_ies("skew90.ies", &s));
    assert_same(p, q, 1e-12);
    rad_photometry_free(q);
    q = load(ctx, write_ldt("skew3.ldt", 3, 24, h, 19, v, skew, 1000.0, 100.0, 1));
    assert_same(p, q, 1e-12);
    rad_photometry_free(q);
    s = ies_default(19, v, 25, h, lean);
    rad_photometry *full = load(ctx, write_ies("lean.ies", &s));
    s = ies_default(19, v, 13, h, lean);
    q = load(ctx, write_ies("lean0.ies", &s));
    assert_same(full, q, 1e-12);
    rad_photometry_free(q);
    q = load(ctx, write_ldt("lean2.ldt", 2, 24, h, 19, v, lean, 1000.0, 100.0, 1));
    assert_same(full, q, 1e-12);
    assert_true(fabs(rad_photometry_intensity(q, v3(1, 0, 0)) - 150.0) < 1e-12); /* +x: C 0 */
    rad_photometry_free(q);
    rad_photometry_free(full);
    rad_photometry_free(p);
    rad_context_destroy(ctx);
}

static double down_cos(double c, double gamma)
{
    (void)c;
    return gamma <= 90.0 ? 1000.0 * cos(gamma * DEG) * (gamma < 90.0) : 0.0;
}
static double up_cos(double c, double gamma)
{
    (void)c;
    return gamma >= 90.0 ? -1000.0 * cos(gamma * DEG) * (gamma > 90.0) : 0.0;
}

static void test_missing_hemisphere(void **state)
{
    (void)state;
    rad_context *ctx = context();
    double v[37], h[1] = {0};
    for (int i = 0; i < 37; i++)
        v[i] = 5.0 * i;
    ies_spec s = ies_default(19, v, 1, h, down_cos);
    rad_photometry *lower = load(ctx, write_ies("lower.ies", &s));
    s = ies_default(37, v, 1, h, down_cos);
    rad_photometry *whole = load(ctx, write_ies("whole.ies", &s));
    assert_same(lower, whole, 1e-12);
    assert_true(rad_photometry_intensity(lower, direction(0, 120)) == 0.0);
    s = ies_default(19, v + 18, 1, h, up_cos);
    rad_photometry *upper = load(ctx, write_ies("upper.ies", &s));
    assert_true(rad_photometry_intensity(upper, direction(0, 30)) == 0.0);
    assert_true(fabs(rad_photometry_intensity(upper, direction(0, 180)) - 1000.0) < 1e-9);
    assert_true(fabs(upper->flux - lower->flux) < 1e-9 * lower->flux); /* mirror images */
    rad_photometry_free(lower);
    rad_photometry_free(whole);
    rad_photometry_free(upper);
    rad_context_destroy(ctx);
}

/* ---- types B and A ---- */

static double beam_c(double h, double v)
{
    (void)h;
    return v <= 90.0 ? 1000.0 * cos(v * DEG) : 0.0;
}
static double beam_b(double h, double v) { return 1000.0 * cos(h * DEG) * cos(v * DEG); }
static double aimed(double h, double v)
{
    /* a narrow beam toward H = 30, V = 0 */
    double d = (h - 30.0) * (h - 30.0) + v * v;
    return 500.0 * exp(-d / 200.0);
}

static void test_types_b_and_a(void **state)
{
    (void)state;
    rad_context *ctx = context();
    double vc[91], hc[1] = {0}, hb[181], vb[181];
    for (int i = 0; i <= 90; i++)
        vc[i] = i;
    for (int i = 0; i <= 180; i++)
        hb[i] = vb[i] = i - 90.0;
    ies_spec s = ies_default(91, vc, 1, hc, beam_c);
    rad_photometry *c = load(ctx, write_ies("beam_c.ies", &s));
    s = ies_default(181, vb, 181, hb, beam_b);
    s.type = 2;
    rad_photometry *b = load(ctx, write_ies("beam_b.ies", &s));
    assert_int_equal(b->type, RAD_PHOTOMETRY_B);
    s.type = 3;
    rad_photometry *a = load(ctx, write_ies("beam_a.ies", &s));
    s.type = 2;
    s.nh = 91, s.h = hb + 90; /* 0..90: left-right symmetric */
    rad_photometry *bs = load(ctx, write_ies("beam_bs.ies", &s));
    assert_string_equal(bs->symmetry, "left-right (H 0 to 90)");
    assert_same(b, bs, 1e-12);
    /* each bilinear web errs by at most (h^2/8)(|f_HH| + |f_VV|) <= 2 x 3.8e-5
     * x 1000 cd at 1 degree, the resampling as much again: 5e-4 of the peak
     * bounds both; the flux pi x 1000 to 1e-4 */
    assert_same(c, b, 5e-4);
    assert_same(c, a, 5e-4);
    assert_true(fabs(c->flux - M_PI * 1000.0) < 1e-4 * M_PI * 1000.0);
    assert_true(fabs(b->flux - M_PI * 1000.0) < 1e-4 * M_PI * 1000.0);
    rad_photometry_free(c);
    rad_photometry_free(a);
    rad_photometry_free(b);
    rad_photometry_free(bs);

    /* frames: type B's H = 30 lies toward +y (C 90, gamma 30), type A's
     * toward... its H rotates about +x from -z toward +y: the same
     * direction; its V = 30 would be toward +x */
    s = ies_default(181, vb, 181, hb, aimed);
    s.type = 2;
    b = load(ctx, write_ies("aimed_b.ies", &s));
    double cm, gm;
    rad_photometry_max(b, &cm, &gm);
    assert_true(fabs(cm - 90.0) < 1e-9 && fabs(gm - 30.0) < 1e-9);
    assert_true(fabs(rad_photometry_intensity(b, direction(90, 30)) - 500.0) < 1.0);
    assert_true(rad_photometry_intensity(b, direction(270, 30)) < 1.0);
    assert_true(rad_photometry_intensity(b, v3(0, 0, 1)) == 0.0); /* behind */
    s.type = 3;
    a = load(ctx, write_ies("aimed_a.ies", &s));
    rad_photometry_max(a, &cm, &gm);
    assert_true(fabs(cm - 90.0) < 1e-9 && fabs(gm - 30.0) < 1e-9);
    rad_photometry_free(a);
    rad_photometry_free(b);
    rad_context_destroy(ctx);
}

/* ---- tilt, multipliers, units, shapes, versions ---- */

static double flat(double h, double v)
{
    (void)h;
    return v <= 90.0 ? 100.0 : 0.0;
}

static void test_tilt(void **state)
{
    (void)state;
    rad_context *ctx = context();
    double v[3] = {0, 45, 90}, h[1] = {0};
    ies_spec s = ies_default(3, v, 1, h, flat);
    s.tilt = "INCLUDE\n1\n3\n0 45 90\n1 0.9 0.5";
    rad_photometry *p = load(ctx, write_ies("tilt_include.ies", &s));
    assert_int_equal(p->tilt_count, 3);
    assert_int_equal(p->tilt_geometry, 1);
    assert_string_equal(p->tilt_source, "include");
    assert_true(fabs(rad_photometry_tilt_factor(p, 22.5) - 0.95) < 1e-15);
    assert_true(fabs(rad_photometry_tilt_factor(p, 67.5) - 0.7) < 1e-15);
    assert_true(rad_photometry_tilt_factor(p, 90) == 0.5 && rad_photometry_tilt_factor(p, 120) == 0.5);
    assert_true(rad_photometry_tilt_factor(p, 0) == 1.0);
    /* the candela are not tilted */
    assert_true(fabs(rad_photometry_intensity(p, v3(0, 0, -1)) - 100.0) < 1e-12);
    rad_photometry_free(p);

    test_text t = {0};
    test_put(&t, "2\n4\n0, 30, 60, 90\n1.0 0.8\n 0.6 0.4\n");
    save("lamp.tlt", &t);
    s.tilt = "lamp.tlt";
    p = load(ctx, write_ies("tilt_file.ies", &s));
    assert_string_equal(p->tilt_source, "lamp.tlt");
    assert_int_equal(p->tilt_geometry, 2);
    assert_true(fabs(rad_photometry_tilt_factor(p, 45) - 0.7) < 1e-15);
    rad_photometry_free(p);

    /* a tilt file that is not there names the .ies line; a bad one its own */
    s.tilt = "absent.tlt";
    rad_photometry *q = NULL;
    rad_api_enter(ctx);
    assert_int_equal(rad_photometry_load(ctx, write_ies("tilt_absent.ies", &s), &q), RAD_ERROR_IO);
    assert_null(q);
    assert_non_null(strstr(rad_context_error(ctx), "tilt_absent.ies:4: TILT=absent.tlt: cannot open"));
    test_put(&t, "1\n3\n0 45\n");
    save("short.tlt", &t);
    s.tilt = "short.tlt";
    rad_api_enter(ctx);
    assert_int_equal(rad_photometry_load(ctx, write_ies("tilt_short.ies", &s), &q), RAD_ERROR_PARSE);
    assert_non_null(strstr(rad_context_error(ctx), "short.tlt:3: expected 3 tilt angles, found 2 (the file ends)"));

    /* The readers' bounds (core/input.c): a tilt file of more than 1 MiB
     * (a sparse one: nothing is written), a folder in place of a file. */
    FILE *big = fopen(path_of("big.tlt"), "wb");
    assert_non_null(big);
    assert_int_equal(ftruncate(fileno(big), (1 << 20) + 1), 0);
    fclose(big);
    s.tilt = "big.tlt";
    rad_api_enter(ctx);
    assert_int_equal(rad_photometry_load(ctx, write_ies("tilt_big.ies", &s), &q), RAD_ERROR_PARSE);
    assert_non_null(strstr(rad_context_error(ctx), "tilt_big.ies:4: TILT=big.tlt: more than 1 MiB: not a tilt file"));
    s.tilt = "folder.tlt";
    assert_int_equal(mkdir(path_of("folder.tlt"), 0700) == 0 || errno == EEXIST, 1);
    rad_api_enter(ctx);
    assert_int_equal(rad_photometry_load(ctx, write_ies("tilt_folder.ies", &s), &q), RAD_ERROR_IO);
    assert_non_null(strstr(rad_context_error(ctx), "TILT=folder.tlt: is a folder, not a tilt file"));
    rad_api_enter(ctx);
    assert_int_equal(rad_photometry_load(ctx, path_of("folder.tlt"), &q), RAD_ERROR_IO);
    assert_non_null(strstr(rad_context_error(ctx), "folder.tlt: is a folder, not a photometric file"));
    assert_null(q);
    rad_context_destroy(ctx);
}

static void test_multipliers_units_versions(void **state)
{
    (void)state;
    rad_context *ctx = context();
    double v[3] = {0, 45, 90}, h[1] = {0};
    struct {
        const char *first;
        double factor; /* the second value of line 11 counts */
    } versions[] = {{NULL, 0.95}, {"IESNA91", 0.95}, {"IESNA:LM-63-1995", 0.95}, {"IESNA:LM-63-2002", 1.0},
                    {"IES:LM-63-2019", 1.0}};
    const char *names[] = {"LM-63-1986", "LM-63-1991", "LM-63-1995", "LM-63-2002", "LM-63-2019"};
    for (int k = 0; k < 5; k++) {
        ies_spec s = ies_default(3, v, 1, h, flat);
        s.first = versions[k].first;
        s.multiplier = 2.0, s.ballast = 0.9, s.second = 0.95;
        s.units = 1, s.width = 2.0, s.length = 4.0, s.height = 0.0;
        char name[32];
        snprintf(name, sizeof name, "version%d.ies", k);
        rad_photometry *p = load(ctx, write_ies(name, &s));
        assert_string_equal(p->version, names[k]);
        double expected = 100.0 * 2.0 * 0.9 * versions[k].factor;
        assert_true(fabs(rad_photometry_intensity(p, v3(0, 0, -1)) - expected) < 1e-12 * expected);
        assert_true(fabs(p->multiplier - 2.0 * 0.9 * versions[k].factor) < 1e-15);
        /* feet: 2 ft = 0.6096 m exactly */
        assert_true(fabs(p->width - 0.6096) < 1e-15 && fabs(p->length - 1.2192) < 1e-15 && p->height == 0.0);
        assert_int_equal(p->shape, RAD_OPENING_RECTANGLE);
        if (k == 0)
            assert_string_equal(p->label, "test_photometry 1986 version0.ies");
        else
            assert_string_equal(p->label, name);
        rad_photometry_free(p);
    }
    /* absolute photometry: lumens -1, no rated lumens, no LOR */
    ies_spec s = ies_default(3, v, 1, h, flat);
    s.lumens = -1;
    rad_photometry *p = load(ctx, write_ies("absolute.ies", &s));
    assert_true(p->rated_lumens == 0.0 && rad_photometry_lor(p) == 0.0);
    assert_true(fabs(rad_photometry_intensity(p, v3(0, 0, -1)) - 100.0) < 1e-12);
    rad_photometry_free(p);
    /* two lamps of 800 lm: 1600 rated */
    s.lumens = 800, s.lamps = 2;
    p = load(ctx, write_ies("two_lamps.ies", &s));
    assert_true(p->rated_lumens == 1600.0);
    assert_true(fabs(rad_photometry_lor(p) - p->flux / 1600.0) < 1e-15);
    rad_photometry_free(p);
    rad_context_destroy(ctx);
}

static void test_shapes_2019(void **state)
{
    (void)state;
    rad_context *ctx = context();
    double v[3] = {0, 45, 90}, h[1] = {0};
    struct {
        double w, l, hh;
        rad_luminous_shape shape;
    } cases[] = {
        {0, 0, 0, RAD_OPENING_POINT},
        {0.3, 0.6, 0, RAD_OPENING_RECTANGLE},
        {0.3, 0.6, 0.1, RAD_OPENING_BOX},
        {-0.2, -0.2, 0, RAD_OPENING_ELLIPSE},
        {-0.2, -0.3, 0, RAD_OPENING_ELLIPSE},
        {-0.2, -0.2, 0.4, RAD_OPENING_VERTICAL_CYLINDER},
        {-0.25, -0.25, -0.25, RAD_OPENING_ELLIPSOID},
        {-0.1, 1.2, -0.1, RAD_OPENING_CYLINDER_X},
        {1.2, -0.1, -0.1, RAD_OPENING_CYLINDER_Y},
        {-0.2, 0, -0.2, RAD_OPENING_VERTICAL_ELLIPSE_X},
        {0, -0.2, -0.2, RAD_OPENING_VERTICAL_ELLIPSE_Y},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        ies_spec s = ies_default(3, v, 1, h, flat);
        s.first = "IES:LM-63-2019";
        s.width = cases[k].w, s.length = cases[k].l, s.height = cases[k].hh;
        char name[32];
        snprintf(name, sizeof name, "shape%zu.ies", k);
        rad_photometry *p = load(ctx, write_ies(name, &s));
        assert_int_equal(p->shape, cases[k].shape);
        assert_true(p->width == fabs(cases[k].w) && p->length == fabs(cases[k].l) && p->height == fabs(cases[k].hh));
        rad_photometry_free(p);
    }
    /* EULUMDAT: width 0 = round, of diameter `length` */
    double c1[1] = {0};
    rad_photometry *p = load(ctx, write_ldt("round.ldt", 1, 1, c1, 3, v, flat, 1000.0, 100.0, 1));
    assert_int_equal(p->shape, RAD_OPENING_RECTANGLE); /* 500 x 400 mm */
    assert_true(fabs(p->length - 0.5) < 1e-15 && fabs(p->width - 0.4) < 1e-15);
    rad_photometry_free(p);
    rad_context_destroy(ctx);
}

/* ---- lumens ---- */

static double lambert(double h, double v)
{
    (void)h;
    return v < 90.0 ? 1000.0 / M_PI * cos(v * DEG) : 0.0;
}

static void test_lumens(void **state)
{
    (void)state;
    rad_context *ctx = context();
    /* 1000/pi cos(gamma) cd: 1000 lm, less h^2/4 = 7.6e-5 at 1 degree */
    double v[91], c1[1] = {0};
    for (int i = 0; i <= 90; i++)
        v[i] = i;
    ies_spec s = ies_default(91, v, 1, c1, lambert);
    rad_photometry *p = load(ctx, write_ies("lumens.ies", &s));
    assert_true(fabs(p->flux - 1000.0) < 1e-3 * 1000.0);
    assert_true(fabs(rad_photometry_lor(p) - 1.0) < 1e-3);
    rad_photometry_free(p);
    /* EULUMDAT: 2500 lm lamps, cd/klm so the luminaire gives 2500 x 0.8:
     * LORL 80 %, no warning; the same file with LORL 60 % warns */
    g_warnings = 0;
    p = load(ctx, write_ldt("lumens.ldt", 1, 1, c1, 91, v, lambert, 1250.0, 80.0, 1));
    assert_true(fabs(p->flux - 1000.0) < 1e-3 * 1000.0);
    assert_true(p->rated_lumens == 1250.0 && fabs(rad_photometry_lor(p) - 0.8) < 1e-3);
    assert_true(p->stated_lor == 0.8);
    assert_int_equal(g_warnings, 0);
    rad_photometry_free(p);
    p = load(ctx, write_ldt("lumens60.ldt", 1, 1, c1, 91, v, lambert, 1250.0, 60.0, 1));
    assert_int_equal(g_warnings, 1);
    assert_non_null(strstr(g_warning, "lumens60.ldt: the intensities integrate to"));
    rad_photometry_free(p);
    /* EULUMDAT absolute photometry (negative lamp count): no rated lumens */
    g_warnings = 0;
    p = load(ctx, write_ldt("absolute.ldt", 1, 1, c1, 91, v, lambert, 1000.0, 100.0, -1));
    assert_true(p->rated_lumens == 0.0 && fabs(p->flux - 1000.0) < 1.0);
    assert_int_equal(g_warnings, 0);
    rad_photometry_free(p);
    rad_context_destroy(ctx);
}

/* ---- malformed files ---- */

static void test_malformed(void **state)
{
    (void)state;
    rad_context *ctx = context();
    struct {
        const char *file;
        rad_result result;
        const char *message;
    } cases[] = {
        {"truncated.ies", RAD_ERROR_PARSE, "truncated.ies:7: expected 3 vertical angles, found 2 (the file ends)"},
        {"token.ies", RAD_ERROR_PARSE, "token.ies:7: expected 3 vertical angles, found 2, then 'abc'"},
        {"negative.ies", RAD_ERROR_PARSE, "negative.ies:9: candela values: -5 is negative (value 2 of 3)"},
        {"nan.ies", RAD_ERROR_PARSE, "nan.ies:9: expected 3 candela values, found 1, then 'nan'"},
        {"order.ies", RAD_ERROR_PARSE, "order.ies:7: vertical angles not increasing: 45 after 90"},
        {"type.ies", RAD_ERROR_PARSE, "type.ies:5: photometric type (1 C, 2 B, 3 A): expected a whole number from 1 to 3, found 4"},
        {"units.ies", RAD_ERROR_PARSE, "units.ies:5: units type (1 feet, 2 metres): expected a whole number from 1 to 2, found 3"},
        {"counts.ies", RAD_ERROR_PARSE, "counts.ies:5: number of vertical angles: expected a whole number from 2 to"},
        {"symmetry.ies", RAD_ERROR_PARSE, "symmetry.ies:8: horizontal angles from 0 to 120: not a symmetry of LM-63"},
        {"vrange.ies", RAD_ERROR_PARSE, "vrange.ies:7: vertical angles from -10 to 90: type C needs 0 to 180"},
        {"notilt.ies", RAD_ERROR_PARSE, "notilt.ies:5: no TILT= line"},
        {"version.ies", RAD_ERROR_PARSE, "version.ies:1: unknown LM-63 version 'IESNA:LM-63-2099'"},
        {"tiltfile.ies", RAD_ERROR_IO, "tiltfile.ies:2: TILT=nothere.tlt: cannot open"},
        {"multiplier.ies", RAD_ERROR_PARSE, "multiplier.ies:5: candela multiplier 0: expected a positive number"},
        {"lumens.ies", RAD_ERROR_PARSE, "lumens.ies:5: lumens per lamp 0: expected a positive number, or -1"},
        {"ballast.ies", RAD_ERROR_PARSE, "ballast.ies:6: ballast factor -1: expected a positive number"},
        {"tiltgeometry.ies", RAD_ERROR_PARSE, "tiltgeometry.ies:3: lamp-to-luminaire geometry: expected a whole number from 1 to 3, found 5"},
        {"typeb.ies", RAD_ERROR_PARSE, "typeb.ies:8: horizontal angles from 0 to 45: type B needs -90 to 90"},
        {"tiltorder.ies", RAD_ERROR_PARSE, "tiltorder.ies:5: tilt angles not increasing: 30 after 60"},
        {"outside.ies", RAD_ERROR_IO, "outside.ies: refers to"},
        {"isym.ldt", RAD_ERROR_PARSE, "isym.ldt:3: symmetry indicator Isym: expected a whole number from 0 to 4, found 7"},
        {"truncated.ldt", RAD_ERROR_PARSE, "truncated.ldt:72: expected 19 intensities (cd/klm), found 10 (the file ends)"},
        {"mc.ldt", RAD_ERROR_PARSE, "mc.ldt:4: Mc = 6 C planes cannot hold symmetry Isym 4"},
        {"cangles.ldt", RAD_ERROR_PARSE, "cangles.ldt:45: C angles not increasing: 80 after 90"},
        {"cf.ldt", RAD_ERROR_PARSE, "cf.ldt:24: conversion factor 0: expected a positive number"},
        {"header.ldt", RAD_ERROR_PARSE, "header.ldt:4: expected number of C planes Mc (a number), found 'x'"},
        {"empty.ldt", RAD_ERROR_PARSE, "empty.ldt:1: empty file"},
        {"negative.ldt", RAD_ERROR_PARSE, "negative.ldt:48: intensities (cd/klm): -1 is negative (value 2 of 3)"},
        {"gamma.ldt", RAD_ERROR_PARSE, "gamma.ldt:46: gamma angles from 0 to 190: expected 0 to 180"},
        {"lamps.ldt", RAD_ERROR_PARSE, "lamps.ldt:27: number of lamps 0: expected a whole number, not 0"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char path[512];
        snprintf(path, sizeof path, "%s/bad/%s", DATA, cases[k].file);
        rad_photometry *p = (rad_photometry *)1;
        rad_api_enter(ctx); /* each load is a call of its own: its first error is kept */
        rad_result r = rad_photometry_load(ctx, path, &p);
        const char *message = rad_context_error(ctx);
        if (r != cases[k].result || !strstr(message, cases[k].message) || strchr(message, '\n'))
            fail_msg("%s: %s, '%s'; expected %s, '%s'", cases[k].file, rad_result_string(r), message,
                     rad_result_string(cases[k].result), cases[k].message);
        assert_null(p);
        /* the public summary fails the same way, its struct zeroed */
        rad_photometry_info info;
        memset(&info, 0xff, sizeof info);
        assert_int_equal(rad_photometry_info_read(ctx, path, &info), cases[k].result);
        assert_non_null(strstr(rad_context_error(ctx), cases[k].message));
        assert_true(info.format[0] == '\0' && info.flux == 0.0);
    }
    rad_context_destroy(ctx);
}

/* The data file the docs quote, and the memory path. */
static void test_data_file_and_memory(void **state)
{
    (void)state;
    rad_context *ctx = context();
    rad_photometry *p = load(ctx, DATA "/downlight_2002.ies");
    assert_string_equal(p->label, "test downlight");
    assert_true(fabs(rad_photometry_intensity(p, direction(0, 22.5)) - 90.0) < 1e-12);
    rad_photometry_free(p);
    const char plain[] = "IESNA:LM-63-2002\nTILT=none\n1,-1,1,2,1,1,2,0,0,0,1,1,0,0,180,0,50,50";
    assert_int_equal(rad_photometry_parse(ctx, "mem.ies", NULL, plain, sizeof plain - 1, &p), RAD_OK);
    assert_true(fabs(p->flux - 4.0 * M_PI * 50.0) < 1e-12 * p->flux);
    rad_photometry_free(p);
    /* CRLF line ends, keyword lines, a 1991 first line, TILT=INCLUDE over
     * several lines */
    const char crlf[] = "IESNA91\r\n[LUMINAIRE] crlf lamp\r\n[MORE] second line\r\nTILT=INCLUDE\r\n1\r\n2\r\n0 90\r\n"
                        "1 0.5\r\n1 -1 1 2 1 1 2 0 0 0\r\n1 1 0\r\n0 180\r\n0\r\n40 40\r\n";
    assert_int_equal(rad_photometry_parse(ctx, "crlf.ies", NULL, crlf, sizeof crlf - 1, &p), RAD_OK);
    assert_string_equal(p->label, "crlf lamp");
    assert_string_equal(p->version, "LM-63-1991");
    assert_true(fabs(p->flux - 4.0 * M_PI * 40.0) < 1e-12 * p->flux);
    assert_true(fabs(rad_photometry_tilt_factor(p, 45) - 0.75) < 1e-15);
    rad_photometry_free(p);
    rad_api_enter(ctx);
    const char tilted[] = "IESNA:LM-63-2002\nTILT=x.tlt\n1,-1,1,2,1,1,2,0,0,0,1,1,0,0,180,0,50,50";
    assert_int_equal(rad_photometry_parse(ctx, "mem.ies", NULL, tilted, sizeof tilted - 1, &p), RAD_ERROR_PARSE);
    assert_null(p);
    rad_context_destroy(ctx);
}

/* Every allocation of a load failing in turn: RAD_ERROR_OUT_OF_MEMORY,
 * no distribution, nothing left in use (ASan checks the frees). */
static void test_allocation_failures(void **state)
{
    (void)state;
    rad_context *ctx = context();
    double v[19], h[25], c1[1] = {0};
    for (int i = 0; i < 19; i++)
        v[i] = 10.0 * i;
    for (int i = 0; i < 25; i++)
        h[i] = 15.0 * i;
    test_text t = {0};
    test_put(&t, "1\n2\n0 90\n1 0.5\n");
    save("alloc.tlt", &t);
    ies_spec s = ies_default(19, v, 7, h, quad);
    s.tilt = "alloc.tlt";
    const char *files[4];
    char names[4][512];
    snprintf(names[0], sizeof names[0], "%s", write_ies("alloc_c.ies", &s));
    s.tilt = NULL, s.type = 2, s.nh = 10, s.h = v, s.v = v, s.nv = 10; /* B: 0..90 both */
    snprintf(names[1], sizeof names[1], "%s", write_ies("alloc_b.ies", &s));
    snprintf(names[2], sizeof names[2], "%s", write_ldt("alloc3.ldt", 3, 24, h, 19, v, quad, 1000.0, 100.0, 1));
    snprintf(names[3], sizeof names[3], "%s", write_ldt("alloc1.ldt", 1, 1, c1, 19, v, rot, 1000.0, 100.0, 1));
    for (int f = 0; f < 4; f++) {
        files[f] = names[f];
        for (uint64_t k = 1;; k++) {
            rad_api_enter(ctx);
            rad_context_fail_allocation(ctx, k);
            rad_photometry *p = (rad_photometry *)1;
            rad_result r = rad_photometry_load(ctx, files[f], &p);
            rad_context_fail_allocation(ctx, 0);
            if (r == RAD_OK) {
                assert_true(k > 3); /* it did allocate */
                rad_photometry_free(p);
                break;
            }
            assert_int_equal(r, RAD_ERROR_OUT_OF_MEMORY);
            assert_null(p);
            assert_int_equal(rad_memory_in_use(ctx, RAD_MEM_CATEGORIES), 0);
        }
    }
    rad_context_destroy(ctx);
}

/* `radiosity photometry FILE...`: the summary's lines, and a bad file
 * named on stderr with status 1 while the good one is still printed. */
static const char *g_binary;

static void test_command(void **state)
{
    (void)state;
    if (!g_binary)
        skip();
    char command[1400], output[8192];
    snprintf(command, sizeof command, "'%s' photometry '%s' '%s/bad/negative.ldt' 2>&1; echo status $?", g_binary,
             DATA "/downlight_2002.ies", DATA);
    FILE *f = popen(command, "r");
    assert_non_null(f);
    size_t n = fread(output, 1, sizeof output - 1, f);
    output[n] = '\0';
    pclose(f);
    /* 100 cd at 0, 80 at 45, 0 at 90 over the lower hemisphere, bilinear:
     * the closed form per cell (photometry.c) gives 327.73 lm */
    assert_non_null(strstr(output, "downlight_2002.ies: IES LM-63-2002, type C, \"test downlight\""));
    assert_non_null(strstr(output, "  symmetry      rotational (C 0)"));
    assert_non_null(strstr(output, "  maximum       100 cd at C 0, gamma 0"));
    assert_non_null(strstr(output, "  flux          327.73 lm"));
    assert_non_null(strstr(output, "  rated lumens  1000 lm, light output ratio 0.3277"));
    assert_non_null(strstr(output, "radiosity: " DATA "/bad/negative.ldt:48: intensities (cd/klm): -1 is negative"));
    assert_non_null(strstr(output, "status 1"));
    snprintf(command, sizeof command, "'%s' photometry 2>&1; echo status $?", g_binary);
    f = popen(command, "r");
    n = fread(output, 1, sizeof output - 1, f);
    output[n] = '\0';
    pclose(f);
    assert_non_null(strstr(output, "no photometric file given"));
    assert_non_null(strstr(output, "status 2"));
}

static int setup(void **state)
{
    (void)state;
    snprintf(g_dir, sizeof g_dir, "/tmp/test_photometry.XXXXXX");
    return mkdtemp(g_dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char command[600];
    snprintf(command, sizeof command, "rm -rf '%s'", g_dir);
    return system(command) == 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    g_binary = argc > 1 ? argv[1] : NULL;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flux_closed_forms),
        cmocka_unit_test(test_flux_against_quadrature),
        cmocka_unit_test(test_every_symmetry_same_distribution),
        cmocka_unit_test(test_c_frame),
        cmocka_unit_test(test_missing_hemisphere),
        cmocka_unit_test(test_types_b_and_a),
        cmocka_unit_test(test_tilt),
        cmocka_unit_test(test_multipliers_units_versions),
        cmocka_unit_test(test_shapes_2019),
        cmocka_unit_test(test_lumens),
        cmocka_unit_test(test_malformed),
        cmocka_unit_test(test_data_file_and_memory),
        cmocka_unit_test(test_allocation_failures),
        cmocka_unit_test(test_command),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
