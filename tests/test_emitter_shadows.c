/*
 * test_emitter_shadows.c - the emitters' light behind occluders, exactly
 * (render/emitter_shadows.h), against closed forms and an independent Monte-Carlo count:
 *   - a point under a square lamp with a parallel square plate between them: the light
 *     that gets through is the lamp's factor less that of the plate's shadow on the lamp's
 *     plane, each a sum of point-to-rectangle factors (VALIDATION.md section 2), at points
 *     whose shadow lies inside the lamp, runs off its edge, or misses it;
 *   - a box standing under the lamp (a convex solid: its faces overlap as seen from the
 *     floor) and a tilted plate: against a count of 2^20 stratified points on the lamp,
 *     each segment tested against every scene triangle (Moller-Trumbore, testlib), within
 *     4 standard errors;
 *   - a grid of 100 small plates between a point and the lamp: more occluders than the
 *     query takes, so it says so (the caller samples); a point behind the lamp gets none;
 *   - a two-sided lamp lights both ways; a lamp of more than EMITTER_ANALYTIC_MAX
 *     triangles has no exact light (the build gives none).
 */
#include <math.h>
#include <stdlib.h>

#include "core/vec3.h"
#include "lights/emitters.h"
#include "render/emitter_light.h"
#include "render/emitter_shadows.h"
#include "testlib.h"

#define EMITTED 10.0    /* Ke */
#define LAMP_HEIGHT 2.0 /* the lamp x, z in [-0.5, 0.5] at y = 2, facing down */
#define LAMP_HALF 0.5

/* The factor from a point to a parallel rectangle [0, a] x [0, b] whose corner lies right
 * above it at height c, signed in a and b (odd in each), so that sums of four give any
 * axis-aligned rectangle. */
static double corner_factor(double a, double b, double c)
{
    double A = a / c, B = b / c;
    double sa = sqrt(1 + A * A), sb = sqrt(1 + B * B);
    return (A / sa * atan(B / sa) + B / sb * atan(A / sb)) / (2 * RAD_PI);
}

/* From the point (px, 0, pz), facing up, to the rectangle [x0, x1] x [z0, z1] at height c. */
static double rectangle_factor(double px, double pz, double x0, double x1, double z0,
                               double z1, double c)
{
    return corner_factor(x1 - px, z1 - pz, c) - corner_factor(x0 - px, z1 - pz, c) -
           corner_factor(x1 - px, z0 - pz, c) + corner_factor(x0 - px, z0 - pz, c);
}

/* The scene's emitters and their exact shadows (NULL when there are none). */
static emitter_shadows *shadows_of(const rad_scene *scene, emitter_set *set)
{
    rad_error error;
    emitter_shadows *shadows = NULL;
    CHECK(emitters_build(scene, set, &error) == RAD_OK);
    CHECK(emitter_shadows_build(scene, set, &shadows, &error) == RAD_OK);
    return shadows;
}

static double green_at(const emitter_shadows *shadows, rad_vec3 x, rad_vec3 n, bool *ok)
{
    rad_rgb e = {-1, -1, -1};
    *ok = emitter_shadows_irradiance(shadows, x, n, EMITTER_SHADOWS_MAX_OCCLUDERS, &e);
    return e.g;
}

/* A scene's start: its materials and the grey floor y = 0, x and z in [-2, 2]. */
static void begin_scene(test_obj *t)
{
    test_obj_add(t, "mtllib shadows.mtl\n");
    test_obj_object(t, "floor", "grey");
    test_obj_rectangle(t, 1, 0, -2, -2, 2, 2, 1);
}

/* The lamp (LAMP_HALF, LAMP_HEIGHT, facing down); writes the scene as `name`. */
static void end_scene(test_obj *t, const char *name)
{
    test_obj_object(t, "lamp", "light");
    test_obj_rectangle(t, 1, LAMP_HEIGHT, -LAMP_HALF, -LAMP_HALF, LAMP_HALF, LAMP_HALF, -1);
    test_write_file(name, t->data);
    free(t->data);
}

static void write_materials(void)
{
    test_write_file("shadows.mtl", "newmtl grey\nKd 0.5 0.5 0.5\n"
                                   "newmtl light\nKd 0 0 0\nKe 10 10 10\n");
}

/* ---- a parallel plate: closed form -------------------------------------------------- */

/* scene coordinates are floats: every one here is a binary fraction, so the closed form
 * and the scene agree to the last bit */
#define PLATE_HEIGHT 1.0
#define PLATE_HALF 0.1875
#define LIFT 0x1p-17 /* the points off their surface (the render lifts its hits too) */

static void parallel_plate(void)
{
    test_obj t = {0};
    begin_scene(&t);
    test_obj_object(&t, "plate", "grey");
    test_obj_rectangle(&t, 1, PLATE_HEIGHT, -PLATE_HALF, -PLATE_HALF, PLATE_HALF, PLATE_HALF, 1);
    end_scene(&t, "plate.obj");
    rad_scene *scene = test_load_scene("plate.obj");
    emitter_set set = {0};
    emitter_shadows *shadows = shadows_of(scene, &set);
    CHECK(shadows != NULL);
    /* points on the floor: the shadow inside the lamp, over its edge, beside it */
    const double points[][2] = {
        {0, 0}, {0.0625, -0.125}, {0.3125, 0}, {0.4375, 0.375}, {1.25, 0.125}};
    const double height = LAMP_HEIGHT - LIFT;
    const double scale = height / (PLATE_HEIGHT - LIFT); /* the shadow's size on the lamp */
    for (size_t k = 0; shadows && k < sizeof(points) / sizeof(points[0]); k++) {
        double px = points[k][0], pz = points[k][1];
        double lamp =
            rectangle_factor(px, pz, -LAMP_HALF, LAMP_HALF, -LAMP_HALF, LAMP_HALF, height);
        /* the plate seen from the point, on the lamp's plane, cut to the lamp */
        double x0 = fmax(-LAMP_HALF, px + (-PLATE_HALF - px) * scale),
               x1 = fmin(LAMP_HALF, px + (PLATE_HALF - px) * scale),
               z0 = fmax(-LAMP_HALF, pz + (-PLATE_HALF - pz) * scale),
               z1 = fmin(LAMP_HALF, pz + (PLATE_HALF - pz) * scale);
        double hidden =
            x0 < x1 && z0 < z1 ? rectangle_factor(px, pz, x0, x1, z0, z1, height) : 0;
        double expected = RAD_PI * EMITTED * (lamp - hidden);
        bool ok;
        double got = green_at(shadows, v3(px, LIFT, pz), v3(0, 1, 0), &ok);
        CHECK(ok);
        CHECK_NEAR(got, expected, 1e-10);
        printf("  plate: point (%.2f, %.2f): %.9f, closed form %.9f (%.1f %% of the lamp hidden)\n",
               px, pz, got, expected, 100 * hidden / lamp);
        /* the open light is the unshadowed contour integral */
        rad_rgb open = emitter_unshadowed_irradiance(&set, scene, v3(px, LIFT, pz), v3(0, 1, 0));
        CHECK_NEAR(open.g, RAD_PI * EMITTED * lamp, 1e-10);
    }
    /* above the lamp (behind it): nothing; in its plane: nothing */
    bool ok;
    CHECK(green_at(shadows, v3(0, 2.5, 0), v3(0, -1, 0), &ok) == 0 && ok);
    /* facing away: nothing */
    CHECK(green_at(shadows, v3(0.3125, LIFT, 0), v3(0, -1, 0), &ok) == 0 && ok);
    emitter_shadows_destroy(shadows);
    emitters_free(&set);
    rad_scene_destroy(scene);
}

/* ---- a box and a tilted plate: Monte Carlo ---------------------------------------- */

/* The lamp's irradiance at x (normal n) with its visibility counted: 2^20 stratified
 * points on the lamp, each segment tested against every triangle but the lamp's; the
 * standard error into *se. */
static double counted_irradiance(const rad_scene *scene, rad_vec3 x, rad_vec3 n, double *se)
{
    const unsigned side = 1024;
    const double cell = 2 * LAMP_HALF / side, area = 4 * LAMP_HALF * LAMP_HALF;
    rad_rng rng = rad_rng_seed(0x5AD0, 1, 2);
    double sum = 0, sum2 = 0;
    for (unsigned i = 0; i < side; i++)
        for (unsigned j = 0; j < side; j++) {
            rad_vec3 y = v3(-LAMP_HALF + (i + rad_rng_uniform(&rng)) * cell, LAMP_HEIGHT,
                            -LAMP_HALF + (j + rad_rng_uniform(&rng)) * cell);
            rad_vec3 d = v3_sub(y, x);
            double r2 = v3_dot(d, d), r = sqrt(r2);
            double cos_x = v3_dot(n, d) / r, cos_y = d.y / r; /* the lamp faces down */
            double value = 0;
            if (cos_x > 0 && cos_y > 0) {
                value = EMITTED * cos_x * cos_y / r2 * area;
                for (uint32_t t = 0; t < scene->triangle_count && value > 0; t++) {
                    const uint32_t *v = scene->triangles[t].vertex;
                    rad_vec3 a = scene->positions[v[0]], b = scene->positions[v[1]],
                             c = scene->positions[v[2]];
                    if (a.y == LAMP_HEIGHT && b.y == LAMP_HEIGHT && c.y == LAMP_HEIGHT)
                        continue; /* the lamp's own */
                    double u, w, s = test_ray_triangle(x, d, a, b, c, &u, &w);
                    if (s > 1e-9 && s < 1 - 1e-9)
                        value = 0;
                }
            }
            sum += value;
            sum2 += value * value;
        }
    double count = (double)side * side, mean = sum / count;
    *se = sqrt(fmax(0, sum2 / count - mean * mean) / count);
    return mean;
}

static void box_and_tilted_plate(void)
{
    test_obj t = {0};
    begin_scene(&t);
    test_obj_object(&t, "box", "grey");
    test_obj_box(&t, -0.625, 0, -0.3125, -0.125, 0.75, 0.1875, false);
    test_obj_object(&t, "tilted", "grey");
    int base = t.vertices;
    test_obj_add(&t, "v 0.125 1.25 -0.3125\nv 0.5 1.5 -0.3125\nv 0.5 1.5 0.1875\n"
                     "v 0.125 1.25 0.1875\n");
    test_obj_add(&t, "f %d %d %d %d\n", base + 1, base + 2, base + 3, base + 4);
    t.vertices += 4;
    end_scene(&t, "box.obj");
    rad_scene *scene = test_load_scene("box.obj");
    emitter_set set = {0};
    emitter_shadows *shadows = shadows_of(scene, &set);
    CHECK(shadows != NULL);
    /* on the floor beside the box and under the plate, on the box's side and top */
    const struct {
        rad_vec3 x, n;
    } at[] = {{{0.0625, LIFT, 0.0}, {0, 1, 0}},          {{0.3125, LIFT, -0.125}, {0, 1, 0}},
              {{-0.8125, LIFT, 0.375}, {0, 1, 0}},        {{-0.125 + LIFT, 0.25, 0.0}, {1, 0, 0}},
              {{-0.375, 0.75 + LIFT, 0.0}, {0, 1, 0}},    {{0.875, LIFT, -0.875}, {0, 1, 0}},
              {{-0.125 - LIFT, 0.25, 0.0}, {-1, 0, 0}}};
    for (size_t k = 0; shadows && k < sizeof(at) / sizeof(at[0]); k++) {
        double se, counted = counted_irradiance(scene, at[k].x, at[k].n, &se);
        bool ok;
        double got = green_at(shadows, at[k].x, at[k].n, &ok);
        CHECK(ok);
        CHECK_ABS(got, counted, 4 * se + 1e-12);
        rad_rgb open = emitter_unshadowed_irradiance(&set, scene, at[k].x, at[k].n);
        printf("  box and plate: point %zu: %.6f, counted %.6f +- %.6f (%.1f %% of the open "
               "light)\n",
               k, got, counted, se, open.g > 0 ? 100 * got / open.g : 0);
    }
    emitter_shadows_destroy(shadows);
    emitters_free(&set);
    rad_scene_destroy(scene);
}

/* ---- too many occluders; a two-sided lamp; a lamp of many triangles ------------------ */

static void limits(void)
{
    test_obj t = {0};
    begin_scene(&t);
    test_obj_object(&t, "grid", "grey");
    for (int i = 0; i < 10; i++)
        for (int j = 0; j < 10; j++) {
            double x = -0.4375 + 0.09375 * i, z = -0.4375 + 0.09375 * j;
            test_obj_rectangle(&t, 1, 1.0, z - 0.015625, x - 0.015625, z + 0.015625,
                               x + 0.015625, 1);
        }
    end_scene(&t, "grid.obj");
    rad_scene *scene = test_load_scene("grid.obj");
    emitter_set set = {0};
    emitter_shadows *shadows = shadows_of(scene, &set);
    bool ok = true;
    rad_rgb untouched = {-1, -1, -1};
    if (shadows)
        ok = emitter_shadows_irradiance(shadows, v3(0, LIFT, 0), v3(0, 1, 0),
                                        EMITTER_SHADOWS_MAX_OCCLUDERS, &untouched);
    CHECK(shadows && !ok && untouched.g == -1); /* 200 triangles in the way: sample */
    emitter_shadows_destroy(shadows);
    emitters_free(&set);
    rad_scene_destroy(scene);

    /* a two-sided lamp halfway up lights the floor below and the ceiling above alike */
    test_obj u = {0};
    test_obj_add(&u, "mtllib shadows.mtl\n");
    test_obj_object(&u, "lamp", "light");
    test_obj_rectangle(&u, 1, 1.0, -LAMP_HALF, -LAMP_HALF, LAMP_HALF, LAMP_HALF, -1);
    test_write_file("two_sided.obj", u.data);
    free(u.data);
    rad_error error;
    scene = test_load_scene("two_sided.obj");
    CHECK(rad_scene_set_surface_flags(scene, "lamp", RAD_SURFACE_TWO_SIDED, &error) == RAD_OK);
    {
        set = (emitter_set){0};
        shadows = shadows_of(scene, &set);
        CHECK(shadows != NULL);
        double expected = RAD_PI * EMITTED *
                          rectangle_factor(0.25, 0.125, -LAMP_HALF, LAMP_HALF, -LAMP_HALF,
                                           LAMP_HALF, 1.0);
        if (shadows) {
            CHECK_NEAR(green_at(shadows, v3(0.25, 0, 0.125), v3(0, 1, 0), &ok), expected, 1e-10);
            CHECK_NEAR(green_at(shadows, v3(0.25, 2, 0.125), v3(0, -1, 0), &ok), expected,
                       1e-10);
        }
        emitter_shadows_destroy(shadows);
        emitters_free(&set);
        rad_scene_destroy(scene);
    }

    /* a lamp of 200 triangles: its unshadowed light is not summed exactly, nor is this */
    test_obj w = {0};
    test_obj_add(&w, "mtllib shadows.mtl\n");
    test_obj_object(&w, "lamp", "light");
    for (int i = 0; i < 10; i++)
        for (int j = 0; j < 10; j++)
            test_obj_rectangle(&w, 1, LAMP_HEIGHT, -0.5 + 0.1 * j, -0.5 + 0.1 * i,
                               -0.4 + 0.1 * j, -0.4 + 0.1 * i, -1);
    test_write_file("tiles.obj", w.data);
    free(w.data);
    scene = test_load_scene("tiles.obj");
    set = (emitter_set){0};
    shadows = shadows_of(scene, &set);
    CHECK(set.count > EMITTER_ANALYTIC_MAX && shadows == NULL);
    emitter_shadows_destroy(shadows);
    emitters_free(&set);
    rad_scene_destroy(scene);
}

int main(void)
{
    test_tmpdir();
    write_materials();
    parallel_plate();
    box_and_tilted_plate();
    limits();
    return test_finish("test_emitter_shadows");
}
