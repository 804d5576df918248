/*
 * pair_hidden.h - proves two polygons wholly hidden from each other, exactly.
 *
 * A plane with polygon p strictly on one side and q strictly on the other is crossed by
 * every segment between them, inside the window where it cuts their convex hull (the
 * convex hull of the points where the segments between their corners cross it). When the
 * scene triangles lying in that plane cover the whole window (up to slivers of 1e-12 of
 * its area: rounding where their edges meet), every segment is blocked and the pair is
 * hidden, with no error. When they leave a few convex pieces of the window
 * uncovered, a segment through a piece r is still blocked when the pair (p, r) or the pair
 * (r, q) is proven hidden the same way, one level down (a street between two buildings
 * whose walls fill the rest, closed off further along). The planes tried are those of
 * the occluders that shaft culling found (occluder_tree.h). It is a proof, not an
 * estimate: false means "not proven", never "visible"; the caller then integrates or
 * samples the pair.
 */
#ifndef RAD_VIEWFACTOR_PAIR_HIDDEN_H
#define RAD_VIEWFACTOR_PAIR_HIDDEN_H

#include "radiosity.h"
#include "surface_viewfactors/occluder_tree.h"
#include "surface_viewfactors/shadow_clip.h"
#include "surface_viewfactors/vf_geometry.h"

/* Most occluders a proof looks at (the first found by occluder_tree_collect). */
#define PAIR_HIDDEN_MAX_OCCLUDERS 64u

/* Levels of uncovered pieces looked into at most. */
#define PAIR_HIDDEN_DEPTH 1u

/* True when some occluder's plane separates p and q (beyond plane_epsilon) and the
 * occluders lying in it (within plane_epsilon) cover the window, or leave pieces that are
 * proven hidden from p or from q through `tree`, PAIR_HIDDEN_DEPTH levels at most: no
 * segment between p and q is free. Looks at the first PAIR_HIDDEN_MAX_OCCLUDERS
 * occluders at most. */
bool pair_proven_hidden(const occluder_tree *tree, const vf_polygon *p, const vf_polygon *q,
                        const shadow_occluder *occluders, uint32_t occluder_count,
                        double plane_epsilon);

#endif
