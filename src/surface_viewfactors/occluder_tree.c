/*
 * occluder_tree.c - the conservative obstruction test, see occluder_tree.h.
 *
 * The hull of the (at most 8) corners is found by brute force: a plane through three
 * corners with every corner on one side is a face plane. A triangle is separated from the
 * hull when all its corners are outside (or on) one face plane, or when all hull corners
 * lie on one side of the triangle's plane. Tree nodes are culled by the same face planes.
 */
#include "surface_viewfactors/occluder_tree.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"
#include "surface_viewfactors/convex_solids.h"

#define LEAF_SIZE 4u
#define MAX_CORNERS (2u * VF_MAX_VERTICES)
#define MAX_PLANES (2u + 2u * VF_MAX_VERTICES * VF_MAX_VERTICES)
#define MAX_DEPTH 64u

typedef struct tree_node {
    double lo[3], hi[3];
    uint32_t first, count; /* a leaf when count > 0; else children at first, first + 1 */
} tree_node;

typedef struct tree_triangle {
    rad_vec3 corner[3];
    rad_vec3 normal; /* unit */
    uint32_t source; /* the radiating polygon it belongs to (vf_polygon.source), or
                        UINT32_MAX */
    uint32_t solid;  /* the convex solid it bounds (convex_solids.h), or UINT32_MAX */
} tree_triangle;

struct occluder_tree {
    tree_node *nodes;
    uint32_t node_count;
    tree_triangle *triangles;
    uint32_t triangle_count;
    convex_solids solids;
    bool use_solids; /* leave out solids' faces turned away from the pair */
};

typedef struct hull {
    rad_vec3 corner[MAX_CORNERS];
    unsigned corner_count;
    rad_vec3 normal[MAX_PLANES]; /* outward unit normals */
    double offset[MAX_PLANES];
    unsigned plane_count;
    double lo[3], hi[3];
    uint32_t exclude[2]; /* the sources of the two polygons */
} hull;

static double axis(rad_vec3 v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }

static int build_node(occluder_tree *tree, uint32_t node, uint32_t first, uint32_t count,
                      rad_vec3 *centres, unsigned depth)
{
    tree_node *n = &tree->nodes[node];
    for (int a = 0; a < 3; a++) {
        n->lo[a] = INFINITY;
        n->hi[a] = -INFINITY;
    }
    double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t t = first; t < first + count; t++)
        for (int a = 0; a < 3; a++) {
            for (int c = 0; c < 3; c++) {
                n->lo[a] = fmin(n->lo[a], axis(tree->triangles[t].corner[c], a));
                n->hi[a] = fmax(n->hi[a], axis(tree->triangles[t].corner[c], a));
            }
            clo[a] = fmin(clo[a], axis(centres[t], a));
            chi[a] = fmax(chi[a], axis(centres[t], a));
        }
    if (count <= LEAF_SIZE || depth >= MAX_DEPTH) {
        n->first = first;
        n->count = count;
        return 1;
    }
    int split = 0;
    for (int a = 1; a < 3; a++)
        if (chi[a] - clo[a] > chi[split] - clo[split])
            split = a;
    double middle = 0.5 * (clo[split] + chi[split]);
    uint32_t i = first, j = first + count;
    while (i < j) {
        if (axis(centres[i], split) < middle) {
            i++;
        } else {
            j--;
            tree_triangle swap = tree->triangles[i];
            tree->triangles[i] = tree->triangles[j];
            tree->triangles[j] = swap;
            rad_vec3 c = centres[i];
            centres[i] = centres[j];
            centres[j] = c;
        }
    }
    uint32_t left = i - first;
    if (left == 0 || left == count)
        left = count / 2; /* identical centres: split by count */
    uint32_t children = tree->node_count;
    tree->node_count += 2;
    n->first = children;
    n->count = 0;
    return build_node(tree, children, first, left, centres, depth + 1) &&
           build_node(tree, children + 1, first + left, count - left, centres, depth + 1);
}

rad_status occluder_tree_build(const rad_scene *scene, const uint32_t *triangle_source,
                               bool solids, occluder_tree **out, rad_error *error)
{
    *out = NULL;
    occluder_tree *tree = rad_alloc_array(1, sizeof(*tree));
    uint32_t count = scene->triangle_count;
    rad_vec3 *centres = rad_alloc_array(count ? count : 1, sizeof(rad_vec3));
    if (tree) {
        tree->triangles = rad_alloc_array(count ? count : 1, sizeof(tree_triangle));
        tree->nodes = rad_alloc_array(2 * (size_t)(count ? count : 1), sizeof(tree_node));
    }
    if (!tree || !centres || !tree->triangles || !tree->nodes) {
        free(centres);
        occluder_tree_destroy(tree);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the occluder tree");
    }
    /* the solids only speed the pairs up: under a budget without room for their search,
     * every triangle stays */
    uint64_t left = rad_memory_budget_left();
    if (solids && (left == UINT64_MAX || left / CONVEX_SOLIDS_SEARCH_BYTES > count)) {
        rad_status status = convex_solids_find(scene, &tree->solids, error);
        if (status != RAD_OK) {
            free(centres);
            occluder_tree_destroy(tree);
            return status;
        }
        tree->use_solids = true;
    }
    for (uint32_t t = 0; t < count; t++) {
        tree_triangle *tt = &tree->triangles[t];
        tt->solid = tree->use_solids ? tree->solids.of_triangle[t] : UINT32_MAX;
        for (int c = 0; c < 3; c++)
            tt->corner[c] = scene->positions[scene->triangles[t].vertex[c]];
        tt->normal = v3_normalize(v3_cross(v3_sub(tt->corner[1], tt->corner[0]),
                                           v3_sub(tt->corner[2], tt->corner[0])));
        tt->source = triangle_source[t];
        centres[t] = v3_scale(v3_add(v3_add(tt->corner[0], tt->corner[1]), tt->corner[2]),
                              1.0 / 3);
    }
    tree->triangle_count = count;
    tree->node_count = 1;
    if (count)
        build_node(tree, 0, 0, count, centres, 0);
    else
        tree->node_count = 0;
    free(centres);
    *out = tree;
    return RAD_OK;
}

void occluder_tree_destroy(occluder_tree *tree)
{
    if (!tree)
        return;
    free(tree->nodes);
    free(tree->triangles);
    convex_solids_free(&tree->solids);
    free(tree);
}

/* 2-D cross product of (ax, ay) and (bx, by). */
static double cross2(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

/* The hull faces through one edge (e0, e1) of a polygon: seen along the edge, every other
 * corner is a direction in the plane across it, and the faces are the planes through the
 * edge and the two extreme directions, when all of them lie within half a turn. Each
 * corner is looked at once per edge, instead of once per candidate plane. */
static unsigned edge_faces(rad_vec3 e0, rad_vec3 e1, const vf_polygon *const polygon[2],
                           rad_vec3 inside, double epsilon, rad_vec3 *normal_out,
                           double *offset_out)
{
    rad_vec3 u = v3_sub(e1, e0);
    double length = v3_length(u);
    if (!(length > 0))
        return 0;
    u = v3_scale(u, 1 / length);
    /* an orthonormal frame across the edge: w towards the polygon's inside, v = u x w */
    rad_vec3 w = v3_sub(inside, e0);
    w = v3_sub(w, v3_scale(u, v3_dot(w, u)));
    double w_length = v3_length(w);
    if (!(w_length > 0))
        return 0;
    w = v3_scale(w, 1 / w_length);
    rad_vec3 v = v3_cross(u, w);
    double x[2 * VF_MAX_VERTICES], y[2 * VF_MAX_VERTICES];
    unsigned count = 0;
    for (int k = 0; k < 2; k++)
        for (unsigned m = 0; m < polygon[k]->count; m++) {
            rad_vec3 r = v3_sub(polygon[k]->vertex[m], e0);
            x[count] = v3_dot(r, w);
            y[count] = v3_dot(r, v);
            count++;
        }
    /* the most counter-clockwise and most clockwise directions: exact when every
     * direction lies within half a turn, which the check below makes sure of */
    unsigned ccw = UINT32_MAX, cw = UINT32_MAX;
    double tiny = epsilon * epsilon;
    for (unsigned k = 0; k < count; k++) {
        if (x[k] * x[k] + y[k] * y[k] <= tiny)
            continue; /* on the edge's line: in every plane through it */
        if (ccw == UINT32_MAX) {
            ccw = cw = k;
            continue;
        }
        if (cross2(x[ccw], y[ccw], x[k], y[k]) > 0)
            ccw = k;
        if (cross2(x[cw], y[cw], x[k], y[k]) < 0)
            cw = k;
    }
    if (ccw == UINT32_MAX)
        return 0;
    unsigned made = 0;
    unsigned extreme[2] = {ccw, cw};
    for (int side = 0; side < 2; side++) {
        unsigned d = extreme[side];
        double d_length = sqrt(x[d] * x[d] + y[d] * y[d]);
        /* outward: every corner at signed distance <= 0 (within epsilon) */
        double sign = side == 0 ? 1.0 : -1.0;
        bool all_on_it = true, fits = true;
        for (unsigned k = 0; k < count && fits; k++) {
            double distance = sign * cross2(x[d], y[d], x[k], y[k]) / d_length;
            fits = distance <= epsilon;
            all_on_it = all_on_it && distance >= -epsilon;
        }
        if (!fits || all_on_it)
            continue; /* more than half a turn, or (degenerate) all on the plane */
        rad_vec3 normal = v3_scale(v3_add(v3_scale(w, -y[d]), v3_scale(v, x[d])),
                                   sign / d_length);
        normal_out[made] = normal;
        offset_out[made++] = v3_dot(normal, e0);
    }
    return made;
}

unsigned occluder_hull_edge_sides(const vf_polygon *p, const vf_polygon *q, unsigned edge,
                                  double epsilon, rad_vec3 *normal_out, double *offset_out)
{
    const vf_polygon *polygon[2] = {p, q};
    const vf_polygon *a = edge < p->count ? p : q;
    unsigned e = edge < p->count ? edge : edge - p->count;
    return edge_faces(a->vertex[e], a->vertex[(e + 1) % a->count], polygon, a->centroid,
                      epsilon, normal_out, offset_out);
}

unsigned occluder_hull_sides(const vf_polygon *p, const vf_polygon *q, double epsilon,
                             rad_vec3 *normal_out, double *offset_out)
{
    unsigned count = 0;
    for (unsigned edge = 0; edge < p->count + q->count; edge++)
        count += occluder_hull_edge_sides(p, q, edge, epsilon, &normal_out[count],
                                          &offset_out[count]);
    return count;
}

static void make_hull(hull *h, const vf_polygon *p, const vf_polygon *q, double epsilon)
{
    h->corner_count = 0;
    for (unsigned k = 0; k < p->count; k++)
        h->corner[h->corner_count++] = p->vertex[k];
    for (unsigned k = 0; k < q->count; k++)
        h->corner[h->corner_count++] = q->vertex[k];
    for (int a = 0; a < 3; a++) {
        h->lo[a] = INFINITY;
        h->hi[a] = -INFINITY;
        for (unsigned k = 0; k < h->corner_count; k++) {
            h->lo[a] = fmin(h->lo[a], axis(h->corner[k], a));
            h->hi[a] = fmax(h->hi[a], axis(h->corner[k], a));
        }
    }
    /* the hull's faces: the two polygons' planes, and planes through an edge of one and a
     * corner of the other that have every corner on one side */
    h->plane_count = 0;
    h->normal[h->plane_count] = v3_scale(p->normal, -1);
    h->offset[h->plane_count++] = -v3_dot(p->normal, p->vertex[0]);
    h->normal[h->plane_count] = v3_scale(q->normal, -1);
    h->offset[h->plane_count++] = -v3_dot(q->normal, q->vertex[0]);
    h->plane_count += occluder_hull_sides(p, q, epsilon, &h->normal[h->plane_count],
                                          &h->offset[h->plane_count]);
}

static bool box_outside(const hull *h, const tree_node *node, double epsilon)
{
    for (int a = 0; a < 3; a++)
        if (node->lo[a] > h->hi[a] + epsilon || node->hi[a] < h->lo[a] - epsilon)
            return true;
    for (unsigned k = 0; k < h->plane_count; k++) {
        rad_vec3 n = h->normal[k];
        /* the box corner furthest against the outward normal */
        double nearest = n.x * (n.x > 0 ? node->lo[0] : node->hi[0]) +
                         n.y * (n.y > 0 ? node->lo[1] : node->hi[1]) +
                         n.z * (n.z > 0 ? node->lo[2] : node->hi[2]);
        if (nearest - h->offset[k] >= -epsilon)
            return true;
    }
    return false;
}

static bool triangle_cuts(const hull *h, const tree_triangle *t, double epsilon)
{
    if (t->source == h->exclude[0] || t->source == h->exclude[1])
        return false;
    for (unsigned k = 0; k < h->plane_count; k++) {
        rad_vec3 n = h->normal[k];
        double o = h->offset[k];
        if (v3_dot(n, t->corner[0]) - o >= -epsilon && v3_dot(n, t->corner[1]) - o >= -epsilon &&
            v3_dot(n, t->corner[2]) - o >= -epsilon)
            return false;
    }
    double offset = v3_dot(t->normal, t->corner[0]);
    bool below = true, above = true;
    for (unsigned m = 0; m < h->corner_count; m++) {
        double d = v3_dot(t->normal, h->corner[m]) - offset;
        below = below && d <= epsilon;
        above = above && d >= -epsilon;
    }
    return !(below || above);
}

const convex_solids *occluder_tree_solids(const occluder_tree *tree)
{
    return tree && tree->solids.of_triangle ? &tree->solids : NULL;
}

void occluder_tree_use_solids(occluder_tree *tree, bool use) { tree->use_solids = use; }

/* The triangles that may cut hull h (built for p and q), as occluder_tree_collect. */
static uint32_t collect_in(const occluder_tree *tree, const hull *h, const vf_polygon *p,
                           const vf_polygon *q, double epsilon, shadow_occluder *out,
                           uint32_t max)
{
    uint32_t found = 0;
    /* a convex solid's faces turned away from p (or, if p cannot see it so, from q) cast
     * no shadow its other faces do not: the last solid met and the polygon it is seen
     * from (NULL: all its faces) */
    uint32_t last_solid = UINT32_MAX;
    const vf_polygon *seen_from = NULL;
    uint32_t stack[2 * MAX_DEPTH + 2];
    unsigned top = 0;
    stack[top++] = 0;
    while (top) {
        const tree_node *node = &tree->nodes[stack[--top]];
        if (box_outside(h, node, epsilon))
            continue;
        if (node->count) {
            for (uint32_t t = node->first; t < node->first + node->count; t++) {
                const tree_triangle *tt = &tree->triangles[t];
                if (!triangle_cuts(h, tt, epsilon))
                    continue;
                if (tt->solid != UINT32_MAX && tree->use_solids) {
                    if (tt->solid != last_solid) {
                        const convex_solid *solid = &tree->solids.solids[tt->solid];
                        last_solid = tt->solid;
                        seen_from = convex_solid_seen_from(solid, p, epsilon)   ? p
                                    : convex_solid_seen_from(solid, q, epsilon) ? q
                                                                                : NULL;
                    }
                    if (seen_from &&
                        convex_solid_face_away(tt->normal, tt->corner[0], seen_from, epsilon))
                        continue;
                }
                if (found == max)
                    return max + 1;
                memcpy(out[found++].corner, tt->corner, sizeof(out->corner));
            }
        } else {
            stack[top++] = node->first;
            stack[top++] = node->first + 1;
        }
    }
    return found;
}

uint32_t occluder_tree_collect(const occluder_tree *tree, const vf_polygon *p,
                               const vf_polygon *q, double epsilon, shadow_occluder *out,
                               uint32_t max)
{
    if (tree->node_count == 0)
        return 0;
    hull h;
    make_hull(&h, p, q, epsilon);
    h.exclude[0] = p->source;
    h.exclude[1] = q->source;
    return collect_in(tree, &h, p, q, epsilon, out, max);
}

uint32_t occluder_tree_collect_from_point(const occluder_tree *tree, rad_vec3 x, rad_vec3 n,
                                          const vf_polygon *q, double epsilon,
                                          shadow_occluder *out, uint32_t max)
{
    if (tree->node_count == 0)
        return 0;
    /* the pyramid of x and q: q's plane, x's, and one plane through x and each edge of q
     * (q convex, x in front of it), with outward normals */
    hull h;
    h.corner_count = 0;
    h.corner[h.corner_count++] = x;
    for (unsigned k = 0; k < q->count; k++)
        h.corner[h.corner_count++] = q->vertex[k];
    for (int a = 0; a < 3; a++) {
        h.lo[a] = INFINITY;
        h.hi[a] = -INFINITY;
        for (unsigned k = 0; k < h.corner_count; k++) {
            h.lo[a] = fmin(h.lo[a], axis(h.corner[k], a));
            h.hi[a] = fmax(h.hi[a], axis(h.corner[k], a));
        }
    }
    h.plane_count = 0;
    h.normal[h.plane_count] = v3_scale(n, -1);
    h.offset[h.plane_count++] = -v3_dot(n, x);
    h.normal[h.plane_count] = v3_scale(q->normal, -1);
    h.offset[h.plane_count++] = -v3_dot(q->normal, q->vertex[0]);
    for (unsigned k = 0; k < q->count; k++) {
        rad_vec3 a = q->vertex[k], b = q->vertex[(k + 1) % q->count];
        rad_vec3 side = v3_cross(v3_sub(b, a), v3_sub(x, a));
        double length = v3_length(side);
        if (!(length > 0))
            continue; /* x on the edge's line: the other planes bound the pyramid */
        side = v3_scale(side, 1 / length);
        double offset = v3_dot(side, a);
        if (v3_dot(side, q->centroid) - offset > 0) { /* turned inward: turn it round */
            side = v3_scale(side, -1);
            offset = -offset;
        }
        h.normal[h.plane_count] = side;
        h.offset[h.plane_count++] = offset;
    }
    h.exclude[0] = h.exclude[1] = q->source;
    vf_polygon point = {.count = 1, .normal = n, .centroid = x, .source = q->source};
    point.vertex[0] = x;
    return collect_in(tree, &h, &point, q, epsilon, out, max);
}
