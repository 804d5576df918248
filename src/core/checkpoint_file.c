/*
 * checkpoint_file.c - the container of a restart file (checkpoint_file.h).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "core/bytes.h"
#include "core/checkpoint_file.h"
#include "core/error.h"
#include "core/hash.h"

rad_status checkpoint_file_write(const char *path, const uint8_t magic[8], uint32_t version,
                                 uint8_t *bytes, size_t size, rad_error *error)
{
    memcpy(bytes, magic, 8);
    bytes_put_u32(bytes + 8, version);
    bytes_put_u64(bytes + size - CHECKPOINT_FILE_TAIL,
                  hash_bytes(RAD_HASH_START, bytes, size - CHECKPOINT_FILE_TAIL));
    return rad_write_file_atomic(path, bytes, size, error);
}

/* The checks of a whole file's bytes: kind, length, version, checksum. */
static rad_status check_bytes(const char *path, const uint8_t magic[8], uint32_t version,
                              const char *what, const uint8_t *bytes, size_t size,
                              rad_error *error)
{
    if (size < 8 || memcmp(bytes, magic, 8))
        return rad_fail(error, RAD_ERR_PARSE, "%s: not a %s", path, what);
    if (size < CHECKPOINT_FILE_HEAD + CHECKPOINT_FILE_TAIL)
        return rad_fail(error, RAD_ERR_PARSE, "%s: truncated checkpoint (%zu bytes)", path,
                        size);
    uint32_t found = bytes_get_u32(bytes + 8);
    if (found != version)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: checkpoint format version %u; this build reads version %u", path,
                        found, version);
    if (hash_bytes(RAD_HASH_START, bytes, size - CHECKPOINT_FILE_TAIL) !=
        bytes_get_u64(bytes + size - CHECKPOINT_FILE_TAIL))
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: corrupted checkpoint (its checksum does not match)", path);
    return RAD_OK;
}

rad_status checkpoint_file_read(const char *path, const uint8_t magic[8], uint32_t version,
                                const char *what, uint8_t **bytes, size_t *size,
                                rad_error *error)
{
    *bytes = NULL;
    *size = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return rad_fail(error, RAD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    rad_status status = RAD_OK;
    uint8_t *data = NULL;
    size_t length = 0;
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
        status = rad_fail(error, RAD_ERR_IO, "%s: not a regular file", path);
        goto done;
    }
    length = (size_t)st.st_size;
    data = rad_alloc_array(length ? length : 1, 1);
    if (!data) {
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory (%zu bytes)", path, length);
        goto done;
    }
    if (length && fread(data, 1, length, f) != length) {
        status = rad_fail(error, RAD_ERR_IO, "%s: read failed", path);
        goto done;
    }
    status = check_bytes(path, magic, version, what, data, length, error);
done:
    fclose(f);
    if (status != RAD_OK) {
        free(data);
        return status;
    }
    *bytes = data;
    *size = length;
    return RAD_OK;
}
