/*
 * sky.c -- the luminance of the CIE skies (docs/lighting.md "Daylight").
 *
 * CIE standard general sky (CIE S 011/E:2003 = ISO 15469:2004, after
 * Kittler, Perez & Darula 1998): with Z a direction's zenith angle, Zs the
 * sun's, and chi the angle between the direction and the sun,
 *
 *     L / Lz = f(chi) phi(Z) / (f(Zs) phi(0))
 *     phi(Z)   = 1 + a exp(b / cos Z)       (phi -> 1 at the horizon, b < 0;
 *                                            phi(0) = 1 + a exp(b))
 *     f(chi)   = 1 + c (exp(d chi) - exp(d pi/2)) + e cos^2 chi
 *
 * the 15 types' (a, b, c, d, e) in light/daylight_file.c.  Traditional CIE
 * overcast sky (Moon & Spencer 1942; CIE 1955): L = Lz (1 + 2 cos Z) / 3,
 * whose horizontal illuminance is exactly 7 pi Lz / 9.
 *
 * Luminance enters as L / 179 W/(m^2 sr) on each channel (docs/units.md
 * "Photometry").
 */
#include "light/sky.h"

#include "photometry/photometry.h"

#include <math.h>

/* Unit direction a and b: the angle between them, accurate near 0 and pi. */
static double angle_between(vec3 a, vec3 b)
{
    return atan2(v3_length(v3_cross(a, b)), v3_dot(a, b));
}

static double indicatrix(const rad_sky *s, double chi)
{
    double cc = cos(chi);
    return 1.0 + s->c * (exp(s->d * chi) - exp(s->d * 0.5 * M_PI)) + s->e * cc * cc;
}

double rad_sky_relative(const rad_sky *sky, vec3 d)
{
    double cz = v3_dot(d, sky->up);
    if (!(cz > 0.0))
        return 0.0;
    if (sky->model == RAD_SKY_CIE_OVERCAST)
        return (1.0 + 2.0 * cz) / 3.0;
    double gradation = 1.0 + sky->a * exp(sky->b / cz);
    return indicatrix(sky, angle_between(d, sky->sun)) * gradation * sky->norm;
}

double rad_daylight_radiance(const rad_daylight *daylight, vec3 d)
{
    double cz = v3_dot(d, daylight->sky.up);
    if (cz > 0.0)
        return daylight->sky.zenith_radiance * rad_sky_relative(&daylight->sky, d);
    return daylight->ground ? daylight->ground_radiance : 0.0;
}

/* Gauss-Legendre nodes and weights on [0, 1], n <= 256 (Newton on the
 * Legendre polynomial from the Chebyshev guess; Golub-Welsch would do as
 * well). */
static void gauss_legendre01(int n, double *x, double *w)
{
    for (int i = 0; i < (n + 1) / 2; i++) {
        double z = cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; it++) {
            double p0 = 1.0, p1 = z;
            for (int k = 2; k <= n; k++) {
                double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            if (n == 1)
                p1 = z, p0 = 1.0;
            dp = n * (z * p1 - p0) / (z * z - 1.0);
            double dz = p1 / dp;
            z -= dz;
            if (fabs(dz) < 1e-16)
                break;
        }
        double wt = 2.0 / ((1.0 - z * z) * dp * dp);
        x[i] = 0.5 * (1.0 - z);
        x[n - 1 - i] = 0.5 * (1.0 + z);
        w[i] = w[n - 1 - i] = 0.5 * wt;
    }
}

double rad_sky_relative_horizontal(const rad_sky *sky, int order)
{
    enum { MAX_ORDER = 256 };
    int n = order > 0 && order <= MAX_ORDER ? order : 64, m = 4 * n;
    double x[MAX_ORDER], w[MAX_ORDER];
    gauss_legendre01(n, x, w);
    /* Polar frame about the sun: s, u (toward the zenith), v. */
    vec3 s = sky->sun, up = sky->up;
    vec3 u = v3_sub(up, v3_scale(s, v3_dot(up, s)));
    if (v3_length(u) < 1e-12)
        u = sky->north;
    u = v3_normalize(u);
    vec3 v = v3_cross(s, u);
    double cs = v3_dot(s, up), su = v3_dot(u, up);
    double sum = 0.0;
    for (int j = 0; j < m; j++) {
        double psi = 2.0 * M_PI * (j + 0.5) / m;
        /* Where the circle of directions at angle psi meets the horizon:
         * cos chi cs + sin chi cos psi su = 0. */
        double chi_h = atan2(cs, -cos(psi) * su);
        vec3 across = v3_add(v3_scale(u, cos(psi)), v3_scale(v, sin(psi)));
        double inner = 0.0;
        for (int i = 0; i < n; i++) {
            double chi = chi_h * x[i];
            vec3 d = v3_add(v3_scale(s, cos(chi)), v3_scale(across, sin(chi)));
            double cz = v3_dot(d, up);
            if (cz > 0.0)
                inner += w[i] * rad_sky_relative(sky, d) * cz * sin(chi);
        }
        sum += inner * chi_h;
    }
    return sum * 2.0 * M_PI / m;
}

void rad_sky_prepare(rad_daylight *daylight)
{
    rad_sky *sky = &daylight->sky;
    if (sky->model == RAD_SKY_CIE_GENERAL) {
        double chi_zenith = sky->sun_zenith;
        sky->norm = 1.0 / (indicatrix(sky, chi_zenith) * (1.0 + sky->a * exp(sky->b)));
    } else {
        sky->norm = 1.0;
    }
    double relative = rad_sky_relative_horizontal(sky, 0);
    if (daylight->zenith_luminance > 0.0)
        sky->zenith_radiance = daylight->zenith_luminance / RAD_LUMINOUS_EFFICACY;
    else
        sky->zenith_radiance = daylight->diffuse_illuminance / RAD_LUMINOUS_EFFICACY / relative;
    sky->horizontal = sky->zenith_radiance * relative;
    double sun = daylight->sun_normal * cos(sky->sun_zenith);
    daylight->ground_radiance = daylight->ground ? daylight->ground_reflectance * (sky->horizontal + sun) / M_PI : 0.0;
}
