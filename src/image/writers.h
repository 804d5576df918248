/*
 * writers.h - the per-format image encoders behind rad_image_write (internal).
 *
 * Each writer encodes a valid image (non-NULL, non-empty) into an open stream, normally
 * the temporary file of an atomic write; it neither opens, closes nor removes files, and
 * reports failures as one line naming `path`. rad_image_write picks the writer by the
 * extension and commits or aborts the file. The .exr writer, rad_exr_write, is declared
 * in exr.h beside its reader.
 */
#ifndef RAD_IMAGE_WRITERS_H
#define RAD_IMAGE_WRITERS_H

#include <stdio.h>

#include "radiosity.h"

/* 8-bit sRGB PNG of radiance * scale (see tonemap.h), through libpng. */
rad_status rad_png_write(const rad_image *image, double scale, FILE *stream,
                         const char *path, rad_error *error);

/* Radiance RGBE (.hdr): flat scanlines, top row first, "-Y H +X W". */
rad_status rad_rgbe_write(const rad_image *image, FILE *stream, const char *path,
                          rad_error *error);

/* Portable float map: "PF", little-endian floats, bottom row first. */
rad_status rad_pfm_write(const rad_image *image, FILE *stream, const char *path,
                         rad_error *error);

#endif
