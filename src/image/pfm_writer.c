/*
 * pfm_writer.c - portable float map output: "PF\nW H\n-1.0\n", then little-endian IEEE
 * binary32 RGB triples, BOTTOM row first (the PFM convention; rad_image keeps row 0 at the
 * top, so rows are written in reverse). Values are stored bit for bit, NaN included.
 */
#include <errno.h>
#include <inttypes.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "image/writers.h"

_Static_assert(sizeof(float) == 4, "PFM needs 32-bit floats");

rad_status rad_pfm_write(const rad_image *image, FILE *stream, const char *path,
                         rad_error *error)
{
    size_t values = (size_t)image->width * 3; /* cannot overflow: width is 32-bit */
    uint8_t *row = rad_alloc_array(values, 4);
    if (!row)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);

    rad_status status = RAD_OK;
    if (fprintf(stream, "PF\n%" PRIu32 " %" PRIu32 "\n-1.0\n", image->width,
                image->height) < 0)
        goto write_failed;
    for (uint32_t y = image->height; y-- > 0;) {
        const float *source = image->rgb + (size_t)y * values;
        for (size_t i = 0; i < values; i++) {
            uint32_t bits;
            memcpy(&bits, &source[i], sizeof(bits));
            row[4 * i + 0] = (uint8_t)(bits & 0xff);
            row[4 * i + 1] = (uint8_t)(bits >> 8 & 0xff);
            row[4 * i + 2] = (uint8_t)(bits >> 16 & 0xff);
            row[4 * i + 3] = (uint8_t)(bits >> 24);
        }
        if (fwrite(row, 4, values, stream) != values)
            goto write_failed;
    }
    free(row);
    return status;

write_failed:
    status = rad_fail(error, RAD_ERR_IO, "%s: write failed: %s", path, strerror(errno));
    free(row);
    return status;
}
