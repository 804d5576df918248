/*
 * patch_point.h - a point of a patch from coordinates in the unit square (internal, inline).
 */
#ifndef RAD_MESH_PATCH_POINT_H
#define RAD_MESH_PATCH_POINT_H

#include "core/vec3.h"
#include "radiosity.h"

/* Point (s, t) in [0,1]^2 of a patch: bilinear on a quad; on a triangle, the unit square
 * folded onto it (uniform by area either way for a parallelogram or a triangle). */
static inline rad_vec3 patch_point(const rad_mesh *mesh, const rad_patch *p, double s, double t)
{
    const rad_vec3 *v = mesh->vertices;
    if (p->vertex_count == 4)
        return v3_add(v3_add(v3_scale(v[p->vertex[0]], (1 - s) * (1 - t)),
                             v3_scale(v[p->vertex[1]], s * (1 - t))),
                      v3_add(v3_scale(v[p->vertex[2]], s * t), v3_scale(v[p->vertex[3]], (1 - s) * t)));
    if (s + t > 1) {
        s = 1 - s;
        t = 1 - t;
    }
    return v3_add(v3_scale(v[p->vertex[0]], 1 - s - t),
                  v3_add(v3_scale(v[p->vertex[1]], s), v3_scale(v[p->vertex[2]], t)));
}

#endif
