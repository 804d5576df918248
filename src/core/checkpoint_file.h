/*
 * checkpoint_file.h - the container every restart file shares: an 8-byte magic naming its
 * kind, a format version (u32), the body, and last the FNV-1a checksum of every byte before
 * it (u64), all little-endian; written atomically (core/atomic_file.h), so a run killed
 * while writing leaves the previous checkpoint whole. Reading checks the magic, the version
 * and the checksum before any byte of the body is used; every message names the file. It
 * does not know what a body holds (surface_viewfactors/checkpoint.c, solve/solve_checkpoint.c)
 * nor when one is written.
 */
#ifndef RAD_CORE_CHECKPOINT_FILE_H
#define RAD_CORE_CHECKPOINT_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "radiosity.h"

enum {
    CHECKPOINT_FILE_HEAD = 12, /* magic, version: the body starts here */
    CHECKPOINT_FILE_TAIL = 8   /* the checksum */
};

/* Fills the head (magic, version) and the tail (checksum) of bytes[0 .. size), whose body
 * the caller has written at CHECKPOINT_FILE_HEAD, and writes the whole atomically to path. */
rad_status checkpoint_file_write(const char *path, const uint8_t magic[8], uint32_t version,
                                 uint8_t *bytes, size_t size, rad_error *error);

/* Reads a whole checkpoint of this kind (`what` names it in messages, e.g. "view-factor
 * checkpoint"): *bytes (free() it) and *size on success, the body at CHECKPOINT_FILE_HEAD,
 * size - CHECKPOINT_FILE_HEAD - CHECKPOINT_FILE_TAIL bytes long. RAD_ERR_IO when the file
 * cannot be read, RAD_ERR_PARSE for another kind of file, another version, a truncated or
 * corrupted one. */
rad_status checkpoint_file_read(const char *path, const uint8_t magic[8], uint32_t version,
                                const char *what, uint8_t **bytes, size_t *size,
                                rad_error *error);

#endif
