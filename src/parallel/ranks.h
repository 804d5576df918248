/*
 * ranks.h - the processes of an MPI job, as the library sees them: how many, which one
 * this is, and the few collective steps the library needs (agree on failure, sum counts,
 * gather bytes to rank 0). The only interface to MPI: ranks.c is the one file that includes
 * mpi.h, and a build without -DRAD_MPI=ON (or a run not launched by mpirun or srun) is one
 * rank, for which every step here is a plain copy. It is not a scheduler: what each rank
 * computes is decided by its caller (partition.h).
 *
 * Every function marked collective must be called by every rank, in the same order.
 */
#ifndef RAD_PARALLEL_RANKS_H
#define RAD_PARALLEL_RANKS_H

#include <stdbool.h>
#include <stdint.h>

#include "radiosity.h"

/* This process's rank, 0 .. ranks_count() - 1; 0 and 1 without MPI. */
int ranks_rank(void);
int ranks_count(void);

/* Collective: how many ranks passed failed = true (0 when all went well). */
int ranks_failures(bool failed);

/* Collective: status when it failed here; when it is RAD_OK here but failed on another
 * rank, RAD_ERR_INVALID with "WHAT: another rank failed" in error; else RAD_OK. For a
 * step that may fail on one rank before the ranks work together. */
rad_status ranks_agree(rad_status status, const char *what, rad_error *error);

/* Collective: every rank gets rank 0's status, and its message when that is a failure;
 * returns it. For a step rank 0 alone does (writing a file) whose outcome all must share. */
rad_status ranks_share_status(rad_status status, rad_error *error);

/* Collective: values[k] becomes the sum over ranks of values[k], on every rank. */
void ranks_sum(uint64_t *values, int count);

/* Collective: values[k] becomes the sum over ranks of values[k], on every rank. For arrays
 * in which each entry is non-zero on one rank at most, the sum is that entry, exactly. */
void ranks_sum_floats(float *values, uint64_t count);

/* Collective: values[] holds `width` doubles per item, n items; each rank has filled the
 * items of its block (partition_block) and afterwards every rank has every block. */
void ranks_share_blocks(double *values, uint32_t n, uint32_t width);

/* Collective: rank 0's `size` bytes at `data` replace every other rank's. */
void ranks_broadcast(void *data, uint64_t size);

/* Collective: rank 0 receives every rank's `size` bytes at `data`, in rank order, in
 * *gathered (one allocation, free() it) with each rank's size in sizes[rank] (room for
 * ranks_count()); other ranks get *gathered = NULL. Fails (on every rank) when rank 0 is out
 * of memory. */
rad_status ranks_gather(const void *data, uint64_t size, void **gathered, uint64_t *sizes,
                        rad_error *error);

/* Collective: every rank's counts[rank] doubles at `mine`, concatenated in rank order, in
 * all[] (room for the sum of counts[]) on every rank; counts[] is the same on every rank.
 * For blocks of unequal, scattered items (the hierarchical solver's leaves). Ends the job
 * (rad_ranks_abort) when a rank's count exceeds what one MPI call carries (2^31 - 1). */
void ranks_share_parts(const double *mine, double *all, const uint64_t *counts);

#endif
