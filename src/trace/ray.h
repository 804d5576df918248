/*
 * ray.h - filling a rad_ray from double-precision vectors (internal, inline).
 */
#ifndef RAD_TRACE_RAY_H
#define RAD_TRACE_RAY_H

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

#endif
