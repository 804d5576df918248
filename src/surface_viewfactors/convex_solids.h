/*
 * convex_solids.h - the scene's triangles that bound convex solids, and which of them a
 * polygon's view can leave out (internal).
 *
 * A segment from a point outside a convex solid that passes through it enters it through
 * a face turned toward the point. So behind a convex solid the faces turned away from the
 * point cast no shadow that the faces turned toward it do not already cast: the view
 * factors behind a city block's buildings need only the walls and roofs that face the
 * polygon, about half of them.
 *
 * A solid here is a connected set of triangles (corners joined where their positions are
 * equal bit for bit) that
 *   - is convex: every corner of the set lies behind or on the plane of each triangle
 *     (front = counter-clockwise, facing out), and not all in one plane;
 *   - is closed: each edge a -> b of a triangle is the edge b -> a of exactly one other,
 *     save at most the edges of one missing face, all of which lie in one plane (a
 *     building standing on the ground has walls and a roof but no floor). Through a
 *     missing face a segment can enter from that face's outer side only, so that solid's
 *     faces are left out only for a polygon on the face's inner side or in its plane.
 * Anything else (an edge three triangles share, a reflex edge, open edges in two planes)
 * is no solid: its triangles stay occluders as they are. A T-junction leaves the edges
 * along it unmatched: when they lie in one plane the solid counts as open there (a face
 * taken for missing: only the faces seen from its inner side are left out, which is
 * safe), else it is no solid.
 */
#ifndef RAD_VIEWFACTOR_CONVEX_SOLIDS_H
#define RAD_VIEWFACTOR_CONVEX_SOLIDS_H

#include <stdbool.h>

#include "radiosity.h"
#include "surface_viewfactors/vf_geometry.h"

/* Face planes kept per solid to tell a polygon outside it; a solid with more distinct face
 * planes than this is not one here. */
#define CONVEX_SOLID_MAX_PLANES 24u

typedef struct convex_solid {
    rad_vec3 normal[CONVEX_SOLID_MAX_PLANES]; /* outward unit normals of its face planes */
    double offset[CONVEX_SOLID_MAX_PLANES];   /* normal . x on the plane */
    unsigned plane_count;
    bool open;               /* one face missing, in the plane: */
    rad_vec3 open_normal;    /* outward unit normal */
    double open_offset;
} convex_solid;

typedef struct convex_solids {
    uint32_t *of_triangle; /* per scene triangle: its solid, or UINT32_MAX */
    convex_solid *solids;
    uint32_t count;
} convex_solids;

/* What the search holds at most while it looks, per triangle (it keeps 4 a triangle and
 * about 800 a solid): a caller under a --max-memory budget without this much room left
 * goes without the solids rather than fail. */
#define CONVEX_SOLIDS_SEARCH_BYTES 256u

/* Finds the scene's convex solids: RAD_ERR_NOMEM, else RAD_OK (with none, it may be). */
rad_status convex_solids_find(const rad_scene *scene, convex_solids *out, rad_error *error);

void convex_solids_free(convex_solids *solids);

/* Whether the faces of `solid` turned away from every point of the polygon may be left
 * out of its view: the polygon lies outside the solid, on the outer side of one of its
 * face planes with a corner beyond it (a polygon lying in a face plane, as the ground
 * under a building's floor does, may lie on the solid's surface, and a segment from
 * there enters through no face), and, for an open solid, on the inner side of the missing
 * face's plane or on it. Within epsilon: a polygon up to epsilon inside the solid passes,
 * and a sliver of its view that thin may go through. */
bool convex_solid_seen_from(const convex_solid *solid, const vf_polygon *polygon,
                            double epsilon);

/* Whether the polygon lies inside the solid: every corner more than epsilon inside each
 * face plane, and for an open solid on the missing face's plane or on its inner side
 * (exactly: the ground under a building, in the plane of its missing floor). A segment
 * from such a polygon to one the solid holds apart (below) leaves it through a face: it
 * cannot pass the missing face, whose plane it crosses at its start at most. */
bool convex_solid_holds(const convex_solid *solid, const vf_polygon *polygon, double epsilon);

/* Whether the polygon lies outside the solid: for an open solid every corner more than
 * epsilon on the inner side of the missing face's plane, and either every corner more
 * than epsilon beyond one face plane or every one of the solid's `corner_count` corners
 * (its triangles' corners: the solid is their hull) more than epsilon on one side of the
 * polygon's own plane. */
bool convex_solid_apart(const convex_solid *solid, const vf_polygon *polygon,
                        const rad_vec3 *corner, uint32_t corner_count, double epsilon);

/* Whether the face with unit normal n through `corner` is turned away from every point of
 * the polygon (each corner behind its plane or on it, within epsilon). */
bool convex_solid_face_away(rad_vec3 n, rad_vec3 corner, const vf_polygon *polygon,
                            double epsilon);

#endif
