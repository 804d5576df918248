/*
 * test_texture_renderers.c - every renderer and solver honours albedo and emission
 * textures the same way, each measured against a closed form:
 *   - textured furnace (path tracer): a closed inward cube with Kd 1 x a uniform texture of
 *     linear albedo t and Ke 2 x the same texture: every pixel is 2 t / (1 - t);
 *   - Whitted: a lamp over a floor textured dark | bright: each pixel is the texel times the
 *     image of a white (Kd 1) floor, and the bright half is rho L_e F(point -> lamp);
 *   - an emission texture seen directly (Kd 0, black | white): the path tracer, Whitted and
 *     the radiosity render show 0 on the black half and Ke on the white one;
 *   - next-event estimation with an emission texture: a floor under a light whose texture
 *     is black on one of its halves, lit by the white half alone: rho L_e F with F the
 *     point-to-rectangle factor of that half (VALIDATION.md section 2), within the path
 *     tracer's own standard error, and by Whitted and radiosity within 1 %; the halves as
 *     two rectangles (the black one sampled by its power floor, measured) and as one quad
 *     whose triangles straddle both (half the light samples land on black texels);
 *   - the solves: the patch exitance of an emission-textured patch is pi Ke x the texture's
 *     mean (black | white: 0.5), in the patch inputs, the dense solve and the hierarchical
 *     solve (Kd 0: B = E);
 *   - importing: glTF emissiveTexture x emissiveFactor x emissive strength, sRGB-decoded;
 *     warnings for a missing map_Ke, a map_Ke without Ke, a second texture-coordinate set.
 * Textures are PNGs written here; 8-bit sRGB values are decoded to linear with the sRGB
 * curve, computed here too.
 */
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/vec3.h" /* RAD_PI */
#include "lights/emitters.h"
#include "testlib.h"

/* A grey PNG of width x 1 whose first `split` columns are sRGB `left`, the rest `right`. */
static void write_stripes(const char *name, uint32_t width, uint32_t split, unsigned left,
                          unsigned right)
{
    unsigned char rgb[3 * 256];
    for (uint32_t x = 0; x < width && x < 256; x++)
        memset(&rgb[3 * x], (int)(x < split ? left : right), 3);
    test_write_png(name, width, 1, rgb);
}

static double mean_green(const rad_image *image)
{
    double sum = 0;
    for (uint32_t y = 0; y < image->height; y++)
        for (uint32_t x = 0; x < image->width; x++)
            sum += test_pixel(image, x, y)[1];
    return sum / ((double)image->width * image->height);
}

/* F from a point to a parallel a x b rectangle at distance c, the normal through one of
 * its corners (VALIDATION.md section 2). */
static double corner_factor(double a, double b, double c)
{
    double X = a / c, Y = b / c;
    return (X / sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) +
            Y / sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y))) /
           (2 * RAD_PI);
}

static double signed_corner(double a, double b, double c)
{
    double s = (a < 0 ? -1 : 1) * (b < 0 ? -1 : 1);
    return s * corner_factor(fabs(a), fabs(b), c);
}

/* F from the point (px, pz) of a plane, facing it, to the rectangle [x0,x1] x [z0,z1] of
 * the parallel plane at distance c: superposition of four corner rectangles. */
static double rectangle_factor(double px, double pz, double x0, double x1, double z0, double z1,
                               double c)
{
    return signed_corner(x1 - px, z1 - pz, c) - signed_corner(x0 - px, z1 - pz, c) -
           signed_corner(x1 - px, z0 - pz, c) + signed_corner(x0 - px, z0 - pz, c);
}

/* ---------------------------------------------------------------------------------- */

/* The unit cube, each face an inward-facing quad with texture coordinates 0..1. */
static void write_textured_cube(const char *name, const char *mtl)
{
    char text[2048];
    int n = snprintf(text, sizeof(text),
                     "mtllib %s\nusemtl glow\n"
                     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                     "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n",
                     mtl);
    /* face x_k = s: corners in the (i, j) = (k+1, k+2) plane ordered (0,0) (1,0) (1,1)
     * (0,1), whose normal is +e_k: inward for s = 0; reversed for s = 1 */
    const int order[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int k = 0; k < 3; k++)
        for (int s = 0; s < 2; s++) {
            n += snprintf(text + n, sizeof(text) - (size_t)n, "o face%d%d\nf", k, s);
            for (int c = 0; c < 4; c++) {
                int corner = s ? 3 - c : c;
                int coordinate[3];
                coordinate[k] = s;
                coordinate[(k + 1) % 3] = order[corner][0];
                coordinate[(k + 2) % 3] = order[corner][1];
                int vertex = 1 + coordinate[0] + 2 * coordinate[1] + 4 * coordinate[2];
                n += snprintf(text + n, sizeof(text) - (size_t)n, " %d/%d", vertex, corner + 1);
            }
            n += snprintf(text + n, sizeof(text) - (size_t)n, "\n");
        }
    test_write_file(name, text);
}

static void textured_furnace(void)
{
    const unsigned value = 188; /* sRGB: linear 0.5029 */
    double t = test_srgb_to_linear(value);
    write_stripes("grey188.png", 4, 4, value, value);
    test_write_file("cube.mtl", "newmtl glow\nKd 1 1 1\nmap_Kd grey188.png\n"
                                "Ke 2 2 2\nmap_Ke grey188.png\n");
    write_textured_cube("cube.obj", "cube.mtl");
    rad_scene *scene = test_load_scene("cube.obj");
    if (!scene)
        return;
    CHECK(scene->texture_count == 1);
    CHECK(scene->materials[0].albedo_texture == 1 && scene->materials[0].emission_texture == 1);
    CHECK(rad_scene_has_emitter(scene));
    rad_camera camera = {{0.5, 0.5, 0.5}, {0.5, 0.5, 1}, {0, 1, 0}, 90};
    rad_image *image = test_new_image(16, 16), *se = test_new_image(16, 16);
    rad_pathtrace_options options = {.samples_per_pixel = 64, .seed = 7};
    rad_error error;
    CHECK(rad_pathtrace(scene, &camera, &options, image, se, NULL, &error) == RAD_OK);
    double expected = 2 * t / (1 - t), mean = mean_green(image), variance = 0;
    for (uint32_t y = 0; y < se->height; y++)
        for (uint32_t x = 0; x < se->width; x++)
            variance += (double)test_pixel(se, x, y)[1] * test_pixel(se, x, y)[1];
    double n = (double)se->width * se->height;
    printf("textured furnace, path tracer: mean %.5f +- %.5f (1 s.e.), expected 2 t / (1 - t) "
           "= %.5f (t = %.5f), %.2f %% off\n",
           mean, sqrt(variance) / n, expected, t, 100 * (mean / expected - 1));
    CHECK_NEAR(mean, expected, 0.01);
    rad_image_destroy(image);
    rad_image_destroy(se);
    rad_scene_destroy(scene);
}

/* ---------------------------------------------------------------------------------- */

/* The floor [0,2] x [0,2] at y = 0 facing up, u = x / 2, and a lamp (Kd 0, Ke 5) facing
 * down over [0.5,1.5]^2 at height 1. */
static void write_lamp_floor(const char *name, const char *mtl, const char *floor_material)
{
    char text[1024];
    snprintf(text, sizeof(text),
             "mtllib %s\n"
             "o floor\nusemtl %s\n"
             "v 0 0 0\nv 0 0 2\nv 2 0 2\nv 2 0 0\n"
             "vt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\n"
             "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"
             "o lamp\nusemtl lamp\n"
             "v 0.5 1 0.5\nv 1.5 1 0.5\nv 1.5 1 1.5\nv 0.5 1 1.5\n"
             "f 5 6 7\nf 5 7 8\n",
             mtl, floor_material);
    test_write_file(name, text);
}

static void whitted_texel_ratio(void)
{
    /* 8 x 1: four dark texels | four bright: pure dark for u in [1/16, 7/16], pure bright
     * for u in [9/16, 15/16] (bilinear between texel centres) */
    const unsigned dark = 64, bright = 230;
    write_stripes("dark_bright.png", 8, 4, dark, bright);
    test_write_file("whitted.mtl", "newmtl painted\nKd 1 1 1\nmap_Kd dark_bright.png\n"
                                   "newmtl white\nKd 1 1 1\n"
                                   "newmtl lamp\nKd 0 0 0\nKe 5 5 5\n");
    write_lamp_floor("painted.obj", "whitted.mtl", "painted");
    write_lamp_floor("white.obj", "whitted.mtl", "white");
    rad_scene *painted = test_load_scene("painted.obj"), *white = test_load_scene("white.obj");
    if (!painted || !white) {
        rad_scene_destroy(painted);
        rad_scene_destroy(white);
        return;
    }
    /* from below the lamp's plane, looking straight down on the floor's middle: image x
     * runs along world -x, the footprint is [0.6, 1.4] in x and z */
    const double height = 0.5, half = 0.4;
    rad_camera camera = {{1, height, 1}, {1, 0, 1}, {0, 0, 1},
                         2 * atan(half / height) * 180 / RAD_PI};
    const uint32_t size = 40;
    rad_image *a = test_new_image(size, size), *b = test_new_image(size, size);
    rad_raytrace_options options = {.light_samples = 256, .samples_per_pixel = 1, .seed = 3};
    rad_error error;
    CHECK(rad_raytrace(painted, &camera, &options, a, &error) == RAD_OK);
    CHECK(rad_raytrace(white, &camera, &options, b, &error) == RAD_OK);
    double t_dark = test_srgb_to_linear(dark), t_bright = test_srgb_to_linear(bright);
    double worst = 0, sum[2] = {0, 0}, expected_sum[2] = {0, 0};
    unsigned count[2] = {0, 0};
    for (uint32_t y = 0; y < size; y++)
        for (uint32_t x = 0; x < size; x++) {
            /* the pixel centre's point on the floor (one sample through the centre) */
            double sx = (2.0 * (x + 0.5) / size - 1) * half / height;
            double sy = (1 - 2.0 * (y + 0.5) / size) * half / height;
            double px = 1 - height * sx, pz = 1 + height * sy, u = px / 2;
            int side = u > 1.0 / 16 && u < 7.0 / 16 ? 0 : u > 9.0 / 16 && u < 15.0 / 16 ? 1 : -1;
            if (side < 0)
                continue;
            double texel = side ? t_bright : t_dark;
            double ratio = test_pixel(a, x, y)[1] / test_pixel(b, x, y)[1];
            worst = fmax(worst, fabs(ratio / texel - 1));
            sum[side] += test_pixel(a, x, y)[1];
            expected_sum[side] += texel * 5 * rectangle_factor(px, pz, 0.5, 1.5, 0.5, 1.5, 1);
            count[side]++;
        }
    printf("Whitted: %u dark and %u bright pixels; pixel / white-floor pixel = texel within "
           "%.2g (relative); dark half %.5f (closed form %.5f), bright half %.5f (closed "
           "form %.5f); ratio %.5f (texels: %.5f)\n",
           count[0], count[1], worst, sum[0] / count[0], expected_sum[0] / count[0],
           sum[1] / count[1], expected_sum[1] / count[1], sum[0] / sum[1], t_dark / t_bright);
    CHECK(count[0] > 200 && count[1] > 200);
    CHECK(worst < 1e-5);
    CHECK_NEAR(sum[0] / expected_sum[0], 1, 0.01);
    CHECK_NEAR(sum[1] / expected_sum[1], 1, 0.01);
    rad_image_destroy(a);
    rad_image_destroy(b);
    rad_scene_destroy(painted);
    rad_scene_destroy(white);
}

/* ---------------------------------------------------------------------------------- */

/* The light [0,2] x [0,2] at y = 1 facing down, u = x / 2 (black for u < 1/2, white for
 * u > 1/2 with the 8-texel texture), Kd 0, Ke 2 x texel; nothing else. */
/* `fold`: the corner (2, 1, 0) moved that far toward the camera, folding the quad along
 * its diagonal: its cells then lie in front of its two triangles, and each hit's texel is
 * looked up on the triangles a quarter of the fold away at most (rad_patch.bulge); when
 * that reach was the cells' one-sided distance behind the triangles (0 here), the texels
 * were lost and the render showed the material's mean, Ke x 1/2. */
static void emission_seen_directly(double fold)
{
    write_stripes("black_white.png", 8, 4, 0, 255);
    test_write_file("glow.mtl", "newmtl glow\nKd 0 0 0\nKe 2 2 2\nmap_Ke black_white.png\n");
    char obj[256];
    snprintf(obj, sizeof(obj),
             "mtllib glow.mtl\no light\nusemtl glow\n"
             "v 0 1 0\nv 2 %.17g 0\nv 2 1 2\nv 0 1 2\n"
             "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
             "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
             1 - fold);
    test_write_file("glow.obj", obj);
    rad_scene *scene = test_load_scene("glow.obj");
    if (!scene)
        return;
    CHECK(rad_scene_has_emitter(scene));
    /* from (1, 0, 1) looking up, 90 degrees: the light fills the image, x along +x */
    rad_camera camera = {{1, 0, 1}, {1, 1, 1}, {0, 0, 1}, 90};
    const uint32_t size = 32;
    rad_image *images[4];
    for (int k = 0; k < 4; k++)
        images[k] = test_new_image(size, size);
    rad_error error;
    rad_pathtrace_options pt = {.samples_per_pixel = 4, .seed = 1};
    CHECK(rad_pathtrace(scene, &camera, &pt, images[0], NULL, NULL, &error) == RAD_OK);
    rad_raytrace_options rt = {.samples_per_pixel = 4, .seed = 1};
    CHECK(rad_raytrace(scene, &camera, &rt, images[1], &error) == RAD_OK);
    /* the radiosity render, with the solve's inputs passed and built inside */
    rad_mesh *mesh = NULL;
    rad_patch_inputs *inputs = NULL;
    rad_rgb *B = NULL;
    if (rad_mesh_build(scene, 0.7, &mesh, &error) == RAD_OK &&
        rad_patch_inputs_build(scene, mesh, &inputs, &error) == RAD_OK &&
        (B = calloc(mesh->patch_count, sizeof(*B))) != NULL) {
        rad_scene_solve_options so = {.solver = RAD_SOLVER_JACOBI};
        CHECK(rad_solve_scene(scene, mesh, &so, B, NULL, &error) == RAD_OK);
        rad_render_options ro = {.samples_per_pixel = 4, .seed = 1, .scene = scene,
                                 .inputs = inputs};
        CHECK(rad_render(mesh, B, &camera, &ro, images[2], &error) == RAD_OK);
        ro.inputs = NULL;
        CHECK(rad_render(mesh, B, &camera, &ro, images[3], &error) == RAD_OK);
        CHECK(memcmp(images[2]->rgb, images[3]->rgb, (size_t)size * size * 3 * sizeof(float)) ==
              0);
        /* a patch's inputs that do not match the mesh are refused */
        rad_patch_inputs wrong = *inputs;
        wrong.n = inputs->n + 1;
        ro.inputs = &wrong;
        CHECK(rad_render(mesh, B, &camera, &ro, images[3], &error) == RAD_ERR_INVALID);
    } else
        test_fail(__FILE__, __LINE__, "%s", error.message);
    const char *names[3] = {"path tracer", "Whitted", "radiosity render"};
    for (int k = 0; k < 3; k++) {
        double black = 0, white = 0;
        unsigned nb = 0, nw = 0;
        for (uint32_t y = 0; y < size; y++)
            for (uint32_t x = 0; x < size; x++) {
                /* whole pixels inside the pure halves: pixel x spans u in [x, x + 1] / size */
                double lo = (double)x / size, hi = (x + 1.0) / size;
                if (lo > 1.0 / 16 && hi < 7.0 / 16) {
                    black = fmax(black, test_pixel(images[k], x, y)[1]);
                    nb++;
                } else if (lo > 9.0 / 16 && hi < 15.0 / 16) {
                    white += test_pixel(images[k], x, y)[1];
                    nw++;
                }
            }
        printf("emission texture seen directly%s, %s: black half at most %.3g, white half "
               "mean %.6f (Ke = 2), %u and %u pixels\n",
               fold > 0 ? " (quad folded)" : "", names[k], black, white / nw, nb, nw);
        CHECK(nb > 100 && nw > 100);
        CHECK(black <= 1e-6);
        CHECK_NEAR(white / nw, 2, 1e-5);
    }
    for (int k = 0; k < 4; k++)
        rad_image_destroy(images[k]);
    free(B);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* ---------------------------------------------------------------------------------- */

/* A floor (Kd 0.8) under a light [0,2] x [0,2] at height 1 (Kd 0, Ke 3 x texel) whose
 * texture is black on [0,1] and white on [1,2], so the floor is lit by the white half
 * alone: L = 0.8 x 3 x F(point -> [1,2] x [0,2]), by next-event samples and cosine-sampled
 * rays combined by MIS. Two ways to texture it:
 *   - two_rectangles: the halves are separate rectangles of one material, each reading
 *     only black or only white texels of an 8-texel stripe: the black one's mean is 0, so
 *     it is sampled by its power floor alone;
 *   - one quad whose two triangles span both halves (mean texel 1/2 each), with a texture
 *     of 128 black | 128 white texels over u in [1/256, 255/256]: half of the light samples
 *     land on black texels and must bring nothing (the bilinear ramp at the middle is 1/128
 *     of the light wide and antisymmetric: it changes F by about 1e-5 relative). */
static void floor_under_half_light(bool two_rectangles)
{
    const char *obj;
    if (two_rectangles) {
        write_stripes("black_white.png", 8, 4, 0, 255);
        obj = "mtllib nee.mtl\n"
              "o floor\nusemtl floor\n"
              "v -3 0 -3\nv -3 0 3\nv 3 0 3\nv 3 0 -3\n"
              "f 1 2 3\nf 1 3 4\n"
              "o black\nusemtl glow\n"
              "v 0 1 0\nv 1 1 0\nv 1 1 2\nv 0 1 2\n"
              "vt 0.1 0\nvt 0.4 0\nvt 0.4 1\nvt 0.1 1\n"
              "f 5/1 6/2 7/3\nf 5/1 7/3 8/4\n"
              "o white\nusemtl glow\n"
              "v 1 1 0\nv 2 1 0\nv 2 1 2\nv 1 1 2\n"
              "vt 0.6 0\nvt 0.9 0\nvt 0.9 1\nvt 0.6 1\n"
              "f 9/5 10/6 11/7\nf 9/5 11/7 12/8\n";
    } else {
        write_stripes("black_white.png", 256, 128, 0, 255);
        obj = "mtllib nee.mtl\n"
              "o floor\nusemtl floor\n"
              "v -3 0 -3\nv -3 0 3\nv 3 0 3\nv 3 0 -3\n"
              "f 1 2 3\nf 1 3 4\n"
              "o light\nusemtl glow\n"
              "v 0 1 0\nv 2 1 0\nv 2 1 2\nv 0 1 2\n"
              "vt 0.00390625 0\nvt 0.99609375 0\nvt 0.99609375 1\nvt 0.00390625 1\n"
              "f 5/1 6/2 7/3\nf 5/1 7/3 8/4\n";
    }
    const char *variant = two_rectangles ? "two rectangles" : "one quad";
    test_write_file("nee.mtl", "newmtl floor\nKd 0.8 0.8 0.8\n"
                               "newmtl glow\nKd 0 0 0\nKe 3 3 3\nmap_Ke black_white.png\n");
    test_write_file("nee.obj", obj);
    rad_scene *scene = test_load_scene("nee.obj");
    if (!scene)
        return;
    rad_error error;
    if (two_rectangles) {
        /* the emitter set: the black rectangle's triangles (mean texel 0) keep the power
         * floor, EMITTER_POWER_FLOOR of the white ones' (same area, mean texel 1) */
        emitter_set emitters;
        CHECK(emitters_build(scene, &emitters, &error) == RAD_OK);
        CHECK(emitters.count == 4);
        for (uint32_t k = 0; k < emitters.count && emitters.count == 4; k++) {
            uint32_t t = emitters.triangle[k];
            bool black = scene->surfaces[scene->triangles[t].surface].name[0] == 'b';
            double expected = (black ? EMITTER_POWER_FLOOR : 1) / (2 + 2 * EMITTER_POWER_FLOOR);
            printf("emitter triangle %u (%s): pdf_area %.6g, expected %.6g\n", t,
                   black ? "black" : "white", emitters.pdf_area_of[t], expected);
            CHECK_NEAR(emitters.pdf_area_of[t], expected, 1e-9);
        }
        emitters_free(&emitters);
    }
    /* looking down from below the light at the floor under the edge between the halves */
    const double height = 0.5, half = 0.1;
    rad_camera camera = {{1, height, 1}, {1, 0, 1}, {0, 0, 1},
                         2 * atan(half / height) * 180 / RAD_PI};
    const uint32_t size = 32;
    rad_image *image = test_new_image(size, size), *se = test_new_image(size, size);
    rad_pathtrace_options options = {.samples_per_pixel = 64, .seed = 11};
    CHECK(rad_pathtrace(scene, &camera, &options, image, se, NULL, &error) == RAD_OK);
    /* the same image for any thread count */
    rad_image *one_thread = test_new_image(size, size);
    rad_pathtrace_options single = options;
    single.threads = 1;
    CHECK(rad_pathtrace(scene, &camera, &single, one_thread, NULL, NULL, &error) == RAD_OK);
    CHECK(memcmp(one_thread->rgb, image->rgb, (size_t)size * size * 3 * sizeof(float)) == 0);
    rad_image_destroy(one_thread);
    /* the closed form, box-filtered over each pixel by a 4 x 4 midpoint rule */
    double measured = 0, expected = 0, both = 0, variance = 0;
    for (uint32_t y = 0; y < size; y++)
        for (uint32_t x = 0; x < size; x++) {
            for (int i = 0; i < 4; i++)
                for (int j = 0; j < 4; j++) {
                    double sx = (2.0 * (x + (i + 0.5) / 4) / size - 1) * half / height;
                    double sy = (1 - 2.0 * (y + (j + 0.5) / 4) / size) * half / height;
                    double px = 1 - height * sx, pz = 1 + height * sy;
                    expected += 0.8 * 3 * rectangle_factor(px, pz, 1, 2, 0, 2, 1) / 16;
                    both += 0.8 * 3 * rectangle_factor(px, pz, 0, 2, 0, 2, 1) / 16;
                }
            measured += test_pixel(image, x, y)[1];
            double s = test_pixel(se, x, y)[1];
            variance += s * s;
        }
    double n = (double)size * size;
    measured /= n;
    expected /= n;
    both /= n;
    double standard_error = sqrt(variance) / n;
    printf("next-event estimation, emission texture (%s): floor radiance %.5f +- %.5f "
           "(1 s.e.), closed form rho Le F(white half) = %.5f (%.2f s.e. off); with the "
           "black half lit it would be %.5f\n",
           variant, measured, standard_error, expected, (measured - expected) / standard_error,
           both);
    CHECK(fabs(measured - expected) <= 4 * standard_error);
    CHECK(standard_error < 0.005 * expected);

    /* Whitted's area-light samples: the same direct light, quasi-random (no error bar) */
    rad_raytrace_options rt = {.light_samples = 256, .samples_per_pixel = 4, .seed = 5};
    CHECK(rad_raytrace(scene, &camera, &rt, image, &error) == RAD_OK);
    double whitted = mean_green(image);
    printf("the same floor by Whitted (%s): %.5f, %.3f %% from the closed form\n", variant,
           whitted, 100 * (whitted / expected - 1));
    CHECK_NEAR(whitted, expected, 0.01);

    /* the radiosity pipeline on the same scene: the light's patches carry their mean
     * emission (0 or 1 x Ke: the patch edges meet at x = 1), the floor's B interpolated at
     * patch resolution */
    rad_mesh *mesh = NULL;
    rad_rgb *B = NULL;
    if (rad_mesh_build(scene, 0.125, &mesh, &error) == RAD_OK &&
        (B = calloc(mesh->patch_count, sizeof(*B))) != NULL) {
        rad_scene_solve_options so = {.solver = RAD_SOLVER_JACOBI, .seed = 1};
        CHECK(rad_solve_scene(scene, mesh, &so, B, NULL, &error) == RAD_OK);
        rad_render_options ro = {.samples_per_pixel = 4, .seed = 1, .scene = scene};
        CHECK(rad_render(mesh, B, &camera, &ro, image, &error) == RAD_OK);
        double radiosity = mean_green(image);
        printf("the same floor by radiosity (%s, %u patches): %.5f, %.2f %% from the closed "
               "form\n",
               variant, mesh->patch_count, radiosity, 100 * (radiosity / expected - 1));
        CHECK_NEAR(radiosity, expected, 0.01); /* discretisation: -2.35 % at 0.25, second order */
    } else
        test_fail(__FILE__, __LINE__, "%s", error.message);
    free(B);
    rad_mesh_destroy(mesh);
    rad_image_destroy(image);
    rad_image_destroy(se);
    rad_scene_destroy(scene);
}

/* ---------------------------------------------------------------------------------- */

/* One patch of Kd 0 and Ke (1, 0.5, 0.25) x a black | white texture: its exitance is
 * pi Ke x 0.5 (the 8 x 8 points fall symmetrically on the two texels), and B = E. */
static void solve_exitance(void)
{
    write_stripes("two.png", 2, 1, 0, 255);
    test_write_file("patch.mtl", "newmtl glow\nKd 0 0 0\nKe 1 0.5 0.25\nmap_Ke two.png\n");
    test_write_file("patch.obj", "mtllib patch.mtl\no light\nusemtl glow\n"
                                 "v 0 0 0\nv 0 0 2\nv 2 0 2\nv 2 0 0\n"
                                 "vt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\n"
                                 "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
    rad_scene *scene = test_load_scene("patch.obj");
    rad_mesh *mesh = NULL;
    rad_patch_inputs *inputs = NULL;
    rad_error error;
    if (!scene || rad_mesh_build(scene, 10, &mesh, &error) != RAD_OK ||
        rad_patch_inputs_build(scene, mesh, &inputs, &error) != RAD_OK) {
        test_fail(__FILE__, __LINE__, "%s", error.message);
        goto done;
    }
    CHECK(mesh->patch_count == 1);
    const double expected[3] = {RAD_PI * 0.5, RAD_PI * 0.25, RAD_PI * 0.125};
    CHECK_NEAR(inputs->exitance[0].r, expected[0], 1e-6);
    CHECK_NEAR(inputs->exitance[0].g, expected[1], 1e-6);
    CHECK_NEAR(inputs->exitance[0].b, expected[2], 1e-6);
    rad_rgb emission;
    CHECK(rad_patch_materials(scene, mesh, NULL, &emission, &error) == RAD_OK);
    CHECK_NEAR(emission.r, 0.5, 1e-6);
    const rad_solver solvers[2] = {RAD_SOLVER_JACOBI, RAD_SOLVER_HIERARCHICAL};
    for (int k = 0; k < 2; k++) {
        rad_rgb B = {0, 0, 0};
        rad_scene_solve_options options = {.solver = solvers[k]};
        CHECK(rad_solve_scene(scene, mesh, &options, &B, NULL, &error) == RAD_OK);
        printf("emission texture in the %s solve: B = (%.6f, %.6f, %.6f), pi Ke x 0.5 = "
               "(%.6f, %.6f, %.6f)\n",
               rad_solver_name(solvers[k]), B.r, B.g, B.b, expected[0], expected[1],
               expected[2]);
        CHECK_NEAR(B.r, expected[0], 1e-6);
        CHECK_NEAR(B.g, expected[1], 1e-6);
        CHECK_NEAR(B.b, expected[2], 1e-6);
    }
done:
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* ---------------------------------------------------------------------------------- */

static void log_to_buffer(void *user, const char *message)
{
    char *buffer = user;
    size_t n = strlen(buffer);
    snprintf(buffer + n, 4096 - n, "%s\n", message);
}

/* Importing: a glTF emissiveTexture (sRGB like baseColor) times emissiveFactor times
 * KHR_materials_emissive_strength (its texCoord 1 is a warning); an MTL map_Ke whose file is missing is a warning and
 * the emission stays Ke; a map_Ke without Ke is a warning (it emits nothing). */
static void import_emission_textures(void)
{
    const unsigned value = 188;
    write_stripes("grey188.png", 4, 4, value, value);
    float data[4 * 3 + 4 * 2] = {0, 0, 0, 0, 0, 2, 2, 0, 2, 2, 0, 0, 0, 1, 0, 0, 1, 0, 1, 1};
    uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
    FILE *file = fopen(test_path("quad.bin"), "wb");
    if (file) {
        fwrite(data, sizeof(data), 1, file);
        fwrite(indices, sizeof(indices), 1, file);
        fclose(file);
    }
    test_write_file(
        "glow.gltf",
        "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_materials_emissive_strength\"],"
        "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"name\":\"light\",\"primitives\":[{\"attributes\":{\"POSITION\":0,"
        "\"TEXCOORD_0\":1,\"TEXCOORD_1\":1},\"indices\":2,\"material\":0}]}],"
        "\"materials\":[{\"name\":\"glow\",\"emissiveFactor\":[1,0.5,0.25],"
        "\"emissiveTexture\":{\"index\":0,\"texCoord\":1},"
        "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4}},"
        "\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1]}}],"
        "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"grey188.png\"}],"
        "\"buffers\":[{\"byteLength\":92,\"uri\":\"quad.bin\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,"
        "\"byteLength\":32},{\"buffer\":0,\"byteOffset\":80,\"byteLength\":12}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
        "\"min\":[0,0,0],\"max\":[2,0,2]},{\"bufferView\":1,\"componentType\":5126,\"count\":4,"
        "\"type\":\"VEC2\"},{\"bufferView\":2,\"componentType\":5123,\"count\":6,"
        "\"type\":\"SCALAR\"}]}");
    static char warnings[4096];
    warnings[0] = 0;
    rad_load_options options = {log_to_buffer, warnings};
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_patch_inputs *inputs = NULL;
    rad_error error;
    CHECK(rad_scene_load(test_path("glow.gltf"), &options, &scene, &error) == RAD_OK);
    /* a second texture-coordinate set is not read: said, and set 0 used */
    CHECK(strstr(warnings, "material 'glow': emission texture 'grey188.png' uses texture "
                           "coordinates 1; only set 0 is read") != NULL);
    if (scene && rad_mesh_build(scene, 10, &mesh, &error) == RAD_OK &&
        rad_patch_inputs_build(scene, mesh, &inputs, &error) == RAD_OK) {
        CHECK(scene->materials[scene->triangles[0].material].emission_texture == 1);
        double t = test_srgb_to_linear(value);
        printf("glTF emissiveTexture (sRGB %u = linear %.5f) x factor (1, 0.5, 0.25) x "
               "strength 4: E = (%.5f, %.5f, %.5f), pi x 4 t x factor = (%.5f, %.5f, %.5f)\n",
               value, t, inputs->exitance[0].r, inputs->exitance[0].g, inputs->exitance[0].b,
               RAD_PI * 4 * t, RAD_PI * 2 * t, RAD_PI * t);
        CHECK_NEAR(inputs->exitance[0].r, RAD_PI * 4 * t, 1e-6);
        CHECK_NEAR(inputs->exitance[0].g, RAD_PI * 2 * t, 1e-6);
        CHECK_NEAR(inputs->exitance[0].b, RAD_PI * t, 1e-6);
    } else
        test_fail(__FILE__, __LINE__, "glow.gltf: %s", error.message);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);

    warnings[0] = 0;
    test_write_file("missing.mtl", "newmtl lost\nKd 0 0 0\nKe 1 1 1\nmap_Ke nowhere.png\n"
                                   "newmtl dark\nKd 0 0 0\nmap_Ke grey188.png\n");
    test_write_file("missing.obj", "mtllib missing.mtl\n"
                                   "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\n"
                                   "vt 0 0\nvt 1 0\nvt 1 1\n"
                                   "o a\nusemtl lost\nf 1/1 2/2 3/3\n"
                                   "o b\nusemtl dark\nf 4/1 5/2 6/3\n");
    scene = NULL;
    CHECK(rad_scene_load(test_path("missing.obj"), &options, &scene, &error) == RAD_OK);
    CHECK(strstr(warnings, "material 'lost': texture 'nowhere.png' not found; its emission is "
                           "the material's colour") != NULL);
    CHECK(strstr(warnings, "material 'dark': an emission texture but an emission factor of 0") !=
          NULL);
    if (scene) {
        for (uint32_t m = 0; m < scene->material_count; m++)
            if (strcmp(scene->materials[m].name, "lost") == 0) {
                CHECK(scene->materials[m].emission_texture == 0);
                CHECK_NEAR(scene->materials[m].emission.g, 1, 1e-12);
            }
        CHECK(rad_scene_has_emitter(scene));
    }
    rad_scene_destroy(scene);
    printf("import warnings:\n%s", warnings);
}

int main(void)
{
    test_tmpdir();
    textured_furnace();
    whitted_texel_ratio();
    emission_seen_directly(0);
    emission_seen_directly(0.01);
    floor_under_half_light(true);
    floor_under_half_light(false);
    solve_exitance();
    import_emission_textures();
    return test_finish("test_texture_renderers");
}
