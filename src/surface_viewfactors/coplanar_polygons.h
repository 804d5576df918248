/*
 * coplanar_polygons.h - the scene's blocking shapes grouped by the plane they lie in.
 *
 * The shapes are the merged convex polygons of the radiating surfaces (vf_geometry.h; a
 * two-sided polygon once) and the triangles of obstruction surfaces: together they cover
 * exactly the scene's triangles. A group holds the shapes whose unit normals agree to 1e-9
 * per component (up to sign) and whose planes are within plane_epsilon of its first's; it
 * keeps that plane and its shapes' corners, sorted along the coordinate axis its corners
 * spread widest in, so that the shapes overlapping a region are found by bisection. Used
 * by pair_hidden.c to ask "what lies in this plane, here?" without a tree search. It is an
 * index, not a test: membership says nothing about blocking.
 */
#ifndef RAD_VIEWFACTOR_COPLANAR_POLYGONS_H
#define RAD_VIEWFACTOR_COPLANAR_POLYGONS_H

#include "radiosity.h"
#include "surface_viewfactors/shadow_clip.h"
#include "surface_viewfactors/vf_geometry.h"

typedef struct coplanar_group {
    rad_vec3 normal;       /* unit, its largest component positive */
    double offset;         /* normal . x = offset */
    uint32_t first, count; /* its shapes: shape[first .. first + count - 1] */
    unsigned axis;         /* the coordinate (0, 1, 2) its shapes are sorted along: their
                              smallest value of it ascending */
    double widest;         /* largest extent of one shape along that axis */
} coplanar_group;

/* A shape's bounding box, and whether every corner lies within plane_epsilon of its
 * group's plane (a shape whose normal differs from the group's by up to 1e-9 may not). */
typedef struct coplanar_box {
    double lo[3], hi[3];
    bool flat;
} coplanar_box;

typedef struct coplanar_polygons {
    coplanar_group *groups;
    uint32_t group_count;
    uint32_t *group_of;    /* per scene triangle: the group of the shape covering it, or
                              UINT32_MAX (degenerate) */
    shadow_polygon *shape; /* the shapes, by group */
    double *low;           /* per shape: its smallest value along its group's axis */
    coplanar_box *box;     /* per shape */
} coplanar_polygons;

rad_status coplanar_polygons_build(const rad_scene *scene, const vf_geometry *geometry,
                                   coplanar_polygons *out, rad_error *error);
void coplanar_polygons_free(coplanar_polygons *planes);

/* The shapes of group g that may overlap [from, to] along its axis: shape[*begin] to
 * shape[*end - 1]. */
void coplanar_polygons_range(const coplanar_polygons *planes, uint32_t g, double from,
                             double to, uint32_t *begin, uint32_t *end);

#endif
