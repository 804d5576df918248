/*
 * ray.h - filling a rad_ray from double-precision vectors (internal, inline).
 */
#ifndef RAD_TRACE_RAY_H
#define RAD_TRACE_RAY_H

#include "core/tolerance.h"
#include "core/vec3.h"
#include "radiosity.h"

static inline void ray_set(rad_ray *ray, rad_vec3 origin, rad_vec3 direction, double t_near,
                           double t_far)
{
    ray->origin[0] = (float)origin.x;
    ray->origin[1] = (float)origin.y;
    ray->origin[2] = (float)origin.z;
    ray->direction[0] = (float)direction.x;
    ray->direction[1] = (float)direction.y;
    ray->direction[2] = (float)direction.z;
    ray->t_near = (float)t_near;
    ray->t_far = (float)t_far;
}

/* The segment from a to b, its ends left out (t from RAD_SEGMENT_END_EPSILON to 1 minus
 * it, so neither end's own surface counts); coincident points give an empty segment. */
static inline void ray_segment(rad_ray *ray, rad_vec3 a, rad_vec3 b)
{
    ray_set(ray, a, v3(b.x - a.x, b.y - a.y, b.z - a.z), RAD_SEGMENT_END_EPSILON,
            1.0f - RAD_SEGMENT_END_EPSILON);
    if (!(ray->direction[0] != 0 || ray->direction[1] != 0 || ray->direction[2] != 0)) {
        ray->direction[0] = 1;
        ray->t_near = 1;
        ray->t_far = 0;
    }
}

#endif
