/*
 * mesh.c - splitting the scene into patches.
 *
 * Three steps:
 *   1. Regions: triangles that share an edge, a surface, a material and (within a degree)
 *      a plane form one smooth region (union-find over shared edges). Values are interpolated across patch
 *      boundaries inside a region and kept apart between regions, so creases stay sharp.
 *   2. Quads: two triangles of one region whose longest edges are the same edge (a quad
 *      split along its diagonal, as exporters do) are merged back into a convex quad,
 *      which subdivides into a regular grid of quad patches.
 *   3. Subdivision: a quad into nu x nv bilinear cells, a triangle into n^2 similar
 *      triangles, each edge no longer than the patch size. Points on an input edge are
 *      computed from that edge's lower-numbered end, so two polygons that split a shared
 *      edge into the same count produce bitwise-identical points, which the weld table
 *      then merges into shared vertices.
 * Then the back sides: each patch of a two-sided surface (RAD_SURFACE_TWO_SIDED) gets a
 * twin after all the others, its corners in reverse order and its vertices in a region of
 * their own (the front region's number + the region count), at the same positions bit for
 * bit, so both sides are ordinary one-sided patches to every solver and renderer.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/edge_key.h"
#include "core/error.h"
#include "core/tolerance.h"
#include "core/union_find.h"
#include "core/vec3.h"
#include "core/weld.h"
#include "mesh/proximity_refine.h"
#include "mesh/shadow_refine.h"

/* Refuse meshes beyond this many patches: the dense form-factor matrix would not fit. */
#define MESH_MAX_PATCHES 50000000u
/* The shadow refinement may add as many patches as the unrefined mesh has, and at least
 * this many (a small scene's shadows still get their finer cells). */
#define SHADOW_BUDGET_FLOOR 4096.0

typedef struct edge_slot {
    uint64_t key;       /* (low vertex << 32) | high vertex; 0 with triangle UINT32_MAX = empty */
    uint32_t triangle;  /* first triangle on the edge */
    uint32_t other;     /* second triangle, or UINT32_MAX */
    uint32_t count;     /* triangles on the edge */
} edge_slot;

typedef struct edge_table {
    edge_slot *slots;
    size_t mask;
} edge_table;

static edge_slot *edge_find(edge_table *table, uint64_t key)
{
    size_t s = edge_key_hash(key) & table->mask;
    while (table->slots[s].triangle != UINT32_MAX && table->slots[s].key != key)
        s = (s + 1) & table->mask;
    return &table->slots[s];
}

typedef struct mesh_input {
    const rad_scene *scene;
    rad_vec3 *normal; /* per triangle */
} mesh_input;

/* Triangles a and b share an edge: are they one smooth region? */
static bool smooth_neighbours(const mesh_input *in, uint32_t a, uint32_t b)
{
    const rad_triangle *ta = &in->scene->triangles[a], *tb = &in->scene->triangles[b];
    return ta->surface == tb->surface && ta->material == tb->material &&
           v3_length(v3_sub(in->normal[a], in->normal[b])) < RAD_REGION_NORMAL;
}

/* The corner index (0..2) at which triangle t's longest edge starts. */
static int longest_edge(const rad_scene *scene, uint32_t t)
{
    const uint32_t *v = scene->triangles[t].vertex;
    int best = 0;
    double best_length = -1;
    for (int k = 0; k < 3; k++) {
        rad_vec3 e = v3_sub(scene->positions[v[(k + 1) % 3]], scene->positions[v[k]]);
        double length = v3_dot(e, e);
        if (length > best_length) {
            best_length = length;
            best = k;
        }
    }
    return best;
}

static bool convex_quad(const rad_vec3 *p, rad_vec3 normal)
{
    for (int k = 0; k < 4; k++) {
        rad_vec3 e0 = v3_sub(p[(k + 1) % 4], p[k]);
        rad_vec3 e1 = v3_sub(p[(k + 2) % 4], p[(k + 1) % 4]);
        if (v3_dot(v3_cross(e0, e1), normal) <= 0)
            return false;
    }
    return true;
}

/* A polygon to subdivide: 3 or 4 scene vertex indices, counter-clockwise. */
typedef struct polygon {
    uint32_t vertex[4];
    uint32_t count;
    uint32_t triangle; /* a source triangle: surface, material, normal */
    double bulge;      /* how far the quad's bilinear cells may stray from its two input
                          triangles (0: flat) */
    uint32_t region;
} polygon;

typedef struct mesh_output {
    const mesh_input *in;
    rad_weld weld;
    rad_patch *patches;
    size_t patch_count, patch_capacity;
    shadow_refiner *refiner; /* splits cells crossed by sharp shadows (shadow_refine.h) */
    proximity_refiner *near; /* splits cells near other surfaces (proximity_refine.h) */
    bool two_sided;          /* the polygon being subdivided */
} mesh_output;

/* Point k/n of the way along the input edge (a, b), computed from its lower-numbered end. */
static rad_vec3 edge_point(const rad_scene *scene, uint32_t a, uint32_t b, uint32_t k,
                           uint32_t n)
{
    if (a > b) {
        uint32_t swap = a;
        a = b;
        b = swap;
        k = n - k;
    }
    if (k == 0)
        return scene->positions[a];
    if (k == n)
        return scene->positions[b];
    return v3_lerp(scene->positions[a], scene->positions[b], (double)k / n);
}

/* How far a cell of a folded quad (corners p on the quad's bilinear surface) lies behind
 * the quad's two input triangles (*behind) and in front of them (*ahead), along the
 * triangles' front normal: the bilinear surface strays from them by
 * lift x min(s (1 - t), t (1 - s)) toward the lifted corner, nothing on the quad's edges
 * and a quarter of the lift at its centre, so a cell's own distance, not the quad's
 * largest, is what rays leaving it must clear (its twin on a two-sided surface, facing
 * the other way, clears *ahead). Taken at the cell's corners, the midpoints of its edges
 * and diagonals, and its centre (on a small cell the distance is nearly linear). Shadow
 * rays that left every cell of the Cornell box's left wall (folded by 3.2 mm) a quarter
 * of the lift off it, 1.6 mm, moved the tall block's penumbra there: 5-7 % too dark
 * against the path tracer and a brute-force sum over the light. */
static void cell_offsets(const mesh_output *out, const polygon *poly, const rad_vec3 *p,
                         uint32_t count, double *behind, double *ahead)
{
    *behind = *ahead = 0;
    if (!(poly->bulge > 0) || poly->count != 4)
        return;
    const rad_vec3 *positions = out->in->scene->positions;
    rad_vec3 c[4];
    for (int k = 0; k < 4; k++)
        c[k] = positions[poly->vertex[k]];
    /* the input triangles (c0, c1, c2) and (c0, c2, c3), folded along c0 -> c2 */
    rad_vec3 diagonal = v3_sub(c[2], c[0]);
    rad_vec3 n_a = v3_normalize(v3_cross(v3_sub(c[1], c[0]), diagonal));
    rad_vec3 n_b = v3_normalize(v3_cross(diagonal, v3_sub(c[3], c[0])));
    rad_vec3 up = v3_add(n_a, n_b);
    double side_a = v3_dot(v3_cross(diagonal, v3_sub(c[1], c[0])), up);
    rad_vec3 q[11]; /* 4 corners, 4 edge midpoints, the centre, 2 diagonal midpoints */
    uint32_t points = 0;
    rad_vec3 centre = v3(0, 0, 0);
    for (uint32_t k = 0; k < count; k++) {
        q[points++] = p[k];
        q[points++] = v3_scale(v3_add(p[k], p[(k + 1) % count]), 0.5);
        centre = v3_add(centre, p[k]);
    }
    q[points++] = v3_scale(centre, 1.0 / count);
    if (count == 4) {
        q[points++] = v3_scale(v3_add(p[0], p[2]), 0.5);
        q[points++] = v3_scale(v3_add(p[1], p[3]), 0.5);
    }
    for (uint32_t k = 0; k < points; k++) {
        double side = v3_dot(v3_cross(diagonal, v3_sub(q[k], c[0])), up);
        rad_vec3 n = side * side_a >= 0 ? n_a : n_b;
        double below = v3_dot(n, v3_sub(c[0], q[k]));
        *behind = fmax(*behind, below);
        *ahead = fmax(*ahead, -below);
    }
}

static int add_patch(mesh_output *out, const polygon *poly, const rad_vec3 *p, uint32_t count)
{
    if (!rad_grow_array((void **)&out->patches, &out->patch_capacity, out->patch_count + 1,
                        sizeof(*out->patches)))
        return 0;
    rad_patch *patch = &out->patches[out->patch_count++];
    memset(patch, 0, sizeof(*patch));
    const rad_triangle *source = &out->in->scene->triangles[poly->triangle];
    patch->vertex_count = count;
    patch->bulge = poly->bulge;
    double ahead;
    cell_offsets(out, poly, p, count, &patch->behind, &ahead);
    patch->surface = source->surface;
    patch->material = source->material;
    for (uint32_t k = 0; k < count; k++) {
        patch->vertex[k] = rad_weld_insert(&out->weld, poly->region, p[k]);
        if (patch->vertex[k] == UINT32_MAX)
            return 0;
    }
    double a0 = 0.5 * v3_length(v3_cross(v3_sub(p[1], p[0]), v3_sub(p[2], p[0])));
    rad_vec3 c0 = v3_scale(v3_add(v3_add(p[0], p[1]), p[2]), 1.0 / 3.0);
    if (count == 3) {
        patch->area = a0;
        patch->centroid = c0;
        patch->normal = v3_normalize(v3_cross(v3_sub(p[1], p[0]), v3_sub(p[2], p[0])));
    } else {
        /* the diagonals' cross product: the mean normal of a slightly folded quad */
        patch->normal = v3_normalize(v3_cross(v3_sub(p[2], p[0]), v3_sub(p[3], p[1])));
        double a1 = 0.5 * v3_length(v3_cross(v3_sub(p[2], p[0]), v3_sub(p[3], p[0])));
        rad_vec3 c1 = v3_scale(v3_add(v3_add(p[0], p[2]), p[3]), 1.0 / 3.0);
        patch->area = a0 + a1;
        patch->centroid = patch->area > 0
                              ? v3_scale(v3_add(v3_scale(c0, a0), v3_scale(c1, a1)), 1.0 / patch->area)
                              : c0;
    }
    return 1;
}

/* A cell of a polygon's grid: a patch, or, where other surfaces are near it
 * (proximity_refine.h) or a sharp light's shadow edge crosses it (shadow_refine.h), its
 * four children, tested again down to each refiner's levels (`near_level` and
 * `shadow_level` count the splits each has made above this cell). An edge's midpoint is
 * the sum of its ends halved, the same bits from either cell that shares the edge, so
 * split neighbours weld their midpoints; an unsplit neighbour leaves a T-vertex, which the
 * display mesh makes continuous (display_mesh.h). */
static int emit_cell(mesh_output *out, const polygon *poly, const rad_vec3 *p, uint32_t count,
                     uint32_t near_level, uint32_t shadow_level)
{
    rad_vec3 normal = out->in->normal[poly->triangle];
    proximity_refiner *near = out->near;
    shadow_refiner *refiner = out->refiner;
    if (near && near_level < near->levels &&
        proximity_refiner_splits(near, p, count, normal, out->two_sided))
        near_level++;
    else if (refiner && shadow_level < refiner->levels &&
             shadow_refiner_splits(refiner, p, count, normal, poly->bulge, out->two_sided))
        shadow_level++;
    else
        return add_patch(out, poly, p, count);
    rad_vec3 m[4];
    for (uint32_t k = 0; k < count; k++)
        m[k] = v3_scale(v3_add(p[k], p[(k + 1) % count]), 0.5);
    if (count == 3) {
        rad_vec3 children[4][3] = {
            {p[0], m[0], m[2]}, {m[0], p[1], m[1]}, {m[2], m[1], p[2]}, {m[0], m[1], m[2]}};
        for (int k = 0; k < 4; k++)
            if (!emit_cell(out, poly, children[k], 3, near_level, shadow_level))
                return 0;
        return 1;
    }
    rad_vec3 centre = v3_scale(v3_add(v3_add(p[0], p[1]), v3_add(p[2], p[3])), 0.25);
    rad_vec3 children[4][4] = {{p[0], m[0], centre, m[3]},
                               {m[0], p[1], m[1], centre},
                               {centre, m[1], p[2], m[2]},
                               {m[3], centre, m[2], p[3]}};
    for (int k = 0; k < 4; k++)
        if (!emit_cell(out, poly, children[k], 4, near_level, shadow_level))
            return 0;
    return 1;
}

static uint32_t divisions(double length, double patch_size)
{
    double n = ceil(length / patch_size - 1e-9);
    return n < 1 ? 1 : n > 65535 ? 65535 : (uint32_t)n;
}

/* How a polygon is split: a triangle into n^2 (n returned in *nu), a quad into nu x nv. */
static void polygon_divisions(const rad_scene *scene, const polygon *poly, double patch_size,
                              uint32_t *nu, uint32_t *nv)
{
    rad_vec3 q[4];
    for (uint32_t k = 0; k < poly->count; k++)
        q[k] = scene->positions[poly->vertex[k]];
    if (poly->count == 3) {
        double longest = fmax(v3_length(v3_sub(q[1], q[0])),
                              fmax(v3_length(v3_sub(q[2], q[1])), v3_length(v3_sub(q[0], q[2]))));
        *nu = divisions(longest, patch_size);
        *nv = *nu;
        return;
    }
    *nu = divisions(fmax(v3_length(v3_sub(q[1], q[0])), v3_length(v3_sub(q[2], q[3]))), patch_size);
    *nv = divisions(fmax(v3_length(v3_sub(q[3], q[0])), v3_length(v3_sub(q[2], q[1]))), patch_size);
}

static int subdivide_triangle(mesh_output *out, const polygon *poly, double patch_size)
{
    const rad_scene *scene = out->in->scene;
    const uint32_t *v = poly->vertex;
    rad_vec3 a = scene->positions[v[0]], b = scene->positions[v[1]], c = scene->positions[v[2]];
    uint32_t n, unused;
    polygon_divisions(scene, poly, patch_size, &n, &unused);
    /* grid point (i, j): a + i/n (b - a) + j/n (c - a), i + j <= n */
#define GRID(i, j)                                                                          \
    ((j) == 0           ? edge_point(scene, v[0], v[1], (i), n)                             \
     : (i) == 0         ? edge_point(scene, v[0], v[2], (j), n)                             \
     : (i) + (j) == n   ? edge_point(scene, v[1], v[2], (j), n)                             \
                        : v3_add(a, v3_add(v3_scale(v3_sub(b, a), (double)(i) / n),          \
                                           v3_scale(v3_sub(c, a), (double)(j) / n))))
    for (uint32_t j = 0; j < n; j++)
        for (uint32_t i = 0; i + j < n; i++) {
            rad_vec3 up[3] = {GRID(i, j), GRID(i + 1, j), GRID(i, j + 1)};
            if (!emit_cell(out, poly, up, 3, 0, 0))
                return 0;
            if (i + j + 1 < n) {
                rad_vec3 down[3] = {GRID(i + 1, j), GRID(i + 1, j + 1), GRID(i, j + 1)};
                if (!emit_cell(out, poly, down, 3, 0, 0))
                    return 0;
            }
        }
#undef GRID
    return 1;
}

static int subdivide_quad(mesh_output *out, const polygon *poly, double patch_size)
{
    const rad_scene *scene = out->in->scene;
    const uint32_t *v = poly->vertex;
    rad_vec3 q[4];
    for (int k = 0; k < 4; k++)
        q[k] = scene->positions[v[k]];
    uint32_t nu, nv;
    polygon_divisions(scene, poly, patch_size, &nu, &nv);
    /* grid point (i, j) at s = i/nu, t = j/nv of the bilinear map over q0 q1 q2 q3 */
#define GRID(i, j)                                                                          \
    ((j) == 0    ? edge_point(scene, v[0], v[1], (i), nu)                                   \
     : (j) == nv ? edge_point(scene, v[3], v[2], (i), nu)                                   \
     : (i) == 0  ? edge_point(scene, v[0], v[3], (j), nv)                                   \
     : (i) == nu ? edge_point(scene, v[1], v[2], (j), nv)                                   \
                 : v3_lerp(v3_lerp(q[0], q[1], (double)(i) / nu),                           \
                           v3_lerp(q[3], q[2], (double)(i) / nu), (double)(j) / nv))
    for (uint32_t j = 0; j < nv; j++)
        for (uint32_t i = 0; i < nu; i++) {
            rad_vec3 cell[4] = {GRID(i, j), GRID(i + 1, j), GRID(i + 1, j + 1), GRID(i, j + 1)};
            if (!emit_cell(out, poly, cell, 4, 0, 0))
                return 0;
        }
#undef GRID
    return 1;
}

/* The scene's polygons, ready to subdivide at any patch size. */
typedef struct mesh_plan {
    mesh_input in;
    polygon *polygons;
    size_t polygon_count;
    uint32_t region_count;
} mesh_plan;

static void plan_free(mesh_plan *plan)
{
    free(plan->in.normal);
    free(plan->polygons);
    memset(plan, 0, sizeof(*plan));
}

/* Steps 1 and 2: regions and quads. */
static rad_status plan_build(const rad_scene *scene, mesh_plan *plan, rad_error *error)
{
    rad_status status = RAD_OK;
    uint32_t T = scene->triangle_count;
    edge_table edges = {NULL, 0};
    uint32_t *parent = NULL, *partner = NULL, *region_of_root = NULL;
    double *bulge = NULL;
    memset(plan, 0, sizeof(*plan));
    plan->in.scene = scene;

    plan->in.normal = rad_alloc_array(T, sizeof(*plan->in.normal));
    parent = rad_alloc_array(T, sizeof(*parent));
    partner = rad_alloc_array(T, sizeof(*partner));
    region_of_root = rad_alloc_array(T, sizeof(*region_of_root));
    plan->polygons = rad_alloc_array(T, sizeof(*plan->polygons));
    bulge = rad_alloc_array(T, sizeof(*bulge));
    size_t edge_slots = 64;
    while (edge_slots < 6 * (size_t)T)
        edge_slots *= 2;
    edges.slots = rad_alloc_array(edge_slots, sizeof(*edges.slots));
    edges.mask = edge_slots - 1;
    if (!plan->in.normal || !parent || !partner || !region_of_root || !plan->polygons ||
        !bulge || !edges.slots) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory while building patches");
        goto done;
    }
    mesh_input *in = &plan->in;
    for (uint32_t t = 0; t < T; t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        in->normal[t] = v3_normalize(v3_cross(v3_sub(scene->positions[v[1]], scene->positions[v[0]]),
                                              v3_sub(scene->positions[v[2]], scene->positions[v[0]])));
        parent[t] = t;
        partner[t] = UINT32_MAX;
    }
    for (size_t s = 0; s <= edges.mask; s++)
        edges.slots[s].triangle = UINT32_MAX;

    /* 1. regions: union triangles across shared edges */
    for (uint32_t t = 0; t < T; t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        for (int k = 0; k < 3; k++) {
            uint64_t key = edge_key(v[k], v[(k + 1) % 3]);
            edge_slot *slot = edge_find(&edges, key);
            if (slot->triangle == UINT32_MAX) {
                slot->key = key;
                slot->triangle = t;
                slot->other = UINT32_MAX;
                slot->count = 1;
                continue;
            }
            if (slot->count++ == 1)
                slot->other = t;
            if (smooth_neighbours(in, slot->triangle, t)) {
                uint32_t ra = union_find_root(parent, slot->triangle);
                uint32_t rb = union_find_root(parent, t);
                if (ra != rb)
                    parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
            }
        }
    }
    uint32_t region_count = 0;
    for (uint32_t t = 0; t < T; t++)
        region_of_root[t] = UINT32_MAX;
    for (uint32_t t = 0; t < T; t++) {
        uint32_t root = union_find_root(parent, t);
        if (region_of_root[root] == UINT32_MAX)
            region_of_root[root] = region_count++;
    }
    plan->region_count = region_count;

    /* 2. quads: pair triangles across a shared longest edge, when the four corners are
     * convex (the region test already bounds the fold to a degree). The bilinear cells of
     * a folded quad stray from the input triangles, which are what blocks rays, by up to a
     * quarter of the fourth corner's lift: that is recorded so that rays can leave from in
     * front. */
    for (uint32_t t = 0; t < T; t++) {
        if (partner[t] != UINT32_MAX)
            continue;
        const uint32_t *v = scene->triangles[t].vertex;
        int k = longest_edge(scene, t);
        edge_slot *slot = edge_find(&edges, edge_key(v[k], v[(k + 1) % 3]));
        if (slot->count != 2)
            continue;
        uint32_t u = slot->triangle == t ? slot->other : slot->triangle;
        if (partner[u] != UINT32_MAX || union_find_root(parent, u) != union_find_root(parent, t))
            continue;
        const uint32_t *w = scene->triangles[u].vertex;
        int m = longest_edge(scene, u);
        /* u must run the edge the other way: b -> a */
        if (w[m] != v[(k + 1) % 3] || w[(m + 1) % 3] != v[k])
            continue;
        rad_vec3 corner[4] = {scene->positions[v[k]], scene->positions[w[(m + 2) % 3]],
                              scene->positions[v[(k + 1) % 3]], scene->positions[v[(k + 2) % 3]]};
        double diagonal = v3_length(v3_sub(corner[2], corner[0]));
        double lift = fabs(v3_dot(in->normal[t], v3_sub(corner[1], corner[0])));
        if (!convex_quad(corner, in->normal[t]))
            continue;
        partner[t] = u;
        partner[u] = t;
        /* over the unit square the bilinear surface strays at most a quarter of the lift
         * from the two triangles' planes, at the centre */
        bulge[t] = bulge[u] = lift > RAD_QUAD_FLATNESS * diagonal ? lift / 4 : 0;
    }

    for (uint32_t t = 0; t < T; t++) {
        polygon *poly = &plan->polygons[plan->polygon_count];
        const uint32_t *v = scene->triangles[t].vertex;
        poly->triangle = t;
        poly->region = region_of_root[union_find_root(parent, t)];
        poly->bulge = bulge[t];
        if (partner[t] == UINT32_MAX) {
            poly->count = 3;
            memcpy(poly->vertex, v, 3 * sizeof(*v));
        } else if (partner[t] > t) {
            const uint32_t *w = scene->triangles[partner[t]].vertex;
            int k = longest_edge(scene, t), m = longest_edge(scene, partner[t]);
            poly->count = 4;
            poly->vertex[0] = v[k];
            poly->vertex[1] = w[(m + 2) % 3];
            poly->vertex[2] = v[(k + 1) % 3];
            poly->vertex[3] = v[(k + 2) % 3];
        } else {
            continue;
        }
        plan->polygon_count++;
    }
done:
    free(parent);
    free(partner);
    free(region_of_root);
    free(bulge);
    free(edges.slots);
    if (status != RAD_OK)
        plan_free(plan);
    return status;
}

static bool polygon_two_sided(const rad_scene *scene, const polygon *poly)
{
    uint32_t surface = scene->triangles[poly->triangle].surface;
    return (scene->surfaces[surface].flags & RAD_SURFACE_TWO_SIDED) != 0;
}

/* The exact number of patches subdividing at this size makes, twins included. */
static double plan_patch_count(const mesh_plan *plan, double patch_size)
{
    double count = 0;
    for (size_t p = 0; p < plan->polygon_count; p++) {
        uint32_t nu, nv;
        polygon_divisions(plan->in.scene, &plan->polygons[p], patch_size, &nu, &nv);
        double sides = polygon_two_sided(plan->in.scene, &plan->polygons[p]) ? 2 : 1;
        count += (double)nu * nv * sides;
    }
    return count;
}

/* The back side of patches [first, end) of one polygon (region `region`): a twin per
 * patch, corners reversed (0, n-1, ..., 1: the same triangles for the renderer's split,
 * the opposite normal), its vertices in region `region` + the plan's region count. */
static int add_twins(mesh_output *out, const mesh_plan *plan, const polygon *poly,
                     uint32_t region, size_t first, size_t end)
{
    for (size_t k = first; k < end; k++) {
        if (!rad_grow_array((void **)&out->patches, &out->patch_capacity, out->patch_count + 1,
                            sizeof(*out->patches)))
            return 0;
        const rad_patch *front = &out->patches[k];
        rad_patch *back = &out->patches[out->patch_count];
        *back = *front;
        for (uint32_t c = 0; c < front->vertex_count; c++) {
            uint32_t corner = c == 0 ? 0 : front->vertex_count - c;
            back->vertex[c] = rad_weld_insert(&out->weld, plan->region_count + region,
                                              out->weld.positions[front->vertex[corner]]);
            if (back->vertex[c] == UINT32_MAX)
                return 0;
        }
        back->normal = v3_scale(front->normal, -1);
        /* the same cell seen from the other side: what lies in front of the triangles
         * for the front lies behind them for the back */
        rad_vec3 corner[4];
        for (uint32_t c = 0; c < front->vertex_count; c++)
            corner[c] = out->weld.positions[front->vertex[c]];
        double behind;
        cell_offsets(out, poly, corner, front->vertex_count, &behind, &back->behind);
        back->twin = (uint32_t)k + 1;
        out->patches[k].twin = (uint32_t)out->patch_count + 1;
        out->patch_count++;
    }
    return 1;
}

double rad_mesh_default_patch_size(const rad_scene *scene, uint32_t target_patches)
{
    if (target_patches == 0)
        target_patches = 1;
    double fallback = sqrt(rad_scene_area(scene) / target_patches);
    mesh_plan plan;
    if (plan_build(scene, &plan, NULL) != RAD_OK)
        return 0; /* out of memory */
    /* the count falls as the size grows: bisect (in log space) for the size whose count is
     * closest to the target */
    rad_vec3 lo_corner, hi_corner;
    rad_scene_bounds(scene, &lo_corner, &hi_corner);
    double hi = v3_length(v3_sub(hi_corner, lo_corner)) * 2; /* one patch per polygon */
    double lo = hi * 1e-7;
    for (int step = 0; step < 60 && hi / lo > 1 + 1e-6; step++) {
        double mid = sqrt(lo * hi);
        if (plan_patch_count(&plan, mid) > target_patches)
            lo = mid;
        else
            hi = mid;
    }
    double below = plan_patch_count(&plan, hi), above = plan_patch_count(&plan, lo);
    double size = fabs(above - target_patches) < fabs(below - target_patches) ? lo : hi;
    plan_free(&plan);
    return size > 0 ? size : fallback;
}

double rad_mesh_patch_count_at(const rad_scene *scene, double patch_size)
{
    mesh_plan plan;
    if (!(patch_size > 0) || plan_build(scene, &plan, NULL) != RAD_OK)
        return 0;
    double count = plan_patch_count(&plan, patch_size);
    plan_free(&plan);
    return count;
}

void rad_mesh_destroy(rad_mesh *mesh)
{
    if (!mesh)
        return;
    free(mesh->vertices);
    free(mesh->patches);
    free(mesh);
}

rad_status rad_mesh_build(const rad_scene *scene, double patch_size, rad_mesh **out,
                          rad_error *error)
{
    rad_mesh_options options = {.patch_size = patch_size};
    return rad_mesh_build_with(scene, &options, out, error);
}

rad_status rad_mesh_build_with(const rad_scene *scene, const rad_mesh_options *options,
                               rad_mesh **out, rad_error *error)
{
    *out = NULL;
    double patch_size = options->patch_size;
    if (!(patch_size > 0) || !isfinite(patch_size))
        return rad_fail(error, RAD_ERR_INVALID, "patch size must be a positive number");
    if (options->shadow_levels < -1 || options->shadow_levels > RAD_SHADOW_LEVELS_MAX)
        return rad_fail(error, RAD_ERR_INVALID,
                        "shadow levels must be from 1 to %d, 0 for the default or -1 for none",
                        RAD_SHADOW_LEVELS_MAX);
    if (options->proximity_levels < 0 || options->proximity_levels > RAD_PROXIMITY_LEVELS_MAX)
        return rad_fail(error, RAD_ERR_INVALID, "proximity levels must be from 0 (none) to %d",
                        RAD_PROXIMITY_LEVELS_MAX);
    mesh_plan plan;
    rad_status status = plan_build(scene, &plan, error);
    if (status != RAD_OK)
        return status;
    shadow_refiner refiner = {0};
    proximity_refiner near = {0};
    mesh_output result = {&plan.in, {0}, NULL, 0, 0, NULL, NULL, false};
    rad_mesh *mesh = rad_alloc_array(1, sizeof(*mesh));
    if (!mesh || !rad_weld_init(&result.weld, 16))
        goto nomem;

    /* 3. subdivide every polygon */
    double count = plan_patch_count(&plan, patch_size);
    if (count > MESH_MAX_PATCHES) {
        status = rad_fail(error, RAD_ERR_INVALID,
                          "patch size %g would make %.0f patches (limit %u): use a larger "
                          "--patch-size",
                          patch_size, count, MESH_MAX_PATCHES);
        goto done;
    }
    uint32_t levels = options->shadow_levels == 0  ? RAD_SHADOW_LEVELS_DEFAULT
                      : options->shadow_levels < 0 ? 0
                                                   : (uint32_t)options->shadow_levels;
    size_t budget = options->max_added_patches ? options->max_added_patches
                                               : (size_t)fmax(count, SHADOW_BUDGET_FLOOR);
    status = shadow_refiner_init(&refiner, scene, levels, budget, error);
    if (status != RAD_OK)
        goto done;
    result.refiner = refiner.tracer ? &refiner : NULL;
    status = proximity_refiner_init(&near, scene, (uint32_t)options->proximity_levels, budget,
                                    error);
    if (status != RAD_OK)
        goto done;
    result.near = near.tracer ? &near : NULL;
    size_t *first_patch = rad_alloc_array(plan.polygon_count + 1, sizeof(*first_patch));
    if (!first_patch)
        goto nomem;
    for (size_t p = 0; p < plan.polygon_count; p++) {
        first_patch[p] = result.patch_count;
        result.two_sided = polygon_two_sided(scene, &plan.polygons[p]);
        int ok = plan.polygons[p].count == 3
                     ? subdivide_triangle(&result, &plan.polygons[p], patch_size)
                     : subdivide_quad(&result, &plan.polygons[p], patch_size);
        if (!ok) {
            free(first_patch);
            goto nomem;
        }
    }
    first_patch[plan.polygon_count] = result.patch_count;
    if (result.patch_count > MESH_MAX_PATCHES) {
        free(first_patch);
        status = rad_fail(error, RAD_ERR_INVALID,
                          "the shadow and proximity refinements made %zu patches (limit "
                          "%u): use a larger --patch-size or fewer --shadow-levels or "
                          "--proximity-levels",
                          result.patch_count, MESH_MAX_PATCHES);
        goto done;
    }
    /* the back sides, after every front */
    for (size_t p = 0; p < plan.polygon_count; p++)
        if (polygon_two_sided(scene, &plan.polygons[p]) &&
            !add_twins(&result, &plan, &plan.polygons[p], plan.polygons[p].region, first_patch[p],
                       first_patch[p + 1])) {
            free(first_patch);
            goto nomem;
        }
    free(first_patch);
    mesh->patch_count = (uint32_t)result.patch_count;
    mesh->patches = result.patches;
    result.patches = NULL;
    mesh->vertex_count = result.weld.count;
    mesh->vertices = rad_weld_take_positions(&result.weld);
    mesh->patch_size = patch_size;
    mesh->shadow_levels = options->shadow_levels;
    mesh->proximity_levels = options->proximity_levels;
    mesh->shadow_splits = refiner.split;
    mesh->shadow_budget_reached = refiner.budget_reached;
    mesh->proximity_splits = near.split;
    mesh->proximity_budget_reached = near.budget_reached;
    *out = mesh;
    mesh = NULL;
    goto done;
nomem:
    status = rad_fail(error, RAD_ERR_NOMEM, "out of memory while building patches");
done:
    shadow_refiner_free(&refiner);
    proximity_refiner_free(&near);
    rad_weld_free(&result.weld);
    free(result.patches);
    plan_free(&plan);
    rad_mesh_destroy(mesh);
    return status;
}
