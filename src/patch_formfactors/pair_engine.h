/*
 * pair_engine.h - computing the symmetric transfer G_ij = A_i F_ij = A_j F_ji of every
 * patch pair, in parallel, and handing each to a sink.
 *
 * What a sink does with G decides the product: the dense patch matrix (formfactors.c) or
 * the surface-to-surface view factors (viewfactors.c). Storing G once per pair is what
 * makes reciprocity exact by construction.
 */
#ifndef RAD_FORMFACTOR_PAIR_ENGINE_H
#define RAD_FORMFACTOR_PAIR_ENGINE_H

#include "radiosity.h"

/* Called once for every pair i < j with G > 0, from thread `thread` (0 .. threads-1). Calls
 * for the same i come from one thread; calls for different pairs may run at once. */
typedef void (*pair_sink_fn)(void *sink, int thread, uint32_t i, uint32_t j, double G);

/* The number of threads pair_engine_run will use for these options. */
int pair_engine_threads(const rad_formfactor_options *options);

/* What a run holds besides the matrix and the mesh, at most: each patch's geometry,
 * quadrature points and buried cells, and each thread's segment batches. */
uint64_t pair_engine_bytes(uint32_t patches, int threads, uint32_t quadrature);

/* rows: NULL for every pair, else only the pairs (i, j > i) of the rows i with rows[i]
 * (an MPI rank's share). */
rad_status pair_engine_run(const rad_mesh *mesh, const rad_tracer *occluders,
                           const rad_formfactor_options *options, const uint8_t *rows,
                           pair_sink_fn sink, void *sink_data, rad_formfactor_report *report,
                           rad_error *error);

/* Rows in rounds, for a caller that checkpoints between them (solve_checkpoint.h): round r
 * computes the rows order[end[r - 1] .. end[r]) (end[-1] = 0), then after_round(user, r,
 * false) runs on the calling thread, outside the parallel work, and ends the run early when
 * it returns true (stopped_after then holds r + 1 rounds done; else `rounds`). A run that
 * fails before its rows (out of memory) calls after_round(user, 0, true) once, so that a
 * caller whose after_round is collective over MPI ranks stays in step with the others. */
typedef struct pair_rounds {
    const uint32_t *order;
    const uint32_t *end;
    uint32_t rounds;
    bool (*after_round)(void *user, uint32_t round, bool failed);
    void *user;
    uint32_t stopped_after;
} pair_rounds;

rad_status pair_engine_run_rounds(const rad_mesh *mesh, const rad_tracer *occluders,
                                  const rad_formfactor_options *options, pair_rounds *rounds,
                                  pair_sink_fn sink, void *sink_data,
                                  rad_formfactor_report *report, rad_error *error);

#endif
