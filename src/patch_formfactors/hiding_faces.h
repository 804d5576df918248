/*
 * hiding_faces.h - the convex face each occluding triangle hides pairs of patches with
 * (internal).
 *
 * A pair of patches is wholly hidden by a convex planar face when their corners lie
 * strictly on either side of its plane and every segment from a corner of one to a corner
 * of the other crosses it strictly inside (exact_pairs_hidden). Scenes give quads as two
 * triangles, and a shadow's cross-section often spans the diagonal: each triangle's face
 * is therefore the convex quad it makes with a neighbour across an edge when that
 * neighbour lies in its plane (its far corner within `flat` of it) and the four corners are
 * convex, else the triangle itself. Edges are matched by their corners' positions, bit for
 * bit; only an edge that exactly two triangles share counts.
 */
#ifndef RAD_PATCH_FORMFACTORS_HIDING_FACES_H
#define RAD_PATCH_FORMFACTORS_HIDING_FACES_H

#include <stdint.h>

#include "radiosity.h"

typedef struct hiding_face {
    rad_vec3 edge_normal[4]; /* in the plane, inward, unit */
    double edge_offset[4];   /* a point x of the plane is inside when every
                                edge_normal . x - edge_offset > 0 */
    unsigned edges;          /* 3 (the triangle alone), 4 (with its neighbour), 0 (degenerate) */
} hiding_face;

/* The faces of `count` triangles (corners, and unit normals or zero for a degenerate
 * one), allocated into *out. */
rad_status hiding_faces_build(const rad_vec3 (*corner)[3], const rad_vec3 *normal,
                              uint32_t count, double flat, hiding_face **out,
                              rad_error *error);

#endif
