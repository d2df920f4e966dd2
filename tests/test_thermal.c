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
    rad_context *ctx = test_context(1);
    problem pb;
    two_surface(&pb, 0.8, 0.5);
    pb.known_t[0] = pb.known_t[1] = 1;
    pb.value[0] = 1000.0, pb.value[1] = 500.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    double q1 = RAD_SIGMA * (pow(1000.0, 4) - pow(500.0, 4)) / (1.0 / 0.8 + (1.0 / 5.0) * (1.0 / 0.5 - 1.0));
    /* q1 = 36,662 W/m^2; without the walls' reflections (1/eps2 - 1) it
     * would be 42,528, with the sign wrong -q1. */
    print_message("two-surface: q1 %.10g W/m^2, closed form %.10g, error %.2g\n", pb.q[0], q1, rel(pb.q[0], q1));
    assert_true(rel(pb.q[0], q1) < 1e-12);
    assert_true(rel(pb.q[1] * 5.0, -q1) < 1e-12);
    /* The surface resistance: J1 = Eb1 - q1 (1 - eps1) / eps1. */
    assert_true(rel(pb.J[0], RAD_SIGMA * 1e12 - q1 * 0.2 / 0.8) < 1e-12);
    assert_true(fabs(pb.balance.relative_imbalance) < 1e-12);

    /* The same flux given on the floor: its temperature comes back. */
    pb.known_t[0] = 0;
    pb.value[0] = q1;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    print_message("two-surface: T1 from q1 %.12g K, error %.2g\n", pb.T[0], rel(pb.T[0], 1000.0));
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
    rad_context *ctx = test_context(1);
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
    print_message("3-4-5 duct: Q1 %.10g W/m (network %.10g, error %.2g), T_R %.10g K (%.10g, %.2g)\n", 3.0 * pb.q[0],
                  Q1, rel(3.0 * pb.q[0], Q1), pb.T[2], TR, rel(pb.T[2], TR));
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
    rad_context *ctx = test_context(1);
    problem pb;
    memset(&pb, 0, sizeof pb);
    pb.n = 1;
    pb.area[0] = 2.0, pb.eps[0] = 0.7, pb.known_t[0] = 1, pb.value[0] = 350.0, pb.t_env = 3.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    double q = 0.7 * RAD_SIGMA * (pow(350.0, 4) - pow(3.0, 4));
    print_message("open plate: q %.10g W/m^2 (%.10g, error %.2g)\n", pb.q[0], q, rel(pb.q[0], q));
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
    rad_context *ctx = test_context(1);
    problem pb, ref;
    cube(&pb, 6);
    mixed_conditions(&pb);
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    double sum = 0.0, scale = 0.0;
    for (size_t i = 0; i < 6; i++)
        sum += pb.q[i], scale += fabs(pb.q[i]);
    print_message("closed cube, mixed conditions: sum q %.2g of sum |q|\n", sum / scale);
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
        double worst = 0.0;
        for (size_t i = 0; i < 6; i++) {
            worst = fmax(worst, fmax(rel(it.J[i], ref.J[i]), rel(it.T[i], ref.T[i])));
            assert_true(rel(it.J[i], ref.J[i]) < 1e-8);
            assert_true(rel(it.T[i], ref.T[i]) < 1e-8);
        }
        print_message("closed cube, %s against LU: J and T within %.2g\n", iterative[k], worst);
    }

    /* Open: the lid gone, a 280 K environment.  The surfaces' net power is
     * what goes to the environment. */
    cube(&pb, 5);
    mixed_conditions(&pb);
    pb.t_env = 280.0;
    assert_int_equal(solve_with(ctx, &pb, "direct", 1e-12), RAD_OK);
    print_message("open box: sum Q %.10g W, to the environment %.10g W, imbalance %.2g of sum |Q|\n",
                  pb.balance.net_power, pb.balance.environment_power, pb.balance.relative_imbalance);
    assert_true(fabs(pb.balance.environment_power) > 1e3);
    assert_true(fabs(pb.balance.relative_imbalance) <= 1e-9);
    assert_true(rel(pb.balance.net_power, pb.balance.environment_power) < 1e-9);
    rad_context_destroy(ctx);
}

static void test_gebhart(void **state)
{
    (void)state;
    rad_context *ctx = test_context(1);
    problem pb;
    cube(&pb, 6);
    mixed_conditions(&pb);
    uint32_t surface[6] = {0, 1, 2, 3, 4, 5};
    rad_thermal_system sys = {.n = 6, .F = pb.F, .area = pb.area, .emissivity = pb.eps,
                              .known_temperature = pb.known_t, .value = pb.value, .surface = surface, .threads = 1};
    rad_solve_params p = {.tolerance = 1e-12, .relaxation = 1.0};
    double G[36];
    assert_int_equal(rad_thermal_gebhart_factors(ctx, &sys, 6, NULL, &p, G), RAD_OK);
    double worst_row = 0.0, worst_reciprocity = 0.0, worst_exchange = 0.0;
    for (size_t i = 0; i < 6; i++) {
        double row = 0.0;
        for (size_t j = 0; j < 6; j++) {
            row += G[6 * i + j];
            double a = pb.eps[i] * pb.area[i] * G[6 * i + j], b = pb.eps[j] * pb.area[j] * G[6 * j + i];
            worst_reciprocity = fmax(worst_reciprocity, fabs(a - b));
            assert_true(fabs(a - b) < 1e-12);
        }
        worst_row = fmax(worst_row, fabs(row - 1.0));
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
        worst_exchange = fmax(worst_exchange, rel(pb.q[i] * pb.area[i], Q));
        assert_true(rel(pb.q[i] * pb.area[i], Q) < 1e-9);
    }
    print_message("Gebhart, cube: rows 1 within %.2g, reciprocity within %.2g, exchange = Q within %.2g\n", worst_row,
                  worst_reciprocity, worst_exchange);
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
    rad_context *ctx = test_context(1);
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

/* ---- through the library: a closed unit cube, floor against the other five faces ---- */

/* The unit cube as "floor" (y = 0) and "walls" (the other five faces, one
 * surface), normals inwards, material Kd rho_floor / rho_walls and Ke as
 * given (W/(m^2 sr)); written to NAME.obj in the work folder. */
static void write_box(const char *name, double rho_floor, double ke_floor, double rho_walls, double ke_walls,
                      char *path, size_t size)
{
    snprintf(path, size, "%s/%s.obj", test_workdir(), name);
    char mtl[600];
    snprintf(mtl, sizeof mtl, "%s/%s.mtl", test_workdir(), name);
    FILE *m = fopen(mtl, "w");
    assert_non_null(m);
    fprintf(m, "newmtl f\nKd %.17g %.17g %.17g\nKe %.17g %.17g %.17g\n", rho_floor, rho_floor, rho_floor, ke_floor,
            ke_floor, ke_floor);
    fprintf(m, "newmtl w\nKd %.17g %.17g %.17g\nKe %.17g %.17g %.17g\n", rho_walls, rho_walls, rho_walls, ke_walls,
            ke_walls, ke_walls);
    fclose(m);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "mtllib %s.mtl\n"
               "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 0 1 0\nv 1 1 0\nv 1 1 1\nv 0 1 1\n"
               "o floor\nusemtl f\nf 1 4 3 2\n"
               "o walls\nusemtl w\nf 5 6 7 8\nf 1 5 8 4\nf 2 3 7 6\nf 1 2 6 5\nf 4 8 7 3\n",
            name);
    fclose(f);
}

typedef struct box_run {
    rad_context *ctx;
    rad_scene *scene;
    rad_solution *sol;
} box_run;

static void box_open(box_run *b, const char *path, double mesh_size, int closure)
{
    b->ctx = test_context(1);
    assert_int_equal(rad_scene_load_file(b->ctx, path, &b->scene), RAD_OK);
    rad_options o = {.solver = "direct", .mesh_size = mesh_size, .closure_correction = closure};
    assert_int_equal(rad_solution_create(b->ctx, b->scene, &o, &b->sol), RAD_OK);
}

static void box_close(box_run *b)
{
    rad_solution_destroy(b->sol);
    rad_scene_destroy(b->scene);
    rad_context_destroy(b->ctx);
}

static rad_thermal *box_solve(box_run *b, const char *bc)
{
    rad_thermal_conditions *c = NULL;
    if (rad_thermal_conditions_load_memory(b->ctx, b->scene, "bc.json", bc, strlen(bc), &c) != RAD_OK)
        fail_msg("%s", rad_context_error(b->ctx));
    rad_thermal *t = NULL;
    if (rad_thermal_solve(b->ctx, b->sol, c, NULL, &t) != RAD_OK)
        fail_msg("%s", rad_context_error(b->ctx));
    rad_thermal_conditions_destroy(c);
    return t;
}

/* Black walls at T2 make the walls' radiosity uniform, sigma T2^4, so the
 * floor of the meshed box has the two-surface answer exactly:
 * q = eps1 sigma (T1^4 - T2^4) on every element.  What the engine's F
 * adds is its closure error (the floor's rows sum to 1 + 4.6e-6 here:
 * q off by 3.1e-7); with --closure-correction none is left (1.4e-14). */
static void test_box_through_library(void **state)
{
    (void)state;
    char path[600];
    write_box("box", 0.5, 0.0, 0.5, 0.0, path, sizeof path);
    box_run b;
    box_open(&b, path, 0.25, 0);
    rad_thermal *t = box_solve(&b, "{\"surfaces\": {\"floor\": {\"emissivity\": 0.8, \"temperature\": 1000},"
                                   " \"walls\": {\"emissivity\": 1, \"temperature\": 500}}}");
    double q = 0.8 * RAD_SIGMA * (pow(1000.0, 4) - pow(500.0, 4));
    rad_thermal_values floor, walls;
    assert_true(rad_thermal_surface_values(t, 0, &floor) && rad_thermal_surface_values(t, 1, &walls));
    print_message("meshed box: floor q %.10g W/m^2 (%.10g, error %.2g)\n", floor.heat_flux, q, rel(floor.heat_flux, q));
    cli_assert_relative(floor.heat_flux, q, 1e-5, "floor q");
    cli_assert_relative(floor.area, 1.0, 1e-12, "floor area");
    cli_assert_relative(walls.area, 5.0, 1e-12, "walls area");
    cli_assert_relative(walls.heat, -q, 1e-4, "walls Q");
    assert_int_equal(floor.condition, RAD_THERMAL_TEMPERATURE);
    for (size_t i = 0; i < rad_solution_element_count(b.sol); i++) {
        rad_thermal_values v;
        assert_true(rad_thermal_element_values(t, i, &v));
        if (rad_solution_element_surface(b.sol, i) == 0)
            cli_assert_relative(v.heat_flux, q, 1e-5, "floor element q");
        else
            cli_assert_relative(v.radiosity, RAD_SIGMA * pow(500.0, 4), 1e-12, "black wall J");
    }
    rad_thermal_balance bal;
    double residual = rad_thermal_get_balance(t, &bal);
    assert_true(residual < 1e-10);
    assert_true(fabs(bal.relative_imbalance) < 1e-9);
    /* Closed: next to nothing leaves (the factors' closure error only). */
    assert_true(fabs(bal.net_power) < 1e-4 * bal.power_scale);
    rad_thermal_destroy(t);

    /* The floor's flux given: its temperature back, to the same error. */
    char bc[400];
    snprintf(bc, sizeof bc, "{\"surfaces\": {\"floor\": {\"emissivity\": 0.8, \"heat_flux\": %.17g},"
                            " \"walls\": {\"emissivity\": 1, \"temperature\": 500}}}", q);
    t = box_solve(&b, bc);
    assert_true(rad_thermal_surface_values(t, 0, &floor));
    cli_assert_relative(floor.temperature, 1000.0, 1e-5, "floor T from q");
    assert_int_equal(floor.condition, RAD_THERMAL_HEAT_FLUX);

    /* Gebhart factors: rows sum to the factors' closure, and
     * eps_s A_s G_st = eps_t A_t G_ts (the analytic F is reciprocal). */
    double G[4];
    assert_int_equal(rad_thermal_gebhart(b.ctx, t, G), RAD_OK);
    assert_true(fabs(G[0] + G[1] - 1.0) < 1e-4 && fabs(G[2] + G[3] - 1.0) < 1e-4);
    cli_assert_relative(0.8 * 1.0 * G[1], 1.0 * 5.0 * G[2], 1e-9, "Gebhart reciprocity");
    assert_true(G[0] < 1e-12); /* the flat floor cannot see itself */
    rad_thermal_destroy(t);

    /* Everything adiabatic or a flux in the closed box: refused, naming the file. */
    rad_thermal_conditions *c = NULL;
    const char *closed = "{\"surfaces\": {\"floor\": {\"heat_flux\": 100}, \"walls\": {\"adiabatic\": true}}}";
    assert_int_equal(rad_thermal_conditions_load_memory(b.ctx, b.scene, "bc.json", closed, strlen(closed), &c),
                     RAD_OK);
    assert_int_equal(rad_thermal_solve(b.ctx, b.sol, c, NULL, &t), RAD_ERROR_INVALID_ARGUMENT);
    assert_null(t);
    assert_non_null(strstr(rad_context_error(b.ctx), "bc.json: "));
    assert_non_null(strstr(rad_context_error(b.ctx), "closed enclosure"));
    rad_thermal_conditions_destroy(c);
    box_close(&b);

    /* Rows closed exactly (rad_options.closure_correction): the closed form to rounding. */
    box_open(&b, path, 0.25, 1);
    t = box_solve(&b, "{\"surfaces\": {\"floor\": {\"emissivity\": 0.8, \"temperature\": 1000},"
                      " \"walls\": {\"emissivity\": 1, \"temperature\": 500}}}");
    assert_true(rad_thermal_surface_values(t, 0, &floor));
    print_message("meshed box, closed rows: floor q error %.2g\n", rel(floor.heat_flux, q));
    cli_assert_relative(floor.heat_flux, q, 1e-12, "floor q, closed rows");
    rad_thermal_get_balance(t, &bal);
    assert_true(fabs(bal.net_power) < 1e-12 * bal.power_scale);
    rad_thermal_destroy(t);
    box_close(&b);
}

/* Known temperatures everywhere and no environment: the thermal J is the
 * engine's own B for E = eps sigma T^4 and rho = 1 - eps on the same F
 * (the emissivities here come from the materials, 1 - Kd). */
static void test_agrees_with_the_radiosity_solve(void **state)
{
    (void)state;
    double eps_f = 0.7, eps_w = 0.4, T_f = 900.0, T_w = 450.0;
    char path[600];
    write_box("box_emit", 1.0 - eps_f, eps_f * RAD_SIGMA * pow(T_f, 4) / M_PI, 1.0 - eps_w,
              eps_w * RAD_SIGMA * pow(T_w, 4) / M_PI, path, sizeof path);
    box_run b;
    box_open(&b, path, 0.34, 0);
    rad_thermal *t = box_solve(&b, "{\"surfaces\": {\"floor\": {\"temperature\": 900}, \"walls\": {\"temperature\":"
                                   " 450}}}");
    assert_int_equal(rad_solution_solve(b.ctx, b.sol), RAD_OK);
    size_t n = rad_solution_element_count(b.sol);
    assert_true(n > 50);
    double worst = 0.0;
    for (size_t i = 0; i < n; i++) {
        double B[3];
        rad_thermal_values v;
        assert_true(rad_solution_element_values(b.sol, i, NULL, NULL, B));
        assert_true(rad_thermal_element_values(t, i, &v));
        cli_assert_relative(v.emissivity, rad_solution_element_surface(b.sol, i) == 0 ? eps_f : eps_w, 1e-12, "eps");
        cli_assert_relative(v.radiosity, B[0], 1e-9, "J = B");
        worst = fmax(worst, rel(v.radiosity, B[0]));
    }
    print_message("J = B: %zu elements, largest relative difference %.2g\n", n, worst);
    rad_thermal_destroy(t);
    box_close(&b);
}

/* A long duct solved as a closed box: square section 1 x 1 m, 40 m long,
 * capped; the bottom (eps 0.8, 1000 K) and top (eps 0.6, 500 K) at
 * temperatures, the sides and caps adiabatic; one element across each
 * face, so each cross-section is four uniform strips.  Far from the caps
 * that is the 2-D enclosure of crossed-strings factors F_opposite =
 * sqrt 2 - 1, F_adjacent = 1 - sqrt 2 / 2, whose network gives per metre
 *     Q_1 = sigma (T1^4 - T2^4) / ((1 - eps1)/eps1 + (1 - eps2)/eps2 + sqrt 2)
 * (the space resistance 1 / (F_12 + F_1R / 2) = sqrt 2), and the sides
 * J_R = (J_1 + J_2) / 2 by symmetry.  Measured: 1.4e-5 on q, 9.8e-7 on T_R
 * (the engine's F and the caps 20 m away). */
static void test_long_duct(void **state)
{
    (void)state;
    const double L = 40.0;
    char obj[2048];
    snprintf(obj, sizeof obj,
             "v 0 0 0\nv 0 0 %g\nv 1 0 %g\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 1 1 %g\nv 0 1 %g\n"
             "o bottom\nf 1 2 3 4\no top\nf 5 6 7 8\no side0\nf 1 5 8 2\no side1\nf 4 3 7 6\n"
             "o cap0\nf 1 4 6 5\no cap1\nf 2 8 7 3\n",
             L, L, L, L);
    rad_context *ctx = test_context(1);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "duct.obj", obj, strlen(obj), NULL, 0, &scene), RAD_OK);
    rad_options o = {.solver = "direct", .mesh_size = 1.0};
    rad_solution *sol = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &sol), RAD_OK);
    const char *bc = "{\"default\": {\"adiabatic\": true}, \"surfaces\": {\"bottom\": {\"emissivity\": 0.8, "
                     "\"temperature\": 1000}, \"top\": {\"emissivity\": 0.6, \"temperature\": 500}}}";
    rad_thermal_conditions *c = NULL;
    assert_int_equal(rad_thermal_conditions_load_memory(ctx, scene, "duct_bc.json", bc, strlen(bc), &c), RAD_OK);
    rad_thermal *t = NULL;
    if (rad_thermal_solve(ctx, sol, c, NULL, &t) != RAD_OK)
        fail_msg("%s", rad_context_error(ctx));
    double dEb = RAD_SIGMA * (pow(1000.0, 4) - pow(500.0, 4));
    double R1 = 0.2 / 0.8, R2 = 0.4 / 0.6;
    double Q1 = dEb / (R1 + R2 + sqrt(2.0));
    double J1 = RAD_SIGMA * pow(1000.0, 4) - Q1 * R1, J2 = RAD_SIGMA * pow(500.0, 4) + Q1 * R2;
    double TR = pow((J1 + J2) / 2.0 / RAD_SIGMA, 0.25);
    int middle = 0;
    double worst_q = 0.0, worst_t = 0.0;
    for (size_t i = 0; i < rad_solution_element_count(sol); i++) {
        double centroid[3];
        rad_thermal_values v;
        assert_true(rad_solution_element_geometry(sol, i, NULL, centroid));
        assert_true(rad_thermal_element_values(t, i, &v));
        size_t surface = rad_solution_element_surface(sol, i);
        if (fabs(centroid[2] - L / 2.0) > 1.0 || surface >= 4)
            continue;
        middle++;
        if (surface == 0)
            worst_q = fmax(worst_q, rel(v.heat_flux, Q1));
        else if (surface == 1)
            worst_q = fmax(worst_q, rel(v.heat_flux, -Q1));
        else
            worst_t = fmax(worst_t, rel(v.temperature, TR));
    }
    assert_int_equal(middle, 8);
    print_message("long duct: middle q within %.2g of the 2-D network (%.10g W/m^2), side T within %.2g (%.10g K)\n",
                  worst_q, Q1, worst_t, TR);
    assert_true(worst_q < 1e-4);
    assert_true(worst_t < 1e-5);
    rad_thermal_destroy(t);
    rad_thermal_conditions_destroy(c);
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* ---- View3D obstruction-only surfaces: they block and take no part ---- */

/* A plate under an obstruction-only square: whatever the plate sends
 * reaches the obstruction or escapes, both the environment, so its net
 * power is exactly eps sigma (T^4 - T_env^4) A however much the square
 * intercepts.  Treated as a surface of the exchange (re-radiating, or at
 * any other temperature) it would send some back and change Q. */
static void test_obstruction_surfaces(void **state)
{
    (void)state;
    static const char vs3[] = "T plate under an obstruction\nC encl=0\nF 3\n"
                              "V 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\n"
                              "V 5 -.5 -.5 .2\nV 6 -.5 1.5 .2\nV 7 1.5 1.5 .2\nV 8 1.5 -.5 .2\n"
                              "S 1 1 2 3 4 0 0 0.7 plate\nO 2 5 6 7 8 0 0 0.5 lid\nE\n";
    rad_context *ctx = test_context(1);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_memory(ctx, "lid.vs3", vs3, strlen(vs3), NULL, 0, &scene), RAD_OK);
    rad_thermal_conditions *c = NULL;
    const char *named = "{\"surfaces\": {\"plate\": {\"temperature\": 900}, \"lid\": {\"adiabatic\": true}}}";
    assert_int_equal(rad_thermal_conditions_load_memory(ctx, scene, "bc.json", named, strlen(named), &c),
                     RAD_ERROR_PARSE);
    assert_non_null(strstr(rad_context_error(ctx), "surfaces.lid: an obstruction-only surface takes no condition"));
    const char *bc = "{\"environment_temperature\": 300, \"default\": {\"temperature\": 900}}";
    assert_int_equal(rad_thermal_conditions_load_memory(ctx, scene, "bc.json", bc, strlen(bc), &c), RAD_OK);
    rad_thermal_surface lid;
    assert_true(rad_thermal_conditions_get(c, 1, &lid));
    assert_int_equal(lid.condition, RAD_THERMAL_OBSTRUCTION);
    assert_int_equal(rad_thermal_conditions_set(ctx, c, 1, &(rad_thermal_surface){RAD_THERMAL_ADIABATIC, 0, 0.5}),
                     RAD_ERROR_INVALID_ARGUMENT);
    rad_options o = {0};
    o.solver = "gauss-seidel";
    o.target_elements = 50;
    rad_solution *sol = NULL;
    assert_int_equal(rad_solution_create(ctx, scene, &o, &sol), RAD_OK);
    rad_thermal *t = NULL;
    assert_int_equal(rad_thermal_solve(ctx, sol, c, NULL, &t), RAD_OK);
    rad_thermal_values plate;
    assert_true(rad_thermal_surface_values(t, 0, &plate));
    double exact = 0.7 * RAD_SIGMA * (pow(900.0, 4) - pow(300.0, 4)) * 1.0;
    print_message("plate under an obstruction: Q = %.12g W, exact %.12g W\n", plate.heat, exact);
    assert_true(rel(plate.heat, exact) < 1e-9);
    rad_thermal_balance b;
    rad_thermal_get_balance(t, &b);
    assert_true(rel(b.net_power, plate.heat) < 1e-12);    /* the lid's power is not summed */
    assert_true(fabs(b.relative_imbalance) < 1e-9);       /* all of it reaches the environment */
    rad_thermal_destroy(t);
    rad_thermal_conditions_destroy(c);
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* ---- bad boundary-condition files: one line naming the file and the key ---- */

static void test_bad_conditions(void **state)
{
    (void)state;
    char path[600];
    write_box("box_bad", 0.5, 0.0, 0.5, 0.0, path, sizeof path);
    rad_context *ctx = test_context(1);
    rad_scene *scene = NULL;
    assert_int_equal(rad_scene_load_file(ctx, path, &scene), RAD_OK);
    static const struct {
        const char *text, *message;
    } bad[] = {
        {"{\"surfaces\": {\"floor\": {\"temperature\": 300}", "bc.json:1: not valid JSON"},
        {"[1, 2]", "bc.json: must be a JSON object"},
        {"{\"surfaces\": {\"floor\": {\"temperature\": 300}, \"roof\": {\"temperature\": 3}}}",
         "bc.json: surfaces.roof: the scene"},
        {"{\"surfaces\": {\"floor\": {\"temperature\": 300}}}",
         "bc.json: surfaces: the scene's surface 'walls' has no condition"},
        {"{\"surfaces\": {\"floor\": {\"emissivity\": 1.5, \"temperature\": 300}}, \"default\": {\"adiabatic\": true}}",
         "bc.json: surfaces.floor.emissivity: must be in (0, 1], got 1.5"},
        {"{\"default\": {\"emissivity\": 0, \"adiabatic\": true}}", "bc.json: default.emissivity: must be in (0, 1]"},
        {"{\"default\": {\"temperature\": -1}}", "bc.json: default.temperature: must be finite and >= 0 K"},
        {"{\"default\": {\"temperature\": 1e999}}", "bc.json: default.temperature: must be finite"},
        {"{\"default\": {\"heat_flux\": -1e999}}", "bc.json: default.heat_flux: must be finite"},
        {"{\"default\": {\"temperature\": 300, \"heat_flux\": 5}}",
         "bc.json: default: more than one of temperature, heat_flux and adiabatic"},
        {"{\"default\": {\"emisivity\": 0.5, \"temperature\": 300}}", "bc.json: default.emisivity: unknown key"},
        {"{\"default\": {\"emissivity\": 0.5}}", "bc.json: default: no condition"},
        {"{\"default\": {\"adiabatic\": \"yes\"}}", "bc.json: default.adiabatic: must be true or false"},
        {"{\"default\": {\"temperature\": \"300\"}}", "bc.json: default.temperature: must be a number"},
        {"{\"default\": {\"temperature\": 300}, \"surfaces\": {\"floor\": {\"adiabatic\": true}, \"floor\": "
         "{\"adiabatic\": true}}}",
         "bc.json: surfaces.floor: given twice"},
        {"{\"default\": {\"adiabatic\": true}, \"environment_temperature\": -3}",
         "bc.json: environment_temperature: must be a finite number >= 0 K"},
        {"{\"default\": {\"adiabatic\": true}, \"environment\": 3}", "bc.json: environment: unknown key"},
        {"{\"default\": {\"adiabatic\": true}} x", "bc.json:1: text after the JSON object"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        rad_thermal_conditions *c = (rad_thermal_conditions *)&c; /* must come back NULL */
        rad_result r = rad_thermal_conditions_load_memory(ctx, scene, "bc.json", bad[k].text, strlen(bad[k].text), &c);
        if (r != RAD_ERROR_PARSE || c != NULL || strncmp(rad_context_error(ctx), bad[k].message, strlen(bad[k].message)))
            fail_msg("case %zu: result %d, message '%s', expected '%s'", k, (int)r, rad_context_error(ctx),
                     bad[k].message);
    }
    /* A default fills in; "adiabatic": false says nothing; the calls check as the file does. */
    const char *good = "{\"environment_temperature\": 3, \"default\": {\"emissivity\": 0.3, \"adiabatic\": true},"
                       " \"surfaces\": {\"floor\": {\"adiabatic\": false, \"temperature\": 350}}}";
    rad_thermal_conditions *c = NULL;
    assert_int_equal(rad_thermal_conditions_load_memory(ctx, scene, "bc.json", good, strlen(good), &c), RAD_OK);
    rad_thermal_surface s;
    assert_true(rad_thermal_conditions_get(c, 1, &s));
    assert_int_equal(s.condition, RAD_THERMAL_ADIABATIC);
    assert_true(s.emissivity == 0.3);
    assert_true(rad_thermal_conditions_get(c, 0, &s));
    assert_true(s.condition == RAD_THERMAL_TEMPERATURE && s.value == 350.0 && s.emissivity == 0.0);
    assert_true(rad_thermal_conditions_environment(c) == 3.0);
    s = (rad_thermal_surface){RAD_THERMAL_TEMPERATURE, -2.0, 0.5};
    assert_int_equal(rad_thermal_conditions_set(ctx, c, 0, &s), RAD_ERROR_INVALID_ARGUMENT);
    s = (rad_thermal_surface){RAD_THERMAL_HEAT_FLUX, 10.0, 1.01};
    assert_int_equal(rad_thermal_conditions_set(ctx, c, 0, &s), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_thermal_conditions_set(ctx, c, 2, &s), RAD_ERROR_INVALID_ARGUMENT);
    assert_int_equal(rad_thermal_conditions_set_environment(ctx, c, NAN), RAD_ERROR_INVALID_ARGUMENT);
    rad_thermal_conditions_destroy(c);
    /* Unset conditions are refused at the solve; a missing file names itself. */
    assert_int_equal(rad_thermal_conditions_create(ctx, scene, &c), RAD_OK);
    rad_solution *sol = NULL;
    rad_options o = {.solver = "direct", .mesh_size = 0.5};
    assert_int_equal(rad_solution_create(ctx, scene, &o, &sol), RAD_OK);
    rad_thermal *t = NULL;
    assert_int_equal(rad_thermal_solve(ctx, sol, c, NULL, &t), RAD_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(rad_context_error(ctx), "surface 'floor' has no condition"));
    rad_thermal_conditions_destroy(c);
    assert_int_equal(rad_thermal_conditions_load_file(ctx, scene, "/nonexistent/bc.json", &c), RAD_ERROR_IO);
    assert_non_null(strstr(rad_context_error(ctx), "/nonexistent/bc.json"));
    rad_solution_destroy(sol);
    rad_scene_destroy(scene);
    rad_context_destroy(ctx);
}

/* ---- the command ---- */

/* One CSV row's numeric field `column` (0-based) of the row whose first
 * field is `name`; NAN when absent. */
static double csv_value(const char *text, const char *name, int column)
{
    size_t len = strlen(name);
    for (const char *line = text; line && *line; line = strchr(line, '\n'), line = line ? line + 1 : NULL) {
        if (strncmp(line, name, len) != 0 || line[len] != ',')
            continue;
        const char *p = line;
        for (int k = 0; k < column; k++) {
            p = strchr(p, ',');
            if (!p)
                return NAN;
            p++;
        }
        return strtod(p, NULL);
    }
    return NAN;
}

static void test_command(void **state)
{
    (void)state;
    const char *dir = test_workdir();
    char cmd_args[2048];
    /* The furnace of docs/thermal.md: the roof gives 30 kW/m^2 x 2 m^2 to
     * the hearth at 700 K through adiabatic walls. */
    snprintf(cmd_args, sizeof cmd_args,
             "thermal %s/furnace.obj --bc %s/furnace_bc.json --mesh-size 0.25 -o %s/heat.csv --gebhart %s/g.json "
             "--stats %s/stats.json",
             RAD_TEST_DATA, RAD_TEST_DATA, dir, dir, dir);
    assert_int_equal(cli_run("%s", cmd_args), 0);
    char path[600];
    snprintf(path, sizeof path, "%s/heat.csv", dir);
    char *csv = test_read_file(path, NULL);
    assert_non_null(csv);
    assert_true(strncmp(csv, "surface,condition,area_m2,emissivity,temperature_K,radiosity_W_m2,irradiation_W_m2,"
                             "heat_flux_W_m2,heat_W\n", 105) == 0);
    print_message("furnace: roof Q %.10g W, hearth Q %.10g W, walls Q %.2g W\n", csv_value(csv, "roof", 8),
                  csv_value(csv, "hearth", 8), csv_value(csv, "walls", 8));
    cli_assert_relative(csv_value(csv, "roof", 8), 60000.0, 1e-12, "roof Q");
    cli_assert_relative(csv_value(csv, "hearth", 8), -60000.0, 1e-4, "hearth Q");
    assert_true(fabs(csv_value(csv, "walls", 8)) < 1e-6);
    cli_assert_relative(csv_value(csv, "hearth", 4), 700.0, 1e-12, "hearth T");
    cli_assert_relative(csv_value(csv, "walls", 3), 0.6, 1e-12, "walls eps from the material");
    double roof_T = csv_value(csv, "roof", 4), walls_T = csv_value(csv, "walls", 4);
    assert_true(roof_T > walls_T && walls_T > 700.0); /* heat flows roof -> walls -> hearth */
    free(csv);
    snprintf(path, sizeof path, "%s/stats.json", dir);
    cJSON *stats = cli_read_json(path);
    assert_non_null(stats);
    assert_true(fabs(cli_stats_number(stats, "thermal", "relative_imbalance")) < 1e-9);
    cli_assert_relative(cli_stats_number(stats, "thermal", "power_scale_W"), 120000.0, 1e-4, "sum |Q|");
    cJSON_Delete(stats);
    snprintf(path, sizeof path, "%s/g.json", dir);
    cJSON *g = cli_read_json(path);
    assert_non_null(g);
    const cJSON *rows = cJSON_GetObjectItem(g, "G");
    assert_int_equal(cJSON_GetArraySize(rows), 3);
    for (int k = 0; k < 3; k++) {
        double sum = 0.0;
        const cJSON *x;
        cJSON_ArrayForEach(x, cJSON_GetArrayItem(rows, k)) sum += x->valuedouble;
        cli_assert_relative(sum, 1.0, 1e-4, "Gebhart row sum");
    }
    cJSON_Delete(g);

    /* Per element, as JSON: every element listed, the balance there too. */
    snprintf(cmd_args, sizeof cmd_args,
             "thermal %s/furnace.obj --bc %s/furnace_bc.json --mesh-size 0.5 --level element -o %s/heat.json "
             "--solver gauss-seidel", RAD_TEST_DATA, RAD_TEST_DATA, dir);
    assert_int_equal(cli_run("%s", cmd_args), 0);
    snprintf(path, sizeof path, "%s/heat.json", dir);
    cJSON *heat = cli_read_json(path);
    assert_non_null(heat);
    const cJSON *elements = cJSON_GetObjectItem(heat, "elements_list");
    assert_int_equal(cJSON_GetArraySize(elements), (int)cJSON_GetObjectItem(heat, "elements")->valuedouble);
    assert_true(cJSON_GetArraySize(elements) == 4 * 2 * 2 + 2 * 4 * 2 + 2 * 2 * 2); /* 0.5 m elements */
    double roof = 0.0;
    const cJSON *e;
    cJSON_ArrayForEach(e, elements) if (strcmp(cJSON_GetObjectItem(e, "name")->valuestring, "roof") == 0) roof +=
        cJSON_GetObjectItem(e, "heat_W")->valuedouble;
    cli_assert_relative(roof, 60000.0, 1e-8, "roof Q over elements (gauss-seidel)");
    assert_true(fabs(cli_stats_number(heat, "balance", "relative_imbalance")) < 1e-8);
    cJSON_Delete(heat);

    /* Refusals: no --bc (usage), a bad file (named; no output written). */
    snprintf(path, sizeof path, "%s/none.csv", dir);
    assert_int_equal(cli_run("thermal %s/furnace.obj -o %s", RAD_TEST_DATA, path), 2);
    char bc[600], errors[600];
    snprintf(bc, sizeof bc, "%s/bad_bc.json", dir);
    FILE *f = fopen(bc, "w");
    assert_non_null(f);
    fputs("{\"default\": {\"adiabatic\": true}, \"surfaces\": {\"hearth\": {\"emissivity\": 2, \"temperature\": 300}}}",
          f);
    fclose(f);
    snprintf(errors, sizeof errors, "%s/errors.txt", dir);
    assert_int_equal(cli_run_capture(errors, "thermal %s/furnace.obj --bc %s -o %s", RAD_TEST_DATA, bc, path), 1);
    char *text = test_read_file(errors, NULL);
    assert_non_null(text);
    assert_non_null(strstr(text, "bad_bc.json: surfaces.hearth.emissivity: must be in (0, 1], got 2"));
    free(text);
    assert_null(fopen(path, "r"));
    assert_int_equal(cli_run("thermal %s/furnace.obj --bc %s/furnace_bc.json -o %s/heat.mtx", RAD_TEST_DATA,
                             RAD_TEST_DATA, dir), 2);
    assert_int_equal(cli_run("thermal %s/furnace.obj --bc %s/furnace_bc.json --solver hierarchical -o %s",
                             RAD_TEST_DATA, RAD_TEST_DATA, path), 2);
}

/* Thermal solves on F: every solver that keeps none is refused before any
 * work, with one line naming it (a usage error), and nothing is written.
 * Galerkin, collocation and instant radiosity were let through once (their
 * names were missing from a list); the capability says it now. */
static void test_solvers_without_f(void **state)
{
    (void)state;
    const char *dir = test_workdir();
    char path[600], errors[600];
    snprintf(path, sizeof path, "%s/refused.csv", dir);
    snprintf(errors, sizeof errors, "%s/refused.txt", dir);
    const char *without[] = {"hierarchical", "shooting", "galerkin-constant", "galerkin-linear", "collocation",
                             "instant-radiosity", "instant-radiosity-clamped"};
    for (size_t k = 0; k < sizeof without / sizeof without[0]; k++)
        assert_int_equal(rad_method_capabilities(RAD_METHOD_SOLVER, without[k]) & RAD_HAS_FORM_FACTORS, 0);
    size_t refused = 0;
    const char *name;
    for (size_t i = 0; rad_method_info(RAD_METHOD_SOLVER, i, &name, NULL); i++) {
        if (rad_method_capabilities(RAD_METHOD_SOLVER, name) & RAD_HAS_FORM_FACTORS)
            continue;
        refused++;
        assert_int_equal(cli_run_capture(errors, "thermal %s/furnace.obj --bc %s/furnace_bc.json --solver %s -o %s",
                                         RAD_TEST_DATA, RAD_TEST_DATA, name, path),
                         2);
        char expected[300];
        snprintf(expected, sizeof expected,
                 "radiosity: --solver %s keeps no form-factor matrix: thermal takes direct, gauss-seidel, jacobi, "
                 "southwell or conjugate-gradient (see radiosity thermal --help)\n",
                 name);
        char *text = test_read_file(errors, NULL);
        assert_non_null(text);
        assert_string_equal(text, expected);
        free(text);
        assert_null(fopen(path, "r"));
    }
    assert_int_equal(refused, sizeof without / sizeof without[0]);
}

static int setup(void **state)
{
    (void)state;
    return cli_setup("thermal");
}

static int teardown(void **state)
{
    (void)state;
    return cli_teardown();
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_thermal PATH_TO_RADIOSITY\n");
        return 2;
    }
    cli_set_binary(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_surface_enclosure),
        cmocka_unit_test(test_reradiating_wall),
        cmocka_unit_test(test_open_plate),
        cmocka_unit_test(test_energy_balance),
        cmocka_unit_test(test_gebhart),
        cmocka_unit_test(test_undetermined),
        cmocka_unit_test(test_box_through_library),
        cmocka_unit_test(test_agrees_with_the_radiosity_solve),
        cmocka_unit_test(test_long_duct),
        cmocka_unit_test(test_obstruction_surfaces),
        cmocka_unit_test(test_bad_conditions),
        cmocka_unit_test(test_command),
        cmocka_unit_test(test_solvers_without_f),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
