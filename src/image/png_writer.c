/*
 * png_writer.c - 8-bit sRGB PNG output through libpng.
 *
 * Each channel is radiance * scale, clamped, sRGB-encoded and rounded (tonemap.h); the file
 * is tagged sRGB. libpng reports errors by longjmp: the handler below copies the message
 * and jumps back into encode(), whose only job after a jump is to return 0. Everything
 * that must be freed is owned by rad_png_write, outside the setjmp frame, so nothing leaks
 * and no local is read after a jump. Warnings are dropped (library code does not print).
 */
#include <png.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "image/tonemap.h"
#include "image/writers.h"

typedef struct png_failure {
    char message[256]; /* libpng's own message for the error that stopped the write */
} png_failure;

static void on_png_error(png_structp png, png_const_charp message)
{
    png_failure *failure = png_get_error_ptr(png);
    snprintf(failure->message, sizeof(failure->message), "%s", message);
    png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp message)
{
    (void)png;
    (void)message;
}

/* Writes the whole image; 0 when libpng signalled an error. `row` holds width * 3 bytes. */
static int encode(png_structp png, png_infop info, FILE *stream, const rad_image *image,
                  double scale, png_bytep row)
{
    if (setjmp(png_jmpbuf(png)))
        return 0;
    png_init_io(png, stream);
    png_set_IHDR(png, info, image->width, image->height, 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    size_t values = (size_t)image->width * 3;
    for (uint32_t y = 0; y < image->height; y++) {
        const float *source = image->rgb + (size_t)y * values;
        for (size_t i = 0; i < values; i++)
            row[i] = rad_tonemap_srgb8(source[i] * scale);
        png_write_row(png, row);
    }
    png_write_end(png, NULL);
    return 1;
}

rad_status rad_png_write(const rad_image *image, double scale, FILE *stream,
                         const char *path, rad_error *error)
{
    png_failure failure = {{0}};
    png_structp png = NULL;
    png_infop info = NULL;
    png_bytep row = rad_alloc_array(image->width, 3);
    if (row)
        png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &failure, on_png_error,
                                      on_png_warning);
    if (png)
        info = png_create_info_struct(png);
    rad_status status = RAD_OK;
    if (!info)
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
    else if (!encode(png, info, stream, image, scale, row))
        status = rad_fail(error, RAD_ERR_IO, "%s: PNG write failed: %s", path,
                          failure.message);
    png_destroy_write_struct(&png, &info); /* harmless when either is NULL */
    free(row);
    return status;
}
