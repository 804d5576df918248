/*
 * convex_solids.c - convex solids among the scene's triangles, see convex_solids.h.
 */
#include "surface_viewfactors/convex_solids.h"

#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/edge_key.h"
#include "core/error.h"
#include "core/union_find.h"
#include "core/vec3.h"
#include "core/weld.h"

#define NONE UINT32_MAX
#define EMPTY UINT64_MAX

/* A solid's planes agree, and its corners lie on them, to this share of its extent. */
#define SOLID_TOLERANCE 1e-9

/* The directed edges a -> b of every triangle, as (a << 32) | b in an open-addressing set. */
typedef struct edge_set {
    uint64_t *keys;
    uint64_t mask;
} edge_set;

static inline uint64_t directed(uint32_t a, uint32_t b) { return ((uint64_t)a << 32) | b; }

/* The slot holding the key, or the empty one where it would go. */
static uint64_t *edge_slot(const edge_set *set, uint64_t key)
{
    uint64_t s = edge_key_hash(key) & set->mask;
    while (set->keys[s] != EMPTY && set->keys[s] != key)
        s = (s + 1) & set->mask;
    return &set->keys[s];
}

/* Inserts the key; false when it was there already. */
static bool edge_insert(edge_set *set, uint64_t key)
{
    uint64_t *slot = edge_slot(set, key);
    if (*slot == key)
        return false;
    *slot = key;
    return true;
}

static bool edge_present(const edge_set *set, uint64_t key) { return *edge_slot(set, key) == key; }

/* What the search holds while it looks at one connected set of triangles. */
typedef struct component_view {
    const rad_scene *scene;
    const uint32_t *vid;        /* per triangle corner: its welded vertex */
    const edge_set *edges;
    const uint32_t *triangles;  /* the set's triangles */
    uint32_t count;
} component_view;

static rad_vec3 corner_of(const component_view *c, uint32_t t, int k)
{
    return c->scene->positions[c->scene->triangles[t].vertex[k]];
}

/* Whether edge k of triangle t (from corner k to the next) is matched by no edge the other
 * way: an edge of the missing face; its ends go to *p and *q. */
static bool open_edge(const component_view *c, uint32_t t, int k, rad_vec3 *p, rad_vec3 *q)
{
    uint32_t from = c->vid[3 * (size_t)t + k], to = c->vid[3 * (size_t)t + (k + 1) % 3];
    if (edge_present(c->edges, directed(to, from)))
        return false;
    *p = corner_of(c, t, k);
    *q = corner_of(c, t, (k + 1) % 3);
    return true;
}

/* The set as a convex solid into *solid, or false. */
static bool component_solid(const component_view *c, convex_solid *solid)
{
    if (c->count < 3)
        return false;
    rad_vec3 lo = corner_of(c, c->triangles[0], 0), hi = lo;
    for (uint32_t i = 0; i < c->count; i++)
        for (int k = 0; k < 3; k++) {
            rad_vec3 p = corner_of(c, c->triangles[i], k);
            lo = v3(fmin(lo.x, p.x), fmin(lo.y, p.y), fmin(lo.z, p.z));
            hi = v3(fmax(hi.x, p.x), fmax(hi.y, p.y), fmax(hi.z, p.z));
        }
    const double eps = SOLID_TOLERANCE * v3_length(v3_sub(hi, lo));
    if (!(eps > 0) || !isfinite(eps))
        return false;
    /* the distinct face planes, outward as the triangles turn */
    solid->plane_count = 0;
    for (uint32_t i = 0; i < c->count; i++) {
        uint32_t t = c->triangles[i];
        rad_vec3 a = corner_of(c, t, 0);
        rad_vec3 n = v3_cross(v3_sub(corner_of(c, t, 1), a), v3_sub(corner_of(c, t, 2), a));
        double length = v3_length(n);
        if (!(length > 0))
            return false;
        n = v3_scale(n, 1 / length);
        double offset = v3_dot(n, a);
        unsigned k = 0;
        while (k < solid->plane_count &&
               !(v3_dot(n, solid->normal[k]) > 1 - 1e-12 && fabs(offset - solid->offset[k]) <= eps))
            k++;
        if (k == solid->plane_count) {
            if (k == CONVEX_SOLID_MAX_PLANES)
                return false;
            solid->normal[k] = n;
            solid->offset[k] = offset;
            solid->plane_count++;
        }
    }
    /* convex: every corner behind or on every face plane; not flat: some corner behind
     * one of them */
    bool deep = false;
    for (unsigned k = 0; k < solid->plane_count; k++)
        for (uint32_t i = 0; i < c->count; i++)
            for (int m = 0; m < 3; m++) {
                double d = v3_dot(solid->normal[k], corner_of(c, c->triangles[i], m)) -
                           solid->offset[k];
                if (d > eps)
                    return false;
                deep = deep || d < -eps;
            }
    if (!deep)
        return false;
    /* closed, or open along edges in one plane: the plane through the first open edge and
     * the open edges' end farthest from its line, then every open edge checked against it */
    solid->open = false;
    rad_vec3 a = {0, 0, 0}, b = {0, 0, 0}, n = {0, 0, 0}, p, q;
    bool have_edge = false;
    for (uint32_t i = 0; i < c->count; i++)
        for (int k = 0; k < 3; k++) {
            if (!open_edge(c, c->triangles[i], k, &p, &q))
                continue;
            if (!have_edge) {
                a = p, b = q;
                have_edge = true;
            }
            rad_vec3 across[2] = {p, q};
            for (int m = 0; m < 2; m++) {
                rad_vec3 candidate = v3_cross(v3_sub(b, a), v3_sub(across[m], a));
                if (v3_dot(candidate, candidate) > v3_dot(n, n))
                    n = candidate;
            }
        }
    if (!have_edge)
        return true;
    double length = v3_length(n);
    if (!(length > 0))
        return false; /* open edges along one line: no face's outline */
    solid->open = true;
    solid->open_normal = v3_scale(n, 1 / length);
    solid->open_offset = v3_dot(solid->open_normal, a);
    for (uint32_t i = 0; i < c->count; i++)
        for (int k = 0; k < 3; k++)
            if (open_edge(c, c->triangles[i], k, &p, &q) &&
                (fabs(v3_dot(solid->open_normal, p) - solid->open_offset) > eps ||
                 fabs(v3_dot(solid->open_normal, q) - solid->open_offset) > eps))
                return false; /* open edges off the missing face's plane */
    /* outward: away from the corners, which must all lie on one side */
    double least = INFINITY, most = -INFINITY;
    for (uint32_t i = 0; i < c->count; i++)
        for (int m = 0; m < 3; m++) {
            double d = v3_dot(solid->open_normal, corner_of(c, c->triangles[i], m)) -
                       solid->open_offset;
            least = fmin(least, d);
            most = fmax(most, d);
        }
    if (least >= -eps) {
        solid->open_normal = v3_scale(solid->open_normal, -1);
        solid->open_offset = -solid->open_offset;
    } else if (most > eps) {
        return false;
    }
    return true;
}

rad_status convex_solids_find(const rad_scene *scene, convex_solids *out, rad_error *error)
{
    *out = (convex_solids){0};
    const uint32_t n = scene->triangle_count;
    uint64_t capacity = 64;
    while (capacity < 6 * (uint64_t)n)
        capacity *= 2;
    uint32_t *vid = rad_alloc_array(3 * (size_t)n + 1, sizeof(*vid));
    uint32_t *parent = rad_alloc_array(3 * (size_t)n + 1, sizeof(*parent));
    uint8_t *bad = rad_alloc_array((size_t)n + 1, 1);
    uint8_t *bad_set = rad_alloc_array(3 * (size_t)n + 1, 1); /* per root vertex */
    uint32_t *start = rad_alloc_array(3 * (size_t)n + 2, sizeof(*start));
    uint32_t *order = rad_alloc_array((size_t)n + 1, sizeof(*order));
    uint32_t *of_triangle = rad_alloc_array((size_t)n + 1, sizeof(*of_triangle));
    convex_solid *solids = NULL;
    edge_set edges = {rad_alloc_array(capacity, sizeof(uint64_t)), capacity - 1};
    rad_weld weld;
    bool welded = rad_weld_init(&weld, n < UINT32_MAX / 3 ? 3 * n + 1 : UINT32_MAX) != 0;
    bool ok = vid && parent && bad && bad_set && start && order && of_triangle && edges.keys && welded;
    for (uint32_t t = 0; ok && t < n; t++)
        for (int k = 0; k < 3; k++) {
            vid[3 * (size_t)t + k] =
                rad_weld_insert(&weld, 0, scene->positions[scene->triangles[t].vertex[k]]);
            ok = ok && vid[3 * (size_t)t + k] != UINT32_MAX;
        }
    uint32_t vertices = ok ? weld.count : 0;
    if (welded)
        rad_weld_free(&weld);
    uint32_t solid_count = 0;
    if (ok) {
        for (uint64_t s = 0; s < capacity; s++)
            edges.keys[s] = EMPTY;
        for (uint32_t v = 0; v < vertices; v++)
            parent[v] = v;
        for (uint32_t t = 0; t < n; t++) {
            const uint32_t *c = &vid[3 * (size_t)t];
            of_triangle[t] = NONE;
            bad[t] = c[0] == c[1] || c[1] == c[2] || c[2] == c[0];
            for (int k = 0; k < 3 && !bad[t]; k++)
                if (!edge_insert(&edges, directed(c[k], c[(k + 1) % 3])))
                    bad[t] = 1; /* the same edge the same way twice: no solid's */
            for (int k = 1; k < 3; k++) {
                uint32_t x = union_find_root(parent, c[0]), y = union_find_root(parent, c[k]);
                if (x != y)
                    parent[x] = y;
            }
        }
        /* the triangles in order of their set (its root vertex), a set bad when one is */
        for (uint32_t t = 0; t < n; t++)
            start[union_find_root(parent, vid[3 * (size_t)t]) + 1]++;
        for (uint32_t v = 0; v < vertices; v++)
            start[v + 1] += start[v];
        for (uint32_t t = 0; t < n; t++) {
            uint32_t root = union_find_root(parent, vid[3 * (size_t)t]);
            order[start[root]++] = t;
            bad_set[root] |= bad[t];
        }
        for (uint32_t v = vertices; v-- > 0;) /* back to the sets' first places */
            start[v + 1] = start[v];
        start[0] = 0;
        uint32_t room = 0;
        convex_solid found;
        for (uint32_t root = 0; ok && root < vertices; root++) {
            if (start[root + 1] == start[root] || bad_set[root])
                continue; /* no set's root, or a bad set */
            component_view view = {scene, vid, &edges, &order[start[root]],
                                   start[root + 1] - start[root]};
            if (!component_solid(&view, &found))
                continue;
            if (solid_count == room) {
                room = room ? 2 * room : 16;
                convex_solid *grown = rad_resize_array(solids, room, sizeof(*solids));
                ok = grown != NULL;
                if (!ok)
                    break;
                solids = grown;
            }
            solids[solid_count] = found;
            for (uint32_t i = 0; i < view.count; i++)
                of_triangle[view.triangles[i]] = solid_count;
            solid_count++;
        }
    }
    free(vid);
    free(parent);
    free(bad);
    free(bad_set);
    free(start);
    free(order);
    free(edges.keys);
    if (!ok) {
        free(of_triangle);
        free(solids);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for finding convex solids");
    }
    out->of_triangle = of_triangle;
    out->solids = solids;
    out->count = solid_count;
    return RAD_OK;
}

void convex_solids_free(convex_solids *solids)
{
    free(solids->of_triangle);
    free(solids->solids);
    *solids = (convex_solids){0};
}

bool convex_solid_seen_from(const convex_solid *solid, const vf_polygon *polygon, double epsilon)
{
    bool outside = false;
    for (unsigned k = 0; k < solid->plane_count && !outside; k++) {
        bool beyond = false;
        outside = true;
        for (unsigned m = 0; m < polygon->count && outside; m++) {
            double d = v3_dot(solid->normal[k], polygon->vertex[m]) - solid->offset[k];
            outside = d >= -epsilon;
            beyond = beyond || d > epsilon;
        }
        outside = outside && beyond;
    }
    if (!outside)
        return false;
    for (unsigned m = 0; solid->open && m < polygon->count; m++)
        if (v3_dot(solid->open_normal, polygon->vertex[m]) - solid->open_offset > epsilon)
            return false;
    return true;
}

bool convex_solid_holds(const convex_solid *solid, const vf_polygon *polygon, double epsilon)
{
    for (unsigned k = 0; k < solid->plane_count; k++)
        for (unsigned m = 0; m < polygon->count; m++)
            if (!(v3_dot(solid->normal[k], polygon->vertex[m]) - solid->offset[k] < -epsilon))
                return false;
    for (unsigned m = 0; solid->open && m < polygon->count; m++)
        if (!(v3_dot(solid->open_normal, polygon->vertex[m]) - solid->open_offset <= 0))
            return false;
    return solid->plane_count > 0;
}

bool convex_solid_apart(const convex_solid *solid, const vf_polygon *polygon,
                        const rad_vec3 *corner, uint32_t corner_count, double epsilon)
{
    for (unsigned m = 0; solid->open && m < polygon->count; m++)
        if (!(v3_dot(solid->open_normal, polygon->vertex[m]) - solid->open_offset < -epsilon))
            return false;
    for (unsigned k = 0; k < solid->plane_count; k++) {
        bool beyond = true;
        for (unsigned m = 0; m < polygon->count && beyond; m++)
            beyond = v3_dot(solid->normal[k], polygon->vertex[m]) - solid->offset[k] > epsilon;
        if (beyond)
            return true;
    }
    /* the polygon's own plane, with every corner of the solid on one side of it */
    double offset = v3_dot(polygon->normal, polygon->vertex[0]);
    int side = 0;
    for (uint32_t c = 0; c < corner_count; c++) {
        double d = v3_dot(polygon->normal, corner[c]) - offset;
        int s = d > epsilon ? 1 : d < -epsilon ? -1 : 0;
        if (s == 0 || (side && s != side))
            return false;
        side = s;
    }
    return corner_count > 0;
}

bool convex_solid_face_away(rad_vec3 n, rad_vec3 corner, const vf_polygon *polygon,
                            double epsilon)
{
    for (unsigned m = 0; m < polygon->count; m++)
        if (v3_dot(n, v3_sub(polygon->vertex[m], corner)) > epsilon)
            return false;
    return true;
}
