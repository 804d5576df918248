/*
 * minmax.h - max and min of two doubles as plain comparisons: compilers inline these as
 * one instruction, where fmax/fmin become library calls unless NaNs are ruled out.
 * Neither argument may be NaN.
 */
#ifndef RAD_CORE_MINMAX_H
#define RAD_CORE_MINMAX_H

static inline double max_d(double a, double b) { return a > b ? a : b; }
static inline double min_d(double a, double b) { return a < b ? a : b; }

#endif
