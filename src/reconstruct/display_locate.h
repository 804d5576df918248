/*
 * display_locate.h - where a hit on a scene triangle lies in the display mesh (internal).
 *
 * A final gather traces thousands of rays a vertex. Traced against the display mesh
 * (every patch split into triangles) each ray walks a tree over tens of thousands of
 * triangles; traced against the scene's own triangles (a Cornell box has 32) it walks
 * almost none, and the display triangle under the hit is then found here: each scene
 * triangle holds a grid over its bounding rectangle (along its longest edge and across),
 * each cell the display triangles that overlap it, each with the affine map from the
 * hit's (u, v) to its own barycentrics. Which display triangles lie on which scene triangle is found by probing:
 * short rays from just in front of points of each display triangle, back onto it, against
 * the scene, keeping the scene triangles of the same surface, material and side.
 *
 * Only the front patches' display triangles are located (display_mesh_front_triangles): a
 * hit on a scene triangle's back is its front patch's back, as with the display tracer.
 * Where no display triangle covers a hit (a sliver that no probe found, a folded quad's
 * cell that strays from its input triangles), display_locate says so and the caller
 * traces that ray against the display mesh instead: the answer never depends on the
 * probes having found everything, only the speed. A miss of the scene's triangles is a
 * miss: the display mesh, made from those triangles, covers nothing else.
 */
#ifndef RAD_RECONSTRUCT_DISPLAY_LOCATE_H
#define RAD_RECONSTRUCT_DISPLAY_LOCATE_H

#include <stdbool.h>

#include "radiosity.h"
#include "reconstruct/display_mesh.h"

typedef struct display_locator display_locator;

/* The bytes a display triangle that building the locator is expected to hold at its
 * peak (test_display_locate holds what every scene it builds keeps under this: 62 on its
 * Cornell box and 69 on its long thin strip, the cells' listings 4-byte indices; 182 and
 * 214 when each listing held its own copy of the map, 88 and 89 with two display
 * triangles a cell, both before 2026-12-06): under a budget, the first check. Once the
 * listings are counted, what they need is checked against the budget again. */
#define DISPLAY_LOCATE_BYTES_PER_TRIANGLE 256u

/* Builds the locator for the first `front` display triangles (positions: every display
 * vertex's, display_mesh_positions) on the scene `scene_tracer` was made from
 * (rad_tracer_create_for_scene). *out is NULL (and the status RAD_OK) when there is
 * nothing to locate, or under a memory budget (--max-memory) that cannot hold the
 * locator and `keep` bytes more (what the caller needs afterwards): the locator only saves
 * time, and is given up before anything else. */
rad_status display_locator_build(const rad_scene *scene, const rad_tracer *scene_tracer,
                                 const rad_mesh *mesh, const display_mesh *display,
                                 const rad_vec3 *positions, uint32_t front, uint64_t keep,
                                 int threads, display_locator **out, rad_error *error);

/* Turns a hit on the scene's triangles into the same hit on the display triangles:
 * hit->triangle becomes the display triangle, u and v its barycentrics of the point (the
 * weights of its corners 1 and 2); t and front stay. A miss stays a miss. False when no
 * display triangle covers the point (the hit is then unchanged). Thread-safe. */
bool display_locate(const display_locator *locator, rad_hit *hit);

/* The bytes the locator holds. */
uint64_t display_locator_bytes(const display_locator *locator);

void display_locator_destroy(display_locator *locator);

#endif
