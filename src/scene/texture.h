/*
 * texture.h - textures (albedo and emission): decoding PNG and JPEG (from a file or from
 * bytes a glb embeds) into linear RGB, and bilinear lookup. What a texel means for a
 * material is material_at.h's; where a patch's points fall on the texture is
 * patch_materials.h's.
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

#endif
