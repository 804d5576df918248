/*
 * checkpoint.c - the restart file of a view-factor run (checkpoint.h).
 *
 * The container (core/checkpoint_file.h): the magic "\x89RADVFC\n", format version (u32),
 * the body, its checksum. The body, little-endian: surface count
 * (u32), scene fingerprint (u64), accuracy (f64), ray cap (u32), seed (u64), rows in the
 * file (u32), sight rays a surface (u32, 0: none; format version 2, and version 1 files,
 * made before the sight rays, are refused); then per row, in increasing row order, the row I (u32), its entry count (u32)
 * and per entry the column J >= I (u32, increasing), the transfer G_IJ (f64, >= 0) and its
 * error bound (f64, >= 0; > 0 when the transfer is 0: a sampled pair that saw nothing). The
 * whole file is checked before any row is used.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/bytes.h"
#include "core/checkpoint_file.h"
#include "core/error.h"
#include "core/hash.h"
#include "surface_viewfactors/checkpoint.h"

static const uint8_t checkpoint_magic[8] = {0x89, 'R', 'A', 'D', 'V', 'F', 'C', '\n'};

enum {
    CHECKPOINT_VERSION = 4, /* 2: rows of pairs some sight ray met (seen_pairs.h); 3: exact
                               occluders, obstructed pairs to an absolute target; 4: the
                               same layout, rows from the exact quadrature with the edge
                               check (polygon_integral.h), not to be mixed with rows of
                               version 3, which could miss light along an edge */
    CHECKPOINT_BEFORE_EDGE_CHECK = 3,
    HEADER_BYTES = 56,  /* magic, version, rows, fingerprint, accuracy, rays, seed, count,
                           sight rays, exact occluders */
    ROW_BYTES = 8,      /* row, entry count */
    ENTRY_BYTES = 20,   /* column, transfer, bound */
    CHECKSUM_BYTES = CHECKPOINT_FILE_TAIL
};

uint64_t vf_checkpoint_fingerprint(const rad_scene *scene)
{
    uint64_t h = RAD_HASH_START;
    h = hash_u32(h, scene->position_count);
    for (uint32_t v = 0; v < scene->position_count; v++) {
        h = hash_f64(h, scene->positions[v].x);
        h = hash_f64(h, scene->positions[v].y);
        h = hash_f64(h, scene->positions[v].z);
    }
    h = hash_u32(h, scene->triangle_count);
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        for (int k = 0; k < 3; k++)
            h = hash_u32(h, scene->triangles[t].vertex[k]);
        h = hash_u32(h, scene->triangles[t].surface);
    }
    h = hash_u32(h, scene->surface_count);
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        h = hash_u32(h, scene->surfaces[s].first_triangle);
        h = hash_u32(h, scene->surfaces[s].triangle_count);
        h = hash_u32(h, scene->surfaces[s].flags);
    }
    return h;
}

rad_status vf_checkpoint_write(const char *path, const vf_checkpoint_job *job,
                               const pending_row *rows, const uint8_t *done, rad_error *error)
{
    uint64_t size = HEADER_BYTES + CHECKSUM_BYTES;
    uint32_t count = 0;
    for (uint32_t I = 0; I < job->rows; I++)
        if (done[I]) {
            size += ROW_BYTES + (uint64_t)rows[I].count * ENTRY_BYTES;
            count++;
        }
    if (size > SIZE_MAX / 2)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: a checkpoint of %llu bytes is too large",
                        path, (unsigned long long)size);
    uint8_t *bytes = rad_alloc_array((size_t)size, 1);
    if (!bytes)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for a checkpoint of %llu bytes",
                        path, (unsigned long long)size);
    bytes_put_u32(bytes + 12, job->rows);
    bytes_put_u64(bytes + 16, job->fingerprint);
    bytes_put_f64(bytes + 24, job->accuracy);
    bytes_put_u32(bytes + 32, job->max_rays);
    bytes_put_u64(bytes + 36, job->seed);
    bytes_put_u32(bytes + 44, count);
    bytes_put_u32(bytes + 48, job->sight_rays);
    bytes_put_u32(bytes + 52, job->exact_occluders);
    uint8_t *p = bytes + HEADER_BYTES;
    for (uint32_t I = 0; I < job->rows; I++) {
        if (!done[I])
            continue;
        bytes_put_u32(p, I);
        bytes_put_u32(p + 4, rows[I].count);
        p += ROW_BYTES;
        for (uint32_t k = 0; k < rows[I].count; k++, p += ENTRY_BYTES) {
            bytes_put_u32(p, rows[I].entries[k].column);
            bytes_put_f64(p + 4, rows[I].entries[k].transfer);
            bytes_put_f64(p + 12, rows[I].entries[k].bound);
        }
    }
    rad_status status =
        checkpoint_file_write(path, checkpoint_magic, CHECKPOINT_VERSION, bytes, (size_t)size,
                              error);
    free(bytes);
    return status;
}

/* The header's job against this run's; RAD_ERR_INVALID naming what differs. */
static rad_status match_job(const char *path, const uint8_t *bytes, const vf_checkpoint_job *job,
                            rad_error *error)
{
    uint32_t rows = bytes_get_u32(bytes + 12);
    if (rows != job->rows || bytes_get_u64(bytes + 16) != job->fingerprint)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: a checkpoint of another scene (%u surfaces, fingerprint %016llx; "
                        "this one: %u, %016llx)",
                        path, rows, (unsigned long long)bytes_get_u64(bytes + 16), job->rows,
                        (unsigned long long)job->fingerprint);
    double accuracy = bytes_get_f64(bytes + 24);
    uint32_t max_rays = bytes_get_u32(bytes + 32);
    uint64_t seed = bytes_get_u64(bytes + 36);
    uint32_t sight_rays = bytes_get_u32(bytes + 48);
    uint32_t exact_occluders = bytes_get_u32(bytes + 52);
    if (accuracy != job->accuracy || max_rays != job->max_rays || seed != job->seed ||
        sight_rays != job->sight_rays || exact_occluders != job->exact_occluders)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: a checkpoint made with other options (--accuracy %.17g, "
                        "--max-rays %u, --seed %llu, --sight-rays %u, --exact-occluders %u; "
                        "this run: %.17g, %u, %llu, %u, %u)",
                        path, accuracy, max_rays, (unsigned long long)seed, sight_rays,
                        exact_occluders, job->accuracy, job->max_rays,
                        (unsigned long long)job->seed, job->sight_rays, job->exact_occluders);
    return RAD_OK;
}

/* Checks the bytes of a whole file and fills rows[] and done[] from them. */
static rad_status parse_checkpoint(const char *path, const uint8_t *bytes, size_t size,
                                   const vf_checkpoint_job *job, pending_row *rows,
                                   uint8_t *done, uint32_t *count, rad_error *error)
{
    if (size < HEADER_BYTES + CHECKSUM_BYTES)
        return rad_fail(error, RAD_ERR_PARSE, "%s: truncated checkpoint (%zu bytes)", path,
                        size);
    rad_status status = match_job(path, bytes, job, error);
    if (status != RAD_OK)
        return status;
    uint32_t listed = bytes_get_u32(bytes + 44), n = job->rows;
    const uint8_t *p = bytes + HEADER_BYTES, *end = bytes + size - CHECKSUM_BYTES;
    int64_t previous = -1;
    for (uint32_t r = 0; r < listed; r++) {
        if (end - p < ROW_BYTES)
            return rad_fail(error, RAD_ERR_PARSE, "%s: truncated checkpoint (row %u of %u)",
                            path, r, listed);
        uint32_t I = bytes_get_u32(p), entries = bytes_get_u32(p + 4);
        p += ROW_BYTES;
        if (I >= n || (int64_t)I <= previous)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s: row %u out of order or beyond the %u surfaces", path, I, n);
        previous = I;
        if ((uint64_t)(end - p) < (uint64_t)entries * ENTRY_BYTES)
            return rad_fail(error, RAD_ERR_PARSE, "%s: truncated checkpoint (row %u)", path, I);
        if (entries) {
            rows[I].entries = rad_alloc_array(entries, sizeof(row_entry));
            if (!rows[I].entries)
                return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for row %u", path, I);
        }
        rows[I].count = rows[I].capacity = entries;
        done[I] = 1;
        int64_t column_before = (int64_t)I - 1;
        for (uint32_t k = 0; k < entries; k++, p += ENTRY_BYTES) {
            row_entry e = {bytes_get_u32(p), bytes_get_f64(p + 4), bytes_get_f64(p + 12)};
            if (e.column >= n || (int64_t)e.column <= column_before ||
                !(e.transfer >= 0 && isfinite(e.transfer)) ||
                !(e.bound >= 0 && isfinite(e.bound)) || !(e.transfer > 0 || e.bound > 0))
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s: row %u: entry %u is out of range or not a finite number",
                                path, I, k);
            column_before = e.column;
            rows[I].entries[k] = e;
        }
    }
    if (p != end)
        return rad_fail(error, RAD_ERR_PARSE, "%s: %lld unexpected bytes after the last row",
                        path, (long long)(end - p));
    *count = listed;
    return RAD_OK;
}

rad_status vf_checkpoint_read(const char *path, const vf_checkpoint_job *job,
                              pending_row *rows, uint8_t *done, uint32_t *count,
                              rad_error *error)
{
    *count = 0;
    uint8_t *bytes = NULL;
    size_t size = 0;
    rad_status status = checkpoint_file_read(path, checkpoint_magic, CHECKPOINT_VERSION,
                                             "view-factor checkpoint", &bytes, &size, error);
    if (status == RAD_ERR_PARSE) { /* a whole file of the version before: say why not */
        rad_error ignored;
        if (checkpoint_file_read(path, checkpoint_magic, CHECKPOINT_BEFORE_EDGE_CHECK,
                                 "view-factor checkpoint", &bytes, &size, &ignored) == RAD_OK)
            status = rad_fail(error, RAD_ERR_PARSE,
                              "%s: a checkpoint of an earlier build (format version %d), "
                              "whose exact clipping could miss light along an edge: its rows "
                              "are not mixed with this build's; run again without --resume",
                              path, CHECKPOINT_BEFORE_EDGE_CHECK);
    }
    if (status == RAD_OK)
        status = parse_checkpoint(path, bytes, size, job, rows, done, count, error);
    if (status != RAD_OK)
        for (uint32_t I = 0; I < job->rows; I++) {
            free(rows[I].entries);
            rows[I] = (pending_row){0};
            done[I] = 0;
        }
    free(bytes);
    return status;
}
