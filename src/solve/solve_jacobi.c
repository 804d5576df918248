/*
 * solve_jacobi.c - Jacobi gathering: B <- E + rho .* (F B), every patch from the previous
 * iterate (two buffers), starting from B = E. Sweep k adds the k-th bounce of light.
 *
 * The change of a sweep is exactly the residual of the previous iterate:
 *     B_new - B_old = E + rho F B_old - B_old = -r(B_old),
 * so the criterion sum_i A_i |B_new - B_old|_1 / sum_i A_i |E_i|_1 costs nothing extra.
 * With reciprocity and rows of rho F summing to < 1, the residual of B_new is no larger, so
 * the returned B_new meets the tolerance. Rows are spread over threads; each row is one
 * thread's dot product and the criterion is summed in patch order, so the answer does not
 * depend on the thread count. The channels are kept as three separate arrays (structure
 * of arrays) so the row dot product vectorises.
 *
 * Over several MPI ranks (parallel/ranks.h; every rank holds the whole F) each rank sweeps
 * its contiguous block of rows and the ranks then exchange their blocks of the new B; a
 * row's dot product and the criterion's sum in patch order are the same whoever computes
 * them, so B is bitwise the serial one.
 */
#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "parallel/partition.h"
#include "parallel/ranks.h"
#include "solve/solve_internal.h"

/* A checkpoint's vectors: the iterate B_k, three channel arrays. */
static void put_iterate(const void *user, byte_sink *body)
{
    const double *const *x = user;
    sink_channels(body, x[0], x[1], x[2], (uint32_t)(x[3] - x[0]));
}

rad_status solve_jacobi(const rad_system *system, solve_params *params, rad_rgb *B,
                        rad_solve_report *report, rad_error *error)
{
    const uint32_t n = system->n;
    const float *F = system->F;
    const double *area = system->area;
    const rad_rgb *rho = system->albedo;
    const rad_rgb *E = system->exitance;

    /* old[c] and new[c] for the three channels, then the per-row weighted change */
    double *work = rad_alloc_array((size_t)n, 7 * sizeof(double));
    if (!work)
        return rad_fail(error, RAD_ERR_NOMEM, "rad_solve: no memory for %u patches", n);
    double *old[3] = {work, work + n, work + 2 * (size_t)n};
    double *cur[3] = {work + 3 * (size_t)n, work + 4 * (size_t)n, work + 5 * (size_t)n};
    double *change = work + 6 * (size_t)n;
    for (uint32_t i = 0; i < n; i++) {
        old[0][i] = E[i].r;
        old[1][i] = E[i].g;
        old[2][i] = E[i].b;
    }

    const double scale = solve_criterion_scale(system);
    const int threads = params->threads;
    (void)threads; /* unused without OpenMP */
    double criterion = INFINITY, smallest = INFINITY;
    uint32_t sweeps = 0, first_row, end_row; /* this rank's rows */
    partition_block(n, ranks_count(), ranks_rank(), &first_row, &end_row);
    /* the observer gets B_k after sweep k + 1, whose change is B_k's residual */
    rad_solve_step observed = {0};
    if (params->observer)
        observed = solve_step(params, n, 0, "gather", NAN);
    solve_checkpoint *cp = params->checkpoint;
    if (!iterate_resume_sweeps(cp, n, old[0], old[1], old[2], &sweeps, &criterion, &smallest, error)) {
        free(work);
        return RAD_ERR_PARSE;
    }
    /* (a resumed final state, whose criterion met the tolerance, takes no further sweep) */
    while (sweeps < params->max_iterations && !(criterion <= params->tolerance)) {
        if (cp) { /* between sweeps: B_sweeps in old[] */
            const double *x[4] = {old[0], old[1], old[2], old[0] + n};
            iterate_state state = {sweeps, criterion, smallest, UINT32_MAX};
            rad_status status = RAD_OK;
            if (iterate_step(cp, system, &state, put_iterate, x, &status, error)) {
                free(work);
                return status;
            }
        }
        const double *x0 = old[0], *x1 = old[1], *x2 = old[2];
        double *y0 = cur[0], *y1 = cur[1], *y2 = cur[2];
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads) \
    if (n >= SOLVE_PARALLEL_MIN)
        for (uint32_t i = first_row; i < end_row; i++) {
            double s[3];
            solve_row_dot(F + (size_t)i * n, x0, x1, x2, 0, n, s);
            y0[i] = E[i].r + rho[i].r * s[0];
            y1[i] = E[i].g + rho[i].g * s[1];
            y2[i] = E[i].b + rho[i].b * s[2];
            change[i] = area[i] * (fabs(y0[i] - x0[i]) + fabs(y1[i] - x1[i]) +
                                   fabs(y2[i] - x2[i]));
        }
        if (ranks_count() > 1) {
            ranks_share_blocks(y0, n, 1);
            ranks_share_blocks(y1, n, 1);
            ranks_share_blocks(y2, n, 1);
            for (uint32_t i = 0; i < n; i++)
                if (i < first_row || i >= end_row)
                    change[i] = area[i] * (fabs(y0[i] - x0[i]) + fabs(y1[i] - x1[i]) +
                                           fabs(y2[i] - x2[i]));
        }
        sweeps++;

        double sum = 0;
        for (uint32_t i = 0; i < n; i++)
            sum += change[i];
        criterion = sum / scale;
        if (solve_diverging(criterion, &smallest)) {
            uint32_t worst = 0;
            for (uint32_t i = 1; i < n; i++)
                if (!(change[i] <= change[worst]))
                    worst = i;
            free(work);
            return solve_fail_diverged(system, "gather", sweeps, criterion, smallest, worst,
                                       report, error);
        }
        if (params->observer) {
            observed.residual = criterion;
            solve_observe(params, system, observed, old[0], old[1], old[2], NULL, false);
            observed = solve_step(params, n, sweeps, "gather", criterion);
        }

        for (int c = 0; c < 3; c++) {
            double *t = old[c];
            old[c] = cur[c];
            cur[c] = t;
        }
        solve_progress(params, criterion);
        if (criterion <= params->tolerance)
            break;
    }

    /* old[] holds the newest iterate; a stop during the last sweep is honoured here */
    if (cp) {
        const double *x[4] = {old[0], old[1], old[2], old[0] + n};
        iterate_state state = {sweeps, criterion, smallest, UINT32_MAX};
        rad_status status = RAD_OK;
        if (iterate_stop(cp, system, &state, put_iterate, x, &status, error)) {
            free(work);
            return status;
        }
    }
    for (uint32_t i = 0; i < n; i++)
        B[i] = (rad_rgb){old[0][i], old[1][i], old[2][i]};
    report->iterations = sweeps;
    report->criterion = criterion;
    report->converged = criterion <= params->tolerance;
    free(work);
    return RAD_OK;
}
