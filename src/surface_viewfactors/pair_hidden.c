/*
 * pair_hidden.c - the exact "wholly hidden" test, see pair_hidden.h.
 */
#include "surface_viewfactors/pair_hidden.h"

#include <math.h>
#include <string.h>

#include "core/vec3.h"
#include "surface_viewfactors/shadow_clip.h"
#include "trace/ray.h"

#define MAX_CROSSINGS (VF_MAX_VERTICES * VF_MAX_VERTICES)

/* Corners of the window as shadow_window_remainder takes them at most. */
#define MAX_WINDOW SHADOW_PIECE_MAX_VERTICES

/* +1 when every corner is in front of the plane beyond epsilon, -1 when every corner is
 * behind it, 0 otherwise. */
static int side_of(const vf_polygon *polygon, rad_vec3 n, double offset, double epsilon)
{
    bool front = true, back = true;
    for (unsigned k = 0; k < polygon->count; k++) {
        double d = v3_dot(n, polygon->vertex[k]) - offset;
        front = front && d > epsilon;
        back = back && d < -epsilon;
    }
    return front ? 1 : back ? -1 : 0;
}

typedef struct planar_point {
    double u, v;
    unsigned index;
} planar_point;

static int by_u_then_v(const planar_point *x, const planar_point *y)
{
    if (x->u != y->u)
        return x->u < y->u ? -1 : 1;
    return (x->v > y->v) - (x->v < y->v);
}

static double turn(const planar_point *o, const planar_point *a, const planar_point *b)
{
    return (a->u - o->u) * (b->v - o->v) - (a->v - o->v) * (b->u - o->u);
}

/* The convex hull of points lying in the plane of unit normal n, counter-clockwise about
 * n, collinear points dropped (monotone chain). Returns its corner count, 0 when it has
 * more than MAX_WINDOW or is degenerate. */
static unsigned window_hull(const rad_vec3 *points, unsigned count, rad_vec3 n,
                            rad_vec3 window[MAX_WINDOW])
{
    rad_vec3 helper = fabs(n.x) < 0.6 ? v3(1, 0, 0) : v3(0, 1, 0);
    rad_vec3 u = v3_normalize(v3_cross(helper, n)), v = v3_cross(n, u);
    planar_point sorted[MAX_CROSSINGS], hull[2 * MAX_CROSSINGS];
    for (unsigned k = 0; k < count; k++)
        sorted[k] = (planar_point){v3_dot(points[k], u), v3_dot(points[k], v), k};
    for (unsigned k = 1; k < count; k++) /* insertion sort: a few dozen points */
        for (unsigned m = k; m > 0 && by_u_then_v(&sorted[m], &sorted[m - 1]) < 0; m--) {
            planar_point swap = sorted[m];
            sorted[m] = sorted[m - 1];
            sorted[m - 1] = swap;
        }
    unsigned h = 0;
    for (unsigned k = 0; k < count; k++) {
        while (h >= 2 && turn(&hull[h - 2], &hull[h - 1], &sorted[k]) <= 0)
            h--;
        hull[h++] = sorted[k];
    }
    for (unsigned k = count - 1, lower = h + 1; k-- > 0;) {
        while (h >= lower && turn(&hull[h - 2], &hull[h - 1], &sorted[k]) <= 0)
            h--;
        hull[h++] = sorted[k];
    }
    h--; /* the last point is the first again */
    if (h < 3 || h > MAX_WINDOW)
        return 0;
    for (unsigned k = 0; k < h; k++)
        window[k] = points[hull[k].index];
    return h;
}

static double pieces_area(const shadow_piece *pieces, int count, rad_vec3 n)
{
    double area = 0;
    for (int k = 0; k < count; k++) {
        rad_vec3 sum = {0, 0, 0};
        for (unsigned m = 0; m < pieces[k].count; m++)
            sum = v3_add(sum, v3_cross(pieces[k].vertex[m],
                                       pieces[k].vertex[(m + 1) % pieces[k].count]));
        area += 0.5 * fabs(v3_dot(sum, n));
    }
    return area;
}

/* The window of p and q in the plane (n, offset) that separates them: the hull of where
 * the segments between their corners cross it. Returns its corner count, 0 when there is
 * none to test. */
static unsigned plane_window(const vf_polygon *p, const vf_polygon *q, rad_vec3 n,
                             double offset, rad_vec3 window[MAX_WINDOW])
{
    rad_vec3 crossings[MAX_CROSSINGS];
    unsigned crossing_count = 0;
    for (unsigned a = 0; a < p->count; a++)
        for (unsigned b = 0; b < q->count; b++) {
            rad_vec3 x = p->vertex[a], y = q->vertex[b];
            double hx = v3_dot(n, x) - offset, hy = v3_dot(n, y) - offset;
            crossings[crossing_count++] = v3_lerp(x, y, hx / (hx - hy));
        }
    return window_hull(crossings, crossing_count, n, window);
}

/* Most shapes of one plane a window is tested against (the first found along the plane's
 * axis): fewer only proves less. */
#define MAX_IN_PLANE 256u

/* Slack of the inside test, as a share of the window's extent: rounding where the crossing
 * points are worked out (shadow_window_remainder drops slivers of 1e-12 of the window's
 * area alike). */
#define INSIDE_SLACK 1e-12

/* True when every one of the `count` points (lying in the plane of unit normal n) is inside
 * the convex shape (either way round) or within `slack` of it. */
static bool shape_contains(const shadow_polygon *shape, rad_vec3 n, const rad_vec3 *points,
                           unsigned count, double slack)
{
    rad_vec3 sum = {0, 0, 0};
    for (unsigned m = 0; m < shape->count; m++)
        sum = v3_add(sum, v3_cross(shape->vertex[m], shape->vertex[(m + 1) % shape->count]));
    double orientation = v3_dot(sum, n);
    if (orientation == 0)
        return false;
    for (unsigned m = 0; m < shape->count; m++) {
        rad_vec3 a = shape->vertex[m], b = shape->vertex[(m + 1) % shape->count];
        rad_vec3 edge = v3_sub(b, a);
        /* n x edge points inwards when the shape runs counter-clockwise about n */
        rad_vec3 inward = v3_cross(n, edge);
        if (orientation < 0)
            inward = v3_scale(inward, -1);
        double least = -slack * v3_length(edge);
        for (unsigned k = 0; k < count; k++)
            if (v3_dot(inward, v3_sub(points[k], a)) < least)
                return false;
    }
    return true;
}

/* The largest extent along x, y or z of the points. */
static double points_extent(const rad_vec3 *points, unsigned count)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (unsigned k = 0; k < count; k++) {
        double x[3] = {points[k].x, points[k].y, points[k].z};
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], x[a]);
            hi[a] = fmax(hi[a], x[a]);
        }
    }
    return fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
}

/* What the shapes of group g leave of the window of p and q in its plane (n, offset):
 * the pieces (into `left`), their count, or -1 (no window, or too many pieces). When they
 * leave nothing and `cover` is not NULL, *cover receives a shape that alone covers the
 * window, or UINT32_MAX. */
static int plane_remainder(const pair_hidden_context *c, uint32_t g, const vf_polygon *p,
                           const vf_polygon *q, shadow_piece *left, uint32_t *cover)
{
    const coplanar_group *group = &c->planes->groups[g];
    rad_vec3 n = group->normal;
    double offset = group->offset, eps = c->plane_epsilon;
    rad_vec3 window[MAX_WINDOW];
    unsigned window_count = plane_window(p, q, n, offset, window);
    if (!window_count)
        return -1;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (unsigned k = 0; k < window_count; k++) {
        double x[3] = {window[k].x, window[k].y, window[k].z};
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], x[a] - eps);
            hi[a] = fmax(hi[a], x[a] + eps);
        }
    }
    uint32_t begin, end;
    coplanar_polygons_range(c->planes, g, lo[group->axis], hi[group->axis], &begin, &end);
    shadow_polygon in_plane[MAX_IN_PLANE];
    uint32_t shape_index[MAX_IN_PLANE];
    uint32_t count = 0;
    for (uint32_t k = begin; k < end && count < MAX_IN_PLANE; k++) {
        const coplanar_box *box = &c->planes->box[k];
        bool outside = false;
        for (int a = 0; a < 3 && !outside; a++)
            outside = box->hi[a] < lo[a] || box->lo[a] > hi[a];
        if (!outside && box->flat) {
            shape_index[count] = k;
            in_plane[count++] = c->planes->shape[k];
        }
    }
    if (count == 0)
        return -1;
    int pieces = shadow_window_remainder(window, window_count, n, in_plane, count, left);
    if (pieces == 0 && cover) {
        *cover = UINT32_MAX;
        double slack = INSIDE_SLACK * points_extent(window, window_count);
        for (uint32_t k = 0; k < count && *cover == UINT32_MAX; k++)
            if (shape_contains(&in_plane[k], n, window, window_count, slack))
                *cover = shape_index[k];
    }
    return pieces;
}

/* True when shape k of group g alone hides q from p: they lie strictly on either side of
 * its plane and every segment between their corners crosses it inside the shape. */
static bool shape_hides(const pair_hidden_context *c, uint32_t g, uint32_t k,
                        const vf_polygon *p, const vf_polygon *q)
{
    const coplanar_group *group = &c->planes->groups[g];
    rad_vec3 n = group->normal;
    double offset = group->offset;
    int side_q = side_of(q, n, offset, c->plane_epsilon);
    if (side_q == 0 || side_of(p, n, offset, c->plane_epsilon) != -side_q)
        return false;
    rad_vec3 crossings[MAX_CROSSINGS];
    unsigned count = 0;
    for (unsigned a = 0; a < p->count; a++)
        for (unsigned b = 0; b < q->count; b++) {
            rad_vec3 x = p->vertex[a], y = q->vertex[b];
            double hx = v3_dot(n, x) - offset, hy = v3_dot(n, y) - offset;
            crossings[count++] = v3_lerp(x, y, hx / (hx - hy));
        }
    double slack = INSIDE_SLACK * points_extent(crossings, count);
    return shape_contains(&c->planes->shape[k], n, crossings, count, slack);
}

/* A probe point of the polygon: `share` of the way from its centroid to corner 0, or to
 * the corner opposite. */
static rad_vec3 probe_point(const vf_polygon *polygon, unsigned which, double share)
{
    rad_vec3 corner = polygon->vertex[which == 0 ? 0 : polygon->count / 2];
    return v3_lerp(polygon->centroid, corner, share);
}

/* The probe segments' points: PROBE_SHARE of the way out; a segment that gets through is
 * cast again once from PROBE_SHARE_AGAIN before it counts as through. A tracer need not be
 * watertight where triangles meet, and symmetric shapes put segments exactly there (two
 * unit squares facing each other across a wall of 0.75 quads cross it at a corner four
 * quads share, which Embree let through on one machine and not on another). */
#define PROBE_SHARE 0.8
#define PROBE_SHARE_AGAIN 0.7305

static void probe_segment(const vf_polygon *p, const vf_polygon *q, unsigned k, double share,
                          rad_ray *ray)
{
    unsigned a = k / 4, b = (k / 2) % 2;
    rad_vec3 x = probe_point(p, a, share), y = probe_point(q, b, share);
    if (k % 2 == 0)
        ray_set(ray, x, v3_sub(y, x), RAD_SEGMENT_END_EPSILON, 1 - RAD_SEGMENT_END_EPSILON);
    else
        ray_set(ray, y, v3_sub(x, y), RAD_SEGMENT_END_EPSILON, 1 - RAD_SEGMENT_END_EPSILON);
}

/* Triangles each probe segment reports at most (the first it crosses, then the next...). */
#define PROBE_HITS 3u
#define PROBE_GROUPS PAIR_HIDDEN_MAX_PLANES

/* Casts the probe segments between p and q, both ways: false when one gets through; else
 * the groups of the triangles they hit first from either end go to groups[] (distinct;
 * their count in *count). */
static bool probe(const pair_hidden_context *c, const vf_polygon *p, const vf_polygon *q,
                  uint32_t groups[PROBE_GROUPS], unsigned *count,
                  pair_hidden_work *work)
{
    rad_ray rays[2 * PAIR_HIDDEN_PROBES], again_rays[2 * PAIR_HIDDEN_PROBES];
    rad_hit hits[2 * PAIR_HIDDEN_PROBES], again_hits[2 * PAIR_HIDDEN_PROBES];
    unsigned n = 2 * PAIR_HIDDEN_PROBES, through[2 * PAIR_HIDDEN_PROBES], missed = 0;
    for (unsigned k = 0; k < n; k++)
        probe_segment(p, q, k, PROBE_SHARE, &rays[k]);
    rad_tracer_intersect(c->tracer, rays, n, hits);
    work->rays += n;
    for (unsigned k = 0; k < n; k++)
        if (hits[k].triangle == RAD_NO_HIT) {
            probe_segment(p, q, k, PROBE_SHARE_AGAIN, &again_rays[missed]);
            through[missed++] = k;
        }
    if (missed > 0) {
        rad_tracer_intersect(c->tracer, again_rays, missed, again_hits);
        work->rays += missed;
        for (unsigned m = 0; m < missed; m++) {
            if (again_hits[m].triangle == RAD_NO_HIT)
                return false;
            rays[through[m]] = again_rays[m];
            hits[through[m]] = again_hits[m];
        }
    }
    *count = 0;
    unsigned times[PROBE_GROUPS];
    /* the triangles each segment crosses after its first, up to PROBE_HITS */
    for (unsigned round = 0;; round++) {
        for (unsigned k = 0; k < n; k++) {
            if (hits[k].triangle == RAD_NO_HIT)
                continue;
            uint32_t g = c->planes->group_of[hits[k].triangle];
            bool known = g == UINT32_MAX;
            for (unsigned m = 0; m < *count && !known; m++)
                if (groups[m] == g) {
                    known = true;
                    times[m]++;
                }
            if (!known && *count < PROBE_GROUPS) {
                times[*count] = 1;
                groups[(*count)++] = g;
            }
        }
        if (round + 1 == PROBE_HITS)
            break;
        unsigned again = 0;
        for (unsigned k = 0; k < n; k++)
            if (hits[k].triangle != RAD_NO_HIT) {
                rays[again] = rays[k];
                rays[again++].t_near = hits[k].t + 1e-4f;
            }
        rad_tracer_intersect(c->tracer, rays, again, hits);
        work->rays += again;
        n = again;
    }
    /* the planes crossed most often first (stable: ties keep the order found) */
    for (unsigned k = 1; k < *count; k++)
        for (unsigned m = k; m > 0 && times[m] > times[m - 1]; m--) {
            unsigned t = times[m];
            times[m] = times[m - 1];
            times[m - 1] = t;
            uint32_t g = groups[m];
            groups[m] = groups[m - 1];
            groups[m - 1] = g;
        }
    return true;
}

/* The convex polygon cut in two across its longest extent, at its middle; false when a
 * half would have more than VF_MAX_VERTICES corners or no area. */
static bool halve(const vf_polygon *polygon, vf_polygon half[2])
{
    rad_vec3 a = polygon->vertex[0], b = polygon->vertex[0];
    double longest = 0;
    for (unsigned i = 0; i < polygon->count; i++)
        for (unsigned j = i + 1; j < polygon->count; j++) {
            double d = v3_length(v3_sub(polygon->vertex[i], polygon->vertex[j]));
            if (d > longest)
                longest = d, a = polygon->vertex[i], b = polygon->vertex[j];
        }
    if (!(longest > 0))
        return false;
    rad_vec3 axis = v3_scale(v3_sub(b, a), 1 / longest);
    double middle = 0.5 * (v3_dot(axis, a) + v3_dot(axis, b));
    for (int side = 0; side < 2; side++) {
        double sign = side ? -1 : 1;
        vf_polygon *h = &half[side];
        *h = *polygon;
        unsigned count = 0;
        for (unsigned k = 0; k < polygon->count; k++) {
            rad_vec3 x = polygon->vertex[k], y = polygon->vertex[(k + 1) % polygon->count];
            double dx = sign * (v3_dot(axis, x) - middle), dy = sign * (v3_dot(axis, y) - middle);
            if (dx <= 0) {
                if (count == VF_MAX_VERTICES)
                    return false;
                h->vertex[count++] = x;
            }
            if ((dx < 0 && dy > 0) || (dx > 0 && dy < 0)) {
                if (count == VF_MAX_VERTICES)
                    return false;
                h->vertex[count++] = v3_lerp(x, y, dx / (dx - dy));
            }
        }
        if (count < 3)
            return false;
        h->count = count;
        vf_polygon_finish(h);
        if (!(h->area > 0))
            return false;
    }
    return true;
}

/* The convex piece r of a plane (normal n) as a polygon facing the point `toward`, off the
 * plane; false when it has more than VF_MAX_VERTICES corners. */
static bool piece_polygon(const shadow_piece *r, rad_vec3 n, rad_vec3 toward, vf_polygon *out)
{
    if (r->count > VF_MAX_VERTICES || r->count < 3)
        return false;
    memset(out, 0, sizeof(*out));
    out->count = r->count;
    bool flip = v3_dot(n, v3_sub(toward, r->vertex[0])) < 0;
    out->normal = flip ? v3_scale(n, -1) : n;
    /* counter-clockwise about its normal: the piece is counter-clockwise about n */
    for (unsigned k = 0; k < r->count; k++)
        out->vertex[k] = r->vertex[flip ? r->count - 1 - k : k];
    out->surface = out->source = UINT32_MAX - 1;
    vf_polygon_finish(out);
    return out->area > 0;
}

/* Separating planes whose coverage is worked out per sub-pair at most. */
#define PLANES_TRIED 6u

/* Planes whose uncovered pieces are looked into, and most pieces per plane. */
#define PLANES_FOLLOWED 2u
#define MAX_PIECES_FOLLOWED 4u

typedef struct candidate {
    uint32_t group;
    double uncovered; /* area its triangles leave of the window */
    int count;        /* the pieces they leave */
    shadow_piece piece[MAX_PIECES_FOLLOWED];
} candidate;


/* Group g among the planes a proof used (once). */
static void note_used(pair_hidden_planes *used, uint32_t g)
{
    for (unsigned k = 0; k < used->count; k++)
        if (used->group[k] == g)
            return;
    if (used->count < PAIR_HIDDEN_MAX_PLANES)
        used->group[used->count++] = g;
}

/* cover: NULL, or where the group and shape go when one shape of a plane alone covers the
 * window of p and q themselves (the caller's pair, not a piece or half); left untouched
 * otherwise. used: receives the planes that settled the proof or a part of it. */
static bool hidden(const pair_hidden_context *c, const pair_hidden_planes *planes, bool probe_all,
                   const vf_polygon *p, const vf_polygon *q, unsigned depth,
                   unsigned *proofs_left, pair_hidden_work *work, uint32_t cover[2],
                   pair_hidden_planes *used)
{
    if (*proofs_left == 0)
        return false;
    (*proofs_left)--;
    work->proofs++;
    pair_hidden_planes own;
    if (probe_all && depth != PAIR_HIDDEN_MAX_DEPTH) {
        if (!probe(c, p, q, own.group, &own.count, work))
            return false;
        planes = &own;
    }
    const uint32_t *groups = planes->group;
    unsigned group_count = planes->count;
    shadow_piece left[SHADOW_MAX_PIECES];
    candidate best[PLANES_FOLLOWED];
    unsigned best_count = 0;
    double p_distance = 0, q_distance = 0;
    /* the planes crossed most often first, PLANES_TRIED that separate p and q at most */
    unsigned tried = 0;
    for (unsigned k = 0; k < group_count && tried < PLANES_TRIED; k++) {
        const coplanar_group *group = &c->planes->groups[groups[k]];
        int side_p = side_of(p, group->normal, group->offset, c->plane_epsilon),
            side_q = side_of(q, group->normal, group->offset, c->plane_epsilon);
        if (side_p == 0 || side_q == 0 || side_p == side_q)
            continue;
        tried++;
        uint32_t shape = UINT32_MAX;
        int pieces = plane_remainder(c, groups[k], p, q, left, cover ? &shape : NULL);
        if (pieces == 0) {
            note_used(used, groups[k]);
            if (cover && shape != UINT32_MAX) {
                cover[0] = groups[k];
                cover[1] = shape;
            }
            return true;
        }
        if (pieces < 0)
            continue;
        double uncovered = pieces_area(left, pieces, group->normal);
        if (best_count == 0 || uncovered < best[0].uncovered) {
            p_distance = fabs(v3_dot(group->normal, p->centroid) - group->offset);
            q_distance = fabs(v3_dot(group->normal, q->centroid) - group->offset);
        }
        if (depth == 0 || (unsigned)pieces > MAX_PIECES_FOLLOWED)
            continue;
        unsigned at = best_count < PLANES_FOLLOWED ? best_count++ : PLANES_FOLLOWED;
        while (at > 0 && best[at - 1].uncovered > uncovered) {
            if (at < PLANES_FOLLOWED)
                best[at] = best[at - 1];
            at--;
        }
        if (at < PLANES_FOLLOWED) {
            best[at].group = groups[k];
            best[at].uncovered = uncovered;
            best[at].count = pieces;
            memcpy(best[at].piece, left, (size_t)pieces * sizeof(*left));
        }
    }
    if (depth == 0)
        return false;
    /* a segment through an uncovered piece is blocked when the piece is hidden from p or
     * from q */
    for (unsigned b = 0; b < best_count; b++) {
        const coplanar_group *group = &c->planes->groups[best[b].group];
        bool all = true;
        for (int k = 0; k < best[b].count && all; k++) {
            vf_polygon to_p, to_q;
            all = piece_polygon(&best[b].piece[k], group->normal, p->centroid, &to_p) &&
                  piece_polygon(&best[b].piece[k], group->normal, q->centroid, &to_q) &&
                  (hidden(c, planes, probe_all, &to_q, q, depth - 1, proofs_left, work, NULL,
                          used) ||
                   hidden(c, planes, probe_all, p, &to_p, depth - 1, proofs_left, work, NULL,
                          used));
        }
        if (all) {
            note_used(used, best[b].group);
            return true;
        }
    }
    /* halve the polygon that widens the window more: p's size counts in proportion to
     * the plane's distance from q, and the other way round */
    bool split_p = p_distance > 0 || q_distance > 0
                       ? p->radius * q_distance >= q->radius * p_distance
                       : p->radius >= q->radius;
    vf_polygon half[2];
    if (!halve(split_p ? p : q, half))
        return false;
    for (int k = 0; k < 2; k++)
        if (!hidden(c, planes, probe_all, split_p ? &half[k] : p, split_p ? q : &half[k],
                    depth - 1, proofs_left, work, NULL, used))
            return false;
    return true;
}

/* Shape k of group g to the front of p's remembered shapes (added when new, the least
 * recently useful dropped when full). */
static void remember_shape(pair_hidden_memory *memory, const vf_polygon *p, uint32_t g,
                           uint32_t k)
{
    if (memory->shapes_of != p) {
        memory->shapes_of = p;
        memory->shape_count = 0;
    }
    unsigned at = 0;
    while (at < memory->shape_count && memory->shape[at] != k)
        at++;
    if (at == memory->shape_count) {
        if (memory->shape_count < PAIR_HIDDEN_SHAPES)
            memory->shape_count++;
        at = memory->shape_count - 1;
    }
    for (; at > 0; at--) {
        memory->shape[at] = memory->shape[at - 1];
        memory->shape_group[at] = memory->shape_group[at - 1];
    }
    memory->shape[0] = k;
    memory->shape_group[0] = g;
}

bool pair_hidden_by_remembered_shape(const pair_hidden_context *context,
                                     pair_hidden_memory *memory, const vf_polygon *p,
                                     const vf_polygon *q)
{
    if (!memory || memory->shapes_of != p)
        return false;
    for (unsigned k = 0; k < memory->shape_count; k++)
        if (shape_hides(context, memory->shape_group[k], memory->shape[k], p, q)) {
            if (k > 0)
                remember_shape(memory, p, memory->shape_group[k], memory->shape[k]);
            memory->shape_proofs++;
            return true;
        }
    return false;
}

bool pair_proven_hidden(const pair_hidden_context *context, pair_hidden_memory *memory,
                        const vf_polygon *p, const vf_polygon *q, pair_hidden_work *work)
{
    if (pair_hidden_by_remembered_shape(context, memory, p, q))
        return true;
    unsigned proofs_left = PAIR_HIDDEN_MAX_PROOFS;
    uint32_t cover[2] = {UINT32_MAX, UINT32_MAX};
    pair_hidden_planes used = {.count = 0};
    bool remembered = memory && memory->p == p;
    /* the planes the last proof used first, with no probe, one level of pieces or halves at
     * most */
    if (remembered && memory->planes.count > 0) {
        if (hidden(context, &memory->planes, false, p, q, PAIR_HIDDEN_REMEMBERED_DEPTH,
                   &proofs_left, work, cover, &used)) {
            work->remembered++;
            if (cover[1] != UINT32_MAX)
                remember_shape(memory, p, cover[0], cover[1]);
            return true;
        }
        proofs_left = PAIR_HIDDEN_MAX_PROOFS;
    }
    /* the planes of the pair's probes at the top, each sub-pair's own below */
    pair_hidden_planes planes;
    if (!probe(context, p, q, planes.group, &planes.count, work))
        return false;
    used.count = 0;
    bool proven = hidden(context, &planes, true, p, q, PAIR_HIDDEN_MAX_DEPTH, &proofs_left, work,
                         cover, &used);
    if (proven && memory) {
        memory->p = p;
        memory->planes = used;
        memory->probed = planes;
        if (cover[1] != UINT32_MAX)
            remember_shape(memory, p, cover[0], cover[1]);
        return true;
    }
    /* last, every plane the last proof's probes found, as above */
    if (!proven && remembered && memory->probed.count > 0) {
        proofs_left = PAIR_HIDDEN_MAX_PROOFS;
        cover[1] = UINT32_MAX;
        if (hidden(context, &memory->probed, false, p, q, PAIR_HIDDEN_REMEMBERED_DEPTH,
                   &proofs_left, work, cover, &used)) {
            work->remembered++;
            if (cover[1] != UINT32_MAX)
                remember_shape(memory, p, cover[0], cover[1]);
            return true;
        }
    }
    return proven;
}
