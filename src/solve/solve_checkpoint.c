/*
 * solve_checkpoint.c - the restart file of a long solve (solve_checkpoint.h).
 *
 * The container (core/checkpoint_file.h): the magic "\x89RADSCK\n", format version, the
 * body, its checksum. The body, little-endian: the kind (u32), the job (patches u32,
 * fingerprint u64, solver u32, quadrature u32, visibility rays u32, max iterations u32,
 * seed u64, tolerance f64, refinement threshold f64, link budget u64), then the kind's own
 * state as its writer lays it out (formfactors.c, this file's ITERATE helpers,
 * solve_hierarchical.c).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/bytes.h"
#include "core/checkpoint_file.h"
#include "core/clock.h"
#include "core/error.h"
#include "parallel/ranks.h"
#include "solve/solve_checkpoint.h"

static const uint8_t solve_checkpoint_magic[8] = {0x89, 'R', 'A', 'D', 'S', 'C', 'K', '\n'};

enum {
    SOLVE_CHECKPOINT_VERSION = 2, /* 2: form-factor rows whose folded cells' segments leave
                                     from their own distance behind the input triangles
                                     (rad_patch.behind), not the quad's largest: not mixed
                                     with rows of version 1 */
    JOB_BYTES = 64, /* kind and the job */
};

/* ---- writing and reading values ---- */

static uint8_t *sink_room(byte_sink *sink, size_t bytes)
{
    if (sink->off || sink->failed)
        return NULL;
    if (sink->size + bytes > sink->capacity) {
        size_t capacity = sink->capacity ? sink->capacity : 4096;
        while (capacity < sink->size + bytes)
            capacity *= 2;
        uint8_t *grown = rad_resize_array(sink->bytes, capacity, 1);
        if (!grown) {
            sink->failed = true;
            return NULL;
        }
        sink->bytes = grown;
        sink->capacity = capacity;
    }
    uint8_t *p = sink->bytes + sink->size;
    sink->size += bytes;
    return p;
}

void sink_u32(byte_sink *sink, uint32_t v)
{
    uint8_t *p = sink_room(sink, 4);
    if (p)
        bytes_put_u32(p, v);
}

void sink_u64(byte_sink *sink, uint64_t v)
{
    uint8_t *p = sink_room(sink, 8);
    if (p)
        bytes_put_u64(p, v);
}

void sink_f64(byte_sink *sink, double v)
{
    uint8_t *p = sink_room(sink, 8);
    if (p)
        bytes_put_f64(p, v);
}

void sink_floats(byte_sink *sink, const float *v, size_t count)
{
    uint8_t *p = sink_room(sink, 4 * count);
    for (size_t k = 0; p && k < count; k++)
        bytes_put_f32(p + 4 * k, v[k]);
}

void sink_rgbs(byte_sink *sink, const rad_rgb *v, size_t count)
{
    uint8_t *p = sink_room(sink, 24 * count);
    for (size_t k = 0; p && k < count; k++) {
        bytes_put_f64(p + 24 * k, v[k].r);
        bytes_put_f64(p + 24 * k + 8, v[k].g);
        bytes_put_f64(p + 24 * k + 16, v[k].b);
    }
}

void sink_channels(byte_sink *sink, const double *x0, const double *x1, const double *x2,
                   uint32_t n)
{
    uint8_t *p = sink_room(sink, 24 * (size_t)n);
    for (size_t k = 0; p && k < n; k++) {
        bytes_put_f64(p + 24 * k, x0[k]);
        bytes_put_f64(p + 24 * k + 8, x1[k]);
        bytes_put_f64(p + 24 * k + 16, x2[k]);
    }
}

void sink_bytes(byte_sink *sink, const void *data, size_t size)
{
    uint8_t *p = sink_room(sink, size);
    if (p && size)
        memcpy(p, data, size);
}

void sink_free(byte_sink *sink)
{
    free(sink->bytes);
    sink->bytes = NULL;
    sink->size = sink->capacity = 0;
}

static const uint8_t *source_take(byte_source *source, size_t bytes)
{
    if (source->short_read || (size_t)(source->end - source->p) < bytes) {
        source->short_read = true;
        return NULL;
    }
    const uint8_t *p = source->p;
    source->p += bytes;
    return p;
}

uint32_t source_u32(byte_source *source)
{
    const uint8_t *p = source_take(source, 4);
    return p ? bytes_get_u32(p) : 0;
}

uint64_t source_u64(byte_source *source)
{
    const uint8_t *p = source_take(source, 8);
    return p ? bytes_get_u64(p) : 0;
}

double source_f64(byte_source *source)
{
    const uint8_t *p = source_take(source, 8);
    return p ? bytes_get_f64(p) : 0;
}

void source_floats(byte_source *source, float *v, size_t count)
{
    const uint8_t *p = source_take(source, 4 * count);
    for (size_t k = 0; k < count; k++)
        v[k] = p ? bytes_get_f32(p + 4 * k) : 0;
}

void source_rgbs(byte_source *source, rad_rgb *v, size_t count)
{
    const uint8_t *p = source_take(source, 24 * count);
    for (size_t k = 0; k < count; k++)
        v[k] = p ? (rad_rgb){bytes_get_f64(p + 24 * k), bytes_get_f64(p + 24 * k + 8),
                             bytes_get_f64(p + 24 * k + 16)}
                 : (rad_rgb){0, 0, 0};
}

void source_channels(byte_source *source, double *x0, double *x1, double *x2, uint32_t n)
{
    const uint8_t *p = source_take(source, 24 * (size_t)n);
    for (size_t k = 0; k < n; k++) {
        x0[k] = p ? bytes_get_f64(p + 24 * k) : 0;
        x1[k] = p ? bytes_get_f64(p + 24 * k + 8) : 0;
        x2[k] = p ? bytes_get_f64(p + 24 * k + 16) : 0;
    }
}

size_t source_left(const byte_source *source) { return (size_t)(source->end - source->p); }

/* ---- the file ---- */

static void put_job(uint8_t *p, uint32_t kind, const solve_checkpoint_job *job)
{
    bytes_put_u32(p, kind);
    bytes_put_u32(p + 4, job->patches);
    bytes_put_u64(p + 8, job->fingerprint);
    bytes_put_u32(p + 16, job->solver);
    bytes_put_u32(p + 20, job->quadrature);
    bytes_put_u32(p + 24, job->visibility_rays);
    bytes_put_u32(p + 28, job->max_iterations);
    bytes_put_u64(p + 32, job->seed);
    bytes_put_f64(p + 40, job->tolerance);
    bytes_put_f64(p + 48, job->refine_threshold);
    bytes_put_u64(p + 56, job->link_budget);
}

static solve_checkpoint_job get_job(const uint8_t *p)
{
    solve_checkpoint_job job;
    job.patches = bytes_get_u32(p + 4);
    job.fingerprint = bytes_get_u64(p + 8);
    job.solver = bytes_get_u32(p + 16);
    job.quadrature = bytes_get_u32(p + 20);
    job.visibility_rays = bytes_get_u32(p + 24);
    job.max_iterations = bytes_get_u32(p + 28);
    job.seed = bytes_get_u64(p + 32);
    job.tolerance = bytes_get_f64(p + 40);
    job.refine_threshold = bytes_get_f64(p + 48);
    job.link_budget = bytes_get_u64(p + 56);
    return job;
}

static const char *solver_word(uint32_t solver)
{
    return solver <= RAD_SOLVER_HIERARCHICAL ? rad_solver_name((rad_solver)solver) : "unknown";
}

/* The file's job against this run's: RAD_ERR_INVALID naming the file and what differs. */
static rad_status match_job(const char *path, const solve_checkpoint_job *file,
                            const solve_checkpoint_job *run, rad_error *error)
{
    if (file->patches != run->patches || file->fingerprint != run->fingerprint)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: a checkpoint of another scene or mesh (%u patches, fingerprint "
                        "%016llx; this run: %u, %016llx)",
                        path, file->patches, (unsigned long long)file->fingerprint,
                        run->patches, (unsigned long long)run->fingerprint);
    if (file->solver != run->solver)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: a checkpoint of the %s solver; this run's is %s", path,
                        solver_word(file->solver), solver_word(run->solver));
    /* the options that differ, each with this run's value */
    char differ[512] = "";
    size_t used = 0;
#define DIFFER(test, format, ...)                                                           \
    if ((test) && used < sizeof(differ))                                                   \
    used += (size_t)snprintf(differ + used, sizeof(differ) - used, "%s" format,            \
                             used ? ", " : "", __VA_ARGS__)
    DIFFER(file->quadrature != run->quadrature, "--quadrature %u (this run: %u)",
           file->quadrature, run->quadrature);
    DIFFER(file->visibility_rays != run->visibility_rays, "--visibility-rays %u (this run: %u)",
           file->visibility_rays, run->visibility_rays);
    DIFFER(file->max_iterations != run->max_iterations, "--max-iterations %u (this run: %u)",
           file->max_iterations, run->max_iterations);
    DIFFER(file->seed != run->seed, "--seed %llu (this run: %llu)",
           (unsigned long long)file->seed, (unsigned long long)run->seed);
    DIFFER(file->tolerance != run->tolerance, "--tolerance %.17g (this run: %.17g)",
           file->tolerance, run->tolerance);
    DIFFER(file->refine_threshold != run->refine_threshold,
           "--refine-threshold %.17g (this run: %.17g)", file->refine_threshold,
           run->refine_threshold);
    DIFFER(file->link_budget != run->link_budget,
           "a link budget of %llu bytes (this run: %llu; --max-memory, --threads)",
           (unsigned long long)file->link_budget, (unsigned long long)run->link_budget);
#undef DIFFER
    if (used)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: a checkpoint made with other options: %s (0: the default)", path,
                        differ);
    return RAD_OK;
}

/* Rank 0: the file's body after the job, checked against this run's job. */
static rad_status read_here(solve_checkpoint *cp, rad_error *error)
{
    uint8_t *bytes = NULL;
    size_t size = 0;
    rad_status status =
        checkpoint_file_read(cp->resume_path, solve_checkpoint_magic, SOLVE_CHECKPOINT_VERSION,
                             "solve checkpoint", &bytes, &size, error);
    if (status != RAD_OK)
        return status;
    size_t body = size - CHECKPOINT_FILE_HEAD - CHECKPOINT_FILE_TAIL;
    const uint8_t *p = bytes + CHECKPOINT_FILE_HEAD;
    uint32_t kind = body >= JOB_BYTES ? bytes_get_u32(p) : 0;
    if (body < JOB_BYTES)
        status = rad_fail(error, RAD_ERR_PARSE, "%s: truncated checkpoint (%zu bytes)",
                          cp->resume_path, size);
    else if (kind < SOLVE_CHECKPOINT_FORMFACTORS || kind > SOLVE_CHECKPOINT_HIERARCHY)
        status = rad_fail(error, RAD_ERR_PARSE, "%s: unknown kind of checkpoint (%u)",
                          cp->resume_path, kind);
    else {
        solve_checkpoint_job job = get_job(p);
        status = match_job(cp->resume_path, &job, &cp->job, error);
        bool hierarchical = job.solver == RAD_SOLVER_HIERARCHICAL;
        if (status == RAD_OK && hierarchical != (kind == SOLVE_CHECKPOINT_HIERARCHY))
            status = rad_fail(error, RAD_ERR_PARSE,
                              "%s: a state of kind %u, which the %s solver does not write",
                              cp->resume_path, kind, solver_word(job.solver));
    }
    if (status == RAD_OK) {
        cp->resumed_size = body - JOB_BYTES;
        cp->resumed = rad_alloc_array(cp->resumed_size ? cp->resumed_size : 1, 1);
        if (!cp->resumed)
            status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory (%zu bytes)",
                              cp->resume_path, size);
        else {
            memcpy(cp->resumed, p + JOB_BYTES, cp->resumed_size);
            cp->resumed_kind = kind;
        }
    }
    free(bytes);
    return status;
}

rad_status solve_checkpoint_read(solve_checkpoint *cp, rad_error *error)
{
    rad_status status = ranks_rank() == 0 ? read_here(cp, error) : RAD_OK;
    status = ranks_share_status(status, error);
    if (status != RAD_OK || ranks_count() == 1)
        return status;
    uint64_t head[2] = {cp->resumed_kind, cp->resumed_size};
    ranks_broadcast(head, sizeof(head));
    if (ranks_rank() != 0) {
        cp->resumed_kind = (uint32_t)head[0];
        cp->resumed_size = (size_t)head[1];
        cp->resumed = rad_alloc_array(cp->resumed_size ? cp->resumed_size : 1, 1);
    }
    status = ranks_agree(cp->resumed ? RAD_OK
                                     : rad_fail(error, RAD_ERR_NOMEM,
                                                "%s: out of memory (%zu bytes)",
                                                cp->resume_path, cp->resumed_size),
                         "reading the checkpoint", error);
    if (status == RAD_OK)
        ranks_broadcast(cp->resumed, cp->resumed_size);
    return status;
}

bool solve_checkpoint_resuming(const solve_checkpoint *cp, uint32_t kind, byte_source *source)
{
    if (!cp || cp->resumed_kind != kind || !cp->resumed)
        return false;
    *source = (byte_source){cp->resumed, cp->resumed + cp->resumed_size, false};
    return true;
}

void solve_checkpoint_resumed(solve_checkpoint *cp)
{
    free(cp->resumed);
    cp->resumed = NULL;
    cp->resumed_size = 0;
    cp->resumed_kind = 0;
}

bool solve_checkpoint_stop_raised(const solve_checkpoint *cp)
{
    if (!cp || !cp->path)
        return false;
    bool stop_here = cp->stop && *cp->stop;
    if (ranks_count() > 1)
        stop_here = ranks_failures(stop_here) > 0;
    return stop_here;
}

bool solve_checkpoint_due(solve_checkpoint *cp, bool *stop)
{
    *stop = false;
    if (!cp || !cp->path)
        return false;
    bool stop_here = solve_checkpoint_stop_raised(cp);
    int write = stop_here || rad_clock_seconds() - cp->last >= cp->interval;
    if (ranks_count() > 1)
        ranks_broadcast(&write, sizeof(write));
    *stop = stop_here;
    return write != 0;
}

rad_status solve_checkpoint_write(solve_checkpoint *cp, uint32_t kind, const byte_sink *body,
                                  double fraction, rad_error *error)
{
    rad_status status = RAD_OK;
    if (ranks_rank() == 0) {
        size_t size = CHECKPOINT_FILE_HEAD + JOB_BYTES + body->size + CHECKPOINT_FILE_TAIL;
        uint8_t *bytes = body->failed ? NULL : rad_alloc_array(size, 1);
        if (!bytes)
            status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for a checkpoint",
                              cp->path);
        else {
            put_job(bytes + CHECKPOINT_FILE_HEAD, kind, &cp->job);
            if (body->size)
                memcpy(bytes + CHECKPOINT_FILE_HEAD + JOB_BYTES, body->bytes, body->size);
            status = checkpoint_file_write(cp->path, solve_checkpoint_magic,
                                           SOLVE_CHECKPOINT_VERSION, bytes, size, error);
        }
        free(bytes);
    }
    status = ranks_share_status(status, error);
    if (status != RAD_OK)
        return status;
    cp->last = rad_clock_seconds();
    cp->written++;
    if (ranks_rank() == 0 && cp->progress)
        cp->progress(cp->progress_user, "checkpoint", fraction);
    return RAD_OK;
}

/* ---- the ITERATE kind ---- */

void iterate_body_begin(const solve_checkpoint *cp, const rad_system *system,
                        const iterate_state *state, byte_sink *body)
{
    const rad_formfactor_report *r = &cp->formfactors;
    body->off = ranks_rank() != 0;
    sink_u32(body, system->n);
    sink_floats(body, system->F, (size_t)system->n * system->n);
    const uint64_t counts[6] = {r->pairs,       r->pairs_facing, r->pairs_refined,
                                r->pairs_clear, r->pairs_exact,  r->rays};
    for (int k = 0; k < 6; k++)
        sink_u64(body, counts[k]);
    sink_u32(body, r->rows_trimmed);
    sink_u32(body, r->largest_row);
    sink_f64(body, r->largest_row_sum);
    sink_u32(body, state->iterations);
    sink_f64(body, state->criterion);
    sink_f64(body, state->smallest);
    sink_u32(body, state->last_shooter);
}

bool iterate_resume_sweeps(solve_checkpoint *cp, uint32_t n, double *x0, double *x1,
                           double *x2, uint32_t *sweeps, double *criterion, double *smallest,
                           rad_error *error)
{
    byte_source source;
    iterate_state state;
    if (!solve_checkpoint_resuming(cp, SOLVE_CHECKPOINT_ITERATE, &source))
        return true;
    if (!iterate_body_read(cp, n, 1, NULL, NULL, &state, &source, error))
        return false;
    source_channels(&source, x0, x1, x2, n);
    solve_checkpoint_resumed(cp);
    *sweeps = state.iterations;
    *criterion = state.criterion;
    *smallest = state.smallest;
    return true;
}

bool iterate_body_read(const solve_checkpoint *cp, uint32_t n, uint32_t vectors, float *F,
                       rad_formfactor_report *formfactors, iterate_state *state,
                       byte_source *source, rad_error *error)
{
    const char *path = cp->resume_path;
    uint64_t matrix = (uint64_t)n * n;
    size_t expected = 4 + 4 * matrix + 6 * 8 + 4 + 4 + 8 + 4 + 8 + 8 + 4 +
                      (size_t)vectors * 24 * n;
    if (source_left(source) != expected || source_u32(source) != n) {
        rad_fail(error, RAD_ERR_PARSE,
                 "%s: %zu bytes of solver state, not the %zu of %u patches and %u vectors",
                 path, source_left(source), expected, n, vectors);
        return false;
    }
    if (F) {
        source_floats(source, F, matrix);
        for (uint64_t k = 0; k < matrix; k++)
            if (!(F[k] >= 0 && F[k] <= 1)) {
                rad_fail(error, RAD_ERR_PARSE, "%s: form factor %llu is not in [0, 1]", path,
                         (unsigned long long)k);
                return false;
            }
    } else {
        source->p += 4 * matrix;
    }
    rad_formfactor_report r = {0};
    r.pairs = source_u64(source);
    r.pairs_facing = source_u64(source);
    r.pairs_refined = source_u64(source);
    r.pairs_clear = source_u64(source);
    r.pairs_exact = source_u64(source);
    r.rays = source_u64(source);
    r.rows_trimmed = source_u32(source);
    r.largest_row = source_u32(source);
    r.largest_row_sum = source_f64(source);
    r.rank_rows = n;
    if (formfactors)
        *formfactors = r;
    state->iterations = source_u32(source);
    state->criterion = source_f64(source);
    state->smallest = source_f64(source);
    state->last_shooter = source_u32(source);
    const uint8_t *vectors_at = source->p;
    for (size_t k = 0; k < (size_t)vectors * 3 * n; k++) {
        double v = bytes_get_f64(vectors_at + 8 * k);
        if (!(v >= 0 && isfinite(v))) {
            rad_fail(error, RAD_ERR_PARSE, "%s: radiosity %zu is not a finite value >= 0",
                     path, k);
            return false;
        }
    }
    return true;
}

bool iterate_step(solve_checkpoint *cp, const rad_system *system, const iterate_state *state,
                  void (*put)(const void *user, byte_sink *body), const void *user,
                  rad_status *status, rad_error *error)
{
    bool stop;
    if (!solve_checkpoint_due(cp, &stop))
        return false;
    byte_sink body = {0};
    iterate_body_begin(cp, system, state, &body);
    put(user, &body);
    *status = solve_checkpoint_write(cp, SOLVE_CHECKPOINT_ITERATE, &body, 1, error);
    sink_free(&body);
    if (*status != RAD_OK)
        return true;
    cp->interrupted = stop;
    return stop;
}

bool iterate_stop(solve_checkpoint *cp, const rad_system *system, const iterate_state *state,
                  void (*put)(const void *user, byte_sink *body), const void *user,
                  rad_status *status, rad_error *error)
{
    if (!solve_checkpoint_stop_raised(cp))
        return false;
    byte_sink body = {0};
    iterate_body_begin(cp, system, state, &body);
    if (put)
        put(user, &body);
    *status = solve_checkpoint_write(cp, SOLVE_CHECKPOINT_ITERATE, &body, 1, error);
    sink_free(&body);
    cp->interrupted = *status == RAD_OK;
    return true;
}
