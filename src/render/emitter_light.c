/*
 * emitter_light.c - the direct light of emissive surfaces at a point and on each patch
 * (emitter_light.h).
 */
#include "render/emitter_light.h"

#include <math.h>
#include <stdbool.h>
#include <omp.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/hemisphere.h"
#include "core/random.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "mesh/patch_point.h"
#include "scene/material_at.h"
#include "trace/ray.h"

#define PATCH_EMITTER_POINTS 4u  /* per side: 16 points per patch */
#define PATCH_EMITTER_SAMPLES 32u /* per point: 512 light samples per patch */
#define PATCH_EMITTER_STREAM 0xE3177E2ull

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
    for (uint32_t k = 0; k < count; k++) {
        uint32_t j = first + k;
        double u0, u1, u2;
        if (by_triangle) {
            /* evenly spaced choices (k + turn) / count, so each triangle gets its share of
             * consecutive samples, and its own Halton points (bases 2, 3) on it */
            u0 = (k + turn) / count;
            uint32_t t = emitters_index(set, u0);
            if (t != current) {
                current = t;
                local = 0;
            }
            u1 = wrap(rad_radical_inverse(local, 2) + shift1);
            u2 = wrap(rad_radical_inverse(local, 3) + shift2);
            local++;
        } else {
            /* the triangle and the point on it from one Halton point (bases 5, 2, 3): a
             * triangle chosen apart from the point's dimensions would take every other
             * Halton point, which covers only stripes of it */
            u0 = wrap(rad_radical_inverse(j, 5) + turn);
            u1 = wrap(rad_radical_inverse(j, 2) + shift1);
            u2 = wrap(rad_radical_inverse(j, 3) + shift2);
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
        double p_light = light.pdf_area * r2 / cos_e; /* per solid angle */
        double p_cosine = cosine_per_light * cos_x / RAD_PI;
        /* L cos_x / p_light times the power heuristic's p_light^2 / (p_light^2 + p_cosine^2),
         * each density times its strategy's sample count */
        rad_rgb value = rgb_scale(light.radiance, cos_x * p_light /
                                                      ((p_light * p_light + p_cosine * p_cosine) * count));
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
    uint32_t side = (uint32_t)floor(sqrt((double)count));
    double turn = 2 * RAD_PI * rad_rng_uniform(rng);
    for (uint32_t k = 0; k < count; k++) {
        double u1 = rad_rng_uniform(rng), u2 = rad_rng_uniform(rng);
        if (k < side * side) {
            u1 = ((k % side) + u1) / side;
            u2 = ((k / side) + u2) / side;
        }
        rad_vec3 w = cosine_direction(n, a, b, u1, u2, turn, &cos_x[k]);
        ray_set(&rays[k], origin, w, 0, INFINITY);
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

rad_status emitter_patch_direct(const emitter_set *set, const rad_scene *scene,
                                const rad_mesh *mesh, const rad_tracer *occluders,
                                double leave, uint64_t seed, int threads, rad_rgb *direct,
                                rad_error *error)
{
    uint32_t n = mesh->patch_count;
    for (uint32_t p = 0; p < n; p++)
        direct[p] = (rad_rgb){0, 0, 0};
    if (set->count == 0 || n == 0)
        return RAD_OK;
    const uint32_t points = PATCH_EMITTER_POINTS * PATCH_EMITTER_POINTS;
    const uint32_t total = points * PATCH_EMITTER_SAMPLES; /* of each kind, per patch */
    size_t size = (size_t)threads * total;
    rad_ray *rays = rad_alloc_array(size, sizeof(*rays));
    rad_rgb *values = rad_alloc_array(size, sizeof(*values));
    uint8_t *blocked = rad_alloc_array(size, sizeof(*blocked));
    rad_ray *cosine_rays = rad_alloc_array(size, sizeof(*cosine_rays));
    rad_hit *hits = rad_alloc_array(size, sizeof(*hits));
    double *cosines = rad_alloc_array(size, sizeof(*cosines));
    bool ok = rays && values && blocked && cosine_rays && hits && cosines;
    if (ok) {
#pragma omp parallel for schedule(dynamic, 32) num_threads(threads)
        for (int64_t p = 0; p < (int64_t)n; p++) {
            size_t base = (size_t)omp_get_thread_num() * total;
            const rad_patch *patch = &mesh->patches[p];
            rad_rng rng = rad_rng_seed(seed ^ PATCH_EMITTER_STREAM, (uint64_t)p, 0);
            double turn = rad_rng_uniform(&rng), shift1 = rad_rng_uniform(&rng),
                   shift2 = rad_rng_uniform(&rng);
            double off = 2 * patch->bulge + leave;
            uint32_t count = 0;
            for (uint32_t q = 0; q < points; q++) {
                double s = ((q % PATCH_EMITTER_POINTS) + rad_rng_uniform(&rng)) / PATCH_EMITTER_POINTS;
                double t = ((q / PATCH_EMITTER_POINTS) + rad_rng_uniform(&rng)) / PATCH_EMITTER_POINTS;
                rad_vec3 x = patch_point(mesh, patch, s, t);
                /* every point samples the whole light and its hemisphere; consecutive Halton
                 * points (one shift for the patch) make the patch's samples cover the light
                 * evenly */
                count += emitter_light_rays_mis(set, scene, x, patch->normal, off,
                                                PATCH_EMITTER_SAMPLES, turn,
                                                q * PATCH_EMITTER_SAMPLES, shift1, shift2,
                                                &rays[base + count], &values[base + count]);
                emitter_cosine_rays(x, patch->normal, off, PATCH_EMITTER_SAMPLES, &rng,
                                    &cosine_rays[base + q * PATCH_EMITTER_SAMPLES],
                                    &cosines[base + q * PATCH_EMITTER_SAMPLES]);
            }
            rad_tracer_occluded(occluders, &rays[base], count, &blocked[base]);
            rad_tracer_intersect(occluders, &cosine_rays[base], total, &hits[base]);
            rad_rgb sum = {0, 0, 0};
            for (uint32_t k = 0; k < count; k++)
                if (!blocked[base + k])
                    rgb_add_to(&sum, values[base + k]);
            for (uint32_t k = 0; k < total; k++)
                rgb_add_to(&sum, emitter_cosine_value(set, scene, &cosine_rays[base + k],
                                                      &hits[base + k], cosines[base + k],
                                                      PATCH_EMITTER_SAMPLES));
            direct[p] = rgb_scale(sum, 1.0 / points); /* the mean of the points' estimates */
        }
    }
    free(rays);
    free(values);
    free(blocked);
    free(cosine_rays);
    free(hits);
    free(cosines);
    if (!ok)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the emitters' direct light");
    return RAD_OK;
}
