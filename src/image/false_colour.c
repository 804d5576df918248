/*
 * false_colour.c - a quantity shown in false colour, with its legend: the lighting
 * designer's view of illuminance (or of radiance) as a colour scale from blue (low) through
 * cyan, green and yellow to red (high), linear or logarithmic, and beside the image a bar
 * of the scale with its values and unit written in a small built-in 3 x 5 pixel font.
 *
 * The result is an image of linear RGB in [0,1] that gives the intended sRGB colours when
 * written as PNG at a fixed exposure of 0 (rad_image_write).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/order.h"
#include "core/rgb.h"

#define LEGEND_WIDTH 96u   /* pixels added on the right */
#define GLYPH_SCALE 2u     /* the 3 x 5 font drawn at twice its size */
#define TICKS 6u

/* sRGB control colours of the scale, low to high. */
static const double scale_colours[][3] = {
    {0.05, 0.05, 0.55}, {0.0, 0.45, 1.0}, {0.0, 0.85, 0.85}, {0.1, 0.8, 0.1},
    {1.0, 0.9, 0.0},    {1.0, 0.45, 0.0}, {0.85, 0.0, 0.0},
};
#define SCALE_STOPS (sizeof(scale_colours) / sizeof(scale_colours[0]))

static double srgb_to_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

/* The colour (linear) of t in [0,1] along the scale. */
static void scale_colour(double t, float *rgb)
{
    t = fmin(fmax(t, 0), 1) * (SCALE_STOPS - 1);
    size_t i = (size_t)t;
    if (i >= SCALE_STOPS - 1)
        i = SCALE_STOPS - 2;
    double f = t - (double)i;
    for (int c = 0; c < 3; c++)
        rgb[c] = (float)srgb_to_linear((1 - f) * scale_colours[i][c] + f * scale_colours[i + 1][c]);
}

/* 3 x 5 glyphs, one row per 3 bits (bit 2 = left), for the characters a legend needs:
 * the values and the units lx, cd/m^2, W/m^2, W/sr and relative. */
typedef struct glyph {
    char c;
    unsigned char rows[5];
} glyph;

static const glyph font[] = {
    {'0', {7, 5, 5, 5, 7}}, {'1', {2, 6, 2, 2, 7}}, {'2', {7, 1, 7, 4, 7}},
    {'3', {7, 1, 7, 1, 7}}, {'4', {5, 5, 7, 1, 1}}, {'5', {7, 4, 7, 1, 7}},
    {'6', {7, 4, 7, 5, 7}}, {'7', {7, 1, 1, 2, 2}}, {'8', {7, 5, 7, 5, 7}},
    {'9', {7, 5, 7, 1, 7}}, {'.', {0, 0, 0, 0, 2}}, {'-', {0, 0, 7, 0, 0}},
    {'+', {0, 2, 7, 2, 0}}, {'e', {0, 7, 7, 4, 7}}, {'k', {4, 5, 6, 5, 5}},
    {'l', {6, 2, 2, 2, 7}}, {'x', {0, 5, 2, 5, 5}}, {'c', {0, 7, 4, 4, 7}},
    {'d', {1, 1, 7, 5, 7}}, {'m', {0, 7, 7, 5, 5}}, {'/', {1, 1, 2, 4, 4}},
    {'W', {5, 5, 5, 7, 5}}, {'^', {2, 5, 0, 0, 0}},
    {' ', {0, 0, 0, 0, 0}}, {'s', {0, 7, 4, 1, 7}}, {'r', {0, 6, 5, 4, 4}},
    {'a', {0, 3, 5, 5, 3}}, {'t', {2, 7, 2, 2, 3}}, {'i', {2, 0, 2, 2, 2}},
    {'v', {0, 5, 5, 5, 2}},
};

static void put_pixel(rad_image *image, int x, int y, float value)
{
    if (x < 0 || y < 0 || (uint32_t)x >= image->width || (uint32_t)y >= image->height)
        return;
    float *p = &image->rgb[((size_t)y * image->width + (size_t)x) * 3];
    p[0] = p[1] = p[2] = value;
}

/* Writes text with its top-left corner at (x, y), white. Unknown characters are blank. */
static void draw_text(rad_image *image, int x, int y, const char *text)
{
    for (; *text; text++, x += 4 * (int)GLYPH_SCALE) {
        const glyph *g = NULL;
        for (size_t k = 0; k < sizeof(font) / sizeof(font[0]); k++)
            if (font[k].c == *text) {
                g = &font[k];
                break;
            }
        if (!g)
            continue;
        for (int row = 0; row < 5; row++)
            for (int col = 0; col < 3; col++)
                if (g->rows[row] & (4 >> col))
                    for (unsigned dy = 0; dy < GLYPH_SCALE; dy++)
                        for (unsigned dx = 0; dx < GLYPH_SCALE; dx++)
                            put_pixel(image, x + col * (int)GLYPH_SCALE + (int)dx,
                                      y + row * (int)GLYPH_SCALE + (int)dy, 1.0f);
    }
}

/* A tick value in at most 6 characters: 0.123, 12.3, 1234, 12.3k, 1.2e+06. */
static void format_value(double v, char *text, size_t size)
{
    double a = fabs(v);
    if (a == 0)
        snprintf(text, size, "0");
    else if (a < 0.01 || a >= 1e6)
        snprintf(text, size, "%.0e", v);
    else if (a < 10)
        snprintf(text, size, "%.3g", v);
    else if (a < 10000)
        snprintf(text, size, "%.0f", v);
    else
        snprintf(text, size, "%.0fk", v / 1000);
}

static double luminance_of(const float *p)
{
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

rad_status rad_image_false_colour(const rad_image *values,
                                  const rad_false_colour_options *options, rad_image **out,
                                  rad_error *error)
{
    *out = NULL;
    rad_false_colour_options defaults = {0};
    if (!options)
        options = &defaults;
    size_t n = (size_t)values->width * values->height;
    double low = options->low, high = options->high;
    if (!(isfinite(low) && isfinite(high)) || low < 0 || (high != 0 && !(high > low)))
        return rad_fail(error, RAD_ERR_INVALID,
                        "false colour: scale %g to %g (need 0 <= low < high, or both 0)", low,
                        high);
    if (high == 0) {
        /* automatic: 0 (or the 1st percentile, logarithmic) to the 99th percentile */
        double *sorted = rad_alloc_array(n ? n : 1, sizeof(*sorted));
        if (!sorted)
            return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the false-colour scale");
        size_t m = 0;
        for (size_t k = 0; k < n; k++) {
            double y = luminance_of(&values->rgb[3 * k]);
            if (isfinite(y) && y > 0)
                sorted[m++] = y;
        }
        qsort(sorted, m, sizeof(*sorted), rad_compare_doubles);
        high = m ? sorted[(size_t)(0.99 * (double)(m - 1))] : 1;
        low = options->logarithmic ? (m ? sorted[(size_t)(0.01 * (double)(m - 1))] : high / 100) : 0;
        free(sorted);
        if (!(high > 0))
            high = 1;
        if (!(low < high))
            low = high / 100;
    }
    if (options->logarithmic && !(low > 0))
        low = high / 1000;
    uint32_t width = values->width + LEGEND_WIDTH, height = values->height;
    rad_status status = rad_image_create(width, height, out, error);
    if (status != RAD_OK)
        return status;
    rad_image *image = *out;
    double span = options->logarithmic ? log(high / low) : high - low;
    for (uint32_t y = 0; y < values->height; y++)
        for (uint32_t x = 0; x < values->width; x++) {
            double v = luminance_of(&values->rgb[((size_t)y * values->width + x) * 3]);
            double t = options->logarithmic ? (v > 0 ? log(v / low) / span : 0) : (v - low) / span;
            scale_colour(isfinite(t) ? t : 0, &image->rgb[((size_t)y * width + x) * 3]);
        }
    /* the legend: a bar from high (top) to low (bottom), ticks and values, the unit */
    int top = (int)GLYPH_SCALE * 8, bottom = (int)height - (int)GLYPH_SCALE * 4;
    int bar_x = (int)values->width + 6, bar_w = 14;
    if (bottom - top >= 20) {
        for (int y = top; y <= bottom; y++) {
            float colour[3];
            scale_colour((double)(bottom - y) / (bottom - top), colour);
            for (int x = bar_x; x < bar_x + bar_w; x++)
                memcpy(&image->rgb[((size_t)y * width + (size_t)x) * 3], colour, sizeof(colour));
        }
        for (unsigned k = 0; k < TICKS; k++) {
            double t = (double)k / (TICKS - 1);
            double v = options->logarithmic ? low * exp(t * span) : low + t * span;
            int y = bottom - (int)lround(t * (bottom - top));
            for (int x = bar_x + bar_w; x < bar_x + bar_w + 4; x++)
                put_pixel(image, x, y, 1.0f);
            char text[32];
            format_value(v, text, sizeof(text));
            draw_text(image, bar_x + bar_w + 6, y - (int)GLYPH_SCALE * 2, text);
        }
    }
    draw_text(image, bar_x, (int)GLYPH_SCALE, options->unit ? options->unit : "");
    return RAD_OK;
}
