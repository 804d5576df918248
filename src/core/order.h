/*
 * order.h - comparison functions for qsort (internal, inline).
 */
#ifndef RAD_CORE_ORDER_H
#define RAD_CORE_ORDER_H

/* Doubles in increasing order (none is NaN). */
static inline int rad_compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#endif
