/*
 * rgb.h - arithmetic on rad_rgb (linear RGB in double), all inline.
 */
#ifndef RAD_CORE_RGB_H
#define RAD_CORE_RGB_H

#include <math.h>
#include <stdbool.h>

#include "radiosity.h"

static inline rad_rgb rgb_add(rad_rgb a, rad_rgb b) { return (rad_rgb){a.r + b.r, a.g + b.g, a.b + b.b}; }
static inline rad_rgb rgb_mul(rad_rgb a, rad_rgb b) { return (rad_rgb){a.r * b.r, a.g * b.g, a.b * b.b}; }
static inline rad_rgb rgb_max0(rad_rgb a)
{
    return (rad_rgb){a.r > 0 ? a.r : 0, a.g > 0 ? a.g : 0, a.b > 0 ? a.b : 0};
}
static inline rad_rgb rgb_scale(rad_rgb a, double s) { return (rad_rgb){a.r * s, a.g * s, a.b * s}; }
static inline void rgb_add_to(rad_rgb *sum, rad_rgb a)
{
    sum->r += a.r;
    sum->g += a.g;
    sum->b += a.b;
}
static inline bool rgb_is_zero(rad_rgb a) { return !(a.r != 0 || a.g != 0 || a.b != 0); }
static inline bool rgb_finite(rad_rgb a) { return isfinite(a.r) && isfinite(a.g) && isfinite(a.b); }
/* Finite and >= 0 in every channel. */
static inline bool rgb_valid(rad_rgb a) { return rgb_finite(a) && a.r >= 0 && a.g >= 0 && a.b >= 0; }
static inline double rgb_luminance(rad_rgb a) { return 0.2126 * a.r + 0.7152 * a.g + 0.0722 * a.b; }

#endif
