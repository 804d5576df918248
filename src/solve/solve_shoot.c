/*
 * solve_shoot.c - progressive refinement (Southwell iteration, Cohen et al. 1988).
 *
 * Every patch keeps its radiosity B and its unshot radiosity dB, both starting at E. A shot
 * takes the patch i with the most unshot power A_i |dB_i|_1, zeroes dB_i and sends it to
 * every patch j (i itself included when F_ii > 0):
 *     delta_j = rho_j F_ji dB_i,   F_ji = A_i F_ij / A_j   (reciprocity)
 *     B_j += delta_j,  dB_j += delta_j
 * so a shot reads row i of F contiguously. Criterion: the unshot fraction
 * sum_j A_j |dB_j|_1 / sum_j A_j |E_j|_1. It is not the residual: B is always the
 * light that has been shot so far, and the residual is rho F dB.
 *
 * One pass over the patches per shot does the update, the unshot sum and the search for the
 * next shooter: fixed blocks of patches (parallel for large n), each summed in order, the
 * blocks combined in order, ties going to the lowest index, so the sequence of shots does
 * not depend on the thread count. The optional ambient term (added once, after stopping)
 * estimates where the unshot energy would end up, for display.
 */
#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "solve/solve_internal.h"

/* The ambient term multiplies the unshot radiosity by 1 / (1 - mean albedo), the sum of
 * all its bounces. A mean albedo of 1 would make that infinite; it is capped here, which
 * bounds the factor at 100. */
#define SHOOT_AMBIENT_ALBEDO_MAX 0.99

/* A shot costs a few nanoseconds per patch and a parallel region a few microseconds (far
 * more when the cores are shared), and there are thousands of shots: below this many
 * patches the shots run on one thread. */
enum { SHOOT_PARALLEL_MIN = 16384 };

/* What one block of patches contributes to the choice of the next shooter. */
typedef struct shoot_block {
    double unshot;  /* sum of A_j |dB_j|_1 over the block, in order */
    double best;    /* largest A_j |dB_j|_1 in the block */
    uint32_t which; /* the first patch reaching `best` */
} shoot_block;

/* Sends `power` (A_i dB_i per channel) from row i to the patches [begin, end) and
 * summarises the block afterwards. w_j = rho_j / A_j. Hot path: no checks. */
static shoot_block shoot_range(const float *restrict row, rad_rgb power,
                               const rad_rgb *restrict w, const double *restrict area,
                               rad_rgb *restrict B, rad_rgb *restrict dB, uint32_t begin,
                               uint32_t end)
{
    shoot_block s = {0, -1, begin};
    for (uint32_t j = begin; j < end; j++) {
        double f = (double)row[j];
        double d0 = w[j].r * f * power.r;
        double d1 = w[j].g * f * power.g;
        double d2 = w[j].b * f * power.b;
        B[j].r += d0;
        B[j].g += d1;
        B[j].b += d2;
        dB[j].r += d0;
        dB[j].g += d1;
        dB[j].b += d2;
        double p = area[j] * (dB[j].r + dB[j].g + dB[j].b);
        s.unshot += p;
        if (p > s.best) {
            s.best = p;
            s.which = j;
        }
    }
    return s;
}

/* The block summary without shooting (before the first shot). */
static shoot_block scan_range(const double *area, const rad_rgb *dB, uint32_t begin,
                              uint32_t end)
{
    shoot_block s = {0, -1, begin};
    for (uint32_t j = begin; j < end; j++) {
        double p = area[j] * (dB[j].r + dB[j].g + dB[j].b);
        s.unshot += p;
        if (p > s.best) {
            s.best = p;
            s.which = j;
        }
    }
    return s;
}

/* Adds rho_i * ambient to every B_i, ambient = (unshot area-weighted mean) /
 * (1 - area-weighted mean albedo), per channel. */
static void add_ambient(const rad_system *system, const rad_rgb *dB, rad_rgb *B)
{
    const uint32_t n = system->n;
    const double *area = system->area;
    const rad_rgb *rho = system->albedo;
    double total = 0, unshot[3] = {0, 0, 0}, albedo[3] = {0, 0, 0};
    for (uint32_t j = 0; j < n; j++) {
        total += area[j];
        unshot[0] += area[j] * dB[j].r;
        unshot[1] += area[j] * dB[j].g;
        unshot[2] += area[j] * dB[j].b;
        albedo[0] += area[j] * rho[j].r;
        albedo[1] += area[j] * rho[j].g;
        albedo[2] += area[j] * rho[j].b;
    }
    double ambient[3];
    for (int c = 0; c < 3; c++) {
        double mean_albedo = fmin(albedo[c] / total, SHOOT_AMBIENT_ALBEDO_MAX);
        ambient[c] = unshot[c] / total / (1.0 - mean_albedo);
    }
    for (uint32_t i = 0; i < n; i++) {
        B[i].r += rho[i].r * ambient[0];
        B[i].g += rho[i].g * ambient[1];
        B[i].b += rho[i].b * ambient[2];
    }
}

/* Shots between two checkpoint steps (each step a clock read, and over MPI ranks two small
 * collectives): a sixteenth of the patches. */
#define SHOOT_CHECKPOINT_DIVISOR 16u

/* A checkpoint's vectors: B, then the unshot dB. */
typedef struct shoot_vectors {
    const rad_rgb *B, *dB;
    uint32_t n;
} shoot_vectors;

static void put_vectors(const void *user, byte_sink *body)
{
    const shoot_vectors *v = user;
    sink_rgbs(body, v->B, v->n);
    sink_rgbs(body, v->dB, v->n);
}

rad_status solve_shoot(const rad_system *system, solve_params *params, rad_rgb *B,
                       rad_solve_report *report, rad_error *error)
{
    const uint32_t n = system->n;
    const float *F = system->F;
    const double *area = system->area;

    /* dB: unshot radiosity; w: rho_j / A_j */
    rad_rgb *work = rad_alloc_array((size_t)n, 2 * sizeof(rad_rgb));
    if (!work)
        return rad_fail(error, RAD_ERR_NOMEM, "rad_solve: no memory for %u patches", n);
    rad_rgb *dB = work, *w = work + n;
    for (uint32_t j = 0; j < n; j++) {
        B[j] = system->exitance[j];
        dB[j] = system->exitance[j];
        const rad_rgb rho = system->albedo[j];
        w[j] = (rad_rgb){rho.r / area[j], rho.g / area[j], rho.b / area[j]};
    }

    solve_checkpoint *cp = params->checkpoint;
    const uint32_t checkpoint_every =
        n / SHOOT_CHECKPOINT_DIVISOR > 0 ? n / SHOOT_CHECKPOINT_DIVISOR : 1;
    double criterion = INFINITY, smallest = INFINITY;
    uint32_t shots = 0;
    byte_source resumed;
    if (solve_checkpoint_resuming(cp, SOLVE_CHECKPOINT_ITERATE, &resumed)) {
        iterate_state state;
        if (!iterate_body_read(cp, n, 2, NULL, NULL, &state, &resumed, error)) {
            free(work);
            return RAD_ERR_PARSE;
        }
        source_rgbs(&resumed, B, n);
        source_rgbs(&resumed, dB, n);
        shots = state.iterations;
        smallest = state.smallest;
        params->last_shooter = state.last_shooter;
        solve_checkpoint_resumed(cp);
    }
    const uint32_t blocks = solve_block_count(n);
    shoot_block block[SOLVE_BLOCKS];
    for (uint32_t b = 0; b < blocks; b++)
        block[b] = scan_range(area, dB, solve_block_begin(n, blocks, b),
                              solve_block_begin(n, blocks, b + 1));

    const double scale = solve_criterion_scale(system);
    const int threads = params->threads;
    (void)threads; /* unused without OpenMP */
    for (;;) {
        if (cp && shots % checkpoint_every == 0) { /* between shots */
            shoot_vectors v = {B, dB, n};
            iterate_state state = {shots, criterion, smallest, params->last_shooter};
            rad_status status = RAD_OK;
            if (iterate_step(cp, system, &state, put_vectors, &v, &status, error)) {
                free(work);
                return status;
            }
        }
        double unshot = 0, best = -1;
        uint32_t shooter = 0;
        for (uint32_t b = 0; b < blocks; b++) {
            unshot += block[b].unshot;
            if (block[b].best > best) {
                best = block[b].best;
                shooter = block[b].which;
            }
        }
        criterion = unshot / scale;
        if (solve_diverging(criterion, &smallest)) {
            free(work);
            return solve_fail_diverged(system, "shoot", shots, criterion, smallest, shooter,
                                       report, error);
        }
        solve_progress(params, criterion);
        if (criterion <= params->tolerance || shots >= params->max_iterations || !(best > 0))
            break;
        if (params->observer && shots % params->observe_every == 0) {
            rad_solve_step step = solve_step(params, n, shots, "shoot", criterion);
            step.unshot = criterion;
            step.shooting_patch = params->last_shooter;
            solve_observe(params, system, step, NULL, NULL, NULL, B, true);
        }

        const rad_rgb d = dB[shooter];
        const double a = area[shooter];
        const rad_rgb power = {a * d.r, a * d.g, a * d.b};
        dB[shooter] = (rad_rgb){0, 0, 0};
        const float *row = F + (size_t)shooter * n;
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= SHOOT_PARALLEL_MIN)
        for (uint32_t b = 0; b < blocks; b++)
            block[b] = shoot_range(row, power, w, area, B, dB, solve_block_begin(n, blocks, b),
                                   solve_block_begin(n, blocks, b + 1));
        shots++;
        params->last_shooter = shooter;
    }

    if (cp) { /* a stop during the last shots (the ambient term is added after resuming) */
        shoot_vectors v = {B, dB, n};
        iterate_state state = {shots, criterion, smallest, params->last_shooter};
        rad_status status = RAD_OK;
        if (iterate_stop(cp, system, &state, put_vectors, &v, &status, error)) {
            free(work);
            return status;
        }
    }
    if (params->ambient)
        add_ambient(system, dB, B);
    report->iterations = shots;
    report->criterion = criterion;
    report->converged = criterion <= params->tolerance;
    free(work);
    return RAD_OK;
}
