/*
 * patch_materials.c - the material at points of mesh patches, and each patch's average
 * albedo and emitted radiance (see patch_materials.h). One probe per point: a short ray
 * along the patch's normal finds the textured scene triangle under it, and material_at.h
 * says what the material is there.
 */
#include "scene/patch_materials.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "mesh/patch_point.h"
#include "scene/material_at.h"

/* Points per patch edge for the averages (8 x 8 per patch). */
#define PATCH_SAMPLES 8

struct patch_material_lookup {
    const rad_scene *scene;
    rad_tracer *tracer;
    uint32_t *triangle_of; /* tracer triangle -> scene triangle */
    double reach;          /* the least reach: float rounding of points at the scene's size */
};

bool patch_material_textured(const patch_material_lookup *lookup, uint32_t material)
{
    return lookup && material_textured(lookup->scene, material);
}

rad_status patch_material_lookup_create(const rad_scene *scene, patch_material_lookup **out,
                                        rad_error *error)
{
    *out = NULL;
    uint32_t count = 0;
    for (uint32_t t = 0; t < scene->triangle_count; t++)
        count += material_textured(scene, scene->triangles[t].material);
    if (count == 0)
        return RAD_OK;
    patch_material_lookup *l = rad_alloc_array(1, sizeof(*l));
    uint32_t(*triangles)[3] = rad_alloc_array(count, sizeof(*triangles));
    if (!l || !triangles || !(l->triangle_of = rad_alloc_array(count, sizeof(uint32_t)))) {
        free(triangles);
        patch_material_lookup_destroy(l);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for texture lookups");
    }
    l->scene = scene;
    uint32_t k = 0;
    for (uint32_t t = 0; t < scene->triangle_count; t++)
        if (material_textured(scene, scene->triangles[t].material)) {
            memcpy(triangles[k], scene->triangles[t].vertex, sizeof(triangles[k]));
            l->triangle_of[k++] = t;
        }
    rad_status status = rad_tracer_create(RAD_TRACER_EMBREE, scene->positions,
                                          scene->position_count,
                                          (const uint32_t(*)[3])triangles, count, &l->tracer,
                                          error);
    free(triangles);
    if (status != RAD_OK) {
        patch_material_lookup_destroy(l);
        return status;
    }
    rad_vec3 lo, hi;
    rad_scene_bounds(scene, &lo, &hi);
    double largest = fmax(fmax(fabs(lo.x), fabs(hi.x)), fmax(fmax(fabs(lo.y), fabs(hi.y)),
                                                            fmax(fabs(lo.z), fabs(hi.z))));
    l->reach = 1e-5 * v3_length(v3_sub(hi, lo)) + 1e-6 * largest;
    *out = l;
    return RAD_OK;
}

void patch_material_lookup_destroy(patch_material_lookup *lookup)
{
    if (!lookup)
        return;
    rad_tracer_destroy(lookup->tracer);
    free(lookup->triangle_of);
    free(lookup);
}

/* The ray from `reach` in front of the point back through it. */
static void probe(rad_ray *ray, rad_vec3 point, rad_vec3 normal, double reach)
{
    rad_vec3 origin = v3_add(point, v3_scale(normal, reach));
    ray->origin[0] = (float)origin.x;
    ray->origin[1] = (float)origin.y;
    ray->origin[2] = (float)origin.z;
    ray->direction[0] = (float)-normal.x;
    ray->direction[1] = (float)-normal.y;
    ray->direction[2] = (float)-normal.z;
    ray->t_near = 0;
    ray->t_far = (float)(2 * reach);
}

/* The material at a probe's hit, or false when it missed. */
static bool material_of_hit(const patch_material_lookup *l, const rad_hit *hit, rad_rgb *albedo,
                            rad_rgb *emission)
{
    if (hit->triangle == RAD_NO_HIT)
        return false;
    uint32_t t = l->triangle_of[hit->triangle];
    *albedo = material_albedo_at(l->scene, t, hit->u, hit->v);
    *emission = material_emission_at(l->scene, t, hit->u, hit->v);
    return true;
}

bool patch_material_at(const patch_material_lookup *l, rad_vec3 point, rad_vec3 normal,
                       double reach, rad_rgb *albedo, rad_rgb *emission)
{
    rad_ray ray;
    rad_hit hit;
    probe(&ray, point, normal, fmax(reach, l->reach));
    rad_tracer_intersect(l->tracer, &ray, 1, &hit);
    return material_of_hit(l, &hit, albedo, emission);
}

/* The means over the patch's 8 x 8 points of the textured albedo and emission; false when
 * no probe found the scene's triangle (the material's values then stand). */
static bool patch_means(const patch_material_lookup *l, const rad_mesh *mesh,
                        const rad_patch *patch, rad_rgb *albedo, rad_rgb *emission)
{
    rad_ray rays[PATCH_SAMPLES * PATCH_SAMPLES];
    rad_hit hits[PATCH_SAMPLES * PATCH_SAMPLES];
    double reach = fmax(2 * patch->bulge, l->reach);
    for (int i = 0; i < PATCH_SAMPLES; i++)
        for (int j = 0; j < PATCH_SAMPLES; j++)
            probe(&rays[i * PATCH_SAMPLES + j],
                  patch_point(mesh, patch, (i + 0.5) / PATCH_SAMPLES, (j + 0.5) / PATCH_SAMPLES),
                  patch->normal, reach);
    rad_tracer_intersect(l->tracer, rays, PATCH_SAMPLES * PATCH_SAMPLES, hits);
    rad_rgb albedo_sum = {0, 0, 0}, emission_sum = {0, 0, 0};
    unsigned found = 0;
    for (int k = 0; k < PATCH_SAMPLES * PATCH_SAMPLES; k++) {
        rad_rgb a, e;
        if (material_of_hit(l, &hits[k], &a, &e)) {
            rgb_add_to(&albedo_sum, a);
            rgb_add_to(&emission_sum, e);
            found++;
        }
    }
    if (!found)
        return false;
    *albedo = rgb_scale(albedo_sum, 1.0 / found);
    *emission = rgb_scale(emission_sum, 1.0 / found);
    return true;
}

rad_status rad_patch_materials(const rad_scene *scene, const rad_mesh *mesh, rad_rgb *albedo,
                               rad_rgb *emission, rad_error *error)
{
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_material *m = &scene->materials[mesh->patches[p].material];
        if (albedo)
            albedo[p] = m->albedo;
        if (emission)
            emission[p] = m->emission;
    }
    patch_material_lookup *l = NULL;
    rad_status status = patch_material_lookup_create(scene, &l, error);
    if (status != RAD_OK || !l)
        return status;
    int64_t n = mesh->patch_count;
#pragma omp parallel for schedule(dynamic, 64)
    for (int64_t p = 0; p < n; p++) {
        const rad_patch *patch = &mesh->patches[p];
        rad_rgb a, e;
        if (!material_textured(scene, patch->material) || !patch_means(l, mesh, patch, &a, &e))
            continue;
        if (albedo)
            albedo[p] = a;
        if (emission)
            emission[p] = e;
    }
    patch_material_lookup_destroy(l);
    return RAD_OK;
}
