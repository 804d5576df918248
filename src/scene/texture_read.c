/*
 * texture_read.c - PNG (libpng's simplified API) and JPEG (libjpeg) decoding for albedo
 * textures, from memory so that files and a glb's embedded images share one path.
 * Texels are 8-bit sRGB (the convention of MTL map_Kd and glTF baseColorTexture) and are
 * stored linear; alpha is dropped.
 */
#include <errno.h>
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <jpeglib.h> /* after stdio.h: it uses FILE and size_t */

#include "core/alloc.h"
#include "core/error.h"
#include "scene/texture.h"

enum { TEXTURE_MAX_SIDE = 32768 };

static double srgb_to_linear(unsigned value)
{
    double c = value / 255.0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

/* 8-bit sRGB RGB rows (top first) into out->rgb. */
static rad_status store(const char *name, const unsigned char *rgb8, uint32_t width,
                        uint32_t height, rad_texture *out, rad_error *error)
{
    float table[256];
    for (unsigned k = 0; k < 256; k++)
        table[k] = (float)srgb_to_linear(k);
    out->rgb = rad_alloc_array((size_t)width * height * 3, sizeof(float));
    if (!out->rgb)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for a %ux%u texture", name,
                        width, height);
    for (size_t k = 0; k < (size_t)width * height * 3; k++)
        out->rgb[k] = table[rgb8[k]];
    out->width = width;
    out->height = height;
    return RAD_OK;
}

static rad_status decode_png(const char *name, const unsigned char *data, size_t size,
                             rad_texture *out, rad_error *error)
{
    png_image image;
    memset(&image, 0, sizeof(image));
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&image, data, size))
        return rad_fail(error, RAD_ERR_PARSE, "%s: cannot read the PNG: %s", name,
                        image.message);
    image.format = PNG_FORMAT_RGB;
    if (image.width == 0 || image.height == 0 || image.width > TEXTURE_MAX_SIDE ||
        image.height > TEXTURE_MAX_SIDE) {
        png_image_free(&image);
        return rad_fail(error, RAD_ERR_PARSE, "%s: PNG of %ux%u pixels", name, image.width,
                        image.height);
    }
    unsigned char *pixels = rad_alloc_array(PNG_IMAGE_SIZE(image), 1);
    if (!pixels) {
        png_image_free(&image);
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", name);
    }
    rad_status status;
    if (!png_image_finish_read(&image, NULL, pixels, 0, NULL))
        status = rad_fail(error, RAD_ERR_PARSE, "%s: cannot read the PNG: %s", name,
                          image.message);
    else
        status = store(name, pixels, image.width, image.height, out, error);
    png_image_free(&image);
    free(pixels);
    return status;
}

typedef struct jpeg_failure {
    struct jpeg_error_mgr manager;
    jmp_buf jump;
    char message[JMSG_LENGTH_MAX];
} jpeg_failure;

static void jpeg_fail(j_common_ptr info)
{
    jpeg_failure *failure = (jpeg_failure *)info->err;
    (*info->err->format_message)(info, failure->message);
    longjmp(failure->jump, 1);
}

static void jpeg_quiet(j_common_ptr info, int level)
{
    (void)info;
    (void)level; /* libjpeg's warnings (corrupt but readable data) are not ours to print */
}

static rad_status decode_jpeg(const char *name, const unsigned char *data, size_t size,
                              rad_texture *out, rad_error *error)
{
    struct jpeg_decompress_struct info;
    jpeg_failure failure;
    unsigned char *volatile pixels = NULL;
    info.err = jpeg_std_error(&failure.manager);
    failure.manager.error_exit = jpeg_fail;
    failure.manager.emit_message = jpeg_quiet;
    if (setjmp(failure.jump)) {
        jpeg_destroy_decompress(&info);
        free(pixels);
        return rad_fail(error, RAD_ERR_PARSE, "%s: cannot read the JPEG: %s", name,
                        failure.message);
    }
    jpeg_create_decompress(&info);
    jpeg_mem_src(&info, data, (unsigned long)size);
    jpeg_read_header(&info, TRUE);
    info.out_color_space = JCS_RGB;
    jpeg_start_decompress(&info);
    uint32_t width = info.output_width, height = info.output_height;
    if (width == 0 || height == 0 || width > TEXTURE_MAX_SIDE || height > TEXTURE_MAX_SIDE ||
        info.output_components != 3) {
        jpeg_destroy_decompress(&info);
        return rad_fail(error, RAD_ERR_PARSE, "%s: JPEG of %ux%u pixels", name, width, height);
    }
    pixels = rad_alloc_array((size_t)width * height, 3);
    if (!pixels) {
        jpeg_destroy_decompress(&info);
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", name);
    }
    while (info.output_scanline < height) {
        JSAMPROW row = pixels + (size_t)info.output_scanline * width * 3;
        jpeg_read_scanlines(&info, &row, 1);
    }
    jpeg_finish_decompress(&info);
    jpeg_destroy_decompress(&info);
    rad_status status = store(name, pixels, width, height, out, error);
    free(pixels);
    return status;
}

rad_status texture_decode(const char *name, const unsigned char *data, size_t size,
                          rad_texture *out, rad_error *error)
{
    memset(out, 0, sizeof(*out));
    snprintf(out->source, sizeof(out->source), "%s", name);
    static const unsigned char png_signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (size >= 8 && memcmp(data, png_signature, 8) == 0)
        return decode_png(name, data, size, out, error);
    if (size >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF)
        return decode_jpeg(name, data, size, out, error);
    return rad_fail(error, RAD_ERR_UNSUPPORTED, "%s: not a PNG or JPEG image", name);
}

rad_status texture_load_file(const char *path, rad_texture *out, rad_error *error)
{
    memset(out, 0, sizeof(*out));
    FILE *file = fopen(path, "rb");
    if (!file)
        return rad_fail(error, RAD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(file), &st) != 0 || !S_ISREG(st.st_mode) || st.st_size <= 0) {
        fclose(file);
        return rad_fail(error, RAD_ERR_IO, "%s: cannot read: not a file or empty", path);
    }
    size_t size = (size_t)st.st_size;
    unsigned char *data = rad_alloc_array(size, 1);
    if (!data) {
        fclose(file);
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
    }
    size_t got = fread(data, 1, size, file);
    fclose(file);
    rad_status status = got == size ? texture_decode(path, data, size, out, error)
                                    : rad_fail(error, RAD_ERR_IO, "%s: cannot read", path);
    free(data);
    return status;
}

void texture_free(rad_texture *texture)
{
    free(texture->rgb);
    texture->rgb = NULL;
}

static const float *texel(const rad_texture *t, long x, long y)
{
    x %= (long)t->width;
    y %= (long)t->height;
    if (x < 0)
        x += t->width;
    if (y < 0)
        y += t->height;
    return &t->rgb[((size_t)y * t->width + (size_t)x) * 3];
}

rad_rgb texture_sample(const rad_texture *t, double u, double v)
{
    if (!isfinite(u) || !isfinite(v))
        u = v = 0;
    u -= floor(u);
    v -= floor(v);
    /* texel centres at (x + 0.5) / width; row 0 is the top, where v = 1 */
    double x = u * t->width - 0.5, y = (1 - v) * t->height - 0.5;
    long x0 = (long)floor(x), y0 = (long)floor(y);
    double fx = x - x0, fy = y - y0;
    const float *a = texel(t, x0, y0), *b = texel(t, x0 + 1, y0);
    const float *c = texel(t, x0, y0 + 1), *d = texel(t, x0 + 1, y0 + 1);
    double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    return (rad_rgb){w[0] * a[0] + w[1] * b[0] + w[2] * c[0] + w[3] * d[0],
                     w[0] * a[1] + w[1] * b[1] + w[2] * c[1] + w[3] * d[1],
                     w[0] * a[2] + w[1] * b[2] + w[2] * c[2] + w[3] * d[2]};
}
