/*
 * refine.c - one level of link refinement (Hanrahan, Salzman and Aupperle 1991).
 *
 * Phase 1 (parallel over links, cheap): each link decides from its stored bound and its
 * source's current radiosity whether it splits and into how many children (settled links
 * are skipped but on full checks). When the children would not fit
 * the budget, the links with the largest bounds split first and the rest stay (the run is
 * then "capped"). Phase 2 (parallel over fixed chunks of links): children are estimated and
 * their visibility traced, written at positions fixed by the chunk's place, then chunks are
 * compacted in order. Nothing depends on the thread count. Over MPI ranks a child whose
 * receiver another rank owns is dropped before it costs anything (that rank makes it from
 * its own copy of the parent, the same way), so each rank's links are the serial run's
 * with its receivers, in the same order.
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/minmax.h"
#include "core/random.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "solve/hierarchical/hierarchy.h"

#define CHUNK_LINKS 1024u   /* parent links per phase-2 chunk */
#define FIRST_RAYS 4u       /* segments every new link gets */
#define MAX_RAYS 64u
#define PARTIAL_FACTOR 0.25 /* partly visible links refine at a quarter of the threshold */
#define SETTLED_SHARE 0.25  /* a link whose error is under this share of its threshold is
                               settled until the next full check */

enum { KEEP = 0, SPLIT_RECEIVER = 1, SPLIT_SOURCE = 2, SPLIT_SELF = 3 };

static unsigned children_of(uint8_t action)
{
    return action == KEEP ? 1 : action == SPLIT_SELF ? 4 : 2;
}

static double brightest(rad_rgb b) { return max_d(b.r, max_d(b.g, b.b)); }

static uint8_t decide(const refine_context *c, hlink *link, float *bound)
{
    *bound = 0;
    if (link->receiver == link->source) {
        *bound = INFINITY;
        return SPLIT_SELF; /* only clusters link to themselves */
    }
    /* the common case touches nothing but the link and its source's B */
    if (!(link->bound > 0) || ((link->flags & LINK_SETTLED) && !c->full_check))
        return KEEP;
    /* a pair its segments found hidden keeps its whole bound: nothing proves it hidden,
     * and light through a window, which all 16 segments between large nodes easily miss,
     * would be lost for good if it counted less (it counted 1/8 until 2026-12-02) */
    double error = brightest(c->node_radiosity[link->source]) * link->bound;
    bool partial = link->visible > 0 && link->visible < LINK_VISIBLE;
    double threshold = c->epsilon * (partial ? PARTIAL_FACTOR : 1);
    *bound = (float)error;
    if (!(error > threshold)) {
        if (error < SETTLED_SHARE * threshold)
            link->flags |= LINK_SETTLED;
        return KEEP;
    }
    link->flags &= (uint16_t)~LINK_SETTLED;
    const hnode *nodes = c->tree->nodes;
    const hnode *p = &nodes[link->receiver], *q = &nodes[link->source];
    bool p_leaf = p->child[0] == HNODE_NONE, q_leaf = q->child[0] == HNODE_NONE;
    if (p_leaf)
        return SPLIT_SOURCE;
    if (q_leaf)
        return SPLIT_RECEIVER;
    /* a cluster receiving pushes one mean irradiance to surfaces of every orientation:
     * split it first; then the larger */
    if (!p->planar)
        return SPLIT_RECEIVER;
    if (!q->planar)
        return SPLIT_SOURCE;
    return p->radius >= q->radius ? SPLIT_RECEIVER : SPLIT_SOURCE;
}

typedef struct pending {
    uint32_t slot;  /* index into the chunk's output */
    uint32_t first; /* its first ray in the batch */
    double factor;  /* two planes' geometric estimate; < 0: a cluster, sample the kernel */
} pending;

typedef struct thread_buffers {
    rad_ray *rays;
    uint8_t *occluded, *blocked;
    double *kernel;
    pending *pend;
    rad_ray *more_rays;
    uint8_t *more_occluded, *more_blocked;
    double *more_kernel;
    float *weight, *more_weight;
} thread_buffers;

/* Children of one chunk of parent links, written to out; returns how many are live. */
static size_t refine_chunk(const refine_context *c, const hlink *links, const uint8_t *action,
                           size_t begin, size_t end, hlink *out, thread_buffers *tb,
                           uint64_t *rays_cast, uint64_t *rays_shared)
{
    const hnode *nodes = c->tree->nodes;
    size_t slot = 0;
    uint32_t pending_count = 0, ray_count = 0;
    for (size_t l = begin; l < end; l++) {
        const hlink *link = &links[l];
        if (action[l] == KEEP) {
            out[slot++] = *link;
            continue;
        }
        uint32_t pairs[4][2];
        unsigned n = 0;
        const hnode *p = &nodes[link->receiver], *q = &nodes[link->source];
        if (action[l] == SPLIT_SELF) {
            for (int a = 0; a < 2; a++)
                for (int b = 0; b < 2; b++) {
                    pairs[n][0] = p->child[a];
                    pairs[n][1] = p->child[b];
                    n++;
                }
        } else if (action[l] == SPLIT_RECEIVER) {
            for (int a = 0; a < 2; a++, n++) {
                pairs[n][0] = p->child[a];
                pairs[n][1] = link->source;
            }
        } else {
            for (int b = 0; b < 2; b++, n++) {
                pairs[n][0] = link->receiver;
                pairs[n][1] = q->child[b];
            }
        }
        for (unsigned k = 0; k < n; k++) {
            hlink *child = &out[slot];
            child->receiver = pairs[k][0];
            child->source = pairs[k][1];
            child->transfer = 0;
            child->visible = (uint16_t)LINK_VISIBLE;
            child->flags = 0;
            child->bound = 0;
            if (c->receiver_role && c->receiver_role[child->receiver] == RECEIVER_ELSEWHERE) {
                child->receiver = HNODE_NONE; /* another rank's: it refines it itself */
                slot++;
                continue;
            }
            if (child->receiver == child->source) {
                if (nodes[child->receiver].planar) /* a plane sends nothing to itself */
                    child->receiver = HNODE_NONE;
                slot++;
                continue;
            }
            link_estimate e = hier_estimate(c->mesh, c->tree, child->receiver, child->source);
            if (!(e.factor > 0) && !(e.factor_bound > 0)) {
                child->receiver = HNODE_NONE;
                slot++;
                continue;
            }
            bool two_patches = nodes[child->receiver].patch != HNODE_NONE &&
                               nodes[child->source].patch != HNODE_NONE;
            child->bound = two_patches ? 0 : (float)e.factor_bound;
            /* two planes: the factor estimate times the visible share; a cluster: the
             * kernel sampled at the segments' ends */
            bool planes = nodes[child->receiver].planar && nodes[child->source].planar;
            tb->pend[pending_count] = (pending){(uint32_t)slot, ray_count,
                                                planes ? e.factor : -1.0};
            hier_segments(c->tree, c->seed, child->receiver, child->source, FIRST_RAYS,
                          &tb->rays[ray_count], &tb->kernel[ray_count], c->leaf_brightness,
                          &tb->weight[ray_count], &tb->blocked[ray_count]);
            ray_count += FIRST_RAYS;
            if (c->receiver_role && c->receiver_role[child->receiver] == RECEIVER_SHARED)
                *rays_shared += FIRST_RAYS;
            pending_count++;
            slot++;
        }
    }
    if (ray_count > 0)
        hier_occluded(c->occluders, tb->rays, ray_count, tb->blocked, tb->occluded);
    *rays_cast += ray_count;
    unsigned extra = c->visibility_rays > FIRST_RAYS ? c->visibility_rays - FIRST_RAYS : 0;
    for (uint32_t k = 0; k < pending_count; k++) {
        const pending *pd = &tb->pend[k];
        hlink *child = &out[pd->slot];
        unsigned visible = 0, total = FIRST_RAYS;
        double kernel_open = 0, weighted_open = 0, weighted_all = 0;
        for (unsigned r = 0; r < FIRST_RAYS; r++) {
            bool open = !tb->occluded[pd->first + r];
            double kernel = tb->kernel[pd->first + r];
            double weighted = kernel * tb->weight[pd->first + r];
            visible += open;
            kernel_open += open ? kernel : 0;
            weighted_open += open ? weighted : 0;
            weighted_all += weighted;
        }
        bool leaves = nodes[child->receiver].patch != HNODE_NONE &&
                      nodes[child->source].patch != HNODE_NONE;
        /* partly visible, or hidden (a gap the first few missed): two patches whose first
         * few segments were all blocked were dropped as hidden, and what the rest of their
         * segments would have found open was lost (the Cornell box's solution 0.06 % of
         * its mean darker for it, on the dense mesh) */
        if (visible < FIRST_RAYS && extra > 0) {
            hier_segments(c->tree, c->seed + 1, child->receiver, child->source, extra,
                          tb->more_rays, tb->more_kernel, c->leaf_brightness, tb->more_weight,
                          tb->more_blocked);
            hier_occluded(c->occluders, tb->more_rays, extra, tb->more_blocked,
                          tb->more_occluded);
            *rays_cast += extra;
            if (c->receiver_role && c->receiver_role[child->receiver] == RECEIVER_SHARED)
                *rays_shared += extra;
            for (unsigned r = 0; r < extra; r++) {
                bool open = !tb->more_occluded[r];
                double kernel = tb->more_kernel[r], weighted = kernel * tb->more_weight[r];
                visible += open;
                kernel_open += open ? kernel : 0;
                weighted_open += open ? weighted : 0;
                weighted_all += weighted;
            }
            total += extra;
        }
        if (visible == 0 && leaves) {
            child->receiver = HNODE_NONE; /* fully hidden */
            continue;
        }
        /* a hidden pair of larger nodes stays (transfer 0) so that refinement can still
         * find what a few segments missed. The visible share is weighted by kernel and
         * radiosity (see hier_visible_share); planes take their factor estimate times it,
         * clusters the sampled kernel itself */
        double share = visible == total  ? 1
                       : weighted_all > 0 ? weighted_open / weighted_all
                                          : (double)visible / total;
        child->visible = link_visible_code(share);
        child->transfer = (float)(pd->factor >= 0 ? pd->factor * share : kernel_open / total);
    }
    size_t live = 0;
    for (size_t k = 0; k < slot; k++)
        if (out[k].receiver != HNODE_NONE)
            out[live++] = out[k];
    return live;
}

typedef struct ranked {
    float bound;
    uint32_t pad;
    size_t index;
} ranked;

static int compare_ranked(const void *a, const void *b)
{
    const ranked *x = a, *y = b;
    if (x->bound != y->bound)
        return x->bound > y->bound ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index;
}

static int grow_store(link_store *store, size_t needed)
{
    if (needed <= store->capacity)
        return 1;
    size_t capacity = store->capacity + store->capacity / 2;
    if (capacity < needed)
        capacity = needed;
    if ((uint64_t)capacity * 2 * sizeof(hlink) > store->max_bytes)
        capacity = needed;
    hlink *a = rad_resize_array(store->links, capacity, sizeof(hlink));
    if (!a)
        return 0;
    store->links = a;
    hlink *b = rad_resize_array(store->spare, capacity, sizeof(hlink));
    if (!b)
        return 0;
    store->spare = b;
    store->capacity = capacity;
    uint64_t bytes = (uint64_t)capacity * 2 * sizeof(hlink);
    if (bytes > store->peak_bytes)
        store->peak_bytes = bytes;
    return 1;
}

int hier_refine_pass(const refine_context *c, link_store *store, refine_result *result)
{
    memset(result, 0, sizeof(*result));
    size_t n = store->count;
    if (n == 0)
        return 1;
    uint8_t *action = rad_alloc_array(n, 1);
    float *bound = rad_alloc_array(n, sizeof(float));
    size_t chunks = (n + CHUNK_LINKS - 1) / CHUNK_LINKS;
    size_t *chunk_start = rad_alloc_array(chunks + 1, sizeof(size_t));
    size_t *chunk_live = rad_alloc_array(chunks, sizeof(size_t));
    if (!action || !bound || !chunk_start || !chunk_live) {
        free(action);
        free(bound);
        free(chunk_start);
        free(chunk_live);
        return 0;
    }
    hlink *links = store->links;
#pragma omp parallel for num_threads(c->threads) schedule(static, 4096)
    for (size_t l = 0; l < n; l++)
        action[l] = decide(c, &links[l], &bound[l]);

    size_t total = 0, split = 0;
    for (size_t l = 0; l < n; l++) {
        total += children_of(action[l]);
        split += action[l] != KEEP;
    }
    size_t fits = (size_t)(store->max_bytes / (2 * sizeof(hlink)));
    int ok = 1;
    if (total > fits) { /* the largest bounds first, while the children fit */
        result->capped = true;
        ranked *order = rad_alloc_array(split ? split : 1, sizeof(ranked));
        if (!order) {
            ok = 0;
        } else {
            size_t m = 0;
            for (size_t l = 0; l < n; l++)
                if (action[l] != KEEP)
                    order[m++] = (ranked){bound[l], 0, l};
            qsort(order, m, sizeof(ranked), compare_ranked);
            total = n;
            split = 0;
            for (size_t k = 0; k < m; k++) {
                size_t more = children_of(action[order[k].index]) - 1;
                if (total + more <= fits) {
                    total += more;
                    split++;
                } else {
                    action[order[k].index] = KEEP;
                }
            }
            free(order);
        }
    }
    if (ok && split > 0 && !grow_store(store, total))
        ok = 0;
    if (!ok || split == 0) {
        free(action);
        free(bound);
        free(chunk_start);
        free(chunk_live);
        result->split = 0;
        return ok;
    }
    chunk_start[0] = 0;
    for (size_t k = 0; k < chunks; k++) {
        size_t end = (k + 1) * CHUNK_LINKS < n ? (k + 1) * CHUNK_LINKS : n;
        size_t sum = 0;
        for (size_t l = k * CHUNK_LINKS; l < end; l++)
            sum += children_of(action[l]);
        chunk_start[k + 1] = chunk_start[k] + sum;
    }
    uint64_t rays = 0, rays_shared = 0;
    int failed = 0;
    unsigned extra_rays = c->visibility_rays > MAX_RAYS ? MAX_RAYS : c->visibility_rays;
    links = store->links;
    hlink *out = store->spare;
#pragma omp parallel num_threads(c->threads) reduction(+ : rays, rays_shared) \
    reduction(| : failed)
    {
        thread_buffers tb;
        size_t most = 4 * (size_t)CHUNK_LINKS;
        tb.rays = rad_alloc_array(most * FIRST_RAYS, sizeof(rad_ray));
        tb.occluded = rad_alloc_array(most * FIRST_RAYS, 1);
        tb.blocked = rad_alloc_array(most * FIRST_RAYS, 1);
        tb.kernel = rad_alloc_array(most * FIRST_RAYS, sizeof(double));
        tb.more_kernel = rad_alloc_array(MAX_RAYS, sizeof(double));
        tb.weight = rad_alloc_array(most * FIRST_RAYS, sizeof(float));
        tb.more_weight = rad_alloc_array(MAX_RAYS, sizeof(float));
        tb.pend = rad_alloc_array(most, sizeof(pending));
        tb.more_rays = rad_alloc_array(MAX_RAYS, sizeof(rad_ray));
        tb.more_occluded = rad_alloc_array(MAX_RAYS, 1);
        tb.more_blocked = rad_alloc_array(MAX_RAYS, 1);
        bool have = tb.rays && tb.occluded && tb.blocked && tb.kernel && tb.pend &&
                    tb.more_rays && tb.more_occluded && tb.more_blocked && tb.more_kernel &&
                    tb.weight && tb.more_weight;
        refine_context local = *c;
        local.visibility_rays = extra_rays;
        failed |= !have; /* whether or not this thread gets a chunk: the same answer for any
                            schedule */
#pragma omp for schedule(dynamic, 1)
        for (size_t k = 0; k < chunks; k++) {
            if (!have)
                continue;
            size_t end = (k + 1) * CHUNK_LINKS < n ? (k + 1) * CHUNK_LINKS : n;
            chunk_live[k] = refine_chunk(&local, links, action, k * CHUNK_LINKS, end,
                                         out + chunk_start[k], &tb, &rays, &rays_shared);
        }
        free(tb.rays);
        free(tb.occluded);
        free(tb.blocked);
        free(tb.kernel);
        free(tb.more_kernel);
        free(tb.weight);
        free(tb.more_weight);
        free(tb.pend);
        free(tb.more_rays);
        free(tb.more_occluded);
        free(tb.more_blocked);
    }
    if (failed) {
        free(action);
        free(bound);
        free(chunk_start);
        free(chunk_live);
        return 0;
    }
    size_t live = 0;
    for (size_t k = 0; k < chunks; k++) {
        if (live != chunk_start[k])
            memmove(out + live, out + chunk_start[k], chunk_live[k] * sizeof(hlink));
        live += chunk_live[k];
    }
    store->spare = store->links;
    store->links = out;
    store->count = live;
    result->split = split;
    result->rays = rays;
    result->rays_shared = rays_shared;
    free(action);
    free(bound);
    free(chunk_start);
    free(chunk_live);
    return 1;
}
