/*
 * vec3.h - double-precision 3-vector arithmetic on rad_vec3, all inline.
 */
#ifndef RAD_CORE_VEC3_H
#define RAD_CORE_VEC3_H

#include <math.h>

#include "radiosity.h"
#include "core/minmax.h"

#define RAD_PI 3.14159265358979323846

static inline rad_vec3 v3(double x, double y, double z) { return (rad_vec3){x, y, z}; }
static inline rad_vec3 v3_add(rad_vec3 a, rad_vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline rad_vec3 v3_sub(rad_vec3 a, rad_vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline rad_vec3 v3_scale(rad_vec3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline double v3_dot(rad_vec3 a, rad_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline rad_vec3 v3_cross(rad_vec3 a, rad_vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double v3_length(rad_vec3 a) { return sqrt(v3_dot(a, a)); }
static inline rad_vec3 v3_normalize(rad_vec3 a)
{
    double l = v3_length(a);
    return l > 0 ? v3_scale(a, 1.0 / l) : a;
}
static inline rad_vec3 v3_lerp(rad_vec3 a, rad_vec3 b, double t)
{
    return v3(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.z + (b.z - a.z) * t);
}
/* The axis-aligned box of `count` points; both corners 0 when there are none. */
static inline void v3_bounds(const rad_vec3 *points, size_t count, rad_vec3 *lo, rad_vec3 *hi)
{
    rad_vec3 a = v3(INFINITY, INFINITY, INFINITY), b = v3(-INFINITY, -INFINITY, -INFINITY);
    for (size_t i = 0; i < count; i++) {
        rad_vec3 p = points[i];
        a = v3(fmin(a.x, p.x), fmin(a.y, p.y), fmin(a.z, p.z));
        b = v3(fmax(b.x, p.x), fmax(b.y, p.y), fmax(b.z, p.z));
    }
    if (count == 0)
        a = b = v3(0, 0, 0);
    *lo = a;
    *hi = b;
}

static inline int v3_is_finite(rad_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

/* The closed polygon `points` with each corner within `relative` of its extent (largest
 * coordinate difference from the first corner) of the corner before it dropped, the last
 * one against the first too: a clip through a corner makes it twice, a hair apart, and an
 * edge of no length has no direction. Returns the corners kept. */
static inline unsigned v3_drop_repeated(rad_vec3 *points, unsigned count, double relative)
{
    if (count < 2)
        return count;
    double extent = 0;
    for (unsigned k = 1; k < count; k++) {
        rad_vec3 d = v3_sub(points[k], points[0]);
        extent = max_d(extent, max_d(fabs(d.x), max_d(fabs(d.y), fabs(d.z))));
    }
    double tiny = relative * extent;
    unsigned kept = 1;
    for (unsigned k = 1; k < count; k++) {
        rad_vec3 d = v3_sub(points[k], points[kept - 1]);
        if (max_d(fabs(d.x), max_d(fabs(d.y), fabs(d.z))) > tiny)
            points[kept++] = points[k];
    }
    while (kept > 1) {
        rad_vec3 d = v3_sub(points[kept - 1], points[0]);
        if (max_d(fabs(d.x), max_d(fabs(d.y), fabs(d.z))) > tiny)
            break;
        kept--;
    }
    return kept;
}

#endif
