/*
 * gather.c - what a final-gather ray meets of a radiosity solution (gather.h).
 */
#include "render/gather.h"

#include "core/rgb.h"
#include "core/vec3.h"

void gather_trace(const gather_view *view, const rad_ray *rays, uint32_t count, rad_hit *hits)
{
    if (!view->locator) {
        rad_tracer_intersect_coherent(view->tracer, rays, count, hits);
        return;
    }
    rad_tracer_intersect_coherent(view->scene_tracer, rays, count, hits);
    for (uint32_t k = 0; k < count; k++)
        if (!display_locate(view->locator, &hits[k]))
            rad_tracer_intersect(view->tracer, &rays[k], 1, &hits[k]);
}

rad_rgb gather_seen(const gather_view *view, const rad_ray *ray, const rad_hit *hit)
{
    if (hit->triangle == RAD_NO_HIT) {
        if (view->lights && view->lights->has_sky)
            return light_set_sky_radiance(view->lights,
                                          v3(ray->direction[0], ray->direction[1],
                                             ray->direction[2]));
        return (rad_rgb){0, 0, 0};
    }
    if (hit->front) {
        const uint32_t *v = view->triangles[hit->triangle];
        double u = hit->u, w = hit->v;
        return rgb_add(rgb_scale(view->reflected[v[0]], 1 - u - w),
                       rgb_add(rgb_scale(view->reflected[v[1]], u),
                               rgb_scale(view->reflected[v[2]], w)));
    }
    uint32_t twin = view->mesh->patches[view->patch_of[hit->triangle]].twin;
    if (!twin || !view->B)
        return (rad_rgb){0, 0, 0};
    return rgb_scale(rgb_max0(rgb_add(view->B[twin - 1], rgb_scale(view->exitance[twin - 1], -1))),
                     1 / RAD_PI);
}
