/*
 * tracer_internal.h - what the tracer front end (tracer.c) shares with its two backends,
 * tracer_embree.c (Embree 3 BVH) and tracer_brute.c (every triangle: the test oracle).
 *
 * One idea: the front end validates and copies the triangles once, into float vertices and
 * index triples that BOTH backends read, so they trace exactly the same geometry and decide
 * the front side with the same code (rad_tracer_hit_front). Not here: any ray arithmetic
 * (backends) or argument checks (tracer.c, at create time only).
 *
 * Query contract (the hot path checks nothing, allocates nothing, and only reads the
 * tracer, so any number of threads may query one tracer at once):
 *   - `rays` holds `count` rays and the output array `count` elements (either may be NULL
 *     when count is 0); the tracer stays alive during the call;
 *   - every ray component is finite, except t_far which may be +INFINITY; the direction is
 *     not zero; 0 <= t_near (Embree's rule: segments never start behind the origin);
 *     t_near > t_far is an empty segment: no hit;
 *   - a hit is any triangle, front or back, met at t in [t_near, t_far];
 *   - a miss is reported as {RAD_NO_HIT, t = INFINITY, u = v = 0, front = false}.
 */
#ifndef RAD_TRACE_TRACER_INTERNAL_H
#define RAD_TRACE_TRACER_INTERNAL_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "radiosity.h"

/* Embree device and scene; defined in tracer_embree.c. */
struct rad_tracer_embree;

struct rad_tracer {
    rad_tracer_backend backend;
    uint32_t vertex_count;   /* vertices in use (the padding vertex not counted) */
    uint32_t triangle_count;
    float *vertices;         /* x, y, z per vertex, (vertex_count + 1) * 3 floats: the last
                                vertex is zero padding because Embree reads each vertex with
                                a 16-byte load */
    uint32_t *indices;       /* 3 vertex indices per triangle, all < vertex_count,
                                counter-clockwise seen from the front */
    struct rad_tracer_embree *embree; /* the Embree backends only, else NULL */
};

/* The miss record of the query contract. */
static inline rad_hit rad_tracer_miss(void)
{
    rad_hit miss = {RAD_NO_HIT, (float)INFINITY, 0.0f, 0.0f, false};
    return miss;
}

/* True when a ray along `direction` meets the front of `triangle`:
 * dot(direction, (p1 - p0) x (p2 - p0)) < 0, in double from the tracer's own float copy so
 * that every backend gives the same answer. */
static inline bool rad_tracer_hit_front(const rad_tracer *tracer, uint32_t triangle,
                                        const float direction[3])
{
    const uint32_t *index = tracer->indices + 3 * (size_t)triangle;
    const float *p0 = tracer->vertices + 3 * (size_t)index[0];
    const float *p1 = tracer->vertices + 3 * (size_t)index[1];
    const float *p2 = tracer->vertices + 3 * (size_t)index[2];
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = (double)p1[k] - p0[k];
        e2[k] = (double)p2[k] - p0[k];
    }
    double normal[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                        e1[0] * e2[1] - e1[1] * e2[0]};
    return direction[0] * normal[0] + direction[1] * normal[1] + direction[2] * normal[2] < 0;
}

/* Embree backend (tracer_embree.c). build fills tracer->embree from vertices/indices;
 * release frees what build made, also after a failed build. */
rad_status rad_tracer_embree_build(rad_tracer *tracer, rad_error *error);
void rad_tracer_embree_release(rad_tracer *tracer);
void rad_tracer_embree_occluded(const rad_tracer *tracer, const rad_ray *rays, uint32_t count,
                                uint8_t *occluded);
/* coherent: Embree's coherent-ray context (rad_tracer_intersect_coherent) */
void rad_tracer_embree_intersect(const rad_tracer *tracer, const rad_ray *rays,
                                 uint32_t count, bool coherent, rad_hit *hits);

/* Brute-force backend (tracer_brute.c): needs nothing beyond vertices/indices. */
void rad_tracer_brute_occluded(const rad_tracer *tracer, const rad_ray *rays, uint32_t count,
                               uint8_t *occluded);
void rad_tracer_brute_intersect(const rad_tracer *tracer, const rad_ray *rays,
                                uint32_t count, rad_hit *hits);

#endif
