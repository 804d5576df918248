/*
 * lit_mesh.h - the lit mesh handed to its per-format writers (internal).
 *
 * lit_mesh.c (rad_lit_mesh_write) reconstructs the vertex radiance (and, given the patch
 * inputs, the vertex illuminance), works out normals, the display colour and the
 * triangles, opens the atomic file and picks the writer by the extension; each writer
 * only encodes into the open stream and reports failures as one line naming `path`.
 *
 * The writers are our own, not Assimp's exporters: Assimp 5.2's PLY exporter has no
 * float properties besides positions, normals and texture coordinates (and truncates
 * colours instead of rounding), its glTF 2.0 exporter cannot write an application
 * attribute such as _RADIANCE or the unlit material, and its OBJ exporter has no place
 * for the linear radiance. The three formats are small enough to write directly.
 */
#ifndef RAD_OUTPUT_LIT_MESH_H
#define RAD_OUTPUT_LIT_MESH_H

#include <stdio.h>

#include "radiosity.h"

typedef struct lit_mesh {
    uint32_t vertex_count;
    const rad_vec3 *position;      /* the mesh's vertices, then the display's added ones */
    const rad_vec3 *normal;        /* unit: the area-weighted mean of the patches' normals */
    const rad_rgb *radiance;       /* linear radiance, rad_reconstruct_vertices */
    const rad_rgb *illuminance;    /* NULL (no patch inputs given: the file holds none),
                                      or the irradiance, reconstructed as the radiance */
    const rad_rgb *display;        /* radiance * scale clamped to [0,1], still linear */
    uint32_t triangle_count;
    const uint32_t (*triangles)[3];/* counter-clockwise: front */
    double scale;                  /* the exposure multiplier */
    bool automatic;                /* scale is the automatic exposure */
} lit_mesh;

rad_status lit_mesh_write_ply(const lit_mesh *mesh, FILE *stream, const char *path,
                              rad_error *error);
rad_status lit_mesh_write_glb(const lit_mesh *mesh, FILE *stream, const char *path,
                              rad_error *error);
rad_status lit_mesh_write_obj(const lit_mesh *mesh, FILE *stream, const char *path,
                              rad_error *error);

/* One line saying what the display colour is ("radiance x 0.0123 (automatic exposure),
 * clamped to [0,1]"), for the files' comments. */
void lit_mesh_describe_colour(const lit_mesh *mesh, char *text, size_t size);

#endif
