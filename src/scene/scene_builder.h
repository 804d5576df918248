/*
 * scene_builder.h - assembling a rad_scene from any source (file importer, built-in).
 *
 * A source adds materials, named surfaces and triangles with raw positions; finish() then
 * checks every coordinate, welds identical positions, drops degenerate triangles (with a
 * warning naming how many and in which surface), orders triangles by surface and drops
 * surfaces left empty. Sources never touch rad_scene arrays directly.
 */
#ifndef RAD_SCENE_BUILDER_H
#define RAD_SCENE_BUILDER_H

#include "radiosity.h"

typedef struct scene_builder scene_builder;

rad_status scene_builder_create(const char *source, const rad_load_options *options,
                                scene_builder **out, rad_error *error);

/* Index of a copy of the material, or UINT32_MAX when out of memory. Materials are kept
 * even when no triangle uses them; finish() clamps values out of their domains. */
uint32_t scene_builder_material(scene_builder *builder, const rad_material *material);

/* Index of the surface with this name, created on first use; UINT32_MAX when out of
 * memory. Triangles added under the same name from several places join one surface. */
uint32_t scene_builder_surface(scene_builder *builder, const char *name);

/* Index of the surface with this name, or UINT32_MAX when there is none (nothing is
 * created). */
uint32_t scene_builder_find_surface(const scene_builder *builder, const char *name);

/* A surface's RAD_SURFACE_* flags (replaced) and emissivity (default 0.9). */
void scene_builder_set_surface_flags(scene_builder *builder, uint32_t surface, uint32_t flags);
void scene_builder_set_surface_emissivity(scene_builder *builder, uint32_t surface,
                                          double emissivity);

/* Adds a triangle by corner positions, front = counter-clockwise. */
rad_status scene_builder_triangle(scene_builder *builder, uint32_t surface, uint32_t material,
                                  rad_vec3 a, rad_vec3 b, rad_vec3 c, rad_error *error);

/* The same with texture coordinates (u, v) for each corner. */
rad_status scene_builder_triangle_uv(scene_builder *builder, uint32_t surface,
                                     uint32_t material, const rad_vec3 corner[3],
                                     const float uv[3][2], rad_error *error);

/* Takes the texture (its texels now belong to the scene); returns 1 + its index, for
 * rad_material.albedo_texture or emission_texture, or 0 when out of memory (the texture
 * is then freed). */
uint32_t scene_builder_texture(scene_builder *builder, rad_texture *texture);

void scene_builder_set_camera(scene_builder *builder, const rad_camera *camera);

/* The file's up direction (unit; (0,1,0) unless set) and metres per unit (0 = unknown). */
void scene_builder_set_frame(scene_builder *builder, rad_vec3 up, double unit_metres);

/* Validates and hands over the scene; the builder is freed in every case. */
rad_status scene_builder_finish(scene_builder *builder, rad_scene **out, rad_error *error);

void scene_builder_destroy(scene_builder *builder);

#endif
