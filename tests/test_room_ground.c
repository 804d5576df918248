/*
 * test_room_ground.c - the default render of a furnished room standing on a ground
 * plane twenty times its size, lit through a window by an emitter outside, against the
 * path tracer (an independent estimator of the same scene, run here).
 *
 * One patch size for the whole scene, derived from its extent, gives the room patches as
 * large as its walls; the proximity refinement (src/mesh/proximity_refine.c) gives the
 * room cells of its own size, and the solver chosen by default must carry the light
 * through the window. The measure: each surface's mean radiance over the pixels that see
 * it (pixels whose neighbours all see the same surface), in the default render and in the
 * path-traced image. The issue asks for 5 %; what the default render meets today is held
 * here (see the measured figures below).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/camera.h"
#include "testlib.h"

#define SIZE 96
#define CAMERA "--eye 4.7,1.8,0.8 --target 1.0,0.9,3.6 --fov 80 --size 96x96"

/* ---- the scene, as OBJ text ---------------------------------------------------------- */

/* Metres, y up. The room's inside is x 0..5, y 0.2..2.8, z 0..4, walls 0.2 m thick, a
 * window 2 m x 1.3 m in the z = 4 wall; the ground is 100 m x 100 m at y = 0; the emitter
 * (3 m x 2 m, radiance 40) stands 3.8 m outside the window, facing it. */
static void write_scene(void)
{
    test_obj t = {0};
    test_obj_add(&t, "mtllib room.mtl\n");
    test_obj_object(&t, "ground", "ground");
    test_obj_rectangle(&t, 1, 0, -47.5, -48, 52.5, 52, 1);
    test_obj_object(&t, "floor", "wood");
    test_obj_rectangle(&t, 1, 0.2, 0, 0, 4, 5, 1);
    test_obj_object(&t, "ceiling", "white");
    test_obj_rectangle(&t, 1, 2.8, 0, 0, 4, 5, -1);
    test_obj_object(&t, "wall_left", "plaster");
    test_obj_rectangle(&t, 0, 0, 0.2, 0, 2.8, 4, 1);
    test_obj_object(&t, "wall_right", "plaster");
    test_obj_rectangle(&t, 0, 5, 0.2, 0, 2.8, 4, -1);
    test_obj_object(&t, "wall_back", "plaster");
    test_obj_rectangle(&t, 2, 0, 0, 0.2, 5, 2.8, 1);
    test_obj_object(&t, "wall_window", "plaster");
    test_obj_rectangle_with_hole(&t, 2, 4, 0, 0.2, 5, 2.8, 1.5, 0.9, 3.5, 2.2, -1);
    test_obj_object(&t, "reveal", "plaster");
    test_obj_rectangle(&t, 0, 1.5, 0.9, 4, 2.2, 4.2, 1);
    test_obj_rectangle(&t, 0, 3.5, 0.9, 4, 2.2, 4.2, -1);
    test_obj_rectangle(&t, 1, 0.9, 4, 1.5, 4.2, 3.5, 1);
    test_obj_rectangle(&t, 1, 2.2, 4, 1.5, 4.2, 3.5, -1);
    test_obj_object(&t, "facade", "facade");
    test_obj_rectangle(&t, 0, -0.2, 0, -0.2, 3, 4.2, -1);
    test_obj_rectangle(&t, 0, 5.2, 0, -0.2, 3, 4.2, 1);
    test_obj_rectangle(&t, 2, -0.2, -0.2, 0, 5.2, 3, -1);
    test_obj_rectangle_with_hole(&t, 2, 4.2, -0.2, 0, 5.2, 3, 1.5, 0.9, 3.5, 2.2, 1);
    test_obj_rectangle(&t, 1, 3, -0.2, -0.2, 4.2, 5.2, 1);
    test_obj_object(&t, "table", "oak");
    test_obj_box(&t, 1.0, 0.2, 1.0, 2.6, 0.95, 1.9, false);
    test_obj_object(&t, "cupboard", "blue");
    test_obj_box(&t, 3.8, 0.2, 0.0, 5.0, 2.1, 0.6, true);
    test_obj_object(&t, "light", "light");
    test_obj_rectangle(&t, 2, 8, 1, 0.6, 4, 2.6, -1);
    test_write_file("room.obj", t.data);
    free(t.data);
    test_write_file("room.mtl", "newmtl ground\nKd 0.3 0.3 0.3\n"
                                "newmtl wood\nKd 0.5 0.35 0.22\n"
                                "newmtl white\nKd 0.8 0.8 0.8\n"
                                "newmtl plaster\nKd 0.7 0.68 0.62\n"
                                "newmtl facade\nKd 0.5 0.5 0.5\n"
                                "newmtl oak\nKd 0.6 0.42 0.26\n"
                                "newmtl blue\nKd 0.2 0.3 0.6\n"
                                "newmtl light\nKd 0 0 0\nKe 40 40 40\n");
}

/* ---- which surface each pixel sees -------------------------------------------------- */

static double luminance(const rad_image *image, uint32_t x, uint32_t y)
{
    const float *p = &image->rgb[3 * ((size_t)y * image->width + x)];
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

/* Per pixel, the surface its centre's camera ray meets (UINT32_MAX: none). */
static void surfaces_seen(const rad_scene *scene, uint32_t *surface)
{
    rad_tracer *tracer = NULL;
    rad_error error;
    CHECK(rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &tracer, &error) == RAD_OK);
    rad_camera camera = {{4.7, 1.8, 0.8}, {1.0, 0.9, 3.6}, {0, 1, 0}, 80};
    camera_frame frame;
    CHECK(camera_frame_make(&camera, SIZE, SIZE, &frame, &error) == RAD_OK);
    for (uint32_t y = 0; y < SIZE; y++)
        for (uint32_t x = 0; x < SIZE; x++) {
            rad_vec3 d = camera_direction(&frame, x + 0.5, y + 0.5, SIZE, SIZE);
            rad_ray ray = {{(float)frame.eye.x, (float)frame.eye.y, (float)frame.eye.z},
                           0,
                           {(float)d.x, (float)d.y, (float)d.z},
                           INFINITY};
            rad_hit hit;
            rad_tracer_intersect(tracer, &ray, 1, &hit);
            surface[y * SIZE + x] = hit.triangle == RAD_NO_HIT || !hit.front
                                        ? UINT32_MAX
                                        : scene->triangles[hit.triangle].surface;
        }
    rad_tracer_destroy(tracer);
}

/* Each surface's mean luminance over the pixels that see it and only it, in `image`;
 * pixels[s] = 0 for a surface seen by no such pixel. */
static void surface_means(const rad_scene *scene, const uint32_t *surface,
                          const rad_image *image, double *mean, uint32_t *pixels)
{
    for (uint32_t s = 0; s < scene->surface_count; s++)
        mean[s] = pixels[s] = 0;
    for (uint32_t y = 1; y + 1 < SIZE; y++)
        for (uint32_t x = 1; x + 1 < SIZE; x++) {
            uint32_t s = surface[y * SIZE + x];
            if (s == UINT32_MAX || surface[y * SIZE + x - 1] != s ||
                surface[y * SIZE + x + 1] != s || surface[(y - 1) * SIZE + x] != s ||
                surface[(y + 1) * SIZE + x] != s)
                continue; /* an edge pixel mixes surfaces */
            mean[s] += luminance(image, x, y);
            pixels[s]++;
        }
    for (uint32_t s = 0; s < scene->surface_count; s++)
        if (pixels[s])
            mean[s] /= pixels[s];
}

/* Renders with `options` and holds each surface seen by 100 pixels or more (but the
 * light) to the reference within `tolerance`, and `skip` (if not NULL) within
 * skip_tolerance instead (0: not held); returns the largest relative difference of the
 * surfaces held to `tolerance`. */
static double check_render(const char *scene_path, const rad_scene *scene,
                           const uint32_t *surface, const double *reference, const char *options,
                           const char *skip, double skip_tolerance, double tolerance)
{
    char command[1024];
    snprintf(command, sizeof(command), "render %s -o %s %s %s", scene_path,
             test_path("render.pfm"), CAMERA, options);
    CHECK(test_run_tool(command) == 0);
    printf("render %s: %s", options, test_read_text(test_path("stderr.txt")));
    rad_image *image = NULL;
    rad_error error;
    CHECK(rad_image_read(test_path("render.pfm"), &image, &error) == RAD_OK);
    if (!image)
        return INFINITY;
    double *mean = calloc(scene->surface_count, sizeof(double));
    uint32_t *pixels = calloc(scene->surface_count, sizeof(uint32_t));
    surface_means(scene, surface, image, mean, pixels);
    double worst = 0;
    uint32_t compared = 0;
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        const char *name = scene->surfaces[s].name;
        if (pixels[s] < 100 || strcmp(name, "light") == 0)
            continue;
        double difference = (mean[s] - reference[s]) / reference[s];
        bool skipped = skip && strcmp(name, skip) == 0;
        printf("  %-12s %5u pixels: %.4f, path tracer %.4f (%+.1f %%)%s\n", name, pixels[s],
               mean[s], reference[s], 100 * difference,
               skipped ? skip_tolerance > 0 ? " (held apart)" : " (not held)" : "");
        if (skipped) {
            if (skip_tolerance > 0)
                CHECK_NEAR(mean[s], reference[s], skip_tolerance);
            continue;
        }
        CHECK_NEAR(mean[s], reference[s], tolerance);
        worst = fmax(worst, fabs(difference));
        compared++;
    }
    CHECK(compared >= 5);
    free(mean);
    free(pixels);
    rad_image_destroy(image);
    return worst;
}

static void test_room_on_ground(void)
{
    write_scene();
    char scene_path[512];
    snprintf(scene_path, sizeof(scene_path), "%s", test_path("room.obj"));
    char command[1024];
    snprintf(command, sizeof(command), "pathtrace %s -o %s %s --spp 512", scene_path,
             test_path("reference.pfm"), CAMERA);
    CHECK(test_run_tool(command) == 0);

    rad_error error;
    rad_scene *scene = NULL;
    rad_image *reference = NULL;
    CHECK(rad_scene_load(scene_path, NULL, &scene, &error) == RAD_OK);
    CHECK(rad_image_read(test_path("reference.pfm"), &reference, &error) == RAD_OK);
    if (!scene || !reference) {
        rad_image_destroy(reference);
        rad_scene_destroy(scene);
        return;
    }
    uint32_t *surface = malloc(SIZE * SIZE * sizeof(*surface));
    double *reference_mean = calloc(scene->surface_count, sizeof(double));
    uint32_t *pixels = calloc(scene->surface_count, sizeof(uint32_t));
    surfaces_seen(scene, surface);
    surface_means(scene, surface, reference, reference_mean, pixels);
    /* measured 2026-12-02, with the emitter's penumbrae refined in the mesh
     * (shadow_refine.c), which makes 4538 patches, so the automatic choice is the
     * hierarchical solver, and the emitters' direct light and a final gather computed at
     * every vertex (vertex_light.c): the room's surfaces -5.1 % (wall_left) to -3.6 %
     * (floor) (-5.4 % on the floor before buried vertices took their open neighbours'
     * light, vertex_light.c); with the
     * patch values interpolated instead -10.8 % to -5.6 %; before the refinement (3920
     * patches, gather) -14 % to -4 %; without the proximity refinement either
     * (--proximity-levels 0: the automatic size of the whole scene) -29 % to -12 %. The
     * ground seen through the window (+10.4 %; +54 % with the patch values, +280 % before
     * the refinement) is held with the per-pixel direct light below. Later the same day,
     * with the light shown on the mesh split where the shadows bend it (light_refine.c):
     * -5.4 % (wall_left) to -4.0 % at the hierarchical solver's default threshold (0.25),
     * and with the automatic choice refining its links to 0.05 on a mesh this small
     * (RAD_AUTO_REFINE_THRESHOLD): -4.1 % (wall_left) to -2.8 % (floor), the 5 %
     * met; the ground +4.5 % */
    double worst = check_render(scene_path, scene, surface, reference_mean, "", "ground", 0,
                                0.05);
    printf("default render: largest difference %.1f %% (the issue asks for 5 %%)\n",
           100 * worst);
    /* the emitters' direct light at every pixel: measured -7.2 % (table) to -5.2 % in the
     * room; the ground -16.8 % (its light from the surfaces next to it is gathered at the
     * pixel along the facade, and moves with the mesh there: -0.8 % to -17 % measured on
     * nearby meshes); later the same day, the rest from the vertices' gather on the finer
     * mesh and the links at 0.05: -3.7 % in the room */
    worst = check_render(scene_path, scene, surface, reference_mean, "--direct pixel", "ground",
                         0.25, 0.10);
    printf("--direct pixel: largest difference %.1f %%\n", 100 * worst);
    /* every solver honours the refinements and the vertex light: Gauss-Seidel and shooting
     * on the default's mesh (measured -3.3 % (ceiling) to -1.4 %; with the light's finer
     * mesh -2.8 % to -2.2 %), the hierarchical solver on its own finer default patches
     * with the proximity refinement asked for (it is off by default there): measured
     * -3.3 % (floor) to -2.3 % (then -2.8 % to -1.9 %) */
    static const char *const solvers[] = {"--solver gauss-seidel", "--solver shoot",
                                          "--solver hierarchical --proximity-levels 3"};
    static const double tolerances[] = {0.045, 0.045, 0.045};
    for (size_t k = 0; k < sizeof(solvers) / sizeof(solvers[0]); k++) {
        worst = check_render(scene_path, scene, surface, reference_mean, solvers[k], "ground",
                             0, tolerances[k]);
        printf("%s: largest difference %.1f %%\n", solvers[k], 100 * worst);
    }
    free(surface);
    free(reference_mean);
    free(pixels);
    rad_image_destroy(reference);
    rad_scene_destroy(scene);
}

int main(void)
{
    test_room_on_ground();
    return test_finish("test_room_ground");
}
