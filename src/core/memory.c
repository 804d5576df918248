/*
 * memory.c - the machine's memory and the process's peak, see memory.h.
 */
#include "core/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include "radiosity.h"

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
