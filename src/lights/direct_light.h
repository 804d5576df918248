/*
 * direct_light.h - direct light from the scene's light sources (rad_light) at a point: the
 * one place every solver and renderer gets it from (internal).
 *
 * A point x with unit normal n receives from each source an irradiance that is known in
 * closed form once its visibility is known. So a query hands back pairs (shadow ray,
 * irradiance at x if that ray is unblocked): the caller traces the rays in a batch
 * (rad_tracer_occluded) and adds up the irradiance of the rays that got through. Point,
 * spot and luminaire: one segment to the light, E = I(direction) cos / (r m)^2 with m the
 * metres per scene unit. Sun: one ray toward a point of its disk (stratified by the
 * caller's sample index), E = E_n cos. Sky and environment: `sky_rays` directions,
 * cosine-weighted and stratified over the hemisphere of n, each E = pi L(direction) /
 * count; the sky's radiance below the horizon is 0.
 *
 * The "sharp" sources (point, spot, luminaire, sun) are the ones a renderer recomputes at
 * each pixel, for exact shadows; the "soft" ones (sky, environment) light a scene smoothly
 * and come into images through the radiosity solution.
 */
#ifndef RAD_LIGHTS_DIRECT_LIGHT_H
#define RAD_LIGHTS_DIRECT_LIGHT_H

#include <stdbool.h>
#include <stdint.h>

#include "core/random.h"
#include "radiosity.h"

typedef struct light_set {
    const rad_scene *scene;
    const rad_light *lights;
    uint32_t count;
    uint32_t sharp_count;  /* point, spot, luminaire, sun */
    bool has_sky;          /* a sky or environment light */
    double metres;         /* per scene unit */
    rad_vec3 up, north, east;
    double leave;          /* how far shadow rays start off a surface: past the float
                              rounding of points at the scene's size and distance from the
                              origin (scene units) */
} light_set;

/* The scene's lights, ready for queries. */
void light_set_init(light_set *set, const rad_scene *scene);

/* Which sources a query includes. */
#define LIGHTS_SHARP 1u
#define LIGHTS_SOFT 2u

/* How many pairs a query with `sky_rays` sky directions may return. */
uint32_t light_set_capacity(const light_set *set, unsigned which, uint32_t sky_rays);

/* Fills rays[k] and irradiance[k] (k < the returned count) for the point x, normal n
 * (unit), rays leaving from x + n * leave. `sample` and `sample_count` stratify the sun's
 * disk and the sky's directions over the caller's samples of one point or pixel (sample in
 * [0, sample_count)); rng supplies the jitter. Only pairs that can carry light are
 * returned (the source in front of the surface, a non-zero intensity). */
uint32_t light_set_rays(const light_set *set, unsigned which, rad_vec3 x, rad_vec3 n,
                        double leave, uint32_t sample, uint32_t sample_count,
                        uint32_t sky_rays, rad_rng *rng, rad_ray *rays,
                        rad_rgb *irradiance);

/* The radiance of the sky and environment lights seen along `direction` (unit): what a
 * ray that leaves the scene sees. Zero when there is none. */
rad_rgb light_set_sky_radiance(const light_set *set, rad_vec3 direction);

#endif
