/*
 * solution_file.c - solution files: the per-patch radiosity B of one scene and meshing,
 * written once and read back by `render --solution` (layout in radiosity.h).
 *
 * Reading checks the whole file before anything uses it: size, magic, version, checksum,
 * values. Tying it to a scene is a separate step (rad_solution_match) because the mesh to
 * compare with is built from the patch size the file itself records.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "core/atomic_file.h"
#include "core/bytes.h"
#include "core/error.h"
#include "core/hash.h"

static const uint8_t solution_magic[8] = {0x89, 'R', 'A', 'D', 'S', 'O', 'L', '\n'};

enum {
    HEADER_BYTES = 40,   /* magic, version, patch count, fingerprint, patch size, levels */
    HEADER_BYTES_V1 = 32, /* without the levels */
    PATCH_BYTES = 24,    /* r, g, b as doubles */
    CHECKSUM_BYTES = 8
};

rad_status rad_solution_write(const rad_scene *scene, const rad_mesh *mesh, const rad_rgb *B,
                              const char *path, rad_error *error)
{
    uint64_t fingerprint;
    rad_status status = rad_solution_fingerprint(scene, mesh, &fingerprint, error);
    if (status != RAD_OK)
        return status;
    uint32_t n = mesh->patch_count;
    if ((uint64_t)n * PATCH_BYTES > (uint64_t)(SIZE_MAX / 2)) /* a 32-bit machine */
        return rad_fail(error, RAD_ERR_NOMEM, "%s: %u patches are too many", path, n);
    size_t size = HEADER_BYTES + (size_t)n * PATCH_BYTES + CHECKSUM_BYTES;
    uint8_t *bytes = rad_alloc_array(size, 1);
    if (!bytes)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for %u patches", path, n);
    memcpy(bytes, solution_magic, sizeof(solution_magic));
    bytes_put_u32(bytes + 8, RAD_SOLUTION_VERSION);
    bytes_put_u32(bytes + 12, n);
    bytes_put_u64(bytes + 16, fingerprint);
    bytes_put_f64(bytes + 24, mesh->patch_size);
    bytes_put_u32(bytes + 32, (uint32_t)mesh->shadow_levels);
    bytes_put_u32(bytes + 36, (uint32_t)mesh->proximity_levels);
    uint8_t *p = bytes + HEADER_BYTES;
    for (uint32_t i = 0; i < n; i++, p += PATCH_BYTES) {
        bytes_put_f64(p, B[i].r);
        bytes_put_f64(p + 8, B[i].g);
        bytes_put_f64(p + 16, B[i].b);
    }
    bytes_put_u64(p, hash_bytes(RAD_HASH_START, bytes, size - CHECKSUM_BYTES));
    status = rad_write_file_atomic(path, bytes, size, error);
    free(bytes);
    return status;
}

/* Checks the bytes of a whole file and fills solution from them. */
static rad_status parse_solution(const char *path, const uint8_t *bytes, size_t size,
                                 rad_solution *solution, rad_error *error)
{
    if (size < sizeof(solution_magic) || memcmp(bytes, solution_magic, sizeof(solution_magic)))
        return rad_fail(error, RAD_ERR_PARSE, "%s: not a radiosity solution file", path);
    if (size < HEADER_BYTES_V1 + CHECKSUM_BYTES)
        return rad_fail(error, RAD_ERR_PARSE, "%s: truncated solution file (%zu bytes)", path,
                        size);
    uint32_t version = bytes_get_u32(bytes + 8);
    if (version != RAD_SOLUTION_VERSION && version != 1)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: solution file format version %u; this build reads versions 1 to %d",
                        path, version, RAD_SOLUTION_VERSION);
    size_t header = version == 1 ? HEADER_BYTES_V1 : HEADER_BYTES;
    uint32_t n = bytes_get_u32(bytes + 12);
    /* fits: n < 2^32, so this is below 2^37 */
    uint64_t expected = header + (uint64_t)n * PATCH_BYTES + CHECKSUM_BYTES;
    if ((uint64_t)size < expected)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: truncated solution file (%zu bytes, %u patches need %llu)", path,
                        size, n, (unsigned long long)expected);
    if ((uint64_t)size > expected)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: %llu unexpected bytes after the end of the solution", path,
                        (unsigned long long)((uint64_t)size - expected));
    uint64_t checksum = hash_bytes(RAD_HASH_START, bytes, size - CHECKSUM_BYTES);
    if (checksum != bytes_get_u64(bytes + size - CHECKSUM_BYTES))
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: corrupted solution file (its checksum does not match)", path);
    solution->patch_count = n;
    solution->fingerprint = bytes_get_u64(bytes + 16);
    solution->patch_size = bytes_get_f64(bytes + 24);
    if (!(solution->patch_size > 0 && isfinite(solution->patch_size)))
        return rad_fail(error, RAD_ERR_PARSE, "%s: patch size %g is not a positive number",
                        path, solution->patch_size);
    solution->shadow_levels = version == 1 ? 0 : (int32_t)bytes_get_u32(bytes + 32);
    solution->proximity_levels = version == 1 ? 0 : (int32_t)bytes_get_u32(bytes + 36);
    if (solution->shadow_levels < -1 || solution->shadow_levels > RAD_SHADOW_LEVELS_MAX ||
        solution->proximity_levels < 0 || solution->proximity_levels > RAD_PROXIMITY_LEVELS_MAX)
        return rad_fail(error, RAD_ERR_PARSE, "%s: mesh levels %d and %d are out of range",
                        path, solution->shadow_levels, solution->proximity_levels);
    solution->B = rad_alloc_array(n, sizeof(*solution->B));
    if (!solution->B)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for %u patches", path, n);
    const uint8_t *p = bytes + header;
    for (uint32_t i = 0; i < n; i++, p += PATCH_BYTES) {
        rad_rgb b = {bytes_get_f64(p), bytes_get_f64(p + 8), bytes_get_f64(p + 16)};
        if (!(b.r >= 0 && b.g >= 0 && b.b >= 0 && isfinite(b.r) && isfinite(b.g) &&
              isfinite(b.b)))
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s: patch %u has a negative or non-finite radiosity", path, i);
        solution->B[i] = b;
    }
    return RAD_OK;
}

rad_status rad_solution_read(const char *path, rad_solution **out, rad_error *error)
{
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f)
        return rad_fail(error, RAD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    rad_status status = RAD_OK;
    uint8_t *bytes = NULL;
    rad_solution *solution = NULL;
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
        status = rad_fail(error, RAD_ERR_IO, "%s: not a regular file", path);
        goto done;
    }
    size_t size = (size_t)st.st_size;
    bytes = rad_alloc_array(size, 1);
    solution = rad_alloc_array(1, sizeof(*solution));
    if (!bytes || !solution) {
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory (%zu bytes)", path, size);
        goto done;
    }
    if (size && fread(bytes, 1, size, f) != size) {
        status = rad_fail(error, RAD_ERR_IO, "%s: read failed", path);
        goto done;
    }
    snprintf(solution->source, sizeof(solution->source), "%s", path);
    status = parse_solution(path, bytes, size, solution, error);
done:
    fclose(f);
    free(bytes);
    if (status == RAD_OK)
        *out = solution;
    else
        rad_solution_destroy(solution);
    return status;
}

rad_status rad_solution_match(const rad_solution *solution, const rad_scene *scene,
                              const rad_mesh *mesh, rad_error *error)
{
    uint64_t fingerprint;
    rad_status status = rad_solution_fingerprint(scene, mesh, &fingerprint, error);
    if (status != RAD_OK)
        return status;
    if (solution->patch_size != mesh->patch_size)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: solved with patch size %.17g, not %.17g", solution->source,
                        solution->patch_size, mesh->patch_size);
    if (solution->patch_count != mesh->patch_count || solution->fingerprint != fingerprint)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: solved for another scene or meshing (%u patches, fingerprint "
                        "%016llx; this scene has %u patches, fingerprint %016llx)",
                        solution->source, solution->patch_count,
                        (unsigned long long)solution->fingerprint, mesh->patch_count,
                        (unsigned long long)fingerprint);
    return RAD_OK;
}

void rad_solution_destroy(rad_solution *solution)
{
    if (!solution)
        return;
    free(solution->B);
    free(solution);
}
