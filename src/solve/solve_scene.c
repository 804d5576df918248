/*
 * solve_scene.c - rad_solve_scene: from a scene and its mesh to the radiosity of every
 * patch, whatever the solver. The one path every caller takes (the CLI's render and solve,
 * the tests, a program using the library):
 *
 *   patch inputs (rad_patch_inputs_build: albedo with textures, emission)   once
 *   the solver: the caller's, or the automatic choice by size and memory    reported
 *   dense:        occluders -> form factors (checked) -> rad_solve
 *   hierarchical: occluders -> rad_solve_hierarchical
 *   B: finite, and at least each patch's own exitance
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "core/alloc.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/memory.h"
#include "patch_formfactors/pair_engine.h"
#include "solve/hierarchical/hierarchy.h"
#include "solve/solve_checkpoint.h"

/* The automatic choice keeps the dense matrix to this share of the machine's memory (the
 * form-factor computation itself refuses above 3/4). */
#define AUTO_DENSE_MEMORY_SHARE 0.5

/* What each thread of the hierarchical solver holds besides the links, at most: its
 * refinement ray buffers (4096 links x 4 segments and 64 more, about 1 MB) and its final
 * gather's, rounded up. */
#define HIERARCHY_THREAD_BYTES ((uint64_t)2 << 20)


static double seconds_now(void) { return omp_get_wtime(); }

/* The dense solvers' matrices: F in floats, and the direct solver's LU copy in doubles. */
static double dense_matrix_bytes(uint32_t patches, rad_solver solver)
{
    double entries = (double)patches * patches;
    return entries * (sizeof(float) + (solver == RAD_SOLVER_DIRECT ? sizeof(double) : 0));
}

double rad_default_patch_size(const rad_scene *scene, rad_solver solver)
{
    if (solver == RAD_SOLVER_HIERARCHICAL)
        return rad_mesh_default_patch_size(scene, RAD_HIERARCHICAL_DEFAULT_PATCHES);
    double size = rad_mesh_default_patch_size(scene, RAD_DEFAULT_PATCHES);
    if (solver == RAD_SOLVER_AUTO && size > 0 &&
        rad_mesh_patch_count_at(scene, size) > RAD_DENSE_MAX_PATCHES)
        return rad_mesh_default_patch_size(scene, RAD_HIERARCHICAL_DEFAULT_PATCHES);
    return size;
}

/* What the solver's large buffers may take: options.max_memory, and, with a memory budget
 * set (rad_memory_budget_set, --max-memory), no more than is left of it; 0 = no limit. */
static uint64_t solver_budget(const rad_scene_solve_options *o)
{
    uint64_t left = rad_memory_budget_left();
    if (left == UINT64_MAX)
        return o->max_memory;
    if (left == 0)
        left = 1; /* nothing left is still a limit */
    return o->max_memory && o->max_memory < left ? o->max_memory : left;
}

/* " the budget of X MB", or with a memory budget set " the X MB left of the budget of Y
 * MB", for the messages of a buffer that does not fit `budget` (solver_budget). */
static void budget_words(uint64_t budget, char *text, size_t size)
{
    uint64_t whole = rad_memory_budget();
    if (whole && budget < whole)
        snprintf(text, size, "the %.1f MB left of the budget of %.1f MB", budget / 1048576.0,
                 whole / 1048576.0);
    else
        snprintf(text, size, "the budget of %.1f MB", budget / 1048576.0);
}

/* With a memory budget: what rad_solve_scene makes before a dense solver's matrix, so
 * that the matrix is judged on what those leave: the patch inputs (unless the caller
 * gives them), the occluders' BVH (its estimate) and the form factors' per-thread
 * buffers. */
static uint64_t before_matrix_bytes(const rad_scene *scene, const rad_mesh *mesh,
                                    const rad_scene_solve_options *o)
{
    uint64_t n = mesh->patch_count;
    uint64_t inputs = o->inputs ? 0 : n * (sizeof(double) + 5 * sizeof(rad_rgb));
    uint64_t threads = o->threads > 0 ? (uint64_t)o->threads : (uint64_t)omp_get_max_threads();
    return inputs + (uint64_t)scene->triangle_count * RAD_EMBREE_BYTES_PER_TRIANGLE +
           pair_engine_bytes(mesh->patch_count, (int)threads, o->quadrature);
}

rad_solver rad_solve_scene_choice(const rad_mesh *mesh, const rad_scene_solve_options *options,
                                  char *reason, size_t size)
{
    rad_scene_solve_options zero = {0};
    const rad_scene_solve_options *o = options ? options : &zero;
    uint32_t patches = mesh->patch_count;
    char ignored[8];
    if (!reason) {
        reason = ignored;
        size = sizeof(ignored);
    }
    if (o->solver != RAD_SOLVER_AUTO) {
        snprintf(reason, size, "asked for");
        return o->solver;
    }
    double matrix_bytes = (double)patches * patches * sizeof(float);
    uint64_t budget = solver_budget(o);
    uint64_t physical = rad_physical_memory_bytes();
    if (patches > RAD_DENSE_MAX_PATCHES) {
        snprintf(reason, size, "%u patches > %d: no dense matrix", patches,
                 RAD_DENSE_MAX_PATCHES);
        return RAD_SOLVER_HIERARCHICAL;
    }
    if (budget && matrix_bytes > (double)budget) {
        snprintf(reason, size, "the %.1f MB matrix would not fit --max-memory (%.1f MB)",
                 matrix_bytes / 1048576.0, (double)budget / 1048576.0);
        return RAD_SOLVER_HIERARCHICAL;
    }
    if (physical && matrix_bytes > AUTO_DENSE_MEMORY_SHARE * (double)physical) {
        snprintf(reason, size, "the %.1f GB matrix would not fit in half of the memory",
                 matrix_bytes / 1e9);
        return RAD_SOLVER_HIERARCHICAL;
    }
    snprintf(reason, size, "%u patches <= %d: dense matrix", patches, RAD_DENSE_MAX_PATCHES);
    return RAD_SOLVER_JACOBI;
}

/* Rewrites an error about one patch as "SCENE: surface 'NAME' (patch P): what" so that the
 * user learns which of their surfaces is involved. */
static rad_status name_patch(const rad_scene *scene, const rad_mesh *mesh, uint32_t patch,
                             rad_status status, rad_error *error)
{
    if (!error || patch >= mesh->patch_count)
        return status;
    const char *what = error->message;
    const char *prefix = "rad_solve: ";
    if (strncmp(what, prefix, strlen(prefix)) == 0)
        what += strlen(prefix);
    char copy[RAD_ERROR_MESSAGE_MAX];
    snprintf(copy, sizeof(copy), "%s", what);
    return rad_fail(error, status, "%s: surface '%s' (patch %u): %s", scene->source,
                    scene->surfaces[mesh->patches[patch].surface].name, patch, copy);
}

/* A resumed ITERATE checkpoint's matrix in place of computing it (*ff NULL: none). */
static rad_status resumed_matrix(solve_checkpoint *cp, uint32_t n, rad_solver solver,
                                 rad_formfactors **ff, rad_formfactor_report *report,
                                 rad_error *error)
{
    byte_source source;
    *ff = NULL;
    if (!solve_checkpoint_resuming(cp, SOLVE_CHECKPOINT_ITERATE, &source))
        return RAD_OK;
    rad_formfactors *m = rad_alloc_array(1, sizeof(*m));
    float *F = rad_alloc_array((size_t)n * n, sizeof(float));
    iterate_state state;
    if (!m || !F) {
        free(m);
        free(F);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the %u x %u matrix of %s", n,
                        n, cp->resume_path);
    }
    if (!iterate_body_read(cp, n, iterate_vectors(solver), F, report, &state,
                           &source, error)) {
        free(m);
        free(F);
        return error ? error->status : RAD_ERR_PARSE;
    }
    m->n = n;
    m->F = F;
    *ff = m;
    cp->formfactors = *report;
    return RAD_OK;
}

static rad_status solve_dense(const rad_scene *scene, const rad_mesh *mesh, const rad_patch_inputs *inputs,
                              const rad_tracer *occluders, const rad_scene_solve_options *o,
                              rad_solver solver, solve_checkpoint *cp, rad_rgb *B,
                              rad_scene_solve_report *r, rad_error *error)
{
    if (solver == RAD_SOLVER_DIRECT && mesh->patch_count > RAD_DIRECT_MAX_PATCHES)
        return rad_fail(error, RAD_ERR_UNSUPPORTED,
                        "the direct solver is for small scenes: %u patches (limit %d): use a "
                        "larger --patch-size or another solver",
                        mesh->patch_count, RAD_DIRECT_MAX_PATCHES);
    rad_formfactor_options ff_options = {o->quadrature, o->visibility_rays, o->seed,
                                         o->threads,    o->progress,        o->progress_user,
                                         inputs->area};
    rad_formfactors *ff = NULL;
    double t0 = seconds_now();
    rad_status status = RAD_OK;
    if (cp) {
        cp->job.quadrature = o->quadrature;
        status = cp->resume_path ? solve_checkpoint_read(cp, error) : RAD_OK;
        if (status == RAD_OK)
            status = resumed_matrix(cp, mesh->patch_count, solver, &ff, &r->formfactors, error);
        if (status != RAD_OK)
            return status;
        r->resumed = cp->resume_path != NULL;
    }
    if (!ff)
        status = formfactors_compute_checkpointed(mesh, occluders, &ff_options, cp, &ff,
                                                  &r->formfactors, error);
    if (status != RAD_OK)
        return status;
    if (cp && cp->interrupted) { /* the checkpoint holds the rows done */
        r->interrupted = true;
        return RAD_OK;
    }
    if (cp)
        cp->formfactors = r->formfactors;
    rad_formfactors_check_areas(ff, mesh, inputs->area, &r->check);
    double t1 = seconds_now();
    r->seconds_form_factors = t1 - t0;
    rad_system system = rad_system_of(inputs, ff);
    rad_solve_options solve_options = {solver,    o->tolerance, o->max_iterations,
                                       true,      o->threads,   o->progress,
                                       o->progress_user, o->observer, o->observer_user,
                                       o->observe_every};
    status = solve_checkpointed(&system, &solve_options, cp, B, &r->solve, error);
    rad_formfactors_destroy(ff);
    r->seconds_solve = seconds_now() - t1;
    if (status != RAD_OK)
        return name_patch(scene, mesh, r->solve.patch, status, error);
    if (cp && cp->interrupted) { /* the checkpoint holds the iterate */
        r->interrupted = true;
        return RAD_OK;
    }
    if (r->formfactors.rows_trimmed > 0) {
        uint32_t p = r->formfactors.largest_row;
        rad_warn(o->log, o->log_user,
                 "%s: the form factors of %u patches summed above 1 and were scaled back "
                 "(the largest, %.4g, at surface '%s'): sampled visibility next to "
                 "occluders or through a slot; a smaller --patch-size or more "
                 "--visibility-rays bring them closer to 1",
                 scene->source, r->formfactors.rows_trimmed, r->formfactors.largest_row_sum,
                 scene->surfaces[mesh->patches[p].surface].name);
    }
    r->iterations = r->solve.iterations;
    r->residual = r->solve.residual;
    r->converged = r->solve.converged || solver == RAD_SOLVER_DIRECT;
    if (!r->converged)
        rad_warn(o->log, o->log_user,
                 "the %s solver stopped at its iteration limit (%u) with %s %.3g, above the "
                 "tolerance",
                 rad_solver_name(solver), r->solve.iterations,
                 solver == RAD_SOLVER_SHOOT ? "unshot fraction" : "criterion",
                 r->solve.criterion);
    return RAD_OK;
}

static rad_status solve_hierarchy(const rad_scene *scene, const rad_mesh *mesh, const rad_patch_inputs *inputs,
                                  const rad_tracer *occluders,
                                  const rad_scene_solve_options *o, solve_checkpoint *cp,
                                  rad_rgb *B, rad_scene_solve_report *r, rad_error *error)
{
    uint64_t budget = solver_budget(o), link_budget = budget;
    if (budget) {
        /* the budget holds the trees first: at most 2 n - 1 elements over the planes and
         * n - 1 clusters above them, with their values, and the per-patch arrays; within a
         * run's budget (rad_memory_budget_set) also each thread's buffers besides the
         * links (refinement's ray buffers, the final gather's) */
        uint64_t n = mesh->patch_count;
        uint64_t trees = 3 * n * (sizeof(hnode) + 3 * sizeof(rad_rgb) + sizeof(size_t)) +
                         n * (sizeof(rad_rgb) + sizeof(float) + sizeof(uint32_t) + sizeof(double));
        uint64_t threads = o->threads > 0 ? (uint64_t)o->threads
                                          : (uint64_t)omp_get_max_threads();
        bool whole_run = rad_memory_budget() != 0;
        uint64_t need = trees + (whole_run ? threads * HIERARCHY_THREAD_BYTES : 0);
        if (need >= budget) {
            char words[96];
            budget_words(budget, words, sizeof(words));
            return rad_fail(error, RAD_ERR_NOMEM,
                            "--max-memory: the element and cluster trees of %u patches%s need "
                            "up to %.1f MB, more than %s",
                            mesh->patch_count,
                            whole_run ? " and the solver's per-thread buffers" : "",
                            need / 1048576.0, words);
        }
        link_budget = budget - need;
        /* and a pass's per-link decisions and ranking, at most a quarter of the links' */
        if (whole_run)
            link_budget -= link_budget / 4;
    }
    /* standing in for the dense solve on a mesh sized for it: its accuracy (radiosity.h) */
    double threshold = o->refine_threshold;
    if (threshold == 0 && o->solver == RAD_SOLVER_AUTO &&
        mesh->patch_count <= RAD_AUTO_FINE_LINKS_PATCHES)
        threshold = RAD_AUTO_REFINE_THRESHOLD;
    rad_hierarchy_options h = {threshold,            o->visibility_rays, o->tolerance,
                               o->max_iterations,   link_budget,        o->seed,
                               o->threads,          o->stop,            o->progress,
                               o->progress_user,    o->observer,        o->observer_user};
    double t0 = seconds_now();
    r->hierarchy.patch = UINT32_MAX;
    rad_status status = RAD_OK;
    if (cp) {
        cp->job.refine_threshold = threshold;
        cp->job.link_budget = link_budget;
        status = cp->resume_path ? solve_checkpoint_read(cp, error) : RAD_OK;
        if (status != RAD_OK)
            return status;
        r->resumed = cp->resume_path != NULL;
    }
    status = solve_hierarchical_checkpointed(mesh, inputs, occluders, &h, cp, B, &r->hierarchy,
                                             error);
    r->seconds_solve = seconds_now() - t0;
    if (status != RAD_OK)
        return name_patch(scene, mesh, r->hierarchy.patch, status, error);
    const rad_hierarchy_report *hr = &r->hierarchy;
    r->iterations = hr->iterations;
    r->residual = hr->residual;
    r->converged = hr->converged;
    r->interrupted = hr->interrupted;
    if (hr->interrupted && cp && cp->path)
        ; /* the caller tells of the checkpoint */
    else if (hr->interrupted)
        rad_warn(o->log, o->log_user,
                 "interrupted: refinement and gathering stopped after %u passes and %u "
                 "sweeps (residual %.3g); going on with the solution so far",
                 hr->passes, hr->iterations, hr->residual);
    else if (!hr->converged)
        rad_warn(o->log, o->log_user,
                 "the hierarchical solver stopped at its sweep limit (%u) with change %.3g, "
                 "above the tolerance",
                 hr->iterations, hr->change);
    if (hr->memory_capped)
        rad_warn(o->log, o->log_user,
                 "--max-memory: the links reached the budget (%.1f MB of links); refinement "
                 "stopped there, so the answer is coarser than the threshold asks",
                 hr->link_bytes / 1048576.0);
    return RAD_OK;
}

rad_status rad_solve_scene(const rad_scene *scene, const rad_mesh *mesh,
                           const rad_scene_solve_options *options, rad_rgb *B,
                           rad_scene_solve_report *report, rad_error *error)
{
    rad_scene_solve_options o = {0};
    if (options)
        o = *options;
    rad_scene_solve_report r = {0};
    if (!scene || !mesh || !B)
        return rad_fail(error, RAD_ERR_INVALID, "rad_solve_scene: no scene, mesh or B");
    if (mesh->patch_count == 0)
        return rad_fail(error, RAD_ERR_INVALID, "%s: the mesh has no patches", scene->source);
    if ((unsigned)o.solver > RAD_SOLVER_HIERARCHICAL)
        return rad_fail(error, RAD_ERR_INVALID, "rad_solve_scene: unknown solver %d",
                        (int)o.solver);
    double t0 = seconds_now();
    r.patches = mesh->patch_count;
    r.solver_chosen = o.solver == RAD_SOLVER_AUTO;
    /* the choice and the matrix's check see the budget as the steps before the matrix
     * will leave it: those bytes are promised while they look */
    uint64_t before_matrix = rad_memory_budget() ? before_matrix_bytes(scene, mesh, &o) : 0;
    rad_memory_budget_reserve(before_matrix);
    r.solver = rad_solve_scene_choice(mesh, &o, r.reason, sizeof(r.reason));
    double dense_bytes = dense_matrix_bytes(mesh->patch_count, r.solver);
    uint64_t budget = solver_budget(&o);
    rad_memory_budget_unreserve(before_matrix);
    if (budget && r.solver != RAD_SOLVER_HIERARCHICAL && dense_bytes > (double)budget) {
        char words[96], before[96] = "";
        budget_words(budget, words, sizeof(words));
        if (before_matrix)
            snprintf(before, sizeof(before),
                     " after %.1f MB for the patch inputs, the occluders and the threads",
                     before_matrix / 1048576.0);
        return rad_fail(error, RAD_ERR_NOMEM,
                        "--max-memory: the %s solver's matrix for %u patches needs %.1f MB (%s), "
                        "more than %s%s: use a larger --patch-size, the hierarchical solver or "
                        "a larger budget",
                        rad_solver_name(r.solver), mesh->patch_count, dense_bytes / 1048576.0,
                        r.solver == RAD_SOLVER_DIRECT ? "12 n^2 bytes" : "4 n^2 bytes", words,
                        before);
    }
    if (!rad_scene_has_emitter(scene) && scene->light_count == 0)
        rad_warn(o.log, o.log_user,
                 "%s: no surface emits light (no material with non-zero Ke) and no light "
                 "source is given: the result will be black (--emit NAME=R,G,B makes a "
                 "surface a light; --point, --spot, --sun, --sky add sources)",
                 scene->source);

    rad_patch_inputs *built = NULL;
    const rad_patch_inputs *inputs = o.inputs;
    rad_tracer *occluders = NULL;
    rad_status status = RAD_OK;
    if (!inputs) {
        status = rad_patch_inputs_build(scene, mesh, &built, error);
        inputs = built;
        r.seconds_inputs = seconds_now() - t0;
    } else if (inputs->n != mesh->patch_count) {
        status = rad_fail(error, RAD_ERR_INVALID,
                          "rad_solve_scene: the patch inputs are for %u patches, the mesh has "
                          "%u",
                          inputs->n, mesh->patch_count);
    }
    if (status == RAD_OK)
        status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE_FAST, scene, &occluders, error);
    /* checkpoints: the job here, its solver's options there (solve_dense, solve_hierarchy) */
    solve_checkpoint checkpoint = {0}, *cp = NULL;
    if (status == RAD_OK && (o.checkpoint || o.resume)) {
        cp = &checkpoint;
        cp->path = o.checkpoint;
        cp->interval = o.checkpoint_interval > 0 ? o.checkpoint_interval : 0;
        cp->last = rad_clock_seconds();
        cp->stop = o.stop;
        cp->progress = o.progress;
        cp->progress_user = o.progress_user;
        cp->resume_path = o.resume;
        cp->job = (solve_checkpoint_job){0, mesh->patch_count, (uint32_t)r.solver, 0,
                                         o.visibility_rays, o.max_iterations, o.seed,
                                         o.tolerance, 0, 0};
        status = rad_solution_fingerprint(scene, mesh, &cp->job.fingerprint, error);
    }
    if (status == RAD_OK)
        status = r.solver == RAD_SOLVER_HIERARCHICAL
                     ? solve_hierarchy(scene, mesh, inputs, occluders, &o, cp, B, &r, error)
                     : solve_dense(scene, mesh, inputs, occluders, &o, r.solver, cp, B, &r,
                                   error);
    if (cp) {
        r.checkpoints = cp->written;
        r.interrupted = r.interrupted || cp->interrupted;
        solve_checkpoint_resumed(cp);
    }
    rad_tracer_destroy(occluders);
    if (status == RAD_OK && cp && cp->interrupted) /* no solution: the checkpoint has it */
        for (uint32_t i = 0; i < mesh->patch_count; i++)
            B[i] = inputs->source[i];
    /* every value finite and at least the patch's own source term (what comes in is >= 0) */
    for (uint32_t i = 0; status == RAD_OK && i < mesh->patch_count; i++) {
        rad_rgb *b = &B[i];
        const rad_rgb *e = &inputs->source[i];
        if (!(isfinite(b->r) && isfinite(b->g) && isfinite(b->b)))
            status = rad_fail(error, RAD_ERR_INTERNAL,
                              "%s: surface '%s' (patch %u): the %s solution is not finite (a "
                              "bug: please report the scene); nothing was written",
                              scene->source, scene->surfaces[mesh->patches[i].surface].name, i,
                              rad_solver_name(r.solver));
        b->r = fmax(b->r, e->r);
        b->g = fmax(b->g, e->g);
        b->b = fmax(b->b, e->b);
    }
    rad_patch_inputs_destroy(built);
    r.seconds = seconds_now() - t0;
    if (report)
        *report = r;
    return status;
}
