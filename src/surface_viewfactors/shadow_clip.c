/*
 * shadow_clip.c - point-to-polygon view factor behind occluders, see shadow_clip.h.
 */
#include "surface_viewfactors/shadow_clip.h"

#include <math.h>
#include <string.h>

#include "core/vec3.h"
#include "geometry/contour.h"
#include "geometry/flat_pieces.h"

#define PIECE_MAX_VERTICES SHADOW_PIECE_MAX_VERTICES

_Static_assert(SHADOW_PIECE_MAX_VERTICES <= CONTOUR_MAX_VERTICES - 1,
               "a piece is a polygon the contour integral takes");
_Static_assert(FLAT_PIECE_MAX_VERTICES == SHADOW_PIECE_MAX_VERTICES,
               "a piece in 3-D holds what it held in its plane");

typedef shadow_piece piece;

/* Corners within 1e-12 of the piece's extent of the corner before them dropped: a clip
 * through a corner makes its crossing point again, a hair away (flat_piece_drop_repeated
 * says why that matters). */
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

void shadow_receiver_prepare(const vf_polygon *receiver, shadow_receiver *out)
{
    out->frame = plane_frame_make(receiver->vertex[0], receiver->normal);
    out->offset = v3_dot(receiver->normal, receiver->vertex[0]);
    out->tiny = 1e-12 * receiver->area;
    out->whole.count = receiver->count;
    for (unsigned k = 0; k < receiver->count; k++)
        out->whole.vertex[k] = plane_frame_flat(&out->frame, receiver->vertex[k]);
    flat_piece_drop_repeated(&out->whole);
}

void shadow_caster_prepare(const shadow_receiver *r, const rad_vec3 *corners, unsigned count,
                           double plane_epsilon, shadow_caster *out)
{
    rad_vec3 N = r->frame.normal;
    piece occluder, above;
    occluder.count = count;
    bool some_low = false;
    for (unsigned k = 0; k < count; k++) {
        occluder.vertex[k] = corners[k];
        some_low = some_low || !(v3_dot(N, corners[k]) - r->offset > plane_epsilon);
    }
    /* most occluders lie wholly above; a wall standing on the receiver crosses its plane */
    const piece *cut = &occluder;
    if (some_low) {
        out->count = 0;
        if (!clip_half_space(&occluder, N, r->offset + plane_epsilon, &above) ||
            above.count < 3 || above.count > SHADOW_CASTER_MAX_VERTICES)
            return;
        cut = &above;
    }
    out->count = cut->count;
    for (unsigned k = 0; k < cut->count; k++) {
        out->at[k] = plane_frame_flat(&r->frame, cut->vertex[k]);
        out->height[k] = v3_dot(N, cut->vertex[k]) - r->offset;
    }
}

/* The caster's shadow on the receiver's plane seen from the point at height H above x_flat
 * (its part below the point, heights < H (1 - 1e-9), projected from the point);
 * false when it casts none. Counter-clockwise. */
static bool project_shadow(flat_point x_flat, double H, const shadow_caster *caster,
                           flat_piece *shadow)
{
    double top = H * (1 - 1e-9);
    bool above = true, some_high = false;
    for (unsigned k = 0; k < caster->count; k++) {
        above = above && caster->height[k] >= top;
        some_high = some_high || !(caster->height[k] < top);
    }
    if (caster->count < 3 || above)
        return false; /* nothing above the receiver's plane, or nothing below the point */
    flat_point at[SHADOW_CASTER_MAX_VERTICES + 1];
    double height[SHADOW_CASTER_MAX_VERTICES + 1];
    unsigned count = 0;
    if (some_high) {
        /* the part at heights <= top: corners and crossings in order */
        for (unsigned k = 0; k < caster->count; k++) {
            unsigned next = k + 1 == caster->count ? 0 : k + 1;
            double da = top - caster->height[k], db = top - caster->height[next];
            if (da >= 0) {
                at[count] = caster->at[k];
                height[count++] = caster->height[k];
            }
            if ((da > 0 && db < 0) || (da < 0 && db > 0)) {
                double t = da / (da - db);
                flat_point a = caster->at[k], b = caster->at[next];
                at[count] = (flat_point){a.u + (b.u - a.u) * t, a.v + (b.v - a.v) * t};
                height[count++] = caster->height[k] + (caster->height[next] - caster->height[k]) * t;
            }
        }
    } else {
        count = caster->count;
        for (unsigned k = 0; k < count; k++) {
            at[k] = caster->at[k];
            height[k] = caster->height[k];
        }
    }
    shadow->count = count;
    for (unsigned k = 0; k < count; k++) {
        double t = H / (H - height[k]);
        shadow->vertex[k] = (flat_point){x_flat.u + (at[k].u - x_flat.u) * t,
                                         x_flat.v + (at[k].v - x_flat.v) * t};
    }
    if (some_high) {
        flat_piece_drop_repeated(shadow);
        if (shadow->count < 3)
            return false;
    }
    double area = flat_piece_area(shadow);
    if (area < 0) {
        for (unsigned k = 0; k < shadow->count / 2; k++) {
            flat_point swap = shadow->vertex[k];
            shadow->vertex[k] = shadow->vertex[shadow->count - 1 - k];
            shadow->vertex[shadow->count - 1 - k] = swap;
        }
    }
    return area != 0;
}

/* Where the occluders come from: casters prepared for the receiver, or corner lists
 * (occluder o has count(o) corners at corners(o)) prepared as they are needed. */
typedef struct occluder_list {
    const shadow_caster *casters;     /* either casters */
    const shadow_occluder *triangles; /* or triangles */
    const shadow_polygon *polygons;   /* or convex polygons */
    const uint32_t *index;            /* NULL: 0 .. count - 1; else index[0 .. count) */
    uint32_t count;
} occluder_list;

static const shadow_caster *caster_of(const occluder_list *list, uint32_t k,
                                      const shadow_receiver *r, double plane_epsilon,
                                      shadow_caster *scratch)
{
    uint32_t o = list->index ? list->index[k] : k;
    if (list->casters)
        return &list->casters[o];
    if (list->triangles)
        shadow_caster_prepare(r, list->triangles[o].corner, 3, plane_epsilon, scratch);
    else
        shadow_caster_prepare(r, list->polygons[o].vertex, list->polygons[o].count,
                              plane_epsilon, scratch);
    return scratch;
}

/* pieces: room for max_pieces visible pieces. */
static double visible_factor(const shadow_receiver *r, rad_vec3 x, rad_vec3 n,
                             const occluder_list *occluders, double plane_epsilon,
                             flat_piece *pieces, unsigned max_pieces)
{
    rad_vec3 N = r->frame.normal;
    double H = v3_dot(N, x) - r->offset;
    if (H <= plane_epsilon)
        return 0;
    /* the shadows are cut from the receiver in its plane's own coordinates */
    flat_point x_flat = plane_frame_flat(&r->frame, x);
    unsigned count = 1;
    pieces[0] = r->whole;
    for (uint32_t k = 0; k < occluders->count && count > 0; k++) {
        shadow_caster scratch;
        flat_piece shadow;
        if (!project_shadow(x_flat, H, caster_of(occluders, k, r, plane_epsilon, &scratch),
                            &shadow))
            continue;
        int made = flat_subtract(pieces, count, &shadow, r->tiny, max_pieces);
        if (made < 0)
            return -1;
        count = (unsigned)made;
    }
    rad_vec3 n_local = v3(v3_dot(n, r->frame.u), v3_dot(n, r->frame.v), v3_dot(n, N));
    double factor = 0;
    for (unsigned k = 0; k < count; k++)
        factor += contour_point_to_flat_polygon(x_flat, H, n_local, pieces[k].vertex,
                                                pieces[k].count);
    return factor;
}

double shadow_visible_factor(rad_vec3 x, rad_vec3 n, const vf_polygon *receiver,
                             const shadow_occluder *occluders, uint32_t occluder_count,
                             double plane_epsilon)
{
    shadow_receiver r;
    shadow_receiver_prepare(receiver, &r);
    occluder_list list = {NULL, occluders, NULL, NULL, occluder_count};
    flat_piece pieces[SHADOW_MAX_PIECES];
    return visible_factor(&r, x, n, &list, plane_epsilon, pieces, SHADOW_MAX_PIECES);
}

double shadow_visible_factor_polygons(rad_vec3 x, rad_vec3 n, const vf_polygon *receiver,
                                      const shadow_polygon *occluders, uint32_t occluder_count,
                                      double plane_epsilon)
{
    shadow_receiver r;
    shadow_receiver_prepare(receiver, &r);
    occluder_list list = {NULL, NULL, occluders, NULL, occluder_count};
    flat_piece pieces[SHADOW_MAX_PIECES];
    return visible_factor(&r, x, n, &list, plane_epsilon, pieces, SHADOW_MAX_PIECES);
}

double shadow_receiver_factor(const shadow_receiver *receiver, rad_vec3 x, rad_vec3 n,
                              const shadow_caster *casters, const uint32_t *index,
                              uint32_t count, double plane_epsilon, flat_piece *pieces,
                              unsigned max_pieces)
{
    occluder_list list = {casters, NULL, NULL, index, count};
    return visible_factor(receiver, x, n, &list, plane_epsilon, pieces, max_pieces);
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

/* An occluder's bounding box: two that share an edge have boxes that touch. */
typedef struct join_box {
    rad_vec3 lo, hi;
} join_box;

static join_box box_of_polygon(const shadow_polygon *p)
{
    join_box box = {p->vertex[0], p->vertex[0]};
    for (unsigned k = 1; k < p->count; k++) {
        box.lo = v3(fmin(box.lo.x, p->vertex[k].x), fmin(box.lo.y, p->vertex[k].y),
                    fmin(box.lo.z, p->vertex[k].z));
        box.hi = v3(fmax(box.hi.x, p->vertex[k].x), fmax(box.hi.y, p->vertex[k].y),
                    fmax(box.hi.z, p->vertex[k].z));
    }
    return box;
}

/* join_occluders on out[a] and out[b], tried only when their boxes touch (a shared edge's
 * corners, equal bit for bit, lie in both): most pairs of a pair's occluders are told
 * apart by six comparisons instead of every edge against every edge, which took 8 % of
 * the 22k-surface city's time. */
static bool try_join(shadow_polygon *out, join_box *box, uint32_t a, uint32_t b)
{
    if (!box) /* more occluders than the boxes' room (an emitter's triangles) */
        return join_occluders(&out[a], &out[b]);
    const join_box *x = &box[a], *y = &box[b];
    if (x->hi.x < y->lo.x || y->hi.x < x->lo.x || x->hi.y < y->lo.y || y->hi.y < x->lo.y ||
        x->hi.z < y->lo.z || y->hi.z < x->lo.z)
        return false;
    if (!join_occluders(&out[a], &out[b]))
        return false;
    box[a] = (join_box){v3(fmin(x->lo.x, y->lo.x), fmin(x->lo.y, y->lo.y), fmin(x->lo.z, y->lo.z)),
                        v3(fmax(x->hi.x, y->hi.x), fmax(x->hi.y, y->hi.y), fmax(x->hi.z, y->hi.z))};
    return true;
}

/* Room for the boxes of as many occluders as an exact pair takes. */
#define JOIN_BOXES RAD_MAX_EXACT_OCCLUDERS

uint32_t shadow_join_occluders(const shadow_occluder *triangles, uint32_t count,
                               shadow_polygon *out)
{
    join_box room[JOIN_BOXES];
    join_box *box = count <= JOIN_BOXES ? room : NULL;
    for (uint32_t k = 0; k < count; k++) {
        out[k].count = 3;
        memcpy(out[k].vertex, triangles[k].corner, 3 * sizeof(rad_vec3));
        if (box)
            box[k] = box_of_polygon(&out[k]);
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
        while (b < count && !try_join(out, box, a, b))
            b++;
        if (b == count) {
            a++;
            continue;
        }
        --count;
        out[b] = out[count];
        if (box)
            box[b] = box[count];
        for (uint32_t x = 0; x < a;) {
            if (try_join(out, box, x, a)) {
                --count;
                out[a] = out[count];
                if (box)
                    box[a] = box[count];
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
    plane_frame frame = plane_frame_make(window[0], normal);
    flat_piece pieces[SHADOW_MAX_PIECES];
    unsigned count = 1;
    pieces[0].count = window_count;
    for (unsigned k = 0; k < window_count; k++)
        pieces[0].vertex[k] = plane_frame_flat(&frame, window[k]);
    double tiny = 1e-12 * fabs(flat_piece_area(&pieces[0]));
    for (uint32_t t = 0; t < polygon_count && count > 0; t++) {
        const shadow_polygon *polygon = &polygons[t];
        flat_piece shape = {.count = polygon->count};
        for (unsigned k = 0; k < polygon->count; k++)
            shape.vertex[k] = plane_frame_flat(&frame, polygon->vertex[k]);
        double area = flat_piece_area(&shape);
        if (area == 0)
            continue;
        if (area < 0)
            for (unsigned k = 0; k < polygon->count; k++)
                shape.vertex[k] = plane_frame_flat(&frame, polygon->vertex[polygon->count - 1 - k]);
        int made = flat_subtract(pieces, count, &shape, tiny, SHADOW_MAX_PIECES);
        if (made < 0)
            return -1;
        count = (unsigned)made;
    }
    for (unsigned k = 0; k < count; k++) {
        left[k].count = pieces[k].count;
        for (unsigned m = 0; m < pieces[k].count; m++)
            left[k].vertex[m] = plane_frame_point(&frame, pieces[k].vertex[m]);
    }
    return (int)count;
}
