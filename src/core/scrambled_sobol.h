/*
 * scrambled_sobol.h - points of the unit square from the first two dimensions of Sobol's
 * sequence, Owen-scrambled (internal, inline).
 *
 * The first 2^m points of the two-dimensional Sobol sequence are a (0, m, 2)-net: every
 * elementary box of area 2^-m (2^a x 2^b cells, a + b = m) holds exactly one point, so
 * they stratify the square at every aspect ratio at once, where a jittered grid stratifies
 * it at one. Owen's nested uniform scrambling (a random permutation of each binary digit,
 * chosen by the digits above it) keeps that property and makes every point uniform, so
 * estimates stay unbiased; their variance falls as N^-3 for smooth integrands against
 * N^-2 for the jittered grid, and no slower than jittering for integrands with edges
 * (Owen 1997). The scramble is a hash of the bits reversed (Burley 2020, "Practical
 * Hash-based Owen Scrambling", JCGT 9(4): the Laine-Karras permutation), one seed a
 * dimension.
 */
#ifndef RAD_CORE_SCRAMBLED_SOBOL_H
#define RAD_CORE_SCRAMBLED_SOBOL_H

#include <stdint.h>

#include "core/random.h"

/* The Laine-Karras permutation of a fraction's bits reversed: each bit flipped by a hash
 * of the bits below it (those above it in the fraction) and the seed; multiplications by
 * even constants carry only upward. */
static inline uint32_t sobol_laine_karras(uint32_t reversed, uint32_t seed)
{
    uint32_t x = reversed + seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/* Owen's scramble of the 32-bit fraction x. */
static inline uint32_t sobol_owen_scramble(uint32_t x, uint32_t seed)
{
    return rad_reverse_bits(sobol_laine_karras(rad_reverse_bits(x), seed));
}

/* The second dimension's generator: direction numbers v_1 = 1/2, v_(k+1) = v_k xor
 * v_k / 2 (the polynomial x + 1), summed by the index's set bits. */
static inline uint32_t sobol_second(uint32_t index)
{
    uint32_t sum = 0;
    for (uint32_t v = 1u << 31; index; index >>= 1, v ^= v >> 1)
        if (index & 1)
            sum ^= v;
    return sum;
}

/* Point `index` of the scrambled sequence as 32-bit binary fractions. */
static inline void sobol_scrambled_bits(uint32_t index, uint32_t seed1, uint32_t seed2,
                                        uint32_t *x1, uint32_t *x2)
{
    *x1 = sobol_owen_scramble(rad_reverse_bits(index), seed1);
    *x2 = sobol_owen_scramble(sobol_second(index), seed2);
}

/* The same points walked in Gray-code order (Antonov and Saleev): step k gives point
 * k xor k / 2, which differs from the step before in one bit, so each coordinate changes
 * by one direction number. The first 2^m steps give the first 2^m points (in another
 * order). Kept with the bits reversed, where the scramble works: there the first
 * dimension's point is its index and the second's direction numbers are r_1 = 1,
 * r_(k+1) = r_k xor 2 r_k. */
typedef struct sobol_walk {
    uint32_t step, first, second; /* the next step; its point's coordinates, reversed */
    uint32_t seed1, seed2;
} sobol_walk;

static inline sobol_walk sobol_walk_start(uint32_t seed1, uint32_t seed2)
{
    return (sobol_walk){0, 0, 0, seed1, seed2};
}

static inline void sobol_walk_next(sobol_walk *walk, uint32_t *x1, uint32_t *x2)
{
    if (walk->step > 0) { /* the step's lowest set bit, and its direction number */
        unsigned bit = 0;
        uint32_t r = 1;
        for (; !((walk->step >> bit) & 1); bit++)
            r ^= r << 1;
        walk->first ^= 1u << bit;
        walk->second ^= r;
    }
    walk->step++;
    *x1 = rad_reverse_bits(sobol_laine_karras(walk->first, walk->seed1));
    *x2 = rad_reverse_bits(sobol_laine_karras(walk->second, walk->seed2));
}

#endif
