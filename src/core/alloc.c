/*
 * alloc.c - the project's allocation functions and their failure hook, see alloc.h.
 */
#include "core/alloc.h"

#include <stdatomic.h>

#include "core/memory.h"

static atomic_bool hook_armed;
static atomic_uint_fast64_t hook_count;
static atomic_uint_fast64_t hook_fail_at;
static atomic_bool hook_injected;

/* True when the hook says this allocation fails. */
static bool hook_fails(void)
{
    if (!atomic_load_explicit(&hook_armed, memory_order_relaxed))
        return false;
    uint_fast64_t number = atomic_fetch_add(&hook_count, 1) + 1;
    if (number != atomic_load(&hook_fail_at))
        return false;
    atomic_store(&hook_injected, true);
    return true;
}

void rad_alloc_fail_nth(uint64_t n)
{
    atomic_store(&hook_armed, false);
    atomic_store(&hook_count, 0);
    atomic_store(&hook_fail_at, n);
    atomic_store(&hook_injected, false);
    atomic_store(&hook_armed, n != 0);
}

uint64_t rad_alloc_count(void) { return atomic_load(&hook_count); }

bool rad_alloc_failure_injected(void) { return atomic_load(&hook_injected); }

void *rad_alloc_array(size_t count, size_t size)
{
    if (size != 0 && count > SIZE_MAX / size)
        return NULL;
    if (hook_fails() || !rad_memory_budget_allows((uint64_t)count * size))
        return NULL;
    return calloc(count ? count : 1, size ? size : 1);
}

void *rad_resize_array(void *array, size_t count, size_t size)
{
    if (size != 0 && count > SIZE_MAX / size)
        return NULL;
    size_t bytes = count * size;
    if (hook_fails() || !rad_memory_budget_allows(bytes))
        return NULL;
    return realloc(array, bytes ? bytes : 1);
}

int rad_grow_array(void **array, size_t *capacity, size_t needed, size_t size)
{
    if (needed <= *capacity)
        return 1;
    size_t cap = *capacity ? *capacity : 16;
    while (cap < needed) {
        if (cap > SIZE_MAX / 2)
            return 0;
        cap *= 2;
    }
    void *grown = rad_resize_array(*array, cap, size);
    if (!grown)
        return 0;
    *array = grown;
    *capacity = cap;
    return 1;
}
