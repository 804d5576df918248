/*
 * near_contacts.c - patches within a hair of each other, see near_contacts.h.
 *
 * Candidates come from a sweep along the scene's longest axis over the patches' bounding
 * boxes grown by the reach; a candidate is kept when the boxes overlap in all three axes,
 * some corner of it lies in front of the patch's plane and its nearest corner lies within
 * the reach of that plane. The list is conservative (a box test, not the exact distance
 * between the two polygons): an extra entry costs a test, a missing one a leak.
 */
#include "mesh/near_contacts.h"

#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/tolerance.h"
#include "core/vec3.h"

typedef struct patch_box {
    double lo[3], hi[3];
    double key; /* lo along the sweep axis */
    uint32_t patch;
} patch_box;

static int by_low(const void *a, const void *b)
{
    double x = ((const patch_box *)a)->key, y = ((const patch_box *)b)->key;
    if (x != y)
        return x < y ? -1 : 1;
    uint32_t p = ((const patch_box *)a)->patch, q = ((const patch_box *)b)->patch;
    return (p > q) - (p < q);
}

static double coordinate(rad_vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

/* True when patch k can block a segment leaving patch i's front within `reach` of it. */
static bool stands_in_front(const rad_mesh *mesh, uint32_t i, uint32_t k, double reach,
                            double plane_epsilon)
{
    const rad_patch *pi = &mesh->patches[i], *pk = &mesh->patches[k];
    rad_vec3 origin = mesh->vertices[pi->vertex[0]];
    double nearest = INFINITY, farthest = -INFINITY;
    for (unsigned c = 0; c < pk->vertex_count; c++) {
        double d = v3_dot(pi->normal, v3_sub(mesh->vertices[pk->vertex[c]], origin));
        nearest = fmin(nearest, d);
        farthest = fmax(farthest, d);
    }
    return farthest > plane_epsilon && nearest < reach;
}

double near_contacts_reach(const rad_mesh *mesh)
{
    rad_vec3 lo, hi;
    v3_bounds(mesh->vertices, mesh->vertex_count, &lo, &hi);
    /* a segment is at most the diagonal long; twice the end fraction for margin */
    return 2.0 * RAD_SEGMENT_END_EPSILON * v3_length(v3_sub(hi, lo));
}

rad_status near_contacts_build(const rad_mesh *mesh, double reach, double plane_epsilon,
                               near_contacts *out, rad_error *error)
{
    uint32_t n = mesh->patch_count;
    *out = (near_contacts){.patch_count = n, .mesh = mesh, .plane_epsilon = plane_epsilon};
    patch_box *boxes = rad_alloc_array(n, sizeof(*boxes));
    uint32_t *count = rad_alloc_array((size_t)n + 1, sizeof(*count));
    out->start = rad_alloc_array((size_t)n + 1, sizeof(*out->start));
    out->offset = rad_alloc_array(n, sizeof(*out->offset));
    out->radius = rad_alloc_array(n, sizeof(*out->radius));
    out->flatness = rad_alloc_array(n, sizeof(*out->flatness));
    uint32_t *pairs = NULL; /* (i, k) in pairs, two per entry */
    size_t pair_count = 0, pair_capacity = 0;
    if (!boxes || !count || !out->start || !out->offset || !out->radius || !out->flatness)
        goto nomem;
    for (uint32_t i = 0; i < n; i++) {
        const rad_patch *p = &mesh->patches[i];
        out->offset[i] = v3_dot(p->normal, mesh->vertices[p->vertex[0]]);
        out->radius[i] = out->flatness[i] = 0;
        for (unsigned c = 0; c < p->vertex_count; c++) {
            rad_vec3 corner = mesh->vertices[p->vertex[c]];
            out->radius[i] = fmax(out->radius[i], v3_length(v3_sub(corner, p->centroid)));
            out->flatness[i] =
                fmax(out->flatness[i], fabs(v3_dot(p->normal, corner) - out->offset[i]));
        }
    }
    rad_vec3 scene_lo, scene_hi;
    v3_bounds(mesh->vertices, mesh->vertex_count, &scene_lo, &scene_hi);
    rad_vec3 size = v3_sub(scene_hi, scene_lo);
    const double diagonal = v3_length(size);
    int axis = size.x >= size.y && size.x >= size.z ? 0 : size.y >= size.z ? 1 : 2;
    for (uint32_t i = 0; i < n; i++) {
        const rad_patch *p = &mesh->patches[i];
        patch_box *b = &boxes[i];
        b->patch = i;
        for (int a = 0; a < 3; a++) {
            b->lo[a] = INFINITY;
            b->hi[a] = -INFINITY;
        }
        for (unsigned c = 0; c < p->vertex_count; c++)
            for (int a = 0; a < 3; a++) {
                double x = coordinate(mesh->vertices[p->vertex[c]], a);
                b->lo[a] = fmin(b->lo[a], x - reach);
                b->hi[a] = fmax(b->hi[a], x + reach);
            }
    }
    for (uint32_t i = 0; i < n; i++)
        boxes[i].key = boxes[i].lo[axis];
    qsort(boxes, n, sizeof(*boxes), by_low);
    for (uint32_t s = 0; s < n; s++)
        for (uint32_t t = s + 1; t < n && boxes[t].lo[axis] <= boxes[s].hi[axis]; t++) {
            const patch_box *a = &boxes[s], *b = &boxes[t];
            if (a->lo[0] > b->hi[0] || b->lo[0] > a->hi[0] || a->lo[1] > b->hi[1] ||
                b->lo[1] > a->hi[1] || a->lo[2] > b->hi[2] || b->lo[2] > a->hi[2])
                continue;
            uint32_t i = a->patch, k = b->patch;
            for (int side = 0; side < 2; side++, i = b->patch, k = a->patch) {
                if (!stands_in_front(mesh, i, k, reach, plane_epsilon))
                    continue;
                if (!rad_grow_array((void **)&pairs, &pair_capacity, 2 * (pair_count + 1),
                                    sizeof(*pairs)))
                    goto nomem;
                pairs[2 * pair_count] = i;
                pairs[2 * pair_count + 1] = k;
                pair_count++;
                count[i]++;
            }
        }
    out->contact = rad_alloc_array(pair_count, sizeof(*out->contact));
    out->side = rad_alloc_array(pair_count, sizeof(*out->side));
    out->box = rad_alloc_array(n ? n : 1, sizeof(*out->box));
    if (!out->contact || !out->side || !out->box)
        goto nomem;
    for (uint32_t i = 0; i < n; i++)
        out->start[i + 1] = out->start[i] + count[i];
    for (uint32_t i = 0; i < n; i++)
        count[i] = out->start[i];
    for (size_t p = 0; p < pair_count; p++)
        out->contact[count[pairs[2 * p]]++] = pairs[2 * p + 1];
    for (uint32_t i = 0; i < n; i++) {
        const rad_patch *p = &mesh->patches[i];
        for (uint32_t c = out->start[i]; c < out->start[i + 1]; c++) {
            uint32_t k = out->contact[c];
            bool above = true, below = true;
            for (unsigned v = 0; v < p->vertex_count; v++) {
                double d = v3_dot(mesh->patches[k].normal, mesh->vertices[p->vertex[v]]) -
                           out->offset[k];
                above = above && d >= -plane_epsilon;
                below = below && d <= plane_epsilon;
            }
            out->side[c] = above && !below ? 1 : below && !above ? -1 : 0;
        }
    }
    /* near_contacts_block looks from an end up to (1.01 RAD_SEGMENT_END_EPSILON +
     * plane_epsilon / length) x the length, a segment being at most the diagonal long;
     * twice plane_epsilon and a billionth of the diagonal more for rounding */
    const double grow =
        1.02 * RAD_SEGMENT_END_EPSILON * diagonal + 2 * plane_epsilon + 1e-9 * diagonal;
    for (uint32_t k = 0; k < n; k++) {
        const rad_patch *pk = &mesh->patches[k];
        for (int a = 0; a < 3; a++) {
            out->box[k][a] = INFINITY;
            out->box[k][3 + a] = -INFINITY;
        }
        for (unsigned v = 0; v < pk->vertex_count; v++)
            for (int a = 0; a < 3; a++) {
                double x = coordinate(mesh->vertices[pk->vertex[v]], a);
                out->box[k][a] = fmin(out->box[k][a], x - grow);
                out->box[k][3 + a] = fmax(out->box[k][3 + a], x + grow);
            }
    }
    free(boxes);
    free(count);
    free(pairs);
    return RAD_OK;
nomem:
    free(boxes);
    free(count);
    free(pairs);
    near_contacts_free(out);
    return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the near contacts of %u patches", n);
}

void near_contacts_free(near_contacts *contacts)
{
    free(contacts->start);
    free(contacts->contact);
    free(contacts->offset);
    free(contacts->radius);
    free(contacts->flatness);
    free(contacts->side);
    free(contacts->box);
    contacts->start = contacts->contact = NULL;
    contacts->offset = contacts->radius = contacts->flatness = NULL;
    contacts->side = NULL;
    contacts->box = NULL;
}

/* Moller-Trumbore in double: the segment a + t d crosses triangle (v0, v1, v2) at some t in
 * (t_low, t_high). */
static bool segment_crosses(rad_vec3 a, rad_vec3 d, rad_vec3 v0, rad_vec3 v1, rad_vec3 v2,
                            double t_low, double t_high)
{
    rad_vec3 e1 = v3_sub(v1, v0), e2 = v3_sub(v2, v0);
    rad_vec3 p = v3_cross(d, e2);
    double det = v3_dot(e1, p);
    if (det == 0)
        return false;
    double inverse = 1.0 / det;
    rad_vec3 s = v3_sub(a, v0);
    double u = v3_dot(s, p) * inverse;
    if (u < 0 || u > 1)
        return false;
    rad_vec3 q = v3_cross(s, e1);
    double v = v3_dot(d, q) * inverse;
    if (v < 0 || u + v > 1)
        return false;
    double t = v3_dot(e2, q) * inverse;
    return t > t_low && t < t_high;
}

static bool crosses_patch(const rad_mesh *mesh, uint32_t k, rad_vec3 a, rad_vec3 d,
                          double t_low, double t_high)
{
    const rad_patch *p = &mesh->patches[k];
    const rad_vec3 *v = mesh->vertices;
    if (segment_crosses(a, d, v[p->vertex[0]], v[p->vertex[1]], v[p->vertex[2]], t_low, t_high))
        return true;
    return p->vertex_count == 4 && segment_crosses(a, d, v[p->vertex[0]], v[p->vertex[2]],
                                                   v[p->vertex[3]], t_low, t_high);
}

/* Can a segment from patch `from` to patch `to` cross one of from's contacts? Not when
 * `to` lies wholly on from's side of that contact's plane (its bounding sphere). */
static bool may_cross(const near_contacts *contacts, uint32_t from, uint32_t to)
{
    const rad_mesh *mesh = contacts->mesh;
    rad_vec3 centre = mesh->patches[to].centroid;
    double margin = contacts->radius[to] + contacts->plane_epsilon;
    for (uint32_t c = contacts->start[from]; c < contacts->start[from + 1]; c++) {
        uint32_t k = contacts->contact[c];
        if (k == to)
            continue;
        double d = v3_dot(mesh->patches[k].normal, centre) - contacts->offset[k];
        int side = contacts->side[c];
        if (side == 0 || (side > 0 && d < margin) || (side < 0 && d > -margin))
            return true;
    }
    return false;
}

bool near_contacts_pair_may_block(const near_contacts *contacts, uint32_t from, uint32_t to)
{
    return may_cross(contacts, from, to) || may_cross(contacts, to, from);
}

/* Whether point a lies in patch k's grown box (near_contacts.box): else no point of k is
 * within the reach of a segment's end at a. */
static bool in_box(const near_contacts *contacts, uint32_t k, rad_vec3 a)
{
    const double *box = contacts->box[k];
    return a.x >= box[0] && a.y >= box[1] && a.z >= box[2] && a.x <= box[3] && a.y <= box[4] &&
           a.z <= box[5];
}

/* Can the segment a + t d, t in (t_low, zone), meet contact k? Not when the stretch where
 * it runs within k's flatness of k's plane lies outside that range, nor when k's bounding
 * sphere is farther from a than the stretch is long. Both tests are exact (k's triangles
 * lie within its flatness of its plane and inside its sphere); they spare the triangle
 * tests for the cells around a point of a folded wall, which lie within a hair of it and
 * which a segment leaving the wall moves away from. */
static bool may_meet(const near_contacts *contacts, uint32_t k, rad_vec3 a, rad_vec3 d,
                     double length, double t_low, double zone)
{
    const rad_patch *patch = &contacts->mesh->patches[k];
    /* the zone is zone x length long: k's triangles, within `slack` of its plane, are not
     * reached from farther than that */
    double reach = zone * length;
    double slack = contacts->flatness[k] + 1e-3 * contacts->plane_epsilon; /* and rounding */
    double distance = v3_dot(patch->normal, a) - contacts->offset[k];
    if (fabs(distance) > reach + slack)
        return false;
    rad_vec3 to_centre = v3_sub(patch->centroid, a);
    double sphere = contacts->radius[k] + reach;
    if (v3_dot(to_centre, to_centre) > sphere * sphere)
        return false;
    double speed = v3_dot(patch->normal, d);
    if (speed == 0)
        return fabs(distance) <= slack;
    double t0 = (-distance - slack) / speed, t1 = (-distance + slack) / speed;
    return max_d(t0, t1) > t_low && min_d(t0, t1) < zone;
}

/* The end `a` of a segment a + t d, t in [0, 1], of the given length: does it cross one
 * of patch `end`'s contacts (other than `other`) within t in (t_low, zone]? */
static bool blocked_near(const near_contacts *contacts, uint32_t end, uint32_t other,
                         rad_vec3 a, rad_vec3 d, double length, double t_low, double zone)
{
    const rad_mesh *mesh = contacts->mesh;
    for (uint32_t c = contacts->start[end]; c < contacts->start[end + 1]; c++) {
        uint32_t k = contacts->contact[c];
        if (k != other && in_box(contacts, k, a) &&
            may_meet(contacts, k, a, d, length, t_low, zone) &&
            crosses_patch(mesh, k, a, d, t_low, zone))
            return true;
    }
    return false;
}

/* Whether point `a`, a segment's end on patch `end`, lies in the box of one of end's
 * contacts other than `other`. */
static bool in_a_contact_box(const near_contacts *contacts, uint32_t end, uint32_t other,
                             rad_vec3 a)
{
    for (uint32_t c = contacts->start[end]; c < contacts->start[end + 1]; c++)
        if (contacts->contact[c] != other && in_box(contacts, contacts->contact[c], a))
            return true;
    return false;
}

bool near_contacts_block(const near_contacts *contacts, uint32_t from, uint32_t to, rad_vec3 a,
                         rad_vec3 b)
{
    /* most ends lie in no contact's box (on the Cornell box, 553 of 6.9 M segments are
     * blocked here): those need no more */
    const bool near_a = in_a_contact_box(contacts, from, to, a);
    const bool near_b = in_a_contact_box(contacts, to, from, b);
    if (!near_a && !near_b)
        return false;
    rad_vec3 d = v3_sub(b, a);
    double length = v3_length(d);
    if (!(length > 2 * contacts->plane_epsilon))
        return false;
    double t_low = contacts->plane_epsilon / length;
    /* what the tracer leaves out, and a little more so that nothing falls between */
    double zone = fmin(0.5, 1.01 * RAD_SEGMENT_END_EPSILON + t_low);
    return (near_a && blocked_near(contacts, from, to, a, d, length, t_low, zone)) ||
           (near_b && blocked_near(contacts, to, from, b, v3_scale(d, -1), length, t_low, zone));
}
