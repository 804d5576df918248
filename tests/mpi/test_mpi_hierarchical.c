/*
 * test_mpi_hierarchical.c - `mpirun -np N radiosity solve --solver hierarchical` for N = 1
 * to 4 on the built-in Cornell box at a fine patch size (about 10,000 patches, 400,000
 * links): the ranks share the links by receiver subtree, so
 *   - the lit mesh is the serial run's, byte for byte (each rank's links and sums are the
 *     serial run's: stronger than any tolerance), and again so in a second 2-rank run with
 *     two threads per rank;
 *   - the links held per rank sum to the serial link count, plus the shared ones (received
 *     above the cut into subtrees) once more for every rank after the first;
 *   - the most links any rank holds falls as ranks are added, at 4 ranks to at most 0.4 of
 *     the serial run's; the largest peak link store too, at 4 ranks to at most 0.5 of the
 *     serial store and below the 2-rank one (a store grows by half its size when full, so
 *     its peak is lumpier than the links).
 * `render` under 3 ranks gives the serial image too. Not a timing test: the time and peak
 * memory lines are only checked to be there.
 */
#include <string.h>

#include "mpi_run.h"

#define SCENE "--solver hierarchical --patch-size 14"

/* The integer after "KEY": in a --stats file; -1 when missing. */
static long long stats_integer_of(const char *text, const char *key)
{
    char quoted[128];
    snprintf(quoted, sizeof(quoted), "\"%s\":", key);
    const char *at = strstr(text, quoted);
    return at ? strtoll(at + strlen(quoted), NULL, 10) : -1;
}

/* The most "rank R of N: K links held" over the ranks of the last run's stderr. */
static long long most_links_held(const char *err, int ranks)
{
    long long most = 0;
    for (int r = 0; r < ranks; r++) {
        char key[64];
        snprintf(key, sizeof(key), "rank %d of %d: ", r, ranks);
        const char *line = strstr(err, key);
        CHECK(line != NULL);
        if (!line)
            continue;
        char *end = NULL;
        long long held = strtoll(line + strlen(key), &end, 10);
        CHECK(strncmp(end, " links held, ", 13) == 0);
        CHECK(strstr(line, "peak memory ") != NULL);
        most = held > most ? held : most;
    }
    return most;
}

/* The largest of the link-store megabytes rank 0 lists for every rank; -1 without it. */
static double most_link_store(const char *err, int ranks)
{
    const char *key = "link store per rank (peak, MB, rank 0 first): ";
    const char *at = strstr(err, key);
    CHECK(at != NULL);
    if (!at)
        return -1;
    at += strlen(key);
    double most = -1;
    for (int r = 0; r < ranks; r++) {
        char *end = NULL;
        double mb = strtod(at, &end);
        CHECK(end != at && mb > 0);
        most = mb > most ? mb : most;
        at = end;
        if (*at == ',')
            at += 2;
    }
    return most;
}

int main(void)
{
    CHECK(test_run_tool("solve -o serial.ply " SCENE " --threads 2 --stats serial.json") == 0);
    const char *stats = test_read_text(test_path("serial.json"));
    long long links = stats_integer_of(stats, "links");
    double serial_store = (double)stats_integer_of(stats, "link_bytes") / 1e6;
    CHECK(stats_integer_of(stats, "patches") > 8000);
    CHECK(links > 200000);

    long long previous = links;
    double store_at_2 = -1;
    for (int ranks = 1; ranks <= 4; ranks++) {
        char arguments[256], name[32];
        snprintf(name, sizeof(name), "ranks%d.ply", ranks);
        snprintf(arguments, sizeof(arguments), "solve -o %s " SCENE " --threads 1", name);
        CHECK(test_run_mpi(ranks, arguments, 0, NULL) == 0);
        CHECK(test_same_bytes(test_path("serial.ply"), test_path(name)));
        if (ranks == 1)
            continue;
        const char *err = test_read_text(test_path("stderr.txt"));
        const char *all = strstr(err, "links: ");
        CHECK(all != NULL);
        long long total = all ? strtoll(all + strlen("links: "), NULL, 10) : -1;
        const char *shared_at = all ? strstr(all, "and the ") : NULL;
        long long shared = shared_at ? strtoll(shared_at + strlen("and the "), NULL, 10) : -1;
        CHECK(total == links);
        CHECK(shared >= 0 && shared < links / 10);
        CHECK(test_rank_work(err, ranks) == links + (ranks - 1) * shared);
        long long most = most_links_held(err, ranks);
        double store = most_link_store(err, ranks);
        printf("%d ranks: at most %lld links (serial %lld), link store at most %.1f MB "
               "(serial %.1f MB)\n",
               ranks, most, links, store, serial_store);
        CHECK(most < previous);
        if (ranks == 2)
            store_at_2 = store;
        if (ranks == 4) {
            CHECK(most <= 0.4 * links);
            CHECK(store > 0 && store <= 0.5 * serial_store && store < store_at_2);
        }
        previous = most;
    }
    /* the same rank count again, other threads: the same bytes */
    CHECK(test_run_mpi(2, "solve -o again.ply " SCENE " --threads 2", 0, NULL) == 0);
    CHECK(test_same_bytes(test_path("ranks2.ply"), test_path("again.ply")));

    CHECK(test_run_tool("render -o serial.png --solver hierarchical --patch-size 40 --size "
                        "64x64 --threads 2") == 0);
    CHECK(test_run_mpi(3, "render -o ranks3.png --solver hierarchical --patch-size 40 --size "
                          "64x64 --threads 1",
                       0, NULL) == 0);
    CHECK(test_same_bytes(test_path("serial.png"), test_path("ranks3.png")));
    return test_finish("test_mpi_hierarchical");
}
