/*
 * alloc.h - every heap allocation of the project: overflow-checked sizes, and a test hook.
 *
 * rad_alloc_array(count, size) returns NULL when count * size overflows or the allocation
 * fails; callers turn NULL into RAD_ERR_NOMEM. Memory is zeroed. rad_resize_array is
 * realloc with the same check (NULL on failure, the array untouched), rad_grow_array grows
 * a doubling buffer. Memory from all three is released with free().
 *
 * The test hook rad_alloc_fail_nth(n) makes the nth allocation counted from that call fail
 * (as if the machine were out of memory), so a test can sweep n over a whole operation and
 * require a clean RAD_ERR_NOMEM each time. Only tests call it; unarmed, the cost is one
 * relaxed atomic load per allocation. Allocations made inside Embree, Assimp, libpng,
 * libjpeg, cJSON and OpenEXR do not pass through here.
 *
 * With a memory budget set (rad_memory_budget_set, --max-memory), an allocation that
 * would take the run over it fails the same way (NULL, then the caller's RAD_ERR_NOMEM),
 * and rad_memory_budget_refusal says how much was asked for (core/memory.h).
 */
#ifndef RAD_CORE_ALLOC_H
#define RAD_CORE_ALLOC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

void *rad_alloc_array(size_t count, size_t size);

void *rad_resize_array(void *array, size_t count, size_t size);

/* Grows *array to hold at least `needed` elements; capacity doubles. 0 on failure (the
 * array and capacity untouched). */
int rad_grow_array(void **array, size_t *capacity, size_t needed, size_t size);

/* Test hook: the nth allocation from now (1 = the next one) fails, the others succeed;
 * n = 0 disarms. Resets the count and the injected flag. */
void rad_alloc_fail_nth(uint64_t n);

/* Allocations since the last rad_alloc_fail_nth call. */
uint64_t rad_alloc_count(void);

/* The armed failure has happened since the last rad_alloc_fail_nth call. */
bool rad_alloc_failure_injected(void);

#endif
