/*
 * atomic_file.h - writing an output file so that it appears whole or not at all.
 *
 * rad_atomic_open() opens "<path>.tmp-<pid>" in the same folder; rad_atomic_commit()
 * flushes, closes and renames it onto path; rad_atomic_abort() closes and removes it.
 * A failed write therefore never leaves a half-written file under the requested name, and
 * SIGTERM, SIGINT or SIGHUP while the temporary is open remove it before the process ends
 * (atomic_file.c).
 */
#ifndef RAD_CORE_ATOMIC_FILE_H
#define RAD_CORE_ATOMIC_FILE_H

#include <stdio.h>

#include "radiosity.h"

typedef struct rad_atomic_file {
    FILE *stream;
    char final_path[4096];
    char temp_path[4096 + 32];
    int slot; /* its entry in the signal cleanup, or -1 */
} rad_atomic_file;

rad_status rad_atomic_open(rad_atomic_file *file, const char *path, rad_error *error);
rad_status rad_atomic_commit(rad_atomic_file *file, rad_error *error);
void rad_atomic_abort(rad_atomic_file *file);

#endif
