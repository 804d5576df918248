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
} tree_triangle;

struct occluder_tree {
    tree_node *nodes;
    uint32_t node_count;
    tree_triangle *triangles;
    uint32_t triangle_count;
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
                               occluder_tree **out, rad_error *error)
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
    for (uint32_t t = 0; t < count; t++) {
        tree_triangle *tt = &tree->triangles[t];
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
    free(tree);
}

unsigned occluder_hull_sides(const vf_polygon *p, const vf_polygon *q, double epsilon,
                             rad_vec3 *normal_out, double *offset_out)
{
    unsigned count = 0;
    const vf_polygon *polygon[2] = {p, q};
    for (int side = 0; side < 2; side++) {
        const vf_polygon *a = polygon[side], *b = polygon[1 - side];
        for (unsigned e = 0; e < a->count; e++) {
            rad_vec3 e0 = a->vertex[e], e1 = a->vertex[(e + 1) % a->count];
            for (unsigned c = 0; c < b->count; c++) {
                rad_vec3 normal = v3_cross(v3_sub(e1, e0), v3_sub(b->vertex[c], e0));
                double length = v3_length(normal);
                if (!(length > 0))
                    continue;
                normal = v3_scale(normal, 1 / length);
                double offset = v3_dot(normal, e0);
                bool below = true, above = true;
                for (int k = 0; k < 2 && (below || above); k++)
                    for (unsigned m = 0; m < polygon[k]->count && (below || above); m++) {
                        double d = v3_dot(normal, polygon[k]->vertex[m]) - offset;
                        below = below && d <= epsilon;
                        above = above && d >= -epsilon;
                    }
                if (below == above)
                    continue; /* straddles, or (degenerate) all on it */
                if (above) {
                    normal = v3_scale(normal, -1);
                    offset = -offset;
                }
                normal_out[count] = normal;
                offset_out[count++] = offset;
            }
        }
    }
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

uint32_t occluder_tree_collect(const occluder_tree *tree, const vf_polygon *p,
                               const vf_polygon *q, double epsilon, shadow_occluder *out,
                               uint32_t max)
{
    if (tree->node_count == 0)
        return 0;
    uint32_t found = 0;
    hull h;
    make_hull(&h, p, q, epsilon);
    h.exclude[0] = p->source;
    h.exclude[1] = q->source;
    uint32_t stack[2 * MAX_DEPTH + 2];
    unsigned top = 0;
    stack[top++] = 0;
    while (top) {
        const tree_node *node = &tree->nodes[stack[--top]];
        if (box_outside(&h, node, epsilon))
            continue;
        if (node->count) {
            for (uint32_t t = node->first; t < node->first + node->count; t++) {
                if (!triangle_cuts(&h, &tree->triangles[t], epsilon))
                    continue;
                if (found == max)
                    return max + 1;
                memcpy(out[found++].corner, tree->triangles[t].corner, sizeof(out->corner));
            }
        } else {
            stack[top++] = node->first;
            stack[top++] = node->first + 1;
        }
    }
    return found;
}
