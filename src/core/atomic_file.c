/*
 * atomic_file.c - temporary file + rename, see atomic_file.h.
 */
#include "core/atomic_file.h"

#include <errno.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"

rad_status rad_atomic_open(rad_atomic_file *file, const char *path, rad_error *error)
{
    memset(file, 0, sizeof(*file));
    if (strlen(path) >= sizeof(file->final_path))
        return rad_fail(error, RAD_ERR_INVALID, "%s: path too long", path);
    strcpy(file->final_path, path);
    snprintf(file->temp_path, sizeof(file->temp_path), "%s.tmp-%ld", path, (long)getpid());
    file->stream = fopen(file->temp_path, "wb");
    if (!file->stream)
        return rad_fail(error, RAD_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    return RAD_OK;
}

rad_status rad_atomic_commit(rad_atomic_file *file, rad_error *error)
{
    int failed = ferror(file->stream) != 0;
    int saved = errno;
    if (fclose(file->stream) != 0 && !failed) {
        failed = 1;
        saved = errno;
    }
    file->stream = NULL;
    if (failed) {
        remove(file->temp_path);
        return rad_fail(error, RAD_ERR_IO, "%s: write failed: %s", file->final_path,
                        strerror(saved));
    }
    if (rename(file->temp_path, file->final_path) != 0) {
        saved = errno;
        remove(file->temp_path);
        return rad_fail(error, RAD_ERR_IO, "%s: cannot write: %s", file->final_path,
                        strerror(saved));
    }
    return RAD_OK;
}

void rad_atomic_abort(rad_atomic_file *file)
{
    if (file->stream) {
        fclose(file->stream);
        file->stream = NULL;
        remove(file->temp_path);
    }
}

rad_status rad_write_file_atomic(const char *path, const void *data, size_t size,
                                 rad_error *error)
{
    rad_atomic_file file;
    rad_status status = rad_atomic_open(&file, path, error);
    if (status != RAD_OK)
        return status;
    if (size && fwrite(data, 1, size, file.stream) != size) {
        int saved = errno;
        rad_atomic_abort(&file);
        return rad_fail(error, RAD_ERR_IO, "%s: write failed: %s", path, strerror(saved));
    }
    return rad_atomic_commit(&file, error);
}
