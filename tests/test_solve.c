/*
 * test_solve.c - the solvers of (I - diag(rho) F) B = E against independent references:
 * a 2-patch system solved in closed form, a furnace whose answer is E / (1 - rho), a
 * random reciprocal system solved directly (and the direct answer checked by plugging it
 * back into the equation here), the solvers against each other, thread-count independence,
 * convergence speed, the ambient term, and argument errors.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "testlib.h"

#define PI 3.14159265358979323846

/* A system whose arrays the test owns. */
typedef struct test_system {
    rad_system s;
    float *F;
    double *area;
    rad_rgb *albedo;
    rad_rgb *exitance;
} test_system;

static void system_alloc(test_system *t, uint32_t n)
{
    t->F = calloc((size_t)n * n, sizeof(float));
    t->area = calloc(n, sizeof(double));
    t->albedo = calloc(n, sizeof(rad_rgb));
    t->exitance = calloc(n, sizeof(rad_rgb));
    if (!t->F || !t->area || !t->albedo || !t->exitance) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    t->s = (rad_system){n, t->F, t->area, t->albedo, t->exitance};
}

static void system_free(test_system *t)
{
    free(t->F);
    free(t->area);
    free(t->albedo);
    free(t->exitance);
}

/* splitmix64: a reproducible stream of uniform numbers in [0,1). */
static double uniform(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15u);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-53;
}

/* Monotonic wall clock, as the library's omp_get_wtime (libgomp: CLOCK_MONOTONIC). */
static double now_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static rad_rgb *rgb_array(uint32_t n)
{
    rad_rgb *a = calloc(n, sizeof(rad_rgb));
    if (!a) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    return a;
}

static rad_status run(const test_system *t, rad_solver solver, double tolerance,
                      uint32_t max_iterations, bool ambient, int threads, rad_rgb *B,
                      rad_solve_report *report)
{
    rad_solve_options o = {0};
    o.solver = solver;
    o.tolerance = tolerance;
    o.max_iterations = max_iterations;
    o.ambient = ambient;
    o.threads = threads;
    rad_error error = {0};
    rad_status status = rad_solve(&t->s, &o, B, report, &error);
    if (status != RAD_OK)
        fprintf(stderr, "rad_solve: %s\n", error.message);
    return status;
}

static const rad_solver all_solvers[] = {RAD_SOLVER_JACOBI, RAD_SOLVER_GAUSS_SEIDEL,
                                         RAD_SOLVER_SHOOT, RAD_SOLVER_DIRECT};
static const char *const solver_names[] = {"jacobi", "gauss-seidel", "shoot", "direct"};

/* Area-weighted relative residual computed here, independently of the library, in long
 * double. */
static double own_residual(const test_system *t, const rad_rgb *B)
{
    uint32_t n = t->s.n;
    long double num = 0, den = 0;
    for (uint32_t i = 0; i < n; i++) {
        long double s[3] = {0, 0, 0};
        for (uint32_t j = 0; j < n; j++) {
            long double f = t->F[(size_t)i * n + j];
            s[0] += f * B[j].r;
            s[1] += f * B[j].g;
            s[2] += f * B[j].b;
        }
        long double r0 = B[i].r - t->exitance[i].r - t->albedo[i].r * s[0];
        long double r1 = B[i].g - t->exitance[i].g - t->albedo[i].g * s[1];
        long double r2 = B[i].b - t->exitance[i].b - t->albedo[i].b * s[2];
        num += t->area[i] * (fabsl(r0) + fabsl(r1) + fabsl(r2));
        den += t->area[i] * (t->exitance[i].r + t->exitance[i].g + t->exitance[i].b);
    }
    return (double)(den > 0 ? num / den : num);
}

static double total_power(const test_system *t, const rad_rgb *B)
{
    double p = 0;
    for (uint32_t i = 0; i < t->s.n; i++)
        p += t->area[i] * (B[i].r + B[i].g + B[i].b);
    return p;
}

/* (1) Two patches facing each other, F12 = 0.5, F21 = 0.25, A1 = 1, A2 = 2 (A1 F12 = A2 F21
 * exactly). Closed form:
 *   B1 = (E1 + rho1 F12 E2) / (1 - rho1 rho2 F12 F21),  B2 = (E2 + rho2 F21 E1) / (same). */
static void test_two_patches(void)
{
    test_system t;
    system_alloc(&t, 2);
    const double F12 = 0.5, F21 = 0.25;
    t.F[1] = (float)F12;
    t.F[2] = (float)F21;
    t.area[0] = 1;
    t.area[1] = 2;
    t.albedo[0] = (rad_rgb){0.8, 0.5, 0.3};
    t.albedo[1] = (rad_rgb){0.6, 0.9, 0.0};
    t.exitance[0] = (rad_rgb){10, 5, 0};
    t.exitance[1] = (rad_rgb){0, 2, 3};

    double expect[2][3];
    for (int c = 0; c < 3; c++) {
        double r1 = c == 0 ? t.albedo[0].r : c == 1 ? t.albedo[0].g : t.albedo[0].b;
        double r2 = c == 0 ? t.albedo[1].r : c == 1 ? t.albedo[1].g : t.albedo[1].b;
        double e1 = c == 0 ? t.exitance[0].r : c == 1 ? t.exitance[0].g : t.exitance[0].b;
        double e2 = c == 0 ? t.exitance[1].r : c == 1 ? t.exitance[1].g : t.exitance[1].b;
        double d = 1 - r1 * r2 * F12 * F21;
        expect[0][c] = (e1 + r1 * F12 * e2) / d;
        expect[1][c] = (e2 + r2 * F21 * e1) / d;
    }
    for (size_t k = 0; k < 4; k++) {
        rad_rgb B[2];
        rad_solve_report report;
        double before = now_seconds();
        CHECK(run(&t, all_solvers[k], 1e-12, 0, false, 0, B, &report) == RAD_OK);
        double outside = now_seconds() - before;
        for (int i = 0; i < 2; i++) {
            CHECK_NEAR(B[i].r, expect[i][0], 1e-9);
            CHECK_NEAR(B[i].g, expect[i][1], 1e-9);
            CHECK_NEAR(B[i].b, expect[i][2], 1e-9);
        }
        CHECK(report.converged);
        CHECK(report.residual <= 1e-11);
        /* the solve's own clock: it ran (some nanoseconds at least, on a nanosecond
         * clock) and it cannot have taken longer than the call measured from outside
         * (1 us of slack for the two clocks' rounding) */
        CHECK(report.seconds > 0);
        CHECK(report.seconds <= outside + 1e-6);
        if (!report.converged)
            fprintf(stderr, "two patches: %s did not converge\n", solver_names[k]);
    }
    system_free(&t);
}

/* (2) A furnace: every point sees every patch in proportion to its area, F_ij = A_j / A
 * (rows sum to 1, reciprocity exact), E = pi everywhere, rho = 0.5: B = pi / (1 - 0.5).
 * F_ii > 0 here, which exercises self-transfer. */
static void test_furnace(void)
{
    const uint32_t n = 50;
    test_system t;
    system_alloc(&t, n);
    uint64_t seed = 1;
    double total = 0;
    for (uint32_t i = 0; i < n; i++) {
        t.area[i] = 0.1 + 3 * uniform(&seed);
        total += t.area[i];
        t.albedo[i] = (rad_rgb){0.5, 0.5, 0.5};
        t.exitance[i] = (rad_rgb){PI, PI, PI};
    }
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = 0; j < n; j++)
            t.F[(size_t)i * n + j] = (float)(t.area[j] / total);

    rad_rgb *B = rgb_array(n);
    for (size_t k = 0; k < 4; k++) {
        rad_solve_report report;
        CHECK(run(&t, all_solvers[k], 1e-10, 0, false, 0, B, &report) == RAD_OK);
        CHECK(report.converged);
        for (uint32_t i = 0; i < n; i++) {
            CHECK_NEAR(B[i].r, 2 * PI, 1e-6);
            CHECK_NEAR(B[i].g, 2 * PI, 1e-6);
            CHECK_NEAR(B[i].b, 2 * PI, 1e-6);
        }
    }
    free(B);
    system_free(&t);
}

/* A random system with exact reciprocity even in float: areas are powers of two and
 * F_ij = q_ij A_j with q symmetric, positive off the diagonal and on a 2^-30 grid, so
 * A_i F_ij = q_ij A_i A_j = A_j F_ji exactly. q is scaled so that the largest row of F sums
 * to 0.95 (every patch sees most of the others: a nearly closed scene). About one patch in
 * eight emits. */
static void random_system(test_system *t, uint32_t n, uint64_t seed)
{
    system_alloc(t, n);
    for (uint32_t i = 0; i < n; i++) {
        t->area[i] = ldexp(1.0, (int)(uniform(&seed) * 4) - 1); /* 0.5, 1, 2 or 4 */
        t->albedo[i] = (rad_rgb){0.9 * uniform(&seed), 0.9 * uniform(&seed),
                                 0.9 * uniform(&seed)};
        if (uniform(&seed) < 0.125)
            t->exitance[i] = (rad_rgb){10 * uniform(&seed), 10 * uniform(&seed),
                                       10 * uniform(&seed)};
    }
    t->albedo[0] = (rad_rgb){0, 0.9, 0.45}; /* the ends of the albedo range */
    t->exitance[1] = (rad_rgb){1, 2, 3};     /* at least one emitter */

    double *q = calloc((size_t)n * n, sizeof(double));
    if (!q)
        exit(1);
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = i + 1; j < n; j++)
            q[(size_t)i * n + j] = q[(size_t)j * n + i] = 0.05 + uniform(&seed);
    double largest = 0;
    for (uint32_t i = 0; i < n; i++) {
        double sum = 0;
        for (uint32_t j = 0; j < n; j++)
            sum += q[(size_t)i * n + j] * t->area[j];
        largest = fmax(largest, sum);
    }
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = 0; j < n; j++) {
            double v = ldexp(floor(ldexp(q[(size_t)i * n + j] * 0.95 / largest, 30)), -30);
            t->F[(size_t)i * n + j] = (float)(v * t->area[j]);
        }
    for (uint32_t i = 0; i < n; i++) {
        double sum = 0;
        for (uint32_t j = 0; j < n; j++) {
            sum += t->F[(size_t)i * n + j];
            if ((double)t->area[i] * t->F[(size_t)i * n + j] !=
                (double)t->area[j] * t->F[(size_t)j * n + i])
                exit(2); /* the construction is broken, not the library */
        }
        if (sum > 0.95)
            exit(2);
    }
    free(q);
}

/* (3) and (5): the iterative solvers agree with the direct one on a random system; the
 * direct answer satisfies the equation; Gauss-Seidel needs fewer sweeps than Jacobi. */
static void test_random_system(void)
{
    const uint32_t n = 200;
    test_system t;
    random_system(&t, n, 7);

    rad_rgb *direct = rgb_array(n), *B = rgb_array(n);
    rad_solve_report report;
    CHECK(run(&t, RAD_SOLVER_DIRECT, 0, 0, false, 0, direct, &report) == RAD_OK);
    CHECK(report.converged);
    CHECK(report.iterations == 0);
    CHECK(report.residual < 1e-12);
    /* independent check: plug the direct answer back into the equation */
    CHECK(own_residual(&t, direct) < 1e-10);
    double worst = 0;
    for (uint32_t i = 0; i < n; i++) {
        double s[3] = {0, 0, 0};
        for (uint32_t j = 0; j < n; j++) {
            s[0] += t.F[(size_t)i * n + j] * direct[j].r;
            s[1] += t.F[(size_t)i * n + j] * direct[j].g;
            s[2] += t.F[(size_t)i * n + j] * direct[j].b;
        }
        worst = fmax(worst, fabs(direct[i].r - t.exitance[i].r - t.albedo[i].r * s[0]));
        worst = fmax(worst, fabs(direct[i].g - t.exitance[i].g - t.albedo[i].g * s[1]));
        worst = fmax(worst, fabs(direct[i].b - t.exitance[i].b - t.albedo[i].b * s[2]));
    }
    CHECK(worst < 1e-12);
    /* the library's residual agrees with the test's own */
    CHECK_NEAR(rad_system_residual(&t.s, t.exitance), own_residual(&t, t.exitance), 1e-9);

    uint32_t sweeps[2] = {0, 0};
    for (size_t k = 0; k < 3; k++) {
        CHECK(run(&t, all_solvers[k], 1e-9, 0, false, 0, B, &report) == RAD_OK);
        CHECK(report.converged);
        CHECK(report.criterion <= 1e-9);
        CHECK(report.residual <= 1e-8);
        CHECK(own_residual(&t, B) <= 1e-8);
        CHECK_NEAR(report.residual, own_residual(&t, B), 1e-6);
        for (uint32_t i = 0; i < n; i++) {
            CHECK_NEAR(B[i].r, direct[i].r, 1e-6);
            CHECK_NEAR(B[i].g, direct[i].g, 1e-6);
            CHECK_NEAR(B[i].b, direct[i].b, 1e-6);
        }
        if (k < 2)
            sweeps[k] = report.iterations;
        else
            CHECK(report.iterations > n); /* shots: more than one per patch */
    }
    printf("random n=%u: Jacobi %u sweeps, Gauss-Seidel %u sweeps\n", n, sweeps[0], sweeps[1]);
    CHECK(sweeps[1] > 0 && sweeps[1] < sweeps[0]);

    /* (6) a capped shooting run: the ambient term adds the unshot energy's estimate */
    rad_rgb *plain = rgb_array(n);
    rad_solve_report with, without;
    CHECK(run(&t, RAD_SOLVER_SHOOT, 1e-9, 10, false, 0, plain, &without) == RAD_OK);
    CHECK(run(&t, RAD_SOLVER_SHOOT, 1e-9, 10, true, 0, B, &with) == RAD_OK);
    CHECK(!with.converged && !without.converged);
    CHECK(with.iterations == 10 && without.iterations == 10);
    CHECK(with.criterion > 1e-9);
    CHECK(without.criterion == with.criterion);
    CHECK(total_power(&t, B) > total_power(&t, plain));
    /* it brings the capped answer closer to the converged one, in total */
    CHECK(fabs(total_power(&t, B) - total_power(&t, direct)) <
          fabs(total_power(&t, plain) - total_power(&t, direct)));
    for (uint32_t i = 0; i < n; i++)
        CHECK(B[i].r >= plain[i].r && B[i].g >= plain[i].g && B[i].b >= plain[i].b);

    /* a capped Jacobi run reports non-convergence and its sweep count */
    CHECK(run(&t, RAD_SOLVER_JACOBI, 1e-9, 3, false, 0, B, &report) == RAD_OK);
    CHECK(!report.converged && report.iterations == 3 && report.criterion > 1e-9);

    free(plain);
    free(B);
    free(direct);
    system_free(&t);
}

/* (4) The answer does not depend on the thread count, bit for bit. n is above the size at
 * which the loops go parallel. */
static void test_threads(void)
{
    const uint32_t n = 700;
    test_system t;
    random_system(&t, n, 11);
    rad_rgb *one = rgb_array(n), *two = rgb_array(n);
    const rad_solver solvers[] = {RAD_SOLVER_JACOBI, RAD_SOLVER_SHOOT, RAD_SOLVER_DIRECT};
    for (size_t k = 0; k < 3; k++) {
        rad_solve_report r1, r2;
        CHECK(run(&t, solvers[k], 1e-7, 0, false, 1, one, &r1) == RAD_OK);
        CHECK(run(&t, solvers[k], 1e-7, 0, false, 2, two, &r2) == RAD_OK);
        CHECK(memcmp(one, two, n * sizeof(rad_rgb)) == 0);
        CHECK(r1.iterations == r2.iterations);
        CHECK(r1.criterion == r2.criterion);
        CHECK(r1.residual == r2.residual);
        CHECK(r1.converged && r2.converged);
    }
    free(one);
    free(two);
    system_free(&t);
}

/* A scene without emitters solves to black with residual 0; a NULL report is allowed. */
static void test_black(void)
{
    const uint32_t n = 20;
    test_system t;
    random_system(&t, n, 3);
    for (uint32_t i = 0; i < n; i++)
        t.exitance[i] = (rad_rgb){0, 0, 0};
    rad_rgb *B = rgb_array(n);
    for (size_t k = 0; k < 4; k++) {
        rad_solve_report report;
        for (uint32_t i = 0; i < n; i++)
            B[i] = (rad_rgb){1, 1, 1};
        CHECK(run(&t, all_solvers[k], 0, 0, true, 0, B, &report) == RAD_OK);
        CHECK(report.converged);
        CHECK(report.residual == 0);
        for (uint32_t i = 0; i < n; i++)
            CHECK(B[i].r == 0 && B[i].g == 0 && B[i].b == 0);
        CHECK(run(&t, all_solvers[k], 0, 0, false, 0, B, NULL) == RAD_OK);
    }
    free(B);
    system_free(&t);
}

typedef struct progress_log {
    int calls;
    double last;
    bool monotone;
    bool in_range;
} progress_log;

static void on_progress(void *user, const char *phase, double fraction)
{
    progress_log *log = user;
    if (log->calls > 0 && fraction < log->last)
        log->monotone = false;
    if (!(fraction >= 0 && fraction <= 1) || !phase)
        log->in_range = false;
    log->last = fraction;
    log->calls++;
}

/* Defaults (NULL options = Jacobi, tolerance 1e-4) and progress reports. */
static void test_defaults_and_progress(void)
{
    const uint32_t n = 100;
    test_system t;
    random_system(&t, n, 5);
    rad_rgb *B = rgb_array(n);
    rad_solve_report report;
    CHECK(rad_solve(&t.s, NULL, B, &report, NULL) == RAD_OK);
    CHECK(report.converged && report.criterion <= 1e-4 && report.criterion > 1e-9);
    CHECK(report.residual <= 1e-4);

    for (size_t k = 0; k < 4; k++) {
        progress_log log = {0, 0, true, true};
        rad_solve_options o = {0};
        o.solver = all_solvers[k];
        o.progress = on_progress;
        o.progress_user = &log;
        CHECK(rad_solve(&t.s, &o, B, &report, NULL) == RAD_OK);
        CHECK(log.calls >= 1 && log.calls <= 102);
        CHECK(log.monotone && log.in_range);
        CHECK(log.last == 1);
    }
    free(B);
    system_free(&t);
}

static void expect_invalid(const rad_system *s, const rad_solve_options *o, rad_rgb *B,
                           rad_status expected, int line)
{
    rad_error error = {0};
    rad_solve_report report = {0};
    report.iterations = 123;
    rad_status status = rad_solve(s, o, B, &report, &error);
    test_checks++;
    if (status != expected || error.status != expected || error.message[0] == 0)
        test_fail(__FILE__, line, "expected %s, got %s (%s)", rad_status_name(expected),
                  rad_status_name(status), error.message);
    CHECK(report.iterations == 0);
}

/* (7) Argument errors. */
static void test_invalid(void)
{
    test_system t;
    random_system(&t, 4, 9);
    rad_rgb B[4];
    rad_solve_options o = {0};
    expect_invalid(NULL, &o, B, RAD_ERR_INVALID, __LINE__);
    expect_invalid(&t.s, &o, NULL, RAD_ERR_INVALID, __LINE__);

    rad_system s = t.s;
    s.n = 0;
    expect_invalid(&s, &o, B, RAD_ERR_INVALID, __LINE__);
    s = t.s;
    s.F = NULL;
    expect_invalid(&s, &o, B, RAD_ERR_INVALID, __LINE__);
    s = t.s;
    s.area = NULL;
    expect_invalid(&s, &o, B, RAD_ERR_INVALID, __LINE__);
    s = t.s;
    s.albedo = NULL;
    expect_invalid(&s, &o, B, RAD_ERR_INVALID, __LINE__);
    s = t.s;
    s.exitance = NULL;
    expect_invalid(&s, &o, B, RAD_ERR_INVALID, __LINE__);

    o.tolerance = -1e-3;
    expect_invalid(&t.s, &o, B, RAD_ERR_INVALID, __LINE__);
    o.tolerance = NAN;
    expect_invalid(&t.s, &o, B, RAD_ERR_INVALID, __LINE__);
    o.tolerance = 0;
    o.threads = -1;
    expect_invalid(&t.s, &o, B, RAD_ERR_INVALID, __LINE__);
    o.threads = 0;
    o.solver = (rad_solver)99;
    expect_invalid(&t.s, &o, B, RAD_ERR_INVALID, __LINE__);
    o.solver = RAD_SOLVER_JACOBI;

    double area = t.area[2];
    t.area[2] = 0;
    expect_invalid(&t.s, &o, B, RAD_ERR_INVALID, __LINE__);
    t.area[2] = NAN;
    expect_invalid(&t.s, &o, B, RAD_ERR_INVALID, __LINE__);
    t.area[2] = area;
    rad_rgb rho = t.albedo[3];
    t.albedo[3].g = 1.5;
    expect_invalid(&t.s, &o, B, RAD_ERR_INVALID, __LINE__);
    t.albedo[3].g = -0.1;
    expect_invalid(&t.s, &o, B, RAD_ERR_INVALID, __LINE__);
    t.albedo[3] = rho;
    rad_rgb e = t.exitance[0];
    t.exitance[0].b = -1;
    expect_invalid(&t.s, &o, B, RAD_ERR_INVALID, __LINE__);
    t.exitance[0].b = INFINITY;
    expect_invalid(&t.s, &o, B, RAD_ERR_INVALID, __LINE__);
    t.exitance[0] = e;
    CHECK(rad_solve(&t.s, &o, B, NULL, NULL) == RAD_OK);
    CHECK(isnan(rad_system_residual(NULL, B)));
    system_free(&t);

    /* a singular system: two patches that see only each other, both white */
    test_system w;
    system_alloc(&w, 2);
    w.F[1] = w.F[2] = 1;
    w.area[0] = w.area[1] = 1;
    w.albedo[0] = w.albedo[1] = (rad_rgb){1, 1, 1};
    w.exitance[0] = (rad_rgb){1, 1, 1};
    o.solver = RAD_SOLVER_DIRECT;
    expect_invalid(&w.s, &o, B, RAD_ERR_INVALID, __LINE__);
    /* the iterative solvers run into their caps and say so */
    rad_solve_report report;
    CHECK(run(&w, RAD_SOLVER_GAUSS_SEIDEL, 0, 50, false, 0, B, &report) == RAD_OK);
    CHECK(!report.converged && report.iterations == 50);
    system_free(&w);

    /* the direct solver refuses large systems before touching F */
    test_system big;
    const uint32_t n = 4097;
    system_alloc(&big, n);
    for (uint32_t i = 0; i < n; i++)
        big.area[i] = 1;
    rad_rgb *Bbig = rgb_array(n);
    expect_invalid(&big.s, &o, Bbig, RAD_ERR_UNSUPPORTED, __LINE__);
    free(Bbig);
    system_free(&big);
}

int main(void)
{
    test_two_patches();
    test_furnace();
    test_random_system();
    test_threads();
    test_black();
    test_defaults_and_progress();
    test_invalid();
    return test_finish("test_solve");
}
