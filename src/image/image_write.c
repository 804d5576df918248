/*
 * image_write.c - rad_image_write: picks the format by the file extension and writes
 * through an atomic file (temporary name + rename), so a failed write leaves nothing.
 *
 * The encoders themselves are in png_writer.c, rgbe_writer.c, pfm_writer.c and exr.c
 * (through OpenEXR, which writes into our temporary file through a custom-stream hook);
 * this file only validates, dispatches, and commits or aborts.
 */
#include <ctype.h>
#include <math.h>
#include <string.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "image/exr.h"
#include "image/tonemap.h"
#include "image/writers.h"

typedef enum image_format {
    FORMAT_UNKNOWN,
    FORMAT_PNG,
    FORMAT_HDR,
    FORMAT_PFM,
    FORMAT_EXR
} image_format;

/* Case-insensitive equality of two NUL-terminated ASCII strings. */
static int same_ignoring_case(const char *a, const char *b)
{
    for (; *a && *b; a++, b++)
        if (tolower((unsigned char)*a) != tolower((unsigned char)*b))
            return 0;
    return *a == *b;
}

/* The extension of the last path component, dot included; NULL when there is none. */
static const char *extension_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    return dot;
}

static image_format format_of(const char *extension)
{
    if (!extension)
        return FORMAT_UNKNOWN;
    if (same_ignoring_case(extension, ".png"))
        return FORMAT_PNG;
    if (same_ignoring_case(extension, ".hdr"))
        return FORMAT_HDR;
    if (same_ignoring_case(extension, ".pfm"))
        return FORMAT_PFM;
    if (same_ignoring_case(extension, ".exr"))
        return FORMAT_EXR;
    return FORMAT_UNKNOWN;
}

rad_status rad_image_write(const rad_image *image, const char *path,
                           const rad_image_write_options *options, rad_error *error)
{
    if (!path || !*path)
        return rad_fail(error, RAD_ERR_INVALID, "rad_image_write: no path");
    if (!image || !image->rgb || image->width == 0 || image->height == 0)
        return rad_fail(error, RAD_ERR_INVALID, "%s: no image to write", path);
    /* a NaN or infinite pixel is never written as a result */
    for (size_t k = 0; k < (size_t)image->width * image->height * 3; k++)
        if (!isfinite(image->rgb[k])) {
            size_t pixel = k / 3;
            return rad_fail(error, RAD_ERR_INTERNAL,
                            "%s: pixel (%zu, %zu) is not finite (a bug: please report the "
                            "scene); nothing was written",
                            path, pixel % image->width, pixel / image->width);
        }
    const char *extension = extension_of(path);
    image_format format = format_of(extension);
    if (format == FORMAT_UNKNOWN)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: unknown image format '%s' (use .png, .hdr, .pfm or .exr)",
                        path, extension ? extension : "");

    /* Settle everything that can fail without touching the disk first. */
    double scale = 1;
    if (format == FORMAT_PNG) {
        rad_status status = rad_tonemap_scale(image, options, &scale);
        if (status == RAD_ERR_INVALID)
            return rad_fail(error, status, "%s: exposure %g is not a finite number", path,
                            options->exposure);
        if (status != RAD_OK)
            return rad_fail(error, status, "%s: automatic exposure: out of memory", path);
    }

    rad_atomic_file file;
    rad_status status = rad_atomic_open(&file, path, error);
    if (status != RAD_OK)
        return status;
    switch (format) {
    case FORMAT_PNG: status = rad_png_write(image, scale, file.stream, path, error); break;
    case FORMAT_HDR: status = rad_rgbe_write(image, file.stream, path, error); break;
    case FORMAT_PFM: status = rad_pfm_write(image, file.stream, path, error); break;
    case FORMAT_EXR:
        status = rad_exr_write(image, options && options->exr_float, file.stream, path,
                               error);
        break;
    case FORMAT_UNKNOWN: status = rad_fail(error, RAD_ERR_INTERNAL, "%s: no writer", path);
    }
    if (status != RAD_OK) {
        rad_atomic_abort(&file);
        return status;
    }
    return rad_atomic_commit(&file, error);
}
