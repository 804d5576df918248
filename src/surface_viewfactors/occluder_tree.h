/*
 * occluder_tree.h - "could anything block the view between these two polygons?"
 *
 * A bounding-volume tree over every scene triangle (obstructions included), queried with
 * the convex hull of two polygons: every segment between them lies inside that hull, so a
 * triangle that is separated from the hull cannot block any of them. The answer is
 * conservative: `false` means provably unobstructed (the analytic value is exact), `true`
 * means some triangle may block and visibility must be sampled.
 */
#ifndef RAD_VIEWFACTOR_OCCLUDER_TREE_H
#define RAD_VIEWFACTOR_OCCLUDER_TREE_H

#include "radiosity.h"
#include "surface_viewfactors/convex_solids.h"
#include "surface_viewfactors/shadow_clip.h"
#include "surface_viewfactors/vf_geometry.h"

typedef struct occluder_tree occluder_tree;

/* triangle_source: per scene triangle, the radiating polygon covering it (its own
 * triangles never block a polygon's view), or UINT32_MAX (vf_geometry.triangle_source).
 * solids: find the scene's convex solids (convex_solids.h), whose faces turned away from a
 * pair occluder_tree_collect leaves out (not under a --max-memory budget without room for
 * their search); false for a caller that changes the occluders it collects, as the sky
 * does, or wants every one. */
rad_status occluder_tree_build(const rad_scene *scene, const uint32_t *triangle_source,
                               bool solids, occluder_tree **out, rad_error *error);
void occluder_tree_destroy(occluder_tree *tree);

/* The convex solids the build found (with `solids`), or NULL. */
const convex_solids *occluder_tree_solids(const occluder_tree *tree);

/* Whether occluder_tree_collect leaves out the faces of the solids the build found (it
 * does after a build that found them); false: every triangle that cuts the hull, for a
 * test to compare. Not while other threads collect from the tree. */
void occluder_tree_use_solids(occluder_tree *tree, bool use);

/* Room for the side planes of the hull of two polygons (at most two per edge). */
#define OCCLUDER_HULL_MAX_SIDES (4u * VF_MAX_VERTICES)

/* The side faces of the convex hull of p and q: the planes through an edge of one that
 * have every corner of both on one side (within epsilon) and touch a corner besides the
 * edge's, as outward unit normals and offsets (n . x = offset); returns how many. With
 * the two polygons' own planes they bound the hull. A pair that wraps more than half a
 * turn around an edge gives no face there: the hull is then looser, never too tight. */
unsigned occluder_hull_sides(const vf_polygon *p, const vf_polygon *q, double epsilon,
                             rad_vec3 *normal, double *offset);

/* The same faces, only those through one edge: edges 0 .. p->count - 1 are p's, the next
 * q->count are q's; at most two faces (room for two). For a caller that can stop as soon
 * as the faces found so far settle its question. */
unsigned occluder_hull_edge_sides(const vf_polygon *p, const vf_polygon *q, unsigned edge,
                                  double epsilon, rad_vec3 *normal, double *offset);

/* The triangles other than the polygons' own that may cut the hull of p and q (touching
 * the hull's boundary within epsilon, scene units, does not count), save the faces of a
 * convex solid (convex_solids.h) turned away from p, or from q when p lies inside it or
 * beyond its missing face: their corners go to `out` (room for `max`); returns how many,
 * or max + 1 when there are more. The segments between p and q that they block are the
 * same as behind all the triangles. */
uint32_t occluder_tree_collect(const occluder_tree *tree, const vf_polygon *p,
                               const vf_polygon *q, double epsilon, shadow_occluder *out,
                               uint32_t max);

/* The same for the pyramid of a point x (unit normal n: only what lies in front of its
 * plane counts) and a convex polygon q whose front faces x: the triangles that may block a
 * segment from x to q, for the exact light from q at x (shadow_visible_factor). q's own
 * triangles (q->source) are left out. */
uint32_t occluder_tree_collect_from_point(const occluder_tree *tree, rad_vec3 x, rad_vec3 n,
                                          const vf_polygon *q, double epsilon,
                                          shadow_occluder *out, uint32_t max);

#endif
