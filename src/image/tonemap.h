/*
 * tonemap.h - from linear radiance to 8-bit sRGB: PNG output and lit-mesh vertex colours
 * (internal).
 *
 * The PNG pipeline per channel is: radiance * scale, clamp to [0,1], the sRGB transfer
 * curve, round to 8 bits. The scale is 2^exposure, or chosen automatically so that the
 * 95th percentile of pixel luminance lands on 0.9. This is display only: the HDR formats
 * store radiance untouched.
 */
#ifndef RAD_IMAGE_TONEMAP_H
#define RAD_IMAGE_TONEMAP_H

#include <stddef.h>
#include <stdint.h>

#include "radiosity.h"

/* Automatic exposure: this percentile of the luminance of the lit pixels (luminance > 0)... */
#define RAD_TONEMAP_AUTO_PERCENTILE 0.95
/* ...is scaled to this linear value (a little below white, so highlights keep some detail). */
#define RAD_TONEMAP_AUTO_TARGET 0.9

/* Rec. 709 / sRGB luminance of linear RGB: 0.2126 R + 0.7152 G + 0.0722 B. */
double rad_tonemap_luminance(double r, double g, double b);

/* The exact piecewise sRGB transfer curve (IEC 61966-2-1) of a linear value; the input is
 * clamped to [0,1] first and NaN counts as 0. Returns the encoded value in [0,1]. */
double rad_tonemap_srgb_encode(double linear);

/* Clamp, sRGB encode, round to the nearest of 0..255. */
uint8_t rad_tonemap_srgb8(double linear);

/* The automatic multiplier for a set of luminances, whatever they come from (the pixels
 * of an image, the vertices of a lit mesh): RAD_TONEMAP_AUTO_TARGET / (the
 * RAD_TONEMAP_AUTO_PERCENTILE quantile of the finite values > 0, linearly interpolated
 * between order statistics); 1 when there is none. Reorders `luminance`. */
double rad_tonemap_auto_scale(double *luminance, size_t count);

/* The multiplier 2^exposure, or, with options NULL or not fixed_exposure, the automatic
 * one: RAD_TONEMAP_AUTO_TARGET / (the RAD_TONEMAP_AUTO_PERCENTILE quantile of the finite
 * luminances > 0, linearly interpolated between order statistics); 1 when no pixel has
 * luminance > 0. Returns RAD_ERR_INVALID for an infinite exposure and RAD_ERR_NOMEM
 * when the automatic one cannot get its temporary array; the caller words the message. */
rad_status rad_tonemap_scale(const rad_image *image, const rad_image_write_options *options,
                             double *scale);

#endif
