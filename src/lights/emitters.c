/*
 * emitters.c - power-proportional sampling of emitting triangles, see emitters.h.
 */
#include "lights/emitters.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "scene/material_at.h"

static double triangle_area(const rad_scene *scene, uint32_t t)
{
    const uint32_t *v = scene->triangles[t].vertex;
    return 0.5 * v3_length(v3_cross(v3_sub(scene->positions[v[1]], scene->positions[v[0]]),
                                    v3_sub(scene->positions[v[2]], scene->positions[v[0]])));
}

/* The power the triangle is sampled by (see emitters.h); 0 for a non-emitter. */
static double triangle_power(const rad_scene *scene, const uint8_t *emits, uint32_t t)
{
    uint32_t m = scene->triangles[t].material;
    if (!emits[m])
        return 0;
    double least = EMITTER_POWER_FLOOR * rgb_luminance(scene->materials[m].emission);
    double mean = rgb_luminance(material_mean_emission(scene, t));
    return (mean > least ? mean : least) * triangle_area(scene, t);
}

rad_status emitters_build(const rad_scene *scene, emitter_set *set, rad_error *error)
{
    memset(set, 0, sizeof(*set));
    uint8_t *emits = rad_alloc_array(scene->material_count ? scene->material_count : 1, 1);
    if (!emits)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for emitters");
    for (uint32_t m = 0; m < scene->material_count; m++)
        emits[m] = material_emits(scene, m);
    uint32_t count = 0;
    for (uint32_t t = 0; t < scene->triangle_count; t++)
        count += emits[scene->triangles[t].material];
    set->triangle = rad_alloc_array(count, sizeof(*set->triangle));
    set->cdf = rad_alloc_array(count, sizeof(*set->cdf));
    set->pdf_area_of = rad_alloc_array(scene->triangle_count, sizeof(*set->pdf_area_of));
    set->shape = rad_alloc_array(count ? count : 1, sizeof(*set->shape));
    set->halton3 = rad_alloc_array(EMITTER_HALTON_TABLE, sizeof(*set->halton3));
    set->halton5 = rad_alloc_array(EMITTER_HALTON_TABLE, sizeof(*set->halton5));
    if (!set->triangle || !set->cdf || !set->pdf_area_of || !set->shape || !set->halton3 ||
        !set->halton5) {
        free(emits);
        emitters_free(set);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for %u emitters", count);
    }
    for (uint32_t j = 0; j < EMITTER_HALTON_TABLE; j++) {
        set->halton3[j] = rad_radical_inverse(j, 3);
        set->halton5[j] = rad_radical_inverse(j, 5);
    }
    double total = 0;
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        double power = triangle_power(scene, emits, t);
        if (!(power > 0))
            continue;
        set->triangle[set->count] = t;
        total += power;
        set->cdf[set->count++] = total;
    }
    free(emits);
    for (uint32_t k = 0; k < set->count; k++) {
        uint32_t t = set->triangle[k];
        double probability = (set->cdf[k] - (k ? set->cdf[k - 1] : 0)) / total;
        set->pdf_area_of[t] = probability / triangle_area(scene, t);
        emitter_triangle *shape = &set->shape[k];
        const rad_triangle *tri = &scene->triangles[t];
        for (int c = 0; c < 3; c++)
            shape->corner[c] = scene->positions[tri->vertex[c]];
        shape->normal = v3_normalize(v3_cross(v3_sub(shape->corner[1], shape->corner[0]),
                                              v3_sub(shape->corner[2], shape->corner[0])));
        shape->emission = scene->materials[tri->material].emission;
        shape->textured = material_emission_texture(scene, tri->material) != NULL;
        shape->two_sided = triangle_two_sided(scene, t);
    }
    for (uint32_t k = 0; k < set->count; k++)
        set->cdf[k] /= total;
    if (set->count)
        set->cdf[set->count - 1] = 1;
    set->total_power = total;
    return RAD_OK;
}

void emitters_free(emitter_set *set)
{
    free(set->triangle);
    free(set->cdf);
    free(set->pdf_area_of);
    free(set->shape);
    free(set->halton3);
    free(set->halton5);
    memset(set, 0, sizeof(*set));
}

uint32_t emitters_index(const emitter_set *set, double u0)
{
    /* the first k with cdf[k] > u0 */
    uint32_t lo = 0, hi = set->count - 1;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (set->cdf[mid] > u0)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

void emitters_sample(const emitter_set *set, const rad_scene *scene, double u0, double u1,
                     double u2, emitter_sample *sample)
{
    uint32_t k = emitters_index(set, u0);
    uint32_t t = set->triangle[k];
    const emitter_triangle *shape = &set->shape[k];
    rad_vec3 a = shape->corner[0], b = shape->corner[1], c = shape->corner[2];
    double r = sqrt(u1); /* uniform in area */
    double wa = 1 - r, wb = r * (1 - u2), wc = r * u2;
    sample->point = v3(wa * a.x + wb * b.x + wc * c.x, wa * a.y + wb * b.y + wc * c.y,
                       wa * a.z + wb * b.z + wc * c.z);
    sample->normal = shape->normal;
    sample->triangle = t;
    sample->u = wb;
    sample->v = wc;
    sample->pdf_area = set->pdf_area_of[t];
    sample->radiance = shape->textured ? material_emission_at(scene, t, wb, wc) : shape->emission;
    sample->two_sided = shape->two_sided;
}

double emitter_cosine(const emitter_sample *sample, rad_vec3 wi, rad_vec3 *facing)
{
    double cosine = -v3_dot(sample->normal, wi);
    bool back = sample->two_sided && cosine < 0;
    if (facing)
        *facing = back ? v3_scale(sample->normal, -1) : sample->normal;
    return back ? -cosine : cosine;
}
