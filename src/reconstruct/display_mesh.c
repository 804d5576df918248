/*
 * display_mesh.c - T-vertices and the display triangles (see display_mesh.h).
 *
 * 1. Every patch edge goes into a hash table keyed by its two vertex ids. Vertices are
 *    shared inside a smooth region only, so an edge used by two patches is interior and
 *    conforming; an edge used once lies on a region's boundary or on one side of a
 *    T-junction.
 * 2. The once-used edges are joined into chains: two of them meeting at a vertex and
 *    parallel (sine of the angle below PARALLEL_SINE) belong to one straight line. The
 *    mesher computes the points of a shared input edge from its lower-numbered end, so
 *    both sides' points lie on that edge's line and meet at its ends.
 * 3. Each chain's vertices are sorted along the line; a vertex strictly inside one of the
 *    chain's edges (by sorted position) is a T-vertex. Its anchors are the nearest
 *    vertices either side that are no T-vertices. Where one side's split nests in the
 *    other's (1 against 3), the anchors are the coarse edge's ends; where neither nests
 *    (2 against 3), every vertex between two common points is inside an edge of the other
 *    side, and the only values both sides' interpolations agree on are linear between
 *    those points, which is what the anchors give.
 * 4. For the triangles, steps 2 and 3 run again with vertices identified by position
 *    across regions (a crease, or two materials side by side, whose sides split their
 *    common edge differently): a point strictly inside a patch edge is its region's own
 *    vertex there when it has one (a T-vertex of step 3), else an added vertex at that
 *    position interpolated along the edge, so that region's values stay its own.
 * 5. A patch with points inside its edges is cut into triangles by ear clipping around its
 *    boundary (corners and those points in order). Collinearity is decided exactly from
 *    which of the patch's edges each point lies on (a convex patch's three boundary points
 *    are collinear only on one edge), so no ear is ever a sliver of zero area.
 */
#include "reconstruct/display_mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/edge_key.h"
#include "core/error.h"
#include "core/union_find.h"
#include "core/vec3.h"
#include "core/weld.h"

/* Two once-used edges meeting at a vertex are on one line when the sine of their angle is
 * below this: the mesher's points lie on their input edge to rounding (1e-16 relative),
 * while real corners of patches turn by far more. */
#define PARALLEL_SINE 1e-6

typedef struct edge_slot {
    uint64_t key;       /* (low vertex << 32) | high vertex; 0 = empty */
    uint32_t count;     /* patches using the edge */
    uint32_t unmatched; /* index among the once-used edges, or UINT32_MAX */
} edge_slot;

typedef struct edge_table {
    edge_slot *slots;
    size_t mask;
} edge_table;

static edge_slot *edge_find(const edge_table *table, uint64_t key)
{
    size_t s = edge_key_hash(key) & table->mask;
    while (table->slots[s].key != 0 && table->slots[s].key != key)
        s = (s + 1) & table->mask;
    return &table->slots[s];
}

static rad_rgb rgb_lerp(rad_rgb a, rad_rgb b, double t)
{
    return (rad_rgb){a.r + t * (b.r - a.r), a.g + t * (b.g - a.g), a.b + t * (b.b - a.b)};
}

static bool parallel(rad_vec3 d0, rad_vec3 d1)
{
    rad_vec3 c = v3_cross(d0, d1);
    return v3_dot(c, c) <= PARALLEL_SINE * PARALLEL_SINE * v3_dot(d0, d0) * v3_dot(d1, d1);
}

typedef struct along {
    double s;        /* distance along the chain's line */
    uint32_t vertex;
} along;

static int compare_along(const void *a, const void *b)
{
    const along *x = a, *y = b;
    if (x->s != y->s)
        return x->s < y->s ? -1 : 1;
    return x->vertex < y->vertex ? -1 : x->vertex > y->vertex;
}

/* Everything steps 1 to 4 work with; freed at the end of display_mesh_build. */
typedef struct work {
    edge_table table;
    uint32_t unmatched_count;
    uint32_t *from, *to;        /* per once-used edge, in its patch's order */
    const rad_vec3 *points;     /* positions of the ids chains are made of */
    const uint32_t *ends[2];    /* per once-used edge: its ends as chain ids */
    uint32_t *first, *incident; /* per id: its once-used edges (CSR) */
    uint32_t *parent;           /* union-find over once-used edges */
    uint32_t *chain_start, *chain_edges; /* edges grouped by chain */
    uint32_t *stamp, *position; /* per id: chain it was last seen in, its sorted place */
    uint32_t stamp_next;
    uint32_t *tindex;           /* per vertex: its T-vertex index or UINT32_MAX */
    uint32_t *insert_start, *insert_count; /* per once-used edge: points inside it */
    uint32_t *inserts;          /* those points in order from each edge's `from` to `to`:
                                   vertex ids, or vertex_count + k for added vertex k */
    size_t insert_total, insert_capacity;
    along *line;
    int *diff;
    size_t line_capacity, diff_capacity;
    display_tvertex *tvertices;
    size_t tvertex_capacity;
    uint32_t tvertex_count;
    /* step 4 */
    uint32_t *canonical;        /* per vertex: the id of its position across regions */
    rad_vec3 *canonical_points; /* per position id */
    uint32_t *copies_first, *copies; /* per position id: the vertices there (CSR) */
    uint32_t *label;            /* per vertex: its region (a union-find root) */
    uint32_t *canonical_ends[2];
    display_extra *extras;
    size_t extra_capacity;
    uint32_t extra_count;
} work;

static void chains_free(work *w)
{
    free(w->first);
    free(w->incident);
    free(w->parent);
    free(w->chain_start);
    free(w->chain_edges);
    w->first = w->incident = w->parent = w->chain_start = w->chain_edges = NULL;
}

static void work_free(work *w)
{
    free(w->table.slots);
    free(w->from);
    free(w->to);
    chains_free(w);
    free(w->stamp);
    free(w->position);
    free(w->tindex);
    free(w->insert_start);
    free(w->insert_count);
    free(w->inserts);
    free(w->line);
    free(w->diff);
    free(w->tvertices);
    free(w->canonical);
    free(w->canonical_points);
    free(w->copies_first);
    free(w->copies);
    free(w->label);
    free(w->canonical_ends[0]);
    free(w->canonical_ends[1]);
    free(w->extras);
}

/* Step 1: the edge table and the once-used edges. */
static bool find_unmatched(const rad_mesh *mesh, work *w)
{
    size_t instances = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        instances += mesh->patches[p].vertex_count;
    size_t slots = 64;
    while (slots < instances + instances / 2)
        slots *= 2;
    w->table.slots = rad_alloc_array(slots, sizeof(*w->table.slots));
    w->table.mask = slots - 1;
    if (!w->table.slots)
        return false;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            uint32_t a = patch->vertex[k], b = patch->vertex[(k + 1) % patch->vertex_count];
            if (a == b)
                continue;
            uint64_t key = edge_key(a, b);
            edge_slot *slot = edge_find(&w->table, key);
            if (slot->key == 0) {
                slot->key = key;
                slot->unmatched = UINT32_MAX;
            }
            slot->count++;
        }
    }
    uint32_t count = 0;
    for (size_t s = 0; s < slots; s++)
        count += w->table.slots[s].key != 0 && w->table.slots[s].count == 1;
    w->unmatched_count = count;
    w->from = rad_alloc_array(count, sizeof(*w->from));
    w->to = rad_alloc_array(count, sizeof(*w->to));
    if (!w->from || !w->to)
        return false;
    uint32_t u = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++) { /* patch order: deterministic */
        const rad_patch *patch = &mesh->patches[p];
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            uint32_t a = patch->vertex[k], b = patch->vertex[(k + 1) % patch->vertex_count];
            if (a == b)
                continue;
            edge_slot *slot = edge_find(&w->table, edge_key(a, b));
            if (slot->count != 1)
                continue;
            slot->unmatched = u;
            w->from[u] = a;
            w->to[u] = b;
            u++;
        }
    }
    return true;
}

/* Step 2: once-used edges into straight chains, grouped. Chains are made of the ids in
 * w->ends (vertex ids, or position ids for step 4), `ids` of them, at w->points. */
static bool build_chains(work *w, uint32_t ids)
{
    uint32_t U = w->unmatched_count;
    const uint32_t *from = w->ends[0], *to = w->ends[1];
    const rad_vec3 *X = w->points;
    w->first = rad_alloc_array((size_t)ids + 1, sizeof(*w->first));
    w->incident = rad_alloc_array(2 * (size_t)U, sizeof(*w->incident));
    w->parent = rad_alloc_array(U, sizeof(*w->parent));
    w->chain_start = rad_alloc_array((size_t)U + 1, sizeof(*w->chain_start));
    w->chain_edges = rad_alloc_array(U, sizeof(*w->chain_edges));
    uint32_t *cursor = rad_alloc_array((size_t)ids + 1, sizeof(*cursor));
    if (!w->first || !w->incident || !w->parent || !w->chain_start || !w->chain_edges ||
        !cursor) {
        free(cursor);
        return false;
    }
    for (uint32_t u = 0; u < U; u++) {
        w->first[from[u] + 1]++;
        w->first[to[u] + 1]++;
        w->parent[u] = u;
    }
    for (uint32_t v = 0; v < ids; v++)
        w->first[v + 1] += w->first[v];
    memcpy(cursor, w->first, ids * sizeof(*cursor));
    for (uint32_t u = 0; u < U; u++) {
        w->incident[cursor[from[u]]++] = u;
        w->incident[cursor[to[u]]++] = u;
    }
    for (uint32_t v = 0; v < ids; v++) {
        rad_vec3 p = X[v];
        for (uint32_t i = w->first[v]; i < w->first[v + 1]; i++) {
            uint32_t ei = w->incident[i];
            rad_vec3 di = v3_sub(X[from[ei] == v ? to[ei] : from[ei]], p);
            for (uint32_t j = i + 1; j < w->first[v + 1]; j++) {
                uint32_t ej = w->incident[j];
                rad_vec3 dj = v3_sub(X[from[ej] == v ? to[ej] : from[ej]], p);
                if (!parallel(di, dj))
                    continue;
                uint32_t ra = union_find_root(w->parent, ei), rb = union_find_root(w->parent, ej);
                if (ra != rb)
                    w->parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
            }
        }
    }
    /* group by root (counting sort; roots are edge indices) */
    for (uint32_t u = 0; u < U; u++)
        w->chain_start[union_find_root(w->parent, u) + 1]++;
    for (uint32_t u = 0; u < U; u++)
        w->chain_start[u + 1] += w->chain_start[u];
    free(cursor);
    uint32_t *next = rad_alloc_array((size_t)U + 1, sizeof(*next));
    if (!next)
        return false;
    memcpy(next, w->chain_start, ((size_t)U + 1) * sizeof(*next));
    for (uint32_t u = 0; u < U; u++)
        w->chain_edges[next[union_find_root(w->parent, u)]++] = u;
    free(next);
    return true;
}

/* Sorts the ids of one chain (its edges chain_edges[begin, end)) along its line into
 * w->line[0, m) (w->position: each id's place) and marks in w->diff[k] the ids strictly
 * inside one of its edges. Returns m, or 0 when no id is inside an edge; SIZE_MAX when
 * out of memory. */
static size_t sort_chain(work *w, uint32_t begin, uint32_t end)
{
    const rad_vec3 *X = w->points;
    const uint32_t *from = w->ends[0], *to = w->ends[1];
    uint32_t e0 = w->chain_edges[begin];
    rad_vec3 origin = X[from[e0]];
    rad_vec3 direction = v3_normalize(v3_sub(X[to[e0]], origin));
    size_t m = 0, most = 2 * (size_t)(end - begin);
    if (!rad_grow_array((void **)&w->line, &w->line_capacity, most, sizeof(*w->line)) ||
        !rad_grow_array((void **)&w->diff, &w->diff_capacity, most + 1, sizeof(*w->diff)))
        return SIZE_MAX;
    uint32_t stamp = ++w->stamp_next;
    for (uint32_t i = begin; i < end; i++) {
        uint32_t e = w->chain_edges[i];
        uint32_t ends[2] = {from[e], to[e]};
        for (int k = 0; k < 2; k++) {
            uint32_t v = ends[k];
            if (w->stamp[v] == stamp)
                continue;
            w->stamp[v] = stamp;
            w->line[m++] = (along){v3_dot(v3_sub(X[v], origin), direction), v};
        }
    }
    qsort(w->line, m, sizeof(*w->line), compare_along);
    for (size_t k = 0; k < m; k++)
        w->position[w->line[k].vertex] = (uint32_t)k;
    memset(w->diff, 0, (m + 1) * sizeof(*w->diff));
    bool any = false;
    for (uint32_t i = begin; i < end; i++) {
        uint32_t e = w->chain_edges[i];
        uint32_t a = w->position[from[e]], b = w->position[to[e]];
        uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
        if (hi > lo + 1) {
            w->diff[lo + 1]++;
            w->diff[hi]--;
            any = true;
        }
    }
    if (!any)
        return 0;
    /* covered: diff's running sum; the line's first and last points never are */
    int covered = 0;
    for (size_t k = 0; k < m; k++) {
        covered += w->diff[k];
        w->diff[k] = covered > 0;
    }
    return m;
}

static bool add_tvertex(work *w, display_tvertex t)
{
    if (!rad_grow_array((void **)&w->tvertices, &w->tvertex_capacity, w->tvertex_count + 1,
                        sizeof(*w->tvertices)))
        return false;
    w->tindex[t.vertex] = w->tvertex_count;
    w->tvertices[w->tvertex_count++] = t;
    return true;
}

/* Step 3 for one chain of vertex ids. */
static bool chain_tvertices(work *w, uint32_t begin, uint32_t end)
{
    size_t m = sort_chain(w, begin, end);
    if (m == SIZE_MAX)
        return false;
    size_t previous = 0;
    for (size_t k = 1; k + 1 < m; k++) {
        if (!w->diff[k]) {
            previous = k;
            continue;
        }
        size_t next = k + 1;
        while (w->diff[next])
            next++;
        const along *A = &w->line[previous], *B = &w->line[next];
        for (size_t j = k; j < next; j++) {
            uint32_t v = w->line[j].vertex;
            if (w->tindex[v] != UINT32_MAX) /* already a T-vertex of another line */
                continue;
            double span = B->s - A->s;
            double t = span > 0 ? (w->line[j].s - A->s) / span : 0.5;
            if (!add_tvertex(w, (display_tvertex){v, A->vertex, B->vertex, t}))
                return false;
        }
        k = next - 1;
    }
    return true;
}

/* The vertex of `region` at position id q: its own, or a vertex added on once-used edge e
 * (UINT32_MAX when out of memory). */
static uint32_t vertex_at(work *w, uint32_t vertex_count, uint32_t q, uint32_t region,
                          uint32_t e, double t)
{
    for (uint32_t c = w->copies_first[q]; c < w->copies_first[q + 1]; c++)
        if (w->label[w->copies[c]] == region)
            return w->copies[c];
    if (!rad_grow_array((void **)&w->extras, &w->extra_capacity, w->extra_count + 1,
                        sizeof(*w->extras)))
        return UINT32_MAX;
    w->extras[w->extra_count] = (display_extra){w->copies[w->copies_first[q]], w->from[e],
                                                w->to[e], t};
    return vertex_count + w->extra_count++;
}

/* Step 4 for one chain of position ids: each once-used edge's inner points. */
static bool chain_inserts(work *w, uint32_t vertex_count, uint32_t begin, uint32_t end)
{
    size_t m = sort_chain(w, begin, end);
    if (m == SIZE_MAX)
        return false;
    if (m == 0)
        return true;
    const uint32_t *from = w->ends[0], *to = w->ends[1];
    for (uint32_t i = begin; i < end; i++) {
        uint32_t e = w->chain_edges[i];
        uint32_t a = w->position[from[e]], b = w->position[to[e]];
        uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
        if (hi <= lo + 1)
            continue;
        uint32_t count = hi - lo - 1;
        if (!rad_grow_array((void **)&w->inserts, &w->insert_capacity, w->insert_total + count,
                            sizeof(*w->inserts)))
            return false;
        w->insert_start[e] = (uint32_t)w->insert_total;
        w->insert_count[e] = count;
        double s_from = w->line[a].s, span = w->line[b].s - s_from;
        for (uint32_t j = 0; j < count; j++) {
            const along *point = &w->line[a < b ? lo + 1 + j : hi - 1 - j];
            double t = span != 0 ? (point->s - s_from) / span : 0.5;
            uint32_t v = vertex_at(w, vertex_count, point->vertex, w->label[w->from[e]], e, t);
            if (v == UINT32_MAX)
                return false;
            w->inserts[w->insert_total + j] = v;
        }
        w->insert_total += count;
    }
    return true;
}

/* Step 4's ids: positions across regions, the vertices at each, and each vertex's
 * region. */
static bool identify_positions(const rad_mesh *mesh, work *w, uint32_t *position_count)
{
    uint32_t V = mesh->vertex_count, U = w->unmatched_count;
    rad_weld weld;
    w->canonical = rad_alloc_array(V, sizeof(*w->canonical));
    w->label = rad_alloc_array(V, sizeof(*w->label));
    if (!w->canonical || !w->label || !rad_weld_init(&weld, V))
        return false;
    bool ok = true;
    for (uint32_t v = 0; v < V && ok; v++) {
        w->canonical[v] = rad_weld_insert(&weld, 0, mesh->vertices[v]);
        ok = w->canonical[v] != UINT32_MAX;
    }
    uint32_t C = weld.count;
    w->canonical_points = ok ? rad_weld_take_positions(&weld) : NULL;
    if (!ok)
        rad_weld_free(&weld);
    w->copies_first = rad_alloc_array((size_t)C + 1, sizeof(*w->copies_first));
    w->copies = rad_alloc_array(V, sizeof(*w->copies));
    w->canonical_ends[0] = rad_alloc_array(U, sizeof(*w->canonical_ends[0]));
    w->canonical_ends[1] = rad_alloc_array(U, sizeof(*w->canonical_ends[1]));
    uint32_t *cursor = rad_alloc_array((size_t)C + 1, sizeof(*cursor));
    if (!ok || !w->canonical_points || !w->copies_first || !w->copies ||
        !w->canonical_ends[0] || !w->canonical_ends[1] || !cursor) {
        free(cursor);
        return false;
    }
    for (uint32_t v = 0; v < V; v++)
        w->copies_first[w->canonical[v] + 1]++;
    for (uint32_t q = 0; q < C; q++)
        w->copies_first[q + 1] += w->copies_first[q];
    memcpy(cursor, w->copies_first, (size_t)C * sizeof(*cursor));
    for (uint32_t v = 0; v < V; v++)
        w->copies[cursor[w->canonical[v]]++] = v;
    free(cursor);
    /* regions: vertices joined by the patches that use them */
    for (uint32_t v = 0; v < V; v++)
        w->label[v] = v;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        for (uint32_t k = 1; k < patch->vertex_count; k++) {
            uint32_t ra = union_find_root(w->label, patch->vertex[0]);
            uint32_t rb = union_find_root(w->label, patch->vertex[k]);
            if (ra != rb)
                w->label[ra < rb ? rb : ra] = ra < rb ? ra : rb;
        }
    }
    for (uint32_t v = 0; v < V; v++)
        w->label[v] = union_find_root(w->label, v);
    for (uint32_t u = 0; u < U; u++) {
        w->canonical_ends[0][u] = w->canonical[w->from[u]];
        w->canonical_ends[1][u] = w->canonical[w->to[u]];
    }
    *position_count = C;
    return true;
}

/* T-vertices ordered so that one whose anchor is itself a T-vertex (two lines crossing
 * at a vertex that is inside an edge of one of them) comes after that anchor; a cycle of
 * such dependencies (no mesher output makes one) is cut where the walk meets it. */
static bool order_tvertices(work *w, display_tvertex **ordered)
{
    uint32_t n = w->tvertex_count;
    uint8_t *state = rad_alloc_array(n, sizeof(*state));
    uint32_t *stack = rad_alloc_array(3 * (size_t)n, sizeof(*stack));
    *ordered = rad_alloc_array(n, sizeof(**ordered));
    if (!state || !stack || !*ordered) {
        free(state);
        free(stack);
        free(*ordered);
        *ordered = NULL;
        return false;
    }
    uint32_t emitted = 0;
    for (uint32_t root = 0; root < n; root++) {
        if (state[root])
            continue;
        size_t top = 0;
        stack[top++] = root;
        while (top > 0) {
            uint32_t i = stack[top - 1];
            if (state[i] == 2) {
                top--;
                continue;
            }
            if (state[i] == 1) {
                state[i] = 2;
                (*ordered)[emitted++] = w->tvertices[i];
                top--;
                continue;
            }
            state[i] = 1;
            uint32_t anchors[2] = {w->tvertices[i].from, w->tvertices[i].to};
            for (int k = 0; k < 2; k++) {
                uint32_t j = w->tindex[anchors[k]];
                if (j != UINT32_MAX && state[j] == 0)
                    stack[top++] = j; /* at most 2 per T-vertex expanded: 3 n in all */
            }
        }
    }
    free(state);
    free(stack);
    return true;
}

/* One boundary point of a patch being cut: a vertex and the patch edges it lies on
 * (bit k: edge k from corner k to corner k + 1). */
typedef struct ring {
    uint32_t *vertex;
    uint8_t *edges;
    uint32_t *next, *prev;
} ring;

static bool ring_alloc(ring *r, size_t size)
{
    r->vertex = rad_alloc_array(size, sizeof(*r->vertex));
    r->edges = rad_alloc_array(size, sizeof(*r->edges));
    r->next = rad_alloc_array(size, sizeof(*r->next));
    r->prev = rad_alloc_array(size, sizeof(*r->prev));
    return r->vertex && r->edges && r->next && r->prev;
}

static void ring_free(ring *r)
{
    free(r->vertex);
    free(r->edges);
    free(r->next);
    free(r->prev);
}

static bool collinear(const ring *r, uint32_t a, uint32_t b, uint32_t c)
{
    return (r->edges[a] & r->edges[b] & r->edges[c]) != 0;
}

/* Cuts the convex polygon r[0, m) (counter-clockwise) into m - 2 triangles by ear
 * clipping: an ear is a corner whose removal leaves neither a zero-area ear nor a chord
 * running along a patch edge. Walking back a step after each cut keeps it linear. */
static uint32_t clip_ears(ring *r, uint32_t m, uint32_t (*out)[3])
{
    for (uint32_t k = 0; k < m; k++) {
        r->next[k] = (k + 1) % m;
        r->prev[k] = (k + m - 1) % m;
    }
    uint32_t count = 0, remaining = m, current = 0, passed = 0;
    while (remaining > 3) {
        uint32_t p = r->prev[current], n = r->next[current];
        bool ear = !collinear(r, p, current, n) && !collinear(r, p, n, r->next[n]) &&
                   !collinear(r, r->prev[p], p, n);
        if (!ear && ++passed <= remaining) {
            current = n;
            continue;
        }
        /* an ear, or (never for a convex patch) a whole turn without one: cut anyway so
         * that the count stays m - 2 */
        out[count][0] = r->vertex[p];
        out[count][1] = r->vertex[current];
        out[count][2] = r->vertex[n];
        count++;
        r->next[p] = n;
        r->prev[n] = p;
        remaining--;
        current = p;
        passed = 0;
    }
    out[count][0] = r->vertex[r->prev[current]];
    out[count][1] = r->vertex[current];
    out[count][2] = r->vertex[r->next[current]];
    return count + 1;
}

/* The T-vertices inside patch edge (a, b): their count, and where they start. */
static uint32_t edge_inserts(const work *w, uint32_t a, uint32_t b, const uint32_t **list)
{
    *list = NULL;
    if (a == b || w->insert_total == 0)
        return 0;
    const edge_slot *slot = edge_find(&w->table, edge_key(a, b));
    if (slot->count != 1 || slot->unmatched == UINT32_MAX)
        return 0;
    uint32_t u = slot->unmatched;
    *list = w->inserts + w->insert_start[u];
    return w->insert_count[u];
}

/* Step 4: the display triangles. */
static bool build_triangles(const rad_mesh *mesh, const work *w, display_mesh *out)
{
    size_t total = 0;
    uint32_t most = 4;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        uint32_t m = patch->vertex_count;
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            const uint32_t *list;
            m += edge_inserts(w, patch->vertex[k], patch->vertex[(k + 1) % patch->vertex_count],
                              &list);
        }
        total += m - 2;
        most = m > most ? m : most;
    }
    if (total > UINT32_MAX)
        return false;
    out->triangles = rad_alloc_array(total, sizeof(*out->triangles));
    out->patch_of = rad_alloc_array(total, sizeof(*out->patch_of));
    ring r = {0};
    if (!out->triangles || !out->patch_of || !ring_alloc(&r, most)) {
        ring_free(&r);
        return false;
    }
    uint32_t t = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        uint32_t n = patch->vertex_count, m = 0;
        for (uint32_t k = 0; k < n; k++) {
            r.vertex[m] = patch->vertex[k];
            r.edges[m] = (uint8_t)((1u << k) | (1u << ((k + n - 1) % n)));
            m++;
            const uint32_t *list;
            uint32_t count = edge_inserts(w, patch->vertex[k], patch->vertex[(k + 1) % n], &list);
            for (uint32_t j = 0; j < count; j++) {
                r.vertex[m] = list[j];
                r.edges[m] = (uint8_t)(1u << k);
                m++;
            }
        }
        uint32_t made;
        if (m == n) { /* no T-vertex: the plain split, as before */
            made = 0;
            for (uint32_t s = 0; s + 2 < n; s++) {
                out->triangles[t + made][0] = patch->vertex[0];
                out->triangles[t + made][1] = patch->vertex[s + 1];
                out->triangles[t + made][2] = patch->vertex[s + 2];
                made++;
            }
        } else {
            made = clip_ears(&r, m, &out->triangles[t]);
        }
        for (uint32_t k = 0; k < made; k++)
            out->patch_of[t + k] = p;
        t += made;
    }
    out->triangle_count = t;
    ring_free(&r);
    return true;
}

rad_status display_mesh_build(const rad_mesh *mesh, bool triangles, display_mesh *out,
                              rad_error *error)
{
    memset(out, 0, sizeof(*out));
    work w;
    memset(&w, 0, sizeof(w));
    uint32_t V = mesh->vertex_count;
    bool ok = find_unmatched(mesh, &w);
    uint32_t U = w.unmatched_count;
    if (ok) {
        w.stamp = rad_alloc_array(V, sizeof(*w.stamp));
        w.position = rad_alloc_array(V, sizeof(*w.position));
        w.tindex = rad_alloc_array(V, sizeof(*w.tindex));
        w.insert_start = rad_alloc_array(U, sizeof(*w.insert_start));
        w.insert_count = rad_alloc_array(U, sizeof(*w.insert_count));
        ok = w.stamp && w.position && w.tindex && w.insert_start && w.insert_count;
    }
    if (ok) { /* steps 2 and 3: T-vertices, by vertex id */
        for (uint32_t v = 0; v < V; v++)
            w.tindex[v] = UINT32_MAX;
        w.points = mesh->vertices;
        w.ends[0] = w.from;
        w.ends[1] = w.to;
        ok = build_chains(&w, V);
        for (uint32_t c = 0; ok && c < U; c++) {
            uint32_t begin = w.chain_start[c], end = w.chain_start[c + 1];
            if (end - begin >= 3) /* a T-vertex needs a coarse edge and two fine ones */
                ok = chain_tvertices(&w, begin, end);
        }
        chains_free(&w);
    }
    if (ok)
        ok = order_tvertices(&w, &out->tvertices);
    out->tvertex_count = ok ? w.tvertex_count : 0;
    uint32_t positions = 0;
    if (ok && triangles) /* step 4: points inside edges, by position across regions */
        ok = identify_positions(mesh, &w, &positions);
    if (ok && triangles) {
        w.points = w.canonical_points;
        w.ends[0] = w.canonical_ends[0];
        w.ends[1] = w.canonical_ends[1];
        ok = build_chains(&w, positions);
        for (uint32_t c = 0; ok && c < U; c++) {
            uint32_t begin = w.chain_start[c], end = w.chain_start[c + 1];
            if (end - begin >= 3)
                ok = chain_inserts(&w, V, begin, end);
        }
        chains_free(&w);
        if (ok && (uint64_t)V + w.extra_count > UINT32_MAX - 1)
            ok = false;
        if (ok)
            ok = build_triangles(mesh, &w, out);
    }
    if (ok) {
        out->extras = w.extras;
        out->extra_count = w.extra_count;
        w.extras = NULL;
    }
    out->vertex_count = V + out->extra_count;
    work_free(&w);
    if (!ok) {
        display_mesh_free(out);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the display triangles of %u "
                                              "patches",
                        mesh->patch_count);
    }
    return RAD_OK;
}

void display_mesh_positions(const rad_mesh *mesh, const display_mesh *display,
                            rad_vec3 *positions)
{
    memcpy(positions, mesh->vertices, mesh->vertex_count * sizeof(*positions));
    for (uint32_t k = 0; k < display->extra_count; k++)
        positions[mesh->vertex_count + k] = mesh->vertices[display->extras[k].at];
}

bool display_mesh_radiance(const rad_mesh *mesh, const display_mesh *display, const rad_rgb *B,
                           rad_rgb *vertex_radiance)
{
    return display_mesh_radiance_weighted(mesh, display, B, NULL, vertex_radiance);
}

bool display_mesh_radiance_weighted(const rad_mesh *mesh, const display_mesh *display,
                                    const rad_rgb *B, const uint8_t *hidden,
                                    rad_rgb *vertex_radiance)
{
    double *weight = rad_alloc_array(mesh->vertex_count, sizeof(*weight));
    memset(vertex_radiance, 0,
           (display ? display->vertex_count : mesh->vertex_count) * sizeof(*vertex_radiance));
    if (!weight)
        return false;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        if (hidden && hidden[p])
            continue; /* seen by no one: it must not darken its visible neighbours */
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            rad_rgb *L = &vertex_radiance[patch->vertex[k]];
            L->r += patch->area * B[p].r;
            L->g += patch->area * B[p].g;
            L->b += patch->area * B[p].b;
            weight[patch->vertex[k]] += patch->area;
        }
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        double scale = weight[v] > 0 ? 1.0 / (RAD_PI * weight[v]) : 0;
        vertex_radiance[v].r *= scale;
        vertex_radiance[v].g *= scale;
        vertex_radiance[v].b *= scale;
    }
    free(weight);
    if (display)
        display_mesh_constrain(mesh, display, vertex_radiance);
    return true;
}

void display_mesh_constrain(const rad_mesh *mesh, const display_mesh *display,
                            rad_rgb *vertex_values)
{
    for (uint32_t i = 0; i < display->tvertex_count; i++) {
        const display_tvertex *tv = &display->tvertices[i];
        vertex_values[tv->vertex] = rgb_lerp(vertex_values[tv->from], vertex_values[tv->to], tv->t);
    }
    for (uint32_t k = 0; k < display->extra_count; k++) {
        const display_extra *x = &display->extras[k];
        vertex_values[mesh->vertex_count + k] =
            rgb_lerp(vertex_values[x->from], vertex_values[x->to], x->t);
    }
}

uint32_t display_mesh_front_triangles(const rad_mesh *mesh, const display_mesh *display)
{
    uint32_t traced = display->triangle_count;
    while (traced > 0 && mesh->patches[display->patch_of[traced - 1]].twin != 0 &&
           mesh->patches[display->patch_of[traced - 1]].twin - 1 < display->patch_of[traced - 1])
        traced--;
    return traced;
}

void display_mesh_free(display_mesh *display)
{
    free(display->triangles);
    free(display->patch_of);
    free(display->tvertices);
    free(display->extras);
    memset(display, 0, sizeof(*display));
}
