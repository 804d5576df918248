/*
 * reconstruct.c - radiance at mesh vertices from per-patch radiosity.
 *
 * Each vertex takes the area-weighted mean of B / pi over the patches that share it; a
 * T-vertex (inside an edge of a neighbouring patch, display_mesh.h) then takes the linear
 * interpolation along that edge, so both sides of it show the same values. Vertices are
 * shared only inside a smooth region (mesh.c), so creases and emitters keep their own
 * values.
 */
#include "reconstruct/display_mesh.h"

void rad_reconstruct_vertices(const rad_mesh *mesh, const rad_rgb *B, rad_rgb *vertex_radiance)
{
    display_mesh display;
    bool found = display_mesh_build(mesh, false, &display, NULL) == RAD_OK;
    /* out of memory for the T-vertices: the area-weighted means alone; out of memory for
     * those too: black */
    (void)display_mesh_radiance(mesh, found ? &display : NULL, B, vertex_radiance);
    if (found)
        display_mesh_free(&display);
}
