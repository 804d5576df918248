/*
 * scene.c - queries on a loaded rad_scene: area, bounds, emitters, a framing camera.
 */
#include <math.h>
#include <stdlib.h>

#include "core/vec3.h"
#include "radiosity.h"

void rad_scene_destroy(rad_scene *scene)
{
    if (!scene)
        return;
    free(scene->positions);
    free(scene->triangles);
    free(scene->materials);
    free(scene->surfaces);
    free(scene);
}

double rad_scene_area(const rad_scene *scene)
{
    double area = 0;
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        rad_vec3 e0 = v3_sub(scene->positions[v[1]], scene->positions[v[0]]);
        rad_vec3 e1 = v3_sub(scene->positions[v[2]], scene->positions[v[0]]);
        area += 0.5 * v3_length(v3_cross(e0, e1));
    }
    return area;
}

void rad_scene_bounds(const rad_scene *scene, rad_vec3 *lo, rad_vec3 *hi)
{
    v3_bounds(scene->positions, scene->position_count, lo, hi);
}

bool rad_scene_has_emitter(const rad_scene *scene)
{
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        rad_rgb e = scene->materials[scene->triangles[t].material].emission;
        if (e.r > 0 || e.g > 0 || e.b > 0)
            return true;
    }
    return false;
}

rad_camera rad_scene_default_camera(const rad_scene *scene)
{
    rad_vec3 lo, hi;
    rad_scene_bounds(scene, &lo, &hi);
    rad_vec3 center = v3_scale(v3_add(lo, hi), 0.5);
    rad_vec3 half = v3_scale(v3_sub(hi, lo), 0.5);
    rad_camera camera;
    camera.fov_degrees = 40.0;
    double tan_half = tan(camera.fov_degrees * RAD_PI / 360.0);
    /* back off until the front face's larger half extent fits the narrower (vertical) fov */
    double extent = fmax(half.x, half.y);
    double distance = extent / tan_half + half.z;
    if (!(distance > 0))
        distance = 1;
    camera.eye = v3(center.x, center.y, center.z - distance * 1.05);
    camera.target = center;
    camera.up = v3(0, 1, 0);
    return camera;
}
