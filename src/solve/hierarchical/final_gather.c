/*
 * final_gather.c - every leaf gathers its ancestors' links again at its own resolution.
 *
 * A link at an ancestor of a leaf hands the leaf its receiver's mean irradiance: the
 * kernel's variation across the receiver and the shadow edges inside it are averaged
 * away. After the hierarchical solution has converged, each leaf gathers every link of
 * its ancestors again: the irradiance at its own centre from the link's source, at a finer
 * resolution of the source too (hier_leaf_gather), times the leaf's own visible fraction,
 * traced with `rays` segments from the leaf to the source (weighted by the kernel and the
 * source's radiosity where each ends: hier_visible_share), for a visible link that brings
 * a large enough share of the light (a hidden one brings none; the others keep their
 * link's fraction). What comes out is a correction per leaf: this irradiance
 * minus what the ancestors' links handed down. The solver keeps it fixed and sweeps again
 * (the correction moves with B only to second order). Parallel over leaves; every random
 * number comes from (seed, leaf, source), so the result does not depend on the thread
 * count. Over MPI ranks each rank corrects its own leaves only (their ancestors' links
 * are all held there).
 */
#include <omp.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "solve/hierarchical/final_gather.h"

/* A visible ancestor's link whose unoccluded irradiance is at least this share of all
 * those links' has its shadow traced from the leaf. */
#define TRACED_SHARE 0.01

typedef struct shadowed {
    uint32_t source;
    float visibility;   /* the link's */
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
    double unoccluded = 0; /* sum over the ancestors' visible links, for the share traced */
    for (uint32_t a = k; a != HNODE_NONE; a = t->nodes[a].parent)
        for (size_t l = c->offsets[a]; l < c->offsets[a + 1]; l++) {
            float visibility = (float)link_visibility(&links[l]);
            uint32_t source = links[l].source;
            if (a == k && t->nodes[source].patch != HNODE_NONE)
                continue; /* between two patches: already exact for the leaf */
            rgb_add_to(&coarse, rgb_scale(c->node_B[source], links[l].transfer));
            if (!(visibility > 0))
                continue;
            rad_rgb h = hier_leaf_gather(c->mesh, t, c->node_B, k, source);
            if (!(h.r + h.g + h.b > 0))
                continue;
            /* the leaf's own link traced its visibility from the leaf already; an
             * ancestor's link found wholly visible by a few segments between two large
             * nodes says little about this leaf, which may lie in a shadow they missed: it
             * is traced from the leaf like a partly visible one */
            if (c->rays == 0 || a == k) {
                rgb_add_to(&sum, rgb_scale(h, visibility));
                continue;
            }
            if (!reserve(b, pending + 1, (pending + 1) * c->rays))
                return false;
            b->pending[pending++] = (shadowed){source, visibility, h};
            unoccluded += h.r + h.g + h.b;
        }
    /* the links that bring a large share of the light: their shadows traced from the leaf;
     * the rest keep their link's visible share */
    size_t traced = 0;
    for (size_t m = 0; m < pending; m++) {
        const shadowed *sh = &b->pending[m];
        if (sh->irradiance.r + sh->irradiance.g + sh->irradiance.b >= TRACED_SHARE * unoccluded)
            b->pending[traced++] = *sh;
        else
            rgb_add_to(&sum, rgb_scale(sh->irradiance, sh->visibility));
    }
    if (traced > 0) {
        for (size_t m = 0; m < traced; m++)
            hier_segments(t, c->seed, k, b->pending[m].source, c->rays, b->rays + m * c->rays,
                          b->kernel + m * c->rays, c->leaf_brightness, b->weight + m * c->rays,
                          b->blocked + m * c->rays);
        size_t count = traced * c->rays;
        hier_occluded(c->occluders, b->rays, (uint32_t)count, b->blocked, b->occluded);
        *rays_cast += count;
        for (size_t m = 0; m < traced; m++) {
            double visible = hier_visible_share(b->kernel + m * c->rays, b->weight + m * c->rays,
                                                b->occluded + m * c->rays, c->rays);
            rgb_add_to(&sum, rgb_scale(b->pending[m].irradiance, visible));
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
