/*
 * memory.h - how much memory the machine has, and the run's memory budget (--max-memory).
 *
 * The budget is one process-wide limit on the bytes the run holds: every byte of the C
 * heap in use (the library's buffers, Assimp's import, libpng, ...: glibc's own count,
 * or AddressSanitizer's under ASan) plus Embree's blocks (its memory monitor), plus what
 * is reserved for buffers made later (an image allocated after the solve). It is drawn
 * down as the run proceeds: rad_memory_budget_need refuses up front what a step will
 * need when its size is known, rad_alloc_array refuses an allocation that would exceed
 * it (the caller's RAD_ERR_NOMEM follows), and Embree's monitor cancels a BVH build that
 * would. The public half is in radiosity.h (rad_memory_budget_*); this header adds the
 * two hooks the allocator and the Embree tracer call.
 *
 * Not here: the hierarchical solver's own link budget (rad_hierarchy_options.max_memory),
 * which rad_solve_scene derives from what is left.
 */
#ifndef RAD_CORE_MEMORY_H
#define RAD_CORE_MEMORY_H

#include <stdbool.h>
#include <stdint.h>

/* The most Embree's monitor counted at once while building a high-quality BVH, per
 * triangle, rounded up: 115, 123, 108, 97 and 122 bytes for 100, 1e3, 1e4, 1e5 and 1e6
 * random triangles (Embree 3.13, measured with rtcSetDeviceMemoryMonitorFunction); a
 * built BVH keeps about 55. The up-front estimate of a BVH. */
#define RAD_EMBREE_BYTES_PER_TRIANGLE 128

/* Physical memory in bytes, or 0 when unknown. */
uint64_t rad_physical_memory_bytes(void);

/* The allocator's hook: false when `bytes` more would exceed the budget (recorded for
 * rad_memory_budget_refusal). Without a budget, true at once. Small requests are checked
 * once every MEMORY_CHECK_BYTES of them per thread (see memory.c), so the budget may be
 * exceeded by at most that much per thread between two checks. */
bool rad_memory_budget_allows(uint64_t bytes);

/* Embree's memory monitor, as rtcSetDeviceMemoryMonitorFunction calls it: counts Embree's
 * blocks (bytes < 0: freed) and returns false to cancel an allocation (post false, bytes
 * > 0) that would exceed the budget, checked as the allocator's requests are. */
bool rad_memory_budget_embree(int64_t bytes, bool post);

/* Asks the kernel to back the whole 2 MiB pages inside [p, p + bytes) with huge pages
 * (transparent huge pages in "madvise" mode): a large matrix filled or read in columns
 * then takes a page fault and a TLB entry per 2 MiB instead of per 4 KiB. Only advice:
 * nothing happens where the kernel does not offer them. */
void rad_advise_huge_pages(void *p, uint64_t bytes);

#endif
