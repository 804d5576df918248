/*
 * script_f.c - Hottel's total exchange factors for grey diffuse surfaces:
 *   scriptF = diag(eps) (I - F diag(1 - eps))^-1 F diag(eps).
 * (I - F diag(rho)) X = F is solved densely: LU with partial pivoting (the elimination in
 * parallel once its columns are long), then all n right-hand sides, in parallel by blocks
 * of columns. O(n^3): hence the size limit. The result does not depend on the thread
 * count: every value is computed by the same operations in the same order.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"

/* A pivot this small relative to the matrix's largest entry means a singular system. */
#define SCRIPT_F_SINGULAR_PIVOT 1e-13
/* The elimination of one column runs in parallel when its update has at least this many
 * multiply-adds (below, the barrier costs more than it saves on a loaded machine). */
#define SCRIPT_F_PARALLEL_WORK 2000000u
/* Right-hand sides are solved in blocks of this many columns, one thread per block. */
enum { SCRIPT_F_COLUMN_BLOCK = 64 };

rad_status rad_viewfactor_matrix_script_f(const rad_viewfactor_matrix *m,
                                          const double *emissivity,
                                          rad_viewfactor_matrix **out, rad_error *error)
{
    *out = NULL;
    uint32_t n = m->n;
    if (n > RAD_SCRIPT_F_MAX_SURFACES)
        return rad_fail(error, RAD_ERR_UNSUPPORTED,
                        "script-F factors are computed densely, for at most %u surfaces "
                        "(this matrix has %u)",
                        RAD_SCRIPT_F_MAX_SURFACES, n);
    for (uint32_t I = 0; I < n; I++)
        if (!(emissivity[I] > 0 && emissivity[I] <= 1))
            return rad_fail(error, RAD_ERR_INVALID,
                            "surface %u: emissivity %g is outside (0,1]", I + 1, emissivity[I]);
    size_t nn = (size_t)n * n;
    double *A = rad_alloc_array(nn, sizeof(*A));
    double *X = rad_alloc_array(nn, sizeof(*X));
    rad_viewfactor_matrix *result = NULL;
    rad_status status = RAD_OK;
    if (!A || !X) {
        status = rad_fail(error, RAD_ERR_NOMEM,
                          "out of memory for the dense script-F system of %u surfaces", n);
        goto done;
    }
    for (uint32_t I = 0; I < n; I++) {
        A[(size_t)I * n + I] = 1;
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
            uint32_t J = m->column[k];
            A[(size_t)I * n + J] -= m->value[k] * (1 - emissivity[J]);
            X[(size_t)I * n + J] = m->value[k];
        }
    }
    double largest = 0;
    for (size_t i = 0; i < nn; i++)
        largest = fmax(largest, fabs(A[i]));

    /* LU with partial pivoting, L below the diagonal; rows of X swapped along */
    for (uint32_t k = 0; k < n; k++) {
        uint32_t p = k;
        for (uint32_t i = k + 1; i < n; i++)
            if (fabs(A[(size_t)i * n + k]) > fabs(A[(size_t)p * n + k]))
                p = i;
        if (!(fabs(A[(size_t)p * n + k]) > SCRIPT_F_SINGULAR_PIVOT * largest)) {
            status = rad_fail(error, RAD_ERR_INVALID,
                              "the script-F system is singular (surface %u): are all "
                              "reflectances 1?",
                              k + 1);
            goto done;
        }
        if (p != k)
            for (uint32_t j = 0; j < n; j++) {
                double t = A[(size_t)k * n + j];
                A[(size_t)k * n + j] = A[(size_t)p * n + j];
                A[(size_t)p * n + j] = t;
                t = X[(size_t)k * n + j];
                X[(size_t)k * n + j] = X[(size_t)p * n + j];
                X[(size_t)p * n + j] = t;
            }
        const double *row_k = A + (size_t)k * n;
        double inverse = 1 / row_k[k];
        /* one parallel region per column costs a barrier each: worth it only when the
         * trailing update is large */
#pragma omp parallel for schedule(static) if ((uint64_t)(n - k) * n > SCRIPT_F_PARALLEL_WORK)
        for (int64_t i = (int64_t)k + 1; i < (int64_t)n; i++) {
            double *row_i = A + (size_t)i * n;
            double factor = row_i[k] * inverse;
            row_i[k] = factor; /* L, kept for the substitutions */
            if (factor == 0)
                continue;
            for (uint32_t j = k + 1; j < n; j++)
                row_i[j] -= factor * row_k[j];
        }
    }
    /* forward and back substitution, the right-hand sides split into blocks of columns:
     * one parallel region, no barrier inside */
    int64_t blocks = ((int64_t)n + SCRIPT_F_COLUMN_BLOCK - 1) / SCRIPT_F_COLUMN_BLOCK;
#pragma omp parallel for schedule(dynamic) if (n >= SCRIPT_F_COLUMN_BLOCK * 2)
    for (int64_t block = 0; block < blocks; block++) {
        uint32_t j0 = (uint32_t)block * SCRIPT_F_COLUMN_BLOCK;
        uint32_t j1 = j0 + SCRIPT_F_COLUMN_BLOCK < n ? j0 + SCRIPT_F_COLUMN_BLOCK : n;
        for (uint32_t i = 1; i < n; i++) { /* L y = P F (rows of X were swapped) */
            const double *row_i = A + (size_t)i * n;
            double *x_i = X + (size_t)i * n;
            for (uint32_t k = 0; k < i; k++) {
                double l = row_i[k];
                if (l == 0)
                    continue;
                const double *x_k = X + (size_t)k * n;
                for (uint32_t j = j0; j < j1; j++)
                    x_i[j] -= l * x_k[j];
            }
        }
        for (uint32_t k = n; k-- > 0;) { /* U x = y */
            double *x_k = X + (size_t)k * n;
            const double *row_k = A + (size_t)k * n;
            for (uint32_t i = k + 1; i < n; i++) {
                double a = row_k[i];
                if (a == 0)
                    continue;
                const double *x_i = X + (size_t)i * n;
                for (uint32_t j = j0; j < j1; j++)
                    x_k[j] -= a * x_i[j];
            }
            double inverse = 1 / row_k[k];
            for (uint32_t j = j0; j < j1; j++)
                x_k[j] *= inverse;
        }
    }

    uint64_t nonzeros = 0;
    for (size_t i = 0; i < nn; i++)
        nonzeros += X[i] != 0;
    status = rad_viewfactor_matrix_create(n, nonzeros, &result, error);
    if (status != RAD_OK)
        goto done;
    uint64_t k = 0;
    for (uint32_t I = 0; I < n; I++) {
        result->area[I] = m->area[I];
        result->row_start[I] = k;
        uint64_t f = m->row_start[I];
        for (uint32_t J = 0; J < n; J++) {
            double x = X[(size_t)I * n + J];
            if (x == 0)
                continue;
            result->column[k] = J;
            result->value[k] = emissivity[I] * x * emissivity[J];
            while (f < m->row_start[I + 1] && m->column[f] < J)
                f++;
            if (f < m->row_start[I + 1] && m->column[f] == J)
                result->error_bound[k] = m->error_bound[f] * emissivity[I] * emissivity[J];
            k++;
        }
    }
    result->row_start[n] = k;
    *out = result;
done:
    free(A);
    free(X);
    return status;
}
