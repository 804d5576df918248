/*
 * test_raytrace.c - Whitted ray tracing (rad_raytrace, `radiosity raytrace`) against closed
 * forms computed here, with the test's own pinhole camera and ray intersections:
 *   - Phong: a tessellated sphere (Kd, Ks, Ns from its MTL) under one point light matches
 *     Kd <N,L> I_L + Ks <V,R>^n I_L with the facet's normal at every pixel (one sample per
 *     pixel = the pixel centre);
 *   - mirror: a mirror (Kd 0, Ks coloured) shows Ks x Le where it reflects an emitter;
 *   - shadows: a floor under an occluder shows exactly Kd I_A where the point light is
 *     hidden (classified geometrically here) and Kd (I_A + <N,L> I_L) elsewhere;
 *   - area light: a floor under a square emitter shows Kd Le F (F the analytic
 *     point-to-parallel-rectangle view factor) plus the specular lobe integrated here by
 *     quadrature; the built-in Cornell box's light shows Ke + Kd I_A exactly;
 *   - determinism: 1 and 2 threads give bitwise the same image;
 *   - the command line: repeated --light (both spellings) equals the API with the same
 *     lights; bad --light / --ambient / --light-samples / --max-depth values exit 2 with a
 *     one-line message and leave no file.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

#define PI 3.14159265358979323846

typedef rad_vec3 vec;

static vec mk(double x, double y, double z) { return (vec){x, y, z}; }
static vec sub(vec a, vec b) { return mk(a.x - b.x, a.y - b.y, a.z - b.z); }
static vec add(vec a, vec b) { return mk(a.x + b.x, a.y + b.y, a.z + b.z); }
static vec scale(vec a, double s) { return mk(a.x * s, a.y * s, a.z * s); }
static double dot(vec a, vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static vec cross(vec a, vec b)
{
    return mk(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static vec unit(vec a) { return scale(a, 1 / sqrt(dot(a, a))); }

/* ------------------------------------------------------------------------------------ */
/* The test's own pinhole camera: vertical fov, right = forward x up, pixel (0,0) at the
 * top-left, one sample per pixel through the pixel centre. */

typedef struct cam {
    vec eye, forward, right, up;
    double tan_half, aspect;
    int width, height;
} cam;

static cam cam_make(vec eye, vec target, vec up, double fov, int width, int height)
{
    cam c;
    c.eye = eye;
    c.forward = unit(sub(target, eye));
    c.right = unit(cross(c.forward, up));
    c.up = cross(c.right, c.forward);
    c.tan_half = tan(fov * PI / 360);
    c.aspect = (double)width / height;
    c.width = width;
    c.height = height;
    return c;
}

static vec cam_ray(const cam *c, int x, int y)
{
    double sx = (2.0 * (x + 0.5) / c->width - 1) * c->tan_half * c->aspect;
    double sy = (1 - 2.0 * (y + 0.5) / c->height) * c->tan_half;
    return unit(add(c->forward, add(scale(c->right, sx), scale(c->up, sy))));
}

static rad_camera to_camera(vec eye, vec target, vec up, double fov)
{
    rad_camera camera = {{eye.x, eye.y, eye.z}, {target.x, target.y, target.z},
                         {up.x, up.y, up.z}, fov};
    return camera;
}

static const float *pixel(const rad_image *image, int x, int y)
{
    return &image->rgb[((size_t)y * image->width + x) * 3];
}

/* Loads a scene the test wrote; NULL (after a failed check) on error. */
static rad_scene *load(const char *name)
{
    rad_scene *scene = NULL;
    rad_error error;
    rad_status status = rad_scene_load(test_path(name), NULL, &scene, &error);
    CHECK(status == RAD_OK);
    if (status != RAD_OK)
        fprintf(stderr, "%s: %s\n", name, error.message);
    return scene;
}

static rad_image *trace(const rad_scene *scene, const rad_camera *camera,
                        const rad_raytrace_options *options, int width, int height)
{
    rad_image *image = NULL;
    rad_error error;
    CHECK(rad_image_create((uint32_t)width, (uint32_t)height, &image, &error) == RAD_OK);
    if (!image)
        return NULL;
    rad_status status = rad_raytrace(scene, camera, options, image, &error);
    CHECK(status == RAD_OK);
    if (status != RAD_OK) {
        fprintf(stderr, "rad_raytrace: %s\n", error.message);
        rad_image_destroy(image);
        return NULL;
    }
    return image;
}

/* ------------------------------------------------------------------------------------ */
/* Phong on a tessellated sphere */

enum { SPHERE_LON = 48, SPHERE_LAT = 24, SPHERE_SIZE = 64 };
#define MAX_SPHERE_TRIANGLES (2 * SPHERE_LON * SPHERE_LAT)

static vec sphere_v[SPHERE_LON * SPHERE_LAT + 2];
static int sphere_t[MAX_SPHERE_TRIANGLES][3];
static int sphere_triangles;

static const double sphere_kd[3] = {0.6, 0.4, 0.2}, sphere_ks[3] = {0.5, 0.45, 0.4};
static const double sphere_ns = 20;
static const vec sphere_eye = {0.3, 0.2, -4}, sphere_light = {3, 4, -5};
static const double sphere_intensity[3] = {1.5, 1.2, 1.0};
static const double sphere_fov = 34;

/* A UV sphere of radius 1 at the origin; coordinates rounded to float, as the loader keeps
 * them, and every triangle wound counter-clockwise seen from outside. */
static void sphere_build(void)
{
    int n = 0;
    sphere_v[n++] = mk(0, 1, 0);
    for (int i = 1; i < SPHERE_LAT; i++)
        for (int j = 0; j < SPHERE_LON; j++) {
            double theta = PI * i / SPHERE_LAT, phi = 2 * PI * j / SPHERE_LON;
            sphere_v[n++] = mk((float)(sin(theta) * cos(phi)), (float)cos(theta),
                               (float)(sin(theta) * sin(phi)));
        }
    sphere_v[n++] = mk(0, -1, 0);
    int bottom = n - 1;
#define RING(i, j) (1 + ((i)-1) * SPHERE_LON + ((j) % SPHERE_LON))
    sphere_triangles = 0;
    for (int j = 0; j < SPHERE_LON; j++) {
        int tri[2][3] = {{0, RING(1, j), RING(1, j + 1)},
                         {bottom, RING(SPHERE_LAT - 1, j + 1), RING(SPHERE_LAT - 1, j)}};
        for (int k = 0; k < 2; k++)
            memcpy(sphere_t[sphere_triangles++], tri[k], sizeof(tri[k]));
        for (int i = 1; i + 1 < SPHERE_LAT; i++) {
            int a = RING(i, j), b = RING(i, j + 1), c = RING(i + 1, j + 1), d = RING(i + 1, j);
            int quad[2][3] = {{a, d, c}, {a, c, b}};
            for (int k = 0; k < 2; k++)
                memcpy(sphere_t[sphere_triangles++], quad[k], sizeof(quad[k]));
        }
    }
#undef RING
    for (int t = 0; t < sphere_triangles; t++) { /* outward: flip where needed */
        vec a = sphere_v[sphere_t[t][0]], b = sphere_v[sphere_t[t][1]], c = sphere_v[sphere_t[t][2]];
        if (dot(cross(sub(b, a), sub(c, a)), add(a, add(b, c))) < 0) {
            int swap = sphere_t[t][1];
            sphere_t[t][1] = sphere_t[t][2];
            sphere_t[t][2] = swap;
        }
    }
    static char obj[1 << 20];
    size_t len = (size_t)snprintf(obj, sizeof(obj), "mtllib sphere.mtl\no ball\nusemtl shiny\n");
    for (int v = 0; v < n; v++)
        len += (size_t)snprintf(obj + len, sizeof(obj) - len, "v %.9g %.9g %.9g\n",
                                sphere_v[v].x, sphere_v[v].y, sphere_v[v].z);
    for (int t = 0; t < sphere_triangles; t++)
        len += (size_t)snprintf(obj + len, sizeof(obj) - len, "f %d %d %d\n",
                                sphere_t[t][0] + 1, sphere_t[t][1] + 1, sphere_t[t][2] + 1);
    test_write_file("sphere.obj", obj);
    char mtl[256];
    snprintf(mtl, sizeof(mtl), "newmtl shiny\nKd %g %g %g\nKs %g %g %g\nNs %g\n", sphere_kd[0],
             sphere_kd[1], sphere_kd[2], sphere_ks[0], sphere_ks[1], sphere_ks[2], sphere_ns);
    test_write_file("sphere.mtl", mtl);
}

/* Closest triangle of the sphere along o + t d (double precision), or -1; smallest
 * barycentric coordinate in *margin. */
static int sphere_hit(vec o, vec d, double *t_out, double *margin)
{
    int best = -1;
    double best_t = INFINITY;
    for (int t = 0; t < sphere_triangles; t++) {
        double u = 0, v = 0;
        double s = test_ray_triangle(o, d, sphere_v[sphere_t[t][0]], sphere_v[sphere_t[t][1]],
                                     sphere_v[sphere_t[t][2]], &u, &v);
        if (s <= 0 || s >= best_t)
            continue;
        best = t;
        best_t = s;
        *margin = fmin(fmin(u, v), 1 - u - v);
    }
    *t_out = best_t;
    return best;
}

static void check_phong(void)
{
    sphere_build();
    rad_scene *scene = load("sphere.obj");
    if (!scene)
        return;
    /* the loader kept the MTL's Phong parameters */
    CHECK(scene->material_count >= 1);
    const rad_material *m = &scene->materials[scene->triangles[0].material];
    CHECK_NEAR(m->specular.r, sphere_ks[0], 1e-6);
    CHECK_NEAR(m->specular.b, sphere_ks[2], 1e-6);
    CHECK_NEAR(m->shininess, sphere_ns, 1e-6);
    CHECK_NEAR(m->albedo.g, sphere_kd[1], 1e-6);
    CHECK(scene->triangle_count == (uint32_t)sphere_triangles);

    rad_point_light light = {{sphere_light.x, sphere_light.y, sphere_light.z},
                             {sphere_intensity[0], sphere_intensity[1], sphere_intensity[2]}};
    rad_raytrace_options options = {0};
    options.lights = &light;
    options.light_count = 1;
    options.samples_per_pixel = 1;
    options.threads = 2;
    vec target = mk(0, 0, 0), up = mk(0, 1, 0);
    rad_camera camera = to_camera(sphere_eye, target, up, sphere_fov);
    rad_image *image = trace(scene, &camera, &options, SPHERE_SIZE, SPHERE_SIZE);
    if (!image) {
        rad_scene_destroy(scene);
        return;
    }
    cam c = cam_make(sphere_eye, target, up, sphere_fov, SPHERE_SIZE, SPHERE_SIZE);
    int compared = 0, lit = 0, highlight = 0, dark = 0, background = 0, bad = 0;
    double worst = 0;
    for (int y = 0; y < SPHERE_SIZE; y++)
        for (int x = 0; x < SPHERE_SIZE; x++) {
            vec d = cam_ray(&c, x, y);
            double t, margin = 0;
            int tri = sphere_hit(sphere_eye, d, &t, &margin);
            const float *got = pixel(image, x, y);
            double expected[3] = {0, 0, 0};
            if (tri < 0) {
                background++;
            } else {
                if (margin < 1e-4)
                    continue; /* too near a facet edge to know which facet the tracer took */
                vec a = sphere_v[sphere_t[tri][0]], b = sphere_v[sphere_t[tri][1]],
                    cc = sphere_v[sphere_t[tri][2]];
                vec N = unit(cross(sub(b, a), sub(cc, a)));
                vec p = add(sphere_eye, scale(d, t));
                vec L = unit(sub(sphere_light, p));
                double NL = dot(N, L);
                if (fabs(NL) < 1e-3)
                    continue; /* the terminator: which side rounding falls on is moot */
                if (NL > 0) {
                    vec R = sub(scale(N, 2 * NL), L);
                    double VR = dot(scale(d, -1), R);
                    double lobe = VR > 0 ? pow(VR, sphere_ns) : 0;
                    for (int k = 0; k < 3; k++)
                        expected[k] = (sphere_kd[k] * NL + sphere_ks[k] * lobe) * sphere_intensity[k];
                    lit++;
                    highlight += lobe > 0.5;
                } else {
                    dark++;
                }
            }
            for (int k = 0; k < 3; k++) {
                double error = expected[k] > 1e-3 ? fabs(got[k] - expected[k]) / expected[k]
                                                  : fabs(got[k] - expected[k]);
                worst = fmax(worst, error);
                if (!(error <= 1e-3)) {
                    if (bad++ < 5)
                        fprintf(stderr, "phong pixel (%d,%d) channel %d: %.7g, expected %.7g\n",
                                x, y, k, got[k], expected[k]);
                }
            }
            compared++;
        }
    printf("phong: %d pixels compared (%d lit, %d in the highlight, %d facing away, %d "
           "background), worst relative error %.3g\n",
           compared, lit, highlight, dark, background, worst);
    CHECK(bad == 0);
    CHECK(lit > 1000);
    CHECK(highlight >= 4);
    CHECK(dark > 50);
    CHECK(background > 500);
    CHECK(worst <= 1e-3);

    /* the command line with two lights, both spellings, against the API with the same two */
    rad_point_light lights[2] = {light, {{-3, 1, -4}, {0.5, 0.25, 0.125}}};
    options.lights = lights;
    options.light_count = 2;
    options.seed = 1; /* the command line's default */
    rad_image *api = trace(scene, &camera, &options, SPHERE_SIZE, SPHERE_SIZE);
    int code = test_run_tool("raytrace sphere.obj -o two.pfm --size 64x64 --spp 1 "
                             "--eye 0.3,0.2,-4 --target 0,0,0 --up 0,1,0 --fov 34 "
                             "--light 3,4,-5:1.5,1.2,1 --threads 2 --light=-3,1,-4:0.5,0.25,0.125");
    CHECK(code == 0);
    if (code != 0)
        fprintf(stderr, "%s", test_read_text(test_path("stderr.txt")));
    rad_image *cli = NULL;
    rad_error error;
    CHECK(rad_image_read(test_path("two.pfm"), &cli, &error) == RAD_OK);
    if (api && cli) {
        size_t n = (size_t)SPHERE_SIZE * SPHERE_SIZE * 3, differ = 0;
        double more = 0;
        for (size_t k = 0; k < n; k++) {
            differ += api->rgb[k] != cli->rgb[k];
            more += api->rgb[k] - image->rgb[k];
        }
        printf("phong: two lights on the command line vs the API: %zu values differ; the "
               "second light adds %.4g in total\n",
               differ, more);
        CHECK(differ == 0);
        CHECK(more > 1); /* the second light is really there */
    }
    rad_image_destroy(cli);
    rad_image_destroy(api);
    rad_image_destroy(image);
    rad_scene_destroy(scene);
}

/* ------------------------------------------------------------------------------------ */
/* A mirror reflecting an emitter */

static void check_mirror(void)
{
    /* mirror: z = 0, 100 x 100, facing +z; lamp: a 1 x 1 square at z = 200 facing -z */
    test_write_file("mirror.obj",
                    "mtllib mirror.mtl\n"
                    "v -50 -50 0\nv 50 -50 0\nv 50 50 0\nv -50 50 0\n"
                    "v -0.5 -0.5 200\nv 0.5 -0.5 200\nv 0.5 0.5 200\nv -0.5 0.5 200\n"
                    "o mirror\nusemtl mirror\nf 1 2 3\nf 1 3 4\n"
                    "o lamp\nusemtl lamp\nf 5 8 7\nf 5 7 6\n");
    test_write_file("mirror.mtl", "newmtl mirror\nKd 0 0 0\nKs 0.9 0.5 0.25\nNs 100\n"
                                  "newmtl lamp\nKd 0 0 0\nKs 0 0 0\nKe 10 20 40\n");
    const double ks[3] = {0.9, 0.5, 0.25}, le[3] = {10, 20, 40};
    rad_scene *scene = load("mirror.obj");
    if (!scene)
        return;
    enum { SIZE = 64 };
    vec eye = mk(0, 0, 20), target = mk(0, 0, 0), up = mk(0, 1, 0);
    double fov = 1.0;
    rad_camera camera = to_camera(eye, target, up, fov);
    rad_raytrace_options options = {0};
    options.samples_per_pixel = 1;
    options.ambient = (rad_rgb){0.3, 0.3, 0.3}; /* K_A = Kd = 0 on both: adds nothing */
    options.threads = 2;
    rad_image *image = trace(scene, &camera, &options, SIZE, SIZE);
    if (!image) {
        rad_scene_destroy(scene);
        return;
    }
    /* The lamp also lights the mirror's Phong lobe: at most Ks Le A / (pi r^2) with
     * r >= 200, A = 1: a relative 8e-6, far below the 1e-4 checked. */
    double lobe_bound = 1.0 / (PI * 200 * 200);
    cam c = cam_make(eye, target, up, fov, SIZE, SIZE);
    int seen = 0, dark = 0, bad = 0;
    double worst = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            vec d = cam_ray(&c, x, y);
            vec p = add(eye, scale(d, -eye.z / d.z)); /* on the mirror */
            vec m = mk(d.x, d.y, -d.z);
            vec q = add(p, scale(m, 200 / m.z)); /* where the reflection meets z = 200 */
            double inside = 0.5 - fmax(fabs(q.x), fabs(q.y));
            const float *got = pixel(image, x, y);
            if (fabs(inside) < 1e-3)
                continue; /* on the lamp's edge */
            for (int k = 0; k < 3; k++) {
                double expected = inside > 0 ? ks[k] * le[k] : 0;
                double error = fabs(got[k] - expected) / (ks[k] * le[k]);
                worst = inside > 0 ? fmax(worst, error) : worst;
                if (!(error <= (inside > 0 ? 1e-4 : lobe_bound)) && bad++ < 5)
                    fprintf(stderr, "mirror pixel (%d,%d) channel %d: %.7g, expected %.7g\n", x,
                            y, k, got[k], expected);
            }
            seen += inside > 0;
            dark += inside < 0;
        }
    printf("mirror: %d pixels see the lamp (worst relative error against Ks x Le %.3g), %d "
           "see only the mirror\n",
           seen, worst, dark);
    CHECK(bad == 0);
    CHECK(seen >= 100);
    CHECK(dark >= 1000);
    rad_image_destroy(image);
    rad_scene_destroy(scene);
}

/* ------------------------------------------------------------------------------------ */
/* Shadows of a point light */

static void check_shadows(void)
{
    /* floor y = 0 (20 x 20), an occluder y = 2 (2 x 2), both facing +y */
    test_write_file("shadow.obj",
                    "mtllib shadow.mtl\n"
                    "v -10 0 -10\nv 10 0 -10\nv 10 0 10\nv -10 0 10\n"
                    "v -1 2 -1\nv 1 2 -1\nv 1 2 1\nv -1 2 1\n"
                    "o floor\nusemtl floor\nf 1 4 3\nf 1 3 2\n"
                    "o occluder\nusemtl card\nf 5 8 7\nf 5 7 6\n");
    test_write_file("shadow.mtl", "newmtl floor\nKd 0.5 0.6 0.7\nnewmtl card\nKd 0.3 0.3 0.3\n");
    const double kd[3] = {0.5, 0.6, 0.7}, ia[3] = {0.1, 0.2, 0.3}, il[3] = {1, 0.8, 0.6};
    const vec light_at = mk(0.5, 6, 0.3);
    rad_scene *scene = load("shadow.obj");
    if (!scene)
        return;
    enum { SIZE = 64 };
    vec eye = mk(0, 12, -9), target = mk(0, 0, 0), up = mk(0, 1, 0);
    double fov = 50;
    rad_camera camera = to_camera(eye, target, up, fov);
    rad_point_light light = {{light_at.x, light_at.y, light_at.z}, {il[0], il[1], il[2]}};
    rad_raytrace_options options = {0};
    options.lights = &light;
    options.light_count = 1;
    options.ambient = (rad_rgb){ia[0], ia[1], ia[2]};
    options.samples_per_pixel = 1;
    options.threads = 2;
    rad_image *image = trace(scene, &camera, &options, SIZE, SIZE);
    if (!image) {
        rad_scene_destroy(scene);
        return;
    }
    cam c = cam_make(eye, target, up, fov, SIZE, SIZE);
    int shadowed = 0, lit = 0, bad = 0;
    double worst_shadow = 0, worst_lit = 0, darkest_lit = INFINITY;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            vec d = cam_ray(&c, x, y);
            vec on_card = add(eye, scale(d, (2 - eye.y) / d.y));
            if (fmax(fabs(on_card.x), fabs(on_card.z)) < 1 + 1e-3)
                continue; /* the occluder itself (or its edge) */
            vec p = add(eye, scale(d, -eye.y / d.y));
            if (fmax(fabs(p.x), fabs(p.z)) > 10 - 1e-3)
                continue; /* beyond the floor */
            vec s = add(p, scale(sub(light_at, p), 2 / light_at.y)); /* at the card's height */
            double inside = 1 - fmax(fabs(s.x), fabs(s.z));
            if (fabs(inside) < 0.01)
                continue; /* the shadow's edge */
            vec D = sub(light_at, p);
            double NL = D.y / sqrt(dot(D, D));
            const float *got = pixel(image, x, y);
            double lum = 0;
            for (int k = 0; k < 3; k++) {
                double expected = kd[k] * ia[k] + (inside > 0 ? 0 : kd[k] * NL * il[k]);
                double error = fabs(got[k] - expected) / expected;
                if (inside > 0)
                    worst_shadow = fmax(worst_shadow, error);
                else
                    worst_lit = fmax(worst_lit, error);
                if (!(error <= 1e-5) && bad++ < 5)
                    fprintf(stderr, "shadow pixel (%d,%d) channel %d: %.7g, expected %.7g (%s)\n",
                            x, y, k, got[k], expected, inside > 0 ? "shadowed" : "lit");
                lum += got[k];
            }
            if (inside > 0)
                shadowed++;
            else {
                lit++;
                darkest_lit = fmin(darkest_lit, lum);
            }
        }
    double ambient_only = kd[0] * ia[0] + kd[1] * ia[1] + kd[2] * ia[2];
    printf("shadows: %d floor pixels hidden from the light (worst error against Kd Ia %.3g), "
           "%d lit (worst %.3g; the darkest lit sum %.4f against %.4f in shadow)\n",
           shadowed, worst_shadow, lit, worst_lit, darkest_lit, ambient_only);
    CHECK(bad == 0);
    CHECK(shadowed >= 100);
    CHECK(lit >= 1000);
    CHECK(darkest_lit > ambient_only * 1.5);
    rad_image_destroy(image);
    rad_scene_destroy(scene);
}

/* ------------------------------------------------------------------------------------ */
/* An area light over a floor */

/* View factor from a point to a rectangle in a parallel plane at height h, the point under
 * one corner, sides a and b (Howell's catalogue, B-3). */
static double corner_factor(double a, double b, double h)
{
    double X = a / h, Y = b / h, sx = sqrt(1 + X * X), sy = sqrt(1 + Y * Y);
    return (X / sx * atan(Y / sx) + Y / sy * atan(X / sy)) / (2 * PI);
}

/* Signed corner term: the rectangle from the point's foot to (x, z) relative to it. */
static double corner(double x, double z, double h)
{
    double f = corner_factor(fabs(x), fabs(z), h);
    return (x < 0) != (z < 0) ? -f : f;
}

static void check_area_light(void)
{
    /* floor y = 0 (10 x 10) facing up; lamp: 1 x 1 at y = 1 facing down */
    test_write_file("area.obj",
                    "mtllib area.mtl\n"
                    "v -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\n"
                    "v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n"
                    "o floor\nusemtl floor\nf 1 4 3\nf 1 3 2\n"
                    "o lamp\nusemtl lamp\nf 5 6 7\nf 5 7 8\n");
    test_write_file("area.mtl", "newmtl floor\nKd 0.5 0.5 0.5\nKs 0.4 0.4 0.4\nNs 10\n"
                                "newmtl lamp\nKd 0 0 0\nKe 2 3 4\n");
    const double kd = 0.5, ks = 0.4, ns = 10, le[3] = {2, 3, 4};
    rad_scene *scene = load("area.obj");
    if (!scene)
        return;
    enum { SIZE = 48 };
    vec eye = mk(0, 0.7, -2.2), target = mk(0, 0, 0.2), up = mk(0, 1, 0);
    double fov = 60;
    rad_camera camera = to_camera(eye, target, up, fov);
    rad_raytrace_options options = {0};
    options.samples_per_pixel = 1;
    options.light_samples = 1024;
    options.threads = 2;
    rad_image *image = trace(scene, &camera, &options, SIZE, SIZE);
    if (!image) {
        rad_scene_destroy(scene);
        return;
    }
    cam c = cam_make(eye, target, up, fov, SIZE, SIZE);
    int probes = 0, bad = 0, mirrored = 0;
    double worst = 0, sum_ratio = 0, lobe_share = 0;
    enum { Q = 160 }; /* midpoint quadrature of the lobe over the lamp */
    for (int y = 0; y < SIZE; y += 3)
        for (int x = 0; x < SIZE; x += 3) {
            vec d = cam_ray(&c, x, y);
            if (d.y >= 0)
                continue; /* the eye is below the lamp: a ray going down meets the floor */
            vec p = add(eye, scale(d, -eye.y / d.y));
            if (fmax(fabs(p.x), fabs(p.z)) > 5 - 1e-3)
                continue;
            double F = corner(0.5 - p.x, 0.5 - p.z, 1) - corner(-0.5 - p.x, 0.5 - p.z, 1) -
                       corner(0.5 - p.x, -0.5 - p.z, 1) + corner(-0.5 - p.x, -0.5 - p.z, 1);
            /* (1/pi) integral of <V,R>^n cos cos' / r^2 over the lamp */
            double lobe = 0;
            vec N = mk(0, 1, 0), V = scale(d, -1);
            for (int i = 0; i < Q; i++)
                for (int j = 0; j < Q; j++) {
                    vec q = mk(-0.5 + (i + 0.5) / Q, 1, -0.5 + (j + 0.5) / Q);
                    vec D = sub(q, p);
                    double r2 = dot(D, D);
                    vec L = scale(D, 1 / sqrt(r2));
                    double NL = L.y, VR = dot(V, sub(scale(N, 2 * NL), L));
                    if (VR > 0)
                        lobe += pow(VR, ns) * NL * L.y / r2;
                }
            lobe /= PI * Q * Q;
            /* the floor's mirror term Ks I_R: its reflected ray may meet the lamp */
            vec m = mk(d.x, -d.y, d.z);
            vec on_lamp = add(p, scale(m, 1 / m.y));
            double inside = 0.5 - fmax(fabs(on_lamp.x), fabs(on_lamp.z));
            if (fabs(inside) < 1e-3)
                continue;
            mirrored += inside > 0;
            const float *got = pixel(image, x, y);
            for (int k = 0; k < 3; k++) {
                double expected = (kd * F + ks * lobe + (inside > 0 ? ks : 0)) * le[k];
                double ratio = got[k] / expected;
                worst = fmax(worst, fabs(ratio - 1));
                sum_ratio += ratio;
                if (!(fabs(ratio - 1) <= 0.01) && bad++ < 5)
                    fprintf(stderr, "area pixel (%d,%d) channel %d: %.6g, expected %.6g\n", x, y,
                            k, got[k], expected);
                if (k == 0)
                    lobe_share = fmax(lobe_share, ks * lobe / (kd * F + ks * lobe));
            }
            probes++;
        }
    double mean = sum_ratio / (3.0 * probes);
    printf("area light: %d floor probes against Kd Le F + Ks Le (lobe quadrature) + Ks Le "
           "where the floor mirrors the lamp (%d probes): worst relative error %.3g, mean "
           "ratio %.5f; the lobe is up to %.0f%% of a probe\n",
           probes, mirrored, worst, mean, 100 * lobe_share);
    CHECK(mirrored >= 5);
    CHECK(bad == 0);
    CHECK(probes >= 60);
    CHECK(fabs(mean - 1) < 0.002);
    CHECK(lobe_share > 0.2); /* the specular part is really tested */
    rad_image_destroy(image);
    rad_scene_destroy(scene);
}

/* ------------------------------------------------------------------------------------ */
/* The Cornell box: the light's own radiance, and 1 vs 2 threads */

static void check_cornell(void)
{
    rad_scene *scene = NULL;
    rad_error error;
    CHECK(rad_scene_cornell_box(&scene, &error) == RAD_OK);
    if (!scene)
        return;
    enum { SIZE = 48 };
    const double ke[3] = {17, 12, 4}, kd_light = 0.78, ia[3] = {0.05, 0.1, 0.2};
    rad_raytrace_options options = {0};
    options.samples_per_pixel = 1;
    options.ambient = (rad_rgb){ia[0], ia[1], ia[2]};
    options.threads = 2;
    rad_image *image = trace(scene, &scene->camera, &options, SIZE, SIZE);
    if (image) {
        /* pixels whose centre ray meets the light (y = 548.7, x 213..343, z 227..332): the
         * light cannot light itself, so they show Ke + Kd Ia exactly */
        rad_camera cc = scene->camera;
        cam c = cam_make(mk(cc.eye.x, cc.eye.y, cc.eye.z), mk(cc.target.x, cc.target.y, cc.target.z),
                         mk(cc.up.x, cc.up.y, cc.up.z), cc.fov_degrees, SIZE, SIZE);
        int on_light = 0, bad = 0;
        for (int y = 0; y < SIZE; y++)
            for (int x = 0; x < SIZE; x++) {
                vec d = cam_ray(&c, x, y);
                vec q = add(c.eye, scale(d, (548.7 - c.eye.y) / d.y));
                if (!(d.y > 0 && q.x > 214 && q.x < 342 && q.z > 228 && q.z < 331))
                    continue;
                on_light++;
                for (int k = 0; k < 3; k++) {
                    double expected = ke[k] + kd_light * ia[k];
                    if (!(fabs(pixel(image, x, y)[k] - expected) <= 1e-6 * expected) && bad++ < 5)
                        fprintf(stderr, "light pixel (%d,%d): %.7g, expected %.7g\n", x, y,
                                pixel(image, x, y)[k], expected);
                }
            }
        printf("cornell: %d pixels on the light show Ke + Kd Ia\n", on_light);
        CHECK(on_light >= 6);
        CHECK(bad == 0);
    }
    rad_image_destroy(image);

    /* every feature at once: jittered samples, area and point lights, ambient; 150 x 9
     * samples a row make the library's 1024-sample packets end inside a pixel, and its
     * 4096-ray shadow batches fill up */
    enum { WIDE = 150, LOW = 40 };
    rad_point_light light = {{278, 400, 280}, {0.3, 0.2, 0.1}};
    options.lights = &light;
    options.light_count = 1;
    options.samples_per_pixel = 9;
    options.light_samples = 9;
    options.seed = 7;
    rad_image *two = trace(scene, &scene->camera, &options, WIDE, LOW);
    options.threads = 1;
    rad_image *one = trace(scene, &scene->camera, &options, WIDE, LOW);
    options.seed = 8;
    rad_image *other_seed = trace(scene, &scene->camera, &options, WIDE, LOW);
    if (one && two && other_seed) {
        size_t n = (size_t)WIDE * LOW * 3, differ = 0, seed_differ = 0;
        for (size_t k = 0; k < n; k++) {
            differ += one->rgb[k] != two->rgb[k];
            seed_differ += one->rgb[k] != other_seed->rgb[k];
        }
        printf("determinism: %zu values differ between 1 and 2 threads (%zu between seeds 7 "
               "and 8)\n",
               differ, seed_differ);
        CHECK(differ == 0);
        CHECK(seed_differ > n / 10); /* the seed is used (black background aside) */
    }
    rad_image_destroy(one);
    rad_image_destroy(two);
    rad_image_destroy(other_seed);

    /* the library refuses bad options */
    rad_image *small = NULL;
    CHECK(rad_image_create(4, 4, &small, &error) == RAD_OK);
    if (small) {
        rad_point_light dark = {{0, 0, 0}, {-1, 0, 0}};
        rad_raytrace_options bad = {0};
        bad.lights = &dark;
        bad.light_count = 1;
        CHECK(rad_raytrace(scene, &scene->camera, &bad, small, &error) == RAD_ERR_INVALID);
        bad.light_count = 0;
        bad.ambient.g = NAN;
        CHECK(rad_raytrace(scene, &scene->camera, &bad, small, &error) == RAD_ERR_INVALID);
        bad.ambient.g = 0;
        bad.threads = -1;
        CHECK(rad_raytrace(scene, &scene->camera, &bad, small, &error) == RAD_ERR_INVALID);
    }
    rad_image_destroy(small);
    rad_scene_destroy(scene);
}

/* ------------------------------------------------------------------------------------ */
/* The command line's new options */

static int count_lines(const char *text)
{
    int lines = 0;
    for (; *text; text++)
        lines += *text == '\n';
    return lines;
}

static void expect_usage_error(const char *arguments, const char *names)
{
    char command[1024];
    snprintf(command, sizeof(command), "raytrace -o out.pfm --size 8x8 %s", arguments);
    int code = test_run_tool(command);
    const char *err = test_read_text(test_path("stderr.txt"));
    if (code != 2 || count_lines(err) != 1 || !strstr(err, names))
        fprintf(stderr, "[%s] exit %d, stderr: %s", arguments, code, err);
    CHECK(code == 2);
    CHECK(count_lines(err) == 1);
    CHECK(strncmp(err, "radiosity: ", 11) == 0);
    CHECK(strstr(err, names) != NULL);
    CHECK(test_count_files("out") == 0);
}

static void check_command_line(void)
{
    expect_usage_error("--light 1,2,3", "--light: '1,2,3' is not X,Y,Z:R,G,B");
    expect_usage_error("--light=1,2,3:1,1", "--light: '1,2,3:1,1'");
    expect_usage_error("--light 1,2,x:1,1,1", "--light: '1,2,x:1,1,1'");
    expect_usage_error("--light 1,2,3:1,1,1,", "--light: '1,2,3:1,1,1,'");
    expect_usage_error("--light 1,2,3:1,1,1 --light 0,0,0:-1,1,1", "must not be negative");
    expect_usage_error("--light", "needs a value");
    expect_usage_error("--ambient 1,2", "--ambient: '1,2' is not R,G,B");
    expect_usage_error("--ambient 0.1,-0.1,0", "--ambient");
    expect_usage_error("--light-samples 0", "--light-samples");
    expect_usage_error("--light-samples many", "--light-samples");
    expect_usage_error("--max-depth -1", "--max-depth");
    expect_usage_error("--max-depth 0", "--max-depth");
    /* a value that looks like an option is still the option's value, as cli_parse reads it */
    expect_usage_error("--eye 0,0,0 --light --ambient", "--light: '--ambient'");

    int code = test_run_tool("raytrace --help");
    CHECK(code == 0);
    CHECK(strstr(test_read_text(test_path("stdout.txt")), "--light X,Y,Z:R,G,B") != NULL);
    /* the built-in Cornell box by default */
    code = test_run_tool("raytrace -o cornell.pfm --size 16x16 --light-samples 4 "
                         "--light 278,400,280:1,1,1 --ambient 0.1,0.1,0.1 --max-depth 2");
    CHECK(code == 0);
    CHECK(test_file_exists(test_path("cornell.pfm")));
}

int main(void)
{
    check_phong();
    check_mirror();
    check_shadows();
    check_area_light();
    check_cornell();
    check_command_line();
    return test_finish("test_raytrace");
}
