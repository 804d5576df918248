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
#include "geometry/flat_pieces.h"
#include "surface_viewfactors/vf_geometry.h"

/* Most convex pieces the visible part may break into on the stack; past them the caller
 * tries again with more room (shadow_receiver_factor's) or samples. */
#define SHADOW_MAX_PIECES 48

typedef struct shadow_occluder {
    rad_vec3 corner[3];
} shadow_occluder;

/* F from the point x (unit normal n) to what of `receiver` the occluders leave visible.
 * Returns -1 when the visible part breaks into more than SHADOW_MAX_PIECES pieces (or a
 * subtraction's parts wait for room beyond FLAT_SUBTRACT_WAITING, flat_pieces.h). */
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

/* A receiving polygon made ready for the factor from many points: its plane's frame and
 * its corners in it. */
typedef struct shadow_receiver {
    plane_frame frame;
    double offset; /* normal . v on its plane */
    double tiny;   /* visible pieces of at most this area are dropped */
    flat_piece whole;
} shadow_receiver;

void shadow_receiver_prepare(const vf_polygon *receiver, shadow_receiver *out);

/* An occluder made ready for a receiver: its part above the receiver's plane (beyond
 * plane_epsilon: what lies at or behind it shades nothing there), each corner's
 * coordinates in the plane's frame and height above it; count 0 when nothing is above. */
#define SHADOW_CASTER_MAX_VERTICES (VF_MAX_VERTICES + 1)

typedef struct shadow_caster {
    flat_point at[SHADOW_CASTER_MAX_VERTICES];
    double height[SHADOW_CASTER_MAX_VERTICES];
    unsigned count;
} shadow_caster;

/* corners: a flat convex polygon, at most VF_MAX_VERTICES of them. */
void shadow_caster_prepare(const shadow_receiver *receiver, const rad_vec3 *corners,
                           unsigned count, double plane_epsilon, shadow_caster *out);

/* The factor from x to what of the receiver the casters index[0 .. count) (NULL: the first
 * count) leave visible; the same as shadow_visible_factor behind the occluders they were
 * made from, with room for max_pieces visible pieces in `pieces` (shadow_visible_factor
 * has SHADOW_MAX_PIECES on the stack): -1 past max_pieces, or as flat_subtract says. */
double shadow_receiver_factor(const shadow_receiver *receiver, rad_vec3 x, rad_vec3 n,
                              const shadow_caster *casters, const uint32_t *index,
                              uint32_t count, double plane_epsilon, flat_piece *pieces,
                              unsigned max_pieces);

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
 * cover the window), or -1 when it breaks into more than SHADOW_MAX_PIECES pieces (or a
 * subtraction's parts wait for room beyond FLAT_SUBTRACT_WAITING, flat_pieces.h). */
int shadow_window_remainder(const rad_vec3 *window, unsigned window_count, rad_vec3 normal,
                            const shadow_polygon *polygons, uint32_t polygon_count,
                            shadow_piece *left);

#endif
