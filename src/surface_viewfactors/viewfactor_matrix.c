/*
 * viewfactor_matrix.c - surface-to-surface view factors for engineers, see radiosity.h.
 *
 * Surface pairs (I, J), J >= I, are visited once, in parallel over rows I: with sight rays
 * (seen_pairs.h) only the pairs some ray of either side met, the others being 0 within
 * 3 / N; without, every pair. A pair is
 * skipped at once when either surface is planar and the other lies wholly behind (or on)
 * its plane. Otherwise every facing polygon pair (p of I, q of J) adds its transfer
 * G_pq = A_p F_pq (pair_transfer.c): 0 when pair_hidden.c proves every segment between
 * them blocked; the analytic value when the occluder tree proves nothing can stand between
 * them; with a few triangles in between, the same integral of the exactly clipped visible
 * part; with many, that value times a sampled visible fraction, with its bound even when
 * no segment got through.
 * G_IJ = sum G_pq is symmetric, so F_IJ = G_IJ / A_I and F_JI = G_IJ / A_J hold
 * reciprocity exactly. A curved surface sees itself: F_II = 2 sum_{p<q} G_pq / A_I.
 *
 * Memory: each row keeps only its non-zero G_IJ (J >= I) while it is computed; the rows
 * are then assembled into compressed sparse rows. Random numbers come from (seed, p, q),
 * so the result is bitwise the same for any thread count. With a memory budget set
 * (rad_memory_budget_set), the matrix is refused up front when its bound cannot fit
 * (matrix_bound_bytes).
 *
 * Over several MPI ranks (parallel/ranks.h) the rows are shared by estimated cost (its
 * polygon pairs, weighted by what a few sampled pairs of the row would cost: facing or not,
 * how many occluders stand between them), each rank computes its rows with its threads,
 * and rank 0 gathers them and assembles the same matrix, bitwise, as one process would.
 *
 * With checkpoints (checkpoint.h) each rank's rows go in 64 rounds, with a collective
 * checkpoint step between two (checkpoint_step); a resumed run starts with the rows of its
 * checkpoint at rank 0 and shares only the others.
 */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/random.h"
#include "core/vec3.h"
#include "parallel/partition.h"
#include "parallel/ranks.h"
#include "surface_viewfactors/checkpoint.h"
#include "surface_viewfactors/coplanar_polygons.h"
#include "surface_viewfactors/matrix_entry.h"
#include "surface_viewfactors/occluder_tree.h"
#include "surface_viewfactors/pair_hidden.h"
#include "surface_viewfactors/pair_transfer.h"
#include "surface_viewfactors/pending_row.h"
#include "surface_viewfactors/seen_pairs.h"
#include "surface_viewfactors/vf_geometry.h"


/* The work a pair's second exact try may spend, as a multiple of the first's (on the
 * 22k-surface generated city, given that room from the start, none of the 56 pairs that
 * need it took 50 ms). */
#define ROOMY_WORK 16u

/* The relative accuracy of F unobstructed for an obstructed pair integrated exactly: it
 * sets the pair's target (a 1e-3 error in it moves the target by 5e-4) and bounds F from
 * above (by it plus its bound). At the pairs' accuracy it cost the 1k and 5k cities 1 to
 * 2 % of their time. */
#define ROUGH_ACCURACY 1e-3

typedef struct pair_counts {
    uint64_t surface_pairs, polygon_pairs, unobstructed_pairs, hidden_pairs, obstructed_pairs,
        exact_pairs, sampled_pairs, unseen_pairs, capped_pairs, short_pairs, rays, unmet_pairs,
        roomy_pairs;
} pair_counts;

/* Progress by polygon pairs, the unit of work (a row's cost is its polygons times the
 * polygons of the surfaces after it, not its surface count): every thread adds what it
 * finished; OpenMP thread 0 reports, after each of its own polygons, so a long row still
 * moves the bar. */
typedef struct pair_progress {
    rad_progress_fn report; /* NULL: none */
    void *user;
    double total;           /* polygon pairs of the whole matrix */
    double done;            /* atomic */
    double reported;        /* thread 0 only: the last fraction sent */
} pair_progress;

static void progress_add(pair_progress *p, double pairs)
{
    double done;
#pragma omp atomic capture
    {
        p->done += pairs;
        done = p->done;
    }
    if (!p->report || omp_get_thread_num() != 0)
        return;
    double fraction = fmin(done / fmax(p->total, 1), 0.999);
    if (fraction >= p->reported + 0.001) {
        p->reported = fraction;
        p->report(p->user, "view factors", fraction);
    }
}

typedef struct engine {
    pair_progress *progress;
    const vf_geometry *geometry;
    const occluder_tree *tree;
    const rad_tracer *occluders;
    pair_hidden_context hidden; /* the tracer and the scene's planes, for hidden proofs */
    const seen_pairs *seen;     /* the surface pairs some sight ray met (NULL: every pair
                                   is integrated) */
    const uint32_t *surfaces_after; /* per surface I: the surfaces J > I with polygons */
    const double *polygons_after;   /* per surface I: the polygons of the surfaces J > I */
    double accuracy;
    uint32_t max_rays;
    uint32_t exact_occluders; /* pairs behind at most this many triangles: shadow clipping */
    uint64_t seed;
} engine;

static double now_seconds(void) { return rad_clock_seconds(); }

/* Sight rays a surface (seen_pairs.h): ceil(-ln 0.05 / accuracy), enough that a pair none
 * met is within `accuracy` absolute (95 % for each pair); at most 2^26, so below an
 * accuracy of about 4.5e-8 the bound is 3 / 2^26. */
static uint32_t sight_rays_for(double accuracy)
{
    return (uint32_t)fmin(ceil(SEEN_PAIRS_BOUND / accuracy), 67108864.0);
}

/* `plane` is flat and `other` lies wholly behind or on its plane. */
static bool behind_plane(const vf_geometry *g, const vf_surface *plane, const vf_surface *other)
{
    double e = g->plane_epsilon;
    if (!plane->planar)
        return false;
    if (v3_dot(plane->normal, other->center) - plane->offset + other->radius <= e)
        return true;
    for (uint32_t k = 0; k < other->polygon_count; k++)
        if (vf_polygon_in_front(&g->polygons[other->first_polygon + k], plane->normal,
                                plane->offset, e))
            return false;
    return true;
}

/* Either surface flat with the other wholly behind or on its plane: nothing passes. */
static bool surfaces_face_away(const vf_geometry *g, const vf_surface *a, const vf_surface *b)
{
    return behind_plane(g, a, b) || behind_plane(g, b, a);
}

/* The most the matrix can take: every pair (I, J >= I) that the rows will visit (both
 * with polygons, not facing away, a planar surface not with itself; with sight rays only
 * the met pairs) one pending entry while computing, and its one or two entries (F_IJ and
 * F_JI) of the assembled matrix (column, value and bound) while the pending rows are
 * still held. *pairs receives the pair count. */
static uint64_t matrix_bound_bytes(const vf_geometry *g, const seen_pairs *seen, uint64_t *pairs)
{
    uint64_t visited = 0, entries = 0;
    for (uint32_t I = 0; I < g->surface_count; I++) {
        const vf_surface *a = &g->surfaces[I];
        if (a->polygon_count == 0)
            continue;
        if (seen) {
            uint64_t met = seen->row_start[I + 1] - seen->row_start[I];
            visited += met + !a->planar;
            entries += 2 * met + !a->planar;
            continue;
        }
        for (uint32_t J = I; J < g->surface_count; J++) {
            const vf_surface *b = &g->surfaces[J];
            if (b->polygon_count == 0 || (J == I && a->planar) ||
                (J != I && surfaces_face_away(g, a, b)))
                continue;
            visited++;
            entries += J == I ? 1 : 2;
        }
    }
    *pairs = visited;
    return visited * sizeof(row_entry) +
           entries * (sizeof(uint32_t) + 2 * sizeof(double)) +
           2 * ((uint64_t)g->surface_count + 1) * sizeof(uint64_t);
}

/* RAD_ERR_NOMEM, naming the matrix, when its bound (matrix_bound_bytes) does not fit the
 * memory budget. */
static rad_status matrix_fits(const vf_geometry *g, const seen_pairs *seen, rad_error *error)
{
    uint64_t pairs, bound = matrix_bound_bytes(g, seen, &pairs);
    char what[160];
    snprintf(what, sizeof(what), "the view-factor matrix of %u surfaces (%llu pairs that %s)",
             g->surface_count, (unsigned long long)pairs,
             seen ? "some sight ray found in sight of each other" : "face each other");
    return rad_memory_budget_need(bound, what, error);
}

/* G_pq and its error bound; 0 when they do not face each other. A pair is taken as hidden
 * only when pair_proven_hidden proves it; every other pair is integrated, exactly or with
 * sampled visibility, and carries its bound (even a sampled 0). */
static double polygon_pair(const engine *e, uint32_t pi, uint32_t qi, pair_workspace *w,
                           pair_hidden_memory *memory, pair_counts *counts, double *bound)
{
    const vf_polygon *whole_p = &e->geometry->polygons[pi], *whole_q = &e->geometry->polygons[qi];
    double eps = e->geometry->plane_epsilon;
    *bound = 0;
    double p_offset = v3_dot(whole_p->normal, whole_p->vertex[0]),
           q_offset = v3_dot(whole_q->normal, whole_q->vertex[0]);
    if (!vf_polygon_in_front(whole_q, whole_p->normal, p_offset, eps) ||
        !vf_polygon_in_front(whole_p, whole_q->normal, q_offset, eps))
        return 0;
    /* Only the part of each in front of the other's plane exchanges anything (the kernel
     * cos cos / r^2 is 0 elsewhere): the integrals, the occluders in between and the
     * sampled segments are those of these parts. A segment from behind the other's plane
     * weighs nothing: where most of a wall stood below a roof, most segments weighed
     * nothing, and the few that did, all blocked, were taken for a measured 0 (a pair
     * 47 % visible came out hidden). */
    vf_polygon part_p, part_q;
    if (!vf_polygon_clip_front(whole_p, whole_q->normal, q_offset, &part_p) ||
        !vf_polygon_clip_front(whole_q, whole_p->normal, p_offset, &part_q))
        return 0;
    const vf_polygon *p = &part_p, *q = &part_q;
    counts->polygon_pairs++;
    double quadrature_error, unobstructed;
    uint64_t stream = rad_mix64(e->seed ^ rad_mix64(((uint64_t)pi << 32) | qi));
    pair_visibility visibility;
    /* a shape that alone hid one of p's earlier pairs often hides this one: an exact test
     * of a few dozen dot products, tried before any ray */
    if (pair_hidden_by_remembered_shape(&e->hidden, memory, whole_p, whole_q)) {
        counts->hidden_pairs++;
        return 0;
    }
    /* a first look with a few dozen segments: most pairs of a large scene are wholly
     * hidden; when it sees nothing, the occluders in between are asked for a proof */
    pair_sample_visibility(p, q, e->occluders, INFINITY, e->max_rays, stream, w, &visibility);
    counts->rays += visibility.rays;
    if (visibility.fraction == 0) {
        pair_hidden_work work = {0, 0, 0};
        bool hidden = pair_proven_hidden(&e->hidden, memory, whole_p, whole_q, &work);
        counts->rays += work.rays;
        if (hidden) {
            counts->hidden_pairs++;
            return 0;
        }
    }
    uint32_t occluders = occluder_tree_collect(e->tree, p, q, eps, w->occluders,
                                               e->exact_occluders);
    if (occluders == 0) {
        counts->unobstructed_pairs++;
        unobstructed = pair_unobstructed(p, q, 0.25 * e->accuracy, eps, &quadrature_error);
        *bound = quadrature_error;
        counts->short_pairs += quadrature_error > e->accuracy * fabs(unobstructed);
        return fmax(unobstructed, 0);
    }
    counts->obstructed_pairs++;
    /* F unobstructed sets the target and bounds F; an exact pair needs no more of it than
     * ROUGH_ACCURACY, a sampled one (whose F is it times the share of segments seen) gets it
     * to the accuracy below */
    double rough_error;
    unobstructed = pair_unobstructed(p, q, ROUGH_ACCURACY, eps, &rough_error);
    if (!(unobstructed > 0)) {
        *bound = rough_error;
        return 0;
    }
    /* The target: the absolute error of F (seen from the smaller polygon, F0 unobstructed)
     * at most accuracy * sqrt(F0), so that a row's errors, added in quadrature, stay
     * within accuracy (the F0 of a row sum to at most 1) while small factors take few
     * points or rays. As a transfer G = A F: accuracy * sqrt(F0) * A. */
    double smaller = fmin(whole_p->area, whole_q->area);
    double f0 = fmin(unobstructed / smaller, 1);
    double target = e->accuracy * sqrt(f0) * smaller;
    if (occluders <= e->exact_occluders) {
        double visible, error;
        /* Each triangle of the splitting meets its share of the tolerance, halved a level
         * down: the estimates add up to more than it where many triangles are split deep
         * (a pair behind a grid of small occluders), and then the pair is done again to an
         * eighth of the target, with 4 times the work budget (kept when it fits that and
         * its bound is smaller). */
        bool exact = pair_obstructed_exact_within(p, q, w->occluders, occluders,
                                                  0.25 * e->accuracy, 0.5 * target, eps,
                                                  PAIR_EXACT_WORK_BUDGET, &visible, &error);
        /* more than SHADOW_MAX_PIECES visible pieces at a point, or out of work (a large
         * polygon behind hundreds of triangles): once more, with room for
         * PAIR_ROOMY_PIECES and ROOMY_WORK times the work, before sampling */
        bool roomy = false;
        if (!exact)
            exact = roomy = pair_obstructed_exact_roomy(p, q, w->occluders, occluders,
                                                        0.25 * e->accuracy, 0.5 * target, eps,
                                                        ROOMY_WORK * PAIR_EXACT_WORK_BUDGET, w,
                                                        &visible, &error);
        counts->roomy_pairs += roomy;
        double finer, finer_error;
        /* the redo, with more room when the first try's room did not do (its finer cells
         * may break into more pieces) */
        if (exact && error > target &&
            ((!roomy && pair_obstructed_exact_within(p, q, w->occluders, occluders,
                                                     0.25 * e->accuracy, 0.125 * target, eps,
                                                     4 * PAIR_EXACT_WORK_BUDGET, &finer,
                                                     &finer_error)) ||
             pair_obstructed_exact_roomy(p, q, w->occluders, occluders, 0.25 * e->accuracy,
                                         0.125 * target, eps,
                                         4 * ROOMY_WORK * PAIR_EXACT_WORK_BUDGET, w, &finer,
                                         &finer_error)) &&
            finer_error < error) {
            visible = finer;
            error = finer_error;
        }
        if (exact) {
            counts->exact_pairs++;
            counts->short_pairs += error > target;
            *bound = error;
            return fmax(fmin(visible, unobstructed + rough_error), 0);
        }
    }
    counts->sampled_pairs++;
    unobstructed = pair_unobstructed(p, q, 0.25 * e->accuracy, eps, &quadrature_error);
    /* the first look's rounds are taken as they came out, not cast again */
    pair_sample_visibility_resume(p, q, e->occluders, e->accuracy / sqrt(f0), e->max_rays,
                                  stream, w, &visibility);
    counts->rays += visibility.rays;
    counts->capped_pairs += visibility.capped;
    counts->unseen_pairs += visibility.unseen;
    *bound = quadrature_error + visibility.bound * unobstructed;
    counts->short_pairs += *bound > target;
    return unobstructed * visibility.fraction;
}

static bool row_push(pending_row *r, uint32_t column, double transfer, double bound)
{
    if (r->count == r->capacity) {
        uint32_t capacity = r->capacity ? 2 * r->capacity : 8;
        row_entry *grown = rad_resize_array(r->entries, capacity, sizeof(*grown));
        if (!grown)
            return false;
        r->entries = grown;
        r->capacity = capacity;
    }
    r->entries[r->count++] = (row_entry){column, transfer, bound};
    return true;
}

/* Surface pair (I, J >= I) of row I into `out` when it has a transfer or a bound. False
 * when out of memory. */
static bool compute_surface_pair(const engine *e, uint32_t I, uint32_t J, pending_row *out,
                                 pair_workspace *w, pair_hidden_memory *memory,
                                 pair_counts *counts)
{
    const vf_geometry *g = e->geometry;
    const vf_surface *a = &g->surfaces[I], *b = &g->surfaces[J];
    counts->surface_pairs++;
    if (J != I && surfaces_face_away(g, a, b)) {
        progress_add(e->progress, (double)a->polygon_count * b->polygon_count);
        return true;
    }
    double transfer = 0, variance = 0;
    for (uint32_t pk = 0; pk < a->polygon_count; pk++) {
        uint32_t pi = a->first_polygon + pk;
        uint32_t q_first = J == I ? pi + 1 : b->first_polygon;
        for (uint32_t qi = q_first; qi < b->first_polygon + b->polygon_count; qi++) {
            double bound;
            double G = polygon_pair(e, pi, qi, w, memory, counts, &bound);
            transfer += G;
            /* sampled parts are independent: their bounds add in quadrature */
            variance += bound * bound;
        }
        progress_add(e->progress, b->first_polygon + b->polygon_count - q_first);
    }
    if (J == I)
        transfer *= 2, variance *= 4;
    /* a sampled 0 is kept with its bound: what the segments could have missed */
    return !((transfer > 0 || variance > 0) && !row_push(out, J, transfer, sqrt(variance)));
}

/* Row I: every J >= I, or with sight rays, I itself (when curved) and the J > I some ray
 * met; the others are 0 within their bound (seen_pairs.h). False when out of memory. */
static bool compute_row(const engine *e, uint32_t I, pending_row *out, pair_workspace *w,
                        pair_counts *counts)
{
    const vf_geometry *g = e->geometry;
    const vf_surface *a = &g->surfaces[I];
    if (a->polygon_count == 0)
        return true;
    /* the row's own: its result cannot depend on which thread ran which row before */
    pair_hidden_memory memory = {0};
    if (!a->planar && !compute_surface_pair(e, I, I, out, w, &memory, counts))
        return false;
    if (!e->seen) {
        for (uint32_t J = I + 1; J < g->surface_count; J++)
            if (g->surfaces[J].polygon_count &&
                !compute_surface_pair(e, I, J, out, w, &memory, counts))
                return false;
        return true;
    }
    const seen_pairs *seen = e->seen;
    double met_polygons = 0;
    for (uint64_t k = seen->row_start[I]; k < seen->row_start[I + 1]; k++) {
        uint32_t J = seen->column[k];
        met_polygons += g->surfaces[J].polygon_count;
        if (!compute_surface_pair(e, I, J, out, w, &memory, counts))
            return false;
    }
    uint64_t met = seen->row_start[I + 1] - seen->row_start[I];
    counts->surface_pairs += e->surfaces_after[I] - met;
    counts->unmet_pairs += e->surfaces_after[I] - met;
    progress_add(e->progress, a->polygon_count * (e->polygons_after[I] - met_polygons));
    return true;
}

/* Where a row is (state[], one byte per row): not computed yet; whole at rank 0 (computed
 * there, sent there or read from a checkpoint); computed here on another rank and not sent
 * yet. */
enum { ROW_PENDING = 0, ROW_AT_ROOT = 1, ROW_HERE = 2 };

/* Rounds of rows when checkpoints may be written: each rank's rows in this many slices. */
#define CHECKPOINT_ROUNDS 64u

/* Sampled pairs per row for its cost estimate. */
#define COST_SAMPLES 8u

/* What one polygon pair of the sample costs, in units of the first look's few dozen rays:
 * nothing much when they face away, the first look, then the analytic integral, the exact
 * shadow clipping of up to exact_occluders occluders, or sampling behind more. */
static double pair_cost_estimate(const engine *e, const vf_surface *a, const vf_surface *b,
                                 shadow_occluder *occluders)
{
    const vf_geometry *g = e->geometry;
    if (surfaces_face_away(g, a, b))
        return 0.05;
    const vf_polygon *p = &g->polygons[a->first_polygon + a->polygon_count / 2];
    const vf_polygon *q = &g->polygons[b->first_polygon + b->polygon_count / 2];
    double eps = g->plane_epsilon;
    if (!vf_polygon_in_front(q, p->normal, v3_dot(p->normal, p->vertex[0]), eps) ||
        !vf_polygon_in_front(p, q->normal, v3_dot(q->normal, q->vertex[0]), eps))
        return 0.05;
    uint32_t count = occluder_tree_collect(e->tree, p, q, eps, occluders, e->exact_occluders);
    if (count == 0)
        return 1.5;
    return count <= e->exact_occluders ? 2.0 + count : 8.0;
}

/* cost[I]: row I's polygon pairs times the mean estimated cost of COST_SAMPLES of its
 * surface pairs, spread over J >= I. False when out of memory. */
static bool estimate_row_costs(const engine *e, int threads, double *cost)
{
    const vf_geometry *g = e->geometry;
    uint32_t n = g->surface_count;
    double *polygons_after = rad_alloc_array((size_t)n + 1, sizeof(double));
    if (!polygons_after)
        return false;
    for (uint32_t I = n; I-- > 0;)
        polygons_after[I] = polygons_after[I + 1] + g->surfaces[I].polygon_count;
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads)
    for (uint32_t I = 0; I < n; I++) {
        const vf_surface *a = &g->surfaces[I];
        double p = a->polygon_count;
        double pairs = p * (polygons_after[I] - p);
        if (!a->planar)
            pairs += 0.5 * p * (p - 1);
        if (a->polygon_count == 0 || !(pairs > 0)) {
            cost[I] = 0;
            continue;
        }
        shadow_occluder occluders[PAIR_EXACT_MAX_OCCLUDERS];
        double sum = 0;
        uint32_t samples = 0;
        if (e->seen) {
            /* only the met pairs are visited (and a curved surface with itself) */
            const seen_pairs *seen = e->seen;
            uint64_t first = seen->row_start[I], met = seen->row_start[I + 1] - first;
            double met_polygons = 0;
            for (uint64_t k = first; k < first + met; k++)
                met_polygons += g->surfaces[seen->column[k]].polygon_count;
            pairs = p * met_polygons + (a->planar ? 0 : 0.5 * p * (p - 1));
            for (uint32_t k = 0; k < COST_SAMPLES && met; k++) {
                uint32_t J = seen->column[first + (met * (2 * k + 1)) / (2 * COST_SAMPLES)];
                sum += pair_cost_estimate(e, a, &g->surfaces[J], occluders);
                samples++;
            }
            cost[I] = pairs * (samples ? sum / samples : 1.0) + 1e-3 * p * polygons_after[I];
            continue;
        }
        for (uint32_t k = 0; k < COST_SAMPLES; k++) {
            uint32_t J = I + (uint32_t)(((uint64_t)(n - I) * (2 * k + 1)) / (2 * COST_SAMPLES));
            if (J >= n || g->surfaces[J].polygon_count == 0 || J == I)
                continue;
            sum += pair_cost_estimate(e, a, &g->surfaces[J], occluders);
            samples++;
        }
        cost[I] = pairs * (samples ? sum / samples : 1.0);
    }
    free(polygons_after);
    return true;
}

/* Row I's record in the bytes sent to rank 0: I, count, then count (column, transfer,
 * bound). */
static uint64_t packed_row_size(const pending_row *r)
{
    return 2 * sizeof(uint32_t) +
           (uint64_t)r->count * (sizeof(uint32_t) + 2 * sizeof(double));
}

static unsigned char *pack_row(unsigned char *at, uint32_t I, const pending_row *r)
{
    memcpy(at, &I, sizeof(I)), at += sizeof(I);
    memcpy(at, &r->count, sizeof(r->count)), at += sizeof(r->count);
    for (uint32_t k = 0; k < r->count; k++) {
        memcpy(at, &r->entries[k].column, sizeof(uint32_t)), at += sizeof(uint32_t);
        memcpy(at, &r->entries[k].transfer, sizeof(double)), at += sizeof(double);
        memcpy(at, &r->entries[k].bound, sizeof(double)), at += sizeof(double);
    }
    return at;
}

/* Reads the rows of `size` packed bytes into rows[] (which must not hold them yet). False
 * when out of memory or the bytes are not whole records of rows below n. */
static bool unpack_rows(const unsigned char *at, uint64_t size, pending_row *rows, uint8_t *state,
                        uint32_t n)
{
    const unsigned char *end = at + size;
    while (at < end) {
        uint32_t I, count;
        if ((uint64_t)(end - at) < 2 * sizeof(uint32_t))
            return false;
        memcpy(&I, at, sizeof(I)), at += sizeof(I);
        memcpy(&count, at, sizeof(count)), at += sizeof(count);
        uint64_t record = (uint64_t)count * (sizeof(uint32_t) + 2 * sizeof(double));
        if (I >= n || rows[I].entries || (uint64_t)(end - at) < record)
            return false;
        if (count) {
            rows[I].entries = rad_alloc_array(count, sizeof(row_entry));
            if (!rows[I].entries)
                return false;
        }
        rows[I].count = rows[I].capacity = count;
        state[I] = ROW_AT_ROOT;
        for (uint32_t k = 0; k < count; k++) {
            memcpy(&rows[I].entries[k].column, at, sizeof(uint32_t)), at += sizeof(uint32_t);
            memcpy(&rows[I].entries[k].transfer, at, sizeof(double)), at += sizeof(double);
            memcpy(&rows[I].entries[k].bound, at, sizeof(double)), at += sizeof(double);
        }
    }
    return true;
}

/* Sends the rows this rank computed since the last call (state ROW_HERE) to rank 0, which
 * puts them in rows[]; they are freed here and become ROW_AT_ROOT on both sides.
 * Collective. */
static rad_status gather_rows(pending_row *rows, uint8_t *state, uint32_t n, rad_error *error)
{
    int rank = ranks_rank(), count = ranks_count();
    uint64_t size = 0;
    for (uint32_t I = 0; I < n; I++)
        if (state[I] == ROW_HERE)
            size += packed_row_size(&rows[I]);
    unsigned char *mine = rad_alloc_array(size ? size : 1, 1);
    uint64_t *sizes = rad_alloc_array((size_t)count, sizeof(uint64_t));
    bool failed = !mine || !sizes;
    if (ranks_failures(failed)) {
        free(mine);
        free(sizes);
        return rad_fail(error, RAD_ERR_NOMEM, failed ? "out of memory packing view-factor rows"
                                                     : "another rank ran out of memory");
    }
    unsigned char *at = mine;
    for (uint32_t I = 0; I < n; I++)
        if (state[I] == ROW_HERE) { /* rank 0 keeps its own in place */
            at = pack_row(at, I, &rows[I]);
            free(rows[I].entries);
            rows[I] = (pending_row){0};
            state[I] = ROW_AT_ROOT;
        }
    void *gathered = NULL;
    rad_status status = ranks_gather(mine, size, &gathered, sizes, error);
    free(mine);
    uint64_t total = 0;
    for (int r = 0; status == RAD_OK && rank == 0 && r < count; r++)
        total += sizes[r];
    if (status == RAD_OK && rank == 0 && !unpack_rows(gathered, total, rows, state, n))
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory (or a malformed message) "
                                                "assembling the rows of %d ranks", count);
    free(gathered);
    free(sizes);
    if (ranks_failures(status != RAD_OK) && status == RAD_OK)
        status = rad_fail(error, RAD_ERR_NOMEM, "rank 0 could not assemble the view factors");
    return status;
}

/* Checkpoints of a run (rad_viewfactor_options.checkpoint): after each round of rows every
 * rank takes part in checkpoint_step, which writes one when the interval has passed (by
 * rank 0's clock) or a stop was asked for on any rank. */
typedef struct checkpointing {
    const char *path;            /* NULL: none (a run that only stops) */
    double interval, last;       /* seconds; rank 0's clock at the last write */
    const volatile int *stop;
    vf_checkpoint_job job;
    rad_progress_fn progress;    /* rank 0: told "checkpoint" with the share of rows in it */
    void *progress_user;
    uint32_t rows_written;       /* rows in the last checkpoint written */
    bool interrupted;            /* stopped on request, the checkpoint written */
    rad_status status;           /* a checkpoint could not be written: every rank stops */
    rad_error error;
} checkpointing;

/* Collective, from one thread of each rank. True when the rows should stop: a stop was
 * asked for, a rank ran out of memory, or a checkpoint could not be written. */
static bool checkpoint_step(checkpointing *cp, pending_row *rows, uint8_t *state, uint32_t n,
                            bool out_of_memory)
{
    uint64_t flags[2] = {cp->stop && *cp->stop, out_of_memory};
    ranks_sum(flags, 2);
    if (flags[1])
        return true;
    int write = ranks_rank() == 0 && cp->path &&
                (flags[0] || now_seconds() - cp->last >= cp->interval);
    ranks_broadcast(&write, sizeof(write));
    if (write) {
        rad_status status = ranks_count() > 1 ? gather_rows(rows, state, n, &cp->error) : RAD_OK;
        uint32_t done = 0;
        for (uint32_t I = 0; I < n; I++)
            done += state[I] == ROW_AT_ROOT;
        if (status == RAD_OK && ranks_rank() == 0)
            status = vf_checkpoint_write(cp->path, &cp->job, rows, state, &cp->error);
        status = ranks_share_status(status, &cp->error);
        if (status != RAD_OK) {
            cp->status = status;
            return true;
        }
        cp->last = now_seconds();
        cp->rows_written = done;
        if (ranks_rank() == 0 && cp->progress)
            cp->progress(cp->progress_user, "checkpoint", n ? (double)done / n : 1);
    }
    if (flags[0])
        cp->interrupted = true;
    return flags[0] != 0;
}

static rad_viewfactor_matrix *assemble(const vf_geometry *g, pending_row *rows, uint32_t n)
{
    rad_viewfactor_matrix *m = rad_alloc_array(1, sizeof(*m));
    if (!m)
        return NULL;
    m->n = n;
    m->area = rad_alloc_array(n ? n : 1, sizeof(double));
    m->row_start = rad_alloc_array((size_t)n + 1, sizeof(uint64_t));
    uint64_t *cursor = rad_alloc_array((size_t)n + 1, sizeof(uint64_t));
    if (!m->area || !m->row_start || !cursor) {
        free(cursor);
        rad_viewfactor_matrix_destroy(m);
        return NULL;
    }
    for (uint32_t I = 0; I < n; I++) {
        m->area[I] = g->surfaces[I].area;
        for (uint32_t k = 0; k < rows[I].count; k++) {
            m->row_start[I + 1]++;
            if (rows[I].entries[k].column != I)
                m->row_start[rows[I].entries[k].column + 1]++;
        }
    }
    for (uint32_t I = 0; I < n; I++)
        m->row_start[I + 1] += m->row_start[I];
    uint64_t total = m->row_start[n];
    m->column = rad_alloc_array(total ? total : 1, sizeof(uint32_t));
    m->value = rad_alloc_array(total ? total : 1, sizeof(double));
    m->error_bound = rad_alloc_array(total ? total : 1, sizeof(double));
    if (!m->column || !m->value || !m->error_bound) {
        free(cursor);
        rad_viewfactor_matrix_destroy(m);
        return NULL;
    }
    memcpy(cursor, m->row_start, ((size_t)n + 1) * sizeof(uint64_t));
    /* row I's own entries (columns >= I) arrive after every transposed entry of column
     * < I, so each row comes out sorted */
    for (uint32_t I = 0; I < n; I++) {
        for (uint32_t k = 0; k < rows[I].count; k++) {
            const row_entry *entry = &rows[I].entries[k];
            uint32_t J = entry->column;
            uint64_t at = cursor[I]++;
            m->column[at] = J;
            m->value[at] = fmin(entry->transfer / m->area[I], 1.0);
            m->error_bound[at] = entry->bound / m->area[I];
            if (J != I) {
                at = cursor[J]++;
                m->column[at] = I;
                m->value[at] = fmin(entry->transfer / m->area[J], 1.0);
                m->error_bound[at] = entry->bound / m->area[J];
            }
        }
        free(rows[I].entries);
        rows[I].entries = NULL;
    }
    free(cursor);
    return m;
}

/* Frees what the matrix's setup holds when it stops before the rows (rows may be NULL). */
static void release_setup(pending_row *rows, uint32_t n, uint8_t *state, uint32_t *mine,
                          rad_tracer *occluders, occluder_tree *tree, coplanar_polygons *planes,
                          vf_geometry *geometry)
{
    for (uint32_t I = 0; rows && I < n; I++)
        free(rows[I].entries);
    free(rows);
    free(state);
    free(mine);
    rad_tracer_destroy(occluders);
    occluder_tree_destroy(tree);
    coplanar_polygons_free(planes);
    vf_geometry_free(geometry);
}

rad_status rad_viewfactor_matrix_compute(const rad_scene *scene,
                                         const rad_viewfactor_options *options,
                                         rad_viewfactor_matrix **out,
                                         rad_viewfactor_report *report, rad_error *error)
{
    *out = NULL;
    rad_viewfactor_options defaults = {0};
    if (!options)
        options = &defaults;
    if (options->threads < 0 || !(options->accuracy >= 0) || options->accuracy >= 1)
        return rad_fail(error, RAD_ERR_INVALID,
                        "view factors: threads must be >= 0 and accuracy in [0, 1)");
    if (options->exact_occluders > RAD_MAX_EXACT_OCCLUDERS)
        return rad_fail(error, RAD_ERR_INVALID,
                        "view factors: exact_occluders must be at most %d (it is %u)",
                        RAD_MAX_EXACT_OCCLUDERS, options->exact_occluders);
    double start = now_seconds();
    int threads = options->threads > 0 ? options->threads : omp_get_max_threads();
    engine e = {.accuracy = options->accuracy > 0 ? options->accuracy : RAD_DEFAULT_ACCURACY,
                .max_rays = options->max_rays ? options->max_rays : RAD_DEFAULT_MAX_RAYS,
                .exact_occluders = options->exact_occluders ? options->exact_occluders
                                                            : RAD_DEFAULT_EXACT_OCCLUDERS,
                .seed = options->seed};
    if (e.max_rays < 64)
        e.max_rays = 64;
    vf_geometry geometry;
    occluder_tree *tree = NULL;
    rad_tracer *occluders = NULL;
    coplanar_polygons planes = {0};
    pending_row *rows = NULL;
    rad_status status = vf_geometry_build(scene, &geometry, error);
    /* without sight rays the matrix's bound is known now; with them, once the rays have
     * found the pairs that see each other */
    if (status == RAD_OK && rad_memory_budget() && options->sight_rays == RAD_SIGHT_RAYS_NONE)
        status = matrix_fits(&geometry, NULL, error);
    if (status == RAD_OK)
        status = occluder_tree_build(scene, geometry.triangle_source, true, &tree, error);
    if (status == RAD_OK)
        status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE_FAST, scene, &occluders, error);
    if (status == RAD_OK)
        status = coplanar_polygons_build(scene, &geometry, &planes, error);
    uint32_t n = scene->surface_count;
    uint8_t *state = NULL;
    uint32_t *mine = NULL;
    if (status == RAD_OK) {
        rows = rad_alloc_array(n ? n : 1, sizeof(pending_row));
        state = rad_alloc_array(n ? n : 1, 1);
        mine = rad_alloc_array(n ? n : 1, sizeof(uint32_t));
        if (!rows || !state || !mine)
            status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for %u rows", n);
    }
    status = ranks_agree(status, "view factors", error);
    int rank = ranks_rank();
    /* a resumed run: rank 0 reads the rows done, and every rank learns which they are */
    uint32_t sight_rays = options->sight_rays == RAD_SIGHT_RAYS_NONE ? 0
                          : options->sight_rays                   ? options->sight_rays
                                                                  : sight_rays_for(e.accuracy);
    vf_checkpoint_job job = {vf_checkpoint_fingerprint(scene), n, e.accuracy, e.max_rays, e.seed,
                             sight_rays, e.exact_occluders};
    uint32_t resumed = 0;
    if (status == RAD_OK && options->resume) {
        if (rank == 0)
            status = vf_checkpoint_read(options->resume, &job, rows, state, &resumed, error);
        status = ranks_share_status(status, error);
        if (status == RAD_OK) {
            ranks_broadcast(state, n);
            ranks_broadcast(&resumed, sizeof(resumed));
        }
    }
    if (status != RAD_OK) {
        release_setup(rows, n, state, mine, occluders, tree, &planes, &geometry);
        return status;
    }
    e.geometry = &geometry;
    e.tree = tree;
    e.occluders = occluders;
    e.hidden = (pair_hidden_context){&planes, occluders, geometry.plane_epsilon};

    /* the pairs some sight ray met (seen_pairs.h): every rank the same, for any rows */
    seen_pairs seen = {0};
    uint32_t *surfaces_after = rad_alloc_array((size_t)n + 1, sizeof(uint32_t));
    double *polygons_after_surface = rad_alloc_array((size_t)n + 1, sizeof(double));
    status = surfaces_after && polygons_after_surface
                 ? RAD_OK
                 : rad_fail(error, RAD_ERR_NOMEM, "out of memory for %u rows", n);
    status = ranks_agree(status, "view factors", error);
    double sight_start = now_seconds();
    if (status == RAD_OK) {
        surfaces_after[n] = 0;
        polygons_after_surface[n] = 0;
        for (uint32_t I = n; I-- > 0;) {
            uint32_t polygons = I + 1 < n ? geometry.surfaces[I + 1].polygon_count : 0;
            surfaces_after[I] = surfaces_after[I + 1] + (polygons > 0);
            polygons_after_surface[I] = polygons_after_surface[I + 1] + polygons;
        }
        if (sight_rays)
            status = seen_pairs_build(scene, &geometry, occluders, sight_rays, e.seed, threads,
                                      &seen, error);
        if (status == RAD_OK && sight_rays && rad_memory_budget())
            status = matrix_fits(&geometry, &seen, error);
        status = ranks_agree(status, "view factors", error);
    }
    double sight_seconds = now_seconds() - sight_start;
    if (status != RAD_OK) {
        seen_pairs_free(&seen);
        free(surfaces_after);
        free(polygons_after_surface);
        release_setup(rows, n, state, mine, occluders, tree, &planes, &geometry);
        return status;
    }
    e.seen = sight_rays ? &seen : NULL;
    e.surfaces_after = surfaces_after;
    e.polygons_after = polygons_after_surface;

    /* over several ranks: who computes which row (owner NULL: this process, all), decided
     * by rank 0 alone so that no rank can disagree; resumed rows are rank 0's already */
    uint32_t *owner = NULL;
    if (ranks_count() > 1) {
        double *cost = rank == 0 ? rad_alloc_array(n ? n : 1, sizeof(double)) : NULL;
        owner = rad_alloc_array(n ? n : 1, sizeof(uint32_t));
        bool failed = (rank == 0 && !cost) || !owner;
        if (!failed && rank == 0) {
            failed = !estimate_row_costs(&e, threads, cost);
            for (uint32_t I = 0; !failed && I < n; I++)
                if (state[I] != ROW_PENDING)
                    cost[I] = 0;
            failed = failed || partition_by_cost(cost, n, ranks_count(), owner, error) != RAD_OK;
            for (uint32_t I = 0; !failed && I < n; I++)
                if (state[I] != ROW_PENDING)
                    owner[I] = 0;
        }
        free(cost);
        if (ranks_failures(failed)) {
            free(owner);
            seen_pairs_free(&seen);
            free(surfaces_after);
            free(polygons_after_surface);
            release_setup(rows, n, state, mine, occluders, tree, &planes, &geometry);
            return rad_fail(error, RAD_ERR_NOMEM, "out of memory sharing %u rows over %d ranks",
                            n, ranks_count());
        }
        ranks_broadcast(owner, (uint64_t)n * sizeof(uint32_t));
    }

    /* the rows this rank computes, and the polygon pairs (I, J >= I) they will visit */
    pair_progress progress = {options->progress, options->progress_user, 0, 0, 0};
    double polygons_after = 0;
    uint32_t rank_rows = 0;
    for (uint32_t I = n; I-- > 0;) {
        double p = geometry.surfaces[I].polygon_count;
        double self = geometry.surfaces[I].planar ? 0 : 0.5 * p * (p - 1);
        if ((!owner || owner[I] == (uint32_t)rank) && state[I] == ROW_PENDING) {
            progress.total += p * polygons_after + self;
            rank_rows++;
        }
        polygons_after += p;
    }
    for (uint32_t I = 0, k = 0; I < n; I++)
        if ((!owner || owner[I] == (uint32_t)rank) && state[I] == ROW_PENDING)
            mine[k++] = I;
    e.progress = &progress;
    /* with checkpoints (or a stop to watch), the rows go in rounds with a checkpoint step
     * between two; else in one */
    checkpointing cp = {options->checkpoint, options->checkpoint_interval, now_seconds(),
                        options->stop, job, options->progress, options->progress_user,
                        0, false, RAD_OK, {0}};
    uint32_t rounds = options->checkpoint || options->stop ? CHECKPOINT_ROUNDS : 1;
    uint8_t computed_state = owner && rank != 0 ? ROW_HERE : ROW_AT_ROOT;
    pair_counts totals = {0};
    bool out_of_memory = false, stopped = false;
    double rows_start = now_seconds();
#pragma omp parallel num_threads(threads)
    {
        pair_workspace w;
        pair_counts counts = {0};
        bool ready = pair_workspace_init(&w, e.max_rays);
        if (!ready) {
#pragma omp atomic write
            out_of_memory = true;
        }
        for (uint32_t round = 0; round < rounds; round++) {
            uint32_t begin = (uint32_t)((uint64_t)rank_rows * round / rounds);
            uint32_t end = (uint32_t)((uint64_t)rank_rows * (round + 1) / rounds);
            /* a stop leaves the round's other rows pending (the checkpoint after it has
             * the rows done), so it takes effect within a row; not in the last round,
             * after which no checkpoint step comes */
            bool stoppable = options->stop && round + 1 < rounds;
#pragma omp for schedule(dynamic, 1)
            for (uint32_t k = begin; k < end; k++) {
                bool failed;
#pragma omp atomic read
                failed = out_of_memory;
                if (failed || !ready || (stoppable && *options->stop))
                    continue;
                if (!compute_row(&e, mine[k], &rows[mine[k]], &w, &counts)) {
#pragma omp atomic write
                    out_of_memory = true;
                } else {
                    state[mine[k]] = computed_state;
                }
            }
            if (round + 1 == rounds)
                break;
            /* MPI from the master thread only; the barrier publishes its answer, and no
             * thread writes `stopped` again before every thread has passed the next round's
             * closing barrier */
#pragma omp master
            stopped = checkpoint_step(&cp, rows, state, n, out_of_memory);
#pragma omp barrier
            if (stopped)
                break;
        }
        pair_workspace_free(&w);
#pragma omp critical
        {
            totals.surface_pairs += counts.surface_pairs;
            totals.polygon_pairs += counts.polygon_pairs;
            totals.unobstructed_pairs += counts.unobstructed_pairs;
            totals.hidden_pairs += counts.hidden_pairs;
            totals.obstructed_pairs += counts.obstructed_pairs;
            totals.exact_pairs += counts.exact_pairs;
            totals.sampled_pairs += counts.sampled_pairs;
            totals.unseen_pairs += counts.unseen_pairs;
            totals.capped_pairs += counts.capped_pairs;
            totals.short_pairs += counts.short_pairs;
            totals.rays += counts.rays;
            totals.unmet_pairs += counts.unmet_pairs;
            totals.roomy_pairs += counts.roomy_pairs;
        }
    }
    double rank_seconds = now_seconds() - rows_start;
    double missed_largest = 0, missed_sum = 0;
    uint32_t missed_rows = 0;
    for (uint32_t I = 0; sight_rays && I < n; I++)
        if (geometry.surfaces[I].polygon_count) {
            missed_largest = fmax(missed_largest, seen.missed[I]);
            missed_sum += seen.missed[I];
            missed_rows++;
        }
    seen_pairs_free(&seen);
    free(surfaces_after);
    free(polygons_after_surface);
    rad_tracer_destroy(occluders);
    occluder_tree_destroy(tree);
    coplanar_polygons_free(&planes);
    rad_viewfactor_matrix *matrix = NULL;
    if (cp.status != RAD_OK) {
        status = cp.status;
        *error = cp.error;
    }
    if (owner) {
        if (status == RAD_OK)
            status = ranks_failures(out_of_memory)
                         ? rad_fail(error, RAD_ERR_NOMEM,
                                    out_of_memory ? "out of memory for view-factor rows"
                                                  : "another rank ran out of memory")
                     : cp.interrupted ? RAD_OK
                                      : gather_rows(rows, state, n, error);
        uint64_t sums[14] = {totals.surface_pairs,      totals.polygon_pairs,
                             totals.unobstructed_pairs, totals.hidden_pairs,
                             totals.obstructed_pairs,   totals.exact_pairs,
                             totals.sampled_pairs,      totals.unseen_pairs,
                             totals.capped_pairs,       totals.short_pairs,
                             totals.rays,               totals.unmet_pairs,
                             totals.roomy_pairs,        seen.rays_cast};
        ranks_sum(sums, 14);
        totals = (pair_counts){sums[0], sums[1], sums[2],  sums[3],  sums[4],  sums[5], sums[6],
                               sums[7], sums[8], sums[9], sums[10], sums[11], sums[12]};
        seen.rays_cast = sums[13];
        free(owner);
        if (status == RAD_OK && rank == 0 && !cp.interrupted)
            matrix = assemble(&geometry, rows, n);
    } else if (status == RAD_OK && out_of_memory) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for view-factor rows");
    } else if (status == RAD_OK && !cp.interrupted) {
        matrix = assemble(&geometry, rows, n);
    }
    for (uint32_t I = 0; I < n; I++)
        free(rows[I].entries);
    free(rows);
    free(state);
    free(mine);
    vf_geometry_free(&geometry);
    if (status != RAD_OK)
        return status;
    if (!matrix && rank == 0 && !cp.interrupted)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the view factors of %u surfaces",
                        n);
    if (options->progress && !cp.interrupted)
        options->progress(options->progress_user, "view factors", 1.0);
    if (report) {
        memset(report, 0, sizeof(*report));
        report->surface_pairs = totals.surface_pairs;
        report->polygon_pairs = totals.polygon_pairs;
        report->unobstructed_pairs = totals.unobstructed_pairs;
        report->hidden_pairs = totals.hidden_pairs;
        report->obstructed_pairs = totals.obstructed_pairs;
        report->exact_pairs = totals.exact_pairs;
        report->sampled_pairs = totals.sampled_pairs;
        report->unseen_pairs = totals.unseen_pairs;
        report->capped_pairs = totals.capped_pairs;
        report->short_pairs = totals.short_pairs;
        report->rays = totals.rays;
        report->unmet_pairs = totals.unmet_pairs;
        report->roomy_pairs = totals.roomy_pairs;
        report->sight_rays = sight_rays;
        report->exact_occluders = e.exact_occluders;
        report->sight_rays_cast = seen.rays_cast;
        report->unmet_bound = sight_rays ? SEEN_PAIRS_BOUND / sight_rays : 0;
        report->sight_seconds = sight_seconds;
        report->missed_largest = missed_largest;
        report->missed_mean = missed_rows ? missed_sum / missed_rows : 0;
        for (uint64_t k = 0; matrix && k < matrix->row_start[n]; k++) {
            report->nonzeros += matrix->value[k] != 0;
            report->largest_error_bound =
                fmax(report->largest_error_bound, matrix->error_bound[k]);
        }
        report->seconds = now_seconds() - start;
        report->threads = threads;
        report->rank_rows = rank_rows;
        report->rank_seconds = rank_seconds;
        report->resumed_rows = resumed;
        report->checkpoint_rows = cp.rows_written;
        report->interrupted = cp.interrupted;
    }
    *out = matrix;
    return RAD_OK;
}

void rad_viewfactor_matrix_destroy(rad_viewfactor_matrix *matrix)
{
    if (!matrix)
        return;
    free(matrix->area);
    free(matrix->row_start);
    free(matrix->column);
    free(matrix->value);
    free(matrix->error_bound);
    free(matrix);
}

double rad_viewfactor_matrix_get(const rad_viewfactor_matrix *matrix, uint32_t row,
                                 uint32_t column)
{
    if (row >= matrix->n || column >= matrix->n)
        return 0;
    uint64_t entry = vf_matrix_entry(matrix, row, column);
    return entry == UINT64_MAX ? 0 : matrix->value[entry];
}
