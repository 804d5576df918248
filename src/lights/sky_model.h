/*
 * sky_model.h - PLACEHOLDER until the sky models land.
 */
#ifndef RAD_LIGHTS_SKY_MODEL_H
#define RAD_LIGHTS_SKY_MODEL_H

#include "radiosity.h"

/* (1 / L_z) x the illuminance of an unobstructed horizontal plane under the sky. */
double sky_horizontal_illuminance_factor(rad_sky_model sky, double sun_elevation);

#endif
