/*
 * progress.c - progress reports of parallel render loops, see progress.h.
 */
#include "render/progress.h"

#include <omp.h>

render_progress render_progress_start(rad_progress_fn report, void *user, const char *phase,
                                      uint64_t total)
{
    return (render_progress){report, user, phase, total ? total : 1, 0};
}

void render_progress_step(render_progress *progress)
{
    uint64_t done;
#pragma omp atomic capture
    done = ++progress->done;
    if (progress->report && omp_get_thread_num() == 0)
        progress->report(progress->user, progress->phase, (double)done / progress->total);
}

void render_progress_finish(const render_progress *progress)
{
    if (progress->report)
        progress->report(progress->user, progress->phase, 1);
}
