/*
 * solve_observe.c - handing a dense solver's steps to rad_solve_options.observer.
 *
 * Fills the rest of a rad_solve_step (B in the observer's layout, the residual when the
 * solver does not have it for free) and keeps the time this takes out of the step's
 * seconds. It decides nothing about when a solver observes: each solver calls it at its
 * own steps (see rad_solve_step in radiosity.h), and rad_solve makes the final call.
 */
#include <math.h>

#include "core/clock.h"
#include "solve/solve_internal.h"

double solve_elapsed(const solve_params *params)
{
    return rad_clock_seconds() - params->start - params->observe_seconds;
}

rad_solve_step solve_step(const solve_params *params, uint32_t n, uint32_t step,
                          const char *phase, double criterion)
{
    rad_solve_step s = {0};
    s.step = step;
    s.phase = phase;
    s.seconds = solve_elapsed(params);
    s.criterion = criterion;
    s.residual = NAN;
    s.unshot = NAN;
    s.shooting_patch = UINT32_MAX;
    s.n = n;
    return s;
}

void solve_observe(solve_params *params, const rad_system *system, rad_solve_step step,
                   const double *x0, const double *x1, const double *x2, const rad_rgb *B_rgb,
                   bool compute_residual)
{
    if (!params->observer)
        return;
    double t0 = rad_clock_seconds();
    if (x0) {
        rad_rgb *B = params->observed;
        for (uint32_t i = 0; i < system->n; i++)
            B[i] = (rad_rgb){x0[i], x1[i], x2[i]};
        B_rgb = B;
    }
    step.B = B_rgb;
    step.n = system->n;
    if (compute_residual)
        step.residual = solve_residual(system, B_rgb, params->threads);
    params->observer(params->observer_user, &step);
    params->observe_seconds += rad_clock_seconds() - t0;
}
