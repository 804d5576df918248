/*
 * shadow_refine.h - where the shadows of the light sources and of the emitting surfaces
 * cross a patch, split it (internal: mesh.c asks it about every cell it makes).
 *
 * The point, spot, luminaire and sun lights (direct_light.h's "sharp" sources) make light
 * that jumps at shadow boundaries; an emitting surface (an area light) makes a penumbra
 * that changes over a short distance where an object stands on or near a lit floor. A patch carries one radiosity value, so a shadow edge
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
 * and the emitters' points are fixed per scene, not from a thread or call order. Not
 * done: the sky's shadows (soft, and from every direction).
 */
#ifndef RAD_MESH_SHADOW_REFINE_H
#define RAD_MESH_SHADOW_REFINE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "lights/direct_light.h"
#include "radiosity.h"

#define SHADOW_REFINE_SIDE 4u /* test points per side of a cell */
#define EMITTER_PROBES 32u     /* points on the emitting triangles, all together */

/* A point on an emitting triangle, standing for its share of the emitters' power. */
typedef struct emitter_probe {
    rad_vec3 point, normal;
    double power;   /* luminance of L_e x the area it stands for */
    bool two_sided;
} emitter_probe;

typedef struct shadow_refiner {
    light_set set;
    emitter_probe probes[EMITTER_PROBES];
    uint32_t probe_count; /* 0: the scene has no emitter */
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
 * scene has neither a sharp light nor an emitting surface). `budget` bounds the patches the splits may add. */
rad_status shadow_refiner_init(shadow_refiner *refiner, const rad_scene *scene,
                               uint32_t levels, size_t budget, rad_error *error);

/* Should the cell with these corners (3 or 4, counter-clockwise, unit normal `normal`)
 * be split? `bulge` lifts its test points as patch_direct does; `two_sided` tests its back
 * too. True also reserves the three patches the split adds. */
bool shadow_refiner_splits(shadow_refiner *refiner, const rad_vec3 *corners, uint32_t count,
                           rad_vec3 normal, double bulge, bool two_sided);

void shadow_refiner_free(shadow_refiner *refiner);

#endif
