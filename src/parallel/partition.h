/*
 * partition.h - shares n items of estimated cost over the ranks of a job so that every
 * rank's total estimated cost is about the same (largest cost first, each to the rank with
 * the least so far). Deterministic: the same costs give the same shares on every rank. It
 * only decides who does what; it does not estimate costs (its callers do) nor talk to
 * other ranks.
 */
#ifndef RAD_PARALLEL_PARTITION_H
#define RAD_PARALLEL_PARTITION_H

#include <stdint.h>

#include "radiosity.h"

/* owner[i] = the rank (0 .. ranks - 1) that does item i; costs must be finite and >= 0.
 * Fails only when out of memory. */
rad_status partition_by_cost(const double *cost, uint32_t n, int ranks, uint32_t *owner,
                             rad_error *error);

/* Rank `rank`'s contiguous share of n items of equal cost: [*begin, *end). */
void partition_block(uint32_t n, int ranks, int rank, uint32_t *begin, uint32_t *end);

#endif
