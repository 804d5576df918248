/*
 * test_compare.c - rad_image_compare and `radiosity compare`: identical images give zero;
 * synthetic differences give the numbers worked out by hand below (one bright block, a
 * uniform scale, partial edge blocks, black reference blocks); the false-colour ramp; the
 * refusals (sizes, NaN and infinity, bad options); and the CLI's report, picture, stats
 * and exit codes.
 *
 * Not tested here: reading and writing the image files themselves (test_image).
 */
#include <math.h>
#include <png.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

/* Values pass through float, so hand-computed numbers hold to float precision. */
#define FLOAT_PRECISION 1e-6

/* The CLI prints 6 significant digits. */
#define PRINTED_PRECISION 1e-5


static rad_image *constant(uint32_t width, uint32_t height, double value)
{
    rad_image *image = test_new_image(width, height);
    for (uint32_t y = 0; y < height; y++)
        for (uint32_t x = 0; x < width; x++)
            test_set_pixel(image, x, y, value, value, value);
    return image;
}

/* Nowhere black: every channel in [0.1, 1.2]. */
static rad_image *gradient(uint32_t width, uint32_t height)
{
    rad_image *image = test_new_image(width, height);
    for (uint32_t y = 0; y < height; y++)
        for (uint32_t x = 0; x < width; x++)
            test_set_pixel(image, x, y, 0.1 + (double)x / width, 0.2 + (double)y / height, 0.5);
    return image;
}

static rad_image *copy(const rad_image *image)
{
    rad_image *out = test_new_image(image->width, image->height);
    memcpy(out->rgb, image->rgb, (size_t)image->width * image->height * 3 * sizeof(float));
    return out;
}

static rad_image *scaled(const rad_image *image, double factor)
{
    rad_image *out = copy(image);
    for (size_t i = 0; i < (size_t)image->width * image->height * 3; i++)
        out->rgb[i] = (float)(factor * image->rgb[i]);
    return out;
}

static void test_identical(void)
{
    rad_image *b = gradient(37, 29); /* odd: 4 x 3 whole blocks of 8 */
    rad_image *a = copy(b);
    rad_image_difference d;
    rad_error error;
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, &error) == RAD_OK);
    CHECK(d.rmse == 0);
    CHECK(d.mean_relative_error == 0);
    CHECK(d.worst_block_error == 0);
    CHECK(d.worst_block_x == 0 && d.worst_block_y == 0);
    CHECK(d.block_count == 12);
    CHECK(d.blocks_within_tolerance == 1);
    CHECK(d.mean_a.r == d.mean_b.r && d.mean_a.g == d.mean_b.g && d.mean_a.b == d.mean_b.b);
    /* mean of 0.1 + x / 37 over x = 0..36: 0.1 + 18 / 37; blue is 0.5 everywhere */
    CHECK_NEAR(d.mean_b.r, 0.1 + 18.0 / 37, FLOAT_PRECISION);
    CHECK_NEAR(d.mean_b.g, 0.2 + 14.0 / 29, FLOAT_PRECISION);
    CHECK_NEAR(d.mean_b.b, 0.5, FLOAT_PRECISION);

    /* Comparing an image with itself is fine too. */
    CHECK(rad_image_compare(b, b, NULL, &d, NULL, &error) == RAD_OK);
    CHECK(d.rmse == 0 && d.blocks_within_tolerance == 1);
    rad_image_destroy(a);
    rad_image_destroy(b);
}

/* b = 1 everywhere on 32 x 24 (N = 768 pixels, 4 x 3 = 12 blocks); a = b except the 8 x 8
 * block at (16, 8), which is 1.5. */
enum { BLOCK_W = 32, BLOCK_H = 24, BRIGHT_X = 16, BRIGHT_Y = 8 };

static rad_image *one_bright_block(void)
{
    rad_image *a = constant(BLOCK_W, BLOCK_H, 1.0);
    for (uint32_t y = BRIGHT_Y; y < BRIGHT_Y + 8; y++)
        for (uint32_t x = BRIGHT_X; x < BRIGHT_X + 8; x++)
            test_set_pixel(a, x, y, 1.5, 1.5, 1.5);
    return a;
}

static void test_one_block(void)
{
    rad_image *b = constant(BLOCK_W, BLOCK_H, 1.0);
    rad_image *a = one_bright_block();
    const double N = BLOCK_W * BLOCK_H;
    rad_image_difference d;
    rad_error error;
    CHECK(rad_image_compare(a, b, &(rad_compare_options){0}, &d, NULL, &error) == RAD_OK);
    /* 64 pixels x 3 channels of 0.5^2 over 3 N values */
    CHECK_NEAR(d.rmse, sqrt(0.25 * 64 / N), FLOAT_PRECISION);
    /* 64 pixels at |0.5 * 3| / 3 = 0.5, over N lit pixels */
    CHECK_NEAR(d.mean_relative_error, 0.5 * 64 / N, FLOAT_PRECISION);
    CHECK_NEAR(d.mean_a.r, 1 + 0.5 * 64 / N, FLOAT_PRECISION);
    CHECK_NEAR(d.mean_a.b, 1 + 0.5 * 64 / N, FLOAT_PRECISION);
    CHECK_NEAR(d.mean_b.g, 1.0, FLOAT_PRECISION);
    CHECK_NEAR(d.worst_block_error, 0.5, FLOAT_PRECISION);
    CHECK(d.worst_block_x == BRIGHT_X && d.worst_block_y == BRIGHT_Y);
    CHECK(d.block_count == 12);
    CHECK_NEAR(d.blocks_within_tolerance, 11.0 / 12, 1e-12);

    /* Blocks of 16: 2 x 1 whole blocks (rows 16..23 are a partial row); the bright square
     * is a quarter of block (16, 0): its mean is 1.125. */
    CHECK(rad_image_compare(a, b, &(rad_compare_options){.block_size = 16}, &d, NULL,
                            &error) == RAD_OK);
    CHECK(d.block_count == 2);
    CHECK_NEAR(d.worst_block_error, 0.125, FLOAT_PRECISION);
    CHECK(d.worst_block_x == 16 && d.worst_block_y == 0);
    CHECK_NEAR(d.blocks_within_tolerance, 0.5, 1e-12);
    /* ...and within a tolerance of 0.2 both are. */
    CHECK(rad_image_compare(a, b,
                            &(rad_compare_options){.block_size = 16, .block_tolerance = 0.2},
                            &d, NULL, &error) == RAD_OK);
    CHECK(d.blocks_within_tolerance == 1);
    rad_image_destroy(a);
    rad_image_destroy(b);
}

static void test_scale(void)
{
    rad_image *b = gradient(40, 24); /* 5 x 3 = 15 blocks */
    rad_image *a = scaled(b, 1.05);
    rad_image_difference d;
    rad_error error;
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, &error) == RAD_OK);
    CHECK_NEAR(d.mean_relative_error, 0.05, 1e-5);
    CHECK_NEAR(d.worst_block_error, 0.05, 1e-5);
    CHECK(d.blocks_within_tolerance == 1);
    CHECK(d.block_count == 15);
    CHECK_NEAR(d.mean_a.r, 1.05 * d.mean_b.r, FLOAT_PRECISION);
    double mean_square = 0; /* rmse = 0.05 * sqrt(mean of b^2) */
    for (size_t i = 0; i < 40 * 24 * 3; i++)
        mean_square += (double)b->rgb[i] * b->rgb[i] / (40 * 24 * 3);
    CHECK_NEAR(d.rmse, 0.05 * sqrt(mean_square), 1e-5);
    rad_image_destroy(a);

    a = scaled(b, 1.2);
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, &error) == RAD_OK);
    CHECK_NEAR(d.mean_relative_error, 0.2, 1e-5);
    CHECK_NEAR(d.worst_block_error, 0.2, 1e-5);
    CHECK(d.blocks_within_tolerance == 0);
    rad_image_destroy(a);

    /* 0.8: a relative error of 0.2 as well (the measure is symmetric in sign). */
    a = scaled(b, 0.8);
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, &error) == RAD_OK);
    CHECK_NEAR(d.mean_relative_error, 0.2, 1e-5);
    CHECK(d.blocks_within_tolerance == 0);
    rad_image_destroy(a);
    rad_image_destroy(b);
}

static void test_partial_blocks(void)
{
    /* 20 x 13 with blocks of 8: 2 x 1 whole blocks cover x < 16, y < 8. */
    rad_image *b = constant(20, 13, 1.0);
    rad_image *a = copy(b);
    test_set_pixel(a, 17, 3, 100, 100, 100); /* right partial column */
    test_set_pixel(a, 4, 10, 100, 100, 100); /* bottom partial row */
    test_set_pixel(a, 19, 12, 100, 100, 100); /* bottom-right corner */
    rad_image_difference d;
    rad_error error;
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, &error) == RAD_OK);
    CHECK(d.block_count == 2);
    CHECK(d.worst_block_error == 0);
    CHECK(d.blocks_within_tolerance == 1);
    /* ...but the pixel measures see them: 3 pixels at 99 (relative 99) of 260 */
    CHECK_NEAR(d.rmse, sqrt(3 * 99.0 * 99.0 / 260), FLOAT_PRECISION);
    CHECK_NEAR(d.mean_relative_error, 3 * 99.0 / 260, FLOAT_PRECISION);

    /* Blocks of 4: 5 x 3 whole blocks (y < 12); the pixel at (17, 3) is in block
     * (16, 0), whose mean is (15 + 100) / 16; (19, 12) is still left out. */
    CHECK(rad_image_compare(a, b, &(rad_compare_options){.block_size = 4}, &d, NULL,
                            &error) == RAD_OK);
    CHECK(d.block_count == 15);
    CHECK_NEAR(d.worst_block_error, 99.0 / 16, FLOAT_PRECISION);
    CHECK(d.worst_block_x == 16 && d.worst_block_y == 0);
    CHECK_NEAR(d.blocks_within_tolerance, 13.0 / 15, 1e-12); /* (4, 8) holds (4, 10) */

    /* An image smaller than one block has no blocks. */
    CHECK(rad_image_compare(a, b, &(rad_compare_options){.block_size = 32}, &d, NULL,
                            &error) == RAD_OK);
    CHECK(d.block_count == 0 && d.worst_block_error == 0 && d.blocks_within_tolerance == 0);
    CHECK(d.rmse > 0);
    rad_image_destroy(a);
    rad_image_destroy(b);
}

static void test_black_reference(void)
{
    /* 16 x 8: block (0, 0) black in both, block (8, 0) black in b only. */
    rad_image *b = constant(16, 8, 0.0);
    rad_image *a = copy(b);
    test_set_pixel(a, 9, 1, 0, 0.5, 0);
    rad_image_difference d;
    rad_error error;
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, &error) == RAD_OK);
    CHECK(d.mean_relative_error == 0); /* no lit reference pixel */
    CHECK(isinf(d.worst_block_error) && d.worst_block_error > 0);
    CHECK(d.worst_block_x == 8 && d.worst_block_y == 0);
    CHECK_NEAR(d.blocks_within_tolerance, 0.5, 1e-12);
    CHECK_NEAR(d.rmse, sqrt(0.25 / (16 * 8 * 3)), FLOAT_PRECISION);

    /* Only lit reference pixels count for the mean relative error: one lit pixel at 2 in
     * b, 3 in a (relative 0.5); the black ones are left out. */
    test_set_pixel(b, 0, 0, 2, 2, 2);
    test_set_pixel(a, 0, 0, 3, 3, 3);
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, &error) == RAD_OK);
    CHECK_NEAR(d.mean_relative_error, 0.5, FLOAT_PRECISION);
    rad_image_destroy(a);
    rad_image_destroy(b);
}

static void test_refusals(void)
{
    rad_image *a = constant(4, 4, 1.0), *b = constant(5, 4, 1.0);
    rad_image_difference d;
    rad_error error;
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, &error) == RAD_ERR_INVALID);
    CHECK(strcmp(error.message, "images differ in size: 4x4 and 5x4") == 0);
    rad_image_destroy(b);

    b = constant(4, 4, 1.0);
    rad_image *picture = constant(4, 4, 7.0);
    test_set_pixel(a, 3, 2, 1, NAN, 1);
    test_set_pixel(a, 1, 3, INFINITY, 1, 1);
    CHECK(rad_image_compare(a, b, NULL, &d, picture, &error) == RAD_ERR_INVALID);
    CHECK(strstr(error.message, "pixel (3, 2) of image a") != NULL);
    CHECK(strchr(error.message, '\n') == NULL);
    CHECK(test_pixel(picture, 0, 0)[0] == 7); /* untouched on failure */

    test_set_pixel(a, 3, 2, 1, 1, 1);
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, &error) == RAD_ERR_INVALID);
    CHECK(strstr(error.message, "pixel (1, 3) of image a") != NULL);
    test_set_pixel(a, 1, 3, 1, 1, 1);
    test_set_pixel(b, 0, 1, 1, 1, -INFINITY);
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, &error) == RAD_ERR_INVALID);
    CHECK(strstr(error.message, "pixel (0, 1) of image b") != NULL);
    test_set_pixel(b, 0, 1, 1, 1, 1);
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, &error) == RAD_OK);

    /* Bad options, a wrong-size picture, missing arguments. */
    CHECK(rad_image_compare(a, b, &(rad_compare_options){.block_tolerance = -0.1}, &d, NULL,
                            &error) == RAD_ERR_INVALID);
    CHECK(rad_image_compare(a, b, &(rad_compare_options){.block_tolerance = NAN}, &d, NULL,
                            &error) == RAD_ERR_INVALID);
    rad_image *small = constant(2, 2, 0.0);
    CHECK(rad_image_compare(a, b, NULL, &d, small, &error) == RAD_ERR_INVALID);
    CHECK(rad_image_compare(NULL, b, NULL, &d, NULL, &error) == RAD_ERR_INVALID);
    CHECK(rad_image_compare(a, NULL, NULL, &d, NULL, &error) == RAD_ERR_INVALID);
    CHECK(rad_image_compare(a, b, NULL, NULL, NULL, NULL) == RAD_ERR_INVALID);
    rad_image_destroy(small);
    rad_image_destroy(picture);
    rad_image_destroy(a);
    rad_image_destroy(b);
}

static bool colour_is(const rad_image *image, uint32_t x, uint32_t y, double r, double g,
                      double b)
{
    const float *p = test_pixel(image, x, y);
    return fabs(p[0] - r) <= FLOAT_PRECISION && fabs(p[1] - g) <= FLOAT_PRECISION &&
           fabs(p[2] - b) <= FLOAT_PRECISION;
}

static void test_false_colour(void)
{
    /* Row 0: a = b * (1 + d) for d = 0, 1/4, 1/2, 3/4, 1, 3, and 1/8; row 1: black
     * reference with black a, then with a lit a. */
    const double relative[] = {0, 0.25, 0.5, 0.75, 1, 3, 0.125};
    const double expected[][3] = {
        {0, 0, 1}, {0, 1, 1}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}, {1, 0, 0}, {0, 0.5, 1},
    };
    rad_image *b = constant(7, 2, 2.0), *a = constant(7, 2, 2.0);
    for (uint32_t x = 0; x < 7; x++) {
        double v = 2 * (1 + relative[x]);
        test_set_pixel(a, x, 0, v, v, v);
    }
    test_set_pixel(b, 0, 1, 0, 0, 0);
    test_set_pixel(a, 0, 1, 0, 0, 0);
    test_set_pixel(b, 1, 1, 0, 0, 0);
    test_set_pixel(a, 1, 1, 0.001, 0, 0);
    test_set_pixel(a, 2, 1, 1.0, 3.0, 2.0); /* |(-1, 1, 0)|_1 / 6 = 1/3: between cyan and green */
    rad_image *picture = test_new_image(7, 2);
    rad_image_difference d;
    rad_error error;
    CHECK(rad_image_compare(a, b, NULL, &d, picture, &error) == RAD_OK);
    for (uint32_t x = 0; x < 7; x++)
        if (!colour_is(picture, x, 0, expected[x][0], expected[x][1], expected[x][2]))
            test_fail(__FILE__, __LINE__, "false colour at relative %g: %g %g %g",
                      relative[x], test_pixel(picture, x, 0)[0], test_pixel(picture, x, 0)[1],
                      test_pixel(picture, x, 0)[2]);
    test_checks++;
    CHECK(colour_is(picture, 0, 1, 0, 0, 1)); /* both black: equal */
    CHECK(colour_is(picture, 1, 1, 1, 0, 0)); /* black reference, lit a: red */
    CHECK(colour_is(picture, 2, 1, 0, 1, 2.0 / 3)); /* 1/3: a third of cyan -> green */
    CHECK(colour_is(picture, 3, 1, 0, 0, 1));

    /* The picture may be one of the images compared. */
    CHECK(rad_image_compare(a, b, NULL, &d, a, &error) == RAD_OK);
    CHECK(colour_is(a, 4, 0, 1, 0, 0) && colour_is(a, 3, 1, 0, 0, 1));
    rad_image_destroy(picture);
    rad_image_destroy(a);
    rad_image_destroy(b);
}

/* The number after "name: " on a line of the CLI's standard output (NAN when absent). */
static double report_value(const char *text, const char *name)
{
    char key[64];
    snprintf(key, sizeof(key), "%s: ", name);
    size_t length = strlen(key);
    for (const char *line = text; *line;) {
        if (strncmp(line, key, length) == 0)
            return strtod(line + length, NULL);
        const char *end = strchr(line, '\n');
        if (!end)
            break;
        line = end + 1;
    }
    return NAN;
}

static void write_image(const rad_image *image, const char *name)
{
    rad_error error;
    if (rad_image_write(image, test_path(name), NULL, &error) != RAD_OK) {
        fprintf(stderr, "%s\n", error.message);
        exit(1);
    }
}

/* A PFM written byte by byte (little-endian, rows bottom to top), so that it may hold what
 * rad_image_write refuses to write: NaN and infinity. */
static void write_pfm_by_hand(const rad_image *image, const char *name)
{
    FILE *f = fopen(test_path(name), "wb");
    if (!f) {
        fprintf(stderr, "cannot write %s\n", name);
        exit(1);
    }
    fprintf(f, "PF\n%u %u\n-1\n", image->width, image->height);
    for (uint32_t y = image->height; y-- > 0;)
        fwrite(image->rgb + (size_t)y * image->width * 3, sizeof(float), (size_t)image->width * 3,
               f);
    fclose(f);
}

static int line_count(const char *text)
{
    int lines = 0;
    for (; *text; text++)
        lines += *text == '\n';
    return lines;
}

static void test_cli(void)
{
    rad_image *b = constant(BLOCK_W, BLOCK_H, 1.0);
    rad_image *a = one_bright_block();
    write_image(a, "a.pfm");
    write_image(b, "b.pfm");
    const double N = BLOCK_W * BLOCK_H;

    CHECK(test_run_tool("compare a.pfm b.pfm -o diff.png --stats stats.json") == 0);
    const char *out = test_read_text(test_path("stdout.txt"));
    CHECK_NEAR(report_value(out, "rmse"), sqrt(0.25 * 64 / N), PRINTED_PRECISION);
    CHECK_NEAR(report_value(out, "mean_relative_error"), 0.5 * 64 / N, PRINTED_PRECISION);
    CHECK_NEAR(report_value(out, "mean_a"), 1 + 0.5 * 64 / N, PRINTED_PRECISION);
    CHECK_NEAR(report_value(out, "mean_b"), 1, PRINTED_PRECISION);
    CHECK(strstr(out, "size: 32x24\n") != NULL);
    CHECK(strstr(out, "worst_block: 16,8 0.5\n") != NULL);
    CHECK(strstr(out, "blocks_within_tolerance: 0.916667 (11 of 12 blocks of 8x8)\n") != NULL);
    CHECK(test_read_text(test_path("stderr.txt"))[0] == 0);
    const char *stats = test_read_text(test_path("stats.json"));
    CHECK(strstr(stats, "\"blocks_within\": 11") != NULL);
    CHECK(strstr(stats, "\"worst_block_x\": 16") != NULL);

    /* The picture: blue where equal, green in the block (50 %), exactly. */
    png_image png = {.version = PNG_IMAGE_VERSION};
    uint8_t decoded[BLOCK_W * BLOCK_H * 3];
    CHECK(png_image_begin_read_from_file(&png, test_path("diff.png")) != 0);
    CHECK(png.width == BLOCK_W && png.height == BLOCK_H);
    if (png.width == BLOCK_W && png.height == BLOCK_H) {
        png.format = PNG_FORMAT_RGB;
        CHECK(png_image_finish_read(&png, NULL, decoded, 0, NULL) != 0);
        const uint8_t *equal = decoded + 3 * (2 * BLOCK_W + 3);
        const uint8_t *bright = decoded + 3 * ((BRIGHT_Y + 2) * BLOCK_W + BRIGHT_X + 5);
        CHECK(equal[0] == 0 && equal[1] == 0 && equal[2] == 255);
        CHECK(bright[0] == 0 && bright[1] == 255 && bright[2] == 0);
    }
    png_image_free(&png);
    CHECK(test_count_files("diff") == 1); /* no temporary left */

    /* Options; the same image gives zeros; the false colour as .pfm holds the ramp. */
    CHECK(test_run_tool("compare b.pfm b.pfm --block 16 --block-tolerance 0.05 -o same.pfm") ==
          0);
    out = test_read_text(test_path("stdout.txt"));
    CHECK(report_value(out, "rmse") == 0);
    CHECK(strstr(out, "worst_block: 0,0 0\n") != NULL);
    CHECK(strstr(out, "blocks_within_tolerance: 1 (2 of 2 blocks of 16x16)\n") != NULL);
    rad_image *same = NULL;
    rad_error error;
    CHECK(rad_image_read(test_path("same.pfm"), &same, &error) == RAD_OK);
    if (same)
        CHECK(colour_is(same, 5, 5, 0, 0, 1));
    rad_image_destroy(same);

    /* Errors: one line naming the file, exit 1. */
    CHECK(test_run_tool("compare a.pfm missing.pfm") == 1);
    const char *err = test_read_text(test_path("stderr.txt"));
    CHECK(strstr(err, "missing.pfm") != NULL && line_count(err) == 1);
    CHECK(strncmp(err, "radiosity: ", 11) == 0);
    CHECK(test_read_text(test_path("stdout.txt"))[0] == 0);
    rad_image *other = constant(8, 8, 1.0);
    write_image(other, "other.hdr");
    CHECK(test_run_tool("compare a.pfm other.hdr -o wrong.png") == 1);
    err = test_read_text(test_path("stderr.txt"));
    CHECK(strstr(err, "images differ in size: 32x24 and 8x8") != NULL);
    CHECK(strstr(err, "a.pfm") != NULL && strstr(err, "other.hdr") != NULL);
    CHECK(line_count(err) == 1);
    CHECK(!test_file_exists(test_path("wrong.png")));
    test_set_pixel(b, 2, 1, NAN, 0, 0);
    write_pfm_by_hand(b, "nan.pfm");
    CHECK(test_run_tool("compare a.pfm nan.pfm") == 1);
    err = test_read_text(test_path("stderr.txt"));
    CHECK(strstr(err, "nan.pfm") && strstr(err, "pixel (2, 1) of image b"));

    /* Usage errors exit 2; --help exits 0. */
    CHECK(test_run_tool("compare a.pfm") == 2);
    CHECK(test_run_tool("compare a.pfm b.pfm -o diff.jpg") == 2);
    CHECK(test_run_tool("compare a.pfm b.pfm --block 0") == 2);
    CHECK(test_run_tool("compare a.pfm b.pfm --block-tolerance -1") == 2);
    CHECK(test_run_tool("compare a.pfm b.pfm --frobnicate") == 2);
    CHECK(test_run_tool("compare --help") == 0);
    CHECK(strstr(test_read_text(test_path("stdout.txt")), "usage: radiosity compare") != NULL);

    rad_image_destroy(other);
    rad_image_destroy(a);
    rad_image_destroy(b);
}

/* The render-accuracy measures: a uniform 1 % error reads 1 % on blocks and pixels; a
 * light far above the median is left out of the pixel measure with 2 pixels around it. */
static void test_accuracy_measures(void)
{
    rad_image *a = test_new_image(32, 32), *b = test_new_image(32, 32);
    for (uint32_t y = 0; y < 32; y++)
        for (uint32_t x = 0; x < 32; x++) {
            double v = 0.3 + 0 * x; /* uniform: the pixel measure is then 1 % too */
            test_set_pixel(b, x, y, v, v, v);
            test_set_pixel(a, x, y, 1.01 * v, 1.01 * v, 1.01 * v);
        }
    rad_image_difference d;
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, NULL) == RAD_OK);
    CHECK_NEAR(d.block_relative_rmse, 0.01, 1e-5);
    CHECK_NEAR(d.pixel_relative_rmse, 0.01, 1e-5);
    CHECK(d.pixels_left_out == 0);
    /* a light at (10, 10) in both, brighter in a: left out with its 5 x 5 neighbourhood */
    test_set_pixel(b, 10, 10, 50, 50, 50);
    test_set_pixel(a, 10, 10, 80, 80, 80);
    CHECK(rad_image_compare(a, b, NULL, &d, NULL, NULL) == RAD_OK);
    CHECK(d.pixels_left_out == 25);
    CHECK_NEAR(d.pixel_relative_rmse, 0.01, 1e-5);
    rad_image_destroy(a);
    rad_image_destroy(b);
}

int main(void)
{
    test_accuracy_measures();
    test_identical();
    test_one_block();
    test_scale();
    test_partial_blocks();
    test_black_reference();
    test_refusals();
    test_false_colour();
    test_cli();
    return test_finish("test_compare");
}
