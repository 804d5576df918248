/*
 * sky_model.h - sky domes (internal): the horizontal illuminance of a sky model, and the
 * angles of a world direction on the sky, for the light-sampling code. The luminance
 * distributions themselves are public: rad_sky_relative_luminance (radiosity.h).
 *
 * Conventions, shared by skies and environment maps: azimuth in radians clockwise from
 * north seen from above (north 0, east pi/2), in [0, 2 pi); elevation in radians above the
 * horizon, in [-pi/2, pi/2]; east = north x up.
 */
#ifndef RAD_LIGHTS_SKY_MODEL_H
#define RAD_LIGHTS_SKY_MODEL_H

#include "radiosity.h"

/* The illuminance of an unobstructed horizontal plane under the sky divided by the zenith
 * luminance: the integral over the upper hemisphere of (L / L_z) sin(h) dOmega. pi for the
 * uniform sky, 7 pi / 9 for the overcast one (closed forms); for the clear sky the
 * quadrature below, to about 1e-9 relative. The sun's elevation (radians) matters for the
 * clear sky only. 0 for an unknown model. */
double sky_horizontal_illuminance_factor(rad_sky_model sky, double sun_elevation);

/* The same integral by quadrature whatever the model (composite Gauss-Legendre in
 * elevation and in azimuth relative to the sun, graded toward the sun, whose circumsolar
 * term has a cone-shaped kink there): what the clear sky uses; the tests hold it to the
 * closed forms of the other two. */
double sky_horizontal_illuminance_quadrature(rad_sky_model sky, double sun_elevation);

/* The azimuth and elevation (radians, conventions above) of `direction` (finite, any
 * length; a zero one gives 0, 0) in the frame of `up` and `north` (unit, perpendicular).
 * A sky or map turned by `rotate_degrees` about up (clockwise seen from above: 90 brings
 * what was north to the east) is looked up at the returned azimuth: the world azimuth
 * minus the rotation. */
void sky_angles(rad_vec3 direction, rad_vec3 up, rad_vec3 north, double rotate_degrees,
                double *azimuth, double *elevation);

/* The unit direction at (azimuth, elevation): the inverse of sky_angles with no rotation
 * (with a rotation r degrees, pass azimuth + r in radians). */
rad_vec3 sky_direction(double azimuth, double elevation, rad_vec3 up, rad_vec3 north);

#endif
