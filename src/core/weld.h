/*
 * weld.h - merging vertices with bitwise-identical positions within a region.
 *
 * A weld table maps (region, exact position) to a vertex index: the first time a position
 * is seen in a region it gets the next index, later lookups return the same one. Exact
 * equality (after folding -0 into +0) is enough because the mesh computes every shared
 * point with the same arithmetic on the same inputs; near-coincident but different points
 * stay separate on purpose.
 */
#ifndef RAD_CORE_WELD_H
#define RAD_CORE_WELD_H

#include <stdint.h>

#include "radiosity.h"

typedef struct rad_weld {
    uint32_t *slots;      /* vertex index + 1, 0 = empty; capacity is a power of two */
    uint32_t *regions;    /* region of each vertex, by vertex index */
    rad_vec3 *positions;  /* position of each vertex, by vertex index */
    uint32_t count;       /* vertices so far */
    uint32_t slot_count;
    uint32_t capacity;    /* allocated vertex arrays */
} rad_weld;

/* 0 on allocation failure. */
int rad_weld_init(rad_weld *weld, uint32_t expected_vertices);

/* Index of the vertex at `position` in `region`, inserting it when new. UINT32_MAX on
 * allocation failure. */
uint32_t rad_weld_insert(rad_weld *weld, uint32_t region, rad_vec3 position);

/* Hands the positions array to the caller (who frees it) and frees the rest. */
rad_vec3 *rad_weld_take_positions(rad_weld *weld);

void rad_weld_free(rad_weld *weld);

#endif
