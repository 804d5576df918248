/*
 * contour.c - Lambert's contour formula with half-space clipping, see contour.h.
 */
#include "formfactor/contour.h"

#include <math.h>

#include "core/vec3.h"

double contour_point_to_polygon(rad_vec3 p, rad_vec3 n, const rad_vec3 *polygon,
                                unsigned count, rad_vec3 polygon_normal, double plane_epsilon)
{
    /* one-sided: p must be in front of the polygon */
    if (v3_dot(polygon_normal, v3_sub(p, polygon[0])) <= plane_epsilon)
        return 0;

    /* clip the polygon to the half-space n . (v - p) >= 0, relative to p */
    rad_vec3 clipped[CONTOUR_MAX_VERTICES];
    unsigned kept = 0;
    double height[CONTOUR_MAX_VERTICES];
    unsigned in_front = 0;
    for (unsigned k = 0; k < count; k++) {
        clipped[k] = v3_sub(polygon[k], p);
        height[k] = v3_dot(n, clipped[k]);
        in_front += height[k] > 0;
    }
    if (in_front == 0)
        return 0;
    if (in_front == count) {
        kept = count; /* the common case: wholly in front, nothing to clip */
    } else {
        rad_vec3 relative[CONTOUR_MAX_VERTICES];
        for (unsigned k = 0; k < count; k++)
            relative[k] = clipped[k];
        for (unsigned k = 0; k < count; k++) {
            unsigned next = (k + 1) % count;
            if (height[k] >= 0)
                clipped[kept++] = relative[k];
            if ((height[k] > 0 && height[next] < 0) || (height[k] < 0 && height[next] > 0)) {
                double t = height[k] / (height[k] - height[next]);
                clipped[kept++] = v3_lerp(relative[k], relative[next], t);
            }
        }
    }

    double sum = 0;
    for (unsigned k = 0; k < kept; k++) {
        rad_vec3 a = clipped[k], b = clipped[(k + 1) % kept];
        rad_vec3 c = v3_cross(a, b);
        double sine = v3_length(c); /* |a||b| sin(beta) */
        if (sine <= 0)
            continue;
        double beta = atan2(sine, v3_dot(a, b));
        sum += beta * v3_dot(n, c) / sine;
    }
    return fabs(sum) / (2.0 * RAD_PI);
}
