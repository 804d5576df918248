/*
 * weld.c - open-addressing hash table over exact positions, see weld.h.
 */
#include "core/weld.h"

#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/random.h"

static uint64_t bits_of(double value)
{
    uint64_t bits;
    value += 0.0; /* folds -0 into +0 */
    memcpy(&bits, &value, sizeof(bits));
    return bits;
}

static uint64_t hash_of(uint32_t region, rad_vec3 p)
{
    uint64_t h = rad_mix64(region);
    h = rad_mix64(h ^ bits_of(p.x));
    h = rad_mix64(h ^ bits_of(p.y));
    return rad_mix64(h ^ bits_of(p.z));
}

static int same(const rad_weld *weld, uint32_t index, uint32_t region, rad_vec3 p)
{
    rad_vec3 q = weld->positions[index];
    return weld->regions[index] == region && bits_of(q.x) == bits_of(p.x) &&
           bits_of(q.y) == bits_of(p.y) && bits_of(q.z) == bits_of(p.z);
}

int rad_weld_init(rad_weld *weld, uint32_t expected_vertices)
{
    memset(weld, 0, sizeof(*weld));
    uint32_t slots = 64;
    while (slots < 2u * expected_vertices && slots < (1u << 31))
        slots *= 2;
    weld->slots = rad_alloc_array(slots, sizeof(*weld->slots));
    weld->slot_count = slots;
    return weld->slots != NULL;
}

static int rehash(rad_weld *weld)
{
    if (weld->slot_count >= (1u << 31))
        return 0;
    uint32_t slots = weld->slot_count * 2;
    uint32_t *table = rad_alloc_array(slots, sizeof(*table));
    if (!table)
        return 0;
    for (uint32_t v = 0; v < weld->count; v++) {
        uint32_t s = (uint32_t)hash_of(weld->regions[v], weld->positions[v]) & (slots - 1);
        while (table[s])
            s = (s + 1) & (slots - 1);
        table[s] = v + 1;
    }
    free(weld->slots);
    weld->slots = table;
    weld->slot_count = slots;
    return 1;
}

uint32_t rad_weld_insert(rad_weld *weld, uint32_t region, rad_vec3 position)
{
    uint32_t mask = weld->slot_count - 1;
    uint32_t s = (uint32_t)hash_of(region, position) & mask;
    for (; weld->slots[s]; s = (s + 1) & mask)
        if (same(weld, weld->slots[s] - 1, region, position))
            return weld->slots[s] - 1;
    if (weld->count == UINT32_MAX - 1)
        return UINT32_MAX;
    if (weld->count >= weld->capacity) {
        size_t cap_p = weld->capacity, cap_r = weld->capacity;
        if (!rad_grow_array((void **)&weld->positions, &cap_p, weld->count + 1u,
                            sizeof(*weld->positions)) ||
            !rad_grow_array((void **)&weld->regions, &cap_r, weld->count + 1u,
                            sizeof(*weld->regions)) ||
            cap_p > UINT32_MAX)
            return UINT32_MAX;
        weld->capacity = (uint32_t)(cap_p < cap_r ? cap_p : cap_r);
    }
    uint32_t index = weld->count++;
    weld->positions[index] = position;
    weld->regions[index] = region;
    weld->slots[s] = index + 1;
    if ((uint64_t)weld->count * 2 > weld->slot_count && !rehash(weld))
        return UINT32_MAX;
    return index;
}

rad_vec3 *rad_weld_take_positions(rad_weld *weld)
{
    rad_vec3 *positions = weld->positions;
    weld->positions = NULL;
    rad_weld_free(weld);
    return positions;
}

void rad_weld_free(rad_weld *weld)
{
    free(weld->slots);
    free(weld->regions);
    free(weld->positions);
    memset(weld, 0, sizeof(*weld));
}
