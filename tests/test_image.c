/*
 * test_image.c - the image module: PFM/HDR/EXR round trips and orientation, hand-made RLE
 * and big-endian files, EXR layouts written by OpenEXR itself (grey, RGBA, data windows,
 * other compressions, tiled), the sRGB curve and exposure, PNG pixels decoded with libpng,
 * and the error paths (missing folder, failed rename, unknown extension, truncated files).
 *
 * The CLI's use of them: `compare` reads .exr, `render --exr-float` writes float channels.
 */
#include <math.h>
#include <openexr.h>
#include <png.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "image/tonemap.h"
#include "testlib.h"

/* RGBE keeps 8 bits for the largest channel; the decoder returns the centre of the
 * truncation step, so every channel is within 1/256 of the pixel's largest channel. */
#define RGBE_RELATIVE_PRECISION (1.0 / 256)
/* Half floats keep 11 significant bits; rounding to nearest is within half a step:
 * relative 2^-11 for normal halves (6.1e-5 to 65504). */
#define HALF_RELATIVE_PRECISION 0x1p-11


/* A smooth gradient: red grows left to right, green top to bottom, blue is constant. */
static rad_image *gradient(uint32_t width, uint32_t height)
{
    rad_image *image = test_new_image(width, height);
    for (uint32_t y = 0; y < height; y++)
        for (uint32_t x = 0; x < width; x++)
            test_set_pixel(image, x, y, (double)x / (width - 1), (double)y / (height - 1), 0.25);
    return image;
}

static size_t read_bytes(const char *path, uint8_t *buffer, size_t capacity)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    size_t n = fread(buffer, 1, capacity, f);
    fclose(f);
    return n;
}

static const char *write_bytes(const char *name, const void *bytes, size_t size)
{
    const char *path = test_path(name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(bytes, 1, size, f) != size || fclose(f) != 0) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
    return path;
}

static void put_float_be(uint8_t *out, float value)
{
    uint32_t bits;
    memcpy(&bits, &value, sizeof(bits));
    out[0] = (uint8_t)(bits >> 24);
    out[1] = (uint8_t)(bits >> 16);
    out[2] = (uint8_t)(bits >> 8);
    out[3] = (uint8_t)bits;
}

/* The number of entries in the scratch folder (including "." and ".."). */
static int scratch_entries(void)
{
    return test_count_files("");
}

/* ----------------------------------------------------------------------------------- */

static void test_create(void)
{
    rad_image *image = NULL;
    rad_error error;
    CHECK(rad_image_create(0, 5, &image, &error) == RAD_ERR_INVALID);
    CHECK(image == NULL);
    CHECK(rad_image_create(5, 0, &image, NULL) == RAD_ERR_INVALID);
    CHECK(rad_image_create(UINT32_MAX, UINT32_MAX, &image, &error) == RAD_ERR_NOMEM);
    CHECK(image == NULL);
    CHECK(rad_image_create(3, 2, &image, &error) == RAD_OK);
    CHECK(image && image->width == 3 && image->height == 2);
    if (image) {
        int zero = 1;
        for (size_t i = 0; i < 3 * 2 * 3; i++)
            zero &= image->rgb[i] == 0;
        CHECK(zero);
    }
    rad_image_destroy(image);
    rad_image_destroy(NULL);
}

static void test_srgb_curve(void)
{
    CHECK_ABS(rad_tonemap_srgb_encode(0), 0, 1e-15);
    CHECK_ABS(rad_tonemap_srgb_encode(1), 1, 1e-12);
    CHECK_ABS(rad_tonemap_srgb_encode(0.0031308), 0.04045, 1e-6);
    CHECK_ABS(rad_tonemap_srgb_encode(0.5), 0.735357, 1e-5);
    CHECK_ABS(rad_tonemap_srgb_encode(0.001), 0.01292, 1e-12); /* linear segment */
    CHECK_ABS(rad_tonemap_srgb_encode(-3), 0, 0);
    CHECK_ABS(rad_tonemap_srgb_encode(7), 1, 0);
    CHECK_ABS(rad_tonemap_srgb_encode(NAN), 0, 0);
    /* Both pieces meet at the knee (continuity within the curve's 4-digit constants). */
    CHECK_ABS(rad_tonemap_srgb_encode(0.0031308 * (1 + 1e-9)),
              rad_tonemap_srgb_encode(0.0031308 * (1 - 1e-9)), 1e-7);
    CHECK(rad_tonemap_srgb8(0.5) == 188);   /* 187.516 */
    CHECK(rad_tonemap_srgb8(0.2) == 124);   /* 123.555 */
    CHECK(rad_tonemap_srgb8(0.0031308) == 10);
    CHECK(rad_tonemap_srgb8(1) == 255);
    CHECK_NEAR(rad_tonemap_luminance(1, 0, 0), 0.2126, 1e-12);
    CHECK_NEAR(rad_tonemap_luminance(0, 1, 0), 0.7152, 1e-12);
    CHECK_NEAR(rad_tonemap_luminance(0, 0, 1), 0.0722, 1e-12);
}

static void test_exposure(void)
{
    /* 100 lit grey pixels of luminance 1..100 and 10 black ones. The 95th percentile of
     * the lit ones sits at position 0.95 * 99 = 94.05 between 95 and 96. */
    rad_image *image = test_new_image(11, 10);
    for (uint32_t i = 0; i < 100; i++)
        test_set_pixel(image, i % 10, i / 10, i + 1.0, i + 1.0, i + 1.0);
    double scale = 0;
    CHECK(rad_tonemap_scale(image, NULL, &scale) == RAD_OK);
    CHECK_NEAR(scale, 0.9 / 95.05, 1e-9);
    rad_image_write_options automatic = {0};
    scale = 0;
    CHECK(rad_tonemap_scale(image, &automatic, &scale) == RAD_OK);
    CHECK_NEAR(scale, 0.9 / 95.05, 1e-9);
    rad_image_write_options fixed = {.fixed_exposure = true, .exposure = 2};
    CHECK(rad_tonemap_scale(image, &fixed, &scale) == RAD_OK);
    CHECK_NEAR(scale, 4, 1e-15);
    fixed.exposure = INFINITY;
    CHECK(rad_tonemap_scale(image, &fixed, &scale) == RAD_ERR_INVALID);

    /* Automatic PNG: the pixel of luminance 100 becomes 100 * 0.9 / 95.05 = 0.94687,
     * sRGB 0.97627 -> 249. */
    const char *path = test_path("auto.png");
    rad_error error;
    CHECK(rad_image_write(image, path, NULL, &error) == RAD_OK);
    png_image png = {.version = PNG_IMAGE_VERSION};
    uint8_t decoded[11 * 10 * 3];
    if (png_image_begin_read_from_file(&png, path)) {
        png.format = PNG_FORMAT_RGB;
        CHECK(png_image_finish_read(&png, NULL, decoded, 0, NULL));
        CHECK(decoded[(9 * 11 + 9) * 3] == 249);
        CHECK(decoded[(9 * 11 + 10) * 3] == 0);
    } else {
        CHECK(!"auto.png readable by libpng");
    }
    png_image_free(&png);
    rad_image_destroy(image);

    rad_image *black = test_new_image(4, 4);
    CHECK(rad_tonemap_scale(black, NULL, &scale) == RAD_OK);
    CHECK(scale == 1);
    rad_image_destroy(black);
}

static void test_pfm_round_trip(void)
{
    const uint32_t w = 16, h = 9;
    rad_image *image = gradient(w, h);
    test_set_pixel(image, 3, 4, -2.5, 1e-30, 65504.0); /* negative, tiny, large: all exact */
    test_set_pixel(image, 5, 0, 1.0 / 3.0, 0.1, 123456.789);
    const char *path = test_path("gradient.pfm");
    rad_error error;
    CHECK(rad_image_write(image, path, NULL, &error) == RAD_OK);

    /* The header, and the convention: the first stored pixel is the bottom-left one. */
    static uint8_t bytes[4096];
    size_t size = read_bytes(path, bytes, sizeof(bytes));
    const char header[] = "PF\n16 9\n-1.0\n";
    size_t header_size = sizeof(header) - 1;
    CHECK(size == header_size + (size_t)w * h * 12);
    CHECK(memcmp(bytes, header, header_size) == 0);
    float first[3];
    memcpy(first, bytes + header_size, sizeof(first)); /* little-endian host assumed */
    CHECK(first[0] == 0 && first[1] == 1 && first[2] == 0.25f);
    const uint8_t little_endian_one[4] = {0x00, 0x00, 0x80, 0x3f};
    CHECK(memcmp(bytes + header_size + 4, little_endian_one, 4) == 0);

    rad_image *back = NULL;
    CHECK(rad_image_read(path, &back, &error) == RAD_OK);
    CHECK(back && back->width == w && back->height == h);
    if (back && back->width == w && back->height == h) {
        CHECK(memcmp(back->rgb, image->rgb, (size_t)w * h * 3 * sizeof(float)) == 0);
        /* The gradient, row 0 at the top: green is 0 on the top row, 1 on the bottom. */
        CHECK(test_pixel(back, 0, 0)[1] == 0);
        CHECK(test_pixel(back, 0, h - 1)[1] == 1);
        CHECK(test_pixel(back, w - 1, 2)[0] == 1);
        CHECK(test_pixel(back, 0, 2)[0] == 0);
        CHECK_NEAR(test_pixel(back, 6, 2)[0], 6.0 / 15, 1e-7);
        CHECK_NEAR(test_pixel(back, 6, 2)[1], 2.0 / 8, 1e-7);
        CHECK(test_pixel(back, 3, 4)[0] == -2.5f && test_pixel(back, 3, 4)[2] == 65504.0f);
    }
    rad_image_destroy(back);
    rad_image_destroy(image);
}

static void test_pfm_variants(void)
{
    /* Big-endian colour (positive scale), 1 x 2: the first stored row is the bottom one. */
    uint8_t colour[64];
    const char header[] = "PF\n1 2\n1.0\n";
    size_t n = sizeof(header) - 1;
    memcpy(colour, header, n);
    const float values[6] = {1, 2, 3, 4, 5, 6};
    for (int i = 0; i < 6; i++)
        put_float_be(colour + n + 4 * i, values[i]);
    rad_image *image = NULL;
    rad_error error;
    CHECK(rad_image_read(write_bytes("be.pfm", colour, n + 24), &image, &error) == RAD_OK);
    if (image) {
        CHECK(image->width == 1 && image->height == 2);
        CHECK(test_pixel(image, 0, 1)[0] == 1 && test_pixel(image, 0, 1)[2] == 3);
        CHECK(test_pixel(image, 0, 0)[0] == 4 && test_pixel(image, 0, 0)[2] == 6);
    }
    rad_image_destroy(image);

    /* Greyscale "Pf", big-endian: read as grey RGB. */
    uint8_t grey[64];
    const char grey_header[] = "Pf\n2 1\n1.0\n";
    n = sizeof(grey_header) - 1;
    memcpy(grey, grey_header, n);
    put_float_be(grey + n, 0.5f);
    put_float_be(grey + n + 4, 2.0f);
    image = NULL;
    CHECK(rad_image_read(write_bytes("grey.pfm", grey, n + 8), &image, &error) == RAD_OK);
    if (image) {
        CHECK(image->width == 2 && image->height == 1);
        CHECK(image->rgb[0] == 0.5f && image->rgb[1] == 0.5f && image->rgb[2] == 0.5f);
        CHECK(image->rgb[3] == 2.0f && image->rgb[5] == 2.0f);
    }
    rad_image_destroy(image);
}

static void test_hdr_round_trip(void)
{
    const uint32_t w = 16, h = 9;
    rad_image *image = gradient(w, h);
    test_set_pixel(image, 1, 1, 1000.0, 1e-3, 12345.0);
    test_set_pixel(image, 2, 1, 1.0, 1.0, 1.0);
    test_set_pixel(image, 3, 1, 0, 0, 0);
    test_set_pixel(image, 4, 1, 1e-20, 3e-21, 0);
    const char *path = test_path("gradient.hdr");
    rad_error error;
    CHECK(rad_image_write(image, path, NULL, &error) == RAD_OK);

    static uint8_t bytes[4096];
    size_t size = read_bytes(path, bytes, sizeof(bytes));
    const char header[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 9 +X 16\n";
    size_t header_size = sizeof(header) - 1;
    CHECK(size == header_size + (size_t)w * h * 4); /* flat */
    CHECK(memcmp(bytes, header, header_size) == 0);

    rad_image *back = NULL;
    CHECK(rad_image_read(path, &back, &error) == RAD_OK);
    CHECK(back && back->width == w && back->height == h);
    if (back && back->width == w && back->height == h) {
        double worst = 0; /* error / largest channel, over all pixels and channels */
        for (uint32_t y = 0; y < h; y++)
            for (uint32_t x = 0; x < w; x++) {
                const float *a = test_pixel(image, x, y), *b = test_pixel(back, x, y);
                double max = fmax(a[0], fmax(a[1], a[2]));
                for (int c = 0; c < 3; c++) {
                    double e = max > 0 ? fabs(b[c] - a[c]) / max : fabs(b[c]);
                    worst = fmax(worst, e);
                }
            }
        CHECK(worst <= RGBE_RELATIVE_PRECISION);
        CHECK(test_pixel(back, 3, 1)[0] == 0 && test_pixel(back, 3, 1)[1] == 0);
        CHECK_NEAR(test_pixel(back, 1, 1)[2], 12345.0, RGBE_RELATIVE_PRECISION);
        /* The other channels share the exponent of the largest one. */
        CHECK_ABS(test_pixel(back, 1, 1)[0], 1000.0, 12345.0 * RGBE_RELATIVE_PRECISION);
        CHECK(test_pixel(back, 1, 1)[1] < 12345.0 * RGBE_RELATIVE_PRECISION);
        CHECK_NEAR(test_pixel(back, 2, 1)[1], 1.0, RGBE_RELATIVE_PRECISION);
        /* Orientation: top row green 0, bottom row green 1. */
        CHECK(test_pixel(back, 8, 0)[1] < 0.01);
        CHECK_NEAR(test_pixel(back, 8, h - 1)[1], 1.0, RGBE_RELATIVE_PRECISION);
    }
    rad_image_destroy(back);
    rad_image_destroy(image);
}

/* A 10 x 2 picture as other tools write it: scanline 0 new-style run-length encoded,
 * scanline 1 flat with an old-style repeat pixel. */
static size_t hand_made_hdr(uint8_t *out, const char *header)
{
    size_t n = strlen(header);
    memcpy(out, header, n);
    const uint8_t rle[] = {
        2, 2, 0, 10,                             /* new-style RLE, width 10 */
        128 + 10, 128,                           /* R: run of 10 x 128 */
        10, 0, 10, 20, 30, 40, 50, 60, 70, 80, 90, /* G: 10 literals */
        128 + 5, 200, 5, 1, 2, 3, 4, 5,          /* B: run of 5 x 200, 5 literals */
        128 + 10, 129,                           /* E: run of 10 x 129 */
        128, 64, 32, 128, 1, 1, 1, 9,            /* flat pixel, then repeat it 9 times */
    };
    memcpy(out + n, rle, sizeof(rle));
    return n + sizeof(rle);
}

static void check_hand_made(const rad_image *image, uint32_t rle_row, double exposure)
{
    CHECK(image->width == 10 && image->height == 2);
    if (image->width != 10 || image->height != 2)
        return;
    for (uint32_t x = 0; x < 10; x++) {
        const float *p = test_pixel(image, x, rle_row);
        double unit = 1.0 / 128 / exposure; /* 2^(129 - 136) */
        CHECK_NEAR(p[0], 128.5 * unit, 1e-7);
        CHECK_NEAR(p[1], (10.0 * x + 0.5) * unit, 1e-7);
        CHECK_NEAR(p[2], (x < 5 ? 200.5 : x - 4 + 0.5) * unit, 1e-7);
        const float *q = test_pixel(image, x, 1 - rle_row);
        unit = 1.0 / 256 / exposure; /* 2^(128 - 136) */
        CHECK_NEAR(q[0], 128.5 * unit, 1e-7);
        CHECK_NEAR(q[1], 64.5 * unit, 1e-7);
        CHECK_NEAR(q[2], 32.5 * unit, 1e-7);
    }
}

static void test_hdr_rle(void)
{
    uint8_t bytes[512];
    rad_image *image = NULL;
    rad_error error;
    size_t n = hand_made_hdr(bytes, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 10\n");
    CHECK(rad_image_read(write_bytes("rle.hdr", bytes, n), &image, &error) == RAD_OK);
    if (image)
        check_hand_made(image, 0, 1);
    rad_image_destroy(image);

    /* Bottom-up rows ("+Y") and an EXPOSURE line (file values = radiance * 2). */
    n = hand_made_hdr(bytes, "#?RGBE\n# made by hand\nEXPOSURE=2\nFORMAT=32-bit_rle_rgbe\n\n"
                             "+Y 2 +X 10\n");
    image = NULL;
    CHECK(rad_image_read(write_bytes("rle-up.hdr", bytes, n), &image, &error) == RAD_OK);
    if (image)
        check_hand_made(image, 1, 2);
    rad_image_destroy(image);

    /* Cut inside the run-length data. */
    n = hand_made_hdr(bytes, "#?RADIANCE\n\n-Y 2 +X 10\n");
    const char *path = write_bytes("rle-cut.hdr", bytes, n - 20);
    image = NULL;
    CHECK(rad_image_read(path, &image, &error) == RAD_ERR_PARSE);
    CHECK(image == NULL);
    CHECK(strstr(error.message, path) != NULL);

    /* A run longer than the scanline. */
    const char *plain = "#?RADIANCE\n\n-Y 2 +X 10\n";
    n = hand_made_hdr(bytes, plain);
    bytes[strlen(plain) + 4] = 128 + 11; /* R: run of 11 instead of 10 */
    CHECK(rad_image_read(write_bytes("rle-long.hdr", bytes, n), &image, &error) ==
          RAD_ERR_PARSE);
}

static void test_png(void)
{
    rad_image *image = test_new_image(2, 2);
    test_set_pixel(image, 0, 0, 0, 1, 0.5);
    test_set_pixel(image, 1, 0, 0.2, 0.001, 2.0);
    test_set_pixel(image, 0, 1, -1, -2, 0.0031308); /* NaN is refused: test_non_finite_outputs */
    test_set_pixel(image, 1, 1, 0.25, 0.25, 0.25);
    const char *path = test_path("pixels.png");
    rad_error error;
    rad_image_write_options options = {.fixed_exposure = true, .exposure = 0};
    CHECK(rad_image_write(image, path, &options, &error) == RAD_OK);

    uint8_t decoded[2 * 2 * 3] = {0};
    png_image png = {.version = PNG_IMAGE_VERSION};
    CHECK(png_image_begin_read_from_file(&png, path) != 0);
    CHECK(png.width == 2 && png.height == 2);
    png.format = PNG_FORMAT_RGB;
    if (png.width == 2 && png.height == 2)
        CHECK(png_image_finish_read(&png, NULL, decoded, 0, NULL) != 0);
    png_image_free(&png);
    const uint8_t expected[2 * 2 * 3] = {
        0, 255, 188, /* 0, 1, 0.5 -> sRGB 0.735357 * 255 = 187.5 */
        124, 3, 255, /* 0.2 -> 123.55; 0.001 -> 12.92 * 0.001 * 255 = 3.29; 2 clamps */
        0, 0, 10,    /* negatives -> 0; 0.0031308 -> 0.04045 * 255 = 10.3 */
        137, 137, 137, /* 0.25 -> 0.537099 * 255 = 136.96 */
    };
    for (int i = 0; i < 12; i++)
        if (decoded[i] != expected[i])
            test_fail(__FILE__, __LINE__, "PNG byte %d = %d, expected %d", i, decoded[i],
                      expected[i]);
    test_checks++;

    /* Exposure +1 doubles: 0.25 -> 0.5 -> 188. Upper-case extension. */
    options.exposure = 1;
    path = test_path("EXPOSED.PNG");
    CHECK(rad_image_write(image, path, &options, &error) == RAD_OK);
    png = (png_image){.version = PNG_IMAGE_VERSION};
    if (png_image_begin_read_from_file(&png, path)) {
        png.format = PNG_FORMAT_RGB;
        CHECK(png_image_finish_read(&png, NULL, decoded, 0, NULL) != 0);
        CHECK(decoded[9] == 188 && decoded[11] == 188);
    } else {
        CHECK(!"EXPOSED.PNG readable by libpng");
    }
    png_image_free(&png);

    /* An infinite exposure is refused before any file is made. */
    options.exposure = -INFINITY;
    int before = scratch_entries();
    CHECK(rad_image_write(image, test_path("inf.png"), &options, &error) == RAD_ERR_INVALID);
    CHECK(scratch_entries() == before);
    rad_image_destroy(image);
}

static void test_write_errors(void)
{
    rad_image *image = gradient(4, 3);
    rad_error error;
    int before = scratch_entries();

    /* A folder that does not exist: I/O error naming the path, nothing left behind. */
    const char *formats[] = {"out.pfm", "out.hdr", "out.png", "out.exr"};
    for (int i = 0; i < 4; i++) {
        char path[4200];
        snprintf(path, sizeof(path), "%s/no-such-folder/%s", test_tmpdir(), formats[i]);
        CHECK(rad_image_write(image, path, NULL, &error) == RAD_ERR_IO);
        CHECK(strstr(error.message, path) != NULL);
        CHECK(strchr(error.message, '\n') == NULL);
        CHECK(!test_file_exists(path));
    }
    CHECK(scratch_entries() == before);

    /* The temporary file is written but the rename fails (a folder has the name): the
     * temporary file is removed. */
    const char *folder = test_path("taken.pfm");
    CHECK(mkdir(folder, 0755) == 0);
    CHECK(rad_image_write(image, folder, NULL, &error) == RAD_ERR_IO);
    CHECK(strstr(error.message, folder) != NULL);
    CHECK(test_count_files("taken.pfm") == 1);
    folder = test_path("taken.exr");
    CHECK(mkdir(folder, 0755) == 0);
    CHECK(rad_image_write(image, folder, NULL, &error) == RAD_ERR_IO);
    CHECK(strstr(error.message, folder) == error.message);
    CHECK(test_count_files("taken.exr") == 1);

    /* Unknown or missing extension. */
    before = scratch_entries();
    const char *jpg = test_path("out.jpg");
    CHECK(rad_image_write(image, jpg, NULL, &error) == RAD_ERR_INVALID);
    CHECK(strstr(error.message,
                 "unknown image format '.jpg' (use .png, .hdr, .pfm or .exr)"));
    CHECK(strstr(error.message, jpg) == error.message);
    CHECK(rad_image_write(image, test_path("no-extension"), NULL, &error) ==
          RAD_ERR_INVALID);
    CHECK(rad_image_write(image, test_path("dotted.dir/file"), NULL, &error) ==
          RAD_ERR_INVALID);
    CHECK(rad_image_write(NULL, test_path("null.pfm"), NULL, &error) == RAD_ERR_INVALID);
    CHECK(scratch_entries() == before);

    /* Upper-case extensions are recognised. */
    CHECK(rad_image_write(image, test_path("UPPER.PFM"), NULL, &error) == RAD_OK);
    CHECK(test_file_exists(test_path("UPPER.PFM")));
    CHECK(test_count_files("UPPER.PFM") == 1); /* no temporary file left */
    rad_image_destroy(image);
}

static void test_read_errors(void)
{
    rad_image *image = gradient(4, 3);
    rad_error error;
    const char *path = test_path("whole.pfm");
    CHECK(rad_image_write(image, path, NULL, &error) == RAD_OK);
    rad_image_destroy(image);
    static uint8_t bytes[4096];
    size_t size = read_bytes(path, bytes, sizeof(bytes));
    CHECK(size > 20);

    /* Truncated pixel data. */
    rad_image *back = NULL;
    const char *cut = write_bytes("cut.pfm", bytes, size - 5);
    CHECK(rad_image_read(cut, &back, &error) == RAD_ERR_PARSE);
    CHECK(back == NULL);
    CHECK(strstr(error.message, cut) == error.message);
    CHECK(strchr(error.message, '\n') == NULL);

    /* Cut in the header, bad headers, not an image at all, empty, missing. */
    CHECK(rad_image_read(write_bytes("header.pfm", bytes, 6), &back, &error) ==
          RAD_ERR_PARSE);
    const char *bad[] = {
        "PF\n0 3\n-1.0\n",          "PF\n4 -3\n-1.0\n", "PF\n4 3\n0\n",
        "PF\n4 3\nabc\n",           "PF\n99999999999 3\n-1\n", "PFX\n",
        "PF\n4294967295 4294967295\n-1\n", "hello",
        "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n-Y 2 +X 2\n", /* header never ends */
        "#?RADIANCE\n\n-Y 2 +Z 2\n",       "#?RADIANCE\n\n-Y 2 +Y 2\n",
        "#?RADIANCE\n\n-Y 2 +X 2\n\x80\x80\x80\x80", /* one pixel of four */
        "#?RADIANCE\n\n-Y 100000 +X 100000\n\x80\x80\x80\x80",
        "#?RADIANCE\nFORMAT=32-bit_rle_jpeg\n\n-Y 1 +X 1\n\x80\x80\x80\x80",
        "#?RADIANCE\nEXPOSURE=-1\n\n-Y 1 +X 1\n\x80\x80\x80\x80",
        "#?RADIANCE\n\n-Y 1 +X 2\n\x01\x01\x01\x01\x80\x80\x80\x80", /* repeat first */
        "",
    };
    for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        back = NULL;
        const char *file = test_write_file("bad.img", bad[i]);
        rad_status status = rad_image_read(file, &back, &error);
        if (status != RAD_ERR_PARSE)
            test_fail(__FILE__, __LINE__, "bad file %zu: status %d (%s), expected parse error",
                      i, (int)status, rad_status_name(status));
        test_checks++;
        CHECK(back == NULL);
        rad_image_destroy(back);
    }
    CHECK(rad_image_read(test_write_file("xyze.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n"
                                                     "-Y 1 +X 1\n\x80\x80\x80\x80"),
                         &back, &error) == RAD_ERR_UNSUPPORTED);
    const char *missing = test_path("missing.pfm");
    CHECK(rad_image_read(missing, &back, &error) == RAD_ERR_IO);
    CHECK(strstr(error.message, missing) == error.message);
}

/* ----------------------------------------------------------------------------------- */
/* OpenEXR                                                                             */

/* How OpenEXR itself sees a file: part 0's storage, compression and channel types. */
typedef struct exr_layout {
    int parts;
    exr_storage_t storage;
    exr_compression_t compression;
    int channels;
    char names[8][8];
    exr_pixel_type_t types[8];
} exr_layout;

static void silent(exr_const_context_t context, exr_result_t code, const char *message)
{
    (void)context;
    (void)code;
    (void)message;
}

static int exr_layout_of(const char *path, exr_layout *layout)
{
    memset(layout, 0, sizeof(*layout));
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = silent;
    exr_context_t context = NULL;
    const exr_attr_chlist_t *list = NULL;
    int ok = exr_start_read(&context, path, &init) == EXR_ERR_SUCCESS &&
             exr_get_count(context, &layout->parts) == EXR_ERR_SUCCESS &&
             exr_get_storage(context, 0, &layout->storage) == EXR_ERR_SUCCESS &&
             exr_get_compression(context, 0, &layout->compression) == EXR_ERR_SUCCESS &&
             exr_get_channels(context, 0, &list) == EXR_ERR_SUCCESS &&
             list->num_channels <= 8;
    for (int i = 0; ok && i < list->num_channels; i++) {
        snprintf(layout->names[i], sizeof(layout->names[i]), "%s",
                 list->entries[i].name.str);
        layout->types[i] = list->entries[i].pixel_type;
        layout->channels++;
    }
    exr_finish(&context);
    return ok;
}

/* A file written by OpenEXR directly (not by our writer), for the layouts we only read. */
typedef struct exr_spec {
    const char *names[4];          /* channels, any order */
    int channels;
    exr_pixel_type_t type;         /* of every channel */
    exr_compression_t compression;
    exr_lineorder_t order;
    int32_t x0, y0;                /* the data window's top-left corner */
    bool tiled;                    /* SPEC_TILE x SPEC_TILE tiles instead of scanlines */
} exr_spec;

enum { SPEC_WIDTH = 7, SPEC_HEIGHT = 5, SPEC_TILE = 4 };

/* Channel c of pixel (x, y), counted from the data window's corner: multiples of 1/4
 * below 100, so exact in half as in float. */
static float spec_value(int c, int x, int y)
{
    return (float)(c + 1) + 0.25f * (float)x + 8.0f * (float)y;
}

static const char *write_spec(const char *name, const exr_spec *spec)
{
    const char *path = test_path(name);
    static float planes[4][SPEC_HEIGHT][SPEC_WIDTH];
    for (int c = 0; c < spec->channels; c++)
        for (int y = 0; y < SPEC_HEIGHT; y++)
            for (int x = 0; x < SPEC_WIDTH; x++)
                planes[c][y][x] = spec_value(c, x, y);
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = silent;
    exr_context_t context = NULL;
    int part = 0;
    exr_attr_box2i_t window;
    window.min.x = spec->x0;
    window.min.y = spec->y0;
    window.max.x = spec->x0 + SPEC_WIDTH - 1;
    window.max.y = spec->y0 + SPEC_HEIGHT - 1;
    exr_attr_v2f_t centre;
    centre.x = centre.y = 0;
    exr_result_t rv = exr_start_write(&context, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_add_part(context, NULL,
                          spec->tiled ? EXR_STORAGE_TILED : EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr(context, part, &window, &window, 1, &centre, 1,
                                          spec->order, spec->compression);
    if (rv == EXR_ERR_SUCCESS && spec->tiled)
        rv = exr_set_tile_descriptor(context, part, SPEC_TILE, SPEC_TILE,
                                     EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN);
    for (int c = 0; c < spec->channels && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(context, part, spec->names[c], spec->type,
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(context);
    int32_t lines = 1;
    if (rv == EXR_ERR_SUCCESS && !spec->tiled)
        rv = exr_get_scanlines_per_chunk(context, part, &lines);
    /* Chunks: scanline blocks of `lines` rows, or SPEC_TILE x SPEC_TILE tiles. */
    int columns = spec->tiled ? (SPEC_WIDTH + SPEC_TILE - 1) / SPEC_TILE : 1;
    int rows = spec->tiled ? (SPEC_HEIGHT + SPEC_TILE - 1) / SPEC_TILE
                           : (SPEC_HEIGHT + lines - 1) / lines;
    exr_encode_pipeline_t encoder = EXR_ENCODE_PIPELINE_INITIALIZER;
    bool started = false;
    for (int i = 0; i < rows * columns && rv == EXR_ERR_SUCCESS; i++) {
        int column = i % columns, row = i / columns;
        int x = spec->tiled ? column * SPEC_TILE : 0;
        int y = spec->tiled ? row * SPEC_TILE : row * lines;
        exr_chunk_info_t chunk;
        if (spec->tiled)
            rv = exr_write_tile_chunk_info(context, part, column, row, 0, 0, &chunk);
        else
            rv = exr_write_scanline_chunk_info(context, part, spec->y0 + y, &chunk);
        if (rv == EXR_ERR_SUCCESS)
            rv = started ? exr_encoding_update(context, part, &chunk, &encoder)
                         : exr_encoding_initialize(context, part, &chunk, &encoder);
        started = started || rv == EXR_ERR_SUCCESS;
        for (int16_t k = 0; rv == EXR_ERR_SUCCESS && k < encoder.channel_count; k++) {
            int c = 0;
            while (strcmp(spec->names[c], encoder.channels[k].channel_name) != 0)
                c++;
            encoder.channels[k].encode_from_ptr = (const uint8_t *)&planes[c][y][x];
            encoder.channels[k].user_pixel_stride = (int32_t)sizeof(float);
            encoder.channels[k].user_line_stride = (int32_t)sizeof(float) * SPEC_WIDTH;
            encoder.channels[k].user_bytes_per_element = (int16_t)sizeof(float);
            encoder.channels[k].user_data_type = EXR_PIXEL_FLOAT;
        }
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_encoding_choose_default_routines(context, part, &encoder);
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_encoding_run(context, part, &encoder);
    }
    if (started)
        exr_encoding_destroy(context, &encoder);
    exr_result_t finished = exr_finish(&context);
    if (rv != EXR_ERR_SUCCESS || finished != EXR_ERR_SUCCESS) {
        fprintf(stderr, "cannot write %s with OpenEXR: %s\n", path,
                exr_get_default_error_message(rv != EXR_ERR_SUCCESS ? rv : finished));
        exit(1);
    }
    return path;
}

/* Reads a spec file and checks every pixel: channels R, G, B (or Y for all three) of
 * spec_value, for the channel's position in spec->names. */
static void check_spec(const char *path, const exr_spec *spec)
{
    int source[3] = {-1, -1, -1};
    for (int c = 0; c < spec->channels; c++) {
        const char *n = spec->names[c];
        for (int k = 0; k < 3; k++)
            if (strcmp(n, (const char *[]){"R", "G", "B"}[k]) == 0 || strcmp(n, "Y") == 0)
                source[k] = c;
    }
    rad_image *image = NULL;
    rad_error error;
    rad_status status = rad_image_read(path, &image, &error);
    if (status != RAD_OK)
        test_fail(__FILE__, __LINE__, "%s", error.message);
    test_checks++;
    if (!image)
        return;
    CHECK(image->width == SPEC_WIDTH && image->height == SPEC_HEIGHT);
    int wrong = 0;
    for (int y = 0; y < SPEC_HEIGHT && image->height == SPEC_HEIGHT; y++)
        for (int x = 0; x < SPEC_WIDTH && image->width == SPEC_WIDTH; x++)
            for (int k = 0; k < 3; k++)
                wrong += test_pixel(image, (uint32_t)x, (uint32_t)y)[k] !=
                         spec_value(source[k], x, y);
    if (wrong)
        test_fail(__FILE__, __LINE__, "%s: %d samples differ from the values written", path,
                  wrong);
    test_checks++;
    rad_image_destroy(image);
}

static void test_exr_round_trip(void)
{
    /* 37 x 23: ZIP stores 16 scanlines per chunk, so the second chunk is partial. */
    const uint32_t w = 37, h = 23;
    rad_image *image = gradient(w, h);
    test_set_pixel(image, 3, 4, -2.5, 1e-3, 65504.0); /* negative, small, largest half */
    test_set_pixel(image, 5, 0, 1.0 / 3.0, 0.1, 1234.567);
    test_set_pixel(image, 6, 0, 0, 0, 0);
    const char *half_path = test_path("gradient.exr");
    const char *float_path = test_path("GRADIENT-FLOAT.EXR");
    rad_error error;
    rad_image_write_options float_options = {.exr_float = true};
    CHECK(rad_image_write(image, half_path, NULL, &error) == RAD_OK);
    CHECK(rad_image_write(image, float_path, &float_options, &error) == RAD_OK);
    CHECK(test_count_files("gradient.exr") == 1); /* no temporary file left */

    /* OpenEXR's view: one scanline part, ZIP, channels B G R (sorted), half or float. */
    const char *paths[2] = {half_path, float_path};
    const exr_pixel_type_t types[2] = {EXR_PIXEL_HALF, EXR_PIXEL_FLOAT};
    for (int i = 0; i < 2; i++) {
        exr_layout layout;
        CHECK(exr_layout_of(paths[i], &layout));
        CHECK(layout.parts == 1 && layout.storage == EXR_STORAGE_SCANLINE);
        CHECK(layout.compression == EXR_COMPRESSION_ZIP);
        CHECK(layout.channels == 3);
        CHECK(strcmp(layout.names[0], "B") == 0 && strcmp(layout.names[1], "G") == 0 &&
              strcmp(layout.names[2], "R") == 0);
        for (int c = 0; c < layout.channels; c++)
            CHECK(layout.types[c] == types[i]);
    }
    uint8_t magic[4];
    CHECK(read_bytes(half_path, magic, 4) == 4 && magic[0] == 0x76 && magic[1] == 0x2f &&
          magic[2] == 0x31 && magic[3] == 0x01);

    /* Half: within half a step of 11 significant bits; float: bit for bit. */
    rad_image *half = NULL, *exact = NULL;
    CHECK(rad_image_read(half_path, &half, &error) == RAD_OK);
    CHECK(rad_image_read(float_path, &exact, &error) == RAD_OK);
    CHECK(half && half->width == w && half->height == h);
    CHECK(exact && exact->width == w && exact->height == h);
    if (half && half->width == w && half->height == h) {
        double worst = 0;
        for (size_t i = 0; i < (size_t)w * h * 3; i++) {
            double a = image->rgb[i], b = half->rgb[i];
            worst = fmax(worst, a != 0 ? fabs(b - a) / fabs(a) : fabs(b));
        }
        printf("test_image: EXR half round trip: largest relative error %.3g "
               "(2^-11 = %.3g)\n", worst, HALF_RELATIVE_PRECISION);
        CHECK(worst <= HALF_RELATIVE_PRECISION);
        CHECK(test_pixel(half, 3, 4)[0] == -2.5f && test_pixel(half, 3, 4)[2] == 65504.0f);
        CHECK(test_pixel(half, 6, 0)[0] == 0 && test_pixel(half, 6, 0)[2] == 0);
        /* Orientation: green 0 on the top row, 1 on the bottom; red 1 on the right. */
        CHECK(test_pixel(half, 0, 0)[1] == 0);
        CHECK(test_pixel(half, 9, h - 1)[1] == 1);
        CHECK(test_pixel(half, w - 1, 7)[0] == 1);
        CHECK_NEAR(test_pixel(half, 18, 17)[0], 18.0 / 36, HALF_RELATIVE_PRECISION);
        CHECK_NEAR(test_pixel(half, 18, 17)[1], 17.0 / 22, HALF_RELATIVE_PRECISION);
    }
    if (exact && exact->width == w && exact->height == h) {
        size_t differ = 0;
        for (size_t i = 0; i < (size_t)w * h * 3; i++)
            differ += memcmp(&exact->rgb[i], &image->rgb[i], sizeof(float)) != 0;
        printf("test_image: EXR float round trip: %zu of %zu values differ\n", differ,
               (size_t)w * h * 3);
        CHECK(differ == 0);
    }
    rad_image_destroy(exact);

    /* Half range: an image with a value above 65504 (half's largest) is written as float so
     * nothing becomes infinity; tiny values in a half image fade gradually. */
    test_set_pixel(image, 0, 0, 1e6, 3e-5, -1e6);
    CHECK(rad_image_write(image, half_path, NULL, &error) == RAD_OK);
    rad_image_destroy(half);
    half = NULL;
    CHECK(rad_image_read(half_path, &half, &error) == RAD_OK);
    if (half) {
        CHECK(test_pixel(half, 0, 0)[0] == 1e6f);
        CHECK(test_pixel(half, 0, 0)[2] == -1e6f);
        CHECK(test_pixel(half, 0, 0)[1] == 3e-5f);
    }
    rad_image_destroy(half);
    half = NULL;
    test_set_pixel(image, 0, 0, 60000, 3e-5, -1);
    CHECK(rad_image_write(image, half_path, NULL, &error) == RAD_OK);
    CHECK(rad_image_read(half_path, &half, &error) == RAD_OK);
    if (half) {
        CHECK_NEAR(test_pixel(half, 0, 0)[0], 60000, 0x1p-11);
        CHECK_NEAR(test_pixel(half, 0, 0)[1], 3e-5, 0x1p-10); /* a subnormal half: 10 bits */
    }
    rad_image_destroy(half);
    rad_image_destroy(image);
}

static void test_exr_layouts(void)
{
    /* Grey: a lone Y channel, uncompressed half. */
    exr_spec grey = {{"Y"}, 1, EXR_PIXEL_HALF, EXR_COMPRESSION_NONE,
                     EXR_LINEORDER_INCREASING_Y, 0, 0, false};
    check_spec(write_spec("grey.exr", &grey), &grey);

    /* RGBA in float, bottom-up line order, a data window that does not start at 0,0: A is
     * ignored, the data window's top-left pixel is pixel 0, rows run top-down. */
    exr_spec rgba = {{"R", "G", "B", "A"}, 4, EXR_PIXEL_FLOAT, EXR_COMPRESSION_NONE,
                     EXR_LINEORDER_DECREASING_Y, 5, -3, false};
    check_spec(write_spec("rgba.exr", &rgba), &rgba);

    /* Other compressions OpenEXR decodes for us. */
    exr_spec piz = {{"B", "G", "R"}, 3, EXR_PIXEL_HALF, EXR_COMPRESSION_PIZ,
                    EXR_LINEORDER_INCREASING_Y, 0, 0, false};
    check_spec(write_spec("piz.exr", &piz), &piz);
    exr_spec rle = {{"R", "G", "B"}, 3, EXR_PIXEL_FLOAT, EXR_COMPRESSION_RLE,
                    EXR_LINEORDER_INCREASING_Y, 0, 0, false};
    check_spec(write_spec("rle.exr", &rle), &rle);

    /* Layouts we do not read: unsupported, one line naming the file. */
    const exr_compression_t none = EXR_COMPRESSION_NONE;
    const exr_lineorder_t down = EXR_LINEORDER_INCREASING_Y;
    const exr_spec unsupported[] = {
        {{"R", "G"}, 2, EXR_PIXEL_HALF, none, down, 0, 0, false},
        {{"Z"}, 1, EXR_PIXEL_FLOAT, none, down, 0, 0, false},
        {{"Y", "RY", "BY"}, 3, EXR_PIXEL_HALF, none, down, 0, 0, false}, /* chroma */
        {{"R", "G", "B"}, 3, EXR_PIXEL_UINT, none, down, 0, 0, false},
        {{"R", "G", "B"}, 3, EXR_PIXEL_HALF, none, down, 0, 0, true},
    };
    const char *expected[] = {"not R, G, B", "not R, G, B", "not R, G, B", "integers",
                              "tiled"};
    for (size_t i = 0; i < sizeof(unsupported) / sizeof(unsupported[0]); i++) {
        const char *path = write_spec("unsupported.exr", &unsupported[i]);
        rad_image *image = NULL;
        rad_error error = {0};
        rad_status status = rad_image_read(path, &image, &error);
        if (status != RAD_ERR_UNSUPPORTED || !strstr(error.message, expected[i]))
            test_fail(__FILE__, __LINE__, "layout %zu: status %s, message '%s'", i,
                      rad_status_name(status), error.message);
        test_checks++;
        CHECK(image == NULL);
        CHECK(strstr(error.message, path) == error.message);
        CHECK(strchr(error.message, '\n') == NULL);
    }
}

static void test_exr_damaged(void)
{
    rad_image *image = gradient(40, 20); /* two ZIP chunks */
    const char *path = test_path("whole.exr");
    rad_error error;
    CHECK(rad_image_write(image, path, NULL, &error) == RAD_OK);
    rad_image_destroy(image);
    static uint8_t bytes[65536];
    size_t size = read_bytes(path, bytes, sizeof(bytes));
    CHECK(size > 100 && size < sizeof(bytes));

    /* Every prefix of the file: a parse error naming the file, never a crash or a read
     * past the bytes present (the sanitizer build checks that). */
    size_t wrong = 0, first_wrong = 0;
    char sample[RAD_ERROR_MESSAGE_MAX] = "";
    for (size_t cut = 0; cut < size; cut++) {
        const char *cut_path = write_bytes("cut.exr", bytes, cut);
        rad_image *back = NULL;
        rad_error cut_error = {0};
        rad_status status = rad_image_read(cut_path, &back, &cut_error);
        int ok = status == RAD_ERR_PARSE && back == NULL &&
                 strstr(cut_error.message, cut_path) == cut_error.message &&
                 strchr(cut_error.message, '\n') == NULL;
        if (!ok && wrong++ == 0)
            first_wrong = cut;
        if (cut == size / 2)
            snprintf(sample, sizeof(sample), "%s", cut_error.message);
        rad_image_destroy(back);
    }
    if (wrong)
        test_fail(__FILE__, __LINE__, "%zu of %zu truncated EXR files not a one-line parse "
                  "error naming the file (first: %zu bytes)", wrong, size, first_wrong);
    test_checks++;
    printf("test_image: truncated EXR: %s\n", sample);

    /* Damaged compressed data: an error or some pixels, but no crash. */
    for (size_t at = size - 60; at < size; at += 7) {
        bytes[at] ^= 0x5a;
        rad_image *back = NULL;
        const char *bent = write_bytes("bent.exr", bytes, size);
        rad_status status = rad_image_read(bent, &back, &error);
        CHECK(status == RAD_OK || status == RAD_ERR_PARSE);
        CHECK((status == RAD_OK) == (back != NULL));
        rad_image_destroy(back);
        bytes[at] ^= 0x5a;
    }
}

/* The command-line tool reads what we wrote: an image compared with itself. */
static void test_exr_cli(void)
{
    rad_image *image = gradient(24, 16);
    rad_error error;
    CHECK(rad_image_write(image, test_path("a.exr"), NULL, &error) == RAD_OK);
    rad_image_destroy(image);
    CHECK(test_run_tool("compare a.exr a.exr -o diff.exr") == 0);
    const char *out = test_read_text(test_path("stdout.txt"));
    CHECK(strstr(out, "rmse: 0\n") != NULL);
    CHECK(strstr(out, "size: 24x16\n") != NULL);
    CHECK(test_file_exists(test_path("diff.exr")));
}

/* `--exr-float` on the command line: the .exr holds exactly the floats of a .pfm of the
 * same render; without it, halves (close, not equal). */
static void test_exr_float_cli(void)
{
    const char *render = "render --patch-size 150 --size 24x18 --spp 1";
    char command[256];
    snprintf(command, sizeof(command), "%s -o same.pfm", render);
    CHECK(test_run_tool(command) == 0);
    snprintf(command, sizeof(command), "%s -o float.exr --exr-float", render);
    CHECK(test_run_tool(command) == 0);
    snprintf(command, sizeof(command), "%s -o half.exr", render);
    CHECK(test_run_tool(command) == 0);
    rad_image *pfm = NULL, *full = NULL, *half = NULL;
    rad_error error;
    CHECK(rad_image_read(test_path("same.pfm"), &pfm, &error) == RAD_OK);
    CHECK(rad_image_read(test_path("float.exr"), &full, &error) == RAD_OK);
    CHECK(rad_image_read(test_path("half.exr"), &half, &error) == RAD_OK);
    if (pfm && full && half) {
        size_t n = (size_t)pfm->width * pfm->height * 3;
        size_t differ_float = 0, differ_half = 0, beyond_half = 0;
        for (size_t k = 0; k < n; k++) {
            differ_float += full->rgb[k] != pfm->rgb[k];
            differ_half += half->rgb[k] != pfm->rgb[k];
            beyond_half += fabs(half->rgb[k] - pfm->rgb[k]) >
                           HALF_RELATIVE_PRECISION * fabs(pfm->rgb[k]) + 1e-7;
        }
        CHECK(differ_float == 0);
        CHECK(differ_half > 0);
        CHECK(beyond_half == 0);
    }
    rad_image_destroy(pfm);
    rad_image_destroy(full);
    rad_image_destroy(half);
}

int main(void)
{
    test_create();
    test_srgb_curve();
    test_exposure();
    test_pfm_round_trip();
    test_pfm_variants();
    test_hdr_round_trip();
    test_hdr_rle();
    test_png();
    test_write_errors();
    test_read_errors();
    test_exr_round_trip();
    test_exr_layouts();
    test_exr_damaged();
    test_exr_cli();
    test_exr_float_cli();
    return test_finish("test_image");
}
