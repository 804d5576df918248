/*
 * fuzz_target.h - what every libFuzzer target of tests/fuzz shares: the entry point
 * libFuzzer calls, the input written to a private temporary file (for the parsers that
 * read paths), and the contract checks that turn a wrong answer into a crash the fuzzer
 * reports: a refusal is one line naming the file, and a loaded scene holds what
 * radiosity.h promises (finite coordinates, indices in range, albedo in [0,1],
 * non-negative finite emission, no degenerate triangle).
 */
#ifndef RAD_FUZZ_TARGET_H
#define RAD_FUZZ_TARGET_H

#include <stddef.h>
#include <stdint.h>

#include "radiosity.h"

/* libFuzzer's entry point: one input, 0 always (a broken contract aborts). */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Writes data to `name` (replacing it) in this process's temporary folder, made on first
 * use under $TMPDIR (else /dev/shm, else /tmp) and removed at exit with the files in it
 * (at most 8 names). Returns the file's path, valid until the next call. Aborts on an I/O
 * error: that is the machine, not the parser. */
const char *fuzz_write_file(const char *name, const uint8_t *data, size_t size);

/* Load options whose warnings go nowhere (a fuzzer's log is for its own lines). */
const rad_load_options *fuzz_quiet_options(void);

/* Aborts unless status is RAD_OK, or error holds one line starting with path. With the
 * environment variable RAD_FUZZ_VERBOSE set, prints the message (or "loaded") first. */
void fuzz_check_refusal(rad_status status, const rad_error *error, const char *path);

/* Aborts unless scene keeps radiosity.h's promises for a loaded scene. */
void fuzz_check_scene(const rad_scene *scene);

#endif
