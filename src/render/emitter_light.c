/*
 * emitter_light.c - the direct light of emissive surfaces at a point (emitter_light.h).
 */
#include "render/emitter_light.h"

#include <math.h>
#include <stdbool.h>

#include "core/hemisphere.h"
#include "core/scrambled_sobol.h"
#include "core/random.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "geometry/contour.h"
#include "scene/material_at.h"
#include "trace/ray.h"


static double wrap(double u) { return u < 1 ? u : u - 1; }

static uint32_t light_rays(const emitter_set *set, const rad_scene *scene, rad_vec3 x,
                           rad_vec3 n, double leave, uint32_t count, double turn, uint32_t first,
                           double shift1, double shift2, bool by_triangle,
                           double cosine_per_light, rad_ray *rays, rad_rgb *irradiance)
{
    if (set->count == 0)
        return 0;
    rad_vec3 origin = v3_add(x, v3_scale(n, leave));
    uint32_t made = 0;
    uint32_t current = UINT32_MAX, local = 0; /* by_triangle: the triangle, its k-th point */
    const double per_sample = 1.0 / count;
    for (uint32_t k = 0; k < count; k++) {
        uint32_t j = first + k;
        double u0, u1, u2;
        if (by_triangle) {
            /* evenly spaced choices (k + turn) / count, so each triangle gets its share of
             * consecutive samples, and its own Halton points (bases 2, 3) on it */
            u0 = (k + turn) * per_sample;
            uint32_t t = emitters_index(set, u0);
            if (t != current) {
                current = t;
                local = 0;
            }
            u1 = wrap(rad_radical_inverse(local, 2) + shift1);
            u2 = wrap(emitters_halton3(set, local) + shift2);
            local++;
        } else {
            /* the triangle and the point on it from one Halton point (bases 5, 2, 3): a
             * triangle chosen apart from the point's dimensions would take every other
             * Halton point, which covers only stripes of it */
            u0 = wrap(emitters_halton5(set, j) + turn);
            u1 = wrap(rad_radical_inverse(j, 2) + shift1);
            u2 = wrap(emitters_halton3(set, j) + shift2);
        }
        emitter_sample light;
        emitters_sample(set, scene, u0, u1, u2, &light);
        rad_vec3 d = v3_sub(light.point, x);
        double r2 = v3_dot(d, d);
        if (!(r2 > 0) || !(light.pdf_area > 0))
            continue;
        rad_vec3 wi = v3_scale(d, 1 / sqrt(r2)), facing;
        double cos_x = v3_dot(n, wi), cos_e = emitter_cosine(&light, wi, &facing);
        if (!(cos_x > 0) || !(cos_e > 0))
            continue;
        /* L cos_x / p_light times the power heuristic's p_light^2 / (p_light^2 + p_cosine^2),
         * each density times its strategy's sample count; p_light = pdf_area r^2 / cos_e per
         * solid angle (without cosine rays the weight is 1: L cos_x cos_e / (pdf_area r^2)) */
        double weight;
        if (cosine_per_light > 0) {
            double p_light = light.pdf_area * r2 / cos_e;
            double p_cosine = cosine_per_light * cos_x * (1 / RAD_PI);
            weight = cos_x * p_light / ((p_light * p_light + p_cosine * p_cosine) * count);
        } else {
            weight = cos_x * cos_e / (light.pdf_area * r2) * per_sample;
        }
        rad_rgb value = rgb_scale(light.radiance, weight);
        if (rgb_is_zero(value))
            continue;
        irradiance[made] = value;
        ray_segment(&rays[made], origin, v3_add(light.point, v3_scale(facing, leave)));
        made++;
    }
    return made;
}

uint32_t emitter_light_rays_mis(const emitter_set *set, const rad_scene *scene, rad_vec3 x,
                                rad_vec3 n, double leave, uint32_t count, double turn,
                                uint32_t first, double shift1, double shift2, rad_ray *rays,
                                rad_rgb *irradiance)
{
    return light_rays(set, scene, x, n, leave, count, turn, first, shift1, shift2, false, 1,
                      rays, irradiance);
}

uint32_t emitter_light_rays_alone(const emitter_set *set, const rad_scene *scene, rad_vec3 x,
                                  rad_vec3 n, double leave, uint32_t count, double turn,
                                  uint32_t first, double shift1, double shift2, rad_ray *rays,
                                  rad_rgb *irradiance)
{
    return light_rays(set, scene, x, n, leave, count, turn, first, shift1, shift2, false, 0,
                      rays, irradiance);
}

uint32_t emitter_light_rays_by_triangle(const emitter_set *set, const rad_scene *scene,
                                        rad_vec3 x, rad_vec3 n, double leave, uint32_t count,
                                        double turn, double shift1, double shift2,
                                        double cosine_per_light, rad_ray *rays,
                                        rad_rgb *irradiance)
{
    return light_rays(set, scene, x, n, leave, count, turn, 0, shift1, shift2, true,
                      cosine_per_light, rays, irradiance);
}

void emitter_cosine_rays(rad_vec3 x, rad_vec3 n, double leave, uint32_t count, rad_rng *rng,
                         rad_ray *rays, double *cos_x)
{
    rad_vec3 a, b;
    hemisphere_frame(n, &a, &b);
    rad_vec3 origin = v3_add(x, v3_scale(n, leave));
    const uint64_t seeds = rad_rng_next(rng);
    const uint32_t seed1 = (uint32_t)seeds, seed2 = (uint32_t)(seeds >> 32);
    /* 2^m points are a net: a grid of 2^columns x 2^rows cells holds one each, so each
     * goes to its cell's slot and rays that follow each other leave in nearby directions
     * (the tracer's and the gather's caches; in sequence order they jump about) */
    const bool net = count > 0 && (count & (count - 1)) == 0;
    unsigned m = 0;
    while (net && (1u << m) < count)
        m++;
    const unsigned columns = (m + 1) / 2, rows = m / 2;
    const double unit = 1.0 / 4294967296.0;
    sobol_walk walk = sobol_walk_start(seed1, seed2);
    for (uint32_t k = 0; k < count; k++) {
        uint32_t x1, x2;
        sobol_walk_next(&walk, &x1, &x2);
        uint32_t slot = !net ? k
                             : ((rows ? x2 >> (32 - rows) : 0) << columns) |
                                   (columns ? x1 >> (32 - columns) : 0);
        rad_vec3 w = cosine_direction(n, a, b, x1 * unit, x2 * unit, 0, &cos_x[slot]);
        ray_set(&rays[slot], origin, w, 0, INFINITY);
    }
}

rad_rgb emitter_cosine_value(const emitter_set *set, const rad_scene *scene, const rad_ray *ray,
                             const rad_hit *hit, double cos_x, uint32_t count)
{
    return emitter_cosine_value_weighted(set, scene, ray, hit, cos_x, count, 1);
}

rad_rgb emitter_cosine_value_weighted(const emitter_set *set, const rad_scene *scene,
                                      const rad_ray *ray, const rad_hit *hit, double cos_x,
                                      uint32_t count, double light_per_cosine)
{
    rad_rgb none = {0, 0, 0};
    if (hit->triangle == RAD_NO_HIT || !(cos_x > 0))
        return none;
    double pdf_area = set->pdf_area_of[hit->triangle];
    if (!(pdf_area > 0) || (!hit->front && !triangle_two_sided(scene, hit->triangle)))
        return none;
    rad_rgb emitted = material_emission_at(scene, hit->triangle, hit->u, hit->v);
    if (rgb_is_zero(emitted))
        return none;
    const uint32_t *v = scene->triangles[hit->triangle].vertex;
    rad_vec3 p0 = scene->positions[v[0]];
    rad_vec3 normal = v3_normalize(v3_cross(v3_sub(scene->positions[v[1]], p0),
                                            v3_sub(scene->positions[v[2]], p0)));
    rad_vec3 d = v3(ray->direction[0], ray->direction[1], ray->direction[2]);
    double length = v3_length(d);
    double cos_e = fabs(v3_dot(normal, d)) / length, distance = (double)hit->t * length;
    if (!(cos_e > 0))
        return none;
    double p_light = light_per_cosine * pdf_area * distance * distance / cos_e,
           p_cosine = cos_x / RAD_PI;
    /* pi L times the power heuristic's p_cosine^2 / (p_cosine^2 + p_light^2), each density
     * times its strategy's sample count */
    return rgb_scale(emitted, RAD_PI * p_cosine * p_cosine /
                                  ((p_cosine * p_cosine + p_light * p_light) * count));
}

bool emitter_unshadowed_exact(const emitter_set *set, const rad_scene *scene)
{
    if (set->count > EMITTER_ANALYTIC_MAX)
        return false;
    for (uint32_t k = 0; k < set->count; k++)
        if (material_emission_texture(scene, scene->triangles[set->triangle[k]].material))
            return false;
    return true;
}

rad_rgb emitter_unshadowed_irradiance(const emitter_set *set, const rad_scene *scene, rad_vec3 x,
                                      rad_vec3 n)
{
    rad_rgb sum = {0, 0, 0};
    for (uint32_t k = 0; k < set->count; k++) {
        uint32_t t = set->triangle[k];
        const uint32_t *v = scene->triangles[t].vertex;
        rad_vec3 corner[3] = {scene->positions[v[0]], scene->positions[v[1]],
                              scene->positions[v[2]]};
        rad_vec3 normal = v3_cross(v3_sub(corner[1], corner[0]), v3_sub(corner[2], corner[0]));
        double length = v3_length(normal);
        if (!(length > 0))
            continue;
        normal = v3_scale(normal, 1 / length);
        double F = contour_point_to_polygon(x, n, corner, 3, normal, 0);
        if (triangle_two_sided(scene, t)) { /* the back: the same triangle turned over */
            rad_vec3 turned[3] = {corner[0], corner[2], corner[1]};
            F += contour_point_to_polygon(x, n, turned, 3, v3_scale(normal, -1), 0);
        }
        if (F > 0)
            rgb_add_to(&sum, rgb_scale(material_emission_at(scene, t, 1.0 / 3, 1.0 / 3), RAD_PI * F));
    }
    return sum;
}

void emitter_to_unshadowed(const emitter_set *set, const rad_scene *scene, rad_vec3 x,
                           rad_vec3 n, rad_rgb *irradiance, uint32_t count)
{
    emitter_scale_to(emitter_unshadowed_irradiance(set, scene, x, n), irradiance, count);
}

void emitter_scale_to(rad_rgb open, rad_rgb *irradiance, uint32_t count)
{
    rad_rgb all = {0, 0, 0};
    for (uint32_t k = 0; k < count; k++)
        rgb_add_to(&all, irradiance[k]);
    rad_rgb scale = {all.r > 0 ? open.r / all.r : 0, all.g > 0 ? open.g / all.g : 0,
                     all.b > 0 ? open.b / all.b : 0};
    for (uint32_t k = 0; k < count; k++)
        irradiance[k] = rgb_mul(irradiance[k], scale);
}
