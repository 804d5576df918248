/*
 * hash.h - FNV-1a, 64 bits: the fingerprint and checksum of solution files, all inline.
 *
 * Not cryptographic: it tells apart scenes and catches damaged files. Every step (xor a
 * byte, multiply by an odd prime) is a bijection of the state, so changing any single byte
 * of the input always changes the hash. Numbers are hashed through their little-endian
 * bytes (core/bytes.h), so the value is the same on every machine.
 */
#ifndef RAD_CORE_HASH_H
#define RAD_CORE_HASH_H

#include <stddef.h>
#include <stdint.h>

#include "core/bytes.h"

#define RAD_HASH_START 0xcbf29ce484222325ull /* FNV-1a 64 offset basis */
#define RAD_HASH_PRIME 0x100000001b3ull      /* FNV-1a 64 prime */

static inline uint64_t hash_bytes(uint64_t hash, const void *data, size_t size)
{
    const uint8_t *p = data;
    for (size_t k = 0; k < size; k++) {
        hash ^= p[k];
        hash *= RAD_HASH_PRIME;
    }
    return hash;
}

static inline uint64_t hash_u32(uint64_t hash, uint32_t v)
{
    uint8_t b[4];
    bytes_put_u32(b, v);
    return hash_bytes(hash, b, sizeof(b));
}

static inline uint64_t hash_f64(uint64_t hash, double v)
{
    uint8_t b[8];
    bytes_put_f64(b, v);
    return hash_bytes(hash, b, sizeof(b));
}

#endif
