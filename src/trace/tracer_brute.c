/*
 * tracer_brute.c - the brute-force backend: every ray against every triangle, in double
 * precision. O(rays x triangles): a test oracle for the Embree backend, not for production.
 *
 * The ray/triangle test is Moller-Trumbore on both sides, edges inclusive, on the same float
 * vertices Embree sees (promoted to double), so the two backends differ only where a ray
 * grazes an edge or two hits are equally near. A ray lying in a triangle's plane misses it.
 */
#include "trace/tracer_internal.h"

#include <math.h>

/* A ray in double precision. */
typedef struct ray64 {
    double origin[3], direction[3];
    double t_near, t_far;
} ray64;

static ray64 to_ray64(const rad_ray *ray)
{
    ray64 r;
    for (int k = 0; k < 3; k++) {
        r.origin[k] = ray->origin[k];
        r.direction[k] = ray->direction[k];
    }
    r.t_near = ray->t_near;
    r.t_far = ray->t_far;
    return r;
}

static void sub(const float *a, const float *b, double out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = (double)a[k] - (double)b[k];
}

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* True when the ray meets `triangle` at some t in [t_near, t_far]; *t, *u, *v then hold
 * the hit with point = (1-u-v) p0 + u p1 + v p2. */
static bool hit_triangle(const rad_tracer *tracer, uint32_t triangle, const ray64 *ray,
                         double *t, double *u, double *v)
{
    const uint32_t *index = tracer->indices + 3 * (size_t)triangle;
    const float *p0 = tracer->vertices + 3 * (size_t)index[0];
    const float *p1 = tracer->vertices + 3 * (size_t)index[1];
    const float *p2 = tracer->vertices + 3 * (size_t)index[2];
    double e1[3], e2[3], p[3], s[3], q[3];
    sub(p1, p0, e1);
    sub(p2, p0, e2);
    cross(ray->direction, e2, p);
    double det = dot(e1, p);
    if (det == 0.0) /* parallel to the plane (or degenerate): no single hit point */
        return false;
    double inv = 1.0 / det;
    for (int k = 0; k < 3; k++)
        s[k] = ray->origin[k] - (double)p0[k];
    double uu = dot(s, p) * inv;
    if (!(uu >= 0.0 && uu <= 1.0))
        return false;
    cross(s, e1, q);
    double vv = dot(ray->direction, q) * inv;
    if (!(vv >= 0.0 && uu + vv <= 1.0))
        return false;
    double tt = dot(e2, q) * inv;
    if (!(tt >= ray->t_near && tt <= ray->t_far))
        return false;
    *t = tt;
    *u = uu;
    *v = vv;
    return true;
}

void rad_tracer_brute_occluded(const rad_tracer *tracer, const rad_ray *rays, uint32_t count,
                               uint8_t *occluded)
{
    for (uint32_t i = 0; i < count; i++) {
        ray64 ray = to_ray64(&rays[i]);
        uint8_t blocked = 0;
        for (uint32_t tri = 0; tri < tracer->triangle_count && !blocked; tri++) {
            double t, u, v;
            blocked = hit_triangle(tracer, tri, &ray, &t, &u, &v);
        }
        occluded[i] = blocked;
    }
}

void rad_tracer_brute_intersect(const rad_tracer *tracer, const rad_ray *rays,
                                uint32_t count, rad_hit *hits)
{
    for (uint32_t i = 0; i < count; i++) {
        ray64 ray = to_ray64(&rays[i]);
        uint32_t best = RAD_NO_HIT;
        double best_t = INFINITY, best_u = 0.0, best_v = 0.0;
        for (uint32_t tri = 0; tri < tracer->triangle_count; tri++) {
            double t, u, v;
            /* Strictly nearer only: on a tie the lower index wins, deterministically. */
            if (hit_triangle(tracer, tri, &ray, &t, &u, &v) && t < best_t) {
                best = tri;
                best_t = t;
                best_u = u;
                best_v = v;
            }
        }
        if (best == RAD_NO_HIT) {
            hits[i] = rad_tracer_miss();
            continue;
        }
        hits[i].triangle = best;
        hits[i].t = (float)best_t;
        hits[i].u = (float)best_u;
        hits[i].v = (float)best_v;
        hits[i].front = rad_tracer_hit_front(tracer, best, rays[i].direction);
    }
}
