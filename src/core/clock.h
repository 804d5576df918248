/*
 * clock.h - the library's one clock: rad_clock_seconds() (radiosity.h), a monotonic
 * wall clock in seconds (CLOCK_MONOTONIC), implemented in clock.c. Every duration the
 * library reports (report->seconds and its kin) and every time the command-line tool
 * prints is a difference of two readings of it.
 */
#ifndef RAD_CORE_CLOCK_H
#define RAD_CORE_CLOCK_H

#include "radiosity.h"

#endif
