/*
 * solve_internal.h - what rad_solve (solve.c) shares with the individual solvers.
 *
 * rad_solve validates the system and the options, applies the defaults, times the run and
 * computes the final residual; a solver only iterates. A solver receives a valid system
 * (n > 0, every array present, areas > 0, albedo in [0,1], exitance >= 0), resolved
 * parameters, and fills B plus the iterations / criterion / converged fields of the
 * report. It does not check its arguments again. F itself is trusted (never scanned).
 *
 * Results never depend on the thread count: every value is computed by one thread in a
 * fixed order, and every sum across patches is taken in a fixed order of fixed blocks.
 */
#ifndef RAD_SOLVE_INTERNAL_H
#define RAD_SOLVE_INTERNAL_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#include "radiosity.h"
#include "solve/solve_checkpoint.h"

/* The options of rad_solve after validation and defaults. */
typedef struct solve_params {
    double tolerance;        /* > 0: stop when the solver's criterion is <= this */
    uint32_t max_iterations; /* > 0: sweeps (gathering) or shots (shooting) */
    bool ambient;            /* shooting: add the ambient term after stopping */
    int threads;             /* > 0: the OpenMP team size */
    rad_progress_fn progress;
    void *progress_user;
    double progress_sent;    /* last fraction passed to progress (solve_progress only) */
    /* the observer (solve_observe.c); observer NULL: none of these is used */
    rad_solve_observer_fn observer;
    void *observer_user;
    uint32_t observe_every;  /* > 0: shooting, shots between two calls */
    double start;            /* clock at the solver's start */
    double observe_seconds;  /* spent observing, left out of rad_solve_step.seconds */
    rad_rgb *observed;       /* n values: B in the observer's layout (Jacobi, Gauss-Seidel) */
    uint32_t last_shooter;   /* shooting: the patch of the last shot, or UINT32_MAX */
    solve_checkpoint *checkpoint; /* NULL: none; else iterate_step between sweeps (shots),
                                     and a resumed ITERATE state taken at the start */
} solve_params;

/* Sums across patches are split into at most this many contiguous blocks of rows, each
 * summed by one thread in order, then the block sums are added in order: the result is
 * the same for any thread count. */
enum { SOLVE_BLOCKS = 256 };

/* Below this many patches a loop over patches runs on one thread (a parallel region would
 * cost more than it saves). */
enum { SOLVE_PARALLEL_MIN = 512 };

/* Rows [begin, end) of block b when n rows are split into `blocks` blocks. */
static inline uint32_t solve_block_begin(uint32_t n, uint32_t blocks, uint32_t b)
{
    return (uint32_t)((uint64_t)n * b / blocks);
}

/* Number of blocks for n rows: min(n, SOLVE_BLOCKS). */
static inline uint32_t solve_block_count(uint32_t n)
{
    return n < SOLVE_BLOCKS ? n : SOLVE_BLOCKS;
}

/* sums[c] = sum over j in [begin, end) of row[j] * x[c][j], accumulated in double. The
 * simd reduction lets the compiler split the sum into vector lanes: the order is fixed by
 * the compiled code, not by the calling thread. Hot path: no checks. */
#if defined(__clang__)
/* clang cannot vectorise under AddressSanitizer and says so; that is no defect of the code */
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wpass-failed"
#endif
static inline void solve_row_dot(const float *restrict row, const double *restrict x0,
                                 const double *restrict x1, const double *restrict x2,
                                 uint32_t begin, uint32_t end, double sums[3])
{
    double s0 = 0, s1 = 0, s2 = 0;
#pragma omp simd reduction(+ : s0, s1, s2)
    for (uint32_t j = begin; j < end; j++) {
        double f = (double)row[j];
        s0 += f * x0[j];
        s1 += f * x1[j];
        s2 += f * x2[j];
    }
    sums[0] = s0;
    sums[1] = s1;
    sums[2] = s2;
}
#if defined(__clang__)
#pragma clang diagnostic pop
#endif

/* sum_i A_i |E_i|_1: the denominator of every relative criterion. Computed in the fixed
 * patch order. */
double solve_exitance_norm(const rad_system *system);

/* Scale that turns an area-weighted L1 norm into the relative criterion: the norm of E,
 * or 1 when E is zero (the criterion is then absolute, so a black scene gives 0). */
double solve_criterion_scale(const rad_system *system);

/* rad_system_residual with an explicit OpenMP team size (> 0). */
double solve_residual(const rad_system *system, const rad_rgb *B, int threads);

/* Reports progress from the criterion: the fraction is log(criterion) / log(tolerance)
 * clamped to [0,1], sent only when it grew by at least 1% (or reached 1). */
void solve_progress(solve_params *params, double criterion);

/* The observer (solve_observe.c). A step's seconds: solver time since params->start, the
 * observing left out. */
double solve_elapsed(const solve_params *params);

/* Hands `step` to the observer with B given as three channel arrays (copied to
 * params->observed) or as rad_rgb (B_rgb, x0 NULL); with compute_residual the step's
 * residual is measured first (one pass over F). Its time goes to params->observe_seconds.
 * Nothing happens without an observer. */
void solve_observe(solve_params *params, const rad_system *system, rad_solve_step step,
                   const double *x0, const double *x1, const double *x2, const rad_rgb *B_rgb,
                   bool compute_residual);

/* A step with the fields every solver sets, the rest NaN / UINT32_MAX / false. */
rad_solve_step solve_step(const solve_params *params, uint32_t n, uint32_t step,
                          const char *phase, double criterion);

/* A solver's criterion falls (Jacobi and shooting: never rises) when no row of rho F sums
 * above 1, which rad_solve checks first; a criterion that is not finite or has grown to
 * this many times the smallest it had means the iteration diverges. */
#define SOLVE_DIVERGENCE_GROWTH 100.0

/* Keeps *smallest up to date; true when the iteration diverges (see above). */
static inline bool solve_diverging(double criterion, double *smallest)
{
    if (!(criterion < INFINITY))
        return true;
    if (criterion < *smallest)
        *smallest = criterion;
    return criterion > SOLVE_DIVERGENCE_GROWTH * *smallest;
}

/* The error for a diverging iteration: what the solver saw and the patch where it saw it
 * (report->patch, for the caller to name its surface). Returns RAD_ERR_INVALID. */
rad_status solve_fail_diverged(const rad_system *system, const char *solver,
                               uint32_t iterations, double criterion, double smallest,
                               uint32_t patch, rad_solve_report *report, rad_error *error);

/* The solvers. Each returns RAD_OK or RAD_ERR_NOMEM (direct: also RAD_ERR_UNSUPPORTED for
 * too large systems, RAD_ERR_INVALID for a singular matrix). `report` is never NULL.
 * iterations: sweeps (Jacobi, Gauss-Seidel), shots (shooting), 0 for the direct solver.
 * criterion: the relative change of the last sweep, the unshot fraction, or (direct) the
 * relative residual of the answer. */
rad_status solve_jacobi(const rad_system *system, solve_params *params, rad_rgb *B,
                        rad_solve_report *report, rad_error *error);
rad_status solve_gauss_seidel(const rad_system *system, solve_params *params, rad_rgb *B,
                              rad_solve_report *report, rad_error *error);
rad_status solve_shoot(const rad_system *system, solve_params *params, rad_rgb *B,
                       rad_solve_report *report, rad_error *error);
rad_status solve_direct(const rad_system *system, solve_params *params, rad_rgb *B,
                        rad_solve_report *report, rad_error *error);

#endif
