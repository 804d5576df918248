/*
 * test_reflector_planes.c - where a flat region's reflected light kinks
 * (src/render/reflector_planes.c), against the bound worked out by hand: a lit 1 x 1
 * square (two patches sharing an edge: one region) on the plane y = 0, facing up, and a
 * wall patch 0.2 tall standing across that plane 3 away. The kink's measure is
 * L A s / (4 pi d^3 H) with d the distance between the centres (here above the region's
 * radius); a patch wholly above the plane, one behind the region's back, one whose plane
 * the region's lies in, and a black region give none. Regions are found by shared
 * vertices, brightest first. Not here: the splits it drives and the image it mends
 * (test_render_accuracy: the tall block's face at the short block's top).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/vec3.h"
#include "render/reflector_planes.h"
#include "solve/patch_inputs.h"
#include "testlib.h"

static rad_patch quad(const rad_vec3 *v, uint32_t a, uint32_t b, uint32_t c, uint32_t d)
{
    rad_patch p = {.vertex = {a, b, c, d}, .vertex_count = 4};
    rad_vec3 n = v3_cross(v3_sub(v[c], v[a]), v3_sub(v[d], v[b]));
    p.area = 0.5 * v3_length(n);
    p.normal = v3_normalize(n);
    p.centroid = v3_scale(v3_add(v3_add(v[a], v[b]), v3_add(v[c], v[d])), 0.25);
    return p;
}

int main(void)
{
    /* the square in two halves (x in [0, 0.5] and [0.5, 1], z in [0, 1]), then a dim
     * square apart from it at x in [5, 6] (its own vertices: a region of its own) */
    rad_vec3 v[] = {{0, 0, 0},   {0.5, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0.5, 0, 1},
                    {1, 0, 1},   {5, 0, 0},   {6, 0, 0}, {5, 0, 1}, {6, 0, 1}};
    rad_patch patches[3] = {quad(v, 0, 3, 4, 1), quad(v, 1, 4, 5, 2), quad(v, 6, 8, 9, 7)};
    CHECK(patches[0].normal.y > 0.999 && patches[2].normal.y > 0.999);
    rad_mesh mesh = {.vertices = v, .vertex_count = 10, .patches = patches, .patch_count = 3};
    rad_rgb B[3] = {{2, 2, 2}, {2, 2, 2}, {0.5, 0.5, 0.5}};
    rad_patch_inputs *inputs = patch_inputs_alloc(3);
    CHECK(inputs != NULL);
    if (!inputs)
        return test_finish("test_reflector_planes");
    for (uint32_t p = 0; p < 3; p++)
        inputs->exitance[p] = (rad_rgb){p == 0 ? 1.0 : 0.0, p == 0 ? 1.0 : 0.0,
                                        p == 0 ? 1.0 : 0.0};
    reflector_set set;
    rad_error error;
    CHECK(reflectors_build(&mesh, B, inputs, &set, &error) == RAD_OK);
    CHECK(set.count == 2);
    /* brightest first: the square, A L = 0.5 x 1 + 0.5 x 2 = 1.5; then the dim one, 0.5 */
    CHECK_NEAR(set.items[0].strength, 1.5, 1e-12);
    CHECK_NEAR(set.items[1].strength, 0.5, 1e-12);
    CHECK_NEAR(set.items[0].centre.x, 0.5, 1e-12);
    CHECK_NEAR(set.items[0].radius, sqrt(0.5), 1e-12);

    /* a wall patch at x = -2.5 (facing +x, toward the square), z in [0.4, 0.6], y in
     * [-0.1, 0.1]: the square's plane crosses it; d = |(3, 0, 0.5 - 0.5)| = 3 */
    rad_vec3 w[] = {{-2.5, -0.1, 0.6}, {-2.5, -0.1, 0.4}, {-2.5, 0.1, 0.4}, {-2.5, 0.1, 0.6}};
    rad_patch wall = quad(w, 0, 1, 2, 3);
    CHECK(wall.normal.x > 0.999);
    double H = 0.25, expected = 1.5 * 0.2 / (4 * RAD_PI * 27 * H);
    double kink = reflector_kink(&set, 1, &wall, w, 0.2, H);
    printf("kink across the square's plane 3 away: %.6g (by hand %.6g)\n", kink, expected);
    CHECK_NEAR(kink, expected, 1e-12);
    /* both regions tested: the dim one lies on the same plane, farther: the square's
     * bound is the largest */
    CHECK_NEAR(reflector_kink(&set, 2, &wall, w, 0.2, H), expected, 1e-12);
    /* none tested: none */
    CHECK(reflector_kink(&set, 0, &wall, w, 0.2, H) == 0);

    /* the same patch lifted wholly above the plane: not crossed */
    rad_vec3 above[4];
    for (int k = 0; k < 4; k++)
        above[k] = v3_add(w[k], v3(0, 0.2, 0));
    CHECK(reflector_kink(&set, 2, &wall, above, 0.2, H) == 0);
    /* turned away from the square (facing -x) and beyond its reach: behind it */
    rad_vec3 back[4] = {w[3], w[2], w[1], w[0]};
    rad_patch away = quad(back, 0, 1, 2, 3);
    CHECK(away.normal.x < -0.999);
    CHECK(reflector_kink(&set, 2, &away, back, 0.2, H) == 0);
    /* a patch in the square's own plane: its corners all on it */
    CHECK(reflector_kink(&set, 2, &patches[0], v, 0.5, H) == 0);

    /* a black square reflects nothing: only the dim region is left */
    reflectors_free(&set);
    B[0] = inputs->exitance[0];
    B[1] = (rad_rgb){0, 0, 0};
    CHECK(reflectors_build(&mesh, B, inputs, &set, &error) == RAD_OK);
    CHECK(set.count == 1);
    CHECK_NEAR(set.items[0].centre.x, 5.5, 1e-12);
    reflectors_free(&set);
    rad_patch_inputs_destroy(inputs);
    return test_finish("test_reflector_planes");
}
