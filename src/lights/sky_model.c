/*
 * sky_model.c - PLACEHOLDER until the sky models land: uniform and CIE overcast.
 */
#include <math.h>

#include "lights/sky_model.h"
#include "radiosity.h"

double rad_sky_relative_luminance(rad_sky_model sky, double elevation, double gamma,
                                  double sun_elevation)
{
    (void)gamma;
    (void)sun_elevation;
    if (!(elevation > 0))
        return 0;
    if (sky == RAD_SKY_CIE_OVERCAST)
        return (1 + 2 * sin(elevation)) / 3;
    return 1;
}

double sky_horizontal_illuminance_factor(rad_sky_model sky, double sun_elevation)
{
    (void)sun_elevation;
    return sky == RAD_SKY_CIE_OVERCAST ? 7 * 3.14159265358979323846 / 9 : 3.14159265358979323846;
}
