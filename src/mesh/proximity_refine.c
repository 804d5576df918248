/*
 * proximity_refine.c - the test that splits a cell much larger than its distance to
 * the surfaces it sees (proximity_refine.h).
 */
#include <math.h>

#include "core/error.h"
#include "core/hash.h"
#include "core/hemisphere.h"
#include "core/random.h"
#include "core/vec3.h"
#include "mesh/proximity_refine.h"

/* A cell is split when its longest edge exceeds this share of the mean distance its
 * rays travel to a surface: at 1/3 the Cornell box keeps its default patches (its mean
 * distance is about 300 of its 555 units, 150 next to a crease, against patches of 26)
 * and a 5 m room gets cells under 0.8 m. */
#define PROXIMITY_SHARE (1.0 / 3.0)
/* ... and when at least this share of them meet a surface (open ground does not). */
#define PROXIMITY_HIT_SHARE 0.25
#define PROXIMITY_STREAM 0x9e0bull
#define PROXIMITY_ROWS 4u /* the rays' strata: 4 x 8 */

rad_status proximity_refiner_init(proximity_refiner *refiner, const rad_scene *scene,
                                  uint32_t levels, size_t budget, rad_error *error)
{
    *refiner = (proximity_refiner){0};
    if (levels == 0 || scene->triangle_count == 0)
        return RAD_OK;
    rad_status status =
        rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &refiner->tracer, error);
    if (status != RAD_OK)
        return status;
    refiner->levels = levels;
    refiner->budget = budget;
    return RAD_OK;
}

void proximity_refiner_free(proximity_refiner *refiner)
{
    rad_tracer_destroy(refiner->tracer);
    *refiner = (proximity_refiner){0};
}

/* The mean distance the rays from x over the hemisphere of n travel to a surface, and
 * the share of them that meet one. */
static void mean_distance(const proximity_refiner *refiner, rad_vec3 x, rad_vec3 n,
                          double offset, uint64_t key, double *distance, double *hit_share)
{
    rad_vec3 a, b;
    hemisphere_frame(n, &a, &b);
    rad_rng rng = rad_rng_seed(key, 0, 0);
    double turn = 2 * RAD_PI * rad_rng_uniform(&rng);
    rad_ray rays[PROXIMITY_RAYS];
    rad_hit hits[PROXIMITY_RAYS];
    rad_vec3 origin = v3_add(x, v3_scale(n, offset));
    const uint32_t columns = PROXIMITY_RAYS / PROXIMITY_ROWS;
    for (uint32_t k = 0; k < PROXIMITY_RAYS; k++) {
        double u1 = ((k / columns) + 0.5) / PROXIMITY_ROWS;
        double u2 = ((k % columns) + 0.5) / columns;
        rad_vec3 d = cosine_direction(n, a, b, u1, u2, turn, NULL);
        rays[k] = (rad_ray){{(float)origin.x, (float)origin.y, (float)origin.z},
                            0.0f,
                            {(float)d.x, (float)d.y, (float)d.z},
                            INFINITY};
    }
    rad_tracer_intersect(refiner->tracer, rays, PROXIMITY_RAYS, hits);
    double sum = 0;
    uint32_t met = 0, backs = 0;
    for (uint32_t k = 0; k < PROXIMITY_RAYS; k++)
        if (hits[k].triangle != RAD_NO_HIT) {
            sum += hits[k].t + offset;
            met++;
            backs += !hits[k].front;
        }
    /* a cell under a box standing on it, or inside another object, meets backs: no one
     * sees it, and splitting it would only add patches (hidden_patches.c says the same) */
    if (2 * backs >= PROXIMITY_RAYS) {
        *hit_share = 0;
        *distance = INFINITY;
        return;
    }
    *hit_share = (double)met / PROXIMITY_RAYS;
    *distance = met ? sum / met : INFINITY;
}

bool proximity_refiner_splits(proximity_refiner *refiner, const rad_vec3 *corners,
                              uint32_t count, rad_vec3 normal, bool two_sided)
{
    if (!refiner->tracer || refiner->budget_reached)
        return false;
    double longest = 0;
    rad_vec3 centre = v3(0, 0, 0);
    for (uint32_t c = 0; c < count; c++) {
        longest = fmax(longest, v3_length(v3_sub(corners[(c + 1) % count], corners[c])));
        centre = v3_add(centre, corners[c]);
    }
    centre = v3_scale(centre, 1.0 / count);
    uint64_t key = PROXIMITY_STREAM;
    for (uint32_t c = 0; c < count; c++)
        key = hash_bytes(key, &corners[c], sizeof(corners[c]));
    /* off the cell's plane by a small share of its size: the rays leave its own
     * triangles behind and still meet a surface touching it */
    double offset = 1e-4 * longest;
    bool split = false;
    for (uint32_t face = 0; face < (two_sided ? 2u : 1u) && !split; face++) {
        double distance, hit_share;
        mean_distance(refiner, centre, face ? v3_scale(normal, -1) : normal, offset,
                      key + face, &distance, &hit_share);
        split = hit_share >= PROXIMITY_HIT_SHARE && longest > PROXIMITY_SHARE * distance;
    }
    if (!split)
        return false;
    if (refiner->added + 3 > refiner->budget) {
        refiner->budget_reached = true;
        return false;
    }
    refiner->added += 3;
    refiner->split++;
    return true;
}
