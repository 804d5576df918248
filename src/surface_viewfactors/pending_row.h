/*
 * pending_row.h - one row I of the surface view factors while it is computed: its non-zero
 * transfers G_IJ (J >= I) with their error bounds, before the rows are assembled into the
 * compressed matrix. Shared by the engine (viewfactor_matrix.c) and its restart files
 * (checkpoint.c); it holds no logic.
 */
#ifndef RAD_VIEWFACTOR_PENDING_ROW_H
#define RAD_VIEWFACTOR_PENDING_ROW_H

#include <stdint.h>

typedef struct row_entry {
    uint32_t column;
    double transfer; /* G_IJ */
    double bound;    /* its estimated absolute error */
} row_entry;

typedef struct pending_row {
    row_entry *entries;
    uint32_t count, capacity;
} pending_row;

#endif
