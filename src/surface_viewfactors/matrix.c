/*
 * matrix.c - an empty rad_viewfactor_matrix to fill by hand. Every array is its own
 * allocation, as the engine makes them, freed one by one by rad_viewfactor_matrix_destroy.
 */
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"

rad_status rad_viewfactor_matrix_create(uint32_t n, uint64_t nonzeros,
                                        rad_viewfactor_matrix **out, rad_error *error)
{
    *out = NULL;
    rad_viewfactor_matrix *m = rad_alloc_array(1, sizeof(*m));
    if (!m || nonzeros > SIZE_MAX)
        goto nomem;
    m->n = n;
    m->area = rad_alloc_array(n, sizeof(*m->area));
    m->row_start = rad_alloc_array((size_t)n + 1, sizeof(*m->row_start));
    m->column = rad_alloc_array((size_t)nonzeros, sizeof(*m->column));
    m->value = rad_alloc_array((size_t)nonzeros, sizeof(*m->value));
    m->error_bound = rad_alloc_array((size_t)nonzeros, sizeof(*m->error_bound));
    if (!m->area || !m->row_start || !m->column || !m->value || !m->error_bound)
        goto nomem;
    *out = m;
    return RAD_OK;
nomem:
    rad_viewfactor_matrix_destroy(m);
    return rad_fail(error, RAD_ERR_NOMEM,
                    "out of memory for a view-factor matrix of %u surfaces and %llu factors", n,
                    (unsigned long long)nonzeros);
}
