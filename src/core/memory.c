/*
 * memory.c - peak resident memory of the process, for reports.
 */
#include <sys/resource.h>

#include "radiosity.h"

uint64_t rad_peak_memory_bytes(void)
{
    struct rusage usage;
    if (getrusage(RUSAGE_SELF, &usage) != 0)
        return 0;
    return (uint64_t)usage.ru_maxrss * 1024u; /* Linux reports kilobytes */
}
