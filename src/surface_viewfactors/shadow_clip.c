/*
 * shadow_clip.c - point-to-polygon view factor behind occluders, see shadow_clip.h.
 */
#include "surface_viewfactors/shadow_clip.h"

#include <math.h>
#include <string.h>

#include "core/vec3.h"
#include "geometry/contour.h"

#define PIECE_MAX_VERTICES SHADOW_PIECE_MAX_VERTICES

_Static_assert(SHADOW_PIECE_MAX_VERTICES <= CONTOUR_MAX_VERTICES - 1,
               "a piece is a polygon the contour integral takes");

typedef shadow_piece piece;

/* Corners within 1e-12 of the piece's extent of the corner before them dropped. A clip
 * through a corner makes its crossing point again, a hair away: the zero-length edge
 * between them has no direction, so `separated` took every shadow to lie outside it and
 * the piece survived shadows that covered it (a pair 0.005 % visible came out 5.8 %). The
 * receiver itself may come with repeated corners (the part of a polygon in front of a
 * plane through one of its corners, vf_polygon_clip_front). */
static void drop_repeated_corners(piece *p)
{
    p->count = v3_drop_repeated(p->vertex, p->count, 1e-12);
}

/* Keeps the part of `in` where dot(normal, v) - offset >= 0 (into `out`), repeated
 * corners dropped; false when the result would have more than PIECE_MAX_VERTICES
 * corners. */
static bool clip_half_space(const piece *in, rad_vec3 normal, double offset, piece *out)
{
    out->count = 0;
    for (unsigned k = 0; k < in->count; k++) {
        rad_vec3 a = in->vertex[k], b = in->vertex[(k + 1) % in->count];
        double da = v3_dot(normal, a) - offset, db = v3_dot(normal, b) - offset;
        bool crosses = (da > 0 && db < 0) || (da < 0 && db > 0);
        if (out->count + (da >= 0) + crosses > PIECE_MAX_VERTICES)
            return false;
        if (da >= 0)
            out->vertex[out->count++] = a;
        if (crosses)
            out->vertex[out->count++] = v3_lerp(a, b, da / (da - db));
    }
    drop_repeated_corners(out);
    return true;
}

static double piece_area(const piece *p, rad_vec3 normal)
{
    rad_vec3 sum = {0, 0, 0};
    for (unsigned k = 0; k < p->count; k++)
        sum = v3_add(sum, v3_cross(p->vertex[k], p->vertex[(k + 1) % p->count]));
    return 0.5 * v3_dot(sum, normal);
}

/* The shadow of one convex occluder (`corners`, `count` of them, flat) on the receiver's
 * plane (normal N . v = offset), seen from x at height H above it; false when it casts
 * none. Counter-clockwise about N. */
static bool project_shadow(rad_vec3 x, double H, rad_vec3 N, double offset,
                           const rad_vec3 *corners, unsigned count, double epsilon,
                           piece *shadow)
{
    piece occluder, low, slab;
    occluder.count = count;
    double top = H * (1 - 1e-9);
    bool behind = true, above = true, between = true;
    for (unsigned k = 0; k < count; k++) {
        occluder.vertex[k] = corners[k];
        double h = v3_dot(N, corners[k]) - offset;
        behind = behind && h <= epsilon;
        above = above && h >= top;
        between = between && h > epsilon && h < top;
    }
    if (behind || above)
        return false; /* wholly behind the receiver's plane, or not below the point */
    if (between) {
        slab = occluder; /* the common case: wholly in between */
    } else {
        /* between the plane and the point: epsilon < h < H (1 - 1e-9) */
        if (!clip_half_space(&occluder, N, offset + epsilon, &low) || low.count < 3)
            return false;
        if (!clip_half_space(&low, v3_scale(N, -1), -(offset + top), &slab) || slab.count < 3)
            return false;
    }
    shadow->count = slab.count;
    for (unsigned k = 0; k < slab.count; k++) {
        rad_vec3 P = slab.vertex[k];
        double h = v3_dot(N, P) - offset;
        shadow->vertex[k] = v3_add(x, v3_scale(v3_sub(P, x), H / (H - h)));
    }
    double area = piece_area(shadow, N);
    if (area < 0) {
        for (unsigned k = 0; k < shadow->count / 2; k++) {
            rad_vec3 swap = shadow->vertex[k];
            shadow->vertex[k] = shadow->vertex[shadow->count - 1 - k];
            shadow->vertex[shadow->count - 1 - k] = swap;
        }
    }
    return area != 0;
}

/* A convex shadow's edges as lines: inward[e] . v - offset[e] > 0 on its inner side;
 * an edge of no length (a repeated corner) has none (inward 0). */
typedef struct shadow_edges {
    rad_vec3 inward[PIECE_MAX_VERTICES];
    double offset[PIECE_MAX_VERTICES];
} shadow_edges;

static void edge_lines(const piece *shadow, rad_vec3 N, shadow_edges *edges)
{
    for (unsigned e = 0; e < shadow->count; e++) {
        rad_vec3 p0 = shadow->vertex[e], p1 = shadow->vertex[(e + 1) % shadow->count];
        edges->inward[e] = v3_cross(N, v3_sub(p1, p0));
        edges->offset[e] = v3_dot(edges->inward[e], p0);
    }
}

static inline bool no_line(rad_vec3 inward)
{
    return inward.x == 0 && inward.y == 0 && inward.z == 0;
}

/* True when the convex pieces a and b cannot overlap: an edge line of either has the
 * other wholly outside (both counter-clockwise about N; b's edge lines given). */
static bool separated(const piece *a, const piece *b, const shadow_edges *b_edges, rad_vec3 N)
{
    for (unsigned k = 0; k < a->count; k++) {
        rad_vec3 p0 = a->vertex[k], p1 = a->vertex[(k + 1) % a->count];
        rad_vec3 inward = v3_cross(N, v3_sub(p1, p0));
        if (no_line(inward))
            continue; /* a repeated corner: no edge, no side */
        double offset = v3_dot(inward, p0);
        bool outside = true;
        for (unsigned m = 0; m < b->count && outside; m++)
            outside = v3_dot(inward, b->vertex[m]) - offset <= 0;
        if (outside)
            return true;
    }
    for (unsigned k = 0; k < b->count; k++) {
        if (no_line(b_edges->inward[k]))
            continue;
        bool outside = true;
        for (unsigned m = 0; m < a->count && outside; m++)
            outside = v3_dot(b_edges->inward[k], a->vertex[m]) - b_edges->offset[k] <= 0;
        if (outside)
            return true;
    }
    return false;
}

/* Splits `in` along the line inward . v = offset into the part on its inner side (>= 0)
 * and the part outside (<= 0), as two clip_half_space calls would, in one pass; false
 * when either would have more than PIECE_MAX_VERTICES corners. */
static bool split_by_line(const piece *in, rad_vec3 inward, double offset, piece *inside,
                          piece *outside)
{
    double d[PIECE_MAX_VERTICES];
    for (unsigned k = 0; k < in->count; k++)
        d[k] = v3_dot(inward, in->vertex[k]) - offset;
    inside->count = outside->count = 0;
    for (unsigned k = 0; k < in->count; k++) {
        unsigned next = k + 1 == in->count ? 0 : k + 1;
        rad_vec3 a = in->vertex[k];
        double da = d[k], db = d[next];
        bool crosses = (da > 0 && db < 0) || (da < 0 && db > 0);
        if (inside->count + (da >= 0) + crosses > PIECE_MAX_VERTICES ||
            outside->count + (da <= 0) + crosses > PIECE_MAX_VERTICES)
            return false;
        if (da >= 0)
            inside->vertex[inside->count++] = a;
        if (da <= 0)
            outside->vertex[outside->count++] = a;
        if (crosses) {
            /* the same point either side: -da / (-da + db) is da / (da - db) bit for bit */
            rad_vec3 x = v3_lerp(a, in->vertex[next], da / (da - db));
            inside->vertex[inside->count++] = x;
            outside->vertex[outside->count++] = x;
        }
    }
    drop_repeated_corners(inside);
    drop_repeated_corners(outside);
    return true;
}

/* Subtracts the convex `shadow` (counter-clockwise about N) from the `count` pieces, into
 * `next`: the parts of each piece outside each shadow edge in turn, pieces of area at most
 * `tiny` dropped. Returns how many, or -1 past SHADOW_MAX_PIECES. */
static int subtract_shadow(const piece *pieces, unsigned count, const piece *shadow, rad_vec3 N,
                           double tiny, piece *next)
{
    shadow_edges edges;
    edge_lines(shadow, N, &edges);
    int made = 0;
    for (unsigned k = 0; k < count; k++) {
        if (separated(&pieces[k], shadow, &edges, N)) {
            if (made == SHADOW_MAX_PIECES)
                return -1;
            next[made++] = pieces[k];
            continue;
        }
        piece buffer[3];
        const piece *remaining = &pieces[k];
        for (unsigned e = 0; e < shadow->count && remaining->count >= 3; e++) {
            if (no_line(edges.inward[e]))
                continue;
            /* the part outside goes straight to `next` (a full `next` fails only when it
             * would be kept); what is inside goes on */
            piece *inside = remaining == &buffer[0] ? &buffer[1] : &buffer[0];
            piece *outside = made < SHADOW_MAX_PIECES ? &next[made] : &buffer[2];
            if (!split_by_line(remaining, edges.inward[e], edges.offset[e], inside, outside))
                return -1;
            if (outside->count >= 3 && piece_area(outside, N) > tiny) {
                if (made == SHADOW_MAX_PIECES)
                    return -1;
                made++;
            }
            remaining = inside;
        }
    }
    return made;
}

/* The factor from x past occluders given as corner lists: occluder o has count(o) corners
 * at corners(o). */
typedef struct occluder_list {
    const shadow_occluder *triangles; /* either triangles */
    const shadow_polygon *polygons;   /* or convex polygons */
    const uint32_t *index;            /* NULL: 0 .. count - 1; else index[0 .. count) */
    uint32_t count;
} occluder_list;

static double visible_factor(rad_vec3 x, rad_vec3 n, const vf_polygon *receiver,
                             const occluder_list *occluders, double plane_epsilon)
{
    rad_vec3 N = receiver->normal;
    double offset = v3_dot(N, receiver->vertex[0]);
    double H = v3_dot(N, x) - offset;
    if (H <= plane_epsilon)
        return 0;
    double tiny = 1e-12 * receiver->area;
    piece buffers[2][SHADOW_MAX_PIECES];
    piece *pieces = buffers[0], *next = buffers[1];
    unsigned count = 1;
    pieces[0].count = receiver->count;
    memcpy(pieces[0].vertex, receiver->vertex, receiver->count * sizeof(rad_vec3));
    drop_repeated_corners(&pieces[0]);
    for (uint32_t k = 0; k < occluders->count && count > 0; k++) {
        uint32_t o = occluders->index ? occluders->index[k] : k;
        piece shadow;
        const rad_vec3 *corners = occluders->triangles ? occluders->triangles[o].corner
                                                       : occluders->polygons[o].vertex;
        unsigned corner_count = occluders->triangles ? 3 : occluders->polygons[o].count;
        if (!project_shadow(x, H, N, offset, corners, corner_count, plane_epsilon, &shadow))
            continue;
        int made = subtract_shadow(pieces, count, &shadow, N, tiny, next);
        if (made < 0)
            return -1;
        piece *swap = pieces;
        pieces = next;
        next = swap;
        count = (unsigned)made;
    }
    double factor = 0;
    for (unsigned k = 0; k < count; k++)
        factor += contour_point_to_polygon(x, n, pieces[k].vertex, pieces[k].count, N,
                                           plane_epsilon);
    return factor;
}

double shadow_visible_factor(rad_vec3 x, rad_vec3 n, const vf_polygon *receiver,
                             const shadow_occluder *occluders, uint32_t occluder_count,
                             double plane_epsilon)
{
    occluder_list list = {occluders, NULL, NULL, occluder_count};
    return visible_factor(x, n, receiver, &list, plane_epsilon);
}

double shadow_visible_factor_polygons(rad_vec3 x, rad_vec3 n, const vf_polygon *receiver,
                                      const shadow_polygon *occluders, uint32_t occluder_count,
                                      double plane_epsilon)
{
    occluder_list list = {NULL, occluders, NULL, occluder_count};
    return visible_factor(x, n, receiver, &list, plane_epsilon);
}

double shadow_visible_factor_subset(rad_vec3 x, rad_vec3 n, const vf_polygon *receiver,
                                    const shadow_occluder *triangles,
                                    const shadow_polygon *polygons, const uint32_t *index,
                                    uint32_t count, double plane_epsilon)
{
    occluder_list list = {triangles, polygons, index, count};
    return visible_factor(x, n, receiver, &list, plane_epsilon);
}

/* Sine of the turn below which a corner of a joined occluder counts as straight (dropped)
 * and above which, turning the wrong way, as reflex (no join). */
#define JOIN_STRAIGHT 1e-12

/* Joins b into a across an edge they share (the same corners, bit for bit, run opposite
 * ways) when they lie in one plane and the union is convex with at most VF_MAX_VERTICES
 * corners; false, a unchanged, otherwise. */
static bool join_occluders(shadow_polygon *a, const shadow_polygon *b)
{
    for (unsigned i = 0; i < a->count; i++) {
        rad_vec3 u = a->vertex[i], v = a->vertex[(i + 1) % a->count];
        for (unsigned j = 0; j < b->count; j++) {
            rad_vec3 bj = b->vertex[j], bn = b->vertex[(j + 1) % b->count];
            if (!(bj.x == v.x && bj.y == v.y && bj.z == v.z && bn.x == u.x && bn.y == u.y &&
                  bn.z == u.z))
                continue;
            /* the first shared edge decides; most pairs share none, so the planes are
             * compared only now */
            rad_vec3 na = {0, 0, 0}, nb = {0, 0, 0};
            for (unsigned k = 0; k < a->count; k++)
                na = v3_add(na, v3_cross(a->vertex[k], a->vertex[(k + 1) % a->count]));
            for (unsigned k = 0; k < b->count; k++)
                nb = v3_add(nb, v3_cross(b->vertex[k], b->vertex[(k + 1) % b->count]));
            double la = v3_length(na), lb = v3_length(nb);
            if (!(la > 0) || !(lb > 0))
                return false;
            rad_vec3 normal = v3_scale(na, 1 / la);
            if (v3_dot(normal, v3_scale(nb, 1 / lb)) < 1 - JOIN_STRAIGHT)
                return false;
            rad_vec3 joined[2 * VF_MAX_VERTICES];
            unsigned n = 0;
            for (unsigned k = 0; k <= i; k++)
                joined[n++] = a->vertex[k];
            for (unsigned k = 2; k < b->count; k++) /* b from after u round to before v */
                joined[n++] = b->vertex[(j + k) % b->count];
            for (unsigned k = i + 1; k < a->count; k++)
                joined[n++] = a->vertex[k];
            /* b's corners off a's plane: not one flat polygon */
            double size = 0;
            for (unsigned k = 0; k < n; k++)
                size = fmax(size, v3_length(v3_sub(joined[k], joined[0])));
            for (unsigned k = 0; k < n; k++)
                if (fabs(v3_dot(normal, v3_sub(joined[k], joined[0]))) > JOIN_STRAIGHT * size)
                    return false;
            rad_vec3 kept[2 * VF_MAX_VERTICES];
            unsigned m = 0;
            for (unsigned k = 0; k < n; k++) {
                rad_vec3 in = v3_sub(joined[k], joined[(k + n - 1) % n]);
                rad_vec3 out = v3_sub(joined[(k + 1) % n], joined[k]);
                double turn = v3_dot(normal, v3_cross(in, out));
                double scale = v3_length(in) * v3_length(out);
                if (turn < -JOIN_STRAIGHT * scale)
                    return false; /* reflex */
                if (turn > JOIN_STRAIGHT * scale)
                    kept[m++] = joined[k];
            }
            if (m < 3 || m > VF_MAX_VERTICES)
                return false;
            memcpy(a->vertex, kept, m * sizeof(rad_vec3));
            a->count = m;
            return true;
        }
    }
    return false;
}

uint32_t shadow_join_occluders(const shadow_occluder *triangles, uint32_t count,
                               shadow_polygon *out)
{
    for (uint32_t k = 0; k < count; k++) {
        out[k].count = 3;
        memcpy(out[k].vertex, triangles[k].corner, 3 * sizeof(rad_vec3));
    }
    /* Joins, each time, the first pair (a, b) in order that joins, until none does; the
     * scan does not start again from (0, 1) after each join. Before row a every pair is
     * known not to join. A join into a changes only a (b takes the last polygon, which
     * already failed with every row before a), so the next pair in order is the first
     * (x, a), x < a, that joins, if any (x is then the changed one: the same again), else
     * in row a itself. */
    uint32_t a = 0;
    while (a < count) {
        uint32_t b = a + 1;
        while (b < count && !join_occluders(&out[a], &out[b]))
            b++;
        if (b == count) {
            a++;
            continue;
        }
        out[b] = out[--count];
        for (uint32_t x = 0; x < a;) {
            if (join_occluders(&out[x], &out[a])) {
                out[a] = out[--count];
                a = x;
                x = 0;
            } else {
                x++;
            }
        }
    }
    return count;
}

int shadow_window_remainder(const rad_vec3 *window, unsigned window_count, rad_vec3 normal,
                            const shadow_polygon *polygons, uint32_t polygon_count,
                            shadow_piece *left)
{
    if (window_count < 3 || window_count > PIECE_MAX_VERTICES)
        return -1;
    piece buffer[SHADOW_MAX_PIECES];
    piece *pieces = left, *next = buffer;
    unsigned count = 1;
    pieces[0].count = window_count;
    memcpy(pieces[0].vertex, window, window_count * sizeof(rad_vec3));
    double tiny = 1e-12 * fabs(piece_area(&pieces[0], normal));
    for (uint32_t t = 0; t < polygon_count && count > 0; t++) {
        const shadow_polygon *polygon = &polygons[t];
        piece shape = {.count = polygon->count};
        memcpy(shape.vertex, polygon->vertex, polygon->count * sizeof(rad_vec3));
        double area = piece_area(&shape, normal);
        if (area == 0)
            continue;
        if (area < 0)
            for (unsigned k = 0; k < polygon->count; k++)
                shape.vertex[k] = polygon->vertex[polygon->count - 1 - k];
        int made = subtract_shadow(pieces, count, &shape, normal, tiny, next);
        if (made < 0)
            return -1;
        piece *swap = pieces;
        pieces = next;
        next = swap;
        count = (unsigned)made;
    }
    if (pieces != left)
        memcpy(left, pieces, count * sizeof(piece));
    return (int)count;
}
