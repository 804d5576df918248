/*
 * final_gather.h - the leaves gather their ancestors' links at their own resolution
 * (internal; see final_gather.c).
 */
#ifndef RAD_HIERARCHY_FINAL_GATHER_H
#define RAD_HIERARCHY_FINAL_GATHER_H

#include <stdbool.h>
#include <stddef.h>

#include "solve/hierarchical/hierarchy.h"

typedef struct final_gather_context {
    const rad_mesh *mesh;
    const hier_tree *tree;
    const rad_tracer *occluders;
    const hlink *links;     /* sorted by receiver */
    const size_t *offsets;  /* node k's links are [offsets[k], offsets[k+1]) */
    const rad_rgb *node_B;  /* pulled radiosity of every node */
    const float *leaf_brightness; /* B.r + B.g + B.b by leaf-order position */
    unsigned rays;          /* segments per partly visible ancestor link; 0: the link's own
                               visible fraction */
    uint64_t seed;
    int threads;
    rad_progress_fn progress; /* "final gather", from the calling thread; may be NULL */
    void *progress_user;
    const volatile int *stop; /* when it becomes non-zero, the gather gives up; may be NULL */
    const uint8_t *receiver_role; /* over MPI ranks: only the leaves RECEIVER_OWN gather;
                                     NULL: every leaf */
    uint32_t first_node, end_node; /* the nodes [first_node, end_node) gather (a round of
                                      the final gather, between checkpoints) */
} final_gather_context;

/* correction[k] for every leaf node k of the context's range (over MPI ranks, this rank's
 * own): the irradiance
 * per unit area its ancestors' links give at its own resolution minus what they hand down
 * (their transfer x B). Adds the segments traced to *rays. Returns 1, or 0 when memory ran
 * out, or -1 when stopped (the corrections are then incomplete and must not be used). */
int hier_final_gather(const final_gather_context *context, rad_rgb *correction,
                      uint64_t *rays);

#endif
