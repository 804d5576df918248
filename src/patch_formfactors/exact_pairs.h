/*
 * exact_pairs.h - the patch pairs that need no sampled visibility: what may stand between
 * two patches, and the exact obstructed transfer where few triangles do.
 *
 * The view-factor engine's methods (src/surface_viewfactors/) applied to patches: the
 * occluder tree over the tracer's own triangles answers "can anything block a segment
 * between these two patches?" exactly (conservatively); when nothing can, the analytic
 * transfer is the answer and no ray is cast. When at most EXACT_PAIRS_MAX_OCCLUDERS (4)
 * triangles can, shadow clipping gives each point's visible factor exactly. Not here: the
 * unoccluded transfer and the sampled visibility (pair_engine.c).
 */
#ifndef RAD_FORMFACTOR_EXACT_PAIRS_H
#define RAD_FORMFACTOR_EXACT_PAIRS_H

#include "radiosity.h"
#include "surface_viewfactors/occluder_tree.h"
#include "surface_viewfactors/vf_geometry.h"

typedef struct screen_node screen_node;
typedef struct screen_triangle screen_triangle;

typedef struct exact_pairs {
    occluder_tree *tree;  /* the tracer's triangles */
    /* the same triangles in a cheaper tree that only screens: a pair whose hull's bounding
     * box and two planes leave no triangle straddling is clear without the hull's faces */
    screen_node *screen_nodes;
    screen_triangle *screen_triangles;
    uint32_t screen_node_count;
    /* per screen triangle, the convex face it hides pairs with (hiding_faces.h) */
    struct hiding_face *hiding_faces;
    /* per patch, the convex solid (the tree's, convex_solids.h) that holds it, or
     * EXACT_NO_SOLID: a segment from it to a patch outside leaves through a face */
    uint32_t *inside_solid;
    rad_vec3 *solid_corner;       /* the corners of each solid's triangles, */
    uint32_t *solid_corner_first; /* solid k's from solid_corner_first[k] to [k + 1] */
    vf_polygon *polygons; /* per patch; count 0 for a folded (bulging) patch: never exact */
    double epsilon;       /* touching a pair's hull within this does not count */
    double plane_epsilon; /* in front of a plane means beyond this (scene units) */
    /* groups of about 16 neighbouring coplanar patches (exact_pairs_group): two groups
     * whose rectangles' hull no triangle cuts make every pair between them clear */
    uint32_t *group_of;   /* per patch, or EXACT_NO_GROUP; NULL: no groups */
    uint32_t group_count, group_words;
    uint64_t *group_clear; /* per group, group_words words: bit h of the row of g, g < h */
    /* per pair of groups g < h that is not clear, at g x group_count + h: the triangles
     * (indices of screen_triangles) that may cut the hull of their rectangles, in row g's
     * list from group_list_first, group_list_count of them (UINT8_MAX: not listed, screen
     * the tree); NULL: no lists */
    uint32_t **group_list;
    uint32_t *group_list_first;
    uint8_t *group_list_count;
} exact_pairs;

#define EXACT_NO_GROUP UINT32_MAX

rad_status exact_pairs_build(const rad_mesh *mesh, const rad_tracer *occluders,
                             double plane_epsilon, exact_pairs *out, rad_error *error);
void exact_pairs_free(exact_pairs *pairs);

typedef enum exact_outcome {
    EXACT_CLEAR,    /* nothing can block: the unoccluded transfer is the answer */
    EXACT_SETTLED,  /* *G holds the exact obstructed transfer */
    EXACT_SAMPLE    /* too many occluders (or a folded patch, or the clipping gave up):
                       sample visibility */
} exact_outcome;

/* Groups the patches: neighbouring coplanar patches of one surface, in cells about four
 * patches wide, each group standing for the rectangle in its plane around its patches;
 * then screens every two groups' rectangles as a pair. The hull of two patches lies in the
 * hull of their groups' rectangles, so a triangle that cuts the first cuts the second:
 * two groups found clear make each pair between them clear, and screening the pair
 * itself (which would say the same) is skipped. Two groups not found clear keep the list of
 * the triangles that may cut their rectangles' hull, and their pairs screen only those: a
 * triangle outside that hull is outside each pair's. A folded patch has no group. */
rad_status exact_pairs_group(exact_pairs *pairs, const rad_mesh *mesh, int threads,
                             rad_error *error);

/* Whether the pair (i, j) is clear by its groups. */
static inline bool exact_pairs_group_clear(const exact_pairs *pairs, uint32_t i, uint32_t j)
{
    if (!pairs->group_of)
        return false;
    uint32_t g = pairs->group_of[i], h = pairs->group_of[j];
    if (g == EXACT_NO_GROUP || h == EXACT_NO_GROUP)
        return false;
    if (g > h) { /* the pair is kept in the lower group's row */
        uint32_t swap = g;
        g = h;
        h = swap;
    }
    return pairs->group_clear[(size_t)g * pairs->group_words + h / 64] >> (h % 64) & 1u;
}

#define EXACT_NO_SOLID UINT32_MAX
#define EXACT_NO_CROSSING UINT32_MAX

/* True when patch j is wholly hidden from patch i: a convex solid holds one of them and
 * the other lies apart from it (convex_solid_holds, convex_solid_apart: the floor under a
 * box), or the screening's triangle across their centroids' segment (`crossing`, from
 * exact_pairs_transfer) hides them: their corners lie strictly on either side of its
 * plane, and every segment from a corner of i to a corner of j crosses it strictly inside
 * its face (itself, or the convex quad it makes with a neighbour in its plane; then so
 * does every segment between the two patches, whose crossings lie in the hull of those).
 * A conservative proof: false says nothing. Thread-safe. */
bool exact_pairs_hidden(const exact_pairs *pairs, uint32_t i, uint32_t j, uint32_t crossing);

/* Classifies the pair (i, j); with `clip` (pairs close enough for their kernel to vary
 * fast across them) also settles a pair that few triangles obstruct, to relative
 * accuracy `accuracy`. *crossing (unless NULL): the triangle (of the screening) the
 * screening found across the centroids' segment, or EXACT_NO_CROSSING. Thread-safe. */
exact_outcome exact_pairs_transfer(const exact_pairs *pairs, uint32_t i, uint32_t j, bool clip,
                                   double accuracy, double *G, uint32_t *crossing);

#endif
