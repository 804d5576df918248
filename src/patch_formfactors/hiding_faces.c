/*
 * hiding_faces.c - the convex face each occluding triangle hides pairs of patches with
 * (hiding_faces.h).
 */
#include "patch_formfactors/hiding_faces.h"

#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"

/* One triangle's edge, its ends in lexicographic order. */
typedef struct edge_record {
    rad_vec3 lo, hi;
    uint32_t triangle;
    unsigned edge; /* from corner `edge` to corner edge + 1 */
} edge_record;

static int position_order(rad_vec3 a, rad_vec3 b)
{
    if (a.x != b.x)
        return a.x < b.x ? -1 : 1;
    if (a.y != b.y)
        return a.y < b.y ? -1 : 1;
    if (a.z != b.z)
        return a.z < b.z ? -1 : 1;
    return 0;
}

static int edge_order(const void *x, const void *y)
{
    const edge_record *a = x, *b = y;
    int order = position_order(a->lo, b->lo);
    if (!order)
        order = position_order(a->hi, b->hi);
    if (!order)
        order = a->triangle < b->triangle ? -1 : a->triangle > b->triangle;
    return order;
}

/* The triangle alone: its three edges' inward normals in its plane. */
static hiding_face triangle_face(const rad_vec3 corner[3], rad_vec3 normal)
{
    hiding_face face = {.edges = 3};
    if (!(v3_length(normal) > 0))
        face.edges = 0;
    for (unsigned k = 0; k < 3 && face.edges; k++) {
        rad_vec3 a = corner[k], b = corner[(k + 1) % 3];
        rad_vec3 inward = v3_cross(normal, v3_sub(b, a));
        double length = v3_length(inward);
        if (!(length > 0) || !isfinite(length)) {
            face.edges = 0; /* degenerate: no point is inside */
            break;
        }
        face.edge_normal[k] = v3_scale(inward, 1 / length);
        face.edge_offset[k] = v3_dot(face.edge_normal[k], a);
    }
    return face;
}

static double side_of(rad_vec3 from, rad_vec3 to, rad_vec3 x, rad_vec3 normal)
{
    return v3_dot(v3_cross(v3_sub(to, from), v3_sub(x, from)), normal);
}

/* Triangles t and u share t's edge k (u's edge m): their quad, when u lies in t's plane
 * and the four corners are convex, becomes both triangles' face. */
static void try_merge(const rad_vec3 (*corner)[3], const rad_vec3 *normal, double flat,
                      uint32_t t, unsigned k, uint32_t u, unsigned m, hiding_face *faces)
{
    rad_vec3 n = normal[t];
    rad_vec3 a = corner[t][k], b = corner[t][(k + 1) % 3], c = corner[t][(k + 2) % 3];
    rad_vec3 d = corner[u][(m + 2) % 3];
    if (!(fabs(v3_dot(n, normal[u])) >= 1 - 1e-12) || !(fabs(v3_dot(n, v3_sub(d, a))) <= flat))
        return;
    /* convex: c and d on either side of the shared edge, a and b on either side of cd */
    double sc = side_of(a, b, c, n), sd = side_of(a, b, d, n);
    double sa = side_of(c, d, a, n), sb = side_of(c, d, b, n);
    if (!((sc > 0 && sd < 0) || (sc < 0 && sd > 0)) || !((sa > 0 && sb < 0) || (sa < 0 && sb > 0)))
        return;
    hiding_face of_t = faces[t], of_u = faces[u], quad = {.edges = 4};
    unsigned from[4][2] = {{0, (k + 1) % 3}, {0, (k + 2) % 3}, {1, (m + 1) % 3}, {1, (m + 2) % 3}};
    for (unsigned e = 0; e < 4; e++) {
        const hiding_face *source = from[e][0] ? &of_u : &of_t;
        quad.edge_normal[e] = source->edge_normal[from[e][1]];
        quad.edge_offset[e] = source->edge_offset[from[e][1]];
    }
    faces[t] = faces[u] = quad;
}

rad_status hiding_faces_build(const rad_vec3 (*corner)[3], const rad_vec3 *normal,
                              uint32_t count, double flat, hiding_face **out,
                              rad_error *error)
{
    *out = NULL;
    hiding_face *faces = rad_alloc_array(count ? count : 1, sizeof(*faces));
    edge_record *records = rad_alloc_array(count ? 3 * (size_t)count : 1, sizeof(*records));
    if (!faces || !records) {
        free(faces);
        free(records);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the occluders' faces");
    }
    for (uint32_t t = 0; t < count; t++) {
        faces[t] = triangle_face(corner[t], normal[t]);
        for (unsigned k = 0; k < 3; k++) {
            rad_vec3 a = corner[t][k], b = corner[t][(k + 1) % 3];
            bool forward = position_order(a, b) <= 0;
            records[3 * (size_t)t + k] = (edge_record){forward ? a : b, forward ? b : a, t, k};
        }
    }
    size_t edges = 3 * (size_t)count;
    qsort(records, edges, sizeof(*records), edge_order);
    for (size_t r = 0; r < edges;) {
        size_t end = r + 1;
        while (end < edges && !position_order(records[end].lo, records[r].lo) &&
               !position_order(records[end].hi, records[r].hi))
            end++;
        const edge_record *x = &records[r], *y = &records[r + 1];
        if (end - r == 2 && x->triangle != y->triangle && faces[x->triangle].edges == 3 &&
            faces[y->triangle].edges == 3)
            try_merge(corner, normal, flat, x->triangle, x->edge, y->triangle, y->edge, faces);
        r = end;
    }
    free(records);
    *out = faces;
    return RAD_OK;
}
