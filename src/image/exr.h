/*
 * exr.h - OpenEXR (.exr) in and out, through OpenEXR's core C API (internal).
 *
 * Both directions use OpenEXR's custom-stream hooks, so the library never opens a file
 * itself: the writer encodes into an open stream (the temporary file of rad_image_write's
 * atomic write, like the other writers in writers.h) and the reader decodes bytes that
 * rad_image_read has already loaded. OpenEXR's messages are caught, never printed, and
 * reported as one line naming `path`.
 */
#ifndef RAD_IMAGE_EXR_H
#define RAD_IMAGE_EXR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "radiosity.h"

/* Scanline, ZIP-compressed EXR with channels R, G, B of linear radiance: half floats, or
 * 32-bit floats when float_channels is true. Half keeps 11 significant bits (relative
 * error <= 2^-11 from 6.1e-5 to 65504); larger magnitudes become infinite, smaller ones
 * lose precision gradually down to 6e-8, then 0. Floats, NaN and infinities are kept. */
rad_status rad_exr_write(const rad_image *image, bool float_channels, FILE *stream,
                         const char *path, rad_error *error);

/* Decodes a single-part scanline EXR held in memory (size bytes at data): channels R, G, B
 * (any others, such as A, are ignored), or a lone Y channel read as grey; half or float
 * samples, any compression OpenEXR knows, any data window (its top-left pixel becomes
 * pixel 0). Tiled, deep, multi-part and other channel layouts are RAD_ERR_UNSUPPORTED;
 * a malformed or truncated file is RAD_ERR_PARSE. */
rad_status rad_exr_read(const uint8_t *data, size_t size, const char *path, rad_image **out,
                        rad_error *error);

#endif
