/*
 * fingerprint.c - rad_solution_fingerprint: a hash of everything a radiosity solution
 * depends on, so a solution file is never applied to another scene or meshing.
 *
 * What is hashed: the scene's positions and triangles, each patch's albedo and source term
 * (exitance plus the reflected direct light of light sources) as rad_patch_inputs_build
 * hands them to every solver (so however materials and lights come to patches,
 * the fingerprint follows), the patch size, and the mesh's counts and patch vertices. Not
 * hashed: names, the file's path, cameras and specular terms, which do not change B. The
 * mesh's computed coordinates are left out on purpose: they follow from the hashed inputs,
 * and leaving them out keeps the value the same for builds that round differently.
 */
#include "core/error.h"
#include "core/hash.h"

rad_status rad_solution_fingerprint(const rad_scene *scene, const rad_mesh *mesh,
                                    uint64_t *fingerprint, rad_error *error)
{
    rad_patch_inputs *inputs = NULL;
    rad_status status = rad_patch_inputs_build(scene, mesh, &inputs, error);
    if (status != RAD_OK)
        return status;
    uint64_t h = RAD_HASH_START;
    h = hash_u32(h, scene->position_count);
    for (uint32_t v = 0; v < scene->position_count; v++) {
        h = hash_f64(h, scene->positions[v].x);
        h = hash_f64(h, scene->positions[v].y);
        h = hash_f64(h, scene->positions[v].z);
    }
    h = hash_u32(h, scene->triangle_count);
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        const rad_triangle *tri = &scene->triangles[t];
        for (int k = 0; k < 3; k++)
            h = hash_u32(h, tri->vertex[k]);
        h = hash_u32(h, tri->material);
        h = hash_u32(h, tri->surface);
    }
    h = hash_f64(h, mesh->patch_size);
    h = hash_u32(h, mesh->vertex_count);
    h = hash_u32(h, mesh->patch_count);
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        h = hash_u32(h, patch->vertex_count);
        for (uint32_t k = 0; k < patch->vertex_count; k++)
            h = hash_u32(h, patch->vertex[k]);
        const rad_rgb *rho = &inputs->albedo[p], *E = &inputs->source[p];
        h = hash_f64(h, rho->r);
        h = hash_f64(h, rho->g);
        h = hash_f64(h, rho->b);
        h = hash_f64(h, E->r);
        h = hash_f64(h, E->g);
        h = hash_f64(h, E->b);
    }
    rad_patch_inputs_destroy(inputs);
    *fingerprint = h;
    return RAD_OK;
}
