/*
 * emitter_light.h - the direct light of emissive surfaces at a point, as shadow-ray pairs
 * (internal): what the radiosity render adds at each pixel sample (--direct pixel) or
 * computes at each mesh vertex (the default), and the work plane's illuminance.
 *
 * Like the light sources' (lights/direct_light.h), a query returns pairs (shadow segment,
 * irradiance at x if the segment is unblocked); the caller traces them in a batch. Each
 * sample is a point on the emitters (emitters.h: a triangle by power, a point uniformly on
 * it) and carries L_e cos_x cos_e / (r^2 pdf_area) / count, so the pairs of one query sum
 * to an unbiased estimate of the irradiance from every emitter.
 */
#ifndef RAD_RENDER_EMITTER_LIGHT_H
#define RAD_RENDER_EMITTER_LIGHT_H

#include "core/random.h"
#include "lights/emitters.h"
#include "radiosity.h"

/* `count` samples for the point x (unit normal n; segments leave from x + n * leave and
 * stop `leave` off the light), each of the whole light, so the query alone is unbiased:
 * sample j (first, first + 1, ...) is the Halton point j in bases 5, 2 and 3, shifted by
 * (turn, shift1, shift2) modulo 1: the first coordinate chooses the triangle, the other
 * two the point on it, so the samples of one query, and of consecutive queries (a caller
 * taking several for one pixel gives them consecutive `first`), cover the light evenly in
 * all three together. Returns how many pairs could carry light (the light in front of
 * the surface and the surface in front of the light).
 * Multiple importance sampling with the cosine-weighted directions below (power
 * heuristic, as many of each): with it, a light sample's irradiance is
 * L cos_x p_L / ((p_L^2 + p_B^2) count) instead of L cos_x / (p_L count), p_L its density
 * per solid angle under light sampling and p_B = cos_x / pi, so points next to an emitter
 * (a wall touching a light, the inside of a furnace) get no 1 / r^2 spikes, and a small
 * far light is left to light sampling (a cosine ray that finds it weighs next to nothing). */
uint32_t emitter_light_rays_mis(const emitter_set *set, const rad_scene *scene, rad_vec3 x,
                                rad_vec3 n, double leave, uint32_t count, double turn,
                                uint32_t first, double shift1, double shift2, rad_ray *rays,
                                rad_rgb *irradiance);
/* The same samples without MIS (light sampling alone: no cosine rays go with them), for
 * emitter_to_unshadowed. */
uint32_t emitter_light_rays_alone(const emitter_set *set, const rad_scene *scene, rad_vec3 x,
                                  rad_vec3 n, double leave, uint32_t count, double turn,
                                  uint32_t first, double shift1, double shift2, rad_ray *rays,
                                  rad_rgb *irradiance);

/* The same for one point that takes all `count` samples at once (a mesh vertex): the
 * triangle choices are evenly spaced, (k + turn) / count, so each emitting triangle gets
 * a run of consecutive samples in proportion to its power, and the points on it are the
 * Halton points (bases 2 and 3, shifted by shift1, shift2) of their place in that run: a
 * low-discrepancy set on every triangle. MIS against cosine_per_light x count cosine rays
 * (emitter_cosine_value_weighted with 1 / cosine_per_light): fewer cosine rays than light
 * samples weigh the cosine half down where light sampling does well (its hit-or-miss
 * noise: 0.7 % on a 1 x 1 lamp with as many of each, 512) and keep it where light
 * sampling spikes (next to an emitter). */
uint32_t emitter_light_rays_by_triangle(const emitter_set *set, const rad_scene *scene,
                                        rad_vec3 x, rad_vec3 n, double leave, uint32_t count,
                                        double turn, double shift1, double shift2,
                                        double cosine_per_light, rad_ray *rays,
                                        rad_rgb *irradiance);

/* `count` cosine-weighted directions around n, rays from x + n * leave, for closest-hit
 * queries against the scene's triangles; cos_x[k] receives each one's cosine. The points
 * of the unit square they map are the first `count` of the Owen-scrambled Sobol sequence
 * (core/scrambled_sobol.h), scrambled afresh from rng: stratified at every aspect ratio.
 * When count is a power of two each point goes to the slot of its cell in a grid of count
 * cells (one each), so consecutive rays leave in nearby directions: in sequence order the
 * gather's tracing and locating took 1.5 times as long. */
void emitter_cosine_rays(rad_vec3 x, rad_vec3 n, double leave, uint32_t count, rad_rng *rng,
                         rad_ray *rays, double *cos_x);

/* The irradiance a cosine-weighted ray brings from the emitter it hit (0 for anything
 * else), MIS-weighted against light sampling: pi L_e p_B^2 / ((p_B^2 + p_L^2) count). */
rad_rgb emitter_cosine_value(const emitter_set *set, const rad_scene *scene, const rad_ray *ray,
                             const rad_hit *hit, double cos_x, uint32_t count);

/* The same when light sampling takes light_per_cosine times as many samples as the
 * `count` cosine rays (power heuristic with each density times its sample count). */
rad_rgb emitter_cosine_value_weighted(const emitter_set *set, const rad_scene *scene,
                                      const rad_ray *ray, const rad_hit *hit, double cos_x,
                                      uint32_t count, double light_per_cosine);

/* Most emitting triangles for which the unshadowed irradiance is summed exactly (each costs
 * one contour integral per query, about as much as a few shadow rays). */
#define EMITTER_ANALYTIC_MAX 64u

/* Whether the emitters' unshadowed irradiance can be computed exactly at any point: at
 * most EMITTER_ANALYTIC_MAX emitting triangles, each of uniform emitted radiance (no
 * emission texture). */
bool emitter_unshadowed_exact(const emitter_set *set, const rad_scene *scene);

/* The emitters' irradiance at x (unit normal n) with no shadows, exactly: for each emitting
 * triangle pi L_e F(x), F Lambert's point-to-polygon factor (contour.h) over the part of
 * the triangle in front of x's surface, on the triangle's emitting side (both sides when
 * two-sided). Only when emitter_unshadowed_exact. With it, the shadowed irradiance is that
 * times the share of the light samples' unshadowed irradiance that gets through (the ratio
 * estimator of Heitz, Hill and McGuire 2018): exact where nothing blocks, and its noise
 * only that of the visibility. */
rad_rgb emitter_unshadowed_irradiance(const emitter_set *set, const rad_scene *scene, rad_vec3 x,
                                      rad_vec3 n);

/* Scales the `count` light samples of one query at x (light sampling alone, each channel)
 * so they sum to the exact unshadowed irradiance there: the unblocked ones then sum to the
 * ratio estimate. Only when emitter_unshadowed_exact. */
void emitter_to_unshadowed(const emitter_set *set, const rad_scene *scene, rad_vec3 x,
                           rad_vec3 n, rad_rgb *irradiance, uint32_t count);

/* The same with the unshadowed irradiance `open` already at hand. */
void emitter_scale_to(rad_rgb open, rad_rgb *irradiance, uint32_t count);


#endif
