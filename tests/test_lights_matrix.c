/*
 * test_lights_matrix.c - every kind of light source (rad_light) through every solver and
 * every renderer, against closed forms and against each other. The scenes are written
 * here, to the scratch folder, in metres:
 *
 *   room: 4 x 3 x 5 m (x, y up, z), faces pointing inwards: a grey floor (albedo 0.5),
 *         a white ceiling, coloured walls (0.5 .. 0.8), a 1 m box standing on the floor.
 *   window: the room with a 2.8 x 1.7 m hole in its back wall (z = 5, facing south: the
 *         scene's north is -z), so the sun, the skies and the environment maps come in.
 *   closed: the window filled with a pane of the wall's material, for the point, spot and
 *         luminaire lights, whose energy is then known in closed form.
 *
 * Cases: point, spot, sun (a 0.53 degree disk), uniform sky, CIE overcast sky, a
 * constant environment map, a map bright in one half, and a luminaire (skipped, with a
 * line saying so, while rad_photometry_candela is the placeholder returning 0). Checks
 * per case:
 *   - every solver (gather, gauss-seidel, shoot, hierarchical, auto) against the direct
 *     solver: per-surface mean radiosity within 1 % (hierarchical 2 %);
 *   - energy (closed room, point and spot): the power absorbed, sum A (1 - rho) B / rho,
 *     equals the lamp's flux, 4 pi I, or the spot's 2 pi I (1 - cos_i + (cos_i - cos_o) / 3);
 *   - rad_render (options.scene set) against rad_pathtrace: per-surface means, and the sky
 *     seen through the window, within 3 standard errors + RENDER_ALLOWANCE; per pixel on
 *     floor pixels lit directly by a sharp light, where the render adds the light exactly;
 *   - rad_raytrace (Whitted, no ambient, one ray through each pixel's centre) on directly
 *     lit floor pixels against rho / pi x the closed-form irradiance (point, spot, sun);
 *   - rad_illuminance at the floor pixels' centres: rho / pi x E against the path
 *     tracer's pixels (and against the closed form where only the direct light is known);
 *   - determinism: the patch inputs and the render bitwise the same with 1 and 2 threads.
 * And the CLI: render, raytrace, pathtrace and illuminance with --point, --sun, --sky and
 * --environment on a small scene; bad values give one-line messages and no output file.
 * A table of every number and its reference goes to stdout. Seeds are fixed.
 */
#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

#define PI 3.14159265358979323846

enum { W = 64, H = 48, MAX_SURFACES = TEST_MAX_SURFACES };
/* Inside the room near the front wall, looking at the window: the back wall, the window's
 * sky, the floor with the box, both side walls and some of the ceiling. */
static const rad_camera camera = {{2, 1.6, 0.3}, {2, 1.1, 5}, {0, 1, 0}, 75};

/* 0.4 m patches: about 700 patches, so the direct O(n^3) oracle and the dense matrices
 * stay cheap under AddressSanitizer. */
#ifndef ROOM_PATCH
#define ROOM_PATCH 0.4
#endif
/* Path tracer samples per pixel: surface means' standard errors of a few tenths of a
 * percent under the sharp lights, about 1 % for the skies (they come in through the
 * window only by BSDF sampling). */
#ifndef PATH_SPP
#define PATH_SPP 256
#endif

/* Geometry */
#define RX 4.0
#define RY 3.0
#define RZ 5.0
#define WX0 0.6 /* the window in the back wall */
#define WX1 3.4
#define WY0 0.9
#define WY1 2.6
#define BX0 2.4 /* the box */
#define BX1 3.4
#define BZ0 2.2
#define BZ1 3.2
#define BH 1.0
#define FLOOR_RHO 0.5

/* Solver agreement (the bounds). */
#define SOLVE_TOLERANCE 1e-7
#define HIER_THRESHOLD 0.05
#define SOLVER_TOLERANCE 0.01
#define HIER_TOLERANCE 0.02
/* Energy of a closed room: the form factors' rows close to a few tenths of a percent,
 * times about 1 / (1 - rho) ~ 3 bounces (test_feature_matrix.c: measured 0.2 .. 0.4 %);
 * the patches' direct light is a mean of 64 points each. 2 % catches a lost bounce. */
#define BALANCE_TOLERANCE 0.02
/* rad_render against the path tracer, relative, beside 3 standard errors: the indirect
 * light is piecewise constant on 0.4 m patches (a tenth of the room, as 0.1 in the unit
 * room of test_feature_matrix.c, where 3 % is justified by measurement); the sharp
 * lights' direct light is exact per pixel. */
#define RENDER_ALLOWANCE 0.03
/* The same for the skies and environment maps, whose direct light is in the patches
 * (piecewise constant), not added per pixel: through the window it falls in a sharp
 * pattern the 0.4 m patches resolve coarsely. Measured (uniform sky): the walls' and
 * ceiling's means 4.2 to 6.6 % below the path tracer at 0.4 m, 0.6 to 2.8 % at 0.2 m
 * (2398 patches): discretisation, converging with the patch size, not a bias. 7 % is the
 * largest at 0.4; a sky missing from the solve or counted twice moves the walls by 50 %
 * or more. */
#define SOFT_RENDER_ALLOWANCE 0.07
/* Per pixel, in directly lit floor pixels at least a patch (0.4 m) from the box and the
 * walls: the direct light is exact in both, the indirect light (10 .. 40 % of such a
 * pixel) is interpolated from patches: 5 % of the pixel, beside 4 of its standard errors.
 * Nearer a concave corner the indirect light is not smooth on the patches' scale:
 * measured (sun), floor pixels 0.1 m from the box's sunlit face show the render 8 to 12 %
 * below the path tracer, its indirect light about half the path tracer's. */
#define PIXEL_ALLOWANCE 0.05

static double channel(rad_rgb v, int c) { return c == 0 ? v.r : c == 1 ? v.g : v.b; }

/* ---------------------------------------------------------------------------------- */
/* The table                                                                           */

static void row(const char *light, const char *what, const char *detail, double value,
                double reference, double bound, bool ok)
{
    double d = value - reference;
    if (fabs(reference) > 1e-12)
        printf("| %-12s | %-14s | %-12s | %12.6g | %12.6g | %+8.3f %% | %6.2f %% | %s |\n",
               light, what, detail, value, reference, 100 * d / fabs(reference),
               100 * bound / fabs(reference), ok ? "ok" : "FAIL");
    else
        printf("| %-12s | %-14s | %-12s | %12.6g | %12.6g | %+8.1e | %8.1e | %s |\n", light,
               what, detail, value, reference, d, bound, ok ? "ok" : "FAIL");
}

/* ---------------------------------------------------------------------------------- */
/* Scene writer                                                                        */

typedef struct obj_text {
    char text[1 << 15];
    size_t length;
    uint32_t vertices;
} obj_text;

static void put(obj_text *o, const char *format, ...) __attribute__((format(printf, 2, 3)));
static void put(obj_text *o, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    int n = vsnprintf(o->text + o->length, sizeof(o->text) - o->length, format, args);
    va_end(args);
    if (n < 0 || (size_t)n >= sizeof(o->text) - o->length) {
        fprintf(stderr, "scene text too long\n");
        exit(1);
    }
    o->length += (size_t)n;
}

#define V3(x, y, z) ((rad_vec3){x, y, z})

/* The quad p, p + u, p + u + v, p + v: its front normal is u x v. */
static void quad(obj_text *o, rad_vec3 p, rad_vec3 u, rad_vec3 v)
{
    rad_vec3 c[4] = {p,
                     {p.x + u.x, p.y + u.y, p.z + u.z},
                     {p.x + u.x + v.x, p.y + u.y + v.y, p.z + u.z + v.z},
                     {p.x + v.x, p.y + v.y, p.z + v.z}};
    for (int k = 0; k < 4; k++)
        put(o, "v %.17g %.17g %.17g\n", c[k].x, c[k].y, c[k].z);
    uint32_t b = o->vertices;
    put(o, "f %u %u %u %u\n", b + 1, b + 2, b + 3, b + 4);
    o->vertices += 4;
}

static const char *const room_mtl = "newmtl grey\nKd 0.5 0.5 0.5\n"
                                    "newmtl white\nKd 0.8 0.8 0.8\n"
                                    "newmtl wall\nKd 0.75 0.7 0.6\n"
                                    "newmtl red\nKd 0.7 0.55 0.5\n"
                                    "newmtl blue\nKd 0.55 0.6 0.75\n"
                                    "newmtl boxpaint\nKd 0.6 0.65 0.8\n";

static void write_room(const char *name, bool window)
{
    static obj_text o;
    memset(&o, 0, sizeof(o));
    put(&o, "mtllib room.mtl\n");
    put(&o, "o floor\nusemtl grey\n");
    quad(&o, V3(0, 0, 0), V3(0, 0, RZ), V3(RX, 0, 0));
    put(&o, "o ceiling\nusemtl white\n");
    quad(&o, V3(0, RY, 0), V3(RX, 0, 0), V3(0, 0, RZ));
    put(&o, "o left\nusemtl red\n");
    quad(&o, V3(0, 0, 0), V3(0, RY, 0), V3(0, 0, RZ));
    put(&o, "o right\nusemtl blue\n");
    quad(&o, V3(RX, 0, 0), V3(0, 0, RZ), V3(0, RY, 0));
    put(&o, "o front\nusemtl wall\n");
    quad(&o, V3(0, 0, 0), V3(RX, 0, 0), V3(0, RY, 0));
    put(&o, "o back\nusemtl wall\n");
    quad(&o, V3(0, 0, RZ), V3(0, WY0, 0), V3(RX, 0, 0));
    quad(&o, V3(0, WY1, RZ), V3(0, RY - WY1, 0), V3(RX, 0, 0));
    quad(&o, V3(0, WY0, RZ), V3(0, WY1 - WY0, 0), V3(WX0, 0, 0));
    quad(&o, V3(WX1, WY0, RZ), V3(0, WY1 - WY0, 0), V3(RX - WX1, 0, 0));
    if (!window) {
        put(&o, "o pane\nusemtl wall\n");
        quad(&o, V3(WX0, WY0, RZ), V3(0, WY1 - WY0, 0), V3(WX1 - WX0, 0, 0));
    }
    put(&o, "o box\nusemtl boxpaint\n");
    quad(&o, V3(BX0, BH, BZ0), V3(0, 0, BZ1 - BZ0), V3(BX1 - BX0, 0, 0));
    quad(&o, V3(BX0, 0, BZ0), V3(0, 0, BZ1 - BZ0), V3(0, BH, 0));
    quad(&o, V3(BX1, 0, BZ0), V3(0, BH, 0), V3(0, 0, BZ1 - BZ0));
    quad(&o, V3(BX0, 0, BZ0), V3(0, BH, 0), V3(BX1 - BX0, 0, 0));
    quad(&o, V3(BX0, 0, BZ1), V3(BX1 - BX0, 0, 0), V3(0, BH, 0));
    test_write_file(name, o.text);
}

/* An equirectangular .pfm (rows bottom to top, little-endian floats), 2:1. */
static void write_pfm(const char *name, uint32_t width, uint32_t height,
                      rad_rgb (*value)(uint32_t x, uint32_t y, uint32_t width, uint32_t height))
{
    FILE *f = fopen(test_path(name), "wb");
    if (!f) {
        fprintf(stderr, "cannot write %s\n", name);
        exit(1);
    }
    fprintf(f, "PF\n%u %u\n-1.0\n", width, height);
    for (uint32_t row_up = 0; row_up < height; row_up++)
        for (uint32_t x = 0; x < width; x++) {
            rad_rgb v = value(x, height - 1 - row_up, width, height); /* y = 0 at the top */
            float px[3] = {(float)v.r, (float)v.g, (float)v.b};
            fwrite(px, sizeof(float), 3, f);
        }
    fclose(f);
}

static rad_rgb map_constant(uint32_t x, uint32_t y, uint32_t width, uint32_t height)
{
    (void)x, (void)y, (void)width, (void)height;
    return (rad_rgb){300, 240, 180};
}

/* Bright from south through west to north (the left half of the map), dim elsewhere, a
 * little brighter above the horizon. */
static rad_rgb map_half(uint32_t x, uint32_t y, uint32_t width, uint32_t height)
{
    double v = (x < width / 2 ? 800 : 100) * (y < height / 2 ? 1 : 0.5);
    return (rad_rgb){v, 0.9 * v, 0.8 * v};
}

/* ---------------------------------------------------------------------------------- */
/* Geometry the test knows in closed form                                             */

static rad_vec3 v_sub(rad_vec3 a, rad_vec3 b) { return V3(a.x - b.x, a.y - b.y, a.z - b.z); }
static rad_vec3 v_cross(rad_vec3 a, rad_vec3 b)
{
    return V3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static double v_dot(rad_vec3 a, rad_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static double v_len(rad_vec3 a) { return sqrt(v_dot(a, a)); }
static rad_vec3 v_unit(rad_vec3 a)
{
    double l = v_len(a);
    return V3(a.x / l, a.y / l, a.z / l);
}

/* Does the ray o + t d, t in (t0, t1), pass through the box? (slabs) */
static bool hits_box(rad_vec3 o, rad_vec3 d, double t0, double t1)
{
    const double lo[3] = {BX0, 0, BZ0}, hi[3] = {BX1, BH, BZ1};
    const double oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
    for (int a = 0; a < 3; a++) {
        if (fabs(dd[a]) < 1e-15) {
            if (oo[a] < lo[a] || oo[a] > hi[a])
                return false;
            continue;
        }
        double ta = (lo[a] - oo[a]) / dd[a], tb = (hi[a] - oo[a]) / dd[a];
        if (ta > tb) {
            double s = ta;
            ta = tb;
            tb = s;
        }
        t0 = fmax(t0, ta);
        t1 = fmin(t1, tb);
        if (t0 > t1)
            return false;
    }
    return true;
}

/* The camera model of the renderers (radiosity.h: vertical fov, right = forward x up,
 * pixel (0,0) the top-left corner). */
static void camera_ray(double x, double y, rad_vec3 *origin, rad_vec3 *direction)
{
    rad_vec3 forward = v_unit(v_sub(camera.target, camera.eye));
    rad_vec3 right = v_unit(v_cross(forward, camera.up));
    rad_vec3 up = v_cross(right, forward);
    double t = tan(camera.fov_degrees * PI / 360), aspect = (double)W / H;
    double sx = (2 * x / W - 1) * t * aspect, sy = (1 - 2 * y / H) * t;
    *origin = camera.eye;
    *direction = V3(forward.x + sx * right.x + sy * up.x, forward.y + sx * right.y + sy * up.y,
                    forward.z + sx * right.z + sy * up.z);
}

/* Pixel classes: a surface index when the centre and four corners hit its front; SKY when
 * all five leave through the window; -1 otherwise. */
#define SKY_CLASS (MAX_SURFACES - 1)
static void classify_pixels(const rad_scene *scene, int *surface)
{
    rad_tracer *tracer = NULL;
    rad_error error = {0};
    CHECK(rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &tracer, &error) == RAD_OK);
    static const double offset[5][2] = {{0.5, 0.5}, {0, 0}, {1, 0}, {0, 1}, {1, 1}};
    rad_ray *rays = malloc(sizeof(rad_ray) * W * H * 5);
    rad_hit *hits = malloc(sizeof(rad_hit) * W * H * 5);
    if (!rays || !hits || !tracer) {
        fprintf(stderr, "out of memory or no tracer\n");
        exit(1);
    }
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int k = 0; k < 5; k++) {
                rad_vec3 o, d;
                camera_ray(x + offset[k][0], y + offset[k][1], &o, &d);
                rad_ray *r = &rays[(y * W + x) * 5 + k];
                r->origin[0] = (float)o.x;
                r->origin[1] = (float)o.y;
                r->origin[2] = (float)o.z;
                r->direction[0] = (float)d.x;
                r->direction[1] = (float)d.y;
                r->direction[2] = (float)d.z;
                r->t_near = 0;
                r->t_far = INFINITY;
            }
    rad_tracer_intersect(tracer, rays, W * H * 5, hits);
    for (int p = 0; p < W * H; p++) {
        int s = -1;
        for (int k = 0; k < 5; k++) {
            const rad_hit *h = &hits[p * 5 + k];
            int t = h->triangle == RAD_NO_HIT ? SKY_CLASS
                    : h->front               ? (int)scene->triangles[h->triangle].surface
                                             : -2;
            s = k == 0 ? t : (s == t ? s : -2);
        }
        surface[p] = s >= 0 ? s : -1;
    }
    free(rays);
    free(hits);
    rad_tracer_destroy(tracer);
}

/* The floor point seen at image point (x, y); false when the ray does not go down. */
static bool floor_point(double x, double y, rad_vec3 *point)
{
    rad_vec3 o, d;
    camera_ray(x, y, &o, &d);
    if (!(d.y < 0))
        return false;
    double t = -o.y / d.y;
    *point = V3(o.x + t * d.x, 0, o.z + t * d.z);
    return point->x > 0 && point->x < RX && point->z > 0 && point->z < RZ;
}

/* ---------------------------------------------------------------------------------- */
/* The light cases                                                                     */

typedef enum light_case {
    POINT,
    SPOT,
    SUN,
    SKY_UNIFORM,
    SKY_OVERCAST,
    ENV_CONSTANT,
    ENV_HALF,
    LUMINAIRE,
    CASE_COUNT
} light_case;

static const char *const case_names[CASE_COUNT] = {"point",   "spot",     "sun",
                                                   "sky",     "overcast", "env-const",
                                                   "env-half", "luminaire"};

static const rad_vec3 point_position = {1.5, 2.5, 2.0};
static const double point_cd = 100;
static const rad_vec3 spot_position = {2.0, 2.8, 2.5};
static const rad_vec3 spot_axis = {0.1, -1, 0.2};
static const double spot_cd = 150, spot_inner = 20, spot_outer = 35;
static const rad_vec3 toward_sun = {-0.25, 0.55, 0.8}; /* from the south, 34 degrees high */
static const double sun_lux = 50000, sun_diameter = 0.53;

static bool is_sharp(light_case c) { return c == POINT || c == SPOT || c == SUN || c == LUMINAIRE; }
static bool is_closed(light_case c) { return c == POINT || c == SPOT || c == LUMINAIRE; }

/* An isotropic photometric web of `cd` candela, built by hand (type C, one horizontal
 * angle: symmetric about the axis). */
static rad_photometry *isotropic_web(double cd)
{
    rad_photometry *ph = calloc(1, sizeof(*ph));
    if (!ph)
        return NULL;
    snprintf(ph->source, sizeof(ph->source), "(test web)");
    ph->photometric_type = 1;
    ph->vertical_count = 3;
    ph->horizontal_count = 1;
    ph->vertical_degrees = malloc(3 * sizeof(double));
    ph->horizontal_degrees = malloc(sizeof(double));
    ph->candela = malloc(3 * sizeof(double));
    if (!ph->vertical_degrees || !ph->horizontal_degrees || !ph->candela) {
        rad_photometry_destroy(ph);
        return NULL;
    }
    ph->vertical_degrees[0] = 0;
    ph->vertical_degrees[1] = 90;
    ph->vertical_degrees[2] = 180;
    ph->horizontal_degrees[0] = 0;
    for (int k = 0; k < 3; k++)
        ph->candela[k] = cd;
    ph->lumens = 4 * PI * cd;
    return ph;
}

/* Adds the case's light; false when it cannot be tested (said on stdout). */
static bool add_light(rad_scene *scene, light_case c)
{
    rad_light l;
    memset(&l, 0, sizeof(l));
    snprintf(l.name, sizeof(l.name), "%s", case_names[c]);
    switch (c) {
    case POINT:
        l.type = RAD_LIGHT_POINT;
        l.position = point_position;
        l.intensity = (rad_rgb){point_cd, point_cd, point_cd};
        break;
    case SPOT:
        l.type = RAD_LIGHT_SPOT;
        l.position = spot_position;
        l.direction = spot_axis;
        l.intensity = (rad_rgb){spot_cd, 0.9 * spot_cd, 0.8 * spot_cd};
        l.inner_degrees = spot_inner;
        l.outer_degrees = spot_outer;
        break;
    case SUN:
        l.type = RAD_LIGHT_DIRECTIONAL;
        l.direction = V3(-toward_sun.x, -toward_sun.y, -toward_sun.z);
        l.intensity = (rad_rgb){sun_lux, sun_lux, sun_lux};
        l.angular_diameter_degrees = sun_diameter;
        break;
    case SKY_UNIFORM:
    case SKY_OVERCAST:
        l.type = RAD_LIGHT_SKY;
        l.sky = c == SKY_UNIFORM ? RAD_SKY_UNIFORM : RAD_SKY_CIE_OVERCAST;
        l.intensity = (rad_rgb){3000, 3000, 3000};
        break;
    case ENV_CONSTANT:
    case ENV_HALF: {
        const char *name = c == ENV_CONSTANT ? "constant.pfm" : "half.pfm";
        write_pfm(name, 32, 16, c == ENV_CONSTANT ? map_constant : map_half);
        rad_error error = {0};
        rad_image *map = NULL;
        CHECK(rad_image_read(test_path(name), &map, &error) == RAD_OK);
        if (!map) {
            fprintf(stderr, "%s: %s\n", name, error.message);
            return false;
        }
        l.type = RAD_LIGHT_ENVIRONMENT;
        l.environment = map;
        l.intensity = (rad_rgb){1, 1, 1};
        break;
    }
    case LUMINAIRE: {
        rad_photometry *web = isotropic_web(point_cd);
        if (!web) {
            fprintf(stderr, "out of memory\n");
            exit(1);
        }
        if (!(rad_photometry_candela(web, 45, 0) > 0)) {
            printf("luminaire: skipped (rad_photometry_candela returns %g for a %g cd web: "
                   "the IES reader has not landed)\n",
                   rad_photometry_candela(web, 45, 0), point_cd);
            rad_photometry_destroy(web);
            return false;
        }
        l.type = RAD_LIGHT_LUMINAIRE;
        l.position = point_position;
        l.direction = V3(0, -1, 0);
        l.photometry = web;
        l.intensity = (rad_rgb){1, 1, 1};
        break;
    }
    case CASE_COUNT:
        return false;
    }
    rad_error error = {0};
    rad_status status = rad_scene_add_light(scene, &l, &error);
    CHECK(status == RAD_OK);
    if (status != RAD_OK) {
        fprintf(stderr, "%s: %s\n", case_names[c], error.message);
        rad_image_destroy(l.environment);
        rad_photometry_destroy(l.photometry);
        return false;
    }
    return true;
}

/* The closed-form irradiance of a sharp light at floor point x (normal +y), shadows by
 * the box and the window's edges included; *relative receives its own uncertainty (the
 * sun's disk: a ray through one point of it changes cos by up to tan(theta) x its
 * radius). Returns -1 when the point is near enough to a shadow edge that a pixel
 * footprint could straddle it (the caller leaves such pixels out). */
static double closed_form_irradiance(light_case c, rad_vec3 x, int ch, double *relative)
{
    *relative = 0;
    if (c == POINT || c == LUMINAIRE || c == SPOT) {
        rad_vec3 L = c == SPOT ? spot_position : point_position;
        rad_vec3 d = v_sub(L, x);
        double r = v_len(d);
        if (hits_box(x, d, 1e-9, 1 - 1e-9))
            return 0;
        double cosn = d.y / r;
        double I = point_cd;
        if (c == SPOT) {
            rad_vec3 axis = v_unit(spot_axis);
            double cos_a = -v_dot(d, axis) / r;
            double co = cos(spot_outer * PI / 180), ci = cos(spot_inner * PI / 180);
            double t = fmin(fmax((cos_a - co) / (ci - co), 0), 1);
            I = spot_cd * (ch == 0 ? 1 : ch == 1 ? 0.9 : 0.8) * t * t;
        }
        return I * cosn / (r * r);
    }
    /* the sun: through the window, past the box */
    rad_vec3 w = v_unit(toward_sun);
    if (hits_box(x, w, 1e-9, INFINITY))
        return 0;
    double t = (RZ - x.z) / w.z;
    double wx = x.x + t * w.x, wy = x.y + t * w.y;
    if (!(wx > WX0 && wx < WX1 && wy > WY0 && wy < WY1))
        return 0;
    double cosn = w.y;
    *relative = sqrt(1 - cosn * cosn) / cosn * (sun_diameter / 2 * PI / 180);
    return sun_lux * cosn;
}

/* Directly lit by the case's sharp light at the pixel's centre and four corners and at
 * eight points half a pixel further out (so the footprint is inside the lit region). */
static bool pixel_fully_lit(light_case c, int px, int py)
{
    for (int j = -1; j <= 2; j++)
        for (int i = -1; i <= 2; i++) {
            rad_vec3 x;
            if (!floor_point(px + 0.5 * (i + 0.5), py + 0.5 * (j + 0.5), &x))
                return false;
            double rel;
            if (!(closed_form_irradiance(c, x, 0, &rel) > 0))
                return false;
        }
    return true;
}

/* The floor point seen at the pixel's centre is at least a patch from the box's
 * footprint and from the walls. */
static bool away_from_corners(int px, int py)
{
    rad_vec3 x;
    if (!floor_point(px + 0.5, py + 0.5, &x))
        return false;
    double dx = fmax(fmax(BX0 - x.x, x.x - BX1), 0), dz = fmax(fmax(BZ0 - x.z, x.z - BZ1), 0);
    double to_walls = fmin(fmin(x.x, RX - x.x), fmin(x.z, RZ - x.z));
    return sqrt(dx * dx + dz * dz) >= ROOM_PATCH && to_walls >= ROOM_PATCH;
}

/* ---------------------------------------------------------------------------------- */
/* Means                                                                               */

typedef test_surface_means means; /* MAX_SURFACES == TEST_MAX_SURFACES */



static const char *surface_name(const rad_scene *scene, int s)
{
    if (s == SKY_CLASS)
        return "(window sky)";
    return s >= 0 && (uint32_t)s < scene->surface_count ? scene->surfaces[s].name : "?";
}

/* ---------------------------------------------------------------------------------- */
/* Solving and rendering                                                               */

static const rad_solver solvers[] = {RAD_SOLVER_DIRECT,       RAD_SOLVER_JACOBI,
                                     RAD_SOLVER_GAUSS_SEIDEL, RAD_SOLVER_SHOOT,
                                     RAD_SOLVER_HIERARCHICAL, RAD_SOLVER_AUTO};
enum { SOLVER_COUNT = sizeof(solvers) / sizeof(solvers[0]) };

static bool solve(const rad_scene *scene, const rad_mesh *mesh, const rad_patch_inputs *inputs,
                  rad_solver solver, rad_rgb *B)
{
    rad_scene_solve_options o;
    memset(&o, 0, sizeof(o));
    o.solver = solver;
    o.tolerance = SOLVE_TOLERANCE;
    o.refine_threshold = HIER_THRESHOLD;
    o.seed = 11;
    o.inputs = inputs;
    rad_scene_solve_report report;
    rad_error error = {0};
    rad_status status = rad_solve_scene(scene, mesh, &o, B, &report, &error);
    CHECK(status == RAD_OK);
    if (status != RAD_OK) {
        fprintf(stderr, "rad_solve_scene(%s): %s\n", rad_solver_name(solver), error.message);
        return false;
    }
    CHECK(report.converged);
    return true;
}

static rad_image *render(const rad_scene *scene, const rad_mesh *mesh,
                         const rad_patch_inputs *inputs, const rad_rgb *B, int threads)
{
    rad_image *image = test_new_image(W, H);
    rad_render_options o;
    memset(&o, 0, sizeof(o));
    o.samples_per_pixel = 16;
    o.edge_samples = 16;
    o.seed = 5;
    o.threads = threads;
    o.scene = scene;
    o.inputs = inputs;
    rad_error error = {0};
    rad_status status = rad_render(mesh, B, &camera, &o, image, &error);
    CHECK(status == RAD_OK);
    if (status != RAD_OK)
        fprintf(stderr, "rad_render: %s\n", error.message);
    return image;
}

static void compare_surfaces(const char *light, const char *what, const rad_scene *scene,
                             const means *value, const means *reference, double relative,
                             double standard_errors, uint32_t min_count)
{
    for (int s = 0; s < MAX_SURFACES; s++) {
        if (reference->count[s] < min_count || value->count[s] == 0)
            continue;
        bool ok = true;
        double worst = -1, v = 0, r = 0, bound = 0;
        for (int c = 0; c < 3; c++) {
            double x = channel(value->mean[s], c), y = channel(reference->mean[s], c);
            double allowed = standard_errors * channel(reference->se[s], c) + relative * fabs(y);
            if (y == 0 && x == 0)
                continue;
            bool good = fabs(x - y) <= allowed;
            ok = ok && good;
            double score = allowed > 0 ? fabs(x - y) / allowed : 1e300;
            if (score > worst) {
                worst = score;
                v = x;
                r = y;
                bound = allowed;
            }
        }
        if (worst < 0)
            continue;
        row(light, what, surface_name(scene, s), v, r, bound, ok);
        CHECK(ok);
    }
}

/* Power absorbed in a closed room: sum A (1 - rho) H, H = B / rho (no emitters). */
static double absorbed_power(const rad_patch_inputs *in, const rad_rgb *B, int c)
{
    double sum = 0;
    for (uint32_t i = 0; i < in->n; i++) {
        double rho = channel(in->albedo[i], c);
        sum += in->area[i] * (1 - rho) * channel(B[i], c) / rho;
    }
    return sum;
}

/* ---------------------------------------------------------------------------------- */
/* One case                                                                            */

static void run_case(light_case c)
{
    const char *name = case_names[c];
    const char *file = is_closed(c) ? "closed.obj" : "window.obj";
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load(test_path(file), NULL, &scene, &error) == RAD_OK);
    if (!scene) {
        fprintf(stderr, "%s: %s\n", file, error.message);
        return;
    }
    if (!add_light(scene, c)) {
        rad_scene_destroy(scene);
        return;
    }
    rad_mesh *mesh = NULL;
    CHECK(rad_mesh_build(scene, ROOM_PATCH, &mesh, &error) == RAD_OK);
    rad_patch_inputs *inputs = NULL, *inputs_two = NULL;
    /* determinism: the patch inputs with one thread and with two */
    int max_threads = omp_get_max_threads();
    omp_set_num_threads(1);
    if (mesh)
        CHECK(rad_patch_inputs_build(scene, mesh, &inputs, &error) == RAD_OK);
    omp_set_num_threads(2);
    if (mesh)
        CHECK(rad_patch_inputs_build(scene, mesh, &inputs_two, &error) == RAD_OK);
    omp_set_num_threads(max_threads);
    if (!mesh || !inputs || !inputs_two) {
        fprintf(stderr, "%s: %s\n", name, error.message);
        rad_patch_inputs_destroy(inputs);
        rad_patch_inputs_destroy(inputs_two);
        rad_mesh_destroy(mesh);
        rad_scene_destroy(scene);
        return;
    }
    uint32_t n = mesh->patch_count;
    bool same_inputs = memcmp(inputs->direct, inputs_two->direct, n * sizeof(rad_rgb)) == 0 &&
                       memcmp(inputs->direct_sharp, inputs_two->direct_sharp,
                              n * sizeof(rad_rgb)) == 0 &&
                       memcmp(inputs->source, inputs_two->source, n * sizeof(rad_rgb)) == 0;
    row(name, "inputs 1 vs 2", "bitwise", same_inputs, 1, 0, same_inputs);
    CHECK(same_inputs);
    rad_patch_inputs_destroy(inputs_two);
    printf("%s: %u patches\n", name, n);
    /* the light reaches the room at all */
    double lit = 0;
    for (uint32_t i = 0; i < n; i++)
        lit += inputs->area[i] * inputs->direct[i].g;
    CHECK(lit > 0);

    /* every solver against the direct one */
    rad_rgb *B[SOLVER_COUNT] = {NULL};
    means solved[SOLVER_COUNT];
    for (int k = 0; k < SOLVER_COUNT; k++) {
        B[k] = calloc(n, sizeof(rad_rgb));
        if (!B[k]) {
            fprintf(stderr, "out of memory\n");
            exit(1);
        }
        if (!solve(scene, mesh, inputs, solvers[k], B[k])) {
            free(B[k]);
            B[k] = NULL;
            continue;
        }
        test_solution_surface_means(scene, mesh, B[k], &solved[k]);
        if (k > 0 && B[0]) {
            double tolerance =
                solvers[k] == RAD_SOLVER_HIERARCHICAL ? HIER_TOLERANCE : SOLVER_TOLERANCE;
            compare_surfaces(name, rad_solver_name(solvers[k]), scene, &solved[k], &solved[0],
                             tolerance, 0, 1);
        }
        /* energy: every lumen the lamp sends is absorbed somewhere in the closed room */
        if (c == POINT || c == SPOT || c == LUMINAIRE) {
            double co = cos(spot_outer * PI / 180), ci = cos(spot_inner * PI / 180);
            for (int ch = 0; ch < 3; ch++) {
                double flux = c == SPOT ? 2 * PI * spot_cd * (ch == 0 ? 1 : ch == 1 ? 0.9 : 0.8) *
                                              (1 - ci + (ci - co) / 3)
                                        : 4 * PI * point_cd;
                double absorbed = absorbed_power(inputs, B[k], ch);
                bool ok = fabs(absorbed - flux) <= BALANCE_TOLERANCE * flux;
                char what[32];
                snprintf(what, sizeof(what), "absorbed.%c", "rgb"[ch]);
                row(name, rad_solver_name(solvers[k]), what, absorbed, flux,
                    BALANCE_TOLERANCE * flux, ok);
                CHECK(ok);
            }
        }
    }
    if (!B[0]) {
        for (int k = 0; k < SOLVER_COUNT; k++)
            free(B[k]);
        rad_patch_inputs_destroy(inputs);
        rad_mesh_destroy(mesh);
        rad_scene_destroy(scene);
        return;
    }

    /* the renderers */
    int surface[W * H];
    classify_pixels(scene, surface);
    rad_image *path = test_new_image(W, H), *path_se = test_new_image(W, H);
    {
        rad_pathtrace_options o;
        memset(&o, 0, sizeof(o));
        o.samples_per_pixel = PATH_SPP;
        o.seed = 3;
        CHECK(rad_pathtrace(scene, &camera, &o, path, path_se, NULL, &error) == RAD_OK);
    }
    rad_image *image = render(scene, mesh, inputs, B[0], 1);
    rad_image *image_two = render(scene, mesh, inputs, B[0], 2);
    bool same_image = memcmp(image->rgb, image_two->rgb, sizeof(float) * 3 * W * H) == 0;
    row(name, "render 1 vs 2", "bitwise", same_image, 1, 0, same_image);
    CHECK(same_image);
    rad_image_destroy(image_two);
    means rendered, traced;
    test_image_surface_means(image, NULL, surface, &rendered);
    test_image_surface_means(path, path_se, surface, &traced);
    compare_surfaces(name, "render/path", scene, &rendered, &traced,
                     is_sharp(c) ? RENDER_ALLOWANCE : SOFT_RENDER_ALLOWANCE, 3, 30);
    if (!is_closed(c))
        CHECK(traced.count[SKY_CLASS] > 30); /* the camera sees the window's sky */

    /* per pixel where a sharp light lights the floor directly */
    int floor_s = -1;
    for (uint32_t s = 0; s < scene->surface_count; s++)
        if (strcmp(scene->surfaces[s].name, "floor") == 0)
            floor_s = (int)s;
    CHECK(floor_s >= 0);
    if (is_sharp(c)) {
        int count = 0, bad = 0;
        double worst = -1, wv = 0, wr = 0, wb = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                int p = y * W + x;
                if (surface[p] != floor_s || !pixel_fully_lit(c, x, y) ||
                    !away_from_corners(x, y))
                    continue;
                count++;
                for (int ch = 0; ch < 3; ch++) {
                    double a = image->rgb[p * 3 + ch], b = path->rgb[p * 3 + ch];
                    double allowed = 4 * path_se->rgb[p * 3 + ch] + PIXEL_ALLOWANCE * b;
                    bad += !(fabs(a - b) <= allowed);
                    if (!(fabs(a - b) <= allowed))
                        printf("%s: pixel (%d, %d) channel %d: render %g, path %g +- %g\n",
                               name, x, y, ch, a, b, (double)path_se->rgb[p * 3 + ch]);
                    if (fabs(a - b) / allowed > worst) {
                        worst = fabs(a - b) / allowed;
                        wv = a;
                        wr = b;
                        wb = allowed;
                    }
                }
            }
        row(name, "render/path px", "worst", wv, wr, wb, bad == 0);
        printf("%s: %d directly lit floor pixels, %d channel values outside\n", name, count, bad);
        CHECK(count >= 20);
        CHECK(bad == 0);

        /* Whitted's direct term against the closed form, one ray through each centre */
        rad_image *whitted = test_new_image(W, H);
        rad_raytrace_options o;
        memset(&o, 0, sizeof(o));
        o.samples_per_pixel = 1;
        o.seed = 9;
        CHECK(rad_raytrace(scene, &camera, &o, whitted, &error) == RAD_OK);
        int wbad = 0;
        worst = -1;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                int p = y * W + x;
                if (surface[p] != floor_s || !pixel_fully_lit(c, x, y))
                    continue;
                rad_vec3 point;
                if (!floor_point(x + 0.5, y + 0.5, &point))
                    continue;
                for (int ch = 0; ch < 3; ch++) {
                    double rel;
                    double expected = FLOOR_RHO / PI * closed_form_irradiance(c, point, ch, &rel);
                    double got = whitted->rgb[p * 3 + ch];
                    /* 1e-4: float hit points (1e-7 relative of a 5 m room) and r^2 */
                    double allowed = (rel + 1e-4) * expected;
                    wbad += !(fabs(got - expected) <= allowed);
                    if (fabs(got - expected) / allowed > worst) {
                        worst = fabs(got - expected) / allowed;
                        wv = got;
                        wr = expected;
                        wb = allowed;
                    }
                }
            }
        row(name, "whitted/cf px", "worst", wv, wr, wb, wbad == 0);
        CHECK(wbad == 0);
        rad_image_destroy(whitted);
    }

    /* rad_illuminance at the floor pixels' centres: rho / pi x E against the path tracer's
     * pixels (means over the floor, and over its directly lit part) */
    {
        rad_vec3 *points = malloc(sizeof(rad_vec3) * W * H);
        rad_vec3 *normals = malloc(sizeof(rad_vec3) * W * H);
        int *pixel = malloc(sizeof(int) * W * H);
        rad_rgb *E = malloc(sizeof(rad_rgb) * W * H);
        if (!points || !normals || !pixel || !E) {
            fprintf(stderr, "out of memory\n");
            exit(1);
        }
        uint32_t count = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                rad_vec3 point;
                if (surface[y * W + x] != floor_s || !floor_point(x + 0.5, y + 0.5, &point))
                    continue;
                points[count] = point;
                normals[count] = V3(0, 1, 0);
                pixel[count++] = y * W + x;
            }
        rad_illuminance_options o;
        memset(&o, 0, sizeof(o));
        o.gather_rays = 256;
        o.seed = 4;
        CHECK(rad_illuminance(scene, mesh, B[0], points, normals, count, &o, E, &error) ==
              RAD_OK);
        for (int part = 0; part < (is_sharp(c) ? 2 : 1); part++) {
            means a, b;
            memset(&a, 0, sizeof(a));
            memset(&b, 0, sizeof(b));
            double var[3] = {0};
            uint32_t m = 0;
            for (uint32_t i = 0; i < count; i++) {
                int p = pixel[i];
                if (part == 1 && !pixel_fully_lit(c, p % W, p / W))
                    continue;
                m++;
                for (int ch = 0; ch < 3; ch++) {
                    (&a.mean[0].r)[ch] += FLOOR_RHO / PI * channel(E[i], ch);
                    (&b.mean[0].r)[ch] += path->rgb[p * 3 + ch];
                    var[ch] += (double)path_se->rgb[p * 3 + ch] * path_se->rgb[p * 3 + ch];
                }
            }
            if (m < 20)
                continue;
            for (int ch = 0; ch < 3; ch++) {
                (&a.mean[0].r)[ch] /= m;
                (&b.mean[0].r)[ch] /= m;
                (&b.se[0].r)[ch] = sqrt(var[ch]) / m;
            }
            a.count[0] = b.count[0] = m;
            /* the surfaces' light is gathered from the interpolated solution: the same
             * allowance as the render's */
            compare_surfaces(name, part ? "illum/path lit" : "illum/path", scene, &a, &b,
                             RENDER_ALLOWANCE, 3, 20);
        }
        free(points);
        free(normals);
        free(pixel);
        free(E);
    }

    rad_image_destroy(image);
    rad_image_destroy(path);
    rad_image_destroy(path_se);
    for (int k = 0; k < SOLVER_COUNT; k++)
        free(B[k]);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* ---------------------------------------------------------------------------------- */
/* The command line                                                                    */

/* One line on stderr that names what is wrong. */
static bool one_line_mentioning(const char *text)
{
    const char *err = test_read_text(test_path("stderr.txt"));
    size_t length = strlen(err);
    const char *newline = strchr(err, '\n');
    bool one = length > 0 && newline && newline == err + length - 1;
    if (!one || !strstr(err, text))
        fprintf(stderr, "stderr was: %s", err);
    return one && strstr(err, text) != NULL;
}

/* How many lines of stderr hold `text`. */
static int lines_with(const char *text)
{
    const char *err = test_read_text(test_path("stderr.txt"));
    int count = 0;
    for (const char *line = err; *line;) {
        const char *end = strchr(line, '\n');
        size_t length = end ? (size_t)(end - line) : strlen(line);
        const char *found = strstr(line, text);
        count += found && found < line + length;
        line += length + (end ? 1 : 0);
    }
    return count;
}

static void run_cli(void)
{
    static const char *const commands[] = {"render", "raytrace", "pathtrace", "illuminance"};
    static const char *const lights[] = {"--point 1.5,2.5,2:100", "--sun -0.25,0.55,0.8:50000",
                                         "--sky cie-overcast:3000",
                                         "--environment half.pfm:1"};
    write_pfm("half.pfm", 32, 16, map_half);
    const char *common = "--patch-size 1 --threads 2";
    for (int k = 0; k < 4; k++)
        for (int l = 0; l < 4; l++) {
            char arguments[1024], out[64];
            bool illuminance = k == 3;
            snprintf(out, sizeof(out), "cli-%d-%d.%s", k, l, illuminance ? "csv" : "pfm");
            if (illuminance)
                snprintf(arguments, sizeof(arguments),
                         "illuminance window.obj %s --plane 0.8 --spacing 1 --gather-rays 16 "
                         "%s -o %s",
                         common, lights[l], out);
            else
                snprintf(arguments, sizeof(arguments),
                         "%s window.obj %s --size 16x12 --spp 4 --eye 2,1.6,0.3 "
                         "--target 2,1.1,5 %s -o %s",
                         commands[k], k == 0 ? common : "--threads 2", lights[l], out);
            int code = test_run_tool(arguments);
            bool ok = code == 0 && test_file_exists(test_path(out));
            /* a scene lit by a light source is not black: no warning may say so */
            if (lines_with("will be black") != 0) {
                fprintf(stderr, "radiosity %s with %s warns of a black image: %s", commands[k],
                        lights[l], test_read_text(test_path("stderr.txt")));
                ok = false;
            }
            printf("cli: radiosity %s ... %s: exit %d%s\n", commands[k], lights[l], code,
                   ok ? "" : " FAIL");
            if (!ok)
                fprintf(stderr, "%s", test_read_text(test_path("stderr.txt")));
            CHECK(ok);
        }
    /* bad values: one line each, no output */
    write_pfm("wide.pfm", 48, 16, map_constant); /* 3:1 */
    for (int k = 0; k < 4; k++) {
        char arguments[1024], out[64];
        bool illuminance = k == 3;
        snprintf(out, sizeof(out), "bad-%d.%s", k, illuminance ? "csv" : "pfm");
        const char *extra = illuminance ? "--plane 0.8 --spacing 1" : "--size 8x8";
        snprintf(arguments, sizeof(arguments), "%s window.obj %s --environment missing.hdr -o %s",
                 commands[k], extra, out);
        CHECK(test_run_tool(arguments) != 0);
        CHECK(one_line_mentioning("missing.hdr"));
        CHECK(!test_file_exists(test_path(out)));
        snprintf(arguments, sizeof(arguments), "%s window.obj %s --environment wide.pfm -o %s",
                 commands[k], extra, out);
        CHECK(test_run_tool(arguments) != 0);
        CHECK(one_line_mentioning("48x16"));
        CHECK(!test_file_exists(test_path(out)));
        /* a sun below the horizon: a one-line warning, no sunlight, the run goes on */
        snprintf(arguments, sizeof(arguments),
                 "%s window.obj %s %s --sun 0,-1,0 --sky uniform:1000 -o %s", commands[k],
                 extra, k == 0 || illuminance ? "--patch-size 1" : "", out);
        CHECK(test_run_tool(arguments) == 0);
        CHECK(lines_with("below the horizon") == 1);
        CHECK(test_file_exists(test_path(out)));
        remove(test_path(out));
    }
}

int main(void)
{
    test_tmpdir();
    test_write_file("room.mtl", room_mtl);
    write_room("window.obj", true);
    write_room("closed.obj", false);
    printf("| light        | check          | detail       |        value |    reference "
           "|      diff |    bound | |\n|---|---|---|---|---|---|---|---|---|\n");
    for (int c = 0; c < CASE_COUNT; c++)
        run_case((light_case)c);
    run_cli();
    return test_finish("test_lights_matrix");
}
