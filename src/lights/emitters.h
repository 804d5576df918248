/*
 * emitters.h - sampling points on the scene's emitting triangles (internal).
 *
 * For next-event estimation (path tracer) and area lights (ray tracer): a triangle is
 * chosen with probability proportional to its power (area x luminance of its MEAN emitted
 * radiance: with an emission texture, the texel's mean over the triangle, see
 * material_mean_emission), then a point uniformly on it, whose radiance is the emitted
 * radiance AT that point (the texel there). pdf_area is the density of the chosen point
 * per unit area, over the whole set: P(t) / A_t, so the estimators stay unbiased for any
 * choice of P as long as every triangle that may emit somewhere has P > 0: a triangle of
 * an emitting material whose estimated mean is (near) 0 keeps a floor of power,
 * EMITTER_POWER_FLOOR of its emission factor's. A material whose emission texture is
 * black everywhere (in the channels where its factor is > 0) emits nowhere: it is not an
 * emitter (material_emits), and nothing is lost. Built once per scene; read-only
 * afterwards (thread safe).
 */
#ifndef RAD_LIGHTS_EMITTERS_H
#define RAD_LIGHTS_EMITTERS_H

#include "core/random.h"
#include "radiosity.h"

/* The least power per unit area of an emitting triangle, as a fraction of the luminance of
 * its material's emission factor (dimensionless): a textured triangle whose 16 x 16
 * estimate of the mean texel is 0 (its bright texels lie between the estimate's points)
 * is still sampled, rarely, so no emission goes unsampled. */
#define EMITTER_POWER_FLOOR 1e-3

/* What sampling needs of one emitting triangle, copied out of the scene once. */
typedef struct emitter_triangle {
    rad_vec3 corner[3];
    rad_vec3 normal;   /* unit front normal */
    rad_rgb emission;  /* the material's emission factor */
    bool textured;     /* with an emission texture: the texel at each point too */
    bool two_sided;
} emitter_triangle;

typedef struct emitter_set {
    uint32_t count;       /* emitting triangles */
    uint32_t *triangle;   /* their scene indices */
    emitter_triangle *shape; /* per emitting triangle, in the same order */
    /* the radical inverses in bases 3 and 5 of 0 .. EMITTER_HALTON_TABLE - 1, the light
     * samples' Halton coordinates (rad_radical_inverse's values, looked up) */
    double *halton3, *halton5;
    double *cdf;          /* cumulative probability, cdf[count - 1] = 1 */
    double *pdf_area_of;  /* per SCENE triangle: density per unit area, 0 for non-emitters */
    double total_power;   /* sum of area x luminance(mean L_e), floors included */
} emitter_set;

/* How many radical inverses each table holds: the light samples a render draws per pixel
 * sample or vertex stay below it (a vertex's 1024, a rim pixel's 1024 samples of 4). */
#define EMITTER_HALTON_TABLE 8192u

rad_status emitters_build(const rad_scene *scene, emitter_set *set, rad_error *error);

/* The radical inverse of j in base 3 or 5 (rad_radical_inverse), from the set's table when
 * j is in it. */
static inline double emitters_halton3(const emitter_set *set, uint32_t j)
{
    return j < EMITTER_HALTON_TABLE && set->halton3 ? set->halton3[j] : rad_radical_inverse(j, 3);
}

static inline double emitters_halton5(const emitter_set *set, uint32_t j)
{
    return j < EMITTER_HALTON_TABLE && set->halton5 ? set->halton5[j] : rad_radical_inverse(j, 5);
}

void emitters_free(emitter_set *set);

typedef struct emitter_sample {
    rad_vec3 point;
    rad_vec3 normal;    /* unit front normal of the triangle */
    uint32_t triangle;  /* scene index */
    double u, v;        /* the point's barycentrics on the triangle (as rad_hit) */
    double pdf_area;    /* density of this point per unit area */
    rad_rgb radiance;   /* L_e at the point: the material's, times its emission texel
                           (front only, unless two_sided) */
    bool two_sided;     /* the triangle's surface radiates from both sides */
} emitter_sample;

/* The emitting triangle (an index into set->triangle) that u0 in [0,1) picks: the first
 * k with cdf[k] > u0. The set must not be empty. */
uint32_t emitters_index(const emitter_set *set, double u0);

/* u0 picks the triangle, (u1, u2) the point; all in [0,1). The set must not be empty. */
void emitters_sample(const emitter_set *set, const rad_scene *scene, double u0, double u1,
                     double u2, emitter_sample *sample);

/* The cosine at the light for light arriving along unit direction wi (from the shading
 * point towards the sample): -<normal, wi>, <= 0 when the point is behind a one-sided
 * emitter; for a two-sided one its absolute value. *facing receives the unit normal of the
 * side that faces the point (where shadow rays end, just off the light); NULL: not
 * wanted. */
double emitter_cosine(const emitter_sample *sample, rad_vec3 wi, rad_vec3 *facing);

#endif
