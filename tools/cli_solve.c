/*
 * cli_solve.c - what `render` and `solve` share: the SOLVE options, and scene -> mesh ->
 * form factors -> solution (or a solution file read back), with its --stats fields.
 * See cli.h.
 */
#include <signal.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

/* Above this many patches the dense n x n matrix (64 MB of factors and 8 M patch pairs at
 * 4096) stops paying: without --solver, the hierarchical solver takes over. */
#define DENSE_MAX_PATCHES 4096u
/* Leaf patches the hierarchical solver's default patch size aims at. */
#define HIERARCHICAL_TARGET_PATCHES 30000u

/* Parses a byte count with an optional K, M or G suffix (powers of 1024). */
static bool parse_bytes(const char *name, const char *text, uint64_t *out)
{
    char *end = NULL;
    double value = strtod(text, &end);
    double scale = 1;
    if (end && *end) {
        if ((end[0] == 'K' || end[0] == 'k') && !end[1])
            scale = 1024.0;
        else if ((end[0] == 'M' || end[0] == 'm') && !end[1])
            scale = 1024.0 * 1024;
        else if ((end[0] == 'G' || end[0] == 'g') && !end[1])
            scale = 1024.0 * 1024 * 1024;
        else
            end = NULL;
    }
    if (!end || end == text || !(value >= 1) || !(value * scale < 1.8e19)) {
        cli_error("--%s: '%s' is not a size in bytes (a number, optionally followed by K, M "
                  "or G)",
                  name, text);
        return false;
    }
    *out = (uint64_t)(value * scale);
    return true;
}

bool cli_parse_solve(const cli_args *args, const cli_shared *shared, cli_solve *solve)
{
    memset(solve, 0, sizeof(*solve));
    const char *solver = args->value[OPT_SOLVER] ? args->value[OPT_SOLVER] : "gather";
    solve->solver_given = args->value[OPT_SOLVER] != NULL;
    if (strcmp(solver, "hierarchical") == 0)
        solve->hierarchical = true;
    else if (strcmp(solver, "gather") == 0 || strcmp(solver, "jacobi") == 0)
        solve->options.solver = RAD_SOLVER_JACOBI;
    else if (strcmp(solver, "gauss-seidel") == 0)
        solve->options.solver = RAD_SOLVER_GAUSS_SEIDEL;
    else if (strcmp(solver, "shoot") == 0)
        solve->options.solver = RAD_SOLVER_SHOOT;
    else if (strcmp(solver, "direct") == 0)
        solve->options.solver = RAD_SOLVER_DIRECT;
    else {
        cli_error("--solver: '%s' is not gather, gauss-seidel, shoot, direct or hierarchical",
                  solver);
        return false;
    }
    solve->options.ambient = true;
    if (args->value[OPT_TOLERANCE]) {
        if (!cli_parse_positive("tolerance", args->value[OPT_TOLERANCE],
                                &solve->options.tolerance))
            return false;
    }
    if (args->value[OPT_MAX_ITERATIONS]) {
        unsigned long value;
        if (!cli_parse_uint("max-iterations", args->value[OPT_MAX_ITERATIONS], UINT32_MAX,
                            &value))
            return false;
        solve->options.max_iterations = (uint32_t)value;
    }
    solve->options.threads = shared->threads;
    solve->options.progress = cli_progress;
    if (args->value[OPT_REFINE_THRESHOLD]) {
        if (!cli_parse_positive("refine-threshold", args->value[OPT_REFINE_THRESHOLD],
                                &solve->hierarchy.refine_threshold))
            return false;
    }
    if (args->value[OPT_MAX_MEMORY] &&
        !parse_bytes("max-memory", args->value[OPT_MAX_MEMORY], &solve->hierarchy.max_memory))
        return false;
    solve->hierarchy.tolerance = solve->options.tolerance;
    solve->hierarchy.max_sweeps = solve->options.max_iterations;
    solve->hierarchy.visibility_rays = shared->formfactor.visibility_rays;
    solve->hierarchy.seed = shared->seed;
    solve->hierarchy.threads = shared->threads;
    solve->hierarchy.progress = cli_progress;
    solve->solution_path = args->value[OPT_SOLUTION];
    solve->save_solution_path = args->value[OPT_SAVE_SOLUTION];
    if (solve->solution_path && solve->save_solution_path) {
        cli_error("--solution and --save-solution together: a solution read from a file "
                  "is saved already");
        return false;
    }
    if (solve->solution_path) {
        /* nothing is solved: options of the form factors and the solver have no effect */
        static const int unused[] = {OPT_SOLVER, OPT_TOLERANCE, OPT_MAX_ITERATIONS,
                                     OPT_VISIBILITY_RAYS, OPT_QUADRATURE};
        static const char *const names[] = {"--solver", "--tolerance", "--max-iterations",
                                            "--visibility-rays", "--quadrature"};
        char given[128] = "";
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

static const char *solver_name(rad_solver solver)
{
    switch (solver) {
    case RAD_SOLVER_JACOBI: return "gather";
    case RAD_SOLVER_GAUSS_SEIDEL: return "gauss-seidel";
    case RAD_SOLVER_SHOOT: return "shoot";
    case RAD_SOLVER_DIRECT: return "direct";
    }
    return "unknown";
}

static volatile sig_atomic_t interrupt_requested;

static void on_interrupt(int signal_number)
{
    (void)signal_number;
    interrupt_requested = 1;
    signal(SIGINT, SIG_DFL); /* a second Ctrl-C ends the run at once */
}

/* B from the hierarchical solver; Ctrl-C stops it cleanly with the solution so far. */
static rad_status solve_hierarchical(const cli_solve *solve, cli_solved *out, rad_error *error)
{
    rad_tracer *occluders = NULL;
    double t0 = cli_now();
    rad_status status =
        rad_tracer_create_for_scene(RAD_TRACER_EMBREE_FAST, out->scene, &occluders, error);
    if (status != RAD_OK)
        return status;
    rad_hierarchy_options options = solve->hierarchy;
    interrupt_requested = 0;
    options.stop = &interrupt_requested;
    void (*previous)(int) = signal(SIGINT, on_interrupt);
    cli_progress_mark();
    status = rad_solve_hierarchical(out->scene, out->mesh, occluders, &options, out->B,
                                    &out->hierarchy, error);
    signal(SIGINT, previous == SIG_ERR ? SIG_DFL : previous);
    rad_tracer_destroy(occluders);
    cli_progress_end();
    out->hierarchical = true;
    out->seconds_solve = cli_now() - t0;
    if (status != RAD_OK)
        return status;
    const rad_hierarchy_report *r = &out->hierarchy;
    if (r->interrupted)
        cli_warn("interrupted: refinement and gathering stopped after %u passes and %u sweeps "
                 "(change %.3g); going on with the solution so far",
                 r->passes, r->sweeps, r->residual);
    else if (!r->converged)
        cli_warn("the hierarchical solver stopped at its sweep limit (%u) with change %.3g, "
                 "above the tolerance",
                 r->sweeps, r->residual);
    if (r->memory_capped)
        cli_warn("--max-memory: the links reached the budget (%.1f MB of links); refinement "
                 "stopped there, so the answer is coarser than the threshold asks",
                 r->link_bytes / 1048576.0);
    return RAD_OK;
}

/* B from the form factors and the solver. */
static rad_status solve_here(const cli_shared *shared, const cli_solve *solve, cli_solved *out,
                             rad_error *error)
{
    rad_tracer *occluders = NULL;
    rad_formfactors *ff = NULL;
    rad_system system = {0};
    double t0 = cli_now();
    rad_status status =
        rad_tracer_create_for_scene(RAD_TRACER_EMBREE_FAST, out->scene, &occluders, error);
    cli_progress_mark();
    if (status == RAD_OK)
        status = rad_formfactors_compute(out->mesh, occluders, &shared->formfactor, &ff,
                                         &out->formfactors, error);
    if (status != RAD_OK)
        goto done;
    double t_ff = cli_now();
    out->seconds_form_factors = t_ff - t0;
    rad_formfactors_check(ff, out->mesh, &out->check);
    double t_check = cli_now();
    out->seconds_check = t_check - t_ff;
    status = rad_system_from_mesh(out->scene, out->mesh, ff, &system, error);
    if (status == RAD_OK)
        status = rad_solve(&system, &solve->options, out->B, &out->report, error);
    if (status != RAD_OK)
        goto done;
    cli_progress_end();
    if (!out->report.converged)
        cli_warn("the solver stopped at its iteration limit (%u) with residual %.3g, above the "
                 "tolerance",
                 out->report.iterations, out->report.criterion);
    out->seconds_solve = cli_now() - t_check;
done:
    rad_system_free_arrays(&system);
    rad_formfactors_destroy(ff);
    rad_tracer_destroy(occluders);
    return status;
}

rad_status cli_solve_scene(const char *scene_path, const cli_shared *shared,
                           const cli_solve *solve, uint32_t target_patches, cli_solved *out,
                           rad_error *error)
{
    memset(out, 0, sizeof(*out));
    rad_solution *solution = NULL;
    double t0 = cli_now();
    rad_status status = cli_load_scene(scene_path, &out->scene, error);
    if (status != RAD_OK)
        goto done;
    if (!rad_scene_has_emitter(out->scene))
        cli_warn("%s: no surface emits light (no material with non-zero Ke): the result will "
                 "be black (--emit NAME=R,G,B makes a surface a light)",
                 out->scene->source);
    double t_load = cli_now();
    out->seconds_load = t_load - t0;

    double patch_size = shared->patch_size;
    if (solve->solution_path) {
        status = rad_solution_read(solve->solution_path, &solution, error);
        if (status != RAD_OK)
            goto done;
        if (patch_size > 0 && patch_size != solution->patch_size) {
            status = error->status = RAD_ERR_INVALID;
            /* the fewest digits (6 or more) that tell the two sizes apart */
            int digits = 6;
            char saved[32], given[32];
            do {
                snprintf(saved, sizeof(saved), "%.*g", digits, solution->patch_size);
                snprintf(given, sizeof(given), "%.*g", digits, patch_size);
            } while (strcmp(saved, given) == 0 && ++digits <= 17);
            snprintf(error->message, sizeof(error->message),
                     "%s: solved with --patch-size %s, not %s (leave --patch-size out "
                     "to use the file's)",
                     solve->solution_path, saved, given);
            goto done;
        }
        patch_size = solution->patch_size;
    }
    if (!(patch_size > 0))
        patch_size = rad_mesh_default_patch_size(
            out->scene, solve->hierarchical ? HIERARCHICAL_TARGET_PATCHES : target_patches);
    status = rad_mesh_build(out->scene, patch_size, &out->mesh, error);
    if (status != RAD_OK)
        goto done;
    out->seconds_mesh = cli_now() - t_load;
    bool hierarchical = solve->hierarchical ||
                        (!solve->solver_given && out->mesh->patch_count > DENSE_MAX_PATCHES);

    if (solution) {
        status = rad_solution_match(solution, out->scene, out->mesh, error);
        if (status != RAD_OK)
            goto done;
        out->B = solution->B; /* taken over */
        solution->B = NULL;
        out->from_file = true;
        goto done;
    }
    out->B = calloc(out->mesh->patch_count ? out->mesh->patch_count : 1, sizeof(*out->B));
    if (!out->B) {
        status = error->status = RAD_ERR_NOMEM;
        snprintf(error->message, sizeof(error->message), "out of memory");
        goto done;
    }
    status = hierarchical ? solve_hierarchical(solve, out, error)
                          : solve_here(shared, solve, out, error);
    if (status != RAD_OK || !solve->save_solution_path)
        goto done;
    double t_save = cli_now();
    status = rad_solution_write(out->scene, out->mesh, out->B, solve->save_solution_path, error);
    out->seconds_save = cli_now() - t_save;
done:
    rad_solution_destroy(solution);
    if (status != RAD_OK)
        cli_solved_free(out);
    return status;
}

void cli_solved_free(cli_solved *solved)
{
    free(solved->B);
    rad_mesh_destroy(solved->mesh);
    rad_scene_destroy(solved->scene);
    solved->B = NULL;
    solved->mesh = NULL;
    solved->scene = NULL;
}

void cli_solved_stats(const cli_solved *s, const cli_solve *solve, cli_stats *stats)
{
    stats_string(stats, "scene", s->scene->source);
    stats_integer(stats, "triangles", s->scene->triangle_count);
    stats_integer(stats, "patches", s->mesh->patch_count);
    stats_number(stats, "patch_size", s->mesh->patch_size);
    stats_number(stats, "seconds_load", s->seconds_load);
    stats_number(stats, "seconds_mesh", s->seconds_mesh);
    if (s->from_file) {
        stats_string(stats, "solution", solve->solution_path);
        return;
    }
    if (s->hierarchical) {
        const rad_hierarchy_report *h = &s->hierarchy;
        stats_string(stats, "solver", "hierarchical");
        stats_integer(stats, "leaves", h->leaves);
        stats_integer(stats, "elements", h->elements);
        stats_integer(stats, "clusters", h->clusters);
        stats_integer(stats, "links", h->links);
        stats_integer(stats, "links_partial", h->links_partial);
        stats_integer(stats, "link_bytes", h->link_bytes);
        stats_integer(stats, "rays_cast", h->rays);
        stats_integer(stats, "refinement_passes", h->passes);
        stats_integer(stats, "iterations", h->sweeps);
        stats_integer(stats, "threads", (unsigned long long)h->threads);
        stats_number(stats, "final_residual", h->residual);
        stats_bool(stats, "converged", h->converged);
        stats_bool(stats, "memory_capped", h->memory_capped);
        stats_bool(stats, "interrupted", h->interrupted);
        stats_number(stats, "seconds_hierarchy", h->seconds_build);
        stats_number(stats, "seconds_refine", h->seconds_refine);
        stats_number(stats, "seconds_gather", h->seconds_gather);
        stats_number(stats, "seconds_final_gather", h->seconds_final);
        stats_number(stats, "seconds_solve", s->seconds_solve);
        if (solve->save_solution_path)
            stats_number(stats, "seconds_save_solution", s->seconds_save);
        return;
    }
    const rad_formfactor_report *ff = &s->formfactors;
    stats_integer(stats, "patch_pairs", ff->pairs);
    stats_integer(stats, "patch_pairs_facing", ff->pairs_facing);
    stats_integer(stats, "patch_pairs_refined", ff->pairs_refined);
    stats_integer(stats, "rays_cast", ff->rays);
    stats_number(stats, "rays_per_second", ff->seconds > 0 ? ff->rays / ff->seconds : 0);
    /* the tracer's own rate: rays per second of tracing per thread, times threads */
    stats_integer(stats, "threads", (unsigned long long)ff->threads);
    stats_number(stats, "tracing_rays_per_second",
                 ff->tracing_seconds > 0 ? ff->rays / (ff->tracing_seconds / ff->threads) : 0);
    stats_number(stats, "seconds_form_factors", s->seconds_form_factors);
    stats_number(stats, "seconds_solve", s->seconds_solve);
    stats_string(stats, "solver", solver_name(solve->options.solver));
    stats_integer(stats, "iterations", s->report.iterations);
    stats_number(stats, "solver_criterion", s->report.criterion);
    stats_number(stats, "final_residual", s->report.residual);
    stats_bool(stats, "converged", s->report.converged);
    stats_number(stats, "seconds_check", s->seconds_check);
    stats_number(stats, "reciprocity_residual", s->check.reciprocity);
    stats_number(stats, "largest_row_sum", s->check.largest_row_sum);
    stats_number(stats, "closure_residual", s->check.closure);
    stats_number(stats, "largest_form_factor", s->check.largest_factor);
    stats_integer(stats, "patches_seeing_nothing", s->check.empty_rows);
    if (solve->save_solution_path)
        stats_number(stats, "seconds_save_solution", s->seconds_save);
}

void cli_solved_summary(const cli_solved *s, const cli_solve *solve, char *text, size_t size)
{
    if (s->from_file) {
        snprintf(text, size, "%u patches, solution read from %s", s->mesh->patch_count,
                 solve->solution_path);
        return;
    }
    if (s->hierarchical) {
        const rad_hierarchy_report *h = &s->hierarchy;
        snprintf(text, size,
                 "%u patches, %llu elements, %llu clusters, %llu links, %.1f M rays, %u sweeps "
                 "(change %.2g)%s%s; tree %.2f s, refine %.2f s, gather %.2f s, final gather "
                 "%.2f s; peak %.0f MB",
                 s->mesh->patch_count, (unsigned long long)h->elements,
                 (unsigned long long)h->clusters, (unsigned long long)h->links, h->rays / 1e6,
                 h->sweeps, h->residual, h->memory_capped ? ", memory capped" : "",
                 h->interrupted ? ", interrupted" : "", h->seconds_build, h->seconds_refine,
                 h->seconds_gather, h->seconds_final,
                 rad_peak_memory_bytes() / 1048576.0);
        return;
    }
    char solved[64];
    if (solve->options.solver == RAD_SOLVER_DIRECT)
        snprintf(solved, sizeof(solved), "direct solve");
    else
        snprintf(solved, sizeof(solved), "%u %s", s->report.iterations,
                 solve->options.solver == RAD_SOLVER_SHOOT ? "shots" : "sweeps");
    snprintf(text, size, "%u patches, %.1f M rays, %s (residual %.2g)", s->mesh->patch_count,
             s->formfactors.rays / 1e6, solved, s->report.residual);
}
