/*
 * edge_key.h - an undirected mesh edge as one 64-bit key, and the hash that spreads such
 * keys over an open-addressing table (the finaliser of MurmurHash3's 64-bit mix).
 */
#ifndef RAD_CORE_EDGE_KEY_H
#define RAD_CORE_EDGE_KEY_H

#include <stdint.h>

/* (low vertex << 32) | high vertex: the same for (a, b) and (b, a). */
static inline uint64_t edge_key(uint32_t a, uint32_t b)
{
    return a < b ? ((uint64_t)a << 32) | b : ((uint64_t)b << 32) | a;
}

static inline uint64_t edge_key_hash(uint64_t key)
{
    key ^= key >> 33;
    key *= 0xff51afd7ed558ccdull;
    key ^= key >> 33;
    return key;
}

#endif
