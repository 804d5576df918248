/*
 * hemisphere.h - directions over the hemisphere of a unit normal (internal, inline): the
 * frame around it and the cosine-weighted direction of a point of the unit square, which
 * every gather, sky sample and cosine-weighted ray uses.
 */
#ifndef RAD_CORE_HEMISPHERE_H
#define RAD_CORE_HEMISPHERE_H

#include <math.h>

#include "core/sine_cosine.h"
#include "core/vec3.h"

/* Two unit vectors completing the unit normal n to an orthonormal frame. */
static inline void hemisphere_frame(rad_vec3 n, rad_vec3 *a, rad_vec3 *b)
{
    rad_vec3 helper = fabs(n.x) < 0.6 ? v3(1, 0, 0) : fabs(n.y) < 0.6 ? v3(0, 1, 0) : v3(0, 0, 1);
    *a = v3_normalize(v3_cross(helper, n));
    *b = v3_cross(n, *a);
}

/* The direction of (u1, u2) in [0,1)^2 with density cos / pi around n (Malley's method:
 * a uniform point of the unit disc lifted onto the hemisphere), its azimuth turned by
 * `turn` radians; *cos_theta receives its cosine to n (NULL: not wanted). */
static inline rad_vec3 cosine_direction(rad_vec3 n, rad_vec3 a, rad_vec3 b, double u1, double u2,
                                        double turn, double *cos_theta)
{
    double r = sqrt(u1), phi = 2 * RAD_PI * u2 + turn, c = sqrt(fmax(0, 1 - u1));
    if (cos_theta)
        *cos_theta = c;
    double sine, cosine;
    sine_cosine(phi, &sine, &cosine);
    return v3_add(v3_scale(n, c), v3_add(v3_scale(a, r * cosine), v3_scale(b, r * sine)));
}

#endif
