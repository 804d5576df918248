/*
 * work_plane.c - the calculation grid of lighting design: points on a horizontal plane at
 * a work-plane height (0.75 m or 0.8 m by the usual standards) over the floor, and the
 * unobstructed horizontal illuminance of the sky that daylight factors are taken against.
 */
#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"
#include "lights/sky_model.h"
#include "trace/ray.h"

#define MAX_WORK_PLANE_POINTS 10000000u

rad_status rad_work_plane(const rad_scene *scene, double height, double spacing,
                          rad_vec3 **points, uint32_t *count, rad_error *error)
{
    *points = NULL;
    *count = 0;
    if (!(height > 0 && isfinite(height)) || !(spacing > 0 && isfinite(spacing)))
        return rad_fail(error, RAD_ERR_INVALID,
                        "work plane: height %g and spacing %g must be positive", height, spacing);
    rad_vec3 up = v3_normalize(scene->up), north = rad_scene_north(scene);
    rad_vec3 east = v3_cross(north, up);
    /* the scene's extent along east, north and up */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < scene->position_count; v++) {
        rad_vec3 p = scene->positions[v];
        double c[3] = {v3_dot(p, east), v3_dot(p, north), v3_dot(p, up)};
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], c[k]);
            hi[k] = fmax(hi[k], c[k]);
        }
    }
    if (scene->position_count == 0)
        return RAD_OK;
    double nx = floor((hi[0] - lo[0]) / spacing), ny = floor((hi[1] - lo[1]) / spacing);
    if (nx < 1)
        nx = 1;
    if (ny < 1)
        ny = 1;
    if (nx * ny > MAX_WORK_PLANE_POINTS)
        return rad_fail(error, RAD_ERR_INVALID,
                        "work plane: a spacing of %g makes %.0f points (at most %u): use a "
                        "larger --spacing",
                        spacing, nx * ny, MAX_WORK_PLANE_POINTS);
    uint32_t columns = (uint32_t)nx, rows = (uint32_t)ny;
    /* centred on the extent, half a spacing in from its edges */
    double x0 = 0.5 * (lo[0] + hi[0]) - 0.5 * (columns - 1) * spacing;
    double y0 = 0.5 * (lo[1] + hi[1]) - 0.5 * (rows - 1) * spacing;
    double level = lo[2] + height;
    rad_vec3 *grid = rad_alloc_array((size_t)columns * rows, sizeof(*grid));
    rad_ray *rays = rad_alloc_array((size_t)columns * rows, sizeof(*rays));
    rad_hit *hits = rad_alloc_array((size_t)columns * rows, sizeof(*hits));
    rad_tracer *tracer = NULL;
    rad_status status = RAD_OK;
    if (!grid || !rays || !hits)
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for a work plane of %u x %u points",
                          columns, rows);
    if (status == RAD_OK)
        status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &tracer, error);
    if (status == RAD_OK) {
        size_t n = (size_t)columns * rows;
        for (size_t k = 0; k < n; k++) {
            double x = x0 + (double)(k % columns) * spacing, y = y0 + (double)(k / columns) * spacing;
            grid[k] = v3_add(v3_add(v3_scale(east, x), v3_scale(north, y)), v3_scale(up, level));
            ray_set(&rays[k], grid[k], v3_scale(up, -1), 0, INFINITY);
        }
        rad_tracer_intersect(tracer, rays, (uint32_t)n, hits);
        uint32_t kept = 0;
        for (size_t k = 0; k < n; k++) {
            const rad_hit *hit = &hits[k];
            if (hit->triangle == RAD_NO_HIT || !hit->front)
                continue;
            grid[kept++] = grid[k];
        }
        /* and not inside furniture or a wall: straight up it sees a front (a ceiling, the
         * underside of a table) or the open sky, never the back of a surface */
        for (uint32_t k = 0; k < kept; k++)
            ray_set(&rays[k], grid[k], up, 0, INFINITY);
        rad_tracer_intersect(tracer, rays, kept, hits);
        uint32_t inside = 0;
        for (uint32_t k = 0; k < kept; k++)
            if (hits[k].triangle == RAD_NO_HIT || hits[k].front)
                grid[inside++] = grid[k];
        kept = inside;
        *count = kept;
        *points = grid;
        grid = NULL;
    }
    rad_tracer_destroy(tracer);
    free(grid);
    free(rays);
    free(hits);
    return status;
}

double rad_sky_horizontal_illuminance(const rad_scene *scene)
{
    double sum = 0;
    rad_vec3 up = v3_normalize(scene->up);
    for (uint32_t l = 0; l < scene->light_count; l++) {
        const rad_light *light = &scene->lights[l];
        if (light->type != RAD_LIGHT_SKY)
            continue;
        double sun_elevation = asin(fmin(fmax(-v3_dot(light->direction, up), -1), 1));
        /* the green channel: a white sky's luminance */
        sum += light->intensity.g * sky_horizontal_illuminance_factor(light->sky, sun_elevation);
    }
    return sum;
}
