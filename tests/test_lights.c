/*
 * test_lights.c - light sources besides emissive surfaces against closed forms: a point
 * light's inverse-square cosine law on a floor (patch inputs and rendered pixels), a
 * spot's cone, the sun on a tilted plane and the shadow of a box, skies on open and closed
 * scenes, and the energy balance of a closed room lit by a point light. Bad light values
 * are refused with a message naming the light, and through the command line.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

#define PI 3.14159265358979323846

/* A square floor of side 2 * half at y = 0 facing +y (centred on the origin), and any
 * extra OBJ lines after it (vertex numbers from 5). */
static rad_scene *floor_scene(double half, const char *extra)
{
    char text[4096];
    snprintf(text, sizeof(text),
             "o floor\n"
             "v %g 0 %g\nv %g 0 %g\nv %g 0 %g\nv %g 0 %g\n"
             "f 1 2 3 4\n%s",
             -half, half, half, half, half, -half, -half, -half, extra ? extra : "");
    const char *path = test_write_file("floor.obj", text);
    rad_scene *scene = NULL;
    rad_error error;
    if (rad_scene_load(path, NULL, &scene, &error) != RAD_OK) {
        test_fail(__FILE__, __LINE__, "load: %s", error.message);
        exit(1);
    }
    return scene;
}

static void add_light(rad_scene *scene, const rad_light *light)
{
    rad_error error;
    if (rad_scene_add_light(scene, light, &error) != RAD_OK) {
        test_fail(__FILE__, __LINE__, "add light: %s", error.message);
        exit(1);
    }
}

static rad_patch_inputs *inputs_of(const rad_scene *scene, double patch_size, rad_mesh **mesh)
{
    rad_error error;
    rad_patch_inputs *inputs = NULL;
    if (rad_mesh_build(scene, patch_size, mesh, &error) != RAD_OK ||
        rad_patch_inputs_build(scene, *mesh, &inputs, &error) != RAD_OK) {
        test_fail(__FILE__, __LINE__, "mesh/inputs: %s", error.message);
        exit(1);
    }
    return inputs;
}

/* The mean over patch p (a floor patch, y = 0) of f(x, z), by a fine midpoint rule over its
 * bounding box (the floor's patches are axis-aligned squares). */
static double patch_mean(const rad_mesh *mesh, uint32_t p, double (*f)(double, double, const void *),
                         const void *data)
{
    const rad_patch *patch = &mesh->patches[p];
    double x0 = INFINITY, x1 = -INFINITY, z0 = INFINITY, z1 = -INFINITY;
    for (uint32_t k = 0; k < patch->vertex_count; k++) {
        rad_vec3 v = mesh->vertices[patch->vertex[k]];
        x0 = fmin(x0, v.x);
        x1 = fmax(x1, v.x);
        z0 = fmin(z0, v.z);
        z1 = fmax(z1, v.z);
    }
    const int m = 16;
    double sum = 0;
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++)
            sum += f(x0 + (i + 0.5) * (x1 - x0) / m, z0 + (j + 0.5) * (z1 - z0) / m, data);
    return sum / (m * m);
}

typedef struct point_source {
    double intensity, height;
} point_source;

/* E = I h / (h^2 + r^2)^(3/2) on the floor below a point light at (0, h, 0). */
static double point_illuminance(double x, double z, const void *data)
{
    const point_source *s = data;
    double r2 = x * x + z * z;
    return s->intensity * s->height / pow(s->height * s->height + r2, 1.5);
}

static void test_point_light_floor(void)
{
    rad_scene *scene = floor_scene(10, NULL);
    point_source source = {100, 2};
    rad_light light = {.type = RAD_LIGHT_POINT, .position = {0, 2, 0}, .intensity = {100, 100, 100}};
    add_light(scene, &light);
    rad_mesh *mesh = NULL;
    rad_patch_inputs *inputs = inputs_of(scene, 0.5, &mesh);
    double worst = 0;
    uint32_t checked = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        rad_vec3 c = mesh->patches[p].centroid;
        if (fabs(c.x) > 6 || fabs(c.z) > 6)
            continue;
        double expected = patch_mean(mesh, p, point_illuminance, &source);
        double d = fabs(inputs->direct[p].g - expected) / expected;
        worst = fmax(worst, d);
        checked++;
        /* the source term is rho H: nothing emits */
        CHECK_NEAR(inputs->source[p].g, 0.5 * inputs->direct[p].g, 1e-12);
        CHECK_NEAR(inputs->direct_sharp[p].r, inputs->direct[p].r, 1e-12);
    }
    printf("point light over a floor: %u patches, worst relative error %.2e\n", checked, worst);
    CHECK(checked > 100);
    CHECK(worst < 0.01);

    /* the same through a rendered image: a camera 10 above looking down; the floor alone
     * sees nothing, so a pixel is rho E / pi at its ground point */
    rad_error error;
    rad_rgb *B = calloc(mesh->patch_count, sizeof(*B));
    rad_scene_solve_report report;
    rad_scene_solve_options options = {.solver = RAD_SOLVER_JACOBI, .threads = 2};
    CHECK(rad_solve_scene(scene, mesh, &options, B, &report, &error) == RAD_OK);
    rad_image *image = test_new_image(65, 65);
    rad_camera camera = {{0, 10, 0}, {0, 0, 0}, {0, 0, -1}, 60};
    rad_render_options render = {.scene = scene, .inputs = inputs, .threads = 2};
    CHECK(rad_render(mesh, B, &camera, &render, image, &error) == RAD_OK);
    double tan_half = tan(30 * PI / 180), pixel_worst = 0;
    for (int j = 0; j <= 30; j += 3) {
        double x = 10 * tan_half * 2.0 * j / 65;
        double expected = 0.5 / PI * point_illuminance(x, 0, &source);
        double d = fabs(test_pixel(image, (uint32_t)(32 + j), 32)[1] - expected) / expected;
        pixel_worst = fmax(pixel_worst, d);
    }
    printf("point light, rendered pixels: worst relative error %.2e\n", pixel_worst);
    CHECK(pixel_worst < 0.01);

    /* an illuminance image: pixels hold E itself at the ground point */
    render.irradiance = true;
    CHECK(rad_render(mesh, B, &camera, &render, image, &error) == RAD_OK);
    double lux_worst = 0;
    for (int j = 0; j <= 30; j += 3) {
        double x = 10 * tan_half * 2.0 * j / 65, expected = point_illuminance(x, 0, &source);
        lux_worst = fmax(lux_worst, fabs(test_pixel(image, (uint32_t)(32 + j), 32)[1] - expected) /
                                        expected);
    }
    printf("point light, illuminance image: worst relative error %.2e\n", lux_worst);
    CHECK(lux_worst < 0.01);
    render.irradiance = false;

    /* the same through rad_illuminance at points of the floor, and its work plane */
    rad_vec3 at[8], up[8];
    rad_rgb E[8];
    for (int k = 0; k < 8; k++) {
        at[k] = (rad_vec3){0.7 * k, 0, 0.3 * k};
        up[k] = (rad_vec3){0, 1, 0};
    }
    rad_illuminance_options measure = {.gather_rays = 64, .threads = 2};
    CHECK(rad_illuminance(scene, mesh, B, at, up, 8, &measure, E, &error) == RAD_OK);
    for (int k = 0; k < 8; k++)
        CHECK_NEAR(E[k].g, point_illuminance(at[k].x, at[k].z, &source), 0.001);
    rad_vec3 *grid = NULL;
    uint32_t grid_count = 0;
    CHECK(rad_work_plane(scene, 0.75, 0.5, &grid, &grid_count, &error) == RAD_OK);
    CHECK(grid_count == 40 * 40);
    CHECK(grid_count > 0 && fabs(grid[0].y - 0.75) < 1e-12 && fabs(grid[0].x + 9.75) < 1e-9);
    free(grid);
    rad_image_destroy(image);
    free(B);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);

    /* in millimetres: the same light 2000 units up gives the same lux */
    rad_scene *mm = floor_scene(10000, NULL);
    mm->unit_metres = 0.001;
    rad_light far = {.type = RAD_LIGHT_POINT, .position = {0, 2000, 0}, .intensity = {100, 100, 100}};
    add_light(mm, &far);
    inputs = inputs_of(mm, 500, &mesh);
    point_source source_mm = {100e6, 2000}; /* I h / (h^2 + r^2)^1.5 with h, r in mm */
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        rad_vec3 c = mesh->patches[p].centroid;
        if (fabs(c.x) < 3000 && fabs(c.z) < 3000)
            CHECK_NEAR(inputs->direct[p].g, patch_mean(mesh, p, point_illuminance, &source_mm),
                       0.01);
    }
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(mm);
    rad_scene_destroy(scene);
}

static void test_spot_cone(void)
{
    rad_scene *scene = floor_scene(10, NULL);
    rad_light spot = {.type = RAD_LIGHT_SPOT, .position = {0, 2, 0}, .direction = {0, -1, 0},
                      .intensity = {100, 100, 100}, .inner_degrees = 20, .outer_degrees = 30};
    add_light(scene, &spot);
    point_source source = {100, 2};
    rad_mesh *mesh = NULL;
    rad_patch_inputs *inputs = inputs_of(scene, 0.1, &mesh);
    uint32_t inside = 0, outside = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        /* the patch's angle from the axis, over its corners */
        double lo = 90, hi = 0;
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            rad_vec3 v = mesh->vertices[patch->vertex[k]];
            double a = atan2(sqrt(v.x * v.x + v.z * v.z), 2) * 180 / PI;
            lo = fmin(lo, a);
            hi = fmax(hi, a);
        }
        if (hi < 19.5) {
            CHECK_NEAR(inputs->direct[p].g, patch_mean(mesh, p, point_illuminance, &source), 0.005);
            inside++;
        } else if (lo > 30.5) {
            CHECK(inputs->direct[p].g == 0);
            outside++;
        }
    }
    printf("spot: %u patches inside the inner cone, %u outside the outer\n", inside, outside);
    CHECK(inside > 100 && outside > 100);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

static void test_sun(void)
{
    /* a plane tilted 30 degrees about x under a sun at the zenith: E_n cos 30 */
    const char *tilted = test_write_file("tilted.obj",
                                         "v -1 0 -1\nv -1 0 1\nv 1 0 1\nv 1 0 -1\n"
                                         "f 1 2 3 4\n");
    rad_scene *scene = NULL;
    rad_error error;
    CHECK(rad_scene_load(tilted, NULL, &scene, &error) == RAD_OK);
    double c = cos(30 * PI / 180), s = sin(30 * PI / 180);
    /* the sun toward (0, cos 30, sin 30): 30 degrees from the plane's normal (0, 1, 0) */
    rad_light sun = {.type = RAD_LIGHT_DIRECTIONAL, .direction = {0, -c, -s},
                     .intensity = {1000, 1000, 1000}};
    add_light(scene, &sun);
    rad_mesh *mesh = NULL;
    rad_patch_inputs *inputs = inputs_of(scene, 0.5, &mesh);
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        CHECK_NEAR(inputs->direct[p].g, 1000 * c, 1e-9);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);

    /* a unit box on the floor under a sun 45 degrees up toward +x: its shadow on the floor
     * outside its footprint is the unit square beside it, area 1 */
    const char *box =
        "o box\n"
        "v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 0 0.5\nv -0.5 0 0.5\n"
        "v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n"
        "f 5 9 10 6\nf 6 10 11 7\nf 7 11 12 8\nf 8 12 9 5\nf 9 12 11 10\n";
    scene = floor_scene(4, box);
    rad_light low_sun = {.type = RAD_LIGHT_DIRECTIONAL, .direction = {-1, -1, 0},
                         .intensity = {1000, 1000, 1000}};
    add_light(scene, &low_sun);
    inputs = inputs_of(scene, 0.05, &mesh);
    double open = 1000 * cos(PI / 4), shadow = 0;
    uint32_t floor_surface = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        if (patch->surface != floor_surface)
            continue;
        rad_vec3 q = patch->centroid;
        bool under_box = fabs(q.x) < 0.5 && fabs(q.z) < 0.5;
        if (!under_box)
            shadow += patch->area * (1 - inputs->direct[p].g / open);
    }
    printf("sun at 45 degrees: shadow of a unit box on the floor %.4f m^2 (1)\n", shadow);
    CHECK_NEAR(shadow, 1.0, 0.02);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);

    /* a roof over everything hides the sun */
    scene = floor_scene(4, "o roof\nv -20 3 -20\nv -20 3 20\nv 20 3 20\nv 20 3 -20\nf 5 6 7 8\n");
    add_light(scene, &low_sun);
    inputs = inputs_of(scene, 0.5, &mesh);
    double most = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        if (mesh->patches[p].surface == floor_surface)
            most = fmax(most, inputs->direct[p].g);
    CHECK(most == 0);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* The area-weighted mean of H over a surface's patches. */
static double surface_mean(const rad_mesh *mesh, const rad_patch_inputs *inputs, uint32_t surface,
                           double *lowest, double *highest)
{
    double sum = 0, area = 0;
    *lowest = INFINITY;
    *highest = -INFINITY;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        if (mesh->patches[p].surface != surface)
            continue;
        sum += mesh->patches[p].area * inputs->direct[p].g;
        area += mesh->patches[p].area;
        *lowest = fmin(*lowest, inputs->direct[p].g);
        *highest = fmax(*highest, inputs->direct[p].g);
    }
    return sum / area;
}

static void test_skies(void)
{
    double lo, hi;
    /* uniform sky of luminance L over an open floor: pi L */
    rad_scene *scene = floor_scene(4, NULL);
    rad_light sky = {.type = RAD_LIGHT_SKY, .sky = RAD_SKY_UNIFORM, .intensity = {1000, 1000, 1000}};
    add_light(scene, &sky);
    rad_mesh *mesh = NULL;
    rad_patch_inputs *inputs = inputs_of(scene, 0.5, &mesh);
    double mean = surface_mean(mesh, inputs, 0, &lo, &hi);
    CHECK_NEAR(mean, PI * 1000, 1e-9);
    CHECK_NEAR(lo, PI * 1000, 1e-9);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);

    /* CIE overcast: 7 pi L_z / 9 on open ground */
    scene = floor_scene(4, NULL);
    sky.sky = RAD_SKY_CIE_OVERCAST;
    add_light(scene, &sky);
    inputs = inputs_of(scene, 0.25, &mesh);
    mean = surface_mean(mesh, inputs, 0, &lo, &hi);
    printf("overcast sky on open ground: mean %.2f (%.2f), patches %.2f .. %.2f\n", mean,
           7 * PI * 1000 / 9, lo, hi);
    CHECK_NEAR(mean, 7 * PI * 1000 / 9, 0.005);
    CHECK_NEAR(lo, 7 * PI * 1000 / 9, 0.05);
    CHECK_NEAR(hi, 7 * PI * 1000 / 9, 0.05);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);

    /* a vertical plane (a wall facing +x) with no ground: the uniform sky gives pi L / 2 */
    const char *wall = test_write_file("wall.obj", "v 0 -1 -1\nv 0 -1 1\nv 0 1 1\nv 0 1 -1\nf 1 4 3 2\n");
    CHECK(rad_scene_load(wall, NULL, &scene, NULL) == RAD_OK);
    sky.sky = RAD_SKY_UNIFORM;
    add_light(scene, &sky);
    inputs = inputs_of(scene, 0.25, &mesh);
    CHECK(mesh->patches[0].normal.x > 0.99);
    mean = surface_mean(mesh, inputs, 0, &lo, &hi);
    printf("uniform sky on a vertical plane: mean %.2f (%.2f)\n", mean, PI * 1000 / 2);
    CHECK_NEAR(mean, PI * 1000 / 2, 0.01);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);

    /* a closed room sees no sky */
    test_write_furnace("room.obj");
    CHECK(rad_scene_load(test_path("room.obj"), NULL, &scene, NULL) == RAD_OK);
    add_light(scene, &sky);
    inputs = inputs_of(scene, 0.25, &mesh);
    double most = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        most = fmax(most, inputs->direct[p].g);
    CHECK(most == 0);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* A closed, inward-facing cube room of side 4 m, as OBJ text. */
#define CUBE_ROOM                                                                          \
    "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\nv 0 0 4\nv 4 0 4\nv 4 4 4\nv 0 4 4\n"          \
    "o zlo\nf 1 2 3 4\no zhi\nf 5 8 7 6\no xlo\nf 1 4 8 5\no xhi\nf 2 6 7 3\n"           \
    "o ylo\nf 1 5 6 2\no yhi\nf 4 3 7 8\n"

/* The power absorbed, sum A (1 - rho) H over the patches' open areas, with H the total
 * irradiance (B - E) / rho (green). */
static double absorbed_power(const rad_mesh *mesh, const rad_patch_inputs *inputs,
                             const rad_rgb *B)
{
    double absorbed = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        double rho = inputs->albedo[p].g;
        absorbed += inputs->area[p] * (1 - rho) * (B[p].g - inputs->exitance[p].g) / rho;
    }
    return absorbed;
}

/* A closed, inward-facing cube room of side 4 m (albedo 0.5, nothing emits) with a point
 * light of intensity I at its centre: the power absorbed, sum A (1 - rho) H with H the
 * total irradiance (B - E) / rho, equals the light's flux 4 pi I. */
static void test_energy(void)
{
    const char *room = test_write_file(
        "cube.obj",
        CUBE_ROOM);
    rad_scene *scene = NULL;
    rad_error error;
    CHECK(rad_scene_load(room, NULL, &scene, &error) == RAD_OK);
    rad_light light = {.type = RAD_LIGHT_POINT, .position = {2, 2, 2}, .intensity = {100, 100, 100}};
    add_light(scene, &light);
    rad_mesh *mesh = NULL;
    rad_patch_inputs *inputs = inputs_of(scene, 0.5, &mesh);
    rad_solver solvers[] = {RAD_SOLVER_JACOBI, RAD_SOLVER_SHOOT, RAD_SOLVER_HIERARCHICAL};
    for (size_t k = 0; k < sizeof(solvers) / sizeof(solvers[0]); k++) {
        rad_rgb *B = calloc(mesh->patch_count, sizeof(*B));
        rad_scene_solve_options options = {.solver = solvers[k], .threads = 2, .inputs = inputs,
                                           .tolerance = 1e-7};
        rad_scene_solve_report report;
        CHECK(rad_solve_scene(scene, mesh, &options, B, &report, &error) == RAD_OK);
        double absorbed = absorbed_power(mesh, inputs, B);
        printf("closed room, point light, %s: absorbed %.3f lm, flux %.3f lm\n",
               rad_solver_name(solvers[k]), absorbed, 4 * PI * 100);
        /* the dense solvers to 0.5 %; the hierarchical one to 1 %: it loses 0.58 % here
         * because its final gather takes far planar nodes as point-to-disk kernels
         * A cos cos / (pi r^2 + A), low seen obliquely (gathered exactly it is within
         * +0.14 %); that fix alone overshoots the furnished room of test_hierarchical by
         * 1.6 %, an over-transfer there that the low kernel hides (docs/DESIGN.md) */
        CHECK_NEAR(absorbed, 4 * PI * 100, solvers[k] == RAD_SOLVER_HIERARCHICAL ? 0.01 : 0.005);
        if (solvers[k] == RAD_SOLVER_HIERARCHICAL) {
            /* refined further (--refine-threshold 0.05 instead of 0.25) its links reach
             * the dense solvers' 0.5 % (measured: -0.085 %; at 0.01, +0.26 %) */
            options.refine_threshold = 0.05;
            CHECK(rad_solve_scene(scene, mesh, &options, B, &report, &error) == RAD_OK);
            absorbed = absorbed_power(mesh, inputs, B);
            printf("closed room, point light, hierarchical, refine threshold 0.05: absorbed "
                   "%.3f lm\n",
                   absorbed);
            CHECK_NEAR(absorbed, 4 * PI * 100, 0.005);
        }
        free(B);
    }
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* The same room with a closed box (5 faces, no bottom) standing on the floor across the
 * floor's patches (each 1 x 1 m, the box 1.4 m square: its foot crosses 4 of them): the
 * floor patches running under the box take the open part's area and light
 * (mesh/exposed_area.c), so no light vanishes at the box's foot and the power absorbed,
 * over the open areas, is the flux: measured -0.05 % (dense) and +0.04 % (hierarchical),
 * held to 0.1 % and 0.5 %. With each patch's
 * whole area (before) the dense solvers absorbed 0.40 % less than the flux here. */
static void test_energy_box_on_floor(void)
{
    const char *room = test_write_file(
        "cube_box.obj",
        CUBE_ROOM
        "v 1.3 0 1.3\nv 2.7 0 1.3\nv 2.7 0 2.7\nv 1.3 0 2.7\n"
        "v 1.3 1.2 1.3\nv 2.7 1.2 1.3\nv 2.7 1.2 2.7\nv 1.3 1.2 2.7\n"
        "o box\nf 13 16 15 14\nf 13 14 10 9\nf 14 15 11 10\nf 15 16 12 11\nf 16 13 9 12\n");
    rad_scene *scene = NULL;
    rad_error error;
    CHECK(rad_scene_load(room, NULL, &scene, &error) == RAD_OK);
    rad_light light = {.type = RAD_LIGHT_POINT, .position = {2, 3, 2}, .intensity = {100, 100, 100}};
    add_light(scene, &light);
    rad_mesh *mesh = NULL;
    rad_patch_inputs *inputs = inputs_of(scene, 1.0, &mesh);
    unsigned partly = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        partly += inputs->area[p] < mesh->patches[p].area * (1 - 1e-9);
    printf("box on the floor: %u patches partly buried\n", partly);
    CHECK(partly == 4); /* the four floor patches the foot crosses */
    rad_solver solvers[] = {RAD_SOLVER_JACOBI, RAD_SOLVER_SHOOT, RAD_SOLVER_HIERARCHICAL};
    for (size_t k = 0; k < sizeof(solvers) / sizeof(solvers[0]); k++) {
        rad_rgb *B = calloc(mesh->patch_count, sizeof(*B));
        rad_scene_solve_options options = {.solver = solvers[k], .threads = 2, .inputs = inputs,
                                           .tolerance = 1e-7, .visibility_rays = 64};
        rad_scene_solve_report report;
        CHECK(rad_solve_scene(scene, mesh, &options, B, &report, &error) == RAD_OK);
        double absorbed = absorbed_power(mesh, inputs, B);
        printf("closed room, box on the floor, point light, %s: absorbed %.3f lm, flux %.3f "
               "lm\n",
               rad_solver_name(solvers[k]), absorbed, 4 * PI * 100);
        CHECK_NEAR(absorbed, 4 * PI * 100, solvers[k] == RAD_SOLVER_HIERARCHICAL ? 0.005 : 0.001);
        free(B);
    }
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

static void test_bad_lights(void)
{
    rad_scene *scene = floor_scene(1, NULL);
    rad_error error;
    rad_light negative = {.type = RAD_LIGHT_POINT, .intensity = {-1, 1, 1}};
    CHECK(rad_scene_add_light(scene, &negative, &error) == RAD_ERR_INVALID);
    CHECK(strstr(error.message, "negative") != NULL);
    rad_light cone = {.type = RAD_LIGHT_SPOT, .direction = {0, -1, 0}, .intensity = {1, 1, 1},
                      .inner_degrees = 40, .outer_degrees = 30};
    CHECK(rad_scene_add_light(scene, &cone, &error) == RAD_ERR_INVALID);
    CHECK(strstr(error.message, "inner") != NULL);
    rad_light nowhere = {.type = RAD_LIGHT_DIRECTIONAL, .intensity = {1, 1, 1}};
    CHECK(rad_scene_add_light(scene, &nowhere, &error) == RAD_ERR_INVALID);
    rad_light nan_light = {.type = RAD_LIGHT_POINT, .position = {NAN, 0, 0}, .intensity = {1, 1, 1}};
    CHECK(rad_scene_add_light(scene, &nan_light, &error) == RAD_ERR_INVALID);
    CHECK(scene->light_count == 0);
    rad_scene_destroy(scene);

    /* through the command line: one line naming the option, exit 2 (usage), nothing written */
    char out[1024];
    snprintf(out, sizeof(out), "%s", test_path("bad.png"));
    CHECK(test_run_tool("render --size 8x8 --point 0,0,0:-5 -o bad.png") == 2);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "--point") != NULL);
    CHECK(test_run_tool("render --size 8x8 --spot 0,0,0:0,-1,0:10:40:30 -o bad.png") == 1);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "inner") != NULL);
    CHECK(test_run_tool("render --size 8x8 --sky cloudy -o bad.png") == 2);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "unknown sky 'cloudy'") != NULL);
    CHECK(test_run_tool("render --size 8x8 --sky cie-clear -o bad.png") == 1);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "needs the sun") != NULL);
    CHECK(test_run_tool("render --size 8x8 --unit furlong -o bad.png") == 2);
    CHECK(!test_file_exists(out));
    CHECK(test_run_tool("render --size 8x8 --sky uniform:-5 -o bad.png") == 2);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "must not be negative") != NULL);
    CHECK(test_run_tool("render --size 8x8 --sun 0,0,0 -o bad.png") == 2);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "zero") != NULL);
    CHECK(test_run_tool("render --size 8x8 --time 2024-06-21T12:00 -o bad.png") == 2);
    CHECK(test_run_tool("render --size 8x8 --sun 45,0 --time 2024-06-21T12:60 -o bad.png") == 1);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "--time") != NULL);
    CHECK(!test_file_exists(out));
    /* Whitted with a sky and more sky directions than a shadow batch holds (4096) */
    CHECK(test_run_tool("raytrace floor.obj --sky uniform --light-samples 5000 --size 8x8 "
                        "--eye 0,3,3 --target 0,0,0 -o sky.pfm") == 0);
    /* the daylight factor is the sky's alone: with a sun it is left out, with a warning */
    CHECK(test_run_tool("illuminance floor.obj --sky cie-overcast --plane 0.5 --gather-rays 16 "
                        "-o df.csv") == 0);
    CHECK(strstr(test_read_text(test_path("df.csv")), "daylight_factor_percent") != NULL);
    CHECK(test_run_tool("illuminance floor.obj --sky cie-clear --sun 1,1,0 --plane 0.5 "
                        "--gather-rays 16 -o df.csv") == 0);
    CHECK(strstr(test_read_text(test_path("df.csv")), "daylight_factor_percent") == NULL);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "no daylight factor") != NULL);
    /* --points: a header line of names is skipped; trailing text on a row is refused */
    test_write_file("named.csv", "x,y,z\n0,0,0\n");
    CHECK(test_run_tool("illuminance floor.obj --point 0,2,0:100 --points named.csv "
                        "--gather-rays 16 -o named_out.csv") == 0);
    test_write_file("junk.csv", "0,0,0\n1,0,1junk\n");
    CHECK(test_run_tool("illuminance floor.obj --point 0,2,0:100 --points junk.csv "
                        "--gather-rays 16 -o junk_out.csv") != 0);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "junk.csv:2") != NULL);
    CHECK(!test_file_exists(test_path("junk_out.csv")));
    /* a type B web is read, but not taken as a light (its angles are not type C's) */
    test_write_file("typeb.ies", "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3 1 2 2 0 0 0\n1 1 10\n"
                                 "-90 0 90\n0\n100 100 100\n");
    CHECK(test_run_tool("render floor.obj --luminaire typeb.ies:0,2,0 --size 8x8 -o b.png") == 1);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "type B") != NULL);
    /* a sun below the horizon: a warning, no sunlight, the run goes on */
    CHECK(test_run_tool("info --sun 0,-1,0") == 0);
    CHECK(strstr(test_read_text(test_path("stdout.txt")), "below the horizon") != NULL);
}

/* A room 4 x 3 x 5 m (albedo 0.5, inward) with a 2 x 1 m window in its south wall under the
 * CIE overcast sky: the illuminance at floor points (rad_illuminance, as the daylight
 * factor is computed) against the path tracer's (pi / rho x the mean radiance of a small
 * patch of floor seen from straight above) within 2 % and 3 standard errors. */
static void test_daylight_factor(void)
{
    const char *room = test_write_file(
        "window_room.obj",
        "v 0 0 0\nv 4 0 0\nv 4 0 5\nv 0 0 5\nv 0 3 0\nv 4 3 0\nv 4 3 5\nv 0 3 5\n"
        "v 1 1 0\nv 3 1 0\nv 3 2 0\nv 1 2 0\nv 0 1 0\nv 4 1 0\nv 4 2 0\nv 0 2 0\n"
        "o floor\nf 1 4 3 2\no ceiling\nf 5 6 7 8\no west\nf 1 5 8 4\no east\nf 2 3 7 6\n"
        "o north\nf 4 8 7 3\n"
        "o south\nf 1 2 14 13\nf 16 15 6 5\nf 13 9 12 16\nf 10 14 15 11\n");
    rad_scene *scene = NULL;
    rad_error error;
    CHECK(rad_scene_load(room, NULL, &scene, &error) == RAD_OK);
    rad_light sky = {.type = RAD_LIGHT_SKY, .sky = RAD_SKY_CIE_OVERCAST, .intensity = {1000, 1000, 1000}};
    add_light(scene, &sky);
    rad_mesh *mesh = NULL;
    CHECK(rad_mesh_build(scene, 0.2, &mesh, &error) == RAD_OK);
    rad_rgb *B = calloc(mesh->patch_count, sizeof(*B));
    rad_scene_solve_options options = {.threads = 2};
    CHECK(rad_solve_scene(scene, mesh, &options, B, NULL, &error) == RAD_OK);
    const rad_vec3 at[] = {{2, 0, 1.2}, {2, 0, 2.5}, {1, 0, 4}, {3.2, 0, 1.8}};
    const int n = (int)(sizeof(at) / sizeof(at[0]));
    rad_vec3 up[4] = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
    rad_rgb E[4];
    rad_illuminance_options measure = {.threads = 2}; /* the default gather */
    CHECK(rad_illuminance(scene, mesh, B, at, up, (uint32_t)n, &measure, E, &error) == RAD_OK);
    double outside = rad_sky_horizontal_illuminance(scene);
    CHECK_NEAR(outside, 7 * PI * 1000 / 9, 1e-9);
    for (int k = 0; k < n; k++) {
        rad_image *image = test_new_image(8, 8), *se = test_new_image(8, 8);
        rad_camera camera = {{at[k].x, 2.9, at[k].z}, at[k], {0, 0, 1}, 2};
        rad_pathtrace_options trace = {.samples_per_pixel = 4096, .threads = 2, .seed = 3 + (uint64_t)k};
        CHECK(rad_pathtrace(scene, &camera, &trace, image, se, NULL, &error) == RAD_OK);
        double mean = 0, var = 0;
        for (uint32_t y = 0; y < 8; y++)
            for (uint32_t x = 0; x < 8; x++) {
                mean += test_pixel(image, x, y)[1] / 64;
                var += pow(test_pixel(se, x, y)[1], 2) / (64.0 * 64.0);
            }
        double traced = PI / 0.5 * mean, error_of_mean = PI / 0.5 * sqrt(var);
        printf("daylight factor at (%.1f, %.1f): radiosity %.3f %%, path tracer %.3f %% +- %.3f\n",
               at[k].x, at[k].z, 100 * E[k].g / outside, 100 * traced / outside,
               100 * error_of_mean / outside);
        CHECK(fabs(E[k].g - traced) <= 0.02 * traced + 3 * error_of_mean);
        rad_image_destroy(image);
        rad_image_destroy(se);
    }
    free(B);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* An IES luminaire (a table written here: I = 1000 cos v candela at 5-degree steps of the
 * vertical angle, rotationally symmetric) 2 m above a floor, aimed down: the illuminance
 * at floor points is I(v) cos^3 v / h^2, through the library and the command line. */
static void test_luminaire(void)
{
    char table[4096];
    int used = snprintf(table, sizeof(table),
                        "IESNA:LM-63-2002\n[TEST] written by test_lights\n[MANUFAC] none\n"
                        "TILT=NONE\n1 -1 1 19 1 1 2 0 0 0\n1 1 100\n");
    for (int k = 0; k < 19; k++)
        used += snprintf(table + used, sizeof(table) - (size_t)used, "%d ", 5 * k);
    used += snprintf(table + used, sizeof(table) - (size_t)used, "\n0\n");
    for (int k = 0; k < 19; k++)
        used += snprintf(table + used, sizeof(table) - (size_t)used, "%.9f ",
                         1000 * cos(5 * k * PI / 180));
    snprintf(table + used, sizeof(table) - (size_t)used, "\n");
    const char *ies = test_write_file("downlight.ies", table);
    rad_photometry *web = NULL;
    rad_error error;
    CHECK(rad_photometry_read(ies, NULL, NULL, &web, &error) == RAD_OK);
    if (!web)
        return;
    CHECK_NEAR(web->lumens, PI * 1000, 0.005); /* a cosine web: pi I0 */
    rad_scene *scene = floor_scene(10, NULL);
    rad_light luminaire = {.type = RAD_LIGHT_LUMINAIRE, .position = {0, 2, 0},
                           .direction = {0, -1, 0}, .intensity = {1, 1, 1}, .photometry = web};
    add_light(scene, &luminaire);
    rad_mesh *mesh = NULL;
    CHECK(rad_mesh_build(scene, 0.5, &mesh, &error) == RAD_OK);
    rad_rgb *B = calloc(mesh->patch_count, sizeof(*B));
    CHECK(rad_solve_scene(scene, mesh, NULL, B, NULL, &error) == RAD_OK);
    double angles[] = {0, 10, 22.5, 37.5, 50, 60};
    rad_vec3 at[6], up[6];
    rad_rgb E[6];
    for (int k = 0; k < 6; k++) {
        at[k] = (rad_vec3){2 * tan(angles[k] * PI / 180) * cos(k), 0, 2 * tan(angles[k] * PI / 180) * sin(k)};
        up[k] = (rad_vec3){0, 1, 0};
    }
    rad_illuminance_options measure = {.threads = 2, .gather_rays = 16};
    CHECK(rad_illuminance(scene, mesh, B, at, up, 6, &measure, E, &error) == RAD_OK);
    char points[1024] = "";
    for (int k = 0; k < 6; k++) {
        double c = cos(angles[k] * PI / 180), expected = 1000 * c * c * c * c / 4;
        /* between listed angles the table is linear in the angle, cos is not: 0.1 % */
        CHECK_NEAR(E[k].g, expected, 0.005);
        size_t len = strlen(points);
        snprintf(points + len, sizeof(points) - len, "%.9f,0,%.9f\n", at[k].x, at[k].z);
    }
    free(B);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene); /* frees the web */

    /* the command line: --luminaire, --points, the CSV's E column */
    test_write_file("floor_points.csv", points);
    char command[1024];
    snprintf(command, sizeof(command),
             "illuminance floor.obj --luminaire downlight.ies:0,2,0 --points floor_points.csv "
             "--gather-rays 16 -o lux.csv --quiet");
    CHECK(test_run_tool(command) == 0);
    const char *csv = test_read_text(test_path("lux.csv"));
    const char *line = strchr(csv, '\n');
    for (int k = 0; k < 6 && line; k++, line = strchr(line + 1, '\n')) {
        double v[10];
        if (sscanf(line + 1, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3],
                   &v[4], &v[5], &v[6], &v[7], &v[8], &v[9]) != 10) {
            CHECK(!"a row of x,y,z,nx,ny,nz,E_r,E_g,E_b,E");
            break;
        }
        double c = cos(angles[k] * PI / 180);
        CHECK_NEAR(v[9], 1000 * c * c * c * c / 4, 0.005);
    }
    /* a malformed file: one line naming it and its line, nothing written */
    test_write_file("short.ies", "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 1 100\n0 45 90\n0\n100 50\n");
    CHECK(test_run_tool("render floor.obj --luminaire short.ies:0,2,0 -o short.png") != 0);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "short.ies") != NULL);
    CHECK(!test_file_exists(test_path("short.png")));
}

/* The false-colour scale: its ends, its legend band, a refused scale. */
static void test_false_colour(void)
{
    rad_image *values = test_new_image(100, 50);
    for (uint32_t y = 0; y < 50; y++)
        for (uint32_t x = 0; x < 100; x++)
            test_set_pixel(values, x, y, x * 10.0, x * 10.0, x * 10.0);
    rad_false_colour_options options = {.low = 0, .high = 990, .unit = "lx"};
    rad_image *out = NULL;
    rad_error error;
    CHECK(rad_image_false_colour(values, &options, &out, &error) == RAD_OK);
    CHECK(out->width == 196 && out->height == 50);
    const float *low = test_pixel(out, 0, 25), *high = test_pixel(out, 99, 25),
                *middle = test_pixel(out, 50, 25);
    CHECK(low[2] > low[0] && low[2] > low[1]);   /* blue at the low end */
    CHECK(high[0] > high[1] && high[0] > high[2]); /* red at the high end */
    CHECK(middle[1] > middle[2]);                 /* green-yellow in the middle */
    rad_image_destroy(out);
    options.low = 5;
    options.high = 1;
    CHECK(rad_image_false_colour(values, &options, &out, &error) == RAD_ERR_INVALID);
    CHECK(out == NULL);
    rad_image_destroy(values);
}

int main(void)
{
    test_false_colour();
    test_point_light_floor();
    test_spot_cone();
    test_sun();
    test_skies();
    test_daylight_factor();
    test_luminaire();
    test_energy();
    test_energy_box_on_floor();
    test_bad_lights();
    return test_finish("test_lights");
}
