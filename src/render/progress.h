/*
 * progress.h - the progress report of a parallel render loop (internal), shared by the
 * radiosity render, the Whitted tracer and the path tracer.
 *
 * A loop over `total` units of work (rows, tiles) calls render_progress_step once per
 * finished unit from whichever thread finished it; the count is atomic, and only OpenMP
 * thread 0 calls the user's callback (rad_progress_fn is called from one thread only), so
 * the callback sees a rising fraction. render_progress_finish reports 1 once the loop is
 * over. With a NULL callback every call does nothing but count.
 */
#ifndef RAD_RENDER_PROGRESS_H
#define RAD_RENDER_PROGRESS_H

#include <stdint.h>

#include "radiosity.h"

typedef struct render_progress {
    rad_progress_fn report; /* NULL: no reports */
    void *user;
    const char *phase;      /* the name the callback receives ("render", ...) */
    uint64_t total;         /* units of work in the loop */
    uint64_t done;          /* units finished so far (atomic) */
} render_progress;

render_progress render_progress_start(rad_progress_fn report, void *user, const char *phase,
                                      uint64_t total);

/* One more unit finished; call from inside the parallel loop. */
void render_progress_step(render_progress *progress);

/* The loop is over: reports 1. Call outside the parallel region. */
void render_progress_finish(const render_progress *progress);

#endif
