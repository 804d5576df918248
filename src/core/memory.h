/*
 * memory.h - how much memory the machine has, to refuse early what cannot fit.
 */
#ifndef RAD_CORE_MEMORY_H
#define RAD_CORE_MEMORY_H

#include <stdint.h>

/* Physical memory in bytes, or 0 when unknown. */
uint64_t rad_physical_memory_bytes(void);

#endif
