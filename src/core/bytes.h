/*
 * bytes.h - little-endian encoding of numbers into byte buffers, all inline.
 *
 * The binary files the library writes (solution files, .ply, .glb) are little-endian
 * whatever the machine: values go through these, never through a struct written whole.
 */
#ifndef RAD_CORE_BYTES_H
#define RAD_CORE_BYTES_H

#include <stdint.h>
#include <string.h>

static inline void bytes_put_u32(uint8_t *p, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

static inline void bytes_put_u64(uint8_t *p, uint64_t v)
{
    for (int k = 0; k < 8; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

static inline void bytes_put_f32(uint8_t *p, float v)
{
    uint32_t bits;
    memcpy(&bits, &v, sizeof(bits));
    bytes_put_u32(p, bits);
}

static inline void bytes_put_f64(uint8_t *p, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof(bits));
    bytes_put_u64(p, bits);
}

static inline uint32_t bytes_get_u32(const uint8_t *p)
{
    uint32_t v = 0;
    for (int k = 0; k < 4; k++)
        v |= (uint32_t)p[k] << (8 * k);
    return v;
}

static inline uint64_t bytes_get_u64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int k = 0; k < 8; k++)
        v |= (uint64_t)p[k] << (8 * k);
    return v;
}

static inline float bytes_get_f32(const uint8_t *p)
{
    uint32_t bits = bytes_get_u32(p);
    float v;
    memcpy(&v, &bits, sizeof(v));
    return v;
}

static inline double bytes_get_f64(const uint8_t *p)
{
    uint64_t bits = bytes_get_u64(p);
    double v;
    memcpy(&v, &bits, sizeof(v));
    return v;
}

#endif
