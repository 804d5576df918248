/*
 * rank_share.h - the hierarchy shared over MPI ranks (internal): the tree cut into
 * receiver subtrees, each owned by one rank, which alone holds the links received inside
 * it; the few nodes above the cut (shared) have their links on every rank; after each
 * sweep the leaves' radiosity goes from their owner to every rank. Not the solver
 * (solve_hierarchical.c) and not MPI (parallel/ranks.c).
 */
#ifndef RAD_HIERARCHY_RANK_SHARE_H
#define RAD_HIERARCHY_RANK_SHARE_H

#include <stdint.h>

#include "solve/hierarchical/hierarchy.h"

/* Receiver subtrees per rank: enough for the cost sharing to even out. */
#define RANK_SHARE_SUBTREES_PER_RANK 8u

typedef struct rank_share {
    int ranks, rank;
    uint8_t *role;         /* per node: RECEIVER_OWN, RECEIVER_SHARED or RECEIVER_ELSEWHERE */
    uint32_t *leaf_owner;  /* per leaf-order position: the rank that computes its B */
    uint64_t *counts;      /* per rank: doubles it sends (3 per leaf it owns) */
    uint64_t *cursor;      /* per rank: scratch for unpacking */
    double *mine, *all;    /* this rank's leaves' B packed; every rank's */
    uint32_t subtrees;     /* receiver subtrees of the cut */
    double seconds_exchanging; /* in rank_share_exchange, waiting included */
} rank_share;

/* Cuts the tree into at least RANK_SHARE_SUBTREES_PER_RANK x ranks subtrees (splitting the
 * one with the most leaves first, while any has two), shares them over the ranks by their
 * leaf count (partition_by_cost) and marks every node's role for this rank. The same on
 * every rank. 0 when out of memory. */
int rank_share_build(const hier_tree *tree, int ranks, int rank, rank_share *share);
void rank_share_free(rank_share *share);

/* Collective: by_position[] holds, in leaf order, the new B of this rank's leaves; after
 * it, every leaf's, bitwise its owner's. */
void rank_share_exchange(rank_share *share, uint32_t leaves, rad_rgb *by_position);

#endif
