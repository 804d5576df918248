/*
 * hidden_patches.c - the patches no one can see: a floor's patches under a box resting on
 * it, a wall's inside another object. Their radiosity is (nearly) zero and right, but a
 * vertex they share with visible patches would average it in and darken the visible
 * side of every contact line; the reconstruction leaves them out
 * (display_mesh_radiance_weighted).
 *
 * A patch is hidden when every one of HIDDEN_RAYS rays from its centre over its
 * hemisphere (cosine-weighted, stratified) meets the back of a surface: it is enclosed.
 * A patch that sees any front, or the open sky, is not. The same rays tell which patches
 * are near another surface (a crease, a contact, a corner): one of them hits within a few
 * patch widths.
 */
#include <math.h>

#include "core/hemisphere.h"
#include "core/random.h"
#include "core/vec3.h"
#include "reconstruct/display_mesh.h"
#include "trace/ray.h"

#define HIDDEN_RAYS 16u
#define HIDDEN_STREAM 0x41DDE4ull

void display_hidden_patches(const rad_mesh *mesh, const rad_tracer *tracer, double leave,
                            uint8_t *hidden, uint8_t *near, double near_widths)
{
#pragma omp parallel for schedule(dynamic, 64)
    for (int64_t p = 0; p < (int64_t)mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        rad_vec3 n = patch->normal;
        rad_vec3 a, b;
        hemisphere_frame(n, &a, &b);
        rad_vec3 origin = v3_add(patch->centroid, v3_scale(n, 2 * patch->behind + leave));
        rad_rng rng = rad_rng_seed(HIDDEN_STREAM, (uint64_t)p, 0);
        rad_ray rays[HIDDEN_RAYS];
        rad_hit hits[HIDDEN_RAYS];
        for (uint32_t k = 0; k < HIDDEN_RAYS; k++) {
            double u1 = ((k % 4) + rad_rng_uniform(&rng)) / 4, u2 = ((k / 4) + rad_rng_uniform(&rng)) / 4;
            rad_vec3 w = cosine_direction(n, a, b, u1, u2, 0, NULL);
            ray_set(&rays[k], origin, w, 0, INFINITY);
        }
        rad_tracer_intersect(tracer, rays, HIDDEN_RAYS, hits);
        uint8_t enclosed = 1;
        double closest = INFINITY;
        for (uint32_t k = 0; k < HIDDEN_RAYS; k++) {
            enclosed &= hits[k].triangle != RAD_NO_HIT && !hits[k].front;
            if (hits[k].triangle != RAD_NO_HIT)
                closest = fmin(closest, hits[k].t);
        }
        hidden[p] = enclosed;
        if (near)
            near[p] = closest < near_widths * sqrt(patch->area);
    }
}
