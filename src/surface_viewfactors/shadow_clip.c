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

/* Keeps the part of `in` where dot(normal, v) - offset >= 0 (into `out`); false when
 * the result would have more than PIECE_MAX_VERTICES corners. */
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
    return true;
}

static double piece_area(const piece *p, rad_vec3 normal)
{
    rad_vec3 sum = {0, 0, 0};
    for (unsigned k = 0; k < p->count; k++)
        sum = v3_add(sum, v3_cross(p->vertex[k], p->vertex[(k + 1) % p->count]));
    return 0.5 * v3_dot(sum, normal);
}

/* The shadow of one occluder on the receiver's plane (normal N . v = offset), seen from x
 * at height H above it; false when it casts none. Counter-clockwise about N. */
static bool project_shadow(rad_vec3 x, double H, rad_vec3 N, double offset,
                           const shadow_occluder *o, double epsilon, piece *shadow)
{
    piece triangle = {{o->corner[0], o->corner[1], o->corner[2]}, 3}, low, slab;
    double top = H * (1 - 1e-9);
    double h0 = v3_dot(N, o->corner[0]) - offset, h1 = v3_dot(N, o->corner[1]) - offset,
           h2 = v3_dot(N, o->corner[2]) - offset;
    if ((h0 <= epsilon && h1 <= epsilon && h2 <= epsilon) || (h0 >= top && h1 >= top && h2 >= top))
        return false; /* wholly behind the receiver's plane, or not below the point */
    if (h0 > epsilon && h1 > epsilon && h2 > epsilon && h0 < top && h1 < top && h2 < top) {
        slab = triangle; /* the common case: wholly in between */
    } else {
        /* between the plane and the point: epsilon < h < H (1 - 1e-9) */
        if (!clip_half_space(&triangle, N, offset + epsilon, &low) || low.count < 3)
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

/* True when the convex pieces a and b cannot overlap: an edge line of either has the
 * other wholly outside (both counter-clockwise about N). */
static bool separated(const piece *a, const piece *b, rad_vec3 N)
{
    for (int pass = 0; pass < 2; pass++) {
        const piece *edges = pass ? b : a, *other = pass ? a : b;
        for (unsigned k = 0; k < edges->count; k++) {
            rad_vec3 p0 = edges->vertex[k], p1 = edges->vertex[(k + 1) % edges->count];
            rad_vec3 inward = v3_cross(N, v3_sub(p1, p0));
            double offset = v3_dot(inward, p0);
            bool outside = true;
            for (unsigned m = 0; m < other->count && outside; m++)
                outside = v3_dot(inward, other->vertex[m]) - offset <= 0;
            if (outside)
                return true;
        }
    }
    return false;
}

/* Subtracts the convex `shadow` (counter-clockwise about N) from the `count` pieces, into
 * `next`: the parts of each piece outside each shadow edge in turn, pieces of area at most
 * `tiny` dropped. Returns how many, or -1 past SHADOW_MAX_PIECES. */
static int subtract_shadow(const piece *pieces, unsigned count, const piece *shadow, rad_vec3 N,
                           double tiny, piece *next)
{
    int made = 0;
    for (unsigned k = 0; k < count; k++) {
        if (separated(&pieces[k], shadow, N)) {
            if (made == SHADOW_MAX_PIECES)
                return -1;
            next[made++] = pieces[k];
            continue;
        }
        piece remaining = pieces[k];
        for (unsigned e = 0; e < shadow->count && remaining.count >= 3; e++) {
            rad_vec3 p0 = shadow->vertex[e], p1 = shadow->vertex[(e + 1) % shadow->count];
            rad_vec3 inward = v3_cross(N, v3_sub(p1, p0));
            double edge_offset = v3_dot(inward, p0);
            piece outside, inside;
            if (!clip_half_space(&remaining, v3_scale(inward, -1), -edge_offset, &outside) ||
                !clip_half_space(&remaining, inward, edge_offset, &inside))
                return -1;
            if (outside.count >= 3 && piece_area(&outside, N) > tiny) {
                if (made == SHADOW_MAX_PIECES)
                    return -1;
                next[made++] = outside;
            }
            remaining = inside;
        }
    }
    return made;
}

double shadow_visible_factor(rad_vec3 x, rad_vec3 n, const vf_polygon *receiver,
                             const shadow_occluder *occluders, uint32_t occluder_count,
                             double plane_epsilon)
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
    for (uint32_t o = 0; o < occluder_count && count > 0; o++) {
        piece shadow;
        if (!project_shadow(x, H, N, offset, &occluders[o], plane_epsilon, &shadow))
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
