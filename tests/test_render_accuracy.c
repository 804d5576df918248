/*
 * test_render_accuracy.c - the radiosity render of the built-in Cornell box against a
 * converged path-traced reference (tests/data, made by the project's path tracer: an
 * independent estimator of the same scene), with the image issue's measures: block
 * relative RMSE of 8 x 8 luminance blocks and pixel relative RMSE without the light. Three
 * renders: the classic one (--direct solution: the emitters' direct light interpolated from
 * the patches), the default (--direct vertex: the emitters' direct light and a final
 * gather of the solution computed at every mesh vertex, then interpolated, except the
 * emitters' light in penumbrae, which their pixels compute) and
 * the one with the emitters' direct light at every pixel (--direct pixel: shadow rays;
 * the light reflected more than once from the vertices' gather); both light-at-the-vertex
 * renders show it on the mesh split where the emitters' shadows bend the light
 * (light_refine.h); each is held to what it measures today, and the default must beat the
 * classic one. A furnace checks that the direct light at pixels and at vertices stays
 * unbiased where every wall is an emitter.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

#ifndef RAD_TEST_DATA
#define RAD_TEST_DATA "tests/data"
#endif

static rad_image *render_cornell(rad_direct_light direct_light, rad_solver solver)
{
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_error error;
    CHECK(rad_scene_cornell_box(&scene, &error) == RAD_OK);
    double size = rad_default_patch_size(scene, solver);
    CHECK(rad_mesh_build(scene, size, &mesh, &error) == RAD_OK);
    rad_rgb *B = calloc(mesh->patch_count, sizeof(*B));
    rad_scene_solve_options solve = {.threads = 2, .solver = solver};
    CHECK(rad_solve_scene(scene, mesh, &solve, B, NULL, &error) == RAD_OK);
    rad_image *image = test_new_image(128, 128);
    rad_render_options render = {.scene = scene, .threads = 2, .direct_light = direct_light};
    CHECK(rad_render(mesh, B, &scene->camera, &render, image, &error) == RAD_OK);
    free(B);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return image;
}

static double luminance_at(const rad_image *image, uint32_t x, uint32_t y)
{
    const float *p = &image->rgb[((size_t)y * image->width + x) * 3];
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

/* The ceiling around the light, which the pixel measure leaves out (the light and 2 pixels
 * around it): the pixels within 3 of a light pixel (the reference's luminance above 5)
 * that the light does not cover (below 0.2, so no rim pixel); their relative error's mean
 * and RMS against the reference. */
static void ceiling_ring(const rad_image *image, const rad_image *reference, double *mean,
                         double *rms)
{
    const int W = (int)reference->width, H = (int)reference->height, R = 3;
    double sum = 0, squares = 0;
    int count = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double ref = luminance_at(reference, (uint32_t)x, (uint32_t)y);
            bool near_light = false;
            for (int dy = -R; dy <= R && !near_light; dy++)
                for (int dx = -R; dx <= R && !near_light; dx++)
                    near_light = y + dy >= 0 && y + dy < H && x + dx >= 0 && x + dx < W &&
                                 luminance_at(reference, (uint32_t)(x + dx),
                                              (uint32_t)(y + dy)) > 5;
            if (!near_light || !(ref < 0.2) || !(ref > 0))
                continue;
            double d = (luminance_at(image, (uint32_t)x, (uint32_t)y) - ref) / ref;
            sum += d;
            squares += d * d;
            count++;
        }
    CHECK(count > 100);
    *mean = count ? sum / count : 0;
    *rms = count ? sqrt(squares / count) : 0;
}

/* The foot of the tall block's front face (image columns 41-60 at 128 x 128): in each
 * column the face's last two pixels above the floor (the lowest of rows 101-115 where the
 * reference's luminance is below 0.07: the face is 0.05-0.066 there, the floor from 0.075
 * up); their relative error's mean and RMS. The face sees mostly the floor at the block's
 * foot, which the solution's patches smear with the part under the block: gathered from
 * them alone it came out 9 % dark (RMS 10.7 %). */
static void block_foot(const rad_image *image, const rad_image *reference, double *mean,
                       double *rms)
{
    double sum = 0, squares = 0;
    int count = 0;
    for (uint32_t x = 41; x <= 60; x++) {
        uint32_t y = 115;
        while (y > 100 && !(luminance_at(reference, x, y) < 0.07))
            y--;
        CHECK(y > 100);
        for (uint32_t row = y - 1; row <= y; row++) {
            double ref = luminance_at(reference, x, row);
            double d = (luminance_at(image, x, row) - ref) / ref;
            sum += d;
            squares += d * d;
            count++;
        }
    }
    *mean = sum / count;
    *rms = sqrt(squares / count);
}

/* The red (left) wall in the tall block's penumbra, pixels x 18-24, y 74-90 (119 pixels):
 * the mean of their relative error against the reference. The wall is a folded quad
 * (3.2 mm); when every cell's shadow rays left from a quarter of that in front of it, the
 * penumbra there came out 2.6 % dark (5-7 % in its direct light, against the path tracer
 * and a sum over the light at the pixels' points). */
static double red_wall_penumbra(const rad_image *image, const rad_image *reference)
{
    double sum = 0;
    uint32_t count = 0;
    for (uint32_t y = 74; y <= 90; y++)
        for (uint32_t x = 18; x <= 24; x++, count++)
            sum += luminance_at(image, x, y) / luminance_at(reference, x, y) - 1;
    return sum / count;
}

/* The tall block's face at the height of the short block's top, pixels x 50-63, y 80-83
 * (4 rows of 14): the mean relative error against the reference of the row where it is
 * largest. The short block's top lights the face above its plane and none of it below, so
 * the face's light has a kink there (reflector_planes.h); interpolated across patches 26
 * units tall it came out too bright (rows 80-83: +1.0, +3.4, +3.3, +1.1 %); on the mesh
 * split where the plane crosses, -0.6 to +0.5 % a row. */
static double short_block_plane(const rad_image *image, const rad_image *reference)
{
    double worst = 0;
    for (uint32_t y = 80; y <= 83; y++) {
        double sum = 0;
        for (uint32_t x = 50; x <= 63; x++)
            sum += luminance_at(image, x, y) / luminance_at(reference, x, y) - 1;
        if (fabs(sum / 14) > fabs(worst))
            worst = sum / 14;
    }
    return worst;
}

/* The light's rim: the pixels the light covers in part (the reference's luminance between
 * 0.3 and 10; the light's own is 12.6, the ceiling around it below 0.2): the RMS of their
 * relative error against the reference. */
static double light_rim(const rad_image *image, const rad_image *reference, uint32_t *count)
{
    double sum = 0;
    *count = 0;
    for (uint32_t y = 0; y < reference->height; y++)
        for (uint32_t x = 0; x < reference->width; x++) {
            double ref = luminance_at(reference, x, y);
            if (ref < 0.3 || ref > 10)
                continue;
            double d = luminance_at(image, x, y) / ref - 1;
            sum += d * d;
            ++*count;
        }
    return *count ? sqrt(sum / *count) : 0;
}

static void test_cornell(void)
{
    rad_image *reference = NULL;
    rad_error error;
    if (rad_image_read(RAD_TEST_DATA "/cornell-128-pathtrace.pfm", &reference, &error) != RAD_OK) {
        test_fail(__FILE__, __LINE__, "%s", error.message);
        return;
    }
    rad_image_difference classic, vertex, per_pixel;
    rad_image *a = render_cornell(RAD_DIRECT_SOLUTION, RAD_SOLVER_AUTO),
              *v = render_cornell(RAD_DIRECT_VERTEX, RAD_SOLVER_AUTO),
              *b = render_cornell(RAD_DIRECT_PIXEL, RAD_SOLVER_AUTO);
    CHECK(rad_image_compare(a, reference, NULL, &classic, NULL, &error) == RAD_OK);
    CHECK(rad_image_compare(v, reference, NULL, &vertex, NULL, &error) == RAD_OK);
    CHECK(rad_image_compare(b, reference, NULL, &per_pixel, NULL, &error) == RAD_OK);
    printf("Cornell box 128 x 128 against the path tracer (65536 spp):\n"
           "  classic render:          block rel RMSE %.4f, pixel rel RMSE %.4f\n"
           "  direct light at vertices (default): block rel RMSE %.4f, pixel rel RMSE %.4f\n"
           "  direct light per pixel:  block rel RMSE %.4f, pixel rel RMSE %.4f\n",
           classic.block_relative_rmse, classic.pixel_relative_rmse,
           vertex.block_relative_rmse, vertex.pixel_relative_rmse,
           per_pixel.block_relative_rmse, per_pixel.pixel_relative_rmse);
    /* measured 2026-12-02 (seed 0, 2 threads) against the 65536-spp reference (its own
     * noise 0.07 % on blocks and 0.34 % a pixel, tests/data/README.md): classic 0.0252 /
     * 0.0271, at the vertices 0.0098 / 0.0134 (0.0102 / 0.0157 before buried vertices took
     * their open neighbours' light, vertex_light.c), per pixel 0.0081 / 0.0157. Against the
     * earlier 16384-spp reference the same renders read 0.0255 / 0.0278, 0.0104 / 0.0168 and
     * 0.0084 / 0.0167: the pixel measure is the renders' own error, not the reference's
     * noise; 60 % of its square came from 1 % of the pixels, on the floor along the
     * blocks' feet, most of it the floor patches running under the blocks. The issue asks
     * for 0.01 / 0.01 at 128 x 128. Later the same day: the emitters' unshadowed light
     * summed exactly (contour integrals, the shadow rays giving the share that gets
     * through) read 0.0097 / 0.0132 at the vertices and 0.0078 / 0.0122 per pixel (the
     * rest from the vertices' gather instead of patch means); then the light shown on the
     * mesh split where the shadows bend it (light_refine.h: 3742 -> 7198 patches, for
     * display) 0.0080 / 0.0114 at the vertices and 0.0078 / 0.0131 per pixel: the default
     * meets the blocks' 1 %, not the pixels'. From seed to seed the renders' blocks move by
     * a few tenths of a percent (the gather's noise at the vertices, the light's rim).
     * 2026-12-03, the lamp's back counting for buried vertices and the rim found by the
     * surfaces met: the same 0.0080 / 0.0114 (0.0141 / 0.0114 with the first alone).
     * The light's finer mesh split at creases too: 0.0074 / 0.0111. 2026-12-03, the
     * vertices' gather corrected by a second one that meets the light just computed at the
     * vertices instead of the patches' means (vertex_radiance.h): 0.0061 / 0.0088 at the
     * vertices, 0.0061 / 0.0111 per pixel: the 1 % / 1 % at 128 x 128; then 1600
     * gather rays a vertex instead of 1024 (vertex_light.h): 0.0057 / 0.0083 and
     * 0.0057 / 0.0107. The emitters' light in penumbrae computed at their pixels
     * (radiosity_render.c) and the light's finer mesh's vertices taking their gathered
     * light from their patch's corners (light_refine.h): 0.0057 / 0.0080 at the vertices,
     * 0.0057 / 0.0108 per pixel. 2026-12-04: the open light's exact value at each hit
     * instead of interpolated (radiosity_render.c) and the folded left wall's shadow rays
     * leaving from each cell's own distance behind its triangles (mesh.c): 0.0047 /
     * 0.0066 at the vertices, 0.0049 / 0.0107 per pixel (the CLI's render: 0.565 / 0.851 %
     * before, 0.547 / 0.718 % with the first alone, 0.467 / 0.702 % with both). Then
     * 1024 more samples on the light's rim: 0.0041 / 0.0066 and 0.0043 / 0.0107.
     * 2026-12-04, the mesh also split where a bright region's plane crosses a patch
     * (reflector_planes.h): 0.0042 / 0.0067 -> 0.0040 / 0.0065 at the vertices, 0.0043 /
     * 0.0107 -> 0.0043 / 0.0106 per pixel, the tall block's face at the short block's top
     * +2.2 % -> +0.0 % (its worst row +3.4 % -> -0.6 %). */
    CHECK(classic.block_relative_rmse < 0.030 && classic.pixel_relative_rmse < 0.033);
    CHECK(vertex.block_relative_rmse < 0.0050 && vertex.pixel_relative_rmse < 0.0075);
    CHECK(per_pixel.block_relative_rmse < 0.0055 && per_pixel.pixel_relative_rmse < 0.0125);
    double penumbra_default = red_wall_penumbra(v, reference),
           penumbra_pixel = red_wall_penumbra(b, reference);
    printf("  the red wall in the tall block's penumbra: mean %+.2f %% at the vertices, "
           "%+.2f %% per pixel\n",
           100 * penumbra_default, 100 * penumbra_pixel);
    CHECK(fabs(penumbra_default) < 0.01 && fabs(penumbra_pixel) < 0.01);
    double plane_default = short_block_plane(v, reference),
           plane_pixel = short_block_plane(b, reference);
    printf("  the tall block's face at the short block's top, its worst row: %+.2f %% at the "
           "vertices, "
           "%+.2f %% per pixel\n",
           100 * plane_default, 100 * plane_pixel);
    CHECK(fabs(plane_default) < 0.01 && fabs(plane_pixel) < 0.01);
    /* the light's rim: 272 samples a pixel (16 first, 256 on an edge) left it at RMS
     * 6.0 % (both renders); with 1024 more on an emitter's rim 1.8 % */
    uint32_t rim_default_pixels, rim_pixel_pixels;
    double rim_default = light_rim(v, reference, &rim_default_pixels),
           rim_pixel = light_rim(b, reference, &rim_pixel_pixels);
    printf("  the light's rim (%u pixels): RMS %.2f %% at the vertices, %.2f %% per pixel\n",
           rim_default_pixels, 100 * rim_default, 100 * rim_pixel);
    CHECK(rim_default_pixels >= 40);
    CHECK(rim_default < 0.04 && rim_pixel < 0.04);
    CHECK(vertex.block_relative_rmse < 0.6 * classic.block_relative_rmse);
    /* the ceiling around the light: a vertex in the gap above the lamp's back, left dark,
     * darkened it by interpolation (a ring down to -51 % at 256 x 256); now such a vertex
     * takes its open neighbours' light, as one under a block does (vertex_light.c).
     * Measured (142 pixels): mean -1.5 %, RMS 4.0 % (the CLI's mesh, seeds 1 and 2, was
     * -2.7 % / 5.1 % before, -1.5 % / 3.9 % after) */
    double ring_mean, ring_rms;
    ceiling_ring(v, reference, &ring_mean, &ring_rms);
    printf("  the ceiling within 3 pixels of the light, at the vertices: mean %+.2f %%, RMS "
           "%.2f %%\n",
           100 * ring_mean, 100 * ring_rms);
    CHECK(fabs(ring_mean) < 0.02 && ring_rms < 0.045);
    /* the tall block's foot: -2.4 % / 2.7 % measured with the second gather (the CLI's
     * mesh, seed 1), -9.1 % / 10.7 % without */
    double foot_mean, foot_rms;
    block_foot(v, reference, &foot_mean, &foot_rms);
    printf("  the tall block's face at its foot, at the vertices: mean %+.2f %%, RMS %.2f %%\n",
           100 * foot_mean, 100 * foot_rms);
    CHECK(fabs(foot_mean) < 0.04 && foot_rms < 0.05);
    CHECK(vertex.pixel_relative_rmse < 0.7 * classic.pixel_relative_rmse);
    CHECK_NEAR(vertex.mean_a.g, vertex.mean_b.g, 0.01);
    /* the mean radiance agrees within the reference's noise and the mesh's bias */
    CHECK_NEAR(per_pixel.mean_a.g, per_pixel.mean_b.g, 0.01);
    /* the per-pixel direct light over every solver's solution: the same accuracy */
    /* (the direct LU solve of 3742 patches is left out for time: it matches the others to
     * 0.000 % in test_lights_matrix and test_feature_matrix) */
    const rad_solver others[] = {RAD_SOLVER_GAUSS_SEIDEL, RAD_SOLVER_SHOOT,
                                 RAD_SOLVER_HIERARCHICAL};
    for (size_t k = 0; k < sizeof(others) / sizeof(others[0]); k++) {
        rad_image *c = render_cornell(RAD_DIRECT_PIXEL, others[k]);
        rad_image_difference d;
        CHECK(rad_image_compare(c, reference, NULL, &d, NULL, &error) == RAD_OK);
        printf("  direct light per pixel, %-12s block rel RMSE %.4f, pixel rel RMSE %.4f\n",
               rad_solver_name(others[k]), d.block_relative_rmse, d.pixel_relative_rmse);
        CHECK(d.block_relative_rmse < 0.014 && d.pixel_relative_rmse < 0.018);
        rad_image_destroy(c);
    }
    rad_image_destroy(a);
    rad_image_destroy(v);
    rad_image_destroy(b);
    rad_image_destroy(reference);
}

/* Every wall emits Ke = 1 and reflects 0.5: L = 2 everywhere, also with the emitters'
 * direct light at every pixel, where each point sits next to emitters (the 1 / r^2 of
 * light sampling alone put pixels 34 % low and 101 % high; MIS keeps them close). */
static void test_furnace(void)
{
    test_write_furnace("furnace.obj");
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_error error;
    CHECK(rad_scene_load(test_path("furnace.obj"), NULL, &scene, &error) == RAD_OK);
    CHECK(rad_mesh_build(scene, 0.05, &mesh, &error) == RAD_OK);
    rad_rgb *B = calloc(mesh->patch_count, sizeof(*B));
    rad_scene_solve_options solve = {.threads = 2, .solver = RAD_SOLVER_JACOBI, .tolerance = 1e-7};
    CHECK(rad_solve_scene(scene, mesh, &solve, B, NULL, &error) == RAD_OK);
    rad_camera camera = {{0.5, 0.5, 0.9}, {0.5, 0.5, 0}, {0, 1, 0}, 100};
    const rad_direct_light modes[] = {RAD_DIRECT_PIXEL, RAD_DIRECT_VERTEX};
    const char *const names[] = {"per pixel", "at the vertices"};
    for (int m = 0; m < 2; m++) {
        rad_image *image = test_new_image(48, 48);
        rad_render_options render = {.scene = scene, .threads = 2, .direct_light = modes[m]};
        CHECK(rad_render(mesh, B, &camera, &render, image, &error) == RAD_OK);
        double lo = INFINITY, hi = 0, sum = 0;
        for (uint32_t y = 0; y < 48; y++)
            for (uint32_t x = 0; x < 48; x++) {
                double g = test_pixel(image, x, y)[1];
                lo = fmin(lo, g);
                hi = fmax(hi, g);
                sum += g;
            }
        printf("furnace, direct light %s: pixels %.4f .. %.4f, mean %.5f (2)\n", names[m], lo,
               hi, sum / (48 * 48));
        CHECK_NEAR(sum / (48 * 48), 2, 0.005);
        CHECK(lo > 2 * 0.95 && hi < 2 * 1.05);
        rad_image_destroy(image);
    }
    free(B);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

int main(void)
{
    test_cornell();
    test_furnace();
    return test_finish("test_render_accuracy");
}
