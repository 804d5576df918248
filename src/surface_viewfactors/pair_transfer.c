/*
 * pair_transfer.c - polygon-to-polygon transfer, see pair_transfer.h.
 */
#include "surface_viewfactors/pair_transfer.h"

#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/random.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "geometry/contour.h"
#include "geometry/parallelogram_integral.h"
#include "geometry/polygon_integral.h"
#include "surface_viewfactors/occluder_tree.h"
#include "trace/ray.h"

/* Deepest subdivision of the outer triangle: 4^12 cells would be far past any need. */
#define MAX_DEPTH 12

/* The same behind occluders, where the integrand has kinks along penumbra edges and each
 * point costs more: what is left at this depth is reported in the error bound. */
#define OBSTRUCTED_MAX_DEPTH 8

/* The strips' deepest split either way behind occluders (parallelogram_integral.h): a strip
 * halves one direction, a few cells a level along a kink where a triangle's depth d costs
 * 4^d. At 8 the --sky-exact tiles of the 150-surface generated city stopped short of their
 * targets (38 of its 150 sky view factors short, the largest bound 2.3e-4); at 10 none
 * are, and the 1k city's matrix moves by 1.6e-8 at most. */
#define OBSTRUCTED_MAX_SPLITS 10

/* A triangle of the outer polygon that something may shade is split at least this many
 * times before the quadrature believes its rules' agreement, and f at its corners and edge
 * midpoints must agree with what its rule points predict (polygon_integral's edge check:
 * light through a gap can reach only a sliver along an edge, as below a tube's rim), in
 * pair_obstructed_exact_within. pair_obstructed_exact (the patches' form factors, on a
 * budget of a millisecond) has neither. */
#define OBSTRUCTED_MIN_DEPTH 2

/* Exact shadow clipping may spend this many (point, occluder) clippings on one pair, about
 * a millisecond, by default (pair_obstructed_exact); a pair that needs more is sampled
 * instead, so the run time stays predictable. */
#define EXACT_WORK_BUDGET 4096u

/* Largest k of a round's k x k stratified segments per replicate. */
#define MAX_STRATA 32u

typedef struct outer_context {
    rad_vec3 normal;         /* of the outer polygon */
    const vf_polygon *inner;
    double plane_epsilon;
    const shadow_occluder *occluders; /* what may stand in between (none: unobstructed) */
    const shadow_polygon *joined;     /* or the same joined into polygons */
    uint32_t occluder_count;
    const uint32_t *order;            /* the occluders, largest solid angle first */
    const shadow_receiver *receiver;  /* inner, made ready for the points */
    const shadow_caster *casters;     /* the occluders made ready for it */
    int max_depth;           /* of the triangles' splitting (polygon_integral) */
    int max_splits;          /* of the strips' either way (parallelogram_integral) */
    int min_depth;           /* polygon_integral.min_depth */
    bool edge_check;         /* polygon_integral.edge_check */
    bool strips;             /* a parallelogram outer polygon by parallelogram_integral.h */
    uint64_t work_left;      /* occluder clippings this pair may still spend */
    flat_piece *pieces;      /* room for max_pieces visible pieces a point */
    unsigned max_pieces;
    bool failed;             /* too many pieces somewhere, or the work budget ran out */
    struct cull_levels *cull; /* NULL: unobstructed, no occluders */
} outer_context;

/* The occluders that can shade the triangle of the outer polygon the integral is at, for
 * each level of its splitting (cull_cell), and the level the points now come from. Set by
 * cull_cell before any point: not initialised. */
typedef struct cull_list {
    bool blocked; /* one occluder hides all of q from the triangle */
    uint32_t count;
    uint32_t index[PAIR_EXACT_MAX_OCCLUDERS];
} cull_list;

_Static_assert(OBSTRUCTED_MAX_DEPTH + 1 <= PARALLELOGRAM_MAX_LEVELS &&
                   OBSTRUCTED_MAX_SPLITS <= PARALLELOGRAM_MAX_SPLITS,
               "the cull levels hold the triangles' depths and the strips' splits");

typedef struct cull_levels {
    const cull_list *now; /* the points' triangle's */
    cull_list list[PARALLELOGRAM_MAX_LEVELS][4]; /* per level and child slot */
} cull_levels;

/* Occluder o's corners. */
static const rad_vec3 *occluder_corners(const outer_context *c, uint32_t o, unsigned *count)
{
    if (c->joined) {
        *count = c->joined[o].count;
        return c->joined[o].vertex;
    }
    *count = 3;
    return c->occluders[o].corner;
}

/* An occluder and how much of the view it takes, for ordering. */
typedef struct occluder_rank {
    double solid_angle;
    uint32_t index;
} occluder_rank;

static int compare_rank(const void *a, const void *b)
{
    const occluder_rank *x = a, *y = b;
    if (x->solid_angle != y->solid_angle)
        return x->solid_angle > y->solid_angle ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index;
}

/*
 * The occluders in order of the solid angle each subtends at `eye` (the outer polygon's
 * centroid), largest first, about |A . d| / |d|^3 with A the polygon's area vector and d
 * from the eye to its centre: the first cell's list, whose order every cell's list keeps.
 * A point's visible part is the receiver less each shadow in turn, and stops at the first
 * that leaves nothing: where a building hides the receiver, its wall comes first and the
 * point costs one subtraction instead of several (40 % of the clipping went into points
 * that end up in the dark), and a large shadow first leaves fewer pieces for the small
 * ones to cut; the cells' test for one occluder hiding everything meets the large ones
 * first too. The 1k generated city: 20 % less time in its pairs, its factors moved by
 * 7e-12 at most. Elsewhere the other rounding may tip a cell's split or a pair's second
 * try (the pieces' count depends on the order), which moves a factor within its bound.
 */
static void order_by_solid_angle(const outer_context *c, rad_vec3 eye, uint32_t *order)
{
    occluder_rank rank[PAIR_EXACT_MAX_OCCLUDERS];
    for (uint32_t o = 0; o < c->occluder_count; o++) {
        unsigned count;
        const rad_vec3 *corner = occluder_corners(c, o, &count);
        rad_vec3 area = {0, 0, 0}, centre = {0, 0, 0};
        for (unsigned v = 0; v < count; v++) {
            area = v3_add(area, v3_cross(corner[v], corner[v + 1 == count ? 0 : v + 1]));
            centre = v3_add(centre, corner[v]);
        }
        rad_vec3 d = v3_sub(v3_scale(centre, 1.0 / count), eye);
        double d2 = v3_dot(d, d);
        double angle = d2 > 0 ? 0.5 * fabs(v3_dot(area, d)) / (d2 * sqrt(d2)) : INFINITY;
        if (!(angle >= 0)) /* NaN (0 / 0 past underflow): the comparison must stay an order */
            angle = 0;
        rank[o] = (occluder_rank){angle, o};
    }
    qsort(rank, c->occluder_count, sizeof(rank[0]), compare_rank);
    for (uint32_t k = 0; k < c->occluder_count; k++)
        order[k] = rank[k].index;
}

/* Whether the flat convex occluder (corners, count) meets every segment from the triangle
 * cell to the polygon q: its plane has the triangle on one side and q on the other (beyond
 * epsilon), and it holds, by epsilon, every point where a segment between their corners
 * crosses the plane. These points span the hull's cross-section, which is then inside it. */
static bool blocks_all(const rad_vec3 *corner, unsigned count, const rad_vec3 *cell,
                       unsigned cell_count, const vf_polygon *q, double epsilon)
{
    rad_vec3 normal = v3_cross(v3_sub(corner[1], corner[0]), v3_sub(corner[2], corner[0]));
    double length = v3_length(normal);
    if (!(length > 0))
        return false;
    normal = v3_scale(normal, 1 / length);
    double offset = v3_dot(normal, corner[0]);
    double s[4] = {0, 0, 0, 0}, t[VF_MAX_VERTICES];
    for (unsigned k = 0; k < cell_count; k++)
        s[k] = v3_dot(normal, cell[k]) - offset;
    for (unsigned k = 0; k < q->count; k++)
        t[k] = v3_dot(normal, q->vertex[k]) - offset;
    double sign = s[0] > 0 ? 1 : -1;
    for (unsigned k = 0; k < cell_count; k++)
        if (!(sign * s[k] > epsilon))
            return false;
    for (unsigned k = 0; k < q->count; k++)
        if (!(sign * t[k] < -epsilon))
            return false;
    /* the occluder's edges as inward unit normals in its plane */
    rad_vec3 inward[VF_MAX_VERTICES];
    double inward_offset[VF_MAX_VERTICES];
    for (unsigned e = 0; e < count; e++) {
        inward[e] = v3_cross(normal, v3_sub(corner[(e + 1) % count], corner[e]));
        double inward_length = v3_length(inward[e]);
        if (!(inward_length > 0))
            return false;
        inward[e] = v3_scale(inward[e], 1 / inward_length);
        inward_offset[e] = v3_dot(inward[e], corner[e]);
    }
    for (unsigned i = 0; i < cell_count; i++)
        for (unsigned j = 0; j < q->count; j++) {
            rad_vec3 x = v3_lerp(cell[i], q->vertex[j], s[i] / (s[i] - t[j]));
            for (unsigned e = 0; e < count; e++)
                if (!(v3_dot(inward[e], x) - inward_offset[e] > epsilon))
                    return false;
        }
    return true;
}

/* Which of the level above's occluders can shade points of the triangle (a, b, d): those
 * that cut the hull of it and the inner polygon (every segment between them lies in it),
 * that is, are not wholly outside one of the hull's side planes (its other faces are the
 * two polygons' planes, which the pair's occluders already cut). */
_Static_assert(2 * (4 + VF_MAX_VERTICES) <= OCCLUDER_HULL_MAX_SIDES,
               "the hull of a 4-corner cell and the inner polygon has room for its sides");

static bool cull_polygon(outer_context *c, const rad_vec3 *cell_corner, unsigned corner_count,
                         int level, int slot, int parent_slot)
{
    const cull_list *parent = level > 0 ? &c->cull->list[level - 1][parent_slot] : NULL;
    cull_list *list = &c->cull->list[level][slot];
    const uint32_t *from = parent ? parent->index : c->order;
    uint32_t from_count = parent ? parent->count : c->occluder_count;
    uint32_t *to = list->index;
    uint32_t kept = 0;
    c->cull->now = list;
    list->blocked = true;
    list->count = 0;
    if (parent && parent->blocked)
        return true; /* 0 all over */
    vf_polygon cell;
    rad_vec3 centroid = {0, 0, 0};
    for (unsigned k = 0; k < corner_count; k++) {
        cell.vertex[k] = cell_corner[k];
        centroid = v3_add(centroid, cell_corner[k]);
    }
    cell.count = corner_count;
    cell.centroid = v3_scale(centroid, 1.0 / corner_count);
    rad_vec3 normal[OCCLUDER_HULL_MAX_SIDES]; /* a 4-corner cell and a 6-corner q: 20 */
    double offset[OCCLUDER_HULL_MAX_SIDES];
    unsigned planes = occluder_hull_sides(&cell, c->inner, c->plane_epsilon, normal, offset);
    for (uint32_t k = 0; k < from_count; k++) {
        uint32_t o = from ? from[k] : k;
        unsigned corners;
        const rad_vec3 *corner = occluder_corners(c, o, &corners);
        bool outside = false;
        for (unsigned m = 0; m < planes && !outside; m++) {
            outside = true;
            for (unsigned v = 0; v < corners && outside; v++)
                outside = v3_dot(normal[m], corner[v]) - offset[m] >= -c->plane_epsilon;
        }
        if (outside)
            continue;
        if (blocks_all(corner, corners, cell.vertex, cell.count, c->inner, c->plane_epsilon))
            return true; /* blocked */
        to[kept++] = o;
    }
    list->blocked = false;
    list->count = kept;
    return kept == 0;
}

static bool cull_cell(void *context, rad_vec3 a, rad_vec3 b, rad_vec3 d, int level, int slot,
                      int parent_slot)
{
    const rad_vec3 corners[3] = {a, b, d};
    return cull_polygon(context, corners, 3, level, slot, parent_slot);
}

static bool cull_parallelogram(void *context, const rad_vec3 corner[4], int level, int slot,
                               int parent_slot)
{
    return cull_polygon(context, corner, 4, level, slot, parent_slot);
}

/* The cell told at (level, slot) is the points' again: its list is intact, since only its
 * own telling and its children's (a level down) have run since. */
static void select_parallelogram(void *context, int level, int slot)
{
    outer_context *c = context;
    c->cull->now = &c->cull->list[level][slot];
}

static inline double point_factor(outer_context *c, rad_vec3 x)
{
    uint32_t count = c->occluder_count;
    const uint32_t *index = NULL; /* all of them */
    if (c->cull && count) {
        if (c->cull->now->blocked)
            return 0;
        count = c->cull->now->count;
        index = c->cull->now->index;
    }
    if (count == 0)
        return contour_point_to_polygon(x, c->normal, c->inner->vertex, c->inner->count,
                                        c->inner->normal, c->plane_epsilon);
    if (c->failed || c->work_left < count) {
        c->failed = true;
        return 0;
    }
    c->work_left -= count;
    double factor = shadow_receiver_factor(c->receiver, x, c->normal, c->casters, index, count,
                                           c->plane_epsilon, c->pieces, c->max_pieces);
    if (factor < 0) {
        c->failed = true;
        return 0;
    }
    return factor;
}

static double point_factor_callback(void *context, rad_vec3 x)
{
    return point_factor(context, x);
}

/* G = int over the smaller polygon of F(x -> the other, as far as it is visible). */
static double integrate_outer(outer_context *c, const vf_polygon *outer, double accuracy,
                              double absolute, double *bound)
{
    rad_vec3 origin, a, b;
    if (c->strips && parallelogram_of(outer->vertex, outer->count, &origin, &a, &b)) {
        /* no forced splits: the probes find what the rule points miss (a band of light
         * through a slit parallel to an edge falls between the lines they lie on) */
        parallelogram_integral strips = {point_factor_callback, c, c->max_splits, &c->failed,
                                         cull_parallelogram, 0, c->edge_check,
                                         select_parallelogram, true};
        return parallelogram_integrate_within(&strips, origin, a, b, accuracy, absolute, bound);
    }
    polygon_integral integral = {point_factor_callback, c, c->max_depth, &c->failed,
                                 c->cull ? cull_cell : NULL, c->min_depth, c->edge_check};
    return polygon_integrate_within(&integral, outer->vertex, outer->count, accuracy, absolute,
                                    bound);
}

double pair_unobstructed(const vf_polygon *p, const vf_polygon *q, double accuracy,
                         double plane_epsilon, double *bound)
{
    const vf_polygon *outer = p->area <= q->area ? p : q, *inner = outer == p ? q : p;
    outer_context c = {.normal = outer->normal,
                       .inner = inner,
                       .plane_epsilon = plane_epsilon,
                       .max_depth = MAX_DEPTH,
                       .max_splits = PARALLELOGRAM_MAX_SPLITS};
    return integrate_outer(&c, outer, accuracy, 0, bound);
}

/* The obstructed transfer behind the triangles, or behind `joined` (count of them) when not
 * NULL. */
static bool obstructed_exact(const vf_polygon *p, const vf_polygon *q,
                             const shadow_occluder *occluders, const shadow_polygon *joined,
                             uint32_t count, double accuracy, double absolute,
                             double plane_epsilon, uint64_t work_budget, flat_piece *pieces,
                             unsigned max_pieces, int min_depth, bool edge_check, bool strips,
                             double *value, double *bound)
{
    const vf_polygon *outer = p->area <= q->area ? p : q, *inner = outer == p ? q : p;
    if (count > PAIR_EXACT_MAX_OCCLUDERS)
        return false; /* more than the exact path takes: sample instead */
    shadow_receiver receiver;
    shadow_receiver_prepare(inner, &receiver);
    shadow_caster casters[PAIR_EXACT_MAX_OCCLUDERS];
    for (uint32_t k = 0; k < count; k++) {
        const rad_vec3 *corners = joined ? joined[k].vertex : occluders[k].corner;
        shadow_caster_prepare(&receiver, corners, joined ? joined[k].count : 3, plane_epsilon,
                              &casters[k]);
    }
    cull_levels levels;
    flat_piece stack_pieces[SHADOW_MAX_PIECES];
    if (!pieces) {
        pieces = stack_pieces;
        max_pieces = SHADOW_MAX_PIECES;
    }
    outer_context c = {.normal = outer->normal,
                       .inner = inner,
                       .plane_epsilon = plane_epsilon,
                       .occluders = occluders,
                       .joined = joined,
                       .occluder_count = count,
                       .receiver = &receiver,
                       .casters = casters,
                       .max_depth = OBSTRUCTED_MAX_DEPTH,
                       .max_splits = OBSTRUCTED_MAX_SPLITS,
                       .min_depth = min_depth,
                       .edge_check = edge_check,
                       .strips = strips,
                       .work_left = work_budget,
                       .pieces = pieces,
                       .max_pieces = max_pieces,
                       .cull = &levels};
    uint32_t order[PAIR_EXACT_MAX_OCCLUDERS];
    order_by_solid_angle(&c, outer->centroid, order);
    c.order = order;
    *value = integrate_outer(&c, outer, accuracy, absolute, bound);
    return !c.failed;
}

/* pair_obstructed_exact_within with room for max_pieces pieces in `pieces` (NULL: the
 * stack's SHADOW_MAX_PIECES). */
static bool joined_exact(const vf_polygon *p, const vf_polygon *q,
                         const shadow_occluder *occluders, uint32_t occluder_count,
                         double accuracy, double absolute, double plane_epsilon,
                         uint64_t work_budget, flat_piece *pieces, unsigned max_pieces,
                         double *value, double *bound)
{
    shadow_polygon joined[PAIR_EXACT_MAX_OCCLUDERS];
    if (occluder_count > PAIR_EXACT_MAX_OCCLUDERS)
        return false;
    uint32_t count = shadow_join_occluders(occluders, occluder_count, joined);
    return obstructed_exact(p, q, NULL, joined, count, accuracy, absolute, plane_epsilon,
                            work_budget, pieces, max_pieces, OBSTRUCTED_MIN_DEPTH, true, true,
                            value, bound);
}

bool pair_obstructed_exact_within(const vf_polygon *p, const vf_polygon *q,
                                  const shadow_occluder *occluders, uint32_t occluder_count,
                                  double accuracy, double absolute, double plane_epsilon,
                                  uint64_t work_budget, double *value, double *bound)
{
    return joined_exact(p, q, occluders, occluder_count, accuracy, absolute, plane_epsilon,
                        work_budget, NULL, 0, value, bound);
}

bool pair_obstructed_exact_roomy(const vf_polygon *p, const vf_polygon *q,
                                 const shadow_occluder *occluders, uint32_t occluder_count,
                                 double accuracy, double absolute, double plane_epsilon,
                                 uint64_t work_budget, pair_workspace *workspace, double *value,
                                 double *bound)
{
    return joined_exact(p, q, occluders, occluder_count, accuracy, absolute, plane_epsilon,
                        work_budget, workspace->pieces, PAIR_ROOMY_PIECES, value, bound);
}

bool pair_obstructed_exact(const vf_polygon *p, const vf_polygon *q,
                           const shadow_occluder *occluders, uint32_t occluder_count,
                           double accuracy, double plane_epsilon, double *value, double *bound)
{
    return obstructed_exact(p, q, occluders, NULL, occluder_count, accuracy, 0, plane_epsilon,
                            EXACT_WORK_BUDGET, NULL, 0, 0, false, false, value, bound);
}

bool pair_workspace_init(pair_workspace *workspace, uint32_t max_rays)
{
    workspace->capacity = max_rays;
    workspace->rays = rad_alloc_array(max_rays, sizeof(rad_ray));
    workspace->occluded = rad_alloc_array(max_rays, 1);
    workspace->weight = rad_alloc_array(max_rays, sizeof(double));
    workspace->pieces = rad_alloc_array(PAIR_ROOMY_PIECES, sizeof(flat_piece));
    workspace->last_p = workspace->last_q = NULL;
    workspace->last_occluders = NULL;
    workspace->last_stream = 0;
    workspace->last_rounds = 0;
    return workspace->rays && workspace->occluded && workspace->weight && workspace->pieces;
}

void pair_workspace_free(pair_workspace *workspace)
{
    free(workspace->rays);
    free(workspace->occluded);
    free(workspace->weight);
    free(workspace->pieces);
}

/* One round: PAIR_REPLICATES independent stratified sets of k x k segments (k a power of
 * 2). */
static uint32_t fill_round(const vf_polygon *p, const vf_polygon *q, unsigned k,
                           uint64_t stream, unsigned round, pair_workspace *w)
{
    uint32_t n = 0;
    unsigned cells = k * k;
    /* k is a power of 2: times its reciprocal is division by it, bit for bit, and the
     * cell's column and row are a mask and a shift */
    double cell = 1.0 / k;
    unsigned shift = 0, mask = k - 1;
    while ((1u << shift) < k)
        shift++;
    for (unsigned r = 0; r < PAIR_REPLICATES; r++) {
        rad_rng rng = rad_rng_seed(stream, round, r);
        /* the cells of q are visited in a shuffled order, paired with p's in order */
        unsigned order[MAX_STRATA * MAX_STRATA];
        for (unsigned m = 0; m < cells; m++)
            order[m] = m;
        for (unsigned m = cells; m > 1; m--) {
            unsigned swap = (unsigned)(rad_rng_uniform(&rng) * m);
            unsigned keep = order[m - 1];
            order[m - 1] = order[swap];
            order[swap] = keep;
        }
        for (unsigned m = 0; m < cells; m++) {
            double s0 = ((m & mask) + rad_rng_uniform(&rng)) * cell;
            double t0 = ((m >> shift) + rad_rng_uniform(&rng)) * cell;
            double s1 = ((order[m] & mask) + rad_rng_uniform(&rng)) * cell;
            double t1 = ((order[m] >> shift) + rad_rng_uniform(&rng)) * cell;
            rad_vec3 x = vf_polygon_sample(p, s0, t0), y = vf_polygon_sample(q, s1, t1);
            rad_vec3 d = v3_sub(y, x);
            double r2 = v3_dot(d, d);
            double cx = v3_dot(p->normal, d), cy = -v3_dot(q->normal, d);
            w->weight[n] = cx > 0 && cy > 0 && r2 > 0 ? cx * cy / (r2 * r2) : 0;
            ray_set(&w->rays[n++], x, d, RAD_SEGMENT_END_EPSILON, 1 - RAD_SEGMENT_END_EPSILON);
        }
    }
    return n;
}

double pair_poisson_upper(uint64_t m)
{
    if (m == 0)
        return PAIR_UNSEEN_BOUND; /* exact: -ln 0.05 */
    double n = m + 1.0;
    double c = 1 - 1 / (9 * n) + PAIR_ONE_SIDED_Z / (3 * sqrt(n));
    return n * c * c * c;
}

/* Round `round` (k x k strata a side) cast and weighed. */
static pair_round cast_round(const vf_polygon *p, const vf_polygon *q,
                             const rad_tracer *occluders, unsigned k, unsigned round,
                             uint64_t stream, pair_workspace *w)
{
    uint32_t n = fill_round(p, q, k, stream, round, w);
    rad_tracer_occluded(occluders, w->rays, n, w->occluded);
    double estimate[PAIR_REPLICATES], mean = 0;
    unsigned cells = k * k;
    /* whether the segments that count (weight > 0) all agree, and how: a segment of no
     * weight (from behind the other's plane) says nothing, so it neither breaks their
     * agreement nor, when they are all blocked, makes a spread of 0 look like a
     * measured one */
    int agreed = -1; /* -1: none weighed yet; else the occluded flag they all share */
    bool all_same = true;
    uint32_t weighed = 0, weighed_blocked = 0;
    for (unsigned r = 0; r < PAIR_REPLICATES; r++) {
        double seen = 0, total = 0;
        for (unsigned m = r * cells; m < (r + 1) * cells; m++) {
            if (!(w->weight[m] > 0))
                continue;
            weighed++;
            weighed_blocked += w->occluded[m] != 0;
            total += w->weight[m];
            seen += w->occluded[m] ? 0 : w->weight[m];
            if (agreed < 0)
                agreed = w->occluded[m];
            all_same = all_same && w->occluded[m] == agreed;
        }
        estimate[r] = total > 0 ? seen / total : (w->occluded[r * cells] ? 0 : 1);
        mean += estimate[r];
    }
    mean /= PAIR_REPLICATES;
    double spread = 0;
    for (unsigned r = 0; r < PAIR_REPLICATES; r++)
        spread += (estimate[r] - mean) * (estimate[r] - mean);
    double standard_error = sqrt(spread / (PAIR_REPLICATES - 1) / PAIR_REPLICATES);
    pair_round result;
    result.fraction = fmin(fmax(mean, 0), 1);
    result.all_same = all_same;
    result.unseen = all_same && agreed == 1;
    /* The replicates' spread says little when one outcome is rare: all segments agreeing
     * have no spread at all, and one segment through a street between two buildings made
     * a spread that passed for a bound 80 times too small. So the bound is at least what
     * the rarer outcome's count allows: m of n segments are consistent with a share up to
     * pair_poisson_upper(m) / n (95 %); a slot narrower than a cell, an occluder between
     * them, is what they could have missed. */
    uint32_t rarer = weighed_blocked < weighed - weighed_blocked ? weighed_blocked
                                                                 : weighed - weighed_blocked;
    double rare_bound = (pair_poisson_upper(rarer) - rarer) / (double)(weighed ? weighed : 1);
    result.bound = all_same ? rare_bound : fmax(PAIR_STUDENT_T * standard_error, rare_bound);
    result.bound = fmin(result.bound, 1); /* a fraction: no weighed segment says no more */
    result.rays = n;
    return result;
}

/* Rounds of 4x more segments from the first; the first `known` rounds are the
 * workspace's record of the last call (same pair and stream), the others are cast and
 * recorded. */
static void sample_rounds(const vf_polygon *p, const vf_polygon *q, const rad_tracer *occluders,
                          double accuracy, uint32_t max_rays, uint64_t stream, unsigned known,
                          pair_workspace *w, pair_visibility *out)
{
    w->last_p = p;
    w->last_q = q;
    w->last_occluders = occluders;
    w->last_stream = stream;
    out->rays = 0;
    out->capped = false;
    /* the rays the rounds would have cast: the budget counts them, cast now or before */
    uint32_t spent = 0;
    unsigned round = 0;
    for (unsigned k = 1;; k *= 2, round++) {
        pair_round result;
        if (round < known) {
            result = w->last_round[round];
        } else {
            result = cast_round(p, q, occluders, k, round, stream, w);
            out->rays += result.rays;
            if (round < PAIR_MAX_ROUNDS) {
                w->last_round[round] = result;
                w->last_rounds = round + 1;
            }
        }
        spent += result.rays;
        out->fraction = result.fraction;
        out->unseen = result.unseen;
        out->bound = result.bound;
        uint32_t next = PAIR_REPLICATES * (2 * k) * (2 * k);
        /* agreeing segments take two rounds at least: one says little */
        if (out->bound <= accuracy && (k >= 2 || !result.all_same))
            return;
        if (spent + next > max_rays || next > w->capacity || 2 * k > MAX_STRATA) {
            out->capped = true;
            return;
        }
    }
}

void pair_sample_visibility(const vf_polygon *p, const vf_polygon *q,
                            const rad_tracer *occluders, double accuracy, uint32_t max_rays,
                            uint64_t stream, pair_workspace *w, pair_visibility *out)
{
    w->last_rounds = 0;
    sample_rounds(p, q, occluders, accuracy, max_rays, stream, 0, w, out);
}

void pair_sample_visibility_resume(const vf_polygon *p, const vf_polygon *q,
                                   const rad_tracer *occluders, double accuracy,
                                   uint32_t max_rays, uint64_t stream, pair_workspace *w,
                                   pair_visibility *out)
{
    /* the stream names the pair (a bijective mix of the seed and the polygons' indices):
     * p and q may be a caller's stack copies, at the same address for every pair */
    bool same = w->last_p == p && w->last_q == q && w->last_occluders == occluders &&
                w->last_stream == stream;
    if (!same)
        w->last_rounds = 0;
    sample_rounds(p, q, occluders, accuracy, max_rays, stream, w->last_rounds, w, out);
}
