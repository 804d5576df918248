/*
 * test_default_patch_size.c - the patch size the automatic solver choice meshes with
 * (rad_default_patch_size, src/solve/solve_scene.c). A scene whose mesh at the dense
 * solvers' size fits them (the Cornell box: about 3000 patches) keeps that size. A scene
 * whose own polygons already outnumber the dense solvers' limit at any size (a sphere of
 * 6000 quads: one patch per polygon is the coarsest mesh) gets the hierarchical solver's
 * size, which the automatic choice then solves with: the dense size would leave the mesh
 * as coarse as the input (a furnished room: 1.24 % block error against 0.31 %). Not here:
 * the renders' accuracy (test_render_accuracy, bench/race).
 */
#include <math.h>
#include <stdio.h>

#include "testlib.h"

static const double pi = 3.14159265358979323846;

/* A UV sphere of radius 3 facing in, `rings` x `segments` quads (no poles: two caps of
 * triangles close it). */
static const char *write_sphere(int rings, int segments)
{
    static char text[1 << 20];
    size_t n = (size_t)snprintf(text, sizeof(text), "v 0 3 0\nv 0 -3 0\n");
    for (int r = 1; r < rings; r++)
        for (int s = 0; s < segments; s++) {
            double theta = pi * r / rings, phi = 2 * pi * s / segments;
            n += (size_t)snprintf(text + n, sizeof(text) - n, "v %.17g %.17g %.17g\n",
                                  3 * sin(theta) * cos(phi), 3 * cos(theta),
                                  3 * sin(theta) * sin(phi));
        }
#define AT(r, s) (3 + ((r) - 1) * segments + ((s) % segments))
    for (int s = 0; s < segments; s++) {
        n += (size_t)snprintf(text + n, sizeof(text) - n, "f 1 %d %d\n", AT(1, s), AT(1, s + 1));
        n += (size_t)snprintf(text + n, sizeof(text) - n, "f 2 %d %d\n", AT(rings - 1, s + 1),
                              AT(rings - 1, s));
        for (int r = 1; r + 1 < rings; r++)
            n += (size_t)snprintf(text + n, sizeof(text) - n, "f %d %d %d %d\n", AT(r, s),
                                  AT(r + 1, s), AT(r + 1, s + 1), AT(r, s + 1));
    }
#undef AT
    return test_write_file("sphere.obj", text);
}

int main(void)
{
    rad_error error = {0};
    rad_scene *cornell = NULL;
    CHECK(rad_scene_cornell_box(&cornell, &error) == RAD_OK);
    if (cornell) {
        double automatic = rad_default_patch_size(cornell, RAD_SOLVER_AUTO);
        double dense = rad_default_patch_size(cornell, RAD_SOLVER_JACOBI);
        double count = rad_mesh_patch_count_at(cornell, automatic);
        printf("Cornell box: automatic patch size %.4g (dense %.4g), %.0f patches\n", automatic,
               dense, count);
        CHECK(automatic == dense);
        CHECK(count > 0 && count <= RAD_DENSE_MAX_PATCHES);
        rad_scene_destroy(cornell);
    }
    rad_scene *sphere = NULL;
    CHECK(rad_scene_load(write_sphere(60, 100), NULL, &sphere, &error) == RAD_OK);
    if (sphere) {
        double automatic = rad_default_patch_size(sphere, RAD_SOLVER_AUTO);
        double dense = rad_default_patch_size(sphere, RAD_SOLVER_JACOBI);
        double hierarchical = rad_default_patch_size(sphere, RAD_SOLVER_HIERARCHICAL);
        double at_dense = rad_mesh_patch_count_at(sphere, dense);
        double count = rad_mesh_patch_count_at(sphere, automatic);
        printf("sphere of 5900 quads and 200 triangles: automatic patch size %.4g (dense %.4g: "
               "%.0f patches; hierarchical %.4g), %.0f patches\n",
               automatic, dense, at_dense, hierarchical, count);
        CHECK(at_dense > RAD_DENSE_MAX_PATCHES);
        CHECK(automatic == hierarchical && automatic < dense);
        CHECK(count > 0.5 * RAD_HIERARCHICAL_DEFAULT_PATCHES &&
              count < 2.0 * RAD_HIERARCHICAL_DEFAULT_PATCHES);
        rad_scene_destroy(sphere);
    }
    return test_finish("test_default_patch_size");
}
