/*
 * test_non_finite_outputs.c - a NaN or infinite value is never written as a result: the
 * image writers (every format) and the lit-mesh writers (every format) refuse it with a
 * message naming the file and the pixel or patch, and leave no file behind.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static void check_image(const char *name, float bad)
{
    rad_image *image = test_new_image(4, 3);
    for (size_t k = 0; k < 4 * 3 * 3; k++)
        image->rgb[k] = 0.5f;
    image->rgb[(2 * 4 + 1) * 3 + 1] = bad; /* pixel (1, 2), green */
    const char *path = test_path(name);
    remove(path);
    rad_error error = {0};
    rad_status status = rad_image_write(image, path, NULL, &error);
    printf("%s: %s\n", name, error.message);
    CHECK(status != RAD_OK);
    CHECK(strstr(error.message, path) != NULL);
    CHECK(strstr(error.message, "(1, 2)") != NULL);
    CHECK(!test_file_exists(path));
    /* and a finite image is written */
    image->rgb[(2 * 4 + 1) * 3 + 1] = 0.25f;
    CHECK(rad_image_write(image, path, NULL, &error) == RAD_OK);
    CHECK(test_file_exists(path));
    rad_image_destroy(image);
}

static void check_lit_mesh(const char *name, double bad)
{
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_error error = {0};
    CHECK(rad_scene_cornell_box(&scene, &error) == RAD_OK);
    CHECK(rad_mesh_build(scene, 200, &mesh, &error) == RAD_OK);
    rad_rgb *B = calloc(mesh->patch_count, sizeof(rad_rgb));
    B[mesh->patch_count / 2].g = bad;
    const char *path = test_path(name);
    remove(path);
    rad_status status = rad_lit_mesh_write(mesh, B, path, NULL, &error);
    printf("%s: %s\n", name, error.message);
    CHECK(status != RAD_OK);
    CHECK(strstr(error.message, path) != NULL);
    CHECK(!test_file_exists(path));
    B[mesh->patch_count / 2].g = 1;
    CHECK(rad_lit_mesh_write(mesh, B, path, NULL, &error) == RAD_OK);
    CHECK(test_file_exists(path));
    free(B);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

int main(void)
{
    const char *images[] = {"nan.png", "nan.hdr", "nan.pfm", "nan.exr"};
    for (int k = 0; k < 4; k++) {
        check_image(images[k], NAN);
        check_image(images[k], INFINITY);
    }
    const char *meshes[] = {"nan.ply", "nan.glb", "nan.obj"};
    for (int k = 0; k < 3; k++) {
        check_lit_mesh(meshes[k], NAN);
        check_lit_mesh(meshes[k], -INFINITY);
    }
    return test_finish("test_non_finite_outputs");
}
