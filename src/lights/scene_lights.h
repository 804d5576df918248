/*
 * scene_lights.h - the scene's light sources (internal): freeing them with the scene.
 */
#ifndef RAD_LIGHTS_SCENE_LIGHTS_H
#define RAD_LIGHTS_SCENE_LIGHTS_H

#include "radiosity.h"

/* Frees the scene's lights and what they own (photometry, environment maps). */
void scene_lights_free(rad_scene *scene);

#endif
