/*
 * memory.c - the machine's memory, the process's peak and the run's memory budget, see
 * memory.h and radiosity.h (rad_memory_budget_*).
 *
 * The heap in use is the allocator's exact count of bytes handed out and not yet freed:
 * glibc's mallinfo2 (arena chunks in use plus mmapped chunks, over every thread's arena),
 * or AddressSanitizer's count under ASan (which replaces malloc). It is read only at the
 * checks: requests of MEMORY_CHECK_BYTES or more, and otherwise once a thread's smaller
 * requests since its last check add up to that much. Embree's bytes come from its
 * monitor; the blocks Embree takes from malloc (most of a BVH under about a million
 * triangles) are then counted twice, which errs on the side of refusing.
 */
#define _DEFAULT_SOURCE /* madvise and MADV_HUGEPAGE, beside POSIX */
#include "core/memory.h"

#include <inttypes.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#if defined(__SANITIZE_ADDRESS__)
#define RAD_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RAD_ASAN 1
#endif
#endif

#if defined(RAD_ASAN)
/* the sanitizer runtime's count of bytes allocated and not freed (its
 * sanitizer/allocator_interface.h, which gcc does not install) */
size_t __sanitizer_get_current_allocated_bytes(void);
#elif defined(__GLIBC__)
#include <malloc.h>
#endif

#include "core/error.h"
#include "radiosity.h"

/* Requests this large are checked one by one; smaller ones once they add up to it. */
#define MEMORY_CHECK_BYTES ((uint64_t)1 << 20)

static atomic_uint_fast64_t budget_limit;    /* 0 = no budget */
static atomic_uint_fast64_t budget_reserved; /* promised to buffers made later */
static atomic_int_fast64_t embree_bytes;     /* Embree's live blocks (its monitor) */
static atomic_uint_fast64_t budget_peak;     /* most in use + reserved + asked at a check */
static atomic_bool refusal_recorded;         /* the first refusal since the budget was set */
static atomic_uint_fast64_t refusal_need, refusal_in_use, refusal_limit;
/* this thread's requests since its last check: the allocator's, and Embree's apart (so
 * that how Embree shares a build among threads does not move the allocator's checks) */
static _Thread_local uint64_t unchecked_bytes, embree_unchecked_bytes;

uint64_t rad_physical_memory_bytes(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGESIZE);
    return pages > 0 && page_size > 0 ? (uint64_t)pages * (uint64_t)page_size : 0;
}

uint64_t rad_peak_memory_bytes(void)
{
    struct rusage usage;
    if (getrusage(RUSAGE_SELF, &usage) != 0)
        return 0;
    return (uint64_t)usage.ru_maxrss * 1024u; /* Linux reports kilobytes */
}

/* The C heap's bytes in use, or 0 when the allocator cannot say. */
static uint64_t heap_in_use(void)
{
#if defined(RAD_ASAN)
    return (uint64_t)__sanitizer_get_current_allocated_bytes();
#elif defined(__GLIBC__)
    struct mallinfo2 info = mallinfo2();
    return (uint64_t)info.uordblks + (uint64_t)info.hblkhd;
#else
    return 0;
#endif
}

uint64_t rad_memory_in_use(void)
{
    int_fast64_t embree = atomic_load(&embree_bytes);
    return heap_in_use() + (embree > 0 ? (uint64_t)embree : 0);
}

void rad_memory_budget_set(uint64_t bytes)
{
    atomic_store(&budget_limit, bytes);
    atomic_store(&budget_reserved, 0);
    atomic_store(&budget_peak, 0);
    atomic_store(&refusal_recorded, false);
}

uint64_t rad_memory_budget(void) { return atomic_load(&budget_limit); }

uint64_t rad_memory_budget_peak(void) { return atomic_load(&budget_peak); }

uint64_t rad_memory_budget_left(void)
{
    uint64_t limit = atomic_load(&budget_limit);
    if (limit == 0)
        return UINT64_MAX;
    uint64_t used = rad_memory_in_use() + atomic_load(&budget_reserved);
    return used < limit ? limit - used : 0;
}

/* Raises the high-water mark to `value`. */
static void peak_raise(uint64_t value)
{
    uint_fast64_t seen = atomic_load_explicit(&budget_peak, memory_order_relaxed);
    while (value > seen &&
           !atomic_compare_exchange_weak_explicit(&budget_peak, &seen, value,
                                                  memory_order_relaxed, memory_order_relaxed))
        ;
}

/* The one check: in use + reserved + need against the limit; a refusal is recorded (the
 * first since the budget was set) for rad_memory_budget_refusal. *in_use receives the
 * bytes in use and reserved. */
static bool budget_fits(uint64_t limit, uint64_t need, uint64_t *in_use)
{
    *in_use = rad_memory_in_use() + atomic_load(&budget_reserved);
    uint64_t total = *in_use + need;
    if (total < *in_use || total > limit) {
        bool first = false;
        if (atomic_compare_exchange_strong(&refusal_recorded, &first, true)) {
            atomic_store(&refusal_need, need);
            atomic_store(&refusal_in_use, *in_use);
            atomic_store(&refusal_limit, limit);
        }
        return false;
    }
    peak_raise(total);
    return true;
}

/* A request of `bytes` is checked: it is large, or this thread's smaller requests since
 * its last check reach MEMORY_CHECK_BYTES with it (they are in use already, so only the
 * request itself is added to what is counted). */
static bool check_due(uint64_t *unchecked, uint64_t bytes)
{
    if (bytes < MEMORY_CHECK_BYTES && *unchecked + bytes < MEMORY_CHECK_BYTES) {
        *unchecked += bytes;
        return false;
    }
    *unchecked = 0;
    return true;
}

bool rad_memory_budget_allows(uint64_t bytes)
{
    uint64_t limit = atomic_load_explicit(&budget_limit, memory_order_relaxed), in_use;
    return limit == 0 || !check_due(&unchecked_bytes, bytes) || budget_fits(limit, bytes, &in_use);
}

bool rad_memory_budget_embree(int64_t bytes, bool post)
{
    uint64_t limit = atomic_load(&budget_limit), in_use;
    if (limit != 0 && bytes > 0 && !post && check_due(&embree_unchecked_bytes, (uint64_t)bytes) &&
        !budget_fits(limit, (uint64_t)bytes, &in_use))
        return false; /* cancelled: never allocated, so not counted */
    atomic_fetch_add(&embree_bytes, bytes);
    return true;
}

void rad_memory_budget_reserve(uint64_t bytes) { atomic_fetch_add(&budget_reserved, bytes); }

void rad_memory_budget_unreserve(uint64_t bytes)
{
    uint_fast64_t held = atomic_load(&budget_reserved);
    while (!atomic_compare_exchange_weak(&budget_reserved, &held, held > bytes ? held - bytes : 0))
        ;
}

/* A byte count in the units --max-memory takes (powers of 1024). */
static void format_bytes(uint64_t bytes, char *text, size_t size)
{
    if (bytes < 1024)
        snprintf(text, size, "%" PRIu64 " bytes", bytes);
    else if (bytes < 1024u * 1024)
        snprintf(text, size, "%.1f KB", bytes / 1024.0);
    else if (bytes < 1024u * 1024 * 1024)
        snprintf(text, size, "%.1f MB", bytes / 1048576.0);
    else
        snprintf(text, size, "%.2f GB", bytes / 1073741824.0);
}

rad_status rad_memory_budget_need(uint64_t bytes, const char *what, rad_error *error)
{
    uint64_t limit = atomic_load(&budget_limit), in_use;
    if (limit == 0 || budget_fits(limit, bytes, &in_use))
        return RAD_OK;
    char need[32], left[32], given[32];
    format_bytes(bytes, need, sizeof(need));
    format_bytes(in_use < limit ? limit - in_use : 0, left, sizeof(left));
    format_bytes(limit, given, sizeof(given));
    if (strcmp(need, left) == 0) { /* alike when rounded: the bytes tell them apart */
        snprintf(need, sizeof(need), "%" PRIu64 " bytes", bytes);
        snprintf(left, sizeof(left), "%" PRIu64 " bytes", in_use < limit ? limit - in_use : 0);
    }
    return rad_fail(error, RAD_ERR_NOMEM,
                    "--max-memory: %s needs %s, more than the %s left of the budget of %s",
                    what, need, left, given);
}

bool rad_memory_budget_refusal(char *text, size_t size)
{
    if (!atomic_load(&refusal_recorded))
        return false;
    char need[32], in_use[32], given[32];
    format_bytes(atomic_load(&refusal_need), need, sizeof(need));
    format_bytes(atomic_load(&refusal_in_use), in_use, sizeof(in_use));
    format_bytes(atomic_load(&refusal_limit), given, sizeof(given));
    snprintf(text, size, "--max-memory: %s more, with %s in use, would exceed the budget of %s",
             need, in_use, given);
    return true;
}

void rad_advise_huge_pages(void *p, uint64_t bytes)
{
#if defined(MADV_HUGEPAGE)
    const uintptr_t huge = (uintptr_t)2 << 20;
    uintptr_t start = ((uintptr_t)p + huge - 1) & ~(huge - 1);
    uintptr_t end = ((uintptr_t)p + (uintptr_t)bytes) & ~(huge - 1);
    if (p && end > start)
        (void)madvise((void *)start, end - start, MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}
