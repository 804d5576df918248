/*
 * patch_inputs.h - the patch inputs' storage (internal): rad_patch_inputs_build fills it
 * from a scene; the light's finer mesh (render/light_refine.c) copies each patch's values
 * to its pieces.
 */
#ifndef RAD_SOLVE_PATCH_INPUTS_H
#define RAD_SOLVE_PATCH_INPUTS_H

#include "radiosity.h"

/* Patch inputs for n patches, every array allocated and unset; NULL when out of memory.
 * rad_patch_inputs_destroy frees them. */
rad_patch_inputs *patch_inputs_alloc(uint32_t n);

#endif
