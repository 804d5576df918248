/*
 * contour.c - Lambert's contour formula with half-space clipping, see contour.h.
 */
#include "geometry/contour.h"

#include <math.h>

#include "core/vec3.h"
#include "geometry/flat_pieces.h"

/* atan2(y, x) for y >= 0, in [0, pi], to about 2e-10 absolute: the contour sum's hot spot.
 * The argument is reduced to [0, tan(pi/12)] (by swapping to min/max and the tangent
 * addition formula), where the Taylor series to degree 13 is exact to ~2e-10. */
static inline double angle_between(double y, double x)
{
    const double tan_15 = 0.26794919243112270, sqrt_3 = 1.7320508075688772;
    double ax = fabs(x);
    double hi = y > ax ? y : ax, lo = y > ax ? ax : y;
    if (!(hi > 0))
        return 0;
    double a = lo / hi, base = 0;
    if (a > tan_15) {
        a = (a * sqrt_3 - 1) / (sqrt_3 + a);
        base = RAD_PI / 6;
    }
    double a2 = a * a;
    double r = base + a * (1 + a2 * (-1.0 / 3 + a2 * (1.0 / 5 + a2 * (-1.0 / 7 + a2 * (1.0 / 9 +
                      a2 * (-1.0 / 11 + a2 * (1.0 / 13)))))));
    if (y > ax)
        r = RAD_PI / 2 - r;
    if (x < 0)
        r = RAD_PI - r;
    return r;
}

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
        double beta = angle_between(sine, v3_dot(a, b));
        sum += beta * v3_dot(n, c) / sine;
    }
    return fabs(sum) / (2.0 * RAD_PI);
}

double contour_point_to_flat_polygon(flat_point x, double height, rad_vec3 n_local,
                                     const flat_point *polygon, unsigned count)
{
    /* r_k = (u_k - x.u, v_k - x.v, -height) in the plane's frame, clipped to the
     * half-space n . r >= 0 as contour_point_to_polygon does */
    double ru[CONTOUR_MAX_VERTICES], rv[CONTOUR_MAX_VERTICES], h[CONTOUR_MAX_VERTICES];
    double below = n_local.z * height;
    unsigned in_front = 0;
    for (unsigned k = 0; k < count; k++) {
        ru[k] = polygon[k].u - x.u;
        rv[k] = polygon[k].v - x.v;
        h[k] = n_local.x * ru[k] + n_local.y * rv[k] - below;
        in_front += h[k] > 0;
    }
    if (in_front == 0)
        return 0;
    double cu[CONTOUR_MAX_VERTICES], cv[CONTOUR_MAX_VERTICES];
    unsigned kept = 0;
    if (in_front == count) {
        for (unsigned k = 0; k < count; k++) {
            cu[k] = ru[k];
            cv[k] = rv[k];
        }
        kept = count;
    } else {
        for (unsigned k = 0; k < count; k++) {
            unsigned next = k + 1 == count ? 0 : k + 1;
            if (h[k] >= 0) {
                cu[kept] = ru[k];
                cv[kept++] = rv[k];
            }
            if ((h[k] > 0 && h[next] < 0) || (h[k] < 0 && h[next] > 0)) {
                double t = h[k] / (h[k] - h[next]);
                cu[kept] = ru[k] + (ru[next] - ru[k]) * t;
                cv[kept++] = rv[k] + (rv[next] - rv[k]) * t;
            }
        }
    }
    /* every corner at z = -height: a x b = (height (b.v - a.v), height (a.u - b.u),
     * a.u b.v - a.v b.u), a . b = a.u b.u + a.v b.v + height^2 */
    double height2 = height * height, sum = 0;
    for (unsigned k = 0; k < kept; k++) {
        unsigned next = k + 1 == kept ? 0 : k + 1;
        double au = cu[k], av = cv[k], bu = cu[next], bv = cv[next];
        double c_u = height * (bv - av), c_v = height * (au - bu), c_z = au * bv - av * bu;
        double sine = sqrt(c_u * c_u + c_v * c_v + c_z * c_z);
        if (sine <= 0)
            continue;
        double beta = angle_between(sine, au * bu + av * bv + height2);
        sum += beta * (n_local.x * c_u + n_local.y * c_v + n_local.z * c_z) / sine;
    }
    return fabs(sum) / (2.0 * RAD_PI);
}
