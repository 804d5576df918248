/*
 * matrix_entry.h - where F_IJ is stored in a rad_viewfactor_matrix (internal, inline).
 */
#ifndef RAD_VFMATRIX_MATRIX_ENTRY_H
#define RAD_VFMATRIX_MATRIX_ENTRY_H

#include "radiosity.h"

/* The index of (row, column) in matrix->column / value, or UINT64_MAX when it is not
 * stored. Binary search: columns ascend within a row. */
static inline uint64_t vf_matrix_entry(const rad_viewfactor_matrix *matrix, uint32_t row,
                                       uint32_t column)
{
    uint64_t lo = matrix->row_start[row], hi = matrix->row_start[row + 1];
    while (lo < hi) {
        uint64_t mid = lo + (hi - lo) / 2;
        if (matrix->column[mid] < column)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < matrix->row_start[row + 1] && matrix->column[lo] == column ? lo : UINT64_MAX;
}

#endif
