/*
 * emitter_shadows.c - the emitters' direct light behind every occluder, exactly
 * (emitter_shadows.h).
 */
#include "render/emitter_shadows.h"

#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/memory.h"
#include "core/rgb.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "render/emitter_light.h"
#include "scene/material_at.h"
#include "surface_viewfactors/occluder_tree.h"
#include "surface_viewfactors/shadow_clip.h"
#include "surface_viewfactors/vf_geometry.h"

/* What the occluder tree's triangles belong to: none of them is a light's own (a light's
 * own triangles lie in its plane, which bounds the pyramid) */
#define NO_SOURCE UINT32_MAX
#define LIGHT_SOURCE (UINT32_MAX - 1)

struct emitter_shadows {
    occluder_tree *tree;
    vf_polygon *light; /* the emitting polygons, fronts toward what they light */
    rad_rgb *radiance; /* their L_e */
    uint32_t count;
    double epsilon; /* scene units: touching the pyramid's boundary is not blocking */
};

void emitter_shadows_destroy(emitter_shadows *shadows)
{
    if (!shadows)
        return;
    occluder_tree_destroy(shadows->tree);
    free(shadows->light);
    free(shadows->radiance);
    free(shadows);
}

static bool same_rgb(rad_rgb a, rad_rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

/* Adds the polygon (corners in either order) as a light facing along `normal`, and its
 * back when `both`. */
static void add_light(emitter_shadows *s, const shadow_polygon *polygon, rad_vec3 normal,
                      rad_rgb radiance, bool both)
{
    for (int side = 0; side < (both ? 2 : 1); side++) {
        vf_polygon *p = &s->light[s->count];
        *p = (vf_polygon){.count = polygon->count, .source = LIGHT_SOURCE};
        rad_vec3 newell = v3(0, 0, 0);
        for (unsigned k = 0; k < polygon->count; k++)
            newell = v3_add(newell, v3_cross(polygon->vertex[k],
                                             polygon->vertex[(k + 1) % polygon->count]));
        rad_vec3 facing = side ? v3_scale(normal, -1) : normal;
        bool reverse = v3_dot(newell, facing) < 0;
        for (unsigned k = 0; k < polygon->count; k++)
            p->vertex[k] = polygon->vertex[reverse ? polygon->count - 1 - k : k];
        p->normal = facing;
        vf_polygon_finish(p);
        s->radiance[s->count++] = radiance;
    }
}

rad_status emitter_shadows_build(const rad_scene *scene, const emitter_set *set,
                                 emitter_shadows **out, rad_error *error)
{
    *out = NULL;
    if (set->count == 0 || !emitter_unshadowed_exact(set, scene))
        return RAD_OK;
    uint64_t left = rad_memory_budget_left();
    if (left != UINT64_MAX &&
        left / 4 < (uint64_t)scene->triangle_count * EMITTER_SHADOWS_BYTES_PER_TRIANGLE)
        return RAD_OK; /* an extra: the light can be sampled */
    emitter_shadows *s = rad_alloc_array(1, sizeof(*s));
    uint32_t *source = rad_alloc_array(scene->triangle_count ? scene->triangle_count : 1,
                                       sizeof(*source));
    shadow_occluder *group = rad_alloc_array(set->count, sizeof(*group));
    shadow_polygon *joined = rad_alloc_array(set->count, sizeof(*joined));
    uint8_t *done = rad_alloc_array(set->count, 1);
    rad_status status = RAD_OK;
    if (s) {
        *s = (emitter_shadows){0};
        s->light = rad_alloc_array(2 * (size_t)set->count, sizeof(*s->light));
        s->radiance = rad_alloc_array(2 * (size_t)set->count, sizeof(*s->radiance));
    }
    if (!s || !source || !group || !joined || !done || !s->light || !s->radiance) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the emitters' shadows");
        goto done;
    }
    for (uint32_t t = 0; t < scene->triangle_count; t++)
        source[t] = NO_SOURCE;
    status = occluder_tree_build(scene, source, true, &s->tree, error);
    if (status != RAD_OK)
        goto done;
    rad_vec3 lo, hi;
    v3_bounds(scene->positions, scene->position_count, &lo, &hi);
    s->epsilon = RAD_PLANE_EPSILON * v3_length(v3_sub(hi, lo));
    /* the emitting triangles by emission, sidedness and plane, joined where they can be */
    for (uint32_t k = 0; k < set->count; k++) {
        if (done[k])
            continue;
        const uint32_t t = set->triangle[k];
        const rad_rgb radiance = material_emission_at(scene, t, 1.0 / 3, 1.0 / 3);
        const bool both = triangle_two_sided(scene, t);
        const uint32_t *v = scene->triangles[t].vertex;
        rad_vec3 a = scene->positions[v[0]];
        rad_vec3 normal = v3_normalize(v3_cross(v3_sub(scene->positions[v[1]], a),
                                                v3_sub(scene->positions[v[2]], a)));
        if (!(v3_length(normal) > 0.5)) { /* no area: no light */
            done[k] = 1;
            continue;
        }
        uint32_t members = 0;
        for (uint32_t m = k; m < set->count; m++) {
            const uint32_t u = set->triangle[m];
            const uint32_t *w = scene->triangles[u].vertex;
            rad_vec3 b = scene->positions[w[0]];
            rad_vec3 other = v3_normalize(v3_cross(v3_sub(scene->positions[w[1]], b),
                                                   v3_sub(scene->positions[w[2]], b)));
            if (done[m] || triangle_two_sided(scene, u) != both ||
                !same_rgb(material_emission_at(scene, u, 1.0 / 3, 1.0 / 3), radiance) ||
                v3_dot(other, normal) < 1 - 1e-12 ||
                fabs(v3_dot(normal, v3_sub(b, a))) > s->epsilon)
                continue;
            done[m] = 1;
            for (int c = 0; c < 3; c++)
                group[members].corner[c] = scene->positions[w[c]];
            members++;
        }
        uint32_t polygons = shadow_join_occluders(group, members, joined);
        for (uint32_t j = 0; j < polygons; j++)
            add_light(s, &joined[j], normal, radiance, both);
    }
done:
    free(source);
    free(group);
    free(joined);
    free(done);
    if (status != RAD_OK) {
        emitter_shadows_destroy(s);
        return status;
    }
    *out = s;
    return RAD_OK;
}

bool emitter_shadows_irradiance(const emitter_shadows *shadows, rad_vec3 x, rad_vec3 n,
                                uint32_t most, rad_rgb *irradiance)
{
    if (most > EMITTER_SHADOWS_MAX_OCCLUDERS)
        most = EMITTER_SHADOWS_MAX_OCCLUDERS;
    shadow_occluder occluders[EMITTER_SHADOWS_MAX_OCCLUDERS];
    rad_rgb sum = {0, 0, 0};
    for (uint32_t k = 0; k < shadows->count; k++) {
        const vf_polygon *light = &shadows->light[k];
        if (!(v3_dot(light->normal, v3_sub(x, light->vertex[0])) > shadows->epsilon))
            continue; /* behind the light, or in its plane */
        bool above = false; /* some of it above x's horizon: else it lights nothing here,
                               and its (flat) pyramid need not be walked */
        for (unsigned c = 0; c < light->count && !above; c++)
            above = v3_dot(n, v3_sub(light->vertex[c], x)) > shadows->epsilon;
        if (!above)
            continue;
        uint32_t found = occluder_tree_collect_from_point(shadows->tree, x, n, light,
                                                          shadows->epsilon, occluders, most);
        if (found > most)
            return false;
        double F = shadow_visible_factor(x, n, light, occluders, found, shadows->epsilon);
        if (F < 0)
            return false;
        rgb_add_to(&sum, rgb_scale(shadows->radiance[k], RAD_PI * F));
    }
    *irradiance = sum;
    return true;
}
