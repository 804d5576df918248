/*
 * solve_checkpoint.h - the restart file of a long solve (rad_scene_solve_options.checkpoint,
 * .resume): what identifies the job, when to write, and the plumbing the solvers share.
 *
 * A checkpoint is one of three kinds, each the state at a point where the solver can stop
 * and go on bitwise as if it had not:
 *   FORMFACTORS  the dense solvers' form-factor rows done (formfactors.c, between rounds);
 *   ITERATE      the whole (trimmed) F and the iterate of Jacobi, Gauss-Seidel or shooting
 *                (between sweeps or shots, or after the last one when a stop came during
 *                it; the solver's own file writes its part); for the direct solver F alone
 *                (a stop before or during its LU, which is started again on resuming);
 *   HIERARCHY    the hierarchical solver's links, B and loop state (between sweeps;
 *                solve_hierarchical.c writes it).
 * The container is core/checkpoint_file.h; the header holds the job (below) and the kind.
 * A checkpoint of another scene, mesh, solver or of other options is refused naming the
 * file. Under MPI rank 0 reads and writes, and the steps here are collective. It does not
 * decide what a solver's state is, and it is not the solution file (solution_file.c).
 */
#ifndef RAD_SOLVE_CHECKPOINT_H
#define RAD_SOLVE_CHECKPOINT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "radiosity.h"

enum {
    SOLVE_CHECKPOINT_FORMFACTORS = 1,
    SOLVE_CHECKPOINT_ITERATE = 2,
    SOLVE_CHECKPOINT_HIERARCHY = 3
};

/* What a checkpoint belongs to: its state is valid only for the same values. Threads and
 * ranks are not in it: the result does not depend on them. */
typedef struct solve_checkpoint_job {
    uint64_t fingerprint;      /* rad_solution_fingerprint of the scene and mesh */
    uint32_t patches;
    uint32_t solver;           /* rad_solver, AUTO resolved */
    uint32_t quadrature, visibility_rays, max_iterations; /* as given (0: default) */
    uint64_t seed;
    double tolerance, refine_threshold; /* as given */
    uint64_t link_budget;      /* hierarchical: the links' byte budget (0 for dense) */
} solve_checkpoint_job;

/* A body being written: grows as values are put; `failed` once out of memory. */
typedef struct byte_sink {
    uint8_t *bytes;
    size_t size, capacity;
    bool failed;
    bool off; /* puts nothing (a rank that does not write) */
} byte_sink;

void sink_u32(byte_sink *sink, uint32_t v);
void sink_u64(byte_sink *sink, uint64_t v);
void sink_f64(byte_sink *sink, double v);
void sink_floats(byte_sink *sink, const float *v, size_t count);
void sink_rgbs(byte_sink *sink, const rad_rgb *v, size_t count);
void sink_bytes(byte_sink *sink, const void *data, size_t size);
void sink_free(byte_sink *sink);

/* A body being read: every get past the end returns 0 and sets `short_read`. */
typedef struct byte_source {
    const uint8_t *p, *end;
    bool short_read;
} byte_source;

uint32_t source_u32(byte_source *source);
uint64_t source_u64(byte_source *source);
double source_f64(byte_source *source);
void source_floats(byte_source *source, float *v, size_t count);
void source_rgbs(byte_source *source, rad_rgb *v, size_t count);
/* Bytes left to read. */
size_t source_left(const byte_source *source);


/* A run's checkpointing: where and when to write, and the checkpoint it resumed from. */
typedef struct solve_checkpoint {
    const char *path;           /* NULL: none is written (a run only resuming) */
    double interval, last;      /* seconds; rank 0's clock at the last write */
    const volatile int *stop;   /* raised (a signal): write one at the next step and stop */
    solve_checkpoint_job job;
    rad_progress_fn progress;   /* rank 0: told "checkpoint" after each write */
    void *progress_user;
    uint32_t written;           /* checkpoints written by this run */
    rad_formfactor_report formfactors; /* dense: the matrix's report (its counts and trim),
                                          kept in ITERATE checkpoints */
    bool interrupted;           /* stopped on request, the checkpoint written */
    /* resuming: the body (after the header) of the checkpoint read, on every rank */
    const char *resume_path;
    uint8_t *resumed;
    size_t resumed_size;
    uint32_t resumed_kind;      /* 0: nothing to resume (or used already) */
} solve_checkpoint;

/* Collective: reads cp->resume_path on rank 0, refuses another job's (RAD_ERR_INVALID
 * naming the file and what differs), and hands the body to every rank (cp->resumed). */
rad_status solve_checkpoint_read(solve_checkpoint *cp, rad_error *error);

/* The body of a checkpoint of `kind` to resume from, as a source (false: none of that kind;
 * then nothing is resumed). */
bool solve_checkpoint_resuming(const solve_checkpoint *cp, uint32_t kind, byte_source *source);

/* Drops the resumed body (after the solver took its state from it). */
void solve_checkpoint_resumed(solve_checkpoint *cp);

/* Collective: whether a stop was raised on any rank (false without a path). Cheap: a read,
 * and over ranks one small collective. */
bool solve_checkpoint_stop_raised(const solve_checkpoint *cp);

/* Collective, between steps of a solver: whether to write a checkpoint now (the interval
 * has passed by rank 0's clock, or a stop was raised on any rank); *stop tells the
 * latter. False without a path. Cheap: the clock, and over ranks two small collectives. */
bool solve_checkpoint_due(solve_checkpoint *cp, bool *stop);

/* Collective: rank 0 writes a checkpoint of `kind` with `body` (other ranks' body is
 * ignored); every rank learns the outcome. On success counts it and tells progress
 * ("checkpoint", fraction: the share of the work the checkpoint holds). */
rad_status solve_checkpoint_write(solve_checkpoint *cp, uint32_t kind, const byte_sink *body,
                                  double fraction, rad_error *error);

/* The checkpointed forms of the library's steps (NULL cp: the plain ones). */
rad_status formfactors_compute_checkpointed(const rad_mesh *mesh, const rad_tracer *occluders,
                                            const rad_formfactor_options *options,
                                            solve_checkpoint *cp, rad_formfactors **out,
                                            rad_formfactor_report *report, rad_error *error);
rad_status solve_checkpointed(const rad_system *system, const rad_solve_options *options,
                              solve_checkpoint *cp, rad_rgb *B, rad_solve_report *report,
                              rad_error *error);
rad_status solve_hierarchical_checkpointed(const rad_mesh *mesh,
                                           const rad_patch_inputs *inputs,
                                           const rad_tracer *occluders,
                                           const rad_hierarchy_options *options,
                                           solve_checkpoint *cp, rad_rgb *B,
                                           rad_hierarchy_report *report, rad_error *error);

/* The ITERATE kind: the whole matrix (trimmed), its report's counts and trim, the solver's
 * scalars, then the solver's vectors (n rad_rgb each: Jacobi and Gauss-Seidel B, shooting
 * B and the unshot dB; none for the direct solver: iterate_vectors). */
typedef struct iterate_state {
    uint32_t iterations;        /* sweeps or shots done */
    double criterion, smallest; /* the last criterion; the smallest (divergence watch) */
    uint32_t last_shooter;      /* shooting; UINT32_MAX otherwise */
} iterate_state;

/* The vectors an ITERATE checkpoint of `solver` holds after F. */
static inline uint32_t iterate_vectors(rad_solver solver)
{
    return solver == RAD_SOLVER_SHOOT ? 2 : solver == RAD_SOLVER_DIRECT ? 0 : 1;
}

/* Starts an ITERATE body on rank 0 (elsewhere the sink stays off): F, its report, state. */
void iterate_body_begin(const solve_checkpoint *cp, const rad_system *system,
                        const iterate_state *state, byte_sink *body);
/* Collective, between a dense solver's steps: writes an ITERATE checkpoint of the body
 * when one is due (`put` adds the solver's vectors to it); true when the solver is to stop
 * here (cp->interrupted) or the checkpoint could not be written (*status). */
bool iterate_step(solve_checkpoint *cp, const rad_system *system, const iterate_state *state,
                  void (*put)(const void *user, byte_sink *body), const void *user,
                  rad_status *status, rad_error *error);
/* Collective, after a dense solver's last step or during a step that cannot be resumed
 * part way (the direct solver's LU): when a stop was raised on any rank, writes an ITERATE
 * checkpoint of `state` (`put`, unless NULL, adds the solver's vectors) and returns true:
 * the solver is to stop (cp->interrupted), or *status says why the checkpoint could not be
 * written. False (nothing written) otherwise. A resumed run must not take a further step
 * from a final state (the sweep solvers stop at once when its criterion meets the
 * tolerance), so that it ends as the uninterrupted run did. */
bool iterate_stop(solve_checkpoint *cp, const rad_system *system, const iterate_state *state,
                  void (*put)(const void *user, byte_sink *body), const void *user,
                  rad_status *status, rad_error *error);
/* Puts three channel arrays as n rad_rgb. */
void sink_channels(byte_sink *sink, const double *x0, const double *x1, const double *x2,
                   uint32_t n);
/* The ITERATE checkpoint being resumed: reads F (n x n) and the matrix's report (counts and
 * trim) into the given places (either may be NULL: skipped), the state into *state, and
 * leaves *source at the vectors. False (error set, naming the file) when the body does not
 * hold `vectors` vectors of finite values >= 0 (shooting's dB included) after F in [0, 1]. */
bool iterate_body_read(const solve_checkpoint *cp, uint32_t n, uint32_t vectors, float *F,
                       rad_formfactor_report *formfactors, iterate_state *state,
                       byte_source *source,
                       rad_error *error);
/* Reads three channel arrays from n rad_rgb. */
void source_channels(byte_source *source, double *x0, double *x1, double *x2, uint32_t n);
/* A one-vector sweep solver's resume (Jacobi, Gauss-Seidel): when `cp` resumes an ITERATE
 * checkpoint, B into x0, x1, x2 and the sweeps done, the criterion and the smallest one so
 * far into *sweeps, *criterion and *smallest (left as they are otherwise). False (error
 * set, naming the file) for a damaged body. */
bool iterate_resume_sweeps(solve_checkpoint *cp, uint32_t n, double *x0, double *x1,
                           double *x2, uint32_t *sweeps, double *criterion, double *smallest,
                           rad_error *error);

#endif
