/*
 * sun_position.c - PLACEHOLDER until the solar position algorithm lands.
 */
#include "core/error.h"
#include "radiosity.h"

rad_status rad_sun_position(const rad_place_time *when, double *azimuth_degrees,
                            double *elevation_degrees, rad_error *error)
{
    (void)when;
    *azimuth_degrees = 0;
    *elevation_degrees = 0;
    return rad_fail(error, RAD_ERR_UNSUPPORTED, "the sun's position is not available yet");
}
