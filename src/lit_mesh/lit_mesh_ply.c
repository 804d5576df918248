/*
 * lit_mesh_ply.c - the lit mesh as binary little-endian PLY (MeshLab, Blender, CloudCompare).
 *
 * Vertex: float x y z, float nx ny nz, uchar red green blue (display colour, sRGB 8-bit:
 * what MeshLab shows), float radiance_r radiance_g radiance_b (linear), and when the
 * mesh has it, float illuminance_r illuminance_g illuminance_b. Face: list uchar int
 * vertex_indices (uchar count and int indices, the pair every reader accepts).
 */
#include <errno.h>
#include <string.h>

#include "core/bytes.h"
#include "core/error.h"
#include "image/tonemap.h"
#include "lit_mesh/lit_mesh.h"

/* A vertex record: position, normal, colour, radiance, then the illuminance if any. */
enum { VERTEX_BYTES = 12 + 12 + 3 + 12, ILLUMINANCE_BYTES = 12, FACE_BYTES = 1 + 3 * 4 };

rad_status lit_mesh_write_ply(const lit_mesh *mesh, FILE *stream, const char *path,
                              rad_error *error)
{
    char colour[256];
    lit_mesh_describe_colour(mesh, colour, sizeof(colour));
    bool illuminance = mesh->illuminance != NULL;
    fprintf(stream,
            "ply\n"
            "format binary_little_endian 1.0\n"
            "comment radiosity lit mesh: per-vertex radiance of a radiosity solution\n"
            "comment red green blue: display colour, sRGB 8-bit, of %s\n"
            "comment radiance_r radiance_g radiance_b: linear radiance, unit of the emitters' "
            "Ke\n",
            colour);
    if (illuminance)
        fprintf(stream, "comment illuminance_r illuminance_g illuminance_b: illuminance "
                        "(irradiance), lux with lights in candela and lux\n");
    fprintf(stream,
            "element vertex %u\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property float nx\nproperty float ny\nproperty float nz\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\n"
            "property float radiance_r\nproperty float radiance_g\nproperty float radiance_b\n",
            mesh->vertex_count);
    if (illuminance)
        fprintf(stream, "property float illuminance_r\nproperty float illuminance_g\n"
                        "property float illuminance_b\n");
    fprintf(stream,
            "element face %u\n"
            "property list uchar int vertex_indices\n"
            "end_header\n",
            mesh->triangle_count);
    uint8_t record[VERTEX_BYTES + ILLUMINANCE_BYTES];
    size_t record_bytes = VERTEX_BYTES + (illuminance ? ILLUMINANCE_BYTES : 0);
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const rad_vec3 *p = &mesh->position[v], *n = &mesh->normal[v];
        const rad_rgb *d = &mesh->display[v], *L = &mesh->radiance[v];
        bytes_put_f32(record + 0, (float)p->x);
        bytes_put_f32(record + 4, (float)p->y);
        bytes_put_f32(record + 8, (float)p->z);
        bytes_put_f32(record + 12, (float)n->x);
        bytes_put_f32(record + 16, (float)n->y);
        bytes_put_f32(record + 20, (float)n->z);
        record[24] = rad_tonemap_srgb8(d->r);
        record[25] = rad_tonemap_srgb8(d->g);
        record[26] = rad_tonemap_srgb8(d->b);
        bytes_put_f32(record + 27, (float)L->r);
        bytes_put_f32(record + 31, (float)L->g);
        bytes_put_f32(record + 35, (float)L->b);
        if (illuminance) {
            const rad_rgb *E = &mesh->illuminance[v];
            bytes_put_f32(record + VERTEX_BYTES, (float)E->r);
            bytes_put_f32(record + VERTEX_BYTES + 4, (float)E->g);
            bytes_put_f32(record + VERTEX_BYTES + 8, (float)E->b);
        }
        if (fwrite(record, record_bytes, 1, stream) != 1)
            goto failed;
    }
    uint8_t face[FACE_BYTES];
    face[0] = 3;
    for (uint32_t t = 0; t < mesh->triangle_count; t++) {
        for (int k = 0; k < 3; k++)
            bytes_put_u32(face + 1 + 4 * k, mesh->triangles[t][k]);
        if (fwrite(face, sizeof(face), 1, stream) != 1)
            goto failed;
    }
    return RAD_OK;
failed:
    return rad_fail(error, RAD_ERR_IO, "%s: write failed: %s", path, strerror(errno));
}
