/*
 * near_contacts.h - the patches that come within a hair of a patch, for visibility.
 *
 * Occlusion segments between two patches leave out a fraction RAD_SEGMENT_END_EPSILON of
 * their length at each end, so that in single precision a patch's own triangles never
 * block it. A surface closer than that to one end is then never seen: a box resting on a
 * floor with its bottom face, a wall modelled twice 1e-6 apart, a box inside a box. Rays
 * leak through it, the patch beneath sees the room as well as the surface in front of it,
 * and its row of form factors sums to 2.
 *
 * So every patch keeps the list of other patches that come within that reach of it and
 * stand in front of its plane, and each segment is also tested, in double precision and
 * against those lists only, for what the tracer cannot resolve. Coplanar patches (the
 * patch's own neighbours, a coincident copy facing the other way) cannot block a segment
 * leaving the patch's front, and are not listed. Most patches have empty lists.
 */
#ifndef RAD_MESH_NEAR_CONTACTS_H
#define RAD_MESH_NEAR_CONTACTS_H

#include <stdbool.h>

#include "radiosity.h"

typedef struct near_contacts {
    uint32_t patch_count;
    uint32_t *start;   /* patch_count + 1: patch i's contacts are contact[start[i] .. start[i+1]) */
    uint32_t *contact; /* patch indices */
    const rad_mesh *mesh;
    double *offset;       /* patch_count: each patch's plane, normal . x = offset */
    double *radius;       /* patch_count: largest distance from the centroid to a corner */
    double *flatness;     /* patch_count: largest distance of a corner from that plane (a
                             cell of a folded quad is not flat) */
    int8_t *side;         /* per contact: the side of the contact's plane the listing patch
                             lies on (+1, -1), or 0 when the plane cuts it */
    double (*box)[6];     /* patch_count: each patch's corners' bounding box (lo x, y, z,
                             hi x, y, z) grown by how far from a segment's end the tracer
                             does not look, at most: an end outside a contact's box cannot
                             meet that contact there */
    double plane_epsilon; /* a crossing must lie this far along the segment from an end */
} near_contacts;

/* Lists, for every patch of the mesh, the patches within `reach` (scene units) of it with
 * a corner in front of its plane by more than plane_epsilon. */
rad_status near_contacts_build(const rad_mesh *mesh, double reach, double plane_epsilon,
                               near_contacts *out, rad_error *error);
void near_contacts_free(near_contacts *contacts);

/* The reach that covers what occlusion segments leave out at their ends in a scene of
 * this bounding box. */
double near_contacts_reach(const rad_mesh *mesh);

static inline bool near_contacts_any(const near_contacts *contacts, uint32_t patch)
{
    return contacts->start[patch + 1] > contacts->start[patch];
}

/* False when no segment between patches `from` and `to` can cross a contact of either
 * where the tracer does not look: for each contact, the other patch lies wholly on the
 * listing patch's side of the contact's plane (the common case: a wall touching a floor
 * and a patch inside the room). A cheap test per pair before one per segment. */
bool near_contacts_pair_may_block(const near_contacts *contacts, uint32_t from, uint32_t to);

/* True when the segment from a (on patch `from`) to b (on patch `to`) crosses one of the
 * two patches' contacts other than from and to themselves where the tracer does not look:
 * within the first (from's contacts) or last (to's) RAD_SEGMENT_END_EPSILON of its length,
 * and more than plane_epsilon from the end. */
bool near_contacts_block(const near_contacts *contacts, uint32_t from, uint32_t to, rad_vec3 a,
                         rad_vec3 b);

#endif
