/*
 * vf_geometry.h - the scene as the view-factor engine sees it: convex planar polygons
 * grouped by surface.
 *
 * The triangles of a radiating surface are merged into maximal flat convex polygons of at
 * most VF_MAX_VERTICES corners: neighbours across a shared edge join when they are coplanar
 * and their union is convex (collinear corners dropped). A wall exported as two triangles,
 * or as many, is one polygon again, which divides the pair count by the square of what was
 * merged. A two-sided surface gets every polygon twice, the second copy reversed.
 * Obstruction surfaces get no polygons: they only block, through the occluder tree and
 * the tracer.
 */
#ifndef RAD_VIEWFACTOR_VF_GEOMETRY_H
#define RAD_VIEWFACTOR_VF_GEOMETRY_H

#include <math.h>

#include "radiosity.h"

#define VF_MAX_VERTICES 6

typedef struct vf_polygon {
    rad_vec3 vertex[VF_MAX_VERTICES]; /* counter-clockwise seen from the front */
    unsigned count;      /* 3 to VF_MAX_VERTICES */
    double fan[VF_MAX_VERTICES - 2]; /* cumulative area fractions of the fan triangles
                                        (0, k, k + 1): uniform sampling */
    rad_vec3 normal;     /* unit front normal */
    double area;
    rad_vec3 centroid;
    double radius;       /* largest distance from the centroid to a corner */
    uint32_t surface;
    uint32_t source;     /* which merged polygon it is: the two copies of a two-sided
                            polygon share it, and so do the scene triangles it covers */
} vf_polygon;

typedef struct vf_surface {
    uint32_t first_polygon, polygon_count;
    double area;        /* sum of its polygons' areas (both copies when two-sided) */
    rad_vec3 center;    /* bounding sphere of its corners */
    double radius;
    bool planar;        /* every polygon in one plane with one front normal: cannot see
                           itself */
    rad_vec3 normal;    /* the plane, when planar: normal . x = offset */
    double offset;
} vf_surface;

typedef struct vf_geometry {
    vf_polygon *polygons;
    uint32_t polygon_count;
    vf_surface *surfaces; /* one per scene surface; obstructions have no polygons */
    uint32_t surface_count;
    uint32_t *triangle_source; /* per scene triangle: the source of the polygon covering it,
                                  UINT32_MAX for obstructions */
    double plane_epsilon; /* in front of a plane means beyond this distance (scene units) */
} vf_geometry;

rad_status vf_geometry_build(const rad_scene *scene, vf_geometry *geometry, rad_error *error);
void vf_geometry_free(vf_geometry *geometry);

/* Area, centroid, bounding radius and triangle-fan shares of a convex polygon whose
 * corners and unit normal are set. */
void vf_polygon_finish(vf_polygon *polygon);

/* The part of `polygon` in front of the plane n . x = offset (on it counts as behind) into
 * `out`, which may be `polygon`; false when none of it with area is. Wholly in front: out
 * is the polygon, bit for bit. A corner on the plane is kept once (corners within 1e-12 of
 * the part's extent of each other are one). When the part would have more than
 * VF_MAX_VERTICES corners,
 * out is the whole polygon: a caller integrating a kernel that vanishes behind the plane
 * gets the same result either way, only with less of its work where it counts. */
bool vf_polygon_clip_front(const vf_polygon *polygon, rad_vec3 n, double offset,
                           vf_polygon *out);

/* A uniform point of the convex polygon from (s, t) in the unit square: the fan triangle
 * (0, k, k + 1) by its area share with s, then s rescaled within it. Inline: the sampled
 * segments of every obstructed pair take two points each. */
static inline rad_vec3 vf_polygon_sample(const vf_polygon *p, double s, double t)
{
    unsigned k = 0;
    while (k + 3 < p->count && s >= p->fan[k])
        k++;
    double low = k ? p->fan[k - 1] : 0, high = p->fan[k];
    s = high > low ? (s - low) / (high - low) : 0;
    double r = sqrt(fmin(fmax(s, 0), 1)), u = 1 - r, v = r * (1 - t), w = r * t;
    const rad_vec3 *a = &p->vertex[0], *b = &p->vertex[k + 1], *c = &p->vertex[k + 2];
    return (rad_vec3){u * a->x + v * b->x + w * c->x, u * a->y + v * b->y + w * c->y,
                      u * a->z + v * b->z + w * c->z};
}

/* True when some corner of `polygon` lies in front of the plane (n, offset) by more than
 * epsilon. */
static inline bool vf_polygon_in_front(const vf_polygon *polygon, rad_vec3 n, double offset,
                                       double epsilon)
{
    for (unsigned k = 0; k < polygon->count; k++) {
        const rad_vec3 *v = &polygon->vertex[k];
        if (n.x * v->x + n.y * v->y + n.z * v->z - offset > epsilon)
            return true;
    }
    return false;
}

#endif
