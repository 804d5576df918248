/*
 * texture.h - albedo textures: decoding PNG and JPEG (from a file or from bytes a glb
 * embeds) into linear RGB, bilinear lookup, and the albedo of a textured surface at a point
 * of a patch: the texel under it, found by a short ray to the scene's own triangle (whose
 * corners carry the texture coordinates). The solve uses each patch's average; the render
 * multiplies the reconstructed irradiance by the texel at each hit.
 */
#ifndef RAD_SCENE_TEXTURE_H
#define RAD_SCENE_TEXTURE_H

#include <stddef.h>

#include "radiosity.h"

/* Decodes PNG or JPEG bytes (told apart by their signature); sRGB 8-bit values become
 * linear. `name` is only for messages. */
rad_status texture_decode(const char *name, const unsigned char *data, size_t size,
                          rad_texture *out, rad_error *error);

rad_status texture_load_file(const char *path, rad_texture *out, rad_error *error);

void texture_free(rad_texture *texture);

/* Bilinear lookup, repeating outside [0,1]; v = 0 is the image's bottom row (OBJ and
 * Assimp's convention). */
rad_rgb texture_sample(const rad_texture *texture, double u, double v);

typedef struct albedo_lookup albedo_lookup;

/* NULL in *out (and RAD_OK) when the scene has no textured triangle. */
rad_status albedo_lookup_create(const rad_scene *scene, albedo_lookup **out, rad_error *error);

void albedo_lookup_destroy(albedo_lookup *lookup);

/* The albedo at `point` of a textured surface facing `normal`: the material's albedo times
 * the texel of the scene triangle found within `reach` along the normal. False when no
 * textured triangle is there (the caller keeps the material's albedo). Thread-safe. */
bool albedo_lookup_at(const albedo_lookup *lookup, rad_vec3 point, rad_vec3 normal,
                      double reach, rad_rgb *albedo);

/* Whether material m has a texture. */
bool albedo_lookup_textured(const albedo_lookup *lookup, uint32_t material);

#endif
