/*
 * solve_gauss_seidel.c - Gauss-Seidel gathering: one array, patches updated in index order,
 * each from the newest values of the others, starting from B = E.
 *
 * Row i solves its own equation for B_i with the other patches fixed:
 *     B_i = (E_i + rho_i sum_{j != i} F_ij B_j) / (1 - rho_i F_ii)
 * (F_ii is 0 for planar patches; the division keeps the method exact Gauss-Seidel when it
 * is not). Criterion: the area-weighted L1 change of the sweep, sum_i A_i |dB_i|_1, relative
 * to sum_i A_i |E_i|_1. The sweep is sequential by nature; each row is a vectorised dot
 * product over the channels kept as three separate arrays.
 */
#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "solve/solve_internal.h"

/* A checkpoint's vectors: the iterate, three channel arrays. */
static void put_iterate(const void *user, byte_sink *body)
{
    const double *const *x = user;
    sink_channels(body, x[0], x[1], x[2], (uint32_t)(x[3] - x[0]));
}

rad_status solve_gauss_seidel(const rad_system *system, solve_params *params, rad_rgb *B,
                              rad_solve_report *report, rad_error *error)
{
    const uint32_t n = system->n;
    const float *F = system->F;
    const double *area = system->area;
    const rad_rgb *rho = system->albedo;
    const rad_rgb *E = system->exitance;

    /* x[c]: the iterate; inv[c]: 1 / (1 - rho_i,c F_ii) */
    double *work = rad_alloc_array((size_t)n, 6 * sizeof(double));
    if (!work)
        return rad_fail(error, RAD_ERR_NOMEM, "rad_solve: no memory for %u patches", n);
    double *x0 = work, *x1 = work + n, *x2 = work + 2 * (size_t)n;
    double *inv[3] = {work + 3 * (size_t)n, work + 4 * (size_t)n, work + 5 * (size_t)n};
    for (uint32_t i = 0; i < n; i++) {
        x0[i] = E[i].r;
        x1[i] = E[i].g;
        x2[i] = E[i].b;
        double fii = (double)F[(size_t)i * n + i];
        double rc[3] = {rho[i].r, rho[i].g, rho[i].b};
        for (int c = 0; c < 3; c++) {
            /* rho F_ii = 1 only for a patch that sees nothing but itself with albedo 1: the
             * system is singular there; keep the plain update, which simply diverges */
            double d = 1.0 - rc[c] * fii;
            inv[c][i] = d > 0 ? 1.0 / d : 1.0;
        }
    }

    const double scale = solve_criterion_scale(system);
    double criterion = INFINITY, smallest = INFINITY;
    uint32_t sweeps = 0;
    if (params->observer)
        solve_observe(params, system, solve_step(params, n, 0, "gauss-seidel", NAN), x0, x1, x2,
                      NULL, true);
    solve_checkpoint *cp = params->checkpoint;
    if (!iterate_resume_sweeps(cp, n, x0, x1, x2, &sweeps, &criterion, &smallest, error)) {
        free(work);
        return RAD_ERR_PARSE;
    }
    /* (a resumed final state, whose criterion met the tolerance, takes no further sweep) */
    while (sweeps < params->max_iterations && !(criterion <= params->tolerance)) {
        if (cp) { /* between sweeps */
            const double *x[4] = {x0, x1, x2, x0 + n};
            iterate_state state = {sweeps, criterion, smallest, UINT32_MAX};
            rad_status status = RAD_OK;
            if (iterate_step(cp, system, &state, put_iterate, x, &status, error)) {
                free(work);
                return status;
            }
        }
        double sum = 0, largest = -1;
        uint32_t worst = 0;
        for (uint32_t i = 0; i < n; i++) {
            const float *row = F + (size_t)i * n;
            double lo[3], hi[3];
            solve_row_dot(row, x0, x1, x2, 0, i, lo);
            solve_row_dot(row, x0, x1, x2, i + 1, n, hi);
            double y0 = (E[i].r + rho[i].r * (lo[0] + hi[0])) * inv[0][i];
            double y1 = (E[i].g + rho[i].g * (lo[1] + hi[1])) * inv[1][i];
            double y2 = (E[i].b + rho[i].b * (lo[2] + hi[2])) * inv[2][i];
            double change = area[i] * (fabs(y0 - x0[i]) + fabs(y1 - x1[i]) + fabs(y2 - x2[i]));
            sum += change;
            if (!(change <= largest)) {
                largest = change;
                worst = i;
            }
            x0[i] = y0;
            x1[i] = y1;
            x2[i] = y2;
        }
        sweeps++;
        criterion = sum / scale;
        if (solve_diverging(criterion, &smallest)) {
            free(work);
            return solve_fail_diverged(system, "gauss-seidel", sweeps, criterion, smallest,
                                       worst, report, error);
        }
        solve_progress(params, criterion);
        if (criterion <= params->tolerance)
            break;
        if (params->observer && sweeps < params->max_iterations) /* the last: rad_solve's */
            solve_observe(params, system, solve_step(params, n, sweeps, "gauss-seidel", criterion),
                          x0, x1, x2, NULL, true);
    }

    if (cp) { /* a stop during the last sweep */
        const double *x[4] = {x0, x1, x2, x0 + n};
        iterate_state state = {sweeps, criterion, smallest, UINT32_MAX};
        rad_status status = RAD_OK;
        if (iterate_stop(cp, system, &state, put_iterate, x, &status, error)) {
            free(work);
            return status;
        }
    }
    for (uint32_t i = 0; i < n; i++)
        B[i] = (rad_rgb){x0[i], x1[i], x2[i]};
    report->iterations = sweeps;
    report->criterion = criterion;
    report->converged = criterion <= params->tolerance;
    free(work);
    return RAD_OK;
}
