/*
 * cli_solve.c - what `render` and `solve` share: the SOLVE options, and scene -> mesh ->
 * solution (rad_solve_scene, or a solution file read back), with its --stats fields. The
 * library decides the solver and runs every phase; this file only parses and reports.
 * See cli.h.
 */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

void cli_parse_two_sided(const cli_args *args, int option, cli_two_sided *out)
{
    int cursor = 0;
    out->count = 0;
    for (const char *name; out->count < CLI_MAX_GIVEN &&
                           (name = cli_next_value(args, option, &cursor));)
        out->name[out->count++] = name;
}

rad_status cli_apply_two_sided(const cli_two_sided *two_sided, rad_scene *scene,
                               rad_error *error)
{
    for (int k = 0; k < two_sided->count; k++) {
        rad_status status =
            rad_scene_set_surface_flags(scene, two_sided->name[k], RAD_SURFACE_TWO_SIDED, error);
        if (status != RAD_OK) {
            char message[RAD_ERROR_MESSAGE_MAX];
            snprintf(message, sizeof(message), "%s", error->message);
            snprintf(error->message, sizeof(error->message), "--two-sided: %.900s", message);
            return status;
        }
    }
    return RAD_OK;
}

bool cli_parse_solve(const cli_args *args, const cli_shared *shared, cli_solve *solve)
{
    memset(solve, 0, sizeof(*solve));
    rad_scene_solve_options *o = &solve->options;
    if (args->value[OPT_SOLVER] && (!rad_solver_from_name(args->value[OPT_SOLVER], &o->solver) ||
                                    o->solver == RAD_SOLVER_AUTO)) {
        cli_error("--solver: '%s' is not gather, gauss-seidel, shoot, direct or hierarchical",
                  args->value[OPT_SOLVER]);
        return false;
    }
    if (args->value[OPT_TOLERANCE] &&
        !cli_parse_positive("tolerance", args->value[OPT_TOLERANCE], &o->tolerance))
        return false;
    if (args->value[OPT_MAX_ITERATIONS]) {
        unsigned long value;
        if (!cli_parse_uint("max-iterations", args->value[OPT_MAX_ITERATIONS], UINT32_MAX,
                            &value))
            return false;
        o->max_iterations = (uint32_t)value;
    }
    if (args->value[OPT_REFINE_THRESHOLD] &&
        !cli_parse_positive("refine-threshold", args->value[OPT_REFINE_THRESHOLD],
                            &o->refine_threshold))
        return false;
    if (args->value[OPT_MAX_MEMORY] &&
        !cli_parse_bytes("max-memory", args->value[OPT_MAX_MEMORY], &o->max_memory))
        return false;
    cli_memory_budget(o->max_memory);
    o->quadrature = shared->formfactor.quadrature;
    o->visibility_rays = shared->formfactor.visibility_rays;
    o->seed = shared->seed;
    o->threads = shared->threads;
    o->log = cli_log;
    o->progress = cli_progress;
    solve->solution_path = args->value[OPT_SOLUTION];
    solve->save_solution_path = args->value[OPT_SAVE_SOLUTION];
    if (solve->solution_path && solve->save_solution_path) {
        cli_error("--solution and --save-solution together: a solution read from a file "
                  "is saved already");
        return false;
    }
    solve->plot_path = args->value[OPT_PLOT];
    solve->record_path = args->value[OPT_RECORD];
    if (!cli_convergence_paths_ok(solve->plot_path, solve->record_path))
        return false;
    solve->resume_path = args->value[OPT_SOLVE_RESUME];
    solve->checkpoint_path =
        args->value[OPT_SOLVE_CHECKPOINT] ? args->value[OPT_SOLVE_CHECKPOINT] : solve->resume_path;
    solve->checkpoint_interval = CLI_CHECKPOINT_INTERVAL;
    if (args->value[OPT_SOLVE_CHECKPOINT_INTERVAL]) {
        if (!solve->checkpoint_path) {
            cli_error("--checkpoint-interval: give --checkpoint FILE (or --resume FILE) too");
            return false;
        }
        if (!cli_parse_checkpoint_interval(args->value[OPT_SOLVE_CHECKPOINT_INTERVAL],
                                           &solve->checkpoint_interval))
            return false;
    }
    if (solve->solution_path && solve->checkpoint_path) {
        cli_error("--solution with %s: nothing is solved, so there is nothing to checkpoint",
                  solve->resume_path ? "--resume" : "--checkpoint");
        return false;
    }
    if (solve->solution_path && (solve->plot_path || solve->record_path)) {
        cli_error("%s with --solution: nothing is solved, so there is no convergence to "
                  "watch", solve->plot_path ? "--plot" : "--record");
        return false;
    }
    if (solve->solution_path) {
        /* nothing is solved: options of the form factors and the solver have no effect */
        static const int unused[] = {OPT_SOLVER,          OPT_TOLERANCE,  OPT_MAX_ITERATIONS,
                                     OPT_VISIBILITY_RAYS, OPT_QUADRATURE, OPT_REFINE_THRESHOLD};
        static const char *const names[] = {"--solver",          "--tolerance",
                                            "--max-iterations",  "--visibility-rays",
                                            "--quadrature",      "--refine-threshold"};
        char given[192] = "";
        for (size_t k = 0; k < sizeof(unused) / sizeof(unused[0]); k++)
            if (args->value[unused[k]]) {
                size_t length = strlen(given);
                snprintf(given + length, sizeof(given) - length, "%s%s", length ? ", " : "",
                         names[k]);
            }
        if (given[0])
            cli_warn("%s: the solution is read from this file, nothing is solved: %s "
                     "ignored",
                     solve->solution_path, given);
    }
    return true;
}

bool cli_solve_outputs_writable(const cli_shared *shared, const cli_solve *solve)
{
    return (!shared->output || cli_output_writable(shared->output)) &&
           (!shared->stats_path || cli_output_writable(shared->stats_path)) &&
           (!solve->save_solution_path || cli_output_writable(solve->save_solution_path)) &&
           (!solve->plot_path || cli_output_writable(solve->plot_path)) &&
           (!solve->record_path || cli_output_writable(solve->record_path)) &&
           (!solve->checkpoint_path || cli_output_writable(solve->checkpoint_path));
}

static volatile sig_atomic_t interrupt_requested;

static void on_interrupt(int signal_number)
{
    (void)signal_number;
    interrupt_requested = 1;
    signal(SIGINT, SIG_DFL); /* a second Ctrl-C ends the run at once */
}

/* The refusal of a solution file solved with another patch size than the one given. */
static rad_status patch_size_mismatch(const rad_solution *solution, double given_size,
                                      rad_error *error)
{
    /* the fewest digits (6 or more) that tell the two sizes apart */
    int digits = 6;
    char saved[32], given[32];
    do {
        snprintf(saved, sizeof(saved), "%.*g", digits, solution->patch_size);
        snprintf(given, sizeof(given), "%.*g", digits, given_size);
    } while (strcmp(saved, given) == 0 && ++digits <= 17);
    error->status = RAD_ERR_INVALID;
    snprintf(error->message, sizeof(error->message),
             "%s: solved with --patch-size %s, not %s (leave --patch-size out to use the "
             "file's)",
             solution->source, saved, given);
    return RAD_ERR_INVALID;
}

rad_status cli_solve_scene(const char *scene_path, const cli_shared *shared,
                           const cli_solve *solve, cli_solved *out, rad_error *error)
{
    memset(out, 0, sizeof(*out));
    rad_solution *solution = NULL;
    double t0 = rad_clock_seconds();
    rad_status status = cli_load_scene(scene_path, &out->scene, error);
    if (status == RAD_OK)
        status = cli_apply_two_sided(&solve->two_sided, out->scene, error);
    if (status != RAD_OK)
        goto done;
    double t_load = rad_clock_seconds();
    out->seconds_load = t_load - t0;

    double patch_size = shared->patch_size;
    if (solve->solution_path) {
        status = rad_solution_read(solve->solution_path, &solution, error);
        if (status != RAD_OK)
            goto done;
        if (patch_size > 0 && patch_size != solution->patch_size) {
            status = patch_size_mismatch(solution, patch_size, error);
            goto done;
        }
        patch_size = solution->patch_size;
    }
    if (!(patch_size > 0) &&
        !((patch_size = rad_default_patch_size(out->scene, solve->options.solver)) > 0)) {
        status = error->status = RAD_ERR_NOMEM;
        snprintf(error->message, sizeof(error->message), "out of memory");
        goto done;
    }
    /* the proximity refinement serves the dense solvers' automatic patch size (a scene's
     * extent says little about its rooms); an explicit --patch-size is taken as it is,
     * and the hierarchical solver's own default leaves are ten times finer already (also
     * when the automatic choice took its size: a scene whose own triangles are finer than
     * the dense size, rad_default_patch_size) */
    bool hierarchical_size =
        solve->options.solver == RAD_SOLVER_HIERARCHICAL ||
        (solve->options.solver == RAD_SOLVER_AUTO && !(shared->patch_size > 0) && !solution &&
         rad_mesh_patch_count_at(out->scene, patch_size) > RAD_DENSE_MAX_PATCHES);
    int proximity_levels =
        shared->proximity_levels < 0                             ? 0
        : shared->proximity_levels > 0                           ? shared->proximity_levels
        : solution                                               ? solution->proximity_levels
        : shared->patch_size > 0                                 ? 0
        : hierarchical_size                                      ? 0
                                                                 : RAD_PROXIMITY_LEVELS_DEFAULT;
    /* a solution file's mesh is rebuilt as it was made, unless the command line says */
    int shadow_levels = shared->shadow_levels == 0 && solution ? solution->shadow_levels
                                                               : shared->shadow_levels;
    rad_mesh_options mesh_options = {.patch_size = patch_size,
                                     .shadow_levels = shadow_levels,
                                     .proximity_levels = proximity_levels};
    status = rad_mesh_build_with(out->scene, &mesh_options, &out->mesh, error);
    if (status != RAD_OK)
        goto done;
    out->seconds_mesh = rad_clock_seconds() - t_load;
    double t_mesh = rad_clock_seconds();
    status = rad_patch_inputs_build(out->scene, out->mesh, &out->inputs, error);
    out->seconds_inputs = rad_clock_seconds() - t_mesh;
    if (status != RAD_OK)
        goto done;

    if (solution) {
        status = rad_solution_match(solution, out->scene, out->mesh, error);
        if (status != RAD_OK)
            goto done;
        out->B = solution->B; /* taken over */
        solution->B = NULL;
        out->from_file = true;
        goto done;
    }
    /* the light at the vertices comes after the solve, when the solver's buffers are
     * freed: it must fit what the scene, mesh and inputs leave, or nothing is solved */
    if (solve->light_at_vertices && rad_memory_budget()) {
        status = rad_memory_budget_need(rad_vertex_light_bytes(out->scene, out->mesh),
                                        "the light at the vertices after the solve (none "
                                        "with --direct solution)",
                                        error);
        if (rad_rank_count() > 1 && rad_ranks_failures(status != RAD_OK) > 0 &&
            status == RAD_OK) {
            status = error->status = RAD_ERR_NOMEM;
            snprintf(error->message, sizeof(error->message),
                     "--max-memory: the light at the vertices does not fit on another rank");
        }
        if (status != RAD_OK)
            goto done;
    }
    out->B = rad_alloc_array(out->mesh->patch_count, sizeof(*out->B));
    if (!out->B) {
        status = error->status = RAD_ERR_NOMEM;
        snprintf(error->message, sizeof(error->message), "out of memory");
        goto done;
    }
    /* Ctrl-C stops a solver that can stop cleanly with the solution so far; any other
     * solve ends at once, as a plain program does */
    rad_scene_solve_options options = solve->options;
    options.inputs = out->inputs;
    rad_solver solver = rad_solve_scene_choice(out->mesh, &options, NULL, 0);
    bool stoppable = solver == RAD_SOLVER_HIERARCHICAL;
    cli_convergence convergence;
    bool writer = rad_rank() == 0; /* under MPI, rank 0 alone writes files */
    status = cli_convergence_begin(&convergence, writer ? solve->plot_path : NULL,
                                   writer ? solve->record_path : NULL, out->scene->source,
                                   solver, out->mesh->patch_count, &options, error);
    if (status != RAD_OK)
        goto done;
    void (*previous)(int) = SIG_DFL;
    interrupt_requested = 0;
    cli_checkpoints checkpoints;
    if (solve->checkpoint_path) { /* every solver stops at a checkpoint */
        options.checkpoint = solve->checkpoint_path;
        options.checkpoint_interval = solve->checkpoint_interval;
        options.resume = solve->resume_path;
        options.stop = cli_checkpoints_begin(&checkpoints, &options.progress,
                                             &options.progress_user);
    } else if (stoppable) {
        options.stop = &interrupt_requested;
        previous = signal(SIGINT, on_interrupt);
    }
    cli_progress_mark();
    status = rad_solve_scene(out->scene, out->mesh, &options, out->B, &out->report, error);
    if (solve->checkpoint_path)
        cli_checkpoints_end(&checkpoints);
    else if (stoppable)
        signal(SIGINT, previous == SIG_ERR ? SIG_DFL : previous);
    cli_progress_end();
    status = cli_convergence_end(&convergence, status, error);
    out->checkpoint_stop = status == RAD_OK && solve->checkpoint_path && out->report.interrupted;
    if (status == RAD_OK && writer && out->report.resumed)
        cli_summary("resumed from %s", solve->resume_path);
    if (status != RAD_OK || !solve->save_solution_path || !writer || out->checkpoint_stop)
        goto done;
    double t_save = rad_clock_seconds();
    status = rad_solution_write(out->scene, out->mesh, out->B, solve->save_solution_path, error);
    out->seconds_save = rad_clock_seconds() - t_save;
done:
    rad_solution_destroy(solution);
    if (status != RAD_OK)
        cli_solved_free(out);
    return status;
}

int cli_checkpoint_stop(const char *command, const cli_solve *solve)
{
    if (rad_rank() == 0)
        cli_error("%s: interrupted: %s holds the solve so far (nothing else was written); "
                  "continue with --resume %s",
                  command, solve->checkpoint_path, solve->checkpoint_path);
    return EXIT_INTERRUPTED;
}

void cli_solved_free(cli_solved *solved)
{
    free(solved->B);
    rad_patch_inputs_destroy(solved->inputs);
    solved->inputs = NULL;
    rad_mesh_destroy(solved->mesh);
    rad_scene_destroy(solved->scene);
    solved->B = NULL;
    solved->mesh = NULL;
    solved->scene = NULL;
}

void cli_solved_stats(const cli_solved *s, const cli_solve *solve, cli_stats *stats)
{
    const rad_scene_solve_report *r = &s->report;
    stats_string(stats, "scene", s->scene->source);
    stats_integer(stats, "triangles", s->scene->triangle_count);
    stats_integer(stats, "patches", s->mesh->patch_count);
    stats_number(stats, "patch_size", s->mesh->patch_size);
    stats_integer(stats, "shadow_splits", s->mesh->shadow_splits);
    stats_integer(stats, "proximity_splits", s->mesh->proximity_splits);
    stats_bool(stats, "shadow_budget_reached", s->mesh->shadow_budget_reached);
    stats_number(stats, "seconds_load", s->seconds_load);
    stats_number(stats, "seconds_mesh", s->seconds_mesh);
    if (s->from_file) {
        stats_string(stats, "solution", solve->solution_path);
        return;
    }
    stats_string(stats, "solver", rad_solver_name(r->solver));
    if (solve->checkpoint_path) {
        stats_integer(stats, "checkpoints_written", r->checkpoints);
        stats_bool(stats, "resumed", r->resumed);
    }
    stats_bool(stats, "solver_chosen", r->solver_chosen);
    stats_string(stats, "solver_reason", r->reason);
    stats_integer(stats, "iterations", r->iterations);
    stats_number(stats, "final_residual", r->residual);
    stats_bool(stats, "converged", r->converged);
    stats_number(stats, "seconds_inputs", s->seconds_inputs);
    stats_number(stats, "seconds_solve", r->seconds_solve);
    if (solve->save_solution_path)
        stats_number(stats, "seconds_save_solution", s->seconds_save);
    if (r->solver == RAD_SOLVER_HIERARCHICAL) {
        const rad_hierarchy_report *h = &r->hierarchy;
        stats_integer(stats, "leaves", h->leaves);
        stats_integer(stats, "elements", h->elements);
        stats_integer(stats, "clusters", h->clusters);
        stats_integer(stats, "links", h->links);
        stats_integer(stats, "links_partial", h->links_partial);
        stats_integer(stats, "link_bytes", h->link_bytes);
        stats_integer(stats, "rays_cast", h->rays);
        stats_integer(stats, "refinement_passes", h->passes);
        stats_integer(stats, "threads", (unsigned long long)h->threads);
        stats_number(stats, "last_change", h->change);
        stats_bool(stats, "memory_capped", h->memory_capped);
        stats_bool(stats, "interrupted", h->interrupted);
        stats_number(stats, "seconds_hierarchy", h->seconds_build);
        stats_number(stats, "seconds_refine", h->seconds_refine);
        stats_number(stats, "seconds_gather", h->seconds_gather);
        stats_number(stats, "seconds_final_gather", h->seconds_final);
        return;
    }
    const rad_formfactor_report *ff = &r->formfactors;
    stats_integer(stats, "patch_pairs", ff->pairs);
    stats_integer(stats, "patch_pairs_facing", ff->pairs_facing);
    stats_integer(stats, "patch_pairs_refined", ff->pairs_refined);
    stats_integer(stats, "patch_pairs_clear", ff->pairs_clear);
    stats_integer(stats, "patch_pairs_exact", ff->pairs_exact);
    stats_integer(stats, "rays_cast", ff->rays);
    stats_number(stats, "rays_per_second", ff->seconds > 0 ? ff->rays / ff->seconds : 0);
    /* the tracer's own rate: rays per second of tracing per thread, times threads */
    stats_integer(stats, "threads", (unsigned long long)ff->threads);
    stats_number(stats, "tracing_rays_per_second",
                 ff->tracing_seconds > 0 ? ff->rays / (ff->tracing_seconds / ff->threads) : 0);
    stats_number(stats, "seconds_form_factors", r->seconds_form_factors);
    stats_number(stats, "solver_criterion", r->solve.criterion);
    stats_number(stats, "reciprocity_residual", r->check.reciprocity);
    stats_number(stats, "largest_row_sum", r->check.largest_row_sum);
    stats_number(stats, "closure_residual", r->check.closure);
    stats_number(stats, "largest_form_factor", r->check.largest_factor);
    stats_integer(stats, "patches_seeing_nothing", r->check.empty_rows);
}

void cli_solved_summary(const cli_solved *s, const cli_solve *solve, char *text, size_t size)
{
    const rad_scene_solve_report *r = &s->report;
    if (s->from_file) {
        snprintf(text, size, "%u patches, solution read from %s", s->mesh->patch_count,
                 solve->solution_path);
        return;
    }
    const char *chosen = r->solver_chosen ? " (chosen: " : "";
    if (r->solver == RAD_SOLVER_HIERARCHICAL) {
        const rad_hierarchy_report *h = &r->hierarchy;
        snprintf(text, size,
                 "%u patches, hierarchical%s%s%s, %llu elements, %llu clusters, %llu links, "
                 "%.1f M rays, %u sweeps (residual %.2g)%s%s; tree %.2f s, refine %.2f s, "
                 "gather %.2f s, final gather %.2f s; peak %.0f MB",
                 s->mesh->patch_count, chosen, r->solver_chosen ? r->reason : "",
                 r->solver_chosen ? ")" : "", (unsigned long long)h->elements,
                 (unsigned long long)h->clusters, (unsigned long long)h->links, h->rays / 1e6,
                 h->iterations, r->residual, h->memory_capped ? ", memory capped" : "",
                 h->interrupted ? ", interrupted" : "", h->seconds_build, h->seconds_refine,
                 h->seconds_gather, h->seconds_final, rad_peak_memory_bytes() / 1048576.0);
        return;
    }
    char solved[64];
    if (r->solver == RAD_SOLVER_DIRECT)
        snprintf(solved, sizeof(solved), "direct solve");
    else
        snprintf(solved, sizeof(solved), "%s, %u %s", rad_solver_name(r->solver), r->iterations,
                 r->solver == RAD_SOLVER_SHOOT ? "shots" : "sweeps");
    snprintf(text, size, "%u patches, %.1f M rays, %s (residual %.2g)", s->mesh->patch_count,
             r->formfactors.rays / 1e6, solved, r->residual);
}
