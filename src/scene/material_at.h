/*
 * material_at.h - the material at a point of a scene triangle (internal): its albedo and
 * its emitted radiance with the material's textures applied.
 *
 * The one place that says what a material is at a point: albedo = Kd x the albedo texel,
 * emitted radiance = Ke x the emission texel, both read at the texture coordinates that
 * the triangle's corners carry (rad_scene.uv), interpolated with the barycentrics of a
 * rad_hit. Every renderer (Whitted, the path tracer, the radiosity render through the
 * patch lookups of patch_materials.h) and every per-patch average goes through it, so a
 * texture is honoured the same way everywhere. What it is not: a BRDF (the specular term
 * stays the material's), and it checks nothing (the scene is valid by construction).
 */
#ifndef RAD_SCENE_MATERIAL_AT_H
#define RAD_SCENE_MATERIAL_AT_H

#include <stdbool.h>

#include "radiosity.h"

/* The material's albedo / emission texture, or NULL when it has none or the scene keeps
 * no texture coordinates (a textured material is then its flat colour everywhere). */
const rad_texture *material_albedo_texture(const rad_scene *scene, uint32_t material);
const rad_texture *material_emission_texture(const rad_scene *scene, uint32_t material);

/* Either texture. */
bool material_textured(const rad_scene *scene, uint32_t material);

/* Albedo and emitted radiance at barycentric point (u, v) of scene triangle t:
 * point = (1-u-v) p0 + u p1 + v p2, as rad_hit gives them. */
rad_rgb material_albedo_at(const rad_scene *scene, uint32_t triangle, double u, double v);
rad_rgb material_emission_at(const rad_scene *scene, uint32_t triangle, double u, double v);

/* The triangle's surface is two-sided (RAD_SURFACE_TWO_SIDED): its back radiates and
 * reflects as its front does, with the same material. */
bool triangle_two_sided(const rad_scene *scene, uint32_t triangle);

/* The material emits somewhere: an emission factor > 0 in some channel and, with an
 * emission texture, a texel that is not black in such a channel. O(texels). */
bool material_emits(const rad_scene *scene, uint32_t material);

/* Points per side of the stratified set that estimates a triangle's mean emitted radiance
 * (16 x 16 = 256 points of equal area). */
#define MATERIAL_MEAN_SAMPLES 16

/* The mean emitted radiance over triangle t: exact without an emission texture, else the
 * mean of the texel over MATERIAL_MEAN_SAMPLES^2 fixed points, one at the centre of each
 * cell of an equal-area split of the triangle. Deterministic. */
rad_rgb material_mean_emission(const rad_scene *scene, uint32_t triangle);

#endif
