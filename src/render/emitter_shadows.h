/*
 * emitter_shadows.h - the emitters' direct light at a point behind every occluder,
 * exactly (internal): exact soft shadows.
 *
 * Where the emitters' unshadowed light is exact (emitter_unshadowed_exact: uniform
 * emission, at most EMITTER_ANALYTIC_MAX triangles), the light that reaches a point x is
 * Lambert's contour integral over the part of each emitting polygon that no occluder hides
 * from x: the triangles that may stand between x and the polygon (an occluder tree walked
 * with their pyramid) are projected from x onto the polygon's plane and cut from it
 * (shadow_clip.h), and the pieces left are integrated. No shadow ray, no noise: a
 * penumbra comes out as the path tracer's converged image would show it, at the cost of a
 * few polygon subtractions. The emitting triangles are first joined into convex polygons
 * (coplanar neighbours of the same emission: a quad lamp is one polygon), both faces of a
 * two-sided one. When more than EMITTER_SHADOWS_MAX_OCCLUDERS triangles stand in the way of
 * one polygon, or the visible part breaks into more pieces than shadow_clip keeps, the
 * query says so and the caller samples the light as before.
 */
#ifndef RAD_RENDER_EMITTER_SHADOWS_H
#define RAD_RENDER_EMITTER_SHADOWS_H

#include <stdbool.h>

#include "lights/emitters.h"
#include "radiosity.h"

/* Occluders of one emitting polygon seen from one point, at most (past them: sampled). */
#define EMITTER_SHADOWS_MAX_OCCLUDERS 64u
/* What the occluder tree holds per scene triangle (its copy, 104 bytes, and two nodes of
 * 56), rounded up. Under a --max-memory budget with less than four times that left per
 * triangle the build gives none: the light is then sampled, as it can be in any case. */
#define EMITTER_SHADOWS_BYTES_PER_TRIANGLE 256u

typedef struct emitter_shadows emitter_shadows;

/* For the emitters of `set` in `scene`: *out NULL when their unshadowed light is not exact
 * (emitter_unshadowed_exact), there are none, or the memory budget is short (above). */
rad_status emitter_shadows_build(const rad_scene *scene, const emitter_set *set,
                                 emitter_shadows **out, rad_error *error);
void emitter_shadows_destroy(emitter_shadows *shadows);

/* The emitters' irradiance at x (unit normal n; only light from in front of its plane
 * counts) with every occluder in place, into *irradiance; false (and *irradiance
 * untouched) when more than `most` occluders (at most EMITTER_SHADOWS_MAX_OCCLUDERS) stand
 * between x and one emitting polygon, or the pieces are too many: a case for sampling.
 * The cost grows with the occluders: a few microseconds for ten of them, about what 64
 * shadow rays cost, so a caller with a cheaper way (radiosity_render.c) asks for fewer.
 * Thread-safe. */
bool emitter_shadows_irradiance(const emitter_shadows *shadows, rad_vec3 x, rad_vec3 n,
                                uint32_t most, rad_rgb *irradiance);

#endif
