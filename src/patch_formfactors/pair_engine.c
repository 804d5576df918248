/*
 * pair_engine.c - the form-factor kernel: analytic transfer times sampled visibility.
 *
 * For a pair (i, j), i < j, of patches that face each other:
 *   - the unoccluded transfer G_ij = A_i Fhat_ij is Lambert's contour formula (contour.c)
 *     integrated over the smaller patch: the midpoint rule on an m x m split, a 4 x 4 one
 *     for pairs close by, adaptive quadrature (polygon_integral.c) for touching pairs;
 *   - a close pair (under EXACT_DISTANCE x the sum of the radii) that no triangle can
 *     come between (exact_pairs.h: its hull is clear) needs no visibility, and one that at
 *     most four triangles cut is settled by exact shadow clipping; a pair farther apart is
 *     not screened (only its patches' groups, when found clear, spare it everything): its
 *     segments, all open, give G exactly as screening would have, and cost less than
 *     screening did (a furnished room on the dense solver: form factors 52.8 -> 10.4 s;
 *     the Cornell box 1.09-1.17 -> 0.93-1.04 s, the image the same within 2e-9);
 *   - otherwise visibility is the kernel-weighted fraction of k x k segments between
 *     jittered stratified points of the two patches that no triangle of the scene blocks.
 *     (A folded patch, which the hull test does not cover, gets 2 x 2 segments first and
 *     the full set only when they disagree.) Surfaces within a hair of either end, where
 *     the tracer does not look, are tested in double precision (near_contacts.c).
 * Pairs where either patch is wholly behind the other's plane need no work (G = 0).
 *
 * Random numbers come from (seed, i, j), so the result is the same for any thread count.
 * Rays are batched per thread and traced with rad_tracer_occluded; the hot loop allocates
 * nothing.
 */
#include "patch_formfactors/pair_engine.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/minmax.h"
#include "core/random.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "geometry/contour.h"
#include "geometry/polygon_pair.h"
#include "mesh/exposed_area.h"
#include "mesh/near_contacts.h"
#include "patch_formfactors/exact_pairs.h"
#include "trace/ray.h"

#define MAX_QUADRATURE 8u
#define MAX_STRATA 16u             /* at most 16 x 16 = 256 rays per pair */
#define BATCH_RAYS 4096u           /* rays traced per call */
#define FIRST_STRATA 2u            /* first pass: 2 x 2 segments per pair */
/* A close pair (under EXACT_DISTANCE x the sum of the radii) that screening leaves to
 * sampling, and a pair with a partly buried patch, take at least CLOSE_STRATA^2 segments
 * (a folded patch's close pair once its first pass of 2 x 2 disagrees):
 * there the kernel and the visibility change fastest across the pair, and a buried
 * patch's row is divided by its open share, so only the segments that land on its open
 * part count. With the default 2 x 2 (--visibility-rays 4) for them, two floor patches
 * under the Cornell box's blocks summed to 1.03 (trimmed, with a warning), and next to
 * test_near_surfaces' interpenetrating boxes a row came out 1.011 and the rows a box cuts
 * up to 0.014 off a traced count; with 3 x 3 at most 1.0032, 1.009 and 0.0066, within the
 * 1 % rows are held to, for the same rays on the Cornell box (15.4 M). */
#define CLOSE_STRATA 3u
/* Pairs closer than NEAR_DISTANCE x (sum of their radii) get NEAR_QUADRATURE^2 points:
 * the midpoint rule is worst where the kernel varies fastest, next to a shared edge. */
#define NEAR_DISTANCE 3.0
#define NEAR_QUADRATURE 4u
/* Pairs closer than TOUCHING_DISTANCE x (sum of their radii) (neighbours across an edge,
 * a box on a floor, walls a hair apart) get the exact transfer, the double contour
 * integral (polygon_pair.h), its adaptive edge integrals to TOUCHING_ACCURACY of the
 * product of the two edges' lengths (the transfer to about 1e-7 relative: test_polygon_pair;
 * 1e-9 took 2.4 times the inner integral's evaluations, 4.2 M on the Cornell box). */
#define TOUCHING_DISTANCE 1.0
#define TOUCHING_ACCURACY 1e-7
/* Pairs at NEAR_DISTANCE x (sum of their radii) or farther, each wholly in front of the
 * other, take the kernel's second-order expansion about both centroids (polygon_pair.h)
 * when the midpoint rule asked for is at most EXPANSION_MAX_QUADRATURE x as many points
 * a side: measured on rectangles turned at random (test_polygon_pair), the expansion errs
 * by under 0.14 (R / D)^4 and the one-point rule by up to 0.25 (R / D)^2 (R the sum of
 * the radii, D the centroids' distance), so from 3 radii on it is the more accurate of
 * the two up to 3 x 3 points, and a sixth of one contour formula's cost. */
#define EXPANSION_MAX_QUADRATURE 3u
/* Close pairs (closer than EXACT_DISTANCE x the sum of their radii) that few triangles
 * obstruct are settled by exact shadow clipping (exact_pairs.h) to EXACT_ACCURACY: there
 * the kernel varies too fast across the pair for kernel-weighted segments to be right
 * (a box sunk into the floor: rows 4 % too high). */
#define EXACT_DISTANCE 3.0
#define EXACT_ACCURACY 1e-2

/* Everything the kernel needs about one patch, precomputed. */
typedef struct patch_geometry {
    rad_vec3 corner[4];
    unsigned corner_count;
    rad_vec3 normal;
    rad_vec3 centroid;
    double radius; /* largest distance from the centroid to a corner */
    double area;
    /* the map from the unit square: quads P = o + s u + t v + s t w (bilinear);
     * triangles P = o + sqrt(s) (u + t w), which is uniform in area */
    rad_vec3 o, u, v, w;
    rad_vec3 lift; /* added to sample points: 2 x behind along the normal (folded quads) */
    polygon_moments moments; /* for the far pairs' expansion */
} patch_geometry;

typedef struct pending_pair {
    uint32_t j;
    uint32_t first_ray, ray_count;
    unsigned full_strata; /* k of the full set (a first pass that disagrees gets it) */
    double unoccluded;    /* G before visibility */
} pending_pair;

typedef struct engine {
    const rad_mesh *mesh;
    const rad_tracer *occluders;
    patch_geometry *geometry;
    rad_vec3 *quadrature_points; /* m*m per patch */
    double *quadrature_weights;  /* m*m per patch, sum to 1 */
    unsigned quadrature_count;
    bool expand_far;             /* far pairs wholly in front of each other by expansion */
    uint8_t *partly_buried;      /* per patch: its open area (options->area) is less than
                                    its area; NULL: none is */
    uint32_t *cells_of;          /* per patch: its open cells' index in open_cells, or
                                    UINT32_MAX */
    uint8_t (*open_cells)[EXPOSED_CELL_BYTES]; /* mesh/exposed_area.h */
    rad_vec3 *near_points;       /* the same with NEAR_QUADRATURE, for close pairs */
    double *near_weights;
    unsigned near_count;
    unsigned strata;             /* k: at most k*k segments per pair */
    unsigned close_strata;       /* the same for a close pair or one with a partly buried
                                    patch (CLOSE_STRATA) */
    unsigned first_strata;       /* the first pass casts first_strata^2 segments */
    uint64_t seed;
    double plane_epsilon;
    near_contacts contacts; /* what the segments' left-out ends could miss */
    exact_pairs exact;      /* what may stand between two patches */
    pair_sink_fn sink;
    void *sink_data;
} engine;

uint64_t pair_engine_bytes(uint32_t patches, int threads, uint32_t quadrature)
{
    uint64_t m = quadrature ? quadrature : RAD_DEFAULT_QUADRATURE;
    uint64_t m_near = m > NEAR_QUADRATURE ? m : NEAR_QUADRATURE;
    uint64_t per_patch = sizeof(patch_geometry) +
                         (m * m + m_near * m_near) * (sizeof(rad_vec3) + sizeof(double)) +
                         sizeof(uint8_t) + sizeof(uint32_t) + EXPOSED_CELL_BYTES / 8;
    uint64_t per_segment = sizeof(rad_ray) + 2 * sizeof(rad_vec3) + sizeof(uint8_t) +
                           sizeof(pending_pair);
    return (uint64_t)patches * per_patch +
           (uint64_t)(threads > 0 ? threads : 1) * 2 * BATCH_RAYS * per_segment;
}

int pair_engine_threads(const rad_formfactor_options *options)
{
    int threads = options && options->threads > 0 ? options->threads : omp_get_max_threads();
    return threads < 1 ? 1 : threads;
}

/* Point of the patch at unit-square coordinates (s, t): bilinear for quads, an
 * area-preserving warp for triangles. */
static inline rad_vec3 patch_point(const patch_geometry *g, double s, double t)
{
    if (g->corner_count == 4)
        return v3(g->o.x + s * g->u.x + t * g->v.x + s * t * g->w.x,
                  g->o.y + s * g->u.y + t * g->v.y + s * t * g->w.y,
                  g->o.z + s * g->u.z + t * g->v.z + s * t * g->w.z);
    double r = sqrt(s);
    return v3(g->o.x + r * (g->u.x + t * g->w.x), g->o.y + r * (g->u.y + t * g->w.y),
              g->o.z + r * (g->u.z + t * g->w.z));
}

static void patch_map(patch_geometry *g)
{
    const rad_vec3 *c = g->corner;
    g->o = c[0];
    g->u = v3_sub(c[1], c[0]);
    if (g->corner_count == 4) {
        g->v = v3_sub(c[3], c[0]);
        g->w = v3_add(v3_sub(c[2], c[1]), v3_sub(c[0], c[3]));
    } else {
        g->v = v3(0, 0, 0);
        g->w = v3_sub(c[2], c[1]);
    }
}

/* Midpoint rule on an m x m split: sub-cell centres (quads) or sub-triangle centroids. */
static void quadrature_for(const patch_geometry *g, unsigned m, rad_vec3 *points,
                           double *weights)
{
    unsigned q = 0;
    if (g->corner_count == 4) {
        double total = 0;
        for (unsigned j = 0; j < m; j++)
            for (unsigned i = 0; i < m; i++) {
                rad_vec3 a = patch_point(g, (double)i / m, (double)j / m);
                rad_vec3 b = patch_point(g, (double)(i + 1) / m, (double)j / m);
                rad_vec3 c = patch_point(g, (double)(i + 1) / m, (double)(j + 1) / m);
                rad_vec3 d = patch_point(g, (double)i / m, (double)(j + 1) / m);
                double area = 0.5 * v3_length(v3_cross(v3_sub(c, a), v3_sub(d, b)));
                points[q] = v3_scale(v3_add(v3_add(a, b), v3_add(c, d)), 0.25);
                weights[q++] = area;
                total += area;
            }
        for (unsigned k = 0; k < q; k++)
            weights[k] = total > 0 ? weights[k] / total : 1.0 / q;
        return;
    }
    /* triangle: m^2 similar sub-triangles of equal area */
    rad_vec3 a = g->corner[0], ab = v3_sub(g->corner[1], a), ac = v3_sub(g->corner[2], a);
    for (unsigned j = 0; j < m; j++)
        for (unsigned i = 0; i + j < m; i++) {
            double u = (i + 1.0 / 3.0) / m, v = (j + 1.0 / 3.0) / m;
            points[q] = v3_add(a, v3_add(v3_scale(ab, u), v3_scale(ac, v)));
            weights[q++] = 1.0 / ((double)m * m);
            if (i + j + 1 < m) {
                u = (i + 2.0 / 3.0) / m;
                v = (j + 2.0 / 3.0) / m;
                points[q] = v3_add(a, v3_add(v3_scale(ab, u), v3_scale(ac, v)));
                weights[q++] = 1.0 / ((double)m * m);
            }
        }
}

/* True when some corner of b lies in front of a's plane. */
static bool any_in_front(const patch_geometry *a, const patch_geometry *b, double epsilon)
{
    for (unsigned k = 0; k < b->corner_count; k++)
        if (v3_dot(a->normal, v3_sub(b->corner[k], a->corner[0])) > epsilon)
            return true;
    return false;
}

/* True when no corner of b lies behind a's plane (beyond epsilon). */
static bool wholly_in_front(const patch_geometry *a, const patch_geometry *b, double epsilon)
{
    for (unsigned k = 0; k < b->corner_count; k++)
        if (v3_dot(a->normal, v3_sub(b->corner[k], a->corner[0])) < -epsilon)
            return false;
    return true;
}

/* Area-weighted unoccluded factor from patch a to patch b, A_a * Fhat_ab, by the midpoint
 * rule over a: m x m points, or NEAR_QUADRATURE^2 for a pair close by. */
static double transfer(const engine *e, uint32_t a, uint32_t b, bool near)
{
    const patch_geometry *ga = &e->geometry[a], *gb = &e->geometry[b];
    unsigned count = near ? e->near_count : e->quadrature_count;
    const rad_vec3 *points = (near ? e->near_points : e->quadrature_points) + (size_t)a * count;
    const double *weights = (near ? e->near_weights : e->quadrature_weights) + (size_t)a * count;
    double sum = 0;
    for (unsigned q = 0; q < count; q++)
        sum += weights[q] * contour_point_to_polygon(points[q], ga->normal, gb->corner,
                                                     gb->corner_count, gb->normal,
                                                     e->plane_epsilon);
    return ga->area * sum;
}

/* The same for a touching pair, G = A_a Fhat_ab = A_b Fhat_ba, exactly: the double
 * contour integral (polygon_pair.h), so that rows sum to what the patches see however
 * close they are (coincident walls, a box on a floor, a shared edge). */
static double touching_transfer(const engine *e, uint32_t a, uint32_t b)
{
    const patch_geometry *ga = &e->geometry[a], *gb = &e->geometry[b];
    return polygon_pair_transfer(ga->corner, ga->corner_count, ga->normal, gb->corner,
                                 gb->corner_count, gb->normal, e->plane_epsilon,
                                 TOUCHING_ACCURACY);
}

/* Where the k*k segments of pair (i, j) start and end, (s, t) on i and (s, t) on j in
 * their unit squares: stratified points, j's strata shuffled against i's; `round` tells
 * the first pass (0) from the refining pass (1) so they draw different points. The same
 * for the same arguments, so the tracing can ask again (trace: the buried cells). */
static void segment_params(const engine *e, uint32_t i, uint32_t j, unsigned k, unsigned round,
                           double (*st)[4])
{
    unsigned count = k * k;
    rad_rng rng = rad_rng_seed(e->seed + round, i, j);
    uint8_t column[MAX_STRATA * MAX_STRATA], row[MAX_STRATA * MAX_STRATA]; /* j's strata */
    for (unsigned t = 0, s = 0; t < k; t++)
        for (unsigned c = 0; c < k; c++, s++) {
            column[s] = (uint8_t)c;
            row[s] = (uint8_t)t;
        }
    for (unsigned s = count; s > 1; s--) { /* shuffle which stratum of j pairs with which of i */
        unsigned r = (unsigned)(((rad_rng_next(&rng) >> 32) * s) >> 32); /* uniform in [0, s) */
        uint8_t swap = column[s - 1];
        column[s - 1] = column[r];
        column[r] = swap;
        swap = row[s - 1];
        row[s - 1] = row[r];
        row[r] = swap;
    }
    const double inv_k = 1.0 / k, to_unit = 1.0 / 4294967296.0;
    unsigned s = 0;
    for (unsigned ti = 0; ti < k; ti++)
        for (unsigned si = 0; si < k; si++, s++) {
            /* four 32-bit jitters from two draws */
            uint64_t a = rad_rng_next(&rng), b = rad_rng_next(&rng);
            unsigned sj = column[s], tj = row[s];
            st[s][0] = (si + (double)(a >> 32) * to_unit) * inv_k;
            st[s][1] = (ti + (double)(a & 0xFFFFFFFFu) * to_unit) * inv_k;
            st[s][2] = (sj + (double)(b >> 32) * to_unit) * inv_k;
            st[s][3] = (tj + (double)(b & 0xFFFFFFFFu) * to_unit) * inv_k;
        }
}

/* Fills the k*k segments of pair (i, j) (segment_params). */
static void make_segments(const engine *e, uint32_t i, uint32_t j, unsigned k, unsigned round,
                          rad_ray *rays, rad_vec3 (*ends)[2])
{
    double st[MAX_STRATA * MAX_STRATA][4];
    segment_params(e, i, j, k, round, st);
    const patch_geometry *gi = &e->geometry[i], *gj = &e->geometry[j];
    for (unsigned s = 0; s < k * k; s++) {
        rad_vec3 p = v3_add(patch_point(gi, st[s][0], st[s][1]), gi->lift);
        rad_vec3 q = v3_add(patch_point(gj, st[s][2], st[s][3]), gj->lift);
        ray_segment(&rays[s], p, q);
        ends[s][0] = p;
        ends[s][1] = q;
    }
}

/* A batch of pairs waiting for their segments to be traced. */
typedef struct batch {
    rad_ray *rays;
    rad_vec3 (*ends)[2]; /* each segment's ends in double precision */
    unsigned round;      /* 0: the first pass, 1: the refining one (segment_params) */
    uint8_t *occluded;
    pending_pair *pending;
    uint32_t ray_count, pending_count;
} batch;

typedef struct thread_work {
    batch first;  /* every facing pair, first_strata^2 segments */
    batch refine; /* pairs the first pass found partly visible, strata^2 segments */
    uint64_t rays_cast, pairs_facing, pairs_refined, pairs_clear, pairs_exact;
    double tracing_seconds; /* this thread's time inside rad_tracer_occluded */
} thread_work;

static void batch_add(const engine *e, batch *b, uint32_t i, uint32_t j, double G, unsigned k,
                      unsigned full_strata, unsigned round)
{
    pending_pair *pair = &b->pending[b->pending_count++];
    pair->j = j;
    pair->first_ray = b->ray_count;
    pair->ray_count = k * k;
    pair->full_strata = full_strata;
    pair->unoccluded = G;
    make_segments(e, i, j, k, round, &b->rays[b->ray_count], &b->ends[b->ray_count]);
    b->ray_count += k * k;
}

static uint32_t visible_count(const batch *b, const pending_pair *pair)
{
    uint32_t visible = 0;
    for (uint32_t r = 0; r < pair->ray_count; r++)
        visible += !b->occluded[pair->first_ray + r];
    return visible;
}

/* The visible fraction of a partly occluded pair, each segment weighted by the transfer
 * kernel cos(theta_i) cos(theta_j) / r^2 at its ends: a shadow over the part of the pair
 * that exchanges the most light (the near ends of two patches meeting at a corner) counts
 * for more, so that visibility and the analytic factor are not treated as independent.
 * r^2 is kept above a quarter of the smaller patch's radius squared so that one segment
 * next to a shared edge cannot take all the weight. */
static double weighted_visibility(const engine *e, const batch *b, const pending_pair *pair,
                                  uint32_t i)
{
    const patch_geometry *gi = &e->geometry[i], *gj = &e->geometry[pair->j];
    double floor_r = 0.5 * min_d(gi->radius, gj->radius);
    double floor_r2 = floor_r * floor_r;
    double total = 0, visible = 0;
    for (uint32_t r = 0; r < pair->ray_count; r++) {
        const rad_ray *ray = &b->rays[pair->first_ray + r];
        rad_vec3 d = v3(ray->direction[0], ray->direction[1], ray->direction[2]);
        double r2 = v3_dot(d, d);
        double length = sqrt(r2);
        double ci = v3_dot(gi->normal, d) / length, cj = -v3_dot(gj->normal, d) / length;
        double kernel = max_d(ci, 0) * max_d(cj, 0) / max_d(r2, floor_r2);
        total += kernel;
        if (!b->occluded[pair->first_ray + r])
            visible += kernel;
    }
    return total > 0 ? visible / total : (double)visible_count(b, pair) / pair->ray_count;
}

static double now_seconds(void) { return rad_clock_seconds(); }

/* Traces a batch of row i (4096 segments at most: the two clock reads are noise beside
 * it), then tests the segments of pairs with near contacts against those. */
/* Whether the point at (s, t) of patch p lies in an open cell (true for a patch not
 * partly buried). */
static bool open_at(const engine *e, uint32_t p, double s, double t)
{
    uint32_t at = e->cells_of ? e->cells_of[p] : UINT32_MAX;
    if (at == UINT32_MAX)
        return true;
    unsigned a = (unsigned)(s * EXPOSED_FINE_SIDE), c = (unsigned)(t * EXPOSED_FINE_SIDE);
    a = a < EXPOSED_FINE_SIDE ? a : EXPOSED_FINE_SIDE - 1;
    c = c < EXPOSED_FINE_SIDE ? c : EXPOSED_FINE_SIDE - 1;
    unsigned bit = a * EXPOSED_FINE_SIDE + c;
    return (e->open_cells[at][bit / 8] >> (bit % 8)) & 1u;
}

static void trace(const engine *e, thread_work *w, batch *b, uint32_t i)
{
    double start = now_seconds();
    rad_tracer_occluded(e->occluders, b->rays, b->ray_count, b->occluded);
    w->tracing_seconds += now_seconds() - start;
    /* a segment with an end buried in a closed object carries nothing: the patch's row
     * is its open part's (mesh/exposed_area.h), and two buried parts inside one closed
     * region (a floor under a bed and the wall behind it) would otherwise see each other */
    if (e->cells_of)
        for (uint32_t p = 0; p < b->pending_count; p++) {
            const pending_pair *pair = &b->pending[p];
            if (e->cells_of[i] == UINT32_MAX && e->cells_of[pair->j] == UINT32_MAX)
                continue;
            double st[MAX_STRATA * MAX_STRATA][4];
            unsigned k = (unsigned)lround(sqrt((double)pair->ray_count));
            segment_params(e, i, pair->j, k, b->round, st);
            for (uint32_t r = 0; r < pair->ray_count; r++)
                if (!b->occluded[pair->first_ray + r] &&
                    (!open_at(e, i, st[r][0], st[r][1]) ||
                     !open_at(e, pair->j, st[r][2], st[r][3])))
                    b->occluded[pair->first_ray + r] = 1;
        }
    bool near_i = near_contacts_any(&e->contacts, i);
    for (uint32_t p = 0; p < b->pending_count; p++) {
        const pending_pair *pair = &b->pending[p];
        if ((!near_i && !near_contacts_any(&e->contacts, pair->j)) ||
            !near_contacts_pair_may_block(&e->contacts, i, pair->j))
            continue;
        for (uint32_t r = pair->first_ray; r < pair->first_ray + pair->ray_count; r++)
            if (!b->occluded[r] &&
                near_contacts_block(&e->contacts, i, pair->j, b->ends[r][0], b->ends[r][1]))
                b->occluded[r] = 1;
    }
}

static void flush_refine(const engine *e, thread_work *w, int thread, uint32_t i)
{
    batch *b = &w->refine;
    if (b->ray_count)
        trace(e, w, b, i);
    for (uint32_t p = 0; p < b->pending_count; p++) {
        const pending_pair *pair = &b->pending[p];
        uint32_t visible = visible_count(b, pair);
        if (visible == pair->ray_count)
            e->sink(e->sink_data, thread, i, pair->j, pair->unoccluded);
        else if (visible)
            e->sink(e->sink_data, thread, i, pair->j,
                    pair->unoccluded * weighted_visibility(e, b, pair, i));
    }
    w->rays_cast += b->ray_count;
    b->ray_count = b->pending_count = 0;
}

/* Traces the first pass; pairs seen wholly visible or wholly hidden are done, the others
 * go to the refining pass with the full number of segments. */
static void flush_first(const engine *e, thread_work *w, int thread, uint32_t i)
{
    batch *b = &w->first;
    if (b->ray_count)
        trace(e, w, b, i);
    for (uint32_t p = 0; p < b->pending_count; p++) {
        const pending_pair *pair = &b->pending[p];
        const unsigned full = pair->full_strata * pair->full_strata;
        uint32_t visible = visible_count(b, pair);
        if (visible == pair->ray_count) {
            e->sink(e->sink_data, thread, i, pair->j, pair->unoccluded);
        } else if (visible == 0) {
            continue;
        } else if (pair->ray_count >= full) {
            e->sink(e->sink_data, thread, i, pair->j,
                    pair->unoccluded * weighted_visibility(e, b, pair, i));
        } else {
            if (w->refine.ray_count + full > BATCH_RAYS)
                flush_refine(e, w, thread, i);
            batch_add(e, &w->refine, i, pair->j, pair->unoccluded, pair->full_strata,
                      pair->full_strata, 1);
            w->pairs_refined++;
        }
    }
    w->rays_cast += b->ray_count;
    b->ray_count = b->pending_count = 0;
}

static void row(const engine *e, thread_work *w, int thread, uint32_t i)
{
    const patch_geometry *gi = &e->geometry[i];
    uint32_t n = e->mesh->patch_count;
    unsigned k = e->first_strata;
    for (uint32_t j = i + 1; j < n; j++) {
        const patch_geometry *gj = &e->geometry[j];
        if (!any_in_front(gi, gj, e->plane_epsilon) || !any_in_front(gj, gi, e->plane_epsilon))
            continue;
        double distance = v3_length(v3_sub(gi->centroid, gj->centroid));
        double radii = gi->radius + gj->radius;
        double settled;
        uint32_t crossing;
        /* a pair with a patch partly buried in a closed object gets its segments even
         * when screening finds it clear or settles it by clipping: its row is divided by
         * the open share, so its buried points must be seen to see nothing (a wall running
         * on past the ceiling it meets: the ceiling touches the pair's hull only along the
         * wall, is not among the occluders found, and such rows came out up to 3.4 once
         * divided) */
        bool partly = e->partly_buried && (e->partly_buried[i] || e->partly_buried[j]);
        /* a pair EXACT_DISTANCE apart or more is not screened: its segments, which it
         * gets in any case unless screening proves it clear, say as much (all of them
         * open: G itself, exactly) at less cost: pair_engine.c's header */
        const bool close = distance < EXACT_DISTANCE * radii;
        crossing = EXACT_NO_CROSSING;
        exact_outcome outcome =
            !partly && exact_pairs_group_clear(&e->exact, i, j) ? EXACT_CLEAR
            : close ? exact_pairs_transfer(&e->exact, i, j, true, EXACT_ACCURACY, &settled,
                                           &crossing)
                    : EXACT_SAMPLE;
        if (partly && (outcome == EXACT_CLEAR || outcome == EXACT_SETTLED))
            outcome = EXACT_SAMPLE;
        bool exact_polygons = e->exact.polygons[i].count && e->exact.polygons[j].count;
        if (outcome == EXACT_SAMPLE && exact_polygons &&
            exact_pairs_hidden(&e->exact, i, j, crossing)) {
            /* one triangle between them hides all: G = 0, no ray, not even the
             * unoccluded transfer */
            w->pairs_facing++;
            w->pairs_exact++;
            continue;
        }
        /* one-sided, from the smaller patch: its points are the finer ones relative to the
         * distance between the two */
        bool i_smaller = gi->area <= gj->area;
        double G;
        if (distance < TOUCHING_DISTANCE * radii)
            G = touching_transfer(e, i, j);
        else if (e->expand_far && distance >= NEAR_DISTANCE * radii &&
                 wholly_in_front(gi, gj, e->plane_epsilon) &&
                 wholly_in_front(gj, gi, e->plane_epsilon))
            G = polygon_pair_expansion(&gi->moments, &gj->moments);
        else if (i_smaller)
            G = transfer(e, i, j, distance < NEAR_DISTANCE * radii);
        else
            G = transfer(e, j, i, distance < NEAR_DISTANCE * radii);
        if (!(G > 0))
            continue;
        const unsigned strata = partly || close ? e->close_strata : e->strata;
        w->pairs_facing++;
        if (outcome == EXACT_CLEAR) {
            w->pairs_clear++;
            e->sink(e->sink_data, thread, i, j, G);
        } else if (outcome == EXACT_SETTLED) {
            w->pairs_exact++;
            if (settled > 0)
                e->sink(e->sink_data, thread, i, j, settled);
        } else if (exact_polygons || partly) {
            /* something may block: the full set of segments at once (a first pass of four
             * would call a pair wholly visible when a small shadow escapes all four). So
             * for a pair with a partly buried patch: when its first four land on the open
             * part, the whole patch's transfer would be taken over the open part's area
             * (the refining pass's fresh segments do not make up for it). A folded wall's
             * factors from a floor patch that a block's corner covers a seventh of came out
             * 5.6 % high, that patch's row 1.4 % above 1. */
            if (w->refine.ray_count + strata * strata > BATCH_RAYS)
                flush_refine(e, w, thread, i);
            batch_add(e, &w->refine, i, j, G, strata, strata, 1);
            w->pairs_refined++;
        } else {
            if (w->first.ray_count + k * k > BATCH_RAYS)
                flush_first(e, w, thread, i);
            batch_add(e, &w->first, i, j, G, k, strata, 0);
        }
    }
    flush_first(e, w, thread, i);
    flush_refine(e, w, thread, i);
}

static unsigned strata_for(uint32_t rays)
{
    if (rays == 0)
        rays = RAD_DEFAULT_VISIBILITY_RAYS;
    unsigned k = (unsigned)lround(sqrt((double)rays));
    return k < 1 ? 1 : k > MAX_STRATA ? MAX_STRATA : k;
}

/* The rows of one call (all, a rank's share, or rounds of them) and their progress. */
typedef struct row_plan {
    const uint8_t *rows;   /* NULL: every row of [0, n) */
    pair_rounds *rounds;   /* NULL: one pass over [0, n) */
} row_plan;

static rad_status run(const rad_mesh *mesh, const rad_tracer *occluders,
                      const rad_formfactor_options *options, row_plan plan, pair_sink_fn sink,
                      void *sink_data, rad_formfactor_report *report, rad_error *error);

rad_status pair_engine_run(const rad_mesh *mesh, const rad_tracer *occluders,
                           const rad_formfactor_options *options, const uint8_t *rows,
                           pair_sink_fn sink, void *sink_data, rad_formfactor_report *report,
                           rad_error *error)
{
    return run(mesh, occluders, options, (row_plan){rows, NULL}, sink, sink_data, report,
               error);
}

rad_status pair_engine_run_rounds(const rad_mesh *mesh, const rad_tracer *occluders,
                                  const rad_formfactor_options *options, pair_rounds *rounds,
                                  pair_sink_fn sink, void *sink_data,
                                  rad_formfactor_report *report, rad_error *error)
{
    return run(mesh, occluders, options, (row_plan){NULL, rounds}, sink, sink_data, report,
               error);
}

static rad_status run(const rad_mesh *mesh, const rad_tracer *occluders,
                      const rad_formfactor_options *options, row_plan plan, pair_sink_fn sink,
                      void *sink_data, rad_formfactor_report *report, rad_error *error)
{
    const uint8_t *rows = plan.rows;
    rad_formfactor_options defaults = {0};
    if (!options)
        options = &defaults;
    uint32_t n = mesh->patch_count;
    unsigned m = options->quadrature ? options->quadrature : RAD_DEFAULT_QUADRATURE;
    if (m > MAX_QUADRATURE)
        return rad_fail(error, RAD_ERR_INVALID, "quadrature %u is above the limit %u", m,
                        MAX_QUADRATURE);
    engine e = {0};
    e.mesh = mesh;
    e.occluders = occluders;
    e.quadrature_count = m * m;
    e.expand_far = m <= EXPANSION_MAX_QUADRATURE;
    if (options->area) { /* the partly buried patches and their open cells */
        uint32_t partly = 0;
        e.partly_buried = rad_alloc_array(n ? n : 1, 1);
        e.cells_of = rad_alloc_array(n ? n : 1, sizeof(*e.cells_of));
        for (uint32_t i = 0; e.partly_buried && e.cells_of && i < n; i++) {
            e.partly_buried[i] = options->area[i] < mesh->patches[i].area * (1 - 1e-12);
            e.cells_of[i] = e.partly_buried[i] ? partly++ : UINT32_MAX;
        }
        e.open_cells = rad_alloc_array(partly ? partly : 1, sizeof(*e.open_cells));
        if (!e.partly_buried || !e.cells_of || !e.open_cells) {
            free(e.partly_buried);
            free(e.cells_of);
            free(e.open_cells);
            return rad_fail(error, RAD_ERR_NOMEM, "out of memory for %u patches", n);
        }
        const double lift = exposed_lift(mesh);
#pragma omp parallel for schedule(dynamic, 4) num_threads(pair_engine_threads(options))
        for (int64_t i = 0; i < (int64_t)n; i++)
            if (e.cells_of[i] != UINT32_MAX)
                patch_open_cells(occluders, mesh, (uint32_t)i, lift, e.open_cells[e.cells_of[i]]);
    }
    unsigned m_near = m > NEAR_QUADRATURE ? m : NEAR_QUADRATURE;
    e.near_count = m_near * m_near;
    e.strata = strata_for(options->visibility_rays);
    e.first_strata = e.strata < FIRST_STRATA ? e.strata : FIRST_STRATA;
    e.close_strata = e.strata > CLOSE_STRATA ? e.strata : CLOSE_STRATA;
    e.seed = options->seed;
    e.sink = sink;
    e.sink_data = sink_data;
    rad_vec3 lo, hi;
    v3_bounds(mesh->vertices, mesh->vertex_count, &lo, &hi);
    e.plane_epsilon = RAD_PLANE_EPSILON * v3_length(v3_sub(hi, lo));

    int threads = pair_engine_threads(options);
    rad_status status = RAD_OK;
    thread_work *work = rad_alloc_array((size_t)threads, sizeof(*work));
    e.geometry = rad_alloc_array(n, sizeof(*e.geometry));
    e.quadrature_points = rad_alloc_array((size_t)n * e.quadrature_count, sizeof(rad_vec3));
    e.quadrature_weights = rad_alloc_array((size_t)n * e.quadrature_count, sizeof(double));
    e.near_points = rad_alloc_array((size_t)n * e.near_count, sizeof(rad_vec3));
    e.near_weights = rad_alloc_array((size_t)n * e.near_count, sizeof(double));
    if (!work || !e.geometry || !e.quadrature_points || !e.quadrature_weights ||
        !e.near_points || !e.near_weights)
        goto nomem;
    for (int t = 0; t < threads; t++) {
        batch *b[2] = {&work[t].first, &work[t].refine};
        for (int k = 0; k < 2; k++) {
            b[k]->rays = rad_alloc_array(BATCH_RAYS, sizeof(*b[k]->rays));
            b[k]->ends = rad_alloc_array(BATCH_RAYS, sizeof(*b[k]->ends));
            b[k]->round = (unsigned)k;
            b[k]->occluded = rad_alloc_array(BATCH_RAYS, sizeof(*b[k]->occluded));
            b[k]->pending = rad_alloc_array(BATCH_RAYS, sizeof(*b[k]->pending));
            if (!b[k]->rays || !b[k]->ends || !b[k]->occluded || !b[k]->pending)
                goto nomem;
        }
    }
    for (uint32_t i = 0; i < n; i++) {
        const rad_patch *patch = &mesh->patches[i];
        patch_geometry *g = &e.geometry[i];
        g->corner_count = patch->vertex_count;
        for (unsigned k = 0; k < patch->vertex_count; k++)
            g->corner[k] = mesh->vertices[patch->vertex[k]];
        g->normal = patch->normal;
        g->area = patch->area;
        patch_map(g);
        g->lift = v3_scale(patch->normal, 2 * patch->behind);
        g->centroid = patch->centroid;
        g->radius = 0;
        for (unsigned k = 0; k < patch->vertex_count; k++)
            g->radius = fmax(g->radius, v3_length(v3_sub(g->corner[k], g->centroid)));
        polygon_moments_of(g->corner, g->corner_count, g->normal, &g->moments);
        quadrature_for(g, m, &e.quadrature_points[(size_t)i * e.quadrature_count],
                       &e.quadrature_weights[(size_t)i * e.quadrature_count]);
        quadrature_for(g, m_near, &e.near_points[(size_t)i * e.near_count],
                       &e.near_weights[(size_t)i * e.near_count]);
    }

    status = near_contacts_build(mesh, near_contacts_reach(mesh), e.plane_epsilon, &e.contacts,
                                 error);
    if (status == RAD_OK)
        status = exact_pairs_build(mesh, occluders, e.plane_epsilon, &e.exact, error);
    if (status == RAD_OK)
        status = exact_pairs_group(&e.exact, mesh, threads, error);
    if (status != RAD_OK)
        goto done;
    double start = rad_clock_seconds();
    double total_pairs = (double)n * (n - 1) / 2;
    uint64_t rows_done = 0;
    if (plan.rounds) { /* the rows in rounds, a callback between two */
        pair_rounds *r = plan.rounds;
        uint32_t total = r->rounds ? r->end[r->rounds - 1] : 0;
        r->stopped_after = r->rounds;
        for (uint32_t round = 0; round < r->rounds; round++) {
            uint32_t first = round ? r->end[round - 1] : 0, last = r->end[round];
#pragma omp parallel num_threads(threads)
            {
                int thread = omp_get_thread_num();
#pragma omp for schedule(dynamic, 1)
                for (uint32_t k = first; k < last; k++) {
                    row(&e, &work[thread], thread, r->order[k]);
                    uint64_t done;
#pragma omp atomic capture
                    done = ++rows_done;
                    if (thread == 0 && options->progress)
                        options->progress(options->progress_user, "form factors",
                                          total ? (double)done / total : 1);
                }
            }
            if (r->after_round && r->after_round(r->user, round, false)) {
                r->stopped_after = round + 1;
                break;
            }
        }
    } else {
#pragma omp parallel num_threads(threads)
        {
            int thread = omp_get_thread_num();
#pragma omp for schedule(dynamic, 1)
            for (uint32_t i = 0; i < n; i++) {
                if (!rows || rows[i])
                    row(&e, &work[thread], thread, i);
                uint64_t done;
#pragma omp atomic capture
                done = ++rows_done;
                if (thread == 0 && options->progress) {
                    /* pairs done when the first `done` rows are finished (rows go in order) */
                    double pairs_done = (double)done * n - (double)done * (done + 1) / 2;
                    options->progress(options->progress_user, "form factors",
                                      total_pairs > 0 ? pairs_done / total_pairs : 1);
                }
            }
        }
    }
    double end = rad_clock_seconds();
    if (report) {
        memset(report, 0, sizeof(*report));
        report->pairs = (uint64_t)total_pairs;
        report->threads = threads;
        for (int t = 0; t < threads; t++) {
            report->rays += work[t].rays_cast;
            report->pairs_facing += work[t].pairs_facing;
            report->pairs_refined += work[t].pairs_refined;
            report->pairs_clear += work[t].pairs_clear;
            report->pairs_exact += work[t].pairs_exact;
            report->tracing_seconds += work[t].tracing_seconds;
        }
        report->seconds = end - start;
    }
    if (options->progress)
        options->progress(options->progress_user, "form factors", 1);
    goto done;
nomem:
    status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for form factors of %u patches", n);
done:
    if (status != RAD_OK && plan.rounds && plan.rounds->after_round)
        plan.rounds->after_round(plan.rounds->user, 0, true); /* failed before the rows */
    if (work)
        for (int t = 0; t < threads; t++) {
            batch *b[2] = {&work[t].first, &work[t].refine};
            for (int k = 0; k < 2; k++) {
                free(b[k]->rays);
                free(b[k]->ends);
                free(b[k]->occluded);
                free(b[k]->pending);
            }
        }
    free(work);
    free(e.geometry);
    free(e.partly_buried);
    free(e.cells_of);
    free(e.open_cells);
    free(e.quadrature_points);
    free(e.quadrature_weights);
    free(e.near_points);
    free(e.near_weights);
    near_contacts_free(&e.contacts);
    exact_pairs_free(&e.exact);
    return status;
}
