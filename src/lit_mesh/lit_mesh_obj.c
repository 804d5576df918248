/*
 * lit_mesh_obj.c - the lit mesh as Wavefront OBJ with vertex colours.
 *
 * `v x y z r g b` is the vertex-colour extension MeshLab and Blender read; r g b is the
 * display colour sRGB-encoded in [0,1] (what those tools show as is). OBJ has no place for
 * a second colour, so the linear radiance follows the vertices as comment lines
 * `#radiance R G B`, one per vertex in the same order: every OBJ reader skips them, and
 * the file stays one file. When the mesh has the illuminance, each `#radiance` line is
 * followed by that vertex's `#illuminance R G B`. Triangles reference the normals:
 * `f a//a b//b c//c`.
 */
#include <errno.h>
#include <string.h>

#include "core/error.h"
#include "image/tonemap.h"
#include "lit_mesh/lit_mesh.h"

rad_status lit_mesh_write_obj(const lit_mesh *mesh, FILE *stream, const char *path,
                              rad_error *error)
{
    char colour[256];
    lit_mesh_describe_colour(mesh, colour, sizeof(colour));
    fprintf(stream,
            "# radiosity lit mesh: per-vertex radiance of a radiosity solution\n"
            "# v x y z r g b: r g b is the display colour, sRGB-encoded, of %s\n"
            "# #radiance R G B: each vertex's linear radiance (unit of the emitters' Ke), in "
            "the order of the v lines\n",
            colour);
    if (mesh->illuminance)
        fprintf(stream, "# #illuminance R G B: after each #radiance line, that vertex's "
                        "illuminance (irradiance; lux with lights in candela and lux)\n");
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const rad_vec3 *p = &mesh->position[v];
        const rad_rgb *d = &mesh->display[v];
        fprintf(stream, "v %.9g %.9g %.9g %.6f %.6f %.6f\n", p->x, p->y, p->z,
                rad_tonemap_srgb_encode(d->r), rad_tonemap_srgb_encode(d->g),
                rad_tonemap_srgb_encode(d->b));
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const rad_vec3 *n = &mesh->normal[v];
        fprintf(stream, "vn %.7f %.7f %.7f\n", n->x, n->y, n->z);
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const rad_rgb *L = &mesh->radiance[v];
        fprintf(stream, "#radiance %.9g %.9g %.9g\n", L->r, L->g, L->b);
        if (mesh->illuminance) {
            const rad_rgb *E = &mesh->illuminance[v];
            fprintf(stream, "#illuminance %.9g %.9g %.9g\n", E->r, E->g, E->b);
        }
    }
    for (uint32_t t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *f = mesh->triangles[t];
        fprintf(stream, "f %u//%u %u//%u %u//%u\n", f[0] + 1, f[0] + 1, f[1] + 1, f[1] + 1,
                f[2] + 1, f[2] + 1);
    }
    if (ferror(stream))
        return rad_fail(error, RAD_ERR_IO, "%s: write failed: %s", path, strerror(errno));
    return RAD_OK;
}
