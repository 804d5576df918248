/*
 * exact_pairs.c - pairs settled without sampling, see exact_pairs.h.
 *
 * An occluder that passes through the smaller patch (interpenetrating surfaces: a box
 * sunk into a floor, two boxes through each other) makes the visible factor jump along
 * the line where it cuts the patch, and adaptive quadrature would chase that line to its
 * depth limit. So the smaller patch is first cut by the plane of every such occluder, and
 * each piece, on one side of it, is integrated on its own.
 */
#include "patch_formfactors/exact_pairs.h"

#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/hemisphere.h"
#include "core/minmax.h"
#include "core/vec3.h"
#include "patch_formfactors/hiding_faces.h"
#include "surface_viewfactors/pair_transfer.h"
#include "trace/tracer_internal.h"

/* Patch pairs with at most this many triangles in between get exact shadow clipping. */
#define EXACT_PAIRS_MAX_OCCLUDERS 4u

/* Most pieces the smaller patch is cut into (at most EXACT_PAIRS_MAX_OCCLUDERS planes). */
#define MAX_PIECES 16u

/* A pair of groups keeps the list of the triangles that may cut its rectangles' hull when
 * it has at most GROUP_LIST_MAX of them (then its patch pairs screen those alone, not the
 * tree), and groups keep lists while there are at most GROUP_LISTS_MAX of them (a list
 * entry per pair of groups: 5 bytes each, 21 MB at the most, and the lists themselves). */
#define GROUP_LIST_MAX 64u
#define GROUP_LISTS_MAX 2048u
#define GROUP_NOT_LISTED UINT8_MAX

/* The screening tree: leaves of at most SCREEN_LEAF triangles, at most SCREEN_DEPTH deep. */
#define SCREEN_LEAF 4u
#define SCREEN_DEPTH 48u

struct screen_node {
    double lo[3], hi[3];
    uint32_t first, count; /* a leaf when count > 0; else children at first, first + 1 */
};

struct screen_triangle {
    rad_vec3 corner[3];
    rad_vec3 normal; /* unit, or zero for a degenerate triangle */
    double offset;
    /* in its plane, the inward unit normals of its edges and their offsets: a point of
     * the plane lies inside when edge_normal[k] . x - edge_offset[k] > 0 for every k */
    rad_vec3 edge_normal[3];
    double edge_offset[3];
    double lo[3], hi[3];
};

static double coordinate(rad_vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

static void screen_build(exact_pairs *pairs, uint32_t node, uint32_t first, uint32_t count,
                         unsigned depth)
{
    screen_node *n = &pairs->screen_nodes[node];
    double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int a = 0; a < 3; a++) {
        n->lo[a] = INFINITY;
        n->hi[a] = -INFINITY;
    }
    for (uint32_t t = first; t < first + count; t++) {
        const screen_triangle *tt = &pairs->screen_triangles[t];
        for (int a = 0; a < 3; a++) {
            n->lo[a] = fmin(n->lo[a], tt->lo[a]);
            n->hi[a] = fmax(n->hi[a], tt->hi[a]);
            double centre = 0.5 * (tt->lo[a] + tt->hi[a]);
            clo[a] = fmin(clo[a], centre);
            chi[a] = fmax(chi[a], centre);
        }
    }
    if (count <= SCREEN_LEAF || depth >= SCREEN_DEPTH) {
        n->first = first;
        n->count = count;
        return;
    }
    int split = 0;
    for (int a = 1; a < 3; a++)
        if (chi[a] - clo[a] > chi[split] - clo[split])
            split = a;
    double middle = 0.5 * (clo[split] + chi[split]);
    uint32_t i = first, j = first + count;
    while (i < j) {
        const screen_triangle *tt = &pairs->screen_triangles[i];
        if (0.5 * (tt->lo[split] + tt->hi[split]) < middle) {
            i++;
        } else {
            j--;
            screen_triangle swap = pairs->screen_triangles[i];
            pairs->screen_triangles[i] = pairs->screen_triangles[j];
            pairs->screen_triangles[j] = swap;
        }
    }
    uint32_t left = i - first;
    if (left == 0 || left == count)
        left = count / 2;
    uint32_t children = pairs->screen_node_count;
    pairs->screen_node_count += 2;
    n->first = children;
    n->count = 0;
    screen_build(pairs, children, first, left, depth + 1);
    screen_build(pairs, children + 1, first + left, count - left, depth + 1);
}

/* What screening needs of a pair: the box of its corners and the two patches' planes
 * (segments that carry light run in front of both); the hull's side planes are found only
 * for a pair with a triangle that passes those (batch_may_cut). */
typedef struct screen_query {
    const exact_pairs *pairs;
    const vf_polygon *p, *q;
    double lo[3], hi[3];
    double epsilon;
} screen_query;

/* True when the box lies wholly behind (or on) the plane n . x = offset. */
static bool box_behind(const double lo[3], const double hi[3], rad_vec3 n, double offset,
                       double epsilon)
{
    double farthest = n.x * (n.x > 0 ? hi[0] : lo[0]) + n.y * (n.y > 0 ? hi[1] : lo[1]) +
                      n.z * (n.z > 0 ? hi[2] : lo[2]);
    return farthest - offset <= epsilon;
}

static bool box_apart(const screen_query *s, const double lo[3], const double hi[3])
{
    for (int a = 0; a < 3; a++)
        if (lo[a] > s->hi[a] + s->epsilon || hi[a] < s->lo[a] - s->epsilon)
            return true;
    return box_behind(lo, hi, s->p->normal, v3_dot(s->p->normal, s->p->vertex[0]), s->epsilon) ||
           box_behind(lo, hi, s->q->normal, v3_dot(s->q->normal, s->q->vertex[0]), s->epsilon);
}

/* Does the segment between the two patches' centroids pass through the triangle, more
 * than epsilon inside it? Then the triangle surely cuts the hull, and its faces are not
 * needed to say so. */
static bool blocks_centroids(const screen_query *s, const screen_triangle *t)
{
    double dp = v3_dot(t->normal, s->p->centroid) - t->offset;
    double dq = v3_dot(t->normal, s->q->centroid) - t->offset;
    if (!((dp > s->epsilon && dq < -s->epsilon) || (dp < -s->epsilon && dq > s->epsilon)))
        return false;
    rad_vec3 crossing = v3_lerp(s->p->centroid, s->q->centroid, dp / (dp - dq));
    for (int k = 0; k < 3; k++)
        if (v3_dot(t->edge_normal[k], crossing) - t->edge_offset[k] <= s->epsilon)
            return false;
    return true;
}

/* May the triangle stand between the pair at all? Its box must meet the hull's box in
 * front of both planes, and its plane must have corners of the pair strictly on both
 * sides. */
static bool may_stand_between(const screen_query *s, const screen_triangle *t)
{
    if (box_apart(s, t->lo, t->hi))
        return false;
    bool below = false, above = false;
    const vf_polygon *polygon[2] = {s->p, s->q};
    for (int k = 0; k < 2; k++)
        for (unsigned c = 0; c < polygon[k]->count; c++) {
            double d = v3_dot(t->normal, polygon[k]->vertex[c]) - t->offset;
            below = below || d < -s->epsilon;
            above = above || d > s->epsilon;
        }
    return below && above;
}

/* May one of these triangles (each standing between the pair) cut its hull? Not one that
 * a side plane of the hull has wholly outside. The planes come one edge at a time
 * (occluder_hull_edge_sides), dropping the triangles each has outside: a clear pair
 * usually stops long before the last edge. */
static bool batch_may_cut(const screen_query *s, const screen_triangle *const *candidate,
                          unsigned count)
{
    uint32_t alive = count == 32 ? UINT32_MAX : (UINT32_C(1) << count) - 1;
    for (unsigned edge = 0; alive && edge < s->p->count + s->q->count; edge++) {
        rad_vec3 normal[2];
        double offset[2];
        unsigned faces = occluder_hull_edge_sides(s->p, s->q, edge, s->epsilon, normal, offset);
        for (unsigned f = 0; f < faces; f++)
            for (unsigned k = 0; k < count; k++) {
                const rad_vec3 *c = candidate[k]->corner;
                if ((alive >> k & 1u) && v3_dot(normal[f], c[0]) - offset[f] >= -s->epsilon &&
                    v3_dot(normal[f], c[1]) - offset[f] >= -s->epsilon &&
                    v3_dot(normal[f], c[2]) - offset[f] >= -s->epsilon)
                    alive &= ~(UINT32_C(1) << k);
            }
    }
    return alive != 0;
}

/* Triangles gathered for one batch_may_cut. */
#define SCREEN_CANDIDATES 32u /* bits of a uint32_t */

static screen_query screen_query_of(const exact_pairs *pairs, const vf_polygon *p,
                                    const vf_polygon *q)
{
    screen_query s;
    s.pairs = pairs;
    s.p = p;
    s.q = q;
    s.epsilon = pairs->epsilon;
    for (int a = 0; a < 3; a++) {
        s.lo[a] = INFINITY;
        s.hi[a] = -INFINITY;
    }
    for (int k = 0; k < 2; k++) {
        const vf_polygon *polygon = k ? q : p;
        for (unsigned c = 0; c < polygon->count; c++)
            for (int a = 0; a < 3; a++) {
                s.lo[a] = min_d(s.lo[a], coordinate(polygon->vertex[c], a));
                s.hi[a] = max_d(s.hi[a], coordinate(polygon->vertex[c], a));
            }
    }
    return s;
}

/* The triangles gathered for one batch_may_cut. */
typedef struct screen_batch {
    const screen_triangle *candidate[SCREEN_CANDIDATES];
    unsigned count;
    uint32_t crossing; /* the triangle across the centroids' segment, or UINT32_MAX */
} screen_batch;

/* Triangle tt met in a screening: true when it settles that something may block. */
static bool screen_triangle_blocks(const screen_query *s, const screen_triangle *tt,
                                   screen_batch *batch)
{
    if (!may_stand_between(s, tt))
        return false;
    if (blocks_centroids(s, tt)) {
        batch->crossing = (uint32_t)(tt - s->pairs->screen_triangles);
        return true;
    }
    batch->candidate[batch->count++] = tt;
    if (batch->count == SCREEN_CANDIDATES) {
        batch->count = 0;
        return batch_may_cut(s, batch->candidate, SCREEN_CANDIDATES);
    }
    return false;
}

/* Walks the screening tree under the query's box: visit(context, t) for each triangle t
 * of a leaf whose box meets it, until a visit returns true (then true). Inline, so each
 * caller gets its visit inlined too. */
static inline bool screen_walk(const screen_query *s, bool (*visit)(void *context, uint32_t t),
                               void *context)
{
    const exact_pairs *pairs = s->pairs;
    uint32_t stack[2 * SCREEN_DEPTH + 2];
    unsigned top = 0;
    stack[top++] = 0;
    while (top) {
        const screen_node *node = &pairs->screen_nodes[stack[--top]];
        if (box_apart(s, node->lo, node->hi))
            continue;
        if (node->count) {
            for (uint32_t t = node->first; t < node->first + node->count; t++)
                if (visit(context, t))
                    return true;
        } else {
            stack[top++] = node->first;
            stack[top++] = node->first + 1;
        }
    }
    return false;
}

/* screen_may_block's visit: the triangle settles that something may block. */
typedef struct blocking_visit {
    const screen_query *s;
    screen_batch *batch;
} blocking_visit;

static bool visit_blocking(void *context, uint32_t t)
{
    blocking_visit *v = context;
    return screen_triangle_blocks(v->s, &v->s->pairs->screen_triangles[t], v->batch);
}

/* screen_collect's visit: the triangles standing between the pair, true past
 * GROUP_LIST_MAX of them. */
typedef struct standing_visit {
    const screen_query *s;
    uint32_t *standing;
    unsigned count;
} standing_visit;

static bool visit_standing(void *context, uint32_t t)
{
    standing_visit *v = context;
    if (!may_stand_between(v->s, &v->s->pairs->screen_triangles[t]))
        return false;
    if (v->count == GROUP_LIST_MAX)
        return true;
    v->standing[v->count++] = t;
    return false;
}

/* False when no triangle can cut the hull of p and q (then the pair is clear). The
 * triangles that stand between the pair are gathered first: one across the centroids'
 * segment settles it without the hull's side planes, which cost more than all the rest. */
static bool screen_may_block(const exact_pairs *pairs, const vf_polygon *p, const vf_polygon *q,
                             uint32_t *crossing)
{
    if (pairs->screen_node_count == 0)
        return false;
    screen_query s = screen_query_of(pairs, p, q);
    screen_batch batch;
    batch.count = 0;
    batch.crossing = UINT32_MAX;
    blocking_visit visit = {&s, &batch};
    if (screen_walk(&s, visit_blocking, &visit)) {
        *crossing = batch.crossing;
        return true;
    }
    return batch.count > 0 && batch_may_cut(&s, batch.candidate, batch.count);
}

/* The same answer from a list of the triangles that may cut a larger hull around p and
 * q's (their groups' rectangles'): a triangle outside that hull is outside theirs too. */
static bool screen_listed_may_block(const exact_pairs *pairs, const vf_polygon *p,
                                    const vf_polygon *q, const uint32_t *listed,
                                    unsigned count, uint32_t *crossing)
{
    screen_query s = screen_query_of(pairs, p, q);
    screen_batch batch;
    batch.count = 0;
    batch.crossing = UINT32_MAX;
    for (unsigned k = 0; k < count; k++)
        if (screen_triangle_blocks(&s, &pairs->screen_triangles[listed[k]], &batch)) {
            *crossing = batch.crossing;
            return true;
        }
    return batch.count > 0 && batch_may_cut(&s, batch.candidate, batch.count);
}

/* The triangles that may cut the hull of p and q: those standing between them that no
 * side plane of the hull has wholly outside, into out[] (indices of screen_triangles);
 * returns how many, or cap + 1 when there are more than cap. */
static unsigned screen_collect(const exact_pairs *pairs, const vf_polygon *p,
                               const vf_polygon *q, uint32_t *out, unsigned cap)
{
    if (pairs->screen_node_count == 0)
        return 0;
    screen_query s = screen_query_of(pairs, p, q);
    uint32_t standing[GROUP_LIST_MAX];
    standing_visit visit = {&s, standing, 0};
    if (screen_walk(&s, visit_standing, &visit))
        return cap + 1;
    const unsigned count = visit.count;
    /* the hull's side planes, an edge at a time, drop the triangles they have outside */
    bool outside[GROUP_LIST_MAX] = {false};
    for (unsigned edge = 0; edge < p->count + q->count; edge++) {
        rad_vec3 normal[2];
        double offset[2];
        unsigned faces = occluder_hull_edge_sides(p, q, edge, s.epsilon, normal, offset);
        for (unsigned f = 0; f < faces; f++)
            for (unsigned k = 0; k < count; k++) {
                const rad_vec3 *c = pairs->screen_triangles[standing[k]].corner;
                outside[k] = outside[k] || (v3_dot(normal[f], c[0]) - offset[f] >= -s.epsilon &&
                                            v3_dot(normal[f], c[1]) - offset[f] >= -s.epsilon &&
                                            v3_dot(normal[f], c[2]) - offset[f] >= -s.epsilon);
            }
    }
    unsigned kept = 0;
    for (unsigned k = 0; k < count; k++) {
        if (outside[k])
            continue;
        if (kept == cap)
            return cap + 1;
        out[kept++] = standing[k];
    }
    return kept;
}

rad_status exact_pairs_build(const rad_mesh *mesh, const rad_tracer *occluders,
                             double plane_epsilon, exact_pairs *out, rad_error *error)
{
    *out = (exact_pairs){.plane_epsilon = plane_epsilon};
    uint32_t vertex_count = occluders->vertex_count, triangle_count = occluders->triangle_count;
    rad_vec3 *positions = rad_alloc_array(vertex_count ? vertex_count : 1, sizeof(*positions));
    rad_triangle *triangles =
        rad_alloc_array(triangle_count ? triangle_count : 1, sizeof(*triangles));
    uint32_t *source = rad_alloc_array(triangle_count ? triangle_count : 1, sizeof(*source));
    out->polygons = rad_alloc_array(mesh->patch_count ? mesh->patch_count : 1,
                                    sizeof(*out->polygons));
    rad_status status = RAD_OK;
    if (!positions || !triangles || !source || !out->polygons) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the occluder tree");
        goto done;
    }
    /* the triangles exactly as the tracer tests them (float corners) */
    double largest = 0;
    for (uint32_t v = 0; v < vertex_count; v++) {
        const float *x = &occluders->vertices[3 * (size_t)v];
        positions[v] = v3(x[0], x[1], x[2]);
        largest = fmax(largest, fmax(fabs(x[0]), fmax(fabs(x[1]), fabs(x[2]))));
    }
    for (uint32_t t = 0; t < triangle_count; t++) {
        for (int c = 0; c < 3; c++)
            triangles[t].vertex[c] = occluders->indices[3 * (size_t)t + c];
        source[t] = UINT32_MAX; /* a patch's own triangles lie in its plane: never cut */
    }
    /* rounded to float, a patch's own triangles lie up to this far off its plane */
    out->epsilon = plane_epsilon + 4.0 * FLT_EPSILON * largest;
    rad_scene scene = {0};
    scene.positions = positions;
    scene.position_count = vertex_count;
    scene.triangles = triangles;
    scene.triangle_count = triangle_count;
    status = occluder_tree_build(&scene, source, true, &out->tree, error);
    if (status != RAD_OK)
        goto done;
    out->screen_triangles =
        rad_alloc_array(triangle_count ? triangle_count : 1, sizeof(*out->screen_triangles));
    out->screen_nodes =
        rad_alloc_array(2 * (size_t)(triangle_count ? triangle_count : 1), sizeof(*out->screen_nodes));
    if (!out->screen_triangles || !out->screen_nodes) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the occluder tree");
        goto done;
    }
    for (uint32_t t = 0; t < triangle_count; t++) {
        screen_triangle *tt = &out->screen_triangles[t];
        for (int c = 0; c < 3; c++)
            tt->corner[c] = positions[triangles[t].vertex[c]];
        rad_vec3 n = v3_cross(v3_sub(tt->corner[1], tt->corner[0]),
                              v3_sub(tt->corner[2], tt->corner[0]));
        double length = v3_length(n);
        tt->normal = length > 0 ? v3_scale(n, 1 / length) : v3(0, 0, 0);
        tt->offset = v3_dot(tt->normal, tt->corner[0]);
        for (int k = 0; k < 3; k++) {
            rad_vec3 a = tt->corner[k], b = tt->corner[(k + 1) % 3];
            rad_vec3 inward = v3_cross(tt->normal, v3_sub(b, a));
            double inward_length = v3_length(inward);
            /* a degenerate triangle has no inside: no point passes its edge tests */
            tt->edge_normal[k] = inward_length > 0 ? v3_scale(inward, 1 / inward_length)
                                                   : v3(0, 0, 0);
            tt->edge_offset[k] = inward_length > 0 ? v3_dot(tt->edge_normal[k], a) : INFINITY;
        }
        for (int a = 0; a < 3; a++) {
            tt->lo[a] = fmin(coordinate(tt->corner[0], a),
                             fmin(coordinate(tt->corner[1], a), coordinate(tt->corner[2], a)));
            tt->hi[a] = fmax(coordinate(tt->corner[0], a),
                             fmax(coordinate(tt->corner[1], a), coordinate(tt->corner[2], a)));
        }
    }
    out->screen_node_count = triangle_count ? 1 : 0;
    if (triangle_count)
        screen_build(out, 0, 0, triangle_count, 0);
    /* the faces that may hide a pair, in the screening order: a triangle, or the convex
     * quad it makes with a neighbour in its plane (to rounding) */
    {
        rad_vec3(*corners)[3] = rad_alloc_array(triangle_count ? triangle_count : 1,
                                                 sizeof(*corners));
        rad_vec3 *normals = rad_alloc_array(triangle_count ? triangle_count : 1,
                                            sizeof(*normals));
        if (!corners || !normals) {
            free(corners);
            free(normals);
            status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the occluders' faces");
            goto done;
        }
        for (uint32_t t = 0; t < triangle_count; t++) {
            for (int c = 0; c < 3; c++)
                corners[t][c] = out->screen_triangles[t].corner[c];
            normals[t] = out->screen_triangles[t].normal;
        }
        status = hiding_faces_build((const rad_vec3(*)[3])corners, normals, triangle_count,
                                    16 * DBL_EPSILON * largest, &out->hiding_faces, error);
        free(corners);
        free(normals);
        if (status != RAD_OK)
            goto done;
    }
    for (uint32_t i = 0; i < mesh->patch_count; i++) {
        const rad_patch *patch = &mesh->patches[i];
        vf_polygon *polygon = &out->polygons[i];
        polygon->count = patch->bulge > 0 ? 0 : patch->vertex_count;
        polygon->surface = patch->surface;
        polygon->source = i; /* never UINT32_MAX, the triangles' source */
        polygon->normal = patch->normal;
        if (polygon->count == 0)
            continue;
        for (unsigned k = 0; k < patch->vertex_count; k++)
            polygon->vertex[k] = mesh->vertices[patch->vertex[k]];
        vf_polygon_finish(polygon);
        polygon->area = patch->area;
    }
    /* the patches a convex solid holds (the floor under a box standing on it) */
    const convex_solids *solids = occluder_tree_solids(out->tree);
    if (solids && solids->count > 0) {
        out->inside_solid = rad_alloc_array(mesh->patch_count ? mesh->patch_count : 1,
                                            sizeof(*out->inside_solid));
        if (!out->inside_solid) {
            status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the occluder tree");
            goto done;
        }
        /* every solid's triangles' corners, to tell a polygon apart by its own plane */
        out->solid_corner_first = rad_alloc_array((size_t)solids->count + 1,
                                                  sizeof(*out->solid_corner_first));
        out->solid_corner = rad_alloc_array(3 * (size_t)(triangle_count ? triangle_count : 1),
                                            sizeof(*out->solid_corner));
        if (!out->solid_corner_first || !out->solid_corner) {
            status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the occluder tree");
            goto done;
        }
        for (uint32_t t = 0; t < triangle_count; t++)
            if (solids->of_triangle[t] != UINT32_MAX)
                out->solid_corner_first[solids->of_triangle[t] + 1] += 3;
        for (uint32_t k = 0; k < solids->count; k++)
            out->solid_corner_first[k + 1] += out->solid_corner_first[k];
        /* filled from each solid's end down: [k + 1] ends at solid k's start */
        const uint32_t total = out->solid_corner_first[solids->count];
        for (uint32_t t = triangle_count; t-- > 0;) {
            uint32_t k = solids->of_triangle[t];
            if (k == UINT32_MAX)
                continue;
            uint32_t at = out->solid_corner_first[k + 1] - 3;
            out->solid_corner_first[k + 1] = at;
            for (int c = 0; c < 3; c++)
                out->solid_corner[at + c] = positions[triangles[t].vertex[c]];
        }
        for (uint32_t k = 0; k < solids->count; k++)
            out->solid_corner_first[k] = out->solid_corner_first[k + 1];
        out->solid_corner_first[solids->count] = total;
        for (uint32_t i = 0; i < mesh->patch_count; i++) {
            out->inside_solid[i] = EXACT_NO_SOLID;
            for (uint32_t k = 0; out->polygons[i].count && k < solids->count; k++)
                if (convex_solid_holds(&solids->solids[k], &out->polygons[i], out->epsilon)) {
                    out->inside_solid[i] = k;
                    break;
                }
        }
    }
done:
    free(positions);
    free(triangles);
    free(source);
    if (status != RAD_OK)
        exact_pairs_free(out);
    return status;
}

/* A group's cell is about this many mean patches wide. */
#define GROUP_WIDTH 4.0

/* Where a patch goes: its surface, its plane (normal and offset rounded), its cell. */
typedef struct group_key {
    uint32_t surface, patch;
    int64_t normal[3], offset, cell[2];
} group_key;

static int compare_keys(const void *pa, const void *pb)
{
    const group_key *a = pa, *b = pb;
    const int64_t ka[6] = {a->normal[0], a->normal[1], a->normal[2], a->offset, a->cell[0],
                           a->cell[1]};
    const int64_t kb[6] = {b->normal[0], b->normal[1], b->normal[2], b->offset, b->cell[0],
                           b->cell[1]};
    if (a->surface != b->surface)
        return a->surface < b->surface ? -1 : 1;
    for (int k = 0; k < 6; k++)
        if (ka[k] != kb[k])
            return ka[k] < kb[k] ? -1 : 1;
    return a->patch < b->patch ? -1 : a->patch > b->patch;
}

static bool same_group(const group_key *a, const group_key *b)
{
    return a->surface == b->surface && a->normal[0] == b->normal[0] &&
           a->normal[1] == b->normal[1] && a->normal[2] == b->normal[2] &&
           a->offset == b->offset && a->cell[0] == b->cell[0] && a->cell[1] == b->cell[1];
}

/* The normal a key's rounding stands for: every patch of a group measures its cell with
 * the same axes. */
static rad_vec3 key_normal(const group_key *key)
{
    return v3_normalize(v3((double)key->normal[0], (double)key->normal[1],
                           (double)key->normal[2]));
}

/* The rectangle in the first member's plane around the members' corners; members off that
 * plane leave the group. False when fewer than two are left (no group). */
static bool group_rectangle(exact_pairs *pairs, const group_key *member, uint32_t count,
                            uint32_t group, vf_polygon *out)
{
    const vf_polygon *first = &pairs->polygons[member[0].patch];
    rad_vec3 n = first->normal, a, b;
    double offset = v3_dot(n, first->vertex[0]);
    hemisphere_frame(n, &a, &b); /* a x b = n: the corners run counter-clockwise */
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    uint32_t kept = 0;
    for (uint32_t m = 0; m < count; m++) {
        const vf_polygon *p = &pairs->polygons[member[m].patch];
        bool on = v3_dot(p->normal, n) > 1 - 1e-9;
        for (unsigned c = 0; on && c < p->count; c++)
            on = fabs(v3_dot(n, p->vertex[c]) - offset) <= pairs->plane_epsilon;
        pairs->group_of[member[m].patch] = on ? group : EXACT_NO_GROUP;
        if (!on)
            continue;
        kept++;
        for (unsigned c = 0; c < p->count; c++) {
            double u = v3_dot(a, p->vertex[c]), v = v3_dot(b, p->vertex[c]);
            lo[0] = fmin(lo[0], u);
            hi[0] = fmax(hi[0], u);
            lo[1] = fmin(lo[1], v);
            hi[1] = fmax(hi[1], v);
        }
    }
    if (kept < 2 || !(hi[0] > lo[0]) || !(hi[1] > lo[1])) {
        for (uint32_t m = 0; m < count; m++)
            pairs->group_of[member[m].patch] = EXACT_NO_GROUP;
        return false;
    }
    *out = *first;
    out->count = 4;
    const double u[4] = {lo[0], hi[0], hi[0], lo[0]}, v[4] = {lo[1], lo[1], hi[1], hi[1]};
    for (int c = 0; c < 4; c++)
        out->vertex[c] = v3_add(v3_scale(n, offset), v3_add(v3_scale(a, u[c]), v3_scale(b, v[c])));
    vf_polygon_finish(out);
    out->normal = n;
    return true;
}

/* Whether some corner of each rectangle lies in front of the other's plane. */
static bool rectangles_face(const vf_polygon *a, const vf_polygon *b, double epsilon)
{
    bool ab = false, ba = false;
    for (unsigned k = 0; k < 4; k++) {
        ab = ab || v3_dot(a->normal, v3_sub(b->vertex[k], a->vertex[0])) > epsilon;
        ba = ba || v3_dot(b->normal, v3_sub(a->vertex[k], b->vertex[0])) > epsilon;
    }
    return ab && ba;
}

/* The groups' lists of triangles freed (each row's, and the tables), none left. */
static void free_group_lists(exact_pairs *pairs)
{
    for (uint32_t g = 0; pairs->group_list && g < pairs->group_count; g++)
        free(pairs->group_list[g]);
    free(pairs->group_list);
    free(pairs->group_list_first);
    free(pairs->group_list_count);
    pairs->group_list = NULL;
    pairs->group_list_first = NULL;
    pairs->group_list_count = NULL;
}

rad_status exact_pairs_group(exact_pairs *pairs, const rad_mesh *mesh, int threads,
                             rad_error *error)
{
    const uint32_t n = mesh->patch_count;
    double area = 0;
    uint32_t flat = 0;
    for (uint32_t p = 0; p < n; p++)
        if (pairs->polygons[p].count) {
            area += pairs->polygons[p].area;
            flat++;
        }
    if (flat < 2 || !(area > 0) || pairs->screen_node_count == 0)
        return RAD_OK; /* nothing to group, or nothing can block */
    const double width = GROUP_WIDTH * sqrt(area / flat);
    group_key *keys = rad_alloc_array(flat, sizeof(*keys));
    pairs->group_of = rad_alloc_array(n, sizeof(*pairs->group_of));
    vf_polygon *rectangles = NULL;
    if (!keys || !pairs->group_of)
        goto nomem;
    uint32_t k = 0;
    for (uint32_t p = 0; p < n; p++) {
        pairs->group_of[p] = EXACT_NO_GROUP;
        const vf_polygon *polygon = &pairs->polygons[p];
        if (!polygon->count)
            continue;
        group_key *key = &keys[k];
        key->surface = polygon->surface;
        key->patch = p;
        key->normal[0] = llround(polygon->normal.x * 1e6);
        key->normal[1] = llround(polygon->normal.y * 1e6);
        key->normal[2] = llround(polygon->normal.z * 1e6);
        rad_vec3 normal = key_normal(key), a, b;
        hemisphere_frame(normal, &a, &b);
        double offset = v3_dot(normal, polygon->centroid) / width * 1e3;
        double cell[2] = {floor(v3_dot(a, polygon->centroid) / width),
                          floor(v3_dot(b, polygon->centroid) / width)};
        if (!(fabs(offset) < 1e15 && fabs(cell[0]) < 1e15 && fabs(cell[1]) < 1e15))
            continue; /* patches far smaller than their distance from the origin: no group */
        key->offset = llround(offset);
        key->cell[0] = (int64_t)cell[0];
        key->cell[1] = (int64_t)cell[1];
        k++;
    }
    flat = k;
    qsort(keys, flat, sizeof(*keys), compare_keys);
    uint32_t groups = 0;
    for (uint32_t first = 0, last; first < flat; first = last) {
        for (last = first + 1; last < flat && same_group(&keys[first], &keys[last]); last++)
            ;
        groups += last - first >= 2;
    }
    rectangles = rad_alloc_array(groups ? groups : 1, sizeof(*rectangles));
    if (!rectangles)
        goto nomem;
    uint32_t made = 0;
    for (uint32_t first = 0, last; first < flat; first = last) {
        for (last = first + 1; last < flat && same_group(&keys[first], &keys[last]); last++)
            ;
        if (last - first >= 2 &&
            group_rectangle(pairs, &keys[first], last - first, made, &rectangles[made]))
            made++;
    }
    free(keys);
    keys = NULL;
    /* a row of words per group, the pair (g, h) in g's row for g < h: each thread writes
     * its rows' words alone; rectangles that do not face each other are not screened (no
     * pair between them faces either) */
    pairs->group_count = made;
    pairs->group_words = (made + 63) / 64;
    pairs->group_clear =
        rad_alloc_array((size_t)made * pairs->group_words + 1, sizeof(*pairs->group_clear));
    if (!pairs->group_clear)
        goto nomem;
    /* the lists only save time: under a memory budget (--max-memory) they are made only
     * when at most a quarter of what is left holds them at their largest */
    const uint64_t left = rad_memory_budget_left();
    const uint64_t largest = (uint64_t)made * made *
                             (sizeof(*pairs->group_list_first) + sizeof(*pairs->group_list_count) +
                              GROUP_LIST_MAX * sizeof(uint32_t) / 2);
    const bool listed = made <= GROUP_LISTS_MAX && (left == UINT64_MAX || largest <= left / 4);
    int short_of_memory = 0;
    if (listed) {
        pairs->group_list = rad_alloc_array(made ? made : 1, sizeof(*pairs->group_list));
        for (uint32_t g = 0; pairs->group_list && g < made; g++)
            pairs->group_list[g] = NULL;
        pairs->group_list_first =
            rad_alloc_array((size_t)made * made + 1, sizeof(*pairs->group_list_first));
        pairs->group_list_count =
            rad_alloc_array((size_t)made * made + 1, sizeof(*pairs->group_list_count));
        if (!pairs->group_list || !pairs->group_list_first || !pairs->group_list_count)
            goto nomem;
        memset(pairs->group_list_count, GROUP_NOT_LISTED, (size_t)made * made + 1);
    }
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads > 0 ? threads : 1)
    for (int64_t g = 0; g < (int64_t)made; g++) {
        uint32_t *row = NULL; /* this row's lists, one after another */
        size_t used = 0, capacity = 0;
        for (uint32_t h = (uint32_t)g + 1; h < made; h++) {
            if (!rectangles_face(&rectangles[g], &rectangles[h], pairs->plane_epsilon))
                continue;
            uint32_t found[GROUP_LIST_MAX], unused;
            unsigned count =
                listed ? screen_collect(pairs, &rectangles[g], &rectangles[h], found,
                                        GROUP_LIST_MAX)
                       : screen_may_block(pairs, &rectangles[g], &rectangles[h], &unused);
            if (count == 0) { /* clear */
                pairs->group_clear[(size_t)g * pairs->group_words + h / 64] |= UINT64_C(1)
                                                                               << (h % 64);
                continue;
            }
            if (!listed)
                continue;
            if (count > GROUP_LIST_MAX)
                continue; /* not listed: its pairs screen the tree */
            if (used + count > capacity) {
                size_t grown = capacity ? 2 * capacity : 256;
                while (grown < used + count)
                    grown *= 2;
                uint32_t *bigger = rad_resize_array(row, grown, sizeof(*row));
                if (!bigger) {
#pragma omp atomic write
                    short_of_memory = 1;
                    break;
                }
                row = bigger;
                capacity = grown;
            }
            memcpy(row + used, found, count * sizeof(*found));
            size_t at = (size_t)g * made + h;
            pairs->group_list_first[at] = (uint32_t)used;
            pairs->group_list_count[at] = (uint8_t)count;
            used += count;
        }
        if (listed)
            pairs->group_list[g] = row;
    }
    if (short_of_memory)
        goto nomem;
    free(rectangles);
    return RAD_OK;
nomem:
    free(keys);
    free(rectangles);
    free(pairs->group_of);
    free(pairs->group_clear);
    free_group_lists(pairs);
    pairs->group_of = NULL;
    pairs->group_clear = NULL;
    pairs->group_count = 0;
    return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the groups of patches");
}

void exact_pairs_free(exact_pairs *pairs)
{
    occluder_tree_destroy(pairs->tree);
    free(pairs->polygons);
    free_group_lists(pairs);
    free(pairs->group_of);
    free(pairs->group_clear);
    free(pairs->screen_nodes);
    free(pairs->screen_triangles);
    free(pairs->hiding_faces);
    free(pairs->inside_solid);
    free(pairs->solid_corner);
    free(pairs->solid_corner_first);
    *pairs = (exact_pairs){0};
}

/* The part of `in` on the side `sign` of the plane n . x = offset; false when it has more
 * corners than a polygon holds or no area. */
static bool clip_polygon(const vf_polygon *in, rad_vec3 n, double offset, double sign,
                         vf_polygon *out)
{
    *out = *in;
    out->count = 0;
    for (unsigned k = 0; k < in->count; k++) {
        rad_vec3 a = in->vertex[k], b = in->vertex[(k + 1) % in->count];
        double da = sign * (v3_dot(n, a) - offset), db = sign * (v3_dot(n, b) - offset);
        bool crosses = (da > 0 && db < 0) || (da < 0 && db > 0);
        if (out->count + (da >= 0) + crosses > VF_MAX_VERTICES)
            return false;
        if (da >= 0)
            out->vertex[out->count++] = a;
        if (crosses)
            out->vertex[out->count++] = v3_lerp(a, b, da / (da - db));
    }
    if (out->count < 3)
        return false;
    vf_polygon_finish(out);
    return out->area > 0;
}

/* Cuts `outer` by the plane of every occluder that passes through it; false when a piece
 * would have too many corners. */
static bool cut_by_occluders(const vf_polygon *outer, const shadow_occluder *occluders,
                             uint32_t count, double epsilon, vf_polygon *pieces,
                             unsigned *piece_count)
{
    pieces[0] = *outer;
    *piece_count = 1;
    for (uint32_t o = 0; o < count; o++) {
        const rad_vec3 *c = occluders[o].corner;
        rad_vec3 n = v3_cross(v3_sub(c[1], c[0]), v3_sub(c[2], c[0]));
        double length = v3_length(n);
        if (!(length > 0))
            continue;
        n = v3_scale(n, 1 / length);
        double offset = v3_dot(n, c[0]);
        unsigned before = *piece_count;
        for (unsigned p = 0; p < before; p++) {
            bool below = false, above = false;
            for (unsigned k = 0; k < pieces[p].count; k++) {
                double d = v3_dot(n, pieces[p].vertex[k]) - offset;
                below = below || d < -epsilon;
                above = above || d > epsilon;
            }
            if (!(below && above))
                continue;
            vf_polygon front, back;
            if (*piece_count >= MAX_PIECES || !clip_polygon(&pieces[p], n, offset, 1, &front) ||
                !clip_polygon(&pieces[p], n, offset, -1, &back))
                return false;
            pieces[p] = front;
            pieces[(*piece_count)++] = back;
        }
    }
    return true;
}

/* Screening the pair (i, j): from its groups' list when they have one, else the tree. When
 * a triangle across the centroids' segment settles it, *crossing says which (else it is
 * left as it is). */
static bool pair_may_block(const exact_pairs *pairs, uint32_t i, uint32_t j, uint32_t *crossing)
{
    const vf_polygon *p = &pairs->polygons[i], *q = &pairs->polygons[j];
    if (pairs->group_list) {
        uint32_t g = pairs->group_of[i], h = pairs->group_of[j];
        if (g != EXACT_NO_GROUP && h != EXACT_NO_GROUP && g != h) {
            if (g > h) {
                uint32_t swap = g;
                g = h;
                h = swap;
            }
            size_t at = (size_t)g * pairs->group_count + h;
            unsigned count = pairs->group_list_count[at];
            if (count != GROUP_NOT_LISTED)
                return screen_listed_may_block(pairs, p, q,
                                               pairs->group_list[g] + pairs->group_list_first[at],
                                               count, crossing);
        }
    }
    return screen_may_block(pairs, p, q, crossing);
}

/* Whether triangle t hides q wholly from p: every corner of p strictly on one side of its
 * plane, every corner of q strictly on the other, and every crossing of its plane by a
 * segment from a corner of p to a corner of q strictly inside its face (hiding_faces.h:
 * itself, or the convex quad it makes with a neighbour in its plane). The crossings of all
 * segments from p to q lie in the convex hull of those (the hull of p and q, cut by the
 * plane), which then lies inside the face: no segment gets past it. */
static bool face_hides(const exact_pairs *pairs, uint32_t t, const vf_polygon *p,
                       const vf_polygon *q)
{
    const screen_triangle *tri = &pairs->screen_triangles[t];
    const hiding_face *face = &pairs->hiding_faces[t];
    const double margin = pairs->epsilon;
    if (!face->edges)
        return false;
    double dp[VF_MAX_VERTICES], dq[VF_MAX_VERTICES];
    int side = 0;
    for (unsigned k = 0; k < p->count; k++) {
        dp[k] = v3_dot(tri->normal, p->vertex[k]) - tri->offset;
        int s = dp[k] > margin ? 1 : dp[k] < -margin ? -1 : 0;
        if (s == 0 || (side && s != side))
            return false;
        side = s;
    }
    for (unsigned k = 0; k < q->count; k++) {
        dq[k] = v3_dot(tri->normal, q->vertex[k]) - tri->offset;
        if (!(side > 0 ? dq[k] < -margin : dq[k] > margin))
            return false;
    }
    for (unsigned a = 0; a < p->count; a++)
        for (unsigned b = 0; b < q->count; b++) {
            double wa = fabs(dq[b]), wb = fabs(dp[a]);
            rad_vec3 x = v3_scale(v3_add(v3_scale(p->vertex[a], wa), v3_scale(q->vertex[b], wb)),
                                  1 / (wa + wb));
            for (unsigned e = 0; e < face->edges; e++)
                if (!(v3_dot(face->edge_normal[e], x) - face->edge_offset[e] > margin))
                    return false;
        }
    return true;
}

/* Whether convex solid k (of the occluder tree) holds apart polygon q. */
static bool solid_apart(const exact_pairs *pairs, const convex_solids *solids, uint32_t k,
                        const vf_polygon *q)
{
    uint32_t first = pairs->solid_corner_first[k];
    return convex_solid_apart(&solids->solids[k], q, pairs->solid_corner + first,
                              pairs->solid_corner_first[k + 1] - first, pairs->epsilon);
}

bool exact_pairs_hidden(const exact_pairs *pairs, uint32_t i, uint32_t j, uint32_t crossing)
{
    const vf_polygon *p = &pairs->polygons[i], *q = &pairs->polygons[j];
    if (p->count == 0 || q->count == 0)
        return false;
    if (pairs->inside_solid) { /* one held by a convex solid, the other apart from it */
        const convex_solids *solids = occluder_tree_solids(pairs->tree);
        uint32_t held_i = pairs->inside_solid[i], held_j = pairs->inside_solid[j];
        if ((held_i != EXACT_NO_SOLID && solid_apart(pairs, solids, held_i, q)) ||
            (held_j != EXACT_NO_SOLID && solid_apart(pairs, solids, held_j, p)))
            return true;
    }
    /* a hiding face crosses the centroids' segment: the triangle the screening found
     * across it is the one tried (its face, a quad, covers its neighbour) */
    return crossing != EXACT_NO_CROSSING && face_hides(pairs, crossing, p, q);
}

exact_outcome exact_pairs_transfer(const exact_pairs *pairs, uint32_t i, uint32_t j, bool clip,
                                   double accuracy, double *G, uint32_t *crossing)
{
    const vf_polygon *p = &pairs->polygons[i], *q = &pairs->polygons[j];
    uint32_t unused;
    crossing = crossing ? crossing : &unused;
    *crossing = EXACT_NO_CROSSING;
    if (p->count == 0 || q->count == 0)
        return EXACT_SAMPLE;
    if (!pair_may_block(pairs, i, j, crossing))
        return EXACT_CLEAR;
    if (!clip)
        return EXACT_SAMPLE; /* the hull's faces might still prove it clear: not worth it */
    shadow_occluder between[EXACT_PAIRS_MAX_OCCLUDERS];
    uint32_t count = occluder_tree_collect(pairs->tree, p, q, pairs->epsilon, between,
                                           EXACT_PAIRS_MAX_OCCLUDERS);
    if (count == 0)
        return EXACT_CLEAR;
    if (count > EXACT_PAIRS_MAX_OCCLUDERS)
        return EXACT_SAMPLE;
    const vf_polygon *outer = p->area <= q->area ? p : q, *inner = outer == p ? q : p;
    vf_polygon pieces[MAX_PIECES];
    unsigned piece_count;
    if (!cut_by_occluders(outer, between, count, pairs->epsilon, pieces, &piece_count))
        return EXACT_SAMPLE;
    double total = 0;
    for (unsigned k = 0; k < piece_count; k++) {
        double value, bound;
        /* a piece is never larger than the inner patch, so it stays the outer polygon */
        if (!pair_obstructed_exact(&pieces[k], inner, between, count, accuracy,
                                   pairs->plane_epsilon, &value, &bound))
            return EXACT_SAMPLE;
        total += value;
    }
    *G = total;
    return EXACT_SETTLED;
}
