/*
 * solve.c - rad_solve: the front door of the solvers.
 *
 * Validates the system and the options, applies the defaults, dispatches to one solver
 * (solve_jacobi.c, solve_gauss_seidel.c, solve_shoot.c, solve_direct.c), times it (the
 * final residual is not included in report->seconds) and measures the relative residual
 * of the answer the same way for all of them. It does not iterate itself. Validation is
 * O(n) (the per-patch arrays); F is trusted, never scanned.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/clock.h"

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/alloc.h"
#include "core/error.h"
#include "core/rgb.h"
#include "solve/solve_internal.h"

/* Defaults for the zero values of rad_solve_options (see radiosity.h). */
#define SOLVE_DEFAULT_TOLERANCE RAD_DEFAULT_TOLERANCE /* residual / unshot fraction */
#define SOLVE_DEFAULT_SWEEPS RAD_DEFAULT_MAX_SWEEPS
#define SOLVE_DEFAULT_SHOTS_PER_PATCH RAD_DEFAULT_SHOTS_PER_PATCH

/* Progress is reported only when the fraction grew by at least this much. */
#define SOLVE_PROGRESS_STEP 0.01

static double wall_seconds(void) { return rad_clock_seconds(); }


static rad_status check_system(const rad_system *system, rad_error *error)
{
    if (!system)
        return rad_fail(error, RAD_ERR_INVALID, "rad_solve: no system given");
    if (system->n == 0)
        return rad_fail(error, RAD_ERR_INVALID, "rad_solve: the system has no patches");
    if (!system->F || !system->area || !system->albedo || !system->exitance)
        return rad_fail(error, RAD_ERR_INVALID,
                        "rad_solve: the system lacks its form factors, areas, albedos or "
                        "exitances");
    for (uint32_t i = 0; i < system->n; i++) {
        double a = system->area[i];
        rad_rgb rho = system->albedo[i];
        rad_rgb e = system->exitance[i];
        if (!(isfinite(a) && a > 0))
            return rad_fail(error, RAD_ERR_INVALID,
                            "rad_solve: patch %u has area %g (must be finite and > 0)", i, a);
        if (!(rgb_finite(rho) && rho.r >= 0 && rho.r <= 1 && rho.g >= 0 && rho.g <= 1 &&
              rho.b >= 0 && rho.b <= 1))
            return rad_fail(error, RAD_ERR_INVALID,
                            "rad_solve: patch %u has albedo (%g, %g, %g) outside [0,1]", i,
                            rho.r, rho.g, rho.b);
        if (!(rgb_finite(e) && e.r >= 0 && e.g >= 0 && e.b >= 0))
            return rad_fail(error, RAD_ERR_INVALID,
                            "rad_solve: patch %u has exitance (%g, %g, %g) (must be finite "
                            "and >= 0)",
                            i, e.r, e.g, e.b);
    }
    return RAD_OK;
}

/* No row of rho F may sum above 1 (+ slack): such a system creates energy. O(n^2) once,
 * cheaper than one sweep. */
static rad_status check_energy(const rad_system *system, int threads, rad_solve_report *report,
                               rad_error *error)
{
    const uint32_t n = system->n;
    double worst = 0;
    uint32_t worst_patch = 0;
    (void)threads; /* unused without OpenMP */
    const uint32_t blocks = solve_block_count(n);
    double block_worst[SOLVE_BLOCKS];
    uint32_t block_patch[SOLVE_BLOCKS];
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= SOLVE_PARALLEL_MIN)
    for (uint32_t b = 0; b < blocks; b++) {
        block_worst[b] = 0;
        block_patch[b] = solve_block_begin(n, blocks, b);
        for (uint32_t i = solve_block_begin(n, blocks, b); i < solve_block_begin(n, blocks, b + 1);
             i++) {
            const float *row = system->F + (size_t)i * n;
            double sum = 0;
            for (uint32_t j = 0; j < n; j++)
                sum += row[j];
            rad_rgb rho = system->albedo[i];
            double gain = sum * fmax(rho.r, fmax(rho.g, rho.b));
            if (!(gain <= block_worst[b])) {
                block_worst[b] = gain;
                block_patch[b] = i;
            }
        }
    }
    for (uint32_t b = 0; b < blocks; b++)
        if (!(block_worst[b] <= worst)) {
            worst = block_worst[b];
            worst_patch = block_patch[b];
        }
    if (worst <= 1 + RAD_ROW_SUM_SLACK)
        return RAD_OK;
    report->patch = worst_patch;
    double sum = 0;
    for (uint32_t j = 0; j < n; j++)
        sum += system->F[(size_t)worst_patch * n + j];
    return rad_fail(error, RAD_ERR_INVALID,
                    "rad_solve: the form factors of patch %u sum to %.6g and its albedo is "
                    "%.3g: the system creates energy (rho x row sum must be at most 1), so no "
                    "solver converges",
                    worst_patch, sum, worst / sum);
}

rad_status solve_fail_diverged(const rad_system *system, const char *solver,
                               uint32_t iterations, double criterion, double smallest,
                               uint32_t patch, rad_solve_report *report, rad_error *error)
{
    const uint32_t n = system->n;
    double sum = 0;
    for (uint32_t j = 0; j < n; j++)
        sum += system->F[(size_t)patch * n + j];
    report->patch = patch;
    report->iterations = iterations;
    report->criterion = criterion;
    return rad_fail(error, RAD_ERR_INVALID,
                    "rad_solve: the %s solver diverges: after %u iterations its criterion is "
                    "%.3g, up from %.3g; patch %u changes the most (its form factors sum to "
                    "%.6g)",
                    solver, iterations, criterion, smallest, patch, sum);
}

static rad_status resolve_options(const rad_solve_options *options, uint32_t n,
                                  solve_params *params, rad_error *error)
{
    rad_solve_options zero = {0};
    const rad_solve_options *o = options ? options : &zero;

    if (o->solver == RAD_SOLVER_HIERARCHICAL)
        return rad_fail(error, RAD_ERR_INVALID,
                        "rad_solve: the hierarchical solver needs the mesh "
                        "(rad_solve_hierarchical, or rad_solve_scene)");
    if (o->solver != RAD_SOLVER_AUTO && o->solver != RAD_SOLVER_JACOBI &&
        o->solver != RAD_SOLVER_GAUSS_SEIDEL && o->solver != RAD_SOLVER_SHOOT &&
        o->solver != RAD_SOLVER_DIRECT)
        return rad_fail(error, RAD_ERR_INVALID, "rad_solve: unknown solver %d",
                        (int)o->solver);
    if (!(o->tolerance >= 0 && isfinite(o->tolerance)))
        return rad_fail(error, RAD_ERR_INVALID,
                        "rad_solve: tolerance %g (must be finite and >= 0)", o->tolerance);
    if (o->threads < 0)
        return rad_fail(error, RAD_ERR_INVALID,
                        "rad_solve: threads %d (must be >= 0; 0 = all cores)", o->threads);

    memset(params, 0, sizeof(*params));
    params->tolerance = o->tolerance > 0 ? o->tolerance : SOLVE_DEFAULT_TOLERANCE;
    params->max_iterations = o->max_iterations;
    if (params->max_iterations == 0) {
        if (o->solver == RAD_SOLVER_SHOOT) {
            uint64_t shots = (uint64_t)n * SOLVE_DEFAULT_SHOTS_PER_PATCH;
            params->max_iterations = shots > UINT32_MAX ? UINT32_MAX : (uint32_t)shots;
        } else {
            params->max_iterations = SOLVE_DEFAULT_SWEEPS;
        }
    }
    params->ambient = o->ambient;
    params->threads = o->threads;
#ifdef _OPENMP
    if (params->threads == 0)
        params->threads = omp_get_max_threads();
#endif
    if (params->threads <= 0)
        params->threads = 1;
    params->progress = o->progress;
    params->progress_user = o->progress_user;
    params->progress_sent = -1;
    params->observer = o->observer;
    params->observer_user = o->observer_user;
    params->observe_every = o->observe_every;
    if (params->observe_every == 0)
        params->observe_every = n / RAD_OBSERVE_SHOTS_DIVISOR > 0 ? n / RAD_OBSERVE_SHOTS_DIVISOR
                                                                  : 1;
    params->last_shooter = UINT32_MAX;
    return RAD_OK;
}

void solve_progress(solve_params *params, double criterion)
{
    if (!params->progress)
        return;
    double fraction = 1;
    if (criterion > params->tolerance) {
        /* criterion starts near 1 and falls geometrically towards the tolerance */
        fraction = criterion >= 1 ? 0 : log(criterion) / log(params->tolerance);
        if (!(fraction >= 0))
            fraction = 0;
        if (fraction > 1)
            fraction = 1;
    }
    if (fraction >= params->progress_sent + SOLVE_PROGRESS_STEP ||
        (fraction == 1 && params->progress_sent < 1)) {
        params->progress_sent = fraction;
        params->progress(params->progress_user, "solve", fraction);
    }
}

rad_status rad_solve(const rad_system *system, const rad_solve_options *options,
                     rad_rgb *B, rad_solve_report *report, rad_error *error)
{
    return solve_checkpointed(system, options, NULL, B, report, error);
}

rad_status solve_checkpointed(const rad_system *system, const rad_solve_options *options,
                              solve_checkpoint *cp, rad_rgb *B, rad_solve_report *report,
                              rad_error *error)
{
    rad_solve_report local;
    if (!report)
        report = &local;
    memset(report, 0, sizeof(*report));
    report->patch = UINT32_MAX;

    rad_status status = check_system(system, error);
    if (status != RAD_OK)
        return status;
    if (!B)
        return rad_fail(error, RAD_ERR_INVALID, "rad_solve: no output array B given");
    solve_params params;
    status = resolve_options(options, system->n, &params, error);
    if (status != RAD_OK)
        return status;

    status = check_energy(system, params.threads, report, error);
    if (status != RAD_OK)
        return status;
    if (params.observer) {
        params.observed = rad_alloc_array(system->n, sizeof(rad_rgb));
        if (!params.observed)
            return rad_fail(error, RAD_ERR_NOMEM,
                            "rad_solve: no memory for the observer's copy of %u patches",
                            system->n);
    }
    double start = wall_seconds();
    params.start = start;
    params.checkpoint = cp;
    switch (options ? options->solver : RAD_SOLVER_JACOBI) {
    case RAD_SOLVER_AUTO:
    case RAD_SOLVER_JACOBI:
        status = solve_jacobi(system, &params, B, report, error);
        break;
    case RAD_SOLVER_GAUSS_SEIDEL:
        status = solve_gauss_seidel(system, &params, B, report, error);
        break;
    case RAD_SOLVER_SHOOT:
        status = solve_shoot(system, &params, B, report, error);
        break;
    case RAD_SOLVER_DIRECT:
        status = solve_direct(system, &params, B, report, error);
        break;
    case RAD_SOLVER_HIERARCHICAL: /* refused by resolve_options */
        break;
    }
    if (status != RAD_OK) {
        free(params.observed);
        return status;
    }

    report->seconds = wall_seconds() - start;
    report->residual = solve_residual(system, B, params.threads);
    if (params.observer) { /* the answer handed out */
        rad_solver solver = options->solver == RAD_SOLVER_AUTO ? RAD_SOLVER_JACOBI
                                                               : options->solver;
        rad_solve_step step = solve_step(&params, system->n, report->iterations,
                                         rad_solver_name(solver), report->criterion);
        step.seconds = report->seconds - params.observe_seconds;
        step.residual = report->residual;
        step.final = true;
        if (solver == RAD_SOLVER_SHOOT) {
            step.unshot = report->criterion;
            step.shooting_patch = params.last_shooter;
        }
        solve_observe(&params, system, step, NULL, NULL, NULL, B, false);
        free(params.observed);
    }
    solve_progress(&params, 0);
    return RAD_OK;
}

static const struct {
    rad_solver solver;
    const char *name;
} solver_names[] = {{RAD_SOLVER_AUTO, "auto"},
                    {RAD_SOLVER_JACOBI, "gather"},
                    {RAD_SOLVER_GAUSS_SEIDEL, "gauss-seidel"},
                    {RAD_SOLVER_SHOOT, "shoot"},
                    {RAD_SOLVER_DIRECT, "direct"},
                    {RAD_SOLVER_HIERARCHICAL, "hierarchical"}};

const char *rad_solver_name(rad_solver solver)
{
    for (size_t k = 0; k < sizeof(solver_names) / sizeof(solver_names[0]); k++)
        if (solver_names[k].solver == solver)
            return solver_names[k].name;
    return "unknown";
}

bool rad_solver_from_name(const char *name, rad_solver *solver)
{
    if (strcmp(name, "jacobi") == 0)
        name = "gather";
    for (size_t k = 0; k < sizeof(solver_names) / sizeof(solver_names[0]); k++)
        if (strcmp(solver_names[k].name, name) == 0) {
            *solver = solver_names[k].solver;
            return true;
        }
    return false;
}
