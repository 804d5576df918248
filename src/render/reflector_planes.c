/*
 * reflector_planes.c - where the light a flat surface reflects kinks
 * (reflector_planes.h).
 */
#include "render/reflector_planes.h"

#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/rgb.h"
#include "core/union_find.h"
#include "core/vec3.h"

/* Sums over a region's patches while it is gathered. */
typedef struct region_sums {
    double area, reflected; /* A and A L */
    rad_vec3 moment;        /* sum of area x centroid */
    rad_vec3 normal;
    uint32_t patches;
} region_sums;

static int by_strength(const void *a, const void *b)
{
    double x = ((const reflector *)a)->strength, y = ((const reflector *)b)->strength;
    return (x < y) - (x > y);
}

rad_status reflectors_build(const rad_mesh *mesh, const rad_rgb *B,
                            const rad_patch_inputs *inputs, reflector_set *out,
                            rad_error *error)
{
    *out = (reflector_set){0};
    uint32_t nv = mesh->vertex_count ? mesh->vertex_count : 1;
    uint32_t *root = rad_alloc_array(nv, sizeof(*root));
    region_sums *sums = rad_alloc_array(nv, sizeof(*sums));
    uint32_t *slot = rad_alloc_array(nv, sizeof(*slot));
    if (!root || !sums || !slot) {
        free(root);
        free(sums);
        free(slot);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the reflecting planes");
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        root[v] = v;
        sums[v] = (region_sums){0};
    }
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        uint32_t a = union_find_root(root, patch->vertex[0]);
        for (uint32_t k = 1; k < patch->vertex_count; k++) {
            uint32_t b = union_find_root(root, patch->vertex[k]);
            if (a != b)
                root[b] = a;
        }
    }
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        region_sums *s = &sums[union_find_root(root, patch->vertex[0])];
        double L = rgb_luminance(rgb_max0(rgb_add(B[p], rgb_scale(inputs->exitance[p], -1))));
        if (s->patches == 0)
            s->normal = patch->normal;
        s->patches++;
        s->area += patch->area;
        s->reflected += patch->area * L;
        s->moment = v3_add(s->moment, v3_scale(patch->centroid, patch->area));
    }
    uint32_t count = 0;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        slot[v] = UINT32_MAX;
        if (root[v] == v && sums[v].area > 0 && sums[v].reflected > 0)
            slot[v] = count++;
    }
    out->items = rad_alloc_array(count ? count : 1, sizeof(*out->items));
    if (!out->items) {
        free(root);
        free(sums);
        free(slot);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the reflecting planes");
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        if (slot[v] != UINT32_MAX) {
            reflector *r = &out->items[slot[v]];
            r->normal = sums[v].normal;
            r->centre = v3_scale(sums[v].moment, 1 / sums[v].area);
            r->offset = v3_dot(r->normal, r->centre);
            r->radius = 0;
            r->strength = sums[v].reflected;
        }
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        uint32_t s = slot[union_find_root(root, patch->vertex[0])];
        if (s == UINT32_MAX)
            continue;
        reflector *r = &out->items[s];
        for (uint32_t k = 0; k < patch->vertex_count; k++)
            r->radius = fmax(r->radius, v3_length(v3_sub(mesh->vertices[patch->vertex[k]],
                                                         r->centre)));
    }
    out->count = count;
    qsort(out->items, count, sizeof(*out->items), by_strength);
    free(root);
    free(sums);
    free(slot);
    return RAD_OK;
}

void reflectors_free(reflector_set *set)
{
    free(set->items);
    *set = (reflector_set){0};
}

double reflector_kink(const reflector_set *set, uint32_t limit, const rad_patch *patch,
                      const rad_vec3 *vertices, double size, double irradiance)
{
    double largest = 0;
    uint32_t count = limit < set->count ? limit : set->count;
    for (uint32_t i = 0; i < count; i++) {
        const reflector *r = &set->items[i];
        double tolerance = 1e-6 * (size + r->radius), lo = INFINITY, hi = -INFINITY;
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            double s = v3_dot(r->normal, vertices[patch->vertex[k]]) - r->offset;
            lo = fmin(lo, s);
            hi = fmax(hi, s);
        }
        if (!(lo < -tolerance && hi > tolerance))
            continue; /* its plane does not cross the patch */
        rad_vec3 to = v3_sub(r->centre, patch->centroid);
        if (!(v3_dot(patch->normal, to) > -r->radius))
            continue; /* wholly behind the patch: seen from none of it */
        double d = fmax(v3_length(to), r->radius);
        double kink = r->strength * size / (4 * RAD_PI * d * d * d * irradiance);
        largest = fmax(largest, kink);
    }
    return largest;
}
