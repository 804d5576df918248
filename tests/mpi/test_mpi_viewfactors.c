/*
 * test_mpi_viewfactors.c - `mpirun -np N radiosity viewfactors` for N = 1 to 4 writes the
 * same bytes as the serial run (Matrix Market to a file; CSV to standard output with 3 ranks), on a
 * generated city whose rows are obstructed (checked: obstructed and sampled pairs occur),
 * and rank 0's summary accounts for every row once. The ranks run one thread each, the
 * serial run two: the matrix depends on neither.
 */
#include <string.h>

#include "mpi_run.h"

/* the command's start: behind at most 4 occluders exactly, the rest sampled (the sampled
 * pairs' random numbers are what ranks must share; the default clips them all) */
#define VIEWFACTORS "viewfactors city.obj --exact-occluders 4"

/* The integer after "KEY": in a --stats file; -1 when missing. */
static long long stats_integer_of(const char *text, const char *key)
{
    char quoted[128];
    snprintf(quoted, sizeof(quoted), "\"%s\":", key);
    const char *at = strstr(text, quoted);
    return at ? strtoll(at + strlen(quoted), NULL, 10) : -1;
}

int main(void)
{
    test_write_city(300, "city.obj");
    CHECK(test_run_tool(VIEWFACTORS " -o serial.mtx --threads 2 --stats serial.json") ==
          0);
    const char *stats = test_read_text(test_path("serial.json"));
    long long surfaces = stats_integer_of(stats, "surfaces");
    CHECK(surfaces == 384); /* 64 buildings: 4 walls, a roof, a ground tile each */
    CHECK(stats_integer_of(stats, "obstructed_pairs") > 1000);
    CHECK(stats_integer_of(stats, "sampled_pairs") > 1000);
    CHECK(test_run_tool(VIEWFACTORS " --threads 2 --quiet") == 0);
    size_t csv_size;
    uint8_t *serial_csv = test_read_bytes(test_path("stdout.txt"), &csv_size);
    CHECK(serial_csv && csv_size > 1000);

    for (int ranks = 1; ranks <= 4; ranks++) {
        char arguments[256], name[32];
        snprintf(name, sizeof(name), "ranks%d.mtx", ranks);
        snprintf(arguments, sizeof(arguments), VIEWFACTORS " -o %s --threads 1", name);
        CHECK(test_run_mpi(ranks, arguments, 0, NULL) == 0);
        CHECK(test_same_bytes(test_path("serial.mtx"), test_path(name)));
        const char *err = test_read_text(test_path("stderr.txt"));
        long long rows = ranks > 1 ? test_rank_work(err, ranks) : 0;
        if (ranks > 1) {
            CHECK(rows == surfaces);
            CHECK(strstr(err, "load imbalance") != NULL);
        } else {
            CHECK(strstr(err, "rank 0 of") == NULL); /* one rank: the serial summary */
        }

        /* CSV on standard output: rank 0 alone prints it (3 ranks: an odd share) */
        if (ranks != 3)
            continue;
        CHECK(test_run_mpi(ranks, VIEWFACTORS " --threads 1 --quiet", 0, NULL) == 0);
        size_t size;
        uint8_t *csv = test_read_bytes(test_path("stdout.txt"), &size);
        CHECK(csv && serial_csv && size == csv_size && memcmp(csv, serial_csv, size) == 0);
        free(csv);
    }
    free(serial_csv);
    return test_finish("test_mpi_viewfactors");
}
