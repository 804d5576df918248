/*
 * patch_direct.c - the direct light of the scene's light sources on each patch: the mean
 * irradiance over PATCH_LIGHT_POINTS^2 stratified jittered points of the patch, each with
 * one shadow ray per point-like source or sun and one direction toward the sky, the
 * directions stratified over the hemisphere across the points (a stratum per point, in
 * an order unrelated to the points' places), traced against the scene's own triangles. Random numbers come from (patch, point),
 * so the result is the same for any thread count.
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/random.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "lights/direct_light.h"
#include "lights/patch_direct.h"
#include "mesh/patch_point.h"

#define PATCH_LIGHT_POINTS 8u /* per side: 64 points per patch, one sky direction each */
#define PATCH_LIGHT_STREAM 0x11647ull

typedef struct thread_buffers {
    rad_ray *rays;
    rad_rgb *irradiance;
    uint8_t *sharp;
    uint8_t *occluded;
} thread_buffers;

rad_status patch_direct_light(const rad_scene *scene, const rad_mesh *mesh, rad_rgb *direct,
                              rad_rgb *direct_sharp, rad_error *error)
{
    uint32_t n = mesh->patch_count;
    for (uint32_t p = 0; p < n; p++) {
        if (direct)
            direct[p] = (rad_rgb){0, 0, 0};
        if (direct_sharp)
            direct_sharp[p] = (rad_rgb){0, 0, 0};
    }
    if (scene->light_count == 0 || n == 0)
        return RAD_OK;
    light_set set;
    light_set_init(&set, scene);
    const uint32_t points = PATCH_LIGHT_POINTS * PATCH_LIGHT_POINTS;
    uint32_t per_point = light_set_capacity(&set, LIGHTS_SHARP | LIGHTS_SOFT, 1);
    size_t capacity = (size_t)points * per_point;
    rad_tracer *tracer = NULL;
    rad_status status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &tracer, error);
    if (status != RAD_OK)
        return status;
    int threads = omp_get_max_threads();
    thread_buffers *buffers = rad_alloc_array((size_t)threads, sizeof(*buffers));
    bool ok = buffers != NULL;
    for (int t = 0; ok && t < threads; t++) {
        buffers[t].rays = rad_alloc_array(capacity, sizeof(rad_ray));
        buffers[t].irradiance = rad_alloc_array(capacity, sizeof(rad_rgb));
        buffers[t].sharp = rad_alloc_array(capacity, sizeof(uint8_t));
        buffers[t].occluded = rad_alloc_array(capacity, sizeof(uint8_t));
        ok = buffers[t].rays && buffers[t].irradiance && buffers[t].sharp && buffers[t].occluded;
    }
    if (ok) {
#pragma omp parallel for schedule(dynamic, 32) num_threads(threads)
        for (int64_t p = 0; p < (int64_t)n; p++) {
            thread_buffers *b = &buffers[omp_get_thread_num()];
            const rad_patch *patch = &mesh->patches[p];
            double leave = 2 * patch->behind + set.leave;
            uint32_t count = 0;
            for (uint32_t q = 0; q < points; q++) {
                rad_rng rng = rad_rng_seed(PATCH_LIGHT_STREAM, (uint64_t)p, q);
                double s = ((q % PATCH_LIGHT_POINTS) + rad_rng_uniform(&rng)) / PATCH_LIGHT_POINTS;
                double t = ((q / PATCH_LIGHT_POINTS) + rad_rng_uniform(&rng)) / PATCH_LIGHT_POINTS;
                rad_vec3 x = patch_point(mesh, patch, s, t);
                uint32_t sharp = light_set_rays(&set, LIGHTS_SHARP, x, patch->normal, leave, q,
                                                points, 0, &rng, &b->rays[count],
                                                &b->irradiance[count]);
                for (uint32_t k = 0; k < sharp; k++)
                    b->sharp[count + k] = 1;
                count += sharp;
                /* 37 is prime to the point count (a power of 4): a permutation of strata */
                uint32_t direction = (q * 37u + 11u) % points;
                uint32_t soft = light_set_rays(&set, LIGHTS_SOFT, x, patch->normal, leave,
                                               direction, points, 1, &rng, &b->rays[count],
                                               &b->irradiance[count]);
                for (uint32_t k = 0; k < soft; k++)
                    b->sharp[count + k] = 0;
                count += soft;
            }
            rad_tracer_occluded(tracer, b->rays, count, b->occluded);
            rad_rgb all = {0, 0, 0}, sharp = {0, 0, 0};
            for (uint32_t k = 0; k < count; k++) {
                if (b->occluded[k])
                    continue;
                rgb_add_to(&all, b->irradiance[k]);
                if (b->sharp[k])
                    rgb_add_to(&sharp, b->irradiance[k]);
            }
            if (direct)
                direct[p] = rgb_scale(all, 1.0 / points);
            if (direct_sharp)
                direct_sharp[p] = rgb_scale(sharp, 1.0 / points);
        }
    }
    if (buffers)
        for (int t = 0; t < threads; t++) {
            free(buffers[t].rays);
            free(buffers[t].irradiance);
            free(buffers[t].sharp);
            free(buffers[t].occluded);
        }
    free(buffers);
    rad_tracer_destroy(tracer);
    if (!ok)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light sources' direct light");
    return RAD_OK;
}
