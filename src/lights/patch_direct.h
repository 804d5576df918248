/*
 * patch_direct.h - the direct light of the scene's light sources on each patch (internal).
 */
#ifndef RAD_LIGHTS_PATCH_DIRECT_H
#define RAD_LIGHTS_PATCH_DIRECT_H

#include "radiosity.h"

/* Per patch, the mean over the patch of the direct irradiance from the scene's lights
 * (shadows included): `direct` from all of them, `direct_sharp` from the point, spot,
 * luminaire and sun lights alone (either may be NULL). Zero when the scene has none. */
rad_status patch_direct_light(const rad_scene *scene, const rad_mesh *mesh, rad_rgb *direct,
                              rad_rgb *direct_sharp, rad_error *error);

#endif
