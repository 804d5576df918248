/*
 * alloc.h - allocation with overflow-checked sizes.
 *
 * rad_alloc_array(count, size) returns NULL when count * size overflows or the allocation
 * fails; callers turn NULL into RAD_ERR_NOMEM. Memory is zeroed.
 */
#ifndef RAD_CORE_ALLOC_H
#define RAD_CORE_ALLOC_H

#include <stdint.h>
#include <stdlib.h>

static inline void *rad_alloc_array(size_t count, size_t size)
{
    if (size != 0 && count > SIZE_MAX / size)
        return NULL;
    return calloc(count ? count : 1, size ? size : 1);
}

/* Grows *array to hold at least `needed` elements; capacity doubles. 0 on failure. */
static inline int rad_grow_array(void **array, size_t *capacity, size_t needed, size_t size)
{
    if (needed <= *capacity)
        return 1;
    size_t cap = *capacity ? *capacity : 16;
    while (cap < needed) {
        if (cap > SIZE_MAX / 2)
            return 0;
        cap *= 2;
    }
    if (cap > SIZE_MAX / size)
        return 0;
    void *grown = realloc(*array, cap * size);
    if (!grown)
        return 0;
    *array = grown;
    *capacity = cap;
    return 1;
}

#endif
