/*
 * shadow_clip.h - the exact view factor from a point to a polygon behind occluders.
 *
 * Each occluding triangle is cut to the slab between the point and the receiving polygon's
 * plane and projected from the point onto that plane; its shadow is subtracted from the
 * visible part of the receiver, kept as a list of convex pieces. The factor is Lambert's
 * contour formula summed over the pieces that remain: exact, with no sampling. The same
 * subtraction tells whether polygons lying in one plane cover a convex window of it.
 */
#ifndef RAD_VIEWFACTOR_SHADOW_CLIP_H
#define RAD_VIEWFACTOR_SHADOW_CLIP_H

#include "radiosity.h"
#include "surface_viewfactors/vf_geometry.h"

/* Most convex pieces the visible part may break into before the caller falls back to
 * sampling. */
#define SHADOW_MAX_PIECES 48

typedef struct shadow_occluder {
    rad_vec3 corner[3];
} shadow_occluder;

/* F from the point x (unit normal n) to what of `receiver` the occluders leave visible.
 * Returns -1 when the visible part breaks into more than SHADOW_MAX_PIECES pieces. */
double shadow_visible_factor(rad_vec3 x, rad_vec3 n, const vf_polygon *receiver,
                             const shadow_occluder *occluders, uint32_t occluder_count,
                             double plane_epsilon);

/* A convex polygon of the scene, as many corners as a view-factor polygon at most. */
typedef struct shadow_polygon {
    rad_vec3 vertex[VF_MAX_VERTICES];
    unsigned count;
} shadow_polygon;

/* The same behind flat convex occluders (either way round): the factor is the same as
 * behind the triangles they join (shadow_join_occluders), each shadow subtracted once
 * rather than by parts. */
double shadow_visible_factor_polygons(rad_vec3 x, rad_vec3 n, const vf_polygon *receiver,
                                      const shadow_polygon *occluders, uint32_t occluder_count,
                                      double plane_epsilon);

/* The same behind the occluders index[0 .. count) of either `triangles` or `polygons` (the
 * other NULL): the ones that can shade x, of those that can shade the pair. */
double shadow_visible_factor_subset(rad_vec3 x, rad_vec3 n, const vf_polygon *receiver,
                                    const shadow_occluder *triangles,
                                    const shadow_polygon *polygons, const uint32_t *index,
                                    uint32_t count, double plane_epsilon);

/* The occluding triangles joined where they can be, into `out` (room for `count`): two
 * join when they share an edge (the same corners, bit for bit), lie in one plane and their
 * union is convex with at most VF_MAX_VERTICES corners (straight corners dropped, to 1e-12
 * of a turn), until no two do. They cover the same points. Returns how many are left (a
 * wall given as 4 triangles: 1). */
uint32_t shadow_join_occluders(const shadow_occluder *triangles, uint32_t count,
                               shadow_polygon *out);

/* A convex piece of a plane, counter-clockwise about its normal. */
#define SHADOW_PIECE_MAX_VERTICES 15

typedef struct shadow_piece {
    rad_vec3 vertex[SHADOW_PIECE_MAX_VERTICES];
    unsigned count;
} shadow_piece;


/* What the convex polygons, lying in the plane of the convex `window` (counter-clockwise
 * about the unit `normal`, 3 to SHADOW_PIECE_MAX_VERTICES corners; the polygons either
 * way round), leave of it: its convex pieces go to `left` (room for SHADOW_MAX_PIECES),
 * slivers of at most 1e-12 of the window's area dropped. Returns how many (0: the polygons
 * cover the window), or -1 when it breaks into more than SHADOW_MAX_PIECES pieces. */
int shadow_window_remainder(const rad_vec3 *window, unsigned window_count, rad_vec3 normal,
                            const shadow_polygon *polygons, uint32_t polygon_count,
                            shadow_piece *left);

#endif
