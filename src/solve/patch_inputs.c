/*
 * patch_inputs.c - the per-patch inputs of the radiosity equation, built in one place for
 * every solver and renderer (rad_patch_inputs_build), and the dense system made of them.
 *
 * Exitance E_i = pi * L_e (the material's emitted radiance, METHOD.md section 3); albedo
 * rho_i the material's; for a textured material both are averages over the patch
 * (rad_patch_materials).
 */
#include <stdint.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"

void rad_patch_inputs_destroy(rad_patch_inputs *inputs)
{
    if (!inputs)
        return;
    free(inputs->area);
    free(inputs->albedo);
    free(inputs->exitance);
    free(inputs);
}

rad_status rad_patch_inputs_build(const rad_scene *scene, const rad_mesh *mesh,
                                  rad_patch_inputs **out, rad_error *error)
{
    *out = NULL;
    uint32_t n = mesh->patch_count;
    rad_patch_inputs *in = rad_alloc_array(1, sizeof(*in));
    if (in) {
        in->n = n;
        in->area = rad_alloc_array(n, sizeof(*in->area));
        in->albedo = rad_alloc_array(n, sizeof(*in->albedo));
        in->exitance = rad_alloc_array(n, sizeof(*in->exitance));
    }
    if (!in || !in->area || !in->albedo || !in->exitance) {
        rad_patch_inputs_destroy(in);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for %u patches", n);
    }
    for (uint32_t i = 0; i < n; i++)
        in->area[i] = mesh->patches[i].area;
    /* the patch means of albedo and emitted radiance (textures applied); E_i = pi L_e */
    rad_status status = rad_patch_materials(scene, mesh, in->albedo, in->exitance, error);
    if (status != RAD_OK) {
        rad_patch_inputs_destroy(in);
        return status;
    }
    for (uint32_t i = 0; i < n; i++)
        in->exitance[i] = (rad_rgb){RAD_PI * in->exitance[i].r, RAD_PI * in->exitance[i].g,
                                    RAD_PI * in->exitance[i].b};
    *out = in;
    return RAD_OK;
}

rad_system rad_system_of(const rad_patch_inputs *inputs, const rad_formfactors *formfactors)
{
    return (rad_system){inputs->n, formfactors ? formfactors->F : NULL, inputs->area,
                        inputs->albedo, inputs->exitance};
}
