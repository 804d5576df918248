/*
 * environment_map.h - looking up an equirectangular radiance map (internal).
 *
 * The map is a rad_image, width = 2 x height, linear RGB, row 0 at the top. Its top edge
 * is the zenith and its bottom edge the nadir: pixel row y has its centre at elevation
 * pi (0.5 - (y + 0.5) / height). Its centre column (u = 0.5, u = x / width across the
 * image) looks north and u grows toward the east: azimuth (radians, clockwise from north
 * seen from above, as in sky_model.h) = 2 pi (u - 0.5), so column x has its centre at
 * azimuth 2 pi ((x + 0.5) / width - 0.5). The world direction's angles come from
 * sky_angles (sky_model.h), which also applies the light's rotation.
 */
#ifndef RAD_LIGHTS_ENVIRONMENT_MAP_H
#define RAD_LIGHTS_ENVIRONMENT_MAP_H

#include "radiosity.h"

/* The radiance toward (azimuth, elevation), radians: bilinear between the four nearest
 * pixel centres, wrapping around in azimuth (any value) and clamped to the first and last
 * rows beyond their centres (elevation is clamped to [-pi/2, pi/2]). Black for a NULL or
 * empty map or a non-finite angle. Trusts the map's size and pixels. */
rad_rgb environment_radiance(const rad_image *map, double azimuth, double elevation);

#endif
