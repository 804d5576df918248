/*
 * patch_materials.h - the material at a point of a mesh patch (internal): albedo and
 * emitted radiance with textures applied, for the per-patch averages of the solve
 * (rad_patch_materials) and for each hit of the radiosity render.
 *
 * A patch knows its material but not the texture coordinates of its points: those belong
 * to the scene triangle under the point, found by a short ray along the patch's normal
 * against a tracer over the textured triangles only; material_at.h then gives the values
 * at the hit's barycentrics. What it is not: a lookup for untextured materials (their
 * values are the material's everywhere, and the caller uses them directly).
 */
#ifndef RAD_SCENE_PATCH_MATERIALS_H
#define RAD_SCENE_PATCH_MATERIALS_H

#include <stdbool.h>

#include "radiosity.h"

typedef struct patch_material_lookup patch_material_lookup;

/* NULL in *out (and RAD_OK) when the scene has no textured triangle. */
rad_status patch_material_lookup_create(const rad_scene *scene, patch_material_lookup **out,
                                        rad_error *error);

void patch_material_lookup_destroy(patch_material_lookup *lookup);

/* Whether material m has a texture (albedo or emission) the lookup serves. */
bool patch_material_textured(const patch_material_lookup *lookup, uint32_t material);

/* The albedo and emitted radiance at `point` of a textured surface facing `normal`: those
 * of the scene triangle found within `reach` along the normal, at the point where the
 * probe meets it. False when no textured triangle is there (the caller keeps its own
 * values; *albedo and *emission are untouched). Thread-safe. */
bool patch_material_at(const patch_material_lookup *lookup, rad_vec3 point, rad_vec3 normal,
                       double reach, rad_rgb *albedo, rad_rgb *emission);

#endif
