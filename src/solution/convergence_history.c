/*
 * convergence_history.c - rad_convergence: the numbers of a solver's steps, kept in order
 * for the convergence plot (convergence_plot.c). It keeps no radiosity: the record
 * (solve_record.c) does that.
 */
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"

rad_status rad_convergence_add(rad_convergence *history, const rad_solve_step *step,
                               rad_error *error)
{
    void *points = history->points;
    if (!rad_grow_array(&points, &history->capacity, history->count + 1,
                        sizeof(rad_convergence_point)))
        return rad_fail(error, RAD_ERR_NOMEM, "no memory for %zu steps of the convergence",
                        history->count + 1);
    history->points = points;
    history->points[history->count++] = (rad_convergence_point){
        step->step, step->seconds, step->criterion, step->residual, step->unshot, step->phase};
    return RAD_OK;
}

void rad_convergence_free(rad_convergence *history)
{
    if (!history)
        return;
    free(history->points);
    history->points = NULL;
    history->count = history->capacity = 0;
}
