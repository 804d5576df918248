/*
 * test_convergence.c - the solvers' observer (rad_solve_step): how many times each solver
 * calls it and with which steps, that every residual it hands over is the residual of the
 * B it hands over (measured here again with rad_system_residual, for the dense solvers),
 * that the last call is the answer with the report's residual, and that observing changes
 * nothing in the answer. Also the history (rad_convergence) it feeds the plot.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "testlib.h"

enum { MAX_CALLS = 4096 };

/* What an observer saw. */
typedef struct seen {
    const rad_system *system; /* dense: measure each B's residual again; NULL: do not */
    uint32_t calls, finals;
    uint32_t step[MAX_CALLS];
    double residual[MAX_CALLS], criterion[MAX_CALLS], unshot[MAX_CALLS], seconds[MAX_CALLS];
    uint32_t shooter[MAX_CALLS];
    const char *phase[MAX_CALLS];
    bool final_last;          /* the final flag was on the last call only */
    double worst_residual_gap; /* largest |handed - measured| / measured */
    rad_rgb *last_B;          /* a copy of the last B handed over */
    uint32_t n;
} seen;

static void observer(void *user, const rad_solve_step *step)
{
    seen *s = user;
    if (s->calls < MAX_CALLS) {
        uint32_t k = s->calls;
        s->step[k] = step->step;
        s->residual[k] = step->residual;
        s->criterion[k] = step->criterion;
        s->unshot[k] = step->unshot;
        s->seconds[k] = step->seconds;
        s->shooter[k] = step->shooting_patch;
        s->phase[k] = step->phase;
    }
    s->calls++;
    s->finals += step->final;
    s->final_last = step->final;
    if (s->system) {
        double measured = rad_system_residual(s->system, step->B);
        double gap = fabs(step->residual - measured) / measured;
        if (!(gap <= s->worst_residual_gap))
            s->worst_residual_gap = gap;
    }
    free(s->last_B);
    s->n = step->n;
    s->last_B = malloc(step->n * sizeof(rad_rgb));
    if (s->last_B)
        memcpy(s->last_B, step->B, step->n * sizeof(rad_rgb));
}

/* A random system with F_ij A_i = F_ji A_j exactly in float, rows of F summing to < 0.9,
 * albedos up to 0.9 and a few emitters: every solver converges on it. */
typedef struct random_system {
    rad_system s;
    float *F;
    double *area;
    rad_rgb *albedo, *exitance;
} random_system;

static double next_uniform(uint64_t *state)
{
    *state = *state * 6364136223846793005u + 1442695040888963407u;
    return (double)(*state >> 11) * 0x1.0p-53;
}

static void random_system_make(random_system *r, uint32_t n, uint64_t seed)
{
    r->F = calloc((size_t)n * n, sizeof(float));
    r->area = calloc(n, sizeof(double));
    r->albedo = calloc(n, sizeof(rad_rgb));
    r->exitance = calloc(n, sizeof(rad_rgb));
    if (!r->F || !r->area || !r->albedo || !r->exitance)
        exit(1);
    for (uint32_t i = 0; i < n; i++) {
        r->area[i] = 1 << (int)(next_uniform(&seed) * 3); /* 1, 2 or 4: exact products */
        r->albedo[i] = (rad_rgb){0.9 * next_uniform(&seed), 0.9 * next_uniform(&seed),
                                 0.9 * next_uniform(&seed)};
        if (i % 7 == 0)
            r->exitance[i] = (rad_rgb){1 + next_uniform(&seed), 2, 3 * next_uniform(&seed)};
    }
    /* F_ij = g_ij A_j with g symmetric and a power of two scale: A_i F_ij = A_j F_ji */
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = i + 1; j < n; j++) {
            float g = (float)ldexp(floor(ldexp(next_uniform(&seed), 12)), -12) / (float)(8 * n);
            r->F[(size_t)i * n + j] = g * (float)r->area[j];
            r->F[(size_t)j * n + i] = g * (float)r->area[i];
        }
    r->s = (rad_system){n, r->F, r->area, r->albedo, r->exitance};
}

static void random_system_free(random_system *r)
{
    free(r->F);
    free(r->area);
    free(r->albedo);
    free(r->exitance);
}

/* Solves with and without the observer: the answers are identical bit for bit, and the
 * calls are checked against the report. */
static void check_dense(const random_system *r, rad_solver solver, uint32_t every)
{
    const uint32_t n = r->s.n;
    rad_rgb *plain = calloc(n, sizeof(rad_rgb)), *watched = calloc(n, sizeof(rad_rgb));
    if (!plain || !watched)
        exit(1);
    rad_solve_options o = {0};
    o.solver = solver;
    o.tolerance = 1e-6;
    o.threads = 2;
    rad_solve_report plain_report, report;
    rad_error error = {0};
    CHECK(rad_solve(&r->s, &o, plain, &plain_report, &error) == RAD_OK);

    seen *s = calloc(1, sizeof(seen));
    if (!s)
        exit(1);
    s->system = &r->s;
    o.observer = observer;
    o.observer_user = s;
    o.observe_every = every;
    CHECK(rad_solve(&r->s, &o, watched, &report, &error) == RAD_OK);
    CHECK(memcmp(plain, watched, n * sizeof(rad_rgb)) == 0);
    CHECK(report.iterations == plain_report.iterations);

    uint32_t expected = report.iterations + 1; /* steps 0 .. iterations */
    if (solver == RAD_SOLVER_DIRECT)
        expected = 1;
    if (solver == RAD_SOLVER_SHOOT) {
        uint32_t k = every ? every : n / RAD_OBSERVE_SHOTS_DIVISOR;
        if (k == 0)
            k = 1;
        expected = (report.iterations + k - 1) / k + 1; /* 0, k, 2k, ... below S, and S */
        for (uint32_t c = 0; c + 1 < s->calls && c < MAX_CALLS; c++)
            CHECK(s->step[c] == c * k);
    } else {
        for (uint32_t c = 0; c < s->calls && c < MAX_CALLS; c++)
            CHECK(s->step[c] == c);
    }
    if (s->calls != expected)
        fprintf(stderr, "%s: %u calls, expected %u (%u iterations)\n", rad_solver_name(solver),
                s->calls, expected, report.iterations);
    CHECK(s->calls == expected);
    CHECK(s->finals == 1 && s->final_last);
    uint32_t last = s->calls - 1;
    CHECK(s->step[last] == report.iterations);
    CHECK(s->residual[last] == report.residual);
    CHECK(s->last_B && memcmp(s->last_B, watched, n * sizeof(rad_rgb)) == 0);
    /* every residual handed over is the one measured here on the B handed over (Jacobi's
     * comes from the next sweep, summed in another order) */
    if (s->worst_residual_gap > 1e-9)
        fprintf(stderr, "%s: residual off by %.3g relative\n", rad_solver_name(solver),
                s->worst_residual_gap);
    CHECK(s->worst_residual_gap <= 1e-9);
    for (uint32_t c = 0; c < s->calls && c < MAX_CALLS; c++) {
        CHECK(s->seconds[c] >= 0);
        CHECK(c == 0 || s->seconds[c] >= s->seconds[c - 1]);
        CHECK(strcmp(s->phase[c], rad_solver_name(solver)) == 0);
        if (solver == RAD_SOLVER_SHOOT) {
            CHECK(s->unshot[c] == s->criterion[c]);
            CHECK(c == 0 || s->unshot[c] <= s->unshot[c - 1]); /* never rises */
            CHECK(c == 0 ? s->shooter[c] == UINT32_MAX : s->shooter[c] < n);
        } else {
            CHECK(isnan(s->unshot[c]) && s->shooter[c] == UINT32_MAX);
        }
        if (solver == RAD_SOLVER_JACOBI || solver == RAD_SOLVER_GAUSS_SEIDEL)
            CHECK(c == 0 ? isnan(s->criterion[c]) : s->criterion[c] > 0);
    }
    /* Jacobi's criterion at sweep k is the residual of B_(k-1) */
    if (solver == RAD_SOLVER_JACOBI)
        for (uint32_t c = 1; c < s->calls && c < MAX_CALLS; c++)
            CHECK_NEAR(s->criterion[c], s->residual[c - 1], 1e-9);
    free(s->last_B);
    free(s);
    free(plain);
    free(watched);
}

/* The hierarchical solver on the Cornell box: one call per sweep and one for the answer. */
static void check_hierarchical(void)
{
    rad_error error = {0};
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    CHECK(rad_scene_cornell_box(&scene, &error) == RAD_OK);
    CHECK(test_mesh_uniform(scene, 120, &mesh, &error) == RAD_OK);
    if (!mesh) {
        rad_scene_destroy(scene);
        return;
    }
    uint32_t n = mesh->patch_count;
    rad_rgb *plain = calloc(n, sizeof(rad_rgb)), *watched = calloc(n, sizeof(rad_rgb));
    seen *s = calloc(1, sizeof(seen));
    if (!plain || !watched || !s)
        exit(1);
    rad_scene_solve_options o = {0};
    o.solver = RAD_SOLVER_HIERARCHICAL;
    o.threads = 2;
    rad_scene_solve_report plain_report, report;
    CHECK(rad_solve_scene(scene, mesh, &o, plain, &plain_report, &error) == RAD_OK);
    o.observer = observer;
    o.observer_user = s;
    CHECK(rad_solve_scene(scene, mesh, &o, watched, &report, &error) == RAD_OK);
    CHECK(memcmp(plain, watched, n * sizeof(rad_rgb)) == 0);
    const rad_hierarchy_report *h = &report.hierarchy;
    fprintf(stderr, "hierarchical: %u patches, %u passes, %u sweeps, %u calls\n", n, h->passes,
            h->iterations, s->calls);
    CHECK(h->iterations > 2);
    CHECK(s->calls == h->iterations + 1);
    CHECK(s->finals == 1 && s->final_last);
    uint32_t last = s->calls - 1;
    CHECK(s->step[last] == h->iterations);
    CHECK(s->residual[last] == h->residual);
    CHECK(s->criterion[last] == h->change);
    CHECK(s->last_B && memcmp(s->last_B, watched, n * sizeof(rad_rgb)) == 0);
    CHECK(strcmp(s->phase[0], "start") == 0 && isnan(s->criterion[0]));
    uint32_t refine = 0, gather = 0, final_gather = 0;
    for (uint32_t c = 0; c < s->calls && c < MAX_CALLS; c++) {
        CHECK(s->step[c] == c);
        CHECK(isfinite(s->residual[c]) && s->residual[c] >= 0);
        refine += strcmp(s->phase[c], "refine") == 0;
        gather += strcmp(s->phase[c], "gather") == 0;
        final_gather += strcmp(s->phase[c], "final gather") == 0;
    }
    /* every refinement pass is followed by one sweep */
    CHECK(refine > 0 && refine <= h->passes);
    CHECK(gather > 0 && final_gather > 0);
    CHECK(refine + gather + final_gather == h->iterations);
    free(s->last_B);
    free(s);
    free(plain);
    free(watched);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* The history keeps each step's numbers in order. */
static void check_history(void)
{
    rad_convergence history = {0};
    rad_error error = {0};
    for (uint32_t k = 0; k < 100; k++) {
        rad_solve_step step = {0};
        step.step = 3 * k;
        step.seconds = 0.5 * k;
        step.criterion = pow(0.5, k);
        step.residual = pow(0.25, k);
        step.unshot = NAN;
        CHECK(rad_convergence_add(&history, &step, &error) == RAD_OK);
    }
    CHECK(history.count == 100);
    CHECK(history.points[99].step == 297 && history.points[99].seconds == 49.5);
    CHECK(history.points[10].residual == pow(0.25, 10) && isnan(history.points[10].unshot));
    rad_convergence_free(&history);
    CHECK(history.count == 0 && history.points == NULL);
    CHECK(rad_convergence_plot_write(&history, test_path("empty.svg"), NULL, &error) ==
          RAD_ERR_INVALID);
}

/* An observer that records every step and keeps the history: what `solve --record
 * --plot` does, for the allocation-failure sweep below. */
typedef struct outputs {
    rad_solve_record *record;
    rad_convergence history;
    rad_status status;
    rad_error error;
} outputs;

static void record_observer(void *user, const rad_solve_step *step)
{
    outputs *o = user;
    if (o->status == RAD_OK)
        o->status = rad_convergence_add(&o->history, step, &o->error);
    if (o->status == RAD_OK)
        o->status = rad_solve_record_add(o->record, step, &o->error);
}

/* Solve, record and plot (the record is committed before the plot is written). */
static rad_status observed_run(const random_system *r, rad_solver solver, rad_error *error)
{
    outputs o = {0};
    rad_status status = rad_solve_record_open(test_path("sweep.json"), "random", "x", r->s.n,
                                              &o.record, error);
    if (status != RAD_OK)
        return status;
    rad_rgb *B = rad_alloc_array(r->s.n, sizeof(rad_rgb));
    if (!B) {
        rad_solve_record_abort(o.record);
        return rad_fail(error, RAD_ERR_NOMEM, "no B");
    }
    rad_solve_options opt = {0};
    opt.solver = solver;
    opt.observer = record_observer;
    opt.observer_user = &o;
    opt.threads = 1;
    status = rad_solve(&r->s, &opt, B, NULL, error);
    if (status == RAD_OK && o.status != RAD_OK) {
        *error = o.error;
        status = o.status;
    }
    if (status == RAD_OK)
        status = rad_solve_record_commit(o.record, error);
    else
        rad_solve_record_abort(o.record);
    rad_convergence_plot_options plot = {"sweep", "sweeps", true, "criterion", NULL, NULL};
    if (status == RAD_OK)
        status = rad_convergence_plot_write(&o.history, test_path("sweep.svg"), &plot, error);
    rad_convergence_free(&o.history);
    free(B);
    return status;
}

/* Every allocation of an observed solve, its record and its plot failing in turn: a clean
 * RAD_ERR_NOMEM each time, no temporary file and no plot left; then the run succeeds. */
static void check_allocation_failures(const random_system *r, rad_solver solver)
{
    rad_error error = {0};
    for (uint64_t n = 1; n < 10000; n++) {
        remove(test_path("sweep.json"));
        remove(test_path("sweep.svg"));
        rad_alloc_fail_nth(n);
        rad_status status = observed_run(r, solver, &error);
        bool injected = rad_alloc_failure_injected();
        rad_alloc_fail_nth(0);
        if (!injected) {
            CHECK(status == RAD_OK);
            CHECK(test_file_exists(test_path("sweep.json")) &&
                  test_file_exists(test_path("sweep.svg")));
            CHECK(n > 4);
            return;
        }
        /* no temporary left; the record may stand, whole, when the plot failed after it */
        CHECK(status == RAD_ERR_NOMEM);
        CHECK(test_count_files("sweep.json.tmp") == 0 && test_count_files("sweep.svg") == 0);
        if (status != RAD_ERR_NOMEM || test_count_files("sweep.json.tmp") != 0 ||
            test_count_files("sweep.svg") != 0)
            fprintf(stderr, "%s: allocation %llu failed: %s\n", rad_solver_name(solver),
                    (unsigned long long)n, rad_status_name(status));
    }
    CHECK(!"the sweep did not end");
}

int main(void)
{
    test_tmpdir();
    random_system r;
    random_system_make(&r, 200, 7);
    check_dense(&r, RAD_SOLVER_JACOBI, 0);
    check_dense(&r, RAD_SOLVER_GAUSS_SEIDEL, 0);
    check_dense(&r, RAD_SOLVER_SHOOT, 0);  /* the default: every n / 16 shots */
    check_dense(&r, RAD_SOLVER_SHOOT, 7);
    check_dense(&r, RAD_SOLVER_SHOOT, 1);
    check_dense(&r, RAD_SOLVER_DIRECT, 0);
    random_system_free(&r);
    random_system_make(&r, 40, 11);
    check_allocation_failures(&r, RAD_SOLVER_JACOBI);
    check_allocation_failures(&r, RAD_SOLVER_GAUSS_SEIDEL);
    check_allocation_failures(&r, RAD_SOLVER_SHOOT);
    random_system_free(&r);
    check_hierarchical();
    check_history();
    return test_finish("test_convergence");
}
