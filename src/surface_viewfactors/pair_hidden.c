/*
 * pair_hidden.c - the exact "wholly hidden" test, see pair_hidden.h.
 */
#include "surface_viewfactors/pair_hidden.h"

#include <math.h>

#include "core/vec3.h"

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

static bool on_plane(const shadow_occluder *o, rad_vec3 n, double offset, double epsilon)
{
    for (int c = 0; c < 3; c++)
        if (fabs(v3_dot(n, o->corner[c]) - offset) > epsilon)
            return false;
    return true;
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

/* Most uncovered pieces of a window looked into, and most planes whose pieces are. */
#define MAX_PIECES_FOLLOWED 8u
#define PLANES_FOLLOWED 2u

static bool proven_hidden(const occluder_tree *tree, const vf_polygon *p, const vf_polygon *q,
                          const shadow_occluder *occluders, uint32_t occluder_count,
                          double plane_epsilon, unsigned depth);

/* The convex piece r of a plane as a polygon facing `toward` (a point off the plane), for
 * the occluder tree: its own triangles are none (source matches no triangle). */
static bool piece_polygon(const shadow_piece *r, rad_vec3 normal, rad_vec3 toward,
                          vf_polygon *out)
{
    if (r->count > VF_MAX_VERTICES)
        return false;
    *out = (vf_polygon){.count = r->count};
    for (unsigned k = 0; k < r->count; k++)
        out->vertex[k] = r->vertex[k];
    bool flip = v3_dot(normal, v3_sub(toward, r->vertex[0])) < 0;
    out->normal = flip ? v3_scale(normal, -1) : normal;
    out->source = UINT32_MAX - 1;
    return true;
}

/* Every segment from `a` to the piece (or from the piece to `a`) is blocked. */
static bool piece_hidden_from(const occluder_tree *tree, const vf_polygon *a,
                              const vf_polygon *piece, double plane_epsilon, unsigned depth)
{
    shadow_occluder found[PAIR_HIDDEN_MAX_OCCLUDERS];
    uint32_t count =
        occluder_tree_collect(tree, a, piece, plane_epsilon, found, PAIR_HIDDEN_MAX_OCCLUDERS);
    return count > 0 && proven_hidden(tree, a, piece, found, count, plane_epsilon, depth);
}

/* A candidate plane: an occluder's plane that separates p and q. */
typedef struct candidate {
    rad_vec3 normal;
    double offset;
    double uncovered; /* area its in-plane occluders leave of the window */
} candidate;

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

/* What the occluders lying in the plane (n, offset) leave of the window of p and q: the
 * pieces (into `left`), their count, or -1 (no window, or too many pieces). */
static int plane_remainder(const vf_polygon *p, const vf_polygon *q,
                           const shadow_occluder *occluders, uint32_t occluder_count,
                           rad_vec3 n, double offset, double plane_epsilon,
                           shadow_piece *left)
{
    shadow_occluder in_plane[PAIR_HIDDEN_MAX_OCCLUDERS];
    uint32_t count = 0;
    for (uint32_t j = 0; j < occluder_count; j++)
        if (on_plane(&occluders[j], n, offset, plane_epsilon))
            in_plane[count++] = occluders[j];
    rad_vec3 window[MAX_WINDOW];
    unsigned window_count = plane_window(p, q, n, offset, window);
    if (!window_count)
        return -1;
    return shadow_window_remainder(window, window_count, n, in_plane, count, left);
}

static bool proven_hidden(const occluder_tree *tree, const vf_polygon *p, const vf_polygon *q,
                          const shadow_occluder *occluders, uint32_t occluder_count,
                          double plane_epsilon, unsigned depth)
{
    if (occluder_count > PAIR_HIDDEN_MAX_OCCLUDERS)
        occluder_count = PAIR_HIDDEN_MAX_OCCLUDERS;
    bool tried[PAIR_HIDDEN_MAX_OCCLUDERS] = {false};
    shadow_piece left[SHADOW_MAX_PIECES];
    /* first every plane alone; then the planes that left the least, piece by piece */
    candidate best[PLANES_FOLLOWED];
    unsigned best_count = 0;
    for (uint32_t i = 0; i < occluder_count; i++) {
        if (tried[i])
            continue;
        tried[i] = true;
        const rad_vec3 *c = occluders[i].corner;
        rad_vec3 n = v3_cross(v3_sub(c[1], c[0]), v3_sub(c[2], c[0]));
        double length = v3_length(n);
        if (!(length > 0))
            continue;
        n = v3_scale(n, 1 / length);
        double offset = v3_dot(n, c[0]);
        int side_p = side_of(p, n, offset, plane_epsilon),
            side_q = side_of(q, n, offset, plane_epsilon);
        if (side_p == 0 || side_q == 0 || side_p == side_q)
            continue;
        for (uint32_t j = i + 1; j < occluder_count; j++)
            tried[j] = tried[j] || on_plane(&occluders[j], n, offset, plane_epsilon);
        int pieces = plane_remainder(p, q, occluders, occluder_count, n, offset, plane_epsilon,
                                     left);
        if (pieces == 0)
            return true;
        if (pieces < 0 || depth == 0 || (unsigned)pieces > MAX_PIECES_FOLLOWED)
            continue;
        double uncovered = pieces_area(left, pieces, n);
        candidate c_new = {n, offset, uncovered};
        unsigned at = best_count < PLANES_FOLLOWED ? best_count++ : PLANES_FOLLOWED;
        while (at > 0 && best[at - 1].uncovered > c_new.uncovered) {
            if (at < PLANES_FOLLOWED)
                best[at] = best[at - 1];
            at--;
        }
        if (at < PLANES_FOLLOWED)
            best[at] = c_new;
    }
    for (unsigned b = 0; b < best_count; b++) {
        int pieces = plane_remainder(p, q, occluders, occluder_count, best[b].normal,
                                     best[b].offset, plane_epsilon, left);
        bool all = pieces > 0 && (unsigned)pieces <= MAX_PIECES_FOLLOWED;
        for (int k = 0; k < pieces && all; k++) {
            vf_polygon to_p, to_q;
            all = piece_polygon(&left[k], best[b].normal, p->vertex[0], &to_p) &&
                  piece_polygon(&left[k], best[b].normal, q->vertex[0], &to_q) &&
                  (piece_hidden_from(tree, p, &to_p, plane_epsilon, depth - 1) ||
                   piece_hidden_from(tree, &to_q, q, plane_epsilon, depth - 1));
        }
        if (all)
            return true;
    }
    return false;
}

bool pair_proven_hidden(const occluder_tree *tree, const vf_polygon *p, const vf_polygon *q,
                        const shadow_occluder *occluders, uint32_t occluder_count,
                        double plane_epsilon)
{
    return proven_hidden(tree, p, q, occluders, occluder_count, plane_epsilon,
                         PAIR_HIDDEN_DEPTH);
}
