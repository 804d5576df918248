/*
 * environment_map.c - bilinear look-up of an equirectangular radiance map, see
 * environment_map.h for the convention (zenith at the top, north in the middle column,
 * east to the right of it).
 */
#include "lights/environment_map.h"

#include <math.h>

#include "core/vec3.h"

static rad_rgb pixel(const rad_image *map, uint32_t x, uint32_t y)
{
    const float *p = map->rgb + ((size_t)y * map->width + x) * 3;
    return (rad_rgb){p[0], p[1], p[2]};
}

static rad_rgb mix(rad_rgb a, rad_rgb b, double t)
{
    return (rad_rgb){a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
}

rad_rgb environment_radiance(const rad_image *map, double azimuth, double elevation)
{
    rad_rgb black = {0, 0, 0};
    if (!map || !map->rgb || map->width == 0 || map->height == 0 || !isfinite(azimuth) ||
        !isfinite(elevation))
        return black;
    uint32_t width = map->width, height = map->height;

    /* continuous pixel coordinates: pixel centres at integers */
    double u = azimuth / (2 * RAD_PI) + 0.5;
    u -= floor(u); /* [0, 1] (1 only by rounding: wrapped below) */
    double v = 0.5 - fmin(fmax(elevation, -RAD_PI / 2), RAD_PI / 2) / RAD_PI;
    double fx = u * width - 0.5, fy = v * height - 0.5;

    double x_floor = floor(fx), y_floor = floor(fy);
    double tx = fx - x_floor, ty = fy - y_floor;
    /* x_floor in [-1, width - 1]: columns wrap around */
    uint32_t x0 = (uint32_t)((long long)x_floor + width) % width;
    uint32_t x1 = (x0 + 1) % width;
    /* rows clamp at the poles */
    uint32_t y0 = y_floor < 0 ? 0 : (uint32_t)y_floor;
    uint32_t y1 = y0 + 1;
    if (y_floor < 0)
        y1 = 0;
    if (y0 >= height)
        y0 = height - 1;
    if (y1 >= height)
        y1 = height - 1;

    rad_rgb top = mix(pixel(map, x0, y0), pixel(map, x1, y0), tx);
    rad_rgb bottom = mix(pixel(map, x0, y1), pixel(map, x1, y1), tx);
    return mix(top, bottom, ty);
}
