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

/* Receiver subtrees per rank: enough for the cost sharing to even out (measured on the
 * Cornell box and a furnished room at 2 and 4 ranks: 8 per rank left the most loaded rank
 * 8 to 28 % above the mean links, 32 per rank 1 to 10 %). */
#define RANK_SHARE_SUBTREES_PER_RANK 32u

typedef struct rank_share {
    int ranks, rank;
    uint32_t subtrees;     /* receiver subtrees of the cut */
    uint32_t *subtree_of;  /* per node: its subtree, or HNODE_NONE above the cut */
    uint8_t *role;         /* per node, once assigned: RECEIVER_OWN, RECEIVER_SHARED or
                              RECEIVER_ELSEWHERE */
    uint32_t *leaf_owner;  /* per leaf-order position, once assigned: the rank computing it */
    uint64_t *counts;      /* per rank: doubles it sends (3 per leaf it owns) */
    uint64_t *cursor;      /* per rank: scratch for unpacking */
    double *mine, *all;    /* this rank's leaves' B packed; every rank's */
    double seconds_exchanging; /* in rank_share_exchange, waiting included */
} rank_share;

/* Cuts the tree into at least RANK_SHARE_SUBTREES_PER_RANK x ranks subtrees (splitting the
 * one with the most leaves first, while any has two). The same on every rank. 0 when out
 * of memory. */
int rank_share_build(const hier_tree *tree, int ranks, int rank, rank_share *share);
void rank_share_free(rank_share *share);

/* Shares the subtrees over the ranks by cost[subtree] (partition_by_cost) and marks every
 * node's role and every leaf's owner. The same on every rank for the same costs. 0 when
 * out of memory. */
int rank_share_assign(rank_share *share, const hier_tree *tree, const double *cost);

/* Collective: by_position[] holds, in leaf order, the new B of this rank's leaves; after
 * it, every leaf's, bitwise its owner's. */
void rank_share_exchange(rank_share *share, uint32_t leaves, rad_rgb *by_position);

#endif
