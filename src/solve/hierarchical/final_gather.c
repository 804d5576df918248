/*
 * final_gather.c - every leaf gathers its ancestors' links again at its own resolution.
 *
 * A link at an ancestor of a leaf hands the leaf its receiver's mean irradiance: the
 * kernel's variation across the receiver and the shadow edges inside it are averaged
 * away. After the hierarchical solution has converged, each leaf gathers every link of
 * its ancestors again: the irradiance at its own centre from the link's source, at a finer
 * resolution of the source too (hier_leaf_gather), times the leaf's own visible fraction,
 * traced with segments from the leaf to the source (weighted by the kernel and the
 * source's radiosity where each ends), LEAF_SEGMENTS x `rays` a leaf dealt out in
 * proportion to each link's share of its light, at least one a link and at most `rays`.
 * Every link is traced, hidden ones too: a link's own few segments between two large
 * nodes say little about a leaf in a shadow of its own, and they decided whether the link
 * was refined, so the coarse links that stay are biased (those found open up, those found
 * hidden down). On the furnished room of `bench/room_generator 1000` (8752 patches),
 * keeping the links' own share for those under 1 % of a leaf's light put the ceiling above
 * the lamps' housings 3 to 4 times too bright and the room's surfaces 8.8 % RMS (by
 * region) from the dense solution; traced, 2.2 %. What comes out is a correction per
 * leaf: this irradiance minus what the ancestors' links handed down. The solver keeps it
 * fixed and sweeps again (the correction moves with B only to second order). Parallel
 * over leaves; every random number comes from (seed, leaf, source), so the result does
 * not depend on the thread count. Over MPI ranks each rank corrects its own leaves only
 * (their ancestors' links are all held there).
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "solve/hierarchical/final_gather.h"

/* A leaf's segments for its links' shadows: about this many times the visibility rays
 * (16 by default), dealt out in proportion to each link's share of the leaf's unoccluded
 * light, at least one a link and at most the visibility rays. */
#define LEAF_SEGMENTS 32.0

typedef struct shadowed {
    uint32_t source;
    float visibility;   /* the link's */
    unsigned rays;      /* segments traced from the leaf */
    rad_rgb irradiance; /* unoccluded */
} shadowed;

typedef struct gather_buffers {
    shadowed *pending;
    size_t pending_capacity;
    rad_ray *rays;
    uint8_t *occluded, *blocked;
    double *kernel;
    float *weight;
    size_t ray_capacity;
} gather_buffers;

static bool reserve(gather_buffers *b, size_t pending, size_t rays)
{
    if (pending > b->pending_capacity) {
        size_t capacity = pending + pending / 2;
        shadowed *p = rad_resize_array(b->pending, capacity, sizeof(*p));
        if (!p)
            return false;
        b->pending = p;
        b->pending_capacity = capacity;
    }
    if (rays > b->ray_capacity) {
        size_t capacity = rays + rays / 2;
        rad_ray *r = rad_resize_array(b->rays, capacity, sizeof(*r));
        if (!r)
            return false;
        b->rays = r;
        uint8_t *o = rad_resize_array(b->occluded, capacity, 1);
        if (!o)
            return false;
        b->occluded = o;
        uint8_t *blocked = rad_resize_array(b->blocked, capacity, 1);
        if (!blocked)
            return false;
        b->blocked = blocked;
        double *k = rad_resize_array(b->kernel, capacity, sizeof(*k));
        if (!k)
            return false;
        b->kernel = k;
        float *w = rad_resize_array(b->weight, capacity, sizeof(*w));
        if (!w)
            return false;
        b->weight = w;
        b->ray_capacity = capacity;
    }
    return true;
}

static bool gather_leaf(const final_gather_context *c, uint32_t k, gather_buffers *b,
                        rad_rgb *out, uint64_t *rays_cast)
{
    const hier_tree *t = c->tree;
    const hlink *links = c->links;
    rad_rgb sum = {0, 0, 0}, coarse = {0, 0, 0};
    size_t pending = 0;
    double unoccluded = 0; /* sum over the links looked at, for each one's share */
    for (uint32_t a = k; a != HNODE_NONE; a = t->nodes[a].parent)
        for (size_t l = c->offsets[a]; l < c->offsets[a + 1]; l++) {
            float visibility = (float)link_visibility(&links[l]);
            uint32_t source = links[l].source;
            if (a == k && t->nodes[source].patch != HNODE_NONE)
                continue; /* between two patches: already exact for the leaf */
            rgb_add_to(&coarse, rgb_scale(c->node_B[source], links[l].transfer));
            if (c->rays == 0 && !(visibility > 0))
                continue;
            rad_rgb h = hier_leaf_gather(c->mesh, t, c->node_B, k, source);
            if (!(h.r + h.g + h.b > 0))
                continue;
            if (c->rays == 0) {
                rgb_add_to(&sum, rgb_scale(h, visibility));
                continue;
            }
            if (!reserve(b, pending + 1, 0))
                return false;
            b->pending[pending++] = (shadowed){source, visibility, 0, h};
            unoccluded += h.r + h.g + h.b;
        }
    /* Every link's shadow traced from the leaf: the link's own visible share (a few
     * segments between its two nodes) says little about a leaf in a shadow of its own
     * (above a lamp's housing, under a table), and it decided whether the link was
     * refined, so the links left coarse are those whose segments happened to miss the
     * occluders (and the hidden ones those that happened to meet them). */
    size_t count = 0;
    for (size_t m = 0; m < pending; m++) {
        shadowed *sh = &b->pending[m];
        double share = (sh->irradiance.r + sh->irradiance.g + sh->irradiance.b) / unoccluded;
        double wanted = ceil(LEAF_SEGMENTS * c->rays * share);
        sh->rays = wanted >= c->rays ? c->rays : wanted > 1 ? (unsigned)wanted : 1;
        count += sh->rays;
    }
    if (pending > 0) {
        if (!reserve(b, pending, count))
            return false;
        size_t at = 0;
        for (size_t m = 0; m < pending; m++) {
            const shadowed *sh = &b->pending[m];
            hier_segments(t, c->seed, k, sh->source, sh->rays, b->rays + at, b->kernel + at,
                          c->leaf_brightness, b->weight + at, b->blocked + at);
            at += sh->rays;
        }
        hier_occluded(c->occluders, b->rays, (uint32_t)count, b->blocked, b->occluded);
        *rays_cast += count;
        at = 0;
        for (size_t m = 0; m < pending; m++) {
            const shadowed *sh = &b->pending[m];
            double visible = hier_visible_share(b->kernel + at, b->weight + at,
                                                b->occluded + at, sh->rays, sh->visibility);
            rgb_add_to(&sum, rgb_scale(sh->irradiance, visible));
            at += sh->rays;
        }
    }
    *out = (rad_rgb){sum.r - coarse.r, sum.g - coarse.g, sum.b - coarse.b};
    return true;
}

int hier_final_gather(const final_gather_context *c, rad_rgb *correction, uint64_t *rays)
{
    const hier_tree *t = c->tree;
    int64_t nodes = t->node_count, first = c->first_node,
            end = c->end_node < t->node_count ? c->end_node : t->node_count;
    uint64_t cast = 0;
    int failed = 0, stopped = 0;
#pragma omp parallel num_threads(c->threads) reduction(+ : cast) reduction(| : failed, stopped)
    {
        gather_buffers b = {0};
#pragma omp for schedule(dynamic, 64)
        for (int64_t k = first; k < end; k++) {
            if (c->progress && omp_get_thread_num() == 0 && k % 8192 == 0)
                c->progress(c->progress_user, "final gather", (double)k / (double)nodes);
            if (c->stop && *c->stop)
                stopped = 1;
            if (t->nodes[k].patch == HNODE_NONE || failed || stopped ||
                (c->receiver_role && c->receiver_role[k] != RECEIVER_OWN))
                continue;
            if (!gather_leaf(c, (uint32_t)k, &b, &correction[k], &cast))
                failed = 1;
        }
        free(b.pending);
        free(b.rays);
        free(b.occluded);
        free(b.blocked);
        free(b.kernel);
        free(b.weight);
    }
    *rays += cast;
    return failed ? 0 : stopped ? -1 : 1;
}
