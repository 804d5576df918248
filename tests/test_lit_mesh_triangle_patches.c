/*
 * test_lit_mesh_triangle_patches.c - rad_lit_mesh_triangle_patches against the .glb that
 * rad_lit_mesh_write writes for the same mesh: as many entries as the file has triangles,
 * and each patch exactly covered by the file's triangles said to be its own (their areas
 * sum to the patch's area, each faces the patch's way and lies in its plane), on the
 * Cornell box coarse and fine, and with a two-sided surface (its twins' triangles too).
 * The same for the table rad_lit_mesh_write gives back (rad_lit_mesh_options
 * .triangle_patches) when the light is computed at the vertices, where patches in the
 * blocks' penumbrae are shown split (light_refine.c): its pieces' triangles must cover
 * their patch exactly too, and there must be more triangles than without the split.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "testlib.h"

static uint32_t get_u32(const uint8_t *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static float get_f32(const uint8_t *b)
{
    uint32_t u = get_u32(b);
    float f;
    memcpy(&f, &u, sizeof(f));
    return f;
}

/* The data of accessor `index` (its buffer view's offset into the binary chunk). */
static const uint8_t *accessor_data(const cJSON *json, int index, const uint8_t *bin,
                                    uint32_t *count)
{
    const cJSON *accessor = cJSON_GetArrayItem(cJSON_GetObjectItem(json, "accessors"), index);
    const cJSON *view = cJSON_GetArrayItem(
        cJSON_GetObjectItem(json, "bufferViews"),
        (int)cJSON_GetNumberValue(cJSON_GetObjectItem(accessor, "bufferView")));
    *count = (uint32_t)cJSON_GetNumberValue(cJSON_GetObjectItem(accessor, "count"));
    return bin + (size_t)cJSON_GetNumberValue(cJSON_GetObjectItem(view, "byteOffset"));
}

static rad_vec3 sub(rad_vec3 a, rad_vec3 b) { return (rad_vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static rad_vec3 cross(rad_vec3 a, rad_vec3 b)
{
    return (rad_vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static double dot(rad_vec3 a, rad_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/* With lit_at_vertices the lit mesh takes the light at the vertices (the scene given) and
 * the table comes from the writer; returns the file's triangle count. */
static uint32_t check_mesh(const char *label, rad_scene *scene, double patch_size,
                           bool lit_at_vertices)
{
    rad_error error = {0};
    rad_mesh *mesh = NULL;
    CHECK(rad_mesh_build(scene, patch_size, &mesh, &error) == RAD_OK);
    if (!mesh)
        return 0;
    rad_rgb *B = calloc(mesh->patch_count, sizeof(*B));
    for (uint32_t i = 0; i < mesh->patch_count; i++)
        B[i] = (rad_rgb){1, 1, 1};
    const char *path = test_path("lit.glb");
    uint32_t *patch_of = NULL, triangles = 0;
    if (lit_at_vertices) {
        rad_lit_mesh_options options = {.scene = scene,
                                        .threads = 2,
                                        .triangle_patches = &patch_of,
                                        .triangle_patch_count = &triangles};
        CHECK(rad_lit_mesh_write(mesh, B, path, &options, &error) == RAD_OK);
    } else {
        CHECK(rad_lit_mesh_write(mesh, B, path, NULL, &error) == RAD_OK);
        CHECK(rad_lit_mesh_triangle_patches(mesh, &patch_of, &triangles, &error) == RAD_OK);
    }
    CHECK(patch_of != NULL);

    size_t size = 0;
    uint8_t *bytes = test_read_bytes(path, &size);
    CHECK(bytes && size > 28);
    uint32_t json_length = bytes ? get_u32(bytes + 12) : 0;
    cJSON *json = bytes ? cJSON_ParseWithLength((const char *)bytes + 20, json_length) : NULL;
    const cJSON *primitive = cJSON_GetArrayItem(
        cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(json, "meshes"), 0),
                            "primitives"),
        0);
    CHECK(primitive != NULL);
    if (primitive && patch_of) {
        const uint8_t *bin = bytes + 20 + json_length + 8;
        uint32_t vertices = 0, indices = 0;
        const uint8_t *position = accessor_data(
            json, (int)cJSON_GetNumberValue(cJSON_GetObjectItem(
                      cJSON_GetObjectItem(primitive, "attributes"), "POSITION")),
            bin, &vertices);
        const uint8_t *index = accessor_data(
            json, (int)cJSON_GetNumberValue(cJSON_GetObjectItem(primitive, "indices")), bin,
            &indices);
        CHECK(triangles == indices / 3);
        double *covered = calloc(mesh->patch_count, sizeof(*covered));
        uint32_t bad_patch = 0, wrong_way = 0, off_plane = 0;
        for (uint32_t t = 0; t < triangles && t < indices / 3; t++) {
            if (patch_of[t] >= mesh->patch_count) {
                bad_patch++;
                continue;
            }
            const rad_patch *patch = &mesh->patches[patch_of[t]];
            rad_vec3 p[3];
            for (int k = 0; k < 3; k++) {
                const uint8_t *v = position + 12 * (size_t)get_u32(index + 4 * (3 * (size_t)t + k));
                p[k] = (rad_vec3){get_f32(v), get_f32(v + 4), get_f32(v + 8)};
            }
            rad_vec3 n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
            double twice = sqrt(dot(n, n));
            covered[patch_of[t]] += twice / 2;
            if (twice > 0 && dot(n, patch->normal) / twice < 0.999)
                wrong_way++;
            rad_vec3 centre = {(p[0].x + p[1].x + p[2].x) / 3, (p[0].y + p[1].y + p[2].y) / 3,
                               (p[0].z + p[1].z + p[2].z) / 3};
            if (fabs(dot(sub(centre, patch->centroid), patch->normal)) > 1e-3 * sqrt(patch->area))
                off_plane++;
        }
        uint32_t uncovered = 0;
        for (uint32_t i = 0; i < mesh->patch_count; i++)
            if (fabs(covered[i] - mesh->patches[i].area) > 1e-4 * mesh->patches[i].area)
                uncovered++;
        if (bad_patch || wrong_way || off_plane || uncovered)
            fprintf(stderr, "%s: %u bad patch indices, %u triangles facing away, %u off their "
                            "patch's plane, %u patches not covered exactly\n",
                    label, bad_patch, wrong_way, off_plane, uncovered);
        CHECK(bad_patch == 0);
        CHECK(wrong_way == 0);
        CHECK(off_plane == 0);
        CHECK(uncovered == 0);
        free(covered);
    }
    cJSON_Delete(json);
    free(bytes);
    free(patch_of);
    free(B);
    rad_mesh_destroy(mesh);
    return triangles;
}

int main(void)
{
    test_tmpdir();
    rad_error error = {0};
    rad_scene *scene = NULL;
    if (rad_scene_cornell_box(&scene, &error) != RAD_OK) {
        fprintf(stderr, "%s\n", error.message);
        return 1;
    }
    uint32_t whole = check_mesh("Cornell box, 200 mm patches", scene, 200, false);
    check_mesh("Cornell box, 40 mm patches", scene, 40, false);
    uint32_t split = check_mesh("Cornell box, 200 mm patches, light at the vertices", scene, 200,
                                true);
    printf("Cornell box, 200 mm patches: %u lit-mesh triangles, %u with the light at the "
           "vertices\n",
           whole, split);
    CHECK(split > whole);
    CHECK(rad_scene_set_surface_flags(scene, "short_block", RAD_SURFACE_TWO_SIDED, &error) ==
          RAD_OK);
    check_mesh("Cornell box, two-sided short block", scene, 60, false);
    check_mesh("Cornell box, two-sided short block, light at the vertices", scene, 60, true);
    rad_scene_destroy(scene);
    return test_finish("test_lit_mesh_triangle_patches");
}
