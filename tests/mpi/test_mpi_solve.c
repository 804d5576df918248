/*
 * test_mpi_solve.c - `mpirun -np N radiosity solve` and `... render` for N = 1 to 4 write
 * the same bytes as the serial run, on the built-in Cornell box (its two boxes obstruct:
 * the form factors cast rays) with the default dense solver (gather, Jacobi: the sweeps
 * are shared over the ranks); Gauss-Seidel (solved whole on every rank from the shared
 * matrix) and the hierarchical solver (its links shared by receiver; see
 * test_mpi_hierarchical) too under 3 ranks, and the per-pixel direct light's image (its
 * rows dealt out over the ranks) under 3 ranks bit for bit. The per-rank
 * summary accounts for every form-factor row once. The ranks run one thread each, the
 * serial run two: the results depend on neither.
 */
#include <string.h>

#include "mpi_run.h"

#define PATCHES "--patch-size 60"

/* The integer after "KEY": in a --stats file; -1 when missing. */
static long long stats_integer_of(const char *text, const char *key)
{
    char quoted[128];
    snprintf(quoted, sizeof(quoted), "\"%s\":", key);
    const char *at = strstr(text, quoted);
    return at ? strtoll(at + strlen(quoted), NULL, 10) : -1;
}

/* The sum over ranks of "rank R of N: K form-factor rows" in the last run's stderr. */
static long long rows_of_ranks(int ranks)
{
    return test_rank_work(test_read_text(test_path("stderr.txt")), ranks);
}

int main(void)
{
    CHECK(test_run_tool("solve -o serial.ply " PATCHES " --threads 2 --stats serial.json") == 0);
    const char *stats = test_read_text(test_path("serial.json"));
    long long patches = stats_integer_of(stats, "patches");
    CHECK(patches > 500);
    CHECK(strstr(stats, "\"solver\": \"gather\"") != NULL);
    CHECK(test_run_tool("render -o serial.png " PATCHES " --size 96x96 --threads 2") == 0);
    CHECK(test_run_tool("solve -o serial-gs.ply " PATCHES " --solver gauss-seidel --threads 2") ==
          0);
    CHECK(test_run_tool("solve -o serial-h.ply " PATCHES " --solver hierarchical --threads 2") ==
          0);

    for (int ranks = 1; ranks <= 4; ranks++) {
        char arguments[256], name[32];
        snprintf(name, sizeof(name), "ranks%d.ply", ranks);
        snprintf(arguments, sizeof(arguments),
                 "solve -o %s " PATCHES " --threads 1 --stats ranks.json", name);
        CHECK(test_run_mpi(ranks, arguments, 0, NULL) == 0);
        CHECK(test_same_bytes(test_path("serial.ply"), test_path(name)));
        if (ranks > 1) {
            CHECK(rows_of_ranks(ranks) == patches);
            CHECK(stats_integer_of(test_read_text(test_path("ranks.json")), "ranks") == ranks);
        }
        snprintf(name, sizeof(name), "ranks%d.png", ranks);
        snprintf(arguments, sizeof(arguments), "render -o %s " PATCHES " --size 96x96 --threads 1",
                 name);
        CHECK(test_run_mpi(ranks, arguments, 0, NULL) == 0);
        CHECK(test_same_bytes(test_path("serial.png"), test_path(name)));
        if (ranks > 1)
            CHECK(rows_of_ranks(ranks) == patches);
    }
    /* the image's rows dealt out over the ranks: the per-pixel direct light (each pixel's
     * own random numbers) as linear floats, bit for bit */
    CHECK(test_run_tool("render -o serial-pixel.pfm " PATCHES
                        " --size 96x96 --direct pixel --threads 2") == 0);
    CHECK(test_run_mpi(3, "render -o pixel.pfm " PATCHES " --size 96x96 --direct pixel --threads 1",
                       0, NULL) == 0);
    CHECK(test_same_bytes(test_path("serial-pixel.pfm"), test_path("pixel.pfm")));
    CHECK(test_run_mpi(3, "solve -o gs.ply " PATCHES " --solver gauss-seidel --threads 1", 0,
                       NULL) == 0);
    CHECK(test_same_bytes(test_path("serial-gs.ply"), test_path("gs.ply")));
    CHECK(test_run_mpi(3, "solve -o h.ply " PATCHES " --solver hierarchical --threads 1", 0,
                       NULL) == 0);
    CHECK(test_same_bytes(test_path("serial-h.ply"), test_path("h.ply")));
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "rank 2 of 3: ") != NULL &&
          strstr(test_read_text(test_path("stderr.txt")), " links held, ") != NULL);
    return test_finish("test_mpi_solve");
}
