/*
 * material_at.c - albedo and emitted radiance at a point of a scene triangle, textures
 * applied (see material_at.h).
 */
#include "scene/material_at.h"

#include <math.h>

#include "core/rgb.h"
#include "scene/texture.h"

static const rad_texture *texture_of(const rad_scene *scene, uint32_t index)
{
    return index > 0 && index <= scene->texture_count && scene->uv ? &scene->textures[index - 1]
                                                                  : NULL;
}

const rad_texture *material_albedo_texture(const rad_scene *scene, uint32_t material)
{
    return texture_of(scene, scene->materials[material].albedo_texture);
}

const rad_texture *material_emission_texture(const rad_scene *scene, uint32_t material)
{
    return texture_of(scene, scene->materials[material].emission_texture);
}

bool material_textured(const rad_scene *scene, uint32_t material)
{
    return material_albedo_texture(scene, material) || material_emission_texture(scene, material);
}

/* The texel of `texture` at barycentric (u, v) of triangle t. */
static rad_rgb texel_at(const rad_scene *scene, const rad_texture *texture, uint32_t t, double u,
                        double v)
{
    const float *uv = &scene->uv[t][0][0]; /* u0 v0 u1 v1 u2 v2 */
    double w0 = 1.0 - u - v;
    return texture_sample(texture, w0 * uv[0] + u * uv[2] + v * uv[4],
                          w0 * uv[1] + u * uv[3] + v * uv[5]);
}

rad_rgb material_albedo_at(const rad_scene *scene, uint32_t triangle, double u, double v)
{
    uint32_t m = scene->triangles[triangle].material;
    const rad_texture *texture = material_albedo_texture(scene, m);
    rad_rgb albedo = scene->materials[m].albedo;
    return texture ? rgb_mul(albedo, texel_at(scene, texture, triangle, u, v)) : albedo;
}

rad_rgb material_emission_at(const rad_scene *scene, uint32_t triangle, double u, double v)
{
    uint32_t m = scene->triangles[triangle].material;
    rad_rgb emission = scene->materials[m].emission;
    if (rgb_is_zero(emission))
        return emission;
    const rad_texture *texture = material_emission_texture(scene, m);
    return texture ? rgb_mul(emission, texel_at(scene, texture, triangle, u, v)) : emission;
}

bool material_emits(const rad_scene *scene, uint32_t material)
{
    rad_rgb e = scene->materials[material].emission;
    if (!(e.r > 0 || e.g > 0 || e.b > 0))
        return false;
    const rad_texture *texture = material_emission_texture(scene, material);
    if (!texture)
        return true;
    const float *texel = texture->rgb;
    for (size_t k = 0; k < (size_t)texture->width * texture->height; k++, texel += 3)
        if ((e.r > 0 && texel[0] > 0) || (e.g > 0 && texel[1] > 0) || (e.b > 0 && texel[2] > 0))
            return true;
    return false;
}

rad_rgb material_mean_emission(const rad_scene *scene, uint32_t triangle)
{
    uint32_t m = scene->triangles[triangle].material;
    rad_rgb emission = scene->materials[m].emission;
    const rad_texture *texture = material_emission_texture(scene, m);
    if (!texture || rgb_is_zero(emission))
        return emission;
    /* cell (i, j) of the unit square, mapped by r = sqrt(s): barycentrics (1 - r, r (1 - t),
     * r t), which keeps areas, so equal cells of the square are equal parts of the triangle
     * (the mapping emitters_sample uses) */
    rad_rgb sum = {0, 0, 0};
    const int n = MATERIAL_MEAN_SAMPLES;
    for (int i = 0; i < n; i++) {
        double r = sqrt((i + 0.5) / n);
        for (int j = 0; j < n; j++) {
            double t = (j + 0.5) / n;
            rgb_add_to(&sum, texel_at(scene, texture, triangle, r * (1 - t), r * t));
        }
    }
    return rgb_mul(emission, rgb_scale(sum, 1.0 / (n * n)));
}

bool triangle_two_sided(const rad_scene *scene, uint32_t triangle)
{
    uint32_t surface = scene->triangles[triangle].surface;
    return (scene->surfaces[surface].flags & RAD_SURFACE_TWO_SIDED) != 0;
}
