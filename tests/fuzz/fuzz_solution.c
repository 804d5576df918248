/*
 * fuzz_solution.c - libFuzzer target: solution files (solution_file.c). Each input is
 * read as it is, and again with its last 8 bytes replaced by the right checksum, so that
 * the checks behind the checksum (patch size, every patch's radiosity) are reached too.
 * The reader takes a path: the input is written to a temporary file.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/hash.h"
#include "fuzz_target.h"

enum { CHECKSUM_BYTES = 8 };

static void read_solution(const uint8_t *data, size_t size)
{
    const char *path = fuzz_write_file("input.sol", data, size);
    rad_solution *solution = NULL;
    rad_error error = {0};
    rad_status status = rad_solution_read(path, &solution, &error);
    fuzz_check_refusal(status, &error, path);
    for (uint32_t i = 0; status == RAD_OK && i < solution->patch_count; i++) {
        rad_rgb b = solution->B[i];
        if (!(b.r >= 0 && b.g >= 0 && b.b >= 0 && isfinite(b.r + b.g + b.b)))
            abort(); /* a radiosity the reader should have refused */
    }
    if (status == RAD_OK && !(solution->patch_size > 0 && isfinite(solution->patch_size)))
        abort();
    rad_solution_destroy(solution);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    read_solution(data, size);
    if (size < 40)
        return 0; /* too short for a header and checksum: nothing behind the checksum */
    uint8_t *fixed = malloc(size);
    if (!fixed)
        return 0;
    memcpy(fixed, data, size);
    bytes_put_u64(fixed + size - CHECKSUM_BYTES,
                  hash_bytes(RAD_HASH_START, fixed, size - CHECKSUM_BYTES));
    read_solution(fixed, size);
    free(fixed);
    return 0;
}
