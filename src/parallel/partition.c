/*
 * partition.c - items shared over ranks by estimated cost (partition.h): the longest
 * processing time first rule, largest item first to the least loaded rank, which comes
 * within 4/3 of the best possible largest load. Ties go to the lower item index and the
 * lower rank, so every rank computes the same shares. Not a cost model: see the callers.
 */
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "parallel/partition.h"

typedef struct costed_item {
    double cost;
    uint32_t index;
} costed_item;

/* Larger cost first, then lower index. */
static int by_cost_descending(const void *a, const void *b)
{
    const costed_item *x = a, *y = b;
    if (x->cost != y->cost)
        return x->cost > y->cost ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index;
}

rad_status partition_by_cost(const double *cost, uint32_t n, int ranks, uint32_t *owner,
                             rad_error *error)
{
    if (ranks <= 1) {
        for (uint32_t i = 0; i < n; i++)
            owner[i] = 0;
        return RAD_OK;
    }
    costed_item *items = rad_alloc_array(n ? n : 1, sizeof(*items));
    double *load = rad_alloc_array((size_t)ranks, sizeof(*load));
    if (!items || !load) {
        free(items);
        free(load);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory sharing %u items over %d ranks",
                        n, ranks);
    }
    for (uint32_t i = 0; i < n; i++)
        items[i] = (costed_item){cost[i], i};
    qsort(items, n, sizeof(*items), by_cost_descending);
    for (uint32_t k = 0; k < n; k++) {
        int least = 0;
        for (int r = 1; r < ranks; r++)
            if (load[r] < load[least])
                least = r;
        owner[items[k].index] = (uint32_t)least;
        load[least] += items[k].cost;
    }
    free(items);
    free(load);
    return RAD_OK;
}

void partition_block(uint32_t n, int ranks, int rank, uint32_t *begin, uint32_t *end)
{
    *begin = (uint32_t)((uint64_t)n * (uint64_t)rank / (uint64_t)ranks);
    *end = (uint32_t)((uint64_t)n * (uint64_t)(rank + 1) / (uint64_t)ranks);
}
