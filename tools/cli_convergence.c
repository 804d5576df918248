/*
 * cli_convergence.c - --plot and --record: watching a solve converge from the command
 * line. An observer (rad_solve_step) keeps each step's numbers for the SVG plot and
 * streams each snapshot to the record; the view-factor command plots the work left
 * instead (its computation has no iteration). The library draws and writes
 * (rad_convergence_plot_write, rad_solve_record_*); this file wires them to the options.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cli.h"

bool cli_convergence_paths_ok(const char *plot_path, const char *record_path)
{
    if (plot_path) {
        const char *dot = strrchr(plot_path, '.');
        if (!dot || strchr(dot, '/') || strcasecmp(dot, ".svg") != 0) {
            cli_error("--plot %s: the plot is an SVG file: give a name ending in .svg",
                      plot_path);
            return false;
        }
    }
    if (plot_path && record_path && strcmp(plot_path, record_path) == 0) {
        cli_error("--plot and --record both name %s", plot_path);
        return false;
    }
    return true;
}

/* The observer: every step into the history and, with a record, into it; the first error
 * is kept and the rest of the steps are then ignored. */
static void observe(void *user, const rad_solve_step *step)
{
    cli_convergence *c = user;
    if (c->status != RAD_OK)
        return;
    c->status = rad_convergence_add(&c->history, step, &c->error);
    if (c->status == RAD_OK && c->record)
        c->status = rad_solve_record_add(c->record, step, &c->error);
}

rad_status cli_convergence_begin(cli_convergence *c, const char *plot_path,
                                 const char *record_path, const char *scene, rad_solver solver,
                                 uint32_t patches, rad_scene_solve_options *options,
                                 rad_error *error)
{
    memset(c, 0, sizeof(*c));
    c->plot_path = plot_path;
    c->solver = solver;
    c->patches = patches;
    snprintf(c->scene, sizeof(c->scene), "%s", scene);
    if (!plot_path && !record_path)
        return RAD_OK;
    if (record_path) {
        rad_status status = rad_solve_record_open(record_path, scene, rad_solver_name(solver),
                                                  patches, &c->record, error);
        if (status != RAD_OK)
            return status;
    }
    options->observer = observe;
    options->observer_user = c;
    return RAD_OK;
}

/* The file's name without its folder, for a title. */
static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

rad_status cli_convergence_end(cli_convergence *c, rad_status solved, rad_error *error)
{
    rad_status status = solved;
    if (status == RAD_OK && c->status != RAD_OK) {
        *error = c->error;
        status = c->status;
    }
    if (c->record) {
        if (status == RAD_OK)
            status = rad_solve_record_commit(c->record, error);
        else
            rad_solve_record_abort(c->record);
        c->record = NULL;
    }
    if (status == RAD_OK && c->plot_path) {
        char title[512];
        snprintf(title, sizeof(title), "%s: %s solver, %u patches", base_name(c->scene),
                 rad_solver_name(c->solver), c->patches);
        rad_convergence_plot_options plot = {title, "sweeps", true, NULL, NULL, NULL};
        switch (c->solver) {
        case RAD_SOLVER_SHOOT:
            plot.step_label = "shots";
            plot.criterion_label = "unshot energy fraction";
            break;
        case RAD_SOLVER_GAUSS_SEIDEL:
        case RAD_SOLVER_HIERARCHICAL:
            plot.criterion_label = "relative change of a sweep";
            break;
        case RAD_SOLVER_DIRECT:
            plot.step_label = "steps (one LU solve)";
            break;
        default: /* Jacobi: its criterion is the residual one sweep earlier */
            break;
        }
        status = rad_convergence_plot_write(&c->history, c->plot_path, &plot, error);
    }
    rad_convergence_free(&c->history);
    return status;
}

/* The view-factor computation's progress as a history: the fraction of polygon pairs left
 * against time; each report also goes on to the terminal's progress. */
static void viewfactor_progress(void *user, const char *phase, double fraction)
{
    cli_viewfactor_plot *p = user;
    cli_progress(NULL, phase, fraction);
    /* the library reports at most 0.999 until the end: a report there is no measurement */
    if (p->status != RAD_OK || strcmp(phase, "view factors") != 0 || fraction >= 0.999)
        return;
    rad_solve_step step = {0};
    step.step = (uint32_t)p->history.count;
    step.seconds = rad_clock_seconds() - p->start;
    step.criterion = 1 - fraction;
    step.residual = step.unshot = NAN;
    p->status = rad_convergence_add(&p->history, &step, &p->error);
}

void cli_viewfactor_plot_begin(cli_viewfactor_plot *p, const char *path,
                               rad_viewfactor_options *options)
{
    memset(p, 0, sizeof(*p));
    p->path = path;
    if (!path)
        return;
    p->start = rad_clock_seconds();
    rad_solve_step first = {0};
    first.criterion = 1;
    first.residual = first.unshot = NAN;
    p->status = rad_convergence_add(&p->history, &first, &p->error);
    if (options->progress) { /* not on the ranks that show no progress */
        options->progress = viewfactor_progress;
        options->progress_user = p;
    }
}

rad_status cli_viewfactor_plot_end(cli_viewfactor_plot *p, const char *scene,
                                   uint32_t surfaces, rad_error *error)
{
    rad_status status = p->status;
    if (status != RAD_OK)
        *error = p->error;
    if (status == RAD_OK && p->path) {
        rad_solve_step last = {0};
        last.step = (uint32_t)p->history.count;
        last.seconds = rad_clock_seconds() - p->start;
        last.criterion = 0; /* all done: below the log axis, so the curve ends at the last
                               report before it */
        last.residual = last.unshot = NAN;
        status = rad_convergence_add(&p->history, &last, error);
        char title[512];
        snprintf(title, sizeof(title), "%s: view factors, %u surfaces (work left, not an error)",
                 base_name(scene), surfaces);
        rad_convergence_plot_options plot = {title, NULL, false, "fraction of polygon pairs left",
                                             "polygon pairs left / all pairs (1)",
                                             "time since the view factors began (s)"};
        if (status == RAD_OK)
            status = rad_convergence_plot_write(&p->history, p->path, &plot, error);
    }
    rad_convergence_free(&p->history);
    return status;
}
