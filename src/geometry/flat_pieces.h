/*
 * flat_pieces.h - convex pieces of a plane in the plane's own 2-D coordinates, and the
 * subtraction of a convex polygon from a list of them.
 *
 * The shadow clipping of exact obstructed view factors keeps what of a receiving polygon
 * its occluders' shadows leave as a list of convex pieces, and cuts each piece along each
 * shadow edge. In the receiver's plane that is 2-D work: a frame (two unit axes and the
 * normal) maps points of the plane to (u, v) and back, and counter-clockwise about the
 * normal is counter-clockwise in (u, v).
 */
#ifndef RAD_GEOMETRY_FLAT_PIECES_H
#define RAD_GEOMETRY_FLAT_PIECES_H

#include <stdbool.h>

#include "core/vec3.h"

/* Most corners of a piece. */
#define FLAT_PIECE_MAX_VERTICES 15

typedef struct flat_point {
    double u, v;
} flat_point;

/* A convex polygon of the plane, counter-clockwise. */
typedef struct flat_piece {
    flat_point vertex[FLAT_PIECE_MAX_VERTICES];
    unsigned count;
} flat_piece;

/* A plane's frame: origin, unit axes u and v, unit normal = u x v. */
typedef struct plane_frame {
    rad_vec3 origin, u, v, normal;
} plane_frame;

/* The frame of the plane through origin with unit normal n (axes of hemisphere_frame). */
plane_frame plane_frame_make(rad_vec3 origin, rad_vec3 n);

/* The coordinates of p (of the plane or not: its projection's). */
static inline flat_point plane_frame_flat(const plane_frame *frame, rad_vec3 p)
{
    rad_vec3 d = v3_sub(p, frame->origin);
    return (flat_point){v3_dot(frame->u, d), v3_dot(frame->v, d)};
}

/* The point of the plane at (u, v). */
static inline rad_vec3 plane_frame_point(const plane_frame *frame, flat_point q)
{
    return v3_add(frame->origin, v3_add(v3_scale(frame->u, q.u), v3_scale(frame->v, q.v)));
}

/* Signed area: positive counter-clockwise. */
double flat_piece_area(const flat_piece *p);

/* Corners within 1e-12 of the piece's extent (largest coordinate difference from the first
 * corner) of the corner before them dropped, the last against the first too. A clip
 * through a corner makes its crossing point again, a hair away, and an edge of no length
 * has no direction: a piece then seemed to lie outside every shadow, and survived shadows
 * that covered it (a pair 0.005 % visible came out 5.8 %). A receiver may come with
 * repeated corners too (the part of a polygon in front of a plane through one of its
 * corners, vf_polygon_clip_front). */
void flat_piece_drop_repeated(flat_piece *p);

/* Parts of one subtraction that may wait for the room a piece vanishing later leaves. */
#define FLAT_SUBTRACT_WAITING 8u

/* Subtracts the convex `shape` (counter-clockwise) from the `count` pieces, in place
 * (room for max_pieces): each piece the shape overlaps gives way to its parts outside each
 * edge of the shape in turn, pieces of area at most `tiny` dropped; a piece the shape
 * misses, or overlaps by at most `tiny`, is kept as it is (it may move down to close the
 * slot of one that vanished; the order of the pieces is not kept; a piece of no corners
 * counts as none). Returns how many, or -1 (the pieces then undefined) when they would be
 * more than max_pieces, when more than FLAT_SUBTRACT_WAITING parts wait at once for room
 * that later pieces leave, or when a piece the shape meets would be cut into a part of
 * more than FLAT_PIECE_MAX_VERTICES corners. */
int flat_subtract(flat_piece *pieces, unsigned count, const flat_piece *shape, double tiny,
                  unsigned max_pieces);

#endif
