/*
 * system_from_mesh.c - the per-patch arrays of the radiosity system from a mesh.
 *
 * Exitance E_i = pi * L_e (the material's emitted radiance, METHOD.md section 3); albedo
 * rho_i the material's, or its average over the patch for a textured one.
 */
#include <stdint.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"

rad_status rad_system_from_mesh(const rad_scene *scene, const rad_mesh *mesh,
                                const rad_formfactors *formfactors, rad_system *system,
                                rad_error *error)
{
    uint32_t n = mesh->patch_count;
    if (formfactors && formfactors->n != n)
        return rad_fail(error, RAD_ERR_INVALID, "form factors are for %u patches, mesh has %u",
                        formfactors->n, n);
    double *area = rad_alloc_array(n, sizeof(*area));
    rad_rgb *albedo = rad_alloc_array(n, sizeof(*albedo));
    rad_rgb *exitance = rad_alloc_array(n, sizeof(*exitance));
    if (!area || !albedo || !exitance) {
        free(area);
        free(albedo);
        free(exitance);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for %u patches", n);
    }
    for (uint32_t i = 0; i < n; i++) {
        const rad_material *m = &scene->materials[mesh->patches[i].material];
        area[i] = mesh->patches[i].area;
        albedo[i] = m->albedo;
        exitance[i] = (rad_rgb){RAD_PI * m->emission.r, RAD_PI * m->emission.g,
                                RAD_PI * m->emission.b};
    }
    if (scene->texture_count > 0) {
        rad_status status = rad_patch_albedo(scene, mesh, albedo, error);
        if (status != RAD_OK) {
            free(area);
            free(albedo);
            free(exitance);
            return status;
        }
    }
    system->n = n;
    system->F = formfactors ? formfactors->F : NULL;
    system->area = area;
    system->albedo = albedo;
    system->exitance = exitance;
    return RAD_OK;
}

void rad_system_free_arrays(rad_system *system)
{
    /* the arrays are const for the solvers, owned here */
    free((void *)(uintptr_t)system->area);
    free((void *)(uintptr_t)system->albedo);
    free((void *)(uintptr_t)system->exitance);
    system->area = NULL;
    system->albedo = NULL;
    system->exitance = NULL;
}
