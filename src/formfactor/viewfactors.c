/*
 * viewfactors.c - surface-to-surface view factors without the patch matrix.
 *
 * A sink for the pair engine that adds each patch pair's transfer G_ij to its surfaces'
 * total, S_IJ += G and S_JI += G, in one table per thread (summed in thread order, so the
 * answer does not depend on scheduling beyond float rounding of per-thread partial sums).
 * F_IJ = S_IJ / A_I. Memory grows with threads x surfaces^2, not with patches^2.
 */
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "formfactor/pair_engine.h"

typedef struct surface_sink {
    double *tables; /* threads x S x S */
    size_t S;
    const rad_patch *patches;
} surface_sink;

static void add_pair(void *data, int thread, uint32_t i, uint32_t j, double G)
{
    surface_sink *sink = data;
    size_t S = sink->S;
    double *table = sink->tables + (size_t)thread * S * S;
    size_t I = sink->patches[i].surface, J = sink->patches[j].surface;
    table[I * S + J] += G;
    table[J * S + I] += G;
}

rad_status rad_viewfactors_compute(const rad_scene *scene, const rad_mesh *mesh,
                                   const rad_tracer *occluders,
                                   const rad_formfactor_options *options, double *matrix,
                                   double *areas, rad_formfactor_report *report,
                                   rad_error *error)
{
    size_t S = scene->surface_count;
    int threads = pair_engine_threads(options);
    if (S && S > SIZE_MAX / S / (size_t)threads)
        return rad_fail(error, RAD_ERR_NOMEM, "%zu surfaces: table size overflows", S);
    surface_sink sink = {rad_alloc_array((size_t)threads * S * S, sizeof(double)), S,
                         mesh->patches};
    double *surface_area = rad_alloc_array(S, sizeof(double));
    if (!sink.tables || !surface_area) {
        free(sink.tables);
        free(surface_area);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for %zu x %zu view factors", S, S);
    }
    rad_status status = pair_engine_run(mesh, occluders, options, add_pair, &sink, report, error);
    if (status == RAD_OK) {
        for (uint32_t p = 0; p < mesh->patch_count; p++)
            surface_area[mesh->patches[p].surface] += mesh->patches[p].area;
        for (size_t I = 0; I < S; I++)
            for (size_t J = 0; J < S; J++) {
                double sum = 0;
                for (int t = 0; t < threads; t++)
                    sum += sink.tables[(size_t)t * S * S + I * S + J];
                matrix[I * S + J] = surface_area[I] > 0 ? sum / surface_area[I] : 0;
            }
        if (areas)
            memcpy(areas, surface_area, S * sizeof(double));
    }
    free(sink.tables);
    free(surface_area);
    return status;
}
