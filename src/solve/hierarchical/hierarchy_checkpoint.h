/*
 * hierarchy_checkpoint.h - the hierarchical solver's state in a solve checkpoint (the
 * HIERARCHY kind of solve/solve_checkpoint.h): its loop's counters and flags, the links in
 * their order, B per patch and what came down to each leaf in the last sweep. The element
 * tree is not in it: it is rebuilt from the mesh, the same every time. It lays the state
 * out and checks it back; solve_hierarchical.c decides when, and shares it over ranks.
 */
#ifndef RAD_HIERARCHY_CHECKPOINT_H
#define RAD_HIERARCHY_CHECKPOINT_H

#include "solve/hierarchical/hierarchy.h"
#include "solve/solve_checkpoint.h"

/* Where in the solver the state was taken. */
enum {
    HIER_AT_PASS = 1,      /* the top of the refine-and-sweep loop */
    HIER_IN_GATHER = 2,    /* between the sweeps to the tolerance after a quiet pass */
    HIER_BEFORE_FINAL = 3, /* the loop done, the final gather next */
    HIER_IN_FINAL = 4      /* between the final gather's rounds of leaves */
};

typedef struct hier_loop_state {
    uint32_t phase;
    uint32_t iterations, passes, quiet_passes;
    uint64_t rays, rays_shared;
    bool memory_capped, refining, converged;
    double sweep_change, first; /* the last sweep's change; the gather's first (progress) */
    uint64_t capacity, peak_bytes; /* the link store's (one rank's; summed over ranks) */
    uint32_t final_rounds;         /* HIER_IN_FINAL: the final gather's rounds done */
} hier_loop_state;

/* Puts the state: links[0 .. count) as given, B per patch, down by leaf-order position,
 * and in phase HIER_IN_FINAL the final gather's rounds done and its correction by leaf-order
 * position (the leaves of the rounds not done: 0). */
void hier_checkpoint_put(byte_sink *body, const hier_loop_state *state, uint32_t patches,
                         const hlink *links, uint64_t count, const rad_rgb *B,
                         const rad_rgb *down_by_position,
                         const rad_rgb *correction_by_position);

/* Reads the state back, checking it against the tree (node indices) and the patch count:
 * the links whose receiver keep[] marks (NULL: all) in *links (count, allocated with room
 * for at least `capacity_wanted` or the count, free() it), B, down and (phase
 * HIER_IN_FINAL; else left alone) the final gather's correction by position (n each).
 * False with error set (naming path) for a body that is not a whole, valid state. */
bool hier_checkpoint_get(byte_source *source, const char *path, const hier_tree *tree,
                         uint32_t patches, const uint8_t *keep, hier_loop_state *state,
                         hlink **links, size_t *count, size_t *capacity, rad_rgb *B,
                         rad_rgb *down_by_position, rad_rgb *correction_by_position,
                         rad_error *error);

#endif
