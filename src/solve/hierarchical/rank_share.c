/*
 * rank_share.c - the hierarchy shared over MPI ranks (rank_share.h): the cut into receiver
 * subtrees, their owners, and the leaves' radiosity exchanged after each sweep. A
 * subtree's leaves are contiguous in leaf order, so a rank's leaves are a few runs of
 * positions; each rank packs its own in position order and every rank unpacks all of them
 * by the owners it computed itself. Knows nothing of links or of the sweep.
 */
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/clock.h"
#include "parallel/partition.h"
#include "parallel/ranks.h"
#include "solve/hierarchical/rank_share.h"

void rank_share_free(rank_share *share)
{
    free(share->subtree_of);
    free(share->role);
    free(share->leaf_owner);
    free(share->counts);
    free(share->cursor);
    free(share->mine);
    free(share->all);
    memset(share, 0, sizeof(*share));
}

/* The cut: roots[] (in preorder) of subtrees covering every leaf once; their count. */
static uint32_t cut_tree(const hier_tree *tree, uint32_t target, uint32_t *roots)
{
    uint32_t count = 1;
    roots[0] = 0;
    while (count < target) {
        uint32_t widest = UINT32_MAX;
        for (uint32_t k = 0; k < count; k++) {
            const hnode *n = &tree->nodes[roots[k]];
            if (n->child[0] != HNODE_NONE &&
                (widest == UINT32_MAX || n->count > tree->nodes[roots[widest]].count))
                widest = k;
        }
        if (widest == UINT32_MAX)
            break; /* every subtree is a leaf */
        const hnode *n = &tree->nodes[roots[widest]];
        roots[widest] = n->child[0];
        roots[count++] = n->child[1];
    }
    for (uint32_t k = 1; k < count; k++) /* preorder: insertion sort, count is small */
        for (uint32_t j = k; j > 0 && roots[j - 1] > roots[j]; j--) {
            uint32_t swap = roots[j];
            roots[j] = roots[j - 1];
            roots[j - 1] = swap;
        }
    return count;
}

int rank_share_build(const hier_tree *tree, int ranks, int rank, rank_share *share)
{
    memset(share, 0, sizeof(*share));
    share->ranks = ranks;
    share->rank = rank;
    uint32_t nodes = tree->node_count, leaves = tree->nodes[0].count;
    uint32_t target = RANK_SHARE_SUBTREES_PER_RANK * (uint32_t)ranks;
    uint32_t *roots = rad_alloc_array(target, sizeof(uint32_t));
    share->subtree_of = rad_alloc_array(nodes, sizeof(uint32_t));
    share->role = rad_alloc_array(nodes, 1);
    share->leaf_owner = rad_alloc_array(leaves, sizeof(uint32_t));
    share->counts = rad_alloc_array((size_t)ranks, sizeof(uint64_t));
    share->cursor = rad_alloc_array((size_t)ranks, sizeof(uint64_t));
    share->all = rad_alloc_array(3 * (size_t)leaves, sizeof(double));
    int ok = roots && share->subtree_of && share->role && share->leaf_owner && share->counts &&
             share->cursor && share->all;
    if (ok) {
        share->subtrees = cut_tree(tree, target, roots);
        /* preorder: a cut root's index passes down to its subtree; nodes above: NONE */
        uint32_t next = 0;
        for (uint32_t k = 0; k < nodes; k++) {
            uint32_t parent = tree->nodes[k].parent;
            if (next < share->subtrees && roots[next] == k)
                share->subtree_of[k] = next++;
            else
                share->subtree_of[k] =
                    parent == HNODE_NONE ? HNODE_NONE : share->subtree_of[parent];
        }
    }
    free(roots);
    if (!ok)
        rank_share_free(share);
    return ok;
}

int rank_share_assign(rank_share *share, const hier_tree *tree, const double *cost)
{
    uint32_t *owner = rad_alloc_array(share->subtrees, sizeof(uint32_t));
    rad_error ignored = {0};
    if (!owner || partition_by_cost(cost, share->subtrees, share->ranks, owner, &ignored) !=
                      RAD_OK) {
        free(owner);
        return 0;
    }
    uint32_t me = (uint32_t)share->rank;
    memset(share->counts, 0, (size_t)share->ranks * sizeof(uint64_t));
    for (uint32_t k = 0; k < tree->node_count; k++) {
        uint32_t subtree = share->subtree_of[k];
        share->role[k] = subtree == HNODE_NONE   ? RECEIVER_SHARED
                         : owner[subtree] == me ? RECEIVER_OWN
                                                : RECEIVER_ELSEWHERE;
        const hnode *n = &tree->nodes[k];
        if (n->patch != HNODE_NONE) { /* a leaf is never above the cut */
            share->leaf_owner[n->first] = owner[subtree];
            share->counts[owner[subtree]] += 3;
        }
    }
    free(owner);
    free(share->mine);
    share->mine = rad_alloc_array(share->counts[me] ? share->counts[me] : 1, sizeof(double));
    return share->mine != NULL;
}

void rank_share_exchange(rank_share *share, uint32_t leaves, rad_rgb *by_position)
{
    double start = rad_clock_seconds();
    uint32_t me = (uint32_t)share->rank;
    size_t at = 0;
    for (uint32_t p = 0; p < leaves; p++)
        if (share->leaf_owner[p] == me) {
            share->mine[at++] = by_position[p].r;
            share->mine[at++] = by_position[p].g;
            share->mine[at++] = by_position[p].b;
        }
    ranks_share_parts(share->mine, share->all, share->counts);
    uint64_t *cursor = share->cursor; /* rank r's part starts after the parts before it */
    for (int r = 0; r < share->ranks; r++)
        cursor[r] = r == 0 ? 0 : cursor[r - 1] + share->counts[r - 1];
    for (uint32_t p = 0; p < leaves; p++) {
        uint32_t owner = share->leaf_owner[p];
        if (owner == me)
            continue; /* its own values: the very ones sent */
        const double *v = share->all + cursor[owner];
        by_position[p] = (rad_rgb){v[0], v[1], v[2]};
        cursor[owner] += 3;
    }
    share->seconds_exchanging += rad_clock_seconds() - start;
}
