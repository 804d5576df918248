/*
 * compare.c - rad_image_compare: how far an image a is from a reference b.
 *
 * Two passes over the pixels. The first checks that every value is finite and sums the
 * per-pixel measures (squared error, relative error, means) and the block means; only when
 * it succeeds does the second paint the optional false-colour picture, so a failed call
 * leaves `false_colour` untouched. Everything is accumulated in double.
 *
 * Conventions (the header's contract, spelled out):
 *   - |v|_1 of an RGB triple is |r| + |g| + |b|; "black" means |v|_1 = 0.
 *   - Blocks tile the image from its top-left corner; a partial block at the right or
 *     bottom edge is left out, so an image smaller than one block has no blocks (then
 *     block_count = 0, worst_block_error = 0 and blocks_within_tolerance = 0).
 *   - A block whose reference mean is black has relative difference 0 when a's mean is
 *     black too, and infinity (HUGE_VAL) otherwise.
 *   - mean_relative_error is 0 when the reference is black everywhere.
 *   - A block is within tolerance when its relative difference is <= block_tolerance.
 *
 * Not here: reading the images (image_read.c) or writing the picture (image_write.c).
 */
#include <inttypes.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"

/* The false colour divides by max(|b|_1, this) (radiance, sum of three channels): far below
 * any radiance a float image holds in practice, so a black reference pixel shows blue where
 * a is black as well and red wherever a is not. */
#define COMPARE_SMALLEST_REFERENCE 1e-30
/* A reference pixel this many times brighter than the median shows a light source. */
#define COMPARE_LIGHT_OVER_MEDIAN 20.0

/* The false-colour ramp: blue, cyan, green, yellow, red at relative difference 0, 1/4,
 * 1/2, 3/4 and 1 (and above), linear in between. Corners are 0 or 1 exactly, so a PNG
 * written at exposure 0 shows them exactly. */
static const float ramp[5][3] = {
    {0, 0, 1}, /* blue: equal */
    {0, 1, 1}, /* cyan */
    {0, 1, 0}, /* green */
    {1, 1, 0}, /* yellow */
    {1, 0, 0}, /* red: 100 % or more */
};

static void ramp_colour(double d, float *out)
{
    double t = fmin(fmax(d, 0.0), 1.0) * 4; /* position along the ramp, 0..4 */
    int k = t >= 4 ? 3 : (int)t;            /* segment ramp[k] -> ramp[k + 1] */
    float f = (float)(t - k);
    for (int c = 0; c < 3; c++)
        out[c] = ramp[k][c] + f * (ramp[k + 1][c] - ramp[k][c]);
}

static double norm1(const float *p)
{
    return fabs((double)p[0]) + fabs((double)p[1]) + fabs((double)p[2]);
}

static double difference1(const float *p, const float *q)
{
    return fabs((double)p[0] - q[0]) + fabs((double)p[1] - q[1]) + fabs((double)p[2] - q[2]);
}

static bool pixel_finite(const float *p)
{
    return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
}

static rad_status not_finite(rad_error *error, const char *which, const float *p, size_t index,
                             uint32_t width)
{
    return rad_fail(error, RAD_ERR_INVALID,
                    "pixel (%zu, %zu) of %s is not finite (%g %g %g)", index % width,
                    index / width, which, (double)p[0], (double)p[1], (double)p[2]);
}

static bool image_ok(const rad_image *image)
{
    return image && image->rgb && image->width > 0 && image->height > 0;
}

/* The relative difference of two blocks' mean colours (sums work as well: the pixel
 * count cancels). */
static double block_relative(const double *sum_a, const double *sum_b)
{
    double diff = fabs(sum_a[0] - sum_b[0]) + fabs(sum_a[1] - sum_b[1]) +
                  fabs(sum_a[2] - sum_b[2]);
    double ref = fabs(sum_b[0]) + fabs(sum_b[1]) + fabs(sum_b[2]);
    if (ref > 0)
        return diff / ref;
    return diff > 0 ? HUGE_VAL : 0.0;
}

static double luminance3(const float *p)
{
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

static int compare_luminance(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* The median luminance of an image; false when out of memory. */
static bool median_luminance(const rad_image *image, size_t pixels, double *median)
{
    double *values = rad_alloc_array(pixels ? pixels : 1, sizeof(*values));
    if (!values)
        return false;
    for (size_t i = 0; i < pixels; i++)
        values[i] = luminance3(image->rgb + 3 * i);
    qsort(values, pixels, sizeof(*values), compare_luminance);
    *median = pixels ? values[pixels / 2] : 0;
    free(values);
    return true;
}

rad_status rad_image_compare(const rad_image *a, const rad_image *b,
                             const rad_compare_options *options,
                             rad_image_difference *difference, rad_image *false_colour,
                             rad_error *error)
{
    if (difference)
        memset(difference, 0, sizeof(*difference));
    if (!image_ok(a) || !image_ok(b) || !difference)
        return rad_fail(error, RAD_ERR_INVALID,
                        "rad_image_compare: an image or the result pointer is missing");
    if (a->width != b->width || a->height != b->height)
        return rad_fail(error, RAD_ERR_INVALID,
                        "images differ in size: %" PRIu32 "x%" PRIu32 " and %" PRIu32
                        "x%" PRIu32,
                        a->width, a->height, b->width, b->height);
    if (false_colour && (!false_colour->rgb || false_colour->width != a->width ||
                         false_colour->height != a->height))
        return rad_fail(error, RAD_ERR_INVALID,
                        "false-colour image is %" PRIu32 "x%" PRIu32
                        ", the images compared %" PRIu32 "x%" PRIu32,
                        false_colour->width, false_colour->height, a->width, a->height);

    uint32_t block = RAD_DEFAULT_BLOCK_SIZE;
    double tolerance = RAD_DEFAULT_BLOCK_TOLERANCE;
    if (options && options->block_size > 0)
        block = options->block_size;
    if (options && options->block_tolerance != 0) {
        tolerance = options->block_tolerance;
        if (!(tolerance > 0)) /* negative or NaN */
            return rad_fail(error, RAD_ERR_INVALID,
                            "block tolerance %g is not a positive number", tolerance);
    }

    const uint32_t width = a->width, height = a->height;
    const size_t pixels = (size_t)width * height; /* fits: the images exist */

    /* Pass 1: per-pixel measures, with the finiteness check. */
    double squared = 0, relative = 0, sum_a[3] = {0}, sum_b[3] = {0};
    size_t lit = 0; /* reference pixels that are not black */
    for (size_t i = 0; i < pixels; i++) {
        const float *p = a->rgb + 3 * i, *q = b->rgb + 3 * i;
        if (!pixel_finite(p))
            return not_finite(error, "image a", p, i, width);
        if (!pixel_finite(q))
            return not_finite(error, "image b (the reference)", q, i, width);
        for (int c = 0; c < 3; c++) {
            double d = (double)p[c] - q[c];
            squared += d * d;
            sum_a[c] += p[c];
            sum_b[c] += q[c];
        }
        double ref = norm1(q);
        if (ref > 0) {
            relative += difference1(p, q) / ref;
            lit++;
        }
    }

    /* Whole blocks only. */
    const uint32_t blocks_x = width / block, blocks_y = height / block;
    uint32_t within = 0, worst_x = 0, worst_y = 0;
    double worst = 0;
    for (uint32_t by = 0; by < blocks_y; by++)
        for (uint32_t bx = 0; bx < blocks_x; bx++) {
            double block_a[3] = {0}, block_b[3] = {0};
            size_t x0 = (size_t)bx * block, y0 = (size_t)by * block;
            for (size_t y = y0; y < y0 + block; y++) {
                const float *p = a->rgb + 3 * (y * width + x0);
                const float *q = b->rgb + 3 * (y * width + x0);
                for (size_t k = 0; k < 3 * (size_t)block; k++) {
                    block_a[k % 3] += p[k];
                    block_b[k % 3] += q[k];
                }
            }
            double e = block_relative(block_a, block_b);
            if (e <= tolerance)
                within++;
            if (e > worst) {
                worst = e;
                worst_x = (uint32_t)x0;
                worst_y = (uint32_t)y0;
            }
        }
    const uint32_t block_count = blocks_x * blocks_y; /* <= pixels / block^2 */

    /* The render-accuracy measures on luminance (the definitions, in the header). */
    {
        double mean_y = 0;
        for (size_t i = 0; i < pixels; i++)
            mean_y += luminance3(b->rgb + 3 * i);
        mean_y /= (double)pixels;
        double floor_y = 1e-3 * mean_y, sum_sq = 0;
        for (uint32_t by = 0; by < blocks_y; by++)
            for (uint32_t bx = 0; bx < blocks_x; bx++) {
                double ya = 0, yb = 0;
                for (size_t y = (size_t)by * block; y < (size_t)(by + 1) * block; y++)
                    for (size_t x = (size_t)bx * block; x < (size_t)(bx + 1) * block; x++) {
                        ya += luminance3(a->rgb + 3 * (y * width + x));
                        yb += luminance3(b->rgb + 3 * (y * width + x));
                    }
                ya /= (double)block * block;
                yb /= (double)block * block;
                double d = fabs(ya - yb) / fmax(yb, floor_y);
                sum_sq += d * d;
            }
        difference->block_relative_rmse =
            blocks_x > 0 && blocks_y > 0 ? sqrt(sum_sq / ((double)blocks_x * blocks_y)) : 0;
        /* the light seen directly: far above the median, and 2 pixels around it */
        double median;
        if (!median_luminance(b, pixels, &median))
            return rad_fail(error, RAD_ERR_NOMEM, "out of memory comparing %" PRIu32 "x%" PRIu32
                            " images", width, height);
        double pixel_sq = 0, kept_sum = 0;
        size_t kept = 0, left_out = 0;
        for (uint32_t y = 0; y < height; y++)
            for (uint32_t x = 0; x < width; x++) {
                bool near_light = false;
                for (int dy = -2; dy <= 2 && !near_light; dy++)
                    for (int dx = -2; dx <= 2 && !near_light; dx++) {
                        int64_t xx = (int64_t)x + dx, yy = (int64_t)y + dy;
                        if (xx < 0 || yy < 0 || xx >= width || yy >= height)
                            continue;
                        near_light = luminance3(b->rgb + 3 * ((size_t)yy * width + (size_t)xx)) >
                                     COMPARE_LIGHT_OVER_MEDIAN * median;
                    }
                if (near_light) {
                    left_out++;
                    continue;
                }
                size_t i = (size_t)y * width + x;
                double ya = luminance3(a->rgb + 3 * i), yb = luminance3(b->rgb + 3 * i);
                pixel_sq += (ya - yb) * (ya - yb);
                kept_sum += yb;
                kept++;
            }
        difference->pixel_relative_rmse =
            kept && kept_sum > 0 ? sqrt(pixel_sq / (double)kept) / (kept_sum / (double)kept) : 0;
        difference->pixels_left_out = (uint32_t)left_out;
    }

    /* Pass 2: the picture, now that every pixel is known to be finite. Each pixel is read
     * before it is written, so false_colour may even be a or b. */
    if (false_colour)
        for (size_t i = 0; i < pixels; i++) {
            const float *p = a->rgb + 3 * i, *q = b->rgb + 3 * i;
            double d = difference1(p, q) / fmax(norm1(q), COMPARE_SMALLEST_REFERENCE);
            ramp_colour(d, false_colour->rgb + 3 * i);
        }

    const double n = (double)pixels;
    difference->rmse = sqrt(squared / (3 * n));
    difference->mean_relative_error = lit ? relative / (double)lit : 0.0;
    difference->mean_a = (rad_rgb){sum_a[0] / n, sum_a[1] / n, sum_a[2] / n};
    difference->mean_b = (rad_rgb){sum_b[0] / n, sum_b[1] / n, sum_b[2] / n};
    difference->worst_block_error = worst;
    difference->worst_block_x = worst_x;
    difference->worst_block_y = worst_y;
    difference->block_count = block_count;
    difference->blocks_within = within;
    difference->blocks_within_tolerance = block_count ? (double)within / block_count : 0.0;
    return RAD_OK;
}
