/*
 * emitter_light.c - the direct light of emissive surfaces at a point and on each patch
 * (emitter_light.h).
 */
#include "render/emitter_light.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/random.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "mesh/patch_point.h"
#include "trace/ray.h"

#define PATCH_EMITTER_POINTS 4u  /* per side: 16 points per patch */
#define PATCH_EMITTER_SAMPLES 8u /* per point: 128 light samples per patch */
#define PATCH_EMITTER_STREAM 0xE3177E2ull

static double wrap(double u) { return u < 1 ? u : u - 1; }

uint32_t emitter_light_rays(const emitter_set *set, const rad_scene *scene, rad_vec3 x,
                            rad_vec3 n, double leave, uint32_t count, double turn,
                            uint32_t first, double shift1, double shift2, rad_rng *rng,
                            rad_ray *rays, rad_rgb *irradiance)
{
    if (set->count == 0)
        return 0;
    rad_vec3 origin = v3_add(x, v3_scale(n, leave));
    uint32_t made = 0;
    for (uint32_t k = 0; k < count; k++) {
        uint32_t j = first + k;
        double u0 = wrap((k + rad_rng_uniform(rng)) / count + turn);
        emitter_sample light;
        emitters_sample(set, scene, u0, wrap(rad_radical_inverse(j, 2) + shift1),
                        wrap(rad_radical_inverse(j, 3) + shift2), &light);
        rad_vec3 d = v3_sub(light.point, x);
        double r2 = v3_dot(d, d);
        if (!(r2 > 0) || !(light.pdf_area > 0))
            continue;
        rad_vec3 wi = v3_scale(d, 1 / sqrt(r2)), facing;
        double cos_x = v3_dot(n, wi), cos_e = emitter_cosine(&light, wi, &facing);
        if (!(cos_x > 0) || !(cos_e > 0))
            continue;
        rad_rgb value = rgb_scale(light.radiance, cos_x * cos_e / (r2 * light.pdf_area * count));
        if (rgb_is_zero(value))
            continue;
        irradiance[made] = value;
        ray_segment(&rays[made], origin, v3_add(light.point, v3_scale(facing, leave)));
        made++;
    }
    return made;
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
    const uint32_t total = points * PATCH_EMITTER_SAMPLES; /* samples per patch */
    rad_ray *rays = rad_alloc_array((size_t)threads * total, sizeof(*rays));
    rad_rgb *values = rad_alloc_array((size_t)threads * total, sizeof(*values));
    uint8_t *blocked = rad_alloc_array((size_t)threads * total, sizeof(*blocked));
    if (!rays || !values || !blocked) {
        free(rays);
        free(values);
        free(blocked);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the emitters' direct light");
    }
#pragma omp parallel for schedule(dynamic, 32) num_threads(threads)
    for (int64_t p = 0; p < (int64_t)n; p++) {
        size_t base = (size_t)omp_get_thread_num() * total;
        const rad_patch *patch = &mesh->patches[p];
        rad_rng rng = rad_rng_seed(seed ^ PATCH_EMITTER_STREAM, (uint64_t)p, 0);
        double shift1 = rad_rng_uniform(&rng), shift2 = rad_rng_uniform(&rng);
        uint32_t count = 0;
        for (uint32_t q = 0; q < points; q++) {
            double s = ((q % PATCH_EMITTER_POINTS) + rad_rng_uniform(&rng)) / PATCH_EMITTER_POINTS;
            double t = ((q / PATCH_EMITTER_POINTS) + rad_rng_uniform(&rng)) / PATCH_EMITTER_POINTS;
            rad_vec3 x = patch_point(mesh, patch, s, t);
            /* every point samples the whole light; consecutive Halton points and turns
             * spread over the points make the patch's samples cover it evenly */
            count += emitter_light_rays(set, scene, x, patch->normal, 2 * patch->bulge + leave,
                                        PATCH_EMITTER_SAMPLES, (q + 0.5) / points,
                                        q * PATCH_EMITTER_SAMPLES, shift1, shift2, &rng,
                                        &rays[base + count], &values[base + count]);
        }
        rad_tracer_occluded(occluders, &rays[base], count, &blocked[base]);
        rad_rgb sum = {0, 0, 0};
        for (uint32_t k = 0; k < count; k++)
            if (!blocked[base + k])
                rgb_add_to(&sum, values[base + k]);
        direct[p] = rgb_scale(sum, 1.0 / points); /* the mean of the points' estimates */
    }
    free(rays);
    free(values);
    free(blocked);
    return RAD_OK;
}
