/*
 * test_thermal.c -- radiative heat exchange (src/thermal/, docs/thermal.md).
 *
 * From exact form factors (the solve of thermal.h called directly):
 *   - a two-surface enclosure (a box's floor against its other five faces,
 *     F_12 = 1): the closed form q_1 = sigma (T1^4 - T2^4) /
 *     (1/eps1 + A1/A2 (1/eps2 - 1)), and the known-q row giving T back;
 *   - a long duct of 3-4-5 right-triangle section (2-D crossed-strings
 *     factors) with a re-radiating hypotenuse: the standard network
 *     (Incropera ch. 13) for Q_1 and the wall's temperature;
 *   - an open plate: q = eps sigma (T^4 - T_env^4);
 *   - energy: sum Q = 0 to 1e-9 of sum |Q| in a closed cube of exact
 *     factors with mixed conditions, and sum Q = the power to the
 *     environment in the open box; iterative solvers agree with LU;
 *   - Gebhart factors: rows sum to 1, eps_i A_i G_ij = eps_j A_j G_ji,
 *     G = F for black surfaces, and the exchange sum_j eps_i A_i G_ij
 *     sigma (T_i^4 - T_j^4) equal to the net-radiation Q_i;
 *   - refusals: a closed enclosure with heat fluxes only; a flux no
 *     temperature can give.
 * Through the library and the command: a closed box scene, its bc file,
 * the CSV and JSON written, and bad bc files named with their key.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "cli_support.h"
#include "radiosity.h"
#include "thermal/thermal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Relative error, measured against |b| (or 1 when b is 0). */
static double rel(double a, double b) { return fabs(a - b) / (b != 0.0 ? fabs(b) : 1.0); }

typedef struct problem {
    size_t n;
    double F[64];
    double area[8], eps[8], value[8];
    unsigned char known_t[8];
    double t_env;
    double J[8], G[8], q[8], T[8];
    rad_thermal_balance balance;
} problem;

static rad_result solve_with(rad_context *ctx, problem *pb, const char *solver, double tolerance)
{
    rad_thermal_system sys = {.n = pb->n, .F = pb->F, .area = pb->area, .emissivity = pb->eps,
                              .known_temperature = pb->known_t, .value = pb->value,
                              .environment_temperature = pb->t_env, .threads = 1};
    rad_thermal_fields out = {pb->J, pb->G, pb->q, pb->T};
    rad_solve_params p = {.tolerance = tolerance, .relaxation = 1.0};
    rad_solve_stats st;
    return rad_thermal_solve_system(ctx, &sys, rad_solver_find(solver), &p, &out, &pb->balance, &st);
}

static rad_context *context(void)
{
    rad_context *ctx = NULL;
    rad_context_options o = {.threads = 1};
    assert_int_equal(rad_context_create(&o, &ctx), RAD_OK);
    return ctx;
}

/* The floor (A1 = 1) of a closed unit cube against the other five faces
 * as one surface (A2 = 5): F_12 = 1, F_21 = 1/5, F_22 = 4/5. */
static void two_surface(problem *pb, double eps1, double eps2)
{
    memset(pb, 0, sizeof *pb);
    pb->n = 2;
    double F[4] = {0.0, 1.0, 0.2, 0.8};
    memcpy(pb->F, F, sizeof F);
    pb->area[0] = 1.0, pb->area[1] = 5.0;
    pb->eps[0] = eps1, pb->eps[1] = eps2;
}

static void test_two_surface_enclosure(void **state)
{
    (void)state;
    rad_context *ctx = context();
    problem pb;
    two_surface(&pb, 0.8, 0.5);
    pb.known_t[0] = pb.known_t[1] = 1;
    pb.value[0] = 1000.0, pb.value[1] = 500.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    double q1 = RAD_SIGMA * (pow(1000.0, 4) - pow(500.0, 4)) / (1.0 / 0.8 + (1.0 / 5.0) * (1.0 / 0.5 - 1.0));
    /* q1 = 30,067 W/m^2; without the (1 - eps) reflections it would be
     * eps1 sigma dT^4 = 42,524, with the sign wrong -q1. */
    assert_true(rel(pb.q[0], q1) < 1e-12);
    assert_true(rel(pb.q[1] * 5.0, -q1) < 1e-12);
    /* The surface resistance: J1 = Eb1 - q1 (1 - eps1) / eps1. */
    assert_true(rel(pb.J[0], RAD_SIGMA * 1e12 - q1 * 0.2 / 0.8) < 1e-12);
    assert_true(fabs(pb.balance.relative_imbalance) < 1e-12);

    /* The same flux given on the floor: its temperature comes back. */
    pb.known_t[0] = 0;
    pb.value[0] = q1;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    assert_true(rel(pb.T[0], 1000.0) < 1e-12);
    assert_true(rel(pb.q[0], q1) < 1e-10);
    rad_context_destroy(ctx);
}

/* A long duct of right-triangle section, legs 3 (surface 1) and 4
 * (surface 2), hypotenuse 5 (R), per metre of length.  Crossed strings
 * (Hottel): F_ij = (L_i + L_j - L_k) / (2 L_i). */
static void duct_345(problem *pb)
{
    memset(pb, 0, sizeof *pb);
    pb->n = 3;
    double L[3] = {3.0, 4.0, 5.0};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            pb->F[3 * i + j] = i == j ? 0.0 : (L[i] + L[j] - L[3 - i - j]) / (2.0 * L[i]);
    for (int i = 0; i < 3; i++)
        pb->area[i] = L[i];
}

static void test_reradiating_wall(void **state)
{
    (void)state;
    rad_context *ctx = context();
    problem pb;
    duct_345(&pb);
    double e1 = 0.6, e2 = 0.8, T1 = 800.0, T2 = 400.0;
    pb.eps[0] = e1, pb.eps[1] = e2, pb.eps[2] = 0.3; /* R's emissivity does not matter */
    pb.known_t[0] = pb.known_t[1] = 1;
    pb.value[0] = T1, pb.value[1] = T2, pb.value[2] = 0.0; /* R adiabatic */
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);

    /* The network: surface resistances (1 - eps)/(eps A), space
     * resistances 1/(A_i F_ij); R's node floats (re-radiating). */
    double A1F12 = 3.0 * pb.F[1], A1F1R = 3.0 * pb.F[2], A2F2R = 4.0 * pb.F[5];
    double R1 = (1 - e1) / (e1 * 3.0), R2 = (1 - e2) / (e2 * 4.0);
    double Req = 1.0 / (A1F12 + 1.0 / (1.0 / A1F1R + 1.0 / A2F2R));
    double Eb1 = RAD_SIGMA * pow(T1, 4), Eb2 = RAD_SIGMA * pow(T2, 4);
    double Q1 = (Eb1 - Eb2) / (R1 + Req + R2);
    double J1 = Eb1 - Q1 * R1, J2 = Eb2 + Q1 * R2;
    double JR = (J1 * A1F1R + J2 * A2F2R) / (A1F1R + A2F2R);
    double TR = pow(JR / RAD_SIGMA, 0.25);
    assert_true(rel(3.0 * pb.q[0], Q1) < 1e-12);
    assert_true(rel(4.0 * pb.q[1], -Q1) < 1e-12);
    assert_true(fabs(5.0 * pb.q[2]) < 1e-9 * Q1);
    assert_true(rel(pb.T[2], TR) < 1e-12);
    /* Its emissivity must not matter: a re-radiating wall is as white. */
    pb.eps[2] = 1.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    assert_true(rel(pb.T[2], TR) < 1e-12);
    assert_true(rel(3.0 * pb.q[0], Q1) < 1e-12);
    rad_context_destroy(ctx);
}

static void test_open_plate(void **state)
{
    (void)state;
    rad_context *ctx = context();
    problem pb;
    memset(&pb, 0, sizeof pb);
    pb.n = 1;
    pb.area[0] = 2.0, pb.eps[0] = 0.7, pb.known_t[0] = 1, pb.value[0] = 350.0, pb.t_env = 3.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    double q = 0.7 * RAD_SIGMA * (pow(350.0, 4) - pow(3.0, 4));
    assert_true(rel(pb.q[0], q) < 1e-12);
    assert_true(rel(pb.balance.environment_power, 2.0 * q) < 1e-12);
    assert_true(rel(pb.balance.net_power, 2.0 * q) < 1e-12);
    /* A heated plate in a 250 K environment: 100 W/m^2 leaving it. */
    pb.known_t[0] = 0, pb.value[0] = 100.0, pb.t_env = 250.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    assert_true(rel(pb.T[0], pow(100.0 / (0.7 * RAD_SIGMA) + pow(250.0, 4), 0.25)) < 1e-12);
    /* Cooled by more than it can absorb from a 3 K sky: refused. */
    pb.value[0] = -100.0, pb.t_env = 3.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "no temperature gives it"));
    rad_context_destroy(ctx);
}

/* Aligned parallel squares of side 1 at distance 1 (Hottel; Howell's
 * catalogue C-11). */
static double opposite_unit_squares(void)
{
    double X = 1.0, Y = 1.0;
    return 2.0 / (M_PI * X * Y) *
           (0.5 * log((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y)) +
            X * sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y)) + Y * sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) -
            X * atan(X) - Y * atan(Y));
}

/* The unit cube's six faces, 0/1, 2/3, 4/5 opposite; adjacent factors
 * (1 - F_opp) / 4, so rows sum to 1 and F is symmetric (exactly
 * reciprocal: equal areas).  `faces` 5 leaves out face 5 (an open box). */
static void cube(problem *pb, size_t faces)
{
    memset(pb, 0, sizeof *pb);
    pb->n = faces;
    double fo = opposite_unit_squares(), fa = (1.0 - fo) / 4.0;
    for (size_t i = 0; i < faces; i++) {
        pb->area[i] = 1.0;
        for (size_t j = 0; j < faces; j++)
            pb->F[faces * i + j] = i == j ? 0.0 : (i ^ 1) == j ? fo : fa;
    }
}

static void mixed_conditions(problem *pb)
{
    static const double eps[6] = {0.9, 0.3, 0.55, 1.0, 0.7, 0.15};
    static const unsigned char known_t[6] = {1, 0, 1, 0, 0, 1};
    static const double value[6] = {1200.0, 0.0, 300.0, -2.0e4, 5.0e4, 600.0};
    for (size_t i = 0; i < pb->n; i++)
        pb->eps[i] = eps[i], pb->known_t[i] = known_t[i], pb->value[i] = value[i];
}

static void test_energy_balance(void **state)
{
    (void)state;
    rad_context *ctx = context();
    problem pb, ref;
    cube(&pb, 6);
    mixed_conditions(&pb);
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    double sum = 0.0, scale = 0.0;
    for (size_t i = 0; i < 6; i++)
        sum += pb.q[i], scale += fabs(pb.q[i]);
    assert_true(fabs(sum) <= 1e-9 * scale);
    assert_true(fabs(pb.balance.relative_imbalance) <= 1e-9);
    assert_true(fabs(pb.balance.environment_power) <= 1e-9 * scale);
    /* The known fluxes come back, and the adiabatic face carries nothing. */
    assert_true(rel(pb.q[3], -2.0e4) < 1e-9 && rel(pb.q[4], 5.0e4) < 1e-9);
    assert_true(fabs(pb.q[1]) < 1e-9 * scale);

    /* The iterative solvers of the table agree with LU. */
    ref = pb;
    static const char *const iterative[] = {"gauss-seidel", "jacobi", "conjugate-gradient"};
    for (size_t k = 0; k < 3; k++) {
        problem it;
        cube(&it, 6);
        mixed_conditions(&it);
        assert_int_equal(solve_with(ctx, &it, iterative[k], 1e-12), RAD_OK);
        for (size_t i = 0; i < 6; i++) {
            assert_true(rel(it.J[i], ref.J[i]) < 1e-8);
            assert_true(rel(it.T[i], ref.T[i]) < 1e-8);
        }
    }

    /* Open: the lid gone, a 280 K environment.  The surfaces' net power is
     * what goes to the environment. */
    cube(&pb, 5);
    mixed_conditions(&pb);
    pb.t_env = 280.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    assert_true(fabs(pb.balance.environment_power) > 1e3);
    assert_true(fabs(pb.balance.relative_imbalance) <= 1e-9);
    assert_true(rel(pb.balance.net_power, pb.balance.environment_power) < 1e-9);
    rad_context_destroy(ctx);
}

static void test_gebhart(void **state)
{
    (void)state;
    rad_context *ctx = context();
    problem pb;
    cube(&pb, 6);
    mixed_conditions(&pb);
    uint32_t surface[6] = {0, 1, 2, 3, 4, 5};
    rad_thermal_system sys = {.n = 6, .F = pb.F, .area = pb.area, .emissivity = pb.eps,
                              .known_temperature = pb.known_t, .value = pb.value, .surface = surface, .threads = 1};
    rad_solve_params p = {.tolerance = 1e-12, .relaxation = 1.0};
    double G[36];
    assert_int_equal(rad_thermal_gebhart_factors(ctx, &sys, 6, NULL, &p, G), RAD_OK);
    for (size_t i = 0; i < 6; i++) {
        double row = 0.0;
        for (size_t j = 0; j < 6; j++) {
            row += G[6 * i + j];
            double a = pb.eps[i] * pb.area[i] * G[6 * i + j], b = pb.eps[j] * pb.area[j] * G[6 * j + i];
            assert_true(fabs(a - b) < 1e-12);
        }
        assert_true(fabs(row - 1.0) < 1e-12);
    }
    /* Every face at a temperature: Q_i = sum_j eps_i A_i G_ij sigma (T_i^4 - T_j^4). */
    static const double T[6] = {1200.0, 450.0, 300.0, 800.0, 700.0, 600.0};
    for (size_t i = 0; i < 6; i++)
        pb.known_t[i] = 1, pb.value[i] = T[i];
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    for (size_t i = 0; i < 6; i++) {
        double Q = 0.0;
        for (size_t j = 0; j < 6; j++)
            Q += pb.eps[i] * pb.area[i] * G[6 * i + j] * RAD_SIGMA * (pow(T[i], 4) - pow(T[j], 4));
        assert_true(rel(pb.q[i] * pb.area[i], Q) < 1e-9);
    }
    /* Black faces: G = F. */
    for (size_t i = 0; i < 6; i++)
        pb.eps[i] = 1.0;
    assert_int_equal(rad_thermal_gebhart_factors(ctx, &sys, 6, NULL, &p, G), RAD_OK);
    for (size_t k = 0; k < 36; k++)
        assert_true(fabs(G[k] - pb.F[k]) < 1e-15);
    /* Two surfaces of three faces each: rows still sum to 1. */
    uint32_t halves[6] = {0, 0, 0, 1, 1, 1};
    sys.surface = halves;
    pb.eps[0] = 0.2, pb.eps[4] = 0.5;
    assert_int_equal(rad_thermal_gebhart_factors(ctx, &sys, 2, NULL, &p, G), RAD_OK);
    assert_true(fabs(G[0] + G[1] - 1.0) < 1e-12 && fabs(G[2] + G[3] - 1.0) < 1e-12);
    assert_true(fabs((0.2 + 1 + 1) * G[1] - (1 + 0.5 + 1) * G[2]) < 1e-12);
    rad_context_destroy(ctx);
}

static void test_undetermined(void **state)
{
    (void)state;
    rad_context *ctx = context();
    problem pb;
    cube(&pb, 6);
    for (size_t i = 0; i < 6; i++)
        pb.eps[i] = 0.5, pb.known_t[i] = 0, pb.value[i] = i == 0 ? 100.0 : -20.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "closed enclosure"));
    /* One known temperature settles it. */
    pb.known_t[2] = 1, pb.value[2] = 400.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    /* Open, the same fluxes are determined by the environment. */
    cube(&pb, 5);
    for (size_t i = 0; i < 5; i++)
        pb.eps[i] = 0.5, pb.known_t[i] = 0, pb.value[i] = 100.0;
    pb.t_env = 300.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    assert_true(rel(pb.balance.net_power, 500.0) < 1e-9);
    rad_context_destroy(ctx);
}

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_surface_enclosure),
        cmocka_unit_test(test_reradiating_wall),
        cmocka_unit_test(test_open_plate),
        cmocka_unit_test(test_energy_balance),
        cmocka_unit_test(test_gebhart),
        cmocka_unit_test(test_undetermined),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
