/*
 * ranks.c - the processes of an MPI job (ranks.h, and the rad_ranks_* functions of
 * radiosity.h): the one file that includes mpi.h. Built without RAD_MPI (the default) it is
 * a single rank and every collective step is a copy. With RAD_MPI, MPI is started only when
 * the process was launched by mpirun or srun (their environment says so), so the same
 * binary run by hand stays an ordinary serial program. Only the calling thread uses MPI
 * (MPI_THREAD_FUNNELED); OpenMP threads never do.
 *
 * It counts the bytes this rank sends and receives, for the run summary. It is not a
 * scheduler and knows nothing of view factors or images.
 */
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "parallel/partition.h"
#include "parallel/ranks.h"

#ifdef RAD_MPI
#include <mpi.h>
#endif

static int rank_index = 0, rank_total = 1;
static uint64_t bytes_communicated = 0;

int ranks_rank(void) { return rank_index; }
int ranks_count(void) { return rank_total; }
int rad_rank(void) { return rank_index; }
int rad_rank_count(void) { return rank_total; }
uint64_t rad_ranks_bytes_communicated(void) { return bytes_communicated; }

/* One rank: the gathered bytes are a copy of its own. */
static rad_status gather_own(const void *data, uint64_t size, void **gathered, uint64_t *sizes,
                             rad_error *error)
{
    sizes[0] = size;
    *gathered = rad_alloc_array(size ? size : 1, 1);
    if (!*gathered)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for %llu bytes of results",
                        (unsigned long long)size);
    memcpy(*gathered, data, size);
    return RAD_OK;
}

#ifdef RAD_MPI

static bool joined = false; /* MPI_Init ran here */

/* Messages of at most 1 GiB: MPI counts are ints. */
#define CHUNK_BYTES ((uint64_t)1 << 30)

/* Open MPI's mpirun, PMIx (srun --mpi=pmix, Open MPI 4) and PMI-2 (srun --mpi=pmi2). */
static bool launched_by_mpi(void)
{
    return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMIX_RANK") || getenv("PMI_RANK");
}

int rad_ranks_begin(void)
{
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (joined || !launched_by_mpi())
        return rank_total;
    if (!initialized) {
        int provided;
        if (MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
            return rank_total;
        joined = true;
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_index);
    MPI_Comm_size(MPI_COMM_WORLD, &rank_total);
    return rank_total;
}

void rad_ranks_end(void)
{
    if (joined)
        MPI_Finalize();
    joined = false;
    rank_index = 0;
    rank_total = 1;
}

void rad_ranks_abort(int exit_code)
{
    if (rank_total > 1)
        MPI_Abort(MPI_COMM_WORLD, exit_code);
    exit(exit_code);
}

int ranks_failures(bool failed)
{
    int mine = failed ? 1 : 0, total = mine;
    if (rank_total > 1) {
        MPI_Allreduce(&mine, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
        bytes_communicated += 2 * sizeof(int);
    }
    return total;
}

void ranks_sum(uint64_t *values, int count)
{
    if (rank_total > 1 && count > 0) {
        MPI_Allreduce(MPI_IN_PLACE, values, count, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
        bytes_communicated += 2 * (uint64_t)count * sizeof(uint64_t);
    }
}

void ranks_broadcast(void *data, uint64_t size)
{
    if (rank_total == 1)
        return;
    for (uint64_t at = 0; at < size; at += CHUNK_BYTES) {
        uint64_t part = size - at < CHUNK_BYTES ? size - at : CHUNK_BYTES;
        MPI_Bcast((unsigned char *)data + at, (int)part, MPI_BYTE, 0, MPI_COMM_WORLD);
    }
    bytes_communicated += size;
}

void ranks_sum_floats(float *values, uint64_t count)
{
    if (rank_total == 1)
        return;
    const uint64_t chunk = CHUNK_BYTES / sizeof(float);
    for (uint64_t at = 0; at < count; at += chunk) {
        uint64_t part = count - at < chunk ? count - at : chunk;
        MPI_Allreduce(MPI_IN_PLACE, values + at, (int)part, MPI_FLOAT, MPI_SUM, MPI_COMM_WORLD);
    }
    bytes_communicated += 2 * count * sizeof(float);
}

void ranks_share_blocks(double *values, uint32_t n, uint32_t width)
{
    if (rank_total == 1)
        return;
    int *counts = rad_alloc_array((size_t)rank_total, sizeof(int));
    int *starts = rad_alloc_array((size_t)rank_total, sizeof(int));
    if (!counts || !starts) { /* cannot go on without the others' values */
        free(counts);
        free(starts);
        rad_ranks_abort(EXIT_FAILURE);
        return;
    }
    for (int r = 0; r < rank_total; r++) {
        uint32_t begin, end;
        partition_block(n, rank_total, r, &begin, &end);
        starts[r] = (int)((uint64_t)begin * width);
        counts[r] = (int)((uint64_t)(end - begin) * width);
    }
    MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, values, counts, starts, MPI_DOUBLE,
                   MPI_COMM_WORLD);
    bytes_communicated += (uint64_t)n * width * sizeof(double);
    free(counts);
    free(starts);
}

/* Sends or receives `size` bytes in chunks of at most CHUNK_BYTES. */
static void send_bytes(const unsigned char *data, uint64_t size)
{
    for (uint64_t at = 0; at < size; at += CHUNK_BYTES) {
        uint64_t part = size - at < CHUNK_BYTES ? size - at : CHUNK_BYTES;
        MPI_Send(data + at, (int)part, MPI_BYTE, 0, 0, MPI_COMM_WORLD);
    }
    bytes_communicated += size;
}

static void receive_bytes(unsigned char *data, uint64_t size, int from)
{
    for (uint64_t at = 0; at < size; at += CHUNK_BYTES) {
        uint64_t part = size - at < CHUNK_BYTES ? size - at : CHUNK_BYTES;
        MPI_Recv(data + at, (int)part, MPI_BYTE, from, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    }
    bytes_communicated += size;
}

rad_status ranks_gather(const void *data, uint64_t size, void **gathered, uint64_t *sizes,
                        rad_error *error)
{
    *gathered = NULL;
    if (rank_total == 1)
        return gather_own(data, size, gathered, sizes, error);
    uint64_t mine = size;
    MPI_Gather(&mine, 1, MPI_UINT64_T, sizes, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    bytes_communicated += sizeof(uint64_t);
    unsigned char *all = NULL;
    uint64_t total = 0;
    if (rank_index == 0) {
        for (int r = 0; r < rank_total; r++)
            total += sizes[r];
        all = rad_alloc_array(total ? total : 1, 1);
    }
    /* rank 0 tells whether it has room before anyone sends */
    int ready = rank_index != 0 || all != NULL;
    MPI_Bcast(&ready, 1, MPI_INT, 0, MPI_COMM_WORLD);
    bytes_communicated += sizeof(int);
    if (!ready)
        return rad_fail(error, RAD_ERR_NOMEM,
                        "rank 0 is out of memory for the %llu bytes of every rank's results",
                        (unsigned long long)total);
    if (rank_index != 0) {
        send_bytes(data, size);
        return RAD_OK;
    }
    memcpy(all, data, size);
    uint64_t at = size;
    for (int r = 1; r < rank_total; r++) {
        receive_bytes(all + at, sizes[r], r);
        at += sizes[r];
    }
    *gathered = all;
    return RAD_OK;
}

#else /* one rank */

int rad_ranks_begin(void) { return 1; }
void rad_ranks_end(void) {}
void rad_ranks_abort(int exit_code) { exit(exit_code); }
int ranks_failures(bool failed) { return failed ? 1 : 0; }
void ranks_broadcast(void *data, uint64_t size)
{
    (void)data;
    (void)size;
}
void ranks_sum(uint64_t *values, int count)
{
    (void)values;
    (void)count;
}
void ranks_sum_floats(float *values, uint64_t count)
{
    (void)values;
    (void)count;
}
void ranks_share_blocks(double *values, uint32_t n, uint32_t width)
{
    (void)values;
    (void)n;
    (void)width;
}

rad_status ranks_gather(const void *data, uint64_t size, void **gathered, uint64_t *sizes,
                        rad_error *error)
{
    return gather_own(data, size, gathered, sizes, error);
}

#endif

rad_status rad_ranks_gather_reports(const rad_rank_report *mine, rad_rank_report *all,
                                    rad_error *error)
{
    void *gathered = NULL;
    uint64_t *sizes = rad_alloc_array((size_t)rank_total, sizeof(uint64_t));
    if (!sizes)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for %d rank reports", rank_total);
    rad_status status = ranks_gather(mine, sizeof(*mine), &gathered, sizes, error);
    if (status == RAD_OK && gathered)
        memcpy(all, gathered, (size_t)rank_total * sizeof(*mine));
    free(gathered);
    free(sizes);
    return status;
}

int rad_ranks_failures(bool failed) { return ranks_failures(failed); }

rad_status ranks_agree(rad_status status, const char *what, rad_error *error)
{
    if (ranks_failures(status != RAD_OK) && status == RAD_OK)
        return rad_fail(error, RAD_ERR_INVALID, "%s: another rank failed", what);
    return status;
}

rad_status ranks_share_status(rad_status status, rad_error *error)
{
    if (ranks_count() == 1)
        return status;
    int shared = (int)status;
    ranks_broadcast(&shared, sizeof(shared));
    if (shared != RAD_OK) {
        rad_error message = {0};
        if (ranks_rank() == 0)
            message = *error;
        ranks_broadcast(&message, sizeof(message));
        *error = message;
        error->status = (rad_status)shared;
    }
    return (rad_status)shared;
}

#ifdef RAD_MPI

void ranks_share_parts(const double *mine, double *all, const uint64_t *counts)
{
    if (rank_total == 1) {
        memcpy(all, mine, counts[0] * sizeof(double));
        return;
    }
    int *sizes = rad_alloc_array((size_t)rank_total, sizeof(int));
    int *starts = rad_alloc_array((size_t)rank_total, sizeof(int));
    uint64_t at = 0;
    bool fits = sizes && starts;
    for (int r = 0; fits && r < rank_total; r++) {
        fits = counts[r] <= (uint64_t)INT32_MAX && at <= (uint64_t)INT32_MAX;
        sizes[r] = fits ? (int)counts[r] : 0;
        starts[r] = fits ? (int)at : 0;
        at += counts[r];
    }
    if (!fits) { /* the same on every rank: none can go on without the others' values */
        free(sizes);
        free(starts);
        rad_ranks_abort(EXIT_FAILURE);
        return;
    }
    MPI_Allgatherv(mine, sizes[rank_index], MPI_DOUBLE, all, sizes, starts, MPI_DOUBLE,
                   MPI_COMM_WORLD);
    bytes_communicated += at * sizeof(double);
    free(sizes);
    free(starts);
}

#else

void ranks_share_parts(const double *mine, double *all, const uint64_t *counts)
{
    memcpy(all, mine, counts[0] * sizeof(double));
}

#endif
