/*
 * solve_direct.c - the direct solver: dense LU factorisation with partial pivoting, in
 * double, of M = I - diag(rho_c) F for each colour channel c, then M B_c = E_c.
 *
 * O(n^3) time and 8 n^2 bytes: a test oracle and a solver for small scenes only, refused
 * above DIRECT_MAX_PATCHES. Channels whose albedos are equal on every patch share one
 * factorisation (grey scenes need one instead of three). The elimination of the rows below
 * each pivot is spread over threads, one row per thread at a time, so the result does not
 * depend on the thread count.
 *
 * With a checkpoint (solve_checkpoint.h) a stop raised before the LU, between two of its
 * panels or after the last substitution writes F alone (an ITERATE checkpoint without
 * vectors) and ends the solve there: a factorisation is not resumed part way, the resumed
 * run factors F again and gives the same bytes. No checkpoint is written on the interval
 * meanwhile (it would hold nothing the form factors' last one does not).
 */
#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "solve/solve_internal.h"

/* RAD_DIRECT_MAX_PATCHES: 4096^2 doubles = 128 MiB and ~45 Gflop per factorisation, the
 * largest system worth it. */
#define DIRECT_MAX_PATCHES RAD_DIRECT_MAX_PATCHES

/* A pivot smaller than this times the largest entry of M means M is singular (to double
 * precision). M has a unit diagonal and entries in [-1, 1], so this is an absolute scale. */
#define DIRECT_PIVOT_MIN 1e-12

/* Columns per panel of the blocked factorisation: the panel's U rows (DIRECT_BLOCK x n
 * doubles, 256 KiB at n = 1024) stay in cache while the trailing rows stream past. */
enum { DIRECT_BLOCK = 32 };

/* Below this many trailing rows, one thread does the update. */
enum { DIRECT_PARALLEL_MIN = 128 };

static double channel(rad_rgb c, int k) { return k == 0 ? c.r : k == 1 ? c.g : c.b; }

static void set_channel(rad_rgb *c, int k, double v)
{
    if (k == 0)
        c->r = v;
    else if (k == 1)
        c->g = v;
    else
        c->b = v;
}

/* True when channels a and b have the same albedo on every patch. */
static bool same_albedo(const rad_system *system, int a, int b)
{
    for (uint32_t i = 0; i < system->n; i++)
        if (channel(system->albedo[i], a) != channel(system->albedo[i], b))
            return false;
    return true;
}

/* Builds M = I - diag(rho_k) F in m (row-major). Returns the largest |M_ij|. */
static double build_matrix(const rad_system *system, int k, double *m)
{
    const uint32_t n = system->n;
    double largest = 0;
    for (uint32_t i = 0; i < n; i++) {
        const float *row = system->F + (size_t)i * n;
        double *out = m + (size_t)i * n;
        double rho = channel(system->albedo[i], k);
        for (uint32_t j = 0; j < n; j++) {
            out[j] = (i == j ? 1.0 : 0.0) - rho * (double)row[j];
            largest = fmax(largest, fabs(out[j]));
        }
    }
    return largest;
}

/* Collective (every rank factors the same matrix): when a stop was raised, writes F as the
 * checkpoint and returns true (cp->interrupted, or *status when it could not be written). */
static bool stop_here(solve_checkpoint *cp, const rad_system *system, rad_status *status,
                      rad_error *error)
{
    iterate_state state = {0, INFINITY, INFINITY, UINT32_MAX};
    return cp && iterate_stop(cp, system, &state, NULL, NULL, status, error);
}

/* Factors the panel of columns [k0, k1) of rows [k0, n) with partial pivoting (rows are
 * swapped across the whole matrix), leaving L below the diagonal of the panel and U on
 * and above it. The columns right of the panel are only swapped, not updated. */
static rad_status factor_panel(double *m, uint32_t n, uint32_t k0, uint32_t k1,
                               uint32_t *pivot, double largest, rad_error *error)
{
    for (uint32_t k = k0; k < k1; k++) {
        uint32_t p = k;
        double best = fabs(m[(size_t)k * n + k]);
        for (uint32_t i = k + 1; i < n; i++) {
            double v = fabs(m[(size_t)i * n + k]);
            if (v > best) {
                best = v;
                p = i;
            }
        }
        if (!(best > DIRECT_PIVOT_MIN * largest))
            return rad_fail(error, RAD_ERR_INVALID,
                            "rad_solve: the radiosity system is singular (pivot %g at row %u); "
                            "is some closed part of the scene perfectly white?",
                            best, k);
        pivot[k] = p;
        if (p != k) {
            double *a = m + (size_t)k * n, *b = m + (size_t)p * n;
            for (uint32_t j = 0; j < n; j++) {
                double t = a[j];
                a[j] = b[j];
                b[j] = t;
            }
        }
        const double *top = m + (size_t)k * n;
        const double inv = 1.0 / top[k];
        for (uint32_t i = k + 1; i < n; i++) {
            double *row = m + (size_t)i * n;
            double l = row[k] * inv;
            row[k] = l;
            for (uint32_t j = k + 1; j < k1; j++)
                row[j] -= l * top[j];
        }
    }
    return RAD_OK;
}

/* In-place LU with partial pivoting, blocked: m = P^-1 L U, L unit lower (below the
 * diagonal), U on and above it; pivot[k] is the row swapped with row k at step k. Each
 * panel of DIRECT_BLOCK columns is factored, the block row right of it is solved with the
 * panel's L, and the trailing matrix receives the panel's rank-DIRECT_BLOCK update in one
 * pass (one row per thread), which reads the big trailing matrix once per panel instead of
 * once per column. */
static rad_status factor(double *m, uint32_t n, uint32_t *pivot, double largest, int threads,
                         const rad_system *system, solve_checkpoint *cp, rad_error *error)
{
    (void)threads; /* unused without OpenMP */
    for (uint32_t k0 = 0; k0 < n; k0 += DIRECT_BLOCK) {
        const uint32_t k1 = n - k0 < DIRECT_BLOCK ? n : k0 + DIRECT_BLOCK;
        rad_status stopped = RAD_OK;
        if (stop_here(cp, system, &stopped, error))
            return stopped;
        rad_status status = factor_panel(m, n, k0, k1, pivot, largest, error);
        if (status != RAD_OK)
            return status;
        if (k1 == n)
            break;

        /* U12: rows [k0, k1), columns [k1, n) <- L11^-1 A12 */
        for (uint32_t r = k0 + 1; r < k1; r++) {
            double *row = m + (size_t)r * n;
            for (uint32_t q = k0; q < r; q++) {
                const double l = row[q];
                const double *u = m + (size_t)q * n;
                for (uint32_t j = k1; j < n; j++)
                    row[j] -= l * u[j];
            }
        }

        /* A22 -= L21 U12 */
#pragma omp parallel for schedule(static) num_threads(threads) \
    if (n - k1 >= DIRECT_PARALLEL_MIN)
        for (uint32_t i = k1; i < n; i++) {
            double *row = m + (size_t)i * n;
            uint32_t q = k0;
            for (; q + 4 <= k1; q += 4) {
                const double l0 = row[q], l1 = row[q + 1], l2 = row[q + 2], l3 = row[q + 3];
                const double *u0 = m + (size_t)q * n, *u1 = u0 + n, *u2 = u1 + n, *u3 = u2 + n;
                for (uint32_t j = k1; j < n; j++)
                    row[j] -= l0 * u0[j] + l1 * u1[j] + l2 * u2[j] + l3 * u3[j];
            }
            for (; q < k1; q++) {
                const double l = row[q];
                const double *u = m + (size_t)q * n;
                for (uint32_t j = k1; j < n; j++)
                    row[j] -= l * u[j];
            }
        }
    }
    return RAD_OK;
}

/* Solves P^-1 L U x = x in place. */
static void substitute(const double *m, uint32_t n, const uint32_t *pivot, double *x)
{
    for (uint32_t k = 0; k < n; k++) {
        double t = x[k];
        x[k] = x[pivot[k]];
        x[pivot[k]] = t;
    }
    for (uint32_t i = 0; i < n; i++) {
        const double *row = m + (size_t)i * n;
        double s = x[i];
        for (uint32_t j = 0; j < i; j++)
            s -= row[j] * x[j];
        x[i] = s;
    }
    for (uint32_t i = n; i-- > 0;) {
        const double *row = m + (size_t)i * n;
        double s = x[i];
        for (uint32_t j = i + 1; j < n; j++)
            s -= row[j] * x[j];
        x[i] = s / row[i];
    }
}

rad_status solve_direct(const rad_system *system, solve_params *params, rad_rgb *B,
                        rad_solve_report *report, rad_error *error)
{
    const uint32_t n = system->n;
    if (n > DIRECT_MAX_PATCHES)
        return rad_fail(error, RAD_ERR_UNSUPPORTED,
                        "the direct solver is for small scenes: %u patches (limit %d)", n,
                        DIRECT_MAX_PATCHES);

    rad_status status = RAD_OK;
    double *m = rad_alloc_array((size_t)n * n, sizeof(double));
    double *x = rad_alloc_array((size_t)n, sizeof(double));
    uint32_t *pivot = rad_alloc_array((size_t)n, sizeof(uint32_t));
    if (!m || !x || !pivot) {
        status = rad_fail(error, RAD_ERR_NOMEM,
                          "rad_solve: no memory for the %u x %u direct solve", n, n);
        goto done;
    }

    bool solved[3] = {false, false, false};
    for (int k = 0; k < 3; k++) {
        if (solved[k])
            continue;
        double largest = build_matrix(system, k, m);
        status = factor(m, n, pivot, largest, params->threads, system, params->checkpoint,
                        error);
        if (status != RAD_OK || (params->checkpoint && params->checkpoint->interrupted))
            goto done;
        for (int c = k; c < 3; c++) {
            if (solved[c] || (c != k && !same_albedo(system, k, c)))
                continue;
            for (uint32_t i = 0; i < n; i++)
                x[i] = channel(system->exitance[i], c);
            substitute(m, n, pivot, x);
            for (uint32_t i = 0; i < n; i++)
                set_channel(&B[i], c, x[i]);
            solved[c] = true;
        }
    }

    if (stop_here(params->checkpoint, system, &status, error))
        goto done;
    report->iterations = 0;
    report->criterion = solve_residual(system, B, params->threads);
    report->converged = report->criterion <= params->tolerance;

done:
    if (status == RAD_OK && params->checkpoint && params->checkpoint->interrupted)
        for (uint32_t i = 0; i < n; i++) /* no solution: the checkpoint has F */
            B[i] = system->exitance[i];
    free(pivot);
    free(x);
    free(m);
    return status;
}
