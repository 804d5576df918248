/*
 * union_find.h - the root of x's set in a disjoint-set forest (parent[x] == x at a root),
 * halving the path on the way.
 */
#ifndef RAD_CORE_UNION_FIND_H
#define RAD_CORE_UNION_FIND_H

#include <stdint.h>

static inline uint32_t union_find_root(uint32_t *parent, uint32_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

#endif
