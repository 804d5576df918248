/*
 * tracer_embree.c - the Embree 3 backend: one device and one committed scene per tracer,
 * holding a single triangle geometry that shares the front end's float vertices and
 * index triples (no second copy).
 *
 * Queries go through Embree's stream calls (rtcOccluded1M / rtcIntersect1M) in chunks of
 * CHUNK rays converted on the stack: no allocation, no checks (contract in
 * tracer_internal.h), thread safe because nothing but the stack is written. Embree 4 drops
 * the stream calls: only the two query functions here would change.
 *
 * Memory: Embree's monitor counts every block it allocates against the run's budget
 * (core/memory.h), which cancels a build that would exceed it; before the build, an
 * estimate (RAD_EMBREE_BYTES_PER_TRIANGLE) refuses up front one that cannot fit.
 *
 * Not here: the front/back decision (rad_tracer_hit_front, shared with the oracle) and any
 * use of Embree's geometric normal, whose orientation convention is not ours.
 */
#include "trace/tracer_internal.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/memory.h"

#if defined(__x86_64__) || defined(__i386__) || defined(_M_X64) || defined(_M_IX86)
#include <pmmintrin.h>
#include <xmmintrin.h>
#define RAD_HAVE_MXCSR 1
#else
#define RAD_HAVE_MXCSR 0
#endif

/* Rays converted per stream call: 256 RTCRayHit are 20 KiB of stack. */
enum { CHUNK = 256 };

/* Embree's memory monitor: its blocks count against the budget (memory.h). */
static bool monitor_memory(void *user, ssize_t bytes, bool post)
{
    (void)user;
    return rad_memory_budget_embree((int64_t)bytes, post);
}

struct rad_tracer_embree {
    RTCDevice device;
    RTCScene scene; /* committed; read-only after rad_tracer_embree_build */
};

/* Embree wants flush-to-zero and denormals-are-zero in every thread that traces. They are
 * set for the duration of a call and the caller's modes restored afterwards, so the
 * library does not change the floating-point behaviour of the calling thread. */
static unsigned int fp_modes_enter(void)
{
#if RAD_HAVE_MXCSR
    unsigned int saved = _mm_getcsr();
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    return saved;
#else
    return 0;
#endif
}

static void fp_modes_leave(unsigned int saved)
{
#if RAD_HAVE_MXCSR
    _mm_setcsr(saved);
#else
    (void)saved;
#endif
}

static const char *error_name(enum RTCError code)
{
    switch (code) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_UNKNOWN: return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    }
    return "unrecognised error";
}

/* RAD_OK when Embree recorded no error on this thread since the last check; else the
 * error, reported as internal (our arguments were validated) unless memory ran out. */
static rad_status check_device(RTCDevice device, const char *step, rad_error *error)
{
    enum RTCError code = rtcGetDeviceError(device);
    if (code == RTC_ERROR_NONE)
        return RAD_OK;
    rad_status status = code == RTC_ERROR_OUT_OF_MEMORY ? RAD_ERR_NOMEM : RAD_ERR_INTERNAL;
    return rad_fail(error, status, "tracer: Embree error %d (%s) while %s", (int)code,
                    error_name(code), step);
}

/* Adds the tracer's triangles to the scene as geometry 0 over shared buffers. */
static rad_status attach_triangles(const rad_tracer *tracer, struct rad_tracer_embree *e,
                                   rad_error *error)
{
    RTCGeometry geometry = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!geometry) {
        rad_status status = check_device(e->device, "creating the triangle geometry", error);
        return status != RAD_OK ? status
                                : rad_fail(error, RAD_ERR_INTERNAL,
                                           "tracer: Embree returned no geometry");
    }
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                               tracer->vertices, 0, 3 * sizeof(float), tracer->vertex_count);
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                               tracer->indices, 0, 3 * sizeof(uint32_t),
                               tracer->triangle_count);
    rad_status status = check_device(e->device, "sharing the vertex and index buffers", error);
    if (status == RAD_OK) {
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(e->scene, geometry);
        status = check_device(e->device, "committing the triangle geometry", error);
    }
    rtcReleaseGeometry(geometry); /* the scene keeps its own reference */
    return status;
}

rad_status rad_tracer_embree_build(rad_tracer *tracer, rad_error *error)
{
    struct rad_tracer_embree *e = rad_alloc_array(1, sizeof(*e));
    if (!e)
        return rad_fail(error, RAD_ERR_NOMEM, "tracer: out of memory");
    tracer->embree = e; /* from here on rad_tracer_embree_release undoes what was made */

    e->device = rtcNewDevice(NULL);
    if (!e->device) {
        enum RTCError code = rtcGetDeviceError(NULL);
        return rad_fail(error, code == RTC_ERROR_OUT_OF_MEMORY ? RAD_ERR_NOMEM
                                                                : RAD_ERR_INTERNAL,
                        "tracer: Embree error %d (%s) while creating the device", (int)code,
                        error_name(code));
    }
    rtcSetDeviceMemoryMonitorFunction(e->device, monitor_memory, NULL);
    e->scene = rtcNewScene(e->device);
    rad_status status = check_device(e->device, "creating the scene", error);
    if (status != RAD_OK)
        return status;
    if (!e->scene)
        return rad_fail(error, RAD_ERR_INTERNAL, "tracer: Embree returned no scene");

    /* Form factors cast many rays per triangle: a slower, better BVH pays for itself. */
    rtcSetSceneBuildQuality(e->scene, RTC_BUILD_QUALITY_HIGH);
    /* watertight: no ray slips between two triangles sharing an edge, even far from the
     * origin where float coordinates are coarse (RAD_TRACER_EMBREE_FAST opts out) */
    if (tracer->backend == RAD_TRACER_EMBREE)
        rtcSetSceneFlags(e->scene, RTC_SCENE_FLAG_ROBUST);
    if (tracer->triangle_count > 0) {
        status = attach_triangles(tracer, e, error);
        if (status != RAD_OK)
            return status;
    }
    char what[64];
    snprintf(what, sizeof(what), "the Embree BVH of %u triangles", tracer->triangle_count);
    uint64_t estimate = (uint64_t)tracer->triangle_count * RAD_EMBREE_BYTES_PER_TRIANGLE;
    status = rad_memory_budget_need(estimate, what, error);
    if (status != RAD_OK)
        return status;
    unsigned int modes = fp_modes_enter();
    rtcCommitScene(e->scene);
    fp_modes_leave(modes);
    return check_device(e->device, "building the BVH", error);
}

void rad_tracer_embree_release(rad_tracer *tracer)
{
    struct rad_tracer_embree *e = tracer->embree;
    if (!e)
        return;
    if (e->scene)
        rtcReleaseScene(e->scene);
    if (e->device)
        rtcReleaseDevice(e->device);
    free(e);
    tracer->embree = NULL;
}

/* Our ray as Embree's: every ray hits every geometry (Debian's Embree has ray masks on). */
static void to_embree_ray(const rad_ray *ray, struct RTCRay *out)
{
    out->org_x = ray->origin[0];
    out->org_y = ray->origin[1];
    out->org_z = ray->origin[2];
    out->tnear = ray->t_near;
    out->dir_x = ray->direction[0];
    out->dir_y = ray->direction[1];
    out->dir_z = ray->direction[2];
    out->time = 0.0f;
    out->tfar = ray->t_far;
    out->mask = 0xFFFFFFFFu;
    out->id = 0;
    out->flags = 0;
}

void rad_tracer_embree_occluded(const rad_tracer *tracer, const rad_ray *rays, uint32_t count,
                                uint8_t *occluded)
{
    unsigned int modes = fp_modes_enter();
    RTCScene scene = tracer->embree->scene;
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context); /* default: incoherent rays, the fastest here */
    struct RTCRay chunk[CHUNK];
    for (uint32_t done = 0; done < count;) {
        uint32_t n = count - done < CHUNK ? count - done : CHUNK;
        for (uint32_t j = 0; j < n; j++)
            to_embree_ray(&rays[done + j], &chunk[j]);
        rtcOccluded1M(scene, &context, chunk, n, sizeof(chunk[0]));
        /* Embree marks an occluded ray by setting tfar to -infinity. */
        for (uint32_t j = 0; j < n; j++)
            occluded[done + j] = chunk[j].tfar == -INFINITY;
        done += n;
    }
    fp_modes_leave(modes);
}

void rad_tracer_embree_intersect(const rad_tracer *tracer, const rad_ray *rays,
                                 uint32_t count, bool coherent, rad_hit *hits)
{
    unsigned int modes = fp_modes_enter();
    RTCScene scene = tracer->embree->scene;
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    if (coherent) /* a final gather's strata from one point: about 2x faster */
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    struct RTCRayHit chunk[CHUNK];
    for (uint32_t done = 0; done < count;) {
        uint32_t n = count - done < CHUNK ? count - done : CHUNK;
        for (uint32_t j = 0; j < n; j++) {
            to_embree_ray(&rays[done + j], &chunk[j].ray);
            chunk[j].hit.geomID = RTC_INVALID_GEOMETRY_ID;
            chunk[j].hit.primID = RTC_INVALID_GEOMETRY_ID;
            chunk[j].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect1M(scene, &context, chunk, n, sizeof(chunk[0]));
        for (uint32_t j = 0; j < n; j++) {
            const struct RTCRayHit *r = &chunk[j];
            rad_hit *hit = &hits[done + j];
            if (r->hit.geomID == RTC_INVALID_GEOMETRY_ID) {
                *hit = rad_tracer_miss();
                continue;
            }
            hit->triangle = r->hit.primID;
            hit->t = r->ray.tfar;
            hit->u = r->hit.u;
            hit->v = r->hit.v;
            hit->front = rad_tracer_hit_front(tracer, r->hit.primID, rays[done + j].direction);
        }
        done += n;
    }
    fp_modes_leave(modes);
}
