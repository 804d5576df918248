/*
 * formfactor.c - the dense patch-to-patch form-factor matrix, and its invariant checks.
 *
 * A sink for the pair engine: each symmetric transfer G_ij becomes F_ij = G / A_i and
 * F_ji = G / A_j, so reciprocity holds by construction. Each pair is written by one thread
 * and to two distinct cells, so no locking is needed.
 */
#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "formfactor/pair_engine.h"

typedef struct dense_sink {
    float *F;
    const rad_patch *patches;
    size_t n;
} dense_sink;

static void store_pair(void *data, int thread, uint32_t i, uint32_t j, double G)
{
    (void)thread;
    dense_sink *sink = data;
    sink->F[i * sink->n + j] = (float)(G / sink->patches[i].area);
    sink->F[j * sink->n + i] = (float)(G / sink->patches[j].area);
}

rad_status rad_formfactors_compute(const rad_mesh *mesh, const rad_tracer *occluders,
                                   const rad_formfactor_options *options,
                                   rad_formfactors **out, rad_formfactor_report *report,
                                   rad_error *error)
{
    *out = NULL;
    size_t n = mesh->patch_count;
    if (n == 0)
        return rad_fail(error, RAD_ERR_INVALID, "the mesh has no patches");
    if (n > SIZE_MAX / n)
        return rad_fail(error, RAD_ERR_NOMEM, "%zu patches: the matrix size overflows", n);
    rad_formfactors *result = calloc(1, sizeof(*result));
    float *F = rad_alloc_array(n * n, sizeof(*F));
    if (!result || !F) {
        free(result);
        free(F);
        return rad_fail(error, RAD_ERR_NOMEM,
                        "out of memory for the %zu x %zu form-factor matrix (%.1f GB): use a "
                        "larger --patch-size",
                        n, n, (double)n * n * sizeof(float) / 1e9);
    }
    dense_sink sink = {F, mesh->patches, n};
    rad_status status = pair_engine_run(mesh, occluders, options, store_pair, &sink, report, error);
    if (status != RAD_OK) {
        free(F);
        free(result);
        return status;
    }
    result->n = (uint32_t)n;
    result->F = F;
    *out = result;
    return RAD_OK;
}

void rad_formfactors_destroy(rad_formfactors *formfactors)
{
    if (!formfactors)
        return;
    free(formfactors->F);
    free(formfactors);
}

void rad_formfactors_check(const rad_formfactors *ff, const rad_mesh *mesh,
                           double *reciprocity_residual, double *closure_residual)
{
    size_t n = ff->n;
    double reciprocity = 0, closure = 0;
    for (size_t i = 0; i < n; i++) {
        double row = 0;
        for (size_t j = 0; j < n; j++) {
            double fij = ff->F[i * n + j];
            row += fij;
            if (j <= i)
                continue;
            double a = mesh->patches[i].area * fij;
            double b = mesh->patches[j].area * ff->F[j * n + i];
            double larger = fmax(a, b);
            if (fmax(fij, ff->F[j * n + i]) > 1e-6 && larger > 0)
                reciprocity = fmax(reciprocity, fabs(a - b) / larger);
        }
        closure = fmax(closure, fabs(row - 1));
    }
    if (reciprocity_residual)
        *reciprocity_residual = reciprocity;
    if (closure_residual)
        *closure_residual = closure;
}
