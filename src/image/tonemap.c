/*
 * tonemap.c - exposure and the sRGB curve for PNG output; see tonemap.h.
 *
 * Not a tone-mapping operator in the Reinhard sense: values above white are clipped. The
 * automatic exposure is a plain percentile so that a few very bright pixels (the light
 * source) do not darken the rest of the picture.
 */
#include "image/tonemap.h"

#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/order.h"
#include "core/rgb.h"

/* Below this linear value the sRGB curve is the straight line 12.92 x (IEC 61966-2-1). */
#define SRGB_LINEAR_KNEE 0.0031308

double rad_tonemap_luminance(double r, double g, double b)
{
    return rgb_luminance((rad_rgb){r, g, b});
}

double rad_tonemap_srgb_encode(double linear)
{
    if (!(linear > 0)) /* also NaN */
        return 0;
    if (linear >= 1)
        return 1;
    if (linear < SRGB_LINEAR_KNEE)
        return 12.92 * linear;
    return 1.055 * pow(linear, 1 / 2.4) - 0.055;
}

uint8_t rad_tonemap_srgb8(double linear)
{
    return (uint8_t)(rad_tonemap_srgb_encode(linear) * 255 + 0.5);
}

double rad_tonemap_auto_scale(double *luminance, size_t count)
{
    size_t lit = 0; /* the finite values > 0, moved to the front */
    for (size_t i = 0; i < count; i++)
        if (luminance[i] > 0 && isfinite(luminance[i]))
            luminance[lit++] = luminance[i];
    if (lit == 0)
        return 1;
    qsort(luminance, lit, sizeof(*luminance), rad_compare_doubles);
    double position = RAD_TONEMAP_AUTO_PERCENTILE * (double)(lit - 1);
    size_t below = (size_t)position;
    double fraction = position - (double)below;
    double quantile = luminance[below];
    if (below + 1 < lit)
        quantile += fraction * (luminance[below + 1] - luminance[below]);
    return RAD_TONEMAP_AUTO_TARGET / quantile;
}

/* The automatic multiplier of an image's pixels; see rad_tonemap_scale. */
static rad_status auto_scale(const rad_image *image, double *scale)
{
    size_t pixels = (size_t)image->width * image->height; /* fits: the image exists */
    double *luminance = rad_alloc_array(pixels, sizeof(*luminance));
    if (!luminance)
        return RAD_ERR_NOMEM;
    for (size_t i = 0; i < pixels; i++) {
        const float *p = image->rgb + 3 * i;
        luminance[i] = rad_tonemap_luminance(p[0], p[1], p[2]);
    }
    *scale = rad_tonemap_auto_scale(luminance, pixels);
    free(luminance);
    return RAD_OK;
}

rad_status rad_tonemap_scale(const rad_image *image, const rad_image_write_options *options,
                             double *scale)
{
    if (!options || !options->fixed_exposure)
        return auto_scale(image, scale);
    if (!isfinite(options->exposure))
        return RAD_ERR_INVALID;
    *scale = exp2(options->exposure);
    return RAD_OK;
}
