/*
 * image.c - creating and freeing a rad_image (linear RGB radiance, row 0 at the top).
 *
 * Only memory lives here; the file formats are in image_write.c (with one writer per
 * format) and image_read.c.
 */
#include <inttypes.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"

rad_status rad_image_create(uint32_t width, uint32_t height, rad_image **out,
                            rad_error *error)
{
    if (!out)
        return rad_fail(error, RAD_ERR_INVALID, "rad_image_create: no output pointer");
    *out = NULL;
    if (width == 0 || height == 0)
        return rad_fail(error, RAD_ERR_INVALID,
                        "image size %" PRIu32 " x %" PRIu32 " is empty", width, height);

    /* width * height pixels of 3 floats: both products are checked (the second one by
     * rad_alloc_array). */
    rad_image *image = NULL;
    if ((size_t)height <= SIZE_MAX / width)
        image = rad_alloc_array(1, sizeof(*image));
    if (image) {
        image->rgb = rad_alloc_array((size_t)width * height, 3 * sizeof(*image->rgb));
        if (!image->rgb) {
            free(image);
            image = NULL;
        }
    }
    if (!image)
        return rad_fail(error, RAD_ERR_NOMEM,
                        "image of %" PRIu32 " x %" PRIu32 " pixels: out of memory", width,
                        height);
    image->width = width;
    image->height = height;
    *out = image;
    return RAD_OK;
}

void rad_image_destroy(rad_image *image)
{
    if (!image)
        return;
    free(image->rgb);
    free(image);
}
