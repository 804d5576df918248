/*
 * shadow_refine.c - the test that splits a cell crossed by a shadow edge or a penumbra
 * (shadow_refine.h).
 *
 * At each of the cell's 4 x 4 test points x_k: E_k, the irradiance of the sharp sources
 * and of the emitters' probe points (the luminance of it) as if nothing were in the way,
 * and V_k, what the unblocked shadow rays bring. The cell is split when both
 *   - the share that gets through, r_k = V_k / E_k (0 where no source reaches x_k),
 *     differs by more than SPLIT_SHARE between two points: a shadow or a cone's edge
 *     runs between them, not a smooth fall-off (that keeps r = 1); and
 *   - max V - min V is more than SPLIT_SHARE of max E: the jump matters to the light the
 *     cell gets.
 */
#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/random.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "lights/emitters.h"
#include "mesh/shadow_refine.h"
#include "trace/ray.h"

#define SPLIT_SHARE 0.25
#define SHADOW_REFINE_STREAM 0x5badull

/* EMITTER_PROBES points on the emitting triangles: triangles by power (stratified over
 * the cumulative power), points uniform on them (a Halton pair); none without emitters. */
static rad_status place_probes(shadow_refiner *refiner, const rad_scene *scene,
                               rad_error *error)
{
    emitter_set emitters;
    rad_status status = emitters_build(scene, &emitters, error);
    if (status != RAD_OK || emitters.count == 0) {
        emitters_free(&emitters);
        return status;
    }
    for (uint32_t k = 0; k < EMITTER_PROBES; k++) {
        emitter_sample sample;
        emitters_sample(&emitters, scene, (k + 0.5) / EMITTER_PROBES,
                        rad_radical_inverse(k + 1, 2), rad_radical_inverse(k + 1, 3), &sample);
        refiner->probes[k] = (emitter_probe){
            sample.point, sample.normal,
            rgb_luminance(sample.radiance) / (sample.pdf_area * EMITTER_PROBES),
            sample.two_sided};
    }
    refiner->probe_count = EMITTER_PROBES;
    emitters_free(&emitters);
    return RAD_OK;
}

/* Shadow rays from x (normal n, lifted by leave) to the probes that face it, with the
 * irradiance each brings unblocked; returns their count. */
static uint32_t probe_rays(const shadow_refiner *refiner, rad_vec3 x, rad_vec3 n, double leave,
                           rad_ray *rays, rad_rgb *irradiance)
{
    uint32_t got = 0;
    rad_vec3 from = v3_add(x, v3_scale(n, leave));
    for (uint32_t k = 0; k < refiner->probe_count; k++) {
        const emitter_probe *probe = &refiner->probes[k];
        rad_vec3 d = v3_sub(probe->point, x);
        double r2 = v3_dot(d, d);
        if (!(r2 > 0))
            continue;
        double r = sqrt(r2);
        double cos_x = v3_dot(n, d) / r;
        double cos_e = -v3_dot(probe->normal, d) / r;
        if (probe->two_sided)
            cos_e = fabs(cos_e);
        if (!(cos_x > 0) || !(cos_e > 0) || !(probe->power > 0))
            continue;
        double e = probe->power * cos_x * cos_e / r2;
        rad_vec3 to = v3_add(probe->point,
                             v3_scale(probe->normal, v3_dot(probe->normal, d) > 0 ? -leave : leave));
        ray_segment(&rays[got], from, to);
        irradiance[got] = (rad_rgb){e, e, e};
        got++;
    }
    return got;
}

rad_status shadow_refiner_init(shadow_refiner *refiner, const rad_scene *scene,
                               uint32_t levels, size_t budget, rad_error *error)
{
    *refiner = (shadow_refiner){0};
    if (levels == 0)
        return RAD_OK;
    light_set_init(&refiner->set, scene);
    rad_status status = place_probes(refiner, scene, error);
    if (status != RAD_OK)
        return status;
    if (refiner->set.sharp_count == 0 && refiner->probe_count == 0)
        return RAD_OK;
    uint32_t points = SHADOW_REFINE_SIDE * SHADOW_REFINE_SIDE;
    refiner->capacity =
        2 * points *
        (light_set_capacity(&refiner->set, LIGHTS_SHARP, 0) + refiner->probe_count);
    refiner->rays = rad_alloc_array(refiner->capacity, sizeof(*refiner->rays));
    refiner->irradiance = rad_alloc_array(refiner->capacity, sizeof(*refiner->irradiance));
    refiner->occluded = rad_alloc_array(refiner->capacity, sizeof(*refiner->occluded));
    refiner->point_of = rad_alloc_array(refiner->capacity, sizeof(*refiner->point_of));
    if (!refiner->rays || !refiner->irradiance || !refiner->occluded || !refiner->point_of) {
        shadow_refiner_free(refiner);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the shadow refinement");
    }
    status =
        rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &refiner->tracer, error);
    if (status != RAD_OK) {
        shadow_refiner_free(refiner);
        return status;
    }
    refiner->levels = levels;
    refiner->budget = budget;
    return RAD_OK;
}

void shadow_refiner_free(shadow_refiner *refiner)
{
    rad_tracer_destroy(refiner->tracer);
    free(refiner->rays);
    free(refiner->irradiance);
    free(refiner->occluded);
    free(refiner->point_of);
    *refiner = (shadow_refiner){0};
}

/* Point (s, t) of the unit square on the cell: bilinear on a quad, folded onto a
 * triangle (as patch_point). */
static rad_vec3 cell_point(const rad_vec3 *c, uint32_t count, double s, double t)
{
    if (count == 4)
        return v3_add(v3_add(v3_scale(c[0], (1 - s) * (1 - t)), v3_scale(c[1], s * (1 - t))),
                      v3_add(v3_scale(c[2], s * t), v3_scale(c[3], (1 - s) * t)));
    if (s + t > 1) {
        s = 1 - s;
        t = 1 - t;
    }
    return v3_add(v3_scale(c[0], 1 - s - t), v3_add(v3_scale(c[1], s), v3_scale(c[2], t)));
}

bool shadow_refiner_splits(shadow_refiner *refiner, const rad_vec3 *corners, uint32_t count,
                           rad_vec3 normal, double bulge, bool two_sided)
{
    if (!refiner->tracer || refiner->budget_reached)
        return false;
    if (refiner->added + 3 > refiner->budget) {
        refiner->budget_reached = true;
        return false;
    }
    const uint32_t side = SHADOW_REFINE_SIDE, points = side * side;
    uint64_t key = SHADOW_REFINE_STREAM;
    for (uint32_t c = 0; c < count; c++)
        key = hash_bytes(key, &corners[c], sizeof(corners[c]));
    double leave = 2 * bulge + refiner->set.leave;
    uint32_t rays = 0;
    uint32_t sides = two_sided ? 2 : 1;
    for (uint32_t face = 0; face < sides; face++) {
        rad_vec3 n = face == 0 ? normal : v3_scale(normal, -1);
        for (uint32_t q = 0; q < points; q++) {
            rad_rng rng = rad_rng_seed(key, face, q);
            /* on a grid that includes the cell's edges and corners: a shadow edge that
             * crosses an edge the cell shares is seen from both sides, so both split and
             * the finer cells meet along it */
            rad_vec3 x = cell_point(corners, count, (double)(q % side) / (side - 1),
                                    (double)(q / side) / (side - 1));
            uint32_t got = 0;
            if (refiner->set.sharp_count)
                got = light_set_rays(&refiner->set, LIGHTS_SHARP, x, n, leave, q, points, 0,
                                     &rng, &refiner->rays[rays], &refiner->irradiance[rays]);
            got += probe_rays(refiner, x, n, leave, &refiner->rays[rays + got],
                              &refiner->irradiance[rays + got]);
            for (uint32_t k = 0; k < got; k++)
                refiner->point_of[rays + k] = face * points + q;
            rays += got;
        }
    }
    if (rays == 0)
        return false;
    rad_tracer_occluded(refiner->tracer, refiner->rays, rays, refiner->occluded);
    double lit[2 * SHADOW_REFINE_SIDE * SHADOW_REFINE_SIDE] = {0};
    double seen[2 * SHADOW_REFINE_SIDE * SHADOW_REFINE_SIDE] = {0};
    for (uint32_t k = 0; k < rays; k++) {
        double y = rgb_luminance(refiner->irradiance[k]);
        lit[refiner->point_of[k]] += y;
        if (!refiner->occluded[k])
            seen[refiner->point_of[k]] += y;
    }
    bool split = false;
    for (uint32_t face = 0; face < sides && !split; face++) {
        double share_low = INFINITY, share_high = -INFINITY;
        double seen_low = INFINITY, seen_high = -INFINITY, lit_high = 0;
        for (uint32_t q = face * points; q < (face + 1) * points; q++) {
            double share = lit[q] > 0 ? seen[q] / lit[q] : 0;
            share_low = fmin(share_low, share);
            share_high = fmax(share_high, share);
            seen_low = fmin(seen_low, seen[q]);
            seen_high = fmax(seen_high, seen[q]);
            lit_high = fmax(lit_high, lit[q]);
        }
        split = lit_high > 0 && share_high - share_low > SPLIT_SHARE &&
                seen_high - seen_low > SPLIT_SHARE * lit_high;
    }
    if (split) {
        refiner->added += 3;
        refiner->split++;
    }
    return split;
}
