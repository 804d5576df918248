/*
 * polygon_integral.h - the adaptive integral of a point function over a convex polygon.
 *
 * The outer integral of a polygon-to-polygon transfer: G = int over P of f(x) dA, with f
 * the exact point-to-polygon factor (contour.h), with or without shadows. Each fan
 * triangle (0, k, k + 1) of P gets the 7-point degree-5 rule (Radon; Strang and Fix),
 * compared with the same rule on its 4 children, and is split further where the two
 * disagree, to a relative tolerance; what is left at the depth limit is the error bound.
 * Where f is not smooth (shadows), its values at the corners and edge midpoints, which no
 * rule point is near, are checked too (edge_check).
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
    /* NULL, or told which triangle (a, b, d) at which level of splitting (0 = a fan
     * triangle) the next points of f belong to, before them: f may drop what does not
     * matter there (the occluders that cannot shade it). The triangle is child `slot`
     * (0 to 3; 0 at level 0) of the one told last at level - 1 with slot `parent_slot`,
     * and that one's call is still the last at its (level - 1, parent_slot): what f keeps
     * per level and slot stays valid for the children. Returns whether f is smooth there
     * (nothing shades it): a triangle where it is not is split to at least min_depth
     * levels before its rules' agreement is believed (a shadow's edge can pass between
     * all 7 points of a large triangle, and between its children's, which then agree on a
     * wrong value). */
    bool (*cell)(void *context, rad_vec3 a, rad_vec3 b, rad_vec3 d, int level, int slot,
                 int parent_slot);
    int min_depth;
    /* where f is not smooth, f at each triangle's corners and edge midpoints must also
     * agree with what its rule points predict (polygon_integral.c) */
    bool edge_check;
} polygon_integral;

/* int over the convex polygon (count corners, counter-clockwise) of f, to the relative
 * tolerance `accuracy` of each fan triangle's value; *bound receives the estimated
 * absolute error. */
double polygon_integrate(const polygon_integral *integral, const rad_vec3 *polygon,
                         unsigned count, double accuracy, double *bound);

/* The same to the looser of the relative `accuracy` and the absolute tolerance `absolute`
 * on the whole integral (shared among the fan triangles by area). */
double polygon_integrate_within(const polygon_integral *integral, const rad_vec3 *polygon,
                                unsigned count, double accuracy, double absolute, double *bound);

#endif
