/*
 * tree.c - the element and cluster tree over a mesh's patches.
 *
 * Patches are first grouped into planes: runs of consecutive patches (the mesh emits an
 * input polygon's cells together) of one surface and one material whose normals differ by
 * less than RAD_REGION_NORMAL and whose centroids lie on the first one's plane. Each plane
 * gets a binary tree over its patches (median split of the centroids along the longest
 * axis: on a quad's nu x nv cells this is a quadtree taken one axis at a time); the planes
 * get a bounding-volume tree the same way (the clusters). Nodes are numbered in preorder.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/minmax.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "geometry/polygon_pair.h"
#include "solve/hierarchical/hierarchy.h"

typedef struct keyed {
    double key;
    uint32_t id;
} keyed;

typedef struct builder {
    const rad_mesh *mesh;
    hier_tree *tree;
    uint32_t *group_first, *group_count; /* plane runs of the mesh order */
    rad_vec3 *group_centroid;
    keyed *scratch;
    uint32_t leaves;
} builder;

static int compare_keyed(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->id < y->id ? -1 : x->id > y->id;
}

static double axis_of(rad_vec3 p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }

/* Sorts ids by their point's coordinate along the longest axis of the points' bounds. */
static void median_order(builder *b, uint32_t *ids, uint32_t n, const rad_vec3 *points)
{
    rad_vec3 lo = points[ids[0]], hi = lo;
    for (uint32_t k = 1; k < n; k++) {
        rad_vec3 p = points[ids[k]];
        lo = v3(min_d(lo.x, p.x), min_d(lo.y, p.y), min_d(lo.z, p.z));
        hi = v3(max_d(hi.x, p.x), max_d(hi.y, p.y), max_d(hi.z, p.z));
    }
    rad_vec3 e = v3_sub(hi, lo);
    int axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
    for (uint32_t k = 0; k < n; k++)
        b->scratch[k] = (keyed){axis_of(points[ids[k]], axis), ids[k]};
    qsort(b->scratch, n, sizeof(keyed), compare_keyed);
    for (uint32_t k = 0; k < n; k++)
        ids[k] = b->scratch[k].id;
}

static void bound_radius(hnode *node)
{
    double r2 = 0;
    for (int k = 0; k < 8; k++) {
        rad_vec3 c = v3(k & 1 ? node->hi.x : node->lo.x, k & 2 ? node->hi.y : node->lo.y,
                        k & 4 ? node->hi.z : node->lo.z);
        rad_vec3 d = v3_sub(c, node->centroid);
        r2 = max_d(r2, v3_dot(d, d));
    }
    node->radius = sqrt(r2);
}

/* m += weight x d d^T (xx, yy, zz, xy, xz, yz). */
static void moment_add(double m[6], rad_vec3 d, double weight)
{
    m[0] += weight * d.x * d.x;
    m[1] += weight * d.y * d.y;
    m[2] += weight * d.z * d.z;
    m[3] += weight * d.x * d.y;
    m[4] += weight * d.x * d.z;
    m[5] += weight * d.y * d.z;
}

/* The second moment of a patch's area about its centroid (polygon_second_moment). */
static void patch_moment(const rad_mesh *mesh, const rad_patch *p, float out[6])
{
    rad_vec3 corner[4];
    for (uint32_t k = 0; k < p->vertex_count && k < 4; k++)
        corner[k] = mesh->vertices[p->vertex[k]];
    double m[6];
    polygon_second_moment(corner, p->vertex_count < 4 ? p->vertex_count : 4, p->centroid, m);
    for (int k = 0; k < 6; k++)
        out[k] = (float)m[k];
}

static void combine(hier_tree *tree, uint32_t index, bool planar)
{
    hnode *n = &tree->nodes[index];
    const hnode *a = &tree->nodes[n->child[0]], *c = &tree->nodes[n->child[1]];
    n->area = a->area + c->area;
    n->centroid = n->area > 0 ? v3_scale(v3_add(v3_scale(a->centroid, a->area),
                                                v3_scale(c->centroid, c->area)),
                                         1.0 / n->area)
                              : v3_scale(v3_add(a->centroid, c->centroid), 0.5);
    double m[6];
    for (int k = 0; k < 6; k++)
        m[k] = (double)a->moment[k] + c->moment[k];
    moment_add(m, v3_sub(a->centroid, n->centroid), a->area);
    moment_add(m, v3_sub(c->centroid, n->centroid), c->area);
    for (int k = 0; k < 6; k++)
        n->moment[k] = (float)m[k];
    n->normal = v3_add(v3_scale(a->normal, a->area), v3_scale(c->normal, c->area));
    double length = v3_length(n->normal);
    n->normal = length > 0 ? v3_scale(n->normal, 1.0 / length) : a->normal;
    n->lo = v3(min_d(a->lo.x, c->lo.x), min_d(a->lo.y, c->lo.y), min_d(a->lo.z, c->lo.z));
    n->hi = v3(max_d(a->hi.x, c->hi.x), max_d(a->hi.y, c->hi.y), max_d(a->hi.z, c->hi.z));
    n->first = a->first;
    n->count = a->count + c->count;
    n->planar = planar;
    bound_radius(n);
}

static uint32_t new_node(hier_tree *tree, uint32_t parent)
{
    uint32_t index = tree->node_count++;
    hnode *n = &tree->nodes[index];
    memset(n, 0, sizeof(*n));
    n->parent = parent;
    n->child[0] = n->child[1] = HNODE_NONE;
    n->patch = HNODE_NONE;
    return index;
}

static uint32_t build_plane(builder *b, uint32_t *patches, uint32_t n, uint32_t parent,
                            const rad_vec3 *centroids)
{
    hier_tree *tree = b->tree;
    uint32_t index = new_node(tree, parent);
    if (n == 1) {
        const rad_patch *p = &b->mesh->patches[patches[0]];
        hnode *leaf = &tree->nodes[index];
        leaf->patch = patches[0];
        leaf->first = b->leaves;
        leaf->count = 1;
        tree->order[b->leaves++] = patches[0];
        leaf->area = p->area;
        leaf->centroid = p->centroid;
        leaf->normal = p->normal;
        patch_moment(b->mesh, p, leaf->moment);
        leaf->lo = leaf->hi = b->mesh->vertices[p->vertex[0]];
        for (uint32_t k = 1; k < p->vertex_count; k++) {
            rad_vec3 v = b->mesh->vertices[p->vertex[k]];
            leaf->lo = v3(min_d(leaf->lo.x, v.x), min_d(leaf->lo.y, v.y), min_d(leaf->lo.z, v.z));
            leaf->hi = v3(max_d(leaf->hi.x, v.x), max_d(leaf->hi.y, v.y), max_d(leaf->hi.z, v.z));
        }
        leaf->planar = true;
        bound_radius(leaf);
        tree->planar_count++;
        return index;
    }
    median_order(b, patches, n, centroids);
    uint32_t half = n / 2;
    tree->nodes[index].child[0] = build_plane(b, patches, half, index, centroids);
    tree->nodes[index].child[1] = build_plane(b, patches + half, n - half, index, centroids);
    combine(tree, index, true);
    tree->planar_count++;
    return index;
}

static uint32_t build_clusters(builder *b, uint32_t *groups, uint32_t n, uint32_t parent,
                               uint32_t *patch_ids, const rad_vec3 *centroids)
{
    if (n == 1) {
        uint32_t g = groups[0];
        return build_plane(b, patch_ids + b->group_first[g], b->group_count[g], parent,
                           centroids);
    }
    hier_tree *tree = b->tree;
    uint32_t index = new_node(tree, parent);
    median_order(b, groups, n, b->group_centroid);
    uint32_t half = n / 2;
    tree->nodes[index].child[0] = build_clusters(b, groups, half, index, patch_ids, centroids);
    tree->nodes[index].child[1] =
        build_clusters(b, groups + half, n - half, index, patch_ids, centroids);
    combine(tree, index, false);
    tree->cluster_count++;
    return index;
}

static void put3(float out[3], rad_vec3 v)
{
    out[0] = (float)v.x;
    out[1] = (float)v.y;
    out[2] = (float)v.z;
}

static void describe_leaf(const rad_mesh *mesh, uint32_t patch, leaf_shape *shape)
{
    const rad_patch *p = &mesh->patches[patch];
    rad_vec3 a = mesh->vertices[p->vertex[0]];
    rad_vec3 ab = v3_sub(mesh->vertices[p->vertex[1]], a);
    rad_vec3 ac = v3_sub(mesh->vertices[p->vertex[2]], a);
    rad_vec3 ad = v3(0, 0, 0);
    shape->first_share = 1;
    if (p->vertex_count == 4) {
        ad = v3_sub(mesh->vertices[p->vertex[3]], a);
        double a0 = v3_length(v3_cross(ab, ac)), a1 = v3_length(v3_cross(ac, ad));
        shape->first_share = a0 + a1 > 0 ? (float)(a0 / (a0 + a1)) : 0.5f;
    }
    put3(shape->a, v3_add(a, v3_scale(p->normal, 2 * p->behind)));
    put3(shape->ab, ab);
    put3(shape->ac, ac);
    put3(shape->ad, ad);
    put3(shape->normal, p->normal);
}

/* Does patch k continue the plane that patch g starts? */
static bool same_plane(const rad_mesh *mesh, uint32_t g, uint32_t k, double epsilon)
{
    const rad_patch *a = &mesh->patches[g], *p = &mesh->patches[k];
    if (a->surface != p->surface || a->material != p->material)
        return false;
    if (1 - v3_dot(a->normal, p->normal) > 0.5 * RAD_REGION_NORMAL * RAD_REGION_NORMAL)
        return false;
    double offset = fabs(v3_dot(a->normal, v3_sub(p->centroid, a->centroid)));
    return offset <= epsilon + 2 * (a->bulge + p->bulge);
}

int hier_tree_build(const rad_mesh *mesh, hier_tree *tree)
{
    memset(tree, 0, sizeof(*tree));
    uint32_t n = mesh->patch_count;
    if (n == 0)
        return 1;
    builder b = {.mesh = mesh, .tree = tree};
    tree->nodes = rad_alloc_array(2 * (size_t)n - 1, sizeof(hnode));
    tree->order = rad_alloc_array(n, sizeof(uint32_t));
    tree->cumulative = rad_alloc_array(n, sizeof(double));
    tree->shapes = rad_alloc_array(n, sizeof(leaf_shape));
    uint32_t *patch_ids = rad_alloc_array(n, sizeof(uint32_t));
    rad_vec3 *centroids = rad_alloc_array(n, sizeof(rad_vec3));
    b.group_first = rad_alloc_array(n, sizeof(uint32_t));
    b.group_count = rad_alloc_array(n, sizeof(uint32_t));
    b.group_centroid = rad_alloc_array(n, sizeof(rad_vec3));
    uint32_t *groups = rad_alloc_array(n, sizeof(uint32_t));
    b.scratch = rad_alloc_array(n, sizeof(keyed));
    int ok = tree->nodes && tree->order && tree->cumulative && tree->shapes && patch_ids && centroids &&
             b.group_first && b.group_count && b.group_centroid && groups && b.scratch;
    if (ok) {
        rad_vec3 lo, hi;
        v3_bounds(mesh->vertices, mesh->vertex_count, &lo, &hi);
        tree->plane_epsilon = RAD_PLANE_EPSILON * v3_length(v3_sub(hi, lo));
        double plane_tolerance = 1e-6 * v3_length(v3_sub(hi, lo));
        uint32_t group_total = 0;
        for (uint32_t k = 0; k < n; k++) {
            patch_ids[k] = k;
            centroids[k] = mesh->patches[k].centroid;
            if (k == 0 || !same_plane(mesh, b.group_first[group_total - 1], k, plane_tolerance)) {
                b.group_first[group_total] = k;
                group_total++;
            }
            b.group_count[group_total - 1]++;
        }
        for (uint32_t g = 0; g < group_total; g++) {
            rad_vec3 sum = v3(0, 0, 0);
            double area = 0;
            for (uint32_t k = 0; k < b.group_count[g]; k++) {
                const rad_patch *p = &mesh->patches[b.group_first[g] + k];
                sum = v3_add(sum, v3_scale(p->centroid, p->area));
                area += p->area;
            }
            b.group_centroid[g] = area > 0 ? v3_scale(sum, 1.0 / area)
                                           : mesh->patches[b.group_first[g]].centroid;
            groups[g] = g;
        }
        build_clusters(&b, groups, group_total, HNODE_NONE, patch_ids, centroids);
        for (uint32_t k = 0; k < n; k++)
            describe_leaf(mesh, tree->order[k], &tree->shapes[k]);
        rad_error unused;
        ok = near_contacts_build(mesh, near_contacts_reach(mesh), tree->plane_epsilon,
                                 &tree->contacts, &unused) == RAD_OK;
    }
    if (ok) {
        double running = 0;
        for (uint32_t k = 0; k < n; k++) {
            running += mesh->patches[tree->order[k]].area;
            tree->cumulative[k] = running;
        }
    }
    free(patch_ids);
    free(centroids);
    free(b.group_first);
    free(b.group_count);
    free(b.group_centroid);
    free(groups);
    free(b.scratch);
    if (!ok)
        hier_tree_free(tree);
    return ok;
}

void hier_tree_free(hier_tree *tree)
{
    free(tree->nodes);
    free(tree->order);
    free(tree->cumulative);
    free(tree->shapes);
    near_contacts_free(&tree->contacts);
    memset(tree, 0, sizeof(*tree));
}
