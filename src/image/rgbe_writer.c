/*
 * rgbe_writer.c - Radiance RGBE (.hdr) output: the standard header, "-Y H +X W" (top row
 * first, left to right), then flat, uncompressed 4-byte pixels. Readers accept flat
 * scanlines everywhere, so no run-length encoder is needed.
 *
 * RGBE keeps one shared exponent: with max = m 2^e (m in [0.5,1)), each channel is stored
 * as floor(c 2^(8-e)) and the exponent as e + 128, so the largest channel keeps 8 bits and
 * the others an absolute precision of 1/256 of it. The format cannot hold negative or NaN
 * values (written as 0) nor values from 2^127 up (clamped to the largest RGBE value).
 */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "image/writers.h"

/* Exponent bias of the E byte; an E byte of 0 means the pixel is black. */
#define RGBE_EXPONENT_BIAS 128
/* The largest value RGBE holds: 255/256 * 2^127. */
#define RGBE_LARGEST 0x1.fep126

static double representable(float value)
{
    if (!(value > 0)) /* negative, zero or NaN */
        return 0;
    return value < RGBE_LARGEST ? value : RGBE_LARGEST;
}

static void encode_rgbe(const float rgb[3], uint8_t out[4])
{
    double r = representable(rgb[0]), g = representable(rgb[1]), b = representable(rgb[2]);
    double max = r > g ? r : g;
    max = max > b ? max : b;
    int exponent = 0;
    if (max > 0)
        frexp(max, &exponent);
    if (max == 0 || exponent + RGBE_EXPONENT_BIAS < 1) { /* black, or too small to hold */
        memset(out, 0, 4);
        return;
    }
    /* c * 2^(8-e) is exact (a power of two) and < 256 since c <= max < 2^e. */
    out[0] = (uint8_t)ldexp(r, 8 - exponent);
    out[1] = (uint8_t)ldexp(g, 8 - exponent);
    out[2] = (uint8_t)ldexp(b, 8 - exponent);
    out[3] = (uint8_t)(exponent + RGBE_EXPONENT_BIAS);
}

rad_status rad_rgbe_write(const rad_image *image, FILE *stream, const char *path,
                          rad_error *error)
{
    uint8_t *row = rad_alloc_array(image->width, 4);
    if (!row)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);

    rad_status status = RAD_OK;
    if (fprintf(stream,
                "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %" PRIu32 " +X %" PRIu32 "\n",
                image->height, image->width) < 0)
        goto write_failed;
    for (uint32_t y = 0; y < image->height; y++) {
        const float *source = image->rgb + (size_t)y * image->width * 3;
        for (uint32_t x = 0; x < image->width; x++)
            encode_rgbe(source + 3 * (size_t)x, row + 4 * (size_t)x);
        if (fwrite(row, 4, image->width, stream) != image->width)
            goto write_failed;
    }
    free(row);
    return status;

write_failed:
    status = rad_fail(error, RAD_ERR_IO, "%s: write failed: %s", path, strerror(errno));
    free(row);
    return status;
}
