/*
 * illuminance.c - irradiance (illuminance) at given points from a radiosity solution:
 * exact shadow rays toward the sharp light sources, then a final gather. Gather rays are
 * cosine-weighted and stratified over the point's hemisphere (an estimate of
 * E = integral L cos dw = pi x the mean radiance of the rays), each bringing the radiance
 * interpolated at the display triangle it hits (B / pi at the vertices, as the renderer
 * shows it; a two-sided patch's back its twin's B / pi) or the sky's when it leaves the
 * scene. Random numbers come from (seed, point), so the values are the same for any
 * thread count.
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/hemisphere.h"
#include "core/random.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "lights/direct_light.h"
#include "reconstruct/display_mesh.h"
#include "render/emitter_light.h"
#include "render/emitter_shadows.h"
#include "lights/emitters.h"
#include "trace/ray.h"

#define GATHER_STREAM 0x6A7E2ull
#define EMITTER_SAMPLES 64u /* light samples, and as many cosine rays, per point */

typedef struct point_buffers {
    rad_ray *rays;
    rad_rgb *value;
    uint8_t *blocked;
    rad_hit *hits;
    double *cosines;
} point_buffers;

rad_status rad_illuminance(const rad_scene *scene, const rad_mesh *mesh, const rad_rgb *B,
                           const rad_vec3 *points, const rad_vec3 *normals, uint32_t count,
                           const rad_illuminance_options *options, rad_rgb *E,
                           rad_error *error)
{
    rad_illuminance_options defaults = {0};
    if (!options)
        options = &defaults;
    if (options->threads < 0)
        return rad_fail(error, RAD_ERR_INVALID, "illuminance: thread count %d is negative",
                        options->threads);
    for (uint32_t i = 0; i < count; i++)
        if (!v3_is_finite(points[i]) || !(v3_length(normals[i]) > 0) ||
            !v3_is_finite(normals[i]))
            return rad_fail(error, RAD_ERR_INVALID,
                            "illuminance: point %u has a non-finite position or a zero normal",
                            i);
    uint32_t gather = options->gather_rays ? options->gather_rays : RAD_DEFAULT_GATHER_RAYS;
    int threads = options->threads > 0 ? options->threads : omp_get_max_threads();
    light_set lights;
    light_set_init(&lights, scene);

    display_mesh display = {0};
    rad_rgb *radiance = NULL;
    rad_vec3 *positions = NULL;
    rad_tracer *surfaces = NULL, *occluders = NULL;
    point_buffers *buffers = NULL;
    uint32_t sharp = light_set_capacity(&lights, LIGHTS_SHARP, 0);
    uint32_t capacity = sharp > gather ? sharp : gather;
    if (capacity < EMITTER_SAMPLES)
        capacity = EMITTER_SAMPLES;
    emitter_set emitters = {0};
    emitter_shadows *shadows = NULL;
    rad_patch_inputs *built = NULL;
    const rad_patch_inputs *inputs = options->inputs;
    rad_rgb *reflected = NULL;
    rad_status status = display_mesh_build(mesh, true, &display, error);
    if (status != RAD_OK)
        goto done;
    radiance = rad_alloc_array(display.vertex_count, sizeof(*radiance));
    positions = rad_alloc_array(display.vertex_count, sizeof(*positions));
    buffers = rad_alloc_array((size_t)threads, sizeof(*buffers));
    if (!radiance || !positions || !buffers)
        goto nomem;
    for (int t = 0; t < threads; t++) {
        point_buffers *b = &buffers[t];
        b->rays = rad_alloc_array(capacity, sizeof(*b->rays));
        b->value = rad_alloc_array(capacity, sizeof(*b->value));
        b->blocked = rad_alloc_array(capacity, sizeof(*b->blocked));
        b->hits = rad_alloc_array(capacity, sizeof(*b->hits));
        b->cosines = rad_alloc_array(capacity, sizeof(*b->cosines));
        if (!b->rays || !b->value || !b->blocked || !b->hits || !b->cosines)
            goto nomem;
    }
    display_mesh_positions(mesh, &display, positions);
    if (inputs && inputs->n != mesh->patch_count) {
        status = rad_fail(error, RAD_ERR_INVALID,
                          "illuminance: the patch inputs are for %u patches, the mesh has %u",
                          inputs->n, mesh->patch_count);
        goto done;
    }
    if (!inputs) {
        status = rad_patch_inputs_build(scene, mesh, &built, error);
        if (status != RAD_OK)
            goto done;
        inputs = built;
    }
    /* what a gather ray sees: the light a surface reflects, its emission left out (the
     * emitters' direct light is sampled on its own) */
    reflected = rad_alloc_array(mesh->patch_count ? mesh->patch_count : 1, sizeof(*reflected));
    if (!reflected)
        goto nomem;
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        reflected[p] = rgb_max0(rgb_add(B[p], rgb_scale(inputs->exitance[p], -1)));
    if (!display_mesh_radiance(mesh, &display, reflected, radiance))
        goto nomem;
    status = emitters_build(scene, &emitters, error);
    if (status == RAD_OK) /* their light exactly, where it can be */
        status = emitter_shadows_build(scene, &emitters, &shadows, error);
    if (status != RAD_OK)
        goto done;
    /* the front patches' triangles (twins come after them, and so do their display
     * triangles); a hit on the back of a two-sided patch takes its twin's B */
    uint32_t traced = display_mesh_front_triangles(mesh, &display);
    status = rad_tracer_create(RAD_TRACER_EMBREE, positions, display.vertex_count,
                               (const uint32_t(*)[3])display.triangles, traced, &surfaces,
                               error);
    if (status == RAD_OK)
        status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &occluders, error);
    if (status != RAD_OK)
        goto done;

#pragma omp parallel for schedule(dynamic, 16) num_threads(threads)
    for (int64_t i = 0; i < (int64_t)count; i++) {
        point_buffers *b = &buffers[omp_get_thread_num()];
        rad_vec3 x = points[i], n = v3_normalize(normals[i]);
        rad_rng rng = rad_rng_seed(options->seed ^ GATHER_STREAM, (uint64_t)i, 0);
        rad_rgb sum = {0, 0, 0};
        /* the sharp sources, exactly */
        uint32_t k = light_set_rays(&lights, LIGHTS_SHARP, x, n, lights.leave, 0, 1, 0, &rng,
                                    b->rays, b->value);
        rad_tracer_occluded(occluders, b->rays, k, b->blocked);
        for (uint32_t q = 0; q < k; q++)
            if (!b->blocked[q])
                rgb_add_to(&sum, b->value[q]);
        rad_rgb behind;
        if (shadows &&
            emitter_shadows_irradiance(shadows, v3_add(x, v3_scale(n, lights.leave)), n,
                                       EMITTER_SHADOWS_MAX_OCCLUDERS, &behind)) {
            rgb_add_to(&sum, behind); /* the emitters' direct light, exactly */
        } else if (emitters.count) {
            /* the emitters' direct light: light samples and cosine rays, MIS-weighted */
            double shift1 = rad_rng_uniform(&rng), shift2 = rad_rng_uniform(&rng);
            k = emitter_light_rays_mis(&emitters, scene, x, n, lights.leave, EMITTER_SAMPLES,
                                       rad_rng_uniform(&rng), 0, shift1, shift2, b->rays,
                                       b->value);
            rad_tracer_occluded(occluders, b->rays, k, b->blocked);
            for (uint32_t q = 0; q < k; q++)
                if (!b->blocked[q])
                    rgb_add_to(&sum, b->value[q]);
            emitter_cosine_rays(x, n, lights.leave, EMITTER_SAMPLES, &rng, b->rays, b->cosines);
            rad_tracer_intersect(occluders, b->rays, EMITTER_SAMPLES, b->hits);
            for (uint32_t q = 0; q < EMITTER_SAMPLES; q++)
                rgb_add_to(&sum, emitter_cosine_value(&emitters, scene, &b->rays[q], &b->hits[q],
                                                      b->cosines[q], EMITTER_SAMPLES));
        }
        /* the gather: cosine-weighted directions, stratified over a grid */
        rad_vec3 a, c;
        hemisphere_frame(n, &a, &c);
        uint32_t side = (uint32_t)floor(sqrt((double)gather));
        rad_vec3 origin = v3_add(x, v3_scale(n, lights.leave));
        for (uint32_t j = 0; j < gather; j++) {
            double u1 = rad_rng_uniform(&rng), u2 = rad_rng_uniform(&rng);
            if (j < side * side) {
                u1 = ((j % side) + u1) / side;
                u2 = ((j / side) + u2) / side;
            }
            rad_vec3 w = cosine_direction(n, a, c, u1, u2, 0, NULL);
            ray_set(&b->rays[j], origin, w, 0, INFINITY);
        }
        rad_tracer_intersect(surfaces, b->rays, gather, b->hits);
        rad_rgb gathered = {0, 0, 0};
        for (uint32_t j = 0; j < gather; j++) {
            const rad_hit *hit = &b->hits[j];
            if (hit->triangle == RAD_NO_HIT) {
                if (lights.has_sky) {
                    const rad_ray *ray = &b->rays[j];
                    rgb_add_to(&gathered,
                               light_set_sky_radiance(&lights, v3(ray->direction[0],
                                                                  ray->direction[1],
                                                                  ray->direction[2])));
                }
                continue;
            }
            if (!hit->front) {
                uint32_t twin = mesh->patches[display.patch_of[hit->triangle]].twin;
                if (twin)
                    rgb_add_to(&gathered, rgb_scale(reflected[twin - 1], 1 / RAD_PI));
                continue;
            }
            const uint32_t *v = display.triangles[hit->triangle];
            double u = hit->u, vv = hit->v;
            rgb_add_to(&gathered, rgb_add(rgb_scale(radiance[v[0]], 1 - u - vv),
                                          rgb_add(rgb_scale(radiance[v[1]], u),
                                                  rgb_scale(radiance[v[2]], vv))));
        }
        E[i] = rgb_add(sum, rgb_scale(gathered, RAD_PI / gather));
    }
    goto done;
nomem:
    status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for illuminance at %u points", count);
done:
    if (buffers)
        for (int t = 0; t < threads; t++) {
            free(buffers[t].rays);
            free(buffers[t].value);
            free(buffers[t].blocked);
            free(buffers[t].hits);
            free(buffers[t].cosines);
        }
    free(buffers);
    rad_tracer_destroy(surfaces);
    rad_tracer_destroy(occluders);
    display_mesh_free(&display);
    emitter_shadows_destroy(shadows);
    emitters_free(&emitters);
    rad_patch_inputs_destroy(built);
    free(reflected);
    free(radiance);
    free(positions);
    return status;
}
