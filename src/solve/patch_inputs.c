/*
 * patch_inputs.c - the per-patch inputs of the radiosity equation, built in one place for
 * every solver and renderer (rad_patch_inputs_build), and the dense system made of them.
 *
 * Exitance E_i = pi * L_e (the material's emitted radiance, METHOD.md section 3); albedo
 * rho_i the material's; for a textured material both are averages over the patch
 * (rad_patch_materials). The scene's light sources add their direct irradiance H_i
 * (lights/patch_direct.c), and the source term S_i = E_i + rho_i H_i is what the solvers
 * take. A patch part of which lies buried inside a closed object (a floor under a box)
 * takes the area of its open part, and H_i that part's mean (mesh/exposed_area.h).
 */
#include <stdint.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "solve/patch_inputs.h"
#include "core/error.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "lights/patch_direct.h"
#include "mesh/exposed_area.h"

void rad_patch_inputs_destroy(rad_patch_inputs *inputs)
{
    if (!inputs)
        return;
    free(inputs->area);
    free(inputs->albedo);
    free(inputs->exitance);
    free(inputs->direct);
    free(inputs->direct_sharp);
    free(inputs->source);
    free(inputs);
}

rad_patch_inputs *patch_inputs_alloc(uint32_t n)
{
    rad_patch_inputs *in = rad_alloc_array(1, sizeof(*in));
    if (in) {
        in->n = n;
        in->area = rad_alloc_array(n, sizeof(*in->area));
        in->albedo = rad_alloc_array(n, sizeof(*in->albedo));
        in->exitance = rad_alloc_array(n, sizeof(*in->exitance));
        in->direct = rad_alloc_array(n, sizeof(*in->direct));
        in->direct_sharp = rad_alloc_array(n, sizeof(*in->direct_sharp));
        in->source = rad_alloc_array(n, sizeof(*in->source));
    }
    if (in && (!in->area || !in->albedo || !in->exitance || !in->direct || !in->direct_sharp ||
               !in->source)) {
        rad_patch_inputs_destroy(in);
        in = NULL;
    }
    return in;
}

rad_status rad_patch_inputs_build(const rad_scene *scene, const rad_mesh *mesh,
                                  rad_patch_inputs **out, rad_error *error)
{
    *out = NULL;
    uint32_t n = mesh->patch_count;
    rad_patch_inputs *in = patch_inputs_alloc(n);
    if (!in) {
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
    /* the light sources' direct light, the first bounce of every solver */
    status = patch_direct_light(scene, mesh, in->direct, in->direct_sharp, error);
    /* the exposed area: the open part of a patch that runs under a box (exposed_area.h);
     * the means over the patch are the open part's */
    double *share = status == RAD_OK ? rad_alloc_array(n ? n : 1, sizeof(*share)) : NULL;
    if (status == RAD_OK && !share)
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for %u patches", n);
    if (status == RAD_OK)
        status = patch_exposed_shares(scene, mesh, share, error);
    for (uint32_t i = 0; status == RAD_OK && i < n; i++)
        if (share[i] < 1) {
            in->area[i] *= share[i];
            in->direct[i] = rgb_scale(in->direct[i], 1 / share[i]);
            in->direct_sharp[i] = rgb_scale(in->direct_sharp[i], 1 / share[i]);
        }
    free(share);
    if (status != RAD_OK) {
        rad_patch_inputs_destroy(in);
        return status;
    }
    for (uint32_t i = 0; i < n; i++)
        in->source[i] = rgb_add(in->exitance[i], rgb_mul(in->albedo[i], in->direct[i]));
    *out = in;
    return RAD_OK;
}

rad_system rad_system_of(const rad_patch_inputs *inputs, const rad_formfactors *formfactors)
{
    /* the areas the matrix was made with (reciprocity holds with them), else the inputs' */
    const double *area = formfactors && formfactors->area ? formfactors->area : inputs->area;
    return (rad_system){inputs->n, formfactors ? formfactors->F : NULL, area,
                        inputs->albedo, inputs->source};
}
