/*
 * residual.c - the relative residual of a candidate solution B of (I - diag(rho) F) B = E:
 *
 *     sum_i A_i |r_i|_1 / sum_i A_i |E_i|_1,   r = B - E - rho .* (F B)
 *
 * with |.|_1 the sum of the three channels' absolute values. When E is zero everywhere the
 * denominator is taken as 1 (an absolute residual), so a black scene solved as black gives
 * 0. This file only measures; it never changes B. Costs one O(n^2) pass over F.
 */
#include <math.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "solve/solve_internal.h"

double solve_exitance_norm(const rad_system *system)
{
    const double *area = system->area;
    const rad_rgb *E = system->exitance;
    double sum = 0;
    for (uint32_t i = 0; i < system->n; i++)
        sum += area[i] * (fabs(E[i].r) + fabs(E[i].g) + fabs(E[i].b));
    return sum;
}

double solve_criterion_scale(const rad_system *system)
{
    double norm = solve_exitance_norm(system);
    return norm > 0 ? norm : 1.0;
}

/* A_i |r_i|_1 for one row; B is read in its array-of-structs layout. */
static double row_residual(const rad_system *system, const rad_rgb *B, uint32_t i)
{
    uint32_t n = system->n;
    const float *row = system->F + (size_t)i * n;
    double s0 = 0, s1 = 0, s2 = 0;
    for (uint32_t j = 0; j < n; j++) {
        double f = (double)row[j];
        s0 += f * B[j].r;
        s1 += f * B[j].g;
        s2 += f * B[j].b;
    }
    const rad_rgb rho = system->albedo[i];
    const rad_rgb e = system->exitance[i];
    double r0 = B[i].r - e.r - rho.r * s0;
    double r1 = B[i].g - e.g - rho.g * s1;
    double r2 = B[i].b - e.b - rho.b * s2;
    return system->area[i] * (fabs(r0) + fabs(r1) + fabs(r2));
}

double solve_residual(const rad_system *system, const rad_rgb *B, int threads)
{
    uint32_t n = system->n;
    uint32_t blocks = solve_block_count(n);
    double partial[SOLVE_BLOCKS];
    (void)threads; /* unused without OpenMP */

#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) \
    if (n >= SOLVE_PARALLEL_MIN)
    for (uint32_t b = 0; b < blocks; b++) {
        uint32_t end = solve_block_begin(n, blocks, b + 1);
        double sum = 0;
        for (uint32_t i = solve_block_begin(n, blocks, b); i < end; i++)
            sum += row_residual(system, B, i);
        partial[b] = sum;
    }

    double numerator = 0;
    for (uint32_t b = 0; b < blocks; b++)
        numerator += partial[b];
    return numerator / solve_criterion_scale(system);
}

double rad_system_residual(const rad_system *system, const rad_rgb *B)
{
    if (!system || !B || !system->F || !system->area || !system->albedo ||
        !system->exitance)
        return NAN;
    int threads = 1;
#ifdef _OPENMP
    threads = omp_get_max_threads();
#endif
    return solve_residual(system, B, threads);
}
