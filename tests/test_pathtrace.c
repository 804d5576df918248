/*
 * test_pathtrace.c - the Monte-Carlo path tracer against independent references.
 *
 *   - furnace (VALIDATION.md section 3): a closed cube with Ke = 1, Kd = 0.5 everywhere
 *     shows 1 / (1 - 0.5) = 2; the image mean within 3 of its standard errors, every pixel
 *     within 5 of its own (plus 1 %). With max_depth D: the truncated series
 *     sum_{b<=D} 0.5^b = 2 - 0.5^D.
 *   - direct light, closed form: a one-sided rectangular emitter facing a large floor and
 *     nothing else; the floor under a point p shows Kd Le F(p -> rectangle), F from the
 *     point-to-parallel-rectangle formula (VALIDATION.md section 2) summed over the four
 *     rectangles that share the corner above p.
 *   - convergence: on the Cornell box the RMSE against a long run falls as 1/sqrt(spp)
 *     (16 against 64 spp), away from the pixels that see the light itself.
 *   - determinism: 1 and 2 threads give bitwise the same image and standard errors.
 *   - the command line: output, --standard-error, --stats, usage errors and exit codes.
 * Statistical checks use fixed seeds, so they pass or fail the same way every run.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

#define PI 3.14159265358979323846

/* ---------------------------------------------------------------------------------- */
/* helpers                                                                             */

static rad_scene *load(const char *name)
{
    rad_scene *scene = NULL;
    rad_error error = {0};
    rad_status status = rad_scene_load(test_path(name), NULL, &scene, &error);
    CHECK(status == RAD_OK);
    if (status != RAD_OK)
        fprintf(stderr, "%s\n", error.message);
    return scene;
}

/* Path traces `scene` into fresh images (caller destroys them); NULL on failure. */
static rad_image *trace(const rad_scene *scene, const rad_camera *camera, uint32_t width,
                        uint32_t height, const rad_pathtrace_options *options,
                        rad_image **standard_error, rad_pathtrace_report *report)
{
    rad_image *image = NULL;
    rad_error error = {0};
    CHECK(rad_image_create(width, height, &image, &error) == RAD_OK);
    if (standard_error)
        CHECK(rad_image_create(width, height, standard_error, &error) == RAD_OK);
    rad_status status = rad_pathtrace(scene, camera, options, image,
                                      standard_error ? *standard_error : NULL, report, &error);
    CHECK(status == RAD_OK);
    if (status != RAD_OK) {
        fprintf(stderr, "rad_pathtrace: %s\n", error.message);
        rad_image_destroy(image);
        return NULL;
    }
    return image;
}

/* Mean of channel c over the block [x0, x0 + n) x [y0, y0 + n), and the standard error
 * of that mean from the per-pixel standard errors (pixels are independent). */
static void block_mean(const rad_image *image, const rad_image *se, uint32_t x0, uint32_t y0,
                       uint32_t nx, uint32_t ny, int c, double *mean, double *mean_se)
{
    double sum = 0, var = 0;
    for (uint32_t y = y0; y < y0 + ny; y++)
        for (uint32_t x = x0; x < x0 + nx; x++) {
            size_t k = ((size_t)y * image->width + x) * 3 + c;
            sum += image->rgb[k];
            var += (double)se->rgb[k] * se->rgb[k];
        }
    double n = (double)nx * ny;
    *mean = sum / n;
    *mean_se = sqrt(var) / n;
}

/* ---------------------------------------------------------------------------------- */
/* furnace                                                                             */


/* From inside, looking at a corner region so that edges and corners are in view. */
static const rad_camera furnace_camera = {{0.5, 0.5, 0.05}, {0.7, 0.4, 1}, {0, 1, 0}, 100};

/* The mean over the image must be within 3 of its standard errors; with every_pixel,
 * each pixel within 5 of its own standard errors plus a 1 % band. The band is there
 * because a pixel's standard error is itself estimated from its samples, and Russian
 * roulette makes their distribution skewed (rare long paths carry more): a pixel that
 * drew none of them reports too small an error, while a local bias (a leak at an edge,
 * self-shadowing) would stand out by far more. */
static void check_furnace(const rad_scene *scene, uint32_t spp, uint32_t max_depth,
                          uint64_t seed, bool every_pixel)
{
    double expected = 2.0 - (max_depth ? pow(0.5, max_depth) : 0.0); /* sum_{b<=D} 0.5^b */
    rad_pathtrace_options options = {.samples_per_pixel = spp, .max_depth = max_depth,
                                     .seed = seed, .threads = 2};
    rad_image *se = NULL;
    rad_pathtrace_report report = {0};
    rad_image *image = trace(scene, &furnace_camera, 48, 40, &options, &se, &report);
    if (!image)
        goto done;
    CHECK(report.rays > (uint64_t)48 * 40 * spp);
    for (int c = 0; c < 3; c++) {
        double mean, mean_se;
        block_mean(image, se, 0, 0, 48, 40, c, &mean, &mean_se);
        if (c == 0)
            printf("furnace spp %u max-depth %u: mean %.6f, expected %.6f, standard error "
                   "%.2g, off by %.2f standard errors; %.2f M rays\n",
                   spp, max_depth, mean, expected, mean_se, (mean - expected) / mean_se,
                   report.rays / 1e6);
        CHECK(mean_se > 0 && mean_se < 0.01);
        CHECK_ABS(mean, expected, 3 * mean_se);
    }
    if (every_pixel) {
        size_t n = (size_t)48 * 40 * 3, outside = 0;
        double worst = 0, farthest = 0;
        for (size_t k = 0; k < n; k++) {
            double d = fabs(image->rgb[k] - expected);
            worst = fmax(worst, d / se->rgb[k]);
            farthest = fmax(farthest, d);
            outside += !(d <= 5 * se->rgb[k] + 0.01 * expected);
        }
        printf("  worst pixel %.2f standard errors from %.4f; farthest %.4f (%.1f %%)\n", worst,
               expected, farthest, 100 * farthest / expected);
        CHECK(outside == 0);
    }
done:
    rad_image_destroy(image);
    rad_image_destroy(se);
}

/* ---------------------------------------------------------------------------------- */
/* direct lighting: a rectangular emitter above a floor                                */

/* Point-to-parallel-rectangle view factor (VALIDATION.md section 2): a x b rectangle at
 * distance c, the point's normal through one of its corners. */
static double corner_rectangle(double a, double b, double c)
{
    double X = a / c, Y = b / c;
    double sx = sqrt(1 + X * X), sy = sqrt(1 + Y * Y);
    return (X / sx * atan(Y / sx) + Y / sy * atan(X / sy)) / (2 * PI);
}

/* Emitter x in [-0.3, 0.7], z in [-0.4, 0.6] at height 1, front facing down (-y); the
 * floor (y = 0, front up) spans 100 x 100. The emitter absorbs everything (Kd = 0), so
 * the floor sees nothing but the light: no interreflection at all. */
static const char *lamp_obj =
    "mtllib lamp.mtl\n"
    "v -50 0 -50\nv 50 0 -50\nv 50 0 50\nv -50 0 50\n"
    "v -0.3 1 -0.4\nv 0.7 1 -0.4\nv 0.7 1 0.6\nv -0.3 1 0.6\n"
    "o floor\nusemtl floor\nf 1 4 3 2\n"
    "o lamp\nusemtl lamp\nf 5 6 7 8\n";

static const char *lamp_mtl = "newmtl floor\nKd 0.5 0.4 0.3\nKe 0 0 0\n"
                              "newmtl lamp\nKd 0 0 0\nKe 10 5 2\n";

static void check_direct_light(void)
{
    test_write_file("lamp.obj", lamp_obj);
    test_write_file("lamp.mtl", lamp_mtl);
    rad_scene *scene = load("lamp.obj");
    if (!scene)
        return;
    /* the rectangle seen from the origin: four rectangles meeting above it */
    double F = corner_rectangle(0.3, 0.4, 1) + corner_rectangle(0.7, 0.4, 1) +
               corner_rectangle(0.3, 0.6, 1) + corner_rectangle(0.7, 0.6, 1);
    const double kd[3] = {0.5, 0.4, 0.3}, le[3] = {10, 5, 2};
    /* a narrow view of the origin from the side, below the lamp's edge */
    rad_camera camera = {{0, 0.9, -1.5}, {0, 0, 0}, {0, 1, 0}, 2};
    rad_pathtrace_options options = {.samples_per_pixel = 1024, .seed = 7, .threads = 2};
    rad_image *se = NULL;
    rad_image *image = trace(scene, &camera, 17, 17, &options, &se, NULL);
    if (image) {
        for (int c = 0; c < 3; c++) {
            double mean, mean_se, expected = kd[c] * le[c] * F;
            block_mean(image, se, 7, 7, 3, 3, c, &mean, &mean_se); /* around pixel (8, 8) */
            printf("direct light channel %d: %.5f, closed form Kd Le F = %.5f (F = %.6f), "
                   "standard error %.2g (%.2f %%), off by %.2f standard errors\n",
                   c, mean, expected, F, mean_se, 100 * mean_se / expected,
                   (mean - expected) / mean_se);
            CHECK_ABS(mean, expected, 3 * mean_se + 0.01 * expected);
        }
    }
    /* with one bounce allowed the answer is the same: there is nothing but direct light */
    options.max_depth = 1;
    options.seed = 8;
    rad_image *se1 = NULL;
    rad_image *image1 = trace(scene, &camera, 17, 17, &options, &se1, NULL);
    if (image1) {
        double mean, mean_se, expected = kd[0] * le[0] * F;
        block_mean(image1, se1, 7, 7, 3, 3, 0, &mean, &mean_se);
        CHECK_ABS(mean, expected, 3 * mean_se + 0.01 * expected);
    }
    rad_image_destroy(image);
    rad_image_destroy(se);
    rad_image_destroy(image1);
    rad_image_destroy(se1);
    rad_scene_destroy(scene);
}

/* ---------------------------------------------------------------------------------- */
/* Cornell box: convergence and determinism                                            */

/* The pixels that may see the light of the Cornell box directly, by the test's own
 * pinhole model of the official camera (eye (278, 273, -800), looking +z, vertical fov
 * 2 atan(12.5/35), +x on the image's left): the light's bounding box in the image plus a
 * pixel. Their error is how much of the pixel the light covers, which stratified camera
 * samples estimate faster than 1/sqrt(spp), and with values near 17 it would swamp the
 * RMSE of everything else. */
static bool sees_light(uint32_t x, uint32_t y, uint32_t width, uint32_t height)
{
    double tan_half = 12.5 / 35.0, lo_x = INFINITY, hi_x = -INFINITY, lo_y = INFINITY,
           hi_y = -INFINITY;
    const double corner_x[2] = {213, 343}, corner_z[2] = {227, 332};
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            double dx = corner_x[i] - 278, dy = 548.7 - 273, dz = corner_z[j] + 800;
            double px = (1 - dx / dz / tan_half) / 2 * width;
            double py = (1 - dy / dz / tan_half) / 2 * height;
            lo_x = fmin(lo_x, px);
            hi_x = fmax(hi_x, px);
            lo_y = fmin(lo_y, py);
            hi_y = fmax(hi_y, py);
        }
    return x + 1.0 >= floor(lo_x) && x <= floor(hi_x) + 1.0 && y + 1.0 >= floor(lo_y) &&
           y <= floor(hi_y) + 1.0;
}

/* RMSE over the pixels that do not see the light; *all_rmse over every pixel. */
static double rmse_without_light(const rad_image *a, const rad_image *b, double *all_rmse,
                                 uint32_t *masked)
{
    double sum = 0, all = 0;
    size_t n = 0;
    *masked = 0;
    for (uint32_t y = 0; y < a->height; y++)
        for (uint32_t x = 0; x < a->width; x++) {
            bool light = sees_light(x, y, a->width, a->height);
            *masked += light;
            for (int c = 0; c < 3; c++) {
                size_t k = ((size_t)y * a->width + x) * 3 + c;
                double d = (double)a->rgb[k] - b->rgb[k];
                all += d * d;
                if (!light) {
                    sum += d * d;
                    n++;
                }
            }
        }
    *all_rmse = sqrt(all / ((size_t)a->width * a->height * 3));
    return sqrt(sum / n);
}

static void check_convergence(const rad_scene *cornell)
{
    enum { N = 48, REFERENCE_SPP = 2048 };
    rad_pathtrace_options options = {.threads = 2};
    options.samples_per_pixel = REFERENCE_SPP;
    options.seed = 1;
    rad_pathtrace_report report = {0};
    rad_image *reference = trace(cornell, &cornell->camera, N, N, &options, NULL, &report);
    options.samples_per_pixel = 16;
    options.seed = 2;
    rad_image *low = trace(cornell, &cornell->camera, N, N, &options, NULL, NULL);
    options.samples_per_pixel = 64;
    options.seed = 3;
    rad_image *high = trace(cornell, &cornell->camera, N, N, &options, NULL, NULL);
    if (reference && low && high) {
        double all16, all64;
        uint32_t masked;
        double e16 = rmse_without_light(low, reference, &all16, &masked);
        double e64 = rmse_without_light(high, reference, &all64, &masked);
        /* the reference's own noise adds in quadrature: sigma^2 (1/n + 1/REFERENCE_SPP) */
        double predicted = sqrt((1.0 / 16 + 1.0 / REFERENCE_SPP) / (1.0 / 64 + 1.0 / REFERENCE_SPP));
        printf("Cornell %dx%d against %d spp (%.2f s, %.1f M rays/s), %u light pixels left "
               "out: RMSE %.5f at 16 spp, %.5f at 64 spp, ratio %.3f (1/sqrt(spp) predicts "
               "%.3f); with the light pixels %.5f and %.5f, ratio %.3f\n",
               N, N, REFERENCE_SPP, report.seconds, report.rays / report.seconds / 1e6, masked,
               e16, e64, e16 / e64, predicted, all16, all64, all16 / all64);
        CHECK(masked > 0 && masked < N * N / 10);
        CHECK(e16 / e64 >= 1.6 && e16 / e64 <= 2.5);
        CHECK(all16 / all64 >= 1.6); /* with the light's edges: at least as fast */
    }
    rad_image_destroy(reference);
    rad_image_destroy(low);
    rad_image_destroy(high);
}

static void check_threads(const rad_scene *cornell)
{
    /* 40 x 40 leaves partial tiles at the right and bottom; 10 spp is not a square */
    rad_pathtrace_options options = {.samples_per_pixel = 10, .seed = 5, .threads = 1};
    rad_image *se1 = NULL, *se2 = NULL, *se3 = NULL;
    rad_image *one = trace(cornell, &cornell->camera, 40, 40, &options, &se1, NULL);
    options.threads = 2;
    rad_image *two = trace(cornell, &cornell->camera, 40, 40, &options, &se2, NULL);
    options.seed = 6;
    rad_image *other = trace(cornell, &cornell->camera, 40, 40, &options, &se3, NULL);
    if (one && two && other) {
        size_t bytes = (size_t)40 * 40 * 3 * sizeof(float);
        CHECK(memcmp(one->rgb, two->rgb, bytes) == 0);
        CHECK(memcmp(se1->rgb, se2->rgb, bytes) == 0);
        CHECK(memcmp(one->rgb, other->rgb, bytes) != 0); /* the seed matters */
    }
    rad_image_destroy(one);
    rad_image_destroy(two);
    rad_image_destroy(other);
    rad_image_destroy(se1);
    rad_image_destroy(se2);
    rad_image_destroy(se3);
}

static void check_api_errors(const rad_scene *cornell)
{
    rad_image *image = NULL, *small = NULL;
    rad_error error = {0};
    CHECK(rad_image_create(8, 8, &image, &error) == RAD_OK);
    CHECK(rad_image_create(4, 8, &small, &error) == RAD_OK);
    rad_pathtrace_options options = {.samples_per_pixel = 1};
    CHECK(rad_pathtrace(cornell, &cornell->camera, &options, image, small, NULL, &error) ==
          RAD_ERR_INVALID);
    options.threads = -1;
    CHECK(rad_pathtrace(cornell, &cornell->camera, &options, image, NULL, NULL, &error) ==
          RAD_ERR_INVALID);
    options.threads = 1;
    rad_camera bad = cornell->camera;
    bad.target = bad.eye;
    CHECK(rad_pathtrace(cornell, &bad, &options, image, NULL, NULL, &error) == RAD_ERR_INVALID);
    /* one sample: the standard error is unknown, reported as infinite */
    rad_image *se = NULL;
    CHECK(rad_image_create(8, 8, &se, &error) == RAD_OK);
    CHECK(rad_pathtrace(cornell, &cornell->camera, &options, image, se, NULL, &error) == RAD_OK);
    CHECK(se && isinf(se->rgb[0]));
    rad_image_destroy(se);
    rad_image_destroy(image);
    rad_image_destroy(small);
}

/* ---------------------------------------------------------------------------------- */
/* command line                                                                        */

static bool same_file(const char *a, const char *b)
{
    FILE *fa = fopen(test_path(a), "rb"), *fb = fopen(test_path(b), "rb");
    bool same = fa && fb;
    while (same) {
        int ca = fgetc(fa), cb = fgetc(fb);
        same = ca == cb;
        if (ca == EOF || cb == EOF)
            break;
    }
    if (fa)
        fclose(fa);
    if (fb)
        fclose(fb);
    return same;
}

static void check_cli(void)
{
    CHECK(test_run_tool("pathtrace --help") == 0);
    CHECK(strstr(test_read_text(test_path("stdout.txt")), "--max-depth") != NULL);

    int code = test_run_tool("pathtrace -o t1.pfm --size 24x20 --spp 8 --threads 1 "
                             "--standard-error t1-se.pfm --stats t1.json");
    CHECK(code == 0);
    if (code != 0)
        fprintf(stderr, "%s\n", test_read_text(test_path("stderr.txt")));
    CHECK(test_run_tool("pathtrace -o t2.pfm --size 24x20 --spp 8 --threads 2") == 0);
    CHECK(same_file("t1.pfm", "t2.pfm"));
    rad_image *image = NULL, *se = NULL;
    rad_error error;
    CHECK(rad_image_read(test_path("t1.pfm"), &image, &error) == RAD_OK);
    CHECK(rad_image_read(test_path("t1-se.pfm"), &se, &error) == RAD_OK);
    CHECK(image && image->width == 24 && image->height == 20);
    CHECK(se && se->width == 24 && se->height == 20);
    rad_image_destroy(image);
    rad_image_destroy(se);
    const char *stats = test_read_text(test_path("t1.json"));
    CHECK(strstr(stats, "\"rays_cast\"") && strstr(stats, "\"samples_per_pixel\": 8") &&
          strstr(stats, "\"mean_radiance_r\""));

    /* usage errors: exit 2, one line, nothing written */
    const char *usage_errors[] = {
        "pathtrace --size 8x8",                                   /* no -o */
        "pathtrace -o u.pfm --max-depth lots",                    /* bad number */
        "pathtrace -o u.pfm --spp 0",                             /* zero samples */
        "pathtrace -o u.txt",                                     /* unknown format */
        "pathtrace -o u.pfm --standard-error u-se.png",           /* noise as a picture */
        "pathtrace -o u.pfm --patch-size 3",                      /* a radiosity option */
        "pathtrace a.obj b.obj -o u.pfm",                         /* two scenes */
    };
    for (size_t k = 0; k < sizeof(usage_errors) / sizeof(usage_errors[0]); k++) {
        code = test_run_tool(usage_errors[k]);
        const char *err = test_read_text(test_path("stderr.txt"));
        if (code != 2)
            fprintf(stderr, "'%s' exited %d: %s\n", usage_errors[k], code, err);
        CHECK(code == 2);
        CHECK(strncmp(err, "radiosity: ", 11) == 0 && strchr(err, '\n') == err + strlen(err) - 1);
    }
    /* errors: exit 1, nothing written */
    CHECK(test_run_tool("pathtrace missing.obj -o m.pfm --size 8x8") == 1);
    CHECK(test_run_tool("pathtrace -o no-such-folder/m.pfm --size 8x8") == 1);
    CHECK(test_run_tool("pathtrace --eye 278,273,-800 --target 278,273,-800 -o m.pfm "
                        "--size 8x8") == 1);
    CHECK(test_count_files("m.") == 0 && test_count_files("u") == 0);
}

int main(void)
{
    test_write_furnace("furnace.obj");
    rad_scene *furnace = load("furnace.obj");
    if (furnace) {
        check_furnace(furnace, 256, 0, 11, true);
        /* the truncated series: where MIS and the depth limit meet, and roulette */
        check_furnace(furnace, 10, 1, 12, false); /* 10 spp: 9 stratified + 1 uniform */
        check_furnace(furnace, 16, 2, 13, false);
        check_furnace(furnace, 16, 7, 14, false); /* Russian roulette from bounce 5 on */
    }
    rad_scene_destroy(furnace);

    check_direct_light();

    rad_scene *cornell = NULL;
    rad_error error;
    CHECK(rad_scene_cornell_box(&cornell, &error) == RAD_OK);
    if (cornell) {
        check_convergence(cornell);
        check_threads(cornell);
        check_api_errors(cornell);
    }
    rad_scene_destroy(cornell);

    check_cli();
    return test_finish("test_pathtrace");
}
