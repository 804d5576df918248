/*
 * emitters.h - sampling points on the scene's emitting triangles (internal).
 *
 * For next-event estimation (path tracer) and area lights (ray tracer): a triangle is
 * chosen with probability proportional to its power (area x luminance of L_e), then a
 * point uniformly on it. pdf_area is the density of the chosen point per unit area, over
 * the whole set: p(t) / A_t. Built once per scene; read-only afterwards (thread safe).
 */
#ifndef RAD_SCENE_EMITTERS_H
#define RAD_SCENE_EMITTERS_H

#include "radiosity.h"

typedef struct emitter_set {
    uint32_t count;       /* emitting triangles */
    uint32_t *triangle;   /* their scene indices */
    double *cdf;          /* cumulative probability, cdf[count - 1] = 1 */
    double *pdf_area_of;  /* per SCENE triangle: density per unit area, 0 for non-emitters */
    double total_power;   /* sum of area x luminance(L_e) */
} emitter_set;

rad_status emitters_build(const rad_scene *scene, emitter_set *set, rad_error *error);
void emitters_free(emitter_set *set);

typedef struct emitter_sample {
    rad_vec3 point;
    rad_vec3 normal;    /* unit front normal of the triangle */
    uint32_t triangle;  /* scene index */
    double pdf_area;    /* density of this point per unit area */
    rad_rgb radiance;   /* L_e of the triangle's material (one-sided: front only) */
} emitter_sample;

/* u0 picks the triangle, (u1, u2) the point; all in [0,1). The set must not be empty. */
void emitters_sample(const emitter_set *set, const rad_scene *scene, double u0, double u1,
                     double u2, emitter_sample *sample);

#endif
