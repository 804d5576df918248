/*
 * test_partition.c - items shared over ranks by estimated cost (src/parallel/partition.c):
 * a hand-worked example of the largest-first rule, ties, one rank, and on random costs
 * Graham's bound for that rule (largest load <= (4/3 - 1/(3m)) of the best possible, which
 * is at least max(total / m, largest item)) with every item given to exactly one rank.
 * Runs in every build: the sharing needs no MPI.
 */
#include <stdlib.h>

#include "core/random.h"
#include "parallel/partition.h"
#include "testlib.h"

static void loads_of(const double *cost, const uint32_t *owner, uint32_t n, int ranks,
                     double *load)
{
    for (int r = 0; r < ranks; r++)
        load[r] = 0;
    for (uint32_t i = 0; i < n; i++)
        load[owner[i]] += cost[i];
}

int main(void)
{
    /* 5, 4, 3, 3, 3 over 2 ranks: 5 -> 0, 4 -> 1, 3 -> 1 (4 < 5), 3 -> 0 (5 < 7),
     * 3 -> 1 (7 < 8): loads 8 and 10 (the best is 9: LPT is not optimal) */
    double cost[5] = {3, 5, 3, 4, 3};
    uint32_t owner[5];
    CHECK(partition_by_cost(cost, 5, 2, owner, NULL) == RAD_OK);
    CHECK(owner[1] == 0 && owner[3] == 1);
    CHECK(owner[0] == 1 && owner[2] == 0 && owner[4] == 1); /* ties: lower index first */
    double load[64];
    loads_of(cost, owner, 5, 2, load);
    CHECK(load[0] == 8 && load[1] == 10);

    /* one rank: everything to rank 0 */
    CHECK(partition_by_cost(cost, 5, 1, owner, NULL) == RAD_OK);
    CHECK(owner[0] == 0 && owner[1] == 0 && owner[2] == 0 && owner[3] == 0 && owner[4] == 0);

    /* no items */
    CHECK(partition_by_cost(cost, 0, 3, owner, NULL) == RAD_OK);

    /* random costs, heavy-tailed like obstructed rows: within Graham's bound */
    enum { N = 5000 };
    double *costs = malloc(N * sizeof(double));
    uint32_t *owners = malloc(N * sizeof(uint32_t)), *again = malloc(N * sizeof(uint32_t));
    CHECK(costs && owners && again);
    for (int ranks = 2; costs && owners && again && ranks <= 64; ranks *= 2) {
        rad_rng rng = rad_rng_seed(7, (uint64_t)ranks, 0);
        double total = 0, largest = 0;
        for (uint32_t i = 0; i < N; i++) {
            double u = rad_rng_uniform(&rng);
            costs[i] = i % 7 == 0 ? 1000 * u * u * u : u; /* a few expensive rows */
            total += costs[i];
            largest = costs[i] > largest ? costs[i] : largest;
        }
        CHECK(partition_by_cost(costs, N, ranks, owners, NULL) == RAD_OK);
        bool in_range = true;
        for (uint32_t i = 0; i < N; i++)
            in_range = in_range && owners[i] < (uint32_t)ranks;
        CHECK(in_range);
        loads_of(costs, owners, N, ranks, load);
        double best_bound = total / ranks > largest ? total / ranks : largest, most = 0, sum = 0;
        for (int r = 0; r < ranks; r++) {
            most = load[r] > most ? load[r] : most;
            sum += load[r];
        }
        CHECK_NEAR(sum, total, 1e-12);
        CHECK(most <= (4.0 / 3 - 1.0 / (3 * ranks)) * best_bound * (1 + 1e-12));
        /* deterministic: the same shares again */
        CHECK(partition_by_cost(costs, N, ranks, again, NULL) == RAD_OK);
        bool same = true;
        for (uint32_t i = 0; i < N; i++)
            same = same && again[i] == owners[i];
        CHECK(same);
    }
    free(costs);
    free(owners);
    free(again);
    return test_finish("test_partition");
}
