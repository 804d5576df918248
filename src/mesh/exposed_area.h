/*
 * exposed_area.h - the share of each patch's area that is not buried inside a closed
 * object (internal).
 *
 * A patch of a floor may run under a box standing on it: the mesh is not cut along the
 * box's foot. The part under the box receives no light and sends none, yet the patch's
 * form factors are integrated over its whole area and its light sources' irradiance
 * averaged over it, so its radiosity came out as the mean over both parts, and what
 * the rest of the scene gathers from its open part (whose visible area the factors see
 * rightly) too dark by that share: light vanished at every box's foot. On the Cornell box
 * the image came out 0.2 % dark everywhere, against the path tracer, which agreed with
 * the render of the direct light alone to 0.005 %.
 *
 * So the patch inputs (rad_patch_inputs) take each patch's exposed area, A_i s_i, and the
 * means over the patch (its direct light, its dense form-factor row) are divided by s_i:
 * B_i is then the radiosity of the open part, and the exchange with it is what that part
 * sends and receives.
 *
 * s_i is measured: 8 x 8 points of the patch (cell centres), each lifted a hair off the
 * surface, cast 8 rays into its hemisphere (two rings, 30 and 60 degrees off the normal);
 * a point is buried when 7 or more of them meet the back of a face first (the renderer's
 * rule for its vertices, render/vertex_light.c). A patch with some points buried and some
 * open is measured again with 32 x 32 points: its share to about 1/1000 (a row divided by
 * a share of 1/64 came out 17 % above 1 on the Cornell box). A patch none of whose points is buried
 * keeps s_i = 1 bit for bit; one all of whose points are keeps 1 too (it sees nothing and
 * nothing sees it: its row is 0 whatever its area).
 */
#ifndef RAD_MESH_EXPOSED_AREA_H
#define RAD_MESH_EXPOSED_AREA_H

#include "radiosity.h"

#include <stdint.h>

/* A partly buried patch is measured at EXPOSED_FINE_SIDE x EXPOSED_FINE_SIDE cells. */
#define EXPOSED_FINE_SIDE 32u
#define EXPOSED_CELL_BYTES (EXPOSED_FINE_SIDE * EXPOSED_FINE_SIDE / 8)

/* share[i] in (0, 1] for each patch of the mesh, made from `scene`. */
rad_status patch_exposed_shares(const rad_scene *scene, const rad_mesh *mesh, double *share,
                                rad_error *error);

/* How far off its surface a patch's points are lifted (and past a fold: 2 x behind). */
double exposed_lift(const rad_mesh *mesh);

/* Which cells of patch `patch`'s fine split are open, as patch_exposed_shares finds them
 * (tracer: made from the scene, rad_tracer_create_for_scene): the point at (s, t) of the
 * unit square (the form factors' map, pair_engine.c) lies in cell (a, b) = (floor(s x 32),
 * floor(t x 32)), open when bit a x 32 + b is set. Returns how many are. */
unsigned patch_open_cells(const rad_tracer *tracer, const rad_mesh *mesh, uint32_t patch,
                          double lift, uint8_t bits[EXPOSED_CELL_BYTES]);

#endif
