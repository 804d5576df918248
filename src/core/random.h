/*
 * random.h - deterministic, stateless random numbers.
 *
 * Every random number is a hash of (seed, what is being computed, sample index), never a
 * stream shared between threads, so results do not depend on the thread count or on the
 * order in which work is done.
 */
#ifndef RAD_CORE_RANDOM_H
#define RAD_CORE_RANDOM_H

#include <stdint.h>

/* SplitMix64 finaliser: a bijective 64-bit mix. */
static inline uint64_t rad_mix64(uint64_t x)
{
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

/* A small generator for a short sequence of numbers, seeded from a hash. */
typedef struct rad_rng {
    uint64_t state;
} rad_rng;

static inline rad_rng rad_rng_seed(uint64_t a, uint64_t b, uint64_t c)
{
    rad_rng rng = {rad_mix64(a ^ rad_mix64(b ^ rad_mix64(c)))};
    return rng;
}

static inline uint64_t rad_rng_next(rad_rng *rng)
{
    rng->state += 0x9E3779B97F4A7C15ull;
    uint64_t z = rng->state;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1). */
static inline double rad_rng_uniform(rad_rng *rng)
{
    return (double)(rad_rng_next(rng) >> 11) * (1.0 / 9007199254740992.0);
}

/* The 32 bits of j in reverse order: j's base-2 radical inverse, as a binary fraction. */
static inline uint32_t rad_reverse_bits(uint32_t j)
{
    j = ((j >> 1) & 0x55555555u) | ((j & 0x55555555u) << 1);
    j = ((j >> 2) & 0x33333333u) | ((j & 0x33333333u) << 2);
    j = ((j >> 4) & 0x0F0F0F0Fu) | ((j & 0x0F0F0F0Fu) << 4);
    j = ((j >> 8) & 0x00FF00FFu) | ((j & 0x00FF00FFu) << 8);
    return (j >> 16) | (j << 16);
}

/* Radical inverse of j in base b: a coordinate of the Halton sequence, in [0, 1). In base
 * 2 the bits of j reversed, the same value exactly (every partial sum of the digits is a
 * binary fraction of at most 32 bits). */
static inline double rad_radical_inverse(uint32_t j, uint32_t b)
{
    if (b == 2)
        return (double)rad_reverse_bits(j) * (1.0 / 4294967296.0);
    double inverse = 1.0 / b, scale = inverse, value = 0;
    for (; j > 0; j /= b, scale *= inverse)
        value += (j % b) * scale;
    return value;
}

#endif
