/*
 * formfactors.c - the dense patch-to-patch form-factor matrix, and its invariant checks.
 *
 * A sink for the pair engine: each symmetric transfer G_ij becomes F_ij = G / A_i and
 * F_ji = G / A_j, so reciprocity holds by construction. Each pair is written by one thread
 * and to two distinct cells, so no locking is needed.
 *
 * Over several MPI ranks (parallel/ranks.h) the rows i (each with its pairs j > i) are
 * shared by estimated cost, their pair count n - 1 - i; each rank fills the cells of its
 * pairs and the ranks sum their matrices, every cell being non-zero on one rank at most, so
 * every rank ends with the whole matrix, bitwise the serial one (a pair's value depends on
 * the pair and the seed only). Memory per rank is therefore not divided.
 *
 * With a checkpoint (solve_checkpoint.h; formfactors_compute_checkpointed) each rank's rows
 * go in CHECKPOINT_ROUNDS rounds of equal cost, and between two the ranks may write one:
 * the rows done so far (row i: its F_ij and F_ji for j > i) gathered at rank 0. A resumed
 * run puts the checkpoint's rows in rank 0's matrix and shares only the others, so the
 * matrix is bitwise the uninterrupted run's.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/memory.h"
#include "parallel/partition.h"
#include "parallel/ranks.h"
#include "solve/solve_checkpoint.h"

/* The dense matrix may take at most this share of the machine's physical memory. */
#define MATRIX_MEMORY_SHARE 0.75
#include "patch_formfactors/pair_engine.h"

typedef struct dense_sink {
    float *F;
    const rad_patch *patches;
    size_t n;
    const double *area; /* NULL: the patches' */
} dense_sink;

static void store_pair(void *data, int thread, uint32_t i, uint32_t j, double G)
{
    (void)thread;
    dense_sink *sink = data;
    double area_i = sink->area ? sink->area[i] : sink->patches[i].area;
    double area_j = sink->area ? sink->area[j] : sink->patches[j].area;
    sink->F[i * sink->n + j] = (float)(G / area_i);
    sink->F[j * sink->n + i] = (float)(G / area_j);
}

/* Scales rows summing above 1 back to 1: F_ij and F_ji both by min(s_i, s_j) with
 * s_i = min(1, 1 / row_i), so reciprocity holds and no row exceeds 1 afterwards. */
static rad_status trim_rows(float *F, size_t n, rad_formfactor_report *report)
{
    double *scale = rad_alloc_array(n, sizeof(*scale));
    if (!scale)
        return RAD_ERR_NOMEM;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        double row = 0;
        for (size_t j = 0; j < n; j++)
            row += F[i * n + j];
        scale[i] = row;
    }
    double largest = 0;
    size_t largest_row = 0, trimmed = 0;
    for (size_t i = 0; i < n; i++) {
        double row = scale[i];
        if (row > largest) {
            largest = row;
            largest_row = i;
        }
        bool over = row > 1 + RAD_ROW_SUM_SLACK;
        scale[i] = over ? 1 / row : 1;
        trimmed += over;
    }
    if (trimmed) {
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < n; j++) {
                double s = scale[i] < scale[j] ? scale[i] : scale[j];
                if (s < 1)
                    F[i * n + j] = (float)(F[i * n + j] * s);
            }
    }
    free(scale);
    report->rows_trimmed = (uint32_t)trimmed;
    report->largest_row_sum = largest;
    report->largest_row = (uint32_t)largest_row;
    return RAD_OK;
}

/* Over several ranks: *rows = this rank's rows (rows[i] = 1), shared by estimated cost;
 * NULL for one rank. Collective. */
static rad_status share_rows(size_t n, uint8_t **rows, rad_error *error)
{
    *rows = NULL;
    if (ranks_count() == 1)
        return RAD_OK;
    double *cost = rad_alloc_array(n, sizeof(*cost));
    uint32_t *owner = rad_alloc_array(n, sizeof(*owner));
    *rows = rad_alloc_array(n, 1);
    rad_status status = cost && owner && *rows ? RAD_OK : RAD_ERR_NOMEM;
    for (size_t i = 0; status == RAD_OK && i < n; i++)
        cost[i] = (double)(n - 1 - i) + 1; /* its pairs, and the row itself */
    if (status == RAD_OK)
        status = partition_by_cost(cost, (uint32_t)n, ranks_count(), owner, error);
    for (size_t i = 0; status == RAD_OK && i < n; i++)
        (*rows)[i] = owner[i] == (uint32_t)ranks_rank();
    free(cost);
    free(owner);
    if (status != RAD_OK)
        rad_fail(error, RAD_ERR_NOMEM, "out of memory sharing %zu rows over %d ranks", n,
                 ranks_count());
    return ranks_agree(status, "form factors", error);
}

/* Over several ranks: every rank gets the whole matrix (the sum of the ranks' cells) and
 * the report's counts summed; report->rank_rows is this rank's share. Collective. */
static rad_status gather_matrix(float *F, size_t n, const uint8_t *rows, rad_status status,
                                rad_formfactor_report *report, rad_error *error)
{
    status = ranks_agree(status, "form factors", error);
    if (status != RAD_OK)
        return status;
    ranks_sum_floats(F, (uint64_t)n * n);
    uint64_t counts[5] = {report->pairs_facing, report->pairs_refined, report->pairs_clear,
                          report->pairs_exact, report->rays};
    ranks_sum(counts, 5);
    report->pairs_facing = counts[0];
    report->pairs_refined = counts[1];
    report->pairs_clear = counts[2];
    report->pairs_exact = counts[3];
    report->rays = counts[4];
    report->rank_rows = 0;
    for (size_t i = 0; i < n; i++)
        report->rank_rows += rows[i];
    return RAD_OK;
}

/* ---- checkpoints between rounds of rows ---- */

/* Rounds of rows between which a checkpoint may be written: each rank's rows in this many
 * slices of equal pair count. */
#define CHECKPOINT_ROUNDS 64u

typedef struct row_checkpoints {
    solve_checkpoint *cp;
    const float *F;
    size_t n;
    const uint32_t *order;   /* this rank's rows, in rounds */
    const uint32_t *end;     /* end of each round in order[] */
    const uint8_t *resumed;  /* rank 0: rows from the resumed checkpoint, in F already */
    uint32_t resumed_rows;   /* how many (every rank) */
    rad_status status;       /* a checkpoint could not be written */
    rad_error error;
} row_checkpoints;

/* Puts row i of the FORMFACTORS kind: i, then F_ij and F_ji for j > i. */
static void sink_row(byte_sink *sink, const float *F, size_t n, uint32_t i)
{
    sink_u32(sink, i);
    for (size_t j = (size_t)i + 1; j < n; j++)
        sink_floats(sink, &F[i * n + j], 1);
    for (size_t j = (size_t)i + 1; j < n; j++)
        sink_floats(sink, &F[j * n + i], 1);
}

/* Collective: rank 0's body of every rank's rows done (after `rounds` rounds). */
static rad_status rows_body(row_checkpoints *c, uint32_t rounds, byte_sink *body,
                            uint32_t *count, rad_error *error)
{
    byte_sink mine = {0};
    uint32_t done = c->end[rounds - 1];
    for (uint32_t k = 0; k < done; k++)
        sink_row(&mine, c->F, c->n, c->order[k]);
    for (uint32_t i = 0; c->resumed && i < c->n; i++)
        if (c->resumed[i])
            sink_row(&mine, c->F, c->n, i);
    uint64_t rows = done + (c->resumed ? c->resumed_rows : 0);
    ranks_sum(&rows, 1);
    *count = (uint32_t)rows;
    rad_status status = mine.failed ? rad_fail(error, RAD_ERR_NOMEM,
                                                "out of memory for a checkpoint's rows")
                                    : RAD_OK;
    status = ranks_agree(status, "writing a checkpoint", error);
    if (status != RAD_OK) {
        sink_free(&mine);
        return status;
    }
    body->off = ranks_rank() != 0;
    sink_u32(body, (uint32_t)c->n);
    sink_u32(body, *count);
    if (ranks_count() == 1) {
        sink_bytes(body, mine.bytes, mine.size);
        sink_free(&mine);
        return RAD_OK;
    }
    void *gathered = NULL;
    uint64_t *sizes = rad_alloc_array((size_t)ranks_count(), sizeof(uint64_t));
    status = ranks_agree(sizes ? RAD_OK : rad_fail(error, RAD_ERR_NOMEM, "out of memory"),
                         "writing a checkpoint", error);
    if (status == RAD_OK)
        status = ranks_gather(mine.bytes, mine.size, &gathered, sizes, error);
    sink_free(&mine);
    if (status == RAD_OK && ranks_rank() == 0) {
        uint64_t total = 0;
        for (int r = 0; r < ranks_count(); r++)
            total += sizes[r];
        sink_bytes(body, gathered, (size_t)total);
    }
    free(gathered);
    free(sizes);
    return status;
}

/* After round r: writes a checkpoint when one is due; true to stop the rows. Collective:
 * over ranks, a rank that failed before its rows (`failed`, out of memory: it calls this
 * once) stops every rank here. */
static bool after_round(void *user, uint32_t round, bool failed)
{
    row_checkpoints *c = user;
    if (ranks_count() > 1 && ranks_failures(failed) > 0) {
        if (!failed)
            c->status =
                rad_fail(&c->error, RAD_ERR_INVALID, "form factors: another rank failed");
        return true;
    }
    if (failed)
        return true;
    if (round + 1 >= CHECKPOINT_ROUNDS)
        return false; /* the rows are done: the solver's first step checkpoints next */
    bool stop;
    if (!solve_checkpoint_due(c->cp, &stop))
        return false;
    byte_sink body = {0};
    uint32_t count = 0;
    rad_status status = rows_body(c, round + 1, &body, &count, &c->error);
    if (status == RAD_OK)
        status = solve_checkpoint_write(c->cp, SOLVE_CHECKPOINT_FORMFACTORS, &body,
                                        c->n ? (double)count / c->n : 1, &c->error);
    sink_free(&body);
    if (status != RAD_OK) {
        c->status = status;
        return true;
    }
    if (stop)
        c->cp->interrupted = true;
    return stop;
}

/* The rows of a FORMFACTORS checkpoint being resumed: done[i] for each (every rank), their
 * values in F on rank 0 only (the ranks' matrices are summed). */
static rad_status resume_rows(solve_checkpoint *cp, float *F, size_t n, uint8_t *done,
                              uint32_t *count, rad_error *error)
{
    byte_source src;
    *count = 0;
    if (!solve_checkpoint_resuming(cp, SOLVE_CHECKPOINT_FORMFACTORS, &src))
        return RAD_OK;
    const char *path = cp->resume_path;
    bool here = ranks_rank() == 0;
    uint32_t size = source_u32(&src), rows = source_u32(&src);
    if (size != n || rows > n)
        return rad_fail(error, RAD_ERR_PARSE, "%s: rows of %u patches (%u of them), not %zu",
                        path, size, rows, n);
    for (uint32_t r = 0; r < rows; r++) {
        uint32_t i = source_u32(&src);
        if (src.short_read || i >= n || done[i])
            return rad_fail(error, RAD_ERR_PARSE, "%s: row %u: %s", path, i,
                            src.short_read ? "truncated" : "repeated or beyond the patches");
        if (source_left(&src) < 8 * (n - 1 - (size_t)i))
            return rad_fail(error, RAD_ERR_PARSE, "%s: row %u: truncated", path, i);
        done[i] = 1;
        for (int half = 0; half < 2; half++)
            for (size_t j = (size_t)i + 1; j < n; j++) {
                float f;
                source_floats(&src, &f, 1);
                if (!(f >= 0 && isfinite(f)))
                    return rad_fail(error, RAD_ERR_PARSE,
                                    "%s: row %u: a form factor that is not finite and >= 0",
                                    path, i);
                if (here)
                    F[half ? j * n + i : i * n + j] = f;
            }
    }
    if (source_left(&src))
        return rad_fail(error, RAD_ERR_PARSE, "%s: %zu unexpected bytes after the rows", path,
                        source_left(&src));
    *count = rows;
    return RAD_OK;
}

/* This rank's rows of those not done, in rounds of equal cost (pairs): order[] and
 * end[CHECKPOINT_ROUNDS]; *mine[i] = 1 for each. Collective. */
static rad_status plan_rounds(size_t n, const uint8_t *done, uint32_t **order, uint32_t *end,
                              uint8_t **mine, rad_error *error)
{
    double *cost = rad_alloc_array(n, sizeof(*cost));
    uint32_t *owner = rad_alloc_array(n, sizeof(*owner));
    *order = rad_alloc_array(n ? n : 1, sizeof(**order));
    *mine = rad_alloc_array(n, 1);
    rad_status status = cost && owner && *order && *mine ? RAD_OK : RAD_ERR_NOMEM;
    for (size_t i = 0; status == RAD_OK && i < n; i++)
        cost[i] = done[i] ? 0 : (double)(n - 1 - i) + 1;
    if (status == RAD_OK && ranks_count() > 1)
        status = partition_by_cost(cost, (uint32_t)n, ranks_count(), owner, error);
    double total = 0;
    uint32_t count = 0;
    for (size_t i = 0; status == RAD_OK && i < n; i++) {
        (*mine)[i] = !done[i] && (ranks_count() == 1 || owner[i] == (uint32_t)ranks_rank());
        if ((*mine)[i]) {
            (*order)[count++] = (uint32_t)i;
            total += cost[i];
        }
    }
    /* round r ends at the first row whose cumulative cost reaches (r + 1) / ROUNDS */
    double sum = 0;
    uint32_t k = 0;
    for (uint32_t r = 0; status == RAD_OK && r < CHECKPOINT_ROUNDS; r++) {
        double limit = total * (r + 1) / CHECKPOINT_ROUNDS;
        while (k < count && (sum < limit || r + 1 == CHECKPOINT_ROUNDS))
            sum += cost[(*order)[k++]];
        end[r] = k;
    }
    free(cost);
    free(owner);
    if (status != RAD_OK)
        rad_fail(error, RAD_ERR_NOMEM, "out of memory sharing %zu rows", n);
    return ranks_agree(status, "form factors", error);
}

/* The rows with checkpoints: after resume_rows, this rank's others in rounds. Sets *mine
 * (this rank's rows, for gather_matrix). */
static rad_status rows_in_rounds(const rad_mesh *mesh, const rad_tracer *occluders,
                                 const rad_formfactor_options *options, solve_checkpoint *cp,
                                 dense_sink *sink, uint8_t **mine,
                                 rad_formfactor_report *report, rad_error *error)
{
    size_t n = sink->n;
    uint8_t *done = rad_alloc_array(n, 1);
    uint32_t *order = NULL, end[CHECKPOINT_ROUNDS], resumed = 0;
    rad_status status = done ? RAD_OK : rad_fail(error, RAD_ERR_NOMEM, "out of memory");
    if (status == RAD_OK)
        status = resume_rows(cp, sink->F, n, done, &resumed, error);
    status = ranks_agree(status, "reading the checkpoint", error);
    if (status == RAD_OK) {
        solve_checkpoint_resumed(cp);
        status = plan_rounds(n, done, &order, end, mine, error);
    }
    row_checkpoints c = {cp,     sink->F, n, order, end, ranks_rank() == 0 ? done : NULL,
                         resumed, RAD_OK,  {0}};
    pair_rounds rounds = {order, end, CHECKPOINT_ROUNDS, after_round, &c, 0};
    if (status == RAD_OK)
        status = pair_engine_run_rounds(mesh, occluders, options, &rounds, store_pair, sink,
                                        report, error);
    if (status == RAD_OK && c.status != RAD_OK) {
        status = c.status;
        if (error)
            *error = c.error;
    }
    if (status == RAD_OK && ranks_rank() == 0)
        for (size_t i = 0; i < n; i++)
            (*mine)[i] |= done[i]; /* rank 0 holds the resumed rows */
    free(done);
    free(order);
    return status;
}

rad_status rad_formfactors_compute(const rad_mesh *mesh, const rad_tracer *occluders,
                                   const rad_formfactor_options *options,
                                   rad_formfactors **out, rad_formfactor_report *report,
                                   rad_error *error)
{
    return formfactors_compute_checkpointed(mesh, occluders, options, NULL, out, report,
                                            error);
}

rad_status formfactors_compute_checkpointed(const rad_mesh *mesh, const rad_tracer *occluders,
                                            const rad_formfactor_options *options,
                                            solve_checkpoint *cp, rad_formfactors **out,
                                            rad_formfactor_report *report, rad_error *error)
{
    *out = NULL;
    size_t n = mesh->patch_count;
    if (n == 0)
        return rad_fail(error, RAD_ERR_INVALID, "the mesh has no patches");
    if (n > SIZE_MAX / n)
        return rad_fail(error, RAD_ERR_NOMEM, "%zu patches: the matrix size overflows", n);
    /* calloc may succeed lazily and the kernel kill the process later: refuse up front */
    uint64_t physical = rad_physical_memory_bytes();
    double bytes = (double)n * n * sizeof(float);
    rad_formfactors *result = NULL;
    float *F = NULL;
    rad_status status = RAD_OK;
    if (physical && bytes > MATRIX_MEMORY_SHARE * (double)physical) {
        status = rad_fail(error, RAD_ERR_NOMEM,
                          "%zu patches need a %.1f GB form-factor matrix and this machine has "
                          "%.1f GB: use a larger --patch-size",
                          n, bytes / 1e9, (double)physical / 1e9);
    } else {
        result = rad_alloc_array(1, sizeof(*result));
        F = rad_alloc_array(n * n, sizeof(*F));
        if (!result || !F)
            status = rad_fail(error, RAD_ERR_NOMEM,
                              "out of memory for the %zu x %zu form-factor matrix (%.1f GB): "
                              "use a larger --patch-size",
                              n, n, (double)n * n * sizeof(float) / 1e9);
    }
    status = ranks_agree(status, "form factors", error); /* every rank, or none, goes on */
    if (status != RAD_OK) {
        free(result);
        free(F);
        return status;
    }
    rad_advise_huge_pages(F, n * n * sizeof(*F));
    dense_sink sink = {F, mesh->patches, n, options ? options->area : NULL};
    rad_formfactor_report local;
    if (!report)
        report = &local;
    uint8_t *rows = NULL;
    double start = rad_clock_seconds();
    if (cp) {
        status = rows_in_rounds(mesh, occluders, options, cp, &sink, &rows, report, error);
        if (status == RAD_OK && cp->interrupted) { /* the checkpoint holds the rows done */
            free(rows);
            free(F);
            free(result);
            return RAD_OK;
        }
        if (status == RAD_OK && ranks_count() == 1) {
            free(rows);
            rows = NULL;
        }
    } else {
        status = share_rows(n, &rows, error);
        if (status == RAD_OK)
            status = pair_engine_run(mesh, occluders, options, rows, store_pair, &sink,
                                     report, error);
    }
    double rank_seconds = rad_clock_seconds() - start;
    if (rows)
        status = gather_matrix(F, n, rows, status, report, error);
    else if (status == RAD_OK)
        report->rank_rows = (uint32_t)n;
    report->rank_seconds = rank_seconds;
    if (status == RAD_OK && trim_rows(F, n, report) != RAD_OK)
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the row sums of %zu patches",
                          n);
    if (rows)
        status = ranks_agree(status, "form factors", error);
    free(rows);
    if (status != RAD_OK) {
        free(F);
        free(result);
        return status;
    }
    result->area = rad_alloc_array(n, sizeof(*result->area));
    if (!result->area) {
        free(F);
        free(result);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for %zu patches' areas", n);
    }
    for (size_t i = 0; i < n; i++)
        result->area[i] = options && options->area ? options->area[i] : mesh->patches[i].area;
    result->n = (uint32_t)n;
    result->F = F;
    *out = result;
    return RAD_OK;
}

void rad_formfactors_destroy(rad_formfactors *formfactors)
{
    if (!formfactors)
        return;
    free(formfactors->F);
    free(formfactors->area);
    free(formfactors);
}

/* Pairs are compared tile by tile so that both F_ij and F_ji are read from cache. */
#define CHECK_TILE 64u

void rad_formfactors_check(const rad_formfactors *ff, const rad_mesh *mesh,
                           rad_formfactor_check *check)
{
    rad_formfactors_check_areas(ff, mesh, ff->area, check);
}

void rad_formfactors_check_areas(const rad_formfactors *ff, const rad_mesh *mesh,
                                 const double *area, rad_formfactor_check *check)
{
    size_t n = ff->n;
    const float *F = ff->F;
    double reciprocity = 0, largest_row = 0, closure = 0, largest = 0;
    uint32_t empty = 0;
    long long tiles = (long long)((n + CHECK_TILE - 1) / CHECK_TILE);
#pragma omp parallel for schedule(dynamic, 1) reduction(max : reciprocity)
    for (long long ti = 0; ti < tiles; ti++) {
        size_t i0 = (size_t)ti * CHECK_TILE, i1 = i0 + CHECK_TILE < n ? i0 + CHECK_TILE : n;
        for (size_t j0 = i0; j0 < n; j0 += CHECK_TILE) {
            size_t j1 = j0 + CHECK_TILE < n ? j0 + CHECK_TILE : n;
            for (size_t i = i0; i < i1; i++)
                for (size_t j = j0 > i + 1 ? j0 : i + 1; j < j1; j++) {
                    double fij = F[i * n + j], fji = F[j * n + i];
                    if (fmax(fij, fji) <= 1e-6)
                        continue;
                    double a = (area ? area[i] : mesh->patches[i].area) * fij,
                           b = (area ? area[j] : mesh->patches[j].area) * fji;
                    reciprocity = fmax(reciprocity, fabs(a - b) / fmax(a, b));
                }
        }
    }
#pragma omp parallel for reduction(max : largest_row, closure, largest) reduction(+ : empty)
    for (size_t i = 0; i < n; i++) {
        double row = 0, row_largest = 0;
        for (size_t j = 0; j < n; j++) {
            row += F[i * n + j];
            row_largest = fmax(row_largest, F[i * n + j]);
        }
        largest_row = fmax(largest_row, row);
        closure = fmax(closure, fabs(row - 1));
        largest = fmax(largest, row_largest);
        empty += row == 0;
    }
    check->reciprocity = reciprocity;
    check->largest_row_sum = largest_row;
    check->closure = closure;
    check->largest_factor = largest;
    check->empty_rows = empty;
}
