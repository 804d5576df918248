/*
 * polygon_integral.h - the adaptive integral of a point function over a convex polygon.
 *
 * The outer integral of a polygon-to-polygon transfer: G = int over P of f(x) dA, with f
 * the exact point-to-polygon factor (contour.h), with or without shadows. Each fan
 * triangle (0, k, k + 1) of P gets the 7-point degree-5 rule (Radon; Strang and Fix),
 * compared with the same rule on its 4 children, and is split further where the two
 * disagree, to a relative tolerance; what is left at the depth limit is the error bound.
 */
#ifndef RAD_GEOMETRY_POLYGON_INTEGRAL_H
#define RAD_GEOMETRY_POLYGON_INTEGRAL_H

#include <stdbool.h>

#include "radiosity.h"

typedef double (*polygon_point_fn)(void *context, rad_vec3 x);

typedef struct polygon_integral {
    polygon_point_fn f;
    void *context;
    int max_depth;      /* deepest split of a fan triangle (4^depth cells at most) */
    const bool *failed; /* when it becomes true (set by f), the integral stops refining */
} polygon_integral;

/* int over the convex polygon (count corners, counter-clockwise) of f, to the relative
 * tolerance `accuracy` of each fan triangle's value; *bound receives the estimated
 * absolute error. */
double polygon_integrate(const polygon_integral *integral, const rad_vec3 *polygon,
                         unsigned count, double accuracy, double *bound);

#endif
