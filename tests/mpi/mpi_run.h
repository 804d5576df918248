/*
 * mpi_run.h - runs the radiosity tool under mpirun for the MPI tests: N ranks on this
 * machine (--oversubscribe), optionally a second program for the last ranks (mpirun's
 * "A : B" form), with standard output and error captured like test_run_tool. Not a
 * launcher for anything else.
 */
#ifndef RAD_TESTS_MPI_RUN_H
#define RAD_TESTS_MPI_RUN_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "testlib.h"

/* `mpirun -np ranks radiosity arguments`, then, when `others` is not NULL,
 * `: -np other_ranks others` (a whole command line). Returns the exit code (-1 when it
 * did not exit). */
static inline int test_run_mpi(int ranks, const char *arguments, int other_ranks,
                               const char *others)
{
    static char command[20000];
    char tail[8000] = "";
    if (others)
        snprintf(tail, sizeof(tail), " : -np %d %s", other_ranks, others);
    snprintf(command, sizeof(command),
             "cd '%s' && '%s' --oversubscribe --allow-run-as-root -np %d '%s' %s%s >'%s' "
             "2>'%s' </dev/null",
             test_tmpdir(), RAD_MPIEXEC, ranks, RAD_TOOL, arguments, tail,
             test_path("stdout.txt"), test_path("stderr.txt"));
    int status = system(command);
    if (status == -1 || !WIFEXITED(status))
        return -1;
    return WEXITSTATUS(status);
}

/* Writes the generated city (bench/city.c) of about `surfaces` surfaces; its path. */
static inline const char *test_write_city(int surfaces, const char *name)
{
    static char command[9000];
    const char *path = test_path(name);
    snprintf(command, sizeof(command), "'%s' %d '%s' >/dev/null", RAD_CITY, surfaces, path);
    if (system(command) != 0)
        test_fail(__FILE__, __LINE__, "cannot generate %s", path);
    return path;
}

/* The sum over ranks of the work each reports in `err` ("rank R of N: K rows", tiles ...),
 * each rank's line present and its K positive. */
static inline long long test_rank_work(const char *err, int ranks)
{
    long long total = 0;
    for (int r = 0; r < ranks; r++) {
        char key[64];
        snprintf(key, sizeof(key), "rank %d of %d: ", r, ranks);
        const char *line = strstr(err, key);
        CHECK(line != NULL);
        long long mine = line ? strtoll(line + strlen(key), NULL, 10) : 0;
        CHECK(mine > 0);
        total += mine;
    }
    return total;
}

#endif
