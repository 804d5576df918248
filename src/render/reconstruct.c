/*
 * reconstruct.c - radiance at mesh vertices from per-patch radiosity.
 *
 * Each vertex takes the area-weighted mean of B / pi over the patches that share it.
 * Vertices are shared only inside a smooth region (mesh.c), so creases and emitters keep
 * their own values.
 */
#include <stdlib.h>
#include <string.h>

#include "core/vec3.h"

void rad_reconstruct_vertices(const rad_mesh *mesh, const rad_rgb *B, rad_rgb *vertex_radiance)
{
    double *weight = calloc(mesh->vertex_count ? mesh->vertex_count : 1, sizeof(*weight));
    memset(vertex_radiance, 0, mesh->vertex_count * sizeof(*vertex_radiance));
    if (!weight)
        return; /* callers check nothing here: black is the graceful failure */
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            rad_rgb *L = &vertex_radiance[patch->vertex[k]];
            L->r += patch->area * B[p].r;
            L->g += patch->area * B[p].g;
            L->b += patch->area * B[p].b;
            weight[patch->vertex[k]] += patch->area;
        }
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        double scale = weight[v] > 0 ? 1.0 / (RAD_PI * weight[v]) : 0;
        vertex_radiance[v].r *= scale;
        vertex_radiance[v].g *= scale;
        vertex_radiance[v].b *= scale;
    }
    free(weight);
}
