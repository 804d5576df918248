/*
 * texture_albedo.c - the albedo of textured surfaces at points, and each patch's average
 * (see texture.h). A patch knows its material but not the texture coordinates of its
 * points; they come from the scene triangle under the point, found by a short ray along
 * the patch's normal against a tracer over the textured triangles only.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"
#include "scene/texture.h"

/* Points per patch edge for the average albedo (8 x 8 per patch). */
#define PATCH_SAMPLES 8

struct albedo_lookup {
    const rad_scene *scene;
    rad_tracer *tracer;
    uint32_t *triangle_of; /* tracer triangle -> scene triangle */
    double reach;          /* the least reach: float rounding of points at the scene's size */
};

static bool material_textured(const rad_scene *scene, uint32_t m)
{
    uint32_t t = scene->materials[m].albedo_texture;
    return t > 0 && t <= scene->texture_count && scene->uv;
}

bool albedo_lookup_textured(const albedo_lookup *lookup, uint32_t material)
{
    return lookup && material_textured(lookup->scene, material);
}

rad_status albedo_lookup_create(const rad_scene *scene, albedo_lookup **out, rad_error *error)
{
    *out = NULL;
    uint32_t count = 0;
    for (uint32_t t = 0; t < scene->triangle_count; t++)
        count += material_textured(scene, scene->triangles[t].material);
    if (count == 0)
        return RAD_OK;
    albedo_lookup *l = calloc(1, sizeof(*l));
    uint32_t(*triangles)[3] = rad_alloc_array(count, sizeof(*triangles));
    if (!l || !triangles || !(l->triangle_of = rad_alloc_array(count, sizeof(uint32_t)))) {
        free(triangles);
        albedo_lookup_destroy(l);
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
        albedo_lookup_destroy(l);
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

void albedo_lookup_destroy(albedo_lookup *lookup)
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

/* The textured albedo at a hit, or false. */
static bool albedo_of_hit(const albedo_lookup *l, const rad_hit *hit, rad_rgb *albedo)
{
    if (hit->triangle == RAD_NO_HIT)
        return false;
    const rad_scene *scene = l->scene;
    uint32_t t = l->triangle_of[hit->triangle];
    const rad_material *m = &scene->materials[scene->triangles[t].material];
    const float *uv = &scene->uv[t][0][0]; /* u0 v0 u1 v1 u2 v2 */
    double w0 = 1.0 - hit->u - hit->v;
    double u = w0 * uv[0] + hit->u * uv[2] + hit->v * uv[4];
    double v = w0 * uv[1] + hit->u * uv[3] + hit->v * uv[5];
    rad_rgb texel = texture_sample(&scene->textures[m->albedo_texture - 1], u, v);
    *albedo = (rad_rgb){m->albedo.r * texel.r, m->albedo.g * texel.g, m->albedo.b * texel.b};
    return true;
}

bool albedo_lookup_at(const albedo_lookup *l, rad_vec3 point, rad_vec3 normal, double reach,
                      rad_rgb *albedo)
{
    rad_ray ray;
    rad_hit hit;
    probe(&ray, point, normal, fmax(reach, l->reach));
    rad_tracer_intersect(l->tracer, &ray, 1, &hit);
    return albedo_of_hit(l, &hit, albedo);
}

/* Point (s, t) in [0,1]^2 of a patch: bilinear on a quad; on a triangle, the unit square
 * folded onto it. */
static rad_vec3 patch_point(const rad_mesh *mesh, const rad_patch *p, double s, double t)
{
    const rad_vec3 *v = mesh->vertices;
    if (p->vertex_count == 4)
        return v3_add(v3_add(v3_scale(v[p->vertex[0]], (1 - s) * (1 - t)),
                             v3_scale(v[p->vertex[1]], s * (1 - t))),
                      v3_add(v3_scale(v[p->vertex[2]], s * t), v3_scale(v[p->vertex[3]], (1 - s) * t)));
    if (s + t > 1) {
        s = 1 - s;
        t = 1 - t;
    }
    return v3_add(v3_scale(v[p->vertex[0]], 1 - s - t),
                  v3_add(v3_scale(v[p->vertex[1]], s), v3_scale(v[p->vertex[2]], t)));
}

rad_status rad_patch_albedo(const rad_scene *scene, const rad_mesh *mesh, rad_rgb *albedo,
                            rad_error *error)
{
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        albedo[p] = scene->materials[mesh->patches[p].material].albedo;
    albedo_lookup *l = NULL;
    rad_status status = albedo_lookup_create(scene, &l, error);
    if (status != RAD_OK || !l)
        return status;
    int64_t n = mesh->patch_count;
#pragma omp parallel for schedule(dynamic, 64)
    for (int64_t p = 0; p < n; p++) {
        const rad_patch *patch = &mesh->patches[p];
        if (!material_textured(scene, patch->material))
            continue;
        rad_ray rays[PATCH_SAMPLES * PATCH_SAMPLES];
        rad_hit hits[PATCH_SAMPLES * PATCH_SAMPLES];
        double reach = fmax(2 * patch->bulge, l->reach);
        for (int i = 0; i < PATCH_SAMPLES; i++)
            for (int j = 0; j < PATCH_SAMPLES; j++)
                probe(&rays[i * PATCH_SAMPLES + j],
                      patch_point(mesh, patch, (i + 0.5) / PATCH_SAMPLES,
                                  (j + 0.5) / PATCH_SAMPLES),
                      patch->normal, reach);
        rad_tracer_intersect(l->tracer, rays, PATCH_SAMPLES * PATCH_SAMPLES, hits);
        rad_rgb sum = {0, 0, 0};
        unsigned found = 0;
        for (int k = 0; k < PATCH_SAMPLES * PATCH_SAMPLES; k++) {
            rad_rgb a;
            if (albedo_of_hit(l, &hits[k], &a)) {
                sum = (rad_rgb){sum.r + a.r, sum.g + a.g, sum.b + a.b};
                found++;
            }
        }
        if (found)
            albedo[p] = (rad_rgb){sum.r / found, sum.g / found, sum.b / found};
    }
    albedo_lookup_destroy(l);
    return RAD_OK;
}
