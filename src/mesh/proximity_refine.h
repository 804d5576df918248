/*
 * proximity_refine.h - where other surfaces are near, split the cell (internal: mesh.c
 * asks it about every cell it makes).
 *
 * One patch size for a whole scene is derived from the whole scene's extent: a furnished
 * room standing on a ground plane twenty times its size gets patches as large as its
 * walls, and renders blotchy and dark. But the light changes over lengths set by how far
 * a point is from what it exchanges light with: a floor next to a table's foot, a room's
 * walls a few metres apart, not the open ground. (Ward, Rubinstein and Clear's split-sphere
 * model of irradiance caching, 1988, rests on the same fact: irradiance varies over the
 * distance to the surroundings.) So every cell sends PROXIMITY_RAYS cosine-weighted rays
 * from its centre; when a quarter or more meet a surface, and the cell's longest edge is
 * more than PROXIMITY_SHARE of the mean distance they travelled, the cell is split in
 * four and the children are tested again, down to `levels` splits, while the patches
 * added stay within a budget. Open ground under the sky (most rays meet nothing) keeps
 * its size; a closed room gets cells a fraction of its size whatever surrounds it.
 *
 * Deterministic: the rays' directions come from the cell's corners, not from a thread or
 * call order. Not done: the budget is spent in scene order (first cells first), so a
 * scene that exhausts it leaves its last surfaces coarse; the mesh reports that.
 */
#ifndef RAD_MESH_PROXIMITY_REFINE_H
#define RAD_MESH_PROXIMITY_REFINE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "radiosity.h"

#define PROXIMITY_RAYS 32u

typedef struct proximity_refiner {
    rad_tracer *tracer;   /* the scene's triangles; NULL: refinement off */
    uint32_t levels;      /* splits of a cell at most */
    size_t budget;        /* patches it may add */
    size_t added;         /* patches added so far */
    uint32_t split;       /* cells split */
    bool budget_reached;
} proximity_refiner;

/* Ready to test cells of `scene` (off, with nothing allocated, when levels is 0). */
rad_status proximity_refiner_init(proximity_refiner *refiner, const rad_scene *scene,
                                  uint32_t levels, size_t budget, rad_error *error);

/* Should the cell with these corners (3 or 4, counter-clockwise, unit normal `normal`)
 * be split? `two_sided` tests its back too. True also reserves the three patches the
 * split adds. */
bool proximity_refiner_splits(proximity_refiner *refiner, const rad_vec3 *corners,
                              uint32_t count, rad_vec3 normal, bool two_sided);

void proximity_refiner_free(proximity_refiner *refiner);

#endif
