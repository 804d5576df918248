/*
 * tracer.c - the tracer front end: validates what rad_tracer_create is given, keeps the
 * float copy of the triangles that every backend reads, and sends queries to the backend.
 *
 * No ray arithmetic here (see tracer_embree.c and tracer_brute.c), and no checks in the
 * queries: they follow the contract written in tracer_internal.h.
 */
#include "trace/tracer_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"

/* A coordinate the float copy can hold exactly enough: finite and within float range. */
static bool coordinate_ok(double c)
{
    return isfinite(c) && fabs(c) <= FLT_MAX;
}

/* Checks every argument; RAD_OK when the tracer can be built. */
static rad_status validate(rad_tracer_backend backend, const rad_vec3 *positions,
                           uint32_t position_count, const uint32_t (*triangles)[3],
                           uint32_t triangle_count, rad_error *error)
{
    if (backend != RAD_TRACER_EMBREE && backend != RAD_TRACER_EMBREE_FAST &&
        backend != RAD_TRACER_BRUTE_FORCE)
        return rad_fail(error, RAD_ERR_INVALID, "tracer: unknown backend %d", (int)backend);
    if (position_count > 0 && !positions)
        return rad_fail(error, RAD_ERR_INVALID, "tracer: %u positions but no array",
                        position_count);
    if (triangle_count > 0 && !triangles)
        return rad_fail(error, RAD_ERR_INVALID, "tracer: %u triangles but no array",
                        triangle_count);
    for (uint32_t i = 0; i < position_count; i++) {
        rad_vec3 p = positions[i];
        if (!coordinate_ok(p.x) || !coordinate_ok(p.y) || !coordinate_ok(p.z))
            return rad_fail(error, RAD_ERR_INVALID,
                            "tracer: position %u (%g, %g, %g) is not finite in float", i,
                            p.x, p.y, p.z);
    }
    for (uint32_t t = 0; t < triangle_count; t++) {
        for (int k = 0; k < 3; k++) {
            if (triangles[t][k] >= position_count)
                return rad_fail(error, RAD_ERR_INVALID,
                                "tracer: triangle %u: vertex index %u out of range (%u "
                                "positions)",
                                t, triangles[t][k], position_count);
        }
    }
    return RAD_OK;
}

rad_status rad_tracer_create(rad_tracer_backend backend, const rad_vec3 *positions,
                             uint32_t position_count, const uint32_t (*triangles)[3],
                             uint32_t triangle_count, rad_tracer **out, rad_error *error)
{
    if (!out)
        return rad_fail(error, RAD_ERR_INVALID, "tracer: no output pointer");
    *out = NULL;
    rad_status status =
        validate(backend, positions, position_count, triangles, triangle_count, error);
    if (status != RAD_OK)
        return status;

    rad_tracer *tracer = rad_alloc_array(1, sizeof(*tracer));
    if (!tracer)
        return rad_fail(error, RAD_ERR_NOMEM, "tracer: out of memory");
    tracer->backend = backend;
    tracer->vertex_count = position_count;
    tracer->triangle_count = triangle_count;
    /* One more vertex than used: zero padding for Embree's 16-byte vertex loads. */
    tracer->vertices = rad_alloc_array((size_t)position_count + 1, 3 * sizeof(float));
    tracer->indices = rad_alloc_array(triangle_count, 3 * sizeof(uint32_t));
    if (!tracer->vertices || !tracer->indices) {
        status = rad_fail(error, RAD_ERR_NOMEM, "tracer: out of memory for %u vertices and "
                          "%u triangles", position_count, triangle_count);
        goto fail;
    }
    for (uint32_t i = 0; i < position_count; i++) {
        tracer->vertices[3 * (size_t)i + 0] = (float)positions[i].x;
        tracer->vertices[3 * (size_t)i + 1] = (float)positions[i].y;
        tracer->vertices[3 * (size_t)i + 2] = (float)positions[i].z;
    }
    for (uint32_t t = 0; t < triangle_count; t++) {
        for (int k = 0; k < 3; k++)
            tracer->indices[3 * (size_t)t + (size_t)k] = triangles[t][k];
    }

    if (backend == RAD_TRACER_EMBREE || backend == RAD_TRACER_EMBREE_FAST) {
        status = rad_tracer_embree_build(tracer, error);
        if (status != RAD_OK)
            goto fail;
    }
    *out = tracer;
    return RAD_OK;

fail:
    rad_tracer_destroy(tracer);
    return status;
}

void rad_tracer_destroy(rad_tracer *tracer)
{
    if (!tracer)
        return;
    if (tracer->embree)
        rad_tracer_embree_release(tracer);
    free(tracer->vertices);
    free(tracer->indices);
    free(tracer);
}

void rad_tracer_occluded(const rad_tracer *tracer, const rad_ray *rays, uint32_t count,
                         uint8_t *occluded)
{
    switch (tracer->backend) {
    case RAD_TRACER_EMBREE:
    case RAD_TRACER_EMBREE_FAST:
        rad_tracer_embree_occluded(tracer, rays, count, occluded);
        break;
    case RAD_TRACER_BRUTE_FORCE:
        rad_tracer_brute_occluded(tracer, rays, count, occluded);
        break;
    }
}

void rad_tracer_intersect(const rad_tracer *tracer, const rad_ray *rays, uint32_t count,
                          rad_hit *hits)
{
    switch (tracer->backend) {
    case RAD_TRACER_EMBREE:
    case RAD_TRACER_EMBREE_FAST:
        rad_tracer_embree_intersect(tracer, rays, count, false, hits);
        break;
    case RAD_TRACER_BRUTE_FORCE:
        rad_tracer_brute_intersect(tracer, rays, count, hits);
        break;
    }
}

void rad_tracer_intersect_coherent(const rad_tracer *tracer, const rad_ray *rays,
                                   uint32_t count, rad_hit *hits)
{
    switch (tracer->backend) {
    case RAD_TRACER_EMBREE:
    case RAD_TRACER_EMBREE_FAST:
        rad_tracer_embree_intersect(tracer, rays, count, true, hits);
        break;
    case RAD_TRACER_BRUTE_FORCE:
        rad_tracer_brute_intersect(tracer, rays, count, hits);
        break;
    }
}
