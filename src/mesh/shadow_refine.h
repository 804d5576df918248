/*
 * shadow_refine.h - where the sharp light sources' shadows cross a patch, split it
 * (internal: mesh.c asks it about every cell it makes).
 *
 * The point, spot, luminaire and sun lights (direct_light.h's "sharp" sources) make light
 * that jumps at shadow boundaries. A patch carries one radiosity value, so a shadow edge
 * crossing it is smeared over the patch, in the lit mesh and in every solver's first
 * bounce. The mesh therefore tests each cell it makes: at 4 x 4 points of the cell (and
 * of its back, for a two-sided surface) the sharp sources' irradiance with and without
 * shadow rays; when the share that gets through differs between points (a shadow edge,
 * or a cone's edge, runs through the cell) and that difference is a large part of the
 * light there, the cell is split in four, and its children are tested again, down to
 * `levels` splits (each halves the edges), while the patches added stay within a budget.
 * The same mesh then serves every solver and renderer, so the dense solvers and the
 * hierarchical one (whose leaves are these patches) all see the shadow at the finer size.
 *
 * Deterministic: the sun's disk point at each test point comes from the cell's corners,
 * not from a thread or call order. Not done: the emitters' (area lights') shadows, and
 * the sky's; both are soft.
 */
#ifndef RAD_MESH_SHADOW_REFINE_H
#define RAD_MESH_SHADOW_REFINE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "lights/direct_light.h"
#include "radiosity.h"

#define SHADOW_REFINE_SIDE 4u /* test points per side of a cell */

typedef struct shadow_refiner {
    light_set set;
    rad_tracer *tracer;   /* the scene's triangles; NULL: refinement off */
    uint32_t levels;      /* splits of a cell at most */
    size_t budget;        /* patches it may add */
    size_t added;         /* patches added so far */
    uint32_t split;       /* cells split */
    bool budget_reached;
    rad_ray *rays;        /* buffers for one cell's test */
    rad_rgb *irradiance;
    uint8_t *occluded;
    uint32_t *point_of;   /* per ray: its test point */
    uint32_t capacity;
} shadow_refiner;

/* Ready to test cells of `scene` (off, with nothing allocated, when levels is 0 or the
 * scene has no sharp light). `budget` bounds the patches the splits may add. */
rad_status shadow_refiner_init(shadow_refiner *refiner, const rad_scene *scene,
                               uint32_t levels, size_t budget, rad_error *error);

/* Should the cell with these corners (3 or 4, counter-clockwise, unit normal `normal`)
 * be split? `bulge` lifts its test points as patch_direct does; `two_sided` tests its back
 * too. True also reserves the three patches the split adds. */
bool shadow_refiner_splits(shadow_refiner *refiner, const rad_vec3 *corners, uint32_t count,
                           rad_vec3 normal, double bulge, bool two_sided);

void shadow_refiner_free(shadow_refiner *refiner);

#endif
